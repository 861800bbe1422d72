"""``sixdof validate``: modal results against simulated time histories."""

from __future__ import annotations

import sys

from sixdof.cli._status import EXIT_VALIDATION_FAILED
from sixdof.cli.commands._common import compile_cache, progress
from sixdof.interrupts import held_signals
from sixdof.io.scenario import load_scenario
from sixdof.io.study_report import validation_text
from sixdof.schema import naming
from sixdof.workflows.validate import validate_scenario


def main(args, workers=None) -> int:
    with held_signals():
        compile_cache()
    scenario = load_scenario(args.scenario)
    with naming(args.scenario):
        found, directory = validate_scenario(scenario, args.out, command_line=" ".join(sys.argv), workers=workers,
                                             progress=progress(args))
    print(validation_text(found))
    print(f"\nWrote {directory}")
    if found.verdict != "PASS":
        failed = sorted({c.mode for c in found.checks if c.verdict != "PASS"})
        print(f"sixdof: validation FAILED for mode(s) {', '.join(map(str, failed))}: the model and the time "
              "histories disagree beyond the limits above", file=sys.stderr)
        return EXIT_VALIDATION_FAILED
    return 0
