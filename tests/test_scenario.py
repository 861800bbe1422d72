"""Scenario files: the bundled ones load, and every mistake gets a message naming what to fix."""

import re
from pathlib import Path

import numpy as np
import pytest

from references import rayleigh_ratio
from sixdof import ScenarioError, load_scenario, parse_scenario
from systems import BRIDGE_INERTIA, BRIDGE_MASS, BRIDGE_POSITIONS, BRIDGE_STIFFNESS
from tolerances import RTOL_DAMPING_RATIO

BASE = """
name = "case"
description = "a machine on four mounts"

[body]
mass = 500.0
inertia = [40.0, 60.0, 80.0]
dimensions = [1.0, 1.5, 0.8]

[[mounts]]
name = "a"
position = [-0.4, -0.6, -0.3]
stiffness = [2e5, 3e5, 8e5]

[[mounts]]
name = "b"
position = [0.4, 0.6, -0.3]
stiffness = [2e5, 3e5, 8e5]
damping = [100.0, 100.0, 400.0]

[damping]
rayleigh = { zeta = 0.02, f_hz = [1.0, 30.0] }

[frf]
f_hz = [0.5, 50.0]
points = 100

[[frf.point]]
name = "drive"
load_point = [0.5, 0.75, 0.4]
load_direction = "z"
response_point = [0.5, 0.75, 0.4]
response_direction = "rx"

[[points]]
name = "corner"
position = [0.5, 0.75, 0.4]

[statics]
gravity = 9.81

[[loads]]
name = "shaker"
point = [0.2, 0.3, 0.4]
force = [0.0, 0.0, 500.0]
signal = { kind = "half_sine", start = 0.1, duration = 0.02 }

[[loads]]
kind = "unbalance"
name = "rotor"
point = [0.0, 0.0, 0.2]
unbalance = 0.01
speed_rpm = 1500.0
axis = [1.0, 0.0, 0.0]

[ground]
quantity = "acceleration"
direction = [1.0, 0.0, 0.0]
signal = { kind = "table", t = [0.0, 0.1, 0.2], values = [0.0, 1.0, 0.0] }

[initial]
q = [0.0, 0.0, 0.001, 0.0, 0.0, 0.0]

[simulation]
duration = 1.0
sample_rate_hz = 500.0
"""


def test_base_scenario_is_valid():
    scenario = parse_scenario(BASE, "case.toml")
    assert scenario.name == "case"
    assert scenario.system.mount_names == ("a", "b")
    assert scenario.frf.grid()[[0, -1]] == pytest.approx([0.5, 50.0])
    assert scenario.points[0].position == (0.5, 0.75, 0.4)
    # Rayleigh from two target ratios: zeta = alpha / 2w + beta w / 2 at both frequencies.
    r = scenario.system.rayleigh
    for f in (1.0, 30.0):
        w = 2 * np.pi * f
        assert rayleigh_ratio(r.alpha, r.beta, w) == pytest.approx(0.02, rel=RTOL_DAMPING_RATIO)


def test_bundled_bridge_scenario_is_the_seed_data():
    system = load_scenario("scenarios/bridge_beam.toml").system
    assert system.body.mass == BRIDGE_MASS
    assert np.diag(system.body.inertia) == pytest.approx(BRIDGE_INERTIA)
    assert system.positions == pytest.approx(np.array(BRIDGE_POSITIONS))
    assert system.stiffnesses == pytest.approx(np.array(BRIDGE_STIFFNESS))


BAD = [
    # (id, (old, new) replacement in BASE or a whole text, message that must appear)
    ("toml syntax", ("mass = 500.0", "mass = = 500"), r"case.toml: expected valid TOML"),
    ("missing name", ('name = "case"', ""), r"case.toml: name: expected a value \(required key\), got nothing"),
    ("empty name", ('name = "case"', 'name = ""'), r"name: expected a non-empty string, got ''"),
    ("name not a string", ('name = "case"', "name = 3"), r"name: expected a non-empty string, got 3"),
    ("unknown top-level key", ("[statics]", "[static]"), r"static: expected one of the keys .*got an unknown key; did you mean 'statics'\?"),
    ("missing body", ("[body]\nmass = 500.0\ninertia = [40.0, 60.0, 80.0]\ndimensions = [1.0, 1.5, 0.8]\n", ""), r"body: expected a value \(required key\)"),
    ("body not a table", ("[body]\nmass = 500.0\ninertia = [40.0, 60.0, 80.0]\ndimensions = [1.0, 1.5, 0.8]\n", 'body = "heavy"\n'), r"body: expected a table \[body\], got 'heavy'"),
    ("negative mass", ("mass = 500.0", "mass = -500.0"), r"body.mass: expected a positive number in kg, got -500.0"),
    ("mass as text", ("mass = 500.0", 'mass = "500 kg"'), r"body.mass: expected a positive number in kg, got '500 kg'"),
    ("infinite mass", ("mass = 500.0", "mass = inf"), r"body.mass: expected a positive number in kg, got inf"),
    ("missing mass", ("mass = 500.0\n", ""), r"body.mass: expected a value \(required key\), got nothing"),
    ("inertia of 2 values", ("inertia = [40.0, 60.0, 80.0]", "inertia = [40.0, 60.0]"), r"body.inertia: expected 3 principal moments .* or a symmetric 3x3 tensor in kg m\^2, got \[40.0, 60.0\]"),
    ("impossible inertia", ("inertia = [40.0, 60.0, 80.0]", "inertia = [10.0, 20.0, 80.0]"), r"body.inertia: expected principal moments that a real body can have \(J1 \+ J2 >= J3; here 10 \+ 20 < 80\)"),
    ("negative inertia", ("inertia = [40.0, 60.0, 80.0]", "inertia = [40.0, -60.0, 80.0]"), r"body.inertia: expected a positive definite tensor"),
    ("asymmetric tensor", ("inertia = [40.0, 60.0, 80.0]", "inertia = [[40.0, 1.0, 0.0], [0.0, 60.0, 0.0], [0.0, 0.0, 80.0]]"), r"body.inertia: expected a symmetric 3x3 tensor"),
    ("zero dimension", ("dimensions = [1.0, 1.5, 0.8]", "dimensions = [1.0, 0.0, 0.8]"), r"body.dimensions: expected 3 positive lengths"),
    ("unknown body key", ("mass = 500.0", "mass = 500.0\nmas = 2.0"), r"body.mas: expected one of the keys dimensions, inertia, mass, got an unknown key; did you mean 'mass'\?"),
    ("no mounts", None, r"mounts: expected at least one \[\[mounts\]\] table, got nothing"),
    ("mount typo", ("position = [0.4, 0.6, -0.3]", "positon = [0.4, 0.6, -0.3]"), r"mounts\[1\].positon: expected one of the keys .*did you mean 'position'\?"),
    ("mount missing stiffness", ("stiffness = [2e5, 3e5, 8e5]\n\n[[mounts]]", "\n[[mounts]]"), r"mounts\[0\].stiffness: expected a value \(required key\), got nothing"),
    ("negative stiffness", ("stiffness = [2e5, 3e5, 8e5]\ndamping", "stiffness = [2e5, -3e5, 8e5]\ndamping"), r"mounts\[1\].stiffness: expected 3 values >= 0 in N/m, not all zero, got \[200000.0, -300000.0, 800000.0\]"),
    ("zero stiffness", ("stiffness = [2e5, 3e5, 8e5]\ndamping", "stiffness = [0, 0, 0]\ndamping"), r"mounts\[1\].stiffness: expected 3 values >= 0 in N/m, not all zero"),
    ("position of 2", ("position = [-0.4, -0.6, -0.3]", "position = [-0.4, -0.6]"), r"mounts\[0\].position: expected 3 coordinates \[x, y, z\] in m from the CG in body axes, got \[-0.4, -0.6\]"),
    ("negative damping", ("damping = [100.0, 100.0, 400.0]", "damping = [100.0, -1.0, 400.0]"), r"mounts\[1\].damping: expected 3 values >= 0 in N s/m"),
    ("axes not orthonormal", ("damping = [100.0, 100.0, 400.0]", "axes = [[1, 1, 0], [0, 1, 0], [0, 0, 1]]"), r"mounts\[1\].axes: expected 3 orthonormal rows .*normalize the rows"),
    ("duplicate mount names", ('name = "b"', 'name = "a"'), r"mounts: expected unique mount names, got 'a repeated'"),
    ("mount name empty", ('name = "b"', 'name = ""'), r"mounts\[1\].name: expected a non-empty string"),
    ("negative loss factor", ("damping = [100.0, 100.0, 400.0]", "loss_factor = [0.1, -0.1, 0.1]"), r"mounts\[1\].loss_factor: expected 3 loss factors >= 0"),
    ("rayleigh mixed keys", ("rayleigh = { zeta = 0.02, f_hz = [1.0, 30.0] }", "rayleigh = { zeta = 0.02, beta = 0.001 }"), r"damping.rayleigh: expected either \{zeta, f_hz\} or \{alpha, beta\}, got \['beta', 'zeta'\]"),
    ("rayleigh equal frequencies", ("f_hz = [1.0, 30.0]", "f_hz = [30.0, 30.0]"), r"damping.rayleigh.f_hz: expected two different positive frequencies in Hz, got \[30.0, 30.0\]"),
    ("rayleigh zeta too big", ("zeta = 0.02", "zeta = 1.5"), r"damping.rayleigh.zeta: expected a damping ratio in \[0, 1\), got 1.5"),
    ("negative alpha", ("rayleigh = { zeta = 0.02, f_hz = [1.0, 30.0] }", "rayleigh = { alpha = -0.1, beta = 0.001 }"), r"damping.rayleigh.alpha: expected a finite number >= 0, got -0.1"),
    ("modal ratios of 4", ("rayleigh = { zeta = 0.02, f_hz = [1.0, 30.0] }", "modal = [0.01, 0.02, 0.03, 0.04]"), r"damping.modal: expected one damping ratio in \[0, 1\) or 6 of them"),
    ("unknown damping key", ("rayleigh = {", "raleigh = {"), r"damping.raleigh: expected one of the keys loss_factor_band_hz, loss_factor_model, loss_factor_terms, modal, rayleigh, rayleigh_excludes_hysteresis, got an unknown key; did you mean 'rayleigh'\?"),
    ("frf reversed range", ("f_hz = [0.5, 50.0]", "f_hz = [50.0, 0.5]"), r"frf.f_hz: expected two frequencies \[low, high\] in Hz with 0 <= low < high, got \[50.0, 0.5\]"),
    ("frf points fractional", ("points = 100", "points = 10.5"), r"frf.points: expected an integer >= 2, got 10.5"),
    ("frf log from zero", ("f_hz = [0.5, 50.0]", "f_hz = [0.0, 50.0]"), r"frf.f_hz: expected a positive low frequency for log spacing"),
    ("frf spacing", ("points = 100", 'points = 100\nspacing = "octave"'), r"frf.spacing: expected 'log' or 'linear', got 'octave'"),
    ("frf point direction", ('load_direction = "z"', 'load_direction = "up"'), r"frf.point\[0\].load_direction: expected one of 'x', 'y', 'z', 'rx', 'ry', 'rz' or a nonzero 3-vector in body axes, got 'up'"),
    ("frf point quantity", ('response_direction = "rx"', 'response_direction = "rx"\nquantity = "compliance"'), r"frf.point\[0\].quantity: expected 'receptance', 'mobility' or 'accelerance', got 'compliance'"),
    ("frf point missing", ('response_point = [0.5, 0.75, 0.4]\n', ""), r"frf.point\[0\].response_point: expected a value \(required key\)"),
    ("frf point bad point", ("load_point = [0.5, 0.75, 0.4]", "load_point = [0.5, 0.75]"), r"frf.point\[0\].load_point: expected 3 coordinates"),
    ("point without position", ('position = [0.5, 0.75, 0.4]', ""), r"points\[0\].position: expected a value \(required key\), got nothing"),
    ("signal without kind", ('signal = { kind = "half_sine", start = 0.1', 'signal = { start = 0.1'), r"loads\[0\].signal.kind: expected one of half_sine, harmonic, .*, got nothing"),
    ("unknown signal kind", ('kind = "half_sine"', 'kind = "half-sine"'), r"loads\[0\].signal.kind: expected one of .*got 'half-sine'"),
    ("negative pulse duration", ("duration = 0.02", "duration = -0.02"), r"loads\[0\].signal.duration: expected"),
    ("signal key typo", ("start = 0.1, duration", "strat = 0.1, duration"), r"loads\[0\].signal.strat: expected one of the keys .*did you mean 'start'\?"),
    ("load kind unknown", ('kind = "unbalance"', 'kind = "imbalance"'), r"loads\[1\].kind: expected one of force, unbalance, got 'imbalance'"),
    ("load point of 2", ("point = [0.2, 0.3, 0.4]", "point = [0.2, 0.3]"), r"loads\[0\].point: expected 3 coordinates"),
    ("unbalance negative", ("unbalance = 0.01", "unbalance = -0.01"), r"loads\[1\].unbalance: expected"),
    ("ground quantity", ('quantity = "acceleration"', 'quantity = "jerk"'), r"ground.quantity: expected .*displacement.*got 'jerk'"),
    ("ground direction zero", ("direction = [1.0, 0.0, 0.0]\nsignal", "direction = [0.0, 0.0, 0.0]\nsignal"), r"ground.direction: expected"),
    ("table times not increasing", ("t = [0.0, 0.1, 0.2]", "t = [0.0, 0.2, 0.1]"), r"ground.signal.t: expected"),
    ("table file missing", ("signal = { kind = \"table\", t = [0.0, 0.1, 0.2], values = [0.0, 1.0, 0.0] }", "signal = { kind = \"table\", file = \"nope.csv\" }"), r"ground.signal.file: expected an existing, readable CSV file"),
    ("initial q of 3", ("q = [0.0, 0.0, 0.001, 0.0, 0.0, 0.0]", "q = [0.0, 0.0, 0.001]"), r"initial.q: expected"),
    ("initial mode 7", ("q = [0.0, 0.0, 0.001, 0.0, 0.0, 0.0]", "mode = 7\namplitude = 0.001"), r"initial.mode: expected"),
    ("zero duration", ("duration = 1.0", "duration = 0.0"), r"simulation.duration: expected"),
    ("negative sample rate", ("sample_rate_hz = 500.0", "sample_rate_hz = -500.0"), r"simulation.sample_rate_hz: expected"),
    ("unknown solver", ("sample_rate_hz = 500.0", 'sample_rate_hz = 500.0\nsolver = "Euler2"'), r"simulation.solver: expected one of .*Tsit5.*got 'Euler2'"),
    ("truncation both ways", ("[statics]", "[superposition]\nn_modes = 3\nf_max_hz = 10.0\n\n[statics]"), r"superposition.n_modes: expected either n_modes or f_max_hz, not both"),
    ("truncation of 7 modes", ("[statics]", "[superposition]\nn_modes = 7\n\n[statics]"), r"superposition.n_modes: expected an integer from 1 to 6, got 7"),
    ("superposition method", ("[statics]", '[superposition]\nmethod = "modal"\n\n[statics]'), r"superposition.method: expected 'auto', 'real' or 'complex', got 'modal'"),
    ("negative gravity", ("gravity = 9.81", "gravity = -9.81"), r"statics.gravity: expected a positive acceleration in m/s\^2, got -9.81"),
    ("zero gravity direction", ("gravity = 9.81", "gravity = 9.81\ndirection = [0, 0, 0]"), r"statics.direction: expected a non-zero 3-vector in body axes, got \[0, 0, 0\]"),
]


def bad_text(change):
    if change is None:  # remove every mount
        return BASE.split("[[mounts]]")[0] + "[damping]" + BASE.split("[damping]")[1]
    old, new = change
    assert old in BASE, old
    return BASE.replace(old, new, 1)


@pytest.mark.parametrize("change, message", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input_names_file_field_expectation_and_value(change, message):
    with pytest.raises(ScenarioError, match=message) as info:
        parse_scenario(bad_text(change), "case.toml")
    assert str(info.value).startswith("case.toml: ")


def readme_mount_keys() -> list[str]:
    """The keys of a ``[[mounts]]`` table as the scenario reference (docs/reference/scenario.md) lists them."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "reference" / "scenario.md").read_text()
    rows = text.split("| **`[[mounts]]`** |")[1].split("| **`[damping]`** |")[0]
    return re.findall(r"^\| `\[*(?:mounts\.)?(\w+)\]*` \|", rows, re.M)


def test_an_unknown_mount_key_lists_the_keys_a_mount_accepts():
    """Exactly the scenario reference's keys, and the nearest of them suggested (``bump_stop``, not the model's
    ``bump_clearance``, which the file may not use)."""
    keys = readme_mount_keys()
    assert {"bump_stop", "maxwell", "dynamic_stiffness", "force_deflection"} <= set(keys)
    text = BASE.replace("damping = [100.0, 100.0, 400.0]", "bump_stp = { clearance = [inf, inf, 0.01], "
                        "stiffness = [0.0, 0.0, 1e6] }", 1)
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, "case.toml")
    assert str(info.value) == (f"case.toml: mounts[1].bump_stp: expected one of the keys {', '.join(sorted(keys))}, "
                               "got an unknown key; did you mean 'bump_stop'?")


def test_missing_file_and_unreadable_file(tmp_path):
    with pytest.raises(ScenarioError, match=r"nope.toml: expected an existing, readable scenario file"):
        load_scenario(tmp_path / "nope.toml")
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ScenarioError, match=r"binary.toml: expected a UTF-8 scenario file, got .*binary.toml: 'utf-8' codec can't decode byte 0xff on line 1$"):
        load_scenario(binary)


CSV_EXPECTED = "ground.signal.file: expected a UTF-8 CSV file of rows of two finite numbers: time in s, value"


@pytest.mark.parametrize(("csv", "message"), [
    ("t,value\n0.0,1.0\n0.1,oops\n", f"{CSV_EXPECTED}, got line 3 of record.csv, field 2: 'oops'"),
    ("t,value\n0.0,1.0\n0.1,nan\n", f"{CSV_EXPECTED}, got line 3 of record.csv, field 2: 'nan'"),
    ("# a record\nt,value\n0.0,0.0\n0.2,1.0\n\n0.1,0.5\n",
     f"{CSV_EXPECTED}, the first column (time in s) strictly increasing, got 0.1 on line 6 of record.csv, after 0.2 "
     "on line 4"),
], ids=["not a number", "not finite", "times not increasing"])
def test_a_bad_csv_names_the_field_that_reads_it_and_its_line(tmp_path, csv, message):
    """Not the table's ``t`` or ``values``, which the file does not write: its ``file``, the CSV's line and column."""
    (tmp_path / "record.csv").write_text(csv)
    text = BASE.replace(
        'signal = { kind = "table", t = [0.0, 0.1, 0.2], values = [0.0, 1.0, 0.0] }',
        'signal = { kind = "table", file = "record.csv" }',
    )
    (tmp_path / "case.toml").write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(tmp_path / "case.toml")
    assert str(info.value) == f"{tmp_path / 'case.toml'}: {message}"
