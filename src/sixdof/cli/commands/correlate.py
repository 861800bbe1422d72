"""``sixdof correlate``: a model against a test (UFF58 or CSV), and with ``--update`` the model updated to it."""

from __future__ import annotations

import json
import sys

from sixdof.cli._status import EXIT_VALIDATION_FAILED
from sixdof.cli.commands._common import progress
from sixdof.io.scenario import load_scenario
from sixdof.io.study_report import correlation_text
from sixdof.schema import naming
from sixdof.workflows.correlate import correlate_scenario, correlation_json


def main(args, workers=None) -> int:
    scenario = load_scenario(args.scenario)
    with naming(args.scenario):
        run, directory = correlate_scenario(scenario, args.test, args.out, update=args.update,
                                            command_line=" ".join(sys.argv), progress=progress(args))
    if args.json:
        print(json.dumps(correlation_json(run)))
    else:
        print(correlation_text(run))
        print(f"\nWrote {directory}")
    if not run.final.correlated:
        which = "updated model" if run.update is not None else "model"
        print(f"sixdof: the {which} and the test are NOT correlated within the limits (see the pairs above); the "
              "results are written", file=sys.stderr)
        return EXIT_VALIDATION_FAILED
    return 0
