"""Accelerations of the named body points over time (``time_points.png``): what equipment mounted on the body
feels, drawn as the centre of gravity's motion is (:mod:`sixdof.plots.time`)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from sixdof.analysis.response import PointMotion
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.dofs import AXES, display_unit
from sixdof.errors import InputError, Plain
from sixdof.plots.common import COMPONENT_COLORS, axis_label, plot_long, require, title
from sixdof.plots.time import (
    DOF_HEIGHT_RANGE,
    DOF_PANELS_HEIGHT,
    RESPONDS_RTOL,
    _shade_zoom,
    _stacked_rows,
    legend_line,
    responding,
)
from sixdof.plots.zoom import event_window, zoom_samples, zoom_window
from sixdof.results import Event


def responding_points(points: Mapping[str, PointMotion]) -> list[str]:
    """The names of the ``points`` whose peak acceleration is above :data:`~sixdof.plots.time.RESPONDS_RTOL` of
    the largest point's (in file order)."""
    peaks = {name: float(np.max(np.abs(p.acceleration))) if np.size(p.acceleration) else 0.0
             for name, p in points.items()}
    largest = max(peaks.values(), default=0.0)
    return [name for name, peak in peaks.items() if largest > 0 and peak > RESPONDS_RTOL * largest]


def plot_point_accelerations(points: Mapping[str, PointMotion], t, *, name: str = "",
                             events: Mapping[str, Event] | None = None, fig: Figure | None = None) -> Figure:
    """Acceleration of each named body point over time, one row per point that responds: its components along
    the body axes that respond (each above :data:`~sixdof.plots.time.RESPONDS_RTOL` of the point's largest), the
    whole record and beside it a zoom (the excitation's shock or switch-on, else the largest excursion); each row's
    title gives the peaks along each axis and the largest in g. The points that do not respond are named in one
    line under the title.

    Parameters
    ----------
    points : mapping of str to sixdof.analysis.response.PointMotion
        The points by name (a run's ``points``), their ``acceleration`` (n, 3) [m/s²] in body axes, absolute or
        relative to the ground (said in the title).
    t : array_like, shape (n,)
        Times [s] of the points' series (the response's ``t``).
    name : str
        Name of the run, put before the title.
    events : mapping of str to sixdof.results.Event, optional
        The excitation's shocks and switch-ons, by load name (a run's ``events``).
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw into, given the layout's size (:func:`~sixdof.plots.common.figure`); default a new
        one. Layout: one row per point that responds: the whole record (left) and its zoom (right).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    sixdof.errors.InputError
        No points, or a point whose acceleration is not (len(t), 3).
    """
    t = np.asarray(t, dtype=float)
    if not points:
        raise InputError("points", "at least one named body point", Plain("none"))
    for point, motion in points.items():
        require(motion, f"points[{point!r}]", PointMotion, "a sixdof.analysis.response.PointMotion")
        if np.shape(motion.acceleration) != (len(t), 3):
            raise InputError(f"points[{point!r}].acceleration", f"shape ({len(t)}, 3) (len(t), axes)",
                             f"shape {np.shape(motion.acceleration)}")
    drawn = responding_points(points) or [next(iter(points))]
    quiet = [point for point in points if point not in drawn]
    relative = any(motion.relative for motion in points.values())
    note = ("" if not quiet else f"not excited (peak at most {RESPONDS_RTOL:g} of the largest point's, not drawn): "
            + ", ".join(quiet))
    stacked = np.stack([np.asarray(points[p].acceleration, dtype=float).T for p in drawn]).reshape(-1, len(t))
    zoom = event_window(events or {}, t) or zoom_window(t, stacked)
    height = float(np.clip(DOF_PANELS_HEIGHT / len(drawn), *DOF_HEIGHT_RANGE))
    heading = ("acceleration of the named body points, relative to the ground" if relative
               else "absolute acceleration of the named body points") + ", along the body axes"
    fig, rows = _stacked_rows(t, [height] * len(drawn), zoom, title(name, heading), note, legend_line=True, fig=fig)
    factor, unit = display_unit(stacked, "m/s^2")
    for point, axes in zip(drawn, rows):
        a = np.asarray(points[point].acceleration, dtype=float)
        peaks = np.max(np.abs(a), axis=0)
        shown = np.flatnonzero(responding(np.hstack([a, np.zeros_like(a)]))[:3])  # the axes it moves along
        for ax, part in zip(axes, (slice(None), zoom_samples(t, zoom or (0, 0)))):
            for c in shown:
                plot_long(ax, t[part], factor * a[part, c], color=COMPONENT_COLORS[c], linewidth=1.0,
                          label=f"along {AXES[c]}")
        axes[0].set_ylabel(axis_label("acceleration", unit))
        along = ", ".join(f"along {AXES[c]} {factor * peaks[c]:.4g}" for c in shown)
        axes[0].set_title(f"point {point}: peak {along} {unit} (largest {peaks.max() / STANDARD_GRAVITY:.3g} g)",
                          fontsize=10, loc="left")
        _shade_zoom(axes, zoom)
    # One legend for the figure, above the panels: every axis a row draws (the first row need not have them all).
    handles = {}
    for axes in rows:
        for handle, label in zip(*axes[0].get_legend_handles_labels()):
            handles.setdefault(label, handle)
    order = [label for label in ("along x", "along y", "along z", "zoomed span") if label in handles]
    legend_line(fig, [handles[label] for label in order], order, ncols=len(order))
    return fig
