"""The random-vibration figure: the input PSD with its RMS, and the response acceleration PSDs."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.random import RandomResponse
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.dofs import AXES, DOFS
from sixdof.plots.common import margins, require, title


def plot_random(random: RandomResponse, *, name: str = "") -> Figure:
    """Input PSD (top, its RMS in the title) and the absolute acceleration PSDs of the CG's translations and of
    each body point along its most excited axis (bottom), log-log, with each curve's RMS in the legend.

    Parameters
    ----------
    random : sixdof.analysis.random.RandomResponse
    name : str
        Name of the run, put before the title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(random, "random", RandomResponse, "a sixdof.analysis.random.RandomResponse")
    f = random.f_hz
    fig = Figure(figsize=(10, 8))
    fig.suptitle(title(name, "random vibration: input and response acceleration PSDs"), fontsize=12)
    margins(fig, left=1.0, right=0.3, top=0.75, bottom=0.6, hspace=0.9, rows=2)
    top, bottom = fig.subplots(2, 1, sharex=True)
    if random.input_kind == "force":
        top.loglog(f, random.input_psd, color="black", linewidth=1.4)
        top.set_ylabel("force PSD [N²/Hz]")
        top.set_title(f"input: force, RMS {random.input_rms:.4g} N", fontsize=10)
    else:
        top.loglog(f, random.input_psd / STANDARD_GRAVITY**2, color="black", linewidth=1.4)
        top.set_ylabel("ground acceleration PSD [g²/Hz]")
        top.set_title(f"input: ground acceleration, {random.input_rms / STANDARD_GRAVITY:.3g} grms", fontsize=10)
    for i in range(3):
        psd = random.qdd_psd[:, i]
        if np.any(psd > 0):
            bottom.loglog(f, psd / STANDARD_GRAVITY**2, linewidth=1.1,
                          label=f"CG {DOFS[i]}: {random.qdd_rms[i] / STANDARD_GRAVITY:.3g} grms")
    for name_, psd, rms in zip(random.points, random.point_acceleration_psd, random.point_acceleration_rms):
        axis = int(np.argmax(rms))
        bottom.loglog(f, psd[:, axis] / STANDARD_GRAVITY**2, linewidth=1.1, linestyle="--",
                      label=f"{name_} {AXES[axis]}: {rms[axis] / STANDARD_GRAVITY:.3g} grms")
    bottom.set_ylabel("acceleration PSD [g²/Hz]")
    bottom.set_xlabel("frequency f [Hz]")
    bottom.set_title("response: absolute acceleration", fontsize=10)
    if bottom.get_lines():
        bottom.legend(fontsize=8, loc="lower left")
        # Six decades below the largest response: a weakly excited DOF's tail would stretch the axis to 1e-16.
        peak = max(float(np.max(line.get_ydata())) for line in bottom.get_lines())
        bottom.set_ylim(peak * 1e-6, peak * 3)
    for ax in (top, bottom):
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlim(f[0], f[-1])
    return fig
