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

The package's modules, each of one job: :mod:`~sixdof.io.store.tree` (the in-memory tree and the layout's
names), :mod:`~sixdof.io.store.codec` (typed results to a tree and back), :mod:`~sixdof.io.store.registry`
(the result classes a file may hold), :mod:`~sixdof.io.store.writer` (the atomic HDF5 writer),
:mod:`~sixdof.io.store.checksum` and :mod:`~sixdof.io.store.reader` (the checked reader).
"""

from sixdof.io.store.codec import DERIVABLE, PROVENANCE_PACKAGES, ROOTS, build_results, load_results, write_results
from sixdof.io.store.reader import UncheckedWarning, load_tree
from sixdof.io.store.tree import (
                                  CHECKSUMS,
                                  CORRELATION_FORMAT,
                                  CRC,
                                  DESIGN_FORMAT,
                                  FORMAT,
                                  FORMAT_VERSION,
                                  UNITS_LABEL,
                                  UNITS_ONE,
                                  Dataset,
                                  Results,
)
from sixdof.io.store.writer import CHUNK_BYTES, LIBVER, discard, publish, save_results

__all__ = ["CHECKSUMS", "CHUNK_BYTES", "CORRELATION_FORMAT", "CRC",
           "DERIVABLE", "DESIGN_FORMAT", "FORMAT", "FORMAT_VERSION", "LIBVER",
           "PROVENANCE_PACKAGES", "ROOTS", "UNITS_LABEL", "UNITS_ONE", "Dataset", "Results", "UncheckedWarning",
           "build_results", "discard", "load_results", "load_tree", "publish", "save_results", "write_results"]
