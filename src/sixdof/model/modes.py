"""The undamped modes of a model (section 2 of the seed paper): frequencies, mass-normalized shapes,
kinetic-energy distribution, effective masses and the decoupled subsystems.

Part of the model: a :class:`~sixdof.model.system.System` needs its own modes for its modal damping
(:attr:`~sixdof.model.system.System.C`) and its mode releases.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.dofs import DOFS, UNITS
from sixdof.errors import InputError, Plain, readonly, real_array
from sixdof.results import Result, label, quantity, result_type

#: A mode is rigid (zero frequency) when its eigenvalue is below this fraction of the largest.
ZERO_MODE_RTOL = 1e-10
#: Two DOFs are coupled when their scaled coupling term exceeds this fraction of the matrix scale.
COUPLING_RTOL = 1e-9
#: M and K are symmetric when ``|X - X'|`` is within this fraction of ``max |X|``: round-off of an assembly
#: (``A' k A`` sums its terms in another order on each side) is ~1e-16, a typing mistake far more.
SYMMETRY_RTOL = 1e-10


@result_type
@dataclass(frozen=True, eq=False)
class Modes(Result):
    """Result of :func:`modal_analysis`.

    Attributes
    ----------
    eigenvalues : ndarray, shape (6,)
        ``omega**2`` ascending [rad^2/s^2] (the seed paper's lambda).
    omega : ndarray, shape (6,)
        Natural circular frequencies [rad/s] (the paper's eigenpulsations p).
    frequency_hz : ndarray, shape (6,)
        Natural frequencies [Hz].
    shapes : ndarray, shape (6, 6)
        Column j is mode j [kg^-0.5 for x, y, z; kg^-0.5 m^-1 for rx, ry, rz], mass-normalized
        (``shapes.T @ M @ shapes = I``); each column's largest-magnitude entry is positive.
    ke_distribution : ndarray, shape (6, 6)
        ``[i, j]`` = share of mode j's kinetic energy in DOF i; each column sums to 1.
    dominant_dof : tuple of str
        The DOF holding the largest kinetic-energy share of each mode.
    effective_mass : ndarray, shape (6, 6)
        ``[i, j]`` = modal effective mass of mode j in DOF i [kg for x, y, z; kg m^2 for rx, ry, rz];
        each row sums to the diagonal of M.
    subsystems : tuple of tuple of str
        Groups of DOFs coupled through M or K (connected components), in DOF order.
    zero_modes : tuple of int
        Indices of rigid-body (zero-frequency) modes: DOFs the mounts leave unrestrained.
    free_dofs : tuple of str
        DOFs taking part in the zero-frequency modes.
    """

    eigenvalues: np.ndarray = quantity("rad^2/s^2", ("mode",))
    omega: np.ndarray = quantity("rad/s", ("mode",))
    frequency_hz: np.ndarray = quantity("Hz", ("mode",))
    shapes: np.ndarray = quantity(UNITS["shapes"], ("dof", "mode"),
                                  description="column j is mode j, mass-normalized: shapes.T @ M @ shapes = I")
    ke_distribution: np.ndarray = quantity(
        "1", ("dof", "mode"), description="share of each mode's kinetic energy in each DOF; columns sum to 1")
    dominant_dof: tuple[str, ...] = quantity("", ("mode",), decode=lambda a: tuple(str(d) for d in a),
                                             description="DOF holding the largest kinetic-energy share of each mode")
    effective_mass: np.ndarray = quantity(UNITS["effective_mass"], ("dof", "mode"))
    subsystems: tuple[tuple[str, ...], ...] = label(encode=lambda s: tuple(",".join(g) for g in s),
                                                    decode=lambda s: tuple(tuple(g.split(",")) for g in s))
    zero_modes: tuple[int, ...] = label(name="rigid_body_modes",
                                        encode=lambda z: np.asarray([j + 1 for j in z], dtype=np.int64),
                                        decode=lambda z: tuple(int(j) - 1 for j in z))
    free_dofs: tuple[str, ...] = label()


def inverse_cholesky(M) -> np.ndarray:
    """``L^-1`` with ``M = L L^T``: turns ``K v = l M v`` into the symmetric ``(L^-1 K L^-T) w = l w``."""
    return np.linalg.inv(np.linalg.cholesky(np.asarray(M, dtype=float)))


def modal_analysis(M: np.ndarray, K: np.ndarray) -> Modes:
    """Natural frequencies and mode shapes of ``M q'' + K q = 0`` (eqs. 2-5 of the seed paper).

    Solved as the symmetric generalized eigenproblem ``K v = lambda M v``, which is better
    conditioned than the paper's ``D = M^-1 K`` and gives mass-normalized shapes directly.

    Parameters
    ----------
    M : array_like, shape (6, 6)
        Mass matrix [kg, kg m^2], symmetric positive definite.
    K : array_like, shape (6, 6)
        Stiffness matrix [N/m, N, N m/rad], symmetric positive semi-definite.

    Returns
    -------
    Modes

    Raises
    ------
    InputError
        If M or K is not a finite (6, 6) symmetric matrix, M is not positive definite, or K has an eigenvalue
        ``lambda`` below ``-ZERO_MODE_RTOL`` times the largest ``|lambda|`` (more negative than round-off
        leaves the zero eigenvalues of an unrestrained body).
    """
    M = _symmetric(M, "M", "a symmetric positive definite (6, 6) mass matrix in kg, kg m^2")
    K = _symmetric(K, "K", "a symmetric positive semi-definite (6, 6) stiffness matrix in N/m, N, N m/rad")
    # LAPACK's reduction (dsygv): M = L L', the symmetric L^-1 K L^-T's eigenpairs, shapes L^-T y. NumPy
    # rather than scipy.linalg.eigh(K, M): the same steps, and no 0.1-0.2 s import of scipy.linalg in a run.
    try:
        L_inv = inverse_cholesky(M)
    except np.linalg.LinAlgError:
        raise InputError("M", "a symmetric positive definite (6, 6) mass matrix in kg, kg m^2",
                         Plain(f"eigenvalues {np.linalg.eigvalsh(M).tolist()}")) from None
    reduced = L_inv @ K @ L_inv.T
    eigenvalues, reduced_shapes = np.linalg.eigh((reduced + reduced.T) / 2)
    shapes = L_inv.T @ reduced_shapes
    # Round-off makes the eigenvalues of unrestrained DOFs tiny and of either sign: they are zero. One more
    # negative than that is no round-off: K is not positive semi-definite (its sqrt would be NaN).
    scale = max(float(np.max(np.abs(eigenvalues))), np.finfo(float).tiny)
    if eigenvalues[0] < -ZERO_MODE_RTOL * scale:
        raise InputError("K", f"a symmetric positive semi-definite stiffness matrix: eigenvalues lambda of "
                         f"K v = lambda M v >= -{ZERO_MODE_RTOL:g} times the largest |lambda| (round-off of zero)",
                         Plain(f"lambda = {eigenvalues[0]:.6g} rad^2/s^2, the largest |lambda| being {scale:.6g}"))
    zero = np.abs(eigenvalues) <= ZERO_MODE_RTOL * scale
    eigenvalues = np.where(zero, 0.0, eigenvalues)
    order = np.argsort(eigenvalues, kind="stable")
    eigenvalues, shapes = eigenvalues[order], shapes[:, order]
    zero = zero[order]
    # Deterministic sign: the largest-magnitude entry of each mode is positive.
    largest = shapes[np.argmax(np.abs(shapes), axis=0), np.arange(6)]
    shapes = shapes * np.sign(largest)

    omega = np.sqrt(eigenvalues)
    ke = shapes * (M @ shapes)  # phi_ij (M phi_j)_i; phi_j' M phi_j = 1
    effective = (shapes.T @ M).T ** 2  # participation Gamma_ij = phi_j' M e_i

    weight = np.sum(ke[:, zero], axis=1)  # each DOF's kinetic-energy share of the rigid-body modes
    free_dofs = tuple(d for d, w, row in zip(DOFS, weight, shapes[:, zero]) if w > 1e-6 and np.any(row))

    return Modes(
        eigenvalues=readonly(eigenvalues),
        omega=readonly(omega),
        frequency_hz=readonly(omega / (2 * np.pi)),
        shapes=readonly(shapes),
        ke_distribution=readonly(ke),
        dominant_dof=tuple(DOFS[i] for i in np.argmax(ke, axis=0)),
        effective_mass=readonly(effective),
        subsystems=coupled_subsystems(M, K),
        zero_modes=tuple(int(j) for j in np.flatnonzero(zero)),
        free_dofs=free_dofs,
    )


def _symmetric(value, field: str, expected: str) -> np.ndarray:
    """``value`` as a finite (6, 6) float array, symmetric within :data:`SYMMETRY_RTOL` (the eigen-solution
    reads one triangle: the other would be silently ignored)."""
    X = real_array(value, field, expected, 2)
    if X.shape != (6, 6):
        raise InputError(field, expected, Plain(f"an array of shape {X.shape}"))
    if not np.all(np.isfinite(X)):
        i, j = np.argwhere(~np.isfinite(X))[0]
        raise InputError(field, expected, Plain(f"{field}[{i}, {j}] = {X[i, j]}"))
    asymmetry = float(np.max(np.abs(X - X.T)))
    if asymmetry > SYMMETRY_RTOL * float(np.max(np.abs(X))):
        i, j = np.unravel_index(np.argmax(np.abs(X - X.T)), X.shape)
        raise InputError(field, expected, Plain(f"{field}[{i}, {j}] = {X[i, j]:.6g} and {field}[{j}, {i}] = "
                                                f"{X[j, i]:.6g}"))
    return X


def coupled_subsystems(M: np.ndarray, K: np.ndarray, rtol: float = COUPLING_RTOL):
    """Groups of DOFs coupled through M or K (section 4 of the seed paper).

    Both matrices are scaled by the mass diagonal (``D^-1/2 X D^-1/2`` with ``D = diag(M)``) so that
    translations and rotations compare on one scale [1 and 1/s^2]; an off-diagonal term couples two
    DOFs when it exceeds ``rtol`` times the largest diagonal term of its scaled matrix.

    Returns
    -------
    tuple of tuple of str
        Connected components of the coupling graph, each in DOF order, ordered by first DOF.
    """
    d = 1.0 / np.sqrt(np.diag(np.asarray(M, dtype=float)))
    coupled = np.zeros((6, 6), dtype=bool)
    for matrix in (M, K):
        scaled = np.abs(d[:, None] * np.asarray(matrix, dtype=float) * d[None, :])
        threshold = rtol * max(float(np.max(np.diag(scaled))), np.finfo(float).tiny)
        coupled |= scaled > threshold
    edges = np.triu(coupled, 1)
    # Row i of (I + A)^5 is nonzero at every DOF within 5 steps of DOF i: its whole component.
    reach = np.linalg.matrix_power(np.eye(6, dtype=int) + edges + edges.T, 5) > 0
    return tuple(dict.fromkeys(tuple(DOFS[j] for j in np.flatnonzero(row)) for row in reach))
