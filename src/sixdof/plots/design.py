"""Figures of a mount-system optimization: the modes against their frequency windows, and each mode's
decoupling, before and after. Modes are paired by the DOF that dominates them (the mode with the largest
kinetic-energy share in that DOF, as the targets select them), since an optimization may reorder them."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.design import mode_of_each_dof
from sixdof.dofs import DOFS
from sixdof.plots.common import DOF_MODE_TICKS, margins, title

_BEFORE, _AFTER = "0.55", "tab:blue"


def plot_design_frequencies(before, after, targets, *, name: str = "") -> Figure:
    """Natural frequency of the mode each DOF dominates, before (grey) and after (blue) the optimization,
    one row per DOF; each frequency target's window shaded on its DOF's row.

    Parameters
    ----------
    before, after : sixdof.model.modes.Modes
    targets : sequence of sixdof.design.spec.Target
    name : str
        Name of the run, put before the title.
    """
    fig = Figure(figsize=(10, 4.8))
    fig.suptitle(title(name, "natural frequency of the mode each DOF dominates: given design vs optimized"),
                 fontsize=12)
    margins(fig, left=1.5, right=0.3, top=0.9, bottom=0.6)
    ax = fig.add_subplot()
    rows = np.arange(len(DOFS))
    pairs = [modes.frequency_hz[mode_of_each_dof(modes)] for modes in (before, after)]
    # The given design hollow and larger: visible where the optimized one sits on it.
    ax.scatter(pairs[0], rows, facecolors="none", edgecolors=_BEFORE, linewidths=1.5, marker="o", s=110, zorder=3,
               label="given design")
    ax.scatter(pairs[1], rows, color=_AFTER, marker="D", s=40, zorder=4, label="optimized")
    for row, (f0, f1) in enumerate(zip(*pairs)):
        ax.annotate(f"{f0:.3g} → {f1:.3g} Hz", (max(f0, f1), row), xytext=(10, 0), textcoords="offset points",
                    va="center", fontsize=8, color="0.3")
    for row in rows:
        ax.annotate("", (pairs[1][row], row), (pairs[0][row], row),
                    arrowprops={"arrowstyle": "->", "color": "0.6", "linewidth": 0.8}, zorder=2)
    windows = [t for t in targets if t.kind == "frequency"]
    for k, target in enumerate(windows):
        row = DOFS.index(target.dof)
        ax.fill_betweenx([row - 0.35, row + 0.35], *target.f_hz, color="tab:green", alpha=0.25, linewidth=0,
                         label="target window" if k == 0 else None)
    ax.set_yticks(rows, DOF_MODE_TICKS)
    ax.set_ylim(-0.6, rows[-1] + 0.6)
    top = max(np.max(pairs), *(t.f_hz[1] for t in windows)) if windows else np.max(pairs)
    ax.set_xlim(0, 1.25 * top)  # room for the values written beside the markers
    ax.set_xlabel("natural frequency f [Hz]")
    ax.grid(True, axis="x", alpha=0.3)
    ax.legend(fontsize=9, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=3, frameon=False)
    return fig


def plot_design_decoupling(before, after, *, covered=None, minimum: float | None = None, coordinates: str = "body",
                           name: str = "") -> Figure:
    """The decoupling (kinetic-energy share of its dominant coordinate [%]) of the mode each DOF dominates,
    before and after, as paired bars; the target's bound (``minimum`` [%]) dashed over the DOFs it covers.

    Parameters
    ----------
    before, after : ndarray, shape (6,)
        Decoupling of the mode each DOF dominates [%], in DOF order.
    covered : sequence of str, optional
        DOFs whose mode the target covers; default all.
    minimum : float, optional
        The decoupling target's bound [%].
    coordinates : {"body", "tra"}
        The coordinates the shares are in (body axes, or the torque-roll axis frame).
    name : str
        Name of the run, put before the title.
    """
    fig = Figure(figsize=(10, 4.2))
    where = "body axes" if coordinates == "body" else "torque-roll-axis coordinates"
    fig.suptitle(title(name, f"decoupling of the mode each DOF dominates ({where})"), fontsize=12)
    margins(fig, left=0.9, right=0.3, top=0.9, bottom=0.6)
    ax = fig.add_subplot()
    x = np.arange(len(DOFS))
    for shift, shares, color, label in ((-0.2, before, _BEFORE, "given design"), (0.2, after, _AFTER, "optimized")):
        bars = ax.bar(x + shift, shares, width=0.38, color=color, label=label)
        ax.bar_label(bars, fmt="%.1f", fontsize=7, padding=1)
    if minimum is not None:
        for k, dof in enumerate(covered or DOFS):
            i = DOFS.index(dof)
            ax.plot([i - 0.45, i + 0.45], [minimum, minimum], color="tab:red", linestyle="--", linewidth=1.2,
                    label=f"target ≥ {minimum:g} %" if k == 0 else None)
    ax.set_xticks(x, DOF_MODE_TICKS)
    ax.set_ylim(0, 108)
    ax.set_ylabel("kinetic energy in the dominant coordinate [%]")
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=9, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=3, frameon=False)
    return fig
