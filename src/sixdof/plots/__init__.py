"""Every figure of sixdof, drawn from a :class:`~sixdof.io.store.Results` tree.

A live run and a stored file give the same tree (:func:`sixdof.io.store.write_results` returns what it
wrote, :func:`sixdof.io.store.load_results` reads it back), so ``sixdof run`` and ``sixdof plot
RESULTS.h5`` draw their figures through the same code.

Figures are built as :class:`matplotlib.figure.Figure` objects without pyplot: no backend, no display
and no global figure list are involved (they render with Agg when saved, work headless, and show in
Jupyter), and nothing needs closing. Each function returns its figure so that tests and users can
inspect or restyle it; :func:`save_all` writes every figure the results allow as PNG.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from sixdof.dofs import DOFS
from sixdof.errors import InputError, Plain
from sixdof.io.store import Results

#: Largest displacement of the drawn body in a mode-shape panel, as a fraction of its largest size.
MODE_SCALE = 0.15
#: Largest rotation drawn in a mode-shape panel [rad]: larger ones stop reading as small rotations.
MAX_DRAWN_ROTATION = 0.3
#: A box side is drawn at least this fraction of the largest side (a 40 m beam 1.2 m wide stays 3-D).
MIN_ASPECT = 0.2
#: Side of the fallback body box along an axis where every mount lies in a plane through the CG, as
#: a fraction of the largest side.
FLAT_SIDE = 0.1
#: Resolution of the PNG files [dots per inch].
DPI = 120
#: Most points drawn per line of a time history: longer ones are drawn through the minimum and
#: maximum of each of ``MAX_POINTS // 2`` equal slices (see :func:`envelope_indices`). A slice must
#: stay narrower than a pixel column for the drawn line to look exactly like the full one: 2000
#: slices cover axes up to 2000 px wide (16 inches at :data:`DPI`).
MAX_POINTS = 4000
#: zlib level of the PNG files: 1 writes several times faster than the default 6 for files about
#: a third larger (the figures are mostly flat colour, which compresses well at any level).
PNG_COMPRESS_LEVEL = 1

_TRANSLATION = "tab:blue"
_ROTATION = "tab:red"
_COMPONENT_COLORS = ("tab:blue", "tab:orange", "tab:green")

# Display units: (factor from SI, label), the first whose scaled peak is >= the threshold wins.
_DISPLAY_UNITS = {
    "m": ((1e3, "mm", 0.01), (1e6, "µm", 0.0)),
    "m/s": ((1e3, "mm/s", 0.01), (1e6, "µm/s", 0.0)),
    "m/s^2": ((1.0, "m/s²", 0.01), (1e3, "mm/s²", 0.0)),
    "rad": ((1e3, "mrad", 0.01), (1e6, "µrad", 0.0)),
    "rad/s": ((1e3, "mrad/s", 0.01), (1e6, "µrad/s", 0.0)),
    "rad/s^2": ((1.0, "rad/s²", 0.01), (1e3, "mrad/s²", 0.0)),
    "N": ((1e-3, "kN", 0.01), (1.0, "N", 0.0)),
    "N m": ((1e-3, "kN m", 0.01), (1.0, "N m", 0.0)),
}


def _display(values: np.ndarray, unit: str) -> tuple[float, str]:
    """Factor and label that show ``values`` (in SI ``unit``) with a readable peak."""
    choices = _DISPLAY_UNITS.get(unit)
    if choices is None:
        return 1.0, unit
    peak = float(np.nanmax(np.abs(values))) if np.size(values) else 0.0
    for factor, label, threshold in choices:
        if peak * factor >= threshold:
            return factor, label
    return choices[0][0], choices[0][1]


def envelope_indices(values: np.ndarray, max_points: int = MAX_POINTS) -> np.ndarray:
    """Indices of the samples that draw ``values`` through at most about ``max_points`` points.

    The samples are cut into ``max_points // 2`` slices of equal length; the indices of each
    slice's minimum and maximum are kept, with the first and last sample. Every drawn point is
    therefore a real sample, and each slice's (so the whole series') extrema are drawn exactly: on
    axes whose pixel columns are wider than a slice the decimated line covers the same pixels as
    the full one. Short series are returned whole.

    Parameters
    ----------
    values : numpy.ndarray
        One series (n,), any unit.
    max_points : int
        Largest number of points wanted (the result has at most ``max_points + 2``).

    Returns
    -------
    numpy.ndarray
        Sorted unique sample indices (int).
    """
    values = np.asarray(values)
    n = len(values)
    if n <= max_points:
        return np.arange(n)
    width = -(-n // max(max_points // 2, 1))  # samples per slice
    slices = -(-n // width)
    # Pad the last slice with its own last sample: a padded index found as an extremum stands for
    # that sample (same value), so clipping it to n - 1 stays exact.
    padded = np.concatenate([values, np.full(slices * width - n, values[-1])]).reshape(slices, width)
    start = np.arange(slices) * width
    keep = np.concatenate([[0, n - 1], start + np.argmin(padded, axis=1), start + np.argmax(padded, axis=1)])
    return np.unique(np.minimum(keep, n - 1))


def _plot_long(ax, t: np.ndarray, values: np.ndarray, *args, **kwargs):
    """``ax.plot(t, values, ...)`` through the :func:`envelope_indices` of a long series."""
    keep = envelope_indices(values)
    return ax.plot(t[keep], values[keep], *args, **kwargs)


def _margins(fig: Figure, left: float, right: float, top: float, bottom: float, wspace: float = 0.0,
             hspace: float = 0.0, columns: int = 1, rows: int = 1, target=None) -> None:
    """Fixed margins and gaps between axes, all in inches, on a figure without a layout engine.

    A fixed layout draws the figure once; a layout engine measures every label first (a second
    draw), which for these figures costs more than drawing them. ``target`` is a GridSpec to adjust
    instead of the figure's subplot parameters.
    """
    width, height = fig.get_size_inches()
    cell_w = (width - left - right - (columns - 1) * wspace) / columns
    cell_h = (height - top - bottom - (rows - 1) * hspace) / rows
    params = {"left": left / width, "right": 1 - right / width, "top": 1 - top / height, "bottom": bottom / height,
              "wspace": wspace / cell_w, "hspace": hspace / cell_h}
    if target is None:
        fig.subplots_adjust(**params)
    else:
        target.update(**params)


def _require(results: Results, *paths: str) -> None:
    if not isinstance(results, Results):
        raise InputError("results", "a sixdof.io.store.Results (from write_results or load_results)", results)
    missing = [p for p in paths if p not in results.datasets]
    if missing:
        raise InputError("results", f"datasets {', '.join('/' + p for p in missing)}", Plain("results without them"))


def _title(results: Results, what: str) -> str:
    return f"{results.name}: {what}" if results.name else what


# ----------------------------------------------------------------------------------------------------
# Modes.
# ----------------------------------------------------------------------------------------------------


def body_box(results: Results) -> np.ndarray:
    """Size [Lx, Ly, Lz] of the box drawn for the body [m], centred on the CG.

    The scenario's ``body.dimensions`` when given; otherwise the box reaching the mounts
    (symmetric about the CG); a side of zero length (every mount in a plane through the CG) is
    made :data:`FLAT_SIDE` of the largest.
    """
    dims = results.body_dimensions
    if dims is not None:
        return np.asarray(dims, dtype=float)
    positions = results.mount_positions
    size = 2.0 * np.max(np.abs(positions), axis=0) if len(positions) else np.ones(3)
    largest = float(np.max(size)) or 1.0
    return np.where(size <= 1e-9 * largest, FLAT_SIDE * largest, size)


def _box(size: np.ndarray) -> tuple[np.ndarray, list[list[int]]]:
    """Corners (8, 3) [m] of a box centred on the origin, and its six faces (corner indices)."""
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float) * size / 2
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    return corners, faces


def _displacement(points: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Small-rotation displacement of body points (n, 3) [m] for generalized coordinates q (6,)."""
    return q[:3] + np.cross(q[3:], points)


def _rotation(theta: np.ndarray) -> np.ndarray:
    """Rotation matrix of the rotation vector ``theta`` [rad] (Rodrigues)."""
    angle = float(np.linalg.norm(theta))
    if angle == 0.0:
        return np.eye(3)
    k = theta / angle
    cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * cross + (1.0 - np.cos(angle)) * cross @ cross


def _drawn_mode(points: np.ndarray, shape: np.ndarray, largest: float) -> np.ndarray:
    """Positions (n, 3) [m] of body points in a mode shape scaled to be visible.

    The shape is scaled so that the largest point displacement is :data:`MODE_SCALE` of the body's
    largest size, but its rotation no more than :data:`MAX_DRAWN_ROTATION`; the rotation is drawn
    as a finite rotation so that the box stays a box (the small-rotation map would stretch it).
    """
    peak = float(np.max(np.linalg.norm(_displacement(points, shape), axis=1)))
    if peak == 0.0:
        return points.copy()
    scale = MODE_SCALE * largest / peak
    rotation = float(np.linalg.norm(shape[3:]))
    if rotation * scale > MAX_DRAWN_ROTATION:
        scale = MAX_DRAWN_ROTATION / rotation
    q = scale * np.asarray(shape, dtype=float)
    return q[:3] + points @ _rotation(q[3:]).T


def _panel_zoom(aspect: np.ndarray, elev: float, azim: float) -> float:
    """Zoom of a 3-D panel that keeps the drawn box and its labels inside the panel's cell.

    matplotlib scales the box to a fixed diagonal, so a tall box projects higher than a flat or long
    one; with fixed margins (no layout engine) it must be zoomed out to fit, and a flat one may be
    zoomed in. 0.85 and 1.0 are the projected height and width (fractions of the diagonal) that fit
    a 5 x 4.6 inch cell at zoom 1, found by eye; 1.15 is the largest zoom wanted.
    """
    unit = np.asarray(aspect, dtype=float) / np.linalg.norm(aspect)
    el, az = np.radians(elev), np.radians(azim)
    height = unit[2] * np.cos(el) + (unit[0] * abs(np.sin(az)) + unit[1] * abs(np.cos(az))) * np.sin(el)
    width = unit[0] * abs(np.cos(az)) + unit[1] * abs(np.sin(az))
    return float(min(1.15, 0.85 / height, 1.0 / width))


def plot_mode_shapes(results: Results) -> Figure:
    """The body (a box) on its mounts, undeformed and deformed in each mode, one panel per mode.

    Each mode shape is scaled so that the largest displacement of a box corner or mount is
    :data:`MODE_SCALE` of the box's largest side (rotations at most :data:`MAX_DRAWN_ROTATION`,
    drawn as finite rotations); light grey is the rest position, colour the
    deformed body; triangles mark the mounts' ground side, dots their body side.

    Parameters
    ----------
    results : Results
        Needs ``/modal/shapes``, ``/modal/frequency_hz`` and ``/modal/dominant_dof``; draws the
        mounts of ``/model/mount_position`` and the box of ``/model/body_dimensions`` when present.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _require(results, "modal/shapes", "modal/frequency_hz", "modal/dominant_dof")
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    shapes = results.array("modal/shapes")
    freqs = results.array("modal/frequency_hz")
    dominant = results.array("modal/dominant_dof")
    ke = results.get("modal/ke_distribution")
    size = body_box(results)
    corners, faces = _box(size)
    mounts = results.mount_positions
    names = results.mount_names
    points = np.vstack([corners, mounts])
    largest = float(np.max(size))

    n = shapes.shape[1]
    columns, rows = _panel_grid(n)
    fig = Figure(figsize=(5.0 * columns, 4.6 * rows))
    fig.suptitle(_title(results, "mode shapes (displacements scaled for visibility)"), fontsize=13)
    _margins(fig, left=0.1, right=0.1, top=0.85, bottom=0.15, wspace=0.2, hspace=0.75, columns=columns, rows=rows)
    drawn = [_drawn_mode(points, shapes[:, j], largest) for j in range(n)]
    # One set of limits for every panel, equal scales on the three axes (nothing distorted) except
    # that MIN_ASPECT keeps slender bodies visible.
    reach = 1.05 * np.max(np.abs(np.concatenate([points, *drawn])), axis=0)
    aspect = np.maximum(reach, MIN_ASPECT * float(np.max(reach)))
    for j in range(n):
        ax = fig.add_subplot(rows, columns, j + 1, projection="3d")
        moved = drawn[j]
        rest_faces = [corners[f] for f in faces]
        ax.add_collection3d(
            Poly3DCollection(rest_faces, facecolors=(0.6, 0.6, 0.6, 0.06), edgecolors=(0.5, 0.5, 0.5, 0.6),
                             linewidths=0.7, linestyles="--")
        )
        ax.add_collection3d(
            Poly3DCollection([moved[:8][f] for f in faces], facecolors=(0.12, 0.47, 0.71, 0.25),
                             edgecolors=(0.05, 0.25, 0.45, 1.0), linewidths=1.2)
        )
        if len(mounts):
            ground = mounts
            ax.scatter(*ground.T, marker="^", s=45, color="black", depthshade=False,
                       label="mount (ground side)")
            body_side = moved[8:]
            ax.scatter(*body_side.T, marker="o", s=22, color="tab:red", depthshade=False,
                       label="mount (body side)")
            for a, b in zip(ground, body_side):
                ax.plot(*np.stack([a, b]).T, color="tab:red", linewidth=1.0)
            if j == 0:
                for name, p in zip(names, ground):
                    ax.text(*p, f" {name}", fontsize=8, color="black")
        for axis, label in enumerate("xyz"):
            getattr(ax, f"set_{label}lim")(-aspect[axis], aspect[axis])
            getattr(ax, f"set_{label}label")(f"{label} [m]", labelpad=1)
        # matplotlib normalizes the array it is given in place
        ax.set_box_aspect(aspect.copy(), zoom=_panel_zoom(aspect, ax.elev, ax.azim))
        ax.tick_params(labelsize=7, pad=2)  # pad 0 puts a tick mark over a label's minus sign
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(MaxNLocator(4, symmetric=True))
        share = ""
        if ke is not None:
            share = f" ({100 * ke.data[DOFS.index(dominant[j]), j]:.0f} % KE)"
        frequency = "rigid-body mode (0 Hz)" if freqs[j] == 0 else f"{freqs[j]:.4g} Hz"
        ax.set_title(f"Mode {j + 1}: {frequency}\ndominant {dominant[j]}{share}", fontsize=11)
        if j == 0 and len(mounts):
            ax.legend(loc="upper left", fontsize=7, frameon=False)
    return fig


def plot_ke_distribution(results: Results) -> Figure:
    """Heatmap of each mode's kinetic-energy distribution over the DOFs, in percent.

    Parameters
    ----------
    results : Results
        Needs ``/modal/ke_distribution`` and ``/modal/frequency_hz``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _require(results, "modal/ke_distribution", "modal/frequency_hz")
    percent = 100.0 * results.array("modal/ke_distribution")
    freqs = results.array("modal/frequency_hz")
    dofs = results.dofs
    n = percent.shape[1]
    fig = Figure(figsize=(1.2 * n + 2.6, 5.0))
    _margins(fig, left=0.75, right=0.1, top=0.35, bottom=0.85)
    ax = fig.add_subplot()
    image = ax.imshow(percent, cmap="Blues", vmin=0.0, vmax=100.0, aspect="auto")
    for i in range(percent.shape[0]):
        for j in range(n):
            value = percent[i, j]
            # Round-off leaves shares like -1e-15: print them as 0, not "-0".
            text = "0" if abs(value) < 0.05 else (f"{value:.0f}" if value >= 9.95 else f"{value:.1f}")
            ax.text(j, i, text, ha="center", va="center", fontsize=10,
                    color="white" if value > 60 else "black")
    ax.set_xticks(range(n), [f"{j + 1}\n{f:.3g} Hz" for j, f in enumerate(freqs)])
    ax.set_yticks(range(len(dofs)), dofs)
    ax.set_xlabel("mode (natural frequency [Hz])")
    ax.set_ylabel("degree of freedom")
    ax.set_title(_title(results, "kinetic-energy distribution [%]"))
    fig.colorbar(image, ax=ax, label="share of the mode's kinetic energy [%]")
    return fig


# ----------------------------------------------------------------------------------------------------
# Time histories.
# ----------------------------------------------------------------------------------------------------


def _dof_grid(fig: Figure, t: np.ndarray):
    """3 x 2 axes: translations left, rotations right, one DOF per axis, shared time axis."""
    axes = fig.subplots(3, 2, sharex=True)
    for ax in axes[-1]:
        ax.set_xlabel("time t [s]")
    for ax in axes.flat:
        ax.grid(True, alpha=0.3)
        ax.set_xlim(t[0], t[-1])
    return [axes[i % 3, i // 3] for i in range(6)]


def plot_time_histories(results: Results, key: str = "q") -> Figure:
    """Time history of each DOF on its own axis: translations in mm, rotations in mrad.

    (µm or µrad when the peak is below 0.01 mm or 0.01 mrad.)

    With ground motion the motion relative to the ground (``/time/<key>_relative``) is drawn
    dashed beside the absolute one.

    Parameters
    ----------
    results : Results
        Needs ``/time/t`` and ``/time/<key>``.
    key : {"q", "qd", "qdd"} or another (n, 6) dataset of ``/time``
        Displacement (default), velocity or acceleration.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _require(results, "time/t", f"time/{key}")
    t = results.array("time/t")
    values = results.array(f"time/{key}")
    units = results[f"time/{key}"].attrs.get("dof_units", ("m", "m", "m", "rad", "rad", "rad"))
    quantity = {"q": "displacement", "qd": "velocity", "qdd": "acceleration"}.get(key, key)
    fig = Figure(figsize=(12, 8))
    fig.suptitle(_title(results, f"{quantity} of the centre of gravity ({key})"), fontsize=13)
    _margins(fig, left=0.8, right=0.15, top=0.7, bottom=0.55, wspace=1.0, hspace=0.55, columns=2, rows=3)
    relative = results.get(f"time/{key}_relative")  # present when the ground moves
    for i, ax in enumerate(_dof_grid(fig, t)):
        shown = values[:, i] if relative is None else np.concatenate([values[:, i], relative.data[:, i]])
        factor, label = _display(shown, units[i])
        _plot_long(ax, t, factor * values[:, i], color=_TRANSLATION if i < 3 else _ROTATION, linewidth=1.0,
                   label="absolute")
        if relative is not None:
            _plot_long(ax, t, factor * relative.data[:, i], color="black", linestyle="--", linewidth=0.9,
                       label="relative to the ground")
            if i == 0:
                ax.legend(fontsize=8, loc="best")
        ax.set_ylabel(f"{results.dofs[i]} [{label}]")
        peak = float(np.max(np.abs(values[:, i])))
        ax.set_title(f"{results.dofs[i]}: peak {factor * peak:.4g} {label}", fontsize=10)
    return fig


def plot_superposition(results: Results) -> Figure:
    """Direct solution and modal superposition overlaid (left), and their difference divided by the
    DOF's peak (right, with the agreement tolerance dashed), per DOF.

    Parameters
    ----------
    results : Results
        Needs ``/time/t``, ``/time/q`` and ``/time/superposition/q``; the agreement attributes of
        ``/time/superposition`` go in the titles when present.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _require(results, "time/t", "time/q", "time/superposition/q")
    t = results.array("time/t")
    attrs = results.attrs.get("time/superposition", {})
    # Superposition in relative coordinates (ground motion) is compared with the relative direct motion.
    in_ground_frame = attrs.get("frame", "absolute") != "absolute" and "time/q_relative" in results.datasets
    direct = results.array("time/q_relative" if in_ground_frame else "time/q")
    modal = results.array("time/superposition/q")
    per_dof = attrs.get("agreement_per_dof")
    units = results["time/q"].attrs.get("dof_units", ("m", "m", "m", "rad", "rad", "rad"))
    fig = Figure(figsize=(13, 13))
    heading = "direct solution vs modal superposition" + (" (motion relative to the ground)" if in_ground_frame else "")
    if "agreement_worst" in attrs:
        verdict = "within" if attrs.get("agreement_ok", 1) else "EXCEEDS"
        heading += (f"\nworst relative difference {attrs['agreement_worst']:.2e} in "
                    f"{attrs['agreement_worst_dof']} ({verdict} tolerance {attrs['agreement_tolerance']:.0e})")
    fig.suptitle(_title(results, heading), fontsize=13)
    _margins(fig, left=0.8, right=0.15, top=1.0, bottom=0.55, wspace=1.1, hspace=0.45, columns=2, rows=6)
    axes = fig.subplots(6, 2, sharex=True)
    for i in range(6):
        factor, label = _display(direct[:, i], units[i])
        left, right = axes[i]
        _plot_long(left, t, factor * direct[:, i], color="black", linewidth=1.6, label="direct (diffrax)")
        _plot_long(left, t, factor * modal[:, i], color="tab:orange", linewidth=1.0, linestyle="--",
                   label="modal superposition")
        left.set_ylabel(f"{results.dofs[i]} [{label}]")
        # The difference relative to the quantity the agreement divides by: the DOF's own peak,
        # or for a quiet DOF (round-off only) the largest peak of all DOFs.
        denominator, against = _agreement_denominator(direct, attrs, i)
        relative = (modal[:, i] - direct[:, i]) / denominator if denominator > 0 else modal[:, i] - direct[:, i]
        _plot_long(right, t, relative, color="tab:purple", linewidth=0.9)
        right.set_ylabel(f"Δ{results.dofs[i]} / {against} [1]")
        right.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
        # Tolerance lines only where they do not flatten the curve into a line.
        if "agreement_tolerance" in attrs and np.max(np.abs(relative)) > 0.1 * attrs["agreement_tolerance"]:
            for sign in (-1, 1):
                right.axhline(sign * attrs["agreement_tolerance"], color="tab:red", linestyle="--", linewidth=0.8)
        if per_dof is not None:
            quiet = " (quiet DOF: round-off only)" if against != "peak" else ""
            right.set_title(f"{results.dofs[i]}: max|Δ| / {against} = {per_dof[i]:.2e}{quiet}", fontsize=9)
        for ax in (left, right):
            ax.grid(True, alpha=0.3)
            ax.set_xlim(t[0], t[-1])
    axes[0, 0].legend(fontsize=9, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=2, frameon=False)
    if "agreement_tolerance" in attrs:
        axes[0, 1].plot([], [], color="tab:red", linestyle="--", linewidth=0.8, label="± tolerance")
        axes[0, 1].legend(fontsize=8, loc="upper right")
    axes[-1, 0].set_xlabel("time t [s]")
    axes[-1, 1].set_xlabel("time t [s]")
    return fig


def _panel_grid(n: int) -> tuple[int, int]:
    """Columns and rows for ``n`` per-mode panels: one row up to 4, else 3 columns."""
    columns = 3 if n > 4 else n
    return columns, -(-n // columns)


def _agreement_denominator(direct: np.ndarray, attrs, i: int) -> tuple[float, str]:
    """What the stored agreement divides DOF ``i``'s difference by, and its name.

    A quiet DOF (listed in ``agreement_quiet``) is measured against the largest peak of all DOFs,
    rotations converted to lengths with ``agreement_length`` (see sixdof.analysis.superposition.compare).
    """
    peaks = np.max(np.abs(direct), axis=0)
    if DOFS[i] not in tuple(attrs.get("agreement_quiet", ())):
        return float(peaks[i]), "peak"
    length = float(attrs.get("agreement_length", 1.0))
    as_length = peaks * np.array([1.0, 1.0, 1.0, length, length, length])
    largest = float(np.max(as_length))
    return (largest / length if i >= 3 else largest), "largest peak"


def plot_mount_forces(results: Results) -> Figure:
    """Force of each mount on the foundation, one axis per component (x, y, z in body axes), one
    line per mount, in kN; the total foundation force (dashed) when stored.

    Components get their own axes because their sizes differ by decades (vertical bearing loads vs
    horizontal ones).

    Parameters
    ----------
    results : Results
        Needs ``/time/t`` and ``/time/mount_force`` (n_mounts, n, 3) [N]; uses
        ``/time/foundation_force`` (n, 3) [N] when present.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _require(results, "time/t", "time/mount_force")
    t = results.array("time/t")
    forces = results.array("time/mount_force")
    names = tuple(results.array("time/mount").tolist()) if "time/mount" in results.datasets else results.mount_names
    total = results.get("time/foundation_force")
    fig = Figure(figsize=(12, 8.5))
    fig.suptitle(_title(results, "mount forces on the foundation (body axes)"), fontsize=13)
    _margins(fig, left=0.8, right=0.15, top=0.75, bottom=0.55, hspace=0.2, rows=3)
    axes = fig.subplots(3, 1, sharex=True)
    colors = [f"C{k % 10}" for k in range(len(names))]
    for c, ax in enumerate(axes):
        component = forces[:, :, c]
        shown = component if total is None else np.concatenate([component, total.data[None, :, c]])
        factor, label = _display(shown, "N")
        for k, name in enumerate(names):
            # Thinner lines for later mounts: symmetric mounts often carry equal forces and would hide.
            width = max(2.4 - 0.4 * k, 0.8)
            _plot_long(ax, t, factor * forces[k, :, c], color=colors[k], linewidth=width, label=f"mount {name}")
        if total is not None:
            _plot_long(ax, t, factor * total.data[:, c], color="black", linewidth=1.2, linestyle="--",
                       label="total")
        ax.set_ylabel(f"F{'xyz'[c]} [{label}]")
        ax.grid(True, alpha=0.3)
        ax.set_xlim(t[0], t[-1])
    axes[0].legend(fontsize=9, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=min(len(names) + 1, 8),
                   frameon=False)
    axes[-1].set_xlabel("time t [s]")
    return fig


# ----------------------------------------------------------------------------------------------------
# Frequency responses.
# ----------------------------------------------------------------------------------------------------


def _mark_modes(ax, results: Results, label: bool = False) -> None:
    freqs = results.get("modal/frequency_hz")
    if freqs is None:
        return
    for j, f in enumerate(freqs.data):
        if f > 0:
            ax.axvline(f, color="grey", linewidth=0.8, linestyle=":", zorder=0)
            if label:
                ax.text(f, 0.99, f"{j + 1}", transform=ax.get_xaxis_transform(), fontsize=8,
                        color="dimgrey", va="top", ha="left")


def plot_bode(results: Results) -> Figure:
    """Bode plot of the direct receptances ``H_ii`` (q_i per own generalized force).

    Magnitude on a log scale and phase; translations (m/N) and rotations (rad/(N m)) on separate
    axes since their units differ. Dotted verticals mark the natural frequencies (numbered).

    Parameters
    ----------
    results : Results
        Needs ``/frf/f_hz`` and ``/frf/receptance``; marks ``/modal/frequency_hz`` when present.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _require(results, "frf/f_hz", "frf/receptance")
    f = results.array("frf/f_hz")
    H = results.array("frf/receptance")
    dofs = results.dofs
    fig = Figure(figsize=(13, 8))
    _margins(fig, left=0.85, right=0.15, top=0.7, bottom=0.55, wspace=1.05, hspace=0.15, columns=2, rows=2)
    heading = "receptance H_ii (response of each DOF to its own generalized force)"
    if "modal/frequency_hz" in results.datasets:
        heading += "; dotted: natural frequencies (mode numbers)"
    fig.suptitle(_title(results, heading), fontsize=13)
    axes = fig.subplots(2, 2, sharex=True, height_ratios=[2, 1])
    logx = f[0] > 0 and f[-1] / f[0] > 20
    for column, (block, unit) in enumerate(((range(0, 3), "m/N"), (range(3, 6), "rad/(N m)"))):
        mag, phase = axes[0, column], axes[1, column]
        for k, i in enumerate(block):
            h = H[:, i, i]
            color = _COMPONENT_COLORS[k]
            label = f"{dofs[i]} per {('Fx', 'Fy', 'Fz', 'Mx', 'My', 'Mz')[i]}"
            mag.plot(f, np.abs(h), color=color, label=label)
            phase.plot(f, np.degrees(np.angle(h)), color=color)
        mag.set_yscale("log")
        mag.set_ylabel(f"|H| [{unit}]")
        mag.set_title("translations" if column == 0 else "rotations", fontsize=11)
        mag.legend(fontsize=9)
        phase.set_ylabel("phase [deg]")
        phase.set_ylim(-190, 190)
        phase.set_yticks([-180, -90, 0, 90, 180])
        phase.set_xlabel("frequency f [Hz]")
        for ax in (mag, phase):
            if logx:
                ax.set_xscale("log")
            ax.grid(True, which="major", alpha=0.4)
            ax.grid(True, which="minor", alpha=0.12)
            _mark_modes(ax, results, label=ax is mag)
        mag.set_xlim(f[0], f[-1])
    return fig


def _point_items(results: Results) -> list[tuple[str, str, np.ndarray, np.ndarray | None, str]]:
    """Stored point FRFs and transmissibilities: (title, kind, magnitude, complex or None, unit)."""
    items = []
    groups = [g for g in results.groups if g.count("/") == 2 and g.startswith("frf/")]
    for group in groups:
        _, kind, name = group.split("/")
        attrs = results.attrs[group]
        if kind == "point" and f"{group}/values" in results.datasets:
            values = results[f"{group}/values"]
            load = (f"{attrs.get('load_kind', 'load')} {_vector_text(attrs.get('load_direction'))} "
                    f"at {_vector_text(attrs.get('load_point'))} m")
            response = (f"{attrs.get('response_kind', 'response')} {_vector_text(attrs.get('response_direction'))} "
                        f"at {_vector_text(attrs.get('response_point'))} m")
            items.append((f"{name}: {attrs.get('quantity', 'FRF')}, {response} per {load}", kind,
                          np.abs(values.data), values.data, values.units))
        elif kind == "force_transmissibility" and f"{group}/transmissibility" in results.datasets:
            magnitude = results[f"{group}/transmissibility"]
            direction = np.asarray(attrs.get("load_direction", np.zeros(3)), dtype=float)
            along = results.array(f"{group}/total")[:, :3] @ direction if direction.any() else None
            items.append((f"{name}: force transmissibility, |foundation force| per {attrs.get('load_kind', 'load')} "
                          f"{_vector_text(direction)} at {_vector_text(attrs.get('load_point'))} m", kind,
                          magnitude.data, along, magnitude.units))
        elif kind == "ground_transmissibility" and f"{group}/transmissibility" in results.datasets:
            magnitude = results[f"{group}/transmissibility"]
            direction = np.asarray(attrs.get("ground_direction", np.zeros(3)), dtype=float)
            along = results.array(f"{group}/absolute") @ direction if direction.any() else None
            items.append((f"{name}: ground transmissibility, motion at {_vector_text(attrs.get('response_point'))} m "
                          f"per ground motion {_vector_text(direction)}", kind, magnitude.data, along, magnitude.units))
    return items


def _vector_text(value) -> str:
    if value is None:
        return "?"
    return "(" + ", ".join(f"{v:.3g}" for v in np.asarray(value, dtype=float)) + ")"


def plot_point_frfs(results: Results) -> Figure:
    """Every stored point FRF and transmissibility: magnitude (log) and phase, one row each.

    The phase of a transmissibility is that of the resultant foundation force (or the absolute
    motion) along the load (or ground) direction.

    Parameters
    ----------
    results : Results
        Needs ``/frf/f_hz`` and at least one group under ``/frf/point``,
        ``/frf/force_transmissibility`` or ``/frf/ground_transmissibility``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    _require(results, "frf/f_hz")
    items = _point_items(results)
    if not items:
        raise InputError("results", "point FRFs or transmissibilities under /frf", Plain("none"))
    f = results.array("frf/f_hz")
    logx = f[0] > 0 and f[-1] / f[0] > 20
    fig = Figure(figsize=(13, 3.2 * len(items) + 1.0))
    fig.suptitle(_title(results, "point frequency responses and transmissibilities"), fontsize=13)
    _margins(fig, left=0.85, right=0.15, top=0.6, bottom=0.55, wspace=0.85, hspace=0.5, columns=2, rows=len(items))
    axes = np.atleast_2d(fig.subplots(len(items), 2, sharex=True, width_ratios=[3, 2]))
    for row, (title, kind, magnitude, complex_values, unit) in enumerate(items):
        mag, phase = axes[row]
        mag.plot(f, magnitude, color="tab:blue")
        mag.set_yscale("log")
        mag.set_ylabel(f"magnitude [{unit}]")
        mag.set_title(title, fontsize=10, loc="left")
        if kind != "point":
            mag.axhline(1.0, color="black", linewidth=0.8, linestyle="--")
        if complex_values is not None:
            phase.plot(f, np.degrees(np.angle(complex_values)), color="tab:blue")
        phase.set_ylabel("phase [deg]")
        phase.set_ylim(-190, 190)
        phase.set_yticks([-180, -90, 0, 90, 180])
        for ax in (mag, phase):
            if logx:
                ax.set_xscale("log")
            ax.grid(True, which="major", alpha=0.4)
            ax.grid(True, which="minor", alpha=0.12)
            _mark_modes(ax, results, label=ax is mag)
        mag.set_xlim(f[0], f[-1])
    for ax in axes[-1]:
        ax.set_xlabel("frequency f [Hz]")
    return fig


# ----------------------------------------------------------------------------------------------------
# Validation against time histories.
# ----------------------------------------------------------------------------------------------------


def plot_validation_frf(results: Results) -> Figure:
    """H1 estimate (random run) against the model FRF of each mode's modal coordinate, one panel
    per mode over its band, with the natural frequency and the estimate's peak marked and the
    coherence below.

    Parameters
    ----------
    results : Results
        Needs groups ``/validation/random/mode_<r>`` (``f_hz``, ``H1``, ``model``, ``coherence``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    groups = _mode_groups(results, "validation/random/mode_")
    if not groups:
        raise InputError("results", "random-run FRFs under /validation/random", Plain("none"))
    rows = _validation_rows(results)
    n = len(groups)
    columns, grid = _panel_grid(n)
    fig = Figure(figsize=(5.0 * columns, 4.6 * grid))
    fig.suptitle(_title(results, "modal FRFs: H1 estimate from a random force vs the model"), fontsize=12)
    cells = fig.add_gridspec(grid, columns)
    _margins(fig, left=0.85, right=0.15, top=0.6, bottom=0.5, wspace=1.0, hspace=1.2, columns=columns, rows=grid,
             target=cells)
    for k, group in enumerate(groups):
        attrs = results.attrs[group]
        mode = int(attrs["mode"])
        f = results.array(f"{group}/f_hz")
        H1, model = results.array(f"{group}/H1"), results.array(f"{group}/model")
        band = attrs.get("band_hz")
        keep = (f > 0) if band is None else (f >= band[0]) & (f <= band[1])
        cell = cells[k // columns, k % columns].subgridspec(2, 1, height_ratios=[3, 1], hspace=0.08)
        mag = fig.add_subplot(cell[0])
        coh = fig.add_subplot(cell[1], sharex=mag)
        mag.tick_params(labelbottom=False)
        mag.semilogy(f[keep], np.abs(H1[keep]), color="tab:grey", marker=".", markersize=4, linewidth=0.6,
                     label="H1 estimate")
        mag.semilogy(f[keep], np.abs(model[keep]), color="black", linewidth=1.2, label="model")
        title = f"mode {mode}"
        if mode in rows:
            i = rows[mode]
            f_model = results.array("validation/f_model_hz")[i]
            mag.axvline(f_model, color="tab:blue", linestyle=":", linewidth=1.0, label="natural frequency")
            title += f": f = {f_model:.4g} Hz"
            if "validation/f_peak_estimated_hz" in results.datasets:
                f_peak = results.array("validation/f_peak_estimated_hz")[i]
                mag.axvline(f_peak, color="tab:red", linestyle="--", linewidth=0.8, label="H1 peak")
                title += f", H1 peak {f_peak:.4g} Hz"
            if "validation/h1_median_error" in results.datasets:
                title += f"\nmedian |H1 - model| / |model| = {results.array('validation/h1_median_error')[i]:.1e}"
        mag.set_title(title, fontsize=10)
        mag.set_ylabel(f"|eta_{mode} / F| [kg^1/2 m/N]")
        mag.grid(True, which="both", alpha=0.25)
        coh.plot(f[keep], results.array(f"{group}/coherence")[keep], color="tab:green", linewidth=0.9)
        coh.set_ylim(0, 1.05)
        coh.set_ylabel("coherence [1]")
        coh.set_xlabel("frequency f [Hz]")
        coh.grid(True, alpha=0.25)
        if band is not None:
            mag.set_xlim(band[0], band[1])  # a peak marker outside the band must not squeeze it
        if k == 0:
            mag.legend(fontsize=7)
    return fig


def _mode_groups(results: Results, prefix: str) -> list[str]:
    groups = [g for g in results.groups if g.startswith(prefix) and g[len(prefix):].isdigit()]
    return sorted(groups, key=lambda g: int(g[len(prefix):]))


def _validation_rows(results: Results) -> dict[int, int]:
    """Row of the validation table of each mode number."""
    if "validation/mode" not in results.datasets:
        return {}
    return {int(m): i for i, m in enumerate(results.array("validation/mode"))}


def plot_free_decays(results: Results) -> Figure:
    """Free decay of each mode's modal coordinate after release from its shape, with the located
    extrema and the fitted exponential envelope; estimated vs model damped frequency and damping in
    each title.

    Parameters
    ----------
    results : Results
        Needs groups ``/validation/decay/mode_<r>`` (``t``, ``eta``, ``extrema_t``,
        ``extrema_value``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    groups = _mode_groups(results, "validation/decay/mode_")
    if not groups:
        raise InputError("results", "free decays under /validation/decay", Plain("none"))
    rows = _validation_rows(results)
    n = len(groups)
    columns, grid = _panel_grid(n)
    fig = Figure(figsize=(5.0 * columns, 3.6 * grid))
    fig.suptitle(_title(results, "free decay from each mode shape: modal coordinate eta_r = phi_r' M q"),
                 fontsize=12)
    _margins(fig, left=0.8, right=0.15, top=0.6, bottom=0.5, wspace=0.9, hspace=0.95, columns=columns, rows=grid)
    axes = np.atleast_1d(fig.subplots(grid, columns, squeeze=False).ravel())
    for ax, group in zip(axes, groups):
        attrs = results.attrs[group]
        mode = int(attrs["mode"])
        t, eta = results.array(f"{group}/t"), results.array(f"{group}/eta")
        _plot_long(ax, t, eta, color="tab:blue", linewidth=1.0)
        te, ve = results.array(f"{group}/extrema_t"), results.array(f"{group}/extrema_value")
        ax.plot(te, ve, "o", color="tab:red", markersize=3, label="extrema")
        if len(te) and "zeta" in attrs:
            omega_d = 2 * np.pi * attrs["f_damped_hz"]
            sigma = attrs["zeta"] * omega_d / np.sqrt(1.0 - attrs["zeta"] ** 2)
            amplitude = np.exp(np.mean(np.log(np.abs(ve)) + sigma * te))
            for sign in (-1, 1):
                _plot_long(ax, t, sign * amplitude * np.exp(-sigma * t), color="black", linestyle="--",
                           linewidth=0.8, label="fitted envelope" if sign > 0 else None)
        title = f"mode {mode}: f_d {attrs.get('f_damped_hz', np.nan):.5g} Hz, zeta {attrs.get('zeta', np.nan):.4f}"
        if mode in rows:
            i = rows[mode]
            title += (f"\nmodel: f_d {results.array('validation/f_damped_model_hz')[i]:.5g} Hz, "
                      f"zeta {results.array('validation/zeta_model')[i]:.4f}")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("time t [s]")
        ax.set_ylabel(f"eta_{mode} [kg^1/2 m]")
        ax.grid(True, alpha=0.3)
        ax.set_xlim(t[0], t[-1])
    axes[0].legend(fontsize=7, loc="upper right")
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig


# ----------------------------------------------------------------------------------------------------
# Everything at once.
# ----------------------------------------------------------------------------------------------------

#: File name, function and the datasets each figure needs (drawn only when present).
FIGURES: tuple[tuple[str, Callable[[Results], Figure], tuple[str, ...]], ...] = (
    ("mode_shapes.png", plot_mode_shapes, ("modal/shapes",)),
    ("ke_distribution.png", plot_ke_distribution, ("modal/ke_distribution",)),
    ("time_dofs.png", plot_time_histories, ("time/q",)),
    ("mount_forces.png", plot_mount_forces, ("time/mount_force",)),
    ("superposition.png", plot_superposition, ("time/superposition/q",)),
    ("bode.png", plot_bode, ("frf/receptance",)),
    ("point_frfs.png", plot_point_frfs, ("frf/f_hz",)),
    ("validation_frf.png", plot_validation_frf, ("validation/mode",)),
    ("free_decays.png", plot_free_decays, ("validation/mode",)),
)


def save_all(results: Results, directory: str | Path, dpi: int = DPI) -> list[Path]:
    """Draw every figure the results hold data for and write each as a PNG in ``directory``.

    Parameters
    ----------
    results : Results
        From :func:`sixdof.io.store.write_results` (live run) or :func:`sixdof.io.store.load_results`.
    directory : str or pathlib.Path
        Created when missing.
    dpi : int
        Resolution of the PNG files [dots per inch].

    Returns
    -------
    list of pathlib.Path
        The files written, in the order of :data:`FIGURES`.
    """
    _require(results)
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name, draw, needs in FIGURES:
        drawable = all(p in results.datasets for p in needs) and (
            (draw is not plot_point_frfs or _point_items(results))
            and (draw is not plot_free_decays or _mode_groups(results, "validation/decay/mode_"))
            and (draw is not plot_validation_frf or _mode_groups(results, "validation/random/mode_"))
        )
        if drawable:
            path = directory / name
            # One draw per figure (no layout engine), fast zlib: see PNG_COMPRESS_LEVEL.
            draw(results).savefig(path, dpi=dpi, pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
            written.append(path)
    return written
