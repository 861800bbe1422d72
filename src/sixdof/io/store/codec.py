"""Typed results to a results tree and back, by the results' own field descriptions (:func:`sixdof.results.quantity`,
``label``, ``part``...): :func:`build_results` and :func:`write_results`, :func:`load_results`."""

from __future__ import annotations

import dataclasses
import datetime as _dt
import functools
import os
import shlex
import sys
from collections.abc import Mapping
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.analysis.mountcheck import mount_check
from sixdof.analysis.response import mount_forces
from sixdof.design.correlation import CorrelationRun
from sixdof.design.record import DesignRecord
from sixdof.dofs import MixedUnits
from sixdof.errors import InputError, Plain
from sixdof.io.store.reader import load_tree
from sixdof.io.store.registry import registered
from sixdof.io.store.tree import (
    CORRELATION_FORMAT,
    DESIGN_FORMAT,
    FORMAT,
    FORMAT_VERSION,
    UNITS_LABEL,
    UNITS_ONE,
    Dataset,
    Results,
    _scale_path,
)
from sixdof.io.store.writer import save_results
from sixdof.results import DERIVED, FIXED_SCALES, RunResults, descriptions

#: The class at the root of a file of each ``format`` (its root attribute).
ROOTS: dict[str, type] = {FORMAT: RunResults, DESIGN_FORMAT: DesignRecord, CORRELATION_FORMAT: CorrelationRun}

#: Packages whose versions are recorded in every file.
PROVENANCE_PACKAGES: tuple[str, ...] = ("sixdof", "numpy", "scipy", "jax", "jaxlib", "diffrax", "equinox", "h5py")


# ----------------------------------------------------------------------------------------------------
# Generic encoding of the results' own field descriptions (sixdof.results: quantity, label, part, ...).
# ----------------------------------------------------------------------------------------------------


def _join(*names: str | None) -> str:
    """HDF5 path of the non-empty ``names`` (``_join("", "modal")`` is ``"modal"``)."""
    return "/".join(name for name in names if name)


def _natural(path: str) -> tuple[str, int]:
    """Sort key of a path: its text, then its trailing number as a number (mode_2 before mode_10)."""
    head = path.rstrip("0123456789")
    return head, int(path[len(head):] or 0)


class _Encoder:
    """Collects the datasets and group attributes of result objects, from their field descriptions."""

    def __init__(self) -> None:
        self.datasets: dict[str, Dataset] = {}
        self.attrs: dict[str, dict[str, Any]] = {"": {}}
        self.labels: dict[str, np.ndarray] = {}  # label scales seen so far (mount names), by axis

    def add(self, path: str, data, units: str | MixedUnits, dims, **attrs) -> None:
        if path in self.datasets:
            raise InputError(path, "a dataset path used once", Plain("a second dataset"))
        self.datasets[path] = Dataset(data, units, tuple(dims), attrs)

    def set_attrs(self, group: str, **attrs) -> None:
        self.attrs.setdefault(group, {}).update({k: v for k, v in attrs.items() if v is not None})

    def scale(self, group: str, dim: str, length: int) -> None:
        """Make sure the axis ``dim`` of a dataset in ``group`` has a dimension scale: a label scale or the
        mode numbers are made in the top-level group (``frf/axis`` serves every FRF below ``/frf``), other
        index scales in ``group`` itself (one free decay's extrema are not another's: a subgroup's axis of
        another length than its parent's would not align in xarray's datatree)."""
        found = _scale_path(self.datasets, _join(group, "_"), dim)
        if found is not None and self.datasets[found].data.shape == (length,):
            return
        labels = [v for v in (FIXED_SCALES.get(dim), self.labels.get(dim)) if v is not None and len(v) == length]
        top = group.split("/")[0]
        shared = (labels or dim == "mode") and _scale_path(self.datasets, _join(top, "_"), dim) is None
        path = _join(top if shared else group, dim)
        if labels:
            self.add(path, np.asarray(list(labels[0]), dtype=str), UNITS_LABEL, (dim,))
        elif dim == "mode":
            self.add(path, np.arange(1, length + 1), UNITS_ONE, (dim,), description="mode number, ascending frequency")
        else:
            self.add(path, np.arange(length), UNITS_ONE, (dim,), description=f"{dim} index")

    def _index(self, path: str, shape: tuple[int, ...]) -> bool:
        """Whether ``path`` is an index scale made by :meth:`scale` (0, 1, ...) of ``shape``."""
        dataset = self.datasets[path]
        return dataset.attrs.get("description") == f"{path.rsplit('/', 1)[-1]} index" and dataset.data.shape == shape

    def quantity(self, obj, name: str, data, meta: dict, group: str, prefix: str, lead: tuple[str, ...] = ()) -> None:
        """The (encoded) ``data`` of the quantity ``name`` of ``obj``, with ``lead`` axes before its own."""
        stored = meta["name"] or name
        leaf = stored.rpartition("/")[2]  # a name may hold a subgroup ("modal/damping_ratio")
        data = np.asarray(data)
        dims = (*lead, *meta["dims"])
        scale = meta["dims"] == (leaf,) and not lead
        path = _join(group, stored if scale else prefix + stored)
        group = path.rpartition("/")[0]
        if scale:
            existing = _scale_path(self.datasets, _join(group, "_"), leaf)
            if existing is not None and np.array_equal(self.datasets[existing].data, data):
                return  # a shared scale (the frequencies of every FRF) is stored once
            if existing is not None and data.dtype.kind in "OSU" and self._index(existing, data.shape):
                del self.datasets[existing]  # made for an array that came before its labels: the labels replace it
                existing = None
            if data.dtype.kind in "OSU":
                self.labels[leaf] = data
                top = group.split("/")[0]
                if existing is None and _scale_path(self.datasets, _join(top, "_"), leaf) is None:
                    path = _join(top, leaf)  # labels (mount names) serve the whole top-level group
        else:
            for dim, length in zip(dims, data.shape):
                self.scale(group, dim, length)
        units = meta["units"](obj) if callable(meta["units"]) else meta["units"]
        description = meta["description"](obj) if callable(meta["description"]) else meta["description"]
        self.add(path, data, units, dims, description=description or None)

    def encode(self, obj, group: str, prefix: str = "") -> None:
        """Every described field of ``obj``, and the derived quantities it stores, into ``group``."""
        for name, meta in descriptions(type(obj), obj):
            value = getattr(obj, name)
            if value is None:
                continue
            kind = meta["kind"]
            if kind == "quantity":
                self.quantity(obj, name, meta["encode"](value), meta, group, prefix)
            elif kind == "label":
                self.set_attrs(group, **{meta["name"] or prefix + name: meta["encode"](value)})
            elif kind == "part":  # in a subgroup of its own, or flattened into this group with a prefix
                flat = "" if meta["prefix"] is None else prefix + meta["prefix"]
                self.encode(value, _join(group, meta["group"]), flat)
            elif kind == "stacked":
                self.stacked(value, meta, _join(group, meta["group"]))
            elif kind == "sequence":
                for item in value:
                    self.encode(item, _join(group, meta["group"], meta["key"](item)))
            elif kind == "parts":
                for key, item in value.items():
                    if "/" in key or not key:
                        raise InputError(f"{name}[{key!r}]", "a name without '/'", key)
                    sub = _join(group, meta["group"], type(item).group, key)
                    self.set_attrs(sub, kind=type(item).__name__)
                    self.encode(item, sub)

    def stacked(self, items, meta: dict, group: str) -> None:
        """Results of one class as one array per field, along the axis ``meta["dim"]``."""
        if not items:
            return
        key, dim = meta["key"], meta["dim"]
        objects = list(items.values()) if key is None else list(items)
        scale = np.asarray(list(items) if key is None else [getattr(o, key) for o in objects])
        text = scale.dtype.kind in "OSU"
        self.add(_join(group, dim), scale, UNITS_LABEL if text else UNITS_ONE, (dim,))
        if text:
            self.labels[dim] = scale
        for name, field_meta in descriptions(registered(meta["cls"])):
            if name != key:
                value = np.stack([field_meta["encode"](getattr(o, name)) for o in objects])
                self.quantity(objects[0], name, value, field_meta, group, meta["prefix"], (dim,))


class _Decoder:
    """Reads result objects back from a :class:`Results` tree, by the same descriptions."""

    def __init__(self, results: Results) -> None:
        self.datasets, self.attrs = results.datasets, results.attrs

    def decode(self, cls, group: str, prefix: str = "", required: bool = True):
        """An instance of ``cls`` from ``group``, or ``None`` when nothing of it is stored and not ``required``."""
        kwargs: dict[str, Any] = {}
        own = False  # found something of its own, not only a dimension scale shared with its parents
        for name, meta in descriptions(cls):
            kind = meta["kind"]
            if kind == "quantity":
                stored = meta["name"] or name
                leaf = stored.rpartition("/")[2]
                scale = meta["dims"] == (leaf,)
                path = (_scale_path(self.datasets, _join(group, stored), leaf) if scale
                        else _join(group, prefix + stored))
                if path in self.datasets:
                    own = own or not scale
                    kwargs[name] = meta["decode"](self.datasets[path].data)
            elif kind == "label":
                stored = meta["name"] or prefix + name
                if stored in self.attrs[group]:
                    own = True
                    kwargs[name] = meta["decode"](self.attrs[group][stored])
            elif kind in ("part", "stacked"):
                sub = _join(group, meta["group"])
                if kind == "stacked":
                    value = self.stacked(meta, sub)
                elif sub in self.attrs:
                    flat = "" if meta["prefix"] is None else prefix + meta["prefix"]
                    value = self.decode(registered(meta["cls"]), sub, flat, required=False)
                else:
                    value = None
                if value is not None:
                    own = True
                    kwargs[name] = value
            elif kind == "sequence":  # its subgroups, in natural order of their names
                parent = _join(group, meta["group"])
                subgroups = sorted((g for g in self.attrs if g.rpartition("/")[0] == parent), key=_natural)
                kwargs[name] = tuple(self.decode(registered(meta["cls"]), sub) for sub in subgroups)
            elif kind == "parts":
                parent = _join(group, meta["group"])
                kwargs[name] = {sub.rpartition("/")[2]: self.decode(self.kind(attrs["kind"], meta["classes"], sub), sub)
                                for sub, attrs in self.attrs.items()
                                if sub.rpartition("/")[0].rpartition("/")[0] == parent and "kind" in attrs}
        if not own and not required:
            return None
        try:
            return cls(**kwargs)
        except TypeError as exc:  # a required part missing: not a file this version wrote
            raise InputError(group or "results", f"a complete {cls.__name__} (format version {FORMAT_VERSION})",
                             Plain(str(exc))) from None

    @staticmethod
    def kind(kind: str, classes: tuple[str, ...], group: str) -> type:
        """The class of the part stored in ``group`` (its ``kind`` attribute), one of ``classes``."""
        if kind not in classes:
            raise InputError(f"{group}.kind", " or ".join(classes), kind)
        return registered(kind)

    def stacked(self, meta: dict, group: str):
        """What :meth:`_Encoder.stacked` wrote in ``group``, or ``None`` when nothing."""
        scale = self.datasets.get(_join(group, meta["dim"]))
        if scale is None:
            return None
        key, cls, names = meta["key"], registered(meta["cls"]), scale.data.tolist()
        columns = {} if key is None else {key: (names, lambda label: label)}  # (values, decode) of each field
        for name, field_meta in descriptions(cls):
            found = self.datasets.get(_join(group, meta["prefix"] + (field_meta["name"] or name)))
            if name != key and found is not None:
                columns[name] = (found.data, field_meta["decode"])
        items = [cls(**{k: decode(data[i]) for k, (data, decode) in columns.items()}) for i in range(len(names))]
        return dict(zip(names, items)) if key is None else tuple(items)


def build_results(run=None, *, command_line: str | None = None, created_utc: str | None = None,
                  extra: Mapping[str, Dataset] | None = None,
                  extra_attrs: Mapping[str, Mapping[str, Any]] | None = None, omit: tuple[str, ...] = (),
                  **parts) -> Results:
    """A run's results as a :class:`Results` tree (nothing is written), from their descriptions.

    Parameters
    ----------
    run : sixdof.results.RunResults or sixdof.design.record.DesignRecord, optional
        What the run computed (or what ``sixdof optimize`` found: a ``design.h5``). Or give a run's parts as
        keywords (``system=..., modes=...``), with ``scenario_text`` for the provenance.
    command_line : str, optional
        Default: this process's command line.
    created_utc : str, optional
        ISO 8601 creation time; default: now (UTC).
    extra : mapping of str to Dataset, optional
        More datasets, by path; their axes must name existing or added dimension scales.
    extra_attrs : mapping of str to mapping, optional
        More attributes, by group path (``""`` is the root).
    omit : tuple of str, optional
        Derived parts of ``run`` not to store (names from :data:`sixdof.results.DERIVED`), recorded in the root's
        ``derived_omitted`` attribute: :func:`load_results` computes them again.

    Returns
    -------
    Results

    Raises
    ------
    sixdof.errors.InputError
        When parts are inconsistent (a cross-check without the direct response it checks, ...).
    """
    if run is None:
        text = parts.pop("scenario_text", None)
        run = RunResults(**parts, provenance={"scenario_text": text or ""})
    unknown = [name for name in omit if name not in DERIVED]
    if unknown:
        raise InputError("omit", f"names from {', '.join(DERIVED)}", unknown[0])
    run = dataclasses.replace(run, **{name: None for name in omit})
    if command_line is None:
        command_line = shlex.join([Path(sys.argv[0]).name, *sys.argv[1:]]) if sys.argv else ""
    if created_utc is None:
        created_utc = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    tree = _Encoder()
    kind = next((name for name, cls in ROOTS.items() if isinstance(run, cls)), None)
    if kind is None:
        raise InputError("run", " or ".join(cls.__name__ for cls in ROOTS.values()), run)
    tree.set_attrs("", format=kind, format_version=FORMAT_VERSION,
                   scenario_text=run.provenance.get("scenario_text", "") or "", created_utc=created_utc,
                   command_line=command_line, python_version=sys.version.split()[0], derived_omitted=tuple(omit),
                   **({"scenario_folder": str(folder)} if (folder := run.provenance.get("scenario_folder")) else {}),
                   **{f"version_{p}": _version(p) for p in PROVENANCE_PACKAGES})
    tree.encode(run, "")
    for path, dataset in (extra or {}).items():
        if not isinstance(dataset, Dataset):
            raise InputError(f"extra[{path!r}]", "a sixdof.io.store.Dataset", dataset)
        tree.datasets[path.strip("/")] = dataset
    for group, attrs in (extra_attrs or {}).items():
        tree.set_attrs(group.strip("/"), **attrs)
    return Results(tree.datasets, tree.attrs)


@functools.cache  # a process's packages do not change; a long run builds a tree per window (~1 ms each)
def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


def write_results(path: str | os.PathLike, run=None, **parts) -> Results:
    """Write a run's results (see :func:`build_results`) atomically to ``path``.

    Parameters
    ----------
    path : str or path-like
        The results file (``outputs/<name>/results.h5``); its folder is created when missing.
    run : sixdof.results.RunResults, optional
        What the run computed.
    **parts
        The other keyword arguments of :func:`build_results`.

    Returns
    -------
    Results
        The tree written, with :attr:`Results.path` set.
    """
    results = build_results(run, **parts)
    return Results(results.datasets, results.attrs, save_results(results, path))


def load_results(path: str | os.PathLike):
    """Read a results file back into the typed objects that the run produced.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    sixdof.results.RunResults or sixdof.design.record.DesignRecord
        The system, modes, time histories, FRFs, validation ... that were written, as the library's own
        result types (a ``design.h5``: the optimization's record); ``provenance`` holds the root attributes
        (scenario text, versions, creation time).

    Raises
    ------
    sixdof.errors.InputError
        If the file is missing or is not a sixdof results file.
    """
    tree = load_tree(path)
    version = tree.attrs[""].get("format_version")
    if version != FORMAT_VERSION:
        raise InputError("results", f"a results file of format version {FORMAT_VERSION} (re-run the scenario to "
                         "write one; load_tree reads older files as a tree)", Plain(f"{path}: version {version}"))
    run = _Decoder(tree).decode(ROOTS[tree.attrs[""]["format"]], "")
    derived = _derive(run, tree.attrs[""].get("derived_omitted", ())) if isinstance(run, RunResults) else {}
    return dataclasses.replace(run, **derived, provenance=dict(tree.attrs[""]))


def _mount_forces(run):
    return mount_forces(run.time_system or run.system, run.response)


def _mount_check(run):
    forces = run.mount_forces if run.mount_forces is not None else _mount_forces(run)
    return mount_check(run.time_system or run.system, forces, run.response.t, run.statics)


#: How each derived part of a run a file may leave out (:data:`sixdof.results.DERIVED`) is computed again
#: from what the file keeps.
DERIVABLE = {"mount_forces": _mount_forces, "mount_check": _mount_check}


def _derive(run, omitted) -> dict[str, Any]:
    """The parts of ``run`` its file left out (``omitted``), computed again from the model and the response."""
    if run.response is None or run.system is None:
        return {}
    return {name: DERIVABLE[name](run) for name in omitted if name in DERIVABLE}
