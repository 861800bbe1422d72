"""Derived responses of a simulation: motion of body points, mount forces, forces on the foundation.

Rigid body, small rotations: a body point ``p`` (from the CG, body axes) moves by
``u_p = u_cg + theta x p`` (:func:`sixdof.model.kinematics.point_map`); the same map takes velocities and
accelerations. A mount deforms by the motion of its body point *relative to the ground* (the
foundation translates rigidly under every mount), and carries ``k delta + c delta'`` along its own
axes (a nonlinear mount, :mod:`sixdof.model.nonlinear`, its force law ``r`` at the static plus dynamic
deflection). Every force here is the dynamic part about static equilibrium (add the static deflection's
forces from :mod:`sixdof.analysis.statics` for totals).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from sixdof.dofs import UNITS
from sixdof.errors import instance, point, readonly
from sixdof.model.kinematics import point_map
from sixdof.model.system import System
from sixdof.results import Result, TimeHistory, quantity, result_type

if TYPE_CHECKING:
    from sixdof.model.system import System


@result_type
@dataclass(frozen=True, eq=False)
class PointMotion(Result):
    """Motion of one body point. Arrays of shape (n, 3) in body axes.

    Attributes
    ----------
    position : ndarray, shape (3,)
        The point, from the CG in body axes [m].
    displacement, velocity, acceleration : ndarray, shape (n, 3)
        [m, m/s, m/s^2]; absolute, or relative to the ground when ``relative``.
    relative : bool
    """

    position: np.ndarray = quantity("m", ("axis",), description="body points from the CG, body axes")
    displacement: np.ndarray = quantity("m", ("t", "axis"), description="displacement of each body point, body axes")
    velocity: np.ndarray = quantity("m/s", ("t", "axis"), description="velocity of each body point, body axes")
    acceleration: np.ndarray = quantity("m/s^2", ("t", "axis"),
                                        description="acceleration of each body point, body axes")
    relative: bool = quantity("1", (), encode=bool, decode=bool,
                              description="true: the point's motion is relative to the ground; false: absolute")


def point_motion(response: TimeHistory, position, *, relative: bool = False) -> PointMotion:
    """Displacement, velocity and acceleration of a body point.

    Parameters
    ----------
    response : TimeHistory
    position : array_like, shape (3,)
        Point from the CG in body axes [m].
    relative : bool, optional
        Relative to the ground instead of absolute. Default False.

    Returns
    -------
    PointMotion

    Raises
    ------
    InputError
        ``position`` is not 3 finite values [m].
    """
    p = point(position)
    T = point_map(p)
    q, qd, qdd = (getattr(response, name + ("_relative" if relative else "")) for name in ("q", "qd", "qdd"))
    return PointMotion(position=readonly(p), displacement=readonly(q @ T.T), velocity=readonly(qd @ T.T),
                       acceleration=readonly(qdd @ T.T), relative=relative)


def points_motion(response: TimeHistory, points, *, relative: bool = False) -> dict[str, PointMotion]:
    """:func:`point_motion` of named points: ``{name: PointMotion}``.

    ``points`` is a mapping ``name -> position`` or a sequence of objects with ``name`` and
    ``position`` attributes (the scenario's ``[[points]]``).
    """
    items = points.items() if isinstance(points, dict) else ((p.name, p.position) for p in points)
    return {name: point_motion(response, pos, relative=relative) for name, pos in items}


def global_damping(system: System) -> np.ndarray:
    """The damping matrix of the global models, Rayleigh and modal: ``C - C_mounts`` (6, 6) [N s/m, N s, N m s/rad].

    What reaches the foundation, in the time domain (:func:`mount_forces`) and in the frequency domain
    (:func:`sixdof.analysis.frf.force_transmissibility`) alike: every damping model of eq. (1) acts on the
    body's motion relative to the ground (it stands for dissipation in the mounts), so its force
    ``(C - C_mounts) q_rel'`` reacts on the foundation as the dashpots' does. Any other choice would break
    the body's momentum balance: the generalized force on the foundation is ``Q - M q''`` only when all
    of ``C`` is in it. Exactly zero without Rayleigh or modal damping (no round-off from ``C - C``).
    """
    if system.rayleigh is None and system.modal_damping is None:
        return np.zeros((6, 6))
    return np.asarray(system.C) - np.asarray(system.C_mounts)


_ON = "exerted by each mount on the foundation, body axes (dynamic part about static equilibrium)"


@result_type
@dataclass(frozen=True, eq=False)
class MountForces(Result):
    """Forces carried by the mounts over time (dynamic part).

    Sign: every force is the one the mount exerts *on the foundation* (the body receives its
    negative): positive along an axis when the body has moved, relative to the ground, along it.

    Attributes
    ----------
    names : tuple of str
        Mount names, in the system's order (m mounts).
    deformation : ndarray, shape (m, n, 3)
        Mount point's displacement relative to the ground, body axes [m].
    elastic, damping, total : ndarray, shape (m, n, 3)
        Spring force ``A' diag(k) A delta``, dashpot force ``A' diag(c) A delta'`` (with the forces of the
        mount's Maxwell branches, :attr:`TimeHistory.maxwell_force`) and their sum, in body axes [N]. A hysteretic
        axis's spring force is its law's ``p d + q z`` (:mod:`sixdof.model.hysteresis`) in a direct solve, its
        linearization in the linear paths.
    local : ndarray, shape (m, n, 3)
        ``total`` along each mount's own axes [N].
    other_damping : ndarray, shape (n, 6)
        Generalized force of the Rayleigh and modal damping, ``(C - C_mounts) q_rel'``
        [N, N m]: not attributable to one mount, transmitted to the foundation all the same.
    foundation_force : ndarray, shape (n, 3)
        Total force on the foundation, body axes [N]: the mounts' plus ``other_damping``'s.
    foundation_moment : ndarray, shape (n, 3)
        Total moment on the foundation about the body's CG, body axes [N m].
    """

    names: tuple[str, ...] = quantity("", ("mount",), name="mount", decode=lambda a: tuple(str(n) for n in a))
    deformation: np.ndarray = quantity("m", ("mount", "t", "axis"), name="mount_deformation",
                                       description="displacement of each mount's body point relative to the ground, "
                                       "body axes")
    elastic: np.ndarray = quantity("N", ("mount", "t", "axis"), name="mount_force_elastic",
                                   description=f"spring force {_ON}")
    damping: np.ndarray = quantity("N", ("mount", "t", "axis"), name="mount_force_damping",
                                   description=f"dashpot and Maxwell branch force {_ON}")
    total: np.ndarray = quantity("N", ("mount", "t", "axis"), name="mount_force", description=f"force {_ON}")
    local: np.ndarray = quantity("N", ("mount", "t", "mount_axis"), name="mount_force_local",
                                 description="mount_force along each mount's own axes u, v, w")
    other_damping: np.ndarray = quantity(UNITS["Q"], ("t", "load"), name="other_damping_force",
                                         description="generalized force of Rayleigh and modal damping "
                                         "(C - C_mounts) q_rel'")
    foundation_force: np.ndarray = quantity("N", ("t", "axis"), description="total force on the foundation, "
                                            "body axes")
    foundation_moment: np.ndarray = quantity("N m", ("t", "axis"), description="total moment on the foundation "
                                             "about the CG, body axes")


def mount_forces(system: System, response: TimeHistory) -> MountForces:
    """Each mount's force and the total force and moment on the foundation.

    Parameters
    ----------
    system : sixdof.model.system.System
        The system that was simulated.
    response : TimeHistory

    Returns
    -------
    MountForces
    """
    instance(system, "system", System)
    instance(response, "response", TimeHistory)
    z, zd = response.q_relative, response.qd_relative
    T = point_map(system.positions)  # (m, 3, 6)
    # The same product as point_motion, so a mount's deformation is its point's relative motion exactly.
    deformation, rate = (np.stack([x @ Tm.T for Tm in T]) for x in (z, zd))  # (m, n, 3)
    A = np.asarray(system.axes)  # (m, 3, 3): rows are the mount's axes
    hysteretic = system.hysteretic
    # A direct solve's hysteretic axes carry their laws' force, with no equivalent dashpot (the linear paths' model).
    direct = hysteretic.count and response.hysteretic_state is not None
    local_elastic, local_damping = (np.einsum("mij,mnj->mni", A, x) * k[:, None, :]
                                    for x, k in ((deformation, system.stiffnesses),
                                                 (rate, system.given_dampings if direct else system.dampings)))
    if direct:
        local_elastic[hysteretic.mount, :, hysteretic.axis] = hysteretic.force(
            **hysteretic.motion(z, zd, response.hysteretic_state)).T
    branches = system.branches
    if branches.count:  # a Maxwell branch's force acts along its mount's axis, beside the dashpot's
        np.add.at(local_damping, (branches.mount, slice(None), branches.axis), response.maxwell_force.T)
    laws = system.nonlinear
    if laws.count:  # a nonlinear axis carries r(static + dynamic deflection) less its static load
        d, d_rate = (np.einsum("mij,mnj->mni", A, x)[laws.mount, :, laws.axis].T for x in (deformation, rate))
        total = laws.static_deflection + d  # (n, ne)
        branch = 0.0 if not branches.count else (
            response.maxwell_force @ laws.branch_map(branches.mount, branches.axis).T)
        # A mount lifted off carries nothing along the axis: neither spring, dashpot nor Maxwell branch.
        contact = laws.in_contact(total, d_rate, branch).T
        local_elastic[laws.mount, :, laws.axis] = contact * laws.force(total).T - laws.static_force[:, None]
        local_damping[laws.mount, :, laws.axis] *= contact
    elastic, damping = (np.einsum("mji,mnj->mni", A, x) for x in (local_elastic, local_damping))
    total = elastic + damping
    other = zd @ global_damping(system).T
    force = total.sum(axis=0) + other[:, :3]
    moment = np.cross(system.positions[:, None, :], total).sum(axis=0) + other[:, 3:]
    return MountForces(
        names=tuple(system.mount_names), deformation=readonly(deformation), elastic=readonly(elastic),
        damping=readonly(damping), total=readonly(total), local=readonly(local_elastic + local_damping),
        other_damping=readonly(other), foundation_force=readonly(force), foundation_moment=readonly(moment),
    )


__all__ = ["PointMotion", "MountForces", "point_motion", "points_motion", "mount_forces", "global_damping"]
