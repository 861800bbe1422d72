"""``sixdof sweep``: many mount variants, chunk by chunk, merged into ``sweep.h5``."""

from __future__ import annotations

import sys

from sixdof.cli._status import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_TERMINATED, Terminated, fail
from sixdof.cli.commands._common import check_workers_option, compile_cache, progress
from sixdof.errors import SolverError
from sixdof.interrupts import held_signals
from sixdof.io import console, study_report
from sixdof.io.output import check_target
from sixdof.io.scenario import load_scenario
from sixdof.io.sweep import load_sweep_spec
from sixdof.schema import naming
from sixdof.workflows.prepare import prepare
from sixdof.workflows.sweep import CHUNKS_SUFFIX, ChunkFolder, sweep_scenario, sweep_tables


def main(args, workers=None) -> int:
    check_workers_option(args)
    with held_signals():
        compile_cache()
    scenario = load_scenario(args.scenario)
    spec = load_sweep_spec(args.spec)
    try:
        with naming(args.scenario):  # the spec's own errors name the spec's file already
            scenario = prepare(scenario)
            result, directory = sweep_scenario(scenario, spec, args.out, chunk_size=args.chunk_size,
                                               workers=args.workers, scheduler=args.scheduler, resume=args.resume,
                                               progress=progress(args), command_line=" ".join(sys.argv))
    except (KeyboardInterrupt, Terminated, SolverError) as exc:
        target = check_target(args.out, scenario.name, "_sweep")
        chunks = target.with_name(target.name + CHUNKS_SUFFIX)
        kept = len(ChunkFolder.finished_in(chunks))
        if not kept:
            raise
        finished = f"the {kept} chunks finished are" if kept > 1 else "the chunk finished is"
        note = f"{finished} kept in {chunks}: the same command with --resume computes only the others"
        if isinstance(exc, SolverError):
            return fail(args, f"the solve failed: {exc}; {note}", EXIT_FAILED)
        if isinstance(exc, Terminated):
            return fail(args, f"terminated (SIGTERM); {note}", EXIT_TERMINATED)
        return fail(args, f"interrupted; {note}", EXIT_INTERRUPTED)
    print(f"{console.title(scenario)}\n")
    print(sweep_tables(directory / "sweep.h5", scenario))
    if result.cross_check is not None:
        print(f"\n{study_report.cross_check_text(result)}")
    resumed = f", {result.resumed} of them resumed" if result.resumed else ""
    figures = len(list(directory.glob("sweep_*.png")))
    print(f"\nWrote {directory / 'sweep.h5'}, summary.md, report.html and {figures} figures ({spec.count} variants, "
          f"{result.engine} engine, {result.chunks} chunk{'s' if result.chunks != 1 else ''}{resumed}, "
          f"{result.backend} with {result.workers} worker{'s' if result.workers != 1 else ''}, "
          f"{result.wall_time_s:.2f} s)")
    return 0
