"""Zooms of the time-history figures: the span worth drawing again beside a whole record (an excitation's shock
or switch-on, else the largest excursion) and the samples a zoom draws."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from sixdof.results import Event

#: A shock's zoom spans this many times its pulse; a switch-on's (and :func:`zoom_window`'s), this many
#: periods of its forcing (of the dominant motion); a zoom covers at most this fraction of the record
#: (a wider one would show what the whole record shows), a shock's at least :data:`ZOOM_MIN_PULSES` pulses.
ZOOM_PULSES = 25
ZOOM_PERIODS = 6
ZOOM_MAX_FRACTION = 0.25
ZOOM_MIN_PULSES = 4


def zoom_samples(t: np.ndarray, window) -> slice:
    """The samples of ``t`` a zoom on ``window`` (start, end [s], ...) draws: those inside and one either
    side (a zoom draws its own samples, not the whole record's per-pixel envelope)."""
    first = max(int(np.searchsorted(t, window[0], side="right")) - 1, 0)
    return slice(first, int(np.searchsorted(t, window[1], side="left")) + 1)


def event_window(events: Mapping[str, Event], t) -> tuple[float, float, str] | None:
    """``(start, end, label)`` [s] of the zoom on the excitation's ``events`` over the record ``t``:
    the shortest shock (:data:`ZOOM_PULSES` pulse lengths, from a tenth of that before it, at most
    :data:`ZOOM_MAX_FRACTION` of the record and at least :data:`ZOOM_MIN_PULSES` pulses), else the first
    switch-on (:data:`ZOOM_PERIODS` forcing periods, at most that fraction of the record). None when no
    event needs one (the whole record shows it already)."""
    t = np.asarray(t, dtype=float)
    duration = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    shocks = sorted((e.duration, e.start, n) for n, e in events.items() if e.kind == "shock")
    starts = sorted((e.start, e.duration, n) for n, e in events.items() if e.kind == "switch-on" and e.duration > 0)
    longest = ZOOM_MAX_FRACTION * duration
    choices = [(min(ZOOM_PULSES * length, longest), start, f"{n} (shock, {length * 1e3:.3g} ms at t = {start:.4g} s)")
               for length, start, n in shocks if ZOOM_MIN_PULSES * length <= longest]
    choices += [(ZOOM_PERIODS * period, start, f"{n} (switch-on at t = {start:.4g} s)") for start, period, n in starts]
    for width, start, label in choices:
        if 0 < width <= longest:
            low = min(max(start - 0.1 * width, t[0]), t[-1] - width)
            return float(low), float(low + width), label
    return None


def zoom_window(t: np.ndarray, dynamic: np.ndarray) -> tuple[float, float, str] | None:
    """``(start, end, label)`` [s] of the span around the largest ``|dynamic|`` (any row of (rows, n))
    covering :data:`ZOOM_PERIODS` periods of its row's dominant motion (from its zero crossings), within
    the record; None when that
    span would cover more than a third of the record (the whole record shows it already) or the row
    does not move."""
    k, i = np.unravel_index(np.argmax(np.abs(dynamic)), dynamic.shape)
    row = dynamic[k]
    duration = t[-1] - t[0]
    if duration <= 0 or not np.any(row):
        return None
    crossings = np.count_nonzero(np.diff(np.signbit(row - np.mean(row))))
    if crossings < 2:
        return None
    width = ZOOM_PERIODS * 2.0 * duration / crossings  # a period is two crossings
    if width > ZOOM_MAX_FRACTION * duration:
        return None
    start = min(max(t[i] - width / 2, t[0]), t[-1] - width)
    return float(start), float(start + width), "the largest excursion"
