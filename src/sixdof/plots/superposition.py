"""The direct solution against the modal superposition over time: both overlaid per DOF, and their difference."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.compare import QUANTITIES, Agreement, relative_to_ground
from sixdof.analysis.contact import ContactSummary
from sixdof.dofs import DOFS, display_unit
from sixdof.errors import InputError
from sixdof.plots.common import (
    DOF_DIRECTIONS,
    DOF_NAMES,
    axis_label,
    figure,
    margins,
    plot_long,
    require,
    time_axes,
    title,
)
from sixdof.plots.time import (
    _HISTORY,
    _UNITS,
    _superscript,
    _time_column,
    not_excited_line,
    responding,
    unexcited,
)
from sixdof.plots.zoom import event_window, zoom_samples
from sixdof.results import Event, TimeHistory


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
    # A hysteretic solve is checked by its energy balance and a tighter second solve, not by the superposition,
    # which can only be of the bearings' linearization: the figure says so, lest it read as a failed check.
    hysteretic = direct.hysteretic_state is not None
    heading = ("hysteretic bearings (direct integration) vs their linearization (modal superposition)" if hysteretic
               else "direct solution vs modal superposition")
    heading += ", relative to the ground" if direct.has_ground else ""
    if hysteretic and agreement is None:
        heading += ("\nnot a cross-check: the difference is the hysteresis (the solve is checked by its energy balance "
                    "and a tighter second solve)")
    if agreement is not None:
        verdict = "within" if agreement.ok else "EXCEEDS"
        worst = DOFS.index(agreement.worst_dof)  # "velocity about x" where rates are compared too
        where = (f"{QUANTITIES[agreement.worst_quantity]} {DOF_DIRECTIONS[worst]}" if agreement.rates
                 else DOF_NAMES[worst])
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
        _overlay_dof(left, zooms[row], i, t, q_direct[:, i], q_modal[:, i], zoom=zoom, first=first if cut else None,
                     hysteretic=hysteretic)
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
                 first: float | None, hysteretic: bool = False) -> None:
    """DOF ``i``'s overlay of the direct solution ``q_direct`` and the superposition ``q_modal`` [m or rad] on
    ``left`` and its zoom ``zoomed`` (or None); ``first``: the time [s] of the first engagement, marked (None: no
    mount engaged before the end); ``hysteretic``: the direct solution's bearings are hysteretic (the legend says
    which curve is which model)."""
    names = (("direct integration (hysteretic)", "modal superposition (linearized)") if hysteretic
             else ("direct integration", "modal superposition"))
    factor, label = display_unit(q_direct, _UNITS["q"][i])
    for ax, part in ((left, slice(None)), (zoomed, None if zoom is None else zoom_samples(t, zoom))):
        if ax is None:
            continue
        plot_long(ax, t[part], factor * q_direct[part], color="black", linewidth=1.6, label=names[0])
        plot_long(ax, t[part], factor * q_modal[part], color="tab:orange", linewidth=1.0, linestyle="--",
                  label=names[1])
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
