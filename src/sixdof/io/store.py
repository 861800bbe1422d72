"""The results file (HDF5): its layout, an atomic writer, and the reader.

A run's typed results (:class:`sixdof.results.RunResults`) are encoded generically from their own
field descriptions (:func:`sixdof.results.quantity`, ``label``, ``part``...) into a :class:`Results`
tree (:func:`build_results`): a flat mapping from HDF5 paths (``"time/q"``) to :class:`Dataset` objects
(array, units, named axes, attributes) plus the attributes of each group. The tree is written
atomically (:func:`save_results`) and read back (:func:`load_tree`); :func:`load_results` decodes it,
by the same descriptions, into the typed objects the run produced. The store never names a result's
fields itself: a field added to a result is written and read back as it is described.

Why h5py and not xarray's DataTree through h5netcdf: the file must keep HDF5 dimension scales shared
between groups, complex arrays as h5py's compound type, the fixed dataset names, and an atomic
write-then-rename; writing with h5py keeps each under our control, keeps xarray (and pandas) out of the
dependencies and of ``import sixdof``, and the file still opens group by group in xarray with
``engine="h5netcdf"`` (tested).

Layout conventions (the file opens in ``xarray`` through ``h5netcdf``):

- every dataset has a ``units`` attribute: SI units, ``"1"`` for dimensionless numbers, ``""`` for
  text labels. Arrays mixing translations and rotations say which unit goes with which DOF
  (``"m (x, y, z); rad (rx, ry, rz)"``) and carry a machine-readable ``dof_units`` attribute;
- every axis of every dataset is named by an HDF5 dimension scale (a 1-D dataset of the same name in
  the same group or a parent group: ``/time/t``, ``/time/dof``, ``/modal/mode``...);
- complex arrays are HDF5 compound ``(r, i)`` (h5py's convention). h5py and h5netcdf (checked with
  1.8, and tested) read them back as complex, so no real/imaginary copies are stored; older netCDF
  readers without complex support see a compound type;
- the root holds the provenance: scenario text, package versions, creation time, command line.

Only this module imports h5py, and only inside the functions that read or write a file, so that
``import sixdof`` stays light.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import os
import shlex
import sys
import uuid
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from sixdof.dofs import AXES, DOFS, LOADS, MOUNT_AXES
from sixdof.errors import InputError, Plain
from sixdof.frozen import Frozen

#: Identifies the file layout; bump FORMAT_VERSION when a fixed name changes meaning.
FORMAT = "sixdof-results"
FORMAT_VERSION = 2  # 2: written from the results' descriptions, read back as typed objects

#: ``units`` of dimensionless numbers and of text labels.
UNITS_ONE = "1"
UNITS_LABEL = ""


#: Packages whose versions are recorded in every file.
PROVENANCE_PACKAGES: tuple[str, ...] = (
    "sixdof", "numpy", "scipy", "jax", "jaxlib", "diffrax", "equinox", "h5py",
)

# HDF5 / netCDF bookkeeping attributes that are not user attributes.
_RESERVED_ATTRS = frozenset(
    {"units", "CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "_Netcdf4Dimid",
     "_Netcdf4Coordinates", "_NCProperties"}
)


# ----------------------------------------------------------------------------------------------------
# The in-memory tree.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Dataset(Frozen):
    """One array of a results file.

    Attributes
    ----------
    data : ndarray
        Read-only array (float, int, complex, or str for labels).
    units : str
        SI units; ``"1"`` dimensionless, ``""`` text labels.
    dims : tuple of str
        Name of each axis; each name is a dimension-scale dataset of the same group or a parent.
    attrs : mapping
        Other attributes (str, int, float, tuple of str, or read-only arrays).
    """

    data: np.ndarray
    units: str
    dims: tuple[str, ...]
    attrs: Mapping[str, Any] = field(default_factory=dict)

    def __check__(self) -> None:
        data = np.asarray(self.data)
        if data.dtype.kind in "OSU":
            data = np.array(data, dtype=str)
        elif data.dtype.kind == "b":
            data = data.astype(np.int8)  # netCDF has no boolean type
        else:
            data = np.array(data)
        data.flags.writeable = False
        self._derive(data=data)
        if not isinstance(self.units, str):
            raise InputError("units", "a string", self.units)
        dims = tuple(self.dims)
        if len(dims) != data.ndim or not all(isinstance(d, str) and d for d in dims):
            raise InputError("dims", f"{data.ndim} non-empty axis names for shape {data.shape}", dims)
        self._derive(dims=dims)
        self._derive(attrs=_attributes(self.attrs))

    def __repr__(self) -> str:
        return f"Dataset(shape={self.data.shape}, dtype={self.data.dtype}, units={self.units!r}, dims={self.dims})"


@dataclass(frozen=True, eq=False)
class Results(Frozen):
    """The content of a results file: datasets by path and the attributes of every group.

    ``results["time/q"]`` is the :class:`Dataset` at ``/time/q``; ``"time" in results`` tells whether
    the group exists; :attr:`attrs` maps each group path (``""`` for the root) to its attributes.
    Build one with :func:`build_results`, read one with :func:`load_results`.

    Attributes
    ----------
    datasets : mapping of str to Dataset
        Keys are paths without the leading slash (``"modal/frequency_hz"``).
    attrs : mapping of str to mapping
        Attributes of each group, keyed by group path (``""``, ``"time"``, ``"time/superposition"``).
    path : pathlib.Path or None
        The file it was read from or written to.
    """

    datasets: Mapping[str, Dataset]
    attrs: Mapping[str, Mapping[str, Any]]
    path: Path | None = None

    def __check__(self) -> None:
        datasets = {str(k).strip("/"): v for k, v in self.datasets.items()}
        for key, value in datasets.items():
            if not isinstance(value, Dataset):
                raise InputError(f"datasets[{key!r}]", "a Dataset", value)
        groups = {""}
        for key in datasets:
            parts = key.split("/")[:-1]
            groups.update("/".join(parts[:i]) for i in range(1, len(parts) + 1))
        attrs = {str(k).strip("/"): _attributes(v) for k, v in self.attrs.items()}
        groups.update(attrs)
        attrs = {g: attrs.get(g, MappingProxyType({})) for g in sorted(groups)}
        self._derive(datasets=MappingProxyType(dict(sorted(datasets.items()))))
        self._derive(attrs=MappingProxyType(attrs))
        _check_dims(self.datasets)

    # Mapping-like access ---------------------------------------------------------------------------
    def __getitem__(self, path: str) -> Dataset:
        try:
            return self.datasets[path.strip("/")]
        except KeyError:
            raise KeyError(f"no dataset {path!r} in the results; have: {', '.join(self.datasets)}") from None

    def __contains__(self, path: str) -> bool:
        path = path.strip("/")
        return path in self.datasets or path in self.attrs

    def get(self, path: str, default: Any = None) -> Dataset | Any:
        """The dataset at ``path``, or ``default`` when there is none."""
        return self.datasets.get(path.strip("/"), default)

    def array(self, path: str) -> np.ndarray:
        """The data of the dataset at ``path`` (read-only)."""
        return self[path].data

    @property
    def groups(self) -> tuple[str, ...]:
        """Paths of every group, the root ``""`` first."""
        return tuple(self.attrs)

    # Shortcuts used by figures and reports -----------------------------------------------------------
    @property
    def name(self) -> str:
        """The scenario name (``""`` when not recorded)."""
        return str(self.attrs[""].get("scenario_name", ""))

    @property
    def dofs(self) -> tuple[str, ...]:
        """DOF names in array order."""
        for path in ("model/dof", "modal/dof", "time/dof", "frf/dof"):
            if path in self.datasets:
                return tuple(self.datasets[path].data.tolist())
        return DOFS

    @property
    def mount_names(self) -> tuple[str, ...]:
        """Mount names, in the order of every per-mount array."""
        return tuple(self.array("model/mount").tolist()) if "model/mount" in self.datasets else ()



# ----------------------------------------------------------------------------------------------------
# Building the tree from the library's result objects.
# ----------------------------------------------------------------------------------------------------


class _Tree:
    """Collects datasets and group attributes; checks names while building."""

    def __init__(self) -> None:
        self.datasets: dict[str, Dataset] = {}
        self.attrs: dict[str, dict[str, Any]] = {"": {}}

    def add(self, path: str, data, units: str, dims, **attrs) -> None:
        if path in self.datasets:
            raise InputError(path, "a dataset path used once", Plain("a second dataset"))
        self.datasets[path] = Dataset(data, units, tuple(dims), attrs)

    def labels(self, group: str, name: str, values) -> None:
        """A dimension scale of text labels (``/group/name``)."""
        self.add(f"{group}/{name}", np.asarray(list(values), dtype=str), UNITS_LABEL, (name,))

    def set_attrs(self, group: str, **attrs) -> None:
        self.attrs.setdefault(group, {}).update({k: v for k, v in attrs.items() if v is not None})


# ----------------------------------------------------------------------------------------------------
# Generic encoding of the results' own field descriptions (sixdof.results: quantity, label, part, ...).
# ----------------------------------------------------------------------------------------------------

#: Axes whose labels are fixed: the scales are written wherever a dataset needs them.
FIXED_SCALES: dict[str, tuple[str, ...]] = {"dof": DOFS, "load": LOADS, "axis": AXES, "mount_axis": MOUNT_AXES}


def _join(group: str, name: str) -> str:
    return f"{group}/{name}" if group else name


def _stored(cls) -> list[tuple[dataclasses.Field, dict]]:
    """The fields of a result class that carry a storage description, in order."""
    return [(f, f.metadata["store"]) for f in dataclasses.fields(cls) if "store" in f.metadata]


def _is_scale_field(name: str, meta: dict) -> bool:
    return tuple(meta["dims"]) == (name,)


class _Encoder:
    """Writes result objects into a :class:`_Tree` from their field descriptions."""

    def __init__(self, tree: _Tree) -> None:
        self.tree = tree
        self.labels: dict[str, np.ndarray] = {}  # label scales seen so far (mount names), by axis

    def scale(self, group: str, dim: str, length: int) -> None:
        """Make sure the axis ``dim`` of a dataset in ``group`` has a dimension scale: a label or index
        scale is made in the top-level group (``frf/axis`` serves every FRF below ``/frf``)."""
        found = _scale_path(self.tree.datasets, _join(group, "_"), dim)
        if found is not None and self.tree.datasets[found].data.shape == (length,):
            return
        top = group.split("/")[0]
        if _scale_path(self.tree.datasets, _join(top, "_"), dim) is None:
            group = top
        if dim in FIXED_SCALES and len(FIXED_SCALES[dim]) == length:
            self.tree.labels(group, dim, FIXED_SCALES[dim])
        elif dim in self.labels and len(self.labels[dim]) == length:
            self.tree.labels(group, dim, self.labels[dim])
        elif dim == "mode":
            self.tree.add(_join(group, dim), np.arange(1, length + 1), UNITS_ONE, (dim,),
                          description="mode number, ascending frequency")
        else:
            self.tree.add(_join(group, dim), np.arange(length), UNITS_ONE, (dim,), description=f"{dim} index")

    def quantity(self, obj, name: str, value, meta: dict, group: str, prefix: str, lead: tuple[str, ...] = ()) -> None:
        stored = meta["name"] or name
        data = np.asarray(meta["encode"](value) if meta["encode"] else value)
        dims = (*lead, *meta["dims"])
        path = _join(group, stored if _is_scale_field(stored, meta) and not lead else prefix + stored)
        group = path.rpartition("/")[0]  # a name may hold a subgroup ("modal/damping_ratio")
        if _is_scale_field(stored, meta) and not lead:
            existing = _scale_path(self.tree.datasets, _join(group, "_"), stored)
            if existing is not None and np.array_equal(self.tree.datasets[existing].data, data):
                return  # a shared scale (the frequencies of every FRF) is stored once
            if data.dtype.kind in "OSU":
                self.labels[stored] = data
                top = group.split("/")[0]
                if existing is None and _scale_path(self.tree.datasets, _join(top, "_"), stored) is None:
                    path = _join(top, stored)  # labels (mount names) serve the whole top-level group
        else:
            for axis, dim in enumerate(dims):
                self.scale(group, dim, data.shape[axis])
        units = meta["units"](obj) if callable(meta["units"]) else meta["units"]
        attrs = {"description": meta["description"] or None, "dof_units": meta["dof_units"]}
        self.tree.add(path, data, units, dims, **{k: v for k, v in attrs.items() if v is not None})

    def encode(self, obj, group: str, prefix: str = "") -> None:
        """Every described field of ``obj`` (and its derived quantities) into ``group``."""
        for f, meta in _stored(type(obj)):
            value = getattr(obj, f.name)
            if value is None:
                continue
            kind = meta["kind"]
            if kind == "quantity":
                self.quantity(obj, f.name, value, meta, group, prefix)
            elif kind == "label":
                stored = meta["name"] or prefix + f.name
                self.tree.set_attrs(group, **{stored: meta["encode"](value) if meta["encode"] else value})
            elif kind == "part":
                sub = _join(group, meta["group"]) if meta["group"] else group
                self.encode(value, sub, prefix + meta["prefix"] if meta["prefix"] is not None else "")
            elif kind == "stacked":
                self.stacked(value, meta, _join(group, meta["group"]) if meta["group"] else group)
            elif kind == "sequence":
                for item in value:
                    self.encode(item, _join(group, f"{meta['group']}/{meta['key'](item)}"))
            elif kind == "parts":
                for key, item in value.items():
                    if "/" in key or not key:
                        raise InputError(f"{f.name}[{key!r}]", "a name without '/'", key)
                    sub = _join(group, f"{meta['group']}/{type(item).group}/{key}")
                    self.tree.set_attrs(sub, kind=type(item).__name__)
                    self.encode(item, sub)
        stores = getattr(obj, "stores", None)
        for name, derived in getattr(type(obj), "derived", {}).items():
            meta = derived.metadata["store"]
            if stores is not None and not stores(name):
                continue
            if meta["kind"] == "label":
                self.tree.set_attrs(group, **{meta["name"] or prefix + name: getattr(obj, name)})
            else:
                self.quantity(obj, name, getattr(obj, name), meta, group, prefix)

    def stacked(self, items, meta: dict, group: str) -> None:
        """Results of one class as one array per field, along the axis ``meta["dim"]``."""
        if not items:
            return
        key, dim = meta["key"], meta["dim"]
        objects = list(items.values()) if key is None else list(items)
        names = list(items.keys()) if key is None else [getattr(o, key) for o in objects]
        scale = np.asarray(names)
        self.tree.add(_join(group, dim), scale, UNITS_LABEL if scale.dtype.kind in "OSU" else UNITS_ONE, (dim,))
        if scale.dtype.kind in "OSU":
            self.labels[dim] = scale
        for f, field_meta in _stored(meta["cls"]()):
            if f.name == key:
                continue
            value = np.stack([np.asarray(field_meta["encode"](getattr(o, f.name)) if field_meta["encode"]
                                         else getattr(o, f.name)) for o in objects])
            self.quantity(objects[0], f.name, value, {**field_meta, "encode": None}, group, meta["prefix"], (dim,))


class _Decoder:
    """Reads result objects back from a :class:`Results` tree, by the same descriptions."""

    def __init__(self, results: Results) -> None:
        self.results = results

    def dataset(self, path: str):
        return self.results.datasets.get(path)

    def decode(self, cls, group: str, prefix: str = "", required: bool = True):
        """An instance of ``cls`` from ``group``, or ``None`` when nothing of it is stored."""
        kwargs: dict[str, Any] = {}
        own = False  # found something of its own, not only a dimension scale shared with its parents
        attrs = self.results.attrs.get(group, {})
        for f, meta in _stored(cls):
            kind = meta["kind"]
            if kind == "quantity":
                stored = meta["name"] or f.name
                scale = _is_scale_field(stored, meta)
                if scale:
                    path = _scale_path(self.results.datasets, _join(group, "_"), stored)
                else:
                    path = _join(group, prefix + stored)
                found = self.dataset(path) if path else None
                if found is not None:
                    own = own or not scale
                    kwargs[f.name] = meta["decode"](found.data) if meta["decode"] else found.data
            elif kind == "label":
                stored = meta["name"] or prefix + f.name
                if stored in attrs:
                    own = True
                    kwargs[f.name] = meta["decode"](attrs[stored]) if meta["decode"] else attrs[stored]
            elif kind == "part":
                sub = _join(group, meta["group"]) if meta["group"] else group
                if meta["group"] and sub not in self.results.attrs:
                    continue
                value = self.decode(meta["cls"](), sub, prefix + meta["prefix"] if meta["prefix"] is not None else "",
                                    required=False)
                if value is not None:
                    own = True
                    kwargs[f.name] = value
            elif kind == "stacked":
                value = self.stacked(meta, _join(group, meta["group"]) if meta["group"] else group)
                if value is not None:
                    own = True
                    kwargs[f.name] = value
            elif kind == "sequence":
                subgroups = self.subgroups(_join(group, meta["group"]))
                kwargs[f.name] = tuple(self.decode(meta["cls"](), sub) for sub in subgroups)
            elif kind == "parts":
                classes = meta["classes"]()
                found = {}
                for sub in self.results.groups:
                    parent, _, key = sub.rpartition("/")
                    if parent.rpartition("/")[0] == _join(group, meta["group"]) and "kind" in self.results.attrs[sub]:
                        found[key] = self.decode(classes[self.results.attrs[sub]["kind"]], sub)
                kwargs[f.name] = found
        if not own and not required:
            return None
        try:
            return cls(**kwargs)
        except TypeError as exc:  # a required part missing: not a file this version wrote
            raise InputError(group or "results", f"a complete {cls.__name__} (format version {FORMAT_VERSION})",
                             Plain(str(exc))) from None

    def subgroups(self, group: str) -> list[str]:
        """Direct subgroups of ``group``, in natural order of their names (mode_2 before mode_10)."""
        children = [g for g in self.results.groups if g.rpartition("/")[0] == group]

        def natural(name: str):
            head = name.rstrip("0123456789")
            return head, int(name[len(head):] or 0)

        return sorted(children, key=lambda g: natural(g.rpartition("/")[2]))

    def stacked(self, meta: dict, group: str):
        scale = self.dataset(_join(group, meta["dim"]))
        if scale is None:
            return None
        names = scale.data.tolist()
        columns = {}
        for f, field_meta in _stored(meta["cls"]()):
            if f.name == meta["key"]:
                continue
            found = self.dataset(_join(group, meta["prefix"] + (field_meta["name"] or f.name)))
            if found is not None:
                columns[f.name] = (found.data, field_meta["decode"])
        items = []
        for i, name in enumerate(names):
            kwargs = {k: decode(data[i]) if decode else data[i] for k, (data, decode) in columns.items()}
            if meta["key"] is not None:
                kwargs[meta["key"]] = name
            items.append(meta["cls"]()(**kwargs))
        return dict(zip(names, items)) if meta["key"] is None else tuple(items)


def build_results(run=None, *, command_line: str | None = None, created_utc: str | None = None,
                  extra: Mapping[str, Dataset] | None = None,
                  extra_attrs: Mapping[str, Mapping[str, Any]] | None = None, **parts) -> Results:
    """A run's results as a :class:`Results` tree (nothing is written), from their descriptions.

    Parameters
    ----------
    run : sixdof.results.RunResults, optional
        What the run computed. Or give its parts as keywords (``system=..., modes=...``), with
        ``scenario_text`` for the provenance.
    command_line : str, optional
        Default: this process's command line.
    created_utc : str, optional
        ISO 8601 creation time; default: now (UTC).
    extra : mapping of str to Dataset, optional
        More datasets, by path; their axes must name existing or added dimension scales.
    extra_attrs : mapping of str to mapping, optional
        More attributes, by group path (``""`` is the root).

    Returns
    -------
    Results

    Raises
    ------
    sixdof.errors.InputError
        When parts are inconsistent (a cross-check without the direct response it checks, ...).
    """
    from sixdof.results import RunResults

    if run is None:
        text = parts.pop("scenario_text", None)
        run = RunResults(**parts, provenance={"scenario_text": text or ""})
    tree = _Tree()
    _provenance(tree, run.provenance.get("scenario_text", ""), command_line, created_utc)
    _Encoder(tree).encode(run, "")
    for path, dataset in (extra or {}).items():
        if not isinstance(dataset, Dataset):
            raise InputError(f"extra[{path!r}]", "a sixdof.io.store.Dataset", dataset)
        tree.datasets[path.strip("/")] = dataset
    for group, attrs in (extra_attrs or {}).items():
        tree.set_attrs(group.strip("/"), **attrs)
    return Results(tree.datasets, tree.attrs)


def _provenance(tree: _Tree, text, command_line, created_utc) -> None:
    if command_line is None:
        command_line = shlex.join([Path(sys.argv[0]).name, *sys.argv[1:]]) if sys.argv else ""
    if created_utc is None:
        created_utc = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    tree.set_attrs(
        "",
        format=FORMAT,
        format_version=FORMAT_VERSION,
        scenario_text=text or "",
        created_utc=created_utc,
        command_line=command_line,
        python_version=sys.version.split()[0],
        **{f"version_{p}": _version(p) for p in PROVENANCE_PACKAGES},
    )


def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


# ----------------------------------------------------------------------------------------------------
# Checks and normalization shared by building and reading.
# ----------------------------------------------------------------------------------------------------


def _attributes(attrs: Mapping[str, Any]) -> Mapping[str, Any]:
    """Attributes in the form they come back from a file (so that round trips compare equal)."""
    out = {}
    for key, value in dict(attrs).items():
        if value is None:
            continue
        if not isinstance(key, str) or not key or key in _RESERVED_ATTRS:
            raise InputError("attrs", "attribute names other than units and HDF5's own", key)
        out[key] = _attribute(key, value)
    return MappingProxyType(out)


def _attribute(key: str, value: Any) -> Any:
    if isinstance(value, (str, np.str_)):
        return str(value)
    if isinstance(value, (bool, np.bool_)):
        return int(value)  # netCDF has no boolean attribute
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, (list, tuple)) and any(isinstance(v, str) for v in value) and not all(
        isinstance(v, str) for v in value
    ):
        # NumPy would turn the numbers into text silently.
        raise InputError(f"attrs[{key!r}]", "a string, a number or an array of numbers or strings", value)
    array = np.asarray(value)
    if array.ndim == 0 and array.dtype.kind in "biufcUS":
        return _attribute(key, array.item())
    if array.dtype.kind in "OSU" or (array.size == 0 and isinstance(value, tuple)):
        if array.ndim != 1 or not all(isinstance(v, (str, np.str_)) for v in array.tolist()):
            raise InputError(f"attrs[{key!r}]", "a string, a number or an array of numbers or strings", value)
        return tuple(str(v) for v in array.tolist())
    if array.dtype.kind == "b":
        array = array.astype(np.int8)
    if array.dtype.kind not in "iuf":
        raise InputError(f"attrs[{key!r}]", "a string, a number or an array of numbers or strings", value)
    array = np.array(array)
    array.flags.writeable = False
    return array


def _check_dims(datasets: Mapping[str, Dataset]) -> None:
    """Every axis names a 1-D dimension scale of its length in its group or a parent group."""
    for path, dataset in datasets.items():
        for axis, (dim, length) in enumerate(zip(dataset.dims, dataset.data.shape)):
            scale = _scale_path(datasets, path, dim)
            if scale is None:
                raise InputError(
                    f"{path}.dims[{axis}]",
                    f"the name of a dimension-scale dataset '{dim}' in its group or a parent group",
                    dim,
                )
            if datasets[scale].data.shape != (length,):
                raise InputError(
                    f"{path}.dims[{axis}]", f"scale '{scale}' of length {length}", datasets[scale].data.shape
                )


def _scale_path(datasets: Mapping[str, Dataset], path: str, dim: str) -> str | None:
    """Path of the dimension scale ``dim`` seen from dataset ``path`` (nearest group first)."""
    parts = path.split("/")[:-1]
    for i in range(len(parts), -1, -1):
        candidate = "/".join([*parts[:i], dim])
        found = datasets.get(candidate)
        if found is not None and found.dims == (dim,):
            return candidate
    return None


def _is_scale(path: str, dataset: Dataset) -> bool:
    return dataset.dims == (path.rsplit("/", 1)[-1],)


# ----------------------------------------------------------------------------------------------------
# Writing (atomic) and reading.
# ----------------------------------------------------------------------------------------------------


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
    written = save_results(results, path)
    return Results(results.datasets, results.attrs, written)


def save_results(results: Results, path: str | os.PathLike) -> Path:
    """Write a :class:`Results` tree to ``path`` atomically.

    The file is written under a temporary name in the same folder, flushed to disk (fsync) and
    renamed over ``path`` in one step (:func:`os.replace`). On any failure, including
    ``KeyboardInterrupt``, the temporary file is removed and an existing ``path`` is left untouched:
    a reader never sees a half-written results file.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    import h5py

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        with h5py.File(temporary, "x") as f:
            _write(f, results)
        # h5py has closed the file: force its bytes to disk before the rename makes it visible.
        with open(temporary, "rb+") as handle:
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    _fsync_directory(path.parent)
    return path


def _fsync_directory(directory: Path) -> None:
    """Make the rename itself durable (POSIX); silently skipped where folders cannot be opened."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _write(f, results: Results) -> None:
    for group, attrs in results.attrs.items():
        node = f.require_group(group) if group else f
        for key, value in attrs.items():
            _write_attribute(node, key, value)
    created = {}
    for path, dataset in results.datasets.items():
        created[path] = _write_dataset(f, path, dataset)
    # Scales first, then attach: h5py refuses to attach a dataset that is not yet a scale.
    for path, dataset in results.datasets.items():
        if _is_scale(path, dataset):
            created[path].make_scale(dataset.dims[0])
    for path, dataset in results.datasets.items():
        if _is_scale(path, dataset):
            continue
        for axis, dim in enumerate(dataset.dims):
            created[path].dims[axis].attach_scale(created[_scale_path(results.datasets, path, dim)])


def _write_dataset(f, path: str, dataset: Dataset):
    import h5py

    data = dataset.data
    if data.dtype.kind == "U":
        node = f.create_dataset(path, data=data.astype(object), dtype=h5py.string_dtype())
    else:
        node = f.create_dataset(path, data=data)
    node.attrs["units"] = dataset.units
    for key, value in dataset.attrs.items():
        _write_attribute(node, key, value)
    return node


def _write_attribute(node, key: str, value: Any) -> None:
    import h5py

    if isinstance(value, tuple):
        node.attrs[key] = np.asarray(value, dtype=object).astype(h5py.string_dtype()) if value else np.array(
            [], dtype=h5py.string_dtype()
        )
    else:
        node.attrs[key] = value


def load_results(path: str | os.PathLike):
    """Read a results file back into the typed objects that the run produced.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    sixdof.results.RunResults
        The system, modes, time histories, FRFs, validation ... that were written, as the library's own
        result types; ``provenance`` holds the root attributes (scenario text, versions, creation time).

    Raises
    ------
    sixdof.errors.InputError
        If the file is missing or is not a sixdof results file.
    """
    from sixdof.results import RunResults

    tree = load_tree(path)
    version = tree.attrs[""].get("format_version")
    if version != FORMAT_VERSION:
        raise InputError("results", f"a results file of format version {FORMAT_VERSION} (re-run the scenario to "
                         "write one; load_tree reads older files as a tree)", Plain(f"{path}: version {version}"))
    run = _Decoder(tree).decode(RunResults, "")
    return dataclasses.replace(run, provenance=dict(tree.attrs[""]))


def load_tree(path: str | os.PathLike) -> Results:
    """Read a results file as its tree of datasets and attributes (the file's own layout).

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Results
        Every dataset (read-only arrays with units and axis names) and every group's attributes.

    Raises
    ------
    sixdof.errors.InputError
        If the file is missing or is not a sixdof results file.
    """
    import h5py

    path = Path(path)
    if not path.is_file():
        raise InputError("results", "an existing results file (.h5)", str(path))
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise InputError("results", "an HDF5 results file written by sixdof", Plain(f"{path} ({exc})")) from None
    with f:
        if f.attrs.get("format") != FORMAT:
            raise InputError("results", f"an HDF5 file with format = {FORMAT!r}", Plain(f"{path} without it"))
        datasets: dict[str, Dataset] = {}
        attrs: dict[str, dict[str, Any]] = {"": _read_attributes(f.attrs)}

        def visit(name: str, node) -> None:
            if isinstance(node, h5py.Group):
                attrs[name] = _read_attributes(node.attrs)
                return
            if node.dtype.kind == "O" or h5py.check_string_dtype(node.dtype) is not None:
                data = np.array(node.asstr()[()], dtype=str)
            else:
                data = node[()]
            if node.is_scale:
                dims = (name.rsplit("/", 1)[-1],)
            else:
                dims = tuple(node.dims[i][0].name.rsplit("/", 1)[-1] for i in range(node.ndim))
            units = node.attrs.get("units", UNITS_LABEL)
            datasets[name] = Dataset(data, str(units), dims, _read_attributes(node.attrs))

        f.visititems(visit)
    return Results(datasets, attrs, path)


def _read_attributes(attrs) -> dict[str, Any]:
    out = {}
    for key, value in attrs.items():
        if key in _RESERVED_ATTRS:
            continue
        if isinstance(value, bytes):
            value = value.decode()
        elif isinstance(value, np.ndarray) and value.dtype.kind == "O":
            value = tuple(v.decode() if isinstance(v, bytes) else str(v) for v in value.tolist())
        out[key] = value
    return out


