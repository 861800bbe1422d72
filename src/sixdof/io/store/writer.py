"""Writing a results tree to HDF5: atomically (a temporary file, flushed, renamed into place), with the
checksums of :mod:`sixdof.io.store.checksum`, and a full disk reported as the system's error."""

from __future__ import annotations

import contextlib
import os
import re
import resource
import uuid
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.dofs import unit_attrs
from sixdof.interrupts import held_signals
from sixdof.io.output import check_room
from sixdof.io.store.checksum import CHECKSUMS_TEXT, crc
from sixdof.io.store.tree import CHECKSUMS, CRC, Dataset, Results, _is_scale, _scale_path

#: HDF5 format versions the writer may use (h5py's ``libver`` bounds): 1.10's, whose metadata carry checksums.
#: HDF5 1.10 (2016) or later reads the files.
LIBVER = ("v110", "v110")


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
        attrs = {**attrs, CHECKSUMS: CHECKSUMS_TEXT} if not group else attrs
        _write_attributes(f.require_group(group) if group else f, attrs)
        crcs[group] = crc(attrs)
    nodes = {}  # each dataset opened once: h5py's f[path] reads its type, shape and layout again each time
    for path, dataset in results.datasets.items():
        if path in written:
            nodes[path] = f[path]
            _write_dataset_attributes(nodes[path], dataset)
        else:
            nodes[path] = _write_dataset(f, path, dataset)
        # The filter checks the data of numeric arrays; the CRC that of the others (see crc).
        data = None if nodes[path].fletcher32 else dataset.data
        crcs[path] = crc({**unit_attrs(dataset.units), **dataset.attrs}, data)
        if _is_scale(path, dataset):
            nodes[path].make_scale(dataset.dims[0])
    # Attach once every scale is made: h5py refuses to attach a dataset that is not yet a scale.
    for path, dataset in results.datasets.items():
        if not _is_scale(path, dataset):
            for axis, dim in enumerate(dataset.dims):
                nodes[path].dims[axis].attach_scale(nodes[_scale_path(results.datasets, path, dim)])
    for path, value in crcs.items():
        (nodes[path] if path in nodes else f[path] if path else f).attrs[CRC] = value


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


def _write_dataset_attributes(node, dataset: Dataset) -> None:
    """A dataset's units (see :class:`~sixdof.dofs.MixedUnits`) and other attributes."""
    _write_attributes(node, {**unit_attrs(dataset.units), **dataset.attrs})


def _write_attributes(node, attrs: Mapping[str, Any]) -> None:
    import h5py

    for key, value in attrs.items():
        node.attrs[key] = np.array(value, dtype=h5py.string_dtype()) if isinstance(value, tuple) else value
