"""A run in time windows of bounded memory, and :func:`simulate`, which joins them."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from sixdof._jax import jax
from sixdof.analysis.contact import merge_events
from sixdof.analysis.direct.breakpoints import _inside, _jump_slots, _padded
from sixdof.analysis.direct.cache import _compiled_window
from sixdof.analysis.direct.form import _GROUND_CODES, first_order_form, loads_of
from sixdof.analysis.direct.nonlinear import _law_motion, _nonlinear_params, _segments, is_nonlinear
from sixdof.analysis.direct.scale import state_scale
from sixdof.analysis.direct.settings import SimulationSettings, cycle_scaled
from sixdof.analysis.direct.solve import _failure, _window_args
from sixdof.analysis.records import SolverStats, merge_stats
from sixdof.analysis.validity import warn_idle, warn_large_rotations
from sixdof.errors import SolverError, instance, integer, memory_check, readonly
from sixdof.excitation import Excitation
from sixdof.model.system import System
from sixdof.progress import Meter, meter
from sixdof.results import TimeHistory, time_concat

#: The most output samples of one window: the bridge beam's 20 s at 1 kHz in one window, 2000 s in 62. A
#: window's arrays take ~0.5 kB per sample in the solve (16 MB) and a few kB in a whole run's workflow; each
#: window costs ~1 ms besides its steps (measured: 40 s in windows of 2048 samples took 1.2x one window).
WINDOW_SAMPLES = 32768


#: Window lengths are multiples of this (windows of a run are equal but the last), so that runs of
#: similar lengths share one compiled solve.
WINDOW_GRANULE = 512


#: Peak memory of :func:`simulate` per output sample [bytes]: the windows, their join and its read-only copy
#: (measured 594 on the bridge traffic scenario, 5e5 samples; a ground motion adds three (n, 3) arrays).
SOLVE_BYTES_PER_SAMPLE = 800


def _arguments(system: System, excitation: Excitation | None, settings: SimulationSettings) -> Excitation:
    """The excitation of a solve (``None``: none), once each argument is checked to be of its kind: so that
    ``simulate(excitation, system, settings)`` is one clear error, not an AttributeError from inside."""
    instance(system, "system", System)
    instance(settings, "settings", SimulationSettings)
    excitation = instance(excitation, "excitation", Excitation, None)
    return Excitation() if excitation is None else excitation


def window_length(samples: int, most: int = WINDOW_SAMPLES) -> int:
    """Samples per window of a run of ``samples`` samples: as equal as possible, at most ``most``, a
    multiple of :data:`WINDOW_GRANULE` (so that similar runs share one compiled solve) where that fits."""
    windows = -(-samples // most)
    return min(most, WINDOW_GRANULE * -(-samples // (windows * WINDOW_GRANULE)))


@dataclass(frozen=True)
class _Run:
    """What every window of a run shares: its arrays and the compiled window solve."""

    params: dict
    r: np.ndarray
    sigma: np.ndarray
    breakpoints: np.ndarray
    jump_slots: int
    window: int
    solve: Callable
    region: np.ndarray | None = None  # the force laws' regions at the start (nonlinear mounts)
    laws: Any = None  # System.nonlinear, with nonlinear mounts
    code: int = 0  # the ground's kind (_GROUND_CODES)
    branches: int = 0  # Maxwell branch states (after them in the state: the hysteretic variables)


def _prepare(system: System, excitation: Excitation, settings: SimulationSettings,
             window: int) -> tuple[_Run, np.ndarray]:
    """The run's shared arrays and compiled solve, and its scaled initial state."""
    vectors, signals = loads_of(excitation, settings)
    t0, t1 = settings.start, settings.start + settings.duration
    ground = excitation.ground
    code = _GROUND_CODES[None if ground is None else ground.quantity]
    r = np.zeros(6) if ground is None else ground.rigid_vector
    sigma = state_scale(system, excitation, settings)
    A, B = first_order_form(system, excitation)
    params = {"A": A, "B": B, "sigma": sigma, "vectors": vectors, "signals": signals,
              "ground_signal": None if ground is None else ground.signal,
              "ground_scale": 0.0 if ground is None else float(ground.scale)}
    params = jax.tree.map(np.asarray, params)
    # Initial state: z = q - r u_g with the ground's displacement at t0 (zero for integrated grounds);
    # q0 includes the equilibrium r u_g(t0), so that at rest no mount is deflected.
    q0, qd0 = excitation.initial_state(system, t0)
    u0 = float(ground.scale * ground.signal(t0)) if code == 1 else 0.0
    # The hysteretic variables start at zero: the bearings at rest at the static equilibrium.
    x0 = np.concatenate([q0 - r * u0, qd0, [0.0, 0.0], excitation.initial_branch_forces(system),
                         np.zeros(system.hysteretic.count)])

    breakpoints = np.array(sorted(b for b in excitation.breakpoints if t0 < b < t1), dtype=float)
    inside = [_inside(breakpoints, ts[0], end) for ts, end in window_spans(settings, window)]
    slots = _jump_slots(max(part.stop - part.start for part in inside))
    laws = system.nonlinear
    xs0 = x0 / sigma
    region = None
    if is_nonlinear(system):
        params = {**params, **_nonlinear_params(system, excitation, sigma, settings)}
        xs0 = np.concatenate([xs0, [0.0, 0.0]])  # the work done and the energy dissipated since the start
        region = laws.state(*_law_motion(laws, params, code, r, t0, x0))
    example = _window_args(params, xs0, np.zeros(window + 1), t0, t1, np.zeros(slots), settings, region)
    solve = _compiled_window(example, solver=settings.solver, code=code, max_steps=settings.max_steps,
                             nonlinear=region is not None)
    return _Run(params, r, sigma, breakpoints, slots, window, solve, region, laws if region is not None else None,
                code, system.branches.count), xs0


def simulate_windows(system: System, excitation: Excitation | None, settings: SimulationSettings, *,
                     window_samples: int = WINDOW_SAMPLES) -> Iterator[TimeHistory]:
    """Integrate eq. (1) in time windows: an iterator of one :class:`~sixdof.results.TimeHistory` per window.

    The windows hold consecutive samples of the run, at most ``window_samples`` each
    (:func:`window_length`). Each starts from the solver's state where the previous one ended, as it is
    (ground integration states included), with the breakpoints inside it; so memory stays bounded by one
    window whatever the duration, and ``settings.max_steps`` applies per window. Joined
    (:func:`simulate` does it), the windows are the run.

    Parameters
    ----------
    system, excitation, settings
        As :func:`simulate`.
    window_samples : int, optional
        The most samples of a window; default :data:`WINDOW_SAMPLES`.

    Yields
    ------
    sixdof.results.TimeHistory
        The window's samples, as :func:`simulate` describes them, with the window's solver statistics.

    Raises
    ------
    InputError
        For arguments of the wrong kind (when called, before any window is solved).
    SolverError
        If the solver fails in a window (step limit, step size collapse) or produces non-finite values
        (while iterating).

    Warns
    -----
    sixdof.analysis.validity.RangeWarning
        For a load that never acts in the simulated time (when called), and, after the last window, for
        rotations of the run beyond :data:`~sixdof.analysis.validity.SMALL_ANGLE_RAD`.
    """
    excitation = _arguments(system, excitation, settings)
    settings = cycle_scaled(system, settings)
    window = window_length(settings.samples, integer(window_samples, "window_samples", "a positive integer", 1))
    warn_idle(excitation, settings.start, settings.start + settings.duration)
    run, xs = _prepare(system, excitation, settings, window)
    return _windows(run, xs, settings)


def _windows(run: _Run, xs: np.ndarray, settings: SimulationSettings) -> Iterator[TimeHistory]:
    rotations = _RotationPeaks()
    region = run.region
    for ts, end in window_spans(settings, run.window):
        history, xs, region = _window(run, xs, region, ts, end, settings)
        rotations.add(history.t, history.q)
        yield history
    rotations.warn()


def window_spans(settings: SimulationSettings, window: int) -> Iterator[tuple[np.ndarray, float]]:
    """The sample times [s] of each window of ``window`` samples, and the time it ends [s]: the next
    window's first sample, or the run's end (where the sample after the last is clipped to)."""
    for first in range(0, settings.samples, window):
        stop = min(first + window, settings.samples)
        yield settings.times_between(first, stop), float(settings.times_between(stop, stop + 1)[0])


def _window(run: _Run, xs0: np.ndarray, region, ts: np.ndarray, end: float, settings: SimulationSettings):
    """Solve one window from ``ts[0]`` to ``end``: its :class:`TimeHistory`, the scaled state at ``end`` and the
    force laws' regions there (``None`` without nonlinear mounts)."""
    n = ts.size
    # Saved at the samples, then at the end (the next window's start), repeated to fill the compiled slots.
    saves = np.concatenate([ts, np.full(run.window + 1 - n, end)])
    inside = _inside(run.breakpoints, ts[0], end)
    jumps = _padded(run.breakpoints[inside], end, run.jump_slots)
    start = time.perf_counter()
    if region is None:
        args = _window_args(run.params, xs0, saves, ts[0], end, jumps, settings)
        xs_end, x, qdd, Q, kin, ok, result, steps = run.solve(*jax.tree.leaves(args))
        extra = {}
    else:
        xs_end, x, qdd, Q, kin, ok, result, steps, extra, region = _segments(run, xs0, region, saves, end, jumps,
                                                                             settings)
    x = np.asarray(x)[:n]
    wall = time.perf_counter() - start
    if not bool(ok):
        raise SolverError(f"direct solve with {settings.solver} (rtol={settings.rtol:g}, atol={settings.atol:g}, "
                          f"max_steps={settings.max_steps} per window) failed in [{ts[0]:.6g}, {end:.6g}] s: "
                          f"{_failure(result)}")
    qdd, Q, kin = np.asarray(qdd)[:n], np.asarray(Q)[:n], np.asarray(kin)[:n]
    bad = np.flatnonzero(~np.all(np.isfinite(x), axis=1))
    if bad.size or not np.all(np.isfinite(qdd)):
        what = f"values (first at t = {ts[bad[0]]:.6g} s)" if bad.size else "accelerations"
        raise SolverError(f"direct solve with {settings.solver} produced non-finite {what}")
    r = run.r
    has_ground = run.params["ground_signal"] is not None
    ground = {f"ground_{m}": np.outer(kin[:, i], r[:3]) for i, m in enumerate(_MOTION)} if has_ground else {}
    n_steps, n_accepted, n_rejected = (int(s) for s in np.asarray(steps))
    energy = {key: value[:n] for key, value in extra.items() if key.startswith("energy")}
    history = TimeHistory(
        t=ts, q=x[:, :6] + np.outer(kin[:, 0], r), qd=x[:, 6:12], qdd=qdd, Q=Q, **ground, **energy,
        maxwell_force=x[:, 14:14 + run.branches] if run.branches else None,
        hysteretic_state=x[:, 14 + run.branches:] if x.shape[1] > 14 + run.branches else None,
        contacts=extra.get("contacts"),
        stats=SolverStats(
            solver=settings.solver, rtol=settings.rtol, atol=settings.atol, scale=readonly(run.sigma),
            num_steps=n_steps, num_accepted=n_accepted, num_rejected=n_rejected,
            # A breakpoint at the window's start was stepped onto as the previous window's end: counted here.
            max_steps=settings.max_steps, num_jumps=int(inside.stop - np.searchsorted(run.breakpoints, ts[0])),
            wall_time_s=wall, num_events=extra["contacts"].count if extra else 0,
        ),
    )
    return history, np.asarray(xs_end), region


_MOTION = ("displacement", "velocity", "acceleration")


class _RotationPeaks:
    """The largest rotation of each axis over a run's windows and its time, for one warning at the end."""

    def __init__(self) -> None:
        self.peak = np.zeros(3)
        self.time = np.zeros(3)

    def add(self, t: np.ndarray, q: np.ndarray) -> None:
        rotations = np.abs(q[:, 3:])
        at = rotations.argmax(axis=0)
        larger = rotations[at, range(3)] > self.peak
        self.peak = np.where(larger, rotations[at, range(3)], self.peak)
        self.time = np.where(larger, t[at], self.time)

    def warn(self) -> None:
        # One row per axis, holding that axis's peak at its time: the run's rotations as the warning sees them.
        q = np.zeros((3, 6))
        q[:, 3:] = np.diag(self.peak)
        warn_large_rotations(self.time, q)


def progress_meter(progress: Any, settings: SimulationSettings) -> Meter:
    """The meter of the simulated time that ``progress`` asks for (:func:`sixdof.progress.meter`), shown
    with the time reached after each window."""
    return meter(progress, settings.duration, "s", "direct solve", origin=settings.start)


def simulate(system: System, excitation: Excitation | None, settings: SimulationSettings,
             progress: Any = None, *, window_samples: int = WINDOW_SAMPLES) -> TimeHistory:
    """Integrate eq. (1) in time for ``system`` under ``excitation``: the windows of
    :func:`simulate_windows`, joined.

    Parameters
    ----------
    system : sixdof.model.system.System
        Provides ``M``, ``C`` (all damping) and ``K``.
    excitation : Excitation or None
        Loads, ground motion, initial state. ``None``: at rest, nothing happens.
    settings : SimulationSettings
    progress : None, bool, "text" or "tqdm", optional
        Show the simulated time reached after each window on stderr (``True`` picks tqdm when
        installed). Drawn between windows, it costs nothing inside the solve. Default: silent.
    window_samples : int, optional
        The most samples of a window (:func:`simulate_windows`).

    Returns
    -------
    sixdof.results.TimeHistory
        Absolute motion, the ground's motion when it moves, the loads' generalized force and the
        solver's statistics (``stats``, over all windows).

    Raises
    ------
    InputError
        If the run's samples cannot fit in memory (:func:`simulate_windows` runs in bounded memory).
    SolverError
        If the solver fails (step limit, step size collapse) or produces non-finite values.

    Warns
    -----
    sixdof.analysis.validity.RangeWarning
        For a load that never acts in the simulated time, and for rotations beyond
        :data:`~sixdof.analysis.validity.SMALL_ANGLE_RAD`.
    """
    _arguments(system, excitation, settings)  # before the settings' size is read
    memory_check("sample_rate_hz", settings.samples * SOLVE_BYTES_PER_SAMPLE, "a number of output samples",
                 f"{settings.samples:.3g} samples")
    meter = progress_meter(progress, settings)
    windows = []
    for window in simulate_windows(system, excitation, settings, window_samples=window_samples):
        windows.append(window)
        meter.show(float(window.t[-1]))
    meter.close()
    contacts = {}
    if windows[0].contacts is not None:
        contacts["contacts"] = merge_events([w.contacts for w in windows])
    return time_concat(windows, stats=merge_stats([w.stats for w in windows]), **contacts)
