"""The 6x6 receptance ``H = Z^-1``, two ways: a batched LU solve of the dynamic stiffness, and the modal sum."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sixdof.analysis.frf.records import FRF, FRFCrossCheck
from sixdof.analysis.statespace import complex_modes, is_classical, modal_basis, modal_damping_ratios
from sixdof.errors import InputError, Plain, SolverError, choice_check, instance, readonly
from sixdof.model.kinematics import mount_matrix
from sixdof.model.system import System

#: A rigid-body mode counts as undamped when its modal damping is below this fraction of the
#: system's frequency scale (largest natural circular frequency or modal damping term); an elastic
#: mode when its damping ratio (viscous plus hysteretic) is below it.
RIGID_DAMPING_RTOL = 1e-12


#: A frequency this close (relative) to an undamped mode's natural frequency is refused: the dynamic
#: stiffness is singular there to round-off (direct and modal receptances of the undamped bridge
#: differ by ~1e-7 at 1e-9 off, by up to 87 % exactly on it).
UNDAMPED_RESONANCE_RTOL = 1e-9


#: Multiply-adds per row block of the modal sum's matrix product (see :meth:`_ModalTerms.evaluate`).
_BLOCK_MACS = 200_000


def _frequencies(f_hz) -> np.ndarray:
    try:
        f = np.atleast_1d(readonly(f_hz))
    except (TypeError, ValueError):
        f = None
    if f is None or f.ndim > 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise InputError("f_hz", "finite frequencies >= 0 in Hz (a number or a 1-D array)", f_hz)
    return f


_check_method = choice_check(("direct", "modal"))


_check_basis = choice_check(("auto", "real", "complex"))


def hysteretic_stiffness(system: System) -> np.ndarray:
    """Hysteretic stiffness ``K_h`` (6, 6) [N/m, N, N m/rad]: mount stiffness times loss factor.

    The complex stiffness of the mounts is ``K + i K_h``.
    """
    eta = system.loss_factors
    if not np.any(eta):
        return np.zeros((6, 6))  # no hysteresis (the common case): exactly zero
    # NumPy, not the JAX assembly: a JAX dispatch costs ~1 ms, a third of the fast receptance's budget.
    return mount_matrix(system.positions, system.stiffnesses * eta, system.axes)


def support_stiffness(system: System, omega) -> np.ndarray:
    """What acts on the body's motion relative to the ground, ``K + i K_h + i w C + K_b(w)``, (nf, 6, 6) complex
    [N/m, N, N m/rad] at ``omega`` (nf,) [rad/s]: springs, loss factors, all viscous damping and the Maxwell
    branches' ``K_b(w) = sum_b R_b' R_b k_b (i w tau_b) / (1 + i w tau_b)``."""
    w = np.asarray(omega, dtype=float)[:, None, None]
    static = np.asarray(system.K, dtype=complex) + 1j * hysteretic_stiffness(system)
    Z = static[None] + (1j * w) * np.asarray(system.C)[None]
    if system.branches.count:
        Z = Z + system.branches.matrix(omega)
    return Z


def dynamic_stiffness(system: System, f_hz) -> np.ndarray:
    """Dynamic stiffness ``Z = K + i K_h - w^2 M + i w C + K_b(w)`` at every frequency, (nf, 6, 6) complex
    (:func:`support_stiffness`, less the inertia).

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz], >= 0.
    """
    omega = 2.0 * np.pi * _frequencies(f_hz)
    return support_stiffness(system, omega) - omega[:, None, None] ** 2 * np.asarray(system.M)[None]


def check_resonances(system: System, f_hz, field: str = "f_hz") -> None:
    """Refuse a frequency on the natural frequency of a mode no damping acts on (its response is infinite).

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    field : str
        Named in the error.

    Raises
    ------
    InputError
        Naming the first such frequency and the mode, when a frequency is within
        :data:`UNDAMPED_RESONANCE_RTOL` (relative) of the natural frequency of an elastic mode whose
        damping ratio, viscous plus hysteretic, is below :data:`RIGID_DAMPING_RTOL`.
    """
    f = _frequencies(f_hz)
    modes = system.modes
    # zeta_r = phi_r' C phi_r / (2 w_r) + phi_r' K_h phi_r / (2 w_r^2); nan for rigid-body modes (never hit).
    hysteretic = modal_damping_ratios(hysteretic_stiffness(system), modes)
    with np.errstate(invalid="ignore"):
        zeta = modal_damping_ratios(system.C, modes) + hysteretic / modes.omega
    if system.branches.count:  # a Maxwell branch damps every mode it deforms: Im(phi' K_b(w_r) phi) > 0
        shapes = np.asarray(modes.shapes)
        zeta = zeta + np.einsum("ir,rij,jr->r", shapes, system.branches.matrix(modes.omega).imag, shapes)
    for r in np.flatnonzero(zeta <= RIGID_DAMPING_RTOL):
        f_r = float(modes.frequency_hz[r])
        hit = np.flatnonzero(np.abs(f - f_r) <= UNDAMPED_RESONANCE_RTOL * f_r)
        if hit.size:
            i = int(hit[0])
            raise InputError(field, f"frequencies off the natural frequency of mode {r + 1} ({f_r:.12g} Hz) by more "
                             f"than {UNDAMPED_RESONANCE_RTOL:.0e} of it: no damping acts on that mode, so its "
                             "response there is infinite (add damping or move the frequency)",
                             Plain(f"{f[i]:.12g} Hz (frequency {i + 1} of {f.size})"))


def receptance(system: System, f_hz, method: str = "direct", basis: str = "auto") -> FRF:
    """Generalized 6x6 receptance ``H(w) = (K + i K_h - w^2 M + i w C)^-1``.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz], finite and >= 0 (> 0 for a system with unrestrained DOFs).
    method : {"direct", "modal"}
        Batched solve of the dynamic stiffness (the reference; works for every system), or
        summation over modes (the fast path, ~5x faster at many frequencies; raises SolverError
        for nearly defective complex modes, e.g. a critically damped mode).
    basis : {"auto", "real", "complex"}
        Modal method only: ``"auto"`` uses real modes when damping and hysteresis are classical and
        complex modes otherwise; ``"complex"`` forces complex modes (always exact); ``"real"``
        insists on real modes and raises if damping is not classical.

    Returns
    -------
    FRF
        ``H`` (nf, 6, 6) complex [m/N, rad/(N m), 1/N]; see :meth:`FRF.units`.

    Raises
    ------
    InputError
        A ``system`` that is not a System; bad frequencies (negative, non-finite; zero for an
        unrestrained system; on the natural frequency of an undamped mode, :func:`check_resonances`),
        method or basis.
    SolverError
        The dynamic stiffness is singular at a requested frequency, or the complex modes are nearly
        defective.
    """
    instance(system, "system", System)  # the FRFs of points and transmissibilities come through here
    f = _frequencies(f_hz)
    check_resonances(system, f)
    _check_method(method, "method")
    _check_basis(basis, "basis")
    if np.any(f == 0.0) and system.modes.zero_modes:
        free = ", ".join(system.modes.free_dofs) or "some DOFs"
        raise InputError("f_hz", f"frequencies > 0 Hz: the mounts leave {free} unrestrained, so the static "
                         "response (f = 0) is unbounded", f.tolist())
    if method == "direct":
        try:
            # Batched LAPACK LU (getrf/getri) with partial pivoting: one call for all frequencies.
            H, used = np.linalg.inv(dynamic_stiffness(system, f)), "dynamic stiffness"
        except np.linalg.LinAlgError:
            raise SolverError("receptance (direct): the dynamic stiffness is singular at a requested frequency "
                              "(an undamped natural frequency hit exactly)") from None
    else:
        terms = _modal_terms(system, basis)
        with np.errstate(divide="ignore", invalid="ignore"):
            H, used = terms.evaluate(2.0 * np.pi * f), terms.basis
    if not np.isfinite(H.view(float)).all():  # the float view: half the cost of complex isfinite
        raise SolverError(f"receptance ({method}): non-finite values; a requested frequency sits exactly on an "
                          "undamped natural frequency")
    H.flags.writeable = False
    return FRF(f_hz=f, H=H, method=method, basis=used)


@dataclass(frozen=True, eq=False)
class _ModalTerms:
    """``H(w) = sum_r R_r / (a_r + i w b_r - w^2) + sum_k S_k / (i w - lambda_k)``: real and complex modes."""

    basis: str
    real_residues: np.ndarray
    a: np.ndarray
    b: np.ndarray
    complex_residues: np.ndarray
    eigenvalues: np.ndarray

    @cached_property
    def _stacked(self) -> np.ndarray:
        """Residues ``S' + i S''`` (P, 36) as the real ``[[S', S''], [-S'', S']]`` (2 P, 72), Re/Im interleaved."""
        S = np.concatenate([self.real_residues.reshape(-1, 36), self.complex_residues.reshape(-1, 36)])
        p = S.shape[0]
        out = np.empty((2 * p, 36, 2))
        out[:p, :, 0], out[:p, :, 1] = S.real, S.imag
        out[p:, :, 0], out[p:, :, 1] = -S.imag, S.real
        return out.reshape(2 * p, 72)

    def evaluate(self, omega: np.ndarray) -> np.ndarray:
        """Receptance (nf, 6, 6) at ``omega`` [rad/s]."""
        # One real (nf, 2 P) x (2 P, 72) product written in place, whose rows are complex results'
        # memory layout: no complex division and no temporary of the result's size.
        w = np.asarray(omega, dtype=float)[:, None]
        nr, nc = self.a.size, self.eigenvalues.size
        # Pole factors g[:, 0] + i g[:, 1] in real arithmetic: NumPy's complex division rescales against
        # overflow, at several times the cost, and these denominators are far from overflow.
        g = np.empty((w.shape[0], 2, nr + nc))
        if nr:
            x = self.a.real - w * w  # x + i y = a_r - w^2 + i w b_r
            y = w * self.b
            y += self.a.imag
            _reciprocal(x, y, g[:, 0, :nr], g[:, 1, :nr])
        if nc:
            x = np.broadcast_to(-self.eigenvalues.real, (w.shape[0], nc))  # x + i y = i w - lambda_k
            y = w - self.eigenvalues.imag
            _reciprocal(x, y, g[:, 0, nr:], g[:, 1, nr:])
        g = g.reshape(w.shape[0], -1)
        stacked = self._stacked
        out = np.empty((g.shape[0], 72))
        # Row blocks below OpenBLAS's threading threshold stay on one thread and in cache: on a busy
        # 2-core machine a threaded product waits a scheduler tick for its second thread (8 ms, not 2).
        step = max(1, _BLOCK_MACS // stacked.size)
        for start in range(0, g.shape[0], step):
            np.matmul(g[start : start + step], stacked, out=out[start : start + step])
        return out.view(complex).reshape(-1, 6, 6)


def _reciprocal(x: np.ndarray, y: np.ndarray, re: np.ndarray, im: np.ndarray) -> None:
    """Write ``1 / (x + i y)`` into ``re + i im`` (real arrays of one shape)."""
    inv = x * x
    inv += y * y
    np.divide(1.0, inv, out=inv)
    np.multiply(x, inv, out=re)
    np.multiply(y, inv, out=im)
    np.negative(im, out=im)


def _modal_terms(system, basis: str) -> _ModalTerms:
    C = np.asarray(system.C, dtype=float)
    modes = system.modes
    phi, _ = modal_basis(modes, C)
    cm = phi.T @ C @ phi
    khm = phi.T @ hysteretic_stiffness(system) @ phi
    km = phi.T @ np.asarray(system.K, dtype=float) @ phi
    # Rayleigh quotients: the eigen-solver's eigenvalues carry absolute errors ~eps * lambda_max,
    # large at the low, lightly damped modes' peaks; the quotients are accurate to ~eps * lambda_r.
    lam = np.where(np.array(modes.eigenvalues) > 0, np.diag(km), 0.0)
    branches = system.branches
    G = phi.T @ branches.rows.T  # (6, nb): each mode's deformation of each Maxwell branch
    scale = max(float(np.max(modes.omega)), float(np.max(np.abs(cm))), np.finfo(float).tiny)
    undamped_rigid = [r for r in modes.zero_modes
                      if cm[r, r] <= RIGID_DAMPING_RTOL * scale and not np.any(G[r] * branches.stiffness)]
    rest = [r for r in range(6) if r not in undamped_rigid]
    classical = is_classical(cm, khm) and not branches.count
    if basis == "real" and not classical:
        raise InputError("basis", "'auto' or 'complex' (damping, hysteresis or Maxwell branches are not diagonal "
                         "in the real modes, so real modes cannot represent them)", basis)
    if classical and basis != "complex":
        return _ModalTerms(basis="real modes", real_residues=np.einsum("ir,jr->rij", phi, phi).astype(complex),
                           a=lam + 1j * np.diag(khm), b=np.diag(cm).copy(),
                           complex_residues=np.zeros((0, 6, 6), dtype=complex), eigenvalues=np.zeros(0, dtype=complex))

    # Complex modes of the coordinates in `rest`; undamped rigid-body modes stay real mass lines -phi phi'/w^2
    # (in first-order form a Jordan block: a double zero eigenvalue, one eigenvector, no eigenvector sum).
    n = len(rest)
    ix = np.ix_(rest, rest)
    stiffness = np.where(lam[rest] > 0, km[ix], 0.0) + 1j * khm[ix]
    maxwell = (G[rest], branches.stiffness, branches.tau) if branches.count else None
    modes_c = complex_modes(stiffness, cm[ix], remedy="use method='direct'", maxwell=maxwell)
    phi_s = phi[:, rest]
    out = phi_s @ modes_c.right[:n, :]  # (6, 2n + nb): q per unit state-mode amplitude
    inp = modes_c.left[:, n:2 * n] @ phi_s.T  # (2n + nb, 6): the generalized force drives eta''
    u = phi[:, undamped_rigid]
    return _ModalTerms(basis="complex modes", real_residues=np.einsum("ir,jr->rij", u, u).astype(complex),
                       a=np.zeros(len(undamped_rigid), dtype=complex), b=np.zeros(len(undamped_rigid)),
                       complex_residues=np.einsum("ik,kj->kij", out, inp), eigenvalues=modes_c.eigenvalues)


def frf_difference(a: FRF, b: FRF) -> np.ndarray:
    """Relative difference of two receptances of one system, per entry, shape (6, 6).

    ``max_f |a_ij - b_ij| / max_f sqrt(|a_ii| |a_jj|)``: every entry is measured against the size of
    the responses it connects (translations ~1e-4 m and rotations ~1e-7 rad each on their own
    scale), and entries that vanish by symmetry do not divide by their own round-off.

    Raises
    ------
    InputError
        If the two were computed at different frequencies.
    """
    if a.f_hz.shape != b.f_hz.shape or not np.array_equal(a.f_hz, b.f_hz):
        raise InputError("f_hz", "the same frequencies for both FRFs", b.f_hz.tolist())
    diag = np.abs(np.diagonal(a.H, axis1=1, axis2=2))  # (nf, 6)
    scale = np.max(np.sqrt(diag[:, :, None] * diag[:, None, :]), axis=0)
    scale = np.where(scale > 0, scale, np.finfo(float).tiny)
    return np.max(np.abs(a.H - b.H), axis=0) / scale


def cross_check(system: System, f_hz) -> FRFCrossCheck:
    """Receptance by both methods and their largest relative difference (see :func:`frf_difference`).

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].

    Returns
    -------
    FRFCrossCheck
    """
    direct = receptance(system, f_hz, method="direct")
    modal = receptance(system, f_hz, method="modal")
    diff = readonly(frf_difference(direct, modal))
    return FRFCrossCheck(direct=direct, modal=modal, relative_difference=diff,
                         max_relative_difference=float(diff.max()))
