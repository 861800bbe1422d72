"""The channels of ``sixdof export`` (issue 49, item 5): what each format writes, once for UFF58 and CSV.

A run's export holds the parts the user chose (:data:`CONTENTS`): ``cg``, the CG's displacement per DOF and the
6x6 receptance; ``points``, the ``[[points]]`` motions (displacement, velocity or acceleration); ``mounts``, each
mount's force on the foundation; ``frfs``, the ``[frf]`` requests (point FRFs, force and ground
transmissibilities). Time histories end with the run's inputs (:func:`time_channels`), which every export of
time histories carries: they are the references.

Node numbers (:func:`export_nodes`), the same whatever is chosen: 0 the ground (and foundation), 1 the CG,
2, 3... the ``[[points]]`` in their order, then the mounts in theirs, then each place an ``[frf]`` request names
that is none of these (in the requests' file order). Directions 1-6 are +X, +Y, +Z, +RX, +RY, +RZ (body axes), a
negative code the opposite way; a direction along no axis is code 0, its vector in the ID line 2 (6 digits).
"""

from __future__ import annotations

import tomllib
from typing import NamedTuple

import numpy as np

from sixdof.analysis.frf.records import ForceTransmissibility, PointFRF, in_file_order
from sixdof.dofs import AXES, DOF_UNITS, DOFS, FORCE_UNITS, LOADS
from sixdof.errors import InputError, Plain
from sixdof.io.settings import Point
from sixdof.schema import build

#: What an export can hold, in file order.
CONTENTS = ("cg", "points", "mounts", "frfs")
#: The point motions an export can hold, with their CSV letter, UFF58 specific data type and SI unit.
POINT_QUANTITIES = {"displacement": ("d", 8, "m"), "velocity": ("v", 11, "m/s"), "acceleration": ("a", 12, "m/s^2")}
#: UFF58 function types. A transmissibility is an FRF here: pyuff writes no function type 5 (transmissibility);
#: its data types tell it (reaction force per excitation force, displacement per displacement).
_FRF = _TRANSMISSIBILITY = 4
_DISPLACEMENT, _REACTION, _VELOCITY, _ACCELERATION, _FORCE = 8, 9, 11, 12, 13  # UFF58 specific data types
GROUND_NODE, CG_NODE = 0, 1
_NONE = (0, 0, "NONE")
#: A point FRF's quantity: the UFF58 data type of its response and the unit suffix.
_FRF_RESPONSES = {"receptance": (_DISPLACEMENT, ""), "mobility": (_VELOCITY, "/s"),
                  "accelerance": (_ACCELERATION, "/s^2")}


class Node(NamedTuple):
    """One node of an export: its ``number``, ``name`` (UFF58 entity), ``kind`` (``"cg"``, ``"point"``,
    ``"mount"`` or ``"frf"``) and ``position`` (3,) [m] from the CG in body axes."""

    number: int
    name: str
    kind: str
    position: np.ndarray


class Channel(NamedTuple):
    """One time history, as both formats write it.

    Attributes
    ----------
    name : str
        The CSV column's name, before its unit (``"top ax"``, ``"mount a Fz"``, ``"ground az"``).
    description : str
        UFF58's ID line 1, after the run's name (``"top acceleration x"``).
    node, direction, entity : int, int, str
        UFF58 response DOF.
    data_type : int
        UFF58 specific data type of the ordinate (8, 9 reaction force, 11, 12, 13 excitation force).
    units : str
        SI units of ``data``.
    data : ndarray, shape (n,)
    reference : tuple of (int, int, str)
        UFF58 reference DOF: ``NONE`` (0, 0) for a response, an input's own DOF.
    """

    name: str
    description: str
    node: int
    direction: int
    entity: str
    data_type: int
    units: str
    data: np.ndarray
    reference: tuple[int, int, str] = _NONE


class Ratio(NamedTuple):
    """One frequency response (complex, per unit reference), as both formats write it.

    Attributes
    ----------
    name, description : str
        The CSV columns' name (``"Re <name> [unit]"``, ``"Im ..."``) and UFF58's ID line 1 (after the run's
        name; 80 characters in all).
    func_type : int
        UFF58 function type: 4 (FRF), transmissibilities too.
    response, reference : tuple of (int, int, str)
        UFF58 node, direction and entity of each.
    ordinate, denominator : tuple of (int, str)
        UFF58 specific data type and SI unit of the response and of the reference.
    values : ndarray, shape (nf,), complex
    note : str
        UFF58's ID line 2: a transmissibility's kind and an off-axis direction's vector, else ``"NONE"``.
    """

    name: str
    description: str
    func_type: int
    response: tuple[int, int, str]
    reference: tuple[int, int, str]
    ordinate: tuple[int, str]
    denominator: tuple[int, str]
    values: np.ndarray
    note: str = "NONE"

    @property
    def unit(self) -> str:
        """Response unit per reference unit, each in parentheses where compound: ``"m/N"``, ``"(m/s)/(N m)"``."""
        def grouped(unit):
            return f"({unit})" if " " in unit or "/" in unit else unit

        return f"{grouped(self.ordinate[1])}/{grouped(self.denominator[1])}"


def _places(name: str, item) -> list[tuple[str, np.ndarray]]:
    if isinstance(item, PointFRF):
        return [(name, item.response_point), (name, item.load_point)]
    if isinstance(item, ForceTransmissibility):
        return [(name, item.load_point)]
    return [(name, item.response_point)]


def scenario_points(run) -> list[tuple[str, np.ndarray]]:
    """The ``[[points]]``, names and positions [m]: those whose motions the run holds, else (an FRF-only run
    stores no point motions) the scenario's, read from the text the results file keeps."""
    if run.points:
        return [(name, np.asarray(motion.position, float)) for name, motion in run.points.items()]
    raw = tomllib.loads(run.provenance.get("scenario_text", "") or "")
    points = [build(Point, table, f"points[{i}]") for i, table in enumerate(raw.get("points", []))]
    return [(point.name, np.asarray(point.position, float)) for point in points]


def export_nodes(run) -> list[Node]:
    """Every node of a run's export, numbered as the module says."""
    nodes = [Node(CG_NODE, "CG", "cg", np.zeros(3))]

    def add(name: str, kind: str, position) -> None:
        nodes.append(Node(len(nodes) + 1, name, kind, np.asarray(position, float)))

    for name, position in scenario_points(run):
        add(name, "point", position)
    if run.system is not None:
        for name, position in zip(run.system.mount_names, run.system.positions):
            add(name, "mount", position)
    for name, item in in_file_order(run.frf_extras):
        for label, place in _places(name, item):
            if _node_at(nodes, place) is None:
                add(label, "frf", place)
    return nodes


def _node_at(nodes: list[Node], position) -> Node | None:
    """The first node exactly at ``position`` (an FRF request's place given as a point's or a mount's)."""
    return next((node for node in nodes if np.array_equal(node.position, np.asarray(position, float))), None)


def direction_code(direction, rotation: bool = False) -> int:
    """UFF58 direction code of a unit vector in body axes: +-1..+-3 along +-X..+-Z, +-4..+-6 about them
    (``rotation``), 0 along no axis."""
    d = np.asarray(direction, float)
    for k in range(3):
        for sign in (1, -1):
            if np.allclose(d, sign * np.eye(3)[k], rtol=0, atol=1e-12):
                return sign * (k + 1 + 3 * rotation)
    return 0


def _note(kind: str = "", **directions) -> str:
    """ID line 2: ``kind`` and the vectors of the directions along no axis (code 0), else ``NONE``."""
    off = [f"{what} along ({', '.join(f'{v:.6g}' for v in np.asarray(d, float))}) body axes"
           for what, d in directions.items() if direction_code(d) == 0]
    return ", ".join(([kind] if kind else []) + off) or "NONE"


def contents(run, what, source: str) -> tuple[str, ...]:
    """The parts an export holds: ``what`` (a comma-separated string or a sequence of :data:`CONTENTS`), or
    every part the run holds when ``None``; a part asked for that the run lacks is refused, naming ``source``."""
    held = {"cg": run.response is not None or run.frf is not None,
            "points": run.response is not None and bool(run.points),
            "mounts": run.response is not None and run.mount_forces is not None,
            "frfs": bool(run.frf_extras)}
    if what is None:
        return tuple(part for part in CONTENTS if held[part])
    words = [w.strip() for w in what.split(",")] if isinstance(what, str) else [str(w).strip() for w in what]
    expected = f"a comma-separated list of {', '.join(CONTENTS)}"
    if not words or any(word not in CONTENTS for word in words):
        raise InputError("--what", expected, what)
    missing = [word for word in words if not held[word]]
    if missing:
        have = ", ".join(part for part in CONTENTS if held[part]) or "none of them"
        raise InputError("--what", f"parts the results hold ({have})",
                         Plain(f"{', '.join(missing)}, which {source} does not hold"))
    return tuple(part for part in CONTENTS if part in words)


def _frame(response, relative: bool = False) -> str:
    """What a body channel's motion is measured from, for its name: nothing when the ground is fixed (absolute and
    relative are the same), else " (absolute)" or " (relative)" (to the ground), as a test tool cannot tell."""
    if not response.has_ground:
        return ""
    return " (relative)" if relative else " (absolute)"


def _inputs(response) -> list[Channel]:
    """The input channels of a run's time histories: with ground motion, the ground's displacement [m],
    velocity [m/s] and acceleration [m/s^2] along x, y, z (body axes), in that order; then, when the run
    applies loads, their generalized force at the CG [N, N m] per load ``Fx .. Mz``; each its own reference."""
    channels = []
    if response.has_ground:
        motions = (("d", "displacement", _DISPLACEMENT, "m", response.ground_displacement),
                   ("v", "velocity", _VELOCITY, "m/s", response.ground_velocity),
                   ("a", "acceleration", _ACCELERATION, "m/s^2", response.ground_acceleration))
        channels += [Channel(f"ground {letter}{axis}", f"ground {kind} {axis} (input)", GROUND_NODE, k + 1,
                             "GROUND", data_type, units, np.asarray(motion[:, k], float),
                             (GROUND_NODE, k + 1, "GROUND"))
                     for letter, kind, data_type, units, motion in motions for k, axis in enumerate(AXES)]
    # Q holds the loads only (the ground acts through the mounts): all zero when the run applies none, and six
    # channels of zeros would only pose as a force input.
    if response.Q is not None and np.any(response.Q):
        channels += [Channel(load, f"applied load {load} (input)", CG_NODE, j + 1, "CG", _FORCE, FORCE_UNITS[j],
                             np.asarray(response.Q[:, j], float), (CG_NODE, j + 1, "CG"))
                     for j, load in enumerate(LOADS)]
    return channels


def time_channels(run, parts: tuple[str, ...], point_quantity: str = "acceleration") -> list[Channel]:
    """The time histories of ``parts``: the CG's displacement per DOF (``cg``), each point's motion per axis
    (``points``, in ``point_quantity``), each mount's force on the foundation per axis (``mounts``: the
    dynamic part, body axes, reaction force), then the inputs (:func:`_inputs`); none without a time response
    or without any of these parts."""
    response = run.response
    if response is None or not {"cg", "points", "mounts"} & set(parts):
        return []
    nodes = {(node.kind, node.name): node.number for node in export_nodes(run)}
    channels = []
    if "cg" in parts:
        frame = _frame(response)
        channels += [Channel(f"{dof}{frame}", f"CG {dof} displacement{frame}", CG_NODE, i + 1, "CG", _DISPLACEMENT,
                             DOF_UNITS[i], np.asarray(response.q[:, i], float)) for i, dof in enumerate(DOFS)]
    if "points" in parts:
        letter, data_type, units = POINT_QUANTITIES[point_quantity]
        for name, motion in run.points.items():
            frame, values = _frame(response, motion.relative), np.asarray(getattr(motion, point_quantity), float)
            channels += [Channel(f"{name} {letter}{axis}{frame}", f"{name} {point_quantity} {axis}{frame}",
                                 nodes["point", name], k + 1, name, data_type, units, values[:, k])
                         for k, axis in enumerate(AXES)]
    if "mounts" in parts:
        forces = run.mount_forces
        for m, name in enumerate(forces.names):
            channels += [Channel(f"mount {name} F{axis}", f"mount {name} force {axis}", nodes["mount", name], k + 1,
                                 name, _REACTION, "N", np.asarray(forces.total[m, :, k], float))
                         for k, axis in enumerate(AXES)]
    return channels + _inputs(response)


def frf_channels(run, parts: tuple[str, ...]) -> list[Ratio]:
    """The frequency responses of ``parts``: the receptance per DOF and load (``cg``), then the ``[frf]``
    requests (``frfs``, in :func:`~sixdof.analysis.frf.in_file_order`): a point FRF from its load to its
    response; a force transmissibility (reaction force per excitation force), the resultant force on the
    foundation (node 0) per axis, then each mount's; a ground transmissibility (displacement per displacement),
    the response point's absolute motion per axis per the ground's (node 0) along its direction."""
    channels = []
    if "cg" in parts and run.frf is not None:
        H = run.frf.direct.H
        channels += [Ratio(f"{dof}/{load}", f"receptance {dof} per {load}", _FRF, (CG_NODE, i + 1, "CG"),
                           (CG_NODE, j + 1, "CG"), (_DISPLACEMENT, DOF_UNITS[i]), (_FORCE, FORCE_UNITS[j]),
                           np.asarray(H[:, i, j], complex))
                     for i, dof in enumerate(DOFS) for j, load in enumerate(LOADS)]
    if "frfs" in parts:
        nodes = export_nodes(run)
        for name, item in in_file_order(run.frf_extras):
            channels += _extra(name, item, nodes)
    return channels


def _load_reference(item, nodes: list[Node]) -> tuple[tuple[int, int, str], tuple[int, str]]:
    """The UFF58 reference DOF of a request's load (its node, direction code and entity) and its data type and
    unit (excitation force, N or N m)."""
    moment = item.load_kind == "moment"
    node = _node_at(nodes, item.load_point)
    return (node.number, direction_code(item.load_direction, moment), node.name), (_FORCE, "N m" if moment else "N")


def _extra(name: str, item, nodes: list[Node]) -> list[Ratio]:
    """The channels of one ``[frf]`` request's result (see :func:`frf_channels`)."""
    if isinstance(item, PointFRF):
        data_type, suffix = _FRF_RESPONSES[item.quantity]
        rotation = item.response_kind == "rotation"
        node = _node_at(nodes, item.response_point)
        reference, denominator = _load_reference(item, nodes)
        return [Ratio(name, f"point FRF {name} ({item.quantity})", _FRF,
                      (node.number, direction_code(item.response_direction, rotation), node.name), reference,
                      (data_type, ("rad" if rotation else "m") + suffix), denominator,
                      np.asarray(item.values, complex),
                      _note(response=item.response_direction, load=item.load_direction))]
    if isinstance(item, ForceTransmissibility):
        reference, denominator = _load_reference(item, nodes)
        note = _note("force transmissibility", load=item.load_direction)
        channels = [Ratio(f"{name} total F{axis}", f"{name} foundation F{axis}", _TRANSMISSIBILITY,
                          (GROUND_NODE, k + 1, "GROUND"), reference, (_REACTION, "N"), denominator,
                          np.asarray(item.total[:, k], complex), note) for k, axis in enumerate(AXES)]
        mounts = {node.name: node.number for node in nodes if node.kind == "mount"}
        for m, mount in enumerate(item.mount_names):
            channels += [Ratio(f"{name} mount {mount} F{axis}", f"{name} mount {mount} F{axis}", _TRANSMISSIBILITY,
                               (mounts[mount], k + 1, mount), reference, (_REACTION, "N"), denominator,
                               np.asarray(item.mount_forces[:, m, k], complex), note) for k, axis in enumerate(AXES)]
        return channels
    node = _node_at(nodes, item.response_point)
    reference = (GROUND_NODE, direction_code(item.ground_direction), "GROUND")
    note = _note("ground transmissibility", ground=item.ground_direction)
    return [Ratio(f"{name} {axis} (absolute)", f"{name} {axis} (absolute)", _TRANSMISSIBILITY,
                  (node.number, k + 1, node.name), reference, (_DISPLACEMENT, "m"), (_DISPLACEMENT, "m"),
                  np.asarray(item.absolute[:, k], complex), note) for k, axis in enumerate(AXES)]


def numbering(run) -> str:
    """The node numbering in words, for a file header: ``"0 ground, 1 CG, 2-3 points, 4-7 mounts"``."""
    nodes = export_nodes(run)
    words = ["0 ground", "1 CG"]
    for kind, what in (("point", "points"), ("mount", "mounts"), ("frf", "frf places")):
        numbers = [node.number for node in nodes if node.kind == kind]
        if numbers:
            span = str(numbers[0]) if len(numbers) == 1 else f"{numbers[0]}-{numbers[-1]}"
            words.append(f"{span} {what if len(numbers) > 1 else what.removesuffix('s')}")
    return ", ".join(words)
