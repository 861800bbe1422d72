"""Vibration severity (issue 49, item 3): the broadband RMS velocity of body points from the steady state, the
random response and the time history, each against a closed form, the zones and margins ``sixdof run`` prints in
its isolation summary, what results.h5 keeps, and the ``[severity]`` table's checks; and ``run`` printing and
storing everything ``sixdof modes`` prints."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sixdof.analysis.random import PSD, RandomInput
from sixdof.analysis.severity import (
    ZONE_BOUNDARIES_MM_S,
    SeveritySettings,
    band_limited_rms,
    harmonic_rms,
    psd_rms,
    severity_from_psd,
    zone_of,
)
from sixdof.errors import InputError
from sixdof.io.console import modes_text, run_text, statics_text
from sixdof.io.isolation_report import ISOLATION_SUMMARY
from sixdof.io.report import DECOUPLING, summary_markdown
from sixdof.io.scenario import parse_scenario
from sixdof.io.store import load_results, write_results
from systems import sdof
from test_run import SCENARIO

MASS, STIFFNESS, DAMPING = 120.0, 4.0e5, 700.0
F_N = math.sqrt(STIFFNESS / MASS) / (2 * math.pi)  # 9.19 Hz
FORCE, F_OP = 300.0, 40.0  # N along z at the CG, Hz

# Four equal mounts in the CG's plane, symmetric about x and y: z decouples (m z'' + c z' + k z = F sin(w t), k and
# c the mounts' sums along z), and a vertical harmonic force at the CG moves the body along z alone.
MOUNTS = "".join(f"""
[[mounts]]
name = "{name}"
position = [{x}, {y}, 0.0]
stiffness = [1e5, 1e5, {STIFFNESS / 4}]
damping = [50.0, 50.0, {DAMPING / 4}]
""" for name, x, y in (("fl", -0.3, -0.2), ("fr", 0.3, -0.2), ("rr", 0.3, 0.2), ("rl", -0.3, 0.2)))
SDOF_TOML = f"""
name = "sdof"
[body]
mass = {MASS}
inertia = [3.0, 4.0, 5.0]
{MOUNTS}
[[loads]]
name = "shaker"
point = [0.0, 0.0, 0.0]
force = [0.0, 0.0, {FORCE}]
signal = {{ kind = "harmonic", f_hz = {F_OP} }}
[[points]]
name = "top"
position = [0.0, 0.0, 0.5]
"""


def sdof_velocity_rms(f_hz: float) -> float:
    """RMS velocity [m/s] of the single DOF under ``FORCE`` at ``f_hz``: w F / |k - m w^2 + i w c| / sqrt(2)."""
    w = 2 * math.pi * f_hz
    return w * FORCE / abs(STIFFNESS - MASS * w**2 + 1j * w * DAMPING) / math.sqrt(2)


def severity_toml(**keys) -> str:
    lines = [f"{k} = {v!r}".replace("'", '"').replace("True", "true") for k, v in keys.items()]
    return "\n[severity]\n" + "\n".join(lines) + "\n"


def run_text_of(tmp_path, text):
    from sixdof.workflows.run import run

    path = tmp_path / "scenario.toml"
    path.write_text(text)
    return run(path)


# ------------------------------------------------------------------------------------------------------------
# The three answers, each against a closed form.
# ------------------------------------------------------------------------------------------------------------


def test_harmonic_rms_adds_the_mean_squares_of_the_frequencies_in_band():
    v = np.array([[3e-3, 0, 0], [0, 4e-3j, 0], [5e-3, 0, 0]])  # m/s phasors at 25, 100 and 2000 Hz
    rms = harmonic_rms([25.0, 100.0, 2000.0], v, (10.0, 1000.0))  # 2000 Hz is outside the band
    np.testing.assert_allclose(rms, [3e-3 / math.sqrt(2), 4e-3 / math.sqrt(2), 0.0], rtol=1e-15)
    both = harmonic_rms([25.0, 100.0], np.array([[3e-3], [4e-3]]), (10.0, 1000.0))
    assert both[0] == pytest.approx(5e-3 / math.sqrt(2), rel=1e-15)  # sqrt((3^2 + 4^2) / 2)


def test_a_flat_psd_integrates_to_its_level_times_the_bandwidth():
    f = np.geomspace(10.0, 1000.0, 301)
    assert psd_rms(f, np.full_like(f, 2.5e-8)) == pytest.approx(math.sqrt(2.5e-8 * 990.0), rel=1e-12)


def test_the_random_velocity_of_a_free_mass_under_a_flat_force_psd_is_the_closed_form():
    # A force PSD S0 on a mass without a mount along x: v = F / (i w m), so v_rms^2 = S0 / (4 pi^2 m^2) (1/f1 - 1/f2)
    # over the band (the PSD 1-2000 Hz, the band 10-1000 Hz: its edges added to the grid).
    system, s0 = sdof(MASS, STIFFNESS), 4.0
    f = np.geomspace(1.0, 2000.0, 2001)
    random = RandomInput(input="force", direction="x", point=(0.0, 0.0, 0.0),
                         psd=PSD(f_hz=(1.0, 2000.0), value=(s0, s0), unit="N^2/Hz"))
    settings = SeveritySettings(zones_mm_s=(1.0, 2.0, 3.0))
    found = severity_from_psd(settings, {"cg": np.zeros(3)}, system, random, f)
    exact = math.sqrt(s0 / (4 * math.pi**2 * MASS**2) * (1 / 10.0 - 1 / 1000.0))
    assert found.rms_velocity[0, 0] == pytest.approx(exact, rel=1e-6)
    np.testing.assert_allclose(found.band_hz, [10.0, 1000.0])
    assert found.source == "random"


def test_the_band_limited_rms_of_a_record_keeps_the_band_and_drops_the_rest():
    fs, t = 5000.0, np.arange(0.0, 4.0, 1 / 5000.0)
    inside, below, above = 2e-3 * np.sin(2 * np.pi * 80.0 * t), 5e-3 * np.sin(2 * np.pi * 1.0 * t), \
        1e-3 * np.sin(2 * np.pi * 2400.0 * t)
    rms, band = band_limited_rms(t, inside + below + above, (10.0, 1000.0), 1.0)
    assert band == (10.0, 1000.0)
    # 80 Hz at a gain of 1 within 1e-7 (order 4, forward and backward: (80/1000)^16, (10/80)^16); 1 Hz and 2.4 kHz
    # keep (1/10)^8 and (1000/2400)^8 (1e-3: 1e-6 of the mean square) of their amplitude.
    assert rms == pytest.approx(2e-3 / math.sqrt(2), rel=2e-6)
    _, top = band_limited_rms(t[::4], (inside + below)[::4], (10.0, 1000.0), 1.0)  # 1250 Hz: its Nyquist 625 Hz
    assert top == (10.0, fs / 8)


def test_the_steady_state_severity_of_a_single_dof_is_the_closed_form(tmp_path):
    results = run_text_of(tmp_path, SDOF_TOML + severity_toml(zones_mm_s=[1.0, 2.0, 4.5], directions=["z"]))
    severity = results.severity
    assert severity.source == "steady" and severity.points == ("top",)  # default: the [[points]]
    exact = sdof_velocity_rms(F_OP)
    assert severity.rms_velocity[0, 2] == pytest.approx(exact, rel=1e-12)
    assert severity.governing[0] == severity.rms_velocity[0, 2]
    assert severity.zones == (zone_of(1e3 * exact, (1.0, 2.0, 4.5)),)
    assert severity.margin[0] == pytest.approx(1 - 1e3 * exact / 2.0, rel=1e-12)


def test_the_random_severity_of_a_single_dof_is_the_integral_of_its_velocity_psd(tmp_path):
    from scipy.integrate import quad

    s0 = 50.0  # N^2/Hz along z at the CG, 2-2000 Hz
    text = SDOF_TOML.split("[[loads]]")[0] + f"""
[random]
input = "force"
direction = "z"
point = [0.0, 0.0, 0.0]
psd = {{ f_hz = [2.0, 2000.0], value = [{s0}, {s0}], unit = "N^2/Hz" }}
time_check = false
[[points]]
name = "top"
position = [0.0, 0.0, 0.5]
"""
    results = run_text_of(tmp_path, text + severity_toml(group=1, foundation="rigid"))
    severity = results.severity
    assert severity.source == "random" and severity.basis.endswith("group 1, rigid foundation")

    def velocity_psd(f):  # the single DOF's: w^2 S0 / |k - m w^2 + i w c|^2
        w = 2 * math.pi * f
        return w**2 * s0 / abs(STIFFNESS - MASS * w**2 + 1j * w * DAMPING) ** 2

    exact = math.sqrt(quad(velocity_psd, 10.0, 1000.0, points=[F_N], limit=200, epsabs=0, epsrel=1e-12)[0])
    assert severity.rms_velocity[0, 2] == pytest.approx(exact, rel=1e-6)
    assert "from the random response, its velocity PSD integrated over 10-1000 Hz" in " ".join(run_text(results).split())


@pytest.mark.long
def test_the_time_history_severity_of_a_single_dof_is_the_closed_form(tmp_path):
    text = SDOF_TOML + "[simulation]\nduration = 3.0\nsample_rate_hz = 4000.0\n"
    results = run_text_of(tmp_path, text + severity_toml(zones_mm_s=[1.0, 2.0, 4.5], source="time",
                                                          points=["fl"]))
    severity = results.severity
    assert severity.source == "time" and severity.window_s == pytest.approx((1.5, 3.0 - 0.3))
    # 1.5 s on, the switch-on transient at 9.2 Hz (zeta 0.016) is down to exp(-1.4) and the 10 Hz high-pass
    # leaves (9.2/10)^8 ... of it: the steady state's RMS to 1 %.
    assert severity.rms_velocity[0, 2] == pytest.approx(sdof_velocity_rms(F_OP), rel=1e-2)
    assert "from the time history band-passed to 10-1000 Hz (Butterworth, order 4, zero phase) over 1.5-2.7 s" \
        in " ".join(run_text(results).split())


# ------------------------------------------------------------------------------------------------------------
# Zones, text and file.
# ------------------------------------------------------------------------------------------------------------


def test_zones_and_the_standard_boundaries():
    boundaries = ZONE_BOUNDARIES_MM_S[(2, "rigid")]
    assert boundaries == (1.4, 2.8, 4.5)
    assert [zone_of(v, boundaries) for v in (0.5, 1.4, 2.0, 2.8, 4.49, 4.5, 30.0)] == list("ABBCCDD")
    assert SeveritySettings(group=1, foundation="flexible").boundaries_mm_s == (3.5, 7.1, 11.0)


@pytest.mark.long
def test_machine_unbalance_prints_and_stores_its_severity(tmp_path):
    from sixdof.workflows.run import run_scenario

    scenarios = Path(__file__).resolve().parents[1] / "scenarios"
    # What `sixdof run` does: the time response streamed into results.h5, which the sink finishes.
    results, folder = run_scenario(scenarios / "machine_unbalance.toml", tmp_path, progress=False, log=lambda *_: None)
    severity = results.severity
    assert severity.points == ("top_corner", "front_left", "rear_right")
    lines = run_text(results).splitlines()
    summary_end = lines.index(f"{DECOUPLING}:")
    start = next(i for i, line in enumerate(lines) if line.startswith("Vibration severity"))
    assert lines.index(f"{ISOLATION_SUMMARY}:") < start < summary_end < lines.index("Details and solver checks:")
    head = " ".join(lines[start:start + 4])
    assert "from the steady state, v_rms = sqrt(sum|v_k|^2/2)" in head and "group 2, flexible foundation" in head
    assert "A/B 2.3, B/C 4.5, C/D 7.1 mm/s" in head
    rows = {row[1].strip(): [c.strip() for c in row[2:-1]] for row in (line.split("|") for line in lines[start:summary_end])
            if len(row) > 2}
    for j, name in enumerate(severity.points):
        v = 1e3 * severity.rms_velocity[j]
        assert rows[name][:3] == [f"{x:.3g}" for x in v]
        assert rows[name][4].startswith(zone_of(v.max(), (2.3, 4.5, 7.1)))
        assert rows[name][5] == f"{100 * (1 - v.max() / 4.5):.0f} %"
    markdown = summary_markdown(results)
    assert "Vibration severity" in markdown
    assert "- 1: (x, ry)\n- 2: (y, rx)\n- 3: (z)\n- 4: (rz)" in markdown  # one list: the decoupled subsystems
    loaded = load_results(folder / "results.h5").severity
    assert loaded.points == severity.points and loaded.zones == severity.zones and loaded.source == "steady"
    np.testing.assert_array_equal(loaded.rms_velocity, severity.rms_velocity)
    np.testing.assert_array_equal(loaded.boundaries, severity.boundaries)


# ------------------------------------------------------------------------------------------------------------
# Bad input: one error naming the file and the field, before anything is computed.
# ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("keys", "field", "expected"), [
    ({"group": 3, "foundation": "rigid"}, "severity.group", "machine group 1"),
    ({"group": 1, "foundation": "soft"}, "severity.foundation", "'rigid' or 'flexible'"),
    ({"group": 1}, "severity.foundation", "group and foundation go together"),
    ({}, "severity.group", "or zones_mm_s"),
    ({"zones_mm_s": [2.0, 2.0, 3.0]}, "severity.zones_mm_s", "positive and increasing"),
    ({"zones_mm_s": [3.0, 2.0]}, "severity.zones_mm_s", "three zone boundaries"),
    ({"zones_mm_s": [1.0, 2.0, 3.0], "group": 2, "foundation": "rigid"}, "severity.zones_mm_s", "not both"),
    ({"group": 2, "foundation": "rigid", "points": ["top", "nowhere"]}, "severity.points[1]", "top, fl, fr, rr, rl"),
    ({"group": 2, "foundation": "rigid", "directions": ["x", "w"]}, "severity.directions", "body axes"),
    ({"group": 2, "foundation": "rigid", "source": "random"}, "severity.source", "a [random] table"),
    ({"group": 2, "foundation": "rigid", "source": "time"}, "severity.source", "[simulation]"),
    ({"group": 2, "foundation": "rigid", "band_hz": [100.0, 10.0]}, "severity.band_hz", "0 < low < high"),
    ({"group": 2, "foundation": "rigid", "speed": 3}, "severity.speed", ""),
])
def test_a_bad_severity_table_names_the_file_and_field(keys, field, expected):
    with pytest.raises(InputError) as caught:
        parse_scenario(SDOF_TOML + severity_toml(**keys), source="machine.toml")
    message = str(caught.value)
    assert message.startswith("machine.toml: ") and caught.value.field == field and expected in message


def test_a_time_severity_needs_a_record_long_and_fine_enough():
    text = SDOF_TOML + "[simulation]\nduration = 0.5\nsample_rate_hz = 4000.0\n"
    with pytest.raises(InputError, match="5 periods of 10 Hz") as caught:
        parse_scenario(text + severity_toml(zones_mm_s=[1, 2, 3], source="time", time_from_s=0.45), source="m.toml")
    assert caught.value.field == "severity.time_from_s"
    coarse = SDOF_TOML + "[simulation]\nduration = 2.0\nsample_rate_hz = 15.0\n"
    with pytest.raises(InputError, match="half the sample rate") as caught:
        parse_scenario(coarse + severity_toml(zones_mm_s=[1, 2, 3], source="time"), source="m.toml")
    assert caught.value.field == "severity.band_hz"


# ------------------------------------------------------------------------------------------------------------
# `sixdof run` prints and stores what `sixdof modes` prints.
# ------------------------------------------------------------------------------------------------------------


def test_run_prints_and_stores_everything_modes_prints(tmp_path):
    from sixdof.workflows.modes import modal_run

    path = tmp_path / "small.toml"
    path.write_text(SCENARIO.split("[[loads]]")[0] + "\n[design]\ntorque_axis = [1.0, 0.0, 0.0]\n")
    modal = modal_run(path)
    results = run_text_of(tmp_path, path.read_text())
    printed = run_text(results)
    blocks = [b for b in modes_text(modal).split("\n\n") if b.strip()]
    assert any("Torque-roll axis" in b for b in blocks) and any("Kinetic energy distribution" in b for b in blocks)
    for block in [*blocks, statics_text(modal.results, modal.no_statics).strip()]:
        assert block.strip() in printed, block
    # In the engineering section: after the isolation summary, before the solver checks.
    assert printed.index(f"{ISOLATION_SUMMARY}:") < printed.index(f"{DECOUPLING}:") \
        < printed.index("Torque-roll axis") < printed.index("Details and solver checks:")
    markdown = summary_markdown(results)
    assert f"## {DECOUPLING}" in markdown and "Torque-roll axis (torque about [1, 0, 0])" in markdown
    write_results(tmp_path / "results.h5", results)
    stored = load_results(tmp_path / "results.h5").design
    for name in ("decoupling_percent", "torque_roll_axis", "decoupling_tra_percent", "elastic_axes",
                 "principal_stiffness"):
        np.testing.assert_array_equal(getattr(stored, name), getattr(modal.metrics, name))
    assert stored.roll_mode == modal.metrics.roll_mode and stored.elastic_center is None
    assert stored.roll_mode_tra_angle_deg == modal.metrics.roll_mode_tra_angle_deg
