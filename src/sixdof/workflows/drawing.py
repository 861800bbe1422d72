"""Who draws a workflow's figures: the drawer given (the command's worker processes), or this process."""

import contextlib

from sixdof.plots.drawer import InProcessDrawer


def drawer(drawing):
    """``drawing`` (a :class:`~sixdof.plots.drawer.FigureDrawer`) as a context that leaves it open (its owner closes
    it), or an :class:`~sixdof.plots.drawer.InProcessDrawer` when ``None``."""
    return InProcessDrawer() if drawing is None else contextlib.nullcontext(drawing)
