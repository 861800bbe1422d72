"""Figures of a design sweep (``sixdof sweep``): how the natural frequencies, the decoupling and the peak responses
spread over the variants, and what moves each frequency.

What a vibration engineer reads off a tolerance or design sweep, and so what is drawn:

- each mode's natural frequency as a box over the variants (:func:`plot_sweep_frequencies`), one panel per mode at
  its own scale (a +-5 % spread of a 0.6 Hz mode is invisible on the axis of a 38 Hz one), the nominal design
  dashed: will a mode move into the band of an excitation?
- each mode's decoupling, the kinetic-energy share of its dominant DOF in percent, on one axis
  (:func:`plot_sweep_decoupling`): does the scatter couple the modes?
- each DOF's peak displacement and acceleration where the sweep simulates (:func:`plot_sweep_peaks`);
- a tornado chart per mode (:func:`plot_sweep_sensitivity`): the change of its frequency as each swept parameter
  goes across its range, largest first, from the least-squares fit of :mod:`sixdof.analysis.sweep_fit`: which
  tolerance to tighten.

The boxes are those of the sweep's summary: the box spans the quartiles, the whiskers the 5th and 95th
percentiles, the line inside is the median, and the variants beyond the whiskers are drawn as points. Modes are
those of the nominal system followed into every variant by their shape (``tracked_frequency_hz``), labelled by
their number and dominant DOF.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.sweep_fit import SPAN_PERCENTILES as SPAN
from sixdof.analysis.sweep_fit import sweep_sensitivity
from sixdof.dofs import DOFS, display_unit, dof_units
from sixdof.plots.common import margins, panel_grid, title

#: Whisker percentiles of every box: those of the sweep's summary table.
WHISKERS = (5.0, 95.0)
#: At most this many parameters per tornado panel (the largest effects); the rest are counted in the panel.
TORNADO_BARS = 8
_BOX = dict(whis=WHISKERS, widths=0.6, patch_artist=True, showfliers=True,
            boxprops=dict(facecolor="tab:blue", alpha=0.35, edgecolor="tab:blue"),
            medianprops=dict(color="tab:blue", linewidth=2), whiskerprops=dict(color="tab:blue"),
            capprops=dict(color="tab:blue"), flierprops=dict(marker=".", markersize=3, markeredgecolor="0.4"))
_LEGEND = (f"boxes: quartiles and median; whiskers: {WHISKERS[0]:g}th and {WHISKERS[1]:g}th percentiles; "
           "points: variants beyond them")
_NOMINAL = dict(color="0.2", linestyle="--", linewidth=1.2)


def mode_labels(modes) -> list[str]:
    """``"mode 1 (x)"``...: each nominal mode's number and dominant DOF."""
    return [f"mode {j + 1} ({dof})" for j, dof in enumerate(modes.dominant_dof)]


def _tracked(result, field: str):
    """The tracked form of a per-mode field of a sweep, else the ascending one (files written before tracking)."""
    tracked = getattr(result, f"tracked_{field}", None)
    return np.asarray(getattr(result, field) if tracked is None else tracked, dtype=float)


def _finite(column: np.ndarray) -> np.ndarray:
    return column[np.isfinite(column)]


def _figure(fig, size) -> Figure:
    if fig is None:
        return Figure(figsize=size)
    fig.clear()
    return fig


def plot_sweep_frequencies(result, modes, *, name: str = "", fig: Figure | None = None) -> Figure:
    """Natural frequency of each mode over a sweep's variants: one panel per mode (one row of up to 6), each a box
    at its own scale [Hz], the nominal frequency dashed.

    Parameters
    ----------
    result : sixdof.analysis.batch.BatchResult
        The sweep's variants (``tracked_frequency_hz``, else ``frequency_hz``).
    modes : sixdof.model.modes.Modes
        The nominal system's modes (labels and the dashed line).
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        Drawn into (cleared first); default a new one.

    Returns
    -------
    matplotlib.figure.Figure
    """
    frequency = _tracked(result, "frequency_hz")
    n = frequency.shape[1]
    fig = _figure(fig, (max(6.0, 1.9 * n), 4.2))
    fig.suptitle(title(name, f"natural frequency of each mode over {len(frequency)} variants"), fontsize=12)
    margins(fig, left=0.7, right=0.2, top=0.75, bottom=0.55, wspace=0.6, columns=n)
    axes = fig.subplots(1, n, squeeze=False)[0]
    for j, (ax, label) in enumerate(zip(axes, mode_labels(modes))):
        ax.boxplot([_finite(frequency[:, j])], **_BOX)
        ax.axhline(modes.frequency_hz[j], **_NOMINAL)
        ax.set_xticks([1], [label])
        ax.set_title(f"nominal {modes.frequency_hz[j]:.4g} Hz", fontsize=9)
        ax.ticklabel_format(axis="y", useOffset=False)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].set_ylabel("natural frequency [Hz]")
    fig.text(0.5, 0.01, f"dashed: nominal design; {_LEGEND}", ha="center", va="bottom", fontsize=8, color="0.3")
    return fig


def plot_sweep_decoupling(result, modes, design=None, *, name: str = "", ax=None) -> Figure:
    """Decoupling of each mode over a sweep's variants: the kinetic-energy share of its dominant DOF [%], one box per
    mode on one axis, the nominal design's marked.

    Parameters
    ----------
    result : sixdof.analysis.batch.BatchResult
        The sweep's variants (``tracked_decoupling_percent``; ``None`` in files written before it was kept).
    modes : sixdof.model.modes.Modes
        The nominal system's modes.
    design : sixdof.analysis.design.DesignMetrics, optional
        The nominal design's metrics (its ``decoupling_percent`` marked); default: from ``modes``.
    name : str
    ax : matplotlib.axes.Axes, optional
        Drawn into; default a new figure of one axes.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        A ``result`` without the decoupling of its variants.
    """
    if result.tracked_decoupling_percent is None:
        raise ValueError("result.tracked_decoupling_percent: expected the decoupling of each variant's modes "
                         "(a sweep written since sixdof keeps it), got None")
    shares = np.asarray(result.tracked_decoupling_percent, dtype=float)
    nominal = (100.0 * np.max(modes.ke_distribution, axis=0) if design is None
               else np.asarray(design.decoupling_percent))
    if ax is None:
        fig = Figure(figsize=(8.5, 4.4))
        margins(fig, left=0.8, right=0.2, top=0.5, bottom=0.7)
        ax = fig.add_subplot()
    fig = ax.get_figure()
    n = shares.shape[1]
    ax.boxplot([_finite(shares[:, j]) for j in range(n)], **_BOX)
    ax.scatter(np.arange(1, n + 1), nominal[:n], marker="D", s=36, facecolors="none", edgecolors="0.1", linewidths=1.3,
               zorder=4, label="nominal design")
    ax.set_xticks(np.arange(1, n + 1), mode_labels(modes)[:n])
    ax.set_ylabel("kinetic energy in the dominant DOF [%]")
    ax.set_ylim(top=100.5)
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    ax.set_title(title(name, f"decoupling of each mode over {len(shares)} variants"), fontsize=11)
    return fig


def plot_sweep_peaks(result, *, name: str = "", ground_moves: bool = False, fig: Figure | None = None) -> Figure:
    """Peak response of each DOF over a sweep's variants: two rows of 6 panels, the peak displacement (top) and
    acceleration (bottom) of x, y, z, rx, ry, rz, each a box in its own display unit.

    Parameters
    ----------
    result : sixdof.analysis.batch.BatchResult
        The sweep's variants, with ``peak_q`` and ``peak_qdd``.
    name : str
    ground_moves : bool
        Whether the ground moves (the peaks are then of the body's absolute motion, said in the title; a stored
        sweep does not record it, and its redrawn figure says "response").
    fig : matplotlib.figure.Figure, optional

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        A ``result`` without peaks (a sweep without a simulation).
    """
    if result.peak_q is None or result.peak_qdd is None:
        raise ValueError("result.peak_q: expected the peaks of a sweep with a simulation, got None")
    fig = _figure(fig, (13.0, 6.4))
    what = "absolute " if ground_moves else ""
    fig.suptitle(title(name, f"peak {what}response of each DOF over {len(result.peak_q)} variants"), fontsize=12)
    margins(fig, left=0.8, right=0.2, top=0.75, bottom=0.55, wspace=0.75, hspace=0.75, columns=6, rows=2)
    axes = fig.subplots(2, 6, squeeze=False)
    for row, (peaks, order, quantity) in enumerate(((result.peak_q, 0, "peak displacement"),
                                                    (result.peak_qdd, 2, "peak acceleration"))):
        for j, (ax, dof, unit) in enumerate(zip(axes[row], DOFS, dof_units(order))):
            values = np.asarray(peaks[:, j], dtype=float)
            scale, shown = display_unit(values, unit)
            ax.boxplot([scale * _finite(values)], **_BOX)
            ax.set_xticks([1], [dof])
            ax.set_ylabel(f"[{shown}]")
            ax.ticklabel_format(axis="y", useOffset=False)
            ax.grid(True, axis="y", alpha=0.3)
        axes[row, 0].set_ylabel(f"{quantity}\n[{display_unit(peaks[:, 0], dof_units(order)[0])[1]}]")
    fig.text(0.5, 0.01, _LEGEND, ha="center", va="bottom", fontsize=8, color="0.3")
    return fig


def plot_sweep_sensitivity(fit, modes, *, name: str = "", fig: Figure | None = None) -> Figure:
    """Tornado chart of each elastic mode: the change of its natural frequency [Hz] as each swept parameter goes
    from its median to its 5th (grey) and 95th (blue) percentile, the others at their medians, the largest
    effects on top (at most :data:`TORNADO_BARS`). One panel per mode, 3 columns from 5 modes on
    (:func:`~sixdof.plots.common.panel_grid`); each panel's title gives the nominal frequency and the fit's R^2.

    Parameters
    ----------
    fit : sixdof.analysis.sweep_fit.SweepSensitivity
    modes : sixdof.model.modes.Modes
        The nominal system's modes (labels).
    name : str
    fig : matplotlib.figure.Figure, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    n = len(fit.modes)
    columns, rows = panel_grid(n)
    bars = min(TORNADO_BARS, len(fit.parameters))
    label_width = min(3.6, 0.058 * max(len(p) for p in fit.parameters) + 0.25)
    fig = _figure(fig, (columns * (label_width + 2.6) + 0.3, rows * (0.32 * bars + 1.7) + 1.0))
    fig.suptitle(title(name, f"what moves each natural frequency (linear fit over {fit.variants} variants)"),
                 fontsize=12)
    margins(fig, left=label_width, right=0.3, top=1.0, bottom=0.5, wspace=label_width + 0.3, hspace=1.2,
            columns=columns, rows=rows)
    axes = fig.subplots(rows, columns, squeeze=False).ravel()
    labels = mode_labels(modes)
    for k, ax in enumerate(axes):
        if k >= n:
            ax.set_visible(False)
            continue
        low, high = fit.effect_low_hz[k], fit.effect_high_hz[k]
        order = np.argsort(-np.abs(high - low), kind="stable")[:bars][::-1]  # the largest on top
        y = np.arange(len(order))
        ax.barh(y, low[order], color="0.6",
                label=f"parameter at its {SPAN[0]:g}th percentile, the others at their medians")
        ax.barh(y, high[order], color="tab:blue", label=f"parameter at its {SPAN[1]:g}th percentile")
        ax.axvline(0.0, color="0.2", linewidth=0.8)
        ax.set_yticks(y, [fit.parameters[i] for i in order], fontsize=8)
        ax.set_xlabel("change of natural frequency [Hz]")
        r2 = fit.r_squared[k]
        fitted = "R² n/a" if not np.isfinite(r2) else f"R² = {r2:.3f}"
        left_out = len(fit.parameters) - len(order)
        more = f"\n({left_out} smaller effect{'s' if left_out > 1 else ''} not shown)" if left_out else ""
        ax.set_title(f"{labels[fit.modes[k]]}: {fit.nominal_hz[k]:.4g} Hz, {fitted}{more}", fontsize=9)
        ax.grid(True, axis="x", alpha=0.3)
        span = np.max(np.abs(np.concatenate([low[order], high[order]]))) or 1.0
        ax.set_xlim(-1.15 * span, 1.15 * span)
    handles, texts = axes[0].get_legend_handles_labels()
    fig.legend(handles, texts, loc="upper center", bbox_to_anchor=(0.5, 1 - 0.42 / fig.get_size_inches()[1]),
               ncols=2, fontsize=8, frameon=False)
    return fig


def _fit(run):
    return sweep_sensitivity(run.sweep, run.system)


#: Each figure of a sweep (``sixdof sweep``, ``sixdof plot sweep.h5``): its file name, whether the sweep's
#: :class:`~sixdof.results.RunResults` (``sweep`` and the nominal ``system``) allows it, and how it is drawn.
SWEEP_FIGURES = (
    ("sweep_frequencies.png", lambda run: run.sweep.count > 0,
     lambda run: plot_sweep_frequencies(run.sweep, run.system.modes, name=run.name)),
    ("sweep_decoupling.png", lambda run: run.sweep.count > 0 and run.sweep.tracked_decoupling_percent is not None,
     lambda run: plot_sweep_decoupling(run.sweep, run.system.modes, name=run.name)),
    ("sweep_peaks.png", lambda run: run.sweep.count > 0 and run.sweep.peak_q is not None,
     lambda run: plot_sweep_peaks(run.sweep, name=run.name)),
    ("sweep_sensitivity.png", lambda run: run.sweep.count > 0 and _fit(run) is not None,
     lambda run: plot_sweep_sensitivity(_fit(run), run.system.modes, name=run.name)),
)


def sweep_figure_names(run) -> list[str]:
    """File names of the figures a sweep's :class:`~sixdof.results.RunResults` allows (:data:`SWEEP_FIGURES`)."""
    return [name for name, drawable, _ in SWEEP_FIGURES if drawable(run)]


def draw_sweep(run, file_name: str) -> Figure:
    """The figure ``file_name`` of :data:`SWEEP_FIGURES` drawn from a sweep's results."""
    return next(draw for name, _, draw in SWEEP_FIGURES if name == file_name)(run)


__all__ = ["SWEEP_FIGURES", "TORNADO_BARS", "WHISKERS", "draw_sweep", "mode_labels", "plot_sweep_decoupling",
           "plot_sweep_frequencies", "plot_sweep_peaks", "plot_sweep_sensitivity", "sweep_figure_names"]
