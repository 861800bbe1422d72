"""Modes across systems, on top of the undamped modes of :mod:`sixdof.model.modes`: repeated eigenvalues and
the pairing of modes by their shapes."""

from __future__ import annotations

import numpy as np

#: Two eigenvalues closer than this fraction of the largest are one repeated eigenvalue.
REPEATED_RTOL = 1e-8


def repeated_groups(eigenvalues, rtol: float = REPEATED_RTOL) -> list[tuple[int, ...]]:
    """Runs of ascending ``eigenvalues`` closer than ``rtol`` of the largest to their neighbour, as index groups:
    repeated eigenvalues (the rigid-body modes' zeros among them), whose modes' shapes are any basis of the
    group's space."""
    eigenvalues = np.asarray(eigenvalues, dtype=float)
    tolerance = rtol * max(float(np.max(np.abs(eigenvalues))), np.finfo(float).tiny)
    groups, run = [], [0]
    for j in range(1, len(eigenvalues)):
        if eigenvalues[j] - eigenvalues[j - 1] <= tolerance:
            run.append(j)
        else:
            if len(run) > 1:
                groups.append(tuple(run))
            run = [j]
    if len(run) > 1:
        groups.append(tuple(run))
    return groups


def pair_by_similarity(similarity) -> np.ndarray:
    """Pair rows with columns of ``similarity`` (..., n, m), most similar pair first, each row and column used
    once: how modes are followed by their shapes (the damped modes of :func:`sixdof.analysis.statespace.damped_modes`,
    a sweep's variants in :func:`sixdof.analysis.batch.run_batch`).

    Entries of ``-inf`` are never paired. Greedy rather than the optimal assignment: a pair whose shapes agree
    best is never broken up to raise the sum of others (which for similar shapes picks the same pairs).

    Returns
    -------
    ndarray of int, shape (..., n)
        The column paired with each row; -1 for a row left unpaired.
    """
    left = np.array(similarity, dtype=float)  # a copy: paired rows and columns are struck out of it
    *batch, n, m = left.shape
    left = left.reshape(-1, n, m)
    cases = np.arange(len(left))
    paired = np.full((len(left), n), -1)
    for _ in range(min(n, m)):
        row, column = np.divmod(np.argmax(left.reshape(len(left), -1), axis=1), m)
        found = left[cases, row, column] > -np.inf
        paired[cases[found], row[found]] = column[found]
        left[cases, row, :] = -np.inf
        left[cases, :, column] = -np.inf
    return paired.reshape(*batch, n)
