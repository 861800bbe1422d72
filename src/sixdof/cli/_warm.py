"""Imported by the figure workers' server before it forks them (:mod:`sixdof.cli.figures`): imports
every plot module and draws a small figure, which loads what matplotlib otherwise loads on a first
drawing (the Agg canvas and PNG writer, the fonts, mathtext's parser for log-axis labels, 3-D axes), so
that each worker forked from the server starts warm.

The server ends with the command that started it, with nothing to clean up: it skips the interpreter's
teardown of matplotlib's modules (~0.3 s), during which it would hold the command's output open (a
caller reading that output through a pipe would wait for it).

Garbage is collected less often, as in the command's process (:func:`sixdof.cli._process.collect_less`), and
what the server loaded is left out of every collection (:func:`gc.freeze`): the workers inherit both, and their
memory pages stay shared with the server's instead of being copied when a collection touches them. They run
at the command's priority: at nice +5 they lost their share of a busy machine's cores to other programs, and the
run waited for its figures (``benchmarks/history.md``).
"""

import atexit
import gc
import os

from sixdof.cli import _process

_process.collect_less()  # before the imports below, which allocate most of what the server holds

from matplotlib.figure import Figure  # noqa: E402

import sixdof.plots.frf  # noqa: E402
import sixdof.plots.modes  # noqa: E402
import sixdof.plots.mount_time  # noqa: E402
import sixdof.plots.superposition  # noqa: E402
import sixdof.plots.time  # noqa: E402
import sixdof.plots.validation  # noqa: E402, F401

_figure = Figure(figsize=(2, 2))
_figure.add_subplot(1, 2, 1, yscale="log").plot([1.0, 1e3])
_figure.add_subplot(1, 2, 2, projection="3d").set_title("warm")
sixdof.plots.png(_figure, dpi=30)
del _figure

gc.freeze()
atexit.register(os._exit, 0)
