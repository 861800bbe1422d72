"""The OpenSeesPy reference models (tests/opensees_models.py) against answers computed apart from OpenSees.

They are the independent side of issue 48's cross-check (item 7) and speed benchmark (item 8), so they are checked
first: the BoucWen material's parameter mapping against the closed form of the n = 1 law on a quasi-static path;
a single mass and a 6-DOF rigid body against scipy solve_ivp of the same ODEs (tests/hysteresis_references.py);
the elastic rigid body against the exact matrix exponential. OpenSees' backward-Euler update of z makes its error
first order in the step: each test shows it halve with the step, and Richardson's extrapolation of two steps
remove most of it, so what is left between the two sides is OpenSees' time-step error and nothing else.
"""

import numpy as np
import pytest

try:
    import openseespy.opensees as ops
except ImportError:
    pytest.skip("openseespy is not installed (the test extra)", allow_module_level=True)
except RuntimeError as error:  # openseespy turns its library's load failure into a RuntimeError
    pytest.skip(f"openseespy does not load ({error}): it needs the system's BLAS and LAPACK (Debian: apt-get "
                "install libblas3 liblapack3)", allow_module_level=True)

from hysteresis_references import (  # noqa: E402
    bouc_wen_sdof_ivp,
    direction_vector,
    rigid_body_ivp,
    rigid_body_matrices,
)
from opensees_models import (  # noqa: E402
    bouc_wen_parameters,
    bouc_wen_sdof,
    peak_change,
    rigid_body_on_bearings,
    time_opensees,
    worst_error,
)
from references import relative_error_per_dof, state_matrices  # noqa: E402
from sixdof import Mount, RigidBody, System  # noqa: E402
from tolerances import (  # noqa: E402
    FIRST_ORDER_RATIO,
    RTOL_BOUC_WEN_MATERIAL,
    RTOL_HYSTERESIS_REFERENCE,
    RTOL_LINALG,
    RTOL_OPENSEES_BODY,
    RTOL_OPENSEES_ELASTIC,
    RTOL_OPENSEES_FORCE,
    RTOL_OPENSEES_PEAK,
    RTOL_OPENSEES_RICHARDSON,
    RTOL_OPENSEES_RICHARDSON_BODY,
    RTOL_SIXDOF_HYSTERESIS,
    SECOND_ORDER_RATIO,
)


def n1_closed_form(d, d_y, beta, gamma):
    """z along a piecewise-monotone deflection path ``d`` (samples, from 0) for n = 1, exactly.

    With s = sgn(d') and sigma = sgn(z) fixed, the law reads dz/dd = (1 - lam z) / d_y, lam = beta s + gamma sigma:
    z = 1/lam + (z0 - 1/lam) exp(-lam (d - d0) / d_y). Each increment is solved so, split where z crosses 0
    (after the signed dd = d_y ln(1 - lam z0) / lam; from z = 0, z moves along s).
    """
    z = np.zeros(len(d))

    def advance(z0, dd, lam):
        return z0 + dd / d_y if lam == 0 else 1 / lam + (z0 - 1 / lam) * np.exp(-lam * dd / d_y)

    for i in range(1, len(d)):
        dd, z0 = d[i] - d[i - 1], z[i - 1]
        s = np.sign(dd)
        sigma = np.sign(z0) if z0 != 0 else s
        lam = beta * s + gamma * sigma
        z1 = advance(z0, dd, lam)
        if np.sign(z1) != sigma and z1 != 0:  # crossed zero: the rest of the increment with sigma = s
            to_zero = -z0 * d_y if lam == 0 else d_y * np.log(1 - lam * z0) / lam
            z1 = advance(0.0, dd - to_zero, beta * s + gamma * s)
        z[i] = z1
    return z


def material_path(d_y, per_yield):
    """0 -> 6 d_y -> -6 d_y -> 3 d_y, ``per_yield`` increments per d_y."""
    legs = [np.linspace(a, b, int(round(abs(b - a) * per_yield)) + 1)[1:] for a, b in [(0, 6), (6, -6), (-6, 3)]]
    return d_y * np.concatenate([[0.0], *legs])


def material_force(arguments, d):
    """The BoucWen material's stress along the deflection samples ``d`` (each set and committed in turn)."""
    ops.wipe()
    ops.uniaxialMaterial("BoucWen", 1, *arguments)
    ops.testUniaxialMaterial(1)
    force = []
    for value in d:
        ops.setStrain(value)
        force.append(ops.getStress())
    ops.wipe()
    return np.array(force)


def test_bouc_wen_material_against_the_n1_closed_form():
    """The mapping of bouc_wen_parameters, beta and gamma apart (b = 0.7, g = 0.3: swapping them changes the
    unloading slope from (1 + 0.4 z) / d_y to (1 - 0.4 z) / d_y), on a cyclic quasi-static path."""
    k, fy, alpha, beta, gamma = 2e6, 1.3e4, 0.1, 0.7, 0.3
    d_y = fy / k
    errors = []
    for per_yield in (200, 400):
        d = material_path(d_y, per_yield)
        z = n1_closed_form(d, d_y, beta, gamma)
        expected = alpha * k * d + (1 - alpha) * fy * z
        errors.append(np.max(np.abs(material_force(bouc_wen_parameters(k, fy, alpha, 1.0, beta, gamma), d)
                                    - expected)) / fy)
    assert np.max(np.abs(z)) > 0.99  # the path reaches the loop's envelope |z| -> 1 / (b + g) = 1
    # Backward Euler along the path: first order in the increment (measured 1.16e-3, 5.8e-4 of Fy).
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=FIRST_ORDER_RATIO)
    assert errors[1] < RTOL_BOUC_WEN_MATERIAL
    # The test tells the two orders apart: beta and gamma swapped are 0.37 Fy off.
    swapped = material_force(bouc_wen_parameters(k, fy, alpha, 1.0, gamma, beta), d)
    assert np.max(np.abs(swapped - expected)) / fy > 100 * RTOL_BOUC_WEN_MATERIAL


SDOF = dict(mass=1000.0, k=1e5, fy=0.1 * 1000.0 * 9.81)  # T = 0.63 s, yield at 0.1 g, d_y = 9.8 mm
T_SDOF = np.arange(0.0, 6.0 + 1e-9, 0.01)
AG_SDOF = 2.0 * np.sin(2 * np.pi * 1.0 * T_SDOF)  # 0.2 g at 1 Hz: ductility ~12, |z| to 1


@pytest.mark.parametrize("alpha, n, beta, gamma, damping", [(0.1, 1.0, 0.5, 0.5, 0.0), (0.05, 2.0, 0.7, 0.3, 300.0)],
                         ids=["n1-defaults", "n2-dashpot"])
def test_single_mass_against_scipy(alpha, n, beta, gamma, damping):
    params = (SDOF["mass"], SDOF["k"], SDOF["fy"], alpha, n, beta, gamma, T_SDOF, AG_SDOF)
    ref = bouc_wen_sdof_ivp(*params, damping=damping, rtol=1e-13)
    assert np.max(np.abs(bouc_wen_sdof_ivp(*params, damping=damping).d - ref.d)) / np.max(np.abs(ref.d)) \
        < RTOL_HYSTERESIS_REFERENCE  # the reference's own error, at the default tolerance
    assert np.max(np.abs(ref.z)) > 0.99 and np.max(np.abs(ref.d)) > 8 * SDOF["fy"] / SDOF["k"]
    runs = [bouc_wen_sdof(*params, substeps=s, damping=damping) for s in (4, 8, 16)]  # dt 2.5, 1.25, 0.625 ms
    peak = [abs(np.max(np.abs(r.d)) - np.max(np.abs(ref.d))) / np.max(np.abs(ref.d)) for r in runs]
    force = [np.max(np.abs(r.force - ref.force)) / np.max(np.abs(ref.force)) for r in runs]
    disp = [np.max(np.abs(r.d - ref.d)) / np.max(np.abs(ref.d)) for r in runs]
    # First order: each halving of the step halves the errors (measured ratios 1.98-2.03).
    for e in (force, disp):
        assert e[0] / e[1] == pytest.approx(2.0, rel=FIRST_ORDER_RATIO)
        assert e[1] / e[2] == pytest.approx(2.0, rel=FIRST_ORDER_RATIO)
    # At 0.625 ms (measured): peak displacement 5.9e-4 (n = 1) and 4.4e-4 (n = 2), force history 2.1e-3 and
    # 2.9e-3 of the peak force.
    assert peak[2] < RTOL_OPENSEES_PEAK
    assert force[2] < RTOL_OPENSEES_FORCE
    # The first-order term is the whole difference: 2 x(h/2) - x(h) is ~65x closer (measured 3.3e-5, 4.2e-5).
    richardson = np.max(np.abs(2 * runs[2].force - runs[1].force - ref.force)) / np.max(np.abs(ref.force))
    assert richardson < RTOL_OPENSEES_RICHARDSON * force[2]


# A 500 kg body with a full inertia tensor on four unequal, damped mounts at the corners of a 0.8 x 0.6 m
# rectangle below the CG: every DOF coupled, modes 6.6-20 Hz.
BODY = dict(mass=500.0, inertia=np.array([[60.0, 4.0, -3.0], [4.0, 45.0, 2.0], [-3.0, 2.0, 70.0]]),
            positions=np.array([[-0.4, -0.3, -0.25], [0.4, -0.3, -0.25], [0.4, 0.3, -0.25], [-0.4, 0.3, -0.25]]),
            stiffness=np.array([[3e5, 2.5e5, 8e5]]) * (1 + 0.1 * np.arange(4))[:, None],
            damping=np.array([[300.0, 500.0, 900.0]]) * (1 + 0.5 * np.arange(4))[:, None])
T_BODY = np.arange(0.0, 2.0 + 1e-9, 0.005)
AG_BODY = 2.0 * np.sin(2 * np.pi * 3.0 * T_BODY) * np.minimum(T_BODY / 0.5, 1.0)
DIRECTION = (1.0, 0.6, 0.4)  # three UniformExcitation patterns, in the principal frame


def test_rigid_body_matrices_are_sixdofs():
    """The references' M, K, C are sixdof's System's for the same body and mounts (one convention)."""
    system = System(RigidBody(BODY["mass"], BODY["inertia"]),
                    [Mount(f"m{j}", p, k, c) for j, (p, k, c) in
                     enumerate(zip(BODY["positions"], BODY["stiffness"], BODY["damping"]))])
    M, K, C = rigid_body_matrices(**BODY)
    for ours, theirs in ((M, system.M), (K, system.K), (C, system.C)):
        np.testing.assert_allclose(ours, theirs, rtol=RTOL_LINALG, atol=RTOL_LINALG * np.abs(theirs).max())


def test_rigid_body_elastic_against_the_exact_solution():
    """Linear bearings (BoucWen with alpha = 1 on u, v of two mounts, Elastic elsewhere) under a first-order-hold
    record along a skew direction, against the exact solution: Newmark's second order.

    scipy.signal.lsim is exact for a first-order hold (one matrix exponential of the state-space system augmented
    with the input's slope; it agrees with references.exact_response's piecewise expm to 6e-15 here).
    """
    import scipy.signal

    hysteresis = [{"u": (100.0, 1.0, 1.0, 0.5, 0.5), "v": (100.0, 1.0, 1.0, 0.5, 0.5)}] * 2 + [{}] * 2
    M, K, C = rigid_body_matrices(**BODY)
    A, B = state_matrices(M, C, K)
    load = B @ (-M @ np.concatenate([direction_vector(DIRECTION), np.zeros(3)]))
    _, q_exact, _ = scipy.signal.lsim((A, load[:, None], np.eye(6, 12), np.zeros((6, 1))), AG_BODY, T_BODY)
    errors = [relative_error_per_dof(rigid_body_on_bearings(**BODY, hysteresis=hysteresis, t=T_BODY,
                                                            ground_acc=AG_BODY, direction=DIRECTION,
                                                            substeps=s).q, q_exact) for s in (2, 4)]
    # Per DOF, relative to its own peak (measured 3.5e-4 to 1.5e-3 at 2.5 ms, then 4.0x smaller).
    np.testing.assert_allclose(errors[0] / errors[1], 4.0, rtol=SECOND_ORDER_RATIO)
    assert np.max(errors[1]) < RTOL_OPENSEES_ELASTIC


HYSTERESIS = [{"u": (150.0, 0.1, 1.0, 0.5, 0.5), "v": (150.0, 0.1, 1.0, 0.5, 0.5)}] * 4  # d_y 0.4-0.6 mm


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_rigid_body_hysteretic_against_scipy():
    """Bouc-Wen on u and v of all four mounts (ductility ~12 along u, ~2 along v), against solve_ivp of the
    6-DOF ODE."""
    case = dict(**BODY, hysteresis=HYSTERESIS, t=T_BODY, ground_acc=AG_BODY, direction=DIRECTION)
    ref = rigid_body_ivp(**case)
    assert np.nanmax(np.abs(ref.z)) > 0.99
    runs = [rigid_body_on_bearings(**case, substeps=s) for s in (8, 16)]  # dt 0.625, 0.3125 ms
    errors = [relative_error_per_dof(r.q, ref.q) for r in runs]
    force = [np.nanmax(np.abs(r.hysteretic_force - ref.hysteretic_force)) / np.nanmax(np.abs(ref.hysteretic_force))
             for r in runs]
    np.testing.assert_allclose(errors[0] / errors[1], 2.0, rtol=FIRST_ORDER_RATIO)
    assert force[0] / force[1] == pytest.approx(2.0, rel=FIRST_ORDER_RATIO)
    # At 0.3125 ms (measured): per DOF 3.4e-4 (z) to 7.2e-3 (rz), the hysteretic forces 3.4e-3 of their peak.
    assert np.max(errors[1]) < RTOL_OPENSEES_BODY
    assert force[1] < RTOL_OPENSEES_FORCE
    # Richardson removes most of it (measured 0.02-0.21 of the error; least on z, whose error is partly
    # Newmark's second-order one).
    richardson = relative_error_per_dof(2 * runs[1].q - runs[0].q, ref.q)
    assert np.all(richardson < RTOL_OPENSEES_RICHARDSON_BODY * errors[1])


@pytest.mark.slow  # 7 s on the 2-core machine
def test_sixdof_and_opensees_are_the_same_model_to_opensees_step_error():
    """Item 7's cross-check: sixdof's direct solve of the same body, bearings and record (Bouc-Wen on u and v of
    every mount, uncoupled as OpenSees' two materials) against OpenSees. What separates them is OpenSees' first-order
    step error: it halves with the step, and Richardson's 2 x(h/2) - x(h) lands far closer to sixdof than either
    run, while sixdof sits on the scipy reference."""
    from sixdof.analysis.direct import SimulationSettings, simulate  # noqa: PLC0415 (the side under test)
    from sixdof.excitation import Excitation, GroundMotion  # noqa: PLC0415
    from sixdof.excitation.signals import Table  # noqa: PLC0415
    from sixdof.model.hysteresis import BoucWen  # noqa: PLC0415

    mounts = [Mount(f"m{j}", p, k, c) for j, (p, k, c) in
              enumerate(zip(BODY["positions"], BODY["stiffness"], BODY["damping"]))]
    laws = [BoucWen(mount=m.name, axes=[axis], yield_force=[fy], post_yield_ratio=a, exponent=n, beta=b, gamma=g)
            for m, axes in zip(mounts, HYSTERESIS) for axis, (fy, a, n, b, g) in axes.items()]
    system = System(RigidBody(BODY["mass"], BODY["inertia"]), mounts, bouc_wen=laws)
    ground = GroundMotion(quantity="acceleration", direction=list(direction_vector(DIRECTION)),
                          signal=Table(t=T_BODY, values=AG_BODY))
    dt = float(T_BODY[1] - T_BODY[0])
    history = simulate(system, Excitation(ground=ground),
                       SimulationSettings(duration=float(T_BODY[-1]) + dt, sample_rate_hz=1 / dt))
    ours = history.q_relative[:T_BODY.size]
    case = dict(**BODY, hysteresis=HYSTERESIS, t=T_BODY, ground_acc=AG_BODY, direction=DIRECTION)
    ref = rigid_body_ivp(**case)
    assert np.max(relative_error_per_dof(ours, ref.q)) < RTOL_SIXDOF_HYSTERESIS
    runs = [rigid_body_on_bearings(**case, substeps=s) for s in (8, 16)]  # dt 0.625, 0.3125 ms
    errors = [relative_error_per_dof(r.q, ours) for r in runs]
    np.testing.assert_allclose(errors[0] / errors[1], 2.0, rtol=FIRST_ORDER_RATIO)
    assert np.max(errors[1]) < RTOL_OPENSEES_BODY
    richardson = relative_error_per_dof(2 * runs[1].q - runs[0].q, ours)
    # Measured: OpenSees at 0.3125 ms 3.4e-4 (z) to 7.4e-3 (rz) from sixdof, each halving 1.96-2.03x closer;
    # Richardson 0.02-0.21 of that (least on z, where Newmark's second-order error is part of it).
    assert np.all(richardson < RTOL_OPENSEES_RICHARDSON_BODY * errors[1])


def test_time_opensees_stops_when_the_peaks_settle():
    record = dict(t=T_BODY[:201], ground_acc=AG_BODY[:201])  # 1 s
    timing = time_opensees(**BODY, hysteresis=HYSTERESIS, **record, direction=DIRECTION, rtol=1e-2, substeps=2)
    changes = [change for _, _, change in timing.tries]
    assert np.isnan(changes[0]) and all(c >= 1e-2 for c in changes[1:-1]) and changes[-1] < 1e-2
    assert len(changes) >= 3  # it had to halve
    assert timing.dt == pytest.approx(0.005 / timing.substeps) and timing.wall_s > 0
    assert [dt for dt, _, _ in timing.tries] == pytest.approx([0.0025 / 2**i for i in range(len(changes))])
    # The change it stops at is the peaks' change between its last two runs.
    previous = rigid_body_on_bearings(**BODY, hysteresis=HYSTERESIS, **record, direction=DIRECTION,
                                      substeps=timing.substeps // 2)
    length = np.max(np.abs(BODY["positions"]))
    assert peak_change(timing.history.q, previous.q, length) == timing.change


def test_accuracy_measures_leave_out_the_dofs_at_rest():
    """A DOF a symmetry leaves at round-off (1e-20) neither counts as moving nor divides by its peak."""
    t = np.linspace(0.0, 1.0, 11)
    q_ref = np.zeros((11, 6))
    q_ref[:, 1], q_ref[:, 3], q_ref[:, 0] = 0.1 * t, 2e-3 * t, 1e-20 * t  # y to 0.1 m, rx to 2e-3 rad (0.04 m at 20 m)
    q = q_ref * (1 + np.array([1.0, 0.02, 0.0, 0.05, 0.0, 0.0]))
    q[5, 1] += 0.003  # y: peak 2 % higher; at t = 0.5, 1 % + 3 % of its peak off
    assert worst_error(q, q_ref, 20.0) == pytest.approx(0.05)  # rx's, x (100 % of nothing) left out
    assert peak_change(q, q_ref, 20.0) == pytest.approx(0.05)
    q[:, 3] = q_ref[:, 3]
    assert worst_error(q, q_ref, 20.0) == pytest.approx(0.04)
    assert peak_change(q, q_ref, 20.0) == pytest.approx(0.02)
