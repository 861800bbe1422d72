"""The random response checked against a time history (issue 19, point 2): the cubic Hermite table the record
is handed over in, the synthesized record against its own Fourier series, the statistical errors against the
scatter of many records, and the check passing for right models and failing for a wrong one."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sixdof import InputError
from sixdof.analysis import random as random_module
from sixdof.analysis.random import PSD, RandomInput, TimeCheckSettings
from sixdof.excitation.signals import Table
from sixdof.validation import random_time
from sixdof.validation.random_time import (
    FAIL,
    PASS,
    Welch,
    fine_grid,
    octave_bands,
    random_time_check,
    record_error,
    sidak_limit,
    synthesize,
)
from systems import sdof, skewed_box, small_box
from tolerances import RTOL_TIME_CHECK_RMS


@pytest.mark.long  # over 10 s on the 2-core machine
def test_a_table_with_slopes_is_a_cubic_hermite_spline():
    t = np.array([0.0, 0.3, 0.5, 1.2, 2.0])
    cubic = lambda x: 1 + 2 * x - 3 * x**2 + 0.7 * x**3  # noqa: E731
    slope = lambda x: 2 - 6 * x + 2.1 * x**2  # noqa: E731
    table = Table(t=t, values=cubic(t), slopes=slope(t))
    x = np.linspace(0.0, 1.999, 97)
    np.testing.assert_allclose(table(x), cubic(x), rtol=0, atol=1e-13)  # exact for a cubic
    np.testing.assert_allclose(table.derivative(x), slope(x), rtol=0, atol=1e-12)
    assert table.breakpoints == (0.0, 2.0)  # value and slope continuous at the inner knots
    assert np.all(np.asarray(table([-0.5, 2.0, 3.0])) == 0.0)  # zero outside, right-continuous at the end
    wavy = Table(t=t, values=np.sin(t), slopes=np.cos(t))  # any data: continuous value and slope at a knot
    for knot in t[1:-1]:
        left, right = np.asarray(wavy([knot - 1e-9, knot + 1e-9]))
        assert abs(right - left) < 1e-8
        d_left, d_right = np.asarray(wavy.derivative(np.array([knot - 1e-9, knot + 1e-9])))
        assert abs(d_right - d_left) < 1e-6
    with pytest.raises(InputError, match="slopes: expected 5 finite slopes in 1/s"):
        Table(t=t, values=cubic(t), slopes=[1.0, 2.0])


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_the_synthesized_record_is_the_fourier_series_of_its_psd():
    psd = PSD(f_hz=[10.0, 40.0, 100.0], value=[0.5, 2.0, 1.0], unit="(m/s^2)^2/Hz")
    record = synthesize(psd, 4.0, seed=3)
    rate = 1.0 / (record.t[1] - record.t[0])
    assert rate == pytest.approx(800.0)  # 8 knots per period of 100 Hz
    values = np.asarray(record.values[:-1])
    n = values.size
    coefficients = 2 * np.fft.rfft(values) / n
    f = np.arange(coefficients.size) * rate / n
    assert np.all(coefficients[(f < 10.0) | (f > 100.0)] == pytest.approx(0.0, abs=1e-12))  # nothing outside
    # Between the knots the spline follows the series within 1e-3 of the RMS (8 knots per period at the top).
    times = np.random.default_rng(0).uniform(0.0, n / rate, 400)
    series = np.real(np.exp(2j * np.pi * np.outer(times, f)) @ coefficients)
    rms = np.sqrt(np.mean(values**2))
    assert np.max(np.abs(np.asarray(record(times)) - series)) < 1e-3 * rms
    slopes = np.real(np.exp(2j * np.pi * np.outer(record.t[:-1], f)) @ (2j * np.pi * f * coefficients))
    np.testing.assert_allclose(record.slopes[:-1], slopes, rtol=0, atol=1e-9 * np.max(np.abs(slopes)))
    # Same seed, same record; another seed, another.
    np.testing.assert_array_equal(synthesize(psd, 4.0, seed=3).values, record.values)
    assert not np.allclose(synthesize(psd, 4.0, seed=4).values, record.values)


def test_the_statistical_errors_match_the_scatter_of_many_records():
    """z values of a correct answer are standard normal: over 300 records of a shaped input, the record mean
    square and the octave bands of its Welch PSD scatter as their stated errors say."""
    psd = PSD(f_hz=[10.0, 50.0, 200.0], value=[0.2, 1.0, 0.3], unit="(m/s^2)^2/Hz")
    duration = 4.0
    rate = 8 * 200.0
    welch = Welch(256, rate)  # 6.25 Hz bins
    f_fine, _ = fine_grid(10.0, 200.0, welch, bandwidth=np.inf)  # no resonance to resolve
    step = welch.bin_hz / 8
    s_fine = psd(f_fine)
    mean_square = np.sum(s_fine) * step
    bins = np.arange(welch.length // 2 + 1) * welch.bin_hz
    expected = welch.expected(f_fine, s_fine, bins)
    # The check's octave bands, the first and last cut at the PSD's edges (10 and 200 Hz), where the Welch
    # estimate has leakage that the expected side must have too (without it the top band was measured 10-20 %
    # low).
    bands = octave_bands(bins, 10.0, 200.0)
    assert [round(centre, 1) for centre, _ in bands] == [15.6, 31.2, 62.5, 125.0, 250.0]
    z_record, z_bands = [], []
    for seed in range(300):
        x = np.asarray(synthesize(psd, duration, seed).values[:-1])
        z_record.append((np.mean(x**2) / mean_square - 1) / record_error(s_fine, step, x.size / rate))
        f, estimate = welch.estimate(x)
        for _, inside in bands:
            z_bands.append((np.sum(estimate[inside]) / np.sum(expected[inside]) - 1)
                           / welch.band_error(expected[inside], x.size))
    z_bands = np.array(z_bands).reshape(-1, len(bands))
    for z in (np.array(z_record), *z_bands.T):  # the record, and each band on its own
        assert abs(np.mean(z)) < 0.2  # 300 values: the mean's own scatter is 0.06
        assert 0.85 < np.std(z) < 1.15


def test_the_limit_is_the_family_wise_three_sigma_rate():
    assert sidak_limit(1) == pytest.approx(3.0, abs=1e-3)  # one value: the two-sided 3-sigma bound
    assert sidak_limit(32) == pytest.approx(3.93, abs=0.01)
    assert sidak_limit(1000) > sidak_limit(32)


def _force_on_the_box(duration=None, seed=0):
    random = RandomInput(input="force", direction=[1.0, 1.0, 1.0], point=[0.2, -0.1, 0.15],
                         psd=PSD(f_hz=[2.0, 60.0], value=[400.0, 400.0], unit="N^2/Hz"))
    return random, TimeCheckSettings(duration=duration, seed=seed)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_a_coupled_box_under_a_random_force_agrees_with_its_time_history():
    system = small_box(zeta=0.04)  # every DOF coupled, modes 10 to 49 Hz
    random, settings = _force_on_the_box()
    check = random_time_check(system, random, {"corner": [0.3, 0.2, 0.1]}, settings)
    assert check.verdict == PASS
    judged = set(check.judged)
    # Every DOF, the point's three axes and every mount axis are excited and judged, and the bands.
    for dof in ("x", "y", "z", "rx", "ry", "rz"):
        assert {f"rms:q:{dof}", f"rms:qdd:{dof}"} <= judged
    assert {f"rms:point:corner:{a}" for a in "xyz"} <= judged
    assert sum(name.startswith("rms:mount_force:") for name in judged) == 9
    assert sum(name.startswith("band:") for name in judged) >= 30
    assert np.max(np.abs(check.z)) <= check.z_limit == pytest.approx(sidak_limit(len(judged)))
    # The default record: 32 segments of 4 bins per half-power bandwidth of the sharpest resonance (0.64 Hz).
    assert check.segment_s == pytest.approx(4 / 0.6387, rel=0.01) and check.averages >= 31
    assert check.sigma.min() > 0.005 and check.sigma.max() < 1.0
    assert not check.notes
    # Its RMS from the FRFs is the random response's, integrated apart (to 4e-8 here).
    response = random_module.random_response(system, random, {"corner": [0.3, 0.2, 0.1]})
    expected = {f"rms:{kind}:{dof}": values[i] for kind, values in (("q", response.q_rms), ("qdd", response.qdd_rms))
                for i, dof in enumerate(("x", "y", "z", "rx", "ry", "rz"))}
    expected |= {f"rms:point:corner:{a}": response.point_acceleration_rms[0, j] for j, a in enumerate("xyz")}
    shown = dict(zip(check.judged, check.frequency_rms))
    assert set(expected) <= set(shown)
    for name, value in expected.items():
        assert shown[name] == pytest.approx(value, rel=RTOL_TIME_CHECK_RMS), name


@pytest.mark.slow  # 4 s on the 2-core machine
def test_a_model_three_percent_too_stiff_fails_the_check(monkeypatch):
    """The FRF side computed for mounts 3 % stiffer (1.5 % in frequency) than the ones integrated."""
    system = small_box(zeta=0.04)
    random, settings = _force_on_the_box(duration=60.0)
    stiffer = dataclasses.replace(system, mounts=tuple(dataclasses.replace(m, stiffness=1.03 * np.asarray(m.stiffness))
                                                       for m in system.mounts))
    real = random_time.transfers
    monkeypatch.setattr(random_time, "transfers", lambda _system, *args, **kwargs: real(stiffer, *args, **kwargs))
    check = random_time_check(system, random, {}, settings)
    assert check.verdict == FAIL
    assert np.max(np.abs(check.z)) > check.z_limit


@pytest.mark.long  # over 10 s on the 2-core machine
def test_loss_factors_are_left_out_of_both_sides_and_said():
    system = skewed_box()  # loss factors on mounts a and c
    random = RandomInput(input="ground_acceleration", direction=[1.0, 0.5, 1.0],
                         psd=PSD(f_hz=[3.0, 80.0], value=[0.01, 0.01], unit="g^2/Hz"))
    check = random_time_check(system, random, {}, TimeCheckSettings(seed=1))
    assert check.verdict == PASS
    assert len(check.notes) == 1 and "loss factors of a, c" in check.notes[0]


def test_a_free_body_is_refused():
    random = RandomInput(input="force", direction="z", point=[0.0, 0.0, 0.0],
                         psd=PSD(f_hz=[2.0, 60.0], value=[1.0, 1.0], unit="N^2/Hz"))
    with pytest.raises(InputError, match="random.time_check: expected a system held in every DOF"):
        random_time_check(sdof(), random)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_the_check_is_stored_with_its_labels_and_read_back(tmp_path):
    """Also a file whose random response has points but no time history: the points' labels arrive after an
    array along them (they used to collide with the index scale made for it)."""
    import xarray as xr

    from sixdof.analysis.random import random_response
    from sixdof.io import store
    from sixdof.results import RunResults

    system = small_box(zeta=0.04)
    random, settings = _force_on_the_box(duration=30.0)
    points = {"corner": [0.3, 0.2, 0.1]}
    check = random_time_check(system, random, points, settings)
    response = dataclasses.replace(random_response(system, random, points), time_check=check)
    store.write_results(tmp_path / "r.h5", RunResults(name="box", system=system, random=response))
    back = store.load_results(tmp_path / "r.h5").random
    assert back.points == ("corner",) and back.time_check.judged == check.judged
    for name in ("z", "sigma", "frequency_rms", "time_rms", "f_hz", "qdd_welch", "point_expected"):
        np.testing.assert_array_equal(getattr(back.time_check, name), getattr(check, name))
    assert back.time_check.verdict == check.verdict and back.time_check.judged_units == check.judged_units
    tree = xr.open_datatree(tmp_path / "r.h5", engine="h5netcdf")
    coords = tree["random/time_check"].dataset.coords
    assert list(coords["point"].values) == ["corner"] and coords["judged"].values[0] == check.judged[0]
    np.testing.assert_array_equal(coords["welch_f_hz"].values, check.f_hz)


SCENARIO = "scenarios/electronics_box.toml"


@pytest.mark.parametrize(("line", "expected"), [
    ("", TimeCheckSettings()),
    ("time_check = false", None),
    ("time_check = true", TimeCheckSettings()),
    ("time_check = { duration = 5.0, seed = 2 }", TimeCheckSettings(duration=5.0, seed=2)),
])
def test_the_scenario_asks_for_the_check(line, expected):
    from pathlib import Path

    from sixdof.io.scenario import parse_scenario

    text = Path(SCENARIO).read_text().replace("[random]\n", f"[random]\n{line}\n")
    assert parse_scenario(text, "box.toml", "scenarios").random.time_check == expected


@pytest.mark.parametrize(("line", "message"), [
    ("time_check = { durations = 5.0 }", r"random\.time_check\.durations: expected one of the keys duration, seed"),
    ("time_check = { duration = -1.0 }", r"random\.time_check\.duration: expected a positive, finite duration in s"),
    ("time_check = { seed = 1.5 }", r"random\.time_check\.seed: expected an integer >= 0"),
    ('time_check = "yes"', r"random\.time_check: expected true, false or a table"),
])
def test_a_bad_time_check_is_one_clear_error(line, message):
    from pathlib import Path

    from sixdof.io.scenario import parse_scenario

    text = Path(SCENARIO).read_text().replace("[random]\n", f"[random]\n{line}\n")
    with pytest.raises(InputError, match=message):
        parse_scenario(text, "box.toml", "scenarios")


@pytest.mark.slow  # 4 s on the 2-core machine
def test_the_figure_shows_each_excited_acceleration_with_its_interval():
    from figures import frozen_tick_difference
    from sixdof import plots

    system = small_box(zeta=0.04)
    random, settings = _force_on_the_box(duration=30.0)
    check = random_time_check(system, random, {"corner": [0.3, 0.2, 0.1]}, settings)
    fig = plots.plot_random_check(check, name="box")
    shown = [ax for ax in fig.axes if ax.get_visible()]
    assert len(shown) == 6  # six excited DOFs and one point: at most six panels
    assert "box: random response against a 30 s time history: PASS" in fig._suptitle.get_text()
    assert shown[0].get_title().startswith("centre of gravity along x: ") and "grms; z-score " in shown[0].get_title()
    assert all(ax.get_xlabel() == "frequency f [Hz]" for ax in shown[-2:])
    assert all("acceleration PSD" in ax.get_ylabel() for ax in shown)
    assert "(rad/s²)²/Hz" in shown[3].get_ylabel()  # rotations in their own unit

    # Frozen ticks (what render() draws) give the same picture, pixel for pixel: the y tick marks over the
    # x grid line at the view's 2 Hz limit, blended in matplotlib's order (they were 3 levels off when drawn under it).
    assert frozen_tick_difference(lambda: plots.plot_random_check(check, name="box")).max() == 0


def test_a_record_too_long_for_memory_is_refused_before_it_is_made():
    random, _ = _force_on_the_box()
    with pytest.raises(InputError, match=r"random\.time_check\.duration: expected a record that fits in this "
                                         r"machine's .* GiB of memory, got 1e\+07 s at 480 Hz"):
        random_time_check(small_box(), random, {}, TimeCheckSettings(duration=1e7))


def test_a_record_too_short_for_the_resolution_is_refused():
    """Bins wider than a quarter of the sharpest resonance's half-power band would make the band errors
    too small (measured: z scattered 1.2-1.5 times wider than stated): such a record is refused."""
    random, _ = _force_on_the_box()
    with pytest.raises(InputError, match=r"random\.time_check\.duration: expected at least 28\.1\d s: 8 Welch "
                                         r"segments of 6\.26\d s, 4 bins per half-power bandwidth"):
        random_time_check(small_box(zeta=0.04), random, {}, TimeCheckSettings(duration=20.0))


def test_a_hermite_table_evaluates_under_jit_as_a_constant():
    import jax

    table = Table(t=np.array([0.0, 1.0, 2.0]), values=np.array([0.0, 1.0, 0.0]), slopes=np.array([1.0, 0.0, -1.0]))
    assert float(jax.jit(lambda t: table(t))(0.5)) == pytest.approx(float(table(0.5)), abs=1e-15)


def test_z_is_the_normal_equivalent_of_a_chi_square_ratio():
    from scipy.stats import chi2, norm

    from sixdof.validation.random_time import z_score

    sigma = 0.18  # nu = 2 / sigma^2 = 61.7 degrees of freedom
    nu = 2 / sigma**2
    for p in (1e-4, 0.01, 0.5, 0.99, 1 - 1e-4):
        assert float(z_score(chi2.ppf(p, nu) / nu, sigma)) == pytest.approx(norm.ppf(p), abs=0.02)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_the_causal_models_of_the_loss_factors_are_carried_on_both_sides():
    # The time model of a run (loss factors as their causal Maxwell models): the record is damped by them and the
    # FRF side is that model's; nothing is left out, and the check still passes.
    from sixdof.model.viscoelastic import causal_loss_factors

    system = skewed_box()  # loss factors on mounts a and c
    timed, _ = causal_loss_factors(system)
    random = RandomInput(input="ground_acceleration", direction=[1.0, 0.5, 1.0],
                         psd=PSD(f_hz=[3.0, 80.0], value=[0.01, 0.01], unit="g^2/Hz"))
    check = random_time_check(timed, random, {}, TimeCheckSettings(seed=1))
    assert check.verdict == PASS and not check.notes
    # The loss factors' damping is there: the resonant responses are below those of the model without them.
    plain = random_time_check(system, random, {}, TimeCheckSettings(seed=1))
    shown, left_out = dict(zip(check.judged, check.frequency_rms)), dict(zip(plain.judged, plain.frequency_rms))
    assert all(shown[name] < left_out[name] for name in shown if name.startswith("rms:q:") and name in left_out)
