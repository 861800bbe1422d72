"""Signals, loads, ground motion and initial states: closed forms written out here, and bad input."""

import math

import numpy as np
import pytest

from sixdof import (
    SIGNAL_KINDS,
    Excitation,
    GroundMotion,
    HalfSine,
    Harmonic,
    Haversine,
    InitialState,
    InputError,
    Load,
    ModeRelease,
    Ramp,
    Random,
    Step,
    Sweep,
    Table,
    Unbalance,
    modal_analysis,
)
from sixdof._jax import jax
from sixdof.excitation import LOAD_KINDS, make_signal
from systems import bridge
from tolerances import ATOL_UNIT_ROUNDOFF, RTOL_MODE_RELEASE_AMPLITUDE, RTOL_SIGNAL

T = np.linspace(-0.5, 3.0, 701)


def close(actual, expected):
    return np.allclose(np.asarray(actual), expected, rtol=0, atol=RTOL_SIGNAL * max(1.0, np.abs(expected).max()))


def test_kinds_are_registered_and_signals_made_from_tables():
    assert set(SIGNAL_KINDS) == {"harmonic", "sweep", "half_sine", "haversine", "step", "ramp",
                                 "table", "random"}
    assert LOAD_KINDS == {"force": Load, "unbalance": Unbalance}
    s = make_signal({"kind": "half_sine", "start": 1.0, "duration": 0.05})
    assert isinstance(s, HalfSine) and s.duration == 0.05


def test_harmonic_closed_form():
    s = Harmonic(f_hz=2.0, phase_deg=45.0, start=0.5, duration=1.0)
    inside = (T >= 0.5) & (T < 1.5)
    expected = np.where(inside, np.sin(2 * np.pi * 2.0 * (T - 0.5) + np.pi / 4), 0.0)
    assert close(s(T), expected)
    assert s.breakpoints == (0.5, 1.5)
    assert Harmonic(f_hz=1.0).breakpoints == (0.0,)
    assert close(s.derivative(np.array([1.0])), 4 * np.pi * np.cos(2 * np.pi * 2.0 * 0.5 + np.pi / 4))


def test_sweeps_closed_form_and_instantaneous_frequency():
    lin = Sweep(f0_hz=1.0, f1_hz=5.0, duration=2.0, start=0.5)
    tau = T - 0.5
    inside = (tau >= 0) & (tau < 2.0)
    assert close(lin(T), np.where(inside, np.sin(2 * np.pi * (tau + tau**2)), 0.0))
    log = Sweep(f0_hz=1.0, f1_hz=8.0, duration=3.0, law="log")
    phase = 2 * np.pi * 3.0 / np.log(8.0) * (8.0 ** (T / 3.0) - 1)
    assert close(log(T), np.where((T >= 0) & (T < 3.0), np.sin(phase), 0.0))
    # the phase rate is 2 pi times the instantaneous frequency (1 Hz -> 8 Hz, an octave a second)
    t = np.array([0.7, 1.9])
    assert np.allclose(np.asarray(log.frequency_hz(t)), 2.0 ** t, rtol=RTOL_SIGNAL)
    assert lin.breakpoints == (0.5, 2.5)


def test_a_sweep_rate_in_octaves_per_minute_is_a_log_sweep():
    # IEC 60068-2-6 style: 5 -> 80 Hz is 4 octaves; at 2 oct/min the sweep lasts 2 minutes and the
    # frequency doubles every 30 s.
    rated = Sweep(f0_hz=5.0, f1_hz=80.0, rate_oct_per_min=2.0, start=1.0)
    assert rated.law == "log" and rated.duration == pytest.approx(120.0, rel=1e-15)
    t = 1.0 + np.array([0.0, 30.0, 60.0, 90.0])
    assert np.allclose(np.asarray(rated.frequency_hz(t)), [5.0, 10.0, 20.0, 40.0], rtol=RTOL_SIGNAL)
    same = Sweep(f0_hz=5.0, f1_hz=80.0, duration=120.0, law="log", start=1.0)
    assert close(rated(T * 50.0), same(T * 50.0))
    down = Sweep(f0_hz=80.0, f1_hz=10.0, rate_oct_per_min=1.0)  # 3 octaves down
    assert down.duration == pytest.approx(180.0)
    for kwargs, message in [
        ({"duration": 10.0}, r"rate_oct_per_min: expected either a duration or a rate, not both"),
        ({"law": "linear"}, r"law: expected 'log' for a sweep at a rate in octaves per minute, got 'linear'"),
    ]:
        with pytest.raises(InputError, match=message):
            Sweep(f0_hz=5.0, f1_hz=80.0, rate_oct_per_min=1.0, **kwargs)
    with pytest.raises(InputError, match=r"duration: expected a sweep time in s, or rate_oct_per_min"):
        Sweep(f0_hz=5.0, f1_hz=80.0)
    with pytest.raises(InputError, match=r"rate_oct_per_min: expected a positive sweep rate"):
        make_signal({"kind": "sweep", "f0_hz": 5.0, "f1_hz": 80.0, "rate_oct_per_min": -1.0})


def test_pulses_step_ramp_closed_form():
    assert close(HalfSine(start=1.0, duration=0.5)(T),
                 np.where((T >= 1) & (T < 1.5), np.sin(np.pi * (T - 1) / 0.5), 0.0))
    assert close(Haversine(start=1.0, duration=0.5)(T),
                 np.where((T >= 1) & (T < 1.5), 0.5 * (1 - np.cos(2 * np.pi * (T - 1) / 0.5)), 0.0))
    assert close(Step(start=1.0)(T), (T >= 1.0).astype(float))
    assert close(Ramp(duration=2.0, start=0.5)(T), np.clip((T - 0.5) / 2.0, 0, 1))
    assert HalfSine(start=1.0, duration=0.05).breakpoints == (1.0, 1.05)
    assert Step(start=2.0).breakpoints == (2.0,)
    assert Ramp(duration=1.0).breakpoints == (0.0, 1.0)
    # right-continuous at breakpoints
    assert float(Step(start=1.0)(1.0)) == 1.0


def test_table_interpolates_and_lists_its_knots():
    s = Table(t=[0.0, 1.0, 2.0], values=[1.0, 3.0, -1.0])
    # Right-continuous at the last knot (issue 13: it gave the value before it, -1): zero from there on.
    assert close(s(np.array([-1.0, 0.0, 0.5, 1.5, 2.0, 2.5])), [0.0, 1.0, 2.0, 1.0, 0.0, 0.0])
    held = Table(t=[0.0, 1.0, 2.0], values=[1.0, 3.0, -1.0], outside="hold")
    assert close(held(np.array([-1.0, 2.5])), [1.0, -1.0])
    assert s.breakpoints == (0.0, 1.0, 2.0)
    assert s.peak == 3.0
    assert close(s.derivative(np.array([0.5, 1.5])), [2.0, -4.0])


def test_random_is_reproducible_band_limited_with_its_rms():
    a = Random(f_hz=[2.0, 10.0], rms=0.3, seed=11)
    b = Random(f_hz=[2.0, 10.0], rms=0.3, seed=11)
    c = Random(f_hz=[2.0, 10.0], rms=0.3, seed=12)
    t = np.linspace(0.0, 400.0, 40_001)  # 100 Hz sampling: 5x the band's top
    x = np.asarray(a(t))
    assert np.array_equal(x, np.asarray(b(t)))
    assert not np.allclose(x, np.asarray(c(t)))
    assert np.all((a.frequencies >= 2.0) & (a.frequencies <= 10.0))
    # the mean square of a sum of sines with distinct frequencies tends to sum a^2/2 = rms^2
    assert np.sqrt(np.mean(x**2)) == pytest.approx(0.3, rel=0.02)
    spectrum = np.abs(np.fft.rfft(x * np.hanning(x.size))) ** 2
    f = np.fft.rfftfreq(t.size, t[1] - t[0])
    assert spectrum[(f < 1.9) | (f > 10.1)].sum() < 1e-3 * spectrum.sum()


def test_signals_are_pytrees_that_jit_without_retracing():
    traces = []

    @jax.jit
    def evaluate(signal, t):
        traces.append(1)
        return signal(t)

    assert float(evaluate(Harmonic(f_hz=1.0), 0.25)) == pytest.approx(1.0, abs=ATOL_UNIT_ROUNDOFF)
    assert float(evaluate(Harmonic(f_hz=2.0, phase_deg=90.0), 0.25)) == pytest.approx(-1.0, abs=ATOL_UNIT_ROUNDOFF)
    assert len(traces) == 1


@pytest.mark.parametrize(
    "cls, kwargs, match",
    [
        (make_signal, {"value": {"kind": "square"}}, "kind: expected one of half_sine, harmonic"),
        (make_signal, {"value": {"kind": ["step"]}}, r"kind: expected one of half_sine, .*got \['step'\]"),
        (make_signal, {"value": {"kind": "harmonic"}}, "f_hz: expected a value"),
        (make_signal, {"value": {"kind": "harmonic", "fhz": 1.0}}, r"fhz: expected one of the keys .*did you mean 'f_hz'\?"),
        (Harmonic, {"f_hz": 0.0}, "f_hz: expected a positive frequency in Hz, at most 1e9, got 0.0"),
        (Harmonic, {"f_hz": "5"}, "f_hz: expected a positive frequency"),
        (Harmonic, {"f_hz": 1.0, "duration": -1.0}, "duration: expected a positive duration"),
        (Sweep, {"f0_hz": 1.0, "f1_hz": 1.0, "duration": 1.0, "law": "log"}, "f1_hz: expected a frequency different"),
        (Sweep, {"f0_hz": 1.0, "f1_hz": 2.0, "duration": 1.0, "law": "exp"}, "law: expected 'linear' or 'log'"),
        (Sweep, {"f0_hz": -1.0, "f1_hz": 2.0, "duration": 1.0}, "f0_hz: expected a positive"),
        (HalfSine, {"start": 0.0, "duration": 0.0}, "duration: expected a positive, finite duration in s, at least 1e-9, got 0.0"),
        (Haversine, {"start": math.inf, "duration": 1.0}, "start: expected a finite time"),
        (Ramp, {"duration": math.inf}, "duration: expected a positive, finite"),
        (Step, {"start": None}, "start: expected a finite time in s, got None"),
        (Table, {"t": [0.0, 1.0, 1.0], "values": [0, 1, 2]}, r"t: expected at least 2 finite, strictly increasing times in s, got t\[2\] = 1 after t\[1\] = 1$"),
        (Table, {"t": [0.0], "values": [0]}, "t: expected at least 2"),
        (Table, {"t": [0.0, 1.0], "values": [0, 1, 2]}, "values: expected 2 finite values"),
        (Table, {"t": [0.0, 1.0], "values": [0, 1], "outside": "extrapolate"}, "outside: expected 'zero' or 'hold'"),
        (Random, {"f_hz": [10.0, 2.0], "rms": 1.0, "seed": 1}, r"f_hz: expected a band \[low, high\] in Hz with 0 < low < high"),
        (Random, {"f_hz": [1.0, 2.0], "rms": 0.0, "seed": 1}, "rms: expected a positive rms"),
        (Random, {"f_hz": [1.0, 2.0], "rms": 1.0, "seed": -1}, "seed: expected an integer >= 0"),
        (Random, {"f_hz": [1.0, 2.0], "rms": 1.0, "seed": 1.5}, "seed: expected an integer >= 0"),
        (Random, {"f_hz": [1.0, 2.0], "rms": 1.0, "seed": 1, "components": 0}, "components: expected an integer from 1 to 10000"),
        (Random, {"f_hz": [1.0, 2.0], "rms": 1.0, "seed": 1, "components": 10_001}, "components: expected an integer from 1 to 10000, got 10001"),
        (Load, {"name": "", "point": [0, 0, 0], "force": [1, 0, 0], "signal": Step()}, "name: expected a non-empty string"),
        (Load, {"name": "a", "point": [0, 0], "force": [1, 0, 0], "signal": Step()}, r"point: expected 3 coordinates \[x, y, z\] in m"),
        (Load, {"name": "a", "point": [0, 0, 0], "signal": Step()}, "force: expected a non-zero force or moment"),
        (Load, {"name": "a", "point": [0, 0, 0], "force": [1, 0, 0]}, "signal: expected a signal"),
        (Load, {"name": "a", "point": [0, 0, 0], "force": [1, 0, 0], "signal": {"kind": "harmonic", "f_hz": -2}},
         "signal.f_hz: expected a positive frequency"),
        (Unbalance, {"name": "u", "point": [0, 0, 0], "unbalance": 0.1}, "f_hz: expected either f_hz .* or speed_rpm"),
        (Unbalance, {"name": "u", "point": [0, 0, 0], "unbalance": 0.1, "f_hz": 1, "speed_rpm": 60}, "got both"),
        (Unbalance, {"name": "u", "point": [0, 0, 0], "unbalance": -0.1, "f_hz": 1}, "unbalance: expected a positive m e in kg m"),
        (Unbalance, {"name": "u", "point": [0, 0, 0], "unbalance": 0.1, "f_hz": 1, "axis": [0, 0, 0]}, "axis: expected a non-zero"),
        (GroundMotion, {"quantity": "jerk", "direction": [1, 0, 0], "signal": Step()}, "quantity: expected 'displacement', 'velocity' or 'acceleration'"),
        (GroundMotion, {"quantity": "velocity", "direction": [0, 0, 0], "signal": Step()}, "direction: expected a non-zero 3-vector"),
        (GroundMotion, {"quantity": "velocity", "direction": [1, 0, 0], "signal": Step(), "scale": 0.0}, "scale: expected a finite non-zero number"),
        (GroundMotion, {"quantity": "displacement", "direction": [1, 0, 0], "signal": Step(start=1.0)},
         "signal: expected a continuous signal for a ground displacement .* got a step signal jumping by 1 at t = 1 s"),
        (GroundMotion, {"quantity": "displacement", "direction": [1, 0, 0], "signal": Table(t=[0, 1], values=[1, 1])},
         "jumping by 1 at t = 0 s"),
        (InitialState, {"q": [0] * 5}, r"q: expected 6 values \[x, y, z, rx, ry, rz\] in m and rad"),
        (InitialState, {"qd": [0, 0, 0, 0, 0, math.nan]}, "qd: expected 6 values"),
        (ModeRelease, {"mode": 7, "amplitude": 1e-3}, "mode: expected a mode number from 1 to 6, got 7"),
        (ModeRelease, {"mode": 0, "amplitude": 1e-3}, "mode: expected a mode number from 1 to 6, got 0"),
        (ModeRelease, {"mode": 2, "amplitude": 0.0}, "amplitude: expected a non-zero amplitude"),
        (Excitation, {"loads": [Load("a", [0, 0, 0], [1, 0, 0], signal=Step())] * 2}, "loads: expected unique load names, got a repeated"),
        (Excitation, {"loads": ["x"]}, r"loads\[0\]: expected a Load or Unbalance"),
    ],
)
def test_bad_parameters_are_named(cls, kwargs, match):
    with pytest.raises(InputError, match=match):
        cls(**kwargs)


# --- loads ----------------------------------------------------------------------------------------


def test_load_generalized_force_is_force_and_moment_about_the_cg():
    load = Load("l", [1.0, 2.0, 3.0], force=[0.0, 0.0, 10.0], moment=[1.0, 0.0, 0.0],
                signal={"kind": "step", "start": 0.0})
    (vector, signal), = load.components()
    # r x F = (2*10 - 3*0, 3*0 - 1*10, 0) = (20, -10, 0); plus the moment
    assert np.allclose(vector, [0, 0, 10, 21, -10, 0], rtol=0, atol=ATOL_UNIT_ROUNDOFF)
    assert np.allclose(Excitation(loads=(load,)).generalized_force([-1.0, 1.0]),
                       [np.zeros(6), vector], rtol=0, atol=ATOL_UNIT_ROUNDOFF)


def test_unbalance_rotates_in_its_plane():
    me, f = 0.02, 25.0
    w = 2 * np.pi * f
    rotor = Unbalance("rotor", [0.1, 0.0, 0.3], unbalance=me, speed_rpm=60 * f, axis=[0, 0, 2])
    assert rotor.force_amplitude == pytest.approx(me * w**2, rel=1e-15)
    t = np.linspace(0.0, 0.1, 201)
    Q = Excitation(loads=(rotor,)).generalized_force(t)
    expected = me * w**2 * np.stack([np.cos(w * t), np.sin(w * t), 0 * t], axis=1)  # axis z: u=x, v=y
    amplitude = me * w**2
    assert np.allclose(Q[:, :3], expected, rtol=0, atol=RTOL_SIGNAL * amplitude * 100)
    assert np.allclose(Q[:, 3:], np.cross([0.1, 0.0, 0.3], expected), rtol=0,
                       atol=RTOL_SIGNAL * amplitude * 100)
    # axis y: u = x, v = y x x = -z
    tilted = Unbalance("r", [0, 0, 0], unbalance=me, f_hz=f, axis=[0, 1, 0], phase_deg=90.0)
    assert np.allclose(Excitation(loads=(tilted,)).generalized_force([0.0])[0, :3],
                       [0, 0, -amplitude], rtol=0, atol=1e-9 * amplitude)


def test_ground_direction_is_normalized_and_continuous_displacements_are_accepted():
    ground = GroundMotion("displacement", [0.0, 3.0, 4.0], {"kind": "haversine", "start": 0.0,
                                                            "duration": 1.0}, scale=0.01)
    assert np.allclose(ground.direction, [0.0, 0.6, 0.8], rtol=0, atol=ATOL_UNIT_ROUNDOFF)
    assert np.allclose(ground.rigid_vector, [0.0, 0.6, 0.8, 0, 0, 0], rtol=0, atol=ATOL_UNIT_ROUNDOFF)
    GroundMotion("velocity", [1, 0, 0], Step(start=1.0))  # a velocity may jump


def test_mode_release_starts_in_the_mode_with_its_dominant_dof_at_the_amplitude():
    beam = bridge("elastomer")
    modes = modal_analysis(beam.M, beam.K)
    q0, qd0 = ModeRelease(mode=4, amplitude=2e-4).state(beam)
    assert modes.dominant_dof[3] == "ry" and q0[4] == pytest.approx(2e-4, rel=RTOL_MODE_RELEASE_AMPLITUDE)
    assert np.allclose(q0 / q0[4] * modes.shapes[4, 3], modes.shapes[:, 3], rtol=1e-12, atol=0)
    assert not np.any(qd0)
    assert Excitation().initial_state(beam)[0].tolist() == [0.0] * 6


def test_excitation_collects_breakpoints():
    excitation = Excitation(
        loads=(Load("a", [0, 0, 0], [1, 0, 0], signal=HalfSine(start=1.0, duration=0.1)),
               Unbalance("u", [0, 0, 0], unbalance=0.1, f_hz=5.0, start=0.5)),
        ground=GroundMotion("acceleration", [0, 1, 0], Table(t=[0.2, 0.3], values=[0.0, 1.0])),
    )
    assert excitation.breakpoints == (0.2, 0.3, 0.5, 1.0, 1.1)
    assert len(excitation.components()) == 3
