"""Direct time integration of eq. (1), ``M q'' + C q' + K q = Q(t)``, with diffrax in float64.

The first-order state is ``x = [z, w, u_g, v_g]`` (14 values):

- ``z = q - r u_g`` (6): the body's displacement *relative to the ground* [m, rad] — what the
  mounts feel;
- ``w = q'`` (6): the body's *absolute* velocity [m/s, rad/s];
- ``u_g, v_g``: displacement [m] and velocity [m/s] of the ground along its direction, integrated
  here when the ground motion is given as a velocity or an acceleration (otherwise unused);

with ``r`` (6,) the generalized coordinates of a unit rigid translation of the foundation. Then

    z' = w - r v_g,        M w' = Q(t) - C (w - r v_g) - K z

which needs at most the *first* derivative of a prescribed ground displacement (a table of
displacements is handled exactly; a relative formulation with ``-M r u_g''`` would need Dirac
deltas at every knot). Without ground motion ``z = q`` and it is the plain first-order form.
All damping (mount dashpots, Rayleigh, modal) acts on the motion relative to the ground, since all of
it stands for dissipation in the mounts.

The solver steps onto every signal breakpoint inside the run (``jump_ts``). The state is divided by
a per-component scale (:func:`state_scale`), so that ``rtol`` and ``atol`` hold relative to each
component's own expected size, translations (~1e-4 m) and rotations (~1e-7 rad) alike. Compiled code
is cached per problem *structure* (solver, signal kinds, numbers of loads, samples and breakpoints);
matrices, signal parameters, times and tolerances are arguments, so new values reuse it.
"""

from __future__ import annotations

import importlib.util
import math
import time
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np

from sixdof._jax import jax, jnp
from sixdof.analysis.validity import warn_idle, warn_large_rotations
from sixdof.errors import InputError, SolverError, integer_check, memory_check, number, number_check, readonly
from sixdof.excitation import Excitation
from sixdof.frozen import Frozen
from sixdof.results import TimeHistory, label

# isort: split
import diffrax  # noqa: E402  (after ._jax: float64 must be on first)

if TYPE_CHECKING:
    from sixdof.model.system import System

#: Explicit Runge-Kutta solvers (the problem is not stiff) and, for comparison, implicit ones.
SOLVERS: dict[str, type] = {
    "Tsit5": diffrax.Tsit5,
    "Dopri5": diffrax.Dopri5,
    "Dopri8": diffrax.Dopri8,
    "Bosh3": diffrax.Bosh3,
    "Heun": diffrax.Heun,
    "Kvaerno3": diffrax.Kvaerno3,
    "Kvaerno5": diffrax.Kvaerno5,
}

#: A state component's scale is at least this fraction of the largest, in energy-consistent units
#: (scale times sqrt(M_ii)): DOFs that only couple in through non-proportional damping still get a
#: finite, small tolerance instead of an infinitely tight or a meaningless one.
SCALE_FLOOR = 1e-6

#: Peak memory of :func:`simulate` per output sample [bytes]: 480 measured (engine scenario, 1.6e6 samples).
SOLVE_BYTES_PER_SAMPLE = 500

_GROUND_CODES = {None: 0, "displacement": 1, "velocity": 2, "acceleration": 3}

#: Progress display of long solves.
PROGRESS_METERS = {"none": diffrax.NoProgressMeter, "text": diffrax.TextProgressMeter,
                   "tqdm": diffrax.TqdmProgressMeter}


# ----------------------------------------------------------------------------------------------------
# Settings and results.
# ----------------------------------------------------------------------------------------------------


def _solver(value, field: str) -> str:
    if value not in SOLVERS:
        raise InputError(field, f"one of {', '.join(SOLVERS)}", value)
    return value


def _tolerance(value, field: str) -> float:
    tolerance = number(value, field, "a tolerance in (0, 1)", low=0.0, strict=True)
    if tolerance >= 1:
        raise InputError(field, "a tolerance in (0, 1)", value)
    return tolerance


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
        A key of :data:`SOLVERS`. Default ``"Tsit5"`` (explicit, 5th order; measured fastest here).
    rtol : float, optional
        Relative tolerance per step. Default 1e-9.
    atol : float, optional
        Absolute tolerance per step *as a fraction of each state component's scale*
        (:func:`state_scale`). Default 1e-9. With the defaults every DOF of the bridge beam stays
        within about 1e-7 of its own peak over a 20 s run (global error grows with the number of
        cycles of the fastest mode, hence the margin).
    max_steps : int, optional
        Step limit; default 1e6 (diffrax's own default, 4096, is too small for 20 s runs).
    """

    duration: float = label(check=number_check("a positive, finite duration in s", low=0.0, strict=True))
    sample_rate_hz: float = label(check=number_check("a positive, finite sample rate in Hz", low=0.0, strict=True))
    start: float = label(check=number_check("a finite time in s"), default=0.0)
    solver: str = label(check=_solver, default="Tsit5")
    rtol: float = label(check=_tolerance, default=1e-9)
    atol: float = label(check=_tolerance, default=1e-9)
    max_steps: int = label(check=integer_check("a positive integer", 1), default=1_000_000)

    def __check__(self) -> None:
        samples = self.duration * self.sample_rate_hz
        memory_check("sample_rate_hz", samples * SOLVE_BYTES_PER_SAMPLE, "a number of output samples",
                     f"{samples:.3g} samples")

    @property
    def times(self) -> np.ndarray:
        """Output times (n,) [s]."""
        n = int(math.floor(self.duration * self.sample_rate_hz * (1 + 1e-12))) + 1
        # Clipped: the tolerance above admits a last sample a rounding past the end, where diffrax won't save.
        return np.minimum(self.start + np.arange(n) / self.sample_rate_hz, self.start + self.duration)


@dataclass(frozen=True)
class SolverStats:
    """Statistics of one solve (stored with the results).

    Attributes
    ----------
    solver : str
    rtol, atol : float
        As given (``atol`` is relative to ``scale``).
    scale : ndarray, shape (14,)
        Per-component scale of the state ``[z (6), w (6), u_g, v_g]`` [m, rad, m/s, rad/s].
    num_steps, num_accepted, num_rejected : int
        Steps attempted, accepted, rejected.
    max_steps : int
    num_jumps : int
        Breakpoints (discontinuities) inside the run the solver stepped onto.
    wall_time_s : float
        Wall-clock time of the solve call [s] (includes compilation when it was the first call of
        its structure).
    """

    solver: str = label(name="solver")
    rtol: float = label()
    atol: float = label()
    scale: np.ndarray = label()
    num_steps: int = label()
    num_accepted: int = label()
    num_rejected: int = label()
    max_steps: int = label()
    num_jumps: int = label()
    wall_time_s: float = label()


# ----------------------------------------------------------------------------------------------------
# Tolerance scale.
# ----------------------------------------------------------------------------------------------------


def state_scale(system: System, excitation: Excitation | None, settings: SimulationSettings) -> np.ndarray:
    """Expected size of each state component, used to make tolerances relative per DOF.

    A modal estimate, made before the solve: each load component ``(Q_k, s_k)`` drives mode ``r``
    to about ``|phi_r' Q_k| peak(s_k) / omega_r^2`` (its static modal response); a ground motion
    with peaks ``U, V, A`` (sampled) drives it to ``|phi_r' M r| min(U, V / omega_r, A / omega_r^2)``
    relative to the ground; an initial state to ``|phi_r' M q0| + |phi_r' M q0'| / omega_r``. Mode
    amplitudes ``eta_r`` map back to DOF ``i`` as ``sum_r |phi_ir| eta_r`` (displacements) and
    ``sum_r |phi_ir| omega_r eta_r`` (velocities). Rigid-body modes use ``omega_r = 2 / duration``.

    The estimate leaves out resonant amplification (up to ``1 / (2 zeta)``), which is the same for
    every DOF that a mode moves: it errs towards tighter tolerances, never looser, and keeps the
    DOFs' relative sizes right, which is what per-DOF accuracy needs; :data:`SCALE_FLOOR` bounds it below.

    Returns
    -------
    ndarray, shape (14,)
        ``[z (6) m, rad; w (6) m/s, rad/s; u_g m; v_g m/s]``, all > 0.
    """
    M = np.asarray(system.M)
    modes = system.modes
    phi = np.asarray(modes.shapes)
    omega = np.maximum(np.asarray(modes.omega), 2.0 / settings.duration)
    eta = np.zeros(6)  # displacement-like modal amplitudes
    eta_dot = np.zeros(6)  # velocity-like, for inputs that are not displacements
    extra_w = np.zeros(6)
    ground_u = ground_v = 1.0
    if excitation is not None:
        for vector, signal in excitation.components():
            eta += np.abs(phi.T @ vector) * signal.peak / omega**2
        if excitation.ground is not None:
            U, V, A = _ground_peaks(excitation.ground, settings)
            gamma = np.abs(phi.T @ M @ excitation.ground.rigid_vector)
            eta += gamma * np.minimum(np.minimum(U, V / omega), A / omega**2)
            extra_w += np.abs(excitation.ground.rigid_vector) * V
            ground_u, ground_v = (U if U > 0 else 1.0), (V if V > 0 else 1.0)
        q0, qd0 = excitation.initial_state(system, settings.start)
        q0 = q0 - excitation.equilibrium(settings.start)  # what moves is the departure from equilibrium
        eta += np.abs(phi.T @ M @ q0)
        eta_dot += np.abs(phi.T @ M @ qd0)
    z = np.abs(phi) @ (eta + eta_dot / omega)
    w = np.abs(phi) @ (omega * eta + eta_dot) + extra_w
    root_m = np.sqrt(np.diag(M))
    if not np.any(np.concatenate([z, w]) > 0):
        return np.ones(14)

    def floored(x):
        floor = SCALE_FLOOR * np.max(x * root_m)
        return np.maximum(x, floor / root_m) if floor > 0 else np.where(x > 0, x, 1.0)

    return np.concatenate([floored(z), floored(w), [ground_u, ground_v]])


def _ground_peaks(ground, settings: SimulationSettings) -> tuple[float, float, float]:
    """Peaks of ground displacement, velocity, acceleration over the run (sampled; a scale only)."""
    t0, t1 = settings.start, settings.start + settings.duration
    inside = [b for b in ground.signal.breakpoints if t0 < b < t1]
    t = np.unique(np.concatenate([np.linspace(t0, t1, 20001), inside]))
    s = ground.scale * np.asarray(ground.signal(t))

    def integral(x):
        return np.concatenate([[0.0], np.cumsum(0.5 * (x[1:] + x[:-1]) * np.diff(t))])

    if ground.quantity == "displacement":
        u, v = s, np.gradient(s, t)
        a = np.gradient(v, t)
    elif ground.quantity == "velocity":
        u, v, a = integral(s), s, np.gradient(s, t)
    else:
        v = integral(s)
        u, a = integral(v), s
    return float(np.max(np.abs(u))), float(np.max(np.abs(v))), float(np.max(np.abs(a)))


# ----------------------------------------------------------------------------------------------------
# The compiled solve.
# ----------------------------------------------------------------------------------------------------


def _ground_kinematics(code: int, ground_signal, ground_scale, t, g):
    """Ground displacement, velocity and acceleration along its direction at ``t``."""
    if code == 0:
        zero = jnp.zeros_like(t)
        return zero, zero, zero
    if code == 1:
        return (ground_scale * ground_signal(t), ground_scale * ground_signal.derivative(t),
                ground_scale * ground_signal.derivative(t, 2))
    if code == 2:
        return g[0], ground_scale * ground_signal(t), ground_scale * ground_signal.derivative(t)
    return g[0], g[1], ground_scale * ground_signal(t)


def _rates(t, x, p, code: int):
    """Unscaled state derivative ``x'``, the loads' generalized force ``Q(t)`` and the ground's ``u, v, a``."""
    z, w, g = x[:6], x[6:12], x[12:]
    Q = jnp.zeros(6)
    for k, signal in enumerate(p["signals"]):
        Q = Q + p["vectors"][k] * signal(t)
    u_g, v_g, a_g = _ground_kinematics(code, p["ground_signal"], p["ground_scale"], t, g)
    relative_velocity = w - p["r"] * v_g
    w_dot = p["Minv"] @ (Q - p["C"] @ relative_velocity - p["K"] @ z)
    # u_g, v_g are integrated only for grounds given as a velocity (u_g) or an acceleration (both).
    g_dot = jnp.stack([v_g if code >= 2 else 0.0, a_g if code == 3 else 0.0])
    return jnp.concatenate([relative_velocity, w_dot, g_dot]), Q, jnp.stack([u_g, v_g, a_g])


def solve_ode(field, x0, t0, t1, saveat, jump_ts, rtol, atol, *, solver: str, max_steps: int, args=None,
              progress: str = "none"):
    """The one diffrax call of sixdof, shared by :func:`simulate` and the batch engine (traceable).

    ``solver`` (a key of :data:`SOLVERS`) with PID step control at ``rtol`` and ``atol`` on the (scaled)
    state, stepping onto every time of ``jump_ts`` (:func:`jump_times`), ``max_steps`` at most; with
    ``throw=False``, the caller turns a failed result code into a :class:`~sixdof.errors.SolverError`.
    """
    controller = diffrax.ClipStepSizeController(diffrax.PIDController(rtol=rtol, atol=atol), jump_ts=jump_ts)
    return diffrax.diffeqsolve(
        diffrax.ODETerm(field), SOLVERS[solver](), t0, t1, None, x0, args=args, saveat=saveat,
        stepsize_controller=controller, max_steps=max_steps, throw=False,
        progress_meter=PROGRESS_METERS[progress](),
    )


def loads_of(excitation: Excitation, settings: SimulationSettings) -> tuple[np.ndarray, tuple]:
    """The loads of a solve, its arguments checked: generalized forces (n_loads, 6) [N, N m] and signals."""
    if not isinstance(excitation, Excitation):
        raise InputError("excitation", "an Excitation", excitation)
    if not isinstance(settings, SimulationSettings):
        raise InputError("settings", "a SimulationSettings", settings)
    components = excitation.components()
    return np.array([v for v, _ in components]).reshape(len(components), 6), tuple(s for _, s in components)


def jump_times(excitation: Excitation, t0: float, t1: float) -> tuple[np.ndarray, int]:
    """The excitation's breakpoints [s] inside ``(t0, t1)`` for the step control, padded beyond ``t1`` with
    distinct, never reached times to a power-of-two length >= 8 (few compiled shapes), and their count."""
    jumps = np.array(sorted(b for b in excitation.breakpoints if t0 < b < t1), dtype=float)
    size = max(8, 1 << max(0, jumps.size - 1).bit_length())
    return np.concatenate([jumps, t1 + 1.0 + np.arange(size - jumps.size)]), int(jumps.size)


@partial(jax.jit, static_argnames=("solver", "code", "max_steps", "progress"))
def _solve(p, x0, ts, t0, t1, jump_ts, rtol, atol, *, solver, code, max_steps, progress):
    sigma = p["sigma"]

    def field(t, xs, args):
        return _rates(t, xs * sigma, args, code)[0] / sigma

    sol = solve_ode(field, x0 / sigma, t0, t1, diffrax.SaveAt(ts=ts), jump_ts, rtol, atol, args=p,
                    solver=solver, max_steps=max_steps, progress=progress)
    xs = sol.ys * sigma

    def outputs(t, x):
        rate, Q, ground = _rates(t, x, p, code)
        return rate[6:12], Q, ground

    qdd, Q, ground = jax.vmap(outputs)(ts, xs)
    stats = (sol.stats["num_steps"], sol.stats["num_accepted_steps"], sol.stats["num_rejected_steps"])
    return xs, qdd, Q, ground, sol.result, stats


def _progress_key(progress: Any) -> str:
    if progress is None or progress is False:
        return "none"
    if progress is True:
        return "tqdm" if importlib.util.find_spec("tqdm") else "text"
    if progress in ("text", "tqdm", "none"):
        return progress
    raise InputError("progress", "None, True, 'text' or 'tqdm'", progress)


def simulate(system: System, excitation: Excitation | None, settings: SimulationSettings,
             progress: Any = None) -> TimeHistory:
    """Integrate eq. (1) in time for ``system`` under ``excitation``.

    Parameters
    ----------
    system : sixdof.model.system.System
        Provides ``M``, ``C`` (all damping) and ``K``.
    excitation : Excitation or None
        Loads, ground motion, initial state. ``None``: at rest, nothing happens.
    settings : SimulationSettings
    progress : None, bool, "text" or "tqdm", optional
        Show progress of long runs (diffrax's progress meters; ``True`` picks tqdm when installed).
        Default: silent.

    Returns
    -------
    sixdof.results.TimeHistory
        Absolute motion, the ground's motion when it moves, the loads' generalized force and the
        solver's statistics (``stats``).

    Raises
    ------
    SolverError
        If the solver fails (step limit, step size collapse) or produces non-finite values.

    Warns
    -----
    sixdof.analysis.validity.RangeWarning
        For a load that never acts in the simulated time, and for rotations beyond
        :data:`~sixdof.analysis.validity.SMALL_ANGLE_RAD`.
    """
    if excitation is None:
        excitation = Excitation()
    vectors, signals = loads_of(excitation, settings)
    progress = _progress_key(progress)
    ts = settings.times
    t0, t1 = settings.start, settings.start + settings.duration
    warn_idle(excitation, t0, t1)
    M = np.asarray(system.M, dtype=float)
    ground = excitation.ground
    code = _GROUND_CODES[None if ground is None else ground.quantity]
    r = np.zeros(6) if ground is None else ground.rigid_vector
    sigma = state_scale(system, excitation, settings)

    # Initial state: z = q - r u_g with the ground's displacement at t0 (zero for integrated grounds);
    # q0 includes the equilibrium r u_g(t0), so that at rest no mount is deflected.
    q0, qd0 = excitation.initial_state(system, t0)
    u0 = float(ground.scale * ground.signal(t0)) if code == 1 else 0.0
    x0 = np.concatenate([q0 - r * u0, qd0, [0.0, 0.0]])

    padded, n_jumps = jump_times(excitation, t0, t1)

    params = {
        "Minv": np.linalg.inv(M),
        "C": np.asarray(system.C, dtype=float),
        "K": np.asarray(system.K, dtype=float),
        "r": r,
        "vectors": vectors,
        "signals": signals,
        "ground_signal": None if ground is None else ground.signal,
        "ground_scale": 0.0 if ground is None else ground.scale,
        "sigma": sigma,
    }
    start = time.perf_counter()
    xs, qdd, Q, kin, result, stats = _solve(
        params, x0, ts, t0, t1, padded, settings.rtol, settings.atol,
        solver=settings.solver, code=code, max_steps=settings.max_steps, progress=progress,
    )
    xs = np.asarray(jax.block_until_ready(xs))
    wall = time.perf_counter() - start
    if not bool(result == diffrax.RESULTS.successful):
        raise SolverError(f"direct solve with {settings.solver} (rtol={settings.rtol:g}, atol={settings.atol:g}, "
                          f"max_steps={settings.max_steps}) failed: {diffrax.RESULTS[result]}")
    qdd, Q, kin = np.asarray(qdd), np.asarray(Q), np.asarray(kin)
    bad = np.flatnonzero(~np.all(np.isfinite(xs), axis=1))
    if bad.size or not np.all(np.isfinite(qdd)):
        what = f"values (first at t = {ts[bad[0]]:.6g} s)" if bad.size else "accelerations"
        raise SolverError(f"direct solve with {settings.solver} produced non-finite {what}")
    motion = ("displacement", "velocity", "acceleration")
    ground_motion = {} if ground is None else {f"ground_{m}": np.outer(kin[:, i], r[:3]) for i, m in enumerate(motion)}
    n_steps, n_accepted, n_rejected = (int(s) for s in stats)
    q = xs[:, :6] + np.outer(kin[:, 0], r)
    warn_large_rotations(ts, q)
    return TimeHistory(
        t=ts, q=q, qd=xs[:, 6:12], qdd=qdd, Q=Q, **ground_motion,
        stats=SolverStats(
            solver=settings.solver, rtol=settings.rtol, atol=settings.atol, scale=readonly(sigma),
            num_steps=n_steps, num_accepted=n_accepted, num_rejected=n_rejected,
            max_steps=settings.max_steps, num_jumps=n_jumps, wall_time_s=wall,
        ),
    )


__all__ = ["SOLVERS", "SCALE_FLOOR", "SimulationSettings", "SolverStats",
           "simulate", "state_scale"]
