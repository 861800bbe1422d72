"""Imported by the figure workers' server before it forks them (:mod:`sixdof.plots.workers`): imports
every plot module and draws a small figure, which loads what matplotlib otherwise loads on a first
drawing (the Agg canvas and PNG writer, the fonts, mathtext's parser for log-axis labels, 3-D axes), so
that each worker forked from the server starts warm."""

import io

from matplotlib.figure import Figure

import sixdof.plots.frf
import sixdof.plots.modes
import sixdof.plots.time
import sixdof.plots.validation  # noqa: F401

_figure = Figure(figsize=(2, 2))
_figure.add_subplot(1, 2, 1, yscale="log").plot([1.0, 1e3])
_figure.add_subplot(1, 2, 2, projection="3d").set_title("warm")
_figure.savefig(io.BytesIO(), format="png", dpi=30)
del _figure
