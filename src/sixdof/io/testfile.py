"""Measured test data in (issue 47, item 1): a test lab's UFF58 file, or sixdof's own CSV export, read into a
:class:`~sixdof.validation.testdata.TestData` in SI units with every channel placed on the body.

UFF58 (read with pyuff): function type 4 sets are FRFs (receptance, mobility or accelerance from the
ordinate's specific data type 8, 11 or 12 over the denominator's 13, force; a reference whose direction is
+-4..+-6 is a moment), function type 1 sets time histories (a set whose ordinate is a force, type 13, is a
reference channel, the others responses). Direction codes +-1..+-3 are translations along +-X, +-Y, +-Z
(the sign flips the direction, not the data), +-4..+-6 rotations about them. Node coordinates come from
datasets 15 or 2411 in the file, or from the scenario's ``[test.nodes]`` (which take precedence); a node
whose definition or displacement coordinate system is not the global one (0) is transformed with the
dataset 2420 that defines it, read as rows 1-3 the local axes in global coordinates and row 4 the local
origin (``p_global = origin + p_local @ R``), or refused. The test frame is then placed in the scenario's
body axes by ``[test] origin`` and ``axes`` (:class:`~sixdof.validation.testdata.TestSetup`).

Units: each axis's unit label (``"m/s^2"``, ``"g"``, ``"mm"``, ``"in"``, ``"lbf"``, ``"N m"``...) converted to
SI; a blank label (or ``NONE``) takes the UFF164 units dataset's length and force factors with the axis's
exponents (UFF: SI = file value / factor); without either the file is refused. Time and frequency have no unit
in UFF's system: a blank abscissa label is s or Hz. Node coordinates (datasets 15, 2411) have no unit label: they
are m, or converted by the dataset 164's length factor.

CSV: the time histories ``sixdof export --format csv`` writes (a unit in every header): the applied loads'
generalized force columns ``Fx [N]`` .. ``Mz [N m]`` at the CG are the references, the scenario's
``[[points]]`` accelerations ``<point> ax [m/s^2]`` .. the responses, at the points' positions (or their
velocities ``<point> vx [m/s]`` or displacements ``<point> dx [m]``, as ``--point-quantity`` exported them); the
other columns (the CG's, the mounts' forces, the ground's) are not read.
"""

from __future__ import annotations

import csv
import math
import re
import warnings
from pathlib import Path

import numpy as np

from sixdof.dofs import LOADS
from sixdof.errors import InputError, Plain
from sixdof.io.scenario import Scenario, load_scenario
from sixdof.validation.testdata import FRF_QUANTITIES, TestData, TestSetup

_TIME, _FRF = 1, 4  # UFF58 function types
_DISPLACEMENT, _VELOCITY, _ACCELERATION, _FORCE = 8, 11, 12, 13  # UFF58 specific data types
_RESPONSE_TYPES = {_DISPLACEMENT: "displacement", _VELOCITY: "velocity", _ACCELERATION: "acceleration"}
_FRF_BY_RESPONSE = {response: frf for frf, response in FRF_QUANTITIES.items()}
_AXIS_NAMES = ("X", "Y", "Z", "RX", "RY", "RZ")
#: Two abscissas are the same when they agree to this fraction of their span (binary UFF58 rebuilds an even axis
#: as min + k * increment; ASCII keeps 6 digits of an uneven one).
ABSCISSA_RTOL = 1e-6

#: SI value of one unit, by label (lower case): lengths, forces and angles, from which the others are made.
_LENGTHS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6, "µm": 1e-6, "in": 0.0254, "ft": 0.3048}
_FORCES = {"n": 1.0, "kn": 1e3, "mn": 1e-3, "lbf": 4.4482216152605, "lb": 4.4482216152605, "kgf": 9.80665}
_ANGLES = {"rad": 1.0, "mrad": 1e-3, "deg": math.pi / 180}
#: Standard gravity [m/s^2]: an acceleration in g.
_G = 9.80665
_BLANK = ("", "none", "unknown")


def _normal(label: str) -> str:
    text = str(label or "").strip().lower().replace("**", "^").replace("²", "^2").replace("*", " ").replace("-", " ")
    return re.sub(r"\s*/\s*", "/", re.sub(r"\s+", " ", text))


def unit_factor(label: str, data_type: int, rotation: bool) -> float | None:
    """SI value of one unit ``label`` of a quantity of UFF specific data type ``data_type`` (8 displacement, 11
    velocity, 12 acceleration, 13 force), a rotation (a moment) when ``rotation``; ``None`` when the label is
    not one of these units."""
    text = _normal(label)
    bases = _ANGLES if rotation else _LENGTHS
    if data_type == _DISPLACEMENT:
        return bases.get(text)
    if data_type == _VELOCITY:
        base, _, per = text.partition("/")
        return bases.get(base) if per in ("s", "sec") else None
    if data_type == _ACCELERATION:
        if text == "g" and not rotation:
            return _G
        base, _, per = text.partition("/")
        return bases.get(base) if per in ("s^2", "s2", "s/s") else None
    if data_type == _FORCE:
        if not rotation:
            return _FORCES.get(text)
        parts = text.split(" ") if " " in text else ([text[:-1], text[-1]] if text.endswith("m") else [text])
        if len(parts) == 2:
            for force, length in (parts, parts[::-1]):
                if force in _FORCES and length in _LENGTHS:
                    return _FORCES[force] * _LENGTHS[length]
    return None


class _Uff:
    """The datasets of one UFF file, and the names its errors give them."""

    def __init__(self, path: Path) -> None:
        import pyuff

        self.path = path
        try:
            with warnings.catch_warnings():  # pyuff leaves the handle of each binary dataset to the collector
                warnings.simplefilter("ignore", ResourceWarning)
                sets = pyuff.UFF(str(path)).read_sets()
        except Exception as exc:  # pyuff raises bare Exceptions for every fault of a file
            raise InputError(str(path), "a universal file (UFF58 with datasets 15, 2411, 2420, 164)",
                             Plain(f"a file pyuff cannot read ({exc})")) from None
        self.sets = [sets] if isinstance(sets, dict) else list(sets)
        self.units = next((s for s in self.sets if s.get("type") == 164), None)

    def where(self, k: int, field: str = "") -> str:
        kind = self.sets[k].get("type", "?")
        return f"{self.path} dataset {k + 1} (UFF{kind}{' ' + field if field else ''})"

    def factor(self, k: int, axis: str, data_type: int, rotation: bool) -> float:
        """SI value of one unit of the ``axis`` ("ordinate" or "orddenom") of dataset ``k``."""
        data = self.sets[k]
        label = str(data.get(f"{axis}_axis_units_lab", "") or "").strip()
        if _normal(label) not in _BLANK:
            factor = unit_factor(label, data_type, rotation)
            if factor is None:
                kind = {_DISPLACEMENT: "a displacement", _VELOCITY: "a velocity", _ACCELERATION: "an acceleration",
                        _FORCE: "a force"}.get(data_type, f"data type {data_type}")
                what = f"{kind}{' (rotation or moment)' if rotation else ''}"
                raise InputError(self.where(k, f"{axis}_axis_units_lab"), f"a unit of {what} that sixdof can "
                                 "convert (m, mm, in, m/s, m/s^2, g, rad, N, lbf, N m...)", label)
            return factor
        if self.units is None:
            raise InputError(self.where(k, f"{axis}_axis_units_lab"), "a unit label, or a units dataset 164 in the "
                             "file", Plain(f"{label or 'a blank label'} and no dataset 164"))
        length, force = (int(data.get(f"{axis}_{e}_unit_exp", 0) or 0) for e in ("len", "force"))
        return 1.0 / (float(self.units["length"]) ** length * float(self.units["force"]) ** force)

    def abscissa(self, k: int, frf: bool) -> np.ndarray:
        """The abscissa of dataset ``k`` in Hz (``frf``) or s."""
        data = self.sets[k]
        label = _normal(data.get("abscissa_axis_units_lab", ""))
        allowed = ("hz",) if frf else ("s", "sec")
        if label not in (*allowed, *_BLANK):
            raise InputError(self.where(k, "abscissa_axis_units_lab"), "Hz" if frf else "s",
                             data.get("abscissa_axis_units_lab"))
        return np.asarray(data["x"], dtype=float)


def load_test(path: str | Path, scenario: Scenario | str | Path | None = None) -> TestData:
    """Read a test's measured FRFs or time histories (see the module).

    Parameters
    ----------
    path : str or pathlib.Path
        A universal file (UFF58, ``.uff``/``.unv``/...) or sixdof's CSV export (``.csv``).
    scenario : sixdof.io.scenario.Scenario or str or pathlib.Path, optional
        The model's scenario: its ``[test]`` table places the test's nodes (``nodes``, ``origin``, ``axes``); a
        CSV needs its ``[[points]]``.

    Returns
    -------
    sixdof.validation.testdata.TestData
        SI units; positions and directions in the scenario's body axes from the CG.

    Raises
    ------
    sixdof.errors.InputError
        One line naming the file, the dataset or column, what was expected and what was found: units that
        cannot be told, a channel on a node without coordinates, mixed sample rates or abscissas, a missing
        reference channel, an unknown function type, a non-global coordinate system without its dataset 2420.
    """
    path = Path(path)
    if scenario is not None and not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if not path.is_file():
        raise InputError(str(path), "a test file (UFF58 or CSV)", Plain("no such file"))
    if path.suffix.lower() == ".csv":
        return _load_csv(path, scenario)
    setup = getattr(scenario, "test", None) or TestSetup()
    return _load_uff(_Uff(path), setup)


# ----------------------------------------------------------------------------------------------------
# UFF.
# ----------------------------------------------------------------------------------------------------


def _coordinate_systems(uff: _Uff) -> dict[int, np.ndarray]:
    """Cartesian coordinate systems of the file's datasets 2420, by label: (4, 3), rows 1-3 the axes, 4 the
    origin."""
    systems = {}
    for k, data in enumerate(uff.sets):
        if data.get("type") != 2420:
            continue
        for label, kind, matrix in zip(data["CS_sys_labels"], data["CS_types"], data["CS_matrices"]):
            if kind != 0:
                raise InputError(uff.where(k, f"coordinate system {label}"), "a Cartesian system (type 0)",
                                 Plain(f"type {kind}"))
            systems[int(label)] = np.asarray(matrix, dtype=float)
    return systems


def _geometry(uff: _Uff, setup: TestSetup) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Each node's position [m] and the rotation (3, 3) taking its displacement coordinate system's vectors
    (rows) to the test frame, from datasets 15 and 2411 (their coordinates converted to m) and ``setup.nodes``."""
    systems = _coordinate_systems(uff)
    length = 1.0 / float(uff.units["length"]) if uff.units is not None else 1.0

    def system(k: int, node: int, label: int, what: str) -> np.ndarray:
        if label == 0:
            return np.vstack([np.eye(3), np.zeros(3)])
        if label not in systems:
            raise InputError(uff.where(k, f"node {node}"), f"{what} coordinate system 0 (global) or one a dataset "
                             "2420 in the file defines", Plain(f"coordinate system {label}, which none defines"))
        return systems[label]

    nodes: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    for k, data in enumerate(uff.sets):
        if data.get("type") not in (15, 2411):
            continue
        for node, def_cs, disp_cs, *xyz in zip(data["node_nums"], data["def_cs"], data["disp_cs"], data["x"],
                                              data["y"], data["z"]):
            node = int(node)
            place = system(k, node, int(def_cs), "definition")
            position = length * (place[3] + np.asarray(xyz, dtype=float) @ place[:3])
            nodes[node] = (position, system(k, node, int(disp_cs), "displacement")[:3])
    for node, position in setup.nodes.items():  # the scenario's word on a node is the last
        nodes[node] = (np.asarray(position, dtype=float), np.eye(3))
    return nodes


def _channel(uff: _Uff, k: int, side: str, nodes, setup: TestSetup):
    """(node, label, position, direction, rotation) of the response (``side`` "rsp") or reference ("ref") of
    dataset ``k``, in body axes."""
    data = uff.sets[k]
    node, code = int(data[f"{side}_node"]), int(data[f"{side}_dir"])
    if not 1 <= abs(code) <= 6:
        raise InputError(uff.where(k, f"{side}_dir"), "a direction code +-1..+-6 (X, Y, Z, RX, RY, RZ)", code)
    if node not in nodes:
        raise InputError(uff.where(k, f"{side}_node"), f"coordinates of node {node} (a dataset 15 or 2411 in the "
                         "file, or [test.nodes] in the scenario)", Plain("none"))
    position, frame = nodes[node]
    axis = (abs(code) - 1) % 3
    direction = math.copysign(1.0, code) * frame[axis]
    label = f"{node}{'+' if code > 0 else '-'}{_AXIS_NAMES[abs(code) - 1]}"
    return (node, label, setup.to_body(position), setup.direction_to_body(direction), abs(code) > 3)


def _same_abscissa(uff: _Uff, k: int, x: np.ndarray, first: int, x0: np.ndarray, unit: str) -> None:
    span = max(abs(x0[-1] - x0[0]), np.finfo(float).tiny)
    if x.shape != x0.shape or np.max(np.abs(x - x0)) > ABSCISSA_RTOL * span:
        def describe(v):
            step = f", step {v[1] - v[0]:.9g}" if v.size > 1 else ""
            return f"{v.size} points from {v[0]:.9g} {unit}{step}"
        raise InputError(uff.where(k, "abscissa"), f"the abscissa of dataset {first + 1} ({describe(x0)}): one "
                         "sample rate and abscissa for every set", Plain(describe(x)))


def _load_uff(uff: _Uff, setup: TestSetup) -> TestData:
    records = [k for k, data in enumerate(uff.sets) if data.get("type") == 58]
    if not records:
        raise InputError(str(uff.path), "function datasets 58 (FRFs or time histories)", Plain("none"))
    for k in records:
        kind = int(uff.sets[k].get("func_type", 0))
        if kind not in (_TIME, _FRF):
            raise InputError(uff.where(k, "func_type"), "function type 1 (time response) or 4 (FRF)", kind)
        if kind != uff.sets[records[0]]["func_type"]:
            raise InputError(uff.where(k, "func_type"), f"function type {uff.sets[records[0]]['func_type']} as "
                             f"dataset {records[0] + 1}: one kind of data per file", kind)
    nodes = _geometry(uff, setup)
    common = {"name": uff.path.stem, "source": str(uff.path)}
    if uff.sets[records[0]]["func_type"] == _FRF:
        return _frfs(uff, records, nodes, setup, common)
    return _time(uff, records, nodes, setup, common)


def _response_type(uff: _Uff, k: int, first: int) -> int:
    kind = int(uff.sets[k].get("ordinate_spec_data_type", 0))
    if kind not in _RESPONSE_TYPES:
        raise InputError(uff.where(k, "ordinate_spec_data_type"), "a response: 8 (displacement), 11 (velocity) or 12 "
                         "(acceleration)", kind)
    expected = int(uff.sets[first].get("ordinate_spec_data_type", 0))
    if kind != expected:
        raise InputError(uff.where(k, "ordinate_spec_data_type"), f"{expected} ({_RESPONSE_TYPES[expected]}) as "
                         f"dataset {first + 1}: one response quantity per file", kind)
    return kind


def _columns(channels: list[tuple]) -> dict:
    nodes, labels, positions, directions, rotation = zip(*channels)
    return {"nodes": np.asarray(nodes, np.int64), "labels": tuple(labels), "positions": np.asarray(positions),
            "directions": np.asarray(directions), "rotation": np.asarray(rotation, bool)}


def _fields(out: list[tuple], ref: list[tuple]) -> dict:
    return {f"{side}_{name}": value for side, channels in (("out", out), ("ref", ref))
            for name, value in _columns(channels).items()}


def _frfs(uff: _Uff, records: list[int], nodes, setup: TestSetup, common: dict) -> TestData:
    first = records[0]
    out: dict[str, tuple] = {}
    ref: dict[str, tuple] = {}
    cells: dict[tuple[str, str], tuple[int, np.ndarray]] = {}
    f0 = uff.abscissa(first, frf=True)
    for k in records:
        data = uff.sets[k]
        kind = _response_type(uff, k, first)
        if int(data.get("orddenom_spec_data_type", 0)) != _FORCE:
            raise InputError(uff.where(k, "orddenom_spec_data_type"), "13 (excitation force): an FRF per force or "
                             "moment", data.get("orddenom_spec_data_type"))
        f = uff.abscissa(k, frf=True)
        _same_abscissa(uff, k, f, first, f0, "Hz")
        response, reference = _channel(uff, k, "rsp", nodes, setup), _channel(uff, k, "ref", nodes, setup)
        if (response[1], reference[1]) in cells:
            raise InputError(uff.where(k), "one FRF per response and reference pair",
                             Plain(f"a second {response[1]} per {reference[1]} (first in dataset "
                                   f"{cells[response[1], reference[1]][0] + 1})"))
        out.setdefault(response[1], response)
        ref.setdefault(reference[1], reference)
        scale = uff.factor(k, "ordinate", kind, response[4]) / uff.factor(k, "orddenom", _FORCE, reference[4])
        cells[response[1], reference[1]] = (k, scale * np.asarray(data["data"], dtype=complex))
    H = np.empty((f0.size, len(out), len(ref)), dtype=complex)
    for i, o in enumerate(out):
        for j, r in enumerate(ref):
            if (o, r) not in cells:
                raise InputError(str(uff.path), f"an FRF for every response and reference ({len(out)} x {len(ref)} "
                                 "datasets 58): a reference channel is missing", Plain(f"none of {o} per {r}"))
            H[:, i, j] = cells[o, r][1]
    quantity = _FRF_BY_RESPONSE[_RESPONSE_TYPES[int(uff.sets[first]["ordinate_spec_data_type"])]]
    return TestData(**common, kind="frf", quantity=quantity, f_hz=f0, H=H,
                    **_fields(list(out.values()), list(ref.values())))


def _even_rate(where: str, t: np.ndarray) -> float:
    """The sample rate [Hz] of the evenly spaced times ``t`` [s]."""
    step = np.diff(t)
    if t.size < 2 or step[0] <= 0 or not np.allclose(step, step[0], rtol=ABSCISSA_RTOL, atol=0):
        raise InputError(where, "evenly spaced, increasing times (one sample rate)",
                         Plain(f"steps from {step.min():.9g} to {step.max():.9g} s" if t.size > 1 else "one sample"))
    return (t.size - 1) / (t[-1] - t[0])


def _time(uff: _Uff, records: list[int], nodes, setup: TestSetup, common: dict) -> TestData:
    first = records[0]
    t0 = uff.abscissa(first, frf=False)
    rate = _even_rate(uff.where(first, "abscissa"), t0)
    responses, inputs, out, ref = [], [], [], []
    kinds = [k for k in records if int(uff.sets[k].get("ordinate_spec_data_type", 0)) != _FORCE]
    for k in records:
        data = uff.sets[k]
        _same_abscissa(uff, k, uff.abscissa(k, frf=False), first, t0, "s")
        channel = _channel(uff, k, "rsp", nodes, setup)
        values = np.asarray(data["data"], dtype=float)
        if int(data.get("ordinate_spec_data_type", 0)) == _FORCE:
            ref.append(channel)
            inputs.append(uff.factor(k, "ordinate", _FORCE, channel[4]) * values)
        else:
            kind = _response_type(uff, k, kinds[0])
            out.append(channel)
            responses.append(uff.factor(k, "ordinate", kind, channel[4]) * values)
    if not ref:
        raise InputError(str(uff.path), "a reference channel: a time history of force (ordinate type 13)",
                         Plain(f"{len(out)} responses and no force"))
    if not out:
        raise InputError(str(uff.path), "response channels (ordinate types 8, 11 or 12)",
                         Plain(f"{len(ref)} forces only"))
    quantity = _RESPONSE_TYPES[int(uff.sets[kinds[0]]["ordinate_spec_data_type"])]
    return TestData(**common, kind="time", quantity=quantity, t=t0, inputs=np.column_stack(inputs),
                    responses=np.column_stack(responses), sample_rate_hz=rate, **_fields(out, ref))


# ----------------------------------------------------------------------------------------------------
# CSV (sixdof export --format csv).
# ----------------------------------------------------------------------------------------------------

_HEADER = re.compile(r"^(?P<name>.*\S)\s*\[(?P<unit>[^\]]*)\]$")
#: What a body channel's column may add to its name (with ground motion: what the motion is measured from).
_FRAMES = ("", " (absolute)")
#: The points' quantities a CSV may hold, by the letter of their columns (``top ax``, ``top vx``, ``top dx``).
_POINT_QUANTITIES = (("a", "acceleration"), ("v", "velocity"), ("d", "displacement"))
_POINT_COLUMNS = {"acceleration": (_ACCELERATION, "m/s^2"), "velocity": (_VELOCITY, "m/s"),
                  "displacement": (_DISPLACEMENT, "m")}


def _load_csv(path: Path, scenario: Scenario | None) -> TestData:
    if scenario is None:
        raise InputError(str(path), "a scenario whose [[points]] place the CSV's columns (load_test(path, "
                         "scenario))", Plain("none"))
    with path.open(newline="", encoding="utf-8") as stream:
        rows = list(csv.reader(stream))
    if len(rows) < 3:
        raise InputError(str(path), "a header row and at least 2 rows of samples", Plain(f"{len(rows)} rows"))
    columns: dict[str, tuple[int, str]] = {}
    for j, header in enumerate(rows[0]):
        match = _HEADER.match(header.strip())
        if match is None:
            raise InputError(f"{path} column {j + 1}", "a header 'name [unit]'", header)
        columns[match["name"]] = (j, match["unit"])
    try:
        table = np.array(rows[1:], dtype=float)
    except ValueError:
        bad = next(i for i, row in enumerate(rows[1:]) if not _numbers(row, len(rows[0])))
        raise InputError(f"{path} row {bad + 2}", f"{len(rows[0])} numbers", rows[bad + 1]) from None

    def column(names: tuple[str, ...], data_type: int, rotation: bool, expected: str) -> np.ndarray:
        name = next((n for n in names if n in columns), None)
        if name is None:
            raise InputError(f"{path} column {names[0]!r}", expected, Plain("no such column"))
        j, unit = columns[name]
        factor = 1.0 if data_type == 0 and unit == "s" else unit_factor(unit, data_type, rotation)
        if factor is None:
            raise InputError(f"{path} column {name!r}", f"a unit sixdof can convert for {expected}", unit)
        return factor * table[:, j]

    t = column(("t",), 0, False, "the times 't [s]'")
    rate = _even_rate(f"{path} column 't'", t)
    if not scenario.points:
        raise InputError(f"{scenario.path or scenario.name} points", "[[points]] whose accelerations are the "
                         "responses", Plain("none"))
    # The points' quantity: the one whose columns the first point has (an export holds one), acceleration first.
    letter, quantity = next(((letter, quantity) for letter, quantity in _POINT_QUANTITIES
                             if any(f"{scenario.points[0].name} {letter}x{frame}" in columns for frame in _FRAMES)),
                            _POINT_QUANTITIES[0])
    data_type, unit = _POINT_COLUMNS[quantity]
    responses, out = [], []
    for p, point in enumerate(scenario.points):
        for a, axis in enumerate("xyz"):
            name = f"{point.name} {letter}{axis}"
            responses.append(column(tuple(name + frame for frame in _FRAMES), data_type, False,
                                    f"the {quantity} of point {point.name!r} ('{name} [{unit}]')"))
            out.append((p + 2, name, np.asarray(point.position, float), np.eye(3)[a], False))
    inputs, ref = [], []
    for j, load in enumerate(LOADS):
        moment = j >= 3
        inputs.append(column((load,), _FORCE, moment, "a reference channel: the applied loads' generalized force "
                             f"'{load} [{'N m' if moment else 'N'}]'"))
        ref.append((1, load, np.zeros(3), np.eye(3)[j % 3], moment))
    return TestData(name=path.stem, source=str(path), kind="time", quantity=quantity, t=t,
                    inputs=np.column_stack(inputs), responses=np.column_stack(responses), sample_rate_hz=rate,
                    **_fields(out, ref))


def _numbers(row: list[str], n: int) -> bool:
    try:
        return len([float(v) for v in row]) == n
    except ValueError:
        return False
