"""Reading a results file back as its tree (:func:`load_tree`), every object checked before it is used: the
checksums, and each dimension-scale reference followed only to an array of the file."""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.dofs import MixedUnits
from sixdof.errors import InputError, Plain
from sixdof.io.store.checksum import crc
from sixdof.io.store.tree import (
    _RESERVED_ATTRS,
    CHECKSUMS,
    CORRELATION_FORMAT,
    CRC,
    DESIGN_FORMAT,
    FORMAT,
    UNITS_LABEL,
    Dataset,
    Results,
)


class UncheckedWarning(UserWarning):
    """A results file without checksums (written by an earlier version) was read: damage would go unnoticed."""


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
            if f.attrs.get("format") not in (FORMAT, DESIGN_FORMAT, CORRELATION_FORMAT):
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
        text = node.dtype.kind == "O" or h5py.check_string_dtype(node.dtype) is not None
        # h5py reads a scalar text dataset as bare bytes: as an array, its shape counts as the writer's does.
        _check_crc(own, checked, None if node.fletcher32 else np.asarray(raw, dtype=object) if text else raw)
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
    (see :func:`crc`), or the file has no checksums (``checked`` false)."""
    if not checked:
        return
    if CRC not in attrs:
        raise _Damage(f"its checksum ({CRC}) is missing")
    stored = int(attrs[CRC])
    found = crc(attrs, data)
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
