"""A results file written while a long computation proceeds: its series appended part by part.

A run of any duration proceeds in time windows (:func:`sixdof.analysis.direct.simulate_windows`); each
window's results are encoded like a whole run's (:func:`sixdof.io.store.build_results`) and every dataset
with a time axis ``t`` is appended along that axis, so memory stays bounded by one window whatever the
duration. The datasets without a time axis (modes, statics, summaries merged over the windows: solver
statistics, agreement, mount peaks) are written once, by :meth:`ResultsStream.finish`, from the run's
final results. A sweep's chunks are merged the same way along the axis ``variant``. The file is written
under a temporary name and renamed into place only when finished, like
:func:`sixdof.io.store.save_results`: a reader never sees a half-written results file.
"""

from __future__ import annotations

import os
import uuid
from pathlib import Path

from sixdof.interrupts import held_signals
from sixdof.io.output import check_room
from sixdof.io.store.codec import build_results
from sixdof.io.store.tree import Results
from sixdof.io.store.writer import LIBVER, _naming, _write, discard, publish
from sixdof.results import axis_slice

#: Samples per HDF5 chunk along the appended axis: large enough for fast appends and reads of whole series,
#: small enough that a short run's file holds little padding.
TIME_CHUNK = 4096


class ResultsStream:
    """An HDF5 results file whose time series arrive window by window.

    Use as a context manager: on an exception the temporary file is removed and ``path`` left as it was.

    Parameters
    ----------
    path : str or path-like
        The results file written by :meth:`finish`.
    axis : str
        The axis appended along: ``"t"`` (a run's windows, default) or ``"variant"`` (a sweep's chunks).
    **parts
        Passed to :func:`sixdof.io.store.build_results` with every window and the final results
        (``command_line``...).
    """

    def __init__(self, path: str | os.PathLike, axis: str = "t", **parts) -> None:
        import h5py

        self.axis = axis
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._parts = parts
        self._temporary = self.path.with_name(f".{self.path.name}.{uuid.uuid4().hex}.tmp")
        self._file = h5py.File(self._temporary, "x", libver=LIBVER)
        self._series: dict[str, tuple[str, ...]] = {}  # path -> dims of the time series appended
        self._nodes: dict = {}  # path -> the h5py dataset of each series, open until the file closes
        self.samples = 0

    def __enter__(self) -> ResultsStream:
        return self

    def __exit__(self, kind, value, traceback) -> None:
        if kind is not None:
            self.abort()

    def append(self, run) -> None:
        """Append one window's series (a :class:`~sixdof.results.RunResults` of that window or chunk)."""
        tree = build_results(run, **self._parts)
        series = {path: d for path, d in tree.datasets.items() if self.axis in d.dims}
        if self._series and set(series) != set(self._series):
            raise ValueError(f"part {self.samples} has the series {sorted(series)}, not {sorted(self._series)}")
        lengths = {d.data.shape[d.dims.index(self.axis)] for d in series.values()}
        if len(lengths) != 1:
            raise ValueError(f"part {self.samples} has series of lengths {sorted(lengths)} along {self.axis}")
        check_room(self._temporary, sum(d.data.nbytes for d in series.values()))
        with held_signals(), _naming(self.path):
            self._append(series, lengths.pop())

    def _append(self, series, n) -> None:
        """Append ``n`` samples of each of a window's ``series`` (path -> Dataset), creating them at the first."""
        for path, dataset in series.items():
            axis = dataset.dims.index(self.axis)
            data = dataset.data
            if dataset.dims == (self.axis,) and dataset.attrs.get("description") == f"{self.axis} index":
                data = data + self.samples  # an index scale (0, 1, ...) numbers the whole file, not each part
            if path not in self._series:
                shape = list(dataset.data.shape)
                shape[axis] = 0
                maxshape = list(shape)
                maxshape[axis] = None
                chunks = list(shape)
                chunks[axis] = TIME_CHUNK
                node = self._file.create_dataset(path, shape=tuple(shape), maxshape=tuple(maxshape),
                                                 chunks=tuple(max(c, 1) for c in chunks), dtype=dataset.data.dtype,
                                                 fletcher32=True)  # its attributes: by finish, with the rest
                self._series[path] = dataset.dims
                self._nodes[path] = node
            node = self._nodes[path]
            node.resize(self.samples + n, axis=axis)
            index = [slice(None)] * dataset.data.ndim
            index[axis] = slice(self.samples, self.samples + n)
            node[tuple(index)] = data
        # Written out now, where a full disk raises: HDF5 would write its caches when it closes the datasets,
        # where h5py can only print the failure, and go on.
        self._file.flush()
        self.samples += n

    def finish(self, run, **attrs) -> Path:
        """Write the datasets without the appended axis from the final results, close, and rename into place.

        ``run`` may be cut to no samples along the axis already (a sweep's merged results, whose per-variant
        arrays the client never holds); ``attrs`` (group path -> attributes) then set what the cut changed
        (the sweep's ``count``).
        """
        # The file has every part's series already: only the rest is encoded, from the run cut to no samples
        # (encoding a long run's kept samples again would double the memory they take).
        run = axis_slice(run, slice(0, 0), self.axis)
        extra = {**self._parts.get("extra_attrs", {}), **attrs}
        tree = build_results(run, **{**self._parts, "extra_attrs": extra})
        datasets = {path: d for path, d in tree.datasets.items() if path in self._series or self.axis not in d.dims}
        with held_signals(), _naming(self.path):
            _write(self._file, Results(datasets, tree.attrs), written=self._series)
            self._file.close()
        publish(self._temporary, self.path)
        return self.path

    def abort(self) -> None:
        """Close and remove the unfinished file (after a failed write too: :func:`sixdof.io.store.discard`)."""
        discard(self._file, self._temporary, self._nodes)


__all__ = ["ResultsStream", "TIME_CHUNK"]
