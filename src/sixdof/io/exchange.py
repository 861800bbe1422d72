"""Results for test and correlation tools (issue 19, point 5): a run's time histories and FRFs as universal
file format dataset 58 (what test labs exchange; written with pyuff) or as CSV.

UFF58 conventions used: node 1 is the centre of gravity, nodes 2, 3... the ``[[points]]`` in their order,
node 0 the ground (the usual finite-element label of the fixed ground; never a body node); directions 1-6
are +X, +Y, +Z, +RX, +RY, +RZ (body axes). Time histories are function type 1 (the CG's displacement,
ordinate type 8; the points' accelerations, type 12), the receptance function type 4 (response displacement
per excitation force, types 8 over 13), all in binary UFF58 (58b) double precision, which reads back exactly
(ASCII UFF58 keeps 6 digits of an uneven abscissa such as a log frequency grid), with SI unit labels and
their length and force exponents. An entity name is cut to UFF58's 10 characters (a point's whole name is in
the ID line).

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
from pathlib import Path
from typing import NamedTuple

import numpy as np

from sixdof.dofs import DOF_UNITS, DOFS, FORCE_UNITS, LOADS
from sixdof.errors import InputError, Plain
from sixdof.io import output
from sixdof.io.settings import Point
from sixdof.io.store import load_results
from sixdof.model.kinematics import point_map
from sixdof.schema import build
from sixdof.validation.testdata import TestSetup

FORMATS = ("uff58", "csv")
#: The files each format writes (at most), named after the run.
_FILES = {"uff58": ("{}.uff", "{}_modes.uff"), "csv": ("{}_time.csv", "{}_frf.csv")}
_TIME, _FRF = 1, 4  # UFF58 function types
_DISPLACEMENT, _VELOCITY, _ACCELERATION, _FORCE = 8, 11, 12, 13  # UFF58 specific data types
_SECONDS, _HERTZ = 17, 18
#: A time history has no denominator (UFF58 type 0, "unknown").
_NO_DENOMINATOR = {"orddenom_spec_data_type": 0, "orddenom_axis_units_lab": "NONE", "orddenom_len_unit_exp": 0,
                   "orddenom_force_unit_exp": 0, "orddenom_temp_unit_exp": 0}
#: The ground's UFF58 node (see the module).
_GROUND_NODE = 0


class _Input(NamedTuple):
    """One input channel of a run's time histories, as both formats write it.

    Attributes
    ----------
    name : str
        Short name: the CSV column's, before its unit (``"ground az"``).
    description : str
        What it is, for UFF58's ID line 1 (``"ground acceleration z"``).
    entity, node, direction : str, int, int
        UFF58 DOF identification: entity name, node and direction (1-6 for +X..+RZ).
    data_type : int
        UFF58 specific data type of the ordinate (8 displacement, 11 velocity, 12 acceleration, 13 excitation
        force).
    units : str
        SI units of ``data``.
    data : ndarray, shape (n,)
        The channel at the response's times.
    """

    name: str
    description: str
    entity: str
    node: int
    direction: int
    data_type: int
    units: str
    data: np.ndarray


def _inputs(response) -> list[_Input]:
    """The input channels of a run's time histories: with ground motion, the ground's displacement [m],
    velocity [m/s] and acceleration [m/s^2] along x, y, z (body axes), in that order; then, when the run
    applies loads, their generalized force at the CG [N, N m] per load ``Fx .. Mz``.

    Parameters
    ----------
    response : sixdof.results.TimeHistory

    Returns
    -------
    list of _Input
    """
    channels = []
    if response.has_ground:
        motions = (("d", "displacement", _DISPLACEMENT, "m", response.ground_displacement),
                   ("v", "velocity", _VELOCITY, "m/s", response.ground_velocity),
                   ("a", "acceleration", _ACCELERATION, "m/s^2", response.ground_acceleration))
        channels += [_Input(f"ground {letter}{axis}", f"ground {kind} {axis}", "GROUND", _GROUND_NODE, k + 1,
                            data_type, units, np.asarray(motion[:, k], float))
                     for letter, kind, data_type, units, motion in motions for k, axis in enumerate("xyz")]
    # Q holds the loads only (the ground acts through the mounts): all zero when the run applies none, and six
    # channels of zeros would only pose as a force input.
    if response.Q is not None and np.any(response.Q):
        channels += [_Input(load, f"applied load {load}", "CG", 1, j + 1, _FORCE, FORCE_UNITS[j],
                            np.asarray(response.Q[:, j], float)) for j, load in enumerate(LOADS)]
    return channels


def _abscissa(x: np.ndarray) -> dict:
    """UFF58 abscissa fields: even spacing (min and increment) when ``x`` is uniform, else the values."""
    step = np.diff(x)
    if x.size > 1 and np.allclose(step, step[0], rtol=1e-9, atol=0):
        return {"abscissa_spacing": 1, "abscissa_min": float(x[0]), "abscissa_inc": float(step[0])}
    return {"abscissa_spacing": 0, "abscissa_min": float(x[0]), "abscissa_inc": 0.0}


#: UFF58 record 6 gives an entity name 10 characters (format 10A1): pyuff writes a longer one whole, which pushes
#: the node and direction out of their columns (a 13-character point name read back as node 0).
_ENTITY_CHARACTERS = 10
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


def _frame(response, relative: bool = False) -> str:
    """What a body channel's motion is measured from, for its name: nothing when the ground is fixed (absolute and
    relative are the same), else " (absolute)" or " (relative)" (to the ground), as a test tool cannot tell."""
    if not response.has_ground:
        return ""
    return " (relative)" if relative else " (absolute)"


def _time_history(label: str, node: int, direction: int, entity: str, data_type: int, units: str, data, t,
                  reference: tuple[int, int, str] = (0, 0, "NONE")) -> dict:
    """One time history as a UFF58 dataset (function type 1, real, double precision): ``label`` its ID line,
    the response at ``node`` along ``direction`` of ``entity``, with ``reference`` (node, direction, entity)."""
    import pyuff

    ref_node, ref_dir, ref_entity = reference
    return pyuff.prepare_58(
        binary=1, func_type=_TIME, rsp_node=node, rsp_dir=direction, ref_node=ref_node, ref_dir=ref_dir,
        ord_data_type=4, id1=label, rsp_ent_name=entity[:_ENTITY_CHARACTERS],
        ref_ent_name=ref_entity[:_ENTITY_CHARACTERS], **_axis("abscissa", _SECONDS, "s"),
        **_axis("ordinate", data_type, units), **_NO_DENOMINATOR, data=np.asarray(data, float), x=t, num_pts=t.size,
        **_abscissa(t))


def uff58_sets(run) -> list[dict]:
    """The UFF58 datasets of a run: the CG's displacement per DOF, each point's acceleration per axis, the
    input channels (:func:`_inputs`), and the receptance per response DOF and load (see the module)."""
    import pyuff

    sets = []
    name = run.name or "sixdof"
    if run.response is not None:
        t = np.asarray(run.response.t, float)
        for i, dof in enumerate(DOFS):
            sets.append(_time_history(f"{name}: CG {dof} displacement{_frame(run.response)}", 1, i + 1, "CG",
                                      _DISPLACEMENT, DOF_UNITS[i], run.response.q[:, i], t))
        for k, (point, motion) in enumerate(run.points.items()):
            for axis in range(3):
                sets.append(_time_history(
                    f"{name}: {point} acceleration {'xyz'[axis]}{_frame(run.response, motion.relative)}", k + 2,
                    axis + 1, point, _ACCELERATION, "m/s^2", motion.acceleration[:, axis], t))
        for channel in _inputs(run.response):
            sets.append(_time_history(f"{name}: {channel.description} (input)", channel.node, channel.direction,
                                      channel.entity, channel.data_type, channel.units, channel.data, t,
                                      reference=(channel.node, channel.direction, channel.entity)))
    if run.frf is not None:
        frf = run.frf.direct
        f = np.asarray(frf.f_hz, float)
        for i, dof in enumerate(DOFS):
            for j, load in enumerate(LOADS):
                sets.append(pyuff.prepare_58(
                    binary=1, func_type=_FRF, rsp_node=1, rsp_dir=i + 1, ref_node=1, ref_dir=j + 1, ord_data_type=6,
                    id1=f"{name}: receptance {dof} per {load}", rsp_ent_name="CG", ref_ent_name="CG",
                    **_axis("abscissa", _HERTZ, "Hz"), **_axis("ordinate", _DISPLACEMENT, DOF_UNITS[i]),
                    **_axis("orddenom", _FORCE, FORCE_UNITS[j]),
                    data=np.asarray(frf.H[:, i, j], complex), x=f, num_pts=f.size, **_abscissa(f)))
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
    points = [build(Point, t, f"points[{i}]").position for i, t in enumerate(raw.get("points", []))]
    if not points and run.points:  # results written from parts, without the scenario's text
        points = [motion.position for motion in run.points.values()]
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


def _write_csv(path: Path, headers: list[str], columns: list[np.ndarray]) -> None:
    with path.open("w", newline="", encoding="utf-8") as stream:
        writer = csv.writer(stream)
        writer.writerow(headers)
        writer.writerows(np.column_stack(columns).tolist())


def export(results: str | Path, out_root: str | Path | None = None, fmt: str = "uff58") -> list[Path]:
    """Write a results file's time histories and FRFs for other tools, into ``<out_root>/<name>_export/``
    (default: beside the results file), all or nothing. The files of the other format there are kept: each
    export replaces its own format's files only.

    ``"uff58"``: ``<name>.uff`` and, with modes, ``<name>_modes.uff`` (see the module).
    ``"csv"``: ``<name>_time.csv`` (t [s], the CG's q [m, rad],
    each point's acceleration [m/s^2], then the input channels: a base-excited run's ground displacement,
    velocity and acceleration, ``ground dx [m]`` ... ``ground az [m/s^2]``, and the applied loads'
    generalized force, ``Fx [N]`` ... ``Mz [N m]``, when there are loads) and ``<name>_frf.csv`` (f [Hz], the
    real and imaginary part of each receptance entry), unit in every column header. With the ground moving, a
    body channel's name says what its motion is measured from: ``x (absolute) [m]``, ``top ax (relative) [m/s^2]``
    (the UFF58 ID lines too).

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    if fmt not in FORMATS:
        raise InputError("--format", " or ".join(FORMATS), fmt)
    results = Path(results)
    run = load_results(results)
    if run.response is None and run.frf is None:
        raise InputError("results", "a run with time histories or FRFs to export", Plain(f"{results}: neither"))
    name = run.name or results.stem
    files = {each: [pattern.format(name) for pattern in patterns] for each, patterns in _FILES.items()}
    (uff_file, modes_file), (time_file, frf_file) = files["uff58"], files["csv"]
    target = output.check_target(out_root if out_root is not None else results.parent, name, "_export")
    written: list[str] = []

    def write(stage: Path) -> None:
        if fmt == "uff58":
            import pyuff

            path = stage / uff_file
            pyuff.UFF(str(path)).write_sets(uff58_sets(run), mode="add")
            written.append(path.name)
            modal = modal_sets(run)
            if modal:
                pyuff.UFF(str(stage / modes_file)).write_sets(modal, mode="add")
                written.append(modes_file)
            return
        if run.response is not None:
            frame = _frame(run.response)
            headers = ["t [s]", *(f"{d}{frame} [{u}]" for d, u in zip(DOFS, DOF_UNITS))]
            columns = [run.response.t, *run.response.q.T]
            for point, motion in run.points.items():
                headers += [f"{point} a{a}{_frame(run.response, motion.relative)} [m/s^2]" for a in "xyz"]
                columns += list(motion.acceleration.T)
            for channel in _inputs(run.response):
                headers.append(f"{channel.name} [{channel.units}]")
                columns.append(channel.data)
            _write_csv(stage / time_file, headers, columns)
            written.append(time_file)
        if run.frf is not None:
            frf = run.frf.direct
            headers, columns = ["f [Hz]"], [frf.f_hz]
            for i, dof in enumerate(DOFS):
                for j, load in enumerate(LOADS):
                    unit = f"{DOF_UNITS[i]}/{FORCE_UNITS[j]}" if " " not in FORCE_UNITS[j] else \
                        f"{DOF_UNITS[i]}/({FORCE_UNITS[j]})"
                    headers += [f"Re {dof}/{load} [{unit}]", f"Im {dof}/{load} [{unit}]"]
                    columns += [frf.H[:, i, j].real, frf.H[:, i, j].imag]
            _write_csv(stage / frf_file, headers, columns)
            written.append(frf_file)

    # Exports of both formats live side by side: re-exporting one must not take the other's files away.
    others = [file for each, names in files.items() if each != fmt for file in names]
    output.write_folder(target, write, carry=others)
    return [target / n for n in written]
