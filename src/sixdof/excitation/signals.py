"""Time signals: dimensionless, jittable multipliers ``s(t)`` of the loads and the ground motion.

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
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from sixdof._jax import jax, jnp
from sixdof.errors import (
    MAX_FREQUENCY_HZ,
    MIN_DURATION_S,
    InputError,
    Plain,
    choice_check,
    finite_array,
    frequency_band,
    increasing_times,
    integer,
    integer_check,
    number_check,
    optional,
    readonly,
    short,
)
from sixdof.frozen import Frozen, checked
from sixdof.schema import build, choices


class Signal(Frozen):
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

    def _inside(self, t):
        """True on the active window ``[start, start + duration)``."""
        return (t >= self.start) & (t < self.start + self.duration)

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
        """Sorted times [s] where the signal or one of its derivatives jumps: by default the ends of its
        active window, ``start`` and ``start + duration`` (when finite)."""
        return tuple(sorted({float(x) for x in (self.start, self.start + self.duration) if math.isfinite(x)}))

    @property
    def support(self) -> tuple[float, float]:
        """``(first, end)`` [s]: the signal is zero outside ``[first, end)`` (``inf`` when it never
        ends); by default its active window ``[start, start + duration)``."""
        return float(self.start), float(self.start + self.duration)

    @property
    def peak(self) -> float:
        """An estimate of ``max |s(t)|``, used to scale the solver's tolerances."""
        return 1.0

    @property
    def max_frequency_hz(self) -> float:
        """Highest frequency [Hz] the signal carries (0 when it has none of its own: steps, ramps,
        tables); bounds the superposition's intervals and the sample-rate warnings."""
        return 0.0

    @property
    def event(self) -> tuple[str, float, float] | None:
        """``(kind, start [s], duration [s])`` of what a figure should zoom on (see
        :class:`sixdof.results.Event`): a pulse is a ``"shock"`` lasting its length, a periodic signal
        a ``"switch-on"`` lasting its first period; None for the rest (steps, ramps, tables, random)."""
        return None


# Field checks shared by the signal kinds.
_TIME = number_check("a finite time in s")
_DURATION = number_check(f"a positive, finite duration in s, at least {short(MIN_DURATION_S)}", low=MIN_DURATION_S)
_LASTING = number_check(f"a positive duration in s, at least {short(MIN_DURATION_S)}", low=MIN_DURATION_S,
                        allow_inf=True)
_FREQUENCY = number_check(f"a positive frequency in Hz, at most {short(MAX_FREQUENCY_HZ)}", low=0.0, strict=True,
                          high=MAX_FREQUENCY_HZ)


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
    f_hz: float = checked(_FREQUENCY)
    phase_deg: float = checked(number_check("a finite phase in degrees"), default=0.0)
    start: float = checked(_TIME, default=0.0)
    duration: float = checked(_LASTING, default=math.inf)

    @property
    def max_frequency_hz(self) -> float:
        return self.f_hz

    @property
    def event(self) -> tuple[str, float, float]:
        return "switch-on", float(self.start), 1.0 / self.f_hz

    def _evaluate(self, t):
        value = jnp.sin(2 * jnp.pi * self.f_hz * (t - self.start) + jnp.deg2rad(self.phase_deg))
        return jnp.where(self._inside(t), value, 0.0)


@dataclass(frozen=True, eq=False)
class Sweep(Signal):
    """Sine sweep ``s(t) = sin(phi(t - start))`` from ``f0_hz`` to ``f1_hz`` over ``duration``.

    ``law = "linear"``: the frequency rises linearly, ``phi(tau) = 2 pi (f0 tau + (f1 - f0)
    tau^2 / (2 T))``. ``law = "log"``: exponentially (constant octaves per second),
    ``phi(tau) = 2 pi f0 T / ln(f1/f0) ((f1/f0)^(tau/T) - 1)``. Zero outside
    ``[start, start + duration)``. A sweep rate in octaves per minute, as test standards state it
    (IEC 60068-2-6: 1 oct/min), gives a log sweep of ``T = 60 |log2(f1/f0)| / rate``.

    Parameters
    ----------
    f0_hz, f1_hz : float
        Start and end frequencies [Hz], > 0 (a downward sweep is allowed; a log sweep needs
        ``f0_hz != f1_hz``).
    duration : float, optional
        Sweep time T [s], > 0; or give ``rate_oct_per_min``.
    start : float, optional
        Start time [s]. Default 0.
    law : {"linear", "log"}, optional
        Default "linear", or "log" with a rate.
    rate_oct_per_min : float, optional
        Sweep rate [octaves per minute], > 0, instead of ``duration``: a log sweep.
    """

    kind: ClassVar[str] = "sweep"
    _static: ClassVar[tuple[str, ...]] = ("law", "rate_oct_per_min")
    f0_hz: float = checked(_FREQUENCY)
    f1_hz: float = checked(_FREQUENCY)
    duration: float | None = checked(optional(_DURATION), default=None)
    start: float = checked(_TIME, default=0.0)
    law: str | None = checked(optional(choice_check(("linear", "log"))), default=None)
    rate_oct_per_min: float | None = checked(
        optional(number_check("a positive sweep rate in octaves per minute", low=0.0, strict=True)), default=None)

    def __check__(self) -> None:
        rate = self.rate_oct_per_min
        law = self.law or ("log" if rate is not None else "linear")
        if law == "log" and self.f0_hz == self.f1_hz:
            raise InputError("f1_hz", "a frequency different from f0_hz for a log sweep", self.f1_hz)
        if rate is not None:
            if self.duration is not None:
                raise InputError("rate_oct_per_min", "either a duration or a rate, not both", rate)
            if law != "log":
                raise InputError("law", "'log' for a sweep at a rate in octaves per minute", law)
            self._derive(duration=60.0 * abs(math.log2(self.f1_hz / self.f0_hz)) / rate)
        elif self.duration is None:
            raise InputError("duration", "a sweep time in s, or rate_oct_per_min for a log sweep", Plain("neither"))
        self._derive(law=law)

    def _evaluate(self, t):
        T = self.duration
        # 0 outside the window keeps exp() finite there; not a clip, whose derivative at the window's
        # start is halved (the mean of both sides).
        tau = jnp.where(self._inside(t), t - self.start, 0.0)
        if self.law == "linear":
            phase = 2 * jnp.pi * (self.f0_hz * tau + (self.f1_hz - self.f0_hz) * tau**2 / (2 * T))
        else:
            ratio = self.f1_hz / self.f0_hz
            phase = 2 * jnp.pi * self.f0_hz * T / jnp.log(ratio) * jnp.expm1(tau / T * jnp.log(ratio))
        return jnp.where(self._inside(t), jnp.sin(phase), 0.0)

    @property
    def max_frequency_hz(self) -> float:
        return max(self.f0_hz, self.f1_hz)

    @property
    def event(self) -> tuple[str, float, float]:
        return "switch-on", float(self.start), 1.0 / self.f0_hz

    def frequency_hz(self, t):
        """Instantaneous frequency [Hz] at ``t`` (inside the sweep window)."""
        tau = jnp.clip(jnp.asarray(t, dtype=float) - self.start, 0.0, self.duration)
        if self.law == "linear":
            return self.f0_hz + (self.f1_hz - self.f0_hz) * tau / self.duration
        return self.f0_hz * (self.f1_hz / self.f0_hz) ** (tau / self.duration)


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
    start: float = checked(_TIME)
    duration: float = checked(_DURATION)

    @property
    def max_frequency_hz(self) -> float:
        return 1.0 / self.duration  # a pulse of duration d carries its energy below about 1/d

    @property
    def event(self) -> tuple[str, float, float]:
        return "shock", float(self.start), float(self.duration)

    def _evaluate(self, t):
        return jnp.where(self._inside(t), jnp.sin(jnp.pi * (t - self.start) / self.duration), 0.0)


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
    start: float = checked(_TIME)
    duration: float = checked(_DURATION)

    @property
    def max_frequency_hz(self) -> float:
        return 1.0 / self.duration

    @property
    def event(self) -> tuple[str, float, float]:
        return "shock", float(self.start), float(self.duration)

    def _evaluate(self, t):
        return jnp.where(self._inside(t), 0.5 * (1.0 - jnp.cos(2 * jnp.pi * (t - self.start) / self.duration)), 0.0)


@dataclass(frozen=True, eq=False)
class Step(Signal):
    """Unit step: 0 before ``start``, 1 from ``start`` on (a suddenly applied, held load).

    Parameters
    ----------
    start : float, optional
        Switch-on time [s]. Default 0.
    """

    kind: ClassVar[str] = "step"
    start: float = checked(_TIME, default=0.0)

    def _evaluate(self, t):
        return jnp.where(t >= self.start, 1.0, 0.0)

    @property
    def support(self) -> tuple[float, float]:
        return float(self.start), math.inf

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return (float(self.start),)


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
    duration: float = checked(_DURATION)
    start: float = checked(_TIME, default=0.0)

    def _evaluate(self, t):
        # Branches on half-open pieces, not a clip: the slope at either end is the one after it.
        rising = jnp.where(t >= self.start, (t - self.start) / self.duration, 0.0)
        return jnp.where(t >= self.start + self.duration, 1.0, rising)

    @property
    def support(self) -> tuple[float, float]:
        return float(self.start), math.inf


@dataclass(frozen=True, eq=False)
class Table(Signal):
    """Tabulated samples, linearly interpolated (a first-order hold), or with their slopes, interpolated by
    cubic Hermite polynomials (value and slope continuous).

    Without slopes every sample time is a breakpoint (the slope changes there). With them only the
    first and last are: inside, value and slope are continuous and only the second derivative jumps,
    which the step control absorbs with a few rejected steps (stepping onto every knot instead was
    measured 5x slower on a 16 kHz table).

    Parameters
    ----------
    t : sequence of float
        Sample times [s], strictly increasing, at least 2.
    values : sequence of float
        Samples (dimensionless multiplier, or ground motion before ``scale``), one per time.
    outside : {"zero", "hold"}, optional
        Value before the first sample and from the last sample's time on: zero (default: a record
        that starts and ends at rest) or the end samples held. Right-continuous like every signal:
        with ``"zero"`` the value *at* the last time is already 0.
    slopes : sequence of float, optional
        The signal's time derivative at each sample [1/s]. Given, the table is a cubic Hermite spline
        (exact for cubics; a sine sampled 8 times per period keeps its amplitude within 1e-3): how
        :mod:`sixdof.validation.random_time` hands a synthesized random record to the direct solve.
    """

    kind: ClassVar[str] = "table"
    _static: ClassVar[tuple[str, ...]] = ("outside",)
    t: np.ndarray = checked(increasing_times)
    values: np.ndarray
    outside: str = checked(choice_check(("zero", "hold")), default="zero")
    slopes: np.ndarray | None = None

    def __check__(self) -> None:
        self._derive(values=finite_array(self.values, "values", f"{self.t.size} finite values (one per time)",
                                         self.t.shape))
        if self.slopes is not None:
            self._derive(slopes=finite_array(self.slopes, "slopes", f"{self.t.size} finite slopes in 1/s (one "
                                             "per time)", self.t.shape))

    def _evaluate(self, t):
        edge = 0.0 if self.outside == "zero" else None  # None: the end samples held
        if self.slopes is None:
            inside = jnp.interp(t, jnp.asarray(self.t), jnp.asarray(self.values), left=edge, right=edge)
        else:
            inside = self._hermite(t, edge)
        # interp takes the segment after every knot but the last, where it gives the value and slope
        # before it; right-continuity wants what follows: the held end sample or zero, flat.
        after = self.values[-1] if self.outside == "hold" else 0.0
        return jnp.where(t >= self.t[-1], after, inside)

    def _hermite(self, t, edge):
        knots, values, slopes = (jnp.asarray(a) for a in (self.t, self.values, self.slopes))
        i = jnp.clip(jnp.searchsorted(knots, t, side="right") - 1, 0, knots.size - 2)
        h = knots[i + 1] - knots[i]
        s = (t - knots[i]) / h
        s2, s3 = s * s, s * s * s
        value = ((2 * s3 - 3 * s2 + 1) * values[i] + (s3 - 2 * s2 + s) * h * slopes[i]
                 + (3 * s2 - 2 * s3) * values[i + 1] + (s3 - s2) * h * slopes[i + 1])
        before = self.values[0] if edge is None else 0.0
        return jnp.where(t < knots[0], before, value)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        if self.slopes is not None:
            return float(self.t[0]), float(self.t[-1])
        return tuple(float(x) for x in self.t)

    @property
    def support(self) -> tuple[float, float]:
        # Zero outside the segments that touch a non-zero sample (and beyond a held non-zero end).
        nonzero = np.flatnonzero(self.values)
        if nonzero.size == 0:
            return math.inf, math.inf  # zero everywhere
        first, last = int(nonzero[0]), int(nonzero[-1])
        held = self.outside == "hold"
        start = -math.inf if held and first == 0 else float(self.t[max(first - 1, 0)])
        end = math.inf if held and last == self.t.size - 1 else float(self.t[min(last + 1, self.t.size - 1)])
        return start, end

    @property
    def peak(self) -> float:
        return float(np.max(np.abs(self.values)))


#: Most sines of a random signal: evaluated at n times a signal builds an (n, components) array, and
#: far fewer sines already make its values Gaussian and its spectrum flat.
MAX_RANDOM_COMPONENTS = 10_000


def _components(value: Any, field: str) -> int:
    expected = f"an integer from 1 to {MAX_RANDOM_COMPONENTS}"
    if integer(value, field, expected, 1) > MAX_RANDOM_COMPONENTS:
        raise InputError(field, expected, value)
    return int(value)


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
        Root-mean-square value [signal unit: 1 for a load's multiplier, the record's for ground motion
        before ``scale``], > 0.
    seed : int
        Seed, >= 0.
    components : int, optional
        Number of sines, 1 to :data:`MAX_RANDOM_COMPONENTS`. Default 64.
    start : float, optional
        Start time [s]. Default 0 (the signal jumps from 0 to its first value there).
    duration : float, optional
        Length [s]. Default: for ever.
    """

    kind: ClassVar[str] = "random"
    _static: ClassVar[tuple[str, ...]] = ("components",)
    _derived: ClassVar[tuple[str, ...]] = ("frequencies", "phases")
    f_hz: tuple[float, float] = checked(frequency_band)
    rms: float = checked(number_check("a positive rms value", low=0.0, strict=True))
    seed: int = checked(integer_check("an integer >= 0", 0))
    components: int = checked(_components, default=64)
    start: float = checked(_TIME, default=0.0)
    duration: float = checked(_LASTING, default=math.inf)

    def __check__(self) -> None:
        rng = np.random.default_rng(self.seed)
        n = self.components
        edges = np.linspace(self.f_hz[0], self.f_hz[1], n + 1)
        self._derive(frequencies=readonly(edges[:-1] + rng.uniform(0.0, 1.0, n) * np.diff(edges)),
                     phases=readonly(rng.uniform(0.0, 2 * np.pi, n)))

    def _evaluate(self, t):
        amplitude = self.rms * jnp.sqrt(2.0 / self.components)
        tau = (t - self.start)[..., None]
        value = amplitude * jnp.sum(jnp.sin(2 * jnp.pi * self.frequencies * tau + self.phases), axis=-1)
        return jnp.where(self._inside(t), value, 0.0)

    @property
    def max_frequency_hz(self) -> float:
        return self.f_hz[1]

    @property
    def peak(self) -> float:
        # A long Gaussian-like record reaches about 4 rms.
        return 4.0 * float(self.rms)


SIGNAL_KINDS: dict[str, type[Signal]] = {
    cls.kind: cls for cls in (Harmonic, Sweep, HalfSine, Haversine, Step, Ramp, Table, Random)
}
"""TOML ``kind`` of a signal (``"harmonic"``, ``"sweep"``, ...) -> its class."""


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
    kind = table.pop("kind", Plain("nothing"))
    if not isinstance(kind, str) or kind not in SIGNAL_KINDS:
        raise InputError("kind", f"one of {choices(SIGNAL_KINDS)}", kind)
    return build(SIGNAL_KINDS[kind], table, "")


def signal_field(value: Any, field: str = "signal") -> Signal:
    """Check of a signal field: errors name the signal's own keys under ``field``."""
    if value is None:
        raise InputError(field, "a signal such as {kind = \"harmonic\", f_hz = 5.0}", Plain("nothing"))
    try:
        return make_signal(value)
    except InputError as exc:
        raise exc.within(field) from None
