"""Mount checks of a run: total (static + dynamic) loads and deflections, tension, and limits.

A body on four symmetric, undamped mounts moves only vertically under a load at its CG: each mount
carries ``mg/4`` at rest and a quarter of the spring force of the single-DOF oscillator
``m z'' + 4 k z = F(t)``, whose response from rest is known in closed form.
"""

import numpy as np
import pytest

from sixdof import (
    Excitation,
    Harmonic,
    Load,
    MountLimitWarning,
    SimulationSettings,
    Step,
    mount_check,
    mount_forces,
    parse_scenario,
    simulate,
)
from sixdof.analysis.mountcheck import merge_mount_checks
from sixdof.analysis.statics import STANDARD_GRAVITY, gravity_statics
from sixdof.cli import main
from sixdof.errors import ScenarioError
from sixdof.io.store import load_results, load_tree
from sixdof.results import time_slice
from sixdof.workflows.run import run_scenario
from systems import four_mount
from tolerances import RTOL_DIRECT_EXACT, RTOL_STATICS

MASS = 500.0
PERIOD = 0.04  # s: the vertical natural period, on the output grid so that peaks fall on samples
K_W = MASS * (2 * np.pi / PERIOD) ** 2 / 4  # N/m per mount along w (vertical)
WEIGHT = MASS * STANDARD_GRAVITY
SETTINGS = SimulationSettings(duration=0.1, sample_rate_hz=1000.0)


def body():
    return four_mount(m=MASS, k=(2e5, 3e5, K_W))


def run(load_z: float, signal):
    system = body()
    loads = (Load("l", [0, 0, 0], force=[0, 0, load_z], signal=signal),) if load_z else ()
    response = simulate(system, Excitation(loads=loads), SETTINGS)
    statics = gravity_statics(system)
    return system, response, mount_check(system, mount_forces(system, response), response.t, statics)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_each_mount_carries_a_quarter_of_the_weight_in_compression():
    statics = gravity_statics(body())
    assert statics.support == pytest.approx(np.full(4, WEIGHT / 4), rel=RTOL_STATICS)
    # the load on a mount is the body pushing it down: -z in body axes, -w along its axes
    assert statics.mount_forces[:, 2] == pytest.approx(np.full(4, -WEIGHT / 4), rel=RTOL_STATICS)
    assert statics.mount_forces_local[:, 2] == pytest.approx(np.full(4, -WEIGHT / 4), rel=RTOL_STATICS)
    _, response, check = run(0.0, None)  # at rest: no load
    assert np.allclose(check.compression, WEIGHT / 4, rtol=RTOL_STATICS, atol=0)
    assert np.allclose(check.deflection[:, :, 2], -WEIGHT / (4 * K_W), rtol=RTOL_STATICS, atol=0)
    assert check.in_tension == () and np.all(np.isnan(check.tension_start_t))
    assert check.violations == ()


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_harmonic_load_adds_to_the_preload_with_the_right_sign():
    f_hz, amplitude = 11.0, 800.0
    system, response, check = run(amplitude, Harmonic(f_hz=f_hz))
    t, w, wn = response.t, 2 * np.pi * f_hz, 2 * np.pi / PERIOD
    r = w / wn
    # undamped oscillator from rest under F sin(w t): z = F / K / (1 - r^2) (sin w t - r sin wn t)
    z = amplitude / (4 * K_W) / (1 - r**2) * (np.sin(w * t) - r * np.sin(wn * t))
    expected = WEIGHT / 4 - K_W * z  # lifting the body (z > 0) unloads the mounts
    scale = K_W * np.abs(z).max()
    for j in range(4):
        assert np.allclose(check.compression[j], expected, rtol=0, atol=RTOL_DIRECT_EXACT * scale)
        assert np.allclose(check.force[j, :, 2], -expected, rtol=0, atol=RTOL_DIRECT_EXACT * scale)
        assert np.allclose(check.deflection[j, :, 2], z - WEIGHT / (4 * K_W), rtol=0,
                           atol=RTOL_DIRECT_EXACT * np.abs(z).max())
    k = np.argmin(expected)
    assert check.min_compression == pytest.approx(np.full(4, expected[k]), abs=RTOL_DIRECT_EXACT * scale)
    assert np.all(check.min_compression_t == t[k])
    assert check.max_compression == pytest.approx(np.full(4, expected.max()), abs=RTOL_DIRECT_EXACT * scale)
    assert check.in_tension == ()  # 800 N never outweighs the 4.9 kN weight
    # without the static preload (no equilibrium under gravity) the dynamic part alone is checked
    dynamic = mount_check(system, mount_forces(system, response), t, None)
    assert not dynamic.preload and check.preload
    assert np.allclose(dynamic.compression, -K_W * z, rtol=0, atol=RTOL_DIRECT_EXACT * scale)
    assert dynamic.in_tension == ("m0", "m1", "m2", "m3")


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_lift_off_is_reported_with_its_peak_and_times():
    # A step of twice the weight upward: z = F / K (1 - cos wn t), so each mount's compression
    # mg/4 - F/4 (1 - cos wn t) crosses zero at wn t = pi/3 and bottoms out at -3 mg / 4 at t = PERIOD / 2.
    _, response, check = run(2 * WEIGHT, Step(start=0.0))
    t = response.t
    expected = WEIGHT / 4 - WEIGHT / 2 * (1 - np.cos(2 * np.pi * t / PERIOD))
    assert check.in_tension == ("m0", "m1", "m2", "m3")
    assert check.min_compression == pytest.approx(np.full(4, -0.75 * WEIGHT), rel=RTOL_DIRECT_EXACT)
    assert check.min_compression_t == pytest.approx(np.full(4, PERIOD / 2), abs=1e-12)
    assert check.tension_start_t == pytest.approx(np.full(4, t[np.argmax(expected < 0)]), abs=1e-12)
    assert t[np.argmax(expected < 0)] == pytest.approx(0.007)  # the first sample after PERIOD / 6
    assert check.violations == ()  # tension allowed by default: reported, not warned about


LIFTED = f"""
name = "lifted"
description = "a pump lifted off its four mounts by a shock"

[body]
mass = {MASS!r}
inertia = [40.0, 60.0, 80.0]

[[mounts]]
name = "m0"
position = [-0.4, -0.6, -0.3]
stiffness = [2e5, 3e5, {K_W!r}]
allow_tension = false
max_deflection = [0.01, 0.01, 0.001]

[[mounts]]
name = "m1"
position = [0.4, -0.6, -0.3]
stiffness = [2e5, 3e5, {K_W!r}]
max_deflection = 0.01

[[mounts]]
name = "m2"
position = [0.4, 0.6, -0.3]
stiffness = [2e5, 3e5, {K_W!r}]

[[mounts]]
name = "m3"
position = [-0.4, 0.6, -0.3]
stiffness = [2e5, 3e5, {K_W!r}]

[[loads]]
name = "shock"
point = [0.0, 0.0, 0.0]
force = [0.0, 0.0, {2 * WEIGHT!r}]
signal = {{ kind = "step", start = 0.0 }}

[simulation]
duration = 0.1
sample_rate_hz = 1000.0
"""


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_limits_turn_into_one_warning_per_mount(tmp_path):
    scenario = parse_scenario(LIFTED, "lifted.toml")
    # m0: tension not allowed, and w beyond 1 mm: the deflection from the unloaded mount is
    # z - mg / 4k = F / 4k (1 - cos wn t) - mg / 4k, at most 3 mg / 4k = 1.19 mm at t = PERIOD / 2
    with pytest.warns(MountLimitWarning) as caught:
        results, folder = run_scenario(scenario, tmp_path, progress=False)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1
    t = results.response.t
    deflection = WEIGHT / (2 * K_W) * (1 - np.cos(2 * np.pi * t / PERIOD)) - WEIGHT / (4 * K_W)
    first_over = t[np.argmax(deflection > 1e-3)]
    assert messages[0] == (
        f"mount 'm0': deflection along w {3 * WEIGHT / (4 * K_W) * 1e3:.4g} mm at t = 0.02 s, beyond its "
        f"max_deflection 1 mm (first at t = {first_over:.4g} s); in tension (allow_tension = false): "
        f"{0.75 * WEIGHT / 1e3:.4g} kN at t = 0.02 s (first at t = 0.007 s)")
    assert results.mount_check.violations == tuple(messages)
    assert messages[0] in results.notes
    summary = (folder / "summary.md").read_text()
    assert "### Mount checks" in summary and "> 0 compression, < 0 tension (uplift)" in summary
    assert f"TENSION {0.75 * WEIGHT / 1e3:.4g} kN, from t = 0.007 s" in summary
    assert f"- {messages[0]}" in summary  # in the summary's warnings
    # the file: new names beside the old ones, read back as the same object
    tree = load_tree(folder / "results.h5")
    assert np.array_equal(tree.array("time/mount_check/compression"), results.mount_check.compression)
    assert tree.datasets["time/mount_check/compression"].units == "N"
    assert tree.array("model/mount_max_deflection")[0] == pytest.approx([0.01, 0.01, 0.001])
    assert list(tree.array("model/mount_allow_tension")) == [0, 1, 1, 1]
    loaded = load_results(folder / "results.h5")
    assert np.array_equal(loaded.mount_check.min_compression, results.mount_check.min_compression)
    assert loaded.mount_check.violations == results.mount_check.violations
    assert [m.allow_tension for m in loaded.system.mounts] == [False, True, True, True]


@pytest.mark.slow  # 2 s on the 2-core machine
def test_cli_prints_the_mount_checks_and_warns(tmp_path, capsys):
    path = tmp_path / "lifted.toml"
    path.write_text(LIFTED)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    out, err = capsys.readouterr()
    assert "Mount checks:" in out and f"TENSION {0.75 * WEIGHT / 1e3:.4g} kN, from t = 0.007 s" in out
    warning = [line for line in err.splitlines() if line.startswith("WARNING: mount 'm0'")]
    assert len(warning) == 1 and "allow_tension = false" in warning[0]


@pytest.mark.parametrize("line, match", [
    ('max_deflection = "0.01"', r"max_deflection: expected a deflection limit in m > 0 \(inf: none\), or 3 of them "
                                r"for the axes u, v, w, got '0.01'"),
    ("max_deflection = true", r"mounts\[0\]\.max_deflection: expected a deflection limit .* got True"),
    ("max_deflection = [0.01, 0.02]", r"mounts\[0\]\.max_deflection: expected .* got \[0.01, 0.02\]"),
    ("max_deflection = -0.01", r"mounts\[0\]\.max_deflection: expected .* got -0.01"),
    ("max_deflection = 0", r"mounts\[0\]\.max_deflection: expected .* got 0"),
    ("max_deflection = nan", r"mounts\[0\]\.max_deflection: expected .* got nan"),
    ('max_deflection = [0.01, "a", 0.01]', r"mounts\[0\]\.max_deflection: expected .* got \[0.01, 'a', 0.01\]"),
    ("allow_tension = 1", r"mounts\[0\]\.allow_tension: expected true or false, got 1"),
    ('allow_tension = "no"', r"mounts\[0\]\.allow_tension: expected true or false, got 'no'"),
    ("max_deflexion = 0.01", r"mounts\[0\]\.max_deflexion: expected one of the keys .*; did you mean "
                             r"'max_deflection'\?"),
    ("allow_tensile = false", r"did you mean 'allow_tension'\?"),
])
def test_bad_limits_are_named(line, match):
    text = LIFTED.replace("allow_tension = false\nmax_deflection = [0.01, 0.01, 0.001]", line)
    with pytest.raises(ScenarioError, match=r"^lifted\.toml: .*" + match):
        parse_scenario(text, "lifted.toml")


def test_limits_parse_per_axis_and_scalar():
    mounts = parse_scenario(LIFTED.replace("max_deflection = 0.01", "max_deflection = [inf, 0.01, 0.003]"),
                            "lifted.toml").system.mounts
    assert list(mounts[1].max_deflection) == [np.inf, 0.01, 0.003]
    assert np.all(np.isinf(mounts[2].max_deflection)) and mounts[2].allow_tension is True
    assert mounts[0].allow_tension is False


def test_windows_merge_to_the_whole_run_check():
    scenario = parse_scenario(LIFTED, "lifted.toml")
    system = scenario.system
    response = simulate(system, scenario.excitation, scenario.simulation)
    forces, statics = mount_forces(system, response), gravity_statics(system)
    whole = mount_check(system, forces, response.t, statics)
    windows = [mount_check(system, time_slice(forces, part), response.t[part], statics)
               for part in (slice(0, 5), slice(5, 21), slice(21, 60), slice(60, None))]
    merged = merge_mount_checks(system, windows)
    assert merged.violations == whole.violations and len(whole.violations) == 1
    for name in ("peak_deflection", "peak_deflection_t", "peak_force", "peak_force_t", "max_compression",
                 "max_compression_t", "min_compression", "min_compression_t", "tension_start_t", "over_limit_t"):
        np.testing.assert_array_equal(getattr(merged, name), getattr(whole, name), err_msg=name)


@pytest.mark.parametrize(("mass", "unit"), [(5.0, "N"), (500.0, "kN")])
def test_the_statics_table_shows_a_light_body_s_loads_in_newtons(mass, unit):
    """One unit per table, the one that shows its largest value from 1 up: a 5 kg box's 12 N per mount read
    0.012 kN; a 500 kg body's stay in kN."""
    from sixdof.io.report import statics_table
    from systems import four_mount

    system = four_mount(m=mass)
    statics = gravity_statics(system)
    text = statics_table(statics, system)
    assert f"Fz [{unit}]" in text and f"carried [{unit}]" in text
    carried = [float(line.split("|")[5]) for line in text.splitlines() if line.startswith("| m") and "mount" not in line]
    weight = mass * STANDARD_GRAVITY / (1.0 if unit == "N" else 1e3)
    assert sum(carried) == pytest.approx(weight, rel=1e-3) and len(carried) == 4
