"""The results file (HDF5): its layout, an atomic writer, and the reader.

A run's typed results (:class:`sixdof.results.RunResults`) are encoded by their own field descriptions
(:func:`sixdof.results.quantity`, ``label``, ``part``...) into a :class:`Results` tree (:func:`build_results`):
:class:`Dataset` objects by HDF5 path (``"time/q"``) and the attributes of each group. The tree is written
atomically (:func:`save_results`), read back (:func:`load_tree`) and decoded by the same descriptions into
the typed objects the run produced (:func:`load_results`): a field added to a result is stored as described.

Layout conventions:

- every dataset has a ``units`` attribute that pint and UDUNITS parse: SI units (``"m/s^2"``,
  ``"N m"``), ``"1"`` for dimensionless numbers, ``""`` for text labels. An array whose DOF or load
  axis mixes translations and rotations has no single unit, hence no ``units``: it carries
  ``units_description`` (``"m (x, y, z); rad (rx, ry, rz)"``) and, per mixed axis, ``<axis>_units``
  with one parseable unit per label, the unit of an element being their product (``dof_units`` of
  ``time/q`` is ``m, m, m, rad, rad, rad``; see :class:`sixdof.dofs.MixedUnits`);
- every axis of every dataset is named by an HDF5 dimension scale (a 1-D dataset of the same name in
  the same group or a parent group: ``/time/t``, ``/time/dof``, ``/modal/mode``...);
- complex arrays are HDF5 compound ``(r, i)`` (h5py's convention), read back as complex by h5py and
  h5netcdf (checked with 1.8, and tested); older netCDF readers see a compound type;
- the root holds the provenance: scenario text, package versions, creation time, command line;
- damage is detected on reading (:func:`load_tree`): the file is written in HDF5 1.10's format
  (:data:`LIBVER`), whose object headers, B-trees and heaps carry checksums; every non-empty numeric array is
  chunked with the ``fletcher32`` filter; and each object's ``sixdof_crc32`` attribute is the CRC-32 of its
  attributes and, where no filter covers them, of its data (text labels, scalars). The root's
  ``sixdof_checksums`` attribute says so; a file without it (an earlier version's) is read with a
  :class:`UncheckedWarning`.

Why h5py and not xarray's DataTree through h5netcdf: the file must keep dimension scales shared between
groups, complex arrays, the fixed dataset names and an atomic write-then-rename; h5py keeps each under
our control and keeps xarray (and pandas) out of the dependencies, and the file still opens group by
group in xarray with ``engine="h5netcdf"`` (tested). h5py is imported only inside the functions that
read or write a file, so that ``import sixdof`` stays light.
"""

from __future__ import annotations

import contextlib
import dataclasses
import datetime as _dt
import functools
import os
import re
import shlex
import sys
import uuid
import warnings
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

# The result classes a results file holds register themselves (sixdof.results.result_type) when their modules are
# imported: each that loads no heavy library on import is imported here (the others: see _HEAVY).
import sixdof.analysis.compare  # noqa: F401
import sixdof.analysis.contact  # noqa: F401
import sixdof.analysis.frf  # noqa: F401
import sixdof.analysis.modal  # noqa: F401
import sixdof.analysis.random  # noqa: F401
import sixdof.analysis.records  # noqa: F401
import sixdof.analysis.srs  # noqa: F401
import sixdof.analysis.statics  # noqa: F401
import sixdof.analysis.steady  # noqa: F401
import sixdof.model.system  # noqa: F401
import sixdof.model.viscoelastic  # noqa: F401
import sixdof.validation.random_time  # noqa: F401
from sixdof.analysis.mountcheck import mount_check
from sixdof.analysis.response import mount_forces
from sixdof.dofs import DOFS, MixedUnits, unit_attrs
from sixdof.errors import InputError, Plain, readonly
from sixdof.frozen import Frozen
from sixdof.interrupts import held_signals
from sixdof.io.output import check_room
from sixdof.results import DERIVED, FIXED_SCALES, RunResults, descriptions, result_class

#: Identifies the file layout; bump FORMAT_VERSION when a fixed name changes meaning.
FORMAT = "sixdof-results"
FORMAT_VERSION = 2  # 2: written from the results' descriptions, read back as typed objects

#: ``units`` of dimensionless numbers and of text labels.
UNITS_ONE = "1"
UNITS_LABEL = ""

#: Packages whose versions are recorded in every file.
PROVENANCE_PACKAGES: tuple[str, ...] = ("sixdof", "numpy", "scipy", "jax", "jaxlib", "diffrax", "equinox", "h5py")

#: HDF5 format versions the writer may use (h5py's ``libver`` bounds): 1.10's, whose metadata carry checksums.
#: HDF5 1.10 (2016) or later reads the files.
LIBVER = ("v110", "v110")
#: Root attribute of a file whose objects carry checksums (see the module); its value says which.
CHECKSUMS = "sixdof_checksums"
_CHECKSUMS_TEXT = "fletcher32 on numeric arrays; sixdof_crc32: CRC-32 of each object's attributes and other data"
#: Attribute of every object (the root, each group and dataset): see :func:`_crc`.
CRC = "sixdof_crc32"

# HDF5's own attributes (dimension scales, netCDF), outside the CRC: they hold object references.
_HDF5_ATTRS = frozenset({"CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "_Netcdf4Dimid",
                         "_Netcdf4Coordinates", "_NCProperties"})
# HDF5 / netCDF bookkeeping attributes that are not user attributes.
_RESERVED_ATTRS = frozenset({"units", "units_description", CHECKSUMS, CRC, *_HDF5_ATTRS})


class UncheckedWarning(UserWarning):
    """A results file without checksums (written by an earlier version) was read: damage would go unnoticed."""


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
    units : str or MixedUnits
        SI units; ``"1"`` dimensionless, ``""`` text labels; :class:`~sixdof.dofs.MixedUnits` where
        translations and rotations mix.
    dims : tuple of str
        Name of each axis; each name is a dimension-scale dataset of the same group or a parent.
    attrs : mapping
        Other attributes (str, int, float, tuple of str, or read-only arrays).
    """

    data: np.ndarray
    units: str | MixedUnits
    dims: tuple[str, ...]
    attrs: Mapping[str, Any] = field(default_factory=dict)

    def __check__(self) -> None:
        kind = np.asarray(self.data).dtype.kind
        # Text as str. Booleans stay booleans (an HDF5 enum, which h5py, h5netcdf and xarray read as bool).
        data = readonly(self.data, str if kind in "OSU" else None)
        if not isinstance(self.units, (str, MixedUnits)):
            raise InputError("units", "a string or MixedUnits", self.units)
        dims = tuple(self.dims)
        if len(dims) != data.ndim or not all(isinstance(d, str) and d for d in dims):
            raise InputError("dims", f"{data.ndim} non-empty axis names for shape {data.shape}", dims)
        self._derive(data=data, dims=dims, attrs=_attributes(self.attrs))

    def __repr__(self) -> str:
        return f"Dataset(shape={self.data.shape}, dtype={self.data.dtype}, units={self.units!r}, dims={self.dims})"


@dataclass(frozen=True, eq=False)
class Results(Frozen):
    """The content of a results file: datasets by path and the attributes of every group.

    ``results["time/q"]`` is the :class:`Dataset` at ``/time/q``; ``"time" in results`` tells whether
    the group exists; :attr:`attrs` maps each group path (``""`` for the root) to its attributes.
    Build one with :func:`build_results`, read one with :func:`load_tree`.

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
        attrs = {str(k).strip("/"): _attributes(v) for k, v in self.attrs.items()}
        # The root, every group given attributes, and every group above a dataset.
        groups = {"", *attrs, *(key[:i] for key in datasets for i, c in enumerate(key) if c == "/")}
        attrs = {g: attrs.get(g, MappingProxyType({})) for g in sorted(groups)}
        self._derive(datasets=MappingProxyType(dict(sorted(datasets.items()))), attrs=MappingProxyType(attrs))
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

    @property
    def name(self) -> str:
        """The scenario name (``""`` when not recorded)."""
        return str(self.attrs[""].get("scenario_name", ""))

    @property
    def dofs(self) -> tuple[str, ...]:
        """DOF names in array order."""
        paths = [p for p in ("model/dof", "modal/dof", "time/dof", "frf/dof") if p in self.datasets]
        return tuple(self.datasets[paths[0]].data.tolist()) if paths else DOFS

    @property
    def mount_names(self) -> tuple[str, ...]:
        """Mount names, in the order of every per-mount array."""
        return tuple(self.array("model/mount").tolist()) if "model/mount" in self.datasets else ()


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
        data = np.asarray(data)
        dims = (*lead, *meta["dims"])
        scale = meta["dims"] == (stored,) and not lead
        path = _join(group, stored if scale else prefix + stored)
        group = path.rpartition("/")[0]  # a name may hold a subgroup ("modal/damping_ratio")
        if scale:
            existing = _scale_path(self.datasets, _join(group, "_"), stored)
            if existing is not None and np.array_equal(self.datasets[existing].data, data):
                return  # a shared scale (the frequencies of every FRF) is stored once
            if existing is not None and data.dtype.kind in "OSU" and self._index(existing, data.shape):
                del self.datasets[existing]  # made for an array that came before its labels: the labels replace it
                existing = None
            if data.dtype.kind in "OSU":
                self.labels[stored] = data
                top = group.split("/")[0]
                if existing is None and _scale_path(self.datasets, _join(top, "_"), stored) is None:
                    path = _join(top, stored)  # labels (mount names) serve the whole top-level group
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
        for name, field_meta in descriptions(_registered(meta["cls"])):
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
                scale = meta["dims"] == (stored,)
                path = _scale_path(self.datasets, _join(group, "_"), stored) if scale else _join(group, prefix + stored)
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
                    value = self.decode(_registered(meta["cls"]), sub, flat, required=False)
                else:
                    value = None
                if value is not None:
                    own = True
                    kwargs[name] = value
            elif kind == "sequence":  # its subgroups, in natural order of their names
                parent = _join(group, meta["group"])
                subgroups = sorted((g for g in self.attrs if g.rpartition("/")[0] == parent), key=_natural)
                kwargs[name] = tuple(self.decode(_registered(meta["cls"]), sub) for sub in subgroups)
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
        return _registered(kind)

    def stacked(self, meta: dict, group: str):
        """What :meth:`_Encoder.stacked` wrote in ``group``, or ``None`` when nothing."""
        scale = self.datasets.get(_join(group, meta["dim"]))
        if scale is None:
            return None
        key, cls, names = meta["key"], _registered(meta["cls"]), scale.data.tolist()
        columns = {} if key is None else {key: (names, lambda label: label)}  # (values, decode) of each field
        for name, field_meta in descriptions(cls):
            found = self.datasets.get(_join(group, meta["prefix"] + (field_meta["name"] or name)))
            if name != key and found is not None:
                columns[name] = (found.data, field_meta["decode"])
        items = [cls(**{k: decode(data[i]) for k, (data, decode) in columns.items()}) for i in range(len(names))]
        return dict(zip(names, items)) if key is None else tuple(items)


def _registered(ref):
    """The result class a field names (:func:`sixdof.results.result_class`), the heavy modules imported first,
    one after the other until it is found, when it is one of theirs."""
    for register in (lambda: None, *_HEAVY):
        register()
        try:
            return result_class(ref)
        except LookupError:
            pass
    return result_class(ref)  # not even there: its error


def _validation() -> None:
    """Register the validation's ValidationReport (its module loads SciPy)."""
    import sixdof.validation.experiment  # noqa: F401


def _batch() -> None:
    """Register the batch engine's BatchResult (a sweep's) and the direct solve's SimulationSettings (their
    modules load JAX)."""
    import sixdof.analysis.batch  # noqa: F401
    import sixdof.analysis.direct  # noqa: F401


#: The heavy modules' registrations, the lighter first: a validation's file is read without JAX (nor a run's
#: file with SciPy: ``sixdof plot`` of a run never loads JAX, tested).
_HEAVY = (_validation, _batch)


def build_results(run=None, *, command_line: str | None = None, created_utc: str | None = None,
                  extra: Mapping[str, Dataset] | None = None,
                  extra_attrs: Mapping[str, Mapping[str, Any]] | None = None, omit: tuple[str, ...] = (),
                  **parts) -> Results:
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
    tree.set_attrs("", format=FORMAT, format_version=FORMAT_VERSION,
                   scenario_text=run.provenance.get("scenario_text", "") or "", created_utc=created_utc,
                   command_line=command_line, python_version=sys.version.split()[0], derived_omitted=tuple(omit),
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
        out[key] = _attribute(value)
        if out[key] is None:
            raise InputError(f"attrs[{key!r}]", "a string, a number or an array of numbers or strings", value)
    return MappingProxyType(out)


def _attribute(value: Any) -> Any:
    """``value`` as str, bool, int, float, tuple of str or read-only array; ``None`` when it is none of these."""
    if isinstance(value, (str, np.str_)):
        return str(value)
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, (list, tuple)) and len({isinstance(v, str) for v in value}) > 1:
        return None  # NumPy would turn the numbers into text silently
    array = np.asarray(value)
    if array.ndim == 0 and array.dtype.kind in "biufU":
        return _attribute(array.item())
    if array.dtype.kind in "OSU" or (array.size == 0 and isinstance(value, tuple)):
        strings = array.ndim == 1 and all(isinstance(v, str) for v in array.tolist())
        return tuple(array.tolist()) if strings else None
    if array.dtype.kind in "biuf":
        return readonly(array, None)  # its own type: mode numbers stay integers (as a file gives them back)
    return None


def _check_dims(datasets: Mapping[str, Dataset]) -> None:
    """Every axis names a 1-D dimension scale of its length in its group or a parent group."""
    for path, dataset in datasets.items():
        for axis, (dim, length) in enumerate(zip(dataset.dims, dataset.data.shape)):
            scale = _scale_path(datasets, path, dim)
            if scale is None:
                raise InputError(f"{path}.dims[{axis}]",
                                 f"the name of a dimension-scale dataset '{dim}' in its group or a parent group", dim)
            if datasets[scale].data.shape != (length,):
                raise InputError(f"{path}.dims[{axis}]", f"scale '{scale}' of length {length}",
                                 datasets[scale].data.shape)


def _scale_path(datasets: Mapping[str, Dataset], path: str, dim: str) -> str | None:
    """Path of the dimension scale ``dim`` seen from dataset ``path`` (nearest group first)."""
    parts = path.split("/")[:-1]
    candidates = ("/".join([*parts[:i], dim]) for i in range(len(parts), -1, -1))
    return next((c for c in candidates if c in datasets and datasets[c].dims == (dim,)), None)


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
    return Results(results.datasets, results.attrs, save_results(results, path))


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
    check_room(temporary, sum(d.data.nbytes for d in results.datasets.values()))
    try:
        with held_signals():
            f = h5py.File(temporary, "x", libver=LIBVER)
            try:
                with _naming(path):
                    _write(f, results)
                    f.close()  # HDF5 writes its caches here: a full disk may fail it too
            except BaseException:
                discard(f, temporary)
                raise
        publish(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return path


@contextlib.contextmanager
def _naming(path: Path):
    """An OSError of HDF5's (a full disk: several lines, with its time stamp, buffer address and temporary name)
    as the system's error of writing ``path``: ``[Errno 28] No space left on device: '.../results.h5'``."""
    try:
        yield
    except (OSError, RuntimeError) as exc:  # h5py raises either, the system's errno in the text or not
        code = getattr(exc, "errno", None) or next(iter(re.findall(r"errno = (\d+)", str(exc))), None)
        if not code or getattr(exc, "filename", None):
            raise
        raise OSError(int(code), os.strerror(int(code)), str(path)) from None


def discard(f, temporary: Path, nodes: dict | None = None) -> None:
    """Close the h5py file ``f``, written under the name ``temporary``, after its write failed, and remove it.

    HDF5 writes what it holds in memory when it closes a file; after a full disk or the file-size limit
    (``ulimit -f``) stopped a write, those writes fail again, each in a traceback, and libhdf5 may crash
    (SIGSEGV) on the state they leave. So the file's space is given back first (it is emptied, which the
    disk allows whatever its state) and the process's file-size limit raised to its hard limit meanwhile:
    the last writes then succeed, into a file that is removed. ``nodes`` (h5py objects of the file kept open
    by the writer) are let go then: their closing writes too.
    """
    import resource

    with contextlib.suppress(Exception):
        os.ftruncate(f.id.get_vfd_handle(), 0)
    limits = resource.getrlimit(resource.RLIMIT_FSIZE)
    try:
        with contextlib.suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_FSIZE, (limits[1], limits[1]))
        with contextlib.suppress(Exception):
            if nodes is not None:
                nodes.clear()
            f.close()
    finally:
        with contextlib.suppress(ValueError, OSError):
            resource.setrlimit(resource.RLIMIT_FSIZE, limits)
        temporary.unlink(missing_ok=True)


def publish(temporary: Path, path: Path) -> None:
    """Make a closed, complete file visible as ``path`` in one step: its bytes forced to disk, renamed over
    ``path`` (:func:`os.replace`), and the rename itself made durable where folders can be opened (POSIX)."""
    with open(temporary, "rb+") as handle:
        os.fsync(handle.fileno())
    os.replace(temporary, path)
    with contextlib.suppress(OSError):
        fd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _write(f, results: Results, written=frozenset()) -> None:
    """Write the tree into the open file ``f``: attributes, datasets (those in ``written`` are in ``f`` already,
    as a streamed run's time series are, without their attributes), dimension scales, checksums."""
    crcs = {}  # each object's CRC, from what is written (reading it back would double the time of a write)
    for group, attrs in results.attrs.items():
        attrs = {**attrs, CHECKSUMS: _CHECKSUMS_TEXT} if not group else attrs
        _write_attributes(f.require_group(group) if group else f, attrs)
        crcs[group] = _crc(attrs)
    nodes = {}  # each dataset opened once: h5py's f[path] reads its type, shape and layout again each time
    for path, dataset in results.datasets.items():
        if path in written:
            nodes[path] = f[path]
            _write_dataset_attributes(nodes[path], dataset)
        else:
            nodes[path] = _write_dataset(f, path, dataset)
        # The filter checks the data of numeric arrays; the CRC that of the others (see _crc).
        data = None if nodes[path].fletcher32 else dataset.data
        crcs[path] = _crc({**unit_attrs(dataset.units), **dataset.attrs}, data)
        if _is_scale(path, dataset):
            nodes[path].make_scale(dataset.dims[0])
    # Attach once every scale is made: h5py refuses to attach a dataset that is not yet a scale.
    for path, dataset in results.datasets.items():
        if not _is_scale(path, dataset):
            for axis, dim in enumerate(dataset.dims):
                nodes[path].dims[axis].attach_scale(nodes[_scale_path(results.datasets, path, dim)])
    for path, crc in crcs.items():
        (nodes[path] if path in nodes else f[path] if path else f).attrs[CRC] = crc


def _write_dataset(f, path: str, dataset: Dataset):
    import h5py

    data = dataset.data
    if data.dtype.kind == "U":
        node = f.create_dataset(path, data=data.astype(object), dtype=h5py.string_dtype())
    elif data.size and data.ndim:  # the filter needs chunks, which a scalar or an empty array cannot have
        node = f.create_dataset(path, data=data, chunks=_chunks(data), fletcher32=True)
    else:
        node = f.create_dataset(path, data=data)
    _write_dataset_attributes(node, dataset)
    return node


#: Largest HDF5 chunk of an array written whole [bytes]: the fletcher32 checksum is per chunk.
CHUNK_BYTES = 1 << 20


def _chunks(data: np.ndarray) -> tuple[int, ...]:
    """Chunks of ``data``: whole but for its longest axis, cut to :data:`CHUNK_BYTES` (h5py's own guess cuts every
    axis, 2501 x 1 samples of a (4, 20001, 3) array: three times slower to write)."""
    shape = list(data.shape)
    axis = int(np.argmax(shape))
    pieces = -(-data.nbytes // CHUNK_BYTES)
    shape[axis] = -(-shape[axis] // pieces)  # chunks of equal length: the last one is not mostly padding
    return tuple(shape)


def _crc(attrs: Mapping[str, Any], data=None) -> int:
    """CRC-32 of an object's attributes (HDF5's own aside) and, for a dataset without the ``fletcher32`` filter
    (text, scalars, empty arrays), of its ``data``: HDF5 checks none of these (text lives in its global heap,
    outside the checksummed metadata; a scalar's bytes are raw data). The same value from what is written and
    from what h5py reads back (:func:`_bytes`)."""
    crc = 0
    for key in sorted(attrs):
        if key not in _HDF5_ATTRS and key != CRC:
            crc = zlib.crc32(_bytes(attrs[key]), zlib.crc32(key.encode(), crc))
    return crc if data is None else zlib.crc32(_bytes(data), crc)


def _bytes(value) -> bytes:
    """The bytes of a value as written (str, tuple of str, number, array) or as h5py reads it back (bytes, NumPy
    scalars, arrays of bytes or str): text as UTF-8, numbers with their type, arrays with their shape."""
    if isinstance(value, str):
        return value.encode("utf-8", "surrogatepass")
    if isinstance(value, bytes):
        return value
    if isinstance(value, tuple):  # text, as attributes hold it (an empty one would become a float array)
        return b"\0".join(_bytes(v) for v in value) + f"{(len(value),)}".encode()
    array = np.asarray(value)
    if array.dtype.kind in "OSU":
        return b"\0".join(_bytes(v) for v in array.ravel().tolist()) + f"{array.shape}".encode()
    return array.tobytes() + f"{array.dtype.str}{array.shape}".encode()


def _write_dataset_attributes(node, dataset: Dataset) -> None:
    """A dataset's units (see :class:`~sixdof.dofs.MixedUnits`) and other attributes."""
    _write_attributes(node, {**unit_attrs(dataset.units), **dataset.attrs})


def _write_attributes(node, attrs: Mapping[str, Any]) -> None:
    import h5py

    for key, value in attrs.items():
        node.attrs[key] = np.array(value, dtype=h5py.string_dtype()) if isinstance(value, tuple) else value


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
    tree = load_tree(path)
    version = tree.attrs[""].get("format_version")
    if version != FORMAT_VERSION:
        raise InputError("results", f"a results file of format version {FORMAT_VERSION} (re-run the scenario to "
                         "write one; load_tree reads older files as a tree)", Plain(f"{path}: version {version}"))
    run = _Decoder(tree).decode(RunResults, "")
    return dataclasses.replace(run, **_derive(run, tree.attrs[""].get("derived_omitted", ())),
                               provenance=dict(tree.attrs[""]))


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
        If the file is missing, is not a sixdof results file, or is damaged: a checksum that fails (see the
        module), an object HDF5 cannot read, a dimension scale that is not in the file. Nothing HDF5 reads is
        followed before it is checked (dimension-scale references are resolved by this reader, not by HDF5's
        own dimension-scale code).

    Warns
    -----
    UncheckedWarning
        The file has no checksums (written by an earlier version): damage to it would go unnoticed.
    """
    import h5py

    path = Path(path)
    if not path.is_file():
        raise InputError("results", "an existing results file (.h5)", str(path))
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise InputError("results", "an HDF5 results file written by sixdof",
                         Plain(f"{path} ({_one_line(exc)})")) from None
    with f:
        where = ["its root"]  # the object being read, for the message
        try:
            if f.attrs.get("format") != FORMAT:
                raise InputError("results", f"an HDF5 file with format = {FORMAT!r}", Plain(f"{path} without it"))
            return _read_tree(f, path, where)
        except InputError as exc:
            if exc.field == "results":
                raise
            raise _damaged(path, where[0], str(exc)) from None
        except (_Damage, OSError, RuntimeError, KeyError, ValueError, TypeError, NotImplementedError) as exc:
            what = _one_line(exc)  # h5py's errors, or what _read_tree found
            if "filter returned failure" in what:  # the fletcher32 filter is the only one the writer uses
                what = f"its data fail their checksum (fletcher32; HDF5 says: {what})"
            raise _damaged(path, where[0], what) from None


class _Damage(Exception):
    """What :func:`_read_tree` found wrong with a file's object (HDF5 read it without an error)."""


def _damaged(path: Path, where: str, what: str) -> InputError:
    return InputError("results", "an undamaged results file (re-run the scenario to write it again)",
                      Plain(f"{path}: {where}: {what}"))


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def _read_tree(f, path: Path, where: list[str]) -> Results:
    """The tree of the open file ``f`` (see :func:`load_tree`); ``where[0]`` names the object being read."""
    import h5py

    root = dict(f.attrs)
    checked = CHECKSUMS in root
    _check_crc(root, checked)
    if not checked:
        warnings.warn(f"{path} was written by an earlier version of sixdof, without checksums: damage to it would "
                      "go unnoticed (re-run the scenario to write it with them)", UncheckedWarning, stacklevel=3)
    names: list[str] = []
    where[0] = "its groups and links"
    f.visit(names.append)
    nodes = {}
    for name in names:
        where[0] = f"object {name}"
        nodes[name] = f[name]
    # Each object's address: a dimension-scale reference is followed only to one of these.
    by_address = {h5py.h5o.get_info(node.id).addr: name for name, node in nodes.items()}
    datasets: dict[str, Dataset] = {}
    attrs: dict[str, dict[str, Any]] = {"": _read_attributes(root)}
    for name, node in nodes.items():
        own = dict(node.attrs)  # each attribute read once: h5py reads it again at each access
        if isinstance(node, h5py.Group):
            where[0] = f"group {name}"
            _check_crc(own, checked)
            attrs[name] = _read_attributes(own)
            continue
        where[0] = f"dataset {name}"
        if not isinstance(node, h5py.Dataset):
            raise _Damage(f"expected a group or a dataset, found {type(node).__name__}")
        raw = node[()]
        _check_crc(own, checked, None if node.fletcher32 else raw)
        text = node.dtype.kind == "O" or h5py.check_string_dtype(node.dtype) is not None
        data = np.array([v.decode() if isinstance(v, bytes) else str(v) for v in np.ravel(raw).tolist()],
                        dtype=str).reshape(np.shape(raw)) if text else raw
        dims = _dims(f, node, own, name, by_address)
        attributes = _read_attributes(own)
        if "units_description" in own:
            units = MixedUnits.from_attrs({**attributes, "units_description": str(own["units_description"])}, dims)
            attributes = {k: v for k, v in attributes.items() if k not in {f"{d}_units" for d in dims}}
        else:
            units = str(own.get("units", UNITS_LABEL))
        datasets[name] = Dataset(data, units, dims, attributes)
    where[0] = "its dimension scales"
    return Results(datasets, attrs, path)


def _check_crc(attrs: Mapping[str, Any], checked: bool, data=None) -> None:
    """Raise unless the :data:`CRC` among an object's ``attrs`` (all of them, as read) holds for them and ``data``
    (see :func:`_crc`), or the file has no checksums (``checked`` false)."""
    if not checked:
        return
    if CRC not in attrs:
        raise _Damage(f"its checksum ({CRC}) is missing")
    stored = int(attrs[CRC])
    found = _crc(attrs, data)
    if stored != found:
        raise _Damage(f"its checksum fails (CRC-32 {found:#010x}, stored {stored:#010x}): its attributes or data "
                      "changed since it was written")


def _dims(f, node, own: Mapping[str, Any], name: str, by_address: Mapping[int, str]) -> tuple[str, ...]:
    """The axis names of the dataset ``node`` (whose attributes are ``own``): its own name if it is a dimension
    scale, else the names of the
    scales its ``DIMENSION_LIST`` references, each checked (one per axis, an object of this file that is a 1-D
    dimension scale of the axis' length) before it is opened. HDF5's dimension-scale functions are not used:
    given references that dangle they fail, or corrupt its heap (SIGABRT)."""
    import h5py

    if _text(own.get("CLASS")) == "DIMENSION_SCALE":
        return (name.rsplit("/", 1)[-1],)
    if node.ndim == 0:
        return ()
    listed = own.get("DIMENSION_LIST")
    if not isinstance(listed, np.ndarray) or listed.shape != (node.ndim,):
        got = "none" if listed is None else f"shape {np.shape(listed)}"
        raise _Damage(f"expected a dimension scale for each of its {node.ndim} axes (DIMENSION_LIST), found {got}")
    dims = []
    for axis, refs in enumerate(listed.tolist()):
        refs = np.ravel(refs).tolist()
        if len(refs) != 1 or not isinstance(refs[0], h5py.Reference) or not refs[0]:
            raise _Damage(f"axis {axis}: expected one dimension-scale reference, found {len(refs)}")
        try:
            target = f[refs[0]]
        except (OSError, RuntimeError, KeyError, ValueError, TypeError) as exc:
            raise _Damage(f"axis {axis}: its dimension scale cannot be opened ({_one_line(exc)})") from None
        scale = by_address.get(h5py.h5o.get_info(target.id).addr) if isinstance(target, h5py.Dataset) else None
        if scale is None:
            raise _Damage(f"axis {axis}: its dimension scale is not an array of the file (a dangling reference)")
        if _text(target.attrs.get("CLASS")) != "DIMENSION_SCALE" or target.shape != (node.shape[axis],):
            raise _Damage(f"axis {axis}: expected a dimension scale of length {node.shape[axis]}, found {scale} of "
                          f"shape {target.shape}")
        dims.append(scale.rsplit("/", 1)[-1])
    return tuple(dims)


def _text(value) -> str | None:
    """An attribute read as text (HDF5's fixed-length strings come as bytes), ``None`` when it is not text."""
    if isinstance(value, (bytes, np.bytes_)):
        return bytes(value).decode(errors="replace")
    return value if isinstance(value, str) else None


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


