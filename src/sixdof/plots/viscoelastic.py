"""The dynamic stiffness figure: measured storage stiffness and loss factor against generalized Maxwell fits."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from sixdof.errors import InputError
from sixdof.model.viscoelastic import MaxwellFit
from sixdof.plots.common import figure, margins, plain_frequencies

#: The fitted curves are drawn this factor beyond each end of their data's band: how the model leaves it.
BEYOND_BAND = 2.0


#: Height [in] of one legend row of :func:`plot_dynamic_stiffness`.
LEGEND_ROW = 0.2


def plot_dynamic_stiffness(fits: Sequence[tuple[str, MaxwellFit]], title: str | None = None, *,
                           fig: Figure | None = None) -> Figure:
    """Storage stiffness (top, log) and loss factor (bottom) against frequency: each fit's data as markers
    and its model as a line of the same colour over the data's band and a factor :data:`BEYOND_BAND` beyond
    each end, with the fit's worst errors in the legend.

    Parameters
    ----------
    fits : sequence of (str, MaxwellFit)
        A label and a fit (:func:`~sixdof.model.viscoelastic.fit_maxwell`,
        :func:`~sixdof.model.viscoelastic.constant_loss_model`) per curve.
    title : str, optional
        Title of the figure; default "dynamic stiffness: data and generalized Maxwell fits".
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: the storage stiffness above the loss factor, the legend below.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    sixdof.errors.InputError
        When ``fits`` is not a non-empty sequence of (label, MaxwellFit) pairs.
    """
    expected = "a non-empty sequence of (label, sixdof.model.viscoelastic.MaxwellFit) pairs"
    fits = list(fits) if isinstance(fits, Sequence) and not isinstance(fits, str) else []
    if not fits or not all(isinstance(item, tuple) and len(item) == 2 and isinstance(item[0], str)
                           and isinstance(item[1], MaxwellFit) for item in fits):
        raise InputError("fits", expected, fits)
    legend_height = LEGEND_ROW * len(fits)  # below the axes: inside them it hid the stiffest curve's data
    fig = figure(fig, (9, 7.5 + legend_height))
    fig.suptitle(title or "dynamic stiffness: data and generalized Maxwell fits", fontsize=12)
    margins(fig, left=1.0, right=0.3, top=0.75, bottom=0.6 + legend_height, hspace=0.45, rows=2)
    top, bottom = fig.subplots(2, 1, sharex=True)
    for label, fit in fits:
        low, high = fit.band_hz
        f = np.geomspace(low / BEYOND_BAND, high * BEYOND_BAND, 400)
        k = fit.dynamic_stiffness(f)
        line, = top.loglog(f, k.real, linewidth=1.4,
                           label=f"{label}: {np.count_nonzero(fit.stiffness)} branches; worst errors "
                                 f"{100 * fit.modulus_error:.2g} % in |K*|, {100 * fit.loss_factor_error:.2g} % in "
                                 "loss factor")
        bottom.semilogx(f, k.imag / k.real, color=line.get_color(), linewidth=1.4)
        top.plot(fit.f_hz, fit.storage, "o", color=line.get_color(), markersize=4, markerfacecolor="none")
        bottom.plot(fit.f_hz, fit.loss_factor, "o", color=line.get_color(), markersize=4, markerfacecolor="none")
    top.set_ylabel("storage stiffness K' [N/m]")
    top.set_title("markers: measured, or a constant loss factor at the natural and operating frequencies; lines: "
                  "Maxwell fits", fontsize=10)
    fig.legend(*top.get_legend_handles_labels(), fontsize=8, loc="lower left", frameon=False,
               bbox_to_anchor=(1.0 / fig.get_figwidth(), 0.05 / fig.get_figheight()))
    bottom.set_ylabel("loss factor η = K''/K' [1]")
    bottom.set_xlabel("frequency f [Hz]")
    bottom.set_ylim(bottom=0.0)
    for ax in (top, bottom):
        ax.grid(True, which="both", alpha=0.25)
    bottom.autoscale(axis="x", tight=True)
    plain_frequencies(bottom)
    return fig


def plot_mount_fits(fits: Sequence[MaxwellFit], name: str = "", *, fig: Figure | None = None) -> Figure:
    """:func:`plot_dynamic_stiffness` of a run's fits (:attr:`sixdof.results.RunResults.viscoelastic`), one curve
    per distinct model: mount axes fitted to the same data alike share a label (``"B u, C u (loss factor 0.1)"``).

    Parameters
    ----------
    fits : sequence of sixdof.model.viscoelastic.MaxwellFit
        The run's fits, one per mount axis.
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        As :func:`plot_dynamic_stiffness`'s. Layout: the storage stiffness above the loss factor, the legend below.

    Returns
    -------
    matplotlib.figure.Figure
    """
    curves: dict[tuple, list[MaxwellFit]] = {}
    for fit in fits:
        key = (fit.source, fit.long_term, *fit.stiffness, *fit.tau, *fit.f_hz, *fit.storage, *fit.loss_factor)
        curves.setdefault(key, []).append(fit)
    labelled = [(f"{', '.join(f.name for f in same) if len(same) <= 2 else f'{len(same)} mount axes'} "
                 f"({same[0].source})", same[0]) for same in curves.values()]
    return plot_dynamic_stiffness(labelled, title=f"{name}: mount dynamic stiffness and Maxwell fits" if name else None,
                                  fig=fig)
