"""A sweep of a scenario's mount variants, chunk by chunk: in this process or on Dask, on disk as it goes.

The sweep's variants are cut into chunks of equal size (:meth:`sixdof.io.sweep.SweepSpec.chunks`); each
chunk is one task (:func:`sweep_chunk`): it draws its variants with its own seed, computes them with the
batch engine (:func:`sixdof.analysis.batch.run_batch`) and solves those of the cross-check sample that
fall in it by diffrax. Where the tasks run is :func:`sixdof.tasks.task_runner`'s business; the results
are the same wherever they ran.

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
import time
import warnings
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from sixdof.analysis.validity import RangeWarning, variants_fit_range
from sixdof.errors import InputError, Plain, SolverError, integer
from sixdof.schema import naming

#: The folder of a sweep's finished chunks, beside its results folder.
CHUNKS_SUFFIX = ".chunks"
_FINGERPRINT = "sweep.json"
#: The temporary name of a chunk file being written (:func:`sixdof.io.store.save_results`).
_DEBRIS = re.compile(r"\.chunk-\d{5,}\.h5\.[0-9a-f]{32}\.tmp")
#: What a chunk file holds, raised when that changes (2: the modes followed by their shapes; 3: peaks of the
#: time model, the loss factors' causal Maxwell models), so that a resumed sweep refuses chunks of an earlier kind
#: up front instead of failing to merge them at the end (or merging peaks of another model).
CHUNK_FORMAT = 3


class Study(NamedTuple):
    """What a sweep needs of a scenario (a :class:`~sixdof.io.scenario.Scenario` will do): the nominal
    system, the excitation and simulation settings of its responses (``None``: frequencies only), and the model
    of those time responses (``None``: ``system``; a scenario's ``time_system`` carries its loss factors as
    causal Maxwell models)."""

    system: Any
    excitation: Any = None
    simulation: Any = None
    time_system: Any = None


def _time_system(scenario):
    """The model of a sweep's time responses and cross-checks: the scenario's ``time_system`` (the loss factors'
    causal Maxwell models, ``[damping] loss_factor_model``), else its ``system``."""
    timed = getattr(scenario, "time_system", None)
    return scenario.system if timed is None else timed


def sweep_chunk(scenario, spec, index: int, checked: tuple[int, ...] = ()):
    """Chunk ``index`` of ``spec``'s sweep of ``scenario`` (or :class:`Study`), one task: its variants'
    frequencies and peaks, and the diffrax peaks of those among ``checked`` (indices in the whole sweep), as
    a :class:`~sixdof.analysis.batch.BatchResult` whose cross-check fields hold only those peaks.

    The frequencies and tracked modes are those of the scenario's ``system`` (the mounts' stiffness ``k``, as
    ``sixdof modes`` reports them); the peaks and their diffrax cross-check those of its ``time_system`` (each
    loss factor as its causal Maxwell model, scaled with its mount axis's stiffness factor, as ``sixdof run``
    simulates)."""
    from sixdof.analysis.batch import direct_peaks, run_batch

    system, excitation, settings = scenario.system, scenario.excitation, scenario.simulation
    timed = _time_system(scenario)
    variants = spec.variants(system, index)
    result = run_batch(system, variants, excitation, settings, time_system=timed, engine=spec.engine, cross_check=0)
    if not checked or result.peak_q is None:
        return result
    rows = spec.chunks()[index]
    direct = direct_peaks(timed, variants, [i - rows.start for i in checked], excitation, settings)
    return dataclasses.replace(result, cross_check_variants=np.asarray(checked, dtype=int),
                               cross_check_peak_q=direct[:, :6], cross_check_peak_qdd=direct[:, 6:])


class _Sweep:
    """What every chunk shares and how they merge: the partition, the cross-check sample, the merged parts."""

    def __init__(self, scenario, spec) -> None:
        from sixdof.analysis.batch import cross_check_sample

        self.scenario, self.spec = scenario, spec
        self.chunks = spec.chunks()
        simulated = scenario.excitation is not None and scenario.simulation is not None
        self.checked = cross_check_sample(spec.count, spec.cross_check if simulated else 0, spec.seed)
        self.start = time.perf_counter()

    def jobs(self, skip=frozenset()) -> Iterator[tuple[int, tuple]]:
        """``(index, arguments of sweep_chunk)`` of every chunk not in ``skip``."""
        for index, rows in enumerate(self.chunks):
            if index not in skip:
                checked = tuple(int(i) for i in self.checked if i in rows)
                yield index, (self.scenario, self.spec, index, checked)

    def run(self, runner, skip=frozenset(), progress=None) -> Iterator[tuple[int, object]]:
        """Each chunk not in ``skip`` computed by ``runner`` (:func:`sixdof.tasks.task_runner`), as it finishes,
        with a meter over the chunks showing variants per second."""
        from sixdof.progress import meter

        where = "" if runner.backend == "in-process" else f" on {runner.workers} Dask workers"
        shown = meter(progress, len(self.chunks), "chunks", "sweep" + where)
        shown.show(len(skip))
        done, variants, began = len(skip), 0, time.perf_counter()
        rate = ""
        for finished in runner.run(sweep_chunk, self.jobs(skip)):
            done += 1
            variants += len(self.chunks[finished.index])
            rate = f"{variants / (time.perf_counter() - began):.4g} variants/s"
            shown.show(done, rate)
            yield finished.index, finished.result
        shown.close(rate)

    def merged(self, results: Iterable, where: dict, sink=None):
        """The sweep's :class:`~sixdof.analysis.batch.BatchResult` from its chunks' results in order, cut to no
        variants, with the cross-check and the provenance ``where`` (:func:`_where`); ``sink`` receives each
        chunk (to keep or write it)."""
        from sixdof.analysis.batch import cross_check_fields
        from sixdof.results import axis_slice

        first, direct, engine, width, count = None, [], [], 0, 0
        for index, result in enumerate(results):
            rows = self.chunks[index]
            if result.count != len(rows):  # never seen: the check that no variant is lost or doubled
                raise SolverError(f"chunk {index} holds {result.count} variants, not {len(rows)}")
            if first is None:
                first = axis_slice(result, slice(0, 0), "variant")
            width = max(width, result.chunk_size)
            count += result.count
            if result.cross_check_variants is not None:
                local = result.cross_check_variants - rows.start
                direct.append(np.hstack([result.cross_check_peak_q, result.cross_check_peak_qdd]))
                engine.append(np.hstack([result.peak_q[local], result.peak_qdd[local]]))
            if sink is not None:
                sink(result)
        if count != self.spec.count:
            raise SolverError(f"the chunks hold {count} variants, not {self.spec.count}")
        checks = {} if not direct else cross_check_fields(self.checked, np.vstack(direct), np.vstack(engine))
        fields = ("cross_check_variants", "cross_check_peak_q", "cross_check_peak_qdd", "cross_check")
        return dataclasses.replace(first, **{name: checks.get(name) for name in fields}, chunk_size=width,
                                   wall_time_s=time.perf_counter() - self.start, chunks=len(self.chunks), **where)


def _where(runner) -> dict:
    """Where the chunks ran: the backend and its worker processes now."""
    return {"backend": runner.backend, "workers": runner.workers}


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
    spec : sixdof.io.sweep.SweepSpec
    chunk_size : int, optional
        Variants per chunk, at least 1 (default: the spec's); with the seed it fixes the variants drawn.
    workers, scheduler, client : optional
        Where the chunks run (:func:`sixdof.tasks.task_runner`): default this process.
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
    from sixdof.tasks import task_runner
    from sixdof.workflows.prepare import prepare

    scenario = prepare(scenario)
    spec = _with_chunk_size(spec, chunk_size)
    _check(scenario, spec)
    with task_runner(workers, scheduler, client) as runner:
        return sweep_on(runner, scenario, spec, progress)


def sweep_on(runner, scenario, spec, progress=None):
    """:func:`sweep` on an open ``runner`` (:func:`sixdof.tasks.task_runner`), ``spec`` already checked."""
    from sixdof.results import axis_concat

    run = _Sweep(scenario, spec)
    found = dict(run.run(runner, progress=progress))
    kept = []
    merged = run.merged((found.pop(i) for i in range(len(run.chunks))), _where(runner), kept.append)
    # The merged result has no variants but every other field of the sweep: the chunks' variants join it.
    return axis_concat([merged, *kept], "variant")


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
        from sixdof.io.store import write_results
        from sixdof.results import RunResults

        if not (self.path / _FINGERPRINT).exists():
            self.path.mkdir(parents=True, exist_ok=True)  # with --out, made only now
            self._hold()
            (self.path / _FINGERPRINT).write_text(json.dumps(self.fingerprint, indent=1), encoding="utf-8")
        write_results(self.file(index), RunResults(name=f"chunk {index}", sweep=result))

    def read(self, index: int):
        from sixdof.io.store import load_results

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
    from sixdof import __version__

    # Pickles of these frozen objects are the same bytes in every process for the same content (checked by the
    # resume tests); a changed accelerogram or force-deflection file changes them.
    model = pickle.dumps((scenario.system, scenario.excitation, scenario.simulation, _time_system(scenario)),
                         protocol=5)
    spec_text = json.dumps({key: value for key, value in dataclasses.asdict(spec).items() if key != "path"},
                           sort_keys=True, default=str)  # the spec's content, not where it was read from
    return {"scenario": hashlib.sha256(model).hexdigest(), "spec": hashlib.sha256(spec_text.encode()).hexdigest(),
            "sixdof version": __version__, "chunk format": CHUNK_FORMAT}


@dataclass(frozen=True)
class SweepOutcome:
    """What :func:`sweep_scenario` wrote and found.

    Attributes
    ----------
    directory : pathlib.Path
        ``<out>/<name>_sweep/`` (``sweep.h5``).
    result : sixdof.analysis.batch.BatchResult
        The merged result cut to no variants: its cross-check and provenance (the variants are in the file).
    count : int
        Variants.
    resumed : int
        Chunks found finished (``resume=True``) and not computed again.
    table : str
        Percentiles of the frequencies and peaks (:func:`sixdof.io.report.summary_table`).
    """

    directory: Path
    result: object
    count: int
    resumed: int
    table: str


def sweep_scenario(scenario, spec, out_root: str | Path = "outputs", *, chunk_size: int | None = None,
                   workers: int | None = None, scheduler: str | None = None, client=None, resume: bool = False,
                   progress=None, command_line: str | None = None) -> SweepOutcome:
    """Run a sweep and write ``<out_root>/<name>_sweep/sweep.h5`` (see the module).

    Parameters
    ----------
    scenario, spec, chunk_size, workers, scheduler, client, progress
        As :func:`sweep`.
    out_root : str or pathlib.Path
    resume : bool
        Continue an interrupted sweep from its chunk folder.
    command_line : str, optional
        Stored in the file's provenance.

    Raises
    ------
    InputError
        Bad spec draws or ``chunk_size`` (``--chunk-size``), an unusable ``out_root``, chunks of an interrupted
        sweep without ``resume`` or of another scenario or spec with it: all before any computing.
    """
    import h5py

    from sixdof.io import output
    from sixdof.io.report import cross_check_text, moving_ground, summary_table, tracked_modes_table
    from sixdof.io.stream import ResultsStream
    from sixdof.results import RunResults
    from sixdof.tasks import task_runner
    from sixdof.workflows.prepare import prepare

    scenario = prepare(scenario)
    spec = _with_chunk_size(spec, chunk_size)
    _check(scenario, spec)
    target = output.check_target(out_root, scenario.name, "_sweep")
    folder = ChunkFolder(target.with_name(target.name + CHUNKS_SUFFIX), fingerprint(scenario, spec), resume)
    run = _Sweep(scenario, spec)
    found = folder.finished()
    try:
        with task_runner(workers, scheduler, client) as runner:
            for index, result in run.run(runner, skip=found, progress=progress):
                folder.write(index, result)
            where = _where(runner)
    finally:
        folder.release()  # the chunks are written (or the sweep stopped): merged below, by this process alone
    outcome = {}

    def write(stage: Path) -> None:
        parts = {"command_line": command_line} if command_line is not None else {}
        path = stage / "sweep.h5"
        with ResultsStream(path, axis="variant", **parts) as stream:
            merged = run.merged((folder.read(i) for i in range(len(run.chunks))), where,
                                lambda chunk: stream.append(RunResults(name=scenario.name, sweep=chunk)))
            stream.finish(RunResults(name=scenario.name, description=scenario.description, system=scenario.system,
                                     sweep=merged, provenance={"scenario_text": scenario.text}),
                          sweep={"count": spec.count})
        with h5py.File(path, "r") as f:  # one column at a time: the client never holds every variant
            outcome["table"] = (summary_table(f["sweep/frequency_hz"], f.get("sweep/peak_q"), moving_ground(scenario))
                                + "\n\n" + tracked_modes_table(scenario.system.modes, f["sweep/tracked_frequency_hz"],
                                                                 f["sweep/tracked_mac"]))
            outcome["notes"] = _fit_reach(scenario, f["sweep/frequency_hz"])
        outcome["result"] = merged
        about = f"{scenario.description}\n\n" if scenario.description else ""
        check = cross_check_text(merged)
        notes = "".join(f"- {note}\n" for note in outcome["notes"])
        (stage / "summary.md").write_text(f"# {scenario.name}: sweep of {spec.count} variants\n\n{about}"
                                          + (f"## Warnings\n\n{notes}\n" if notes else "")
                                          + f"{outcome['table']}\n" + (f"\n{check}\n" if check else ""),
                                          encoding="utf-8")

    output.write_folder(target, write)
    folder.remove(len(run.chunks))
    for note in outcome["notes"]:
        warnings.warn(note, RangeWarning, stacklevel=2)
    return SweepOutcome(directory=target, result=outcome["result"], count=spec.count, resumed=len(found),
                        table=outcome["table"])


def _fit_reach(scenario, frequency_hz) -> list[str]:
    """What the variants' natural frequencies (``frequency_hz``, (variant, mode) [Hz], read a column at a time) reach
    that the scenario's Maxwell fits do not vouch for (:func:`~sixdof.analysis.validity.variants_fit_range`)."""
    fits = getattr(scenario, "viscoelastic", ())
    if not fits:
        return []
    columns = [np.asarray(frequency_hz[:, j]) for j in range(frequency_hz.shape[1])]
    elastic = np.concatenate([c[c > 0] for c in columns])
    return variants_fit_range(fits, [float(elastic.min()), float(elastic.max())]) if elastic.size else []


__all__ = ["ChunkFolder", "SweepOutcome", "fingerprint", "sweep", "sweep_chunk", "sweep_scenario"]
