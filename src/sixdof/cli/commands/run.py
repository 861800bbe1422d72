"""``sixdof run``: everything a scenario asks for, written under ``--out``."""

from __future__ import annotations

import sys

from sixdof.cli.commands._common import compile_cache, progress, warn_uplift
from sixdof.interrupts import held_signals
from sixdof.io import console
from sixdof.plots import figure_names
from sixdof.schema import naming
from sixdof.workflows.run import run_scenario


def main(args, workers=None) -> int:
    with held_signals():
        compile_cache()
    with naming(args.scenario):  # what the run finds wrong in the scenario names its file too
        results, directory = run_scenario(args.scenario, args.out, progress=progress(args),
                                          command_line=" ".join(sys.argv), workers=workers)
    print(console.run_text(results))
    warn_uplift(results)
    gifs = len(results.modes.frequency_hz) if results.scenario.output.animate_modes and results.modes is not None else 0
    animations = f", {gifs} mode animations (mode_1.gif...)" if gifs else ""
    print(f"\nWrote {directory}: results.h5, {len(figure_names(results))} figures{animations}, summary.md, "
          "report.html")
    return 0
