"""The response-spectrum figure: the spectrum along each direction analysed against period, each mode marked at its
period with the value it received."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.spectrum import ResponseSpectrum
from sixdof.plots.common import margins, merge_identical, require, title

#: A mode is marked on a direction's curve when its effective mass there is at least this share of the mass
#: the direction's modes carry (the others receive the spectrum but do not respond to it).
MARKED_SHARE = 0.01


def plot_spectrum(spectrum: ResponseSpectrum, ax=None, *, name: str = "") -> Figure:
    """Pseudo-acceleration [m/s^2] against period [s]: the spectrum along each direction at the analysis's damping
    ratio (curves equal along two directions drawn once), and each mode that responds along a direction marked at
    its period and spectral value there, numbered (hollow where its damping differs from the curve's).

    Parameters
    ----------
    spectrum : sixdof.analysis.spectrum.ResponseSpectrum
    name : str
        Name of the run, put before the title.

    ax : matplotlib.axes.Axes, optional
        Axes to draw into (the run's title is then left to the caller); default a new figure's.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(spectrum, "spectrum", ResponseSpectrum, "a sixdof.analysis.spectrum.ResponseSpectrum")
    if ax is None:
        fig = Figure(figsize=(10, 6))
        fig.suptitle(title(name, f"response spectrum and the modes ({spectrum.combination.upper()}, "
                           f"{100 * spectrum.damping:g} % damping)"), fontsize=12)
        margins(fig, left=0.9, right=0.3, top=0.9, bottom=0.6)
        ax = fig.add_subplot()
    fig = ax.figure
    ax.set_title(spectrum.spectrum, fontsize=8)
    T = spectrum.curve_period
    curves = [(curve, f"direction {d}", k) for k, (d, curve) in enumerate(zip(spectrum.direction, spectrum.curve))]
    colors = {}
    for curve, label, k in merge_identical(curves):
        line, = ax.plot(T, curve, linewidth=1.6, label=label.replace(" = direction", " ="))
        colors[k] = line.get_color()
    marks = {}  # (period, value) -> [(mode, direction, color, own damping)]: modes at one point labelled once
    for k, direction in enumerate(spectrum.direction):
        color = colors.get(k) or colors[next(j for j in colors if np.allclose(spectrum.curve[j], spectrum.curve[k]))]
        mass = spectrum.effective_mass[k]
        for j in np.flatnonzero(mass >= MARKED_SHARE * max(float(mass.sum()), np.finfo(float).tiny)):
            at = (round(float(spectrum.period[j]), 6), round(float(spectrum.spectral_acceleration[k, j]), 6))
            marks.setdefault(at, []).append((j + 1, direction, color,
                                             np.isclose(spectrum.mode_damping[j], spectrum.damping)))
    # Labels of neighbouring modes alternate below and above their markers, which are drawn over any label.
    for n, ((period, value), modes) in enumerate(sorted(marks.items())):
        for _, _, color, own in modes:
            ax.plot(period, value, "o", markersize=7, color=color, markerfacecolor=color if own else "white",
                    markeredgewidth=1.5, zorder=5)
        text = ", ".join(f"{j} ({d})" for j, d, _, _ in modes)
        ax.annotate(f"mode {text}" if len(modes) == 1 else f"modes {text}", (period, value),
                    textcoords="offset points", xytext=(7, -14 if n % 2 == 0 else 6), fontsize=9, color=modes[0][2],
                    bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.8})
    ax.plot([], [], "o", color="0.3", label="a mode at its period (hollow: its own damping)")
    ax.set_xlabel("period T [s]")
    ax.set_ylabel("pseudo-acceleration $S_a$ [m/s²]")
    ax.set_xlim(T[0], T[-1])
    ax.set_ylim(0, 1.12 * max(float(np.max(spectrum.curve)), float(np.max(spectrum.spectral_acceleration))))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=9, loc="upper right")
    return fig
