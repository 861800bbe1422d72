"""``sixdof plot``: every figure of a results file drawn again."""

from __future__ import annotations

from sixdof.workflows.redraw import redraw


def main(args, workers=None) -> int:
    for figure in redraw(args.results, args.out, workers=workers):
        print(figure)
    return 0
