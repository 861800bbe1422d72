"""Who draws a workflow's figures: the drawer given (the command's worker processes), or this process."""

import contextlib

from sixdof.plots.workers import FigureWorkers


def drawer(drawing):
    """``drawing`` (``submit(results)``, ``save(folder) -> list of paths``) as a context that leaves it open, or
    figures drawn in this process when ``None``."""
    return FigureWorkers(processes=0) if drawing is None else contextlib.nullcontext(drawing)
