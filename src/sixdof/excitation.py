"""Excitation of eq. (1): time signals, point loads, rotating unbalance, ground motion, initial state.

Signals
-------
A signal is a dimensionless multiplier ``s(t)`` of a load's force and moment vectors (the amplitude
lives in the load, in N and N m) or of a ground motion's ``scale``. Every signal

- is a frozen dataclass whose field names are the scenario file's keys (``kind`` picks the class, see
  :data:`SIGNAL_KINDS`), validated when built;
- evaluates as a pure ``jax.numpy`` function, ``signal(t)``, on a scalar ``t`` (inside a jitted
  solver) or on an array of times [s], returning an array of the same shape;
- is a JAX pytree whose numeric parameters are leaves: a jitted function that takes signals as
  arguments compiles once per signal *kind* and reuses the compiled code for new parameter values;
- lists in ``breakpoints`` the times [s] where it or one of its derivatives jumps (pulse start and
  end, table knots, step and ramp times). Between consecutive breakpoints it is smooth (analytic), so
  a time integrator must step exactly onto each breakpoint; a solver that does not can step clean
  over a short pulse and report success;
- is right-continuous at its breakpoints: ``s(b)`` is the value just after ``b``.

Outside its active window every signal is zero (``table`` may instead hold its end values).

Loads and other excitation
--------------------------
:class:`Load` (a force at a body point plus a moment, times a signal) and :class:`Unbalance`
(a rotating force ``m e Omega^2``) each expand into *components*: pairs of a constant generalized
force vector (6,) and a signal, ``Q(t) = sum_k Q_k s_k(t)``. :class:`GroundMotion` prescribes a rigid
translation of the foundation under every mount; :class:`InitialState` and :class:`ModeRelease` give
``q(0), q'(0)``. :class:`Excitation` holds them all.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import MISSING, dataclass, field, fields
from typing import Any, ClassVar

import numpy as np

from ._jax import jax, jnp
from .errors import InputError, Plain, finite_array

# A ground displacement that jumps needs an infinite force: breakpoints of a displacement signal
# may not change its value by more than this fraction of its peak.
_CONTINUITY_RTOL = 1e-6


# ----------------------------------------------------------------------------------------------------
# Small validators (bare field names: the scenario parser puts the path in front).
# ----------------------------------------------------------------------------------------------------


def _number(value: Any, name: str, expected: str, *, low: float | None = None, strict: bool = False,
            allow_inf: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(name, expected, value)
    x = float(value)
    if math.isnan(x) or (math.isinf(x) and not allow_inf):
        raise InputError(name, expected, value)
    if low is not None and (x < low or (strict and x == low)):
        raise InputError(name, expected, value)
    return x


def _vector3(value: Any, name: str, expected: str) -> np.ndarray:
    return finite_array(value, name, expected, (3,))


def _integer(value: Any, name: str, expected: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise InputError(name, expected, value)
    return int(value)


def _name(value: Any) -> str:
    if not isinstance(value, str) or not value:
        raise InputError("name", "a non-empty string", value)
    return value


# ----------------------------------------------------------------------------------------------------
# Signals.
# ----------------------------------------------------------------------------------------------------


class Signal:
    """Base of the time signals: a dimensionless, jittable function of time ``t`` [s].

    Subclasses are frozen dataclasses; they are registered as JAX pytrees whose leaves are the
    numeric fields (names in ``_static`` are compile-time constants instead).
    """

    kind: ClassVar[str] = ""
    _static: ClassVar[tuple[str, ...]] = ()
    _derived: ClassVar[tuple[str, ...]] = ()  # arrays computed at validation, leaves too

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)

        def flatten(signal):
            names = [f.name for f in fields(signal)] + list(cls._derived)
            dynamic = tuple(getattr(signal, n) for n in names if n not in cls._static)
            static = tuple(getattr(signal, n) for n in names if n in cls._static)
            return dynamic, static

        def unflatten(static, dynamic):
            # Rebuilt from (possibly traced) leaves without validation: they were validated once.
            signal = object.__new__(cls)
            names = [f.name for f in fields(cls)] + list(cls._derived)
            dyn, stat = iter(dynamic), iter(static)
            for n in names:
                object.__setattr__(signal, n, next(stat) if n in cls._static else next(dyn))
            return signal

        jax.tree_util.register_pytree_node(cls, flatten, unflatten)

    def __call__(self, t):
        """Value of the signal at time(s) ``t`` [s]: a jax array of ``t``'s shape (dimensionless)."""
        return self._evaluate(jnp.asarray(t, dtype=float))

    def _evaluate(self, t):  # pragma: no cover - every kind overrides it
        raise NotImplementedError

    def derivative(self, t, order: int = 1):
        """Time derivative of order 1 or 2 at ``t`` [1/s, 1/s^2] (right-continuous at breakpoints).

        Exact (forward-mode automatic differentiation of the smooth piece holding ``t``).
        """
        if order not in (1, 2):
            raise InputError("order", "1 or 2", order)
        t = jnp.asarray(t, dtype=float)

        def first(x):
            return jax.jvp(self._evaluate, (x,), (jnp.ones_like(x),))[1]

        if order == 1:
            return first(t)
        return jax.jvp(first, (t,), (jnp.ones_like(t),))[1]

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Sorted times [s] where the signal or one of its derivatives jumps."""
        return ()

    @property
    def peak(self) -> float:
        """An estimate of ``max |s(t)|``, used to scale the solver's tolerances."""
        return 1.0


def _window(t, start, duration):
    """True on ``[start, start + duration)``."""
    return (t >= start) & (t < start + duration)


def _breaks(*times: float) -> tuple[float, ...]:
    return tuple(sorted({float(x) for x in times if math.isfinite(x)}))


@dataclass(frozen=True, eq=False)
class Harmonic(Signal):
    """``s(t) = sin(2 pi f (t - start) + phase)`` on ``[start, start + duration)``, zero outside.

    Parameters
    ----------
    f_hz : float
        Frequency [Hz], > 0.
    phase_deg : float, optional
        Phase at ``start`` [deg]; ``90`` gives a cosine. Default 0 (the load starts from zero).
    start : float, optional
        Switch-on time [s]. Default 0.
    duration : float, optional
        How long it lasts [s], > 0. Default: for ever.
    """

    kind: ClassVar[str] = "harmonic"
    f_hz: float
    phase_deg: float = 0.0
    start: float = 0.0
    duration: float = math.inf

    def __post_init__(self) -> None:
        object.__setattr__(self, "f_hz", _number(self.f_hz, "f_hz", "a positive frequency in Hz",
                                                 low=0.0, strict=True))
        object.__setattr__(self, "phase_deg", _number(self.phase_deg, "phase_deg",
                                                      "a finite phase in degrees"))
        object.__setattr__(self, "start", _number(self.start, "start", "a finite time in s"))
        object.__setattr__(self, "duration", _number(
            self.duration, "duration", "a positive duration in s", low=0.0, strict=True,
            allow_inf=True))

    def _evaluate(self, t):
        tau = t - self.start
        value = jnp.sin(2 * jnp.pi * self.f_hz * tau + jnp.deg2rad(self.phase_deg))
        return jnp.where(_window(t, self.start, self.duration), value, 0.0)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return _breaks(self.start, self.start + self.duration)


@dataclass(frozen=True, eq=False)
class Sweep(Signal):
    """Sine sweep ``s(t) = sin(phi(t - start))`` from ``f0_hz`` to ``f1_hz`` over ``duration``.

    ``law = "linear"``: the frequency rises linearly, ``phi(tau) = 2 pi (f0 tau + (f1 - f0)
    tau^2 / (2 T))``. ``law = "log"``: exponentially (constant octaves per second),
    ``phi(tau) = 2 pi f0 T / ln(f1/f0) ((f1/f0)^(tau/T) - 1)``. Zero outside
    ``[start, start + duration)``.

    Parameters
    ----------
    f0_hz, f1_hz : float
        Start and end frequencies [Hz], > 0 (a downward sweep is allowed; a log sweep needs
        ``f0_hz != f1_hz``).
    duration : float
        Sweep time T [s], > 0.
    start : float, optional
        Start time [s]. Default 0.
    law : {"linear", "log"}, optional
        Default "linear".
    """

    kind: ClassVar[str] = "sweep"
    _static: ClassVar[tuple[str, ...]] = ("law",)
    f0_hz: float
    f1_hz: float
    duration: float
    start: float = 0.0
    law: str = "linear"

    def __post_init__(self) -> None:
        for name in ("f0_hz", "f1_hz"):
            object.__setattr__(self, name, _number(getattr(self, name), name,
                                                   "a positive frequency in Hz", low=0.0, strict=True))
        object.__setattr__(self, "duration", _number(self.duration, "duration",
                                                     "a positive, finite duration in s", low=0.0,
                                                     strict=True))
        object.__setattr__(self, "start", _number(self.start, "start", "a finite time in s"))
        if self.law not in ("linear", "log"):
            raise InputError("law", "'linear' or 'log'", self.law)
        if self.law == "log" and self.f0_hz == self.f1_hz:
            raise InputError("f1_hz", "a frequency different from f0_hz for a log sweep", self.f1_hz)

    def _evaluate(self, t):
        T = self.duration
        tau = jnp.clip(t - self.start, 0.0, T)  # keeps exp() finite outside the window
        if self.law == "linear":
            phase = 2 * jnp.pi * (self.f0_hz * tau + (self.f1_hz - self.f0_hz) * tau**2 / (2 * T))
        else:
            ratio = self.f1_hz / self.f0_hz
            phase = 2 * jnp.pi * self.f0_hz * T / jnp.log(ratio) * jnp.expm1(tau / T * jnp.log(ratio))
        return jnp.where(_window(t, self.start, T), jnp.sin(phase), 0.0)

    def frequency_hz(self, t):
        """Instantaneous frequency [Hz] at ``t`` (inside the sweep window)."""
        tau = jnp.clip(jnp.asarray(t, dtype=float) - self.start, 0.0, self.duration)
        if self.law == "linear":
            return self.f0_hz + (self.f1_hz - self.f0_hz) * tau / self.duration
        return self.f0_hz * (self.f1_hz / self.f0_hz) ** (tau / self.duration)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return _breaks(self.start, self.start + self.duration)


def _pulse_fields(signal) -> None:
    object.__setattr__(signal, "start", _number(signal.start, "start", "a finite time in s"))
    object.__setattr__(signal, "duration", _number(signal.duration, "duration",
                                                   "a positive, finite duration in s", low=0.0,
                                                   strict=True))


@dataclass(frozen=True, eq=False)
class HalfSine(Signal):
    """Half-sine shock pulse ``sin(pi (t - start) / duration)`` on ``[start, start + duration)``.

    Parameters
    ----------
    start : float
        Pulse start [s].
    duration : float
        Pulse length [s], > 0. Peak 1 at mid-pulse.
    """

    kind: ClassVar[str] = "half_sine"
    start: float
    duration: float

    def __post_init__(self) -> None:
        _pulse_fields(self)

    def _evaluate(self, t):
        value = jnp.sin(jnp.pi * (t - self.start) / self.duration)
        return jnp.where(_window(t, self.start, self.duration), value, 0.0)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return _breaks(self.start, self.start + self.duration)


@dataclass(frozen=True, eq=False)
class Haversine(Signal):
    """Haversine pulse ``(1 - cos(2 pi (t - start) / duration)) / 2``: smooth start and end, peak 1.

    Parameters
    ----------
    start : float
        Pulse start [s].
    duration : float
        Pulse length [s], > 0.
    """

    kind: ClassVar[str] = "haversine"
    start: float
    duration: float

    def __post_init__(self) -> None:
        _pulse_fields(self)

    def _evaluate(self, t):
        value = 0.5 * (1.0 - jnp.cos(2 * jnp.pi * (t - self.start) / self.duration))
        return jnp.where(_window(t, self.start, self.duration), value, 0.0)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return _breaks(self.start, self.start + self.duration)


@dataclass(frozen=True, eq=False)
class Step(Signal):
    """Unit step: 0 before ``start`` [s], 1 from ``start`` on (a suddenly applied, held load)."""

    kind: ClassVar[str] = "step"
    start: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", _number(self.start, "start", "a finite time in s"))

    def _evaluate(self, t):
        return jnp.where(t >= self.start, 1.0, 0.0)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return _breaks(self.start)


@dataclass(frozen=True, eq=False)
class Ramp(Signal):
    """Linear rise from 0 at ``start`` to 1 at ``start + duration``, then held at 1.

    Parameters
    ----------
    duration : float
        Rise time [s], > 0.
    start : float, optional
        Start of the rise [s]. Default 0.
    """

    kind: ClassVar[str] = "ramp"
    duration: float
    start: float = 0.0

    def __post_init__(self) -> None:
        _pulse_fields(self)

    def _evaluate(self, t):
        return jnp.clip((t - self.start) / self.duration, 0.0, 1.0)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return _breaks(self.start, self.start + self.duration)


@dataclass(frozen=True, eq=False)
class Table(Signal):
    """Tabulated samples, linearly interpolated (a first-order hold).

    Parameters
    ----------
    t : sequence of float
        Sample times [s], strictly increasing, at least 2.
    values : sequence of float
        Samples (dimensionless multiplier, or ground motion before ``scale``), one per time.
    outside : {"zero", "hold"}, optional
        Value before the first and after the last sample: zero (default: a record that starts and
        ends at rest) or the end samples held.

    Every sample time is a breakpoint (the slope changes there).
    """

    kind: ClassVar[str] = "table"
    _static: ClassVar[tuple[str, ...]] = ("outside",)
    t: np.ndarray
    values: np.ndarray
    outside: str = "zero"

    def __post_init__(self) -> None:
        expected_t = "at least 2 finite, strictly increasing times in s"
        try:
            times = np.array(self.t, dtype=float)
        except (TypeError, ValueError):
            raise InputError("t", expected_t, self.t) from None
        if times.ndim != 1 or times.size < 2 or not np.all(np.isfinite(times)):
            raise InputError("t", expected_t, self.t)
        if np.any(np.diff(times) <= 0):
            bad = int(np.flatnonzero(np.diff(times) <= 0)[0])
            raise InputError("t", expected_t,
                             Plain(f"t[{bad + 1}] = {times[bad + 1]:g} after t[{bad}] = {times[bad]:g}"))
        expected_v = f"{times.size} finite values (one per time)"
        try:
            values = np.array(self.values, dtype=float)
        except (TypeError, ValueError):
            raise InputError("values", expected_v, self.values) from None
        if values.shape != times.shape or not np.all(np.isfinite(values)):
            raise InputError("values", expected_v, self.values)
        if self.outside not in ("zero", "hold"):
            raise InputError("outside", "'zero' or 'hold'", self.outside)
        times.flags.writeable = False
        values.flags.writeable = False
        object.__setattr__(self, "t", times)
        object.__setattr__(self, "values", values)

    def _evaluate(self, t):
        knots, values = jnp.asarray(self.t), jnp.asarray(self.values)
        if self.outside == "zero":
            return jnp.interp(t, knots, values, left=0.0, right=0.0)
        return jnp.interp(t, knots, values)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return tuple(float(x) for x in self.t)

    @property
    def peak(self) -> float:
        return float(np.max(np.abs(self.values)))


@dataclass(frozen=True, eq=False)
class Random(Signal):
    """Band-limited random signal, reproducible from its seed, smooth (a sum of sines).

    ``s(t) = a sum_k sin(2 pi f_k (t - start) + phi_k)`` on ``[start, start + duration)`` with
    ``components`` frequencies ``f_k``, one drawn uniformly in each of as many equal sub-bands of
    ``f_hz`` (a flat spectrum without the periodicity of an even grid), random phases ``phi_k`` and
    ``a = rms sqrt(2 / components)``, so the mean square is ``rms^2``. Both are drawn with
    ``numpy.random.default_rng(seed)``: the same seed gives the same signal on every machine.
    They are kept as the attributes ``frequencies`` [Hz] and ``phases`` [rad], shape (components,).

    Parameters
    ----------
    f_hz : sequence of 2 floats
        Band ``[low, high]`` [Hz], 0 < low < high.
    rms : float
        Root-mean-square value, > 0.
    seed : int
        Seed, >= 0.
    components : int, optional
        Number of sines, >= 1. Default 64.
    start : float, optional
        Start time [s]. Default 0 (the signal jumps from 0 to its first value there).
    duration : float, optional
        Length [s]. Default: for ever.
    """

    kind: ClassVar[str] = "random"
    _static: ClassVar[tuple[str, ...]] = ("components",)
    _derived: ClassVar[tuple[str, ...]] = ("frequencies", "phases")
    f_hz: tuple[float, float]
    rms: float
    seed: int
    components: int = 64
    start: float = 0.0
    duration: float = math.inf

    def __post_init__(self) -> None:
        expected = "a band [low, high] in Hz with 0 < low < high"
        try:
            band = np.array(self.f_hz, dtype=float)
        except (TypeError, ValueError):
            raise InputError("f_hz", expected, self.f_hz) from None
        if band.shape != (2,) or not np.all(np.isfinite(band)) or not 0 < band[0] < band[1]:
            raise InputError("f_hz", expected, self.f_hz)
        object.__setattr__(self, "f_hz", (float(band[0]), float(band[1])))
        object.__setattr__(self, "rms", _number(self.rms, "rms", "a positive rms value", low=0.0,
                                                strict=True))
        object.__setattr__(self, "seed", _integer(self.seed, "seed", "an integer >= 0", 0))
        object.__setattr__(self, "components", _integer(self.components, "components",
                                                         "an integer >= 1", 1))
        object.__setattr__(self, "start", _number(self.start, "start", "a finite time in s"))
        object.__setattr__(self, "duration", _number(
            self.duration, "duration", "a positive duration in s", low=0.0, strict=True,
            allow_inf=True))
        rng = np.random.default_rng(self.seed)
        n = self.components
        edges = np.linspace(band[0], band[1], n + 1)
        frequencies = edges[:-1] + rng.uniform(0.0, 1.0, n) * np.diff(edges)
        phases = rng.uniform(0.0, 2 * np.pi, n)
        frequencies.flags.writeable = False
        phases.flags.writeable = False
        object.__setattr__(self, "frequencies", frequencies)
        object.__setattr__(self, "phases", phases)

    def _evaluate(self, t):
        amplitude = self.rms * jnp.sqrt(2.0 / self.components)
        tau = (t - self.start)[..., None]
        value = amplitude * jnp.sum(jnp.sin(2 * jnp.pi * self.frequencies * tau + self.phases), axis=-1)
        return jnp.where(_window(t, self.start, self.duration), value, 0.0)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return _breaks(self.start, self.start + self.duration)

    @property
    def peak(self) -> float:
        # A long Gaussian-like record reaches about 4 rms.
        return 4.0 * float(self.rms)


#: TOML ``kind`` of a signal -> its class.
SIGNAL_KINDS: dict[str, type[Signal]] = {
    cls.kind: cls for cls in (Harmonic, Sweep, HalfSine, Haversine, Step, Ramp, Table, Random)
}


def make_signal(value: Signal | Mapping[str, Any]) -> Signal:
    """A signal from a signal object or a table such as ``{"kind": "harmonic", "f_hz": 5.0}``.

    Raises
    ------
    InputError
        For an unknown kind, an unknown or missing key, or a bad value (field names bare, such as
        ``f_hz``; ``kind`` for the kind).
    """
    if isinstance(value, Signal):
        return value
    if not isinstance(value, Mapping):
        raise InputError("", "a signal table such as {kind = \"harmonic\", f_hz = 5.0}", value)
    table = dict(value)
    kind = table.pop("kind", None)
    if kind not in SIGNAL_KINDS:
        raise InputError("kind", f"one of {', '.join(sorted(SIGNAL_KINDS))}",
                         Plain("nothing") if kind is None else kind)
    cls = SIGNAL_KINDS[kind]
    known = {f.name for f in fields(cls) if f.init}
    for key in table:
        if key not in known:
            raise InputError(key, f"one of the keys {', '.join(sorted(known))}", Plain("an unknown key"))
    missing = [f.name for f in fields(cls) if f.init and f.name not in table
               and f.default is MISSING and f.default_factory is MISSING]
    if missing:
        raise InputError(missing[0], "a value (required key)", Plain("nothing"))
    return cls(**table)


def _signal_field(value: Any) -> Signal:
    if value is None:
        raise InputError("signal", "a signal such as {kind = \"harmonic\", f_hz = 5.0}", Plain("nothing"))
    try:
        return make_signal(value)
    except InputError as exc:
        raise (InputError("signal", exc.expected, exc.got) if not exc.field else exc.within("signal"))


# ----------------------------------------------------------------------------------------------------
# Loads.
# ----------------------------------------------------------------------------------------------------


def _generalized(point: np.ndarray, force: np.ndarray, moment: np.ndarray) -> np.ndarray:
    """``[F, r x F + M]`` (6,): the virtual-work transpose of the point map (as model.load_vector)."""
    q = np.concatenate([force, np.cross(point, force) + moment])
    q.flags.writeable = False
    return q


@dataclass(frozen=True, eq=False)
class Load:
    """A force at a body point plus a moment, both scaled by a signal: ``F(t) = force s(t)``.

    Parameters
    ----------
    name : str
        Label for tables and files.
    point : array_like, shape (3,)
        Point of application from the CG in body axes [m].
    force : array_like, shape (3,), optional
        Force amplitude in body axes [N]. Default zero.
    moment : array_like, shape (3,), optional
        Moment amplitude in body axes [N m]. Default zero. ``force`` and ``moment`` are not both zero.
    signal : Signal or mapping
        The time signal (a mapping with a ``kind`` key is built with :func:`make_signal`).
    """

    kind: ClassVar[str] = "force"
    name: str
    point: np.ndarray
    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    moment: np.ndarray = field(default_factory=lambda: np.zeros(3))
    signal: Signal | None = None

    def __post_init__(self) -> None:
        _name(self.name)
        object.__setattr__(self, "point", _vector3(self.point, "point", "3 coordinates [x, y, z] in m"))
        object.__setattr__(self, "force", _vector3(self.force, "force", "3 force components in N"))
        object.__setattr__(self, "moment", _vector3(self.moment, "moment",
                                                    "3 moment components in N m"))
        if not (np.any(self.force) or np.any(self.moment)):
            raise InputError("force", "a non-zero force or moment (N, N m)", self.force)
        object.__setattr__(self, "signal", _signal_field(self.signal))

    def components(self) -> tuple[tuple[np.ndarray, Signal], ...]:
        """``((Q, signal),)``: the generalized force (6,) [N, N m] multiplied by the signal."""
        return ((_generalized(self.point, self.force, self.moment), self.signal),)


def _plane_basis(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors ``u, v`` spanning the plane normal to ``axis`` with ``u x v = axis``.

    ``u`` is the body axis (x, then y, then z on ties) least aligned with ``axis``, made normal to it.
    """
    e = np.eye(3)[int(np.argmin(np.abs(axis)))]
    u = e - np.dot(e, axis) * axis
    u /= np.linalg.norm(u)
    return u, np.cross(axis, u)


@dataclass(frozen=True, eq=False)
class Unbalance:
    """A rotating unbalance: the force ``m e Omega^2`` turning at constant speed in a plane.

    ``F(t) = m e Omega^2 (cos(theta) u + sin(theta) v)``, ``theta = Omega (t - start) + phase``,
    zero before ``start``. ``u, v`` span the plane normal to ``axis`` with ``u x v = axis`` (the
    rotation is positive about ``axis``); ``u`` is the body axis least aligned with ``axis``
    (x first on ties) made normal to it: for ``axis = z``, ``u = x`` and ``v = y``; for
    ``axis = x``, ``u = y, v = z``; for ``axis = y``, ``u = x, v = -z``.

    Parameters
    ----------
    name : str
    point : array_like, shape (3,)
        Centre of the rotor's plane of unbalance from the CG in body axes [m].
    unbalance : float
        ``m e`` [kg m], > 0.
    f_hz : float, optional
        Rotation frequency [Hz]; give this or ``speed_rpm``.
    speed_rpm : float, optional
        Rotation speed [rev/min].
    axis : array_like, shape (3,), optional
        Spin axis in body axes (normalized here). Default ``[0, 0, 1]``.
    phase_deg : float, optional
        Angle of the force from ``u`` at ``start`` [deg]. Default 0.
    start : float, optional
        Time the rotor is at speed from [s]. Default 0.
    """

    kind: ClassVar[str] = "unbalance"
    name: str
    point: np.ndarray
    unbalance: float
    f_hz: float | None = None
    speed_rpm: float | None = None
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    phase_deg: float = 0.0
    start: float = 0.0

    def __post_init__(self) -> None:
        _name(self.name)
        object.__setattr__(self, "point", _vector3(self.point, "point", "3 coordinates [x, y, z] in m"))
        object.__setattr__(self, "unbalance", _number(self.unbalance, "unbalance",
                                                      "a positive m e in kg m", low=0.0, strict=True))
        if (self.f_hz is None) == (self.speed_rpm is None):
            raise InputError("f_hz", "either f_hz (Hz) or speed_rpm (rev/min), exactly one",
                             Plain("both" if self.f_hz is not None else "neither"))
        if self.f_hz is not None:
            object.__setattr__(self, "f_hz", _number(
                self.f_hz, "f_hz", "a positive rotation frequency in Hz", low=0.0, strict=True))
        else:
            object.__setattr__(self, "speed_rpm", _number(
                self.speed_rpm, "speed_rpm", "a positive speed in rev/min", low=0.0, strict=True))
        axis = _vector3(self.axis, "axis", "a non-zero 3-vector (spin axis, body axes)")
        if not np.any(axis):
            raise InputError("axis", "a non-zero 3-vector (spin axis, body axes)", self.axis)
        axis = axis / np.linalg.norm(axis)
        axis.flags.writeable = False
        object.__setattr__(self, "axis", axis)
        object.__setattr__(self, "phase_deg", _number(self.phase_deg, "phase_deg",
                                                      "a finite phase in degrees"))
        object.__setattr__(self, "start", _number(self.start, "start", "a finite time in s"))

    @property
    def frequency_hz(self) -> float:
        """Rotation frequency [Hz]."""
        return self.f_hz if self.f_hz is not None else self.speed_rpm / 60.0

    @property
    def force_amplitude(self) -> float:
        """``m e Omega^2`` [N]."""
        return self.unbalance * (2 * np.pi * self.frequency_hz) ** 2

    def components(self) -> tuple[tuple[np.ndarray, Signal], ...]:
        """Two components: ``u`` times ``cos(theta)`` and ``v`` times ``sin(theta)`` (see class doc)."""
        u, v = _plane_basis(self.axis)
        amplitude = self.force_amplitude
        zero = np.zeros(3)
        cos = Harmonic(f_hz=self.frequency_hz, phase_deg=self.phase_deg + 90.0, start=self.start)
        sin = Harmonic(f_hz=self.frequency_hz, phase_deg=self.phase_deg, start=self.start)
        return (
            (_generalized(self.point, amplitude * u, zero), cos),
            (_generalized(self.point, amplitude * v, zero), sin),
        )


#: TOML ``kind`` of a load -> its class (``"force"`` when the key is absent).
LOAD_KINDS: dict[str, type] = {"force": Load, "unbalance": Unbalance}


# ----------------------------------------------------------------------------------------------------
# Ground motion and initial conditions.
# ----------------------------------------------------------------------------------------------------

GROUND_QUANTITIES = ("displacement", "velocity", "acceleration")


@dataclass(frozen=True, eq=False)
class GroundMotion:
    """Rigid translation of the foundation under every mount: ``scale s(t)`` along ``direction``.

    The foundation moves as one rigid block (no rotation); every mount's lower end follows it. The
    mount springs and dashpots then act on the body's motion *relative to the ground*.
    ``velocity`` and ``acceleration`` grounds start at rest at zero displacement at the start of a
    simulation and are integrated with the body. A ``displacement`` signal must be continuous (a
    jump would need an infinite force); its slope may jump.

    Parameters
    ----------
    quantity : {"displacement", "velocity", "acceleration"}
        What ``scale s(t)`` is: m, m/s or m/s^2.
    direction : array_like, shape (3,)
        Direction in body axes (normalized here).
    signal : Signal or mapping
        Shape in time (for an accelerogram: ``{kind = "table", file = "record.csv"}``).
    scale : float, optional
        Multiplies the signal [m, m/s or m/s^2 per signal unit]: ``9.81`` for a record in g.
        Default 1.
    """

    quantity: str
    direction: np.ndarray
    signal: Signal | None = None
    scale: float = 1.0

    def __post_init__(self) -> None:
        if self.quantity not in GROUND_QUANTITIES:
            raise InputError("quantity", "'displacement', 'velocity' or 'acceleration'", self.quantity)
        direction = _vector3(self.direction, "direction", "a non-zero 3-vector in body axes")
        if not np.any(direction):
            raise InputError("direction", "a non-zero 3-vector in body axes", self.direction)
        direction = direction / np.linalg.norm(direction)
        direction.flags.writeable = False
        object.__setattr__(self, "direction", direction)
        object.__setattr__(self, "signal", _signal_field(self.signal))
        object.__setattr__(self, "scale", _number(self.scale, "scale", "a finite non-zero number",))
        if self.scale == 0.0:
            raise InputError("scale", "a finite non-zero number", self.scale)
        if self.quantity == "displacement":
            self._check_continuous()

    def _check_continuous(self) -> None:
        points = np.array(self.signal.breakpoints, dtype=float)
        if points.size == 0:
            return
        # Look just left of each breakpoint (far enough not to be flushed as a denormal) and
        # extrapolate with the slope there, so that a steep but continuous signal passes.
        gap = np.min(np.diff(points)) / 2 if points.size > 1 else np.inf
        eps = np.minimum(1e-9 * np.maximum(1.0, np.abs(points)), gap)
        left = points - eps
        predicted = np.asarray(self.signal(left)) + np.asarray(self.signal.derivative(left)) * eps
        after = np.asarray(self.signal(points))
        jump = np.abs(after - predicted) > _CONTINUITY_RTOL * self.signal.peak
        if np.any(jump):
            i = int(np.flatnonzero(jump)[0])
            raise InputError(
                "signal",
                "a continuous signal for a ground displacement (a jump needs an infinite force; "
                "use quantity = 'velocity' or 'acceleration')",
                Plain(f"a {self.signal.kind} signal jumping by {after[i] - predicted[i]:.6g} at "
                      f"t = {points[i]:.6g} s"),
            )

    @property
    def rigid_vector(self) -> np.ndarray:
        """``r`` (6,): the generalized coordinates of a unit ground translation (no rotation)."""
        return np.concatenate([self.direction, np.zeros(3)])


def _six(value: Any, name: str, expected: str) -> np.ndarray:
    return finite_array(value, name, expected, (6,))


@dataclass(frozen=True, eq=False)
class InitialState:
    """Initial displacement and velocity of the body (absolute: in the fixed frame).

    Parameters
    ----------
    q : array_like, shape (6,), optional
        ``q(start)`` [m, m, m, rad, rad, rad]. Default zero (static equilibrium).
    qd : array_like, shape (6,), optional
        ``q'(start)`` [m/s, rad/s]. Default zero.
    """

    q: np.ndarray = field(default_factory=lambda: np.zeros(6))
    qd: np.ndarray = field(default_factory=lambda: np.zeros(6))

    def __post_init__(self) -> None:
        object.__setattr__(self, "q", _six(self.q, "q", "6 values [x, y, z, rx, ry, rz] in m and rad"))
        object.__setattr__(self, "qd", _six(self.qd, "qd",
                                            "6 values [x, y, z, rx, ry, rz] in m/s and rad/s"))

    def state(self, system) -> tuple[np.ndarray, np.ndarray]:
        """``(q0, qd0)``, each (6,) [m, rad; m/s, rad/s]."""
        return np.array(self.q), np.array(self.qd)


@dataclass(frozen=True, eq=False)
class ModeRelease:
    """Free vibration: release from rest in one undamped mode shape.

    ``q(0) = amplitude phi / phi[d]`` with ``phi`` the mode's shape and ``d`` its dominant DOF (the
    DOF holding the largest share of the mode's kinetic energy, :attr:`sixdof.modal.Modes.dominant_dof`),
    so ``amplitude`` is the initial displacement of that DOF; ``q'(0) = 0``.

    Parameters
    ----------
    mode : int
        Mode number, 1-based in ascending frequency (1 to 6).
    amplitude : float
        Initial value of the mode's dominant DOF [m for x, y, z; rad for rx, ry, rz], non-zero.
    """

    mode: int
    amplitude: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "mode", _integer(self.mode, "mode", "a mode number from 1 to 6", 1))
        if self.mode > 6:
            raise InputError("mode", "a mode number from 1 to 6", self.mode)
        amplitude = _number(self.amplitude, "amplitude", "a non-zero amplitude in m or rad")
        if amplitude == 0.0:
            raise InputError("amplitude", "a non-zero amplitude in m or rad", self.amplitude)
        object.__setattr__(self, "amplitude", amplitude)

    def state(self, system) -> tuple[np.ndarray, np.ndarray]:
        """``(q0, qd0)`` for ``system`` (6,) each [m, rad; m/s, rad/s]."""
        from .dofs import DOFS
        from .modal import modal_analysis

        modes = modal_analysis(system.M, system.K)
        j = self.mode - 1
        d = DOFS.index(modes.dominant_dof[j])
        shape = modes.shapes[:, j]
        return self.amplitude * shape / shape[d], np.zeros(6)


@dataclass(frozen=True, eq=False)
class Excitation:
    """Everything that drives eq. (1) in one simulation.

    Parameters
    ----------
    loads : sequence of Load or Unbalance, optional
        Acting together; names unique.
    ground : GroundMotion, optional
    initial : InitialState or ModeRelease, optional
        Default: at rest in static equilibrium.
    """

    loads: tuple = ()
    ground: GroundMotion | None = None
    initial: InitialState | ModeRelease | None = None

    def __post_init__(self) -> None:
        loads = tuple(self.loads)
        for i, load in enumerate(loads):
            if not isinstance(load, tuple(LOAD_KINDS.values())):
                raise InputError(f"loads[{i}]", "a Load or Unbalance", load)
        names = [load.name for load in loads]
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise InputError("loads", "unique load names", Plain(f"{', '.join(repeated)} repeated"))
        object.__setattr__(self, "loads", loads)
        if self.ground is not None and not isinstance(self.ground, GroundMotion):
            raise InputError("ground", "a GroundMotion", self.ground)
        if self.initial is not None and not isinstance(self.initial, (InitialState, ModeRelease)):
            raise InputError("initial", "an InitialState or a ModeRelease", self.initial)

    def components(self) -> tuple[tuple[np.ndarray, Signal], ...]:
        """Every load's ``(Q (6,) [N, N m], signal)`` pairs, in load order."""
        return tuple(c for load in self.loads for c in load.components())

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Sorted times [s] where any load or ground signal or a derivative jumps."""
        times = {b for _, s in self.components() for b in s.breakpoints}
        if self.ground is not None:
            times.update(self.ground.signal.breakpoints)
        return tuple(sorted(times))

    def initial_state(self, system) -> tuple[np.ndarray, np.ndarray]:
        """``(q0, qd0)`` (6,) each, absolute [m, rad; m/s, rad/s]; zeros without ``initial``."""
        if self.initial is None:
            return np.zeros(6), np.zeros(6)
        return self.initial.state(system)


def generalized_force(excitation: Excitation, t) -> np.ndarray:
    """The loads' generalized force ``Q(t) = sum_k Q_k s_k(t)`` (ground motion not included).

    Parameters
    ----------
    excitation : Excitation
    t : array_like, shape (n,)
        Times [s].

    Returns
    -------
    ndarray, shape (n, 6)
        [N, N, N, N m, N m, N m].
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.zeros((t.size, 6))
    for vector, signal in excitation.components():
        out += np.asarray(signal(t))[:, None] * vector[None, :]
    return out


__all__ = [
    "SIGNAL_KINDS", "LOAD_KINDS", "GROUND_QUANTITIES", "Signal", "Harmonic", "Sweep", "HalfSine",
    "Haversine", "Step", "Ramp", "Table", "Random", "make_signal", "Load", "Unbalance",
    "GroundMotion", "InitialState", "ModeRelease", "Excitation", "generalized_force",
]
