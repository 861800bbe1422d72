"""Direct integration of eq. (1) against answers computed apart from the solver.

Every comparison is per DOF, relative to that DOF's own peak (issue 3, point 6): the bridge beam's
translations (~1e-4 m) and rotations (~1e-6 rad) are each held to the same relative accuracy.
The damping is non-proportional (mount dashpots with different ratios per mount and axis).
"""

import jax
import numpy as np
import pytest
import scipy.integrate
import scipy.linalg

from references import (
    FREE,
    exact_response,
    harmonic_from_rest,
    oscillator,
    ramp_response,
    relative_error_per_dof,
    state_matrices,
    steady_state_amplitude,
    table_pieces,
)
from sixdof import (
    Excitation,
    GroundMotion,
    HalfSine,
    Harmonic,
    InitialState,
    InputError,
    Load,
    ModeRelease,
    Ramp,
    SimulationSettings,
    SolverError,
    Step,
    Table,
    modal_analysis,
    simulate,
)
from sixdof.analysis.direct import SOLVERS, simulate_windows, state_scale, window_length
from sixdof.results import time_concat
from systems import bridge, skewed_machine
from tolerances import (
    ATOL_UNIT_ROUNDOFF,
    RTOL_DIRECT_EXACT,
    RTOL_ENERGY_BALANCE,
    RTOL_MODE_RELEASE_AMPLITUDE,
    RTOL_RELATIVE_MOTION,
    RTOL_SIGNAL,
)

# An off-centre load with all three force components: every DOF of the bridge responds.
POINT = np.array([0.3, 10.0, 1.0])
FORCE = np.array([5e3, 2e4, -1e5])
Q0 = np.concatenate([FORCE, np.cross(POINT, FORCE)])


@pytest.fixture(scope="module")
def beam():
    return bridge("elastomer")


def load(signal, initial=None):
    return Excitation(loads=(Load("load", POINT, force=FORCE, signal=signal),), initial=initial)


def assert_each_dof(*pairs, rtol=RTOL_DIRECT_EXACT):
    """Each ``(actual, expected)`` pair agrees per DOF, relative to the DOF's own peak."""
    for actual, expected in pairs:
        error = relative_error_per_dof(actual, expected)
        assert np.all(error < rtol), error


def test_test_system_damping_is_non_proportional(beam):
    modes = modal_analysis(beam.M, beam.K)
    modal_c = modes.shapes.T @ beam.C @ modes.shapes
    off = np.abs(modal_c - np.diag(np.diag(modal_c)))
    # Coupling terms are a sizeable fraction of the diagonal ones: classical modes do not decouple.
    assert off.max() > 0.1 * np.sqrt(np.outer(np.diag(modal_c), np.diag(modal_c)))[off.argmax()
                                                                                  // 6, off.argmax() % 6]


# Runs of one structure (signal kinds, number of samples) share one compiled solver: the tests
# below pick their durations so that n = 1501 samples wherever they can.
THREE_SECONDS = SimulationSettings(duration=3.0, sample_rate_hz=500.0)


@pytest.fixture(scope="module")
def harmonic_run(beam):
    excitation = load(Harmonic(f_hz=5.0, phase_deg=30.0))
    return excitation, simulate(beam, excitation, THREE_SECONDS)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_harmonic_load_matches_matrix_exponential(beam, harmonic_run):
    f, phase = 5.0, 30.0
    run = harmonic_run[1]
    pieces = [(0.0, 3.0, oscillator(2 * np.pi * f, np.deg2rad(phase), 0.0))]
    q, qd = exact_response(beam.M, beam.C, beam.K, Q0, pieces, run.t)
    assert_each_dof((run.q, q), (run.qd, qd))
    # qdd from the equation of motion at the exact state
    qdd = np.linalg.solve(beam.M, (np.outer(np.sin(2 * np.pi * f * run.t + np.deg2rad(phase)), Q0)
                                   - qd @ beam.C.T - q @ beam.K.T).T).T
    assert_each_dof((run.qdd, qdd))
    assert run.stats.num_rejected < run.stats.num_accepted
    assert run.stats.num_steps == run.stats.num_accepted + run.stats.num_rejected


def test_full_inertia_and_inclined_mounts_match_matrix_exponential():
    machine = skewed_machine()
    point, force, moment = np.array([0.1, -0.2, 0.3]), np.array([200.0, -150.0, 400.0]), np.array([10.0, 0.0, -20.0])
    vector = np.concatenate([force, np.cross(point, force) + moment])
    f = 12.0
    excitation = Excitation(loads=(Load("l", point, force=force, moment=moment,
                                        signal=Harmonic(f_hz=f)),))
    run = simulate(machine, excitation, SimulationSettings(duration=0.75, sample_rate_hz=2000.0))
    pieces = [(0.0, 0.75, oscillator(2 * np.pi * f, 0.0, 0.0))]
    q, qd = exact_response(machine.M, machine.C, machine.K, vector, pieces, run.t)
    assert_each_dof((run.q, q), (run.qd, qd))


PULSE = (4.0, 0.05, 5.0)  # start, length, end of run [s]


@pytest.fixture(scope="module")
def pulse_run(beam):
    start, length, end = PULSE
    return simulate(beam, load(HalfSine(start=start, duration=length)),
                    SimulationSettings(duration=end, sample_rate_hz=5000.0))


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_short_pulse_after_rest_is_seen_and_right(beam, pulse_run):
    # From rest the adaptive step grows without bound; a 50 ms pulse at t = 4 s would be stepped
    # over without the breakpoints.
    start, length, end = PULSE
    run = pulse_run
    assert run.stats.num_jumps == 2
    pieces = [(0.0, start, FREE), (start, start + length, oscillator(np.pi / length, 0.0, start)),
              (start + length, end, FREE)]
    q, qd = exact_response(beam.M, beam.C, beam.K, Q0, pieces, run.t)
    assert np.all(np.abs(run.q[run.t > start + length]).max(axis=0) > 0)
    assert_each_dof((run.q, q), (run.qd, qd))


@pytest.mark.slow  # 2 s on the 2-core machine
def test_tabulated_load_matches_first_order_hold(beam):
    rng = np.random.default_rng(7)
    knots = np.concatenate([[0.2], np.sort(rng.uniform(0.25, 2.2, 25)), [2.3]])
    values = np.concatenate([[0.0], rng.uniform(-1.0, 1.0, 25), [0.0]])
    run = simulate(beam, load(Table(t=knots, values=values)), THREE_SECONDS)
    assert run.stats.num_jumps == knots.size
    q, qd = exact_response(beam.M, beam.C, beam.K, Q0, table_pieces(knots, values, 3.0), run.t)
    assert_each_dof((run.q, q), (run.qd, qd))


def test_harmonic_steady_state_amplitude_is_receptance_times_force(beam):
    # Started on the steady state (from H), the run must stay on it: amplitude |H(w) Q0| per DOF.
    f = 4.0
    w = 2 * np.pi * f
    X = steady_state_amplitude(beam.M, beam.C, beam.K, Q0, w)  # q(t) = Im(X e^{iwt}) for Q0 sin(wt)
    initial = InitialState(q=X.imag, qd=(1j * w * X).imag)
    run = simulate(beam, load(Harmonic(f_hz=f), initial), SimulationSettings(duration=1.5, sample_rate_hz=1000.0))
    expected = np.imag(np.exp(1j * w * run.t)[:, None] * X[None, :])
    assert_each_dof((run.q, expected))
    last_period = run.t >= 1.5 - 1.0 / f
    amplitude = np.abs(run.q[last_period]).max(axis=0)
    # Sampled peaks (1 ms) sit within (w dt)^2 / 2 of the amplitude.
    assert np.allclose(amplitude, np.abs(X), rtol=(w * 1e-3) ** 2 / 2 + RTOL_DIRECT_EXACT, atol=0)


def test_slow_ramp_follows_static_deflection(beam):
    # On a ramp Q0 t / T the exact solution is q = K^-1 Q(t) - K^-1 C K^-1 Q0 / T (started there).
    T = 4.0
    static, lag = ramp_response(beam.C, beam.K, Q0, T)
    excitation = load(Ramp(duration=T), InitialState(q=-lag, qd=static / T))
    run = simulate(beam, excitation, SimulationSettings(duration=T, sample_rate_hz=200.0))
    expected = np.outer(run.t / T, static) - lag
    assert_each_dof((run.q, expected))
    # and it is slow: the damping lag is a small part of the static deflection
    assert np.all(np.abs(lag) < 0.05 * np.abs(static))


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_energy_balance_after_a_shock(beam, pulse_run):
    start, length, end = PULSE
    run = pulse_run
    rate = 5000.0
    t, q, qd = run.t, run.q, run.qd

    def integral(values, a, b):
        # Simpson on each smooth piece; the pulse edges are sample times.
        inside = (t >= a - 0.5 / rate) & (t <= b + 0.5 / rate)
        return scipy.integrate.simpson(values[inside], x=t[inside])

    power_in = np.einsum("ni,ni->n", run.Q, qd)
    dissipation = np.einsum("ni,ij,nj->n", qd, beam.C, qd)
    work = integral(power_in, start, start + length)
    dissipated = sum(integral(dissipation, a, b) for a, b in
                     [(0.0, start), (start, start + length), (start + length, end)])
    stored = 0.5 * qd[-1] @ beam.M @ qd[-1] + 0.5 * q[-1] @ beam.K @ q[-1]
    assert work > 0 and dissipated > 0.1 * work and stored > 0.01 * work
    assert abs(work - dissipated - stored) < RTOL_ENERGY_BALANCE * work


@pytest.mark.slow  # 2 s on the 2-core machine
def test_step_from_static_deflection_stays_put(beam):
    static = np.linalg.solve(beam.K, Q0)
    run = simulate(beam, load(Step(start=0.0), InitialState(q=static)),
                   SimulationSettings(duration=1.0, sample_rate_hz=100.0))
    assert_each_dof((run.q, np.broadcast_to(static, run.q.shape)))
    assert np.all(np.abs(run.qd).max(axis=0) < RTOL_DIRECT_EXACT * np.abs(static) * 240.0)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_mode_release_vibrates_in_that_mode(beam):
    modes = modal_analysis(beam.M, beam.K)
    release = ModeRelease(mode=5, amplitude=1e-4)
    run = simulate(beam, Excitation(initial=release),
                   SimulationSettings(duration=0.75, sample_rate_hz=2000.0))
    assert run.q[0, 2] == pytest.approx(1e-4, rel=RTOL_MODE_RELEASE_AMPLITUDE)  # mode 5 is dominated by z
    A, _ = state_matrices(beam.M, beam.C, beam.K)
    x0 = np.concatenate([run.q[0], np.zeros(6)])
    exact = np.array([scipy.linalg.expm(A * ti) @ x0 for ti in run.t[::50]])
    assert_each_dof((run.q[::50], exact[:, :6]))
    assert modes.dominant_dof[4] == "z"


# --- ground motion ---------------------------------------------------------------------------------


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_harmonic_ground_acceleration_matches_matrix_exponential(beam):
    a0, f = 0.5, 1.5  # m/s^2, Hz, along the beam
    w = 2 * np.pi * f
    ground = GroundMotion("acceleration", [0.0, 1.0, 0.0], Harmonic(f_hz=f), scale=a0)
    run = simulate(beam, Excitation(ground=ground), THREE_SECONDS)
    r = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    # relative motion: M z'' + C z' + K z = -M r a_g(t)
    pieces = [(0.0, 3.0, oscillator(w, 0.0, 0.0))]
    z, zd = exact_response(beam.M, beam.C, beam.K, -beam.M @ r * a0, pieces, run.t)
    assert_each_dof((run.q_relative, z), (run.qd_relative, zd))
    v, u = harmonic_from_rest(a0, w, run.t)  # ground starts at rest
    assert np.allclose(run.ground_displacement[:, 1], u, rtol=0, atol=RTOL_DIRECT_EXACT * u.max())
    assert np.allclose(run.ground_velocity[:, 1], v, rtol=0, atol=RTOL_DIRECT_EXACT * v.max())
    assert np.allclose(run.ground_acceleration[:, 1], a0 * np.sin(w * run.t), rtol=0, atol=RTOL_SIGNAL)
    assert_each_dof((run.q, z + np.outer(u, r)[:, :6] * 1.0))
    absolute_qdd = run.qdd_relative + np.outer(a0 * np.sin(w * run.t), r)
    assert np.allclose(run.qdd, absolute_qdd, rtol=0, atol=RTOL_RELATIVE_MOTION * np.abs(run.qdd).max())


@pytest.mark.slow  # 2 s on the 2-core machine
def test_ground_velocity_is_the_same_motion_as_its_acceleration(beam):
    v0, f = 0.05, 2.0
    w = 2 * np.pi * f
    ground = GroundMotion("velocity", [0.0, 1.0, 0.0], Harmonic(f_hz=f), scale=v0)
    run = simulate(beam, Excitation(ground=ground), THREE_SECONDS)
    r = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    # a_g = v0 w cos(w t), and the velocity jumps from 0 to 0 at t = 0: no impulse
    pieces = [(0.0, 3.0, oscillator(w, np.pi / 2, 0.0))]
    z, _ = exact_response(beam.M, beam.C, beam.K, -beam.M @ r * v0 * w, pieces, run.t)
    assert_each_dof((run.q_relative, z))
    u, _ = harmonic_from_rest(v0, w, run.t)
    assert np.allclose(run.ground_displacement[:, 1], u, rtol=0, atol=RTOL_DIRECT_EXACT * u.max())


@pytest.mark.slow  # 3 s on the 2-core machine
def test_tabulated_ground_displacement_matches_first_order_hold(beam):
    # Absolute form: M q'' + C q' + K q = K r u_g + C r u_g', with u_g piecewise linear.
    rng = np.random.default_rng(3)
    knots = np.linspace(0.1, 2.1, 21)
    values = np.concatenate([[0.0], rng.uniform(-1.0, 1.0, 19), [0.0]])
    scale = 2e-3
    direction = np.array([0.0, 0.6, 0.8])
    ground = GroundMotion("displacement", direction, Table(t=knots, values=values), scale=scale)
    run = simulate(beam, Excitation(ground=ground), THREE_SECONDS)
    r = np.concatenate([direction, np.zeros(3)])
    forcing = np.stack([beam.K @ r, beam.C @ r], axis=1) * scale  # (6, 2) times [s, s']
    q, qd = exact_response(beam.M, beam.C, beam.K, forcing,
                           table_pieces(knots, values, 3.0, c=np.eye(2)), run.t)
    assert_each_dof((run.q, q), (run.qd, qd))
    u = scale * np.interp(run.t, knots, values, left=0.0, right=0.0)
    assert np.allclose(run.ground_displacement, np.outer(u, direction), rtol=0, atol=ATOL_UNIT_ROUNDOFF)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_stiff_mounts_carry_the_body_with_the_ground():
    stiff = bridge("elastomer", stiffness_factor=100.0)  # 6 to 380 Hz
    amplitude, length = 0.01, 3.0
    ground = GroundMotion("displacement", [0.0, 1.0, 0.0], {"kind": "haversine", "start": 0.0,
                                                            "duration": length}, scale=amplitude)
    run = simulate(stiff, Excitation(ground=ground),
                   SimulationSettings(duration=length, sample_rate_hz=750.0))
    f_low = modal_analysis(stiff.M, stiff.K).frequency_hz[0]
    # Quasi-static: the body lags the ground by about (f_ground / f_low)^2 of its motion.
    lag_bound = 2 * (1.0 / length / f_low) ** 2
    assert lag_bound < 0.01  # so "follows" means something
    ground_y = run.ground_displacement[:, 1]
    assert np.abs(run.q[:, 1] - ground_y).max() < lag_bound * amplitude
    assert np.abs(run.q[:, 1]).max() == pytest.approx(amplitude, rel=lag_bound)
    # the other DOFs stay small next to the carried motion (m, rad times the beam's half-length)
    lever = np.array([1.0, 1.0, 1.0, 20.0, 20.0, 20.0])
    others = [0, 2, 3, 4, 5]
    assert np.all(np.abs(run.q[:, others] * lever[others]).max(axis=0) < lag_bound * amplitude)


# --- solver behaviour ------------------------------------------------------------------------------


def test_new_parameters_reuse_the_compiled_solver(beam):
    simulate(beam, load(Harmonic(f_hz=2.0)), THREE_SECONDS)
    compiled = []  # functions XLA compiles, from JAX's public monitoring events
    watching = [True]
    jax.monitoring.register_event_duration_secs_listener(
        lambda event, seconds, fun_name="", **_: compiled.append(fun_name)
        if watching[0] and event == "/jax/core/compile/backend_compile_duration" else None)
    simulate(bridge("elastomer", stiffness_factor=1.3), load(Harmonic(f_hz=7.0, phase_deg=10.0)),
             SimulationSettings(duration=1.5, sample_rate_hz=1000.0, start=0.5))
    watching[0] = False
    assert not [name for name in compiled if "_solve" in name], compiled


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_step_limit_raises_a_solver_error(beam):
    settings = SimulationSettings(duration=2.0, sample_rate_hz=100.0, max_steps=20)
    with pytest.raises(SolverError, match=r"failed in \[0, 2\] s: .*maximum number of solver steps"):
        simulate(beam, load(Harmonic(f_hz=5.0)), settings)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_step_limit_applies_per_window(beam):
    # A run that needs more steps than max_steps in all runs through in windows that each need fewer.
    settings = SimulationSettings(duration=2.0, sample_rate_hz=100.0, max_steps=400)
    with pytest.raises(SolverError, match="maximum number of solver steps"):
        simulate(beam, load(Harmonic(f_hz=5.0)), settings)
    run = simulate(beam, load(Harmonic(f_hz=5.0)), settings, window_samples=20)
    assert run.stats.num_windows == 11 and run.stats.num_steps > settings.max_steps


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_no_excitation_stays_at_rest(beam):
    run = simulate(beam, None, SimulationSettings(duration=1.5, sample_rate_hz=1000.0))
    assert run.q.shape == (1501, 6) and np.all(run.q == 0) and np.all(run.qdd == 0)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_state_scale_balances_translations_and_rotations(beam, harmonic_run):
    excitation, run = harmonic_run
    ratio = np.abs(run.q).max(axis=0) / state_scale(beam, excitation, THREE_SECONDS)[:6]
    # peaks sit within a decade or so of their scale, although they span 4 decades in size
    assert np.ptp(np.log10(np.abs(run.q).max(axis=0))) > 3
    assert np.all((ratio > 0.05) & (ratio < 20)), ratio


@pytest.mark.parametrize("kwargs, match", [
    ({"duration": 0.0, "sample_rate_hz": 10.0}, "duration: expected a positive"),
    ({"duration": 1.0, "sample_rate_hz": -1.0}, "sample_rate_hz: expected a positive"),
    ({"duration": 1.0, "sample_rate_hz": 10.0, "solver": "Euler"}, "solver: expected one of Tsit5"),
    ({"duration": 1.0, "sample_rate_hz": 10.0, "rtol": 0.0}, r"rtol: expected a tolerance in \(0, 1\)"),
    ({"duration": 1.0, "sample_rate_hz": 10.0, "atol": "1e-9"}, "atol: expected a tolerance"),
    ({"duration": 1.0, "sample_rate_hz": 10.0, "max_steps": 1.5}, "max_steps: expected a positive integer"),
    ({"duration": 1.0, "sample_rate_hz": 10.0, "start": float("nan")}, "start: expected a finite time"),
])
def test_bad_settings_are_named(kwargs, match):
    with pytest.raises(InputError, match=match):
        SimulationSettings(**kwargs)


def test_solvers_are_named():
    assert "Tsit5" in SOLVERS and SimulationSettings(duration=1.0, sample_rate_hz=1.0).solver == "Tsit5"
    assert SimulationSettings(duration=1.0, sample_rate_hz=4.0).times.tolist() == [0, 0.25, 0.5, 0.75, 1.0]


@pytest.mark.parametrize("rate", [44.1, 100.0, 333.0, 1000.0])
def test_sample_times_never_pass_the_end(rate):
    # duration = (N - 1) / rate used to put the last sample a rounding past start + duration, where
    # the solver refuses to save.
    for n in range(2, 3000, 7):
        settings = SimulationSettings(duration=(n - 1) / rate, sample_rate_hz=rate, start=0.3)
        times = settings.times
        assert times.size == n
        assert times[-1] <= settings.start + settings.duration


# --- windows ---------------------------------------------------------------------------------------


@pytest.mark.slow  # 3 s on the 2-core machine
def test_windows_carry_the_state_across_a_breakpoint(beam, pulse_run):
    # Windows of 2000 samples: one ends exactly at the pulse's start (sample 20000), the next holds the
    # pulse's end. The solver restarts from the state it reached, and the run stays exact.
    start, length, end = PULSE
    settings = SimulationSettings(duration=end, sample_rate_hz=5000.0)
    assert window_length(settings.samples, 2000) == 2000
    windows = list(simulate_windows(beam, load(HalfSine(start=start, duration=length)), settings,
                                    window_samples=2000))
    assert [w.t.size for w in windows] == [2000] * 12 + [1001]
    assert windows[10].t[0] == start and sum(w.stats.num_jumps for w in windows) == 2
    run = time_concat(windows)
    np.testing.assert_array_equal(run.t, settings.times)
    pieces = [(0.0, start, FREE), (start, start + length, oscillator(np.pi / length, 0.0, start)),
              (start + length, end, FREE)]
    q, qd = exact_response(beam.M, beam.C, beam.K, Q0, pieces, run.t)
    assert_each_dof((run.q, q), (run.qd, qd), (run.q, pulse_run.q))


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_windows_carry_the_ground_integration(beam):
    # A ground acceleration is integrated twice inside the solve: its velocity and displacement states
    # cross every window boundary.
    a0, f = 0.5, 1.5
    w = 2 * np.pi * f
    ground = GroundMotion("acceleration", [0.0, 1.0, 0.0], Harmonic(f_hz=f), scale=a0)
    run = simulate(beam, Excitation(ground=ground), THREE_SECONDS, window_samples=256)
    assert run.stats.num_windows == 6
    r = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    z, zd = exact_response(beam.M, beam.C, beam.K, -beam.M @ r * a0, [(0.0, 3.0, oscillator(w, 0.0, 0.0))], run.t)
    assert_each_dof((run.q_relative, z), (run.qd_relative, zd))
    v, u = harmonic_from_rest(a0, w, run.t)
    assert np.allclose(run.ground_displacement[:, 1], u, rtol=0, atol=RTOL_DIRECT_EXACT * u.max())
    assert np.allclose(run.ground_velocity[:, 1], v, rtol=0, atol=RTOL_DIRECT_EXACT * v.max())


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_simulate_is_the_join_of_its_windows(beam):
    excitation = load(Harmonic(f_hz=5.0, phase_deg=30.0))
    windows = list(simulate_windows(beam, excitation, THREE_SECONDS, window_samples=512))
    run = simulate(beam, excitation, THREE_SECONDS, window_samples=512)
    assert [w.t.size for w in windows] == [512, 512, 477]
    for name in ("t", "q", "qd", "qdd", "Q"):
        np.testing.assert_array_equal(getattr(run, name), np.concatenate([getattr(w, name) for w in windows]))
    assert run.stats.num_steps == sum(w.stats.num_steps for w in windows) and run.stats.num_windows == 3


@pytest.mark.parametrize("samples, most, expected", [(1501, 32768, 1536), (20001, 32768, 20480),
                                                     (2_000_001, 32768, 32768), (101, 32768, 512),
                                                     (20001, 16384, 10240), (25001, 2000, 2000), (201, 20, 20)])
def test_window_length(samples, most, expected):
    assert window_length(samples, most) == expected


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_progress_is_shown_between_windows(beam, capsys):
    simulate(beam, load(Harmonic(f_hz=5.0)), SimulationSettings(duration=1.0, sample_rate_hz=100.0),
             progress="text", window_samples=40)
    shown = capsys.readouterr().err
    assert "direct solve: 0.39 / 1 s (39%)" in shown and shown.endswith("direct solve: 1 / 1 s (100%)\n")
    with pytest.raises(InputError, match="progress: expected None, True, 'text' or 'tqdm'"):
        simulate(beam, None, THREE_SECONDS, progress="bar")


# --- the solver's stages ---------------------------------------------------------------------------


@pytest.mark.slow  # 2 s each on the 2-core machine
@pytest.mark.parametrize("name", ["Tsit5", "Dopri8", "Heun"])  # first same as last, or not; 7 and 14 stages
def test_unrolled_stages_are_diffrax_s_method(name):
    # The same tableau, error estimate, first-same-as-last reuse across a jump and dense output as
    # diffrax's own solver: the same steps, and the same values to round-off.
    import diffrax

    from sixdof.analysis.unrolled import UnrolledERK

    A = jax.numpy.array([[0.0, 1.0], [-40.0, -0.3]])

    def field(t, y, args):
        return A @ y + jax.numpy.array([0.0, jax.numpy.where(t >= 0.31, 1.0, 0.0) + jax.numpy.sin(3 * t)])

    ts = jax.numpy.linspace(0.0, 2.0, 41)
    results = []
    for solver in (getattr(diffrax, name)(), UnrolledERK(getattr(diffrax, name)())):
        control = diffrax.ClipStepSizeController(diffrax.PIDController(rtol=1e-8, atol=1e-8),
                                                 jump_ts=jax.numpy.array([0.31]))
        sol = diffrax.diffeqsolve(diffrax.ODETerm(field), solver, 0.0, 2.0, None, jax.numpy.array([1.0, 0.0]),
                                  saveat=diffrax.SaveAt(ts=ts), stepsize_controller=control, max_steps=100_000)
        results.append((np.asarray(sol.ys), int(sol.stats["num_steps"])))
    (expected, expected_steps), (ys, steps) = results
    assert steps == expected_steps
    assert np.abs(ys - expected).max() < 1e-12 * np.abs(expected).max()


@pytest.mark.slow  # 2 s on the 2-core machine
def test_without_breakpoints_no_clipping_takes_the_same_steps():
    # A run without breakpoints traces no step clipping (jump_ts of length 0): it must step exactly as the
    # clipped solve does when its breakpoints lie beyond the end.
    import diffrax

    from sixdof.analysis.direct import jump_times, solve_ode

    harmonic = load(Harmonic(f_hz=3.0))
    none, count = jump_times(harmonic, 0.0, 2.0)
    assert none.shape == (0,) and count == 0
    padded, count = jump_times(load(HalfSine(start=0.5, duration=0.1)), 0.0, 2.0)
    assert padded.shape == (8,) and count == 2 and np.all(padded[2:] > 2.0)

    A = jax.numpy.array([[0.0, 1.0], [-40.0, -0.3]])

    def field(t, y, args):
        return A @ y + jax.numpy.array([0.0, jax.numpy.sin(3 * t)])

    ts = jax.numpy.linspace(0.0, 2.0, 41)
    runs = [solve_ode(field, jax.numpy.array([1.0, 0.0]), 0.0, 2.0, diffrax.SaveAt(ts=ts), jumps, 1e-8, 1e-8,
                      solver="Tsit5", max_steps=100_000) for jumps in (none, padded[2:])]
    unclipped, clipped = [(np.asarray(sol.ys), int(sol.stats["num_steps"])) for sol in runs]
    assert unclipped[1] == clipped[1] > 20
    assert np.abs(unclipped[0] - clipped[0]).max() <= 1e-13 * np.abs(clipped[0]).max()


@pytest.mark.slow  # 2 s on the 2-core machine
def test_default_tolerances_keep_a_long_ringing_within_the_promise():
    """A 0.002 kg body on four mounts with modes from 1 to 600 Hz rings 5000 cycles of its 600 Hz mode: at a fixed
    1e-9 it ended 1.01e-6 of a DOF's peak off the exact answer (the global error grows with the cycles of the
    fastest mode). The defaults divide the tolerances by the cycles over CYCLES_PER_TOLERANCE and keep every DOF,
    in q, q' and q'', within RTOL_DIRECT_EXACT of its own peak against the matrix exponential."""
    from sixdof import Mount, RigidBody, System
    from sixdof.analysis.direct import CYCLES_PER_TOLERANCE

    mass, a, b = 0.002, 0.02, 0.03
    k = (2 * np.pi * np.array([1.0, 3.0, 600.0])) ** 2 * mass / 4  # x 1 Hz, y 3 Hz, z 600 Hz
    mounts = [Mount(f"m{i}", [sx * a, sy * b, -0.01], k, 1e-6 * k)
              for i, (sx, sy) in enumerate([(-1, -1), (1, -1), (1, 1), (-1, 1)])]
    system = System(RigidBody(mass, [2e-6, 3e-6, 4e-6]), mounts)
    f_max = float(np.max(system.modes.frequency_hz))
    assert f_max / np.min(system.modes.frequency_hz) == pytest.approx(600.0, rel=1e-5)
    settings = SimulationSettings(duration=5000 / f_max, sample_rate_hz=10 * f_max)
    excitation = Excitation(initial=InitialState(q=[1e-3, 1e-3, 1e-5, 1e-3, 1e-3, 1e-3], qd=[0.0] * 6))
    run = simulate(system, excitation, settings)
    assert run.stats.rtol == pytest.approx(1e-9 * CYCLES_PER_TOLERANCE / 5000, rel=1e-9)
    A, _ = state_matrices(np.asarray(system.M), np.asarray(system.C), np.asarray(system.K))
    step = scipy.linalg.expm(A * (run.t[1] - run.t[0]))  # the samples are evenly spaced
    x = np.empty((run.t.size, 12))
    x[0] = np.concatenate([run.q[0], run.qd[0]])
    for i in range(1, run.t.size):
        x[i] = step @ x[i - 1]
    assert_each_dof((run.q, x[:, :6]), (run.qd, x[:, 6:]), (run.qdd, (x @ A.T)[:, 6:]))


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_default_tolerances_hold_for_a_tone_far_above_the_modes():
    """The bundled compressor made 5000 t (mass and inertia x 10^4: modes at 0.05-0.15 Hz) under its 24.7 Hz
    unbalance: the tone is mass-controlled and the switch-on rings at 1 / (omega_r Omega), 160 times below the
    static modal estimate, which let the direct solve end 5.6e-6 of y's peak off. The state scale of a tone keeps
    every DOF, in q, q' and q'', within RTOL_DIRECT_EXACT of the exact engine's answer."""
    from pathlib import Path

    from sixdof import parse_scenario, superpose

    text = (Path(__file__).resolve().parents[1] / "scenarios" / "machine_unbalance.toml").read_text()
    scenario = parse_scenario(text.replace("mass = 500.0", "mass = 5.0e6")
                              .replace("[60.4, 93.75, 86.7]", "[6.04e5, 9.375e5, 8.67e5]"))
    assert np.max(scenario.system.modes.frequency_hz) < 0.2
    run = simulate(scenario.system, scenario.excitation, scenario.simulation)
    exact = superpose(scenario.system, scenario.excitation, scenario.simulation.times)
    assert_each_dof((run.q, exact.q), (run.qd, exact.qd), (run.qdd, exact.qdd))


def test_scaled_tolerances_stop_at_the_floor():
    """A run of many cycles divides the tolerances down to MIN_TOLERANCE, not below (float64 round-off)."""
    from sixdof.analysis.direct import CYCLES_PER_TOLERANCE, MIN_TOLERANCE, cycle_scaled
    from sixdof.model.parts import Mount, RigidBody
    from sixdof.model.system import System

    system = System(RigidBody(1.0, [1.0, 1.0, 1.0]),
                    [Mount(f"m{i}", p, [(2 * np.pi * 600) ** 2 / 4] * 3) for i, p in
                     enumerate([[0.5, 0.5, -0.5], [-0.5, 0.5, -0.5], [-0.5, -0.5, -0.5], [0.5, -0.5, -0.5]])])
    f_max = float(np.max(system.modes.frequency_hz))
    short = SimulationSettings(duration=100 * CYCLES_PER_TOLERANCE / f_max, sample_rate_hz=3 * f_max)
    assert cycle_scaled(system, short).rtol == pytest.approx(1e-9 / 100)
    long = SimulationSettings(duration=1e5 * CYCLES_PER_TOLERANCE / f_max, sample_rate_hz=3 * f_max)
    assert cycle_scaled(system, long).rtol == MIN_TOLERANCE == cycle_scaled(system, long).atol
