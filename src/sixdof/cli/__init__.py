"""The ``sixdof`` command: parses arguments, calls the library, prints tables, writes under outputs/.

Exit status: 0 done; 1 the solve failed or a figure could not be drawn; 2 bad input (nothing computed,
nothing written); 3 ``validate`` found the model and the time histories disagreeing beyond their limits
(verdict FAIL; its results were written), ``optimize`` did not meet every target, or ``correlate``
found the model (the updated one with ``--update``) and the test not correlated; 74 a file could not be
written (full disk, file-size limit, permissions); 130 interrupted (SIGINT), 141 its output's reader went
away (``sixdof run ... | head``: the rest of the output is dropped, silently), 143 terminated (SIGTERM).
Whatever the status, results already in place are left whole: a results folder is replaced completely or
not at all (:mod:`sixdof.io.output`).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import os
import select
import signal
import sys
import threading
import warnings
from contextlib import contextmanager
from functools import partial

from sixdof import __version__
from sixdof.cli import _process
from sixdof.cli._status import (
    EXIT_BAD_INPUT,
    EXIT_CANNOT_WRITE,
    EXIT_CLOSED_PIPE,
    EXIT_FAILED,
    EXIT_INTERRUPTED,
    EXIT_TARGETS_NOT_MET,
    EXIT_TERMINATED,
    EXIT_VALIDATION_FAILED,
    Terminated,
    fail,
)
from sixdof.cli.figures import FigureWorkers
from sixdof.interrupts import held_signals

__all__ = ["EXIT_BAD_INPUT", "EXIT_CANNOT_WRITE", "EXIT_CLOSED_PIPE", "EXIT_FAILED", "EXIT_INTERRUPTED",
           "EXIT_TARGETS_NOT_MET", "EXIT_TERMINATED", "EXIT_VALIDATION_FAILED", "main"]

#: The commands that draw figures: worker processes start drawing before the command's modules load.
DRAWING = ("run", "validate", "plot")

#: Delay before an interruption swallowed by a finalizer is raised again [s] (:func:`_cleanup_errors`).
REDELIVERY_S = 0.02


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``sixdof`` command. Returns the process exit status.

    Called without ``argv`` (as the ``sixdof`` command, reading ``sys.argv``), the process ends as soon
    as the exit handlers registered from then on have run and its output is flushed
    (:func:`sixdof.cli._process.skip_teardown`); those a program registered before do not run. Only then is
    the process tuned (:mod:`sixdof.cli._process`): a program calling ``main(argv)`` keeps its settings.
    """
    status = [EXIT_FAILED]  # what the process ends with if the command raises
    try:
        if argv is None and threading.current_thread() is threading.main_thread():
            # First: from here on a SIGTERM is one line and 143, not a silent death by the signal.
            signal.signal(signal.SIGTERM, _terminate)
        args = _parser().parse_args(argv)
        if argv is None:
            _process.skip_teardown(status)
            _process.collect_less()  # the command's process is sixdof's: a program calling main() keeps its settings
            _process.keep_freed_memory()
            _process.compile_faster()
            if args.command in DRAWING:
                _process.one_blas_thread()
    except KeyboardInterrupt:  # while the command starts, before it has done anything
        status[0] = _stopped("interrupted; no partial results were left", EXIT_INTERRUPTED)
        return status[0]
    except Terminated:
        status[0] = _stopped("terminated (SIGTERM); no partial results were left", EXIT_TERMINATED)
        return status[0]
    status[0] = _command(args)
    return status[0]


def _stopped(message: str, status: int) -> int:
    print(f"sixdof: {message}", file=sys.stderr)
    return status


def _terminate(signum, frame):
    raise Terminated


def _command(args) -> int:
    """Run the parsed command; its exit status (errors become one line on stderr)."""
    try:
        with _signals(), _cleanup_errors(args.debug), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            try:
                status = _dispatch(args)
                # Flushed here, where a closed pipe is caught, not by the last flush at exit, which cannot report it.
                sys.stdout.flush()
                return status
            finally:
                for warning in caught:  # after the command's own output, one line each
                    print(f"WARNING: {warning.message}", file=sys.stderr)
    except Exception as exc:
        if isinstance(exc, BrokenPipeError) and _closed_pipes():
            return EXIT_CLOSED_PIPE  # whoever read the output stopped reading: nothing failed, nothing to say
        cause = _interruption(exc)  # one a library wrapped (Python 3.11's __set_name__ in a RuntimeError)
        if isinstance(cause, KeyboardInterrupt):
            return fail(args, f"interrupted; {_left(cause)}", EXIT_INTERRUPTED)
        if isinstance(cause, Terminated):
            return fail(args, f"terminated (SIGTERM); {_left(cause)}", EXIT_TERMINATED)
        failure = _failure(exc)
        if failure is None:
            raise  # not a user's error: its traceback is what to report
        return fail(args, *failure)
    except KeyboardInterrupt as exc:
        return fail(args, f"interrupted; {_left(exc)}", EXIT_INTERRUPTED)
    except Terminated as exc:
        return fail(args, f"terminated (SIGTERM); {_left(exc)}", EXIT_TERMINATED)


def _dispatch(args) -> int:
    """The command's module (:mod:`sixdof.cli.commands`), imported only now and only its own (``sixdof plot``
    loads no JAX), its ``main`` called with the figure workers of a command that draws: started first, they import
    matplotlib while this process loads the workflows (NumPy, JAX) and computes."""
    with FigureWorkers() if args.command in DRAWING else contextlib.nullcontext() as workers:
        with held_signals():  # what loads here is held with the rest: a Ctrl-C is one line, not an import's traceback
            command = importlib.import_module(f"sixdof.cli.commands.{args.command}")
        return command.main(args, workers)


def _interruption(exc: BaseException) -> BaseException | None:
    """The KeyboardInterrupt or :class:`Terminated` that ``exc`` was raised from or while handling, if any."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, (KeyboardInterrupt, Terminated)):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def _left(interruption: BaseException) -> str:
    """What an interruption left: nothing, or (received while they were put in place) complete results."""
    written = getattr(interruption, "written", None)  # set by sixdof.io.output once the results are in place
    if written is None:
        return "no partial results were left"
    return f"it came once the results were complete, and they are in place in {written}"


def _failure(exc: Exception) -> tuple[str, int] | None:
    """The line to print and the exit status for an error a command raised; ``None`` for an unexpected one.

    The error classes are imported here, once a command failed, not before it starts: :mod:`sixdof.errors`
    loads NumPy (0.07-0.13 s), which the figure workers that ``run``, ``validate`` and ``plot`` start first
    need not wait for.
    """
    from sixdof.cli.figures import FigureError  # noqa: PLC0415 (see above)
    from sixdof.errors import InputError, SolverError  # noqa: PLC0415 (see above)

    if isinstance(exc, InputError):
        return f"error: {exc}", EXIT_BAD_INPUT
    if isinstance(exc, SolverError):
        return f"the solve failed, nothing was written: {exc}", EXIT_FAILED
    if isinstance(exc, FigureError):
        return f"a figure could not be drawn, nothing was written: {exc}", EXIT_FAILED
    if isinstance(exc, OSError):
        where = f" {exc.filename}" if exc.filename else ""
        reason = " ".join(str(exc.strerror or exc).split())  # one line, whatever the library's message held
        return f"could not write{where}: {reason}; results already in place are unchanged", EXIT_CANNOT_WRITE
    return None


def _closed_pipes() -> bool:
    """Whether stdout or stderr is a pipe that nobody reads any more (``sixdof run ... | head -3``). Each such
    stream is pointed at /dev/null, so that what is left to write (the last flush) goes nowhere quietly, as
    in the Python documentation's "Note on SIGPIPE".

    Asked of the streams themselves, not of the BrokenPipeError: one from elsewhere (a socket) is a failure.
    """
    closed = False
    for stream in (sys.stdout, sys.stderr):
        try:
            fd = stream.fileno()
        except (AttributeError, ValueError, OSError):  # replaced by a stream without a file (a test's capture)
            continue
        poll = select.poll()
        poll.register(fd, 0)  # errors and hang-ups are reported whatever is asked; a pipe without readers has one
        if any(events & (select.POLLERR | select.POLLHUP) for _, events in poll.poll(0)):
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, fd)
            os.close(devnull)
            closed = True
    return closed



@contextmanager
def _signals():
    """SIGTERM raises :class:`Terminated`; a file-size limit (SIGXFSZ) makes writes fail with an OSError
    instead of killing the process."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, _terminate),
                signal.SIGXFSZ: signal.signal(signal.SIGXFSZ, signal.SIG_IGN)}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


@contextmanager
def _cleanup_errors(debug: bool):
    """Errors raised while objects are destroyed (h5py closing a file the disk refused, after the write
    already failed) repeat the failure in tracebacks: printed only with ``--debug``. An interruption raised
    there is not lost: its signal comes again."""
    previous, alarm = sys.unraisablehook, []
    interruptions = {KeyboardInterrupt: signal.SIGINT, Terminated: signal.SIGTERM}

    def hook(unraisable) -> None:
        lost = interruptions.get(unraisable.exc_type)
        if lost is not None and threading.current_thread() is threading.main_thread():
            # A signal whose handler ran inside a finalizer or a garbage-collector callback (JAX's
            # _xla_gc_callback, while JAX imports): its exception cannot leave there and would be lost, the
            # run going on to the end. The signal is sent again by a timer once this hook has returned (not
            # by a thread: starting one waits, and the signal would come back into the hook), to whatever
            # handles it then (held back while a file is written).
            alarm.append(signal.signal(signal.SIGALRM, lambda signum, frame: os.kill(os.getpid(), lost)))
            signal.setitimer(signal.ITIMER_REAL, REDELIVERY_S)
        elif debug:
            previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    except BaseException:
        # Destroy what the failure left behind while the hook is still in place. Not after a success, which
        # leaves nothing failing behind: a collection then costs ~0.05 s of a run, with JAX's objects loaded.
        gc.collect()
        raise
    finally:
        sys.unraisablehook = previous
        if alarm:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, alarm[0])


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="sixdof", description="Vibration of a rigid body with six degrees of freedom on elastic mounts."
    )
    parser.add_argument("--version", action="version", version=f"sixdof {__version__}")
    # Accepted before the command and after it (``sixdof --debug run ...``, ``sixdof run ... --debug``): the
    # command's copies default to SUPPRESS, so that they do not reset what was given before the command.
    shared = argparse.ArgumentParser(add_help=False)
    for parsers, default in ((parser, False), (shared, argparse.SUPPRESS)):
        parsers.add_argument("--debug", action="store_true", default=default, help="show the traceback of errors")
        parsers.add_argument("--quiet", action="store_true", default=default, help="no progress meter")
    commands = parser.add_subparsers(required=True, metavar="COMMAND")
    add = partial(commands.add_parser, parents=[shared])

    modes = add("modes", help="natural frequencies, mode shapes, statics of a scenario")
    modes.add_argument("scenario", help="scenario file (TOML)")
    modes.add_argument("--json", action="store_true", help="print one JSON object instead of tables")
    modes.add_argument("--sensitivity", action="store_true",
                       help="with --json: derivatives of frequencies and decoupling per mount-axis stiffness")
    modes.set_defaults(command="modes")

    run = add("run", help="simulate a scenario; write results, figures and a summary")
    run.add_argument("scenario", help="scenario file (TOML)")
    run.add_argument("--out", default="outputs", help="results go to OUT/<scenario name>/ (default: outputs)")
    run.set_defaults(command="run")

    check = add(
        "validate", help="check modal frequencies, damping and FRFs against simulated time histories (exit 3 on FAIL)"
    )
    check.add_argument("scenario", help="scenario file (TOML)")
    check.add_argument("--out", default="outputs", help="results go to OUT/<name>_validation/ (default: outputs)")
    check.set_defaults(command="validate")

    correlate = add("correlate", help="correlate the model with a test (UFF58 or CSV): identified modes, MAC, "
                    "with --update the [update] variables fitted (exit 3 if not correlated)")
    correlate.add_argument("scenario", help="scenario file (TOML); its [test] table places the test's nodes")
    correlate.add_argument("--test", required=True, help="measured data: UFF58 FRFs or time histories, or CSV as "
                           "`sixdof export --format csv` writes it")
    correlate.add_argument("--update", action="store_true", help="update the model to the test ([update] table)")
    correlate.add_argument("--out", default="outputs", help="results go to OUT/<name>_correlation/ (default: outputs)")
    correlate.add_argument("--json", action="store_true", help="print one JSON object instead of tables")
    correlate.set_defaults(command="correlate")

    sweep = add(
        "sweep", help="run many mount variants of a scenario; store frequency and peak distributions"
    )
    sweep.add_argument("scenario", help="scenario file (TOML)")
    sweep.add_argument("--spec", required=True, help="variation spec (TOML; see docs/guides/sweeps.md)")
    sweep.add_argument("--out", default="outputs", help="results go to OUT/<name>_sweep/ (default: outputs)")
    sweep.add_argument("--chunk-size", type=int, default=None,
                       help="variants per chunk: one task, one seed, one file (default: the spec's, else 1000)")
    _where_arguments(sweep, "chunks")
    sweep.add_argument("--resume", action="store_true",
                       help="continue an interrupted sweep from the chunks it finished (OUT/<name>_sweep.chunks/)")
    sweep.set_defaults(command="sweep")

    design = add("optimize", help="optimize the mounts for the scenario's [design] targets (exit 3 if not all met)")
    design.add_argument("scenario", help="scenario file (TOML) with [[design.target]] and [[design.vary]]")
    design.add_argument("--out", default="outputs", help="results go to OUT/<name>_design/ (default: outputs)")
    _where_arguments(design, "robustness samples' chunks")
    design.set_defaults(command="optimize")

    examples = add("examples", help="copy the bundled example scenarios into a folder, to run and adapt")
    examples.add_argument("folder", help="where the scenario files go (created if missing; if any of them is "
                          "already there, nothing is copied and it is named: none is overwritten)")
    examples.set_defaults(command="examples")

    exchange = add("export", help="write a results file's time histories (CG, points, mount forces) and FRFs "
                   "(receptance, point FRFs, transmissibilities) as UFF58 (with the modes as UFF55) or CSV for test "
                   "tools")
    exchange.add_argument("results", help="results file (results.h5 of a run)")
    exchange.add_argument("--format", choices=("uff58", "csv"), default="uff58", help="file format (default uff58)")
    exchange.add_argument("--what", default=None, metavar="PARTS",
                          help="comma-separated parts to export: cg (the CG's displacement and the receptance), "
                          "points (the [[points]] motions), mounts (the mount forces), frfs (the [frf] point FRFs and "
                          "transmissibilities); default all the results hold")
    exchange.add_argument("--point-quantity", choices=("displacement", "velocity", "acceleration"),
                          default="acceleration", help="the points' motion (default acceleration)")
    exchange.add_argument("--out", help="files go to OUT/<name>_export/ (default: beside the results file)")
    exchange.set_defaults(command="export")

    plot = add("plot", help="redraw every figure from a results file, without re-running")
    plot.add_argument("results", help="results file (results.h5 of a run, sweep.h5, design.h5, correlation.h5) "
                      "or a folder: every results file in it")
    plot.add_argument("--out", help="folder for the PNG files (default: beside the results file)")
    plot.set_defaults(command="plot")
    return parser


def _where_arguments(parser, what: str) -> None:
    """``--workers`` and ``--scheduler``: where a study's chunks run (:func:`sixdof.workflows.tasks.task_runner`)."""
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, metavar="N",
                       help=f"compute the {what} on a local Dask cluster of N worker processes (default: in this "
                       "process)")
    where.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help=f"compute the {what} on an existing Dask cluster (tcp://host:8786)")


