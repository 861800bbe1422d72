"""Mode shapes (the body as a box on its mounts) and the kinetic-energy distribution of each mode."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from sixdof.dofs import DOFS, distinct_digits
from sixdof.errors import InputError
from sixdof.model.modes import Modes
from sixdof.model.system import System
from sixdof.plots import FIXED_TITLES
from sixdof.plots.common import DOF_NAMES, margins, name_apart, name_line, require

#: Largest displacement of the drawn body in a mode-shape panel, as a fraction of its largest size.
MODE_SCALE = 0.15
#: Largest rotation drawn in a mode-shape panel [rad]: larger ones stop reading as small rotations.
MAX_DRAWN_ROTATION = 0.3
#: A mode whose drawn motion, in the view of the whole body, stays below this fraction of the body's largest
#: size cannot be seen there (a slender beam rolling about its length: 17 degrees move the corners of its 1.2 x 2 m
#: section 0.35 m, 0.9 % of its 40 m); its panel looks end-on along the rotation's axis instead.
VISIBLE = 0.05
#: Length of the mount axes drawn for inclined mounts, as a fraction of the body's largest side (in view).
AXIS_LENGTH = 0.12
#: A box side is drawn at least this fraction of the largest side (a 40 m beam 1.2 m wide stays 3-D).
MIN_ASPECT = 0.2
#: Side of the fallback body box along an axis where every mount lies in a plane through the CG, as
#: a fraction of the largest side.
FLAT_SIDE = 0.1
#: Mounts closer than this, as a fraction of the drawn span along each axis (a bridge's pair of bearings 0.39 m
#: apart on a 40 m beam, 0.03), are drawn at one place: they get one label ("1, 2"), one would hide the other.
SAME_PLACE = 0.06
#: Columns of the mode-shape panels (one for a single mode), and each panel's cell [inch]: width, and height
#: with its title.
COLUMNS = 2
PANEL = (5.0, 5.3)
#: Fraction of a panel's axes the drawn box spans at most (the rest holds the tick labels).
FILL = 0.84
#: View (elevation, azimuth) [deg] along each body axis for the end-on panels: right-handed, the vertical up.
END_VIEWS = {0: (0.0, 0.0), 1: (0.0, -90.0), 2: (90.0, -90.0)}

_MODES = "a sixdof.model.modes.Modes"
# The box's corners (signs, in units of half its sides) and its six faces (corner indices).
_CORNERS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
_FACES = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]


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


def dof_words(system: System | None) -> tuple[str, ...]:
    """Each DOF in words, in :data:`~sixdof.dofs.DOFS` order, from the body's axes: the vertical (gravity's axis
    when the system carries it, else z) bounces and yaws, the longer horizontal side of :func:`body_box` is
    the longitudinal axis (rolled about), the other the lateral one (pitched about); equal sides: the first."""
    up = 2 if system is None or system.gravity_preload is None else int(np.argmax(np.abs(system.gravity_preload)))
    size = body_box(system)
    first, second = (a for a in range(3) if a != up)
    along, across = (second, first) if size[second] > 1.01 * size[first] else (first, second)
    axis = "xyz"
    moves = {up: "vertical bounce along", along: "longitudinal motion along", across: "lateral motion along"}
    turns = {up: "yaw about", along: "roll about", across: "pitch about"}
    return (*(f"{moves[a]} {axis[a]}" for a in range(3)), *(f"{turns[a]} {axis[a]}" for a in range(3)))


def mode_words(modes: Modes, j: int, words: tuple[str, ...]) -> str:
    """Mode ``j``'s dominant DOF in ``words`` with its share of the kinetic energy: "mostly roll about y (96 % of
    kinetic energy)"; under half, the two largest shares ("coupled: ... 48 % and ... 40 % of kinetic energy")."""
    share = np.asarray(modes.ke_distribution)[:, j]
    first = DOFS.index(modes.dominant_dof[j])
    if share[first] >= 0.5:
        return f"mostly {words[first]} ({100 * share[first]:.0f} % of kinetic energy)"
    second = next(i for i in np.argsort(share)[::-1] if i != first)
    return (f"coupled: {words[first]} {100 * share[first]:.0f} %\nand {words[second]} {100 * share[second]:.0f} % "
            "of kinetic energy")


def drawn_mode(points: np.ndarray, shape: np.ndarray, largest: float, plane=(0, 1, 2)) -> np.ndarray:
    """Positions (n, 3) [m] of body points in a mode shape scaled to be visible.

    The shape is scaled by :func:`mode_scale` (its largest point displacement :data:`MODE_SCALE` of
    ``largest``, its rotation at most :data:`MAX_DRAWN_ROTATION`); the rotation is drawn as a finite rotation so
    that the box stays a box (the small-rotation map would stretch it).

    Parameters
    ----------
    points : numpy.ndarray
        Body points (n, 3) [m] from the CG at rest.
    shape : numpy.ndarray
        Mode shape (6,) [any scale].
    largest : float
        Size [m] the drawn displacement is measured against: the body's largest side, or its section's.
    plane : sequence of int
        The body axes whose displacement components count (those of the view).
    """
    q = mode_scale(points, shape, largest, plane) * np.asarray(shape, dtype=float)
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


def mode_scale(points: np.ndarray, shape: np.ndarray, largest: float, plane=(0, 1, 2)) -> float:
    """The factor :func:`drawn_mode` multiplies ``shape`` by (0 for a zero shape): the largest point
    displacement (its components along ``plane``) :data:`MODE_SCALE` of ``largest`` [m], the rotation at most
    :data:`MAX_DRAWN_ROTATION`."""
    peak = peak_motion(points, shape, plane)
    if peak == 0.0:
        return 0.0
    scale = MODE_SCALE * largest / peak
    rotation = float(np.linalg.norm(np.asarray(shape, dtype=float)[3:]))
    return MAX_DRAWN_ROTATION / rotation if rotation * scale > MAX_DRAWN_ROTATION else scale


def peak_motion(points: np.ndarray, q: np.ndarray, plane=(0, 1, 2)) -> float:
    """Largest displacement [m] of ``points`` (n, 3) [m] under the small motion ``q`` (6,) [m, rad], its components
    along ``plane`` only."""
    q = np.asarray(q, dtype=float)
    moved = q[:3] + np.cross(q[3:], points)  # small-rotation map
    return float(np.max(np.linalg.norm(moved[:, list(plane)], axis=1)))


def end_view_axis(points: np.ndarray, shape: np.ndarray, largest: float) -> int | None:
    """The body axis a mode's panel looks along: ``None`` (the whole body, obliquely) unless its drawn motion there
    stays below :data:`VISIBLE` of ``largest`` [m]; then the axis nearest its rotation's."""
    shape = np.asarray(shape, dtype=float)
    scale = mode_scale(points, shape, largest)
    if scale == 0.0 or peak_motion(points, scale * shape) >= VISIBLE * largest:
        return None
    return int(np.argmax(np.abs(shape[3:])))


@dataclass(frozen=True)
class _Scene:
    """What every panel draws: the box, the mounts (names, positions and w axes [m]) and the DOFs in words."""

    size: np.ndarray
    corners: np.ndarray
    mounts: np.ndarray
    names: tuple[str, ...]
    w_axes: np.ndarray | None  # None: every mount along the body axes
    words: tuple[str, ...]

    @classmethod
    def of(cls, system: System | None) -> _Scene:
        size = body_box(system)
        mounts = np.zeros((0, 3)) if system is None else system.positions
        inclined = system is not None and not np.allclose(system.axes, np.eye(3))
        return cls(size, _CORNERS * size / 2, mounts, () if system is None else system.mount_names,
                   system.axes[:, 2] if inclined else None, dof_words(system))

    @property
    def points(self) -> np.ndarray:
        return np.vstack([self.corners, self.mounts])


@dataclass(frozen=True)
class _View:
    """One panel's view: along a body axis (``None``: the whole body, obliquely), the body axes of its picture,
    the size [m] the drawn motion is measured against, and the half-spans [m] of its three axes."""

    along: int | None
    plane: tuple[int, ...]
    largest: float
    reach: np.ndarray

    def scale(self, scene: _Scene, shape: np.ndarray) -> float:
        return mode_scale(scene.points, shape, self.largest, self.plane)

    def moved(self, scene: _Scene, shape: np.ndarray) -> np.ndarray:
        return drawn_mode(scene.points, shape, self.largest, self.plane)


def _views(scene: _Scene, shapes: np.ndarray) -> list[_View]:
    """Each mode's :class:`_View`: the whole-body panels share their limits (one scale for the body in all of
    them); an end-on panel's limits fit the body's section and its motion."""
    points, largest = scene.points, float(np.max(scene.size))
    along = [end_view_axis(points, shape, largest) for shape in shapes.T]
    whole = [drawn_mode(points, shape, largest) for shape, a in zip(shapes.T, along) if a is None]
    reach = 1.05 * np.max(np.abs(np.concatenate([points, *whole])), axis=0)
    shared = np.maximum(reach, MIN_ASPECT * float(np.max(reach)))
    views = []
    for shape, a in zip(shapes.T, along):
        if a is None:
            views.append(_View(None, (0, 1, 2), largest, shared))
            continue
        plane = tuple(i for i in range(3) if i != a)
        section = float(np.max(scene.size[list(plane)]))
        moved = drawn_mode(points, shape, section, plane)
        end = 1.15 * np.max(np.abs(np.concatenate([points, moved])), axis=0)  # room for the names below
        end[list(plane)] = np.maximum(end[list(plane)], MIN_ASPECT * float(np.max(end[list(plane)])))
        views.append(_View(a, plane, section, end))
    return views


def plot_mode_shapes(modes: Modes, system: System | None = None, *, fig=None, name: str = "") -> Figure:
    """The body (a box) on its mounts at rest and deformed in each mode, one 3-D panel per mode.

    Each panel's title gives the natural frequency, the mode's dominant DOF in words (:func:`dof_words`: vertical
    bounce, lateral, longitudinal, roll, pitch, yaw, with the body axis) with its share of the kinetic energy (the
    decoupling), and the scale the shape is drawn at in words. A mode shape has no amplitude of its own: each is
    scaled so that the largest displacement of a box corner or mount is :data:`MODE_SCALE` of the box's largest
    side, its rotation at most :data:`MAX_DRAWN_ROTATION` (drawn as a finite rotation: the box stays a box). The
    panels of the whole body share one set of limits, equal scales on the three axes (nothing distorted). A mode
    whose drawn motion there stays below :data:`VISIBLE` of the body's size (a slender beam rolling about its length) is
    seen end-on instead, along the body axis nearest its rotation, orthographically and again to equal scales, its
    largest in-view displacement :data:`MODE_SCALE` of the section's larger side: the rotation shows at its true
    shape. Light grey dashed is the rest position, blue the deformed body; triangles mark the mounts' ground side
    (named; mounts drawn at one place, within :data:`SAME_PLACE`, share a label: "1, 2"), red dots their body
    side, a red line the mount's deflection; inclined mounts show their w axis (black, from the ground side).

    Parameters
    ----------
    modes : sixdof.model.modes.Modes
        Natural frequencies [Hz], mass-normalized shapes (6, n_modes), dominant DOFs and
        kinetic-energy shares.
    system : sixdof.model.system.System, optional
        Gives the mounts (names, positions [m] from the CG, axes) and the box (:func:`body_box`); without
        it a 1 m cube is drawn and no mounts.
    fig : matplotlib.figure.Figure or matplotlib.figure.SubFigure, optional
        Draw into this figure: one 3-D panel per mode in a grid of :data:`COLUMNS` columns (one for a single
        mode), mode 1 top left, row by row, under a one-row key at its top; its title and size are left as they
        are. Default: a new figure, :data:`PANEL` inches a panel.
    name : str
        Name of the run, put before the title (new figure only).

    Returns
    -------
    matplotlib.figure.Figure
        The new figure, or the one holding ``fig``.
    """
    require(modes, "modes", Modes, _MODES)
    scene = _Scene.of(system)
    shapes = np.asarray(modes.shapes, dtype=float)
    n = shapes.shape[1]
    columns = 1 if n == 1 else COLUMNS
    rows = -(-n // columns)
    views = _views(scene, shapes)
    digits = distinct_digits(modes.frequency_hz, 4)
    titles = [_mode_title(modes, j, digits, scene, view) for j, view in enumerate(views)]
    lines = [t.count("\n") + 1 for t in titles]  # 3, or 4 for a coupled mode or an end-on view
    new, apart = fig is None, 0.0  # apart: a long name's own line above a new figure [in]
    if new:
        # Room above each row for its longest title (0.18 inch a line), under the title and key for the first.
        first, longest = max(lines[:columns]), max(lines)
        heading = "mode shapes (each drawn to its own scale)"
        apart = 0.22 * name_apart(name, heading, PANEL[0] * columns, 13)
        extra = 0.18 * (first - 3 + (longest - 3) * (rows - 1)) + apart  # beyond three lines a title
        fig = Figure(figsize=(PANEL[0] * columns, PANEL[1] * rows + 0.75 + extra))
        fig.suptitle(name_line(name, heading, PANEL[0] * columns, 13), fontsize=13)
        grid = fig.add_gridspec(rows, columns)
        margins(fig, left=0.3, right=0.2, top=1.06 + 0.18 * first + apart, bottom=0.25, wspace=0.4,
                hspace=0.56 + 0.18 * longest, columns=columns, rows=rows, target=grid)
    else:
        grid = fig.add_gridspec(rows, columns, left=0.05, right=0.97, top=0.85, bottom=0.04, wspace=0.08,
                                hspace=0.3)
    for j, view in enumerate(views):
        ax = fig.add_subplot(grid[j // columns, j % columns], projection="3d")
        _draw_mode(ax, scene, shapes[:, j], view)
        ax.set_title(titles[j], fontsize=10.5)
        # At the axes' top: 3-D axes lower a title to 0.92 of their height, which only matplotlib's automatic
        # placement (off in sixdof.plots.render) raises again at each draw.
        ax.title.set_y(1.0)
    _legend(fig, scene, 1.0 - (0.62 + apart) / fig.get_size_inches()[1] if new else 0.99)
    return fig.get_figure(root=True)


#: Frames of one period of a mode's animation (:func:`write_mode_animations`), and their rate [1/s].
ANIMATION_FRAMES = 24
ANIMATION_FPS = 12
#: Resolution of the animations [dots per inch]: one :data:`PANEL` is 400 x 424 pixels.
ANIMATION_DPI = 80


def write_mode_animations(modes: Modes, system: System | None, folder, *, frames: int | None = None) -> list:
    """Each mode as an animated GIF, ``mode_1.gif``, ``mode_2.gif``... in ``folder``: the panel of
    :func:`plot_mode_shapes` (same view, scale and title) with the body oscillating through one period,
    ``q(t) = sin(2 pi t / T) x`` the drawn shape, looping (:data:`ANIMATION_FRAMES` frames at
    :data:`ANIMATION_FPS` a second, written by matplotlib's ``PillowWriter``).

    Parameters
    ----------
    modes : sixdof.model.modes.Modes
    system : sixdof.model.system.System or None
        As :func:`plot_mode_shapes`'s.
    folder : str or pathlib.Path
        An existing folder; files of these names there are replaced.
    frames : int, optional
        Frames of one period (at least 2); default :data:`ANIMATION_FRAMES`.

    Returns
    -------
    list of pathlib.Path
        The files written, in mode order.
    """
    require(modes, "modes", Modes, _MODES)
    frames = ANIMATION_FRAMES if frames is None else frames
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 2:
        raise InputError("frames", "an integer number of frames per period, at least 2", frames)
    scene = _Scene.of(system)
    shapes = np.asarray(modes.shapes, dtype=float)
    with matplotlib.rc_context(FIXED_TITLES):  # as every figure file (sixdof.plots.render)
        return [_animate(modes, j, scene, view, Path(folder) / f"mode_{j + 1}.gif", frames)
                for j, view in enumerate(_views(scene, shapes))]


def _animate(modes: Modes, j: int, scene: _Scene, view: _View, path, frames: int):
    """Mode ``j`` drawn in ``view`` through one period into the GIF ``path``; the path."""
    from matplotlib.animation import PillowWriter  # noqa: PLC0415 (matplotlib's animation: only when writing)

    shape = np.asarray(modes.shapes[:, j], dtype=float)
    fig = Figure(figsize=PANEL)
    ax = fig.add_subplot(projection="3d")
    text = _mode_title(modes, j, distinct_digits(modes.frequency_hz, 4), scene, view)
    margins(fig, left=0.3, right=0.2, top=0.85 + 0.18 * (text.count("\n") + 1), bottom=0.25)  # the key, the title
    artists = _draw_mode(ax, scene, shape, view)
    _legend(fig, scene, 0.99, columns=2)
    ax.set_title(text, fontsize=10)
    ax.title.set_y(1.0)
    drawn = view.scale(scene, shape) * shape
    writer = PillowWriter(fps=ANIMATION_FPS)
    with writer.saving(fig, path, ANIMATION_DPI):
        for k in range(frames):
            for artist in artists:
                artist.remove()
            q = np.sin(2.0 * np.pi * k / frames) * drawn
            artists = _draw_moved(ax, scene, q[:3] + scene.points @ finite_rotation(q[3:]).T)
            writer.grab_frame()
    return path


def _mode_title(modes: Modes, j: int, digits: int, scene: _Scene, view: _View) -> str:
    """Mode ``j``'s panel title: its frequency, dominant motion with its share of kinetic energy, and the scale."""
    f = modes.frequency_hz[j]
    frequency = "rigid-body mode (0 Hz)" if f == 0 else f"{f:.{digits}g} Hz"
    return (f"Mode {j + 1}: {frequency}\n{mode_words(modes, j, scene.words)}\n"
            f"{_scale_words(scene, modes.shapes[:, j], view)}")


def _rotation_axis(rotation: np.ndarray) -> str:
    """The axis of a rotation vector in words: the body axis it lies within 25° of ("y": a long beam's roll,
    which its thin section hides in the drawing), else its direction."""
    axis = rotation / np.linalg.norm(rotation)
    k = int(np.argmax(np.abs(axis)))
    if abs(axis[k]) >= np.cos(np.radians(25.0)):
        return "xyz"[k]
    return "(" + ", ".join(f"{v:.2f}" for v in axis) + ")"


def _scale_words(scene: _Scene, shape: np.ndarray, view: _View) -> str:
    """The drawing scale of one panel in words: how large its largest motion is drawn, and its rotation."""
    q = view.scale(scene, shape) * shape
    peak = peak_motion(scene.points, q, view.plane)
    turned = float(np.degrees(np.linalg.norm(q[3:])))
    of = "body size" if view.along is None else "section"
    size = f"{100 * peak / view.largest:.2g} % of {of} ({view.largest:.3g} m)"
    words = f"drawn: largest motion {size}"
    rotates = turned >= 0.01  # a translation's round-off rotation (1e-15 deg) is none
    if view.along is not None:
        angle = f" {turned:.2g}°" if rotates else ""
        return f"seen end-on, along {'xyz'[view.along]}, the axis it is turned{angle} about\n{words}"
    # The turn on a line of its own: beside the scale, the line outgrows a panel and runs into the next one's.
    return f"{words}\nturned {turned:.2g}° about {_rotation_axis(q[3:])}" if rotates else words


def _legend(fig, scene: _Scene, top: float, columns: int | None = None) -> None:
    """The key to the panels at ``top`` (a fraction of ``fig``'s height), in ``columns`` (default: one row)."""
    from matplotlib.lines import Line2D  # noqa: PLC0415 (matplotlib: only when drawing)
    from matplotlib.patches import Patch  # noqa: PLC0415 (matplotlib: only when drawing)

    handles = [Patch(facecolor=(0.6, 0.6, 0.6, 0.1), edgecolor=(0.5, 0.5, 0.5), linestyle="--", label="at rest"),
               Patch(facecolor=(0.12, 0.47, 0.71, 0.3), edgecolor=(0.05, 0.25, 0.45), label="mode shape")]
    if len(scene.mounts):
        handles += [Line2D([], [], marker="^", color="black", linestyle="none", label="mount, ground side"),
                    Line2D([], [], marker="o", color="tab:red", label="mount, body side (line: deflection)")]
    if scene.w_axes is not None:
        handles.append(Line2D([], [], color="black", linewidth=1.3, label="mount w axis"))
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, top), ncol=columns or len(handles), fontsize=9,
               frameon=False, borderaxespad=0.0, columnspacing=1.2)


def _draw_mode(ax, scene: _Scene, shape: np.ndarray, view: _View) -> list:
    """One mode in ``ax`` (3-D axes): the box at rest and moved, the mounts, limits, view and zoom; the artists
    of the moved body (:func:`_draw_moved`)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: PLC0415 (3-D axes, only for the mode shapes)

    corners, mounts = scene.corners, scene.mounts
    size = view.largest
    # Artists drawn in their zorder, not sorted by depth: the box's faces (each collection still orders
    # its own) under the mounts, and the mounts' names over everything, never crossed by an edge.
    ax.computed_zorder = False
    ax.add_collection3d(Poly3DCollection([corners[f] for f in _FACES], facecolors=(0.6, 0.6, 0.6, 0.06),
                                         edgecolors=(0.5, 0.5, 0.5, 0.7), linewidths=0.8, linestyles="--"))
    moving = _draw_moved(ax, scene, view.moved(scene, shape))
    down = 1 if view.along == 2 else 2  # the body axis pointing up the panel
    if len(mounts):
        ax.scatter(*mounts.T, marker="^", s=55, color="black", depthshade=False, zorder=3)
        plane = list(view.plane)
        for group in same_place(mounts[:, plane] / (2.0 * view.reach[plane])):
            p = np.mean(mounts[group], axis=0)  # below the ground side, on white: clear of markers and edges
            p[down] -= 0.05 * size
            ax.text(*p, ", ".join(scene.names[k] for k in group), fontsize=8.5, color="black", ha="center",
                    va="top", bbox={"facecolor": "white", "alpha": 0.8, "pad": 0.6, "linewidth": 0}, zorder=10)
        if scene.w_axes is not None:  # each mount's w axis (its normal direction), from its ground side
            for p, w in zip(mounts, scene.w_axes):
                ax.plot(*np.stack([p, p + AXIS_LENGTH * size * w]).T, color="black", linewidth=1.3)
    aspect = view.reach.copy()
    for axis, label in enumerate("xyz"):
        getattr(ax, f"set_{label}lim")(-view.reach[axis], view.reach[axis])
        if axis in view.plane:
            # y's label further out: the middle tick ("0") of the receding axis otherwise lands on it
            getattr(ax, f"set_{label}label")(f"{label} [m]", labelpad={"x": 2, "y": 7, "z": 5}[label], fontsize=9)
            # fewer ticks on a short side: five on the cabinet's 1.2 m depth beside its 2 m height run together
            bins = max(2, round(4 * view.reach[axis] / float(np.max(view.reach[list(view.plane)]))))
            getattr(ax, f"{label}axis").set_major_locator(MaxNLocator(bins, symmetric=True))
        else:  # the line of sight of an end-on view: no extent on the picture, nor ticks
            getattr(ax, f"set_{label}ticks")([])
            aspect[axis] = 1e-3 * float(np.max(view.reach))
    ax.tick_params(labelsize=8, pad=4)  # a smaller pad puts a tick mark over a label's minus sign
    if view.along is not None:
        ax.view_init(*END_VIEWS[view.along])
        ax.set_proj_type("ortho")
    _fit(ax, aspect)
    return moving


def _draw_moved(ax, scene: _Scene, moved: np.ndarray) -> list:
    """The body at ``moved`` (its corners, then its mounts' body side [m]) in ``ax``: the box, the mounts' body
    side and their deflection from the ground side; the artists drawn."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: PLC0415 (3-D axes, only for the mode shapes)

    box = Poly3DCollection([moved[:8][f] for f in _FACES], facecolors=(0.12, 0.47, 0.71, 0.25),
                           edgecolors=(0.05, 0.25, 0.45, 1.0), linewidths=1.3, zorder=1)
    artists = [ax.add_collection3d(box)]
    if len(scene.mounts):
        body_side = moved[8:]
        artists.append(ax.scatter(*body_side.T, marker="o", s=28, color="tab:red", depthshade=False, zorder=4))
        for a, b in zip(scene.mounts, body_side):
            artists += ax.plot(*np.stack([a, b]).T, color="tab:red", linewidth=1.2, zorder=2)
    return artists


def _fit(ax, aspect: np.ndarray) -> None:
    """Equal scales on the axes (``aspect``: their half-spans), zoomed so that the box spans :data:`FILL` of the
    axes' width or height, whichever it reaches first (matplotlib scales every box to one diagonal: a long
    box or an end-on view would otherwise be drawn small)."""
    from mpl_toolkits.mplot3d import proj3d  # noqa: PLC0415 (3-D axes, only for the mode shapes)

    ax.set_box_aspect(aspect.copy())  # matplotlib normalizes the array it is given in place
    ax.apply_aspect()
    box = _CORNERS * [np.ptp(getattr(ax, f"get_{label}lim")()) / 2 for label in "xyz"]  # limits about 0
    x, y, _ = proj3d.proj_transform(*box.T, ax.get_proj())
    pixels = ax.transData.transform(np.column_stack([x, y]))
    spans = np.ptp(pixels, axis=0) / [ax.bbox.width, ax.bbox.height]
    ax.set_box_aspect(aspect.copy(), zoom=FILL / float(np.max(spans)))


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
    heading = "kinetic-energy distribution [%]"
    width = 1.2 * n + 3.7  # the DOFs' names at the left: 1.1 in
    if ax is None:
        apart = 0.22 * name_apart(name, heading, width, 12)  # a long name's own line [in]
        fig = Figure(figsize=(width, 5.0 + apart))
        margins(fig, left=1.85, right=0.1, top=0.35 + apart, bottom=0.85)
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
    ax.set_yticks(range(len(DOFS)), DOF_NAMES)
    ax.set_xlabel("mode (natural frequency [Hz])")
    ax.set_ylabel("degree of freedom")
    ax.set_title(name_line(name, heading, width, 12))
    fig.colorbar(image, ax=ax, label="share of the mode's kinetic energy [%]")
    return fig
