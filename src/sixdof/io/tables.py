"""How sixdof lays out its text: the one Markdown table formatter (:func:`table`), prose wrapped to
:data:`LINE` characters, and values at round-off shown as 0."""

from __future__ import annotations

import textwrap
from collections.abc import Sequence

import numpy as np


def table(headers: Sequence[str], rows: Sequence[Sequence[object]], align: str | None = None) -> str:
    """A Markdown pipe table, columns padded so it also reads well in a terminal.

    ``align`` gives one character per column: ``l`` left, ``r`` right (default: first column left,
    others right).
    """
    cells = [[str(h) for h in headers]] + [[str(c) for c in row] for row in rows]
    align = align or "l" + "r" * (len(headers) - 1)
    widths = [max(len(row[i]) for row in cells) for i in range(len(headers))]

    def line(row):
        padded = (c.ljust(w) if a == "l" else c.rjust(w) for c, w, a in zip(row, widths, align))
        return "| " + " | ".join(padded) + " |"

    rule = "|" + "|".join(("-" * (w + 1) + ":") if a == "r" else ("-" * (w + 2)) for w, a in zip(widths, align)) + "|"
    return "\n".join([line(cells[0]), rule, *(line(r) for r in cells[1:])])


#: In the printed tables, a value at most this fraction of the largest of its table is round-off, shown as 0.
SHOWN_AS_ZERO_RTOL = 1e-12


def without_round_off(values, scale=1.0, axis=None) -> np.ndarray:
    """``values`` with those at round-off of the largest (each times ``scale``, to compare units) set to 0: the
    largest of all, or along ``axis`` (an int or a tuple of them: each row's own largest)."""
    values = np.asarray(values, dtype=float)
    size = np.abs(values) * scale
    return np.where(size > SHOWN_AS_ZERO_RTOL * np.max(size, axis=axis, keepdims=True, initial=0.0), values, 0.0)


def fixed(value: float, digits: int) -> str:
    """``value`` with ``digits`` decimals, never "-0.000" (a value that rounds to zero has no sign)."""
    text = f"{value:.{digits}f}"
    return text.lstrip("-") if float(text) == 0 else text


def wrapped(text: str) -> str:
    """Prose for the terminal and the summary: lines of at most :data:`LINE` characters."""
    return textwrap.fill(text, LINE)


#: Longest line of prose printed.
LINE = 100

