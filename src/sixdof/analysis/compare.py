"""Agreement of two time histories, DOF by DOF: the cross-check of every direct solve."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.dofs import DOFS
from sixdof.errors import InputError, number, readonly
from sixdof.results import label, result_type

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


@result_type
@dataclass(frozen=True, eq=False)
class Agreement:
    """Agreement of two time histories of ``q``, DOF by DOF (result of :func:`compare`), and with
    :func:`compare_motion` of their velocities ``qd`` and accelerations ``qdd`` too.

    Attributes
    ----------
    per_dof : ndarray, shape (6,)
        ``max_t |q_ref - q_other| / peak_t |q_ref|`` for each DOF (dimensionless; quiet DOFs: see
        :func:`compare`).
    worst_dof : str
        Name of the DOF with the largest relative difference of all quantities compared.
    worst : float
        That value [1].
    worst_quantity : str
        The quantity it is in: ``"q"``, ``"qd"`` or ``"qdd"``.
    tolerance : float
        Largest acceptable value of ``worst`` [1].
    ok : bool
        ``worst <= tolerance``: the verdict over every quantity compared.
    peak : ndarray, shape (6,)
        ``peak_t |q_ref|`` of each DOF [m, rad].
    error : ndarray, shape (6,)
        ``max_t |q_ref - q_other|`` of each DOF [m, rad].
    quiet : tuple of str
        DOFs whose displacement is negligible, judged against the largest peak (or the floor).
    length : float
        Length [m] converting rotations to displacements when DOFs are compared with each other.
    absolute_peak : ndarray, shape (6,), or None
        ``peak_t |q|`` of the reference's absolute motion [m, rad] when ``q_ref`` is relative to a moving
        ground: :data:`QUIET_RTOL` of its largest is the floor of every denominator (see :func:`compare`).
    per_dof_qd, peak_qd, error_qd, absolute_peak_qd : ndarray, shape (6,), or None
        The same for the velocities [m/s, rad/s] (:func:`compare_motion`; ``None`` from :func:`compare`).
    per_dof_qdd, peak_qdd, error_qdd, absolute_peak_qdd : ndarray, shape (6,), or None
        The same for the accelerations [m/s^2, rad/s^2].
    omega : float or None
        The angular frequency [rad/s] turning the largest displacement into the velocities' and accelerations'
        floors (:func:`compare_motion`).
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
    worst_quantity: str = label(default="q")
    per_dof_qd: np.ndarray | None = label(default=None)
    peak_qd: np.ndarray | None = label(default=None)
    error_qd: np.ndarray | None = label(default=None)
    absolute_peak_qd: np.ndarray | None = label(default=None)
    per_dof_qdd: np.ndarray | None = label(default=None)
    peak_qdd: np.ndarray | None = label(default=None)
    error_qdd: np.ndarray | None = label(default=None)
    absolute_peak_qdd: np.ndarray | None = label(default=None)
    omega: float | None = label(default=None)

    derived = {"definition": label()}

    @property
    def rates(self) -> bool:
        """Whether velocities and accelerations were compared too (:func:`compare_motion`)."""
        return self.per_dof_qd is not None

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
                "length; relative to a moving ground, no denominator below 1e-6 of the largest absolute motion)"
                + ("; the same for qd and qdd" if self.rates else ""))

    def __str__(self) -> str:
        def values(per_dof):
            return ", ".join(f"{d} {v:.2e}" for d, v in zip(DOFS, per_dof))

        where = f"{self.worst_dof}, {QUANTITIES[self.worst_quantity]}" if self.rates else self.worst_dof
        text = (f"worst {self.worst:.2e} ({where}) vs tolerance {self.tolerance:.0e}: "
                f"{'ok' if self.ok else 'OVER TOLERANCE'}\n  per DOF: {values(self.per_dof)}")
        if self.rates:
            text += (f"\n  per DOF, velocity: {values(self.per_dof_qd)}"
                     f"\n  per DOF, acceleration: {values(self.per_dof_qdd)}")
        return text


#: The quantities :func:`compare_motion` compares, by their :class:`~sixdof.results.TimeHistory` names.
QUANTITIES = {"q": "displacement", "qd": "velocity", "qdd": "acceleration"}
#: The ground motion each quantity is taken relative to.
_GROUND = {"q": "ground_displacement", "qd": "ground_velocity", "qdd": "ground_acceleration"}


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
        Largest acceptable relative error [1] (default 1e-6).
    length : float
        Length [m] converting rotations into displacements for the quiet test (e.g. the body's
        half-size); default 1 m.
    quiet_rtol : float
        Relative size below which a DOF is quiet [1] (default 1e-6).
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
    return agreement_of(column_peaks(ref), column_peaks(ref - other), absolute, tolerance,
                        length=length, quiet_rtol=quiet_rtol)


def compare_motion(direct, modal, tolerance: float = AGREEMENT_TOLERANCE, *, length: float = 1.0,
                   quiet_rtol: float = QUIET_RTOL, omega: float | None = None, keep=None) -> Agreement:
    """Agreement of two motions in displacement, velocity and acceleration, each DOF of each judged as
    :func:`compare` judges ``q``: relative to the ground when it moves (the direct solve's ground taken from
    both, with the floor from the absolute motion), on its own peak. The verdict is over all three.

    The direct solve's ``qd`` is its state and its ``qdd`` the equation of motion evaluated on that state;
    the superposition's are exact derivatives of its solution. Displacements alone can agree while the
    accelerations do not: an error in the high modes is ``omega^2`` times larger in ``qdd``.

    The velocities' and accelerations' floors also hold ``quiet_rtol`` times the largest displacement (relative
    or absolute) times ``omega`` and ``omega^2``: a body at rest on a displaced ground, whose velocities and
    accelerations are round-off in both paths, is judged against the motion its displacement would have at
    that frequency, not called infinitely wrong.

    Parameters
    ----------
    direct, modal : sixdof.results.TimeHistory
        Reference (direct) and compared (modal) histories on the same time grid.
    tolerance, length, quiet_rtol : float
        As in :func:`compare`: relative error [1], length [m], relative size [1].
    omega : float, optional
        The highest natural angular frequency [rad/s] (``system.modes.omega.max()``): the scale from
        displacements to velocities and accelerations for their floors. Default: no such floor.
    keep : array_like of bool, shape (n,), optional
        The samples compared (default all).

    Returns
    -------
    Agreement

    Raises
    ------
    InputError
        A tolerance, length or ``omega`` that is not a positive number; ``direct``'s or ``modal``'s ``q``,
        ``qd``, ``qdd`` not finite arrays of shape (n, 6), or of different shapes.
    """
    for name, value in (("tolerance", tolerance), ("length", length), ("quiet_rtol", quiet_rtol)):
        number(value, name, "a positive number", low=0.0, strict=True)
    if omega is not None:
        number(omega, "omega", "a positive angular frequency in rad/s", low=0.0, strict=True)
    rows = slice(None) if keep is None else np.asarray(keep, dtype=bool)
    parts = {}
    for key in QUANTITIES:
        absolute = _history(np.asarray(getattr(direct, key))[rows], f"direct.{key}")
        other = _history(np.asarray(getattr(modal, key))[rows], f"modal.{key}")
        if absolute.shape != other.shape:
            raise InputError(f"modal.{key}", f"shape {absolute.shape} like direct.{key}", f"shape {other.shape}")
        ground = getattr(direct, _GROUND[key], None)
        if ground is None:
            parts[key] = (column_peaks(absolute), column_peaks(absolute - other), None)
            continue
        shift = np.hstack([np.asarray(ground)[rows], np.zeros((absolute.shape[0], 3))])
        relative = absolute - shift
        parts[key] = (column_peaks(relative), column_peaks(relative - (other - shift)), column_peaks(absolute))
    return agreement_of(*parts["q"], tolerance, length=length, quiet_rtol=quiet_rtol,
                        rates={key: parts[key] for key in ("qd", "qdd")}, omega=omega)


def _relative_errors(peak, error, scale, quiet_rtol, size):
    """Each DOF's error over its peak, or over the largest peak (or the floor ``quiet_rtol * size``) for a quiet
    DOF: ``(per_dof, quiet)`` (see :func:`compare`)."""
    largest = float(np.max(peak * scale))
    floor = quiet_rtol * size
    quiet = (peak * scale < quiet_rtol * largest) | (peak * scale < floor)
    denominator = np.where(quiet, max(largest, floor) / scale, peak)
    with np.errstate(divide="ignore", invalid="ignore"):
        per_dof = np.where(denominator > 0, error / denominator, np.where(error > 0, np.inf, 0.0))
    return per_dof, quiet & (max(largest, floor) > 0)


def agreement_of(peak, error, absolute_peak=None, tolerance: float = AGREEMENT_TOLERANCE, *, length: float = 1.0,
                 quiet_rtol: float = QUIET_RTOL, rates=None, omega: float | None = None) -> Agreement:
    """The :class:`Agreement` of histories with these per-DOF peaks of the reference and largest differences
    [m, rad] (see :func:`compare`; ``absolute_peak``: the peaks of the reference's absolute motion, relative
    histories only; ``rates``: ``{"qd": (peak, error, absolute_peak), "qdd": (...)}`` of the velocities and
    accelerations and ``omega`` [rad/s], see :func:`compare_motion`): how a run made of time windows combines
    its windows' maxima."""
    scale = np.array([1.0, 1.0, 1.0, length, length, length])

    def arrays(p, e, a):
        return (np.asarray(p, dtype=float), np.asarray(e, dtype=float),
                None if a is None else np.asarray(a, dtype=float))

    def size(values):
        return 0.0 if values is None else float(np.max(values * scale))

    found = {"q": arrays(peak, error, absolute_peak)}
    found.update({key: arrays(*value) for key, value in (rates or {}).items()})
    displacement = max(size(found["q"][0]), size(found["q"][2]))  # the largest displacement, relative or absolute
    fields, quiet, worst = {}, None, (-1.0, "x", "q")
    for key, (p, e, a) in found.items():
        # The floor: the absolute motion's size, and for the rates the displacement's times omega (q'), omega^2 (q'').
        order = list(QUANTITIES).index(key)
        floor = max(size(a), 0.0 if key == "q" or omega is None else displacement * float(omega) ** order)
        per_dof, flags = _relative_errors(p, e, scale, quiet_rtol, floor)
        quiet = flags if quiet is None else quiet
        index = int(np.argmax(per_dof))  # a NaN is the largest (argmax returns the first one)
        if np.isnan(worst[0]):
            pass
        elif np.isnan(per_dof[index]) or per_dof[index] > worst[0]:  # the first quantity on a tie: q before its rates
            worst = (float(per_dof[index]), DOFS[index], key)
        suffix = "" if key == "q" else f"_{key}"
        fields.update({f"per_dof{suffix}": readonly(per_dof), f"peak{suffix}": readonly(p),
                       f"error{suffix}": readonly(e), f"absolute_peak{suffix}": None if a is None else readonly(a)})
    return Agreement(**fields, worst_dof=worst[1], worst=worst[0], worst_quantity=worst[2], tolerance=float(tolerance),
                     ok=bool(worst[0] <= tolerance), length=float(length),
                     quiet=tuple(d for d, flag in zip(DOFS, quiet) if flag),
                     omega=None if omega is None else float(omega))


def merge_agreements(agreements) -> Agreement:
    """One :class:`Agreement` over consecutive time windows from each window's (same tolerance and length)."""
    first = agreements[0]

    def merged(key):
        suffix = "" if key == "q" else f"_{key}"
        absolute = [getattr(a, f"absolute_peak{suffix}") for a in agreements]
        return (np.max([getattr(a, f"peak{suffix}") for a in agreements], axis=0),
                np.max([getattr(a, f"error{suffix}") for a in agreements], axis=0),
                None if absolute[0] is None else np.max(absolute, axis=0))

    return agreement_of(*merged("q"), first.tolerance, length=first.length,
                        rates={key: merged(key) for key in ("qd", "qdd")} if first.rates else None, omega=first.omega)


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
