"""Magnitudes that look like a slip of units are said, with the numbers and the likely slip."""

import re
from pathlib import Path

import numpy as np
import pytest

from sixdof.analysis.validity import (
    DENSITY_RANGE,
    INERTIA_BOX_RATIO,
    REACH_RATIO,
    UNBALANCE_WEIGHT_RATIO,
    implausible_inputs,
)
from sixdof.cli import main
from sixdof.io.scenario import load_scenario, parse_scenario
from sixdof.workflows.prepare import prepare

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
MACHINE = (SCENARIOS / "machine_unbalance.toml").read_text()
# The machine on its first mount alone ([severity] then names only the points and that mount).
ONE_MOUNT = (MACHINE.split('[[mounts]]\nname = "front_right"')[0] + MACHINE[MACHINE.index("[[loads]]"):]).replace(
    'points = ["top_corner", "front_left", "rear_right"]', 'points = ["top_corner", "front_left"]')
CORNERS = ("[-0.5, -0.35, -0.45]", "[0.5, -0.35, -0.45]", "[0.5, 0.35, -0.45]", "[-0.5, 0.35, -0.45]")


def scenario(text: str):
    return parse_scenario(text, "slip.toml", SCENARIOS)


def messages(text: str) -> list[str]:
    s = scenario(text)
    return implausible_inputs(s.system, s.excitation, {p.name: p.position for p in s.points})


@pytest.mark.parametrize("path", sorted(SCENARIOS.glob("*.toml")), ids=lambda p: p.stem)
def test_the_bundled_scenarios_are_plausible(path):
    s = prepare(load_scenario(path))
    assert implausible_inputs(s.system, s.excitation, {p.name: p.position for p in s.points}) == []


def test_a_mass_in_tonnes_is_told_by_the_inertia_and_dimensions():
    (message,) = messages(MACHINE.replace("mass = 500.0", "mass = 0.5"))
    # The uniform box of 0.5 kg with the 500 kg block's inertia is sqrt(1000) = 31.6 times the block.
    assert re.search(r"31\.6 times the body's dimensions \[1\.2, 0\.8, 0\.9\] m", message)
    assert "Is the mass in tonnes? 500 kg would match the dimensions" in message


def test_a_mass_in_tonnes_without_dimensions_is_told_by_the_mounts():
    text = MACHINE.replace("mass = 500.0", "mass = 0.5").replace("dimensions = [1.2, 0.8, 0.9]", "")
    (message,) = messages(text)
    reach = np.linalg.norm([0.5, 0.35, 0.45])
    half = np.linalg.norm(np.sqrt(1000) * np.array([1.2, 0.8, 0.9])) / 2
    assert f"within {reach:.4g} m of the CG" in message and f"({half:.4g} m)" in message
    assert "Is the mass in tonnes with the inertia in kg m^2?" in message


def test_a_body_lighter_than_air_is_told_by_its_density():
    """Mass and inertia both in t: the inertia box matches, the density (0.58 kg/m^3) does not."""
    text = MACHINE.replace("mass = 500.0", "mass = 0.5").replace("[60.4, 93.75, 86.7]", "[0.0604, 0.09375, 0.0867]")
    (message,) = messages(text)
    density = 0.5 / (1.2 * 0.8 * 0.9)
    assert f"mean density of {density:.3g} kg/m^3" in message and density < DENSITY_RANGE[0]
    assert "Is the mass in tonnes?" in message


def test_positions_in_mm_are_named_with_their_value_in_m():
    text = MACHINE
    for corner in CORNERS:
        text = text.replace(corner, "[" + ", ".join(str(round(1000 * float(v))) for v in corner[1:-1].split(",")) + "]")
    (message,) = messages(text)
    reach = np.linalg.norm([500, 350, 450])
    assert message.startswith(f"4 position(s) lie more than {REACH_RATIO:g} times the body's half-size (0.85 m, from "
                              "its dimensions)")
    assert f"{reach:.4g} m away" in message and "Are the positions in mm? In m this one would be [-0.5, -0.35, -0.45]" \
        in message


def test_a_speed_in_rpm_typed_as_hz_is_named_with_the_force_it_makes():
    """The issue's fan: an unbalance at "1480 Hz" meant as 1480 rpm; the force is 3600 times what was meant."""
    (message,) = messages(MACHINE.replace("speed_rpm = 1480.0", "f_hz = 1480.0"))
    force = 0.005 * (2 * np.pi * 1480) ** 2
    weight = 500 * 9.80665
    assert force > UNBALANCE_WEIGHT_RATIO * weight
    assert f"is {force / 1e3:.4g} kN at 1480 Hz, {force / weight:.3g} times the body's weight" in message
    assert f"Is 1480 a speed in rev/min? That is {1480 / 60:.4g} Hz and {force / 3600:.4g} N" in message


def test_an_unbalance_given_in_g_mm_is_named():
    (message,) = messages(MACHINE.replace("unbalance = 0.005", "unbalance = 5000.0"))
    assert "Is the unbalance in g mm?" in message


def test_a_one_mount_layout_is_a_mechanism():
    text = ONE_MOUNT
    (message,) = messages(text.replace(CORNERS[0], "[0.0, 0.0, -0.45]"))
    assert message.startswith("the mounts leave the body unrestrained (a mechanism): 3 zero-frequency mode(s)")


@pytest.mark.parametrize("factor, flagged", [(1.01, False), (0.99, True)])
def test_an_inertia_box_is_a_slip_only_beyond_its_limit(factor, flagged):
    """The inertia's box just inside 1 / INERTIA_BOX_RATIO of the dimensions (mass at the centre) is no slip; just
    outside, it is. The box scales as sqrt(J): J times (factor / ratio)^2."""
    scale = (factor / INERTIA_BOX_RATIO) ** 2
    inertia = ", ".join(f"{v * scale:.9g}" for v in (60.4, 93.75, 86.7))
    found = messages(MACHINE.replace("[60.4, 93.75, 86.7]", f"[{inertia}]"))
    assert bool(found) == flagged
    if flagged:
        assert "Check the units of mass [kg], inertia [kg m^2] and dimensions [m]" in found[0]


@pytest.mark.slow  # 2 s on the 2-core machine
def test_modes_and_run_warn_of_a_slip(tmp_path, capsys):
    path = tmp_path / "fan.toml"
    path.write_text(MACHINE.replace("speed_rpm = 1480.0", "f_hz = 1480.0").replace("duration = 3.0", "duration = 0.01")
                    .replace("sample_rate_hz = 2000.0", "sample_rate_hz = 20000.0"))
    for command in (["modes", str(path)], ["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]):
        assert main(command) == 0
        lines = [line for line in capsys.readouterr().err.splitlines() if "rev/min" in line]
        assert len(lines) == 1 and lines[0].startswith("WARNING: loads[0] (rotor): the unbalance force")


def test_one_mount_at_the_cg_is_a_mechanism_not_a_division_by_zero():
    text = ONE_MOUNT
    text = text.replace(CORNERS[0], "[0.0, 0.0, 0.0]").replace("dimensions = [1.2, 0.8, 0.9]", "")
    (message,) = messages(text)
    assert message.startswith("the mounts leave the body unrestrained (a mechanism)")
