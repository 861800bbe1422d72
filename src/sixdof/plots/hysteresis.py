"""The hysteresis loops figure: force against deflection for every hysteretic mount axis of a direct solve."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.response import MountForces
from sixdof.model.system import System
from sixdof.plots.common import figure, margins, require, title
from sixdof.results import TimeHistory

#: Axes whose peak deflection is below this share of the largest one's are left out (they barely moved).
DRAWN_SHARE = 1e-3
#: Loops drawn side by side.
COLUMNS = 4


def plot_hysteresis(system: System, response: TimeHistory, forces: MountForces, *, name: str = "",
                    fig: Figure | None = None) -> Figure:
    """Force [kN] against deflection from rest [mm] of each hysteretic mount axis (Bouc-Wen, friction pendulum)
    that moved, one panel each: the loops of a direct solve, whose areas are the energy each axis dissipated.
    The linear paths' stiffness of the axis (initial or effective) is drawn dashed through the origin.

    Parameters
    ----------
    system : sixdof.model.system.System
        With hysteretic mounts (:attr:`~sixdof.model.system.System.hysteretic`).
    response : sixdof.results.TimeHistory
        A direct solve's (with :attr:`~sixdof.results.TimeHistory.hysteretic_state`).
    forces : sixdof.analysis.response.MountForces
        Of ``response``.
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one panel (force against deflection) per mount axis that moved, in rows of up to a few columns.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(system, "system", System, "a sixdof.model.system.System")
    require(response, "response", TimeHistory, "a sixdof.results.TimeHistory")
    require(forces, "forces", MountForces, "a sixdof.analysis.response.MountForces")
    h = system.hysteretic
    d = response.q_relative @ h.rows.T
    force = forces.local[h.mount, :, h.axis].T
    peaks = np.abs(d).max(axis=0) if h.count else np.zeros(0)
    drawn = [e for e in range(h.count) if peaks[e] > DRAWN_SHARE * max(peaks.max(), 1e-300)]
    columns = max(1, min(COLUMNS, len(drawn)))
    rows = max(1, -(-len(drawn) // columns))
    fig = figure(fig, (3.2 * columns + 0.8, 2.9 * rows + 0.9))
    fig.suptitle(title(name, "hysteresis loops: force against deflection of each hysteretic mount axis"),
                 fontsize=12)
    margins(fig, left=0.8, right=0.2, top=0.7, bottom=0.6, wspace=0.75, hspace=0.7, columns=columns, rows=rows)
    linear = h.linear_stiffness
    for k, e in enumerate(drawn):
        ax = fig.add_subplot(rows, columns, k + 1)
        ax.plot(1e3 * d[:, e], 1e-3 * force[:, e], color="C0", linewidth=0.9)
        span = np.array([-peaks[e], peaks[e]])
        ax.plot(1e3 * span, 1e-3 * linear[e] * span, color="0.4", linewidth=0.8, linestyle="--",
                label=f"{h.linearization[e]}: {1e-3 * linear[e]:.4g} kN/m" + (
                    f" at D = {1e3 * h.design_displacement[e]:.4g} mm" if h.linearization[e] == "effective" else ""))
        ax.axhline(0.0, color="0.8", linewidth=0.6)
        ax.axvline(0.0, color="0.8", linewidth=0.6)
        law = "friction pendulum" if h.pendulum[e] else "Bouc-Wen"
        ax.set_title(f"mount {system.mounts[h.mount[e]].name}, axis {'uvw'[h.axis[e]]} ({law})", fontsize=10)
        ax.set_xlabel("deflection along the axis [mm]")
        ax.set_ylabel("force along the axis [kN]")
        ax.set_ylim(*(1.15 * np.array([-1, 1]) * max(1e-3 * np.abs(force[:, e]).max(), 1e-12)))
        ax.grid(True, alpha=0.25)
        ax.legend(fontsize=7, loc="upper left")
    if not drawn:
        ax = fig.add_subplot()
        ax.text(0.5, 0.5, "no hysteretic mount axis moved", ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
    return fig
