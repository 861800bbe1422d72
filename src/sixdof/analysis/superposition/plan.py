"""The modal basis, the method chosen and why, the modes kept, and the runs that make a result (:class:`Plan`)."""

from __future__ import annotations

import numpy as np

from sixdof.analysis.statespace import CLASSICAL_RTOL, modal_basis
from sixdof.analysis.statespace import coupling as coupling_of
from sixdof.analysis.superposition.coordinates import _modal_coordinates
from sixdof.errors import InputError, integer, number
from sixdof.model.modes import modal_analysis


class Plan:
    """The modal basis, the method chosen and why, the modes kept, and the runs that make a result.

    Parameters
    ----------
    M, C : ndarray, shape (6, 6)
        Mass and viscous damping matrices.
    modes : sixdof.analysis.modal.Modes or ndarray
        The undamped modes (anything with ``eigenvalues`` and ``shapes``), or the stiffness matrix K
        to compute them from.
    method, n_modes, f_max_hz, branches
        As :func:`modal_solve`'s.
    """

    def __init__(self, M, C, modes, method="auto", n_modes=None, f_max_hz=None, branches=None):
        if isinstance(modes, np.ndarray):
            modes = modal_analysis(M, modes)
        self.basis, self.omega2 = modal_basis(modes, C)
        D = self.basis.T @ C @ self.basis
        self.D = 0.5 * (D + D.T)
        self.coupling = float(np.max(coupling_of(self.D), initial=0.0))
        self.branches = branches
        self.classical = self.coupling <= CLASSICAL_RTOL and branches is None
        if branches is not None:
            if method == "real":
                raise InputError("method", "'auto' or 'complex' (Maxwell branches couple the real modes)", method)
            if n_modes is not None or f_max_hz is not None:
                raise InputError("n_modes" if n_modes is not None else "f_max_hz", "no truncation with Maxwell "
                                 "branches (a dropped mode has no static residual through a branch)",
                                 n_modes if n_modes is not None else f_max_hz)
        self.kept = _select(self.omega2, n_modes, f_max_hz)
        self.dropped = np.flatnonzero(~np.isin(np.arange(6), self.kept))
        self.method = method
        self.chosen = "real" if method == "real" or (method == "auto" and self.classical) else "complex"
        self.reason = _reason(method, self.coupling, self.classical, branches)
        # The response; with truncation, the same with every mode (its error); with real modes forced
        # on non-classical damping, the exact complex-mode response (the error of neglecting the coupling).
        self.runs = ((self.chosen, tuple(int(i) for i in self.kept)),)
        if self.dropped.size:
            self.runs += ((self.chosen, tuple(range(6))),)
        if self.chosen == "real" and not self.classical:
            self.runs += (("complex", tuple(range(6))),)
        # |lambda| <= omega + d for every mode: bounds the phase an interval spans (a Maxwell branch adds at
        # most its relaxation rate and its stiffness's frequency, Gershgorin on the scaled state matrix).
        self.fastest = float(np.sqrt(np.max(self.omega2)) + np.max(np.diag(self.D)))
        if branches is not None:
            coupling = np.abs(self.basis.T @ branches.rows.T) * np.sqrt(branches.stiffness)[None, :]
            self.fastest += float(np.max(1.0 / branches.tau) + np.max(coupling.sum(axis=0))
                                  + np.max(coupling.sum(axis=1)))

    def coordinates(self, run):
        solve_method, kept = run
        return _modal_coordinates(self.basis, self.omega2, self.D, np.asarray(kept), solve_method,
                                  all_complex=self.method == "complex", branches=self.branches)


def _reason(method, coupling, classical, branches=None) -> str:
    if branches is not None:
        return (f"{method}: Maxwell branches ({branches.count} states) couple the real modes: complex modes of the "
                "augmented first-order system")
    if method == "auto" and classical:
        return (f"auto: damping is classical (largest modal coupling {coupling:.1e} <= {CLASSICAL_RTOL:.0e}): "
                "real modes")
    if method == "auto":
        return (f"auto: damping couples the real modes (largest coupling |D_ij|/sqrt(D_ii D_jj) = {coupling:.2e} > "
                f"{CLASSICAL_RTOL:.0e}, non-proportional damping): complex modes")
    if method == "real" and classical:
        return f"forced real modes; damping is classical (coupling {coupling:.1e})"
    if method == "real":
        return (f"forced real modes on non-classical damping (coupling {coupling:.2e}): the off-diagonal modal "
                "damping is neglected, the result is approximate (see approximation)")
    return f"forced complex modes (damping coupling {coupling:.1e})"


def _select(omega2, n_modes, f_max_hz):
    keep = np.ones(6, dtype=bool)
    n_rigid = int(np.sum(omega2 == 0.0))
    if n_modes is not None:
        if integer(n_modes, "n_modes", "an integer from 1 to 6", 1) > 6:
            raise InputError("n_modes", "an integer from 1 to 6", n_modes)
        if n_modes < n_rigid:
            raise InputError("n_modes", f"at least {n_rigid} (the rigid-body modes have no static residual)", n_modes)
        keep &= np.arange(6) < n_modes
    if f_max_hz is not None:
        number(f_max_hz, "f_max_hz", "a positive frequency in Hz", low=0.0, strict=True)
        keep &= np.sqrt(omega2) / (2 * np.pi) <= f_max_hz
        if not np.any(keep):
            lowest = np.sqrt(omega2[0]) / (2 * np.pi)
            raise InputError("f_max_hz", f"at least the lowest natural frequency ({lowest:.4g} Hz)", f_max_hz)
    return np.flatnonzero(keep)
