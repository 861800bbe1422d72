"""The in-memory results tree (:class:`Results` of :class:`Dataset` by HDF5 path) and the names of the layout
(see :mod:`sixdof.io.store`): what the codec builds, the writer writes and the reader gives back."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from sixdof.dofs import DOFS, MixedUnits
from sixdof.errors import InputError, readonly
from sixdof.frozen import Frozen

#: Identifies the file layout; bump FORMAT_VERSION when a fixed name changes meaning.
FORMAT = "sixdof-results"
FORMAT_VERSION = 2  # 2: written from the results' descriptions, read back as typed objects
#: The layout of ``design.h5`` (``sixdof optimize``), written and read by the same code.
DESIGN_FORMAT = "sixdof-design"
#: The layout of ``correlation.h5`` (``sixdof correlate``).
CORRELATION_FORMAT = "sixdof-correlation"

#: ``units`` of dimensionless numbers and of text labels.
UNITS_ONE = "1"
UNITS_LABEL = ""


#: Root attribute of a file whose objects carry checksums (see the module); its value says which.
CHECKSUMS = "sixdof_checksums"
#: Attribute of every object (the root, each group and dataset): see :func:`~sixdof.io.store.checksum.crc`.
CRC = "sixdof_crc32"

# HDF5's own attributes (dimension scales, netCDF), outside the CRC: they hold object references.
_HDF5_ATTRS = frozenset({"CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "_Netcdf4Dimid",
                         "_Netcdf4Coordinates", "_NCProperties"})
# HDF5 / netCDF bookkeeping attributes that are not user attributes.
_RESERVED_ATTRS = frozenset({"units", "units_description", CHECKSUMS, CRC, *_HDF5_ATTRS})


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
