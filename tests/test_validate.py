"""Modal results against time histories (sixdof.validation): H1 estimation against its statistical
error, free-decay estimation against closed forms, and the whole validation on a small system."""

import numpy as np
import pytest
import scipy.signal

from references import displacement_resonance_hz, log_decrement
from sixdof import (
    Excitation,
    Harmonic,
    InitialState,
    InputError,
    Load,
    SimulationSettings,
    receptance,
    simulate,
    validate,
)
from sixdof.io.report import validation_text
from sixdof.validation import (
    ValidationSettings,
    decay_estimate,
    effective_averages,
    estimate_frf,
    h1_random_error,
    peak_frequency,
)
from systems import small_box
from tolerances import H1_MAX_SIGMAS, H1_MEDIAN_SIGMAS, H1_SIGMA_CALIBRATION, RTOL_DECAY, RTOL_DIRECT_STEADY_STATE


def test_h1_agrees_with_the_true_frf_within_its_random_error():
    # A digital two-mode filter driven by white noise, plus output noise: the true FRF is exact
    # (freqz) and the estimate's error is random, with the Bendat-Piersol standard deviation.
    rng = np.random.default_rng(1)
    fs, n, nperseg = 100.0, 2**16, 2048  # bins 1/19 of the 8 Hz bandwidth: resolution bias << sigma
    poles = [radius * np.exp(sign * 2j * np.pi * f / fs) for radius, f in ((0.97, 8), (0.95, 22)) for sign in (1, -1)]
    b, a = scipy.signal.zpk2tf([], poles, 1.0)
    x = rng.standard_normal(n)
    clean = scipy.signal.lfilter(b, a, x)
    y = clean + 0.3 * np.std(clean) * rng.standard_normal(n)
    est = estimate_frf(x, y, fs, nperseg)
    _, H = scipy.signal.freqz(b, a, worN=est.f_hz, fs=fs)
    eps = est.random_error[:, 0]
    usable = (est.coherence[:, 0] >= 0.5) & (eps <= 0.2)
    assert usable.sum() > 400
    z = (np.abs(est.H1[usable, 0]) - np.abs(H[usable])) / (np.abs(H[usable]) * eps[usable])
    assert np.max(np.abs(z)) <= H1_MAX_SIGMAS
    # The error formula is calibrated, not merely an upper bound: the normalized errors' mean
    # square is near 1 (it could fail either way).
    assert abs(np.mean(z**2) - 1.0) <= H1_SIGMA_CALIBRATION


def test_effective_averages_of_hann_with_half_overlap():
    w = scipy.signal.get_window("hann", 1024)
    # Welch (1967): rho = 0.167 for Hann at 50 %, so K / (1 + 2 rho^2) for many segments.
    assert effective_averages(w, 1024, 512, 1000) == pytest.approx(1000 / 1.0556, rel=2e-3)
    assert effective_averages(w, 1024, 0, 10) == 10
    assert h1_random_error(1.0, 10) == 0.0


def test_decay_estimate_of_a_damped_sinusoid():
    zeta, f_n = 0.03, 7.0
    w_n = 2 * np.pi * f_n
    w_d = w_n * np.sqrt(1 - zeta**2)
    t = np.linspace(0.0, 8 / (w_d / 2 / np.pi), 513)
    x = 2.5 * np.exp(-zeta * w_n * t) * np.cos(w_d * t + 0.7)
    est = decay_estimate(t, x)
    assert est.f_damped_hz == pytest.approx(w_d / (2 * np.pi), rel=RTOL_DECAY)
    assert est.zeta == pytest.approx(zeta, rel=RTOL_DECAY)
    assert est.log_decrement == pytest.approx(log_decrement(zeta), rel=RTOL_DECAY)


def test_peak_frequency_of_a_sampled_resonance():
    f = np.linspace(0.0, 20.0, 201)
    zeta, f_n = 0.05, 7.33
    mag = 1 / np.abs(1 - (f / f_n) ** 2 + 2j * zeta * f / f_n)
    exact = displacement_resonance_hz(f_n, zeta)
    # The parabola on log magnitude lands well inside the 0.1 Hz bin.
    assert abs(peak_frequency(f, mag, 5.0, 10.0) - exact) < 0.1 * 0.1
    assert np.isnan(peak_frequency(f, mag, 30.0, 40.0))


def test_harmonic_simulation_steady_state_matches_frf():
    # Started on the steady state the FRF predicts, the time-domain solver must stay on it.
    system = small_box()
    f0, point, force = 9.0, np.array([0.2, -0.1, 0.3]), np.array([50.0, -80.0, 120.0])
    Q = np.concatenate([force, np.cross(point, force)])
    q_hat = receptance(system, [f0]).H[0] @ Q
    w = 2 * np.pi * f0
    # sin(w t) = Re(-i e^{i w t}): the steady state is Re(-i q_hat e^{i w t}).
    ss = -1j * q_hat
    excitation = Excitation(loads=[Load("h", point, force=force, signal=Harmonic(f_hz=f0))],
                            initial=InitialState(q=ss.real, qd=(1j * w * ss).real))
    run = simulate(system, excitation, SimulationSettings(duration=1.0, sample_rate_hz=400.0))
    expected = (ss[None, :] * np.exp(1j * w * run.t)[:, None]).real
    assert np.max(np.abs(run.q - expected) / np.abs(ss)) <= RTOL_DIRECT_STEADY_STATE


@pytest.mark.slow  # ~15 s on 2 cores, mostly two solver compilations
def test_validation_of_a_small_system():
    system = small_box()
    report = validate(system)
    assert len(report.rows) == 6 and [r.mode for r in report.rows] == list(range(1, 7))
    for row in report.rows:
        # Free decay: damped frequency and damping ratio of each mode (Rayleigh: classical).
        assert abs(row.f_damped_error) <= RTOL_DECAY
        assert abs(row.zeta_error) <= RTOL_DECAY * row.zeta_model
        # The estimated FRF peak lies within a bin of the model's, and the model's within
        # 2 zeta^2 of the natural frequency (displacement resonance of a modal coordinate).
        assert abs(row.f_peak_estimated_hz - row.f_peak_model_hz) <= row.frequency_resolution_hz
        assert abs(row.f_peak_model_hz / row.f_model_hz - 1) <= 2 * row.zeta_model**2 + 1e-3
        # H1 against the (held) model FRF: within its own random error, bin by bin.
        assert row.h1_error_in_sigmas <= H1_MEDIAN_SIGMAS
    headers, rows = report.table()
    assert headers[0] == "mode" and len(rows) == 6
    text = validation_text(report)
    assert "zeta_decay" in text and "free decays" in text


def test_bad_estimation_input():
    with pytest.raises(InputError, match=r"^nperseg: expected an integer from 8 to the number of "
                                         r"samples 100, got 1000"):
        estimate_frf(np.zeros(100), np.zeros(100), 10.0, 1000)
    with pytest.raises(InputError, match=r"^y: expected samples of shape \(100,\)"):
        estimate_frf(np.zeros(100), np.zeros(99), 10.0, 50)
    with pytest.raises(InputError, match=r"^x: expected a free decay with at least 4 extrema"):
        decay_estimate(np.linspace(0, 1, 50), np.exp(-np.linspace(0, 1, 50)))
    with pytest.raises(InputError, match=r"^settings: expected a ValidationSettings, got 3"):
        validate(small_box(), settings=3)
    with pytest.raises(InputError, match=r"^load_direction: expected one of 'x', 'y', 'z'"):
        validate(small_box(), settings=ValidationSettings(load_direction="rx"))
