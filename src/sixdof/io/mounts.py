"""The ``[[mounts]]`` tables of a scenario file: each mount, its Maxwell branches, its bump stop, and the measured
tables read beside it (``dynamic_stiffness``, ``force_deflection``), checked (:mod:`sixdof.io.scenario` reads the
file)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.errors import InputError, Plain, choice_check, number_check
from sixdof.files import read_table_csv
from sixdof.model import viscoelastic
from sixdof.model.hysteresis import BoucWen, FrictionPendulum, check_on_mount
from sixdof.model.nonlinear import ForceDeflection
from sixdof.model.parts import Maxwell, Mount
from sixdof.model.viscoelastic import AXES, read_dynamic_stiffness
from sixdof.schema import Table, build, make, reject_unknown


@dataclass(frozen=True, eq=False)
class MeasuredStiffness:
    """A ``dynamic_stiffness`` table of a mount, read and checked (the fit is made by
    :func:`sixdof.workflows.prepare.prepare`).

    Attributes
    ----------
    mount, axis : str
    field : str
        Its place in the file (``mounts[0].dynamic_stiffness``), for the errors of its fit.
    f_hz, storage, loss : ndarray
        The data [Hz, N/m, N/m] (:func:`~sixdof.model.viscoelastic.read_dynamic_stiffness`).
    terms : int or None
    max_modulus_error, max_loss_angle_error_deg : float
        The worst fit accepted [1, deg].
    file : str
        As the scenario names it.
    """

    mount: str
    axis: str
    field: str
    f_hz: np.ndarray
    storage: np.ndarray
    loss: np.ndarray
    terms: Any
    max_modulus_error: float
    max_loss_angle_error_deg: float
    file: str


#: The keys of a ``bump_stop`` table and the :class:`~sixdof.model.system.Mount` fields they fill.
_BUMP_STOP = {"clearance": "bump_clearance", "stiffness": "bump_stiffness"}
#: The keys of a ``[[mounts]]`` table (as docs/reference/scenario.md lists them): the Mount's fields, ``bump_stop`` in
#: place of the two it fills, and the tables read beside the mount.
#: Its unknown keys are checked against this list alone.
_MOUNT_KEYS = (*(f.name for f in dataclasses.fields(Mount) if f.init and f.name not in _BUMP_STOP.values()),
              "bump_stop", "maxwell", "dynamic_stiffness", "force_deflection", "hysteresis", "friction_pendulum")
#: The laws a ``hysteresis`` table names, and the keys of each besides ``law``.
_HYSTERESIS_LAWS = {"bouc_wen": BoucWen}


def read_mount(raw: Any, path: str, base_dir: Path) -> tuple[Mount, list[Maxwell], list, list, list]:
    """A ``[[mounts]]`` table: the mount, its ``[[mounts.maxwell]]`` branches, its ``dynamic_stiffness`` tables
    (:class:`MeasuredStiffness`, fitted later), its ``force_deflection`` tables
    (:class:`~sixdof.model.nonlinear.ForceDeflection`) and its hysteretic laws (``hysteresis``,
    ``friction_pendulum``: :mod:`sixdof.model.hysteresis`)."""
    if not isinstance(raw, dict):
        raise InputError(path, "a table", raw)
    for key in _BUMP_STOP.values():  # the model's names of bump_stop's keys
        if key in raw:
            raise InputError(f"{path}.{key}", "bump_stop = {clearance = [...], stiffness = [...]}", Plain(key))
    reject_unknown(raw, _MOUNT_KEYS, path)
    table = dict(raw)
    maxwell, measured = table.pop("maxwell", []), table.pop("dynamic_stiffness", [])
    stop, curves = table.pop("bump_stop", None), table.pop("force_deflection", [])
    hysteresis, pendulum = table.pop("hysteresis", None), table.pop("friction_pendulum", None)
    if stop is not None:
        keys = Table(stop, f"{path}.bump_stop", tuple(_BUMP_STOP))
        table.update({model: keys.value(key) for key, model in _BUMP_STOP.items()})
    try:
        mount = build(Mount, table, path)
    except InputError as error:  # named as the file names them
        for key, model in _BUMP_STOP.items():
            if error.field.endswith(f".{model}"):
                raise InputError(error.field.replace(model, f"bump_stop.{key}"), error.expected, error.got) from None
        raise
    tables = Table({"maxwell": maxwell}, path, ("maxwell",)).tables("maxwell")
    branches = []
    for j, branch in enumerate(tables):
        field = f"{path}.maxwell[{j}]"
        keys = Table(branch, field, ("stiffness", "tau"))
        branches.append(make(Maxwell, field, name=f"{mount.name} {j + 1}", mount=mount.name,
                             stiffness=keys.value("stiffness"), tau=keys.value("tau")))
    fits = []
    for j, data in enumerate([measured] if isinstance(measured, dict) else measured):
        field = f"{path}.dynamic_stiffness" + (f"[{j}]" if isinstance(measured, list) else "")
        fits.append(_fit(mount, data, field, base_dir))
    axes = [fit.axis for fit in fits]
    if len(set(axes)) < len(axes):
        raise InputError(f"{path}.dynamic_stiffness", "one table per axis", Plain(f"axes {', '.join(axes)}"))
    tables = []
    for j, curve in enumerate([curves] if isinstance(curves, dict) else curves):
        field = f"{path}.force_deflection" + (f"[{j}]" if isinstance(curves, list) else "")
        keys = Table(curve, field, ("file", "axis"))
        file = keys.string("file")
        deflection, force = read_table_csv(file, base_dir, f"{field}.file", ("deflection in m", "force in N"))
        tables.append(make(ForceDeflection, field, mount=mount.name, axis=keys.value("axis"), deflection=deflection,
                           force=force, source=file))
    axes = [t.axis for t in tables]
    if len(set(axes)) < len(axes):
        raise InputError(f"{path}.force_deflection", "one table per axis", Plain(f"axes {', '.join(axes)}"))
    if set(axes) & {fit.axis for fit in fits}:
        raise InputError(f"{path}.force_deflection", "axes without a dynamic_stiffness fit (each replaces the "
                         "axis's stiffness)", Plain(f"axes {', '.join(sorted(set(axes)))}"))
    laws = _hysteretic_laws(mount, hysteresis, pendulum, path)
    taken = {law_axis for law in laws for law_axis in law.axes} & set(axes)
    if taken:
        raise InputError(f"{path}.force_deflection", "axes without a hysteretic law (each replaces the axis's "
                         "force)", Plain(f"axes {', '.join(sorted(taken))}"))
    return mount, branches, fits, tables, laws


def _hysteretic_laws(mount: Mount, hysteresis: Any, pendulum: Any, path: str) -> list:
    """The ``hysteresis`` and ``friction_pendulum`` tables of a mount, each checked on it
    (:func:`~sixdof.model.hysteresis.check_on_mount`)."""
    laws = []
    if hysteresis is not None:
        field = f"{path}.hysteresis"
        keys = _table(hysteresis, field)
        law = choice_check(tuple(_HYSTERESIS_LAWS))(keys.pop("law", None), f"{field}.law")
        laws.append((field, build(_HYSTERESIS_LAWS[law], {"mount": mount.name, **keys}, field)))
    if pendulum is not None:
        field = f"{path}.friction_pendulum"
        laws.append((field, build(FrictionPendulum, {"mount": mount.name, **_table(pendulum, field)}, field)))
    if len(laws) == 2 and set(laws[0][1].axes) & set(laws[1][1].axes):
        raise InputError(f"{path}.friction_pendulum", "axes without a hysteresis law (one law per axis)",
                         Plain(f"axes {', '.join(sorted(set(laws[0][1].axes) & set(laws[1][1].axes)))}"))
    for field, law in laws:
        check_on_mount(law, mount, field, path)
    return [law for _, law in laws]


def _table(raw: Any, field: str) -> dict:
    if not isinstance(raw, dict):
        raise InputError(field, "a table", raw)
    return dict(raw)


def _fit(mount: Mount, raw: Any, field: str, base_dir: Path) -> MeasuredStiffness:
    """One ``dynamic_stiffness`` table: the measured data of ``file`` along ``axis``, read and checked."""
    table = Table(raw, field, ("file", "axis", "terms", "max_modulus_error", "max_loss_angle_error_deg"))
    axis = choice_check(tuple(AXES))(table.value("axis"), f"{field}.axis")
    if mount.loss_factor[AXES.index(axis)] > 0:
        raise InputError(f"{field}.axis", "an axis without a loss_factor (the measured loss factor replaces it)",
                         axis)
    file = table.string("file")
    f_hz, storage, loss = read_dynamic_stiffness((base_dir / file).resolve(), f"{field}.file")
    limits = [number_check(expected, low=0.0, strict=True)(table.value(key, default), f"{field}.{key}")
              for key, default, expected in (
                  ("max_modulus_error", viscoelastic.FIT_MODULUS_ERROR, "a relative error > 0"),
                  ("max_loss_angle_error_deg", viscoelastic.FIT_LOSS_ANGLE_ERROR_DEG, "an angle in deg > 0"))]
    return MeasuredStiffness(mount=mount.name, axis=axis, field=field, f_hz=f_hz, storage=storage, loss=loss,
                             terms=table.value("terms", None), max_modulus_error=limits[0],
                             max_loss_angle_error_deg=limits[1], file=file)

