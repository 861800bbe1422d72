"""Time histories of the centre of gravity: its motion per DOF under the input that drives it, and the pieces the
other time figures share (which DOFs respond, the time columns). The mounts' forces over time are in
:mod:`sixdof.plots.mount_time`, the direct solution against the modal superposition in
:mod:`sixdof.plots.superposition`."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.dofs import AXES, FORCE_UNITS, display_unit, dof_units
from sixdof.errors import InputError
from sixdof.plots.common import (
    COMPONENT_COLORS,
    DOF_DIRECTIONS,
    DOF_NAMES,
    LOAD_NAMES,
    ROTATION,
    TRANSLATION,
    axis_label,
    figure,
    margins,
    plot_long,
    require,
    title,
)
from sixdof.plots.zoom import event_window, zoom_samples
from sixdof.results import Event, TimeHistory

_HISTORY = "a sixdof.results.TimeHistory"
#: SI unit of each DOF's column of each quantity of a TimeHistory.
_UNITS = {"q": dof_units(0), "qd": dof_units(1), "qdd": dof_units(2), "Q": FORCE_UNITS}
_QUANTITIES = {"q": "displacement", "qd": "velocity", "qdd": "acceleration", "Q": "applied force and moment"}
_GROUND = {"q": "ground_displacement", "qd": "ground_velocity", "qdd": "ground_acceleration"}

#: A DOF, or a component of the input, is drawn when its peak is above this fraction of the largest peak of its
#: kind: translations against translations [m, m/s or m/s^2], rotations against rotations [rad...], forces against
#: forces [N], moments against moments [N m]; with a moving ground the relative and the absolute motion each against
#: their own (a DOF is drawn when either is). Below it a trace is a flat line beside the largest of its kind (a
#: single-axis load's cross-coupling through a slightly asymmetric body): it is named with its peak, not drawn.
RESPONDS_RTOL = 1e-3
#: A DOF whose peak is below this fraction of the largest DOF's peak (in SI units, rotations in rad as they
#: are) is not excited at all: what it holds is round-off of the others, drawn as a line it would look like a signal.
UNEXCITED_RTOL = 1e-9
#: Height of each panel of :func:`plot_time_histories` [in]: the input's, and a DOF's, which shares
#: :data:`DOF_PANELS_HEIGHT` among the DOFs drawn within these bounds (one DOF gets a tall panel, six a row each).
INPUT_HEIGHT = 2.0
DOF_PANELS_HEIGHT = 7.5
DOF_HEIGHT_RANGE = (1.6, 3.0)
#: Colour of the ground's motion where it is drawn beside the body's.
GROUND_COLOR = "0.45"


def plot_time_histories(history: TimeHistory, key: str = "q", *, name: str = "",
                        events: Mapping[str, Event] | None = None, steady=None,
                        fig: Figure | None = None) -> Figure:
    """The input on its own axis above, then the time history of each DOF that responds on its own axis:
    translations in mm, rotations in mrad.

    (µm or µrad when the peak is below 0.01 mm or 0.01 mrad; velocities and accelerations
    likewise.) The input, from ``history`` itself: the applied force at the centre of gravity (``Q``, each
    component that responds), and the moment about it on its own axes unless it is the moment of those forces
    (loads at fixed points: then its peaks are quoted), and, with
    ground motion, the ground's acceleration along each axis it moves along, with the body's absolute
    acceleration at the centre of gravity on the same axes (what isolation is about). With ground motion,
    displacements and velocities relative to the ground are drawn solid (the mount strokes), accelerations
    absolute (what the body feels); the other dashed on the same scale, or, where it would flatten the first (a
    ground that moves away after a shock), only its peak quoted. Only the DOFs that respond are drawn
    (:data:`RESPONDS_RTOL`), each panel's height shared out by how many are; the others are named, with their
    peaks, in one line under the title (``fig.texts``, starting "not excited"). Given ``events``, the one worth
    a zoom (:func:`~sixdof.plots.zoom.event_window`: a shock first, else a switch-on) is drawn again in a zoom
    panel beside each row's whole record, its span shaded there.

    Parameters
    ----------
    history : sixdof.results.TimeHistory
        Times [s], the motion of the centre of gravity, the applied loads and the ground's motion.
    key : {"q", "qd", "qdd", "Q"}
        Displacement [m, rad] (default), velocity [m/s, rad/s], acceleration [m/s^2, rad/s^2] or
        the applied generalized force [N, N m] (then no input panel: the DOF panels are the input).
    name : str
        Name of the run, put before the title.
    events : mapping of str to sixdof.results.Event, optional
        The excitation's shocks and switch-ons, by load name (a run's ``events``).
    steady : sixdof.analysis.steady.SteadyState, optional
        The steady state at the operating frequencies (harmonic loads without end): its amplitude (the
        sum over the frequencies, the most their harmonics reach together) dotted at plus and minus, and
        given beside the peak, which a switch-on transient may dominate.
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one row per input (the load or ground motion) above one row per DOF that responds, each
        with its zoom on the right when the run has an event.

    Returns
    -------
    matplotlib.figure.Figure
        Its axes, top to bottom: the input panels (their titles start "applied", "ground"), then the DOFs drawn in
        the order x, y, z, rx, ry, rz; with a zoom each row's whole record is followed by its zoom.

    Raises
    ------
    sixdof.errors.InputError
        For another ``key``, or a history without that quantity.
    """
    require(history, "history", TimeHistory, _HISTORY)
    if key not in _UNITS:
        raise InputError("key", f"one of {', '.join(_UNITS)}", key)
    values = getattr(history, key)
    if values is None:
        raise InputError(f"history.{key}", "an (n, 6) array", values)
    t = history.t
    zoom = event_window(events or {}, t)
    # The motion relative to the ground only when the ground moves (not merely present as zeros).
    ground = getattr(history, _GROUND[key]) if key in _GROUND else None
    relative = getattr(history, f"{key}_relative") if ground is not None and np.any(ground != 0) else None
    # With the ground moving, displacements and velocities that matter (mount strokes) are relative to it,
    # accelerations (what the body feels) absolute: that one is drawn solid, the other dashed on the same
    # scale unless it would flatten the first (a ground that moves away after a shock), when its peak is
    # only quoted.
    main_is_relative = relative is not None and key in ("q", "qd")
    main, other = (relative, values) if main_is_relative else (values, relative)
    drawn = responding(main) | (responding(other) if other is not None else False)
    inputs = [] if key == "Q" else input_panels(history)
    dofs = [int(i) for i in np.flatnonzero(drawn)]
    height = float(np.clip(DOF_PANELS_HEIGHT / max(len(dofs), 1), *DOF_HEIGHT_RANGE))
    note = "" if len(dofs) == 6 else not_excited_line(main, [i for i in range(6) if not drawn[i]], _UNITS[key])
    heading = (f"{_QUANTITIES[key]} at the centre of gravity" if key == "Q"
               else f"{_QUANTITIES[key]} of the centre of gravity" + (", with the input above" if inputs else ""))
    order = {"q": 0, "qd": 1, "qdd": 2}.get(key)
    amplitude = np.zeros(6)  # of the absolute motion, per DOF
    if steady is not None and order is not None and not main_is_relative and len(steady.f_hz):
        amplitude = np.sum(np.abs(steady.q) * (2 * np.pi * np.asarray(steady.f_hz))[:, None] ** order, axis=0)
    # The figure's legend, from the first DOF drawn, when it has more than its one curve to explain.
    legend = bool(dofs) and (relative is not None or zoom is not None or amplitude[dofs[0]] > 0)
    fig, rows = _stacked_rows(t, [INPUT_HEIGHT] * len(inputs) + [height] * max(len(dofs), 1), zoom,
                              title(name, heading), note, legend_line=legend or zoom is not None, fig=fig,
                              first_title_lines=inputs[0][2] if inputs else 1)
    for (draw, *_), axes in zip(inputs, rows):
        draw(axes, t, zoom)
    if not dofs:  # nothing moves: said on the one panel
        for ax in rows[-1]:
            ax.set_yticks([])
            ax.text(0.5, 0.5, "no DOF moves", transform=ax.transAxes, ha="center", va="center", color="0.4")
        return fig
    for k, (i, axes) in enumerate(zip(dofs, rows[len(inputs):])):
        paired = other
        if paired is not None and np.array_equal(paired[:, i], main[:, i]):
            paired = None  # a rotation: the ground does not rotate, relative and absolute are one
        names = (("relative to the ground", "absolute") if main_is_relative
                 else ("absolute", "relative to the ground") if paired is not None else ("response", ""))
        _history_dof(fig, axes, i, t, main[:, i], None if paired is None else paired[:, i], unit=_UNITS[key][i],
                     names=names, zoom=zoom, steady=steady, steady_amplitude=float(amplitude[i]),
                     legend=legend and k == 0)
    return fig


def _stacked_rows(t: np.ndarray, heights: list[float], zoom, heading: str, note: str, legend_line: bool,
                  fig: Figure | None = None, first_title_lines: int = 1) -> tuple[Figure, list[list]]:
    """A figure of one row per entry of ``heights`` [in] under ``heading``, the line ``note`` (if any) and a line
    for the legend and the zoom's heading (``legend_line``), and its axes, one list per row: its whole record, then
    its zoom when ``zoom`` (:func:`~sixdof.plots.zoom.event_window`) is given; one time axis per column, labelled
    under the last row. The first row's title has ``first_title_lines`` lines (the others' fit between rows)."""
    gap, bottom = 0.55, 0.55  # between rows (each has a title), under the last (its time labels)
    # From the top [in]: the title, the note, the line of the legend and the zoom's heading, the first row's title.
    legend_at = _legend_at(bool(note))
    top = legend_at + (0.25 if legend_line else -0.1) + 0.35 + 0.17 * (first_title_lines - 1)
    fig = figure(fig, (12, top + bottom + sum(heights) + gap * (len(heights) - 1)))
    height = fig.get_figheight()
    fig.suptitle(heading, fontsize=13, y=1 - 0.15 / height, va="top")
    if note:
        fig.text(0.9 / 12, 1 - 0.55 / height, note, fontsize=9.5, color="0.3", va="top", ha="left")
    columns = 1 if zoom is None else 2
    spec = fig.add_gridspec(len(heights), columns, height_ratios=heights,
                            width_ratios=None if zoom is None else (3, 2))
    # The right margin holds half the last time label ("0.10" ends past the axes).
    margins(fig, left=0.9, right=0.3, top=top, bottom=bottom, wspace=0.9, hspace=gap, columns=columns,
            rows=len(heights), target=spec)
    rows = [[fig.add_subplot(spec[r, c]) for c in range(columns)] for r in range(len(heights))]
    _time_column([row[0] for row in rows], (t[0], t[-1]))
    if zoom is not None:  # on the legend's line, over the zoom column: the first row's title may be long
        _time_column([row[1] for row in rows], zoom[:2])
        fig.text(1 - 0.3 / 12, 1 - legend_at / height, f"zoom: {zoom[2]}", fontsize=9, va="top", ha="right")
    return fig, rows


def notes(fig: Figure) -> list[str]:
    """The "not excited" line of a figure of :func:`plot_time_histories` or :func:`plot_superposition` (empty when
    every DOF is drawn)."""
    return [text.get_text() for text in fig.texts if text.get_text().startswith("not excited")]


def responding(values: np.ndarray) -> np.ndarray:
    """Which columns of ``values`` (n, 6) respond (bool (6,)): their peak is above :data:`RESPONDS_RTOL` of the
    largest of their kind (columns 0-2 and 3-5: translations and rotations, or forces and moments) and more
    than round-off of the largest of all (:func:`unexcited`)."""
    values = np.asarray(values)
    peaks = np.max(np.abs(values), axis=0) if len(values) else np.zeros(values.shape[1])
    drawn = ~unexcited(values) & (peaks > 0)
    for kind in (slice(0, 3), slice(3, 6)):
        drawn[kind] &= peaks[kind] > RESPONDS_RTOL * peaks[kind].max(initial=0.0)
    return drawn


def unexcited(values: np.ndarray) -> np.ndarray:
    """Which columns of ``values`` (n, m) are :data:`UNEXCITED_RTOL` of the largest or less (bool (m,))."""
    values = np.asarray(values)
    peaks = np.max(np.abs(values), axis=0) if len(values) else np.zeros(values.shape[1])
    largest = float(peaks.max(initial=0.0))
    return peaks <= UNEXCITED_RTOL * largest if largest > 0 else np.zeros(values.shape[1], bool)


def not_excited_line(values: np.ndarray, quiet: list[int], units, difference: np.ndarray | None = None) -> str:
    """The one line naming the DOFs ``quiet`` that a figure leaves out: those exactly zero together, those at
    round-off (:func:`unexcited`) together, the others each with its peak in ``values`` (n, 6) [SI ``units`` per
    DOF]; given ``difference`` (6,), the relative difference of a cross-check (for those at round-off, the
    largest)."""
    if not quiet:
        return ""
    peaks = np.max(np.abs(values), axis=0) if len(values) else np.zeros(6)
    roundoff = unexcited(values)
    zero = [i for i in quiet if peaks[i] == 0 and (difference is None or difference[i] == 0)]
    tiny = [i for i in quiet if roundoff[i] and i not in zero]
    parts = [f"{', '.join(DOF_DIRECTIONS[i] for i in zero)} (exactly zero)"] if zero else []
    if tiny:
        most = "" if difference is None else f", relative difference at most {max(difference[i] for i in tiny):.1e}"
        parts.append(f"{', '.join(DOF_DIRECTIONS[i] for i in tiny)} (round-off only{most})")
    for i in quiet:
        if i not in zero and i not in tiny:
            factor, unit = display_unit(peaks[i], units[i])
            what = f"peak {factor * peaks[i]:.3g} {unit}"
            if difference is not None:
                what += f", relative difference {difference[i]:.1e}"
            parts.append(f"{DOF_DIRECTIONS[i]} ({what})")
    return (f"not excited (peak at most {RESPONDS_RTOL:g} of the largest of its kind, not drawn): "
            + "; ".join(parts))


def input_panels(history: TimeHistory) -> list[tuple]:
    """The input panels of :func:`plot_time_histories` a history calls for, each ``(draw, what, lines)``:
    ``draw(axes, t, zoom)`` draws it on a row's axes; ``what`` is "ground y" or "applied force"; ``lines``, those
    of its title (2: an applied force's, with the moments about the centre of gravity it implies quoted). The
    ground's acceleration along each axis it moves along (with the body's beside it), then the applied force at
    the centre of gravity, or the moment when no force is applied."""
    panels = []
    ground = history.ground_acceleration
    if ground is not None and np.any(ground != 0):
        moving = responding(np.hstack([ground, np.zeros_like(ground)]))[:3]
        for c in np.flatnonzero(moving):
            panels.append((lambda axes, t, zoom, c=int(c): _ground_panel(axes, t, zoom, history, c),
                           f"ground {AXES[c]}", 1))
    Q = history.Q
    if Q is not None and np.any(Q != 0):
        applied = responding(Q)
        forces, moments = np.flatnonzero(applied[:3]), 3 + np.flatnonzero(applied[3:])
        implied = len(forces) and len(moments) and _implied(Q[:, forces], Q[:, moments])
        if len(forces):
            panels.append((lambda axes, t, zoom: _load_panel(axes, t, zoom, Q, forces, moments if implied else ()),
                           "applied force", 2 if implied else 1))
        if len(moments) and not implied:
            panels.append((lambda axes, t, zoom: _load_panel(axes, t, zoom, Q, moments, ()), "applied moment", 1))
    return panels


def _implied(forces: np.ndarray, moments: np.ndarray) -> bool:
    """Whether the ``moments`` (n, m) [N m] are a fixed combination of the ``forces`` (n, k) [N] (forces applied at
    fixed points, their moments about the centre of gravity): their peaks are then quoted, not drawn again. A moment
    of its own (an engine's torque) is drawn on its own axes."""
    coefficients, *_ = np.linalg.lstsq(forces, moments, rcond=None)
    return bool(np.linalg.norm(moments - forces @ coefficients) <= 1e-6 * np.linalg.norm(moments))


def _ground_panel(axes, t: np.ndarray, zoom, history: TimeHistory, c: int) -> None:
    """The ground's acceleration along axis ``c`` and the body's absolute acceleration at the centre of gravity
    along it, on one scale, their peaks in m/s² and g in the title."""
    ground, body = history.ground_acceleration[:, c], history.qdd[:, c]
    factor, unit = display_unit(np.concatenate([ground, body]), "m/s^2")
    for ax, part in zip(axes, (slice(None), zoom_samples(t, zoom or (0, 0)))):
        plot_long(ax, t[part], factor * ground[part], color=GROUND_COLOR, linewidth=1.0, label="ground")
        plot_long(ax, t[part], factor * body[part], color=TRANSLATION, linewidth=1.0,
                  label="body (centre of gravity, absolute)")
    peak_ground, peak_body = float(np.max(np.abs(ground))), float(np.max(np.abs(body)))
    axes[0].set_ylabel(axis_label("acceleration", unit))
    axes[0].set_title(f"ground and body acceleration along {AXES[c]}, peaks: ground {factor * peak_ground:.4g} {unit} "
                      f"({peak_ground / STANDARD_GRAVITY:.3g} g), body {factor * peak_body:.4g} {unit} "
                      f"({peak_body / STANDARD_GRAVITY:.3g} g, {peak_body / peak_ground:.2f} of the ground's)",
                      fontsize=10, loc="left")
    axes[0].legend(fontsize=8, loc="upper right", framealpha=0.85)
    _shade_zoom(axes, zoom)


def _load_panel(axes, t: np.ndarray, zoom, Q: np.ndarray, shown, quoted) -> None:
    """The components ``shown`` of the applied generalized force ``Q`` (n, 6) [N, N m], one colour each; the peaks of
    those ``quoted`` (moments beside forces) in the title."""
    unit_si = FORCE_UNITS[int(shown[0])]
    factor, unit = display_unit(Q[:, list(shown)], unit_si)
    for ax, part in zip(axes, (slice(None), zoom_samples(t, zoom or (0, 0)))):
        for j in shown:
            plot_long(ax, t[part], factor * Q[part, j], color=COMPONENT_COLORS[j % 3], linewidth=1.0,
                      label=LOAD_NAMES[j])
    what = "force" if unit_si == "N" else "moment"
    peaks = ", ".join(f"{DOF_DIRECTIONS[j]} {factor * np.max(np.abs(Q[:, j])):.4g}" for j in shown)
    heading = f"applied {what} at the centre of gravity: peak {peaks} {unit}"
    if len(quoted):
        scale, moment_unit = display_unit(Q[:, list(quoted)], "N m")
        moments = ", ".join(f"{DOF_DIRECTIONS[j]} {scale * np.max(np.abs(Q[:, j])):.4g}" for j in quoted)
        heading += f"\nmoments about it (not drawn): peak {moments} {moment_unit}"  # a line of its own: long
    axes[0].set_ylabel(f"{what} [{unit}]")
    axes[0].set_title(heading, fontsize=10, loc="left")
    if len(shown) > 1:
        axes[0].legend(fontsize=8, loc="upper right", framealpha=0.85, ncols=len(shown))
    _shade_zoom(axes, zoom)


def _legend_at(note: bool) -> float:
    """Where [in from the top] :func:`_stacked_rows` keeps the line of the legend and the zoom's heading: under
    the title, and the note when there is one."""
    return 0.55 + (0.3 if note else 0.0)


def legend_line(fig: Figure, handles, labels, ncols: int) -> None:
    """The legend of a figure of :func:`_stacked_rows`, on the line kept for it above the panels (inside one it
    would sit on a curve)."""
    fig.legend(handles, labels, fontsize=8, loc="upper left", frameon=False, ncols=ncols,
               bbox_to_anchor=(0.8 / fig.get_figwidth(), 1 - _legend_at(bool(notes(fig))) / fig.get_figheight()))


def _shade_zoom(axes, zoom) -> None:
    """The zoomed span shaded on a row's whole record."""
    if zoom is not None:
        axes[0].axvspan(*zoom[:2], color="0.85", zorder=0, label="zoomed span")


def _history_dof(fig: Figure, axes, i: int, t: np.ndarray, main: np.ndarray, other: np.ndarray | None, *, unit: str,
                 names: tuple[str, str], zoom, steady, steady_amplitude: float, legend: bool) -> None:
    """DOF ``i``'s panels of :func:`plot_time_histories` (its whole record, then its zoom): ``main`` solid,
    ``other`` dashed unless it would flatten it (SI ``unit``); the steady-state amplitude dotted and the figure's
    legend (``legend``: the first DOF drawn) taken from it."""
    whole, *rest = axes
    main_peak = float(np.max(np.abs(main)))
    other_peak = 0.0 if other is None else float(np.max(np.abs(other)))
    drawn_other = other is not None and other_peak <= OTHER_SCALE * main_peak
    shown = main if not drawn_other else np.concatenate([main, other])
    factor, label = display_unit(shown, unit)
    for ax, part in zip((whole, *rest), (slice(None), *(zoom_samples(t, zoom) for _ in rest))):
        plot_long(ax, t[part], factor * main[part], color=TRANSLATION if i < 3 else ROTATION,
                  linewidth=1.0, label=None if names[0] == "response" else names[0])  # alone: no legend entry
        if drawn_other:
            plot_long(ax, t[part], factor * other[part], color="black", linestyle="--", linewidth=0.9,
                      label=names[1])
    if steady_amplitude > 0:
        # The loss factors act in the frequency domain only: the time response tends to another steady state.
        what = ("steady-state amplitude (FRF, with loss factors the time response lacks)" if steady.loss_factors
                else "steady-state amplitude")
        for ax in (whole, *rest):
            for sign in (1, -1):
                ax.axhline(sign * factor * steady_amplitude, color="0.3", linestyle=":", linewidth=1.0,
                           label=what if sign > 0 else None)
    _shade_zoom(axes, zoom)
    if legend:
        legend_line(fig, *whole.get_legend_handles_labels(), ncols=4)
    whole.set_ylabel(axis_label(DOF_DIRECTIONS[i], label))
    heading = f"{DOF_NAMES[i]}: peak {factor * main_peak:.4g} {label}"
    if other is not None:
        scale, other_unit = display_unit(other_peak, unit)
        heading = (f"{DOF_NAMES[i]}: peak {names[0]} {factor * main_peak:.4g} {label}, {names[1]} "
                   f"{scale * other_peak:.4g} {other_unit}" + ("" if drawn_other else " (not drawn)"))
    if steady_amplitude > 0:  # the peak may be the switch-on's: the steady state's amplitude beside it
        scale, steady_unit = display_unit(steady_amplitude, unit)  # its own unit: 0.1587 um, not 0.0001587 mm
        heading += f", steady-state amplitude {scale * steady_amplitude:.4g} {steady_unit}"
    whole.set_title(heading, fontsize=10, loc="left")


#: The second curve of a ground-driven run (absolute or relative motion) is drawn on the first's scale only
#: while its peak is at most this many times the first's.
OTHER_SCALE = 10.0

def _time_column(column, span, heading: str | None = None) -> None:
    """A column of time panels: one shared time axis over ``span`` [s] with at most 6 ticks (a short zoom's
    would crowd), labelled under the last panel only, grids, and ``heading`` over the first."""
    for ax in column[1:]:
        ax.sharex(column[0])
    for ax in column:
        ax.set_xlim(*span)
        ax.xaxis.set_major_locator(MaxNLocator(6, steps=[1, 2, 5, 10]))  # 0.1 s steps rather than 0.08
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelbottom=ax is column[-1])
    column[-1].set_xlabel("time t [s]")
    if heading:
        column[0].set_title(heading, fontsize=9, loc="left")


def _superscript(exponent: int) -> str:
    """``-9`` as ``⁻⁹``: a power of ten in a label without mathtext."""
    return str(exponent).translate(str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹"))
