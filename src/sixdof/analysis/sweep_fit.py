"""What moves each natural frequency in a sweep: the swept parameters read off the variants, and a linear
least-squares fit of each tracked mode's frequency on them (:func:`sweep_sensitivity`), drawn as a tornado chart
by :func:`sixdof.plots.sweep.plot_sweep_sensitivity`.

Why a fit and not one parameter at a time: a sweep's variants draw every parameter at once (random draws, one
per mount and axis with ``independent``, or a grids' full factorial), so no pair of variants differs in one
parameter alone. The least-squares slope of a frequency on all the parameters together is each one's effect
with the others accounted for; for a one-at-a-time design it is that design's finite difference. Natural
frequencies go as the square root of stiffness, near enough to linear over a tolerance band (+-30 %: the
coefficient of determination R^2 of the bundled bridge's fit is above 0.99), and R^2 says where it is not
(interactions, crossing modes): there the boxes of the distributions are the answer, not the bars.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.dofs import AXES, MOUNT_AXES
from sixdof.errors import readonly

#: The percentiles of each parameter's draws that a tornado bar spans (those of the sweep's summary).
SPAN_PERCENTILES = (5.0, 95.0)
#: Names and units of the swept fields of :class:`~sixdof.analysis.batch.Variants`: (field, words, unit, axes).
_FIELDS = (("stiffness_factor", "stiffness", "factor", MOUNT_AXES),
           ("damping_factor", "damping", "factor", MOUNT_AXES),
           ("position_offset", "position", "m", AXES))


@dataclass(frozen=True)
class SweepSensitivity:
    """Result of :func:`sweep_sensitivity`: each swept parameter's effect on each elastic mode's frequency.

    Attributes
    ----------
    parameters : tuple of str
        Each swept parameter in words (``"stiffness of mounts 1, 2 (w)"``): the variants' columns that vary,
        those drawn together (one shared draw) as one.
    units : tuple of str
        Each parameter's unit: ``"factor"`` (stiffness, damping) or ``"m"`` (position offsets).
    low, high : ndarray, shape (n_params,)
        Each parameter's 5th and 95th percentile over the variants (:data:`SPAN_PERCENTILES`).
    modes : ndarray of int, shape (n_modes,)
        The nominal modes fitted (indices from 0): those with a natural frequency above 0.
    nominal_hz : ndarray, shape (n_modes,)
        Their nominal natural frequencies [Hz].
    slope : ndarray, shape (n_modes, n_params)
        d(frequency) / d(parameter) of the fit [Hz per factor, Hz per m].
    effect_low_hz, effect_high_hz : ndarray, shape (n_modes, n_params)
        The fitted change of the frequency [Hz] as the parameter goes from its median to ``low`` and to ``high``,
        the others at their medians: the two ends of a tornado bar.
    r_squared : ndarray, shape (n_modes,)
        The fit's coefficient of determination (1: the linear fit explains all of the spread; NaN: the frequency
        does not vary).
    variants : int
        Variants fitted (those in which every fitted mode was found).
    """

    parameters: tuple[str, ...]
    units: tuple[str, ...]
    low: np.ndarray
    high: np.ndarray
    modes: np.ndarray
    nominal_hz: np.ndarray
    slope: np.ndarray
    effect_low_hz: np.ndarray
    effect_high_hz: np.ndarray
    r_squared: np.ndarray
    variants: int


def _mounts(names: list[str]) -> str:
    return f"mount {names[0]}" if len(names) == 1 else f"mounts {', '.join(names)}"


def swept_parameters(variants, mount_names) -> tuple[np.ndarray, tuple[str, ...], tuple[str, ...]]:
    """The parameters a sweep varies, read off its variants alone.

    Every (field, mount, axis) column of :class:`~sixdof.analysis.batch.Variants` whose values differ between
    variants is swept; columns equal in every variant come from one shared draw and are one parameter.

    Parameters
    ----------
    variants : sixdof.analysis.batch.Variants
    mount_names : sequence of str

    Returns
    -------
    values : ndarray, shape (nv, n_params)
        Each variant's value of each parameter (a factor, or an offset [m]).
    parameters, units : tuple of str
        Each parameter in words, and its unit.
    """
    columns, parameters, units = [], [], []
    for field, words, unit, axes in _FIELDS:
        values = np.asarray(getattr(variants, field))
        groups: dict[bytes, list[tuple[int, int]]] = {}
        for m in range(values.shape[1]):
            for a in range(values.shape[2]):
                column = values[:, m, a]
                if column.size and np.ptp(column) > 0:
                    groups.setdefault(np.ascontiguousarray(column).tobytes(), []).append((m, a))
        for members in groups.values():
            m0, a0 = members[0]
            columns.append(values[:, m0, a0])
            mounts = list(dict.fromkeys(str(mount_names[m]) for m, _ in members))
            used = "".join(axes[a] for a in sorted({a for _, a in members}))
            parameters.append(f"{words} of {_mounts(mounts)} ({', '.join(used)})")
            units.append(unit)
    count = np.asarray(variants.stiffness_factor).shape[0]
    values = np.stack(columns, axis=1) if columns else np.zeros((count, 0))
    return values, tuple(parameters), tuple(units)


def sweep_sensitivity(result, system) -> SweepSensitivity | None:
    """Each swept parameter's effect on each elastic mode's natural frequency: a linear least-squares fit of the
    frequency of each nominal mode, followed by its shape (``tracked_frequency_hz``; ``frequency_hz`` in files
    without it), on the swept parameters (:func:`swept_parameters`). See the module for why a fit.

    Parameters
    ----------
    result : sixdof.analysis.batch.BatchResult
        A sweep's variants.
    system : sixdof.model.system.System
        The nominal system (its modes and mount names).

    Returns
    -------
    SweepSensitivity or None
        ``None`` where nothing is swept or the variants are too few to fit (at least two more than the
        parameters).
    """
    values, parameters, units = swept_parameters(result.variants, system.mount_names)
    frequency = result.frequency_hz if result.tracked_frequency_hz is None else result.tracked_frequency_hz
    frequency = np.asarray(frequency, dtype=float)
    modes = np.flatnonzero(system.modes.frequency_hz > 0)
    rows = np.all(np.isfinite(frequency[:, modes]), axis=1)
    if not parameters or not modes.size or rows.sum() < len(parameters) + 2:
        return None
    x, f = values[rows], frequency[rows][:, modes]
    median = np.median(x, axis=0)
    design = np.hstack([np.ones((len(x), 1)), x - median])
    coefficients, *_ = np.linalg.lstsq(design, f, rcond=None)
    slope = coefficients[1:].T  # (n_modes, n_params)
    residual = f - design @ coefficients
    total = ((f - f.mean(axis=0)) ** 2).sum(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        r_squared = np.where(total > 0, 1.0 - (residual ** 2).sum(axis=0) / total, np.nan)
    low, high = np.percentile(x, SPAN_PERCENTILES, axis=0)
    return SweepSensitivity(
        parameters=parameters, units=units, low=readonly(low), high=readonly(high), modes=readonly(modes, int),
        nominal_hz=readonly(system.modes.frequency_hz[modes]), slope=readonly(slope),
        effect_low_hz=readonly(slope * (low - median)), effect_high_hz=readonly(slope * (high - median)),
        r_squared=readonly(r_squared), variants=int(rows.sum()))


__all__ = ["SPAN_PERCENTILES", "SweepSensitivity", "sweep_sensitivity", "swept_parameters"]
