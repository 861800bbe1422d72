"""Static deflection under gravity and the force each mount carries."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from sixdof.dofs import UNITS
from sixdof.errors import InputError, number
from sixdof.model.kinematics import mount_local_map
from sixdof.results import Result, label, quantity

if TYPE_CHECKING:
    from sixdof.model.system import System

STANDARD_GRAVITY = 9.80665  # m/s^2


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
        Direction of gravity in body axes (normalized here). Default ``-z``.

    Returns
    -------
    Statics

    Raises
    ------
    InputError
        If ``g`` or ``direction`` is invalid, or the mounts cannot carry the weight (the body is free
        to move along gravity).
    """
    g = number(g, "statics.gravity", "a positive acceleration in m/s^2", low=0.0, strict=True)
    d = np.asarray(direction, dtype=float)
    if d.shape != (3,) or not np.all(np.isfinite(d)) or np.linalg.norm(d) == 0:
        raise InputError("statics.direction", "a non-zero 3-vector", direction)
    gravity = g * d / np.linalg.norm(d)
    Q = np.concatenate([system.body.mass * gravity, np.zeros(3)])  # weight acts at the CG
    K = np.asarray(system.K)
    q, *_ = np.linalg.lstsq(K, Q, rcond=None)
    if np.linalg.norm(K @ q - Q) > 1e-8 * np.linalg.norm(Q):
        raise InputError("mounts", "mounts that can carry the body's weight along gravity",
                         "a layout with no stiffness against gravity (the body would fall freely)")
    # The load on a mount is k delta along its axes (the spring pushes the body back with -k delta):
    # the same sign as the dynamic forces of sixdof.analysis.response, so that the two add up.
    local = system.stiffnesses * (mount_local_map(system.positions, system.axes) @ q)
    forces = np.einsum("nji,nj->ni", system.axes, local)
    support = forces @ (gravity / g)
    # Round-off can leave a mount carrying nothing with a tiny negative value: not uplift.
    uplift_tol = 1e-9 * system.body.mass * g
    uplift = tuple(n for n, s in zip(system.mount_names, support) if s < -uplift_tol)
    return Statics(gravity, q, forces, local, support, uplift)
