"""A test against the model (issue 47): the stability diagram of the modal identification, the MAC matrix of
test and model modes, the measured FRFs over the model's, and the history of a model update.

Each function draws from the typed results alone and returns its figure; ``ax=`` (one panel) or ``fig=``
(several, the layout in the docstring) draws onto the caller's.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle
from matplotlib.ticker import FixedLocator, FuncFormatter, MaxNLocator, NullFormatter

from sixdof.errors import InputError, Plain, readonly
from sixdof.plots.common import margins, plain_log_ticks, require, title
from sixdof.validation.correlation import Correlation
from sixdof.validation.identify import STABILITY_CLASSES, Identification
from sixdof.validation.testdata import FRF_QUANTITIES, RESPONSE_UNITS, TestData

#: Characters per line of a variable's name in the update history's legends (long tied-mount names wrap).
LEGEND_WIDTH = 36
#: Marker, size, colour and legend text of each stability class (:data:`~sixdof.validation.identify.STABILITY_CLASSES`:
#: 0 new ... 3 stable in frequency, damping and participation vector): the more stable, the bolder.
STABILITY_STYLE = tuple(
    (marker, size, color, "new pole" if code == 0 else f"stable in {STABILITY_CLASSES[code]}")
    for code, (marker, size, color) in enumerate((("o", 3.0, "lightgrey"), ("s", 3.5, "tab:cyan"),
                                                  ("D", 3.5, "tab:blue"), ("^", 5.0, "tab:green"))))
#: Colours of the references in the FRF overlay (cycled past ten references).
REFERENCE_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink",
                    "tab:olive", "tab:cyan", "tab:grey")
#: Line styles of the FRF overlay: the test, the model and the updated model.
TEST_STYLE, MODEL_STYLE, UPDATED_STYLE = "-", "--", ":"
#: Fraction of the stability diagram's height, at its top, kept for the selected modes' labels.
LABEL_BAND = 0.16


def _unit(text: str) -> str:
    return text.replace("^2", "²")


def frf_unit(quantity: str, rotation: bool, moment: bool) -> str:
    """The SI unit of an FRF of ``quantity`` (receptance, mobility, accelerance) from a translation or a rotation
    per a force or a moment: ``"(m/s²)/N"``, ``"rad/(N m)"``."""
    translation, angular = RESPONSE_UNITS[FRF_QUANTITIES[quantity]]
    response = _unit(angular if rotation else translation)
    response = f"({response})" if "/" in response else response
    return f"{response}/(N m)" if moment else f"{response}/N"


# ----------------------------------------------------------------------------------------------------
# Stability diagram.
# ----------------------------------------------------------------------------------------------------


def _label_rows(fig: Figure, ax, frequencies, texts, fontsize: float) -> list[int]:
    """The row (0 at the top) of each selected mode's label so that no two labels on a row overlap: a label
    goes on the first row whose previous label ends left of it (widths estimated from the font size)."""
    width_px = ax.get_position().width * fig.get_size_inches()[0] * 72.0  # the axes' width [pt]
    low, high = ax.get_xlim()
    ends: list[float] = []  # right end of the last label of each row, in points from the left
    rows = []
    for f, text in zip(frequencies, texts):
        start = (f - low) / (high - low) * width_px
        length = 0.6 * fontsize * len(text) + 6.0
        row = next((r for r, end in enumerate(ends) if end < start), len(ends))
        if row == len(ends):
            ends.append(0.0)
        ends[row] = start + length
        rows.append(row)
    return rows


def plot_stability(identification: Identification, ax=None, H=None, f_hz=None, *, unit: str = "",
                   name: str = "") -> Figure:
    """The stability diagram of a modal identification: the poles of every model order over frequency, marked
    by their stability against the previous order, with the selected modes.

    Each pole (one of each complex pair) is drawn at its natural frequency [Hz] and model order, its marker
    saying how stable it is (:data:`STABILITY_STYLE`, in words in the legend). Each identified mode's pole is
    ringed in red, with a red vertical at its frequency labelled with the mode number and frequency at the top
    (labels that would overlap go on lower rows). Given the FRFs, their sum of magnitudes over every output and
    reference (a mode indicator: its peaks are the modes) is drawn in grey on a log scale on a twin axis at
    the right.

    Parameters
    ----------
    identification : sixdof.validation.identify.Identification
        From :func:`~sixdof.validation.identify.identify_modes`: its ``stability`` (poles, classes, selection)
        and ``modes`` (identified frequencies [Hz]), and its ``band_hz`` (the span drawn).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (the figure's title is left as it is); the mode indicator gets a twin of them.
        Default: a new figure.
    H : array_like, shape (nf, n_out, n_ref), optional
        The FRFs identified (any quantity) for the mode indicator; needs ``f_hz``.
    f_hz : array_like, shape (nf,), optional
        Their frequencies [Hz]; only those in the band are drawn.
    unit : str
        Unit of ``H`` for the indicator's axis label (``"(m/s^2)/N"``); ``""`` when unknown.
    name : str
        Name of the run, put before the title (new figure only).

    Returns
    -------
    matplotlib.figure.Figure
        The new figure, or the one holding ``ax``.
    """
    require(identification, "identification", Identification,
            "a sixdof.validation.identify.Identification (from identify_modes)")
    diagram, modes = identification.stability, identification.modes
    indicator = None
    if H is not None or f_hz is not None:
        if H is None or f_hz is None:
            raise InputError("H" if H is None else "f_hz", "the FRFs H and their frequencies f_hz together",
                             Plain("only one of them"))
        f, H = np.asarray(f_hz, dtype=float), np.asarray(H)
        if H.ndim != 3 or f.ndim != 1 or H.shape[0] != f.size:
            raise InputError("H", f"FRFs of shape (nf, n_out, n_ref) with nf = {f.size} (f_hz's length)",
                             Plain(f"an array of shape {H.shape}"))
        indicator = f, np.abs(H).sum(axis=(1, 2))
    if ax is None:
        fig = Figure(figsize=(12, 6.5))
        margins(fig, left=0.85, right=1.1 if indicator is not None else 0.3, top=0.75, bottom=1.25)
        ax = fig.add_subplot()
        fig.suptitle(title(name, f"stability diagram: poly-reference LSCF poles of orders 1-{diagram.max_order} "
                                 f"({identification.quantity}), {modes.frequency_hz.size} modes selected"),
                     fontsize=12)
    fig = ax.figure
    lo, hi = identification.band_hz
    inside = (diagram.frequency_hz >= lo) & (diagram.frequency_hz <= hi)
    for code, (marker, size, color, text) in enumerate(STABILITY_STYLE):
        pick = inside & (diagram.stability == code)
        ax.plot(diagram.frequency_hz[pick], diagram.order[pick], linestyle="none", marker=marker, markersize=size,
                color=color, markeredgewidth=0.0 if code == 0 else 0.5, markeredgecolor="black",
                label=f"{text} ({int(pick.sum())})", zorder=2 + code)
    selected = np.asarray(diagram.selected, dtype=int)
    ax.plot(diagram.frequency_hz[selected], diagram.order[selected], linestyle="none", marker="o", markersize=10,
            markerfacecolor="none", markeredgecolor="tab:red", markeredgewidth=1.3, label="pole of a selected mode",
            zorder=7)
    ax.set_xlim(lo, hi)
    top = diagram.max_order + 1
    ax.set_ylim(0, top / (1.0 - LABEL_BAND))
    ax.set_xlabel("natural frequency f [Hz]")
    ax.set_ylabel("model order p [1]")
    ax.grid(True, alpha=0.3)
    texts = [f"{j + 1}: {f:.4g} Hz" for j, f in enumerate(modes.frequency_hz)]
    rows = _label_rows(fig, ax, modes.frequency_hz, texts, 8.0)
    for f, text, row in zip(modes.frequency_hz, texts, rows):
        ax.axvline(f, color="tab:red", linewidth=0.8, linestyle="-", alpha=0.6, zorder=1)
        ax.text(f, 0.985 - 0.045 * row, text, transform=ax.get_xaxis_transform(), fontsize=8, color="tab:red",
                va="top", ha="left", zorder=8,
                bbox={"facecolor": "white", "alpha": 0.9, "edgecolor": "none", "pad": 1.0})  # over another's line
    if indicator is not None:
        f, total = indicator
        keep = (f >= lo) & (f <= hi)
        twin = ax.twinx()
        twin.semilogy(f[keep], total[keep], color="dimgrey", linewidth=1.0, label="mode indicator: sum of |H|")
        twin.set_ylabel(f"sum of |H| over outputs and references [{_unit(unit)}]" if unit
                        else "sum of |H| over outputs and references", color="dimgrey")
        twin.tick_params(axis="y", colors="dimgrey")
        twin.set_zorder(ax.get_zorder() - 1)  # the poles above the curve
        ax.patch.set_visible(False)
        handles, labels = ax.get_legend_handles_labels()
        extra, extra_labels = twin.get_legend_handles_labels()
        handles, labels = handles + extra, labels + extra_labels
    else:
        handles, labels = ax.get_legend_handles_labels()
    ax.legend(handles, labels, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, frameon=False)
    return fig


# ----------------------------------------------------------------------------------------------------
# MAC matrix.
# ----------------------------------------------------------------------------------------------------


#: The outline of a MAC pair within the verdict's limits (True) and outside them (False).
PAIR_COLORS = {True: "tab:green", False: "tab:red"}


def plot_mac(correlation: Correlation, ax=None, *, body: bool = False, name: str = "") -> Figure:
    """The MAC matrix of the test modes (rows) against the model modes (columns), each cell's value written in
    it, the pairs outlined (green within the verdict's limits, red dashed not), and a colour bar from 0 to 1.

    Modes are numbered from 1, with their frequency [Hz] in the tick labels; the title states the verdict's
    limits and whether the pairs meet them.

    Parameters
    ----------
    correlation : sixdof.validation.correlation.Correlation
        From :func:`~sixdof.validation.correlation.correlate_modes`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (the colour bar takes room from them; the figure's title is left as it is). Default: a
        new figure.
    body : bool
        Draw the MAC on the six body DOFs (``mac_body``) instead of the measured channels (``mac``).
    name : str
        Name of the run, put before the title (new figure only).

    Returns
    -------
    matplotlib.figure.Figure
        The new figure, or the one holding ``ax``.

    Raises
    ------
    sixdof.errors.InputError
        ``body`` for a correlation without body shapes.
    """
    require(correlation, "correlation", Correlation, "a sixdof.validation.correlation.Correlation")
    matrix = correlation.mac_body if body else correlation.mac
    if matrix is None:
        raise InputError("correlation.mac_body", "a MAC on the six body DOFs (correlate_modes with body shapes)",
                         Plain("none"))
    n_test, n_model = matrix.shape
    where = "the six body DOFs" if body else "the measured channels"
    bar_axes = None
    if ax is None:
        fig = Figure(figsize=(max(6.5, 1.0 * n_model + 3.5), max(5.0, 0.7 * n_test + 2.6)))
        margins(fig, left=1.3, right=1.5, top=0.9, bottom=0.8)
        ax = fig.add_subplot()
        width, height = fig.get_size_inches()
        box = ax.get_position()
        # The colour bar in the right margin: 0.25 in from the matrix, 0.22 in wide, its label beside it.
        bar_axes = fig.add_axes((box.x1 + 0.25 / width, box.y0, 0.22 / width, box.height))
        verdict = "correlated" if correlation.correlated else "not correlated"
        fig.suptitle(title(name, f"MAC on {where}: {verdict}; pairs outlined, green within the limits, red not\n"
                                 f"(limits: |frequency error| <= {correlation.max_frequency_error_percent:g} %, "
                                 f"MAC on the channels >= {correlation.min_mac:g})"), fontsize=11)
    fig = ax.figure
    image = ax.imshow(matrix, cmap="Blues", vmin=0.0, vmax=1.0, aspect="auto")
    for i in range(n_test):
        for j in range(n_model):
            value = float(matrix[i, j])
            ax.text(j, i, f"{value:.2f}", ha="center", va="center", fontsize=9,
                    color="white" if value > 0.6 else "black")
    # Each pair judged as the verdict judges it (on the channels' MAC, whichever MAC is drawn).
    for t, m, ok in zip(correlation.pair_test, correlation.pair_model, correlation.pair_within):
        ax.add_patch(Rectangle((m - 0.5, t - 0.5), 1.0, 1.0, fill=False, linewidth=2.2,
                               edgecolor=PAIR_COLORS[bool(ok)], linestyle="-" if ok else "--"))
    ax.set_xticks(range(n_model), [f"{j + 1}\n{f:.4g} Hz" for j, f in enumerate(correlation.f_model)], fontsize=8)
    ax.set_yticks(range(n_test), [f"{i + 1}: {f:.4g} Hz" for i, f in enumerate(correlation.f_test)], fontsize=8)
    ax.set_xlabel("model mode (natural frequency)")
    ax.set_ylabel("test mode (identified frequency)")
    bar = (fig.colorbar(image, ax=ax, fraction=0.05, pad=0.03) if bar_axes is None
           else fig.colorbar(image, cax=bar_axes))
    bar.set_label(f"MAC on {where} [1]")
    return fig


# ----------------------------------------------------------------------------------------------------
# FRF overlay.
# ----------------------------------------------------------------------------------------------------


def _frequency_ticks(axis, low: float, high: float) -> None:
    """A log frequency axis from ``low`` to ``high`` [Hz] labelled in plain numbers at 1, 2 and 5 times a power
    of ten (the other integers unlabelled): fixed positions, so that an axis shared by 30 panels is not asked
    for its ticks again at each (the overlay's drawing time is mostly ticks)."""
    decades = 10.0 ** np.arange(np.floor(np.log10(low)), np.ceil(np.log10(high)) + 1)

    def within(mantissas):
        values = np.outer(decades, mantissas).ravel()
        return values[(values >= low * (1 - 1e-9)) & (values <= high * (1 + 1e-9))]

    axis.set_major_locator(FixedLocator(within((1, 2, 5))))
    axis.set_minor_locator(FixedLocator(within((3, 4, 6, 7, 8, 9))))
    axis.set_major_formatter(FuncFormatter(lambda value, _position: f"{value:g}"))
    axis.set_minor_formatter(NullFormatter())


def wrapped_phase_deg(f_hz: np.ndarray, values) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [Hz] and the phase [deg] of complex ``values`` in (-180, 180], with a NaN point inserted
    where it wraps: a line through it then breaks there instead of drawing a vertical across the panel (noise
    about +-180 deg would fill the panel with them), and a noisy phase is not unwrapped into drifting turns."""
    phase = np.degrees(np.angle(values))
    jumps = np.flatnonzero(np.abs(np.diff(phase)) > 180.0) + 1
    return np.insert(np.asarray(f_hz, dtype=float), jumps, np.nan), np.insert(phase, jumps, np.nan)


def _model_frf(values, field: str, shape: tuple[int, ...]) -> np.ndarray | None:
    if values is None:
        return None
    values = np.asarray(values)
    if values.shape != shape:
        raise InputError(field, f"FRFs on the test's channels, shape {shape} (nf, n_out, n_ref)",
                         Plain(f"an array of shape {values.shape}"))
    return values


def plot_frf_overlay(test: TestData, H_model, fig: Figure | None = None, H_updated=None, *,
                     name: str = "") -> Figure:
    """The measured FRFs against the model's on every channel: one panel per response channel, the magnitude
    (log) above a smaller phase, each reference a colour, the test solid, the model dashed and the updated model
    dotted.

    Why one panel per response channel, the references together: a model that is wrong at a channel (a mode
    shape that differs there, a channel mislabelled in the test) is wrong for every reference at once, which
    a panel shows at a glance, and the panels laid out as the channels come (a triaxial node's x, y and z on
    one row of three) read as the test's geometry. A panel per reference would put 15 curves in each, too many
    to tell a misfit from its neighbours.

    Parameters
    ----------
    test : sixdof.validation.testdata.TestData
        Measured FRFs (``kind == "frf"``): ``f_hz`` [Hz], ``H`` (nf, n_out, n_ref) in SI units of its
        ``quantity``, the channel labels.
    H_model : array_like, shape (nf, n_out, n_ref)
        The model's FRFs on the same channels, frequencies and quantity (``test.response_rows() @ H6 @
        test.load_columns()`` times ``(i w)^k``).
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw on: its grid is 3 columns (the number of channels up to 4: one row) of channel
        panels, each a magnitude above a phase of a third of its height; a legend of the references and line
        styles under them. Its title and margins are left as they are. Default: a new figure.
    H_updated : array_like, shape (nf, n_out, n_ref), optional
        The updated model's FRFs on the same channels.
    name : str
        Name of the test or run, put before the title (new figure only).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    sixdof.errors.InputError
        Time data rather than FRFs; model FRFs of another shape.
    """
    require(test, "test", TestData, "a sixdof.validation.testdata.TestData")
    if test.kind != "frf" or test.H is None:
        raise InputError("test", "measured FRFs (estimate them from the time histories first)",
                         Plain(f"test data of kind {test.kind!r}"))
    f, H = test.f_hz, test.H
    H_model = _model_frf(H_model, "H_model", H.shape)
    H_updated = _model_frf(H_updated, "H_updated", H.shape)
    n_out, n_ref = H.shape[1], H.shape[2]
    columns = 3 if n_out > 4 else n_out
    rows = -(-n_out // columns)
    new = fig is None
    if new:
        fig = Figure(figsize=(5.0 * columns, 3.4 * rows + 1.6))
        against = "the model (dashed)" + (" and the updated model (dotted)" if H_updated is not None else "")
        fig.suptitle(title(name, f"measured {test.quantity} (solid) against {against}: {n_out} response channels, "
                                 f"{n_ref} references"), fontsize=12)
    cells = fig.add_gridspec(rows, columns)
    margins(fig, left=0.9, right=0.15, top=0.85 if new else 0.4, bottom=1.1, wspace=0.95, hspace=0.65,
            columns=columns, rows=rows, target=cells)
    positive = f > 0
    first = None
    for o in range(n_out):
        cell = cells[o // columns, o % columns].subgridspec(2, 1, height_ratios=[3, 1], hspace=0.06)
        mag = fig.add_subplot(cell[0], sharex=first)
        phase = fig.add_subplot(cell[1], sharex=mag)
        first = first or mag
        for j in range(n_ref):
            color = REFERENCE_COLORS[j % len(REFERENCE_COLORS)]
            for values, style, width in ((H, TEST_STYLE, 0.9), (H_model, MODEL_STYLE, 1.1),
                                         (H_updated, UPDATED_STYLE, 1.3)):
                if values is None:
                    continue
                h = values[positive, o, j]
                mag.plot(f[positive], np.abs(h), color=color, linestyle=style, linewidth=width)
                phase.plot(*wrapped_phase_deg(f[positive], h), color=color, linestyle=style, linewidth=width)
        moments = set(bool(r) for r in test.ref_rotation)
        units = " or ".join(frf_unit(test.quantity, bool(test.out_rotation[o]), m) for m in sorted(moments))
        mag.set_yscale("log")
        mag.set_xscale("log")
        mag.set_title(f"response {test.out_labels[o]}", fontsize=10)
        mag.set_ylabel(f"|H| [{units}]", fontsize=9)
        mag.tick_params(which="both", labelbottom=False)
        mag.grid(True, which="both", alpha=0.25)
        phase.set_ylim(-200, 200)
        phase.set_yticks([-180, 0, 180])
        phase.set_ylabel("phase\n[deg]", fontsize=8)
        if o + columns >= n_out:  # the lowest panel of its column
            phase.set_xlabel("frequency f [Hz]", fontsize=9)
        phase.grid(True, alpha=0.25)
    first.set_xlim(f[positive][0], f[positive][-1])
    _frequency_ticks(first.xaxis, f[positive][0], f[positive][-1])
    handles = [first.plot([], [], color=REFERENCE_COLORS[j % len(REFERENCE_COLORS)], linewidth=2.5)[0]
               for j in range(n_ref)]
    labels = [f"reference {label}" for label in test.ref_labels]
    for values, style, text in ((H, TEST_STYLE, "test"), (H_model, MODEL_STYLE, "model"),
                                (H_updated, UPDATED_STYLE, "updated model")):
        if values is not None:
            handles.append(first.plot([], [], color="black", linestyle=style)[0])
            labels.append(text)
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 6), fontsize=9, frameon=False)
    return fig


# ----------------------------------------------------------------------------------------------------
# Update history.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class UpdateHistory:
    """What :func:`plot_update_history` draws: the objective and the variables at every iteration of every
    start of a model update.

    Attributes
    ----------
    start_index : ndarray of int, shape (n_iterations,)
        The start each iteration belongs to (from 0; -1: the polish from the best start's end), in the order
        run; a start's iterations are consecutive.
    objective : ndarray, shape (n_iterations,)
        The objective at each iteration [1].
    x : ndarray, shape (n_iterations, n_variables)
        The variables at each iteration (units: ``units``).
    variables : tuple of str
        Their names.
    initial : ndarray, shape (n_variables,)
        The given model's values.
    units : tuple of str
        Each variable's unit (``"1"`` for a factor).
    objective_name : str
        What the objective is, for the axis label.
    """

    start_index: np.ndarray
    objective: np.ndarray
    x: np.ndarray
    variables: tuple[str, ...]
    initial: np.ndarray
    units: tuple[str, ...]
    objective_name: str = "objective"

    def __post_init__(self) -> None:
        start = readonly(np.asarray(self.start_index, dtype=int), int)
        objective = readonly(np.asarray(self.objective, dtype=float))
        x = readonly(np.atleast_2d(np.asarray(self.x, dtype=float)))
        initial = readonly(np.asarray(self.initial, dtype=float).ravel())
        n = start.size
        if start.ndim != 1 or n == 0 or objective.shape != (n,):
            raise InputError("history", "a start index and an objective per iteration (at least one)",
                             Plain(f"shapes {start.shape} and {objective.shape}"))
        if x.shape != (n, initial.size) or len(self.variables) != initial.size or len(self.units) != initial.size:
            raise InputError("history.x", f"({n} iterations, {initial.size} variables) with a name and unit each",
                             Plain(f"shape {x.shape}, {len(self.variables)} names, {len(self.units)} units"))
        object.__setattr__(self, "start_index", start)
        object.__setattr__(self, "objective", objective)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "initial", initial)
        object.__setattr__(self, "variables", tuple(str(v) for v in self.variables))
        object.__setattr__(self, "units", tuple(str(u) for u in self.units))


#: The fields of :class:`sixdof.design.update.UpdateResult` an :class:`UpdateHistory` is read from.
UPDATE_FIELDS = ("history_start_index", "history_objective", "history_x", "variable", "initial", "variable_units")


def update_history(update) -> UpdateHistory:
    """The :class:`UpdateHistory` of a :class:`sixdof.design.update.UpdateResult` (or of anything with its
    ``history_start_index``, ``history_objective``, ``history_x``, ``variable``, ``initial`` and
    ``variable_units``); an :class:`UpdateHistory` is returned as is."""
    if isinstance(update, UpdateHistory):
        return update
    missing = [name for name in UPDATE_FIELDS if not hasattr(update, name)]
    if missing:
        raise InputError("update", "a sixdof.design.update.UpdateResult or an UpdateHistory",
                         Plain(f"a {type(update).__name__} without {', '.join(missing)}"))
    objective = getattr(update, "objective", "")
    return UpdateHistory(start_index=update.history_start_index, objective=update.history_objective,
                         x=update.history_x, variables=tuple(update.variable), initial=update.initial,
                         units=tuple(update.variable_units),
                         objective_name=f"{objective} objective" if isinstance(objective, str) and objective
                         else "objective")


def _best_start(history: UpdateHistory) -> int:
    """The start whose last iteration has the lowest objective (the one the polish, if any, goes on from)."""
    starts = sorted({int(s) for s in history.start_index if s >= 0})
    last = {s: history.objective[np.flatnonzero(history.start_index == s)[-1]] for s in starts}
    return min(starts, key=lambda s: last[s])


def plot_update_history(update, fig: Figure | None = None, *, name: str = "") -> Figure:
    """How a model update went: the objective against the iteration for every start, and the variables of the
    best start against its iterations.

    Left panel: the objective [1] (log) against the iteration within each start, one line per start (the
    polish from the best start's end, if any, in black, its iterations counted on from that end). Right panel:
    the best start's variables (and the polish's) over their given values, ``x / x0`` [1]; variables given as 0
    (a centre-of-gravity offset, an angle change) cannot be normalized, and are drawn in their own units in a
    third panel below the second.

    Parameters
    ----------
    update : sixdof.design.update.UpdateResult or UpdateHistory
        The update's history (see :func:`update_history`).
    fig : matplotlib.figure.Figure, optional
        An empty figure to draw on: objective left, the variables right (the ones given as 0 below them). Its
        title and margins are left as they are. Default: a new figure.
    name : str
        Name of the run, put before the title (new figure only).

    Returns
    -------
    matplotlib.figure.Figure
    """
    history = update_history(update)
    best = _best_start(history)
    zero = history.initial == 0.0
    new = fig is None
    if new:
        fig = Figure(figsize=(14, 6.5))
        fig.suptitle(title(name, "model update: the objective at each iteration of each start, "
                                 f"and the variables of the best start (start {best + 1})"), fontsize=12)
    cells = fig.add_gridspec(2, 2)
    margins(fig, left=0.9, right=2.6, top=0.75 if new else 0.3, bottom=0.6, wspace=1.0, hspace=1.0, columns=2,
            rows=2, target=cells)
    objective_ax = fig.add_subplot(cells[:, 0])
    starts = sorted({int(s) for s in history.start_index if s >= 0})
    for s in starts:
        values = history.objective[history.start_index == s]
        objective_ax.semilogy(np.arange(values.size), values, marker=".", markersize=4, linewidth=1.0,
                              label=f"start {s + 1}" + (" (best)" if s == best else ""))
    polish = history.start_index == -1
    best_count = int(np.sum(history.start_index == best))
    if polish.any():
        values = history.objective[polish]
        objective_ax.semilogy(best_count - 1 + np.arange(1, values.size + 1), values, color="black", marker=".",
                              markersize=4, linewidth=1.2, label="polish (output error) from the best start")
    objective_ax.set_xlabel("iteration within the start [1]")
    objective_ax.set_ylabel(f"{history.objective_name} [1]")
    objective_ax.set_title("objective", fontsize=10)
    objective_ax.grid(True, which="both", alpha=0.3)
    objective_ax.legend(fontsize=8)
    objective_ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    low, high = objective_ax.get_ylim()
    if high / low < 1e3:
        plain_log_ticks(objective_ax.yaxis)
    path = (history.start_index == best) | polish
    iterations = np.arange(int(path.sum()))
    values = history.x[path]
    panels = [(~zero, cells[:, 1] if not zero.any() else cells[0, 1])]
    if zero.any():
        panels.append((zero, cells[1, 1]))
    for k, (pick, cell) in enumerate(panels):
        if not pick.any():
            continue
        ax = fig.add_subplot(cell)
        for v in np.flatnonzero(pick):
            unit = history.units[v]
            if k == 0:
                label = (f"{history.variables[v]} (given {history.initial[v]:.4g}"
                         + ("" if unit in ("1", "") else f" {unit}") + ")")
                ax.plot(iterations, values[:, v] / history.initial[v], linewidth=1.2,
                        label=textwrap.fill(label, LEGEND_WIDTH, subsequent_indent="  "))
            else:
                ax.plot(iterations, values[:, v], linewidth=1.2,
                        label=textwrap.fill(f"{history.variables[v]} [{unit}]", LEGEND_WIDTH, subsequent_indent="  "))
        if polish.any():
            ax.axvline(best_count - 0.5, color="black", linewidth=0.8, linestyle=":")
        if k == 0:
            ax.axhline(1.0, color="grey", linewidth=0.8, linestyle="--")
            ax.set_ylabel("x / x0 (over the given value) [1]")
            ax.set_title("variables over their given values (dotted: the polish starts)", fontsize=10)
        else:
            units = sorted({history.units[v] for v in np.flatnonzero(pick)})
            ax.set_ylabel(f"value [{', '.join(units)}]")
            ax.set_title("variables given as 0, in their units", fontsize=10)
        ax.set_xlabel(f"iteration of start {best + 1}" + (" and the polish" if polish.any() else "") + " [1]")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    return fig
