"""The spectrum-compatible records' figure: each record's spectrum, their mean and the target, with the band of
EN 1998-1 3.2.3.1.2(4)c and its 90 % floor; the accelerograms below."""

from __future__ import annotations

import textwrap

import numpy as np
from matplotlib.figure import Figure

from sixdof.plots.common import figure, margins, plain_log_ticks, plot_long, title


def plot_records(records, check, *, name: str = "", fig: Figure | None = None) -> Figure:
    """Top: pseudo-acceleration [m/s^2] against period [s] (log): each record's 5 %-damped spectrum (thin), their
    mean (thick), the target and 90 % of it over the band 0.2 T1-2 T1 (shaded) that EN 1998-1 3.2.3.1.2(4)c checks.
    Bottom: the accelerograms [m/s^2] against time [s], the first in colour, with ``ag S``.

    Parameters
    ----------
    records : sixdof.analysis.matching.SpectrumCompatibleRecords
    check : sixdof.analysis.matching.RecordCheck
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: the records' spectra above their accelerograms.

    Returns
    -------
    matplotlib.figure.Figure
    """
    count = records.acceleration.shape[0]
    fig = figure(fig, (10, 8))
    verdict = "meet EN 1998-1 3.2.3.1.2" if check.passed else "do NOT meet EN 1998-1 3.2.3.1.2"
    fig.suptitle(title(name, f"{count} spectrum-compatible records ({verdict})"), fontsize=12)
    margins(fig, left=0.9, right=0.3, top=1.0, bottom=0.6, hspace=0.9, rows=2)
    top, bottom = fig.add_subplot(2, 1, 1), fig.add_subplot(2, 1, 2)
    top.set_title(textwrap.fill(records.target_source or records.method, 170), fontsize=7)
    lo, hi = check.band
    top.axvspan(lo, hi, color="0.92", zorder=0, label=f"0.2 T1-2 T1 (T1 = {hi / 2:.4g} s)")
    T = records.periods
    for k, spectrum in enumerate(records.spectra):
        top.plot(T, spectrum, color="0.6", linewidth=0.6, label="each record" if k == 0 else None)
    top.plot(T, records.mean_spectrum, color="tab:blue", linewidth=2.0, label=f"mean of the {count}")
    top.plot(T, records.target, color="black", linewidth=1.4, linestyle="--", label="target (elastic, 5 %)")
    inside = (check.check_periods >= lo) & (check.check_periods <= hi)
    top.plot(check.check_periods[inside], 0.9 * check.target[inside], color="tab:red", linewidth=1.2,
             linestyle=":", label="90 % of the target (the floor)")
    top.set_xscale("log")
    plain_log_ticks(top.xaxis)
    top.set_xlim(T[0], T[-1])
    top.set_ylim(0, None)
    top.set_xlabel("period T [s]")
    top.set_ylabel("pseudo-acceleration $S_a$ [m/s²]")
    top.grid(True, which="both", alpha=0.3)
    top.legend(fontsize=8, loc="lower center")
    t = records.t
    for k in range(count - 1, -1, -1):  # the first drawn last, over the others
        plot_long(bottom, t, records.acceleration[k], color="tab:blue" if k == 0 else "0.75",
                  linewidth=0.7 if k == 0 else 0.5, label="record 1" if k == 0 else None)
    for sign in (1, -1):
        bottom.axhline(sign * check.ag_s, color="black", linewidth=0.8, linestyle="--",
                       label=f"± ag S = {check.ag_s:.4g} m/s²" if sign == 1 else None)
    bottom.set_xlim(t[0], t[-1])
    bottom.set_xlabel("time t [s]")
    bottom.set_ylabel("ground acceleration [m/s²]")
    bottom.grid(True, alpha=0.3)
    bottom.legend(fontsize=8, loc="upper right")
    peak = np.max(np.abs(records.acceleration), axis=1)
    bottom.set_title(f"peaks {peak.min():.3g} to {peak.max():.3g} m/s², mean {check.pga_mean:.4g} m/s²", fontsize=8)
    return fig
