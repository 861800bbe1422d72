"""The excitation's breakpoints, padded to few compiled shapes, that the step control steps onto."""

from __future__ import annotations

import numpy as np

from sixdof.excitation import Excitation


def jump_times(excitation: Excitation, t0: float, t1: float) -> tuple[np.ndarray, int]:
    """The excitation's breakpoints [s] inside ``(t0, t1)`` for the step control, padded beyond ``t1`` with
    distinct, never reached times to a power-of-two length >= 8 (few compiled shapes), none if there are none
    (:func:`solve_ode` then traces no clipping), and their count."""
    jumps = np.array(sorted(b for b in excitation.breakpoints if t0 < b < t1), dtype=float)
    return _padded(jumps, t1, _jump_slots(jumps.size)), int(jumps.size)


def _jump_slots(count: int) -> int:
    return 0 if count == 0 else max(8, 1 << (count - 1).bit_length())


def _inside(breakpoints: np.ndarray, t0: float, t1: float) -> slice:
    """The sorted ``breakpoints`` strictly inside ``(t0, t1)``: those the step control must step onto."""
    return slice(int(np.searchsorted(breakpoints, t0, "right")), int(np.searchsorted(breakpoints, t1, "left")))


def _padded(jumps: np.ndarray, t1: float, size: int) -> np.ndarray:
    return np.concatenate([jumps, t1 + 1.0 + np.arange(size - jumps.size)])
