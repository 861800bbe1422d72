"""Figures drawn in worker processes while a run computes (the ``sixdof`` command's ``run``, ``validate`` and
``plot``): a :class:`~sixdof.plots.drawer.FigureDrawer` for the workflows, private to the command (a program
calling the library draws in its own process, :class:`~sixdof.plots.drawer.InProcessDrawer`).

Importing this module loads neither matplotlib nor NumPy: the command line starts the workers before
anything else.
"""

from __future__ import annotations

import contextlib
import dataclasses
import multiprocessing
import multiprocessing.connection
import os
import signal
import threading
from collections.abc import Iterator
from concurrent.futures import Future, ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import forkserver
from pathlib import Path
from typing import TYPE_CHECKING

from sixdof.plots import FIGURES, file_settings, render_files

if TYPE_CHECKING:
    from sixdof.results import RunResults

#: Imported once by the worker server before it forks the workers: every plot module, and a small
#: drawing that loads the rest (Agg, the fonts, mathtext's parser, 3-D axes): each worker starts warm.
_PRELOAD = ["sixdof.cli._warm"]
#: Handed out first when several figures are submitted at once: the slowest of each batch (measured),
#: so that the workers finish together.
_SLOWEST_FIRST = ("superposition.png", "bode.png", "point_frfs.png", "mode_shapes.png")


class FigureError(RuntimeError):
    """A figure could not be drawn in a worker process; the message names the figure and the error (the
    worker's traceback is the exception's cause)."""


class FigureWorkers:
    """The figures of a run, drawn to PNG in worker processes while the run computes.

    The workers are forked from a server process that imports matplotlib and the plotting code once
    (:mod:`multiprocessing`'s "forkserver"), started when this object is made: the command line makes
    it before it loads anything else, so that the imports overlap the scenario's parsing and solve. A
    fresh server, not a fork of this process, which may hold JAX's threads (forking them is unsafe).
    As with any such server, a script that starts workers must guard its main code with
    ``if __name__ == "__main__":`` (the workers import the main module).

    :meth:`submit` hands over every figure a :class:`~sixdof.results.RunResults` allows that was not
    submitted yet, so the modal and FRF figures are drawn while the solve runs; :meth:`save` waits for
    them and writes the files they come back as. Only this process writes files (into a run's
    staging folder: all or nothing, :mod:`sixdof.io.output`). A figure that fails, or a worker that
    dies, raises :class:`FigureError` in :meth:`save`. Use it as a context manager: leaving the block
    on an error or an interrupt stops the workers at once (they ignore SIGINT: Ctrl-C reaches the
    whole process group, and this process alone handles it).

    Parameters
    ----------
    processes : int, optional
        Number of workers; default: the CPUs this process may use (at least 2: the main process
        mostly waits once the solve is done).
    dpi : int, optional
        Resolution of the PNG files [dots per inch]; default the first run's ``[output] dpi``
        (:func:`sixdof.plots.file_settings`).
    formats : sequence of str, optional
        The files each figure is written as (:data:`sixdof.plots.FORMATS`); default the first run's
        ``[output] formats``.
    """

    def __init__(self, processes: int | None = None, dpi: int | None = None, formats=None) -> None:
        self.dpi, self.formats = dpi, formats
        self._jobs: dict[str, Future] = {}  # each figure's PNG to come
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(_PRELOAD)
        with _sigint_ignored():  # the server and its workers inherit it: Ctrl-C is this process' business
            forkserver.ensure_running()  # returns at once; the server imports matplotlib meanwhile
        self._pool = ProcessPoolExecutor(processes or max(_usable_cpus(), 2), mp_context=context,
                                         initializer=_start_worker)
        # Starting a worker waits for the server's imports: hand jobs over from a thread meanwhile.
        self._handover = ThreadPoolExecutor(1, thread_name_prefix="sixdof-figures")

    def submit(self, run: RunResults) -> None:
        """Start drawing every figure ``run`` allows that was not submitted before."""
        if not self._jobs:  # the workers get only the fields a figure reads: the scenario's settings go with each job
            formats, dpi = file_settings(run)
            self.formats, self.dpi = self.formats or formats, self.dpi or dpi
        new = [(name, reads) for name, reads, drawable, _ in FIGURES if name not in self._jobs and drawable(run)]
        new.sort(key=lambda job: _SLOWEST_FIRST.index(job[0]) if job[0] in _SLOWEST_FIRST else len(_SLOWEST_FIRST))
        fields = _Drawn(run)
        for name, reads in new:
            self._jobs[name] = self._handover.submit(self._pool.submit, _render, fields.run(reads), name,
                                                     self.formats or ("png",), self.dpi)

    def save(self, directory: Path) -> list[Path]:
        """Wait for the submitted figures and write them into ``directory``; the files, in the order of
        :data:`sixdof.plots.FIGURES`."""
        written = []
        for name in [name for name, *_ in FIGURES if name in self._jobs]:
            try:
                files = self._jobs[name].result().result()
            except BrokenProcessPool as exc:
                raise FigureError(f"{name}: a figure worker ended abruptly ({exc})") from exc
            for file, content in files.items():
                path = directory / file
                path.write_bytes(content)
                written.append(path)
        return written

    def close(self, cancel: bool = False) -> None:
        """Let the workers go; with ``cancel``, stop them where they are."""
        self._handover.shutdown(wait=not cancel, cancel_futures=cancel)
        if cancel:
            # ProcessPoolExecutor can only wait for running jobs: end the workers instead (SIGTERM).
            for process in list((getattr(self._pool, "_processes", None) or {}).values()):
                process.terminate()
        self._pool.shutdown(wait=True, cancel_futures=cancel)

    def __enter__(self) -> FigureWorkers:
        return self

    def __exit__(self, kind, error, traceback) -> None:
        self.close(cancel=kind is not None)


def _usable_cpus() -> int:
    """CPUs this process may run on (all of the machine's where the system cannot tell)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


@contextlib.contextmanager
def _sigint_ignored() -> Iterator[None]:
    """SIGINT ignored during the block, in the main thread (where Python handles signals): a process
    started meanwhile inherits the ignoring, from its first instruction on."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _render(run: RunResults, name: str, formats: tuple[str, ...], dpi: int | None) -> dict[str, bytes]:
    """:func:`sixdof.plots.render_files` in a worker; its errors come back as :class:`FigureError` (sixdof's
    own errors take arguments that do not survive the trip between processes)."""
    try:
        return render_files(run, name, formats, dpi)
    except Exception as exc:
        raise FigureError(f"{name}: {type(exc).__name__}: {exc}") from exc


def _start_worker() -> None:
    """Set up a worker: it ignores SIGINT (Ctrl-C reaches the whole process group; the main process handles
    it and stops the workers; inherited from the server already, unless something else started it) and
    ends when the main process ends, however it ends (a process killed with SIGKILL cannot stop its
    workers, which would wait for jobs forever)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_with, args=(multiprocessing.parent_process().sentinel,), daemon=True).start()


def _exit_with(sentinel: int) -> None:
    multiprocessing.connection.wait([sentinel])  # ready when the main process is gone
    os._exit(1)


class _Drawn:
    """What workers get of a run to draw a figure: its name and the fields the figure reads. Time histories
    go without their solver statistics and superposition details: no figure draws them, and their classes
    would load JAX in the worker. Each field is prepared once for every figure that reads it."""

    def __init__(self, run: RunResults) -> None:
        self._source, self._fields = run, {}

    def field(self, name: str):
        if name not in self._fields:
            from sixdof.results import TimeHistory  # noqa: PLC0415 (NumPy: loaded after the workers have started)

            value = getattr(self._source, name)
            if isinstance(value, TimeHistory):
                value = dataclasses.replace(value, stats=None, superposition=None)
            self._fields[name] = value
        return self._fields[name]

    def run(self, reads: tuple[str, ...]) -> RunResults:
        from sixdof.results import RunResults  # noqa: PLC0415 (NumPy: loaded after the workers have started)

        return RunResults(name=self._source.name, **{name: self.field(name) for name in reads})
