"""The shock-response-spectrum figure: the base shock's SRS against the body points', what the isolators remove."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.srs import ShockSpectra
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.dofs import AXES
from sixdof.plots.common import axis_label, margins, merge_identical, plain_log_ticks, require, title

G = STANDARD_GRAVITY


def plot_srs(spectra: ShockSpectra, ax=None, *, name: str = "") -> Figure:
    """Maximax absolute-acceleration SRS [g] against natural frequency [Hz], log-log: the base acceleration's
    (black) and each body point's along each axis that sees at least 1 % of the largest peak.

    Parameters
    ----------
    spectra : sixdof.analysis.srs.ShockSpectra
    name : str
        Name of the run, put before the title.

    ax : matplotlib.axes.Axes, optional
        Axes to draw into (the run's title is then left to the caller); default a new figure's.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(spectra, "spectra", ShockSpectra, "a sixdof.analysis.srs.ShockSpectra")
    f = spectra.f_hz
    if ax is None:
        fig = Figure(figsize=(10, 6))
        fig.suptitle(title(name, f"shock response spectra (maximax absolute acceleration, Q = {spectra.q:g})"),
                     fontsize=12)
        margins(fig, left=1.0, right=0.3, top=0.7, bottom=0.6)
        ax = fig.add_subplot()
    fig = ax.figure
    if spectra.input is not None:
        ax.loglog(f, spectra.input / G, color="black", linewidth=1.8, label="base (input)")
    largest = float(np.max(spectra.points)) if spectra.points.size else 0.0
    curves = [(curve, f"{point} along {axis}", None) for point, point_curves in zip(spectra.names, spectra.points)
              for axis, curve in zip(AXES, point_curves) if largest > 0 and np.max(curve) >= 0.01 * largest]
    for curve, label, _ in merge_identical(curves):
        ax.loglog(f, curve / G, linewidth=1.2, label=label)
    ax.set_xlabel("natural frequency f [Hz]")
    ax.set_ylabel(axis_label("peak absolute acceleration", "g"))
    ax.set_xlim(f[0], f[-1])
    ax.grid(True, which="both", alpha=0.25)
    for axis in (ax.xaxis, ax.yaxis):
        plain_log_ticks(axis)
    if ax.get_lines():
        ax.legend(fontsize=8, loc="best")
    return fig
