"""What a figure looks like at the files' resolution, for the tests that compare two drawings of it."""

from __future__ import annotations

import io

import numpy as np
from matplotlib.image import imread

from sixdof import plots


def pixels(figure) -> np.ndarray:
    """The figure as the RGBA pixels of its PNG at :data:`sixdof.plots.DPI` (levels in [0, 1])."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=plots.DPI)
    return imread(io.BytesIO(buffer.getvalue()), format="png")


def frozen_tick_difference(draw) -> np.ndarray:
    """``|pixels|`` of ``draw()`` with its unlabelled ticks frozen (what render() draws) minus those of
    ``draw()`` as matplotlib draws it."""
    frozen = draw()
    plots.common.freeze_unlabelled_ticks(frozen)
    return np.abs(pixels(frozen) - pixels(draw()))



def _drawn_tick_labels(axis) -> list:
    """The tick labels of ``axis`` that matplotlib draws: those of ticks in its view (a locator's ticks beyond the
    limits keep labels at stale positions, never drawn)."""
    low, high = sorted(axis.get_view_interval())
    slack = 1e-9 * (high - low)
    ticks = [*axis.get_major_ticks(), *axis.get_minor_ticks()]
    return [label for tick in ticks if low - slack <= tick.get_loc() <= high + slack
            for label in (tick.label1, tick.label2)]


def assert_texts_clear(figure) -> None:
    """Drawn, every text of ``figure`` (titles, tick and axis labels, annotations, legends) lies inside it, none
    clipped at its edges, and no two of its titles and legends overlap."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(figure).draw()
    renderer = figure.canvas.get_renderer()
    titles = [figure._suptitle] if figure._suptitle is not None else []  # no public getter of the artist
    labels = []
    for ax in figure.axes:
        titles += [getattr(ax, name) for name in ("title", "_left_title", "_right_title")]
        labels += [*_drawn_tick_labels(ax.xaxis), *_drawn_tick_labels(ax.yaxis), ax.xaxis.label, ax.yaxis.label,
                   *ax.texts]
    legends = [legend for legend in [*figure.legends, *(ax.get_legend() for ax in figure.axes)] if legend is not None]
    boxes = {id(artist): (artist.get_text() if hasattr(artist, "get_text") else "legend",
                          artist.get_window_extent(renderer))
             for artist in [*titles, *labels, *legends]
             if artist.get_visible() and (not hasattr(artist, "get_text") or artist.get_text())}
    width, height = figure.canvas.get_width_height()
    for text, box in boxes.values():
        assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= width and box.y1 <= height, (text, box.bounds)
    heads = [boxes[id(artist)] for artist in [*titles, *legends] if id(artist) in boxes]
    for a in range(len(heads)):
        for b in range(a + 1, len(heads)):
            assert not heads[a][1].overlaps(heads[b][1]), (heads[a][0], heads[b][0])


def dof_of(label: str) -> str:
    """The DOF (``"x"``... ``"rz"``) a time panel's axis label names in words (``"about x [mrad]"`` -> ``"rx"``);
    any other label's quantity as it is (``"force [N]"`` -> ``"force"``)."""
    from sixdof.dofs import DOFS
    from sixdof.plots.common import DOF_DIRECTIONS

    quantity = label.split(" [", 1)[0]
    return dict(zip(DOF_DIRECTIONS, DOFS)).get(quantity, quantity)
