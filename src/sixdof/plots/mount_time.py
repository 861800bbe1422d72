"""The mounts' forces over time: each mount's force on the foundation, its total normal (and shear) force against its
limits."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from sixdof.analysis.mountcheck import MountCheck
from sixdof.analysis.response import MountForces
from sixdof.dofs import AXES, display_unit
from sixdof.errors import InputError
from sixdof.plots.common import (
    axis_label,
    figure,
    margins,
    plot_long,
    require,
    time_axes,
    title,
)
from sixdof.plots.time import (
    _time_column,
)
from sixdof.plots.zoom import event_window, zoom_samples, zoom_window
from sixdof.results import Event

#: Legend of the tension shading: a mount that pulls on the body (a linear one holds; one with tension = false lifts
#: off instead, spring, dashpot and branches together, so it is never shaded).
TENSION_LABEL = "tension (the mount pulls; one that cannot pull lifts off instead)"


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
