"""Time histories: the centre of gravity's motion per DOF under the input that drives it, the mount forces
on the foundation, each mount's total normal force, and the direct solution against the modal superposition."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from sixdof.analysis.compare import QUANTITIES, Agreement, relative_to_ground
from sixdof.analysis.contact import ContactSummary
from sixdof.analysis.mountcheck import MountCheck
from sixdof.analysis.response import MountForces
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.dofs import AXES, DOFS, FORCE_UNITS, LOADS, display_unit, dof_units
from sixdof.errors import InputError
from sixdof.plots.common import (
    COMPONENT_COLORS,
    DOF_DIRECTIONS,
    DOF_NAMES,
    ROTATION,
    TRANSLATION,
    axis_label,
    figure,
    margins,
    plot_long,
    require,
    time_axes,
    title,
)
from sixdof.plots.zoom import event_window, zoom_samples, zoom_window
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
                              title(name, heading), note, legend_line=legend or zoom is not None, fig=fig)
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


def _stacked_rows(t: np.ndarray, heights: list[float], zoom, heading: str, note: str,
                  legend_line: bool, fig: Figure | None = None) -> tuple[Figure, list[list]]:
    """A figure of one row per entry of ``heights`` [in] under ``heading``, the line ``note`` (if any) and a line
    for the legend and the zoom's heading (``legend_line``), and its axes, one list per row: its whole record, then
    its zoom when ``zoom`` (:func:`~sixdof.plots.zoom.event_window`) is given; one time axis per column, labelled
    under the last row."""
    gap, bottom = 0.55, 0.55  # between rows (each has a title), under the last (its time labels)
    # From the top [in]: the title, the note, the line of the legend and the zoom's heading, the first row's title.
    legend_at = 0.55 + (0.3 if note else 0.0)
    top = legend_at + (0.25 if legend_line else -0.1) + 0.35
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
    parts = [f"{', '.join(DOFS[i] for i in zero)} (exactly zero)"] if zero else []
    if tiny:
        most = "" if difference is None else f", relative difference at most {max(difference[i] for i in tiny):.1e}"
        parts.append(f"{', '.join(DOFS[i] for i in tiny)} (round-off only{most})")
    for i in quiet:
        if i not in zero and i not in tiny:
            factor, unit = display_unit(peaks[i], units[i])
            what = f"peak {factor * peaks[i]:.3g} {unit}"
            if difference is not None:
                what += f", relative difference {difference[i]:.1e}"
            parts.append(f"{DOFS[i]} ({what})")
    return (f"not excited (peak at most {RESPONDS_RTOL:g} of the largest of its kind, not drawn): "
            + "; ".join(parts))


def input_panels(history: TimeHistory) -> list[tuple]:
    """The input panels of :func:`plot_time_histories` a history calls for, each ``(draw, what)``: ``draw(axes, t,
    zoom)`` draws it on a row's axes; ``what`` is "ground y" or "applied force". The ground's acceleration along
    each axis it moves along (with the body's beside it), then the applied force at the centre of gravity, or
    the moment when no force is applied."""
    panels = []
    ground = history.ground_acceleration
    if ground is not None and np.any(ground != 0):
        moving = responding(np.hstack([ground, np.zeros_like(ground)]))[:3]
        for c in np.flatnonzero(moving):
            panels.append((lambda axes, t, zoom, c=int(c): _ground_panel(axes, t, zoom, history, c),
                           f"ground {AXES[c]}"))
    Q = history.Q
    if Q is not None and np.any(Q != 0):
        applied = responding(Q)
        forces, moments = np.flatnonzero(applied[:3]), 3 + np.flatnonzero(applied[3:])
        implied = len(forces) and len(moments) and _implied(Q[:, forces], Q[:, moments])
        if len(forces):
            panels.append((lambda axes, t, zoom: _load_panel(axes, t, zoom, Q, forces, moments if implied else ()),
                           "applied force"))
        if len(moments) and not implied:
            panels.append((lambda axes, t, zoom: _load_panel(axes, t, zoom, Q, moments, ()), "applied moment"))
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
            plot_long(ax, t[part], factor * Q[part, j], color=COMPONENT_COLORS[j % 3], linewidth=1.0, label=LOADS[j])
    what = "force" if unit_si == "N" else "moment"
    peaks = ", ".join(f"{LOADS[j]} {factor * np.max(np.abs(Q[:, j])):.4g}" for j in shown)
    heading = f"applied {what} at the centre of gravity: peak {peaks} {unit}"
    if len(quoted):
        scale, moment_unit = display_unit(Q[:, list(quoted)], "N m")
        moments = ", ".join(f"{LOADS[j]} {scale * np.max(np.abs(Q[:, j])):.4g}" for j in quoted)
        heading += f"; moments about it (not drawn): peak {moments} {moment_unit}"
    axes[0].set_ylabel(f"{what} [{unit}]")
    axes[0].set_title(heading, fontsize=10, loc="left")
    if len(shown) > 1:
        axes[0].legend(fontsize=8, loc="upper right", framealpha=0.85, ncols=len(shown))
    _shade_zoom(axes, zoom)


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
        # Above the panels, under the title (and the note): inside one it would sit on a curve.
        fig.legend(*whole.get_legend_handles_labels(), fontsize=8, loc="upper left", frameon=False,
                   bbox_to_anchor=(0.8 / fig.get_figwidth(), 1 - (0.55 + 0.3 * bool(notes(fig))) / fig.get_figheight()),
                   ncols=4)
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


#: Legend of the tension shading: a mount that pulls on the body (a linear one holds; one with tension = false lifts
#: off instead, spring, dashpot and branches together, so it is never shaded).
TENSION_LABEL = "tension (the mount pulls; one with tension = false lifts off instead)"
#: The second curve of a ground-driven run (absolute or relative motion) is drawn on the first's scale only
#: while its peak is at most this many times the first's.
OTHER_SCALE = 10.0


def plot_superposition(direct: TimeHistory, modal: TimeHistory, agreement: Agreement | None = None, *,
                       name: str = "", events: Mapping[str, Event] | None = None,
                       contacts: ContactSummary | None = None, fig: Figure | None = None) -> Figure:
    """Direct solution and modal superposition overlaid (left), and their difference divided by the
    DOF's peak (right, with the agreement tolerance dashed), one row per DOF that responds
    (:data:`RESPONDS_RTOL`); the others are named in one line under the title (``fig.texts``, starting "not
    excited"), each with its peak and the agreement's relative difference.

    With nonlinear mounts the (linear) superposition holds only until the first of them engages: the
    overlays mark that time, and the differences, their peaks and the titles cover the record up to it
    (what the run's agreement compares).

    Parameters
    ----------
    direct : sixdof.results.TimeHistory
        The direct solve; its absolute displacement ``q`` [m, rad] is compared.
    modal : sixdof.results.TimeHistory
        The modal superposition at the same times.
    agreement : sixdof.analysis.compare.Agreement, optional
        ``compare(direct, modal)``: its worst difference goes in the title, its per-DOF values in
        the panels' titles, its tolerance [1] dashed, and its quiet DOFs are divided by the largest
        peak (rotations times its ``length`` [m]).
    name : str
        Name of the run, put before the title.
    events : mapping of str to sixdof.results.Event, optional
        The excitation's shocks and switch-ons: the overlay of the one worth a zoom
        (:func:`~sixdof.plots.zoom.event_window`) is drawn again in a middle column.
    contacts : sixdof.analysis.contact.ContactSummary, optional
        What the nonlinear mounts did: the differences are drawn until its ``first_engaged_t`` [s] (nan:
        none engaged, the whole record).

    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one row per DOF that responds: both solutions overlaid (left, with its zoom when the run
        has an event) and their difference (right).

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(direct, "direct", TimeHistory, _HISTORY)
    require(modal, "modal", TimeHistory, _HISTORY)
    require(agreement, "agreement", (Agreement, type(None)), "a sixdof.analysis.compare.Agreement (or None)")
    require(contacts, "contacts", (ContactSummary, type(None)), "a sixdof.analysis.contact.ContactSummary (or None)")
    if modal.q.shape != direct.q.shape:
        raise InputError("modal.q", f"shape {direct.q.shape} (that of direct.q)", f"shape {modal.q.shape}")
    t = direct.t
    q_direct, q_modal = relative_to_ground(direct, modal)  # what the agreement compares
    # After a nonlinear mount engages the two differ by design: the differences end there, as the agreement does.
    first = np.nan if contacts is None else float(contacts.first_engaged_t)
    cut = bool(first < t[-1])  # False for nan
    compared = slice(0, max(int(np.searchsorted(t, first, side="right")), 1)) if cut else slice(None)
    end = max(first, t[min(1, len(t) - 1)]) if cut else t[-1]
    peaks = np.max(np.abs(q_direct[compared]), axis=0)
    zoom = event_window(events or {}, t)
    heading = "direct solution vs modal superposition" + (", relative to the ground" if direct.has_ground else "")
    if agreement is not None:
        verdict = "within" if agreement.ok else "EXCEEDS"
        where = agreement.worst_dof + (f" {QUANTITIES[agreement.worst_quantity]}" if agreement.rates else "")
        heading += (f"\nworst relative difference {agreement.worst:.2e} in {where}"
                    f"{' before the first engagement' if cut else ''} ({verdict} tolerance {agreement.tolerance:.0e})")
    # The DOFs that move get a row; the others are named in one line with their differences (the agreement's).
    drawn = responding(q_direct)
    dofs = [int(i) for i in np.flatnonzero(drawn)] or [int(np.argmax(peaks))]
    note = not_excited_line(q_direct, [i for i in range(6) if i not in dofs], _UNITS["q"],
                            None if agreement is None else np.asarray(agreement.per_dof))
    fig, axes, zooms = _superposition_panels(t, zoom, end, len(dofs), lines=3 if cut else 2, note=note,
                                             fig=fig)
    quiet_compared = unexcited(q_direct[compared])  # a DOF still at rest when the first mount engages
    span = f" for t ≤ {first:.4g} s" if cut else ""
    tolerance_drawn = False
    for row, i in enumerate(dofs):
        left, right = axes[row]
        _overlay_dof(left, zooms[row], i, t, q_direct[:, i], q_modal[:, i], zoom=zoom, first=first if cut else None)
        tolerance_drawn |= _difference_dof(right, i, t, q_direct, q_modal, compared, peaks, agreement,
                                           quiet_compared=bool(quiet_compared[i]), span=span)
    if tolerance_drawn:
        heading += "; dashed red: ± tolerance"
    if cut:
        heading += (f"\ndash-dot red: a nonlinear mount first engages at t = {first:.4g} s; the superposition is not "
                    "valid after it (differences drawn until then)")
    fig.suptitle(title(name, heading), fontsize=13, y=1 - 0.15 / fig.get_figheight(), va="top")
    # Above the first panel; compact, clear of the zoom's heading.
    axes[0, 0].legend(*axes[0, 0].get_legend_handles_labels(), fontsize=9, loc="lower left",
                      bbox_to_anchor=(0.0, 1.0), ncols=3, frameon=False, handlelength=1.5, columnspacing=1.0)
    time_axes(axes, t)
    axes[0, 1].set_xlim(t[0], end)  # the differences' column: the span compared (its axes share it)
    return fig


#: Height of a row of :func:`plot_superposition` [in]: :data:`SUPERPOSITION_HEIGHT` shared among the DOFs drawn,
#: within these bounds.
SUPERPOSITION_HEIGHT = 9.0
SUPERPOSITION_ROW_RANGE = (1.6, 3.0)


def _superposition_panels(t: np.ndarray, zoom, end: float, rows: int, lines: int,
                          note: str, fig: Figure | None = None) -> tuple[Figure, np.ndarray, list]:
    """The figure of :func:`plot_superposition` and its axes: ``(fig, axes, zooms)``, the overlays and differences
    (rows, 2) (the differences' time axis to ``end`` [s]) and each row's zoom of the overlay (None without
    ``zoom``); room at the top for a title of ``lines`` lines and the line ``note`` (if any)."""
    row = float(np.clip(SUPERPOSITION_HEIGHT / rows, *SUPERPOSITION_ROW_RANGE))
    gap, bottom = 0.45, 0.55
    note_at = 0.25 + 0.26 * lines
    top = note_at + (0.3 if note else 0.0) + 0.35  # the title, the note, the legend above the first row
    fig = figure(fig, (13 if zoom is None else 15, top + bottom + rows * row + gap * (rows - 1)))
    if note:
        fig.text(0.8 / fig.get_figwidth(), 1 - note_at / fig.get_figheight(), note, fontsize=9.5, color="0.3",
                 va="top", ha="left")
    if zoom is None:
        margins(fig, left=0.8, right=0.3, top=top, bottom=bottom, wspace=1.1, hspace=gap, columns=2, rows=rows)
        axes = np.asarray(fig.subplots(rows, 2, sharex="col", squeeze=False))
        zooms = [None] * rows
    else:  # the overlay's zoom between the overlay and the difference
        spec = fig.add_gridspec(rows, 3, width_ratios=(3, 2, 3))
        margins(fig, left=0.8, right=0.3, top=top, bottom=bottom, wspace=1.0, hspace=gap, columns=3, rows=rows,
                target=spec)
        grid = np.array([[fig.add_subplot(spec[i, c]) for c in range(3)] for i in range(rows)])
        _time_column(grid[:, 0], (t[0], t[-1]))
        _time_column(grid[:, 2], (t[0], end))
        axes, zooms = grid[:, [0, 2]], list(grid[:, 1])
        _time_column(zooms, zoom[:2], f"zoom: {zoom[2]}")
    return fig, axes, zooms


def _overlay_dof(left, zoomed, i: int, t: np.ndarray, q_direct: np.ndarray, q_modal: np.ndarray, *, zoom,
                 first: float | None) -> None:
    """DOF ``i``'s overlay of the direct solution ``q_direct`` and the superposition ``q_modal`` [m or rad] on
    ``left`` and its zoom ``zoomed`` (or None); ``first``: the time [s] of the first engagement, marked (None: no
    mount engaged before the end)."""
    factor, label = display_unit(q_direct, _UNITS["q"][i])
    for ax, part in ((left, slice(None)), (zoomed, None if zoom is None else zoom_samples(t, zoom))):
        if ax is None:
            continue
        plot_long(ax, t[part], factor * q_direct[part], color="black", linewidth=1.6,
                  label="direct integration")
        plot_long(ax, t[part], factor * q_modal[part], color="tab:orange", linewidth=1.0, linestyle="--",
                  label="modal superposition")
    left.set_ylabel(axis_label(DOF_DIRECTIONS[i], label))
    if zoom is not None:
        left.axvspan(*zoom[:2], color="0.85", zorder=0)
    if first is not None:
        for ax in (left, zoomed):
            if ax is not None:
                ax.axvline(first, color="tab:red", linestyle="-.", linewidth=1.0,
                           label="first engagement")  # its time: in the name and the titles


def _difference_dof(right, i: int, t: np.ndarray, q_direct: np.ndarray, q_modal: np.ndarray, compared: slice,
                    peaks: np.ndarray, agreement: Agreement | None, *, quiet_compared: bool, span: str) -> bool:
    """DOF ``i``'s difference of the superposition from the direct solution (both (n, 6) [m, rad]) over the
    samples ``compared``, divided as the agreement divides it, on ``right``; ``span``: the titles' note of the
    span compared. Returns whether the tolerance lines were drawn."""
    # Divided as the agreement divides it: by the DOF's own peak, or for a quiet DOF (round-off
    # only) by the largest peak of all DOFs, rotations times the agreement's length, or by the floor a
    # moving ground sets (see compare).
    denominator, against = float(peaks[i]), "peak"
    if agreement is not None and DOFS[i] in tuple(agreement.quiet):
        length = float(agreement.length)
        largest = float(np.max(peaks * np.array([1.0, 1.0, 1.0, length, length, length])))
        denominator = float(agreement.denominator[i])
        against = "largest peak" if largest >= agreement.floor else "1e-6 of the absolute motion"
    difference = q_modal[compared, i] - q_direct[compared, i]
    relative = difference / denominator if denominator > 0 else difference
    if quiet_compared or not np.any(relative):  # round-off against round-off: its size said, not drawn
        size = float(np.max(np.abs(relative))) if relative.size else 0.0
        text = ("identical: both exactly zero" if size == 0 else
                f"round-off only: max|Δ| / {against} = {size:.1e}")
        right.text(0.5, 0.5, text, transform=right.transAxes, ha="center", va="center", fontsize=10,
                   color="0.4")
        right.set_yticks([])
        # A DOF at rest until the first engagement may move after it: "not excited" only for the span compared.
        right.set_title(f"{DOF_NAMES[i]}: not excited{span}", fontsize=9)
        return False
    # The power of ten in the axis label, not in an offset text above the axes (where the title is).
    largest = float(np.max(np.abs(relative))) if relative.size else 0.0
    exponent = int(np.floor(np.log10(largest))) if largest > 0 else 0
    unit = 10.0 ** exponent
    plot_long(right, t[compared], relative / unit, color="tab:purple", linewidth=0.9)
    right.set_ylabel(axis_label(f"difference / {against}", f"×10{_superscript(exponent)}" if exponent else "1"))
    # Tolerance lines only where they do not flatten the curve into a line.
    tolerance_drawn = agreement is not None and largest > 0.1 * agreement.tolerance
    if tolerance_drawn:
        for sign in (-1, 1):
            right.axhline(sign * agreement.tolerance / unit, color="tab:red", linestyle="--", linewidth=0.8)
    if agreement is not None:
        # Drawn, so more than round-off: quiet only against the largest peak (see compare).
        note = " (quiet DOF)" if against != "peak" else ""
        right.set_title(f"{DOF_NAMES[i]}: max|Δ| / {against}{span} = {agreement.per_dof[i]:.2e}{note}", fontsize=9)
    return tolerance_drawn


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


def plot_mount_forces(forces: MountForces, t, *, name: str = "", fig: Figure | None = None) -> Figure:
    """Force of each mount on the foundation, one axis per component (x, y, z in body axes), one
    line per mount, in kN; the total foundation force dashed.

    Components get their own axes because their sizes differ by decades (vertical bearing loads vs
    horizontal ones).

    Parameters
    ----------
    forces : sixdof.analysis.response.MountForces
        ``total`` (n_mounts, n, 3) [N] of the mounts ``names``; ``foundation_force`` (n, 3) [N]
        drawn when not ``None``.
    t : array_like, shape (n,)
        Times [s] of the forces (the response's ``t``).
    name : str
        Name of the run, put before the title.

    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: three rows, the x, y and z components of the mount forces.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(forces, "forces", MountForces, "a sixdof.analysis.response.MountForces")
    t = np.asarray(t, dtype=float)
    values = np.asarray(forces.total)
    if values.ndim != 3 or values.shape[1:] != (len(t), 3) or values.shape[0] != len(forces.names):
        raise InputError("forces.total", f"shape ({len(forces.names)}, {len(t)}, 3) (mounts, len(t), axes)",
                         f"shape {values.shape}")
    names = forces.names
    total = forces.foundation_force
    fig = figure(fig, (12, 8.5))
    fig.suptitle(title(name, "mount forces on the foundation (body axes)"), fontsize=13)
    margins(fig, left=0.8, right=0.15, top=0.75, bottom=0.55, hspace=0.2, rows=3)
    axes = fig.subplots(3, 1, sharex=True)
    for c, ax in enumerate(axes):
        component = values[:, :, c]
        shown = component if total is None else np.concatenate([component, total[None, :, c]])
        factor, label = display_unit(shown, "N")
        for k, mount in enumerate(names):
            # Thinner lines for later mounts: symmetric mounts often carry equal forces and would hide.
            width = max(2.4 - 0.4 * k, 0.8)
            plot_long(ax, t, factor * values[k, :, c], color=f"C{k % 10}", linewidth=width, label=f"mount {mount}")
        if total is not None:
            plot_long(ax, t, factor * total[:, c], color="black", linewidth=1.2, linestyle="--", label="total")
        ax.set_ylabel(axis_label(f"force along {AXES[c]}", label))
    axes[0].legend(fontsize=9, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=min(len(names) + 1, 8),
                   frameon=False)
    time_axes(axes, t)
    return fig


def plot_mount_loads(check: MountCheck, t, *, name: str = "", events: Mapping[str, Event] | None = None,
                     fig: Figure | None = None) -> Figure:
    """Total normal force of each mount over the run (static preload plus dynamic, > 0 compression), one
    row per mount, all in one unit: the whole record on the left, tension shaded red and the static load
    dashed (the whole records share one force range); on the right a zoom, its span marked on the left and
    its force range its own, where single cycles and short events can be read: on the excitation's shock
    or switch-on (:func:`~sixdof.plots.zoom.event_window`), else on the largest dynamic excursion
    (:func:`~sixdof.plots.zoom.zoom_window`). A record too short for a zoom is drawn alone.

    Parameters
    ----------
    check : sixdof.analysis.mountcheck.MountCheck
        ``compression`` (n_mounts, n) [N] and ``static_force`` of the mounts ``names``.
    t : array_like, shape (n,)
        Times [s] of ``compression`` (the response's ``t``).
    name : str
        Name of the run, put before the title.
    events : mapping of str to sixdof.results.Event, optional
        The excitation's shocks and switch-ons, by load name (a run's ``events``).

    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one row per mount: the whole record (left) and its zoom (right).

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(check, "check", MountCheck, "a sixdof.analysis.mountcheck.MountCheck")
    t = np.asarray(t, dtype=float)
    compression = np.asarray(check.compression, dtype=float)
    if compression.shape != (len(check.names), len(t)):
        raise InputError("check.compression", f"shape ({len(check.names)}, {len(t)}) (mounts, len(t))",
                         f"shape {compression.shape}")
    static = -np.asarray(check.static_force)[:, 2] if check.preload else np.zeros(len(check.names))
    dynamic = compression - static[:, None]
    window = event_window(events or {}, t) or zoom_window(t, dynamic)
    factor, unit = display_unit(compression, "N")
    rows = len(check.names)
    fig = figure(fig, (12, 1.4 + 1.55 * rows + 0.6))
    fig.suptitle(title(name, "normal force of each mount (static + dynamic; > 0 compression, < 0 tension)"),
                 fontsize=12)
    columns = 1 if window is None else 2
    grid = fig.add_gridspec(rows, columns, width_ratios=None if window is None else (3, 2))
    # The zoom's y labels need room: 0.5 in let the record's last time label touch them.
    margins(fig, left=0.9, right=0.2, top=1.05, bottom=0.55, wspace=0.8, hspace=0.45, columns=columns, rows=rows,
            target=grid)
    low, high = factor * compression.min(), factor * compression.max()
    pad = 0.08 * max(high - low, 1e-30)
    for k, mount in enumerate(check.names):
        panels = [fig.add_subplot(grid[k, 0])] + ([] if window is None else [fig.add_subplot(grid[k, 1])])
        for ax, part in zip(panels, (slice(None), zoom_samples(t, window or (0, 0)))):
            force = compression[k, part]
            plot_long(ax, t[part], factor * force, color="tab:blue", linewidth=1.0, label="normal force N")
            ax.axhline(factor * static[k], color="0.35", linestyle="--", linewidth=0.9, label="static (gravity)")
            ax.axhline(0.0, color="black", linewidth=0.6)
            ax.fill_between(t[part], factor * np.minimum(force, 0.0), 0.0, where=force < 0,
                            color="tab:red", alpha=0.35, linewidth=0, label=TENSION_LABEL)
            ax.set_ylim(low - pad, high + pad)
            ax.grid(True, alpha=0.3)
        whole = panels[0]
        whole.set_xlim(t[0], t[-1])
        whole.xaxis.set_major_locator(MaxNLocator(8, steps=[1, 2, 5, 10]))  # 0, 5, 10 s rather than 2.5 steps
        whole.set_ylabel(axis_label("normal force", unit))
        tension = "" if check.min_compression[k] >= 0 else f", TENSION first at t = {check.tension_start_t[k]:.4g} s"
        whole.set_title(f"mount {mount}: {factor * check.min_compression[k]:.4g} to "
                        f"{factor * check.max_compression[k]:.4g} {unit} "
                        f"(static {factor * static[k]:.4g} {unit}){tension}",
                        fontsize=9, loc="left")
        if window is not None:
            whole.axvspan(*window[:2], color="0.85", zorder=0, label="zoomed span")
            panels[1].set_xlim(*window[:2])
            panels[1].xaxis.set_major_locator(MaxNLocator(6, steps=[1, 2, 5, 10]))
            # The zoom's own force range, static load kept in view: its cycles are what it is for.
            seen = np.concatenate([factor * compression[k, zoom_samples(t, window)], [factor * static[k], 0.0]
                                   if np.any(compression[k] < 0) else [factor * static[k]]])
            spread = max(float(np.ptp(seen)), 1e-12 * max(abs(float(seen.max())), 1.0))
            panels[1].set_ylim(float(seen.min()) - 0.08 * spread, float(seen.max()) + 0.08 * spread)
            if k == 0:
                panels[1].set_title(f"zoom: {window[2]}", fontsize=9, loc="left")
        if k == rows - 1:
            for ax in panels:
                ax.set_xlabel("time t [s]")
        else:
            for ax in panels:
                ax.tick_params(labelbottom=False)
    handles, labels = fig.axes[0].get_legend_handles_labels()
    if not np.any(compression < 0):  # no tension: its patch would say what is not there
        handles, labels = zip(*[(h, label) for h, label in zip(handles, labels) if label != TENSION_LABEL])
    fig.legend(handles, labels, fontsize=9, loc="upper left", bbox_to_anchor=(0.9 / 12, 1 - 0.4 / fig.get_figheight()),
               ncols=len(labels), frameon=False)
    return fig


def plot_mount_shear(check: MountCheck, t, *, name: str = "", events: Mapping[str, Event] | None = None,
                     fig: Figure | None = None) -> Figure:
    """Shear load of each mount, the resultant of its u and v loads (static + dynamic), one row per mount in
    one unit: the whole record, and beside it the zoom of :func:`plot_mount_loads`; each row's title gives
    its peak shear load and peak shear deflection (the resultant of the u and v deflections), which sets
    an elastomer's shear strain.

    Parameters
    ----------
    check : sixdof.analysis.mountcheck.MountCheck
        ``force`` and ``deflection`` (n_mounts, n, 3) along the mounts' axes [N, m].
    t : array_like, shape (n,)
        Times [s] of the check's series.
    name : str
        Name of the run, put before the title.
    events : mapping of str to sixdof.results.Event, optional
        The excitation's shocks and switch-ons, by load name (a run's ``events``).

    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one row per mount: the whole record (left) and its zoom (right).

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(check, "check", MountCheck, "a sixdof.analysis.mountcheck.MountCheck")
    t = np.asarray(t, dtype=float)
    force, deflection = (np.asarray(a, dtype=float) for a in (check.force, check.deflection))
    if force.shape != (len(check.names), len(t), 3):
        raise InputError("check.force", f"shape ({len(check.names)}, {len(t)}, 3) (mounts, len(t), axes)",
                         f"shape {force.shape}")
    shear = np.hypot(force[..., 0], force[..., 1])
    sliding = np.hypot(deflection[..., 0], deflection[..., 1])
    # The excitation's event where it loads the mounts in shear (a vertical impact may not), else the largest
    # swing of the shear itself.
    window = event_window(events or {}, t)
    swing = float(np.ptp(shear)) if shear.size else 0.0
    if window is None or float(np.ptp(shear[:, zoom_samples(t, window)])) < 0.25 * swing:
        window = zoom_window(t, shear - shear[:, :1])
    factor, unit = display_unit(shear, "N")
    rows = len(check.names)
    # Each row's title on two lines (on one it ran past its panel into the zoom's heading): 0.15 in more per row.
    fig = figure(fig, (12, 1.4 + 1.7 * rows + 0.6))
    fig.suptitle(title(name, "shear load of each mount (resultant of u and v, static + dynamic)"), fontsize=12)
    spec = fig.add_gridspec(rows, 1 if window is None else 2, width_ratios=None if window is None else (3, 2))
    margins(fig, left=0.9, right=0.2, top=0.9, bottom=0.55, wspace=0.8, hspace=0.6,
            columns=1 if window is None else 2, rows=rows, target=spec)
    panels = [[fig.add_subplot(spec[k, c]) for c in range(1 if window is None else 2)] for k in range(rows)]
    _time_column([row[0] for row in panels], (t[0], t[-1]))
    if window is not None:
        _time_column([row[1] for row in panels], window[:2], f"zoom: {window[2]}")
    top = 1.08 * factor * float(np.max(shear))
    for k, (mount, row) in enumerate(zip(check.names, panels)):
        for ax, part in zip(row, (slice(None), zoom_samples(t, window or (0, 0)))):
            plot_long(ax, t[part], factor * shear[k, part], color="tab:purple", linewidth=1.0)
            ax.set_ylim(0.0, top)
        row[0].set_ylabel(axis_label("shear force", unit))
        if window is not None:
            row[0].axvspan(*window[:2], color="0.85", zorder=0)
        j, i = int(np.argmax(sliding[k])), int(np.argmax(shear[k]))
        scale, shown = display_unit(sliding[k, j], "m")
        row[0].set_title(f"mount {mount}: peak shear load {factor * shear[k, i]:.4g} {unit} at t = {t[i]:.4g} s,\n"
                         f"peak shear deflection {scale * sliding[k, j]:.4g} {shown} at t = {t[j]:.4g} s",
                         fontsize=9, loc="left")
    return fig
