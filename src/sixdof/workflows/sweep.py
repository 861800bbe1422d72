"""A sweep of a scenario's mount variants, chunk by chunk: in this process or on Dask, on disk as it goes.

The sweep's variants are cut into chunks of equal size (:meth:`sixdof.analysis.sweep.SweepSpec.chunks`); each
chunk is one task (:func:`sixdof.analysis.sweep.sweep_chunk`): it draws its variants with its own seed, computes
them with the batch engine (:func:`sixdof.analysis.batch.run_batch`) and solves those of the cross-check sample
that fall in it by diffrax. Where the tasks run is :func:`sixdof.workflows.tasks.task_runner`'s business; the
results are the same wherever they ran.

:func:`sweep` returns the whole sweep in memory. :func:`sweep_scenario` writes it: each finished chunk
goes to its own file in ``<out>/<name>_sweep.chunks/`` (:class:`ChunkFolder`) as it arrives, so the client
holds a few chunks at most; once all are there they are merged in order into ``<out>/<name>_sweep/sweep.h5``
(:class:`sixdof.io.stream.ResultsStream` along the axis ``variant``) and the chunk folder is removed. An
interrupted sweep keeps its chunks; ``resume=True`` computes only the missing ones, after checking that
the scenario and the spec are those the chunks were computed from (:func:`fingerprint`).
"""

from __future__ import annotations

import dataclasses
import fcntl
import hashlib
import json
import os
import pickle
import re
import warnings
from pathlib import Path

import numpy as np

from sixdof import __version__
from sixdof.analysis.sweep import ChunkedSweep, Study, sweep_on, time_system_of, where_ran
from sixdof.analysis.validity import RangeWarning, variants_fit_range
from sixdof.errors import InputError, Plain, integer
from sixdof.io import html_report, output
from sixdof.io.report import moving_ground
from sixdof.io.store import load_results, write_results
from sixdof.io.stream import ResultsStream
from sixdof.io.study_report import cross_check_text, summary_table, tracked_modes_table
from sixdof.plots import png
from sixdof.plots.sweep import draw_sweep, sweep_figure_names
from sixdof.results import RunResults, axis_slice
from sixdof.schema import naming
from sixdof.workflows.prepare import prepare
from sixdof.workflows.tasks import task_runner

#: The folder of a sweep's finished chunks, beside its results folder.
CHUNKS_SUFFIX = ".chunks"
_FINGERPRINT = "sweep.json"
#: The temporary name of a chunk file being written (:func:`sixdof.io.store.save_results`).
_DEBRIS = re.compile(r"\.chunk-\d{5,}\.h5\.[0-9a-f]{32}\.tmp")
#: What a chunk file holds, raised when that changes (2: the modes followed by their shapes; 3: peaks of the
#: time model, the loss factors' causal Maxwell models; 4: the tracked modes' decoupling), so that a resumed sweep
#: refuses chunks of an earlier kind up front instead of failing to merge them at the end (or merging peaks of
#: another model).
CHUNK_FORMAT = 4


def _check(scenario, spec) -> None:
    """``spec.check`` before any computing, its refusals of the scenario's mounts named with the scenario's file
    (those of the spec name the spec's)."""
    with naming(getattr(scenario, "path", None)):  # a Study has no file
        spec.check(scenario.system)


def _with_chunk_size(spec, chunk_size):
    """``spec`` with ``chunk_size`` variants per chunk where one is given, checked as the spec file's own is
    (``dataclasses.replace`` checks nothing: 0 read as "not given", -5 failed only once computed)."""
    if chunk_size is None:
        return spec
    return dataclasses.replace(spec, chunk_size=integer(chunk_size, "--chunk-size", "a positive integer", 1))


def sweep(scenario, spec, *, chunk_size: int | None = None, workers: int | None = None,
          scheduler: str | None = None, client=None, progress=None):
    """Run a scenario's variants: frequencies always, peak responses when it has a simulation; in memory.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario
    spec : sixdof.analysis.sweep.SweepSpec
    chunk_size : int, optional
        Variants per chunk, at least 1 (default: the spec's); with the seed it fixes the variants drawn.
    workers, scheduler, client : optional
        Where the chunks run (:func:`sixdof.workflows.tasks.task_runner`): default this process.
    progress : None, bool, "text" or "tqdm", optional
        Show the chunks done (:func:`sixdof.progress.meter`).

    Returns
    -------
    sixdof.analysis.batch.BatchResult
        Every variant, in order.

    Raises
    ------
    InputError
        Bad spec draws, a ``chunk_size`` below 1 (``--chunk-size``) or a bad place to run: before any computing.
    """
    scenario = scenario if isinstance(scenario, Study) else prepare(scenario)  # a Study is a model already
    spec = _with_chunk_size(spec, chunk_size)
    _check(scenario, spec)
    with task_runner(workers, scheduler, client) as runner:
        return sweep_on(runner, scenario, spec, progress)


# ----------------------------------------------------------------------------------------------------
# On disk: the chunks as they finish, merged into sweep.h5.
# ----------------------------------------------------------------------------------------------------


class ChunkFolder:
    """``<out>/<name>_sweep.chunks/``: one results file per finished chunk (``chunk-00012.h5``, written
    atomically) and ``sweep.json``, the fingerprint of the scenario and spec they come from. Made when the
    first chunk is written: a sweep that fails before leaves nothing behind.

    A sweep holds a shared ``flock`` on the folder while it writes there (the kernel releases it however the
    process ends, SIGKILL included). The temporary file of a chunk being written when its sweep was killed
    (``.chunk-00012.h5.<32 hex digits>.tmp``, :func:`sixdof.io.store.save_results`) is removed by the next sweep
    that opens the folder, when no live sweep holds it: those names only, nothing else in the folder.

    Parameters
    ----------
    path : pathlib.Path
    fingerprint : dict
        What the chunks depend on (:func:`fingerprint`).
    resume : bool
        Whether chunks found there may be used; without it, finding any is an error (before computing).
    """

    def __init__(self, path: Path, fingerprint: dict, resume: bool) -> None:
        self.path, self.fingerprint = path, fingerprint
        self._lock: int | None = None  # the descriptor holding the folder's shared lock
        if path.is_symlink() or (path.exists() and not path.is_dir()):
            raise InputError("--out", f"no file or link named {path.name} (a sweep keeps its chunks in a folder "
                             "there)", Plain(str(path)))
        if path.is_dir():
            self._remove_debris()
            self._hold()
        found = self.finished()
        if found and not resume:
            raise InputError("--resume", f"a fresh start, or --resume to continue the interrupted sweep whose "
                             f"{len(found)} finished chunks are in {path} (remove that folder to start over)",
                             Plain("no --resume"))
        if found:
            try:
                before = json.loads((path / _FINGERPRINT).read_text(encoding="utf-8"))
            except (OSError, ValueError):
                raise InputError("--resume", f"a chunk folder with its {_FINGERPRINT}", Plain(str(path))) from None
            changed = [key for key in fingerprint if before.get(key) != fingerprint[key]]
            if changed:
                raise InputError("--resume", "the scenario and sweep spec that the chunks in "
                                 f"{path} were computed from", Plain(f"a different {', '.join(changed)}"))

    def _hold(self) -> None:
        """Take the folder's shared lock (see the class), for as long as this process lives or :meth:`remove`."""
        if self._lock is None:
            self._lock = os.open(self.path, os.O_RDONLY)
            fcntl.flock(self._lock, fcntl.LOCK_SH)

    def release(self) -> None:
        """Let go of the folder's lock: this process writes no more there."""
        if self._lock is not None:
            os.close(self._lock)
            self._lock = None

    def _remove_debris(self) -> None:
        """Remove the chunks' temporary files that killed sweeps left, unless a live sweep holds the folder."""
        fd = os.open(self.path, os.O_RDONLY)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return  # a live sweep writes there: its temporary files are its own
        else:
            for entry in self.path.iterdir():
                if _DEBRIS.fullmatch(entry.name) and entry.is_file() and not entry.is_symlink():
                    entry.unlink(missing_ok=True)
        finally:
            os.close(fd)  # releases the lock

    def file(self, index: int) -> Path:
        return self.path / f"chunk-{index:05d}.h5"

    def finished(self) -> set[int]:
        """The chunks whose files are complete (a file appears only once written whole)."""
        return self.finished_in(self.path)

    @staticmethod
    def finished_in(path: Path) -> set[int]:
        """The finished chunks in the chunk folder ``path`` (none where there is none)."""
        return {int(p.stem.split("-")[1]) for p in path.glob("chunk-*.h5")} if path.is_dir() else set()

    def write(self, index: int, result) -> None:
        if not (self.path / _FINGERPRINT).exists():
            self.path.mkdir(parents=True, exist_ok=True)  # with --out, made only now
            self._hold()
            (self.path / _FINGERPRINT).write_text(json.dumps(self.fingerprint, indent=1), encoding="utf-8")
        write_results(self.file(index), RunResults(name=f"chunk {index}", sweep=result))

    def read(self, index: int):
        return load_results(self.file(index)).sweep

    def remove(self, chunks: int) -> None:
        """Remove the chunk files, the fingerprint and the folder: only what sixdof wrote there."""
        for index in range(chunks):
            self.file(index).unlink(missing_ok=True)
        (self.path / _FINGERPRINT).unlink(missing_ok=True)
        self.release()
        try:
            self.path.rmdir()
        except OSError:
            pass  # absent, or something else is in it: the user's, left alone


def fingerprint(scenario, spec) -> dict:
    """What a sweep's chunks depend on: the scenario's models (frequency and time: ``loss_factor_model``), excitation
    and settings (the data of the files it reads included, not its name or comments), the spec (chunks and seeds
    included) and sixdof's version."""
    # Pickles of these frozen objects are the same bytes in every process for the same content (checked by the
    # resume tests); a changed accelerogram or force-deflection file changes them.
    model = pickle.dumps((scenario.system, scenario.excitation, scenario.simulation, time_system_of(scenario)),
                         protocol=5)
    spec_text = json.dumps({key: value for key, value in dataclasses.asdict(spec).items() if key != "path"},
                           sort_keys=True, default=str)  # the spec's content, not where it was read from
    return {"scenario": hashlib.sha256(model).hexdigest(), "spec": hashlib.sha256(spec_text.encode()).hexdigest(),
            "sixdof version": __version__, "chunk format": CHUNK_FORMAT}


def sweep_scenario(scenario, spec, out_root: str | Path = "outputs", *, chunk_size: int | None = None,
                   workers: int | None = None, scheduler: str | None = None, client=None, resume: bool = False,
                   progress=None, command_line: str | None = None):
    """Run a sweep chunk by chunk into its chunk folder (kept until the sweep is whole: ``resume``), then merge it
    into ``<out_root>/<name>_sweep/``: ``sweep.h5`` and ``summary.md`` (see the module).

    Parameters
    ----------
    scenario, spec, chunk_size, workers, scheduler, client, progress
        As :func:`sweep`.
    out_root : str or pathlib.Path
    resume : bool
        Continue an interrupted sweep from its chunk folder.
    command_line : str, optional
        Stored in the file's provenance.

    Returns
    -------
    tuple of (sixdof.analysis.batch.BatchResult, pathlib.Path)
        The merged result cut to no variants (its cross-check and provenance: the variants are in the file) and
        the folder written.

    Raises
    ------
    InputError
        Bad spec draws or ``chunk_size`` (``--chunk-size``), an unusable ``out_root``, chunks of an interrupted
        sweep without ``resume`` or of another scenario or spec with it: all before any computing.
    """
    scenario = prepare(scenario)
    spec = _with_chunk_size(spec, chunk_size)
    _check(scenario, spec)
    target = output.check_target(out_root, scenario.name, "_sweep")
    folder = ChunkFolder(target.with_name(target.name + CHUNKS_SUFFIX), fingerprint(scenario, spec), resume)
    run = ChunkedSweep(scenario, spec)
    found = folder.finished()
    try:
        with task_runner(workers, scheduler, client) as runner:
            for index, result in run.run(runner, skip=found, progress=progress):
                folder.write(index, result)
            where = where_ran(runner)
    finally:
        folder.release()  # the chunks are written (or the sweep stopped): merged below, by this process alone
    merged = []

    def merge(sink):
        merged.append(dataclasses.replace(run.merged((folder.read(i) for i in range(len(run.chunks))), where, sink),
                                          resumed=len(found)))
        return merged[0]

    notes = []
    output.write_folder(target, lambda stage: notes.extend(_save_into(stage, scenario, spec.count, merge,
                                                                      command_line)))
    folder.remove(len(run.chunks))
    _warn(notes)
    return merged[0], target


def save_sweep(result, scenario, out_root: str | Path = "outputs", *, command_line: str | None = None) -> Path:
    """Write a sweep computed in memory (:func:`sweep`) into ``<out_root>/<name>_sweep/``: ``sweep.h5`` and
    ``summary.md``, as :func:`sweep_scenario` writes them. Returns the folder."""
    scenario = prepare(scenario)
    target = output.check_target(out_root, scenario.name, "_sweep")

    def merge(sink):
        sink(result)
        return axis_slice(result, slice(0, 0), "variant")

    notes = []
    output.write_folder(target, lambda stage: notes.extend(_save_into(stage, scenario, result.count, merge,
                                                                      command_line)))
    _warn(notes)
    return target


def sweep_tables(path: str | Path, scenario) -> str:
    """The percentiles of a sweep file's frequencies and peaks and its tracked modes
    (:func:`sixdof.io.study_report.summary_table`, :func:`~sixdof.io.study_report.tracked_modes_table`), read a
    column at a time: the client never holds every variant."""
    import h5py

    with h5py.File(path, "r") as f:
        return (summary_table(f["sweep/frequency_hz"], f.get("sweep/peak_q"), moving_ground(scenario))
                + "\n\n" + tracked_modes_table(scenario.system.modes, f["sweep/tracked_frequency_hz"],
                                                 f["sweep/tracked_mac"]))


def _warn(notes: list[str]) -> None:
    """The warnings of a sweep written: what its variants reach that the Maxwell fits do not vouch for."""
    for note in notes:
        warnings.warn(note, RangeWarning, stacklevel=3)


def _save_into(stage: Path, scenario, count: int, merge, command_line: str | None) -> list[str]:
    """``sweep.h5`` (its variants streamed by ``merge(sink)``, which returns the merged result cut to no variants),
    ``summary.md`` and ``report.html`` into ``stage``; returns the warnings of variants the Maxwell fits do not
    vouch for."""
    parts = {"command_line": command_line} if command_line is not None else {}
    path = stage / "sweep.h5"
    with ResultsStream(path, axis="variant", **parts) as stream:
        merged = merge(lambda chunk: stream.append(RunResults(name=scenario.name, sweep=chunk)))
        stream.finish(RunResults(name=scenario.name, description=scenario.description, system=scenario.system,
                                 sweep=merged, provenance={"scenario_text": scenario.text}),
                      sweep={"count": count})
    import h5py

    table = sweep_tables(path, scenario)
    with h5py.File(path, "r") as f:
        notes = _fit_reach(scenario, f["sweep/frequency_hz"])
    about = f"{scenario.description}\n\n" if scenario.description else ""
    check = cross_check_text(merged)
    listed = "".join(f"- {note}\n" for note in notes)
    summary = (f"# {scenario.name}: sweep of {count} variants\n\n{about}"
               + (f"## Warnings\n\n{listed}\n" if listed else "") + f"{table}\n" + (f"\n{check}\n" if check else ""))
    (stage / "summary.md").write_text(summary, encoding="utf-8")
    write_sweep_figures(stage, load_results(path))
    html_report.write_report(stage, f"{scenario.name}: sweep of {count} variants", summary,
                             figures=sorted(stage.glob("*.png")), system=scenario.given_system,
                             scenario_text=scenario.text)
    return notes


def write_sweep_figures(directory: Path, run) -> list[Path]:
    """Draw every figure a sweep's results allow (:data:`sixdof.plots.sweep.SWEEP_FIGURES`: its variants'
    frequencies, decoupling, peaks and what moves each frequency) into ``directory``; the files written."""
    written = []
    for name in sweep_figure_names(run):
        (directory / name).write_bytes(png(draw_sweep(run, name)))
        written.append(directory / name)
    return written


def _fit_reach(scenario, frequency_hz) -> list[str]:
    """What the variants' natural frequencies (``frequency_hz``, (variant, mode) [Hz], read a column at a time) reach
    that the scenario's Maxwell fits do not vouch for (:func:`~sixdof.analysis.validity.variants_fit_range`)."""
    fits = getattr(scenario, "viscoelastic", ())
    if not fits:
        return []
    columns = [np.asarray(frequency_hz[:, j]) for j in range(frequency_hz.shape[1])]
    elastic = np.concatenate([c[c > 0] for c in columns])
    return variants_fit_range(fits, [float(elastic.min()), float(elastic.max())]) if elastic.size else []


__all__ = ["ChunkFolder", "fingerprint", "save_sweep", "sweep", "sweep_scenario", "sweep_tables",
           "write_sweep_figures"]
