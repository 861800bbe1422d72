"""Frequency-response functions (sixdof.analysis.frf) against closed forms, identities, python-control, an
independent ODE integration, and each other (direct solve vs modal summation)."""

import numpy as np
import pytest
import scipy.integrate

from references import (
    hysteretic_transmissibility,
    relative_transmissibility,
    sdof_receptance,
    state_matrices,
    viscous_transmissibility,
)
from sixdof import (
    InputError,
    Mount,
    Rayleigh,
    RigidBody,
    System,
    force_transmissibility,
    ground_transmissibility,
    point_frf,
    receptance,
)
from sixdof.analysis import frf
from systems import bridge, sdof, skewed_box
from tolerances import (
    ATOL_UNIT_ROUNDOFF,
    RTOL_FRF_CLOSED_FORM,
    RTOL_FRF_IDENTITY,
    RTOL_FRF_METHODS,
    RTOL_STEADY_STATE,
)

# Log-spaced across all six bridge modes (0.625 .. 38 Hz), dense enough to sample every peak.
F_BRIDGE = np.geomspace(0.05, 200.0, 4001)


CASES = {
    "rayleigh (real modes)": lambda: bridge(rayleigh=Rayleigh.from_ratio(0.02, (0.6, 38.0))),
    "modal damping (real modes)": lambda: bridge(modal_damping=(0.01, 0.02, 0.02, 0.03, 0.05, 0.05)),
    "dashpots (complex modes)": lambda: bridge("equal"),
    "hysteretic (complex modes)": lambda: bridge(loss_factor=[0.05, 0.05, 0.1]),
    "hysteretic + dashpots + rayleigh": lambda: bridge(
        "equal", rayleigh=Rayleigh(0.01, 1e-4), loss_factor=[0.0, 0.1, 0.1]),
    "undamped": lambda: bridge(),
    "skewed, coupled": skewed_box,
}


@pytest.mark.parametrize("method", ["direct", "modal"])
@pytest.mark.parametrize("case", ["dashpots (complex modes)", "hysteretic + dashpots + rayleigh",
                                  "skewed, coupled"])
def test_dynamic_stiffness_times_receptance_is_identity(case, method):
    system = CASES[case]()
    f = F_BRIDGE[::10]
    Z = frf.dynamic_stiffness(system, f)
    H = receptance(system, f, method=method).H
    # Mass-scaled, D^-1 Z D^-1 and D H D with D = diag(M)^(1/2), both are dimensionless per entry
    # ([1/s^2] and [s^2]) and their product is I entry by entry, translations and rotations alike.
    d = np.sqrt(np.diag(system.M))
    residual = (Z / np.outer(d, d)) @ (H * np.outer(d, d)) - np.eye(6)
    assert np.max(np.abs(residual)) <= RTOL_FRF_IDENTITY


@pytest.mark.parametrize("case", list(CASES))
def test_direct_and_modal_receptances_agree(case):
    system = CASES[case]()
    f = F_BRIDGE if case != "undamped" else F_BRIDGE + 1e-3  # keep off the undamped poles exactly
    check = frf.cross_check(system, f)
    assert check.max_relative_difference <= RTOL_FRF_METHODS
    expected_basis = "real modes" if ("real" in case or case == "undamped") else "complex modes"
    assert check.modal.basis == expected_basis


@pytest.mark.parametrize("case", ["rayleigh (real modes)", "modal damping (real modes)"])
def test_complex_modes_reproduce_real_modes_for_classical_damping(case):
    system = CASES[case]()
    real = receptance(system, F_BRIDGE, method="modal", basis="real")
    cplx = receptance(system, F_BRIDGE, method="modal", basis="complex")
    assert cplx.basis == "complex modes"
    assert np.max(frf.frf_difference(real, cplx)) <= RTOL_FRF_METHODS


def test_unrestrained_dofs_with_damped_rigid_modes():
    # x is unrestrained (zero stiffness) but damped: a damped rigid-body mode, whose complex modes
    # are 0 and -c/m; rz is unrestrained and undamped: a pure mass line.
    mounts = [Mount(str(i), p, [0.0, 2e5, 5e5], damping=[80.0, 30.0, 100.0])
              for i, p in enumerate([(1.0, 1.0, -0.3), (-1.0, 1.0, -0.3), (0.0, -1.0, -0.3)])]
    system = System(RigidBody(300.0, [40.0, 50.0, 60.0]), mounts)
    check = frf.cross_check(system, np.geomspace(0.01, 100.0, 2001))
    assert check.modal.basis == "complex modes"
    assert check.max_relative_difference <= RTOL_FRF_METHODS


def test_hysteretic_stiffness_is_the_mount_assembly():
    # frf assembles K_h in NumPy (speed); kinematics.mount_matrix_jax is the reference assembly (JAX).
    from sixdof.model.kinematics import mount_matrix_jax

    system = skewed_box()
    expected = np.asarray(mount_matrix_jax(system.positions, system.stiffnesses * system.loss_factors,
                                       system.axes))
    got = frf.hysteretic_stiffness(system)
    d = np.abs(np.diag(expected))
    assert np.max(np.abs(got - expected) / np.sqrt(np.outer(d, d))) <= RTOL_FRF_IDENTITY
    assert np.array_equal(frf.hysteretic_stiffness(bridge()), np.zeros((6, 6)))


def test_receptance_is_symmetric_and_readonly():
    result = receptance(CASES["skewed, coupled"](), F_BRIDGE[::50])
    scale = np.max(np.abs(result.H), axis=0)
    assert np.max(np.abs(result.H - np.swapaxes(result.H, 1, 2)) / scale) <= RTOL_FRF_IDENTITY
    with pytest.raises(ValueError):
        result.H[0, 0, 0] = 1.0


def test_static_receptance_of_a_restrained_system():
    system = bridge("equal", loss_factor=[0.05, 0.05, 0.1])
    result = receptance(system, [0.0, 1.0])
    expected = np.linalg.inv(system.K + 1j * frf.hysteretic_stiffness(system))
    d = np.abs(np.diag(expected))
    assert np.max(np.abs(result.H[0] - expected) / np.sqrt(np.outer(d, d))) <= RTOL_FRF_CLOSED_FORM
    assert np.all(result.mobility()[0] == 0) and np.all(result.accelerance()[0] == 0)


def test_units_of_entries():
    units = receptance(bridge(), [1.0]).units("accelerance")
    assert units[2, 2] == "(m/s^2)/N"
    assert units[3, 3] == "(rad/s^2)/(N m)"
    assert receptance(bridge(), [1.0]).units()[0, 4] == "m/(N m)"


F_SDOF = np.geomspace(0.1, 1000.0, 3001)


@pytest.mark.parametrize("method", ["direct", "modal"])
@pytest.mark.parametrize("c, eta", [(0.0, 0.0), (350.0, 0.0), (0.0, 0.12), (200.0, 0.07)])
def test_sdof_receptance_closed_form(method, c, eta):
    m, k = 120.0, 4.0e5
    f = F_SDOF + 1e-3 if c == eta == 0 else F_SDOF
    w = 2 * np.pi * f
    result = receptance(sdof(m, k, c, eta), f, method=method)
    expected = sdof_receptance(m, k, c, eta, w)
    assert np.max(np.abs(result.H[:, 2, 2] / expected - 1)) <= RTOL_FRF_CLOSED_FORM
    # The unrestrained DOFs are mass lines: -1/(m w^2), -1/(J w^2).
    mass_line = -1.0 / (np.array([m, m, 3.0, 4.0, 5.0])[None, :] * w[:, None] ** 2)
    free = [0, 1, 3, 4, 5]
    assert np.max(np.abs(result.H[:, free, free] / mass_line - 1)) <= RTOL_FRF_CLOSED_FORM
    # The point FRF at the CG along z, as accelerance, is -w^2 times the same.
    acc = point_frf(sdof(m, k, c, eta), f, [0, 0, 0], "z", [0, 0, 0], [0, 0, 2.0],
                        quantity="accelerance", method=method)
    assert acc.unit == "(m/s^2)/N"
    assert np.max(np.abs(acc.values / (-(w**2) * expected) - 1)) <= RTOL_FRF_CLOSED_FORM


@pytest.mark.parametrize("method", ["direct", "modal"])
@pytest.mark.parametrize("zeta, eta", [(0.0, 0.0), (0.05, 0.0), (0.3, 0.0), (0.0, 0.02), (0.0, 0.25)])
def test_sdof_transmissibility(method, zeta, eta):
    m, k = 120.0, 4.0e5
    wn = np.sqrt(k / m)
    f = F_SDOF + 1e-3 if zeta == eta == 0 else F_SDOF
    r = 2 * np.pi * f / wn
    expected = hysteretic_transmissibility(r, eta) if eta else viscous_transmissibility(r, zeta)
    system = sdof(m, k, c=2 * zeta * m * wn, eta=eta)
    force = force_transmissibility(system, f, [0, 0, 0], "z", method=method)
    assert np.max(np.abs(force.transmissibility / expected - 1)) <= RTOL_FRF_CLOSED_FORM
    ground = ground_transmissibility(system, f, [0, 0, 1] if eta else "z", [0, 0, 0], method=method)
    assert np.max(np.abs(ground.transmissibility / expected - 1)) <= RTOL_FRF_CLOSED_FORM
    if not eta:  # relative motion per ground motion: r^2 / sqrt((1 - r^2)^2 + (2 zeta r)^2)
        relative = relative_transmissibility(r, zeta)
        assert np.max(np.abs(np.abs(ground.relative[:, 2]) / relative - 1)) <= RTOL_FRF_CLOSED_FORM


def test_point_frf_reciprocity_and_quantities():
    system = CASES["hysteretic + dashpots + rayleigh"]()
    a, b = [0.3, 19.0, 1.0], [-0.6, -10.0, -1.0]
    ab = point_frf(system, F_BRIDGE, a, [0, 1, 1], b, "x")
    ba = point_frf(system, F_BRIDGE, b, "x", a, [0, 1, 1])
    assert np.max(np.abs(ab.values - ba.values)) <= RTOL_FRF_IDENTITY * np.max(np.abs(ab.values))
    w = 2 * np.pi * F_BRIDGE
    mob = point_frf(system, F_BRIDGE, a, [0, 1, 1], b, "x", quantity="mobility", method="modal")
    assert mob.unit == "(m/s)/N"
    assert np.max(np.abs(mob.values - 1j * w * ab.values)) <= RTOL_FRF_METHODS * np.max(
        np.abs(mob.values))
    # A moment in, a rotation out: the generalized receptance entry itself.
    rot = point_frf(system, F_BRIDGE, a, "rx", b, "rz")
    assert rot.unit == "rad/(N m)" and rot.load_kind == "moment" and rot.response_kind == "rotation"
    H = receptance(system, F_BRIDGE).H
    assert np.array_equal(rot.values, H[:, 5, 3])


@pytest.mark.parametrize("case", ["dashpots (complex modes)", "hysteretic (complex modes)",
                                  "skewed, coupled", "rayleigh (real modes)", "modal damping (real modes)",
                                  "hysteretic + dashpots + rayleigh"])
def test_foundation_load_balances_applied_load_and_inertia(case):
    # Mount by mount, the forces on the foundation (plus the global damping's, which acts on the
    # motion relative to the ground like the dashpots) sum to the applied load minus the body's
    # inertia force, Q + w^2 M q: an independent path through the mount-level assembly.
    system = CASES[case]()
    point, direction = np.array([0.2, 5.0, 1.0]), np.array([0.3, -0.2, 1.0])
    result = force_transmissibility(system, F_BRIDGE, point, direction)
    d = direction / np.linalg.norm(direction)
    Q = np.concatenate([d, np.cross(point, d)])
    q = receptance(system, F_BRIDGE).H @ Q
    w = 2 * np.pi * F_BRIDGE
    expected = Q[None, :] + (w**2)[:, None] * (q @ system.M.T)
    scale = np.max(np.abs(expected), axis=0)
    assert np.max(np.abs(result.total - expected) / scale) <= RTOL_FRF_IDENTITY
    assert result.mount_forces.shape == (F_BRIDGE.size, len(system.mounts), 3)
    # Static load: everything applied goes to the foundation, force and moment.
    static = force_transmissibility(system, [0.0], point, direction)
    assert np.max(np.abs(static.total[0] - Q) / np.abs(Q).max()) <= RTOL_FRF_CLOSED_FORM
    assert static.transmissibility[0] == pytest.approx(1.0, rel=RTOL_FRF_CLOSED_FORM)


def test_ground_transmissibility_absolute_and_relative():
    system = CASES["hysteretic + dashpots + rayleigh"]()
    point = [0.5, 19.0, 1.0]
    result = ground_transmissibility(system, F_BRIDGE, "y", point, method="modal")
    # Relative coordinates: Z q_rel = w^2 M q_g (the ground's inertial load).
    qg = np.array([0, 1.0, 0, 0, 0, 0])
    w = 2 * np.pi * F_BRIDGE
    q_rel = receptance(system, F_BRIDGE).H @ (system.M @ qg) * (w**2)[:, None]
    # y ground motion drives the symmetric bridge's (y, z, rx) subsystem, each DOF measured on its
    # own scale; (x, ry, rz) stay at round-off beside the translations and rotations that move.
    coupled, decoupled = [1, 2, 3], [0, 4, 5]
    scale = np.max(np.abs(result.q), axis=0)
    error = np.abs(result.q - qg - q_rel)
    assert np.max(error[:, coupled] / scale[coupled]) <= RTOL_FRF_METHODS
    assert np.max(np.abs(result.q[:, decoupled]) / scale[[1, 3, 3]]) <= RTOL_FRF_METHODS
    assert np.allclose(result.relative, result.absolute - [0, 1.0, 0], rtol=0, atol=ATOL_UNIT_ROUNDOFF)
    # Static ground motion carries the body along rigidly; fast ground motion leaves it behind.
    ends = ground_transmissibility(system, [0.0, 1e3], "y", point)
    assert np.allclose(ends.absolute[0], [0, 1.0, 0], rtol=0, atol=RTOL_FRF_CLOSED_FORM)
    assert ends.transmissibility[1] < 1e-3


@pytest.mark.parametrize("case", ["dashpots (complex modes)", "skewed, coupled"])
def test_receptance_matches_python_control_state_space(case):
    control = pytest.importorskip("control")
    base = CASES[case]()  # rebuilt without loss factors: a state space has no hysteresis
    system = System(base.body, [Mount(m.name, m.position, m.stiffness, damping=m.damping, axes=m.axes)
                                for m in base.mounts])
    A, B = state_matrices(system.M, system.C, system.K)
    Cout = np.hstack([np.eye(6), np.zeros((6, 6))])
    sys = control.ss(A, B, Cout, np.zeros((6, 6)))
    f = F_BRIDGE[::20]
    peer = control.frequency_response(sys, 2 * np.pi * f, squeeze=False).complex  # (6, 6, nf)
    ours = receptance(system, f, method="modal")
    peer_frf = frf.FRF(f_hz=ours.f_hz, H=np.moveaxis(peer, -1, 0), method="control", basis="")
    assert np.max(frf.frf_difference(ours, peer_frf)) <= RTOL_FRF_CLOSED_FORM


def test_harmonic_steady_state_matches_frf():
    # Started exactly on the steady state the FRF predicts, an independent integration of
    # M q'' + C q' + K q = Re(Q e^{iwt}) must stay on it: any error in H leaves a free transient.
    system = bridge("equal", rayleigh=Rayleigh.from_ratio(0.02, (0.6, 38.0)))
    f0 = 0.9  # between the low modes: every DOF responds
    w = 2 * np.pi * f0
    point, force = np.array([0.3, 12.0, 1.0]), np.array([2e3, 5e3, -1e4])
    Q = np.concatenate([force, np.cross(point, force)])
    q_hat = receptance(system, [f0]).H[0] @ Q
    M, C, K = system.M, system.C, system.K
    Minv = np.linalg.inv(M)

    def rhs(t, x):
        q, v = x[:6], x[6:]
        return np.concatenate([v, Minv @ (Q * np.cos(w * t) - C @ v - K @ q)])

    t = np.linspace(0.0, 4.0 / f0, 201)
    x0 = np.concatenate([q_hat.real, (1j * w * q_hat).real])
    amp = np.abs(q_hat)
    sol = scipy.integrate.solve_ivp(rhs, (0.0, t[-1]), x0, method="DOP853", t_eval=t,
                                    rtol=1e-11, atol=np.concatenate([amp, w * amp]) * 1e-12)
    assert sol.success
    expected = (q_hat[:, None] * np.exp(1j * w * t)[None, :]).real
    assert np.max(np.abs(sol.y[:6] - expected) / amp[:, None]) <= RTOL_STEADY_STATE


@pytest.mark.parametrize("f_hz", [[-1.0, 2.0], [1.0, np.nan], [[1.0, 2.0]], [], "abc"])
def test_bad_frequencies(f_hz):
    with pytest.raises(InputError, match=r"^f_hz: expected finite frequencies >= 0 in Hz"):
        receptance(bridge(), f_hz)


def point_frf_with(**changed):
    args = dict(load_point=[0, 0, 0], load_direction="z", response_point=[0, 1, 0], response_direction="z")
    return point_frf(bridge(), [1.0], **(args | changed))


@pytest.mark.parametrize("call, message", [
    (lambda: receptance(sdof(), [0.0, 1.0], method="modal"),
     r"^f_hz: expected frequencies > 0 Hz: the mounts leave x, y, rx, ry, rz unrestrained"),
    (lambda: receptance(bridge("equal"), [1.0], method="exact"), r"^method: expected 'direct' or 'modal', got 'exact'"),
    (lambda: receptance(bridge("equal"), [1.0], method="modal", basis="x"),
     r"^basis: expected 'auto', 'real' or 'complex', got 'x'"),
    (lambda: receptance(bridge("equal"), [1.0], method="modal", basis="real"),
     r"^basis: expected 'auto' or 'complex' \(damping"),
    (lambda: point_frf_with(quantity="velocity"),
     r"^quantity: expected 'receptance', 'mobility' or 'accelerance', got 'velocity'"),
    (lambda: point_frf_with(load_direction="w"), r"^load_direction: expected "),
    (lambda: point_frf_with(load_direction=[0, 0, 0]), r"^load_direction: expected "),
    (lambda: point_frf_with(response_direction=[1, 2]), r"^response_direction: expected "),
    (lambda: point_frf_with(load_point=[0, np.inf, 0]), r"^load_point: expected "),
    (lambda: point_frf_with(response_point="top"), r"^response_point: expected "),
    (lambda: ground_transmissibility(bridge(), [1.0], "rx", [0, 0, 0]),
     r"^ground_direction: expected one of 'x', 'y', 'z' or a nonzero 3-vector in body axes, got 'rx'"),
])
def test_bad_input_names_its_field(call, message):
    with pytest.raises(InputError, match=message):
        call()
