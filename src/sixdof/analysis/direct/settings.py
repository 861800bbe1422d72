"""The settings of a direct simulation (the scenario's ``[simulation]`` table), and the tolerances it steps with."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from sixdof.errors import InputError, Plain, integer_check, number, number_check
from sixdof.frozen import Frozen
from sixdof.model.system import System
from sixdof.results import label, result_type

#: The solvers (diffrax's methods of these names). Explicit Runge-Kutta methods suit the problem (it is not
#: stiff: 0.6 to 38 Hz for the bridge beam); the implicit ones are there for comparison.
SOLVERS: dict[str, str] = {
    "Tsit5": "explicit Runge-Kutta, order 5(4), Tsitouras",
    "Dopri5": "explicit Runge-Kutta, order 5(4), Dormand-Prince",
    "Dopri8": "explicit Runge-Kutta, order 8(7), Dormand-Prince",
    "Bosh3": "explicit Runge-Kutta, order 3(2), Bogacki-Shampine",
    "Heun": "explicit Runge-Kutta, order 2(1)",
    "Kvaerno3": "implicit (ESDIRK), order 3(2)",
    "Kvaerno5": "implicit (ESDIRK), order 5(4)",
}


def _solver(value, field: str) -> str:
    if value not in SOLVERS:
        raise InputError(field, f"one of {', '.join(SOLVERS)}", value)
    return value


def _tolerance(value, field: str) -> float:
    tolerance = number(value, field, "a tolerance in (0, 1)", low=0.0, strict=True)
    if tolerance >= 1:
        raise InputError(field, "a tolerance in (0, 1)", value)
    return tolerance


#: The most samples a simulation may have: at 15 us each at least (the bundled bridge, 2000 s at 1 kHz: 2,000,001
#: samples in 30 s) 10^9 take 4 h, and their results file 1.4 TB with four mounts and a body point.
MAX_SAMPLES = 10**9


#: The least a sample of a simulation costs [s], measured as above.
SECONDS_PER_SAMPLE = 15e-6


@result_type
@dataclass(frozen=True)
class SimulationSettings(Frozen):
    """How to run a direct simulation (the scenario's ``[simulation]`` table).

    Parameters
    ----------
    duration : float
        Simulated time [s], > 0.
    sample_rate_hz : float
        Output samples per second [Hz], > 0; samples at ``start + k / sample_rate_hz`` up to
        ``start + duration``.
    start : float, optional
        Start time [s]. Default 0.
    solver : str, optional
        A key of :data:`SOLVERS`. Default ``"Tsit5"``, chosen by measurement (benchmarks/bench_direct.py,
        bridge beam, 20 s at 1 kHz): at today's accuracy it runs ~10x faster than scipy's DOP853; Dopri8 at
        1e-10, as accurate, takes a third of the steps but only ~0.8x the time (the stages are unrolled
        and saving the 20,001 samples costs the same for both) for ~1 s more tracing and compilation at
        a process's first run of a structure. Choose ``"Dopri8"`` for long runs, or with tolerances of
        1e-11 for a 7x smaller error at about Tsit5's cost.
    rtol : float, optional
        Relative tolerance per step [1]. Default 1e-9.
    atol : float, optional
        Absolute tolerance per step [1] *as a fraction of each state component's scale*
        (:func:`state_scale`). Default 1e-9. Both hold for runs of up to :data:`CYCLES_PER_TOLERANCE`
        cycles of the highest natural frequency; a longer run is solved at tolerances divided by its
        cycles over that (:func:`cycle_scaled`), since the global error grows with the number of cycles
        of the fastest mode. With the defaults every DOF of the bridge beam stays within 3e-8 of its own
        peak over a 20 s run.
    max_steps : int, optional
        Step limit *per window* (:func:`simulate_windows`: at most :data:`WINDOW_SAMPLES` samples), so a
        run of any duration that needs fewer than ``max_steps / WINDOW_SAMPLES`` steps per sample
        (30 by default; the bridge beam at 1 kHz needs 0.9 with Tsit5) never reaches it. Default 1e6.
    min_contact_s : float, optional
        Runs with nonlinear mounts: the shortest excursion past a knot of a force law (a contact, a lift-off) that
        the solve is sure to see [s]. A change of region is found as a sign change between two steps, so the step
        is capped at half of this. Default 1e-3.
    """

    duration: float = label(check=number_check("a positive, finite duration in s", low=0.0, strict=True))
    sample_rate_hz: float = label(check=number_check("a positive, finite sample rate in Hz", low=0.0, strict=True))
    start: float = label(check=number_check("a finite time in s"), default=0.0)
    solver: str = label(check=_solver, default="Tsit5")
    rtol: float = label(check=_tolerance, default=1e-9)
    atol: float = label(check=_tolerance, default=1e-9)
    max_steps: int = label(check=integer_check("a positive integer", 1), default=1_000_000)
    min_contact_s: float = label(check=number_check("a positive duration in s", low=0.0, strict=True), default=1e-3)

    def __check__(self) -> None:
        product = self.duration * self.sample_rate_hz  # inf past float's range, 0 below it
        if product < 1:
            raise InputError("sample_rate_hz", f"a rate giving at least 2 samples over the duration of "
                             f"{self.duration:g} s (at least {1 / self.duration:.3g} Hz)", self.sample_rate_hz)
        if not product < MAX_SAMPLES:
            raise InputError("duration", f"at most {MAX_SAMPLES:,} samples (duration x sample_rate_hz; each takes "
                             f"{SECONDS_PER_SAMPLE * 1e6:g} us of computing at least)",
                             Plain(f"{self.duration:g} s at {self.sample_rate_hz:g} Hz, {product:.3g} samples"))

    @property
    def samples(self) -> int:
        """Number of output samples."""
        return int(math.floor(self.duration * self.sample_rate_hz * (1 + 1e-12))) + 1

    @property
    def times(self) -> np.ndarray:
        """Output times (n,) [s]."""
        return self.times_between(0, self.samples)

    def times_between(self, first: int, stop: int) -> np.ndarray:
        """Output times [s] of the samples ``first`` to ``stop - 1``."""
        # Clipped: the tolerance above admits a last sample a rounding past the end, where diffrax won't save.
        return np.minimum(self.start + np.arange(first, stop) / self.sample_rate_hz, self.start + self.duration)


#: A run's ``rtol`` and ``atol`` hold as given for up to this many cycles of its highest natural frequency; a longer
#: run divides both by its cycles over this. The global error grows with the number of cycles of the fastest mode
#: (each step's error accumulates): a 0.002 kg body on mounts with modes from 1 to 600 Hz, ringing 5000 cycles of
#: its 600 Hz mode, ended 1.01e-6 of its peak off the exact matrix exponential at 1e-9 and 1.04e-7 at 1e-10
#: (Tsit5; about 0.2 tol per cycle). 500 cycles keep the default 1e-9 within ~1e-7, ten times inside the 1e-6
#: promised; the bridge beam's 20 s runs (761 cycles of 38 Hz) solve at 6.6e-10.
CYCLES_PER_TOLERANCE = 500.0


#: The least tolerance :func:`cycle_scaled` divides down to (one given smaller is kept as given).
MIN_TOLERANCE = 1e-12


def cycle_scaled(system: System, settings: SimulationSettings) -> SimulationSettings:
    """``settings`` with ``rtol`` and ``atol`` divided by the run's cycles of its highest natural frequency over
    :data:`CYCLES_PER_TOLERANCE`, when there are more (unchanged otherwise), down to :data:`MIN_TOLERANCE`: what
    the solver steps with, and what its statistics record."""
    cycles = float(np.max(system.modes.frequency_hz, initial=0.0)) * settings.duration
    if cycles <= CYCLES_PER_TOLERANCE:
        return settings
    factor = CYCLES_PER_TOLERANCE / cycles
    # Not below MIN_TOLERANCE: a step's round-off (float64, ~1e-16 of the state) is the floor no step size passes,
    # and the solver would run out of steps for it (a 2000 s run with a 600 Hz mode asked for 4e-13).
    return dataclasses.replace(settings, rtol=max(settings.rtol * factor, min(settings.rtol, MIN_TOLERANCE)),
                               atol=max(settings.atol * factor, min(settings.atol, MIN_TOLERANCE)))
