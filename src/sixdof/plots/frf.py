"""Frequency responses: the Bode plot of the direct receptances and the point FRFs and
transmissibilities."""

from __future__ import annotations

import textwrap
from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.frf import FRF, ForceTransmissibility, FRFCrossCheck, GroundTransmissibility, PointFRF
from sixdof.errors import InputError, Plain
from sixdof.model.modes import Modes
from sixdof.plots.common import (
    COMPONENT_COLORS,
    DOF_NAMES,
    LOAD_NAMES,
    figure,
    margins,
    mark_modes,
    mark_operating,
    name_apart,
    natural_frequencies,
    plain_frequencies,
    require,
    title,
)


def phase_deg(values) -> np.ndarray:
    """The phase [deg] of complex ``values`` along frequency, unwrapped (no jumps of 360 deg where it passes
    +-180) and starting within (-180, 180]."""
    phase = np.degrees(np.unwrap(np.angle(values)))
    if phase.size:
        phase -= 360.0 * np.round((phase[0] - 1e-9) / 360.0)
    return phase


def _finish(mag, phase, f: np.ndarray, frequency_hz: np.ndarray | None, operating_hz=None) -> None:
    """Phase axis [deg] (ticks every 90 deg over what is drawn), grids, natural and operating frequencies
    and frequency span of a magnitude and phase pair."""
    phase.set_ylabel("phase [deg]")
    drawn = np.concatenate([line.get_ydata() for line in phase.get_lines()] or [np.zeros(1)])
    # The 90-degree steps around what is drawn, at least 180 deg (a receptance's -180..0 without an empty
    # half above it).
    low, high = 90.0 * np.floor(drawn.min() / 90.0), 90.0 * np.ceil(drawn.max() / 90.0)
    low = min(low, high - 180.0)
    phase.set_ylim(low - 10, high + 10)
    phase.set_yticks(np.arange(low, high + 1, 90.0 if high - low <= 720 else 180.0))
    for ax in (mag, phase):
        if f[0] > 0 and f[-1] / f[0] > 20:  # a log axis needs f > 0 and pays off over a wide span
            ax.set_xscale("log")
        ax.grid(True, which="major", alpha=0.4)
        ax.grid(True, which="minor", alpha=0.12)
        mark_modes(ax, frequency_hz, label=ax is mag)
        mark_operating(ax, operating_hz, label=ax is mag)
    mag.set_xlim(f[0], f[-1])
    if mag.get_xscale() == "log":
        for ax in (mag, phase):
            plain_frequencies(ax)


def plot_bode(frf: FRF | FRFCrossCheck, modes: Modes | None = None, ax=None, *, name: str = "",
              operating_hz=None, fig: Figure | None = None) -> Figure:
    """Bode plot of the direct receptances ``H_ii`` (q_i per own generalized force).

    Magnitude on a log scale and phase; translations (m/N) and rotations (rad/(N m)) on separate
    axes since their units differ. Dotted verticals mark the natural frequencies (numbered).

    Parameters
    ----------
    frf : sixdof.analysis.frf.FRF or sixdof.analysis.frf.FRFCrossCheck
        Frequencies ``f_hz`` [Hz] and receptance ``H`` (nf, 6, 6) [m/N, m/(N m), rad/N, rad/(N m)],
        as :func:`sixdof.receptance` returns; of a cross-check, its ``direct`` receptance.
    modes : sixdof.model.modes.Modes, optional
        Natural frequencies [Hz] to mark.
    ax : array of matplotlib.axes.Axes, shape (2, 2), optional
        Draw into these axes: magnitude above phase, translations left and rotations right (as
        ``fig.subplots(2, 2, sharex=True)`` makes them); the figure's title and margins are left as
        they are. Default: a new figure.
    name : str
        Name of the run, put before the title (new figure only).
    operating_hz : array_like, optional
        Operating frequencies [Hz] to mark (a run's harmonic loads: its ``steady_state.f_hz``).
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw the whole plot into, title included, given its size
        (:func:`~sixdof.plots.common.figure`); instead of ``ax``. Layout: a 2 x 2 grid, magnitude above phase,
        translations left and rotations right.

    Returns
    -------
    matplotlib.figure.Figure
        The new figure, ``fig``, or the one holding ``ax``.
    """
    if isinstance(frf, FRFCrossCheck):
        frf = frf.direct
    require(frf, "frf", FRF, "a sixdof.analysis.frf.FRF or FRFCrossCheck (from receptance or cross_check)")
    frequency_hz = natural_frequencies(modes)
    f, H = frf.f_hz, frf.H
    if ax is None:
        fig = figure(fig, (13, 8))
        marks = ["dotted: natural frequencies (mode numbers)" if frequency_hz is not None else "",
                 "dash-dot red: operating frequencies" if operating_hz is not None and np.size(operating_hz) else ""]
        heading = "receptance $H_{ii}$ (response of each DOF to its own generalized force)"
        if any(marks):
            heading += "\n" + "; ".join(m for m in marks if m)
        long_name = name_apart(name, heading.split("\n")[0], 13.0, 12)  # the name, then on a line of its own
        margins(fig, left=0.85, right=0.15, top=0.9 + 0.2 * long_name, bottom=1.3, wspace=1.05, hspace=0.15,
                columns=2, rows=2)  # the legends under the phases
        fig.suptitle(f"{name}:\n{heading}" if long_name else title(name, heading), fontsize=12)
        axes = fig.subplots(2, 2, sharex=True, height_ratios=[2, 1])
    else:
        axes = np.asarray(ax, dtype=object)
        if axes.shape != (2, 2):
            raise InputError("ax", "Axes of shape (2, 2): magnitude above phase, translations left",
                             Plain(f"shape {axes.shape}"))
        fig = axes[0, 0].figure
    for column, (block, unit) in enumerate(((range(0, 3), "m/N"), (range(3, 6), "rad/(N m)"))):
        mag, phase = axes[0, column], axes[1, column]
        for k, i in enumerate(block):
            h = H[:, i, i]
            mag.plot(f, np.abs(h), color=COMPONENT_COLORS[k], label=f"{DOF_NAMES[i]} per {LOAD_NAMES[i]}")
            phase.plot(f, phase_deg(h), color=COMPONENT_COLORS[k])
        mag.set_yscale("log")
        mag.set_ylabel(f"|H| [{unit}]")
        mag.set_title("translations" if column == 0 else "rotations", fontsize=11)
        if ax is None:  # under the phase, clear of the curves and of the mode numbers and operating labels
            phase.legend(*mag.get_legend_handles_labels(), fontsize=9, loc="upper center", frameon=False,
                         bbox_to_anchor=(0.5, -0.3))
        else:
            mag.legend(fontsize=9)
        phase.set_xlabel("frequency f [Hz]")
        _finish(mag, phase, f, frequency_hz, operating_hz)
    return fig


def _vector_text(value) -> str:
    return "(" + ", ".join(f"{v:.3g}" for v in np.asarray(value, dtype=float)) + ")"


def _point_item(key: str, item) -> tuple[str, bool, np.ndarray, np.ndarray | None, str]:
    """(title, is a transmissibility, magnitude, complex values or None, unit) of one named item."""
    if isinstance(item, PointFRF):
        load = f"{item.load_kind} {_vector_text(item.load_direction)} at {_vector_text(item.load_point)} m"
        response = (f"{item.response_kind} {_vector_text(item.response_direction)} "
                    f"at {_vector_text(item.response_point)} m")
        return f"{key}: {item.quantity}, {response} per {load}", False, item.magnitude, item.values, item.unit
    if isinstance(item, ForceTransmissibility):
        direction = np.asarray(item.load_direction, dtype=float)
        along = item.along_load if direction.any() else None
        unit = "N/(N m)" if item.load_kind == "moment" else "N/N"
        # The magnitude is the resultant's (every direction); a phase needs one component: along the load.
        return (f"{key}: force transmissibility, |resultant foundation force| per {item.load_kind} "
                f"{_vector_text(direction)} at {_vector_text(item.load_point)} m (phase: along the load)", True,
                item.transmissibility, along, unit)
    if isinstance(item, GroundTransmissibility):
        direction = np.asarray(item.ground_direction, dtype=float)
        along = item.absolute @ direction if direction.any() else None
        return (f"{key}: ground transmissibility, absolute motion at {_vector_text(item.response_point)} m "
                f"along the ground motion {_vector_text(direction)}, per ground motion", True,
                item.transmissibility, along, "m/m")
    raise InputError(f"extras[{key!r}]", "a PointFRF, ForceTransmissibility or GroundTransmissibility", item)


def plot_point_frfs(extras: Mapping[str, PointFRF | ForceTransmissibility | GroundTransmissibility],
                    modes: Modes | None = None, *, name: str = "", fig: Figure | None = None) -> Figure:
    """Point FRFs and transmissibilities: magnitude (log) and phase, one row each.

    The phase of a transmissibility is that of the resultant foundation force (or the absolute
    motion) along the load (or ground) direction.

    Parameters
    ----------
    extras : mapping of str to PointFRF, ForceTransmissibility or GroundTransmissibility
        Named items on the same frequencies [Hz] (from :func:`sixdof.point_frf`,
        :func:`sixdof.force_transmissibility`, :func:`sixdof.ground_transmissibility`), in the
        order drawn; magnitudes in their own units (m/N, N/N, m/m...).
    modes : sixdof.model.modes.Modes, optional
        Natural frequencies [Hz] to mark.
    name : str
        Name of the run, put before the title.
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one row per point FRF or transmissibility: magnitude (left) and phase (right).

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(extras, "extras", Mapping, "a mapping of names to point FRFs or transmissibilities")
    items = [(item.f_hz, *_point_item(key, item)) for key, item in extras.items()]
    if not items:
        raise InputError("extras", "at least one point FRF or transmissibility", Plain("none"))
    frequency_hz = natural_frequencies(modes)
    fig = figure(fig, (13, 3.5 * len(items) + 1.3))
    fig.suptitle(title(name, "point frequency responses and transmissibilities"), fontsize=13)
    # Room above each row for a title of two lines.
    margins(fig, left=0.85, right=0.15, top=0.95, bottom=0.55, wspace=0.85, hspace=0.8, columns=2, rows=len(items))
    axes = np.atleast_2d(fig.subplots(len(items), 2, sharex=True, width_ratios=[3, 2]))
    for row, (f, heading, ratio, magnitude, complex_values, unit) in enumerate(items):
        mag, phase = axes[row]
        mag.plot(f, magnitude, color="tab:blue")
        if np.any(magnitude > 0):
            mag.set_yscale("log")
        else:  # a log axis cannot hold it: a response the load does not reach (by symmetry, say)
            mag.text(0.5, 0.5, "zero at every frequency: the load does not excite this response",
                     transform=mag.transAxes, ha="center", va="center", fontsize=10)
        mag.set_ylabel(f"magnitude [{unit.replace('^2', '²')}]")
        # Wrapped to the magnitude panel's width: beyond it a title runs over the phase column.
        mag.set_title(textwrap.fill(heading, 80), fontsize=10, loc="left")
        if ratio:
            mag.axhline(1.0, color="black", linewidth=0.8, linestyle="--")
        if complex_values is not None:
            phase.plot(f, phase_deg(complex_values), color="tab:blue")
        _finish(mag, phase, f, frequency_hz)
    for a in axes[-1]:
        a.set_xlabel("frequency f [Hz]")
    return fig
