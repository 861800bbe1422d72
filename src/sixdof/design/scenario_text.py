"""A scenario's text with another model written into it: the optimized design's mounts (``sixdof optimize``'s
``optimized.toml``) or the updated model's mounts, body and centre of gravity (model updating's
``updated.toml``), which ``sixdof run`` takes as they are. One writer for both: comments and layout kept
(tomlkit), only the changed keys rewritten, relative file references made absolute (the file lives elsewhere)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def scenario_text(scenario, system, *, name: str, note: str, header: str, cg_offset=None) -> str:
    """``scenario``'s text with the mounts and body of ``system``.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario
        The scenario the text comes from (its ``text``, ``path``, ``description`` and ``given_system``).
    system : sixdof.model.system.System
        The model to write: every mount's ``position``, ``stiffness`` and (where given or turned) ``axes``, and
        the body's ``mass`` and ``inertia`` where they differ from the scenario's own.
    name : str
        The new scenario's name.
    note : str
        Said in the description (after the original's, in parentheses).
    header : str
        Comment lines put first (each ending in a newline).
    cg_offset : array_like, shape (3,), optional
        Where the centre of gravity of ``system`` lies from the scenario's [m, body axes]: every other position
        measured from the CG (``[[points]]`` positions, loads' ``point``, the test nodes or the test frame's
        origin) is moved by ``-cg_offset``. ``system``'s mount positions are taken as they are (already from
        the new CG).

    Returns
    -------
    str
        Every float is written at full precision (``repr``), so the text reads back as ``system`` exactly.
    """
    import tomlkit

    document = tomlkit.parse(scenario.text)
    document["name"] = name
    document["description"] = f"{scenario.description} ({note})" if scenario.description else note
    given = scenario.given_system.body
    if system.body.mass != given.mass:
        document["body"]["mass"] = float(system.body.mass)
    inertia = np.asarray(system.body.inertia, dtype=float)
    if not np.array_equal(inertia, np.asarray(given.inertia, dtype=float)):
        document["body"]["inertia"] = _inertia(inertia)
    for table, mount in zip(document["mounts"], system.mounts):
        table["position"] = [float(v) for v in mount.position]
        table["stiffness"] = [float(v) for v in mount.stiffness]
        if "axes" in table or not np.allclose(mount.axes, np.eye(3), rtol=0, atol=1e-15):
            table["axes"] = [[float(v) for v in row] for row in mount.axes]
    if cg_offset is not None and np.any(np.asarray(cg_offset, dtype=float) != 0):
        _move_from_cg(document, np.asarray(cg_offset, dtype=float))
    base = scenario.path.parent if scenario.path is not None else Path(".")
    _absolute_files(document, base.resolve())
    return header + tomlkit.dumps(document)


def _inertia(inertia: np.ndarray) -> list:
    """The inertia tensor as a scenario writes it: principal moments [Jxx, Jyy, Jzz] where diagonal, else 3 x 3."""
    if np.count_nonzero(inertia - np.diag(np.diag(inertia))) == 0:
        return [float(v) for v in np.diag(inertia)]
    return [[float(v) for v in row] for row in inertia]


def _shifted(value, offset: np.ndarray) -> list[float]:
    return [float(v) for v in np.asarray([float(v) for v in value]) - offset]


def _move_from_cg(document, offset: np.ndarray) -> None:
    """Every position measured from the CG in ``document`` moved by ``-offset`` (the CG moved by ``offset``)."""
    for table in document.get("points", []):
        table["position"] = _shifted(table["position"], offset)
    for table in document.get("loads", []):
        if "point" in table:
            table["point"] = _shifted(table["point"], offset)
    test = document.get("test")
    if test is not None:
        if "origin" in test:  # the test frame's nodes are measured from its origin, which lies from the CG
            test["origin"] = _shifted(test["origin"], offset)
        else:  # the nodes are in body axes from the CG
            nodes = test.get("nodes", {})
            for key in list(nodes.keys()):
                nodes[key] = _shifted(nodes[key], offset)


def _absolute_files(node, base: Path) -> None:
    """Every ``file = "..."`` below ``node`` made absolute against ``base``."""
    items = node.items() if hasattr(node, "items") else enumerate(node) if isinstance(node, list) else ()
    for key, value in list(items):
        if key == "file" and isinstance(value, str) and not Path(value).is_absolute():
            node[key] = str(base / value)
        elif hasattr(value, "items") or isinstance(value, list):
            _absolute_files(value, base)
