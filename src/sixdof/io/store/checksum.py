"""The checksums of a results file beyond HDF5's own (see :mod:`sixdof.io.store`): each object's ``sixdof_crc32``,
the CRC-32 of its attributes and of the data no filter covers, the same from what is written and what is read."""

from __future__ import annotations

import zlib
from collections.abc import Mapping
from typing import Any

import numpy as np

from sixdof.io.store.tree import _HDF5_ATTRS, CRC

#: The root's :data:`~sixdof.io.store.tree.CHECKSUMS` attribute: what is checked.
CHECKSUMS_TEXT = "fletcher32 on numeric arrays; sixdof_crc32: CRC-32 of each object's attributes and other data"


def crc(attrs: Mapping[str, Any], data=None) -> int:
    """CRC-32 of an object's attributes (HDF5's own aside) and, for a dataset without the ``fletcher32`` filter
    (text, scalars, empty arrays), of its ``data``: HDF5 checks none of these (text lives in its global heap,
    outside the checksummed metadata; a scalar's bytes are raw data). The same value from what is written and
    from what h5py reads back (:func:`_bytes`)."""
    total = 0
    for key in sorted(attrs):
        if key not in _HDF5_ATTRS and key != CRC:
            total = zlib.crc32(_bytes(attrs[key]), zlib.crc32(key.encode(), total))
    return total if data is None else zlib.crc32(_bytes(data), total)


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
