"""Agreement of two time histories, DOF by DOF: the cross-check of every direct solve."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.dofs import DOFS
from sixdof.errors import InputError, number, readonly
from sixdof.results import label

#: Default tolerance of :func:`compare`.
AGREEMENT_TOLERANCE = 1e-6
#: In :func:`compare`, a DOF whose peak is below this fraction of the largest peak (rotations
#: converted to lengths) is "quiet": its error is measured against the largest peak instead.
QUIET_RTOL = 1e-6


def column_peaks(values) -> np.ndarray:
    """The largest magnitude of each column of ``values`` (n, k), shape (k,); zeros when n = 0.

    Reduced along the rows of a transposed copy of the magnitudes: numpy reduces across the rows of a narrow
    array several times slower (for 20,001 x 6: 0.44 against 0.06 ms, the copy included).
    """
    return np.abs(np.asarray(values, dtype=float).T, order="C").max(axis=1, initial=0.0)


@dataclass(frozen=True, eq=False)
class Agreement:
    """Agreement of two time histories of ``q``, DOF by DOF (result of :func:`compare`).

    Attributes
    ----------
    per_dof : ndarray, shape (6,)
        ``max_t |q_ref - q_other| / peak_t |q_ref|`` for each DOF (dimensionless; quiet DOFs: see
        :func:`compare`).
    worst_dof : str
        Name of the DOF with the largest value of ``per_dof``.
    worst : float
        That value.
    tolerance : float
        Largest acceptable value of ``worst``.
    ok : bool
        ``worst <= tolerance``.
    peak : ndarray, shape (6,)
        ``peak_t |q_ref|`` of each DOF [m, rad].
    error : ndarray, shape (6,)
        ``max_t |q_ref - q_other|`` of each DOF [m, rad].
    quiet : tuple of str
        DOFs whose response is negligible, judged against the largest peak.
    length : float
        Length [m] converting rotations to displacements when DOFs are compared with each other.
    absolute_peak : ndarray, shape (6,), or None
        ``peak_t |q|`` of the reference's absolute motion [m, rad] when ``q_ref`` is relative to a moving
        ground: :data:`QUIET_RTOL` of its largest is the floor of every denominator (see :func:`compare`).
    """

    per_dof: np.ndarray = label()
    worst_dof: str = label()
    worst: float = label()
    tolerance: float = label()
    ok: bool = label(decode=bool)
    peak: np.ndarray = label()
    error: np.ndarray = label()
    quiet: tuple[str, ...] = label()
    length: float = label()
    absolute_peak: np.ndarray | None = label(default=None)

    derived = {"definition": label()}

    @property
    def denominator(self) -> np.ndarray:
        """What each DOF's error is divided by, (6,) [m, rad]: its peak, or for a quiet DOF the larger of the
        largest peak and the floor from the absolute motion, in its unit (see :func:`compare`)."""
        scale = np.array([1.0, 1.0, 1.0, self.length, self.length, self.length])
        return np.where(np.isin(DOFS, self.quiet), max(float(np.max(self.peak * scale)), self.floor) / scale,
                        self.peak)

    @property
    def floor(self) -> float:
        """The floor of the denominators [m]: :data:`QUIET_RTOL` of the largest absolute motion (rotations times
        ``length``), 0 without ground motion."""
        if self.absolute_peak is None:
            return 0.0
        scale = np.array([1.0, 1.0, 1.0, self.length, self.length, self.length])
        return QUIET_RTOL * float(np.max(np.asarray(self.absolute_peak) * scale))

    @property
    def definition(self) -> str:
        """What ``per_dof`` measures (stored beside it)."""
        return ("per DOF: max_t |q_ref - q| / max_t |q_ref| (quiet DOFs: / the largest peak, rotations times "
                "length; relative to a moving ground, no denominator below 1e-6 of the largest absolute motion)")

    def __str__(self) -> str:
        values = ", ".join(f"{d} {v:.2e}" for d, v in zip(DOFS, self.per_dof))
        return (f"worst {self.worst:.2e} ({self.worst_dof}) vs tolerance {self.tolerance:.0e}: "
                f"{'ok' if self.ok else 'OVER TOLERANCE'}\n  per DOF: {values}")


def relative_to_ground(direct, modal) -> tuple[np.ndarray, np.ndarray]:
    """The displacements (n, 6) [m, rad] of two histories that the cross-check compares: relative to the
    ground when it moves, the direct solve's ground taken from both.

    Their difference is that of the absolute motions, but each DOF is judged against the peak of its motion
    relative to the ground (what deforms the mounts), not against a ground that may drift away (a base
    half-sine leaves the ground moving: its 528 mm hid the electronics box's 7 mm stroke, and errors 75 times
    larger than the ones reported)."""
    ground = getattr(direct, "ground_displacement", None)
    if ground is None:
        return np.asarray(direct.q), np.asarray(modal.q)
    shift = np.hstack([np.asarray(ground), np.zeros((len(ground), 3))])
    return np.asarray(direct.q) - shift, np.asarray(modal.q) - shift


def compare(direct_q, modal_q, tolerance: float = AGREEMENT_TOLERANCE, *, length: float = 1.0,
            quiet_rtol: float = QUIET_RTOL, absolute=None) -> Agreement:
    """Agreement of a modal-superposition history with a reference (direct) one, DOF by DOF.

    For each DOF i: ``max_t |q_ref_i - q_i| / peak_t |q_ref_i|``, each DOF relative to its own peak,
    so that rotations (~1e-7 rad) and translations (~1e-4 m) are each judged on their own scale.

    A DOF that hardly moves cannot be judged on its own peak (its peak is round-off, or a remote
    coupling): when ``peak_i * s_i < quiet_rtol * max_j(peak_j * s_j)``, with ``s`` = 1 for
    translations and ``length`` [m/rad] for rotations, DOF i is *quiet* and its error is divided by
    ``max_j(peak_j * s_j) / s_i`` instead (the largest response expressed in its unit). When the
    reference is identically zero, the error is ``0`` if the histories are identical, else ``inf``.

    Histories relative to a moving ground (``absolute`` given) have a floor: the difference of two absolute
    motions cannot be resolved below round-off of those motions, so a DOF whose relative peak is below
    ``quiet_rtol`` times the largest absolute motion (``max_j(abs_peak_j * s_j)``) is quiet too, and no
    DOF's denominator is below that floor. A body that rides a pre-displaced ground (relative motion zero,
    the two solutions ~1e-17 m apart) is then judged against a millionth of the ground's displacement, not
    called infinitely wrong. Without ground motion the floor is the quiet threshold itself: nothing changes.

    Parameters
    ----------
    direct_q, modal_q : array_like, shape (n, 6), or objects with a ``q`` attribute
        Reference and compared histories of q [m, rad] on the same time grid.
    tolerance : float
        Largest acceptable relative error (default 1e-6).
    length : float
        Length [m] converting rotations into displacements for the quiet test (e.g. the body's
        half-size); default 1 m.
    quiet_rtol : float
        Relative size below which a DOF is quiet (default 1e-6).
    absolute : array_like, shape (n, 6), optional
        The reference's absolute motion [m, rad] when ``direct_q`` is relative to a moving ground.

    Returns
    -------
    Agreement

    Raises
    ------
    InputError
        If the shapes differ or are not (n, 6), or a value is not finite, or ``tolerance`` /
        ``length`` is not positive.
    """
    ref = _history(direct_q, "direct_q")
    other = _history(modal_q, "modal_q")
    if ref.shape != other.shape:
        raise InputError("modal_q", f"shape {ref.shape} like direct_q", f"shape {other.shape}")
    for name, value in (("tolerance", tolerance), ("length", length), ("quiet_rtol", quiet_rtol)):
        number(value, name, "a positive number", low=0.0, strict=True)
    absolute = None if absolute is None else column_peaks(_history(absolute, "absolute"))
    return agreement_of(column_peaks(ref), column_peaks(ref - other), tolerance,
                        length=length, quiet_rtol=quiet_rtol, absolute_peak=absolute)


def agreement_of(peak, error, tolerance: float = AGREEMENT_TOLERANCE, *, length: float = 1.0,
                 quiet_rtol: float = QUIET_RTOL, absolute_peak=None) -> Agreement:
    """The :class:`Agreement` of histories with these per-DOF peaks of the reference and largest differences
    [m, rad] (see :func:`compare`; ``absolute_peak``: the peaks of the reference's absolute motion, relative
    histories only): how a run made of time windows combines its windows' maxima."""
    peak, error = (np.asarray(x, dtype=float) for x in (peak, error))
    scale = np.array([1.0, 1.0, 1.0, length, length, length])
    largest = float(np.max(peak * scale))
    floor = 0.0 if absolute_peak is None else quiet_rtol * float(np.max(np.asarray(absolute_peak) * scale))
    quiet = (peak * scale < quiet_rtol * largest) | (peak * scale < floor)
    denominator = np.where(quiet, max(largest, floor) / scale, peak)
    with np.errstate(divide="ignore", invalid="ignore"):
        per_dof = np.where(denominator > 0, error / denominator, np.where(error > 0, np.inf, 0.0))
    worst_index = int(np.argmax(per_dof))
    worst = float(per_dof[worst_index])
    return Agreement(per_dof=readonly(per_dof), worst_dof=DOFS[worst_index], worst=worst, tolerance=float(tolerance),
                     ok=bool(worst <= tolerance), peak=readonly(peak), error=readonly(error), length=float(length),
                     quiet=tuple(d for d, flag in zip(DOFS, quiet) if flag and max(largest, floor) > 0),
                     absolute_peak=None if absolute_peak is None else readonly(np.asarray(absolute_peak, dtype=float)))


def merge_agreements(agreements) -> Agreement:
    """One :class:`Agreement` over consecutive time windows from each window's (same tolerance and length)."""
    first = agreements[0]
    absolute = None if first.absolute_peak is None else np.max([a.absolute_peak for a in agreements], axis=0)
    return agreement_of(np.max([a.peak for a in agreements], axis=0), np.max([a.error for a in agreements], axis=0),
                        first.tolerance, length=first.length, absolute_peak=absolute)


def _history(value, name: str) -> np.ndarray:
    """``value`` (or its ``q``) as an array of shape (n, 6) of finite values [m, rad]."""
    value = getattr(value, "q", value)
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(name, "an array of shape (n, 6) in m and rad", value) from None
    if array.ndim != 2 or array.shape[1] != 6 or array.shape[0] < 1:
        raise InputError(name, "an array of shape (n, 6) in m and rad", f"shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(name, "finite values", "non-finite values")
    return array
