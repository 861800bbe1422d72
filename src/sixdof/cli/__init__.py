"""The ``sixdof`` command: parses arguments, calls the library, prints tables, writes under outputs/.

Exit status: 0 done; 1 the solve failed or a figure could not be drawn; 2 bad input (nothing computed,
nothing written); 3 ``validate`` found the model and the time histories disagreeing beyond their limits
(verdict FAIL; its results were written); 74 a file could not be written (full disk, file-size limit,
permissions); 130 interrupted (SIGINT), 141 its output's reader went away (``sixdof run ... | head``: the rest
of the output is dropped, silently), 143 terminated (SIGTERM). Whatever the status, results already in place are
left whole: a results folder is replaced completely or not at all (:mod:`sixdof.io.output`).
"""

from __future__ import annotations

import argparse
import json
import os
import select
import signal
import sys
import threading
import traceback
import warnings
from contextlib import contextmanager
from functools import partial

from sixdof.cli import _process
from sixdof.interrupts import held_signals

EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_VALIDATION_FAILED = 3
EXIT_TARGETS_NOT_MET = 3  # optimize: the best compromise is written, as validate writes a failed validation
EXIT_CANNOT_WRITE = 74  # EX_IOERR of sysexits.h
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports a process killed by it
EXIT_CLOSED_PIPE = 141  # 128 + SIGPIPE: as a shell reports a command killed by writing to a closed pipe (`yes | head`)
EXIT_TERMINATED = 143  # 128 + SIGTERM

#: Delay before an interruption swallowed by a finalizer is raised again [s] (:func:`_cleanup_errors`).
REDELIVERY_S = 0.02


class Terminated(BaseException):
    """SIGTERM, raised like KeyboardInterrupt so that a run cleans up after itself."""


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
            if args.command in (_run, _validate, _plot):
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
                status = args.command(args)
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
            return _fail(args, f"interrupted; {_left(cause)}", EXIT_INTERRUPTED)
        if isinstance(cause, Terminated):
            return _fail(args, f"terminated (SIGTERM); {_left(cause)}", EXIT_TERMINATED)
        failure = _failure(exc)
        if failure is None:
            raise  # not a user's error: its traceback is what to report
        return _fail(args, *failure)
    except KeyboardInterrupt as exc:
        return _fail(args, f"interrupted; {_left(exc)}", EXIT_INTERRUPTED)
    except Terminated as exc:
        return _fail(args, f"terminated (SIGTERM); {_left(exc)}", EXIT_TERMINATED)


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
    from sixdof.cli.figures import FigureError
    from sixdof.errors import InputError, SolverError

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


def _title(scenario) -> str:
    """The first line a command prints of its scenario: its name and description (the name alone without one)."""
    return f"{scenario.name}: {scenario.description}" if scenario.description else scenario.name


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
        import gc

        # Destroy what the failure left behind while the hook is still in place. Not after a success, which
        # leaves nothing failing behind: a collection then costs ~0.05 s of a run, with JAX's objects loaded.
        gc.collect()
        raise
    finally:
        sys.unraisablehook = previous
        if alarm:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, alarm[0])


def _fail(args, message: str, status: int) -> int:
    if args.debug:
        traceback.print_exc()
    print(f"sixdof: {message}", file=sys.stderr)
    return status


def _parser() -> argparse.ArgumentParser:
    from sixdof import __version__

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
    modes.set_defaults(command=_modes)

    run = add("run", help="simulate a scenario; write results, figures and a summary")
    run.add_argument("scenario", help="scenario file (TOML)")
    run.add_argument("--out", default="outputs", help="results go to OUT/<scenario name>/ (default: outputs)")
    run.set_defaults(command=_run)

    check = add(
        "validate", help="check modal frequencies, damping and FRFs against simulated time histories (exit 3 on FAIL)"
    )
    check.add_argument("scenario", help="scenario file (TOML)")
    check.add_argument("--out", default="outputs", help="results go to OUT/<name>_validation/ (default: outputs)")
    check.set_defaults(command=_validate)

    sweep = add(
        "sweep", help="run many mount variants of a scenario; store frequency and peak distributions"
    )
    sweep.add_argument("scenario", help="scenario file (TOML)")
    sweep.add_argument("--spec", required=True, help="variation spec (TOML; see the README)")
    sweep.add_argument("--out", default="outputs", help="results go to OUT/<name>_sweep/ (default: outputs)")
    sweep.add_argument("--chunk-size", type=int, default=None,
                       help="variants per chunk: one task, one seed, one file (default: the spec's, else 1000)")
    _where_arguments(sweep, "chunks")
    sweep.add_argument("--resume", action="store_true",
                       help="continue an interrupted sweep from the chunks it finished (OUT/<name>_sweep.chunks/)")
    sweep.set_defaults(command=_sweep)

    design = add("optimize", help="optimize the mounts for the scenario's [design] targets (exit 3 if not all met)")
    design.add_argument("scenario", help="scenario file (TOML) with [[design.target]] and [[design.vary]]")
    design.add_argument("--out", default="outputs", help="results go to OUT/<name>_design/ (default: outputs)")
    _where_arguments(design, "robustness samples' chunks")
    design.set_defaults(command=_optimize)

    examples = add("examples", help="copy the bundled example scenarios into a folder, to run and adapt")
    examples.add_argument("folder", help="where the scenario files go (created if missing; if any of them is "
                          "already there, nothing is copied and it is named: none is overwritten)")
    examples.set_defaults(command=_examples)

    exchange = add("export", help="write a results file's time histories and FRFs as UFF58 or CSV for test tools")
    exchange.add_argument("results", help="results file (results.h5 of a run)")
    exchange.add_argument("--format", choices=("uff58", "csv"), default="uff58", help="file format (default uff58)")
    exchange.add_argument("--out", help="files go to OUT/<name>_export/ (default: beside the results file)")
    exchange.set_defaults(command=_export)

    plot = add("plot", help="redraw every figure from a results file, without re-running")
    plot.add_argument("results", help="results file (results.h5 of a run)")
    plot.add_argument("--out", help="folder for the PNG files (default: beside the results file)")
    plot.set_defaults(command=_plot)
    return parser


def _modes(args) -> int:
    with held_signals():
        from sixdof.io.scenario import load_scenario
        from sixdof.schema import naming

        scenario = load_scenario(args.scenario)  # its imports held with the rest: NumPy and JAX load there
    with naming(args.scenario):  # what the analysis finds wrong in the scenario names its file too
        return _show_modes(args, scenario)


def _show_modes(args, scenario) -> int:
    from sixdof.analysis.design import design_metrics
    from sixdof.analysis.statespace import damping_ratios
    from sixdof.analysis.statics import try_gravity_statics
    from sixdof.analysis.validity import RangeWarning, implausible_inputs, static_range
    from sixdof.errors import InputError, Plain
    from sixdof.io import report

    system = scenario.system
    modes = system.modes
    statics, no_statics = try_gravity_statics(system, scenario.statics.gravity, scenario.statics.direction)
    points = {p.name: p.position for p in scenario.points}
    for note in static_range(statics, system) + implausible_inputs(system, scenario.excitation, points):
        warnings.warn(note, RangeWarning, stacklevel=1)
    zeta = damping_ratios(system.C, modes, system.branches)
    if args.json:
        print(json.dumps(_modes_json(scenario, modes, statics, zeta, sensitivity=args.sensitivity)))
        return 0
    if args.sensitivity:
        raise InputError("--sensitivity", "--json as well (the derivatives are arrays)", Plain("--sensitivity alone"))
    print(f"{_title(scenario)}\n")
    print(report.modes_table(modes, zeta if system.C.any() or system.maxwell else None, system))
    print(report.damping_note(system))
    print("\nKinetic energy distribution [%] (share of each mode's kinetic energy in each DOF):")
    print(report.ke_table(modes))
    print()
    print(report.subsystems_text(modes))
    print()
    print(report.design_text(design_metrics(system, scenario.design.torque_axis)))
    _print_statics(scenario, statics, no_statics)
    return 0


def _print_statics(scenario, statics, no_statics: str | None = None) -> None:
    """The statics under gravity (or why there are none), what gravity's geometric stiffness does to the modes
    (:func:`~sixdof.analysis.validity.geometric_stiffness_note`), and a warning for mounts in tension."""
    from sixdof.analysis.validity import geometric_stiffness_note
    from sixdof.io import report

    print(f"\nStatics under gravity ({scenario.statics.gravity} m/s^2 along {list(scenario.statics.direction)}):")
    if statics is None:
        print(no_statics)
        return
    print(report.statics_table(statics, scenario.system))
    note = geometric_stiffness_note(scenario.system, scenario.statics.vector)
    if note is not None:
        print(note)
    if statics.uplift:
        warnings.warn(f"mounts in tension (uplift): {', '.join(statics.uplift)}", stacklevel=1)



def _run(args) -> int:
    from sixdof.cli.figures import FigureWorkers

    # Started first: the figure workers import matplotlib while this process loads the scenario and solves.
    with FigureWorkers() as workers:
        with held_signals():
            import numpy as np

            from sixdof.io import report
            from sixdof.io.scenario import load_scenario
            from sixdof.schema import naming
            from sixdof.workflows.run import run_scenario

            _compile_cache()
        scenario = load_scenario(args.scenario)
        with naming(args.scenario):  # what the run finds wrong in the scenario names its file too
            outcome = run_scenario(scenario, args.out, progress=_progress(args), command_line=" ".join(sys.argv),
                                   workers=workers)
    print(f"{_title(scenario)}\n")
    print(report.modes_table(outcome.modes, outcome.damping_ratios, scenario.system))
    print(report.damping_note(scenario.system))
    if scenario.viscoelastic:
        print(f"\nVisco-elastic mounts (Maxwell fits):\n{report.viscoelastic_table(scenario.viscoelastic)}")
    if outcome.statics is not None:
        _print_statics(scenario, outcome.statics)
    if outcome.steady_state is not None:
        print(f"\n{report.steady_state_text(outcome.steady_state)}")
    if outcome.random is not None:
        print(f"\nRandom vibration:\n{report.random_text(outcome.random)}")
    if outcome.srs is not None:
        print(f"\n{report.srs_text(outcome.srs)}")
    if outcome.agreement is not None:
        info = outcome.superposition.superposition
        until = " until the first nonlinear mount engaged" if outcome.contacts is not None else ""
        print(f"\nDirect solve vs modal superposition ({info.method} modes){until}: {outcome.agreement}")
        truncation = info.truncation
        if truncation is not None:
            kept = ", ".join(str(j + 1) for j in info.modes_kept)
            print(f"Truncated to modes {kept}; against all modes: {truncation}")
        ground = scenario.excitation.ground if scenario.excitation is not None else None
        if ground is not None and ground.baseline != "none":
            print(report.baseline_text(ground))
        stats = outcome.response.stats
        print(f"Solver {stats.solver}: {stats.num_accepted} steps, {stats.num_rejected} rejected, "
              f"{stats.wall_time_s:.2f} s")
        if outcome.contacts is not None:
            checks = report.nonlinear_text(outcome.contacts, outcome.energy, outcome.refined, outcome.agreement, stats)
            print(f"\nNonlinear mounts:\n{checks}")
        limits = np.stack([m.max_deflection for m in scenario.system.mounts])
        print(f"\nMount checks:\n{report.mount_check_text(outcome.mount_check, limits)}")
        if outcome.points:
            steady = outcome.steady_state is not None
            points = report.points_table(outcome.points, report.moving_ground(scenario), steady,
                                         ground=outcome.response)
            print(f"\nBody points: {points}")
    if outcome.frf is not None:
        print(f"FRF direct vs modal: {outcome.frf.max_relative_difference:.1e} (worst relative difference)")
    print(f"\nWrote {outcome.directory}: {outcome.results_path.name}, {len(outcome.figures)} figures, "
          f"{outcome.summary_path.name}")
    return 0


def _validate(args) -> int:
    from sixdof.cli.figures import FigureWorkers
    from sixdof.io.report import validation_text
    from sixdof.io.scenario import load_scenario
    from sixdof.schema import naming
    from sixdof.workflows.run import validate_scenario

    with FigureWorkers() as workers:  # started first: they import matplotlib while this process computes
        with held_signals():
            _compile_cache()
        scenario = load_scenario(args.scenario)
        with naming(args.scenario):
            report, directory = validate_scenario(scenario, args.out, command_line=" ".join(sys.argv),
                                                  workers=workers, progress=_progress(args))
    print(validation_text(report))
    print(f"\nWrote {directory}")
    if report.verdict != "PASS":
        failed = sorted({c.mode for c in report.checks if c.verdict != "PASS"})
        print(f"sixdof: validation FAILED for mode(s) {', '.join(map(str, failed))}: the model and the time "
              "histories disagree beyond the limits above", file=sys.stderr)
        return EXIT_VALIDATION_FAILED
    return 0


def _optimize(args) -> int:
    with held_signals():
        from sixdof.design.workflow import optimize_scenario
        from sixdof.io.scenario import load_scenario
        from sixdof.schema import naming

    _check_workers(args)
    scenario = load_scenario(args.scenario)
    with naming(args.scenario):
        outcome = optimize_scenario(scenario, args.out, progress=_progress(args), workers=args.workers,
                                    scheduler=args.scheduler)
    print(f"\nWrote {outcome.directory}: {', '.join(p.name for p in outcome.files)}")
    if not outcome.met:
        print("sixdof: the targets are not all met (see above); the best compromise is written", file=sys.stderr)
        return EXIT_TARGETS_NOT_MET
    return 0


def _where_arguments(parser, what: str) -> None:
    """``--workers`` and ``--scheduler``: where a study's chunks run (:func:`sixdof.tasks.task_runner`)."""
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, metavar="N",
                       help=f"compute the {what} on a local Dask cluster of N worker processes (default: in this "
                       "process)")
    where.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help=f"compute the {what} on an existing Dask cluster (tcp://host:8786)")


def _check_workers(args) -> None:
    """``--workers`` checked before anything is read (:func:`sixdof.tasks.check_workers`)."""
    if args.workers is not None:
        from sixdof.errors import integer
        from sixdof.tasks import check_workers

        check_workers(integer(args.workers, "--workers", "a number of worker processes >= 1", 1))


def _export(args) -> int:
    from sixdof.io.exchange import export

    files = export(args.results, args.out, args.format)
    print(f"Wrote {files[0].parent}: {', '.join(f.name for f in files)}")
    return 0


def _sweep(args) -> int:
    with held_signals():
        from sixdof.errors import SolverError
        from sixdof.io import report
        from sixdof.io.output import check_target
        from sixdof.io.scenario import load_scenario
        from sixdof.io.sweep import load_sweep_spec
        from sixdof.schema import naming
        from sixdof.sweeps import CHUNKS_SUFFIX, ChunkFolder, sweep_scenario

        _check_workers(args)
        _compile_cache()
    scenario = load_scenario(args.scenario)
    spec = load_sweep_spec(args.spec)
    try:
        with naming(args.scenario):  # the spec's own errors name the spec's file already
            outcome = sweep_scenario(scenario, spec, args.out, chunk_size=args.chunk_size, workers=args.workers,
                                     scheduler=args.scheduler, resume=args.resume, progress=_progress(args),
                                     command_line=" ".join(sys.argv))
    except (KeyboardInterrupt, Terminated, SolverError) as exc:
        chunks = check_target(args.out, scenario.name, "_sweep")
        chunks = chunks.with_name(chunks.name + CHUNKS_SUFFIX)
        kept = len(ChunkFolder.finished_in(chunks))
        if not kept:
            raise
        finished = f"the {kept} chunks finished are" if kept > 1 else "the chunk finished is"
        note = f"{finished} kept in {chunks}: the same command with --resume computes only the others"
        if isinstance(exc, SolverError):
            return _fail(args, f"the solve failed: {exc}; {note}", EXIT_FAILED)
        if isinstance(exc, Terminated):
            return _fail(args, f"terminated (SIGTERM); {note}", EXIT_TERMINATED)
        return _fail(args, f"interrupted; {note}", EXIT_INTERRUPTED)
    result = outcome.result
    print(f"{_title(scenario)}\n")
    print(outcome.table)
    if result.cross_check is not None:
        print(f"\n{report.cross_check_text(result)}")
    resumed = f", {outcome.resumed} of them resumed" if outcome.resumed else ""
    print(f"\nWrote {outcome.directory / 'sweep.h5'} and summary.md ({outcome.count} variants, {result.engine} engine, "
          f"{result.chunks} chunk{'s' if result.chunks != 1 else ''}{resumed}, {result.backend} with "
          f"{result.workers} worker{'s' if result.workers != 1 else ''}, {result.wall_time_s:.2f} s)")
    return 0


def _progress(args) -> bool:
    """Whether to show progress: not with ``--quiet``, and only where someone watches (redirected to a log,
    a meter redrawn in place would be noise)."""
    return not args.quiet and sys.stderr.isatty()


def _compile_cache() -> None:
    """Reuse compiled solvers across runs (JAX's persistent cache; SIXDOF_JAX_CACHE=off disables)."""
    from sixdof._jax import enable_compilation_cache

    enable_compilation_cache()


def _examples(args) -> int:
    from sixdof.examples import copy_examples

    copied = copy_examples(args.folder)
    print(f"Copied {len(copied)} files into {args.folder}; run one with\n"
          f"  sixdof run {os.path.join(args.folder, 'bridge_beam_traffic.toml')}")
    return 0


def _plot(args) -> int:
    from sixdof.cli.figures import FigureWorkers

    with FigureWorkers() as workers:  # started first: they import matplotlib while the file is read
        from sixdof.workflows.run import redraw

        figures = redraw(args.results, args.out, workers=workers)
    for figure in figures:
        print(figure)
    return 0


def _modes_json(scenario, modes, statics, zeta, sensitivity: bool = False) -> dict:
    """The modal and statics groups of the results file (:func:`sixdof.io.store.build_results`), each key the
    name of its dataset or attribute there (mode numbers from 1, like the file's), NaN as null; and, for
    scripts written before those names, the keys of earlier versions (``frequencies_hz``, ``omega_rad_s``,
    ``damping_ratios``, ``zero_modes`` (indices from 0), and in ``statics`` ``mounts``, ``mount_forces_n``,
    ``support_n``). ``mount_forces_n`` keeps the sign of those versions: the force of each mount on the body [N],
    ``-mount_force``."""
    import numpy as np

    from sixdof.io.store import build_results
    from sixdof.results import RunResults

    tree = build_results(RunResults(name=scenario.name, system=scenario.system, modes=modes, statics=statics,
                                    damping_ratios=zeta))

    def plain(value):
        if isinstance(value, (tuple, list)):
            return [plain(v) for v in value]
        value = np.asarray(value)
        if value.dtype.kind == "f":
            # NaN (rigid-body mode) and inf (overdamped: no oscillating pole) -> null: JSON has neither
            return np.where(np.isfinite(value), value.astype(object), None).tolist()
        return value.tolist()

    def group(name):
        found = {path.split("/", 1)[1]: plain(d.data) for path, d in tree.datasets.items()
                 if path.startswith(f"{name}/") and "/" not in path[len(name) + 1:]}
        return {**found, **{key: plain(value) for key, value in tree.attrs.get(name, {}).items()}}

    modal = group("modal")
    modal["subsystems"] = [list(g) for g in modes.subsystems]  # stored comma-joined: HDF5 has no ragged lists
    out = {"name": scenario.name, "dofs": modal["dof"], **modal,
           "frequencies_hz": modal["frequency_hz"], "omega_rad_s": modal["omega"],
           "damping_ratios": modal["damping_ratio"], "zero_modes": list(modes.zero_modes), "statics": None}
    laws = scenario.system.nonlinear
    # Modes of a system with nonlinear mounts are those of its linearization about the static equilibrium.
    out["linearized_axes"] = list(laws.names)
    out["linearized_stiffness"] = [float(k) for k in laws.tangent]
    out["geometric_stiffness"] = scenario.system.geometric_stiffness  # whether K (so the modes) holds gravity's K_G
    out["full_model_poles"] = _full_model_poles(scenario.system, modes, plain)
    out.update(_design_json(scenario, sensitivity, plain))
    if statics is not None:
        fixed = group("statics")
        # Earlier versions gave the force each mount exerts on the body (Fz > 0 under -z gravity); today's
        # mount_force is the body's force on the mount, its opposite. The legacy key keeps its own sign.
        legacy = plain(0.0 - np.asarray(statics.mount_forces))  # 0.0 - x: no -0.0
        out["statics"] = {**fixed, "mounts": fixed["mount"], "mount_forces_n": legacy,
                          "support_n": fixed["support"]}
    return out


def _full_model_poles(system, modes, plain) -> dict | None:
    """With Maxwell branches, the pole of each mode in the full visco-elastic model (the augmented state space,
    :func:`sixdof.analysis.statespace.damped_modes`), as the modes table's "f full model" column shows it:
    ``frequency_hz`` |lambda| / 2 pi, ``damped_frequency_hz`` Im(lambda) / 2 pi and ``damping_ratio``
    -Re(lambda) / |lambda|, per mode (null: a rigid-body or overdamped mode); None without branches."""
    import numpy as np

    from sixdof.analysis.statespace import damped_modes

    if not system.branches.count:
        return None
    poles, _ = damped_modes(system.C, modes, system.branches)
    size = np.abs(poles)
    return {"frequency_hz": plain(size / (2 * np.pi)), "damped_frequency_hz": plain(poles.imag / (2 * np.pi)),
            "damping_ratio": plain(-poles.real / size)}


def _design_json(scenario, sensitivity: bool, plain) -> dict:
    """The design metrics (:func:`sixdof.analysis.design.design_metrics`), modes numbered from 1, absent
    values null; with ``sensitivity``, the derivatives (mode, mount, axis) per mount-axis stiffness [N/m]."""
    import numpy as np

    from sixdof.analysis.design import design_metrics, sensitivities

    metrics = design_metrics(scenario.system, scenario.design.torque_axis)
    optional = {name: None if getattr(metrics, name) is None else plain(getattr(metrics, name))
                for name in ("torque_axis", "torque_roll_axis", "roll_mode_tra_angle_deg", "decoupling_tra_percent",
                             "elastic_center")}
    out = {"decoupling_percent": plain(metrics.decoupling_percent), **optional,
           "roll_mode": None if metrics.roll_mode is None else metrics.roll_mode + 1,
           "elastic_axes": plain(metrics.elastic_axes), "principal_stiffness": plain(metrics.principal_stiffness)}
    if sensitivity:
        from sixdof.io.report import without_round_off

        found = sensitivities(scenario.system)

        def shown(values):  # masked: no derivative -> null; round-off of the mode's largest (1e-36 for 0) -> 0
            return plain(np.where(values.mask, np.nan, without_round_off(values.data, axis=(1, 2))))

        out.update(frequency_sensitivity=shown(found.frequency), decoupling_sensitivity=shown(found.decoupling),
                   repeated_modes=[[j + 1 for j in group] for group in found.repeated_modes],
                   sensitivity_axes=["mode", "mount", "mount_axis"])
    return out
