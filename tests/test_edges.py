"""Physics at the edges (issue 13, point 5): signals at their breakpoints, the foundation force of every
damping model in time and frequency, a ground displaced at the start, and what is reported when the
input leaves the model's range (an undamped resonance hit, a load that never acts, large rotations).

Every expected value is written out here from the signal's or the system's closed form.
"""

import math

import numpy as np
import pytest

from sixdof import (
    Excitation,
    GroundMotion,
    InitialState,
    InputError,
    Load,
    ModeRelease,
    Mount,
    Rayleigh,
    RigidBody,
    ScenarioError,
    SimulationSettings,
    System,
    Unbalance,
    force_transmissibility,
    mount_forces,
    parse_scenario,
    receptance,
    run_scenario,
    simulate,
    superpose,
)
from sixdof.analysis.frf import UNDAMPED_RESONANCE_RTOL, cross_check
from sixdof.analysis.statics import STANDARD_GRAVITY, gravity_statics
from sixdof.analysis.validity import SMALL_ANGLE_RAD, RangeWarning, body_length, static_range
from sixdof.excitation import HalfSine, Harmonic, Haversine, Ramp, Random, Step, Sweep, Table
from sixdof.workflows.prepare import prepare
from systems import bridge
from tolerances import RTOL_AT_REST, RTOL_DIRECT_STEADY_STATE, RTOL_LINALG, RTOL_SIGNAL

TWO_PI = 2 * math.pi


# ----------------------------------------------------------------------------------------------------
# (a) Right-continuity: value and derivatives at a breakpoint are the limits from the right.
# ----------------------------------------------------------------------------------------------------


def _random_at_start():
    s = Random(f_hz=[1.0, 5.0], rms=0.7, seed=3, components=4, start=0.5, duration=2.0)
    a = 0.7 * math.sqrt(2.0 / 4)
    w, phi = TWO_PI * np.asarray(s.frequencies), np.asarray(s.phases)
    return s, {0.5: (a * np.sum(np.sin(phi)), a * np.sum(w * np.cos(phi)), -a * np.sum(w**2 * np.sin(phi))),
               2.5: (0.0, 0.0, 0.0)}


# signal -> {breakpoint: (s, s', s'') just after it}, written from each kind's formula.
RIGHT_LIMITS = {
    "harmonic": lambda: (Harmonic(f_hz=2.0, phase_deg=30.0, start=1.0, duration=3.0), {
        1.0: (0.5, 4 * math.pi * math.cos(math.pi / 6), -(4 * math.pi) ** 2 * 0.5),
        4.0: (0.0, 0.0, 0.0)}),
    # phi(tau) = 2 pi (f0 tau + (f1 - f0) tau^2 / 2T): phi'(0) = 2 pi f0, phi''(0) = 2 pi (f1 - f0) / T.
    "linear sweep": lambda: (Sweep(f0_hz=1.0, f1_hz=3.0, duration=2.0, start=0.5), {
        0.5: (0.0, TWO_PI * 1.0, TWO_PI * 2.0 / 2.0), 2.5: (0.0, 0.0, 0.0)}),
    # phi'(tau) = 2 pi f0 r^(tau/T): phi''(0) = 2 pi f0 ln(r) / T.
    "log sweep": lambda: (Sweep(f0_hz=1.0, f1_hz=8.0, duration=3.0, start=0.5, law="log"), {
        0.5: (0.0, TWO_PI, TWO_PI * math.log(8.0) / 3.0), 3.5: (0.0, 0.0, 0.0)}),
    "half-sine": lambda: (HalfSine(start=1.0, duration=0.5), {
        1.0: (0.0, math.pi / 0.5, 0.0), 1.5: (0.0, 0.0, 0.0)}),
    "haversine": lambda: (Haversine(start=1.0, duration=0.5), {
        1.0: (0.0, 0.0, 0.5 * (TWO_PI / 0.5) ** 2), 1.5: (0.0, 0.0, 0.0)}),
    "step": lambda: (Step(start=1.0), {1.0: (1.0, 0.0, 0.0)}),
    "ramp": lambda: (Ramp(duration=2.0, start=1.0), {1.0: (0.0, 0.5, 0.0), 3.0: (1.0, 0.0, 0.0)}),
    "table, zero outside": lambda: (Table(t=[0.0, 1.0, 2.5], values=[1.0, 3.0, -1.0]), {
        0.0: (1.0, 2.0, 0.0), 1.0: (3.0, -4.0 / 1.5, 0.0), 2.5: (0.0, 0.0, 0.0)}),
    "table, held": lambda: (Table(t=[0.0, 1.0, 2.5], values=[1.0, 3.0, -1.0], outside="hold"), {
        0.0: (1.0, 2.0, 0.0), 1.0: (3.0, -4.0 / 1.5, 0.0), 2.5: (-1.0, 0.0, 0.0)}),
    "random": _random_at_start,
}


@pytest.mark.parametrize("case", RIGHT_LIMITS)
def test_signals_are_right_continuous_at_every_breakpoint(case):
    signal, limits = RIGHT_LIMITS[case]()
    assert signal.breakpoints == tuple(sorted(limits))  # every breakpoint is checked
    b = np.array(sorted(limits))
    got = np.stack([np.asarray(signal(b)), np.asarray(signal.derivative(b)), np.asarray(signal.derivative(b, 2))])
    expected = np.array([limits[x] for x in sorted(limits)]).T
    assert np.allclose(got, expected, rtol=RTOL_SIGNAL, atol=RTOL_SIGNAL * np.abs(expected).max())


# Both time paths sample Q, qdd, the ground's velocity and the foundation force at output times that
# fall on breakpoints (every 1/200 s): they must take the values after the breakpoint.
EDGES = SimulationSettings(duration=0.4, sample_rate_hz=200.0)
LOAD_POINT, LOAD_FORCE = np.array([0.3, 10.0, 1.0]), np.array([5e3, 2e4, -1e5])


def _both_paths(system, excitation):
    direct = simulate(system, excitation, EDGES)
    return direct, superpose(system, excitation, direct.t)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_table_load_ending_on_a_sample_is_off_there():
    # The table ends at 0.2 s, on a sample, with its load still on: from 0.2 s on it is zero.
    beam = bridge("elastomer")
    signal = Table(t=[0.05, 0.2], values=[0.5, 1.0])
    excitation = Excitation(loads=(Load("l", LOAD_POINT, force=LOAD_FORCE, signal=signal),))
    direct, modal = _both_paths(beam, excitation)
    k = int(np.flatnonzero(direct.t == 0.2)[0])
    assert np.all(direct.Q[k] == 0.0)
    Minv = np.linalg.inv(beam.M)
    for run in (direct, modal):
        # Right limit: no load in the balance (the left one would add M^-1 Q, as large as qdd itself).
        expected = -(run.qd[k] @ beam.C.T + run.q[k] @ beam.K.T) @ Minv.T
        scale = np.abs(run.qdd).max(axis=0)
        assert np.all(np.abs(run.qdd[k] - expected) <= RTOL_LINALG * scale)
        # ... and the test can tell: the load before 0.2 s moves every DOF's qdd far beyond the tolerance.
        assert np.all(np.abs(Minv @ excitation.generalized_force([0.2 - 1e-9])[0]) > 1e3 * RTOL_LINALG * scale)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_a_ground_ramp_gives_its_right_slope_at_both_ends():
    # The ground rises by 1 mm from 0.05 s to 0.25 s (samples): velocity 5 mm/s from 0.05 s, zero from
    # 0.25 s, and the dashpots and the foundation force follow that velocity at those very samples.
    beam = bridge("elastomer", rayleigh=Rayleigh(0.02, 2e-4))
    direction = np.array([0.3, 1.0, -0.5]) / np.linalg.norm([0.3, 1.0, -0.5])
    ground = GroundMotion("displacement", direction, Ramp(duration=0.2, start=0.05), scale=1e-3)
    direct, modal = _both_paths(beam, Excitation(ground=ground))
    r = np.concatenate([direction, np.zeros(3)])
    Minv = np.linalg.inv(beam.M)
    for t_b, u, v in ((0.05, 0.0, 1e-3 / 0.2), (0.25, 1e-3, 0.0)):
        k = int(np.flatnonzero(direct.t == t_b)[0])
        assert np.allclose(direct.ground_velocity[k], v * direction, rtol=0, atol=RTOL_SIGNAL * 1e-3 / 0.2)
        for run in (direct, modal):
            z, zd = run.q[k] - r * u, run.qd[k] - r * v
            expected = -(zd @ beam.C.T + z @ beam.K.T) @ Minv.T
            assert np.all(np.abs(run.qdd[k] - expected) <= RTOL_LINALG * np.abs(run.qdd).max(axis=0))
        wrench = beam.K @ (direct.q[k] - r * u) + beam.C @ (direct.qd[k] - r * v)
        force = mount_forces(beam, direct).foundation_force[k]
        assert np.allclose(force, wrench[:3], rtol=0, atol=RTOL_LINALG * np.abs(wrench[:3]).max())


# ----------------------------------------------------------------------------------------------------
# (b) The foundation force: one definition in time and in frequency, with every damping model.
# ----------------------------------------------------------------------------------------------------

DAMPING_MODELS = {
    "mount dashpots": lambda: bridge("elastomer"),
    "rayleigh": lambda: bridge(rayleigh=Rayleigh.from_ratio(0.05, (0.6, 38.0))),
    "modal": lambda: bridge(modal_damping=(0.01, 0.02, 0.02, 0.03, 0.05, 0.05)),
    "all three": lambda: bridge("equal", rayleigh=Rayleigh(0.02, 2e-4), modal_damping=0.01),
}


@pytest.mark.slow  # 1-2 s each on the 2-core machine
@pytest.mark.parametrize("f_hz", [1.4, 25.0])
@pytest.mark.parametrize("model", DAMPING_MODELS)
def test_time_domain_foundation_force_has_the_frf_amplitude(model, f_hz):
    # A harmonic load Re(F e^{iwt}) on the body, started on the steady state the receptance predicts:
    # the direct solve's foundation force, projected on e^{iwt} over whole periods, is the force
    # transmissibility times the load (the issue measured 9-11 % apart with Rayleigh or modal damping).
    system = DAMPING_MODELS[model]()
    direction = np.array([0.2, 0.5, 1.0]) / np.linalg.norm([0.2, 0.5, 1.0])
    amplitude = 1e4  # N
    Q = amplitude * np.concatenate([direction, np.cross(LOAD_POINT, direction)])
    w = TWO_PI * f_hz
    q_hat = receptance(system, [f_hz]).H[0] @ Q
    load = Load("l", LOAD_POINT, force=amplitude * direction, signal=Harmonic(f_hz=f_hz, phase_deg=90.0))
    excitation = Excitation(loads=(load,), initial=InitialState(q=q_hat.real, qd=(1j * w * q_hat).real))
    periods = 4
    run = simulate(system, excitation, SimulationSettings(duration=periods / f_hz, sample_rate_hz=100 * f_hz))
    force = mount_forces(system, run).foundation_force[:-1]  # whole periods, the end left out
    phasor = 2 * np.mean(force * np.exp(-1j * w * run.t[:-1])[:, None], axis=0)
    frf = force_transmissibility(system, [f_hz], LOAD_POINT, direction)
    expected = amplitude * frf.total_force[0]
    assert np.max(np.abs(phasor - expected)) <= RTOL_DIRECT_STEADY_STATE * np.abs(expected).max()
    assert np.linalg.norm(phasor) == pytest.approx(amplitude * frf.transmissibility[0], rel=RTOL_DIRECT_STEADY_STATE)
    # The global damping's share is there, and is no round-off where there is global damping.
    assert (np.abs(frf.other_damping).max() > 1e-3 * np.abs(frf.total).max()) == (model != "mount dashpots")


# ----------------------------------------------------------------------------------------------------
# (c) A ground displaced at the start: the body starts in equilibrium with it.
# ----------------------------------------------------------------------------------------------------

CONSTANT_GROUNDS = {
    "held table": (Table(t=[-1.0, 10.0], values=[4.0, 4.0], outside="hold"), 1e-3),
    "finished ramp": (Ramp(duration=1.0, start=-3.0), 1e-2),
}


@pytest.mark.slow  # 3 s each on the 2-core machine
@pytest.mark.parametrize("case", CONSTANT_GROUNDS)
def test_a_constant_ground_displacement_leaves_the_body_at_rest(case):
    signal, scale = CONSTANT_GROUNDS[case]
    beam = bridge("elastomer", rayleigh=Rayleigh(0.01, 1e-4))
    direction = np.array([0.3, 1.0, -0.5]) / np.linalg.norm([0.3, 1.0, -0.5])
    excitation = Excitation(ground=GroundMotion("displacement", direction, signal, scale=scale))
    u = scale * float(signal(0.0))
    at_rest = np.concatenate([u * direction, np.zeros(3)])
    direct, modal = _both_paths(beam, excitation)
    assert np.array_equal(direct.q, np.broadcast_to(at_rest, direct.q.shape))
    assert np.all(direct.qd == 0) and np.all(direct.qdd == 0)
    assert np.all(mount_forces(beam, direct).foundation_force == 0)
    # The modal path transforms to modes and back: at rest to round-off of the ground's displacement.
    fastest = TWO_PI * beam.modes.frequency_hz.max()
    for value, size in ((modal.q - at_rest, u), (modal.qd, u * fastest), (modal.qdd, u * fastest**2)):
        assert np.abs(value).max() <= RTOL_AT_REST * size


def test_initial_states_are_measured_from_the_displaced_equilibrium():
    beam = bridge("elastomer")
    ground = GroundMotion("displacement", [0, 0, 1], Ramp(duration=1.0, start=-2.0), scale=2e-3)
    shift = np.array([0, 0, 2e-3, 0, 0, 0])
    offset = np.array([1e-4, 0, 0, 0, 2e-6, 0])
    q0, qd0 = Excitation(ground=ground, initial=InitialState(q=offset, qd=offset)).initial_state(beam, 0.0)
    assert np.array_equal(q0, offset + shift) and np.array_equal(qd0, offset)
    mode = Excitation(ground=ground, initial=ModeRelease(mode=3, amplitude=1e-3)).initial_state(beam, 0.0)[0]
    alone = Excitation(initial=ModeRelease(mode=3, amplitude=1e-3)).initial_state(beam, 0.0)[0]
    assert np.array_equal(mode, alone + shift)
    # A ground given as a velocity starts at zero displacement: no shift.
    velocity = GroundMotion("velocity", [0, 0, 1], Ramp(duration=1.0, start=-2.0))
    assert np.array_equal(Excitation(ground=velocity).initial_state(beam, 0.0)[0], np.zeros(6))


# ----------------------------------------------------------------------------------------------------
# (d) Said clearly: an undamped resonance hit, a load that never acts, large rotations.
# ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["direct", "modal"])
def test_a_frequency_on_an_undamped_resonance_is_refused_naming_it_and_the_mode(method):
    # Exactly on it the two methods differed by up to 87 % (mode 5 of the bridge), with no word said.
    beam = bridge()
    f5 = float(beam.modes.frequency_hz[4])
    with pytest.raises(InputError, match=rf"^f_hz: expected frequencies off the natural frequency of mode 5 "
                       rf"\({f5:.12g} Hz\) by more than 1e-09 of it: no damping acts on that mode.* "
                       rf"got {f5:.12g} Hz \(frequency 2 of 3\)$"):
        receptance(beam, [1.0, f5, 30.0], method=method)
    # Just outside the band it is computed, and both methods still agree to ~1e-7.
    near = f5 * (1 + 2 * UNDAMPED_RESONANCE_RTOL)
    assert cross_check(beam, [near]).max_relative_difference < 1e-6
    # Damping on every mode: the resonance is finite and computed.
    assert np.all(np.isfinite(receptance(bridge("equal"), [f5], method=method).H))


def test_only_the_mode_no_damping_acts_on_is_refused():
    beam = bridge(modal_damping=(0.01, 0.02, 0.0, 0.03, 0.05, 0.05))  # mode 3 left undamped
    f = beam.modes.frequency_hz
    receptance(beam, [f[0], f[1], f[3]])  # damped modes: fine
    with pytest.raises(InputError, match=r"natural frequency of mode 3 .* got "):
        force_transmissibility(beam, [f[2]], LOAD_POINT, "z")


def test_a_scenario_grid_on_an_undamped_resonance_is_refused_before_computing():
    body = ("[body]\nmass = 300.0\ninertia = [20.0, 30.0, 25.0]\n" + "".join(
        f'[[mounts]]\nname = "{i}"\nposition = [{x}, {y}, -0.3]\nstiffness = [1e5, 1.5e5, 4e5]\n'
        for i, (x, y) in enumerate([(-0.3, -0.4), (0.3, -0.4), (0.3, 0.4), (-0.3, 0.4)])))
    lowest = float(parse_scenario(f'name = "free"\n{body}').system.modes.frequency_hz[0])
    text = f'name = "free"\n{body}[frf]\nf_hz = [{lowest!r}, 100.0]\npoints = 10\nspacing = "linear"\n'
    with pytest.raises(ScenarioError, match=rf"^free.toml: frf.f_hz: expected frequencies off the natural "
                       rf"frequency of mode 1 .* got {lowest:.12g} Hz \(frequency 1 of 10\)$"):
        prepare(parse_scenario(text, "free.toml"))  # the run's first step, before anything is computed


IDLE = {
    "pulse after the end": (Load("late", LOAD_POINT, force=LOAD_FORCE, signal=HalfSine(start=0.5, duration=0.01)),
                            "loads[1] (late): its half_sine signal is zero outside [0.5, 0.51) s"),
    "pulse before the start": (Load("early", LOAD_POINT, force=LOAD_FORCE, signal=HalfSine(start=-1.0, duration=0.5)),
                               "loads[1] (early): its half_sine signal is zero outside [-1, -0.5) s"),
    "step at the end": (Load("last", LOAD_POINT, force=LOAD_FORCE, signal=Step(start=0.4)),
                        "loads[1] (last): its step signal is zero outside [0.4, inf) s"),
    "all-zero table": (Load("nil", LOAD_POINT, force=LOAD_FORCE, signal=Table(t=[0.0, 0.1], values=[0.0, 0.0])),
                       "loads[1] (nil): its table signal is zero throughout"),
    "table ended": (Load("done", LOAD_POINT, force=LOAD_FORCE, signal=Table(t=[-2.0, -1.0, 0.0], values=[1.0, 2.0, 0.0])),
                    "loads[1] (done): its table signal is zero outside [-2, 0) s"),
    "unbalance after the end": (Unbalance("rotor", LOAD_POINT, unbalance=0.1, f_hz=20.0, start=1.0),
                                "loads[1] (rotor): its harmonic signal is zero outside [1, inf) s"),
}
ACTING = Load("acting", LOAD_POINT, force=LOAD_FORCE, signal=HalfSine(start=0.05, duration=0.02))


@pytest.mark.parametrize("case", IDLE)
def test_a_load_that_never_acts_is_named(case):
    load, message = IDLE[case]
    assert Excitation(loads=(ACTING, load)).idle(0.0, 0.4) == (message,)


def test_loads_acting_for_a_moment_of_the_run_are_not_idle():
    held = Table(t=[-2.0, -1.0], values=[0.0, 1.0], outside="hold")  # on from -1 s for ever
    loads = (ACTING, Load("held", LOAD_POINT, force=LOAD_FORCE, signal=held),
             Load("tail", LOAD_POINT, force=LOAD_FORCE, signal=HalfSine(start=0.39, duration=0.5)),
             Load("head", LOAD_POINT, force=LOAD_FORCE, signal=Ramp(duration=1.0, start=-5.0)))
    assert Excitation(loads=loads).idle(0.0, 0.4) == ()
    ground = GroundMotion("acceleration", [0, 0, 1], HalfSine(start=2.0, duration=0.1))
    assert Excitation(ground=ground).idle(0.0, 0.4) == (
        "ground motion: its half_sine signal is zero outside [2, 2.1) s",)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_both_time_paths_warn_of_a_load_that_never_acts():
    beam = bridge("elastomer")
    excitation = Excitation(loads=(ACTING, IDLE["pulse after the end"][0]))
    expected = r"^loads\[1\] \(late\): its half_sine signal is zero outside \[0\.5, 0\.51\) s, so it never acts " \
               r"in the simulated time \[0, 0\.4\] s$"
    with pytest.warns(RangeWarning, match=expected):
        direct = simulate(beam, excitation, EDGES)
    with pytest.warns(RangeWarning, match=expected):
        superpose(beam, excitation, direct.t)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_rotations_beyond_small_angles_are_warned_with_the_numbers():
    beam = bridge("elastomer")
    excitation = Excitation(initial=InitialState(q=[0, 0, 0, 0.0, 0.15, 0.0]))
    with pytest.warns(RangeWarning, match=r"^rotations beyond small-angle theory: \|ry\| reaches ") as caught:
        run = simulate(beam, excitation, EDGES)
    peak = np.abs(run.q[:, 4]).max()
    k = int(np.argmax(np.abs(run.q[:, 4])))
    message = str(caught[0].message)
    assert f"|ry| reaches {peak:.3g} rad ({math.degrees(peak):.3g} deg) at t = {run.t[k]:.6g} s." in message
    assert "|rx|" not in message and "|rz|" not in message  # rx, rz stay small
    assert np.abs(run.q[:, [3, 5]]).max() <= SMALL_ANGLE_RAD
    assert "valid to |theta| <= 0.1 rad (5.73 deg, error theta^2/2 = 0.5%)" in message
    with pytest.warns(RangeWarning, match=r"^rotations beyond small-angle theory: \|ry\| reaches "):
        superpose(beam, excitation, run.t)


def two_springs(k_left, k_right, mass=100.0, half_span=0.5):
    """A body on two vertical springs at y = -+half_span [m] under its weight at the CG: each carries half of
    it, so the CG sags by the mean deflection and the body tilts about x by their difference over the span."""
    body = RigidBody(mass, [8.0, 5.0, 9.0], dimensions=[1.2, 1.0, 0.5])
    return System(body, [Mount("left", [0.0, -half_span, 0.0], [1e5, 1e5, k_left]),
                         Mount("right", [0.0, half_span, 0.0], [1e5, 1e5, k_right])])


def test_statics_no_mount_could_give_are_named_with_the_numbers():
    weight = 100.0 * STANDARD_GRAVITY
    half_size = math.hypot(1.2, 1.0, 0.5) / 2
    # Stiffness meant in N/mm, given in N/m: the CG sags by W / (2 k) = 1.96 m, more than the half-size.
    system = two_springs(250.0, 250.0)
    statics = gravity_statics(system)
    sag = weight / (2 * 250.0)
    assert statics.q[2] == pytest.approx(-sag, rel=RTOL_LINALG)
    assert static_range(statics, system) == [
        f"the static deflection under gravity, {1e3 * sag:.4g} mm at the CG, exceeds the body's half-size "
        f"({1e3 * half_size:.4g} mm): no mount is linear over such a stroke. Are the stiffnesses in N/m (not N/mm)?"]
    # Springs of 2 and 100 kN/m: 245 and 4.9 mm, a tilt of 0.240 rad about x, and a sag well inside the body.
    system = two_springs(2e3, 1e5)
    tilt = (weight / 2 / 2e3 - weight / 2 / 1e5) / 1.0
    (message,) = static_range(gravity_statics(system), system)
    assert message.startswith(f"the static rotation under gravity, {tilt:.3g} rad ({math.degrees(tilt):.3g} deg), "
                              "is beyond small-angle theory")
    # Stiffer by 10: a tilt of 0.024 rad and a sag of 13 mm, nothing to say; nor without statics.
    system = two_springs(2e4, 1e6)
    assert static_range(gravity_statics(system), system) == [] and static_range(None, system) == []


def test_a_mount_at_the_cg_is_no_stiffness_in_n_per_mm():
    """Without dimensions the body's size comes from its inertia, not only from the mounts' reach: one mount
    under the CG (reach 0) at 5 Hz is no warning, the same mount 1000 times too soft still is one."""
    a, b, c = 1.2, 1.0, 0.5  # a uniform box: its inertia gives back its half-diagonal
    body = RigidBody(100.0, 100.0 / 12 * np.array([b**2 + c**2, a**2 + c**2, a**2 + b**2]))
    half_size = math.hypot(a, b, c) / 2

    def at_cg(k):
        return System(body, [Mount("under", [0.0, 0.0, 0.0], [k, k, k])])

    assert static_range(gravity_statics(at_cg(1e5)), at_cg(1e5)) == []  # a sag of 9.8 mm
    assert body_length(at_cg(1e5)) == pytest.approx(half_size, rel=RTOL_LINALG)
    sag = 100.0 * STANDARD_GRAVITY / 1e2
    assert static_range(gravity_statics(at_cg(1e2)), at_cg(1e2)) == [
        f"the static deflection under gravity, {1e3 * sag:.4g} mm at the CG, exceeds the body's half-size "
        f"({1e3 * half_size:.4g} mm): no mount is linear over such a stroke. Are the stiffnesses in N/m (not N/mm)?"]


RUN = """
name = "idle"
[body]
mass = 300.0
inertia = [20.0, 30.0, 25.0]
[[mounts]]
name = "a"
position = [-0.3, -0.4, -0.3]
stiffness = [1e5, 1.5e5, 4e5]
damping = [150.0, 150.0, 500.0]
[[mounts]]
name = "b"
position = [0.3, 0.4, -0.3]
stiffness = [1e5, 1.5e5, 4e5]
damping = [150.0, 150.0, 500.0]
[[mounts]]
name = "c"
position = [0.3, -0.4, -0.35]
stiffness = [1e5, 1.5e5, 4e5]
damping = [150.0, 150.0, 500.0]
[[loads]]
name = "late"
point = [0.4, 0.5, 0.3]
force = [0.0, 0.0, 1000.0]
signal = { kind = "half_sine", start = 0.5, duration = 0.02 }
[simulation]
duration = 0.2
sample_rate_hz = 1000.0
"""


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_run_warns_once_of_a_load_that_never_acts(tmp_path):
    # The superposition cross-check would say it again: a run says it once.
    with pytest.warns(RangeWarning) as caught:
        run_scenario(parse_scenario(RUN, "idle.toml"), tmp_path, progress=False)
    assert [str(w.message) for w in caught if issubclass(w.category, RangeWarning)] == [
        "loads[0] (late): its half_sine signal is zero outside [0.5, 0.52) s, so it never acts in the simulated "
        "time [0, 0.2] s"]
