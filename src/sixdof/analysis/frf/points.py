"""Responses between points of the body and its mounts: point FRFs, force and ground transmissibility."""

from __future__ import annotations

import numpy as np

from sixdof.analysis.frf.receptance import receptance, support_stiffness
from sixdof.analysis.frf.records import (
    _QUANTITY_SUFFIX,
    ForceTransmissibility,
    GroundTransmissibility,
    PointFRF,
    _check_quantity,
    _ratio_unit,
)
from sixdof.analysis.response import global_damping
from sixdof.dofs import AXES, DOFS
from sixdof.errors import InputError, direction_check, point, readonly
from sixdof.model.kinematics import point_map, response_row, unit_load
from sixdof.model.system import System


def parse_direction(value, field: str, rotations: bool = True) -> tuple[np.ndarray, bool]:
    """Unit vector in body axes and whether it is rotational ('rx', 'ry', 'rz')."""
    names = ", ".join(f"'{d}'" for d in (DOFS if rotations else AXES))
    expected = f"one of {names} or a nonzero 3-vector in body axes"
    if isinstance(value, str):
        rotational = rotations and value in DOFS[3:]
        axis = value[1:] if rotational else value
        if axis not in AXES:
            raise InputError(field, expected, value)
        return np.eye(3)[AXES.index(axis)], rotational
    return direction_check(expected)(value, field), False


def point_frf(system: System, f_hz, load_point, load_direction, response_point, response_direction,
              quantity: str = "receptance", method: str = "direct") -> PointFRF:
    """FRF between a load at one body point and the motion of another.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    load_point : array_like, shape (3,)
        Where the load acts, from the CG in body axes [m].
    load_direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a nonzero 3-vector [1] (normalized): a unit force along it; or
        ``"rx"``, ``"ry"``, ``"rz"``: a unit moment about that body axis.
    response_point : array_like, shape (3,)
        Where the motion is observed, from the CG in body axes [m].
    response_direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a 3-vector [1]: the point's translation along it; or ``"rx"``,
        ``"ry"``, ``"rz"``: the body's rotation about that axis (the same at every point).
    quantity : {"receptance", "mobility", "accelerance"}
        Displacement, velocity or acceleration per load.
    method : {"direct", "modal"}
        How the body's receptance is computed (:func:`~sixdof.analysis.frf.receptance.receptance`).

    Returns
    -------
    PointFRF
        ``values`` in m/N, m/(s N), m/(s^2 N) for force in, translation out (``unit`` says which).

    Raises
    ------
    InputError
        A point that is not 3 finite values [m], a direction that is neither a label nor a nonzero
        3-vector, a ``quantity`` not one of the three, or what
        :func:`~sixdof.analysis.frf.receptance.receptance` refuses (frequencies, ``method``).
    SolverError
        As :func:`~sixdof.analysis.frf.receptance.receptance`.
    """
    _check_quantity(quantity, "quantity")
    lp = point(load_point, "load_point")
    ld, moment = parse_direction(load_direction, "load_direction")
    rp = point(response_point, "response_point")
    rd, rotation = parse_direction(response_direction, "response_direction")
    frf = receptance(system, f_hz, method=method)
    values = (frf.quantity(quantity) @ unit_load(lp, ld, moment)) @ response_row(rp, rd, rotation)
    unit = _ratio_unit(("rad" if rotation else "m") + _QUANTITY_SUFFIX[quantity], "N m" if moment else "N")
    return PointFRF(f_hz=frf.f_hz, values=readonly(values, complex), quantity=quantity, unit=unit,
                    load_point=lp, load_direction=ld, response_point=rp, response_direction=rd,
                    load_kind="moment" if moment else "force",
                    response_kind="rotation" if rotation else "translation", method=method)


def force_transmissibility(system: System, f_hz, load_point, load_direction,
                           method: str = "direct") -> ForceTransmissibility:
    """Forces passed to the foundation by each mount, and their resultant, per unit applied load.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    load_point : array_like, shape (3,)
        Where the load acts, from the CG in body axes [m].
    load_direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a nonzero 3-vector [1] (unit force), or ``"rx"``, ``"ry"``,
        ``"rz"`` (unit moment).
    method : {"direct", "modal"}
        How the body's receptance is computed.

    Returns
    -------
    ForceTransmissibility
        Mount forces (nf, n_mounts, 3) [N] and resultant (nf, 6) [N, N m] per unit load (per N of a force,
        per N m of a moment), complex: the mounts' stiffness, loss factor and dashpots, and the global
        (Rayleigh, modal) damping's force.

    Raises
    ------
    InputError
        A point that is not 3 finite values [m], a direction that is neither a label nor a nonzero
        3-vector, or what :func:`~sixdof.analysis.frf.receptance.receptance` refuses
        (frequencies, ``method``).
    SolverError
        As :func:`~sixdof.analysis.frf.receptance.receptance`.
    """

    lp = point(load_point, "load_point")
    ld, moment = parse_direction(load_direction, "load_direction")
    frf = receptance(system, f_hz, method=method)
    forces, other, total = foundation_forces(system, frf.omega, frf.H @ unit_load(lp, ld, moment))
    return ForceTransmissibility(f_hz=frf.f_hz, mount_names=system.mount_names, mount_forces=readonly(forces, complex),
                                 total=readonly(total, complex), other_damping=readonly(other, complex),
                                 load_point=lp, load_direction=ld,
                                 load_kind="moment" if moment else "force", method=method)


def mount_impedances(system: System, omega) -> np.ndarray:
    """Each mount's complex stiffness along its own axes, ``k (1 + i eta) + i w c`` plus its Maxwell branches',
    (nf, n_mounts, 3) [N/m] at ``omega`` (nf,) [rad/s]."""
    omega = np.asarray(omega, dtype=float)
    local = system.stiffnesses * (1.0 + 1j * system.loss_factors) + 1j * omega[:, None, None] * system.dampings
    branches = system.branches
    if branches.count:
        np.add.at(local, (slice(None), branches.mount, branches.axis), branches.dynamic_stiffness(omega))
    return local


def foundation_forces(system: System, omega, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What the mounts and the global damping pass to the foundation for the complex motion amplitudes ``q``
    (nf, 6) at the circular frequencies ``omega`` (nf,) [rad/s], the ground at rest.

    Returns each mount's force in body axes, ``A' diag(k (1 + i eta) + i w c + K_b) A u`` (nf, n_mounts, 3), the
    global damping's generalized force ``i w (C - C_mounts) q`` (nf, 6), and their resultant about the CG's
    rest position (nf, 6); complex, in the units of ``q`` times stiffness.
    """
    t = point_map(system.positions)  # (n, 3, 6)
    u = np.einsum("nij,fj->fni", t, q)  # mount point displacements (nf, n, 3)
    # Each mount's complex stiffness in body axes, A' diag(k (1 + i eta) + i w c + K_b) A: (nf, n, 3, 3).
    local = mount_impedances(system, omega)
    impedances = np.einsum("nai,fna,naj->fnij", system.axes, local, system.axes)
    forces = np.einsum("fnij,fnj->fni", impedances, u)
    other = 1j * omega[:, None] * (q @ global_damping(system).T)
    return forces, other, np.einsum("nia,fni->fa", t, forces) + other


def ground_transmissibility(system: System, f_hz, ground_direction, response_point,
                            method: str = "direct") -> GroundTransmissibility:
    """Motion of a body point per unit rigid translation of the ground under every mount.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    ground_direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a nonzero 3-vector [1] (normalized): the ground's translation.
    response_point : array_like, shape (3,)
        Body point observed, from the CG in body axes [m].
    method : {"direct", "modal"}
        How the body's receptance is computed (:func:`~sixdof.analysis.frf.receptance.receptance`).

    Returns
    -------
    GroundTransmissibility
        Absolute and relative point motion per unit ground motion [m/m] (also the ratio of
        velocities or of accelerations), and the generalized motion ``q`` per unit ground motion.

    Raises
    ------
    InputError
        A point that is not 3 finite values [m], a direction that is neither x, y, z nor a nonzero
        3-vector, or what :func:`~sixdof.analysis.frf.receptance.receptance` refuses
        (frequencies, ``method``).
    SolverError
        As :func:`~sixdof.analysis.frf.receptance.receptance`.
    """
    d, _ = parse_direction(ground_direction, "ground_direction", rotations=False)
    rp = point(response_point, "response_point")
    frf = receptance(system, f_hz, method=method)
    qg = np.concatenate([d, np.zeros(3)])
    # All damping acts on the motion relative to the ground: Z q = (K + i K_h + i w C + K_b(w)) q_g.
    drive = support_stiffness(system, frf.omega) @ qg
    q = np.einsum("fij,fj->fi", frf.H, drive)
    absolute = q @ point_map(rp).T
    return GroundTransmissibility(f_hz=frf.f_hz, q=readonly(q, complex), absolute=readonly(absolute, complex),
                                  relative=readonly(absolute - d[None, :], complex), ground_direction=d,
                                  response_point=rp, method=method)
