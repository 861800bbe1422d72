"""Transmissibility and isolation at the operating frequencies (:mod:`sixdof.analysis.isolation_summary`)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.isolation_summary import IsolationSummary
from sixdof.plots.common import (
    COMPONENT_COLORS,
    margins,
    mark_modes,
    natural_frequencies,
    plain_frequencies,
    require,
    title,
)

#: The y label of each kind of curve: dimensionless ratios of amplitudes.
LABELS = {"force": "force transmissibility |F_foundation / F_applied| [1]",
          "moment": "moment transmissibility |M_foundation / M_applied| [1]",
          "motion": "motion transmissibility |x_body / x_ground| [1]"}
#: Face colour of the isolation region (|T| < 1 for every excited mode).
ISOLATION_COLOR = "tab:green"


def _efficiency(value: float) -> str:
    return f"isolation {100 * value:.1f} %" + ("" if value >= 0 else " (amplified)")


def _panel(ax, curves, frequency_hz) -> None:
    """One kind's curves, the isolation region above the highest of their boundaries, |T| = 1, the natural and
    the operating frequencies with the efficiency read off at each."""
    f = curves[0].f_hz
    top = max(curves, key=lambda c: c.isolation_hz)
    boundary = top.isolation_hz
    mode = max(top.excited_modes, key=lambda r: frequency_hz[r]) + 1 if frequency_hz is not None else None
    which = f" (mode {mode}, the highest excited)" if mode is not None else ""
    ax.axvspan(boundary, f[-1], color=ISOLATION_COLOR, alpha=0.12, zorder=0,
               label=f"isolation region: f > sqrt(2) x {boundary / np.sqrt(2):.4g} Hz{which} = {boundary:.4g} Hz")
    ax.axhline(1.0, color="black", linewidth=0.8, zorder=1)
    for k, curve in enumerate(curves):
        many = len(curves) > 1
        label = f"load pattern at {', '.join(f'{v:.4g}' for v in curve.operating_hz)} Hz" if many else (
            {"force": "force on the foundation / applied force", "moment": "moment on the foundation / applied moment",
             "motion": "CG / ground translation"}[curve.kind])
        ax.loglog(curve.f_hz, curve.values, color=COMPONENT_COLORS[k % len(COMPONENT_COLORS)], linewidth=1.4,
                  label=label, zorder=4)  # over the operating frequencies' labels: they never hide it
    ax.set_xlim(f[0], f[-1])
    ax.set_ylabel(LABELS[curves[0].kind])
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.12)
    mark_modes(ax, frequency_hz, label=True)
    for curve in curves:
        for f_op, t, eff in zip(curve.operating_hz, curve.at_operating, curve.efficiency):
            ax.axvline(f_op, color="tab:red", linewidth=1.0, linestyle="-.", zorder=2)
            ax.plot([f_op], [t], "o", color="tab:red", markersize=5, zorder=3)
            ax.annotate(f"operating {f_op:.4g} Hz\n|T| = {t:.3g}, {_efficiency(eff)}", (f_op, t),
                        xytext=(6, 12), textcoords="offset points", fontsize=8, color="tab:red", va="bottom",
                        bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 1.0}, zorder=3.5)
    ax.legend(loc="lower left", fontsize=8)
    plain_frequencies(ax)


def plot_transmissibility(summary: IsolationSummary, modes=None, fig: Figure | None = None, *,
                          name: str = "") -> Figure:
    """Force transmissibility of the operating loads and motion transmissibility of the ground, log-log against
    frequency, with the operating frequencies marked and their isolation efficiency written beside them, and
    the isolation region shaded.

    Parameters
    ----------
    summary : sixdof.analysis.isolation_summary.IsolationSummary
        The curves (:func:`~sixdof.analysis.isolation_summary.isolation_summary`).
    modes : sixdof.model.modes.Modes, optional
        Given, the modes' natural frequencies are marked (dotted, numbered) where the summary reckons them
        (:attr:`~sixdof.analysis.isolation_summary.IsolationSummary.natural_hz`: with Maxwell branches, the
        full model's poles, where the curves peak).
    fig : matplotlib.figure.Figure, optional
        Draw into this figure: one panel per kind of curve (force, moment of a torque, ground motion, from the
        top), sharing the frequency axis;
        its title and margins are left as they are. Default: a new figure.
    name : str
        Name of the run, put before the title (new figure only).

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(summary, "summary", IsolationSummary, "a sixdof.analysis.isolation_summary.IsolationSummary")
    # The frequencies the isolation regions are reckoned from: on Maxwell mounts the full model's, not the modes'.
    frequency_hz = None if natural_frequencies(modes) is None else summary.natural_hz
    kinds = [curves for curves in ([c for c in summary.loads if c.kind == kind] for kind in ("force", "moment"))
             if curves] + ([[summary.motion]] if summary.motion is not None else [])
    if not kinds:
        raise ValueError("summary: no transmissibility to draw (no operating frequency)")
    new = fig is None
    if new:
        fig = Figure(figsize=(9.0, 1.0 + 4.2 * len(kinds)))
    axes = np.atleast_1d(fig.subplots(len(kinds), 1, sharex=True, squeeze=False)[:, 0])
    for ax, curves in zip(axes, kinds):
        _panel(ax, list(curves), frequency_hz)
    axes[-1].set_xlabel("frequency [Hz]")
    if new:
        fig.suptitle(title(name, "transmissibility and isolation at the operating frequencies"))
        margins(fig, left=0.9, right=0.3, top=0.55, bottom=0.6, hspace=0.3, rows=len(kinds))
    return fig
