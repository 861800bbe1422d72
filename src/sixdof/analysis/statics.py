"""Static deflection under gravity and the force each mount carries."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from sixdof.dofs import UNITS
from sixdof.errors import InputError, Plain, instance, number
from sixdof.model.kinematics import mount_local_map, mount_matrix
from sixdof.model.system import System
from sixdof.results import Result, label, quantity, result_type

STANDARD_GRAVITY = 9.80665  # m/s^2


@result_type
@dataclass(frozen=True, eq=False)
class Statics(Result):
    """Result of :func:`gravity_statics`.

    Attributes
    ----------
    gravity : ndarray, shape (3,)
        Gravity acceleration vector in body axes [m/s^2].
    q : ndarray, shape (6,)
        Static deflection of the CG [m] and rotation [rad] from the unloaded state.
    mount_forces : ndarray, shape (n_mounts, 3)
        Load on each mount: the force the body exerts on it, which the mount passes to the
        foundation, in body axes [N] (the sign convention of every mount force of sixdof: a mount
        carrying the weight under ``-z`` gravity has ``Fz < 0``).
    mount_forces_local : ndarray, shape (n_mounts, 3)
        The same forces along each mount's own axes u, v, w [N]: ``k delta`` for the static
        deflection ``delta`` of the mount along its axes.
    support : ndarray, shape (n_mounts,)
        Component of each mount's load along gravity [N]: positive in compression (the mount
        carries the body), negative in tension (uplift).
    uplift : tuple of str
        Names of the mounts in tension (uplift): they would have to pull the body down.
    """

    gravity: np.ndarray = quantity("m/s^2", ("axis",), description="gravity in body axes")
    q: np.ndarray = quantity(UNITS["q"], ("dof",),
                             description="static deflection under gravity from the unloaded state")
    mount_forces: np.ndarray = quantity("N", ("mount", "axis"), name="mount_force",
                                        description="load on each mount (force of the body on it, passed to the "
                                        "foundation), body axes")
    mount_forces_local: np.ndarray = quantity("N", ("mount", "mount_axis"), name="mount_force_local",
                                              description="load on each mount along the mount's own axes u, v, w")
    support: np.ndarray = quantity("N", ("mount",),
                                   description="load along gravity: > 0 compression, < 0 tension (uplift)")
    uplift: tuple[str, ...] = label()


def try_gravity_statics(system: System, g: float = STANDARD_GRAVITY, direction=(0.0, 0.0, -1.0)):
    """:func:`gravity_statics`, or ``(None, reason)`` when the mounts cannot carry the weight.

    A layout that leaves the body free along gravity still has modes worth reporting: callers that
    report everything use this and print the reason instead of failing.

    Returns
    -------
    tuple of (Statics or None, str or None)
    """
    try:
        return gravity_statics(system, g, direction), None
    except InputError as exc:
        if exc.field != "mounts":
            raise
        return None, f"no static equilibrium under gravity: {exc.got}"


def gravity_statics(system: System, g: float = STANDARD_GRAVITY, direction=(0.0, 0.0, -1.0)) -> Statics:
    """Static equilibrium of the body on its mounts under its own weight.

    Parameters
    ----------
    system : sixdof.model.system.System
    g : float
        Gravity acceleration [m/s^2], > 0.
    direction : array_like, shape (3,)
        Direction of gravity in body axes [1] (normalized here). Default ``-z``.

    Returns
    -------
    Statics

    Raises
    ------
    InputError
        If ``system`` is not a System, ``g`` or ``direction`` is invalid, or the mounts cannot carry the
        weight (the body is free to move along gravity).
    """
    instance(system, "system", System)
    g = number(g, "statics.gravity", "a positive acceleration in m/s^2", low=0.0, strict=True)
    d = np.asarray(direction, dtype=float)
    if d.shape != (3,) or not np.all(np.isfinite(d)) or np.linalg.norm(d) == 0:
        raise InputError("statics.direction", "a non-zero 3-vector", direction)
    gravity = g * d / np.linalg.norm(d)
    Q = np.concatenate([system.body.mass * gravity, np.zeros(3)])  # weight acts at the CG
    q = _newton(system, Q) if system.nonlinear.count else _linear(system, Q)
    local = _mount_loads(system, mount_local_map(system.positions, system.axes) @ q)
    forces = np.einsum("nji,nj->ni", system.axes, local)
    support = forces @ (gravity / g)
    # Round-off can leave a mount carrying nothing with a tiny negative value: not uplift.
    uplift_tol = 1e-9 * system.body.mass * g
    uplift = tuple(n for n, s in zip(system.mount_names, support) if s < -uplift_tol)
    return Statics(gravity, q, forces, local, support, uplift)


def with_gravity_preload(system: System, gravity) -> System:
    """``system`` carrying its mounts' static preload under ``gravity``, whose geometric stiffness its K then holds
    (:attr:`~sixdof.model.system.System.K_geometric`, ``[statics] geometric_stiffness = true``).

    The preload is solved for this system (:func:`gravity_statics`: nonlinear mounts at their static equilibrium)
    and given to it as :attr:`~sixdof.model.system.System.mount_preload`: call it again for a copy with other
    mounts, which keeps the preload it was given.

    Parameters
    ----------
    system : sixdof.model.system.System
    gravity : array_like, shape (3,), or None
        Gravity [m/s^2] in body axes; None: ``system`` without a preload.

    Returns
    -------
    sixdof.model.system.System

    Raises
    ------
    InputError
        ``statics.geometric_stiffness`` when the mounts cannot carry the weight (no static equilibrium, so no
        preload).
    """
    if gravity is None:
        return dataclasses.replace(system, gravity_preload=None, mount_preload=None)
    g = float(np.linalg.norm(np.asarray(gravity, dtype=float)))
    try:
        statics = gravity_statics(system, g, gravity)
    except InputError as exc:
        if exc.field != "mounts":
            raise
        raise InputError("statics.geometric_stiffness", "false, or mounts that carry the body's weight (the "
                         "geometric stiffness is that of their static preload)", exc.got) from None
    return dataclasses.replace(system, gravity_preload=gravity, mount_preload=statics.mount_forces)


def replace_with_preload(system: System, **changes) -> System:
    """``dataclasses.replace(system, **changes)`` with the gravity preload ``system`` carries (if any) solved again
    for the copy (:func:`with_gravity_preload`): a copy with other mounts, whose statics are its own."""
    gravity = system.gravity_preload
    plain = dataclasses.replace(system, gravity_preload=None, mount_preload=None, **changes)
    return plain if gravity is None else with_gravity_preload(plain, gravity)


#: An eigenvalue of the stiffness scaled to unit diagonal below this fraction of the largest is a zero stiffness
#: (a mechanism): round-off leaves ~1e-16 there, while a real mount set stays far above (one mount of 1e12 N/m
#: among three of 1e4 N/m: 5e-9).
MECHANISM_RTOL = 1e-12
#: Gravity drives a mechanism when its load along the motion exceeds this fraction of the whole (scaled) load:
#: a motion it does not drive sees round-off only.
MECHANISM_LOAD_RTOL = 1e-8


def _linear(system: System, Q: np.ndarray) -> np.ndarray:
    q = solve_stiffness(np.asarray(system.K_mounts), Q)  # from the unloaded state: no preload yet
    if q is None:
        raise InputError("mounts", "mounts that can carry the body's weight and its moment",
                         "a layout that leaves a motion gravity drives unresisted (the body would fall or tip over)")
    return q


def solve_stiffness(K: np.ndarray, Q: np.ndarray) -> np.ndarray | None:
    """The displacement ``q`` (6,) [m, rad] with ``K q = Q`` (6,) [N, N m], or ``None`` when ``Q`` drives a motion
    that ``K`` (6, 6) [N/m, N, N m/rad] does not resist (a mechanism).

    Whether ``K`` is singular is decided on ``K`` scaled to unit diagonal (each DOF in its own units, by its own
    stiffness), not on ``K`` itself: its entries span many decades (N/m against N m/rad, a stiff mount beside soft
    ones), so a residual or an eigenvalue of ``K`` relative to its largest calls a merely ill-conditioned ``K``
    singular. A motion that ``Q`` does not drive (free but unloaded) gets no displacement.
    """
    diagonal = np.diag(K)
    scale = np.where(diagonal > 0, 1.0 / np.sqrt(np.where(diagonal > 0, diagonal, 1.0)), 1.0)
    eigenvalues, vectors = np.linalg.eigh(scale[:, None] * K * scale[None, :])
    load = vectors.T @ (scale * Q)
    stiff = eigenvalues > MECHANISM_RTOL * max(eigenvalues.max(), 0.0)
    if np.any(np.abs(load[~stiff]) > MECHANISM_LOAD_RTOL * np.linalg.norm(load)):
        return None
    return scale * (vectors[:, stiff] @ (load[stiff] / eigenvalues[stiff]))


#: Newton iterations of the nonlinear statics: a piecewise-linear law needs one per change of region.
NEWTON_ITERATIONS = 100


def _mount_loads(system: System, deflection: np.ndarray) -> np.ndarray:
    """The load of each mount along its axes (n, 3) [N] at its deflections ``deflection`` (n, 3) [m] from the unloaded
    mount: ``r(delta)``, ``k delta`` for a linear axis (the spring pushes the body back with ``-r``; the same sign as
    the dynamic forces of :mod:`sixdof.analysis.response`, so that the two add up)."""
    local = system.given_stiffnesses * deflection
    laws = system.nonlinear
    if laws.count:
        local[laws.mount, laws.axis] = laws.force(deflection[laws.mount, laws.axis])
    return local


def _newton(system: System, Q: np.ndarray) -> np.ndarray:
    """The equilibrium ``sum_mounts L' r(L q) = Q`` of a system with nonlinear mounts, by Newton's method with
    backtracking (exact once every law stays in its region: each is linear there)."""
    laws = system.nonlinear
    local_map = mount_local_map(system.positions, system.axes)  # (n, 3, 6)

    def residual(q):
        return np.einsum("nia,ni->a", local_map, _mount_loads(system, local_map @ q)) - Q

    def tangent(q):
        deflection = local_map @ q
        stiffness = np.array(system.given_stiffnesses)
        stiffness[laws.mount, laws.axis] = laws.slopes(deflection[laws.mount, laws.axis])
        return mount_matrix(system.positions, stiffness, system.axes)

    q = np.array(system.equilibrium, dtype=float)
    G = residual(q)
    size = np.linalg.norm(Q)
    for _ in range(NEWTON_ITERATIONS):
        K = tangent(q)
        # Converged to round-off: the residual's floor is set by the mount loads summed (K q), which a stiff mount
        # makes far larger than the weight; measured against the weight alone, an ill-conditioned K never converges.
        if np.linalg.norm(G) <= 1e-10 * (size + np.linalg.norm(K, 2) * np.linalg.norm(q)):
            return q
        step, *_ = np.linalg.lstsq(K, -G, rcond=None)
        length = 1.0
        while length > 1e-6:  # backtracking: a full step may jump past a knot into a worse region
            trial = q + length * step
            G_trial = residual(trial)
            if np.linalg.norm(G_trial) < np.linalg.norm(G):
                break
            length /= 2
        else:
            break
        q, G = trial, G_trial
    raise InputError("mounts", "mounts that can carry the body's weight along gravity (a static equilibrium of "
                     "the nonlinear mounts)",
                     Plain(f"no equilibrium found: Newton's method stopped with an unbalanced force of "
                           f"{np.linalg.norm(G[:3]):.4g} N and moment {np.linalg.norm(G[3:]):.4g} N m (mounts "
                           "lifting off, or stops and tables too soft to carry the weight)"))


def check_pendulum_loads(system: System) -> None:
    """Refuse a friction pendulum whose mount carries no compressive load at ``system``'s
    :attr:`~sixdof.model.system.System.equilibrium` (its restoring force and friction are proportional to it)."""
    h = system.hysteretic
    for e in np.flatnonzero(h.pendulum & (h.static_load <= 0)):
        j = int(h.mount[e])
        raise InputError(f"mounts[{j}].friction_pendulum", "a friction pendulum on a mount that carries load at rest "
                         "(in compression along w at the static equilibrium: sixdof.analysis.statics.at_equilibrium)",
                         Plain(f"{system.mount_names[j]} carries {-h.static_load[e]:.4g} N of tension at rest"
                               if h.static_load[e] < 0 else f"{system.mount_names[j]} carries no load at rest"))


def at_equilibrium(system: System, statics: Statics) -> System:
    """``system`` linearized about ``statics`` (:attr:`~sixdof.model.system.System.equilibrium` set to its
    deflection): where its nonlinear mounts sit at rest, and the load its friction pendulums carry.

    Raises
    ------
    InputError
        If a mount that cannot carry tension (``tension = False``) has lifted off at rest, or a friction pendulum's
        mount carries no compressive load (:func:`check_pendulum_loads`).
    """
    system = dataclasses.replace(system, equilibrium=statics.q)
    check_pendulum_loads(system)
    laws = system.nonlinear
    for e in range(laws.count):
        if "lift-off" in laws.kinds[e] and laws.static_deflection[e] > 0:
            j = int(laws.mount[e])
            raise InputError(f"mounts[{j}].tension", "false only on a mount in compression at rest (one that lifts "
                             "off only under load)", Plain(f"{system.mount_names[j]} is in tension at rest: it lifts "
                                                           f"off {laws.static_deflection[e]:.4g} m under the body's "
                                                           "weight"))
    return system
