"""The first-order form of eq. (1) and what follows from it, each decided once for every path.

- :func:`modal_basis`: the undamped mass-normalized modes with every degenerate group (repeated
  frequencies, the rigid-body modes) rotated so that the damping is diagonal on it: any orthonormal
  basis of such a group is a set of modes, and this one makes the classical-damping test exact for
  every C that some set of real modes diagonalizes.
- :func:`coupling` and :func:`is_classical`: THE classical-damping test. Damping (or hysteresis) is
  classical when every normalized off-diagonal term ``|D_ij| / sqrt(D_ii D_jj)`` of its modal matrix is
  at most :data:`CLASSICAL_RTOL`; the real modes then decouple it. Used by the damping ratios, the
  modal superposition and the modal FRF alike.
- :func:`complex_modes`: eigenvalues and right and left eigenvectors of the first-order modal system
  ``eta'' + D eta' + K_m eta = g`` (``K_m`` may be complex: hysteresis), with the condition check that
  refuses nearly defective systems.
- :func:`damped_modes` and :func:`damping_ratios`: the damped pole and shape paired with each mode and
  the exact damping ratio from it; :func:`modal_damping_ratios`, the diagonal approximation
  ``phi' C phi / (2 omega)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.analysis.modal import pair_by_similarity, repeated_groups
from sixdof.errors import SolverError

#: Damping is classical when its largest normalized modal coupling is at most this. Round-off of the
#: modal transform leaves ~1e-15 (measured on every bundled layout with Rayleigh or modal damping);
#: a coupling this small changes no response by more than about its own size, far below the 1e-10
#: to which the FRF paths and the 1e-6 to which the time paths are checked against each other.
CLASSICAL_RTOL = 1e-12
#: Terms of a modal matrix at most this fraction of its largest are round-off of the modal transform (~1e-16
#: measured), zero to :func:`coupling`.
ROUND_OFF_RTOL = 1e-14
#: Two modes are degenerate (any basis of their eigenspace is a set of modes) when their eigenvalues
#: differ by less than this fraction of the largest eigenvalue.
DEGENERATE_RTOL = 1e-9
#: Complex modes are refused when their eigenvector matrix is worse conditioned than this (a nearly
#: defective system, e.g. an exactly critically damped coupled mode, cannot be diagonalized reliably).
MAX_EIGENVECTOR_CONDITION = 1e10


def modal_basis(modes, C) -> tuple[np.ndarray, np.ndarray]:
    """Mass-normalized real modes with degenerate groups rotated to diagonalize ``C`` on them.

    Parameters
    ----------
    modes : sixdof.model.modes.Modes
        The undamped modes.
    C : array_like, shape (6, 6)
        Viscous damping [N s/m, ...].

    Returns
    -------
    basis : ndarray, shape (6, 6)
        Column r is mode r (mass-normalized).
    omega2 : ndarray, shape (6,)
        ``omega_r^2`` [rad^2/s^2], equal within each degenerate group (their mean).
    """
    C = np.asarray(C, dtype=float)
    basis = np.array(modes.shapes)
    omega2 = np.array(modes.eigenvalues)
    for group in repeated_groups(omega2, DEGENERATE_RTOL):
        block = basis[:, group]
        _, rotation = np.linalg.eigh(block.T @ C @ block)
        basis[:, group] = block @ rotation
        omega2[list(group)] = np.mean(omega2[list(group)])
    return basis, omega2


def coupling(D) -> np.ndarray:
    """Normalized couplings ``|D_ij| / sqrt(|D_ii D_jj|)`` of a modal matrix, 0 on the diagonal.

    Terms at round-off of the matrix (at most :data:`ROUND_OFF_RTOL` of its largest) are zero: a mode that
    no damper resists (a rigid-body mode of a body free to turn about its mounts) has round-off there,
    which divided by its round-off diagonal would read as a coupling. Between an undamped coordinate and
    another, any term above round-off is a full coupling (1). Values are capped at 1.
    """
    magnitude = np.abs(np.asarray(D))
    magnitude = np.where(magnitude > ROUND_OFF_RTOL * float(np.max(magnitude, initial=0.0)), magnitude, 0.0)
    d = np.sqrt(np.diag(magnitude))
    product = np.outer(d, d)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(product > 0.0, magnitude / np.where(product > 0.0, product, 1.0),
                         np.where(magnitude > 0.0, 1.0, 0.0))
    np.fill_diagonal(ratio, 0.0)
    return np.minimum(ratio, 1.0)


def is_classical(*modal_matrices) -> bool:
    """THE classical-damping test: every modal matrix given (``Phi' C Phi``, ``Phi' K_h Phi``) is
    diagonal to :data:`CLASSICAL_RTOL` (see :func:`coupling`)."""
    return all(np.max(coupling(D), initial=0.0) <= CLASSICAL_RTOL for D in modal_matrices)


@dataclass(frozen=True, eq=False)
class ComplexModes:
    """Complex modes of ``eta'' + D eta' + K_m eta = g`` in the state ``y = [eta, eta']`` (``[eta, eta', f]``
    with ``nb`` Maxwell branch forces ``f``, :func:`complex_modes`).

    Attributes
    ----------
    eigenvalues : ndarray, shape (2n + nb,), complex
        [1/s].
    right : ndarray, shape (2n + nb, 2n + nb), complex
        Column k is the eigenvector of ``eigenvalues[k]``.
    left : ndarray, shape (2n + nb, 2n + nb), complex, or None
        ``right^-1``: row k is the left eigenvector normalized so that ``left @ right = I`` (``None``
        when asked for without a ``remedy``: eigenvalues and shapes only).
    condition : float
        Condition number of ``right``.
    """

    eigenvalues: np.ndarray
    right: np.ndarray
    left: np.ndarray
    condition: float


def complex_modes(stiffness, D, *, remedy: str | None, maxwell=None) -> ComplexModes:
    """Complex modes of the first-order form of ``eta'' + D eta' + K_m eta = g``.

    The state is scaled, ``x = [S eta, eta']`` with ``S = diag(sqrt(K_m,rr))`` (1 for rigid modes), so
    that every block of the state matrix is of size ~omega_max rather than omega_max^2: the
    eigenvalues' absolute errors, ~eps ||A||, then stay small beside the low modes' distance from the
    imaginary axis. The eigenvectors returned are those of the unscaled state ``[eta, eta']``.

    With Maxwell branches (``maxwell = (G, k, tau)``: ``G = Phi' R'`` (n, nb) the modal deformation of each
    branch state, its stiffness ``k`` [N/m] and relaxation time ``tau`` [s]) the system is
    ``eta'' + D eta' + K_m eta + G f = g``, ``f' = k G' eta' - f / tau``, in the state ``[eta, eta', f]``
    (branch forces scaled by ``sqrt(k)``, which makes both coupling blocks ``sqrt(k) G``, ~omega).

    Parameters
    ----------
    stiffness : array_like, shape (n, n)
        Modal stiffness ``K_m`` [rad^2/s^2] (complex with hysteresis: ``Omega^2 + i Phi' K_h Phi``).
    D : array_like, shape (n, n)
        Modal damping ``Phi' C Phi`` [1/s].
    maxwell : tuple of arrays ``(G, k, tau)``, optional
        Maxwell branches: ``G`` (n, nb) [1/sqrt(kg)], ``k`` (nb,) [N/m], ``tau`` (nb,) [s].
    remedy : str or None
        What the caller's user can do when the modes are nearly defective (ends the error message);
        ``None`` when the caller needs the eigenvalues only, which stay accurate then.

    Returns
    -------
    ComplexModes

    Raises
    ------
    SolverError
        When the eigenvector matrix is worse conditioned than :data:`MAX_EIGENVECTOR_CONDITION`.
    """
    stiffness = np.asarray(stiffness)
    D = np.asarray(D, dtype=float)
    n = D.shape[0]
    diagonal = np.real(np.diag(stiffness))
    s = np.where(diagonal > 0, np.sqrt(np.abs(diagonal)), 1.0)
    A = np.block([[np.zeros((n, n)), np.diag(s)], [-stiffness / s[None, :], -D]])
    unscale = np.concatenate([s, np.ones(n)])
    if maxwell is not None:
        G, k, tau = (np.asarray(a, dtype=float) for a in maxwell)
        coupled = G * np.sqrt(k)[None, :]
        A = np.block([[A, np.concatenate([np.zeros((n, k.size)), -coupled])],
                      [np.zeros((k.size, n)), coupled.T, np.diag(-1.0 / tau)]])
        unscale = np.concatenate([unscale, 1.0 / np.sqrt(k)])
    eigenvalues, V = np.linalg.eig(A)  # LAPACK's dgeev, as scipy.linalg.eig, without importing scipy.linalg
    eigenvalues, V = eigenvalues.astype(complex), V.astype(complex)  # real when every mode is overdamped
    condition = float(np.linalg.cond(V))
    if remedy is not None and (not np.isfinite(condition) or condition > MAX_EIGENVECTOR_CONDITION):
        raise SolverError(
            f"complex modes: eigenvector matrix condition number {condition:.3g} exceeds "
            f"{MAX_EIGENVECTOR_CONDITION:.0e} (nearly defective, e.g. a critically damped mode); {remedy}"
        )
    left = None if remedy is None else np.linalg.inv(V) * unscale[None, :]
    return ComplexModes(eigenvalues=eigenvalues, right=V / unscale[:, None], left=left, condition=condition)


def modal_damping_ratios(C, modes) -> np.ndarray:
    """Damping ratio of each undamped mode, ``phi_r' C phi_r / (2 omega_r)`` (6,).

    Exact for classical (proportional) damping; for non-proportional damping it is the usual
    diagonal approximation (:func:`damping_ratios` gives the exact ones). Rigid-body modes get ``nan``.
    """
    diag = np.einsum("ir,ij,jr->r", modes.shapes, np.asarray(C, dtype=float), modes.shapes)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(modes.omega > 0, diag / (2.0 * modes.omega), np.nan)


def damped_modes(C, modes, branches=None) -> tuple[np.ndarray, np.ndarray]:
    """The damped pole of each undamped mode and its (complex) displacement shape.

    Each undamped mode r is paired with the complex mode whose displacement shape matches it best
    (mass-weighted MAC, which in mass-normalized modal coordinates is ``|v_r|^2 / |v|^2``), each
    complex mode used once. For classical damping the pole is the closed form
    ``omega_r (-zeta_r + i sqrt(1 - zeta_r^2))`` and the shape the real mode.

    Parameters
    ----------
    C : array_like, shape (6, 6)
        Viscous damping [N s/m ...].
    modes : sixdof.model.modes.Modes
        The undamped modes.
    branches : sixdof.model.parts.Branches, optional
        Maxwell branches (``System.branches``): the poles are then those of the full visco-elastic model
        (the augmented first-order system), paired with the undamped modes of the long-term stiffness.

    Returns
    -------
    poles : ndarray, shape (6,), complex
        ``lambda_r = -zeta_r omega_r + i omega_r sqrt(1 - zeta_r^2)`` [1/s], the one with
        ``Im > 0``; ``nan`` for rigid-body modes and modes damped at or beyond critical.
    shapes : ndarray, shape (6, 6), complex
        Column r: displacement part of the eigenvector of ``poles[r]`` in physical coordinates
        [m, rad] (any scale; its velocity part is ``poles[r]`` times it). A free response started
        from ``q = Re(s), q' = Re(lambda s)`` stays ``Re(s e^{lambda t})``: that mode alone.
    """
    phi = np.asarray(modes.shapes)
    D = phi.T @ np.asarray(C, dtype=float) @ phi
    n = phi.shape[1]
    poles = np.full(n, np.nan + 0j)
    shapes = np.zeros((n, n), dtype=complex)
    maxwell = None if branches is None or not branches.count else (phi.T @ branches.rows.T, branches.stiffness,
                                                                    branches.tau)
    if maxwell is None and is_classical(D):
        zeta = modal_damping_ratios(C, modes)
        under = (modes.omega > 0) & (zeta < 1)
        poles[under] = modes.omega[under] * (-zeta[under] + 1j * np.sqrt(1.0 - zeta[under] ** 2))
        return poles, phi.astype(complex)
    complex_ = complex_modes(np.diag(modes.eigenvalues), D, remedy=None, maxwell=maxwell)
    eigenvalues, vectors = complex_.eigenvalues, complex_.right
    oscillating = np.flatnonzero(eigenvalues.imag > 1e-9 * np.abs(eigenvalues).max())
    top = vectors[:n, oscillating]
    similarity = np.abs(top) ** 2 / np.real(np.sum(np.conj(top) * top, axis=0))
    similarity[modes.omega <= 0] = -np.inf  # rigid-body modes have no pole
    for r, j in enumerate(pair_by_similarity(similarity)):
        if j >= 0:
            poles[r] = eigenvalues[oscillating[j]]
            shapes[:, r] = phi @ top[:, j]
    return poles, shapes


def damping_ratios(C, modes, branches=None) -> np.ndarray:
    """Exact damping ratio of each mode, from the complex eigenvalues of the damped system.

    ``zeta_r = -Re(lambda_r) / |lambda_r|`` with ``lambda_r`` the pole paired with mode r
    (:func:`damped_modes`). For classical damping this equals :func:`modal_damping_ratios`; for
    non-proportional damping (mount dashpots) it is the ratio a free decay shows, where the diagonal
    approximation is only first-order. A mode that no oscillating pole is paired with (its eigenvalues are
    real: damped at or beyond critical) gets ``inf``: it is overdamped, and the diagonal value, which may
    read well below 1, would say otherwise. Classical damping, or a mode that no damping couples to another,
    keeps its closed form, exact there, at or above 1 for an overdamped mode. Rigid-body modes get ``nan``.

    Parameters
    ----------
    C : array_like, shape (6, 6)
        Viscous damping [N s/m ...].
    modes : sixdof.model.modes.Modes
        The undamped modes.
    branches : sixdof.model.parts.Branches, optional
        Maxwell branches: the ratios of the full visco-elastic model's poles (:func:`damped_modes`).

    Returns
    -------
    ndarray, shape (6,)
        Damping ratio of each undamped mode (dimensionless); ``inf`` for a mode without an oscillating
        pole (overdamped), ``nan`` for a rigid-body mode.
    """
    approximate = modal_damping_ratios(C, modes)
    phi = np.asarray(modes.shapes)
    D = phi.T @ np.asarray(C, dtype=float) @ phi
    has_branches = branches is not None and branches.count > 0
    if not has_branches and is_classical(D):
        return approximate
    poles, _ = damped_modes(C, modes, branches)
    paired = np.isfinite(poles)
    # An elastic mode without a pole is overdamped: its diagonal ratio is exact (>= 1) only when no damping
    # couples it to another mode, else it has no single ratio.
    alone = (not has_branches) & (np.max(coupling(D), axis=1) <= CLASSICAL_RTOL)
    exact = np.where(modes.omega > 0, np.where(alone, approximate, np.inf), np.nan)
    exact[paired] = -poles[paired].real / np.abs(poles[paired])
    return exact
