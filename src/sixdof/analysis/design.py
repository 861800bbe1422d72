"""Mount-system design metrics: the torque-roll axis, the decoupling of the modes in body and TRA
coordinates, the elastic centre and principal elastic axes of the mount set, and the sensitivities of
the natural frequencies and of the decoupling to each mount axis' stiffness.

Definitions (Harris' Shock and Vibration Handbook, ch. 3; the mount-design literature):

- **Torque-roll axis (TRA)**: the axis a free body starts to rotate about under a torque about the unit
  vector ``e``: the direction of ``J^-1 e``, ``J`` the full inertia tensor about the CG.
- **Decoupling** of a mode: the kinetic-energy share of its dominant coordinate, in percent. In TRA
  coordinates the coordinates are rotated so that the first rotation is about the TRA (translations
  rotated alike); the roll coordinate's share does not depend on how the other two axes are chosen.
- **Elastic centre**: the point where a force produces only translation and a moment only rotation: the
  point ``r`` where the stiffness matrix, referred to ``r``, has no translation-rotation coupling,
  ``B + A S(r) = 0`` (``A``, ``B`` the translational and coupling blocks at the CG, ``S(r) x = r x x``).
  It exists only when ``-A^-1 B`` is skew-symmetric. **Principal elastic axes**: the eigenvectors of
  ``A``, along which a force at the elastic centre moves the body in its own direction.

The sensitivities are exact derivatives, by automatic differentiation (JAX) through the assembly of K
(:func:`sixdof.model.kinematics.stiffness_jax`, with the statics of gravity's geometric stiffness when the
system has it) and the symmetric eigen-solution. A frequency of a
repeated pair (or triple) has no derivative of its own: each member gets the derivative of the group's
mean eigenvalue, which is unique, and the group is reported; the decoupling of such modes, whose shapes
are not unique, gets no derivative (masked in the arrays, null in JSON; never a NaN).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.analysis.modal import repeated_groups
from sixdof.errors import InputError, instance, readonly
from sixdof.model.kinematics import stiffness_jax
from sixdof.model.modes import inverse_cholesky
from sixdof.model.system import System
from sixdof.results import Result, label, quantity, result_type

#: The elastic centre exists when the symmetric part of ``-A^-1 B`` is at most this fraction of the mount
#: set's length scale ``sqrt(trace(C) / trace(A))`` (``C`` the rotational stiffness block).
ELASTIC_CENTER_RTOL = 1e-6


@result_type
@dataclass(frozen=True, eq=False)
class DesignMetrics(Result):
    """Result of :func:`design_metrics` (stored in ``/design``).

    Attributes
    ----------
    decoupling_percent : ndarray, shape (6,)
        Kinetic-energy share of each mode's dominant body coordinate [%].
    dominant_dof : tuple of str
        That coordinate, per mode.
    elastic_axes : ndarray, shape (3, 3)
        Rows: the principal elastic axes (unit vectors, body axes), by ascending ``principal_stiffness``.
    principal_stiffness : ndarray, shape (3,)
        Translational stiffness along each principal elastic axis [N/m].
    torque_axis, torque_roll_axis : ndarray, shape (3,), or None
        The unit torque axis given and the TRA (unit vector, body axes, pointing the torque's way); None
        without a torque axis.
    roll_mode : int or None
        Index (from 0) of the mode with the largest kinetic-energy share in rotation about the TRA.
    roll_mode_tra_angle_deg : float or None
        Angle between that mode's rotation axis and the TRA [deg], 0 to 90.
    decoupling_tra_percent : ndarray, shape (6,), or None
        Each mode's largest kinetic-energy share in TRA coordinates [%].
    elastic_center : ndarray, shape (3,), or None
        From the CG in body axes [m]; None when the mount set has none.
    """

    decoupling_percent: np.ndarray = quantity("percent", ("mode",),
                                              description="kinetic-energy share of each mode's dominant DOF")
    dominant_dof: tuple[str, ...] = quantity("", ("mode",), name="decoupling_dof",
                                             decode=lambda a: tuple(str(d) for d in a),
                                             description="the DOF of decoupling_percent, per mode")
    elastic_axes: np.ndarray = quantity("1", ("elastic_axis", "axis"),
                                        description="rows: principal elastic axes (body axes), ascending stiffness")
    principal_stiffness: np.ndarray = quantity("N/m", ("elastic_axis",),
                                               description="translational stiffness along each principal axis")
    torque_axis: np.ndarray | None = quantity("1", ("axis",), default=None,
                                              description="unit torque axis given (body axes)")
    torque_roll_axis: np.ndarray | None = quantity("1", ("axis",), default=None,
                                                   description="torque-roll axis, unit vector in body axes")
    roll_mode: int | None = label(default=None, encode=int, decode=int)
    roll_mode_tra_angle_deg: float | None = label(default=None, encode=float, decode=float)
    decoupling_tra_percent: np.ndarray | None = quantity("percent", ("mode",), default=None,
                                                         description="largest kinetic-energy share in TRA coordinates")
    elastic_center: np.ndarray | None = quantity("m", ("axis",), default=None,
                                                 description="elastic centre from the CG, body axes")

    group = "design"


def design_metrics(system, torque_axis=None) -> DesignMetrics:
    """Decoupling, torque-roll axis and elastic centre of a system (see the module's definitions).

    Parameters
    ----------
    system : sixdof.model.system.System
    torque_axis : array_like, shape (3,), optional
        Axis of the exciting torque in body axes [1] (an engine's crankshaft); normalized. Without it there is
        no TRA, roll mode or TRA decoupling.

    Returns
    -------
    DesignMetrics

    Raises
    ------
    InputError
        A ``torque_axis`` that is not a nonzero 3-vector.
    """
    instance(system, "system", System)
    M, K, modes = system.M, system.K, system.modes
    shares = modes.ke_distribution
    tra = roll = angle = tra_shares = axis = None
    if torque_axis is not None:
        axis = np.asarray(torque_axis, dtype=float)
        if axis.shape != (3,) or not np.all(np.isfinite(axis)) or np.linalg.norm(axis) == 0:
            raise InputError("torque_axis", "a nonzero vector [x, y, z] in body axes", torque_axis)
        axis = axis / np.linalg.norm(axis)
        tra = torque_roll_axis(M, axis)
        frame = tra_frame(tra)
        T = np.kron(np.eye(2), frame)  # body coordinates -> TRA coordinates, translations and rotations alike
        p = T.T @ modes.shapes
        tra_shares = p * ((T.T @ M @ T) @ p)
        roll = int(np.argmax(tra_shares[3]))
        rotation = modes.shapes[3:, roll]
        cosine = abs(float(rotation @ tra)) / float(np.linalg.norm(rotation))
        angle = float(np.degrees(np.arccos(min(cosine, 1.0))))
        tra_shares = readonly(100.0 * np.max(tra_shares, axis=0))
    stiffness, vectors = np.linalg.eigh(K[:3, :3])
    rows = vectors.T * np.sign(vectors.T[np.arange(3), np.argmax(np.abs(vectors.T), axis=1)])[:, None]
    return DesignMetrics(
        decoupling_percent=readonly(100.0 * np.max(shares, axis=0)),
        dominant_dof=modes.dominant_dof,
        torque_axis=None if axis is None else readonly(axis),
        torque_roll_axis=None if tra is None else readonly(tra),
        roll_mode=roll,
        roll_mode_tra_angle_deg=angle,
        decoupling_tra_percent=tra_shares,
        elastic_center=elastic_center(K),
        elastic_axes=readonly(rows),
        principal_stiffness=readonly(stiffness),
    )


def mode_of_each_dof(modes) -> np.ndarray:
    """Index of the mode with the largest kinetic-energy share in each DOF, (6,): the mode a design target
    on that DOF means."""
    return np.argmax(modes.ke_distribution, axis=1)


def torque_roll_axis(M, torque_axis) -> np.ndarray:
    """Unit direction of ``J^-1 e`` (``J`` the rotational block of ``M``, the inertia tensor about the CG):
    the axis a free body starts to rotate about under a torque about the unit vector ``e``."""
    direction = np.linalg.solve(np.asarray(M, dtype=float)[3:, 3:], np.asarray(torque_axis, dtype=float))
    return direction / np.linalg.norm(direction)


def tra_frame(first: np.ndarray) -> np.ndarray:
    """An orthonormal right-handed frame (3, 3), columns its axes, the first along ``first``."""
    helper = np.eye(3)[int(np.argmin(np.abs(first)))]
    second = np.cross(first, helper)
    second /= np.linalg.norm(second)
    return np.column_stack([first, second, np.cross(first, second)])


def elastic_center(K) -> np.ndarray | None:
    """The elastic centre of the stiffness matrix ``K`` (6, 6) about the CG, from the CG in body axes [m]:
    the point ``r`` with ``B + A S(r) = 0``; None when no point decouples K (the symmetric part of
    ``-A^-1 B`` exceeds :data:`ELASTIC_CENTER_RTOL` of the length scale) or the mounts do not restrain
    every translation."""
    K = np.asarray(K, dtype=float)
    A, B, C = K[:3, :3], K[:3, 3:], K[3:, 3:]
    if np.linalg.matrix_rank(A) < 3:
        return None
    X = -np.linalg.solve(A, B)  # S(r) when r exists
    length = np.sqrt(np.trace(C) / np.trace(A))
    if np.max(np.abs(X + X.T)) / 2 > ELASTIC_CENTER_RTOL * length:
        return None
    skew = (X - X.T) / 2
    return readonly(np.array([skew[2, 1], skew[0, 2], skew[1, 0]]))


# ----------------------------------------------------------------------------------------------------
# Sensitivities (automatic differentiation).
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Sensitivities:
    """Result of :func:`sensitivities`: derivatives with respect to each mount axis' stiffness.

    Attributes
    ----------
    frequency : numpy.ma.MaskedArray, shape (6, n_mounts, 3)
        d(natural frequency of mode j) / d(stiffness of mount m along its axis u, v or w) [Hz per N/m];
        masked for zero-frequency modes (no finite derivative).
    decoupling : numpy.ma.MaskedArray, shape (6, n_mounts, 3)
        d(decoupling_percent of mode j) / d(the same) [% per N/m]; masked for repeated modes (their shapes
        are not unique) and zero-frequency modes.
    repeated_modes : tuple of tuple of int
        Groups (indices from 0) of modes with one repeated frequency: each member's frequency derivative
        is the group mean's.
    """

    frequency: np.ndarray
    decoupling: np.ndarray
    repeated_modes: tuple[tuple[int, ...], ...]


def sensitivities(system) -> Sensitivities:
    """Exact derivatives of the natural frequencies and of the decoupling with respect to every mount axis'
    stiffness, by forward-mode automatic differentiation through assembly and eigen-solution.

    Parameters
    ----------
    system : sixdof.model.system.System

    Returns
    -------
    Sensitivities
    """
    from sixdof._jax import jax, jnp

    instance(system, "system", System)

    M = np.asarray(system.M, dtype=float)
    L_inv = inverse_cholesky(M)
    positions, axes = np.asarray(system.positions), np.asarray(system.axes)
    weight = system.preload_weight  # the geometric stiffness's statics are differentiated too

    def modal(stiffness):
        eigenvalues, _, shares = modes_jax(M, L_inv, stiffness_jax(positions, stiffness, axes, weight))
        return eigenvalues, 100.0 * jnp.max(shares, axis=0)

    stiffness = np.asarray(system.stiffnesses, dtype=float)
    eigenvalues = np.asarray(modal(stiffness)[0])
    d_eigenvalues, d_decoupling = (np.array(d) for d in jax.jacfwd(modal)(stiffness))  # (6, n, 3) each
    groups = repeated_groups(eigenvalues)
    shapeless = np.zeros(len(eigenvalues), dtype=bool)  # modes whose shape (so decoupling) is not unique
    for group in groups:  # the group mean's derivative is basis-independent; a member's is not
        d_eigenvalues[list(group)] = d_eigenvalues[list(group)].mean(axis=0)
        shapeless[list(group)] = True
    rigid = eigenvalues <= system.modes.eigenvalues.max() * 1e-10  # f = sqrt(l) has no finite derivative
    omega = np.sqrt(np.where(rigid, 1.0, eigenvalues))
    frequency = d_eigenvalues / (4.0 * np.pi * omega)[:, None, None]  # f = sqrt(l) / 2 pi
    return Sensitivities(frequency=_masked(frequency, rigid), decoupling=_masked(d_decoupling, rigid | shapeless),
                         repeated_modes=tuple(g for g in groups))


def _masked(values: np.ndarray, undefined: np.ndarray) -> np.ma.MaskedArray:
    """``values`` (modes, ...) as a read-only masked array, the modes ``undefined`` masked (their data 0, never
    NaN)."""
    mask = np.broadcast_to(undefined[:, None, None], values.shape)
    data = readonly(np.where(mask, 0.0, values))
    found = np.ma.masked_array(data, mask=readonly(mask, bool), copy=False)
    found.harden_mask()
    return found


def modes_jax(M, L_inv, K):
    """Eigenvalues (ascending) [rad^2/s^2], mass-normalized shapes (6, 6) and kinetic-energy shares (6, 6) of
    ``K v = l M v`` in JAX: differentiable with respect to K (the design's sensitivities and optimizer)."""
    from sixdof._jax import jnp

    eigenvalues, vectors = jnp.linalg.eigh(L_inv @ K @ L_inv.T)
    shapes = L_inv.T @ vectors
    return eigenvalues, shapes, shapes * (M @ shapes)


