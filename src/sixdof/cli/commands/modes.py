"""``sixdof modes``: natural frequencies, mode shapes, decoupling, statics."""

from __future__ import annotations

import json

from sixdof.cli.commands._common import print_statics
from sixdof.errors import InputError, Plain
from sixdof.io import console
from sixdof.schema import naming
from sixdof.workflows.modes import modal_run, modes_json


def main(args, workers=None) -> int:
    if args.sensitivity and not args.json:  # before anything is computed
        raise InputError("--sensitivity", "--json as well (the derivatives are arrays)", Plain("--sensitivity alone"))
    with naming(args.scenario):  # what the analysis finds wrong in the scenario names its file too
        run = modal_run(args.scenario, sensitivity=args.sensitivity)
    if args.json:
        print(json.dumps(modes_json(run)))
        return 0
    print(console.modes_text(run))
    print_statics(run.results, run.no_statics)
    return 0
