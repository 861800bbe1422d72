"""Loss factors in the time domain (issue 45): by default the time paths carry each mount's loss factor as a
causal Maxwell model checked at every natural and operating frequency, the frequency paths keep k (1 + i eta)."""

import dataclasses
import math

import numpy as np
import pytest

from sixdof.io.scenario import parse_scenario
from sixdof.model.viscoelastic import (
    LOSS_FACTOR_TARGET,
    LOSS_MODULUS_TARGET,
    constant_loss_model,
    loss_fit_misses,
)
from sixdof.workflows.prepare import prepare

RPM = 1480.0  # the fan's operating speed: 24.7 Hz, above its mounts' 5-13 Hz modes

FAN = """
name = "fan"
[body]
mass = 450.0
inertia = [40.0, 55.0, 60.0]
{mounts}
[[loads]]
kind = "unbalance"
name = "impeller"
point = [0.0, 0.0, 0.3]
unbalance = 0.02
speed_rpm = {rpm}
axis = [0.0, 1.0, 0.0]
{damping}
[simulation]
duration = 6.0
sample_rate_hz = 400.0
"""


def mounts(eta: float) -> str:
    """Four inclined rubber mounts (40 deg, in the x-z plane), ``eta`` along every axis."""
    text = ""
    for x, y in ((0.6, 0.45), (-0.6, 0.45), (-0.6, -0.45), (0.6, -0.45)):
        s, c = math.sin(math.radians(40.0)) * np.sign(x), math.cos(math.radians(40.0))
        text += (f'[[mounts]]\nname = "m{len(text)}"\nposition = [{x}, {y}, -0.25]\nstiffness = [1.5e5, 1.5e5, 6e5]\n'
                 f"loss_factor = [{eta}, {eta}, {eta}]\n"
                 f"axes = [[{c:.6f}, 0.0, {s:.6f}], [0.0, 1.0, 0.0], [{-s:.6f}, 0.0, {c:.6f}]]\n")
    return text


def fan(tmp_path, eta=0.1, damping=""):
    return prepare(parse_scenario(FAN.format(mounts=mounts(eta), rpm=RPM, damping=damping), source="fan.toml",
                                  base_dir=tmp_path))


def closed_form(fit, f_hz):
    """``k0 + sum k_i i w tau_i / (1 + i w tau_i)`` at ``f_hz``, written out."""
    w = 2 * np.pi * np.asarray(f_hz, dtype=float)
    return fit.long_term + sum(k * 1j * w * t / (1 + 1j * w * t) for k, t in zip(fit.stiffness, fit.tau))


def test_the_default_is_causal_in_time_and_exact_in_frequency(tmp_path):
    sc = fan(tmp_path)
    assert sc.loss_factor_model == "causal"
    np.testing.assert_array_equal(sc.system.loss_factors, 0.1)  # the frequency paths: k (1 + i eta) as given
    assert not sc.system.maxwell and not np.any(sc.time_system.loss_factors) and sc.time_system.maxwell
    fits = sc.causal_loss_fits
    assert len(fits) == 12 and {f.source for f in fits} == {"loss factor 0.1"}
    natural = sc.system.modes.frequency_hz
    checked = np.sort(np.concatenate([natural, [RPM / 60.0]]))
    for fit in fits:  # checked at every natural frequency and the operating frequency, against the closed form
        np.testing.assert_allclose(fit.f_hz, checked, rtol=1e-12)
        k = closed_form(fit, checked)
        target = fit.storage[0] * (1 + 0.1j)
        assert np.max(np.abs(np.abs(k) / abs(target) - 1)) <= LOSS_MODULUS_TARGET
        assert np.max(np.abs(k.imag / k.real / 0.1 - 1)) <= LOSS_FACTOR_TARGET
        assert fit.modulus_error == pytest.approx(np.max(np.abs(np.abs(k) / abs(target) - 1)), rel=1e-9)
    # The time system's stiffness is the long-term one, axis by axis.
    m = sc.time_system.mounts[0]
    assert m.stiffness[0] == fits[0].long_term < 1.5e5 and m.stiffness[2] == fits[2].long_term < 6e5


def test_frfs_keep_the_exact_complex_stiffness(tmp_path):
    from sixdof.analysis.frf import receptance

    sc = fan(tmp_path)
    system = sc.system
    lossy = dataclasses.replace(system, mounts=tuple(dataclasses.replace(m, stiffness=m.stiffness * m.loss_factor,
                                                                         loss_factor=np.zeros(3))
                                                     for m in system.mounts))
    K, M, K_eta = np.asarray(system.K), np.asarray(system.M), np.asarray(lossy.K)
    f_hz = np.array([3.0, 7.5, 24.67, 60.0])
    H = receptance(system, f_hz).H
    for f, h in zip(f_hz, H):
        w = 2 * np.pi * f
        np.testing.assert_allclose(h, np.linalg.inv(K - w**2 * M + 1j * K_eta), rtol=1e-9,
                                   atol=1e-12 * np.abs(h).max())


@pytest.mark.parametrize("eta", [0.1, 0.2, 0.3])
@pytest.mark.parametrize("spread", [20.0, 100.0])
def test_wide_spreads_miss_the_targets_and_say_so(eta, spread):
    check = np.geomspace(2.0, 2.0 * spread, 6)
    fit = dataclasses.replace(constant_loss_model(1e6, eta, (1.0, 4.0 * spread), check_hz=check),
                              name="a u", source=f"loss factor {eta:g}")
    k = closed_form(fit, check)
    modulus, loss = np.abs(np.abs(k) / (1e6 * math.hypot(1, eta)) - 1), np.abs(k.imag / k.real / eta - 1)
    assert fit.modulus_error == pytest.approx(modulus.max(), rel=1e-9)
    assert fit.loss_factor_error == pytest.approx(loss.max(), rel=1e-9)
    # Kramers-Kronig: over the span |K| must change by about span^(2 eta / pi): beyond the targets here.
    assert modulus.max() > LOSS_MODULUS_TARGET or loss.max() > LOSS_FACTOR_TARGET
    # ... but far better than the pure spring's 100 % in loss factor or the fractional spring's |K|.
    rise = spread ** (2 * math.atan(eta) / math.pi)
    assert modulus.max() < (rise - 1) / (rise + 1) and loss.max() < 0.5
    said = loss_fit_misses([fit])
    assert len(said) == 1 and said[0].startswith(f"the causal Maxwell model of loss factor {eta:g} (a u)")
    assert f"by up to {100 * fit.modulus_error:.3g} % in |K*|" in said[0]
    assert f"and {100 * fit.loss_factor_error:.3g} % in loss factor" in said[0]


@pytest.mark.parametrize("eta", [0.1, 0.2])
def test_narrow_spreads_meet_the_targets(eta):
    check = np.geomspace(5.0, 5.0 * (4.0 if eta == 0.1 else 2.0), 6)
    fit = constant_loss_model(1e6, eta, (2.5, 50.0), check_hz=check)
    k = closed_form(fit, check)
    assert np.max(np.abs(np.abs(k) / (1e6 * math.hypot(1, eta)) - 1)) <= LOSS_MODULUS_TARGET
    assert np.max(np.abs(k.imag / k.real / eta - 1)) <= LOSS_FACTOR_TARGET
    assert not loss_fit_misses([dataclasses.replace(fit, source=f"loss factor {eta:g}")])


def late_over_steady(response, steady, t_late=5.0):
    """Late-time peak of each translation over the exact steady-state amplitude (the DOFs that move)."""
    late = np.max(np.abs(response.q[response.t >= t_late, :3]), axis=0)
    amplitude = np.abs(steady.q[0, :3])
    moving = amplitude > 1e-3 * amplitude.max()
    return late[moving] / amplitude[moving]


@pytest.mark.long  # over 10 s on the 2-core machine
def test_the_fan_s_switch_on_transient_decays_to_the_exact_steady_state(tmp_path):
    from sixdof.analysis.validity import RangeWarning
    from sixdof.workflows.run import run_scenario

    sc = fan(tmp_path)
    lines = []
    results, folder = run_scenario(sc, tmp_path / "out", progress=False, log=lines.append)
    steady = results.steady_state  # k (1 + i eta) exactly
    ratio = late_over_steady(results.response, steady)
    assert np.all(np.abs(ratio - 1) < 0.03), ratio  # the direct solve, 5-6 s after switch-on
    assert np.all(np.abs(late_over_steady(results.superposition, steady) - 1) < 0.03)
    assert results.agreement.ok
    # Statics with the long-term stiffness, said once, in the summary and in results.h5.
    weight = np.array([0.0, 0.0, -450.0 * 9.80665, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(results.statics.q, np.linalg.solve(np.asarray(sc.time_system.K), weight),
                               rtol=1e-9, atol=1e-15)
    said = [line for line in lines if line.startswith("statics: with the long-term")]
    assert len(said) == 1 and "worst errors at the natural and operating frequencies" in said[0]
    assert said[0] in (folder / "summary.md").read_text()
    from sixdof.io.store import load_results

    stored = load_results(folder / "results.h5")
    assert stored.loss_factor_model == "causal" and stored.loss_factor_statics == said[0]
    assert stored.time_system is not None and len(stored.time_system.maxwell) == len(sc.time_system.maxwell)

    hysteretic = fan(tmp_path, damping='[damping]\nloss_factor_model = "hysteretic"')
    with pytest.warns(RangeWarning, match=r'loss_factor_model = "hysteretic": the time paths .* leave out the loss '
                                          r"factors of mount\(s\)"):
        before, _ = run_scenario(hysteretic, tmp_path / "before", progress=False, log=lambda *a: None)
    assert np.max(late_over_steady(before.response, before.steady_state)) > 1.3  # never decays
