"""What every figure shares: display units, envelope decimation of long series, fixed margins, the
per-mode panel grid, titles, natural-frequency marks and input checks.

Only this package imports matplotlib, and never pyplot: figures are
:class:`matplotlib.figure.Figure` objects (see :mod:`sixdof.plots`).
"""

from __future__ import annotations

import struct
import zlib
from functools import partial

import matplotlib
import numpy as np
from matplotlib.axis import Ticker
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter, NullFormatter, NullLocator

from sixdof.errors import InputError, Plain
from sixdof.model.modes import Modes

#: Resolution of the PNG files [dots per inch] when the scenario does not set ``[output] dpi``.
DPI = 150
#: Most points drawn per line of a time history: longer ones are drawn through the minimum and
#: maximum of each of ``MAX_POINTS // 2`` equal slices (see :func:`envelope_indices`). A slice must
#: stay narrower than a pixel column for the drawn line to look exactly like the full one: 2000
#: slices cover axes up to 2000 px wide (13 inches at :data:`DPI`).
MAX_POINTS = 4000
#: zlib level of the PNG files: 1 writes several times faster than the default 6 for files about
#: a third larger (the figures are mostly flat colour, which compresses well at any level).
PNG_COMPRESS_LEVEL = 1

TRANSLATION = "tab:blue"
ROTATION = "tab:red"
COMPONENT_COLORS = ("tab:blue", "tab:orange", "tab:green")
# Every figure's words for the DOFs, loads and axes, from here: titles and labels in words with their units,
# never the internal codes (x, rx, Fz, dof_3) nor snake_case.
#: Each DOF in words, for titles and legends (``DOFS`` order: x, y, z, rx, ry, rz): the centre of gravity's
#: translations along the body axes and the small rotations about them.
DOF_NAMES = ("translation along x", "translation along y", "translation along z", "rotation about x",
             "rotation about y", "rotation about z")
#: Each DOF's direction alone, for the axis label of a panel whose title names the DOF (``"about x [mrad]"``).
DOF_DIRECTIONS = ("along x", "along y", "along z", "about x", "about y", "about z")
#: Tick label of the mode each DOF dominates, on two lines (``"translation\nalong x"``).
DOF_MODE_TICKS = tuple(name.replace(" ", "\n", 1) for name in DOF_NAMES)
#: Each generalized load in words (``LOADS`` order: Fx, Fy, Fz, Mx, My, Mz).
LOAD_NAMES = ("force along x", "force along y", "force along z", "moment about x", "moment about y",
              "moment about z")


def axis_label(quantity: str, unit: str) -> str:
    """An axis label: the quantity in words and its unit in brackets, ``"normal force [kN]"``."""
    return f"{quantity} [{unit}]"


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


def plot_long(ax, t: np.ndarray, values: np.ndarray, *args, **kwargs):
    """``ax.plot(t, values, ...)`` through the :func:`envelope_indices` of a long series."""
    keep = envelope_indices(values)
    return ax.plot(t[keep], values[keep], *args, **kwargs)


def time_axes(axes: np.ndarray, t: np.ndarray) -> None:
    """Grid and the span of ``t`` [s] on every axes of a grid, "time t [s]" under its last row."""
    for ax in np.ravel(axes):
        ax.grid(True, alpha=0.3)
        ax.set_xlim(t[0], t[-1])
    for ax in np.atleast_1d(axes[-1]):
        ax.set_xlabel("time t [s]")


def plain_tick(value: float, _position=None, mantissas=(1, 2, 5)) -> str:
    """A log-axis tick as a plain number, only at ``mantissas`` (1, 2 and 5) times a power of ten (a formatter)."""
    if value <= 0:
        return ""
    mantissa = round(value / 10 ** np.floor(np.log10(value)), 6)
    return f"{value:g}" if mantissa in mantissas else ""


def plain_log_ticks(axis, mantissas=(1, 2, 5)) -> None:
    """Ticks of a log ``axis`` labelled in plain numbers at ``mantissas`` (1, 2 and 5) times a power of ten (20,
    50, 100 rather than 2 x 10^1, 5 x 10^1, 10^2; ``4 x 10^-2`` beside ``10^-2``)."""
    formatter = FuncFormatter(partial(plain_tick, mantissas=tuple(mantissas)))
    axis.set_major_formatter(formatter)
    axis.set_minor_formatter(formatter)


def plain_frequencies(ax) -> None:
    """:func:`plain_log_ticks` on a frequency axis spanning at most three decades (wider ones keep their
    decades, 1-2-5 would crowd them)."""
    low, high = ax.get_xlim()
    if low > 0 and high / low <= 1e3:
        plain_log_ticks(ax.xaxis)


def merge_identical(curves):
    """``[(values, name, note)]`` with curves identical to an earlier one (to round-off) dropped and their
    names joined to its with " = ": drawn over another, a curve would hide it and leave a legend entry
    without a visible line (points that move as one, a symmetric body's)."""
    kept: list[list] = []
    for values, name, note in curves:
        same = next((entry for entry in kept if np.allclose(values, entry[0], rtol=1e-9, atol=0.0)), None)
        if same is None:
            kept.append([values, name, note])
        else:
            same[1] += f" = {name}"
    return [tuple(entry) for entry in kept]


def margins(fig: Figure, left: float, right: float, top: float, bottom: float, wspace: float = 0.0,
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


def figure(fig: Figure | None, figsize: tuple[float, float]) -> Figure:
    """The figure a multi-panel plot draws in: a new one of ``figsize`` [in], or ``fig``, a caller's empty
    :class:`~matplotlib.figure.Figure`, set to that size (the plots lay their margins and rows out in inches)."""
    if fig is None:
        return Figure(figsize=figsize)
    require(fig, "fig", Figure, "a matplotlib.figure.Figure (or None for a new one)")
    if fig.axes:
        raise InputError("fig", "an empty matplotlib Figure (the plot lays out its own panels)",
                         Plain(f"a figure with {len(fig.axes)} axes"))
    fig.set_size_inches(figsize)
    return fig


def panel_grid(n: int) -> tuple[int, int]:
    """Columns and rows for ``n`` per-mode panels: one row up to 4, else 3 columns."""
    columns = 3 if n > 4 else n
    return columns, -(-n // columns)


def title(name: str, what: str) -> str:
    """``"<name>: <what>"``, or ``what`` alone for an unnamed run."""
    return f"{name}: {what}" if name else what


#: Width of an average title glyph [em], with room for wide letters: about 150 characters of a long name fill a
#: 13 in line at 12 pt (0.52 em each, measured); a line is given 0.65 em a character.
TITLE_GLYPH_EM = 0.65


def name_apart(name: str, what: str, width: float, fontsize: float) -> bool:
    """Whether ``title(name, what)`` on one line would run past ``width`` [in] at ``fontsize`` [pt]: a long run
    name (a nonlinear run's "(linear model, exact until ...)") then goes on a line of its own
    (:func:`name_line`)."""
    return bool(name) and len(title(name, what)) * TITLE_GLYPH_EM * fontsize / 72.0 > width


def name_line(name: str, what: str, width: float, fontsize: float) -> str:
    """:func:`title`, with the name on a line of its own where :func:`name_apart` says one line is too long."""
    return f"{name}:\n{what}" if name_apart(name, what, width, fontsize) else title(name, what)


def require(value, field: str, kind: type | tuple[type, ...], expected: str):
    """``value`` when it is a ``kind``; otherwise an :class:`InputError` naming ``field``."""
    if not isinstance(value, kind):
        raise InputError(field, expected, value)
    return value


def natural_frequencies(modes) -> np.ndarray | None:
    """``modes.frequency_hz`` [Hz] of a :class:`~sixdof.model.modes.Modes`, or ``None``."""
    require(modes, "modes", (Modes, type(None)), "a sixdof.model.modes.Modes (or None)")
    return None if modes is None else modes.frequency_hz


#: Natural frequencies closer than this factor get their mode numbers on staggered rows, so that they do
#: not run together ("12" for modes 1 and 2).
CLOSE_MODES = 1.12


#: Fraction of a magnitude panel's height, at its top, kept for the mode numbers.
LABEL_BAND = 0.2


def mark_modes(ax, frequency_hz: np.ndarray | None, label: bool = False) -> None:
    """Dotted verticals at the natural frequencies [Hz] above 0, numbered when ``label`` (the numbers of
    modes within :data:`CLOSE_MODES` of the previous one a row lower, up to three rows) in a band at the top
    that the curves are kept out of (the y range raised so what is drawn ends at :data:`LABEL_BAND` below
    the top)."""
    if frequency_hz is None:
        return
    if label:
        low, high = ax.get_ylim()
        if ax.get_yscale() == "log":
            ax.set_ylim(low, low * (high / low) ** (1.0 / (1.0 - LABEL_BAND)))
        else:
            ax.set_ylim(low, low + (high - low) / (1.0 - LABEL_BAND))
    row, previous = 0, None
    for j, f in enumerate(frequency_hz):
        if f > 0:
            ax.axvline(f, color="grey", linewidth=0.8, linestyle=":", zorder=0)
            if label:
                row = (row + 1) % 3 if previous is not None and f < CLOSE_MODES * previous else 0
                ax.text(f, 0.99 - 0.055 * row, f"{j + 1}", transform=ax.get_xaxis_transform(), fontsize=8,
                        color="dimgrey", va="top", ha="left")
            previous = f


def mark_operating(ax, operating_hz, label: bool = False) -> None:
    """Dash-dot red verticals at the operating frequencies [Hz] (a run's harmonic loads), labelled at the
    bottom when ``label``."""
    for f in np.atleast_1d(operating_hz if operating_hz is not None else []):
        ax.axvline(f, color="tab:red", linewidth=1.0, linestyle="-.", zorder=1)
        if label:
            ax.text(f, 0.02, f" operating {f:.4g} Hz", transform=ax.get_xaxis_transform(), fontsize=8,
                    color="tab:red", va="bottom", ha="left", rotation=90,
                    bbox={"facecolor": "white", "alpha": 0.75, "edgecolor": "none", "pad": 1.0})  # over a curve


def freeze_unlabelled_ticks(fig: Figure) -> None:
    """Draw every set of unlabelled ticks of ``fig`` as two artists that look the same: one line
    collection for their grid lines and one line of tick marks, at the positions the axis' own locator
    gives for its final limits.

    matplotlib makes a tick object of five artists for each tick, labelled or not: the ~300 minor ticks of
    a Bode plot cost ~40 % of its drawing, the unlabelled time ticks of the panels stacked above a shared
    time axis ~20 % of theirs. Which ticks have no label: the minor ticks of a log axis spanning more than
    about a decade, the major ticks whose labels are hidden (panels sharing an axis). Labelled ticks stay
    as they are. For a finished figure only (:func:`sixdof.plots.render`): frozen ticks no longer follow
    the limits.
    """
    found = []  # every axis' positions first, then its ticker: axes sharing an axis share their tickers
    for ax in fig.axes:
        if ax.name != "rectilinear":
            continue
        for axis in (ax.xaxis, ax.yaxis):
            for which in ("major", "minor"):
                ticker = getattr(axis, which)
                # The axis' own positions: the minor ones without those on a major tick (matplotlib drops them).
                values = np.asarray(axis.get_majorticklocs() if which == "major" else axis.get_minorticklocs(),
                                    dtype=float)
                values = values[_inside(axis, values)]
                tick = (axis.get_major_ticks if which == "major" else axis.get_minor_ticks)(1)[0]
                if _unlabelled(axis, ticker, values, tick):
                    found.append((axis, which, values, tick))
    for axis, which, values, tick in found:
        setattr(axis, which, Ticker())  # its own: the axes sharing this axis keep theirs
        (axis.set_major_locator if which == "major" else axis.set_minor_locator)(NullLocator())
        (axis.set_major_formatter if which == "major" else axis.set_minor_formatter)(NullFormatter())
        if len(values):
            _draw_ticks(axis, values, tick)


def _unlabelled(axis, ticker, values: np.ndarray, tick) -> bool:
    """Whether the ticks at ``values`` show no text: their labels are hidden or empty, and so is the
    axis' offset text (``1e-11``, drawn from the major ticks)."""
    labels = ticker.formatter.format_ticks(values)
    if (tick.label1.get_visible() or tick.label2.get_visible()) and any(labels):
        return False
    return ticker is not axis.major or not (axis.offsetText.get_visible() and ticker.formatter.get_offset())


def _inside(axis, values: np.ndarray) -> np.ndarray:
    """Which ``values`` lie in the axis' view, as matplotlib decides which ticks to draw: in the axis'
    scale, within 1e-10 of the view's span (a tick computed as 2 x 0.1 on a view starting at 0.2 is in)."""
    transform = axis.get_transform()
    low, high = sorted(transform.transform(np.asarray(axis.get_view_interval(), dtype=float)))
    slack = 1e-10 * (high - low)
    scaled = transform.transform(values)
    return (scaled >= low - slack) & (scaled <= high + slack)


def _draw_ticks(axis, values: np.ndarray, tick) -> None:
    """Grid lines and tick marks at ``values`` along ``axis``, styled as its tick object ``tick``."""
    ax, zorder = axis.axes, axis.get_zorder()
    if axis is ax.yaxis:
        # matplotlib draws the x axis before the y axis, and artists of equal zorder in the axes' children
        # before either: just above the axes' zorder, the y ticks stay over the x axis' labelled ones (a y
        # tick mark over an x grid line at the view's limit, as drawn before freezing).
        zorder = np.nextafter(zorder, np.inf)

    def at(across: float) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) of the positions, ``across`` in axes coordinates the other way."""
        other = np.full_like(values, across)
        return (values, other) if axis is ax.xaxis else (other, values)

    grid = tick.gridline
    if grid.get_visible():
        ends = np.stack([np.stack(at(0.0), axis=-1), np.stack(at(1.0), axis=-1)], axis=1)
        ax.add_collection(LineCollection(ends, transform=grid.get_transform(), colors=[grid.get_color()],
                                         linewidths=grid.get_linewidth(), linestyles=grid.get_linestyle(),
                                         alpha=grid.get_alpha(), zorder=zorder), autolim=False)
    for mark, across in ((tick.tick1line, 0.0), (tick.tick2line, 1.0)):
        if mark.get_visible():
            marks = Line2D(*at(across))
            marks.update_from(mark)
            marks.set(transform=mark.get_transform(), clip_on=False, zorder=zorder)
            ax.add_artist(marks)


def png_bytes(rgba: np.ndarray, dpi: float) -> bytes:
    """An RGBA image (height, width, 4) of uint8 as a PNG file, ``dpi`` dots per inch, every row unfiltered.

    Pillow, which matplotlib writes PNG with, picks each row's filter by trying them all: two thirds of the
    encoding of these flat-colour figures (0.2 of 0.3 s of CPU for a run's six), for files no smaller than
    unfiltered rows compressed at :data:`PNG_COMPRESS_LEVEL` (2.36 MB against 2.30 MB for those six). The
    file says, as matplotlib's do, its resolution and the software that drew it.
    """
    height, width, _ = rgba.shape
    rows = np.empty((height, 4 * width + 1), dtype=np.uint8)
    rows[:, 0] = 0  # filter type 0 (none) for every row
    rows[:, 1:] = rgba.reshape(height, -1)

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    per_metre = round(dpi / 0.0254)
    software = f"Matplotlib version{matplotlib.__version__}, https://matplotlib.org/".encode("latin-1")
    return b"".join([
        b"\x89PNG\r\n\x1a\n",
        chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)),  # 8-bit RGBA, not interlaced
        chunk(b"pHYs", struct.pack(">IIB", per_metre, per_metre, 1)),
        chunk(b"tEXt", b"Software\x00" + software),
        chunk(b"IDAT", zlib.compress(rows.tobytes(), PNG_COMPRESS_LEVEL)),
        chunk(b"IEND", b""),
    ])
