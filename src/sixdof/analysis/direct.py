"""Direct time integration of eq. (1), ``M q'' + C q' + K q = Q(t)``, with diffrax in float64.

The first-order state is ``x = [z, w, u_g, v_g, f]`` (14 values and one per Maxwell branch state):

- ``z = q - r u_g`` (6): the body's displacement *relative to the ground* [m, rad] — what the
  mounts feel;
- ``w = q'`` (6): the body's *absolute* velocity [m/s, rad/s];
- ``u_g, v_g``: displacement [m] and velocity [m/s] of the ground along its direction, integrated
  here when the ground motion is given as a velocity or an acceleration (otherwise unused);
- ``f``: the force in each Maxwell branch of a visco-elastic mount [N]
  (:attr:`sixdof.model.system.System.branches`: rows ``R``, stiffnesses ``k_b``, relaxation times ``tau_b``);

with ``r`` (6,) the generalized coordinates of a unit rigid translation of the foundation. Then

    z' = w - r v_g,    M w' = Q(t) - C (w - r v_g) - K z - R' f,    f' = k_b R (w - r v_g) - f / tau_b

which needs at most the *first* derivative of a prescribed ground displacement (a table of
displacements is handled exactly; a relative formulation with ``-M r u_g''`` would need Dirac
deltas at every knot). Without ground motion ``z = q`` and it is the plain first-order form.
All damping (mount dashpots, Rayleigh, modal) acts on the motion relative to the ground, since all of
it stands for dissipation in the mounts. It is linear, ``x' = A x + B u(t)`` with the input
``u = [s_1(t) ... s_n(t), v_g or a_g]`` (:func:`first_order_form`).

The solver steps onto every signal breakpoint (``jump_ts``). The state is divided by a per-component
scale (:func:`state_scale`), so that ``rtol`` and ``atol`` hold relative to each component's own
expected size, translations (~1e-4 m) and rotations (~1e-7 rad) alike.

A run proceeds in time windows of at most :data:`WINDOW_SAMPLES` output samples
(:func:`simulate_windows`): the solver's state at the end of a window starts the next one as it is, so
memory stays bounded whatever the duration; :func:`simulate` joins the windows. Explicit Runge-Kutta
methods run with their stages unrolled (:mod:`sixdof.analysis.unrolled`). The traced solve of one
window depends only on the problem's *structure* (solver, signal kinds, numbers of loads, window
samples and breakpoints, ground kind); matrices, signal parameters, times and tolerances are
arguments. It is traced once per process, and with the persistent JAX compilation cache on (the command
line turns it on, :func:`sixdof._jax.enable_compilation_cache`) also serialized with
:mod:`jax.export` beside it: a later process loads it without tracing and without importing diffrax.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib.util
import json
import math
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sixdof._jax import jax, jnp
from sixdof.analysis.records import SolverStats, merge_stats
from sixdof.analysis.validity import warn_idle, warn_large_rotations
from sixdof.errors import (
    InputError,
    Plain,
    SolverError,
    instance,
    integer,
    integer_check,
    memory_check,
    number,
    number_check,
    readonly,
)
from sixdof.excitation import Excitation
from sixdof.frozen import Frozen
from sixdof.model.system import System
from sixdof.progress import Meter, meter
from sixdof.results import TimeHistory, label, result_type, time_concat

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

#: A state component's scale is at least this fraction of the largest, in energy-consistent units
#: (scale times sqrt(M_ii)): DOFs that only couple in through non-proportional damping still get a
#: finite, small tolerance instead of an infinitely tight or a meaningless one.
SCALE_FLOOR = 1e-6

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

_GROUND_CODES = {None: 0, "displacement": 1, "velocity": 2, "acceleration": 3}


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
        Relative tolerance per step. Default 1e-9.
    atol : float, optional
        Absolute tolerance per step *as a fraction of each state component's scale*
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


# ----------------------------------------------------------------------------------------------------
# Tolerance scale.
# ----------------------------------------------------------------------------------------------------


def _tone(signal) -> float:
    """The angular frequency [rad/s] of a harmonic signal (:class:`~sixdof.excitation.Harmonic`); 0 for any
    other (its content reaches down to the modes)."""
    return 2 * np.pi * signal.f_hz if signal.kind == "harmonic" else 0.0


def state_scale(system: System, excitation: Excitation | None, settings: SimulationSettings) -> np.ndarray:
    """Expected size of each state component, used to make tolerances relative per DOF.

    A modal estimate, made before the solve: each load component ``(Q_k, s_k)`` drives mode ``r``
    to about ``|phi_r' Q_k| peak(s_k) / omega_r^2`` (its static modal response), or, for a tone at ``Omega``
    above ``omega_r``, ``|phi_r' Q_k| peak(s_k) / (omega_r Omega)``: the mode is mass-controlled there
    (``1 / Omega^2``), and the switch-on leaves it ringing at ``1 / (omega_r Omega)`` (an unbalance at
    24.7 Hz on modes at 0.1 Hz: 160 times below the static estimate, which let that run's direct solve drift
    to 5.6e-6 of its peak under a 1e-6 tolerance); a ground motion
    with peaks ``U, V, A`` (sampled) drives it to ``|phi_r' M r| min(U, V / omega_r, A / omega_r^2)``
    relative to the ground; an initial state to ``|phi_r' M q0| + |phi_r' M q0'| / omega_r``. Mode
    amplitudes ``eta_r`` map back to DOF ``i`` as ``sum_r |phi_ir| eta_r`` (displacements) and
    ``sum_r |phi_ir| omega_r eta_r`` (velocities). Rigid-body modes use ``omega_r = 2 / duration``.

    The estimate leaves out resonant amplification (up to ``1 / (2 zeta)``), which is the same for
    every DOF that a mode moves: it errs towards tighter tolerances, never looser, and keeps the
    DOFs' relative sizes right, which is what per-DOF accuracy needs; :data:`SCALE_FLOOR` bounds it below.

    A Maxwell branch's force is at most its stiffness times its deformation: ``k_b |R_b| z``.

    Returns
    -------
    ndarray, shape (14 + nb,)
        ``[z (6) m, rad; w (6) m/s, rad/s; u_g m; v_g m/s; f (nb) N]``, all > 0.
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
            eta += np.abs(phi.T @ vector) * signal.peak / (omega * np.maximum(omega, _tone(signal)))
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
    branches = system.branches
    if not np.any(np.concatenate([z, w]) > 0):
        return np.ones(14 + branches.count)

    def floored(x):
        floor = SCALE_FLOOR * np.max(x * root_m)
        return np.maximum(x, floor / root_m) if floor > 0 else np.where(x > 0, x, 1.0)

    z, w = floored(z), floored(w)
    return np.concatenate([z, w, [ground_u, ground_v], branches.stiffness * (np.abs(branches.rows) @ z)])


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
# The first-order form and the traced solve of one window.
# ----------------------------------------------------------------------------------------------------


def mechanical_form(Minv, K, C, rows, k_b, tau) -> np.ndarray:
    """``A`` (..., 12 + nb, 12 + nb) of ``x' = A x`` for the state ``x = [z, w, f]`` without ground motion:
    ``z' = w``, ``M w' = -K z - C w - R' f``, ``f' = k_b R w - f / tau`` (:attr:`System.branches`).

    Broadcasts over leading dimensions (a batch of variants: :func:`sixdof.analysis.batch.run_batch`).

    Parameters
    ----------
    Minv : array_like, shape (6, 6)
        Inverse mass matrix [1/kg, 1/(kg m^2)].
    K, C : array_like, shape (..., 6, 6)
        Stiffness and damping [N/m, ...; N s/m, ...].
    rows : array_like, shape (..., nb, 6)
        Each branch state's deformation per unit ``q`` [m/m, m/rad].
    k_b : array_like, shape (..., nb)
        Branch stiffnesses [N/m].
    tau : array_like, shape (nb,)
        Relaxation times [s].
    """
    K, C, rows, k_b = (np.asarray(a, dtype=float) for a in (K, C, rows, k_b))
    tau = np.asarray(tau, dtype=float)
    nb = tau.size
    batch = np.broadcast_shapes(K.shape[:-2], C.shape[:-2], rows.shape[:-2], k_b.shape[:-1])
    A = np.zeros(batch + (12 + nb, 12 + nb))
    A[..., :6, 6:12] = np.eye(6)
    A[..., 6:12, :6] = -Minv @ K
    A[..., 6:12, 6:12] = -Minv @ C
    A[..., 6:12, 12:] = -Minv @ np.swapaxes(rows, -1, -2)
    A[..., 12:, 6:12] = k_b[..., None] * rows
    A[..., 12:, 12:] = np.diag(-1.0 / tau)
    return A


def first_order_form(system: System, excitation: Excitation) -> tuple[np.ndarray, np.ndarray]:
    """``A`` (N, N) and ``B`` (N, n_loads + 1) of ``x' = A x + B u(t)`` for the state ``x = [z, w, u_g, v_g, f]``
    (``N = 14 + nb``, ``nb`` Maxwell branch states).

    The input is ``u = [s_1(t) ... s_n(t), g(t)]``: the load signals, then the ground's velocity ``v_g``
    (ground given as a displacement or a velocity) or acceleration ``a_g`` (given as an acceleration,
    whose velocity is then the state ``v_g``); ``g = 0`` without ground motion.
    """
    vectors, _ = _load_vectors(excitation)
    n = vectors.shape[0]
    Minv = np.linalg.inv(np.asarray(system.M, dtype=float))
    C, K = np.asarray(system.C, dtype=float), np.asarray(system.K, dtype=float)
    branches = system.branches
    R, k_b = branches.rows, branches.stiffness
    size = 14 + branches.count
    A = np.zeros((size, size))
    mechanical = np.r_[0:12, 14:size]  # z, w and f; u_g, v_g (12, 13) between
    A[np.ix_(mechanical, mechanical)] = mechanical_form(Minv, K, C, R, k_b, branches.tau)
    B = np.zeros((size, n + 1))
    B[6:12, :n] = Minv @ vectors.T
    ground = excitation.ground
    if ground is not None:
        # The ground's velocity v_g enters z' = w - r v_g, the dashpots' force -C (w - r v_g) and the
        # branches' f' = k_b R (w - r v_g) - f / tau.
        r = ground.rigid_vector
        by_velocity = np.concatenate([-r, Minv @ C @ r, [0.0, 0.0], -k_b * (R @ r)])
        if ground.quantity == "acceleration":
            A[:, 13] += by_velocity
            A[12, 13] = 1.0  # u_g' = v_g
            B[13, n] = 1.0  # v_g' = a_g
        else:
            B[:, n] = by_velocity
            if ground.quantity == "velocity":
                B[12, n] = 1.0  # u_g' = v_g
    return A, B


def _ground_kinematics(code: int, p, t, g):
    """Ground displacement, velocity and acceleration along its direction at ``t`` (``g``: the state's ``u_g, v_g``)."""
    signal, scale = p["ground_signal"], p["ground_scale"]
    if code == 0:
        zero = jnp.zeros_like(t)
        return zero, zero, zero
    if code == 1:
        return scale * signal(t), scale * signal.derivative(t), scale * signal.derivative(t, 2)
    if code == 2:
        return g[0], scale * signal(t), scale * signal.derivative(t)
    return g[0], g[1], scale * signal(t)


def _input(t, g, p, code: int):
    """The input ``u(t)`` of :func:`first_order_form` (``g``: the state's ``u_g, v_g``)."""
    _, v_g, a_g = _ground_kinematics(code, p, t, g)
    return jnp.stack([*(signal(t) for signal in p["signals"]), a_g if code == 3 else v_g])


def solve_ode(field, x0, t0, t1, saveat, jump_ts, rtol, atol, *, solver: str, max_steps: int, args=None, event=None,
              dtmax=None):
    """The one diffrax call of sixdof, shared by :func:`simulate_windows` and the batch engine (traceable).

    ``solver`` (a key of :data:`SOLVERS`; explicit methods with unrolled stages,
    :mod:`sixdof.analysis.unrolled`) with PID step control at ``rtol`` and ``atol`` on the (scaled)
    state, stepping onto every time of ``jump_ts`` (:func:`jump_times`), ``max_steps`` at most; with
    ``throw=False``, the caller turns a failed result code into a :class:`~sixdof.errors.SolverError`.
    """
    import diffrax

    from sixdof.analysis import unrolled

    controller = diffrax.PIDController(rtol=rtol, atol=atol, dtmax=dtmax)
    # No breakpoints (``jump_ts`` of length 0, a static shape): no clipping traced. Clipping makes every step
    # check the jumps and redo its first stage after one; without it the bridge traffic solve (no breakpoints)
    # traces, lowers and compiles in 0.65 instead of 0.85 s, for the same steps and values.
    if jump_ts.shape[0]:
        controller = diffrax.ClipStepSizeController(controller, jump_ts=jump_ts)
    return diffrax.diffeqsolve(
        diffrax.ODETerm(field), unrolled.solver(solver), t0, t1, None, x0, args=args, saveat=saveat,
        stepsize_controller=controller, max_steps=max_steps, throw=False, event=event,
        # Never differentiated in reverse mode: diffrax's default adjoint traces a checkpointed loop for it, which
        # made the first (cold) solve 0.25-0.3 s longer to trace and compile, for the same steps and results.
        adjoint=diffrax.ForwardMode(),
    )


def _solve_window(p, xs0, ts, t0, t1, jump_ts, rtol, atol, *, solver: str, code: int, max_steps: int):
    """One window from ``t0`` to ``t1``, saved at ``ts`` (traced): scaled end state, states and outputs at ``ts``."""
    import diffrax

    A, B, sigma = p["A"], p["B"], p["sigma"]
    # On the scaled state xs = x / sigma the field is one product [A_s | B_s] [xs; u(t)] (A and B scaled
    # once): a single dot per stage, which XLA runs fastest on the CPU (measured against A_s xs + B_s u).
    AB = jnp.concatenate([A * sigma[None, :], B], axis=1) / sigma[:, None]

    def field(t, xs, AB):
        return AB @ jnp.concatenate([xs, _input(t, xs[12:14] * sigma[12:14], p, code)])

    sol = solve_ode(field, xs0, t0, t1, diffrax.SaveAt(ts=ts), jump_ts, rtol, atol, args=AB,
                    solver=solver, max_steps=max_steps)
    xs = sol.ys * sigma

    def outputs(t, x):
        u = _input(t, x[12:14], p, code)
        return (A @ x + B @ u)[6:12], p["vectors"].T @ u[:-1], jnp.stack(_ground_kinematics(code, p, t, x[12:14]))

    qdd, Q, ground = jax.vmap(outputs)(ts, xs)
    stats = jnp.stack([sol.stats["num_steps"], sol.stats["num_accepted_steps"], sol.stats["num_rejected_steps"]])
    # The result as its integer code (a pytree leaf), so that the compiled solve returns plain arrays.
    result = jax.tree.leaves(sol.result)[0]
    return sol.ys[-1], xs, qdd, Q, ground, sol.result == diffrax.RESULTS.successful, result, stats


def _solve_segment(p, xs0, ts, t0, t1, jump_ts, rtol, atol, region, *, solver: str, code: int, max_steps: int):
    """A window's solve with nonlinear mounts, from ``t0`` until ``t1`` or the first change of region (traced).

    Inside the regions ``region`` (ne,) of the force laws the motion is linear: the field is ``A x + B u`` with
    each law's slope and intercept there in place of its tangent at rest. Leaving a region is an event,
    root-found on the step's dense output; the caller restarts from it in the next region. Two more states
    integrate the work done on the body and the energy dissipated (:func:`sixdof.analysis.contact.energy_balance`).
    Returns what :func:`_solve_window` does, with the work and dissipation at ``ts``, the time the segment
    ended, whether an event ended it and which boundary (ne, 2: below, above).
    """
    import diffrax

    A, B, sigma = p["A"], p["B"], p["sigma"]
    laws = p["laws"]
    rows, knots = laws["rows"], laws["knots"]
    size = A.shape[0]
    pick = jax.vmap(lambda table, i: table[i])
    slope, intercept = pick(laws["slope"], region), pick(laws["intercept"], region)
    # In the region: r = a + s (d_s + L z), written as its tangent at rest (already in K) plus a correction.
    dK = rows.T @ ((slope - laws["tangent"])[:, None] * rows)
    f0 = rows.T @ (intercept + slope * laws["static"] - laws["force"])
    Minv = p["Minv"]
    A = A.at[6:12, :6].add(-Minv @ dK)
    c = jnp.zeros(size).at[6:12].set(-Minv @ f0)
    # The dashpots of mounts lifted off are off: C_off z', z' = w - r v_g, no longer resists the motion.
    C_off = rows.T @ (((1.0 - pick(laws["contact"], region)) * laws["damping"])[:, None] * rows)
    # So are the Maxwell branches of a lifted mount: they carry nothing and relax, f' = -f / tau.
    lifts = laws["lifts"]
    lifted = lifts & (region == laws["lifted_region"])
    off = laws["branches"].T @ lifted.astype(A.dtype)
    big = 1e30
    padded = jnp.concatenate([jnp.full((knots.shape[0], 1), -jnp.inf), knots, jnp.full((knots.shape[0], 1), jnp.inf)],
                             axis=1)
    low, high = (jnp.clip(pick(padded, region + shift), -big, big) for shift in (0, 1))
    scale = jnp.concatenate([sigma, p["energy_scale"]])
    C, K, R, k_b, tau = p["C"], p["K"], p["R"], p["k_b"], p["tau"]
    r = p["r"]

    def motion(t, x):
        """``x'`` in the region, and the input ``u``."""
        u = _input(t, x[12:14], p, code)
        dx = A @ x + B @ u + c
        zd, f = dx[:6], x[14:]
        dx = dx.at[6:12].add(Minv @ (C_off @ zd + R.T @ (off * f)))
        return dx.at[14:].add(-off * k_b * (R @ zd)), u

    def field(t, ys, args):
        x = ys[:size] * sigma
        dx, u = motion(t, x)
        z, w, f = x[:6], x[6:12], x[14:]
        zd = dx[:6]
        v_g = _ground_kinematics(code, p, t, x[12:14])[1]
        # The generalized force of the mounts on the foundation.
        mounts = K @ z + dK @ z + f0 + (C - C_off) @ zd + R.T @ ((1.0 - off) * f)
        power = p["vectors"].T @ u[:-1] @ w - v_g * (r @ mounts)  # the ground moves against the mounts' force
        loss = zd @ (C - C_off) @ zd + jnp.sum(f * f / (k_b * tau))
        return jnp.concatenate([dx, jnp.stack([power, loss])]) / scale

    # Distances to the region's knots, below and above (ne, 2), over each axis's deflection scale: the event is the
    # nearest reaching zero (one continuous function, which bisection brackets on the step's dense output). A mount
    # that lifts off leaves contact where its whole load F = r(d) + c d' + f_b would pull (F / k_max, a deflection,
    # reaching zero), and touches again where d < 0 and F < 0 both hold.
    delta, length = laws["hysteresis"], laws["hysteresis"] / REGION_HYSTERESIS

    def distances(t, y):
        x = y[:size] * sigma
        d = laws["static"] + rows @ x[:6]
        rate = rows @ (x[6:12] - r * _ground_kinematics(code, p, t, x[12:14])[1])
        at = jnp.sum(knots < d[:, None], axis=1)  # the region of d alone, lifted or not
        load = pick(laws["intercept"], at) + pick(laws["slope"], at) * d + laws["damping"] * rate
        e = (load + laws["branches"] @ x[14:]) / laws["stiffness_scale"]
        below = jnp.where(lifted, jnp.maximum(d - low, e), d - low)
        above = jnp.where(lifts & ~lifted, jnp.minimum(high - d, -e), high - d)
        return jnp.stack([below + delta, above + delta], axis=1) / length[:, None]

    event = diffrax.Event(lambda t, y, args, **kw: jnp.min(distances(t, y)), direction=False,
                          root_finder=_event_bisection())
    # An event is a sign change between steps: capped steps see every excursion past a knot that lasts two steps.
    sol = solve_ode(field, xs0, t0, t1, diffrax.SaveAt(ts=ts, t1=True), jump_ts, rtol, atol, args=None,
                    solver=solver, max_steps=max_steps, event=event, dtmax=p["dtmax"])
    # The state where the segment ended is saved after the samples before it (those after it are inf).
    last = jnp.sum(jnp.isfinite(sol.ts)) - 1
    ys = jnp.where(jnp.arange(ts.size)[:, None] < last, sol.ys[:-1], sol.ys[last])
    xs = ys[:, :size] * sigma

    def outputs(t, x):
        dx, u = motion(t, x)
        return dx[6:12], p["vectors"].T @ u[:-1], jnp.stack(_ground_kinematics(code, p, t, x[12:14]))

    qdd, Q, ground = jax.vmap(outputs)(ts, xs)
    energy = ys[:, size:] * p["energy_scale"]
    stats = jnp.stack([sol.stats["num_steps"], sol.stats["num_accepted_steps"], sol.stats["num_rejected_steps"]])
    at_end = distances(sol.ts[last], sol.ys[last])
    crossed = (sol.result == diffrax.RESULTS.event_occurred) & (at_end == jnp.min(at_end))
    ok = (sol.result == diffrax.RESULTS.successful) | (sol.result == diffrax.RESULTS.event_occurred)
    result = jax.tree.leaves(sol.result)[0]
    return sol.ys[last], xs, qdd, Q, ground, ok, result, stats, energy, sol.ts[last], crossed


def _event_bisection():
    """The root finder of the events: bisection that stops once the time is bracketed to its tolerance.

    The distances of :func:`_solve_segment` fall through zero at every event (``flip=True``), so it needs no check
    that they change sign within the step, nor that they are near zero where it stops: a ground velocity that jumps
    at a breakpoint (a kinked displacement, a table) makes a lift-off mount's dashpot load jump between one step's
    end (just before the breakpoint) and the next one's start (just after). That next step is then past the event
    at both ends, its value there is not small, and the root is its start.
    """
    import optimistix as optx

    class EventBisection(optx.Bisection):
        def terminate(self, fn, y, args, options, state, tags):
            return jnp.abs(state.lower - state.upper) < self.atol + self.rtol * jnp.abs(y), optx.RESULTS.successful

    return EventBisection(rtol=1e-12, atol=1e-12, flip=True)


def _failure(result) -> str:
    """diffrax's message for a result code returned by :func:`_solve_window`."""
    import diffrax

    item = jax.tree.unflatten(jax.tree.structure(diffrax.RESULTS.successful), [np.asarray(result)])
    return diffrax.RESULTS[item]


# ----------------------------------------------------------------------------------------------------
# The compiled solve of a window, per problem structure: traced once per process, exported across them.
# ----------------------------------------------------------------------------------------------------

#: Compiled window solves of this process, by structure key.
_COMPILED: dict[str, Callable] = {}

#: The files whose code the traced solve runs: a change to any of them makes exported solves stale.
_TRACED_SOURCES = ("analysis/direct.py", "analysis/unrolled.py", "excitation/signals.py")


def _export_dir() -> Path | None:
    """Folder of the exported solves, or ``None`` when they are not kept.

    They are kept beside the persistent JAX compilation cache, when that is on (it holds the compiled code
    they need), when equinox's runtime checks compile to NaNs (``EQX_ON_ERROR=nan`` or ``off``, as the
    command line sets: the default checks are host callbacks, which cannot be exported) and when
    flatbuffers, which :mod:`jax.export` writes with, is installed.
    """
    cache = jax.config.jax_compilation_cache_dir
    if not cache or os.environ.get("EQX_ON_ERROR") not in ("nan", "off") or not importlib.util.find_spec("flatbuffers"):
        return None
    return Path(cache) / "sixdof_solves"


def _installed(module: str) -> str:
    """Where ``module`` is installed and when, without importing it (part of the structure key)."""
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return "absent"
    stat = os.stat(spec.origin)
    return f"{spec.origin}:{stat.st_mtime_ns}:{stat.st_size}"


def _structure_key(treedef, specs, statics: dict) -> str:
    """Everything the traced solve depends on besides its arguments' values."""
    package = Path(__file__).resolve().parent.parent
    sources = hashlib.sha256(b"".join((package / name).read_bytes() for name in _TRACED_SOURCES)).hexdigest()
    return json.dumps({
        "statics": statics, "treedef": str(treedef), "arguments": [f"{s.dtype}{list(s.shape)}" for s in specs],
        "sources": sources, "jax": jax.__version__, "backend": jax.default_backend(),
        "x64": bool(jax.config.jax_enable_x64), "eqx_on_error": os.environ.get("EQX_ON_ERROR", "raise"),
        "diffrax": _installed("diffrax"), "equinox": _installed("equinox"),
    }, sort_keys=True)


def _load_exported(path: Path, key: str, specs) -> Callable | None:
    """The exported solve stored at ``path`` for ``key``, compiled; ``None`` when it is absent, for another
    key, damaged or unusable (then the solve is traced anew)."""
    try:
        header, payload = path.read_bytes().split(b"\n", 1)
        meta = json.loads(header)
        if meta["key"] != key or meta["sha256"] != hashlib.sha256(payload).hexdigest():
            return None
        exported = jax.export.deserialize(bytearray(payload))
        if [(a.shape, a.dtype) for a in exported.in_avals] != [(s.shape, s.dtype) for s in specs]:
            return None
        solve = jax.jit(exported.call)
        solve.lower(*specs)  # what can fail before a call fails here
        return solve
    except Exception:  # noqa: BLE001 - a cache entry of any damage is ignored; the solve is traced instead
        return None


def _save_exported(path: Path, key: str, traced, specs) -> Callable:
    """Export ``traced`` and store it for ``key`` (atomically); the exported solve, or ``traced`` when it cannot
    be exported (the cache is then left alone: a run never fails for its cache)."""
    try:
        exported = jax.export.export(traced)(*specs)
        payload = bytes(exported.serialize())
    except Exception:  # noqa: BLE001 - e.g. host callbacks after all: compile it without exporting
        return traced
    header = json.dumps({"key": key, "sha256": hashlib.sha256(payload).hexdigest()}).encode()
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary.write_bytes(header + b"\n" + payload)
        os.replace(temporary, path)
    except OSError:
        temporary.unlink(missing_ok=True)
    return jax.jit(exported.call)


def _compiled_window(args: tuple, *, solver: str, code: int, max_steps: int, nonlinear: bool = False) -> Callable:
    """The jitted :func:`_solve_window` for the structure of ``args``, called with ``jax.tree.leaves(args)`` (a
    jitted function, not an ahead-of-time compiled one: its calls take JAX's fast path, ~1 ms less each)."""
    leaves, treedef = jax.tree.flatten(args)
    specs = [jax.ShapeDtypeStruct(np.shape(leaf), np.asarray(leaf).dtype) for leaf in leaves]
    statics = {"solver": solver, "code": code, "max_steps": max_steps}
    traced = _solve_segment if nonlinear else _solve_window
    key = _structure_key(treedef, specs, {**statics, "nonlinear": nonlinear})
    compiled = _COMPILED.get(key)
    if compiled is not None:
        return compiled
    folder = _export_dir()
    path = None if folder is None else folder / f"{hashlib.sha256(key.encode()).hexdigest()[:32]}.jaxexport"
    compiled = None if path is None else _load_exported(path, key, specs)
    if compiled is None:

        def _solve(*leaves):
            return traced(*jax.tree.unflatten(treedef, leaves), **statics)

        compiled = jax.jit(_solve)  # compiled at its first call
        if path is not None:
            compiled = _save_exported(path, key, compiled, specs)
    _COMPILED[key] = compiled
    return compiled


# ----------------------------------------------------------------------------------------------------
# Windows of a run.
# ----------------------------------------------------------------------------------------------------


def _load_vectors(excitation: Excitation) -> tuple[np.ndarray, tuple]:
    components = excitation.components()
    return np.array([v for v, _ in components]).reshape(len(components), 6), tuple(s for _, s in components)


def loads_of(excitation: Excitation, settings: SimulationSettings) -> tuple[np.ndarray, tuple]:
    """The loads of a solve, its arguments checked: generalized forces (n_loads, 6) [N, N m] and signals."""
    instance(excitation, "excitation", Excitation)
    instance(settings, "settings", SimulationSettings)
    return _load_vectors(excitation)


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


def _arguments(system: System, excitation: Excitation | None, settings: SimulationSettings) -> Excitation:
    """The excitation of a solve (``None``: none), once each argument is checked to be of its kind: so that
    ``simulate(excitation, system, settings)`` is one clear error, not an AttributeError from inside."""
    instance(system, "system", System)
    instance(settings, "settings", SimulationSettings)
    excitation = instance(excitation, "excitation", Excitation, None)
    return Excitation() if excitation is None else excitation


def jump_times(excitation: Excitation, t0: float, t1: float) -> tuple[np.ndarray, int]:
    """The excitation's breakpoints [s] inside ``(t0, t1)`` for the step control, padded beyond ``t1`` with
    distinct, never reached times to a power-of-two length >= 8 (few compiled shapes), none if there are none
    (:func:`solve_ode` then traces no clipping), and their count."""
    jumps = np.array(sorted(b for b in excitation.breakpoints if t0 < b < t1), dtype=float)
    return _padded(jumps, t1, _jump_slots(jumps.size)), int(jumps.size)


def _jump_slots(count: int) -> int:
    return 0 if count == 0 else max(8, 1 << (count - 1).bit_length())


def _inside(breakpoints: np.ndarray, t0: float, t1: float) -> slice:
    """The sorted ``breakpoints`` strictly inside ``(t0, t1)``: those the step control must step onto."""
    return slice(int(np.searchsorted(breakpoints, t0, "right")), int(np.searchsorted(breakpoints, t1, "left")))


def _padded(jumps: np.ndarray, t1: float, size: int) -> np.ndarray:
    return np.concatenate([jumps, t1 + 1.0 + np.arange(size - jumps.size)])


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
    x0 = np.concatenate([q0 - r * u0, qd0, [0.0, 0.0], excitation.initial_branch_forces(system)])

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
                code), xs0


def is_nonlinear(system: System) -> bool:
    """Whether a mount of ``system`` has a kink in its force law (a bump stop, lift-off or a table that is not
    linear): then only the direct solve answers it exactly."""
    return bool(np.isfinite(system.nonlinear.knots).any())


#: Hysteresis of a change of region, relative to the deflection scale of the axis: after an event the solver
#: restarts exactly on the knot, and must not see that knot again before it has moved away from it.
REGION_HYSTERESIS = 1e-10


def _nonlinear_params(system: System, excitation: Excitation, sigma: np.ndarray, settings: SimulationSettings) -> dict:
    """The arrays :func:`_solve_segment` needs besides the linear solve's."""
    laws, branches = system.nonlinear, system.branches
    M = np.asarray(system.M, dtype=float)
    ground = excitation.ground
    scale_d = np.abs(laws.rows) @ sigma[:6]
    energy = 0.5 * float(np.sum(np.diag(M) * sigma[6:12] ** 2))
    return {"laws": {"rows": laws.rows, "knots": laws.knots, "slope": laws.slope, "intercept": laws.intercept,
                     "static": laws.static_deflection, "force": laws.static_force, "tangent": laws.tangent,
                     "hysteresis": REGION_HYSTERESIS * scale_d, "contact": laws.contact, "damping": laws.damping,
                     "lifts": laws.lifts, "lifted_region": laws.lifted_region, "stiffness_scale": laws.stiffness_scale,
                     "branches": laws.branch_map(branches.mount, branches.axis)},
            "Minv": np.linalg.inv(M), "C": np.asarray(system.C, dtype=float),
            "K": np.asarray(system.K, dtype=float), "R": branches.rows.reshape(-1, 6),
            "k_b": branches.stiffness, "tau": branches.tau,
            "r": np.zeros(6) if ground is None else ground.rigid_vector, "energy_scale": np.full(2, energy),
            "dtmax": np.float64(settings.min_contact_s / 2)}


def _window_args(params, xs0, ts, t0, t1, jumps, settings, region=None) -> tuple:
    """The arguments of :func:`_solve_window` (with ``region``: of :func:`_solve_segment`), as float64 arrays."""
    scalars = (np.float64(t0), np.float64(t1))
    args = (params, np.asarray(xs0), ts, *scalars, jumps, np.float64(settings.rtol), np.float64(settings.atol))
    return args if region is None else (*args, np.asarray(region, dtype=np.int64))


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
        maxwell_force=x[:, 14:] if x.shape[1] > 14 else None, contacts=extra.get("contacts"),
        stats=SolverStats(
            solver=settings.solver, rtol=settings.rtol, atol=settings.atol, scale=readonly(run.sigma),
            num_steps=n_steps, num_accepted=n_accepted, num_rejected=n_rejected,
            # A breakpoint at the window's start was stepped onto as the previous window's end: counted here.
            max_steps=settings.max_steps, num_jumps=int(inside.stop - np.searchsorted(run.breakpoints, ts[0])),
            wall_time_s=wall, num_events=extra["contacts"].count if extra else 0,
        ),
    )
    return history, np.asarray(xs_end), region


#: Consecutive events a window may have without the solve moving on (a contact chattering on a knot).
MAX_STALLED_EVENTS = 100


def _segments(run: _Run, xs0: np.ndarray, region: np.ndarray, saves: np.ndarray, end: float, jumps: np.ndarray,
              settings: SimulationSettings):
    """A window with nonlinear mounts: solved region by region (:func:`_solve_segment`), each from the event
    that ended the previous one. Returns what the linear window solve does, and the work, dissipation and
    :class:`~sixdof.analysis.contact.ContactEvents` of the window, and the regions at its end."""
    from sixdof.analysis.contact import ContactEvents

    laws = run.laws
    size = run.sigma.size
    t0 = float(saves[0])
    x = qdd = Q = kin = energy = None
    steps = np.zeros(3, dtype=np.int64)
    events, stalled = [], 0
    xs = xs0
    while True:
        args = _window_args(run.params, xs, np.clip(saves, t0, end), t0, end, jumps, settings, region)
        xs_end, xs_t, qdd_t, Q_t, kin_t, ok, result, steps_t, energy_t, t_end, crossed = (
            np.asarray(a) for a in run.solve(*jax.tree.leaves(args)))
        steps += steps_t
        if not ok:
            return xs_end, xs_t, qdd_t, Q_t, kin_t, ok, result, steps, {}, region
        # The samples of this segment: from its start (the window's first sample only in its first segment).
        mine = ((saves >= t0) if x is None else (saves > t0)) & (saves <= t_end)
        if x is None:
            x, qdd, Q, kin, energy = (np.array(a) for a in (xs_t, qdd_t, Q_t, kin_t, energy_t))
        for whole, part in ((x, xs_t), (qdd, qdd_t), (Q, Q_t), (kin, kin_t), (energy, energy_t)):
            whole[mine] = part[mine]
        if not crossed.any():
            break
        stalled = stalled + 1 if t_end <= t0 + 1e-12 * max(1.0, abs(t0)) else 0
        if stalled > MAX_STALLED_EVENTS:
            raise SolverError(f"direct solve: the contact of {laws.names[int(np.argmax(crossed.any(axis=1)))]} "
                              f"chatters at t = {t_end:.9g} s ({MAX_STALLED_EVENTS} changes of state without "
                              "moving on); give the stop damping or a softer contact stiffness")
        x_end = xs_end[:size] * run.sigma
        new = _next_region(run, float(t_end), x_end, region, crossed)
        for e in np.flatnonzero(new != region):
            events.append((float(t_end), int(e), int(region[e]), int(new[e])))
        d = laws.static_deflection + laws.rows @ x_end[:6]
        xs_end = xs_end.copy()
        xs_end[size + 1] += _released(laws, d, region, new) / run.params["energy_scale"][1]
        xs, t0, region = xs_end, float(t_end), new
    events = np.array(events, dtype=float).reshape(-1, 4)
    contacts = ContactEvents(names=laws.names, static_region=laws.static_region, t=readonly(events[:, 0]),
                             law=readonly(events[:, 1], np.int64), region_from=readonly(events[:, 2], np.int64),
                             region_to=readonly(events[:, 3], np.int64))
    extra = {"energy_input": energy[:, 0], "energy_dissipated": energy[:, 1], "contacts": contacts}
    return xs_end, x, qdd, Q, kin, True, result, steps, extra, region


def _ground_velocity(params: dict, code: int, t: float, x: np.ndarray) -> float:
    """The ground's velocity along its direction [m/s] at ``t`` and state ``x`` (:func:`_ground_kinematics`'s)."""
    if code in (1, 2):
        signal = params["ground_signal"]
        value = signal.derivative(np.float64(t)) if code == 1 else signal(np.float64(t))
        return float(params["ground_scale"] * np.asarray(value))
    return float(x[13]) if code == 3 else 0.0


def _law_motion(laws, params: dict, code: int, r: np.ndarray, t: float, x: np.ndarray):
    """Each force law's deflection [m], its rate [m/s] (from the relative velocity ``z' = w - r v_g``) and the force
    of its Maxwell branches [N] at time ``t`` and state ``x``."""
    d = laws.static_deflection + laws.rows @ x[:6]
    rate = laws.rows @ (x[6:12] - r * _ground_velocity(params, code, t, x))
    return d, rate, params["laws"]["branches"] @ x[14:]


def _next_region(run: _Run, t: float, x: np.ndarray, region: np.ndarray, crossed: np.ndarray) -> np.ndarray:
    """The force laws' regions after an event at time ``t`` and state ``x``: the triggered axis moves across its
    knot (``crossed`` (ne, 2): below, above), and every axis sitting on a knot goes where it is moving. A mount
    that lifts off, lifted, stays so until its event; in contact, it lifts off where its load reached zero first."""
    laws, p = run.laws, run.params
    d, rate, branch = _law_motion(laws, p, run.code, run.r, t, x)
    ahead = laws.region(d + np.sign(rate) * p["laws"]["hysteresis"])
    new = np.where(crossed[:, 0], region - 1, np.where(crossed[:, 1], region + 1, ahead))
    lifted = laws.lifts & (region == laws.lifted_region)
    high = np.take_along_axis(np.concatenate([laws.knots, np.full((laws.count, 1), np.inf)], axis=1),
                              region[:, None], axis=1)[:, 0]
    load = laws.trial_force(d, rate, branch) / laws.stiffness_scale
    lifts_off = laws.lifts & ~lifted & crossed[:, 1] & (-load <= high - d)
    new = np.where(lifted, np.where(crossed[:, 0], np.minimum(laws.region(d), laws.lifted_region - 1), region),
                   np.where(lifts_off, laws.lifted_region, new))
    return np.clip(new, 0, laws.knots.shape[1]).astype(np.int64)


def _released(laws, d: np.ndarray, before: np.ndarray, after: np.ndarray) -> float:
    """The energy a change of region from ``before`` to ``after`` at deflections ``d`` [m] takes out of the mounts
    [J]: a mount lifting off while compressed (its dashpot pulled first) lets go of its spring's energy, which its
    free relaxation dissipates; touching again while compressed takes it back."""
    return float(np.sum(laws.potential(d) * (laws.contact[np.arange(laws.count), before]
                                             - laws.contact[np.arange(laws.count), after])))


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


# ----------------------------------------------------------------------------------------------------
# The whole run.
# ----------------------------------------------------------------------------------------------------


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
        from sixdof.analysis.contact import merge_events

        contacts["contacts"] = merge_events([w.contacts for w in windows])
    return time_concat(windows, stats=merge_stats([w.stats for w in windows]), **contacts)


__all__ = ["SOLVERS", "SCALE_FLOOR", "WINDOW_SAMPLES", "SimulationSettings", "SolverStats", "first_order_form",
           "merge_stats", "simulate", "simulate_windows", "state_scale", "window_length", "CYCLES_PER_TOLERANCE",
           "cycle_scaled"]
