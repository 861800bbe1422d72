"""Stationary random vibration from the FRF matrix (issue 19): the response PSDs and RMS values of the body's
motion, of its points' accelerations and of each mount's deflection and force, under a base-acceleration or
a force PSD given by breakpoints (MIL-STD-810H 514, IEC 60068-2-64), and each mode's Miles estimate.

For a single input of PSD ``S(f)`` and a response ``y = T(f) u``, ``S_y(f) = |T(f)|^2 S(f)`` and
``y_rms^2 = integral S_y df`` (Simpson's rule on a log grid fine enough for every mode's half-power band, with
the PSD's breakpoints: trapezoids there err by up to 5e-4 on a resonance's flanks, cancelling in part).
The FRFs are the receptance's (:func:`sixdof.analysis.frf.receptance`, with dashpots, Rayleigh and modal
damping and the mounts' loss factors), so the random response models the same mounts as the FRFs.

Miles' equation: a mode r of frequency f_r and quality factor Q_r = 1 / (2 zeta_r) under a PSD flat near
f_r gives its dominant DOF an acceleration RMS of ``|phi_ir p_r| sqrt(pi/2 f_r Q_r S(f_r))`` with p_r the
mode's participation in the input (``phi_r^T M r`` for the base, ``phi_r^T Q`` for a force); zeta_r
includes the mounts' loss factors (half the modal loss factor) as the FRF does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sixdof.analysis.frf import (
    hysteretic_stiffness,
    mount_impedances,
    parse_direction,
    receptance,
    support_stiffness,
)
from sixdof.analysis.statespace import damping_ratios, modal_damping_ratios
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.dofs import DOFS, MixedUnits, dof_units, mixed_units
from sixdof.errors import (
    InputError,
    Plain,
    boolean,
    check_frequencies,
    choice_check,
    finite_array,
    instance,
    integer_check,
    number_check,
    optional,
    point_check,
    readonly,
)
from sixdof.frozen import Frozen, checked
from sixdof.model.kinematics import mount_local_map, point_map, unit_load
from sixdof.model.system import System
from sixdof.results import Result, label, part, quantity, result_type
from sixdof.schema import build

#: PSD units accepted, and their factor to SI ((m/s^2)^2/Hz or N^2/Hz).
PSD_UNITS = {"g^2/Hz": STANDARD_GRAVITY**2, "(m/s^2)^2/Hz": 1.0, "N^2/Hz": 1.0}
INPUTS = ("ground_acceleration", "force")
#: Frequency points per half-power bandwidth of the most lightly damped mode in band (the grid's density).
POINTS_PER_BANDWIDTH = 20


def _breakpoints(value, field: str) -> np.ndarray:
    expected = "increasing frequencies [Hz] > 0, at least 2"
    f = finite_array(value, field, expected, (-1,))
    if f.size < 2 or np.any(f <= 0) or np.any(np.diff(f) <= 0):
        raise InputError(field, expected, value)
    check_frequencies(f[-1], field, value)
    return f


@dataclass(frozen=True)
class PSD(Frozen):
    """An input PSD by breakpoints, interpolated log-log between them and zero outside ``[f_hz[0], f_hz[-1]]``.

    Parameters
    ----------
    f_hz : array_like
        Increasing breakpoint frequencies [Hz] > 0.
    value : array_like
        The PSD at each breakpoint, > 0, in ``unit``.
    unit : {"g^2/Hz", "(m/s^2)^2/Hz", "N^2/Hz"}
    """

    f_hz: np.ndarray = checked(_breakpoints)
    value: np.ndarray = checked(lambda v, field: finite_array(v, field, "PSD values > 0, one per frequency", (-1,)))
    unit: str = "g^2/Hz"

    def __check__(self) -> None:
        if self.value.shape != self.f_hz.shape or np.any(self.value <= 0):
            raise InputError("value", f"{self.f_hz.size} PSD values > 0 (one per frequency)", self.value.tolist())
        if self.unit not in PSD_UNITS:
            raise InputError("unit", " or ".join(f"'{u}'" for u in PSD_UNITS), self.unit)

    def __call__(self, f_hz) -> np.ndarray:
        """The PSD in SI ((m/s^2)^2/Hz or N^2/Hz) at ``f_hz``."""
        f = np.asarray(f_hz, dtype=float)
        inside = (f >= self.f_hz[0]) & (f <= self.f_hz[-1])
        logs = np.interp(np.log(np.where(inside, f, self.f_hz[0])), np.log(self.f_hz), np.log(self.value))
        return np.where(inside, np.exp(logs), 0.0) * PSD_UNITS[self.unit]

    @property
    def rms(self) -> float:
        """The input's RMS in SI (m/s^2 or N): the exact integral of the log-log segments."""
        f, s = self.f_hz, self.value * PSD_UNITS[self.unit]
        span = np.log(f[1:] / f[:-1])
        # A segment S = s0 (f / f0)^b holds s0 f0 ((f1 / f0)^(b+1) - 1) / (b + 1) = s0 f0 L expm1(x) / x, with
        # L = ln(f1 / f0) and x = (b + 1) L: one form, exact as b nears -1 (where it tends to s0 f0 L), no switch.
        x = np.diff(np.log(s)) + span
        with np.errstate(divide="ignore", invalid="ignore"):
            relative = np.where(x == 0.0, 1.0, np.expm1(x) / x)
        return float(np.sqrt(np.sum(s[:-1] * f[:-1] * span * relative)))


# ----------------------------------------------------------------------------------------------------
# The time check: its settings (the ``time_check`` key of ``[random]``) and its result, which the random
# response holds; :mod:`sixdof.validation.random_time` computes it.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class TimeCheckSettings(Frozen):
    """The ``[random]`` table's ``time_check``: ``false`` to skip it, or ``{ duration, seed }``.

    Parameters
    ----------
    duration : float, optional
        Analysed record [s] (after the settling time), at least ``MIN_AVERAGES`` Welch segments of
        ``BINS_PER_BANDWIDTH`` bins per half-power bandwidth of the sharpest resonance in band. Default:
        ``AVERAGES`` such segments, at most ``MAX_DEFAULT_S`` (but never below the least); the constants of
        :mod:`sixdof.validation.random_time`.
    seed : int, optional
        Seed of the record (``numpy.random.default_rng``). Default 0.
    """

    duration: float | None = checked(optional(number_check("a positive, finite duration in s", low=0.0,
                                                           strict=True)), default=None)
    seed: int = checked(integer_check("an integer >= 0", 0), default=0)


def time_check_settings(value, field: str = "time_check") -> TimeCheckSettings | None:
    """``value`` of the scenario key: ``true`` (defaults), ``false`` (None: no check) or a table."""
    if isinstance(value, dict):
        return build(TimeCheckSettings, value, field)
    if isinstance(value, TimeCheckSettings):
        return value
    try:
        return TimeCheckSettings() if boolean(value, field) else None
    except InputError:
        raise InputError(field, "true, false or a table { duration = s, seed = integer }", value) from None


@result_type
@dataclass(frozen=True, eq=False)
class RandomTimeCheck(Result):
    """Result of :func:`~sixdof.validation.random_time.random_time_check` (stored in ``/random_time_check``).

    Attributes
    ----------
    judged : tuple of str
        What each value is: ``rms:<quantity>`` for a record's mean square, ``band:<quantity>@<fc>Hz`` for an
        octave band of a Welch PSD; quantities ``q:<dof>``, ``qdd:<dof>``, ``point:<name>:<axis>``
        (acceleration), ``mount_force:<name>:<u|v|w>``.
    frequency_rms, time_rms : ndarray, shape (judged,)
        The RMS from the FRFs and from the record, in each value's unit (``units``).
    sigma : ndarray, shape (judged,)
        The relative standard error of the record's mean square.
    z : ndarray, shape (judged,)
        The ratio of the record's mean square to the FRFs' as a standard normal value
        (:func:`~sixdof.validation.random_time.z_score`; about ``(ratio - 1) / sigma`` while sigma is small).
    f_hz : ndarray, shape (nf,)
        Welch bins [Hz].
    band_hz : (float, float)
        The input PSD's band [Hz].
    qdd_welch, qdd_expected : ndarray, shape (nf, 6)
        Welch PSD of the CG's acceleration from the record, and its expected value from the FRFs.
    point_welch, point_expected : ndarray, shape (n_points, nf, 3)
        The same for each point's acceleration [(m/s^2)^2/Hz].
    z_limit : float
        Largest ``|z|`` that passes (see :mod:`sixdof.validation.random_time`).
    verdict : str
        ``PASS`` when every ``|z| <= z_limit``.
    """

    judged: tuple[str, ...] = quantity("", ("judged",), name="judged", decode=lambda a: tuple(str(n) for n in a))
    judged_units: tuple[str, ...] = label()
    frequency_rms: np.ndarray = quantity(lambda r: _judged_units(r.judged_units), ("judged",),
                                         description="RMS from the FRF-derived PSD")
    time_rms: np.ndarray = quantity(lambda r: _judged_units(r.judged_units), ("judged",),
                                    description="RMS of the time record")
    sigma: np.ndarray = quantity("1", ("judged",), description="relative standard error of the record's mean square")
    z: np.ndarray = quantity("1", ("judged",), description="time/frequency mean square as a standard normal "
                             "value (Wilson-Hilferty)")
    f_hz: np.ndarray = quantity("Hz", ("welch_f_hz",), name="welch_f_hz")
    qdd_welch: np.ndarray = quantity(lambda r: _check_psd_units(), ("welch_f_hz", "dof"))
    qdd_expected: np.ndarray = quantity(lambda r: _check_psd_units(), ("welch_f_hz", "dof"))
    point_welch: np.ndarray = quantity("(m/s^2)^2/Hz", ("point", "welch_f_hz", "axis"))
    point_expected: np.ndarray = quantity("(m/s^2)^2/Hz", ("point", "welch_f_hz", "axis"))
    points: tuple[str, ...] = quantity("", ("point",), name="point", decode=lambda a: tuple(str(n) for n in a))
    z_limit: float = label(decode=float)
    verdict: str = label()
    seed: int = label(decode=int)
    duration_s: float = label(decode=float)
    settle_s: float = label(decode=float)
    segment_s: float = label(decode=float)
    averages: int = label(decode=int)
    degrees_of_freedom: float = label(decode=float)
    sample_rate_hz: float = label(decode=float)
    knot_rate_hz: float = label(decode=float)
    solver_steps: int = label(decode=int)
    wall_time_s: float = label(decode=float)
    notes: tuple[str, ...] = label(default=())
    band_hz: tuple[float, float] | None = label(default=None, encode=lambda band: np.asarray(band, dtype=float),
                                                decode=lambda band: (float(band[0]), float(band[1])))

    @property
    def worst(self) -> int:
        """Index of the value with the largest ``|z|``."""
        return int(np.argmax(np.abs(self.z)))


def _judged_units(units) -> MixedUnits:
    return MixedUnits((("judged", tuple(units)),), "m, rad, m/s^2, rad/s^2 or N: each judged value's unit")


def _check_psd_units() -> MixedUnits:
    squared = tuple(f"({u})^2/Hz" for u in dof_units(2))
    return MixedUnits((("dof", squared),), "(m/s^2)^2/Hz or (rad/s^2)^2/Hz")


# ----------------------------------------------------------------------------------------------------
# The random response.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RandomInput(Frozen):
    """The ``[random]`` table: ``input`` (``"ground_acceleration"`` or ``"force"``), its ``direction`` (an axis
    name or a 3-vector, body axes), the force's ``point`` [m], the ``psd``, and ``time_check``: the check of
    the answer against a time history (:mod:`sixdof.validation.random_time`; ``false`` skips it)."""

    input: str = checked(choice_check(INPUTS))
    direction: object = "z"
    psd: PSD | None = None
    point: np.ndarray | None = checked(optional(point_check), default=None)
    time_check: object = checked(time_check_settings, default=True)

    def __check__(self) -> None:
        direction, _ = parse_direction(self.direction, "direction", rotations=False)
        self._derive(direction=tuple(float(v) for v in direction))
        if not isinstance(self.psd, PSD):
            raise InputError("psd", "a table { f_hz = [...], value = [...], unit = \"g^2/Hz\" }", self.psd)
        force = self.input == "force"
        if force and self.point is None:
            raise InputError("point", "the force's point [x, y, z] in m", Plain("nothing"))
        if not force and self.point is not None:
            raise InputError("point", "no point for a ground acceleration (the ground moves under every mount)",
                             self.point)
        unit_ok = (self.psd.unit == "N^2/Hz") == force
        if not unit_ok:
            raise InputError("psd.unit", "N^2/Hz for a force" if force else "g^2/Hz or (m/s^2)^2/Hz for an "
                             "acceleration", self.psd.unit)


def _per_mode(dominant: tuple[str, ...]) -> MixedUnits:
    """Units of an acceleration of each mode's dominant DOF."""
    units = tuple(dof_units(2)[DOFS.index(d)] for d in dominant)
    return MixedUnits((("mode", units),), "m/s^2 or rad/s^2: the acceleration of each mode's dominant DOF")


def _psd_units(order: int) -> MixedUnits:
    """Units of the PSD of q (order 0) or q'' (2): the square of each DOF's unit per Hz."""
    squared = tuple(f"({u})^2/Hz" for u in dof_units(order))
    return MixedUnits((("dof", squared),), mixed_units(squared[0], squared[3]))


@result_type
@dataclass(frozen=True, eq=False)
class RandomResponse(Result):
    """Result of :func:`random_response` (stored in ``/random``).

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
    input_psd : ndarray, shape (nf,)
        The input PSD in SI [(m/s^2)^2/Hz or N^2/Hz].
    q_psd, qdd_psd : ndarray, shape (nf, 6)
        PSD of the CG's absolute displacement [m^2/Hz, rad^2/Hz] and acceleration.
    q_rms, qdd_rms : ndarray, shape (6,)
        Their RMS [m, rad; m/s^2, rad/s^2]; 3-sigma values are three times these.
    point_acceleration_psd : ndarray, shape (n_points, nf, 3) ; point_acceleration_rms : (n_points, 3)
        Absolute acceleration of each ``[[points]]`` point along the body axes [(m/s^2)^2/Hz; m/s^2].
    mount_deflection_rms, mount_force_rms : ndarray, shape (n_mounts, 3)
        Along each mount's own axes u, v, w [m; N]: deflection relative to the ground, force through the
        mount (spring, dashpot and loss factor).
    miles_rms, exact_rms : ndarray, shape (6,)
        Per mode: Miles' estimate of its dominant DOF's acceleration RMS, and that DOF's RMS from the PSD
        [m/s^2 or rad/s^2]; nan for rigid-body modes.
    input_rms : float
        The input's RMS [m/s^2 or N].
    time_check : RandomTimeCheck or None
        The same answer checked against a time history (the run adds it; stored in ``/random/time_check``).
    """

    f_hz: np.ndarray = quantity("Hz", ("f_hz",))
    input_psd: np.ndarray = quantity(lambda r: r.input_unit, ("f_hz",))
    q_psd: np.ndarray = quantity(_psd_units(0), ("f_hz", "dof"))
    qdd_psd: np.ndarray = quantity(_psd_units(2), ("f_hz", "dof"))
    q_rms: np.ndarray = quantity(MixedUnits((("dof", dof_units(0)),), mixed_units("m", "rad")), ("dof",))
    qdd_rms: np.ndarray = quantity(MixedUnits((("dof", dof_units(2)),), mixed_units("m/s^2", "rad/s^2")), ("dof",))
    point_acceleration_psd: np.ndarray = quantity("(m/s^2)^2/Hz", ("point", "f_hz", "axis"))
    point_acceleration_rms: np.ndarray = quantity("m/s^2", ("point", "axis"))
    mount_deflection_rms: np.ndarray = quantity("m", ("mount", "mount_axis"))
    mount_force_rms: np.ndarray = quantity("N", ("mount", "mount_axis"))
    miles_rms: np.ndarray = quantity(lambda r: _per_mode(r.dominant_dof), ("mode",))
    exact_rms: np.ndarray = quantity(lambda r: _per_mode(r.dominant_dof), ("mode",))
    points: tuple[str, ...] = quantity("", ("point",), name="point", decode=lambda a: tuple(str(n) for n in a))
    mounts: tuple[str, ...] = quantity("", ("mount",), name="mount", decode=lambda a: tuple(str(n) for n in a))
    dominant_dof: tuple[str, ...] = label()
    input_kind: str = label()
    input_rms: float = label(decode=float)
    time_check: object = part("RandomTimeCheck", group="time_check", default=None)

    @property
    def input_unit(self) -> str:
        return "N^2/Hz" if self.input_kind == "force" else "(m/s^2)^2/Hz"


def frequency_grid(system, psd: PSD) -> np.ndarray:
    """A log grid over the PSD's band with :data:`POINTS_PER_BANDWIDTH` points per half-power bandwidth of
    the most lightly damped mode in band (viscous and hysteretic damping together).

    Each interval between the PSD's breakpoints is its own log grid with an even number of steps, from one
    breakpoint exactly to the next: Simpson's pairs never straddle a kink of the PSD, and no point falls a
    rounding away from a breakpoint (``exp(log(10))`` is 10.000000000000002), which unevens Simpson's weights
    (2.9e-4 of a mean square, measured)."""
    low, high = float(psd.f_hz[0]), float(psd.f_hz[-1])
    zeta = _modal_damping(system)
    f_n = system.modes.frequency_hz
    inside = (f_n >= low) & (f_n <= high) & (f_n > 0)
    least = float(np.min(zeta[inside])) if np.any(inside) else 0.05
    step = np.log1p(2.0 * max(least, 1e-4) / POINTS_PER_BANDWIDTH)
    pieces = []
    for a, b in zip(psd.f_hz[:-1], psd.f_hz[1:]):
        steps = 2 * max(1, math.ceil(np.log(b / a) / step / 2))
        piece = np.exp(np.linspace(np.log(a), np.log(b), steps + 1))
        piece[0], piece[-1] = a, b  # exactly: outside them the PSD is zero or has another slope
        pieces.append(piece[:-1])
    return np.append(np.concatenate(pieces), high)


def _modal_damping(system) -> np.ndarray:
    """Each mode's damping ratio with the mounts' loss factors (half the modal loss factor) added: what the
    FRF's resonances show."""
    modes = system.modes
    viscous = damping_ratios(system.C, modes, system.branches)
    # An overdamped mode (inf) has no resonance for Miles' equation: its diagonal ratio keeps the estimate finite.
    viscous = np.nan_to_num(np.where(np.isinf(viscous), modal_damping_ratios(system.C, modes), viscous))
    with np.errstate(divide="ignore", invalid="ignore"):
        loss = np.einsum("ir,ij,jr->r", modes.shapes, hysteretic_stiffness(system), modes.shapes) / modes.eigenvalues
    return viscous + 0.5 * np.nan_to_num(loss)


@dataclass(frozen=True)
class Transfers:
    """The responses to a unit input (1 m/s^2 or 1 N) at frequencies ``f_hz`` (complex, SI): ``q`` (nf, 6)
    the CG's absolute displacement, ``point_acceleration`` (n_points, nf, 3) the points' absolute
    acceleration, ``mount_deflection`` and ``mount_force`` (n_mounts, nf, 3) along each mount's axes."""

    f_hz: np.ndarray
    q: np.ndarray
    point_acceleration: np.ndarray
    mount_deflection: np.ndarray
    mount_force: np.ndarray

    @property
    def qdd(self) -> np.ndarray:
        return self.q * -((2 * np.pi * self.f_hz) ** 2)[:, None]


def transfers(system, random: RandomInput, f_hz, points=None) -> Transfers:
    """The FRFs from ``random``'s input to every response :func:`random_response` reports, at ``f_hz`` [Hz]
    (> 0), with the mounts' loss factors (:func:`sixdof.validation.experiment.integrated_model` removes them
    for a comparison with a time solve)."""
    f = np.asarray(f_hz, dtype=float)
    omega = 2 * np.pi * f
    H = receptance(system, f).H
    d = np.asarray(random.direction)
    if random.input == "force":
        q = H @ unit_load(random.point, d, moment=False)  # (nf, 6) per N
        ground = np.zeros((len(f), 6), complex)
    else:
        # Per unit ground acceleration: the ground's displacement is -1/w^2 of it; all damping acts on the
        # motion relative to the ground (as in sixdof.analysis.frf.ground_transmissibility).
        rigid = np.concatenate([d, np.zeros(3)])
        drive = support_stiffness(system, omega) @ rigid
        ground = -rigid[None, :] / omega[:, None] ** 2
        q = np.einsum("fij,fj->fi", H, drive) * (-1.0 / omega**2)[:, None]
    point = np.stack([q @ point_map(p).T * -(omega**2)[:, None] for p in dict(points or {}).values()]) \
        if points else np.zeros((0, len(f), 3), complex)
    local = mount_local_map(system.positions, system.axes)  # (n_mounts, 3, 6)
    deflection = np.einsum("mij,fj->mfi", local, q - ground)  # the mounts deform with the relative motion
    force = deflection * mount_impedances(system, omega).transpose(1, 0, 2)
    return Transfers(f, q, point, deflection, force)


def random_response(system, random: RandomInput, points=None) -> RandomResponse:
    """The stationary random response of ``system`` to ``random`` (see the module).

    Parameters
    ----------
    system : sixdof.model.system.System
    random : RandomInput
    points : mapping of str to array_like, optional
        Named body points [m] whose absolute acceleration is reported.

    Returns
    -------
    RandomResponse

    Raises
    ------
    InputError
        For a ``system`` that is not a System or a ``random`` that is not a RandomInput.
    """
    from scipy.integrate import simpson


    instance(system, "system", System)
    instance(random, "random", RandomInput)
    points = dict(points or {})
    f = frequency_grid(system, random.psd)
    omega = 2 * np.pi * f
    frf = transfers(system, random, f, points)
    d = np.asarray(random.direction)
    if random.input == "force":
        participation = system.modes.shapes.T @ unit_load(random.point, d, moment=False)
    else:
        participation = system.modes.shapes.T @ (np.asarray(system.M) @ np.concatenate([d, np.zeros(3)]))
    s = random.psd(f)
    q_psd = np.abs(frf.q) ** 2 * s[:, None]
    qdd_psd = q_psd * omega[:, None] ** 4

    def rms(psd, axis=0):
        return np.sqrt(simpson(psd, x=f, axis=axis))

    point_psd = np.abs(frf.point_acceleration) ** 2 * s[None, :, None]
    modes = system.modes
    zeta = _modal_damping(system)
    dominant = np.array([DOFS.index(dof) for dof in modes.dominant_dof])
    elastic = modes.frequency_hz > 0
    qdd_rms = rms(qdd_psd)
    with np.errstate(divide="ignore", invalid="ignore"):
        miles = np.abs(modes.shapes[dominant, np.arange(6)] * participation) * np.sqrt(
            np.pi / 2 * modes.frequency_hz / (2 * zeta) * random.psd(modes.frequency_hz))
    return RandomResponse(
        f_hz=readonly(f), input_psd=readonly(s), q_psd=readonly(q_psd), qdd_psd=readonly(qdd_psd),
        q_rms=readonly(rms(q_psd)), qdd_rms=readonly(qdd_rms), point_acceleration_psd=readonly(point_psd),
        point_acceleration_rms=readonly(rms(point_psd, axis=1)),
        mount_deflection_rms=readonly(rms(np.abs(frf.mount_deflection) ** 2 * s[None, :, None], axis=1)),
        mount_force_rms=readonly(rms(np.abs(frf.mount_force) ** 2 * s[None, :, None], axis=1)),
        miles_rms=readonly(np.where(elastic, miles, np.nan)),
        exact_rms=readonly(np.where(elastic, qdd_rms[dominant], np.nan)),
        points=tuple(points), mounts=tuple(m.name for m in system.mounts), dominant_dof=modes.dominant_dof,
        input_kind=random.input, input_rms=random.psd.rms)
