"""Mode shapes (the body as a box on its mounts) and the kinetic-energy distribution of each mode."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from sixdof.dofs import DOFS
from sixdof.model.modes import Modes
from sixdof.model.system import System
from sixdof.plots.common import distinct_digits, margins, panel_grid, require, title

#: Largest displacement of the drawn body in a mode-shape panel, as a fraction of its largest size.
MODE_SCALE = 0.15
#: Largest rotation drawn in a mode-shape panel [rad]: larger ones stop reading as small rotations.
MAX_DRAWN_ROTATION = 0.3
#: Length of the mount axes drawn for inclined mounts, as a fraction of the body's largest side.
AXIS_LENGTH = 0.12
#: A box side is drawn at least this fraction of the largest side (a 40 m beam 1.2 m wide stays 3-D).
MIN_ASPECT = 0.2
#: Side of the fallback body box along an axis where every mount lies in a plane through the CG, as
#: a fraction of the largest side.
FLAT_SIDE = 0.1
#: Mounts closer than this, as a fraction of the drawn span along each axis (a bridge's pair of bearings 0.39 m
#: apart on a 40 m beam, 0.03), are drawn at one place: they get one label ("1, 2"), one would hide the other.
SAME_PLACE = 0.06

_MODES = "a sixdof.model.modes.Modes"


def body_box(system: System | None) -> np.ndarray:
    """Size [Lx, Ly, Lz] of the box drawn for the body [m], centred on the CG.

    The body's ``dimensions`` when given; otherwise the box reaching the mounts (symmetric about
    the CG) or the uniform box of the body's inertia (:attr:`~sixdof.model.parts.RigidBody.inertia_box`),
    whichever is larger along each axis; a side of zero length is made :data:`FLAT_SIDE` of the largest.
    Without a system: a 1 m cube.

    Parameters
    ----------
    system : sixdof.model.system.System or None

    Returns
    -------
    numpy.ndarray
        Shape (3,) [m].
    """
    if system is None:
        return np.ones(3)
    require(system, "system", System, "a sixdof.model.system.System (or None)")
    if system.body.dimensions is not None:
        return np.asarray(system.body.dimensions, dtype=float)
    positions = system.positions
    reach = 2.0 * np.max(np.abs(positions), axis=0) if len(positions) else np.zeros(3)
    # Mounts in a plane through the CG, or one mount under it, reach no side: the inertia gives the body its size.
    size = np.maximum(reach, system.body.inertia_box)
    largest = float(np.max(size)) or 1.0
    return np.where(size <= 1e-9 * largest, FLAT_SIDE * largest, size)


def drawn_mode(points: np.ndarray, shape: np.ndarray, largest: float) -> np.ndarray:
    """Positions (n, 3) [m] of body points in a mode shape scaled to be visible.

    The shape is scaled so that the largest point displacement is :data:`MODE_SCALE` of the body's
    largest size, but its rotation no more than :data:`MAX_DRAWN_ROTATION`; the rotation is drawn
    as a finite rotation so that the box stays a box (the small-rotation map would stretch it).

    Parameters
    ----------
    points : numpy.ndarray
        Body points (n, 3) [m] from the CG at rest.
    shape : numpy.ndarray
        Mode shape (6,) [any scale].
    largest : float
        The body's largest size [m].
    """
    q = mode_scale(points, shape, largest) * np.asarray(shape, dtype=float)
    return q[:3] + points @ finite_rotation(q[3:]).T


def finite_rotation(rotation: np.ndarray) -> np.ndarray:
    """The rotation matrix (3, 3) of a rotation vector [rad] (Rodrigues' formula): by its length about its
    direction."""
    angle = float(np.linalg.norm(rotation))
    if angle == 0.0:
        return np.eye(3)
    x, y, z = np.asarray(rotation, dtype=float) / angle
    cross = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])  # cross @ p is axis x p
    return np.eye(3) + np.sin(angle) * cross + (1.0 - np.cos(angle)) * cross @ cross


def mode_scale(points: np.ndarray, shape: np.ndarray, largest: float) -> float:
    """The factor :func:`drawn_mode` multiplies ``shape`` by (0 for a zero shape): the largest point
    displacement :data:`MODE_SCALE` of ``largest`` [m], the rotation at most :data:`MAX_DRAWN_ROTATION`."""
    shape = np.asarray(shape, dtype=float)
    peak = float(np.max(np.linalg.norm(shape[:3] + np.cross(shape[3:], points), axis=1)))  # small-rotation map
    if peak == 0.0:
        return 0.0
    scale = MODE_SCALE * largest / peak
    rotation = float(np.linalg.norm(shape[3:]))
    return MAX_DRAWN_ROTATION / rotation if rotation * scale > MAX_DRAWN_ROTATION else scale


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


def plot_mode_shapes(modes: Modes, system: System | None = None, *, name: str = "") -> Figure:
    """The body (a box) on its mounts, undeformed and deformed in each mode, one panel per mode.

    Each mode shape is scaled so that the largest displacement of a box corner or mount is
    :data:`MODE_SCALE` of the box's largest side (rotations at most :data:`MAX_DRAWN_ROTATION`,
    drawn as finite rotations); each panel gives the factor the mass-normalized shape is drawn at. Light
    grey is the rest position, colour the deformed body; triangles mark the mounts' ground side (named; mounts
    drawn at one place, within :data:`SAME_PLACE`, share a label: "1, 2"), dots their body side; inclined mounts
    show their w axis.

    Parameters
    ----------
    modes : sixdof.model.modes.Modes
        Natural frequencies [Hz], mass-normalized shapes (6, n_modes), dominant DOFs and
        kinetic-energy shares.
    system : sixdof.model.system.System, optional
        Gives the mounts (names, positions [m] from the CG) and the box (:func:`body_box`); without
        it a 1 m cube is drawn and no mounts.
    name : str
        Name of the run, put before the title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    require(modes, "modes", Modes, _MODES)
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: PLC0415 (3-D axes, only for the mode shapes)

    freqs = modes.frequency_hz
    digits = distinct_digits(freqs, 4)
    dominant = modes.dominant_dof
    size = body_box(system)
    # The box's corners [m] about the CG and its six faces (corner indices).
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float) * size / 2
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    mounts = np.zeros((0, 3)) if system is None else system.positions
    names = () if system is None else system.mount_names
    points = np.vstack([corners, mounts])
    largest = float(np.max(size))

    drawn = [drawn_mode(points, shape, largest) for shape in modes.shapes.T]
    scales = [mode_scale(points, shape, largest) for shape in modes.shapes.T]
    inclined = system is not None and not np.allclose(system.axes, np.eye(3))
    columns, rows = panel_grid(len(drawn))
    fig = Figure(figsize=(5.0 * columns, 4.6 * rows + 0.4))
    fig.suptitle(title(name, "mode shapes (displacements scaled for visibility)"), fontsize=13)
    margins(fig, left=0.1, right=0.1, top=1.15, bottom=0.15, wspace=0.2, hspace=0.95, columns=columns, rows=rows)
    # One set of limits for every panel, equal scales on the three axes (nothing distorted) except
    # that MIN_ASPECT keeps slender bodies visible.
    reach = 1.05 * np.max(np.abs(np.concatenate([points, *drawn])), axis=0)
    aspect = np.maximum(reach, MIN_ASPECT * float(np.max(reach)))
    labelled = same_place(mounts / (2.0 * aspect))
    for j, moved in enumerate(drawn):
        ax = fig.add_subplot(rows, columns, j + 1, projection="3d")
        # Artists drawn in their zorder, not sorted by depth: the box's faces (each collection still orders
        # its own) under the mounts, and the mounts' names over everything, never crossed by an edge.
        ax.computed_zorder = False
        ax.add_collection3d(Poly3DCollection([corners[f] for f in faces], facecolors=(0.6, 0.6, 0.6, 0.06),
                                             edgecolors=(0.5, 0.5, 0.5, 0.6), linewidths=0.7, linestyles="--"))
        ax.add_collection3d(Poly3DCollection([moved[:8][f] for f in faces], facecolors=(0.12, 0.47, 0.71, 0.25),
                                             edgecolors=(0.05, 0.25, 0.45, 1.0), linewidths=1.2))
        if len(mounts):
            ax.scatter(*mounts.T, marker="^", s=45, color="black", depthshade=False, label="mount (ground side)")
            body_side = moved[8:]
            ax.scatter(*body_side.T, marker="o", s=22, color="tab:red", depthshade=False, label="mount (body side)")
            for a, b in zip(mounts, body_side):
                ax.plot(*np.stack([a, b]).T, color="tab:red", linewidth=1.0)
            for group in labelled:  # below the ground side, on white: clear of markers and edges
                p = np.mean(mounts[group], axis=0)
                ax.text(p[0], p[1], p[2] - 0.04 * largest, ", ".join(names[k] for k in group), fontsize=7,
                        color="black", ha="center", va="top",
                        bbox={"facecolor": "white", "alpha": 0.8, "pad": 0.6, "linewidth": 0}, zorder=10)
            if inclined:  # each mount's w axis (its normal direction), from its ground side
                for p, w in zip(mounts, system.axes[:, 2]):
                    ax.plot(*np.stack([p, p + AXIS_LENGTH * largest * w]).T, color="black", linewidth=1.3)
            if j == 0:
                if inclined:
                    ax.plot([], [], color="black", linewidth=1.3, label="mount w axis")
                ax.legend(loc="upper left", fontsize=7, frameon=False)
        for axis, label in enumerate("xyz"):
            getattr(ax, f"set_{label}lim")(-aspect[axis], aspect[axis])
            # y's label further out: the middle tick ("0") of the receding axis otherwise lands on it
            getattr(ax, f"set_{label}label")(f"{label} [m]", labelpad={"x": 1, "y": 6, "z": 4}[label])
        # matplotlib normalizes the array it is given in place
        ax.set_box_aspect(aspect.copy(), zoom=_panel_zoom(aspect, ax.elev, ax.azim))
        ax.tick_params(labelsize=7, pad=2)  # pad 0 puts a tick mark over a label's minus sign
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(MaxNLocator(4, symmetric=True))
        share = f" ({100 * modes.ke_distribution[DOFS.index(dominant[j]), j]:.0f} % KE)"
        frequency = "rigid-body mode (0 Hz)" if freqs[j] == 0 else f"{freqs[j]:.{digits}g} Hz"
        shape = scales[j] * modes.shapes[:, j]
        moved_by = float(np.max(np.linalg.norm(shape[:3] + np.cross(shape[3:], points), axis=1)))
        turned = float(np.degrees(np.linalg.norm(shape[3:])))
        turned = turned if turned >= 0.01 else 0.0  # a translation's round-off rotation (1e-15 deg) is none
        ax.set_title(f"Mode {j + 1}: {frequency}\ndominant {dominant[j]}{share}\n"
                     f"drawn: {moved_by:.2g} m, {turned:.2g}° (mass-normalized shape × {scales[j]:.3g})", fontsize=10)
        # At the axes' top, clear of the legend: 3-D axes lower a title to 0.92 of their height, which only
        # matplotlib's automatic placement (off in sixdof.plots.render) raises again at each draw.
        ax.title.set_y(1.0)
    return fig


def same_place(points: np.ndarray, within: float = SAME_PLACE) -> list[list[int]]:
    """Indices of ``points`` (n, 3) grouped by place: each joins the first group whose first point is within
    ``within`` of it (same unit as ``points``), in order."""
    groups: list[list[int]] = []
    for k, p in enumerate(points):
        group = next((g for g in groups if np.linalg.norm(points[g[0]] - p) < within), None)
        if group is None:
            groups.append([k])
        else:
            group.append(k)
    return groups


def plot_ke_distribution(modes: Modes, ax=None, *, name: str = "") -> Figure:
    """Heatmap of each mode's kinetic-energy distribution over the DOFs, in percent.

    Parameters
    ----------
    modes : sixdof.model.modes.Modes
        Kinetic-energy shares (6, n_modes) [1] and natural frequencies [Hz].
    ax : matplotlib.axes.Axes, optional
        Draw into these axes (the colour bar is taken from them); default: a new figure.
    name : str
        Name of the run, put before the title.

    Returns
    -------
    matplotlib.figure.Figure
        The new figure, or the one holding ``ax``.
    """
    require(modes, "modes", Modes, _MODES)
    percent = 100.0 * np.asarray(modes.ke_distribution)
    freqs = modes.frequency_hz
    n = percent.shape[1]
    if ax is None:
        fig = Figure(figsize=(1.2 * n + 2.6, 5.0))
        margins(fig, left=0.75, right=0.1, top=0.35, bottom=0.85)
        ax = fig.add_subplot()
    fig = ax.figure
    image = ax.imshow(percent, cmap="Blues", vmin=0.0, vmax=100.0, aspect="auto")
    for (i, j), value in np.ndenumerate(percent):
        # Round-off leaves shares like -1e-15: print them as 0, not "-0".
        # One decimal throughout, so that a column visibly adds up to 100 (93.5 and 6.5, not 93 and 6.5).
        text = "0.0" if abs(value) < 0.05 else f"{value:.1f}"
        ax.text(j, i, text, ha="center", va="center", fontsize=10, color="white" if value > 60 else "black")
    digits = distinct_digits(freqs, 3)
    ax.set_xticks(range(n), [f"{j + 1}\n{f:.{digits}g}" for j, f in enumerate(freqs)])  # close modes told apart
    ax.set_yticks(range(len(DOFS)), DOFS)
    ax.set_xlabel("mode (natural frequency [Hz])")
    ax.set_ylabel("degree of freedom")
    ax.set_title(title(name, "kinetic-energy distribution [%]"))
    fig.colorbar(image, ax=ax, label="share of the mode's kinetic energy [%]")
    return fig
