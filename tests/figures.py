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
