"""A generated table of bad scenario files and bad API calls: each one gets one clear error naming the file
and the field, before any computation, and ``sixdof run`` leaves nothing behind.

The table is generated from the bundled engine scenario (every mount, load, point and FRF request kind):
every number, vector and name in it is replaced in turn by a value of the wrong kind (a string, a boolean,
a NaN, a table, a vector one entry short or nested once too deep), and an unknown key is put in every
table. A mutation that sixdof accepted would be a bad input passing silently.
"""

import json
import math
import re
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from sixdof import InputError, RigidBody, ScenarioError, load_scenario
from sixdof.cli import EXIT_BAD_INPUT, main
from sixdof.excitation import Harmonic
from sixdof.model.parts import Mount

SCENARIOS = Path(__file__).parents[1] / "scenarios"
ENGINE = SCENARIOS / "engine_inclined_mounts.toml"
#: Bundled scenarios the table is generated from: between them every mount, load, signal, ground motion,
#: point and FRF request kind of the scenario format.
SOURCES = ("engine_inclined_mounts", "machine_unbalance", "bridge_beam_ground")


def toml_text(value, top=True) -> str:
    """``value`` written as TOML: top-level keys with inline values (enough for a scenario)."""
    if top:
        return "\n".join(f"{json.dumps(key)} = {toml_text(item, False)}" for key, item in value.items()) + "\n"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{json.dumps(key)} = {toml_text(item, False)}" for key, item in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(toml_text(item, False) for item in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    return json.dumps(value)


def field_name(path: tuple) -> str:
    """``("mounts", 0, "position")`` as the error messages write it: ``mounts[0].position``."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else part)
    return text


def leaves(value, path=()):
    """(path, value) of every number, string and numeric vector of a parsed scenario."""
    if isinstance(value, dict):
        for key, item in value.items():
            yield from leaves(item, (*path, key))
    elif isinstance(value, list) and value and all(isinstance(item, dict) for item in value):
        for i, item in enumerate(value):
            yield from leaves(item, (*path, i))
    else:
        yield path, value


def tables(value, path=()):
    """The path of every table of a parsed scenario."""
    if isinstance(value, dict):
        yield path
        for key, item in value.items():
            yield from tables(item, (*path, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            if isinstance(item, dict):
                yield from tables(item, (*path, i))


def replaced(tree, path, value):
    """A copy of ``tree`` with the item at ``path`` set to ``value``."""
    tree = json.loads(json.dumps(tree))
    node = tree
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    return tree


# Free text and file names: any string is a valid value there.
FREE_TEXT = {"description"}


def mutations(value):
    """Wrong-kind values for a leaf: (label, value)."""
    if isinstance(value, bool):
        return [("string", "true"), ("number", 1)]
    if isinstance(value, (int, float)):
        return [("string", str(value)), ("boolean", True), ("NaN", math.nan), ("table", {"value": value})]
    if isinstance(value, str):
        return [("number", 1), ("boolean", False), ("list", [value])]
    if isinstance(value, list):
        flat = np.ravel(value).tolist()
        names = all(isinstance(v, str) for v in value)  # a list of names: any length, strings already
        out = [("one entry short", value[:-1] if not names else None), ("nested too deep", [value]),
               ("a string entry", [str(flat[0])] + value[1:] if not isinstance(value[0], list) and not names else None),
               ("a boolean entry", [True] + value[1:] if not isinstance(value[0], list) else None)]
        return [(label, mutated) for label, mutated in out if mutated is not None]
    return []


def cases():
    for source in SOURCES:
        scenario = tomllib.loads((SCENARIOS / f"{source}.toml").read_text())
        for path, value in leaves(scenario):
            if path[-1] in FREE_TEXT:
                continue
            for label, mutated in mutations(value):
                yield pytest.param(replaced(scenario, path, mutated), field_name(path),
                                   id=f"{source}: {field_name(path)} {label}")
        for path in tables(scenario):
            if path:
                yield pytest.param(replaced(scenario, (*path, "colour"), "red"), field_name(path),
                                   id=f"{source}: {field_name(path)} unknown key")


CASES = list(cases())


def test_the_table_is_large():
    assert len(CASES) >= 200


@pytest.mark.parametrize(("tree", "field"), CASES)
def test_each_bad_file_is_refused_naming_file_and_field(tmp_path, capsys, tree, field):
    shutil.copy(SCENARIOS / "ground_accelerogram.csv", tmp_path)  # the record a ground motion reads
    file = tmp_path / "bad.toml"
    file.write_text(toml_text(tree))
    with pytest.raises(ScenarioError) as error:
        load_scenario(file)
    message = str(error.value)
    assert message.startswith(f"{file}: ")
    assert field in message, message

    out = tmp_path / "outputs"
    assert main(["run", str(file), "--out", str(out), "--quiet"]) == EXIT_BAD_INPUT
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and str(file) in captured.err and field in captured.err
    assert not out.exists()  # nothing written, not even the output folder


@pytest.mark.parametrize(("content", "problem"), [
    (b"0,0,5\n1,1,5\n2,0,5\n", "line 2 of record.csv"),
    ("t,a\n0,0\n1,1.5\xe9\n".encode("latin-1"), "can't decode"),
    (bytes(range(256)) * 4, "record.csv"),
    (b"0,0\n1,abc\n", "line 2 of record.csv"),
    (b"# only a comment\n", "0 rows"),
])
def test_bad_csv_files_are_refused_naming_the_signal_file(tmp_path, content, problem):
    (tmp_path / "record.csv").write_bytes(content)
    text = ENGINE.read_text().replace('signal = { kind = "harmonic", f_hz = 26.667 }',
                                      'signal = { kind = "table", file = "record.csv" }')
    (tmp_path / "case.toml").write_text(text)
    with pytest.raises(ScenarioError, match=rf"case.toml: loads\[0\].signal.file: expected .*{problem}"):
        load_scenario(tmp_path / "case.toml")


@pytest.mark.parametrize(("old", "new", "field", "expected"), [
    ("points = 1500", "points = 1000000000", r"frf.points", r"fits in this machine's .* GiB of memory, got "
     r"1000000000 frequencies, about .* GiB"),
    ('f_hz = 26.667 }', 'f_hz = 26.667 }\n[[loads]]\nname = "noise"\npoint = [0.0, 0.0, 0.0]\nforce = [1.0, 0.0, 0.0]\n'
     'signal = { kind = "random", f_hz = [1.0, 50.0], rms = 1.0, seed = 1, components = 100000000 }',
     r"loads\[1\].signal.components", r"an integer from 1 to 10000"),
    ("dimensions = [0.7, 0.9, 0.6]", "dimensions = " + "[" * 10_000 + "1.0" + "]" * 10_000, "", "valid TOML"),
    ("position = [-0.35, 0.15, 0.05]", "position = [-1e300, 0.15, 0.05]", r"mounts\[0\].position",
     "stay finite"),
])
def test_sizes_that_cannot_be_held_are_refused_with_the_numbers(tmp_path, old, new, field, expected):
    assert old in ENGINE.read_text()
    (tmp_path / "case.toml").write_text(ENGINE.read_text().replace(old, new, 1))
    with pytest.raises(ScenarioError, match=rf"case.toml: {field}.*expected .*{expected}"):
        load_scenario(tmp_path / "case.toml")


@pytest.mark.parametrize("mass", ["500", True, np.bool_(True), [500.0], None, complex(500.0)])
def test_api_strings_and_booleans_are_not_numbers(mass):
    with pytest.raises(InputError, match="mass: expected a positive number in kg"):
        RigidBody(mass=mass, inertia=[1.0, 1.0, 1.0])


@pytest.mark.parametrize("stiffness", [["1e5", 1e5, 1e5], [True, 1e5, 1e5], np.array(["1", "2", "3"]),
                                       np.array([True, True, True]), [[1e5, 1e5, 1e5]]])
def test_api_vectors_of_strings_or_booleans_are_refused(stiffness):
    with pytest.raises(InputError, match="stiffness: expected 3 values >= 0 in N/m"):
        Mount(name="m", position=[0.0, 0.0, 0.0], stiffness=stiffness)


def test_api_numpy_scalars_and_arrays_are_numbers():
    body = RigidBody(mass=np.float32(500.0), inertia=np.array([10, 20, 25], dtype=np.int64))
    mount = Mount(name="m", position=np.zeros(3, dtype=np.float32), stiffness=[np.int32(1), np.float64(2.0), 3])
    assert body.mass == 500.0 and body.inertia[2, 2] == 25.0
    assert mount.stiffness.tolist() == [1.0, 2.0, 3.0]


# Valid keyword arguments of every public constructor; each one is replaced in turn by a wrong kind.
VALID_CALLS = {
    "RigidBody": {"mass": 500.0, "inertia": [40.0, 60.0, 80.0], "dimensions": [1.0, 1.5, 0.8]},
    "Mount": {"name": "a", "position": [0.4, 0.6, -0.3], "stiffness": [2e5, 3e5, 8e5], "damping": [1.0, 1.0, 4.0],
              "loss_factor": [0.1, 0.1, 0.1], "axes": np.eye(3).tolist(), "max_deflection": [0.01, 0.01, 0.005],
              "allow_tension": False},
    "Rayleigh": {"alpha": 0.1, "beta": 1e-4},
    "Harmonic": {"f_hz": 5.0, "phase_deg": 10.0, "start": 0.5, "duration": 2.0},
    "HalfSine": {"start": 0.1, "duration": 0.02},
    "Haversine": {"start": 0.1, "duration": 0.02},
    "Ramp": {"duration": 1.0, "start": 0.5},
    "Random": {"f_hz": [1.0, 20.0], "rms": 2.0, "seed": 3, "components": 16, "start": 0.0, "duration": 4.0},
    "Step": {"start": 0.5},
    "Sweep": {"f0_hz": 1.0, "f1_hz": 20.0, "duration": 5.0, "start": 0.0, "law": "log"},
    "Table": {"t": [0.0, 1.0, 2.0], "values": [0.0, 1.0, 0.0], "outside": "hold"},
    "Load": {"name": "push", "point": [0.1, 0.0, 0.0], "force": [1.0, 0.0, 0.0], "moment": [0.0, 0.0, 1.0],
             "signal": Harmonic(f_hz=2.0)},
    "Unbalance": {"name": "rotor", "point": [0.0, 0.0, 0.1], "unbalance": 0.01, "speed_rpm": 1500.0,
                  "axis": [1.0, 0.0, 0.0], "phase_deg": 0.0, "start": 0.0},
    "GroundMotion": {"quantity": "acceleration", "direction": [1.0, 0.0, 0.0], "scale": 2.0,
                     "signal": Harmonic(f_hz=2.0)},
    "InitialState": {"q": [0.0] * 6, "qd": [0.0] * 6},
    "ModeRelease": {"mode": 1, "amplitude": 1e-3},
    "SimulationSettings": {"duration": 1.0, "sample_rate_hz": 100.0, "start": 0.0, "rtol": 1e-8, "atol": 1e-8,
                           "max_steps": 1000},
}


def api_cases():
    for name, kwargs in VALID_CALLS.items():
        for key, value in kwargs.items():
            for label, mutated in mutations(value):
                yield pytest.param(name, {**kwargs, key: mutated}, key, id=f"{name}.{key} {label}")


API_CASES = list(api_cases())


def test_every_valid_api_call_is_valid():
    import sixdof

    for name, kwargs in VALID_CALLS.items():
        getattr(sixdof, name)(**kwargs)
    assert len(API_CASES) >= 100


@pytest.mark.parametrize(("name", "kwargs", "field"), API_CASES)
def test_each_bad_api_call_is_refused_naming_the_field(name, kwargs, field):
    import sixdof

    with pytest.raises(InputError) as error:
        getattr(sixdof, name)(**kwargs)
    assert field in str(error.value)


def _one_of_each():
    """A system, an excitation with one load, and simulation settings: the model arguments of the API."""
    from sixdof import Excitation, Load, SimulationSettings, System

    load = Load(name="push", point=[0.1, 0.0, 0.0], force=[1.0, 0.0, 0.0], signal=Harmonic(f_hz=2.0))
    system = System(RigidBody(**VALID_CALLS["RigidBody"]), [Mount(**VALID_CALLS["Mount"])])
    return system, Excitation(loads=[load]), SimulationSettings(duration=1.0, sample_rate_hz=100.0)


def _call(name, *args):
    """``sixdof.<name>`` (or, with a dot, the analysis module's function) called with ``args``."""
    import importlib

    import sixdof

    if "." in name:
        module, function = name.rsplit(".", 1)
        return getattr(importlib.import_module(f"sixdof.analysis.{module}"), function)(*args)
    return getattr(sixdof, name)(*args)


# API functions called with a model argument in another's place: (function, argument order, message).
WRONG_KINDS = [
    ("simulate", "excitation system settings", r"system: expected a System, got an Excitation"),
    ("simulate", "system settings excitation", r"settings: expected a SimulationSettings, got an Excitation"),
    ("simulate", "system system settings", r"excitation: expected an Excitation or None, got a System"),
    ("superpose", "excitation system times", r"system: expected a System, got an Excitation"),
    ("superpose", "system settings times", r"excitation: expected an Excitation or None, got a SimulationSettings"),
    ("receptance", "excitation f_hz", r"system: expected a System, got an Excitation"),
    ("point_frf", "f_hz system point x point x", r"system: expected a System, got an array of shape \(2,\)"),
    ("force_transmissibility", "excitation f_hz point x", r"system: expected a System, got an Excitation"),
    ("ground_transmissibility", "excitation f_hz x point", r"system: expected a System, got an Excitation"),
    ("steady.steady_state", "excitation system", r"system: expected a System, got an Excitation"),
    ("steady.steady_state", "system system", r"excitation: expected an Excitation, got a System"),
    ("random.random_response", "system excitation", r"random: expected a RandomInput, got an Excitation"),
    ("gravity_statics", "excitation", r"system: expected a System, got an Excitation"),
    ("design_metrics", "excitation", r"system: expected a System, got an Excitation"),
    ("sensitivities", "settings", r"system: expected a System, got a SimulationSettings"),
    ("mount_forces", "system excitation", r"response: expected a TimeHistory, got an Excitation"),
]


@pytest.mark.parametrize(("name", "order", "match"), WRONG_KINDS, ids=[f"{n}({o})" for n, o, _ in WRONG_KINDS])
def test_api_arguments_of_another_kind_are_named(name, order, match):
    system, excitation, settings = _one_of_each()
    given = {"system": system, "excitation": excitation, "settings": settings, "times": np.linspace(0.0, 1.0, 11),
             "f_hz": np.array([1.0, 2.0]), "point": [0.0, 0.0, 0.0], "x": "x"}
    with pytest.raises(InputError, match=f"^{match}$"):
        _call(name, *(given[word] for word in order.split()))


@pytest.mark.parametrize(("field", "make", "got"), [
    ("mounts", lambda body, mount, load: dict(body=body, mounts=mount), "a Mount"),
    ("mounts", lambda body, mount, load: dict(body=body, mounts="front"), "'front'"),
    ("maxwell", lambda body, mount, load: dict(body=body, mounts=[mount], maxwell=mount), "a Mount"),
    ("force_deflection", lambda body, mount, load: dict(body=body, mounts=[mount], force_deflection=mount), "a Mount"),
    ("loads", lambda body, mount, load: dict(loads=load), "a Load"),
    ("loads", lambda body, mount, load: dict(loads={"push": load}), "a dict"),
])
def test_one_item_where_a_sequence_of_them_goes_is_named(field, make, got):
    # As System(mounts=...) has always done, one item alone is refused (not wrapped): a sequence is expected.
    from sixdof import Excitation, System

    (system, excitation, _) = _one_of_each()
    kwargs = make(system.body, system.mounts[0], excitation.loads[0])
    kind = {"mounts": "Mount", "maxwell": "Maxwell", "force_deflection": "ForceDeflection", "loads": "Load or Unbalance"}
    with pytest.raises(InputError, match=rf"^{field}: expected a sequence of {kind[field]}, got {re.escape(got)}"):
        (Excitation if field == "loads" else System)(**kwargs)
    # Any iterable of them is a sequence.
    assert Excitation(loads=iter([excitation.loads[0]])).loads == excitation.loads
