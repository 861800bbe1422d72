"""The viscous damping matrix C: mount dashpots, Rayleigh and modal damping, combined."""

from __future__ import annotations

import numpy as np
import scipy.linalg

from sixdof.analysis.modal import modal_analysis

#: Damping is classical (the real modes decouple it) when Phi' C Phi is diagonal to this fraction.
CLASSICAL_RTOL = 1e-9


def damping_matrix(system) -> np.ndarray:
    """Total damping matrix of a :class:`~sixdof.model.system.System` (6, 6) [N s/m, N s, N m s/rad].

    ``C = C_mounts + alpha M + beta K + M Phi diag(2 zeta_r omega_r) Phi' M``: the mounts'
    dashpots, the Rayleigh term and the modal term, each optional, summed. The modal term gives mode
    r exactly the ratio ``zeta_r`` on top of what the others give (zero for rigid-body modes).
    """
    C = np.array(system.C_mounts, dtype=float)
    if system.rayleigh is not None:
        C += system.rayleigh.alpha * system.M + system.rayleigh.beta * system.K
    if system.modal_damping is not None:
        modes = modal_analysis(system.M, system.K)
        zeta = np.broadcast_to(np.asarray(system.modal_damping, dtype=float), (6,))
        mphi = system.M @ modes.shapes
        C += mphi @ np.diag(2.0 * zeta * modes.omega) @ mphi.T
    return 0.5 * (C + C.T)


def modal_damping_ratios(C: np.ndarray, modes) -> np.ndarray:
    """Damping ratio of each undamped mode, ``phi_r' C phi_r / (2 omega_r)`` (6,).

    Exact for classical (proportional) damping; for non-proportional damping it is the usual
    diagonal approximation (:func:`damping_ratios` gives the exact ones). Rigid-body modes get ``nan``.
    """
    diag = np.einsum("ir,ij,jr->r", modes.shapes, np.asarray(C, dtype=float), modes.shapes)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(modes.omega > 0, diag / (2.0 * modes.omega), np.nan)


def damping_ratios(M: np.ndarray, C: np.ndarray, K: np.ndarray, modes) -> np.ndarray:
    """Exact damping ratio of each mode, from the eigenvalues of ``lambda^2 M + lambda C + K``.

    Each undamped mode r is paired with the complex mode whose displacement shape matches it best
    (mass-weighted MAC), and ``zeta_r = -Re(lambda) / |lambda|``. For classical damping this equals
    :func:`modal_damping_ratios`; for non-proportional damping (mount dashpots) it is the ratio a
    free decay shows, where the diagonal approximation is only first-order. Modes whose damping is
    critical or more (real eigenvalues) and rigid-body modes keep the diagonal value (``nan`` for
    rigid-body modes).

    Parameters
    ----------
    M, C, K : array_like, shape (6, 6)
        Mass [kg, kg m^2], damping [N s/m ...] and stiffness [N/m ...] matrices.
    modes : sixdof.analysis.modal.Modes
        The undamped modes of (M, K).

    Returns
    -------
    ndarray, shape (6,)
        Damping ratio of each undamped mode (dimensionless).
    """
    M, C, K = (np.asarray(a, dtype=float) for a in (M, C, K))
    approximate = modal_damping_ratios(C, modes)
    D = modes.shapes.T @ C @ modes.shapes
    scale = max(float(np.max(np.abs(np.diag(D)))), np.finfo(float).tiny)
    off_diagonal = D - np.diag(np.diag(D))
    if np.max(np.abs(off_diagonal)) <= CLASSICAL_RTOL * scale:
        return approximate
    n = M.shape[0]
    state = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    eigenvalues, vectors = scipy.linalg.eig(state)
    oscillating = np.flatnonzero(eigenvalues.imag > 1e-9 * np.abs(eigenvalues).max())
    exact = approximate.copy()
    pairs = []
    for r in np.flatnonzero(modes.omega > 0):
        phi = modes.shapes[:, r]
        for k in oscillating:
            v = vectors[:n, k]
            mac = abs(phi @ M @ v) ** 2 / ((phi @ M @ phi) * np.real(np.conj(v) @ M @ v))
            pairs.append((mac, r, k))
    # Pair undamped and complex modes by shape, most similar first, each used once.
    paired_modes, paired_poles = set(), set()
    for _, r, k in sorted(pairs, reverse=True):
        if r not in paired_modes and k not in paired_poles:
            paired_modes.add(r)
            paired_poles.add(k)
            exact[r] = -eigenvalues[k].real / abs(eigenvalues[k])
    return exact
