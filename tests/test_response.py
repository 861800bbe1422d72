"""Point motions, mount forces and foundation forces, checked by statics and by hand kinematics.

The runs reuse the structures of tests/test_direct.py (same signal kinds and sample counts), so
they reuse its compiled solvers.
"""

import numpy as np
import pytest

from sixdof import (
    Excitation,
    GroundMotion,
    Harmonic,
    InitialState,
    InputError,
    Load,
    SimulationSettings,
    Step,
    mount_forces,
    point_motion,
    simulate,
)
from sixdof.analysis.response import points_motion
from systems import bridge, skewed_machine
from tolerances import RTOL_DIRECT_EXACT, RTOL_LINALG, RTOL_RELATIVE_MOTION

HARMONIC = SimulationSettings(duration=3.0, sample_rate_hz=500.0)
POINT = np.array([0.3, 10.0, 1.0])
FORCE = np.array([5e3, 2e4, -1e5])


@pytest.fixture(scope="module")
def harmonic():
    beam = bridge("elastomer")
    excitation = Excitation(loads=(Load("l", POINT, force=FORCE, signal=Harmonic(f_hz=5.0)),))
    return beam, simulate(beam, excitation, HARMONIC)


def test_point_motion_is_rigid_body_kinematics(harmonic):
    _, run = harmonic
    p = np.array([0.6, -20.0, 1.0])
    motion = point_motion(run, p)
    for field, q in (("displacement", run.q), ("velocity", run.qd), ("acceleration", run.qdd)):
        expected = q[:, :3] + np.cross(q[:, 3:], p)  # u_cg + theta x p
        assert np.allclose(getattr(motion, field), expected, rtol=0,
                           atol=RTOL_LINALG * np.abs(expected).max())
    named = points_motion(run, {"end": p, "cg": [0, 0, 0]})
    assert np.array_equal(named["cg"].displacement, run.q[:, :3])
    assert not named["end"].relative


def test_static_deflection_puts_the_load_on_the_mounts():
    # Started at the static deflection under a step load, the body stays there: the mounts carry
    # the load, and their forces and moments balance it (statics of the free body).
    machine = skewed_machine()
    point, force, moment = np.array([0.1, -0.2, 0.3]), np.array([200.0, -150.0, -900.0]), np.array(
        [10.0, 0.0, -20.0])
    vector = np.concatenate([force, np.cross(point, force) + moment])
    static = np.linalg.solve(machine.K, vector)
    excitation = Excitation(loads=(Load("l", point, force=force, moment=moment,
                                        signal=Step(start=0.0)),), initial=InitialState(q=static))
    run = simulate(machine, excitation, SimulationSettings(duration=1.0, sample_rate_hz=100.0))
    forces = mount_forces(machine, run)
    assert forces.total.shape == (4, run.t.size, 3)
    scale = np.abs(force).max()
    assert np.allclose(forces.foundation_force, force, rtol=0, atol=RTOL_DIRECT_EXACT * scale)
    lever = np.abs(machine.positions).max()
    assert np.allclose(forces.foundation_moment, np.cross(point, force) + moment, rtol=0,
                       atol=RTOL_DIRECT_EXACT * scale * lever)
    # each mount by hand: its point moved by u = u_cg + theta x p; force A' diag(k) A u
    for j, mount in enumerate(machine.mounts):
        u = static[:3] + np.cross(static[3:], mount.position)
        local = mount.stiffness * (mount.axes @ u)
        assert np.allclose(forces.local[j, -1], local, rtol=0, atol=RTOL_DIRECT_EXACT * scale)
        assert np.allclose(forces.total[j, -1], mount.axes.T @ local, rtol=0,
                           atol=RTOL_DIRECT_EXACT * scale)
    assert np.all(np.abs(forces.damping) < RTOL_DIRECT_EXACT * scale)


def test_foundation_force_balances_the_body_inertia(harmonic):
    # Newton: M q'' = Q - (forces on the foundation), and the dashpots carry the damping part.
    beam, run = harmonic
    forces = mount_forces(beam, run)
    wrench = np.concatenate([forces.foundation_force, forces.foundation_moment], axis=1)
    expected = run.Q - run.qdd @ beam.M.T
    assert np.allclose(wrench, expected, rtol=0, atol=RTOL_LINALG * np.abs(expected).max(axis=0))
    assert np.all(forces.other_damping == 0)  # all damping is in the dashpots here
    dashpots = np.einsum("mni,m->ni", forces.damping, np.ones(4))
    expected_damping = run.qd_relative @ beam.C_mounts.T
    assert np.allclose(dashpots, expected_damping[:, :3], rtol=0,
                       atol=RTOL_LINALG * np.abs(expected_damping[:, :3]).max())


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_ground_motion_deforms_mounts_by_the_relative_motion():
    beam = bridge("elastomer")
    ground = GroundMotion("acceleration", [0.0, 1.0, 0.0], Harmonic(f_hz=1.5), scale=0.5)
    run = simulate(beam, Excitation(ground=ground), HARMONIC)
    absolute = point_motion(run, beam.positions[0])
    relative = point_motion(run, beam.positions[0], relative=True)
    assert np.allclose(absolute.displacement - relative.displacement, run.ground_displacement,
                       rtol=0, atol=RTOL_RELATIVE_MOTION * np.abs(run.ground_displacement).max())
    assert np.allclose(absolute.acceleration - relative.acceleration, run.ground_acceleration,
                       rtol=0, atol=RTOL_RELATIVE_MOTION * np.abs(run.ground_acceleration).max())
    forces = mount_forces(beam, run)
    assert np.array_equal(forces.deformation[0], relative.displacement)
    # the ground carries the body: the foundation force is the body's inertia force
    assert np.allclose(forces.foundation_force, -beam.body.mass * run.qdd[:, :3], rtol=0,
                       atol=RTOL_LINALG * beam.body.mass * np.abs(run.qdd[:, :3]).max())


def test_bad_point_is_named(harmonic):
    with pytest.raises(InputError, match=r"position: expected 3 coordinates \[x, y, z\] in m"):
        point_motion(harmonic[1], [1.0, 2.0])
