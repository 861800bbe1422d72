"""Results for test and correlation tools (issue 19, point 5; issue 49, item 5): what a run computed, as
universal file format dataset 58 (what test labs exchange; written with pyuff) or as CSV.

An export holds the parts the user chose (``--what``, :data:`~sixdof.io.export_channels.CONTENTS`; default all
the run holds): ``cg``, the CG's displacement per DOF and the 6x6 receptance; ``points``, the ``[[points]]``
motions (``--point-quantity``: displacement, velocity or acceleration, the default); ``mounts``, each mount's force
on the foundation; ``frfs``, the ``[frf]`` requests: point FRFs, force and ground transmissibilities.

UFF58 conventions (:mod:`sixdof.io.export_channels`): node 0 the ground and foundation (the usual finite-element
label of the fixed ground; never a body node), node 1 the centre of gravity, nodes 2, 3... the ``[[points]]`` in
their order, then the mounts, then the places of ``[frf]`` requests that are none of these; the file opens with a
header (dataset 151, the numbering in its description line) and the nodes' positions in body axes from the CG
(dataset 15, ASCII: 6 significant digits). Directions 1-6 are +X, +Y, +Z, +RX, +RY, +RZ (body axes), 0 a direction
along no axis (its vector in the ID line 2, with a transmissibility's kind). Time histories are function type 1:
the CG's displacement (ordinate type 8), the points' motion (8, 11 or 12), the mounts' force (9, reaction force, in
N: the dynamic force each exerts on the foundation, body axes); FRFs function type 4: the receptance (response
displacement per excitation force, types 8 over 13) and point FRFs (8, 11 or 12 per their quantity, over 13);
transmissibilities function type 4 too (pyuff writes no type 5), told by their data types: a force
transmissibility's resultant force on the foundation (node 0) and each mount's force (9 over 13, N/N or N/(N m) for
a moment load), a ground transmissibility's absolute motion of its point per unit ground motion (8 over 8, m/m).
All in binary UFF58 (58b) double precision (ord_data_type 4 real, 6 complex), which reads back exactly (ASCII UFF58
keeps 6 digits of an uneven abscissa such as a log frequency grid), with SI unit labels and their length and force
exponents. An entity name is cut to UFF58's 10 characters (a point's whole name is in the ID line).

The time histories end with the run's inputs: a base-excited run's ground motion, displacement, velocity and
acceleration (types 8, 11, 12) at node 0 along +X, +Y, +Z, entity ``GROUND``; a run with loads, the applied
generalized force at the CG (excitation force, type 13, in N and N m: the reference of the receptances) at
node 1 along +X..+RZ. An input channel names its own DOF as its reference too (the response channels'
reference is ``NONE``, node 0, direction 0), so a test tool can tell the reference channels, a shaker's
control accelerometer or a force gauge, from the responses: this is sixdof's convention, UFF58 itself has
no input flag for a time history.

Beside the UFF58 file, ``<name>_modes.uff`` holds the model's undamped modes for a test lab's pre-test MAC
(issue 47, item 8): dataset 15, the nodes (the scenario's ``[test.nodes]`` in the test frame, else the
``[[points]]`` numbered 2, 3... in body axes from the CG, as above), and per mode a dataset 55 (normal mode,
3 translations per node, displacement, mass-normalized shapes [kg^-0.5] in the nodes' frame, with frequency and
modal damping ratio). Both are ASCII: UFF55 and UFF15 keep 6 significant digits.
"""

from __future__ import annotations

import csv
import tomllib
import warnings
from datetime import datetime
from pathlib import Path

import numpy as np

from sixdof.errors import InputError, Plain
from sixdof.io import output
from sixdof.io.export_channels import (
    POINT_QUANTITIES,
    Channel,
    Ratio,
    contents,
    export_nodes,
    frf_channels,
    numbering,
    scenario_points,
    time_channels,
)
from sixdof.io.store import load_results
from sixdof.model.kinematics import point_map
from sixdof.schema import build
from sixdof.validation.testdata import TestSetup

FORMATS = ("uff58", "csv")
#: The files each format writes (at most), named after the run.
_FILES = {"uff58": ("{}.uff", "{}_modes.uff"), "csv": ("{}_time.csv", "{}_frf.csv")}
_DISPLACEMENT = 8  # UFF58 specific data type
_SECONDS, _HERTZ = 17, 18
#: A time history has no denominator (UFF58 type 0, "unknown").
_NO_DENOMINATOR = {"orddenom_spec_data_type": 0, "orddenom_axis_units_lab": "NONE", "orddenom_len_unit_exp": 0,
                   "orddenom_force_unit_exp": 0, "orddenom_temp_unit_exp": 0}


def _abscissa(x: np.ndarray) -> dict:
    """UFF58 abscissa fields: even spacing (min and increment) when ``x`` is uniform, else the values."""
    step = np.diff(x)
    if x.size > 1 and np.allclose(step, step[0], rtol=1e-9, atol=0):
        return {"abscissa_spacing": 1, "abscissa_min": float(x[0]), "abscissa_inc": float(step[0])}
    return {"abscissa_spacing": 0, "abscissa_min": float(x[0]), "abscissa_inc": 0.0}


#: UFF58 record 6 gives an entity name 10 characters (format 10A1): pyuff writes a longer one whole, which pushes
#: the node and direction out of their columns (a 13-character point name read back as node 0).
_ENTITY_CHARACTERS = 10
#: An ID line (records 1-5) and a dataset 151's lines have 80 characters: pyuff writes a longer one whole.
_ID_CHARACTERS = 80
#: The length and force exponents UFF58 records 8-11 give each unit sixdof writes (time has none: UFF58's unit
#: system is length, force and temperature).
_UNIT_EXPONENTS = {"m": (1, 0), "m/s": (1, 0), "m/s^2": (1, 0), "rad": (0, 0), "rad/s": (0, 0), "rad/s^2": (0, 0),
                   "N": (0, 1), "N m": (1, 1), "s": (0, 0), "Hz": (0, 0)}


def _axis(axis: str, data_type: int, units: str) -> dict:
    """The UFF58 fields of one axis (``"abscissa"``, ``"ordinate"`` or ``"orddenom"``): its specific data type,
    unit label and the label's length and force exponents."""
    length, force = _UNIT_EXPONENTS[units]
    return {f"{axis}_spec_data_type": data_type, f"{axis}_axis_units_lab": units, f"{axis}_len_unit_exp": length,
            f"{axis}_force_unit_exp": force, f"{axis}_temp_unit_exp": 0}


def _time_set(name: str, channel: Channel, t: np.ndarray) -> dict:
    """One time history as a UFF58 dataset (function type 1, real, double precision)."""
    import pyuff

    ref_node, ref_dir, ref_entity = channel.reference
    return pyuff.prepare_58(
        binary=1, func_type=1, rsp_node=channel.node, rsp_dir=channel.direction, ref_node=ref_node, ref_dir=ref_dir,
        ord_data_type=4, id1=f"{name}: {channel.description}"[:_ID_CHARACTERS],
        rsp_ent_name=channel.entity[:_ENTITY_CHARACTERS], ref_ent_name=ref_entity[:_ENTITY_CHARACTERS],
        **_axis("abscissa", _SECONDS, "s"),
        **_axis("ordinate", channel.data_type, channel.units), **_NO_DENOMINATOR, data=channel.data, x=t,
        num_pts=t.size, **_abscissa(t))


def _ratio_set(name: str, ratio: Ratio, f: np.ndarray) -> dict:
    """One frequency response as a UFF58 dataset (function type 4 or 5, complex, double precision)."""
    import pyuff

    (rsp_node, rsp_dir, rsp_entity), (ref_node, ref_dir, ref_entity) = ratio.response, ratio.reference
    return pyuff.prepare_58(
        binary=1, func_type=ratio.func_type, rsp_node=rsp_node, rsp_dir=rsp_dir, ref_node=ref_node, ref_dir=ref_dir,
        ord_data_type=6, id1=f"{name}: {ratio.description}"[:_ID_CHARACTERS], id2=ratio.note[:_ID_CHARACTERS],
        rsp_ent_name=rsp_entity[:_ENTITY_CHARACTERS], ref_ent_name=ref_entity[:_ENTITY_CHARACTERS],
        **_axis("abscissa", _HERTZ, "Hz"), **_axis("ordinate", *ratio.ordinate),
        **_axis("orddenom", *ratio.denominator), data=ratio.values, x=f, num_pts=f.size, **_abscissa(f))


def _header_sets(run, name: str) -> list[dict]:
    """Dataset 151 (the node numbering in its description) and dataset 15 (every node in body axes from the
    CG, no coordinate system of its own)."""
    import pyuff

    nodes = export_nodes(run)
    header = pyuff.prepare_151(model_name=f"{name} (sixdof export)"[:_ID_CHARACTERS],
                               description=f"nodes: {numbering(run)}"[:_ID_CHARACTERS], db_app="sixdof",
                               program="sixdof export")
    # The run's date, not the export's (UFF's DD-MMM-YY and HH:MM:SS): one results file exports to the same bytes.
    try:
        created = datetime.fromisoformat(str(run.provenance.get("created_utc", "")))
    except ValueError:  # results written from parts, without provenance
        created = datetime(1970, 1, 1)
    header |= {f"date_{key}": created.strftime("%d-%b-%y") for key in ("db_created", "db_saved", "file_written")}
    header |= {f"time_{key}": created.strftime("%H:%M:%S") for key in ("db_created", "db_saved", "file_written")}
    zeros = np.zeros(len(nodes), dtype=np.int64)
    positions = np.array([node.position for node in nodes])
    geometry = pyuff.prepare_15(node_nums=np.array([node.number for node in nodes]), def_cs=zeros, disp_cs=zeros,
                                color=zeros + 1, x=positions[:, 0], y=positions[:, 1], z=positions[:, 2])
    return [header, geometry]


def uff58_sets(run, what=None, point_quantity: str = "acceleration") -> list[dict]:
    """The UFF58 file's datasets for the parts ``what`` (see :func:`export`): the header and nodes, the time
    histories (:func:`~sixdof.io.export_channels.time_channels`), then the frequency responses
    (:func:`~sixdof.io.export_channels.frf_channels`)."""
    parts = contents(run, what, "the results")
    name = run.name or "sixdof"
    sets = _header_sets(run, name)
    channels = time_channels(run, parts, point_quantity)
    if channels:
        t = np.asarray(run.response.t, float)
        sets += [_time_set(name, channel, t) for channel in channels]
    ratios = frf_channels(run, parts)
    if ratios:
        f = np.asarray(run.frf.direct.f_hz, float)
        sets += [_ratio_set(name, ratio, f) for ratio in ratios]
    return sets


def mode_nodes(run) -> tuple[np.ndarray, np.ndarray, TestSetup]:
    """The nodes the mode shapes are written at: node numbers (n,), their coordinates (n, 3) [m] in the test
    frame, and the ``[test]`` setup placing that frame in body axes; the scenario's ``[test.nodes]`` (read from
    the text the results file keeps), else its ``[[points]]`` (numbered 2, 3..., body axes, as the UFF58 file)."""
    raw = tomllib.loads(run.provenance.get("scenario_text", "") or "")
    setup = build(TestSetup, raw["test"], "test") if isinstance(raw.get("test"), dict) else TestSetup()
    if setup.nodes:
        numbers = sorted(setup.nodes)
        return np.asarray(numbers, np.int64), np.asarray([setup.nodes[n] for n in numbers], float), setup
    points = [position for _, position in scenario_points(run)]
    return np.arange(2, len(points) + 2, dtype=np.int64), np.asarray(points, float).reshape(-1, 3), TestSetup()


def modal_sets(run) -> list[dict]:
    """The UFF15 and UFF55 datasets of a run's modes at :func:`mode_nodes` (see the module); none without
    modes or nodes."""
    import pyuff

    numbers, local, setup = mode_nodes(run)
    if run.modes is None or numbers.size == 0:
        return []
    axes = np.asarray(setup.axes)
    # Body-axis translations of each node per mode, turned into the test frame (rows of axes: its axes).
    shapes = np.einsum("ij,njm->nim", axes, point_map(setup.to_body(local)) @ np.asarray(run.modes.shapes))
    zeros = np.zeros(numbers.size, dtype=np.int64)
    sets = [pyuff.prepare_15(node_nums=numbers, def_cs=zeros, disp_cs=zeros, color=zeros + 1, x=local[:, 0],
                             y=local[:, 1], z=local[:, 2])]
    ratios = run.damping_ratios if run.damping_ratios is not None else np.zeros(6)
    name = run.name or "sixdof"
    for j, f in enumerate(np.asarray(run.modes.frequency_hz, float)):
        zeta = float(ratios[j]) if np.isfinite(ratios[j]) else 0.0
        sets.append(pyuff.prepare_55(
            model_type=1, id1=f"{name}: mode {j + 1}", id2="sixdof undamped mode, mass-normalized [kg^-0.5]",
            id3="NONE", id4="NONE", id5="NONE", analysis_type=2, data_ch=2, spec_data_type=_DISPLACEMENT,
            data_type=2, n_data_per_node=3, r1=shapes[:, 0, j], r2=shapes[:, 1, j], r3=shapes[:, 2, j],
            node_nums=numbers, load_case=1, mode_n=j + 1, freq=float(f), modal_m=1.0, modal_damp_vis=zeta,
            modal_damp_his=0.0))
    return sets


def _write_uff(path: Path, sets: list[dict]) -> None:
    import pyuff

    with warnings.catch_warnings():  # pyuff leaves the text handle it reopens after each binary dataset open
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(sets, mode="add")


def _write_csv(path: Path, headers: list[str], columns: list[np.ndarray]) -> None:
    with path.open("w", newline="", encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow(headers)
        writer.writerows(np.column_stack(columns).tolist())


def export(results: str | Path, out_root: str | Path | None = None, fmt: str = "uff58", what=None,
           point_quantity: str = "acceleration") -> list[Path]:
    """Write a results file's time histories and frequency responses for other tools, into
    ``<out_root>/<name>_export/`` (default: beside the results file), all or nothing. The files of the other
    format there are kept: each export replaces its own format's files only.

    ``"uff58"``: ``<name>.uff`` and, with modes, ``<name>_modes.uff`` (see the module).
    ``"csv"``: ``<name>_time.csv`` (``t [s]``, then per part: the CG's q ``x [m]`` .. ``rz [rad]``, each point's
    motion ``top ax [m/s^2]`` (``dx [m]``, ``vx [m/s]``), each mount's force ``mount a Fx [N]``; then the input
    channels: a base-excited run's ground displacement, velocity and acceleration, ``ground dx [m]`` ...
    ``ground az [m/s^2]``, and the applied loads' generalized force, ``Fx [N]`` ... ``Mz [N m]``, when there are
    loads) and ``<name>_frf.csv`` (``f [Hz]``, the real and imaginary part of each receptance entry ``Re x/Fx
    [m/N]``, point FRF ``Re drive [(m/s)/N]``, force transmissibility ``Re to_floor total Fz [N/N]``, ``Re
    to_floor mount a Fz [N/N]`` and ground transmissibility ``Re base z (absolute) [m/m]``), unit in every column
    header. With the ground moving, a body channel's name says what its motion is measured from: ``x (absolute)
    [m]``, ``top ax (relative) [m/s^2]`` (the UFF58 ID lines too).

    Parameters
    ----------
    results : str or pathlib.Path
    out_root : str or pathlib.Path, optional
    fmt : str
        ``"uff58"`` or ``"csv"``.
    what : str or sequence of str, optional
        The parts: ``"cg"``, ``"points"``, ``"mounts"``, ``"frfs"`` (a comma-separated string or a sequence);
        default every part the run holds. A part the run lacks is refused.
    point_quantity : str
        The points' motion: ``"displacement"`` [m], ``"velocity"`` [m/s] or ``"acceleration"`` [m/s^2].

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    sixdof.errors.InputError
        A format, part or point quantity not known, a part the run does not hold, a file not a sixdof results file.
    """
    if fmt not in FORMATS:
        raise InputError("--format", " or ".join(FORMATS), fmt)
    if point_quantity not in POINT_QUANTITIES:
        raise InputError("--point-quantity", " or ".join(POINT_QUANTITIES), point_quantity)
    results = Path(results)
    run = load_results(results)
    if run.response is None and run.frf is None:
        raise InputError("results", "a run with time histories or FRFs to export", Plain(f"{results}: neither"))
    parts = contents(run, what, str(results))
    channels, ratios = time_channels(run, parts, point_quantity), frf_channels(run, parts)
    name = run.name or results.stem
    files = {each: [pattern.format(name) for pattern in patterns] for each, patterns in _FILES.items()}
    (uff_file, modes_file), (time_file, frf_file) = files["uff58"], files["csv"]
    target = output.check_target(out_root if out_root is not None else results.parent, name, "_export")
    written: list[str] = []

    def write(stage: Path) -> None:
        if fmt == "uff58":
            _write_uff(stage / uff_file, uff58_sets(run, parts, point_quantity))
            written.append(uff_file)
            modal = modal_sets(run)
            if modal:
                _write_uff(stage / modes_file, modal)
                written.append(modes_file)
            return
        if channels:
            _write_csv(stage / time_file, ["t [s]", *(f"{c.name} [{c.units}]" for c in channels)],
                       [run.response.t, *(c.data for c in channels)])
            written.append(time_file)
        if ratios:
            headers = ["f [Hz]", *(f"{part} {r.name} [{r.unit}]" for r in ratios for part in ("Re", "Im"))]
            columns = [run.frf.direct.f_hz, *(v for r in ratios for v in (r.values.real, r.values.imag))]
            _write_csv(stage / frf_file, headers, columns)
            written.append(frf_file)

    # Exports of both formats live side by side: re-exporting one must not take the other's files away.
    others = [file for each, names in files.items() if each != fmt for file in names]
    output.write_folder(target, write, carry=others)
    return [target / n for n in written]
