"""Peak responses of a system under a suite of ground accelerograms, and their design value (EN 1998-1 4.3.3.4.3).

Each record drives the foundation as a ground acceleration table (a first-order hold, as
``[ground] signal = { kind = "table" }`` does) along one direction; the direct solve
(:func:`sixdof.analysis.direct.simulate`) integrates eq. (1), and the peaks of each run are taken from its samples:
|q| relative to the ground per DOF, the mounts' dynamic deflections and loads along their own axes u, v, w
(:func:`sixdof.analysis.response.mount_forces`, as :mod:`sixdof.analysis.mountcheck` forms them), the force and
moment on the foundation and the base shear (the foundation force's resultant in the body's x-y plane).

EN 1998-1:2004 4.3.3.4.3(3): with at least 7 time-history analyses the design value of a response is the average of
the analyses' values, otherwise the most unfavourable (:func:`design_value`). Peaks are magnitudes, so "most
unfavourable" is the largest and the average is that of the magnitudes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.analysis.direct import SimulationSettings, simulate
from sixdof.analysis.frf.points import parse_direction
from sixdof.analysis.matching import EC8_MEAN_RECORDS
from sixdof.analysis.response import mount_forces
from sixdof.dofs import motion_units
from sixdof.errors import InputError, Plain, instance, readonly
from sixdof.excitation import Excitation, GroundMotion, Table
from sixdof.model.system import System
from sixdof.results import Result, label, quantity, result_type

#: The rules of :func:`design_value`.
RULES = {"mean": f"mean of the records' peaks (at least {EC8_MEAN_RECORDS} records, EN 1998-1 4.3.3.4.3(3))",
         "max": f"most unfavourable record (fewer than {EC8_MEAN_RECORDS} records, EN 1998-1 4.3.3.4.3(3))"}


def design_value(peaks) -> tuple[np.ndarray, str]:
    """The design value of a response from its peaks under each record (EN 1998-1 4.3.3.4.3(3)).

    Parameters
    ----------
    peaks : array_like, shape (records, ...)
        Peak values of each record (any unit; signs are dropped).

    Returns
    -------
    value : ndarray, shape (...)
        The mean of ``|peaks|`` over the records with at least :data:`EC8_MEAN_RECORDS` of them, else the largest.
    rule : str
        ``"mean"`` or ``"max"`` (described in :data:`RULES`).
    """
    peaks = np.abs(np.asarray(peaks, dtype=float))
    if peaks.ndim < 1 or peaks.shape[0] < 1:
        raise InputError("peaks", "an array (records, ...) of at least one record", Plain(f"shape {peaks.shape}"))
    if peaks.shape[0] >= EC8_MEAN_RECORDS:
        return peaks.mean(axis=0), "mean"
    return peaks.max(axis=0), "max"


@result_type
@dataclass(frozen=True, eq=False)
class RecordPeaks(Result):
    """Peak responses under each record of a suite and their design values (:func:`record_peaks`).

    Attributes
    ----------
    direction : tuple of float
        The ground's direction (unit 3-vector, body axes).
    rule : str
        ``"mean"`` or ``"max"`` (:func:`design_value`, :data:`RULES`).
    names : tuple of str
        The mounts.
    peak_q : ndarray, shape (record, dof)
        Peak |q| relative to the ground [m, rad].
    peak_deflection, peak_force : ndarray, shape (record, mount, mount_axis)
        Peak |dynamic deflection| [m] and |dynamic load| [N] of each mount along its axes u, v, w.
    peak_base_force, peak_base_moment : ndarray, shape (record, axis)
        Peak |force| [N] and |moment| about the centre of gravity [N m] on the foundation, per body axis.
    peak_base_shear : ndarray, shape (record,)
        Peak of the foundation force's resultant in the body's x-y plane [N].
    design_* : ndarray
        The design values of the peaks above (their shapes without the record axis).
    """

    direction: tuple[float, float, float] = label(decode=lambda v: tuple(float(x) for x in v))
    rule: str = label(decode=str)
    names: tuple[str, ...] = quantity("", ("mount",), name="mount", decode=lambda a: tuple(str(n) for n in a))
    peak_q: np.ndarray = quantity(motion_units(0), ("record", "dof"),
                                  description="peak |q| relative to the ground under each record")
    peak_deflection: np.ndarray = quantity("m", ("record", "mount", "mount_axis"),
                                           description="peak |dynamic deflection| of each mount, mount axes")
    peak_force: np.ndarray = quantity("N", ("record", "mount", "mount_axis"),
                                      description="peak |dynamic load| on each mount, mount axes")
    peak_base_force: np.ndarray = quantity("N", ("record", "axis"), description="peak |force| on the foundation")
    peak_base_moment: np.ndarray = quantity("N m", ("record", "axis"),
                                            description="peak |moment| on the foundation about the centre of gravity")
    peak_base_shear: np.ndarray = quantity("N", ("record",),
                                           description="peak foundation force resultant in the body's x-y plane")
    design_q: np.ndarray = quantity(motion_units(0), ("dof",), description="design value of peak_q")
    design_deflection: np.ndarray = quantity("m", ("mount", "mount_axis"),
                                             description="design value of peak_deflection")
    design_force: np.ndarray = quantity("N", ("mount", "mount_axis"), description="design value of peak_force")
    design_base_force: np.ndarray = quantity("N", ("axis",), description="design value of peak_base_force")
    design_base_moment: np.ndarray = quantity("N m", ("axis",), description="design value of peak_base_moment")
    design_base_shear: float = label(decode=float)


def _records(records) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    found = []
    for i, record in enumerate(records):
        try:
            t, a = (np.asarray(x, dtype=float) for x in record)
        except (TypeError, ValueError):
            raise InputError(f"records[{i}]", "a pair (t [s], a [m/s^2]) of arrays", record) from None
        if t.ndim != 1 or t.size < 2 or a.shape != t.shape or not np.all(np.isfinite(a)):
            raise InputError(f"records[{i}]", "a pair (t, a) of equal-length arrays, finite", Plain(
                f"shapes {t.shape} and {a.shape}"))
        found.append((t, a))
    if not found:
        raise InputError("records", "at least one record (t, a)", Plain("none"))
    return tuple(found)


def _peaks(system: System, t, a, direction, sample_rate_hz: float | None) -> dict[str, np.ndarray]:
    """The peaks of one record's run (see :class:`RecordPeaks`)."""
    ground = GroundMotion(quantity="acceleration", direction=direction, signal=Table(t=t - t[0], values=a))
    rate = sample_rate_hz or 1.0 / float(t[1] - t[0])
    response = simulate(system, Excitation(ground=ground), SimulationSettings(duration=float(t[-1] - t[0]),
                                                                              sample_rate_hz=rate))
    forces = mount_forces(system, response)
    axes = np.asarray(system.axes)
    deflection = np.einsum("mij,mnj->mni", axes, np.asarray(forces.deformation))
    base = np.asarray(forces.foundation_force)
    return dict(peak_q=np.max(np.abs(response.q_relative), axis=0),
                peak_deflection=np.max(np.abs(deflection), axis=1),
                peak_force=np.max(np.abs(np.asarray(forces.local)), axis=1),
                peak_base_force=np.max(np.abs(base), axis=0),
                peak_base_moment=np.max(np.abs(np.asarray(forces.foundation_moment)), axis=0),
                peak_base_shear=np.max(np.hypot(base[:, 0], base[:, 1])))


def record_peaks(system: System, records, direction, *, sample_rate_hz: float | None = None) -> RecordPeaks:
    """Run ``system`` under each ground acceleration record and combine the peaks (EN 1998-1 4.3.3.4.3(3)).

    Parameters
    ----------
    system : sixdof.model.system.System
    records : sequence of (t, a)
        Each a ground acceleration record: uniform times [s] (shifted to start at 0) and accelerations [m/s^2],
        e.g. :attr:`sixdof.analysis.matching.SpectrumCompatibleRecords.records`. Each run lasts its record.
    direction : {"x", "y", "z"} or array_like, shape (3,)
        The ground's direction, body axes.
    sample_rate_hz : float, optional
        Samples of each run at which the peaks are sought [Hz]; default the record's own rate.

    Returns
    -------
    RecordPeaks
    """
    instance(system, "system", System)
    records = _records(records)
    vector, _ = parse_direction(direction, "direction", rotations=False)
    runs = [_peaks(system, t, a, vector, sample_rate_hz) for t, a in records]
    peaks = {key: np.array([run[key] for run in runs]) for key in runs[0]}
    design = {}
    for key, values in peaks.items():
        design[key.replace("peak_", "design_")], rule = design_value(values)
    return RecordPeaks(direction=tuple(float(x) for x in vector), rule=rule, names=tuple(system.mount_names),
                       **{k: readonly(v) for k, v in peaks.items()},
                       **{k: readonly(v) for k, v in design.items() if k != "design_base_shear"},
                       design_base_shear=float(design["design_base_shear"]))
