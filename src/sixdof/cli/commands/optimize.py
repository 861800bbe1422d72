"""``sixdof optimize``: the mounts optimized for the scenario's ``[design]`` targets."""

from __future__ import annotations

import sys

from sixdof.cli._status import EXIT_TARGETS_NOT_MET
from sixdof.cli.commands._common import check_workers_option, progress
from sixdof.io.scenario import load_scenario
from sixdof.schema import naming
from sixdof.workflows.optimize import DESIGN_FILES, optimize_scenario


def main(args, workers=None) -> int:
    check_workers_option(args)
    scenario = load_scenario(args.scenario)
    with naming(args.scenario):
        design, directory = optimize_scenario(scenario, args.out, progress=progress(args), workers=args.workers,
                                              scheduler=args.scheduler)
    print(f"\nWrote {directory}: {', '.join(DESIGN_FILES)}")
    if not design.met:
        print("sixdof: the targets are not all met (see above); the best compromise is written", file=sys.stderr)
        return EXIT_TARGETS_NOT_MET
    return 0
