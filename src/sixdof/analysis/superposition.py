"""Modal superposition in time: an exact linear engine that cross-checks every direct solve.

The response of ``M q'' + C q' + K q = Q(t)`` is computed in modal coordinates, with no ODE solver:

1. the undamped modes ``Phi`` (mass-normalized, :func:`sixdof.analysis.modal.modal_analysis`) transform the
   equations to ``eta'' + D eta' + Omega^2 eta = Phi' Q(t)`` with ``D = Phi' C Phi``;
2. when ``D`` is diagonal (classical damping: Rayleigh, modal ratios, any C the real modes
   diagonalize) each mode is a single-degree-of-freedom oscillator (method ``"real"``); otherwise
   (mount dashpots) the coupled modes are solved through the complex modes of the first-order system
   ``y' = [[0, I], [-Omega^2, -D]] y + [0, Phi' Q]`` (method ``"complex"``), exact for any viscous C;
3. both give first-order coordinates ``z' = lambda z + f(t)`` (a complex mode, one per conjugate pair;
   an oscillator damped near or beyond critical, or a rigid-body mode, as a chain of two,
   ``u' = lambda_1 u + f``, ``x' = lambda_2 x + u``, exact where its modes cannot be told apart),
   each advanced over every output interval by its exact transition
   ``z_{k+1} = e^{lambda h} z_k + d_k``, ``d_k = int_{t_k}^{t_{k+1}} e^{lambda (t_{k+1} - s)} f(s) ds``.
   The recursion runs on the output intervals (blocked: a matrix product within blocks of steps, a
   doubling scan across them); the excitation's
   breakpoints (where a signal or a derivative jumps) split only the Gauss-Legendre quadrature of
   ``d_k``, never the recursion. On a uniform grid every interval without a breakpoint shares one
   kernel, so their increments are one matrix product with the signals' values on the nodes;
4. modes may be truncated (by count or frequency) with a static residual-flexibility correction for
   the modes left out.

The input side (:class:`Drive`: the excitation's signals on the quadrature nodes of a time grid) is
separate from the system side (the poles and maps of :func:`_modal_coordinates`), so that many systems
can run on one drive; and a run continues exactly from where another ended (``start``, a
:class:`SuperpositionState` carrying the modal coordinates and the ground's integrals), window after
window, without the direct solve's state.

:func:`compare` measures the agreement of two time histories DOF by DOF.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache, partial

import numpy as np

from sixdof._jax import jax
from sixdof.analysis.compare import compare
from sixdof.analysis.records import SuperpositionInfo, SuperpositionState
from sixdof.analysis.statespace import CLASSICAL_RTOL, complex_modes, modal_basis
from sixdof.analysis.statespace import coupling as coupling_of
from sixdof.analysis.validity import warn_idle, warn_large_rotations
from sixdof.errors import (
    InputError,
    SolverError,
    finite_array,
    handed_over,
    increasing_times,
    instance,
    integer,
    number,
    readonly,
)
from sixdof.excitation import Excitation
from sixdof.model.modes import modal_analysis
from sixdof.model.system import System
from sixdof.results import TimeHistory

METHODS = ("auto", "real", "complex")

# Gauss-Legendre with n nodes on a piece of length l integrates f with the error
#     l^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^3) f^(2n)(xi)                      (Abramowitz & Stegun 25.4.30).
# An increment's integrand e^{lambda (t_{k+1} - s)} g(s), with g carrying circular frequencies up to
# omega, has |f^(2n)| <= (|lambda| + omega)^(2n) max|f|: relative to l max|f| the error is at most
#     (n!)^4 / ((2n+1) ((2n)!)^3) theta^(2n),    theta = (|lambda| + omega) l.
# The running integral of a ground velocity or acceleration integrates the polynomial interpolating
# the n nodes; with |prod (y - y_j)| <= 2^n (n!)^2 / (2n)! on [-1, 1] at the Legendre roots it errs,
# relative to l max|f|, by at most
#     n! / (2n)! theta^n,    theta = omega l.
# The nodes per piece are the fewest that keep both below QUADRATURE_RTOL, far below float64
# round-off (2^-53 = 1.1e-16): the quadrature adds no error of its own. Measured on the bridge (20 s at
# 1 kHz, theta = 0.37 rad): the error against the exact discretization stops changing from 4 nodes on,
# the bound asks for 6; with 3 it is 3e-10 where the bound says 2e-10.
#: Largest relative error allowed to the quadrature of one piece (see the bound above).
QUADRATURE_RTOL = 1e-18
#: Fewest Gauss-Legendre nodes per piece (exact for the piecewise-linear signals, whose omega is 0,
#: and the quadratic ground displacement of a piecewise-linear acceleration).
MIN_NODES = 3
#: Most Gauss-Legendre nodes per piece; a longer phase splits an interval's quadrature into pieces.
MAX_NODES = 24


def _largest_phases(n: int) -> tuple[float, float]:
    """The largest ``theta`` [rad] for which n nodes meet :data:`QUADRATURE_RTOL`: quadrature, interpolation."""
    log_rtol = math.log(QUADRATURE_RTOL)
    log_gauss = 4 * math.lgamma(n + 1) - math.log(2 * n + 1) - 3 * math.lgamma(2 * n + 1)
    log_interpolation = math.lgamma(n + 1) - math.lgamma(2 * n + 1)
    return math.exp((log_rtol - log_gauss) / (2 * n)), math.exp((log_rtol - log_interpolation) / n)


_PHASES = {n: _largest_phases(n) for n in range(MIN_NODES, MAX_NODES + 1)}


def quadrature_size(theta: float, theta_ground: float = 0.0) -> tuple[int, int]:
    """Gauss-Legendre nodes per piece and pieces per interval so that the error bound holds.

    Parameters
    ----------
    theta : float
        ``(|lambda|_max + omega) h`` [rad]: the phase an interval's increment spans.
    theta_ground : float
        ``omega h`` [rad] of a ground velocity or acceleration integrated on the nodes (0 without).

    Returns
    -------
    nodes, pieces : int
    """
    most = _PHASES[MAX_NODES]
    pieces = max(1, math.ceil(theta / most[0]), math.ceil(theta_ground / most[1]))
    nodes = next(n for n, (q, i) in _PHASES.items() if theta / pieces <= q and theta_ground / pieces <= i)
    return nodes, pieces


def quadrature_for(step, fastest, omega, ground) -> tuple[int, int]:
    """:func:`quadrature_size` for intervals of at most ``step`` [s], the fastest pole ``|lambda|`` and
    the highest signal frequency ``omega`` [rad/s], and a ground motion (a :class:`GroundInput` or None,
    integrated on the nodes unless given as a displacement)."""
    integrated = ground is not None and ground.quantity != "displacement"
    return quadrature_size((fastest + omega) * step, omega * step if integrated else 0.0)


def superpose(
    system: System,
    excitation,
    t,
    *,
    method: str = "auto",
    n_modes: int | None = None,
    f_max_hz: float | None = None,
    residual: bool = True,
    start: SuperpositionState | None = None,
    **options,
) -> TimeHistory:
    """Time response of a system to an excitation by modal superposition.

    The same response as :func:`sixdof.analysis.direct.simulate` computed independently: modal transform,
    exact recursion of the decoupled modal equations with the Duhamel integral by Gauss-Legendre
    quadrature between the excitation's breakpoints, transform back (see :func:`modal_solve`).

    ``q`` is absolute (motion in the fixed frame), like the direct solver's: ground motion enters as
    ``K r u_g + C r v_g`` (mount springs and all viscous damping acting on the body's motion
    relative to the ground), with ``u_g, v_g`` integrated exactly from a velocity or acceleration
    signal, the ground starting at rest at zero displacement at ``t[0]`` (see
    :class:`GroundInput`).

    A long run may go window by window: ``start=previous.superposition.end`` continues the previous
    window's run exactly (its modal coordinates and ground integrals), from the previous window's last
    time to this window's times (which may begin there or one step later).

    Parameters
    ----------
    system : sixdof.model.system.System
    excitation : sixdof.excitation.Excitation or None
        Loads, ground motion and initial state (None: at rest, no load).
    t : array_like, shape (n,)
        Output times [s], strictly increasing; the initial state is applied at ``t[0]``.
    method : {"auto", "real", "complex"}
        See :func:`modal_solve`.
    n_modes : int, optional
        Number of modes kept, lowest first.
    f_max_hz : float, optional
        Highest natural frequency kept [Hz].
    residual : bool
        Static residual correction for the dropped modes (default True).
    start : SuperpositionState, optional
        Continue a run from this state (``superposition.end`` of its previous window) instead of
        starting from the excitation's initial state at ``t[0]``; the same system, excitation and
        options. Loads idle in this window are then not warned about (the run as a whole decides).
    **options
        Passed to :func:`modal_solve` (``quadrature_nodes``, ``max_step``).

    Returns
    -------
    sixdof.results.TimeHistory
        With the method, modes kept, truncation error and end state in ``superposition``.

    Raises
    ------
    InputError
        On arguments of the wrong kind, bad times, options or a ``start`` from another computation.
    SolverError
        If the complex modes cannot be computed reliably.

    Warns
    -----
    sixdof.analysis.validity.RangeWarning
        For a load that never acts from ``t[0]`` to ``t[-1]``, and for rotations beyond
        :data:`~sixdof.analysis.validity.SMALL_ANGLE_RAD`.
    """
    instance(system, "system", System)
    if instance(excitation, "excitation", Excitation, None) is None:
        excitation = Excitation()
    t = increasing_times(t, "t")
    q0 = qd0 = f0 = None
    if start is None:
        q0, qd0 = excitation.initial_state(system, t[0])  # in equilibrium with a ground displaced at t[0]
        f0 = excitation.initial_branch_forces(system)
        warn_idle(excitation, t[0], t[-1])
    branches = system.branches if system.branches.count else None
    loads, ground, omega = excitation_inputs(excitation, system.K, system.C, branches)
    history = modal_solve(
        system.M, system.C, system.K, t, loads, excitation.breakpoints, q0, qd0, method=method, n_modes=n_modes,
        f_max_hz=f_max_hz, residual=residual, signal_omega=omega, ground=ground, start=start, modes=system.modes,
        branches=branches, branch_forces=f0, **options,
    )
    warn_large_rotations(history.t, history.q)
    return history


@dataclass(frozen=True, eq=False)
class Loads:
    """Generalized forces as scalar signals times fixed vectors: ``Q(t) = sum_c g_c(t) vectors[c]``.

    Parameters
    ----------
    vectors : ndarray, shape (n_c, 6)
        Generalized force per unit of each signal [N, N m].
    values : callable
        ``values(times, order)`` for a sorted 1-D array of times [s] and ``order`` 0, 1 or 2 returns
        the signals or their time derivatives, one column per signal, shape (len(times), n_c).
    rates : bool
        Whether ``values`` knows the derivatives (orders 1 and 2).
    """

    vectors: np.ndarray
    values: object
    rates: bool = True


def excitation_inputs(excitation, K, C, branches=None):
    """An :class:`~sixdof.excitation.Excitation` as the engine's inputs for the stiffness and damping K, C (and
    the Maxwell branches, :class:`~sixdof.model.system.Branches`, that the ground's velocity also drives).

    Returns
    -------
    loads : Loads or None
        One column per load component.
    ground : GroundInput or None
        The ground motion, entering as ``K r u_g + C r v_g``.
    omega : float
        Highest circular frequency [rad/s] the signals carry (0 for piecewise-linear ones).
    """
    components = excitation.components()
    signals = [signal for _, signal in components]
    ground = None
    if excitation.ground is not None:
        r = np.asarray(excitation.ground.rigid_vector, dtype=float)
        b_g = None if branches is None else -branches.stiffness * (branches.rows @ r)
        ground = ground_input(excitation.ground, np.asarray(K) @ r, np.asarray(C) @ r, b_g)
        signals.append(excitation.ground.signal)
    return signal_loads(components), ground, 2 * np.pi * max((s.max_frequency_hz for s in signals), default=0.0)


def signal_loads(components) -> Loads | None:
    """Load components ``(Q, signal)`` (:meth:`~sixdof.excitation.Excitation.components`) as :class:`Loads`,
    one column per component (None without any)."""
    if not components:
        return None
    vectors = np.array([np.asarray(vector, dtype=float) for vector, _ in components]).reshape(-1, 6)
    signals = [signal for _, signal in components]

    def values(times, order=0):
        if len(signals) == 1:
            return signal_values(signals[0], times, order)[:, None]
        out = np.empty((times.size, len(signals)))
        for c, signal in enumerate(signals):
            out[:, c] = signal_values(signal, times, order)
        return out

    return Loads(vectors=vectors, values=values)


def ground_input(motion, k_g, c_g, b_g=None) -> GroundInput:
    """A :class:`~sixdof.excitation.GroundMotion` as the :class:`GroundInput` of a system (``k_g = K r``,
    ``c_g = C r``, ``b_g = -k_b R r``: Maxwell branches)."""
    scale, signal = float(motion.scale), motion.signal
    return GroundInput(
        quantity=motion.quantity,
        signal=lambda times: scale * signal_values(signal, times, 0),
        rate=lambda times: scale * signal_values(signal, times, 1),
        k_g=np.asarray(k_g, dtype=float), c_g=np.asarray(c_g, dtype=float),
        b_g=None if b_g is None else np.asarray(b_g, dtype=float),
    )


@partial(jax.jit, static_argnums=2)
def _compiled_signal(signal, times, order):
    """A signal (order 0) or its derivative; signals are pytrees: one compilation per kind and length."""
    return signal(times) if order == 0 else signal.derivative(times, order)


def signal_values(signal, times, order=0) -> np.ndarray:
    """A signal (``order`` 0) or its time derivative (1, 2) at sorted ``times`` (1-D) [s], in one compiled call.

    Only the times inside the signal's support are evaluated (a short pulse costs little); they are
    padded to a size with four significant bits (at most 1/8 wasted), so that new grids reuse a few
    compilations per signal kind.
    """
    low, high = np.searchsorted(times, signal.support)  # zero outside [first, end)
    if low > 0 or high < times.size:
        values = np.zeros(times.size)
        if high > low:
            values[low:high] = signal_values(signal, times[low:high], order)
        return values
    n = times.size
    size = _padded_size(n)
    padded = times if size == n else np.concatenate([times, np.full(size - n, times[-1] if n else 0.0)])
    return np.asarray(_compiled_signal(signal, padded, order), dtype=float)[:n]


def _padded_size(n: int) -> int:
    """At least n and 1024, with four significant bits."""
    size = max(1024, n)
    step = 1 << max(size.bit_length() - 4, 0)
    return -(-size // step) * step


def modal_solve(
    M,
    C,
    K,
    t,
    force=None,
    breakpoints=(),
    q0=None,
    qd0=None,
    *,
    method: str = "auto",
    n_modes: int | None = None,
    f_max_hz: float | None = None,
    residual: bool = True,
    force_rates=None,
    max_step: float | None = None,
    signal_omega: float | None = None,
    quadrature_nodes: int | None = None,
    ground=None,
    start: SuperpositionState | None = None,
    modes=None,
    branches=None,
    branch_forces=None,
) -> TimeHistory:
    """Response of ``M q'' + C q' + K q = Q(t)`` by modal superposition.

    With Maxwell branches (visco-elastic mounts) the equations gain ``+ R' f`` and
    ``f' = k_b R (q' - r v_g) - f / tau_b`` (:mod:`sixdof.analysis.direct`): the coupled modes are then the
    complex modes of the augmented first-order system ``[eta, eta', f]``, the branches starting from
    ``branch_forces`` at ``t[0]``.

    Parameters
    ----------
    M, C, K : array_like, shape (6, 6)
        Mass [kg, kg m^2], viscous damping [N s/m, ...] (symmetric positive semi-definite) and
        stiffness [N/m, ...] (symmetric positive semi-definite) matrices.
    t : array_like, shape (n,)
        Output times [s], strictly increasing, n >= 2. The initial state is given at ``t[0]``.
    force : callable or Loads, optional
        ``force(times)`` for a 1-D array of times [s] returns the generalized force, shape
        (len(times), 6) [N, N m]; or :class:`Loads` (signals times vectors, with their derivatives).
        Default: no force (free response).
    breakpoints : sequence of float
        Times [s] where the force or one of its derivatives jumps; the quadrature never straddles
        them.
    q0, qd0 : array_like, shape (6,), optional
        Initial displacement [m, rad] and velocity [m/s, rad/s] at ``t[0]``. Default zero.
    method : {"auto", "real", "complex"}
        ``"auto"`` uses real modes when the damping is classical, complex modes otherwise.
        Forcing ``"real"`` on non-classical damping neglects the modal coupling; the resulting
        error is reported in ``approximation``.
    n_modes : int, optional
        Keep only the ``n_modes`` lowest modes (rigid-body modes must all be kept).
    f_max_hz : float, optional
        Keep only the modes with natural frequency <= ``f_max_hz`` [Hz].
    residual : bool
        Add the static residual correction ``R Q(t)``, ``R = sum_dropped phi phi' / omega^2``, for
        the dropped modes (residual flexibility).
    force_rates : tuple of two callables, optional
        ``(dQ/dt, d2Q/dt2)`` with the signature of a callable ``force``: the residual correction then
        enters ``qd`` and ``qdd`` as well (with :class:`Loads` the rates come from its signals).
    max_step : float, optional
        Longest quadrature piece [s]: splits each interval's quadrature further (never its recursion).
    signal_omega : float, optional
        Highest circular frequency [rad/s] in the force and ground signal: with the fastest mode it
        sets the quadrature nodes (see :func:`quadrature_size`). Default: the Nyquist frequency of the
        output grid, ``pi / h`` (a force that the samples resolve).
    quadrature_nodes : int, optional
        Gauss-Legendre nodes per piece, overriding the automatic choice (one piece per interval
        unless ``max_step`` asks for more).
    ground : GroundInput, optional
        Motion of the foundation, adding ``Q_g = k_g u_g(t) + c_g v_g(t)`` to the force, with the
        ground displacement and velocity obtained from the signal exactly on the quadrature grid
        (see :class:`GroundInput`).
    start : SuperpositionState, optional
        Continue a run from its end state (``superposition.end`` of the previous window; ``q0``,
        ``qd0`` are then ignored): its time must be at most ``t[0]``.
    modes : sixdof.analysis.modal.Modes, optional
        The undamped modes of ``(M, K)`` when already known (``System.modes``).
    branches : sixdof.model.system.Branches, optional
        Maxwell branches (``System.branches``); none by default. Complex modes only, every mode kept.
    branch_forces : array_like, shape (nb,), optional
        The branches' forces at ``t[0]`` [N]; default relaxed (zero).

    Returns
    -------
    sixdof.results.TimeHistory
        With the method, modes kept, truncation error and end state in ``superposition``.

    Raises
    ------
    InputError
        On malformed arrays, times, options, a truncation that drops rigid-body modes or a ``start``
        from another computation.
    SolverError
        If the complex modes cannot be computed reliably or the result is not finite.
    """
    M, C, K = (finite_array(m, name, "a finite 6x6 matrix", (6, 6)) for m, name in ((M, "M"), (C, "C"), (K, "K")))
    t = increasing_times(t, "t")
    if method not in METHODS:
        raise InputError("method", "one of 'auto', 'real', 'complex'", method)
    if quadrature_nodes is not None and integer(quadrature_nodes, "quadrature_nodes", "an integer in [1, 64]",
                                                1) > 64:
        raise InputError("quadrature_nodes", "an integer in [1, 64]", quadrature_nodes)
    if max_step is not None:
        number(max_step, "max_step", "a positive duration in s", low=0.0, strict=True)
    if signal_omega is not None:
        number(signal_omega, "signal_omega", "a circular frequency >= 0 in rad/s", low=0.0)
    q0, qd0 = (np.zeros(6) if x is None else finite_array(x, name, "6 finite values", (6,))
               for x, name in ((q0, "q0"), (qd0, "qd0")))
    breakpoints = _breakpoints(breakpoints)
    t_start = _start_time(start, t)

    plan = Plan(M, C, K if modes is None else modes, method, n_modes, f_max_hz, branches)
    loads = _as_loads(force, force_rates)
    residual_rates = bool(residual and plan.dropped.size and loads is not None and loads.rates and ground is None)
    times = t if t_start == t[0] else np.concatenate([[t_start], t])
    step = float(np.max(np.diff(times)))
    nodes, pieces = quadrature_for(step, plan.fastest, np.pi / step if signal_omega is None else signal_omega, ground)
    if quadrature_nodes is not None:
        nodes, pieces = int(quadrature_nodes), 1
    if max_step is not None:
        pieces = max(pieces, math.ceil(step / max_step))
    drive = make_drive(times, t.size, breakpoints, loads, ground, nodes=nodes, pieces=pieces,
                       rates=residual_rates, ground_start=None if start is None else start.ground)
    return _respond(plan, drive, M, q0, qd0, start, residual, residual_rates, branch_forces)


def _start_time(start, t) -> float:
    """The time a run starts from: ``t[0]``, or the state's time when it continues one."""
    if start is None:
        return float(t[0])
    if not isinstance(start, SuperpositionState):
        raise InputError("start", "a SuperpositionState (superposition.end of the previous window)", start)
    if not start.t <= t[0]:
        raise InputError("start", f"a state at or before t[0] = {t[0]:g} s", f"a state at {start.t:g} s")
    return float(start.t)


def _as_loads(force, force_rates) -> Loads | None:
    """``force`` (None, :class:`Loads` or a callable of (n, 6) with its optional rates) as :class:`Loads`."""
    if force is None or isinstance(force, Loads):
        return force
    functions = (force,) + (tuple(force_rates) if force_rates is not None else ())

    def values(times, order=0):
        return _evaluate(functions[order], times, "force" if order == 0 else f"force_rates[{order - 1}]")

    return Loads(vectors=np.eye(6), values=values, rates=force_rates is not None)


class Plan:
    """The modal basis, the method chosen and why, the modes kept, and the runs that make a result.

    Parameters
    ----------
    M, C : ndarray, shape (6, 6)
        Mass and viscous damping matrices.
    modes : sixdof.analysis.modal.Modes or ndarray
        The undamped modes (anything with ``eigenvalues`` and ``shapes``), or the stiffness matrix K
        to compute them from.
    method, n_modes, f_max_hz, branches
        As :func:`modal_solve`'s.
    """

    def __init__(self, M, C, modes, method="auto", n_modes=None, f_max_hz=None, branches=None):
        if isinstance(modes, np.ndarray):
            modes = modal_analysis(M, modes)
        self.basis, self.omega2 = modal_basis(modes, C)
        D = self.basis.T @ C @ self.basis
        self.D = 0.5 * (D + D.T)
        self.coupling = float(np.max(coupling_of(self.D), initial=0.0))
        self.branches = branches
        self.classical = self.coupling <= CLASSICAL_RTOL and branches is None
        if branches is not None:
            if method == "real":
                raise InputError("method", "'auto' or 'complex' (Maxwell branches couple the real modes)", method)
            if n_modes is not None or f_max_hz is not None:
                raise InputError("n_modes" if n_modes is not None else "f_max_hz", "no truncation with Maxwell "
                                 "branches (a dropped mode has no static residual through a branch)",
                                 n_modes if n_modes is not None else f_max_hz)
        self.kept = _select(self.omega2, n_modes, f_max_hz)
        self.dropped = np.flatnonzero(~np.isin(np.arange(6), self.kept))
        self.method = method
        self.chosen = "real" if method == "real" or (method == "auto" and self.classical) else "complex"
        self.reason = _reason(method, self.coupling, self.classical, branches)
        # The response; with truncation, the same with every mode (its error); with real modes forced
        # on non-classical damping, the exact complex-mode response (the error of neglecting the coupling).
        self.runs = ((self.chosen, tuple(int(i) for i in self.kept)),)
        if self.dropped.size:
            self.runs += ((self.chosen, tuple(range(6))),)
        if self.chosen == "real" and not self.classical:
            self.runs += (("complex", tuple(range(6))),)
        # |lambda| <= omega + d for every mode: bounds the phase an interval spans (a Maxwell branch adds at
        # most its relaxation rate and its stiffness's frequency, Gershgorin on the scaled state matrix).
        self.fastest = float(np.sqrt(np.max(self.omega2)) + np.max(np.diag(self.D)))
        if branches is not None:
            coupling = np.abs(self.basis.T @ branches.rows.T) * np.sqrt(branches.stiffness)[None, :]
            self.fastest += float(np.max(1.0 / branches.tau) + np.max(coupling.sum(axis=0))
                                  + np.max(coupling.sum(axis=1)))

    def coordinates(self, run):
        solve_method, kept = run
        return _modal_coordinates(self.basis, self.omega2, self.D, np.asarray(kept), solve_method,
                                  all_complex=self.method == "complex", branches=self.branches)


def _reason(method, coupling, classical, branches=None) -> str:
    if branches is not None:
        return (f"{method}: Maxwell branches ({branches.count} states) couple the real modes: complex modes of the "
                "augmented first-order system")
    if method == "auto" and classical:
        return (f"auto: damping is classical (largest modal coupling {coupling:.1e} <= {CLASSICAL_RTOL:.0e}): "
                "real modes")
    if method == "auto":
        return (f"auto: damping couples the real modes (largest coupling |D_ij|/sqrt(D_ii D_jj) = {coupling:.2e} > "
                f"{CLASSICAL_RTOL:.0e}, non-proportional damping): complex modes")
    if method == "real" and classical:
        return f"forced real modes; damping is classical (coupling {coupling:.1e})"
    if method == "real":
        return (f"forced real modes on non-classical damping (coupling {coupling:.2e}): the off-diagonal modal "
                "damping is neglected, the result is approximate (see approximation)")
    return f"forced complex modes (damping coupling {coupling:.1e})"


def _respond(plan, drive, M, q0, qd0, start, residual, residual_rates, branch_forces=None) -> TimeHistory:
    """The history of the plan's runs on the drive, from ``(q0, qd0)`` and the branch forces, or the state
    ``start``."""
    if start is not None and start.runs != plan.runs:
        raise InputError("start", f"the state of the same computation (runs {plan.runs})", f"runs {start.runs}")
    outputs, ends, branch_force = [], [], None
    for index, run in enumerate(plan.runs):
        modal = plan.coordinates(run)
        B = plan.basis[:, list(run[1])]
        z0 = modal.initial @ np.concatenate([B.T @ (M @ q0), B.T @ (M @ qd0)]) if start is None else \
            np.asarray(start.coordinates[index])
        if start is None and branch_forces is not None and np.any(branch_forces):
            z0 = z0 + modal.branch_inputs @ branch_forces  # the coordinates of the branch states
        z = run_coordinates(modal, drive, z0)
        ends.append(readonly(z[-1], complex))
        outputs.append(modal.motion(z[drive.first:], drive, second=index == 0))
        if index == 0:
            eigenvalues = modal.eigenvalues
            if plan.branches is not None:
                branch_force = modal.branch_forces(z[drive.first:])
    q, qd, qdd = outputs[0]

    kept, dropped = plan.kept, plan.dropped
    if dropped.size and residual:
        Bd = plan.basis[:, dropped]
        R = Bd @ np.diag(1.0 / plan.omega2[dropped]) @ Bd.T  # static flexibility of the dropped modes
        q = q + drive.force_out @ R.T
        if residual_rates:
            qd = qd + drive.rates_out[0] @ R.T
            qdd = qdd + drive.rates_out[1] @ R.T
    truncation = approximation = None
    full = outputs[1][0] if dropped.size else q
    if dropped.size:
        truncation = compare(full, q)
    if plan.chosen == "real" and not plan.classical:
        approximation = compare(outputs[-1][0], full)

    if not np.isfinite(np.sum(q) + np.sum(qd) + np.sum(qdd)):  # one pass each; a NaN or inf anywhere shows
        bad = next(name for name, value in (("q", q), ("qd", qd), ("qdd", qdd)) if not np.all(np.isfinite(value)))
        raise SolverError(f"modal superposition produced non-finite values in {bad}")
    end = SuperpositionState(t=float(drive.times[-1]), coordinates=tuple(ends), runs=plan.runs,
                             ground=drive.ground_end)
    info = SuperpositionInfo(
        method=plan.chosen, reason=plan.reason, coupling=plan.coupling, modes_kept=tuple(int(i) for i in kept),
        frequency_hz=readonly(np.sqrt(plan.omega2[kept]) / (2 * np.pi)), eigenvalues=readonly(eigenvalues, complex),
        residual=bool(residual and dropped.size > 0), residual_rates=residual_rates, truncation=truncation,
        approximation=approximation, n_intervals=drive.n_intervals, quadrature_nodes=drive.nodes_per_interval,
        end=end,
    )
    return TimeHistory(t=drive.t, q=handed_over(q), qd=handed_over(qd), qdd=handed_over(qdd),
                       maxwell_force=branch_force, superposition=info)


def _select(omega2, n_modes, f_max_hz):
    keep = np.ones(6, dtype=bool)
    n_rigid = int(np.sum(omega2 == 0.0))
    if n_modes is not None:
        if integer(n_modes, "n_modes", "an integer from 1 to 6", 1) > 6:
            raise InputError("n_modes", "an integer from 1 to 6", n_modes)
        if n_modes < n_rigid:
            raise InputError("n_modes", f"at least {n_rigid} (the rigid-body modes have no static residual)", n_modes)
        keep &= np.arange(6) < n_modes
    if f_max_hz is not None:
        number(f_max_hz, "f_max_hz", "a positive frequency in Hz", low=0.0, strict=True)
        keep &= np.sqrt(omega2) / (2 * np.pi) <= f_max_hz
        if not np.any(keep):
            lowest = np.sqrt(omega2[0]) / (2 * np.pi)
            raise InputError("f_max_hz", f"at least the lowest natural frequency ({lowest:.4g} Hz)", f_max_hz)
    return np.flatnonzero(keep)


# ----------------------------------------------------------------------------------------------------
# The system side: first-order modal coordinates.
# ----------------------------------------------------------------------------------------------------

#: A single oscillator is one complex mode (one coordinate per conjugate pair) while its damped
#: frequency is at least this fraction of its natural frequency (damping ratio <= 0.968): the
#: transform to that mode and back then amplifies round-off at most ~2x. Closer to critical damping,
#: and for rigid-body modes, the two modes cannot be told apart: it is a chain of two coordinates.
SEPARATE_MODES = 0.25


@dataclass(frozen=True, eq=False)
class ModalCoordinates:
    """First-order modal coordinates ``z`` (m of them) of ``eta'' + D eta' + Omega^2 eta = f(t)`` (p modes).

    ``z_i' = poles_i z_i + inputs_i . f + [z_{source_i}]`` (the bracket when ``source_i >= 0``: the
    second coordinate of a chain), ``[eta; eta'] = Re(outputs @ z)``, ``z(t0) = initial @ [eta; eta']``.

    Attributes
    ----------
    poles : ndarray, shape (m,), complex
        [1/s].
    source : ndarray, shape (m,), int
        The coordinate feeding each one (-1: none); a source is never fed itself.
    inputs : ndarray, shape (m, p), complex
        Modal force to each coordinate.
    outputs : ndarray, shape (2p, m), complex
        Coordinates to ``[eta; eta']`` (conjugate pairs weighted 2).
    initial : ndarray, shape (m, 2p), complex
        ``[eta; eta']`` to the coordinates.
    basis : ndarray, shape (6, p)
        The modes' shapes (mass-normalized).
    damping, stiffness : ndarray, shape (p, p), (p,)
        Modal damping used and ``omega^2`` [1/s, 1/s^2].
    eigenvalues : ndarray, shape (2p + nb,), complex
        Every eigenvalue of the first-order system [1/s].
    branch_inputs : ndarray, shape (m, nb), complex
        Each Maxwell branch state to each coordinate: what a direct input to the branches (the ground's
        velocity) drives, and how their initial forces start the coordinates.
    branch_outputs : ndarray, shape (nb, m), complex
        Coordinates to the branch forces ``f`` [N] (conjugate pairs weighted 2).
    branch_modal : ndarray, shape (p, nb)
        ``G = B' R'``: the branches' modal force per unit branch force (``eta'' = ... - G f``).
    """

    poles: np.ndarray
    source: np.ndarray
    inputs: np.ndarray
    outputs: np.ndarray
    initial: np.ndarray
    basis: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    eigenvalues: np.ndarray
    branch_inputs: np.ndarray
    branch_outputs: np.ndarray
    branch_modal: np.ndarray

    def forcing(self, vectors, branch_vectors=None):
        """Modal force per unit of each column (generalized force ``vectors`` (n_c, 6), and direct input to the
        Maxwell branch states ``branch_vectors`` (n_c, nb)) to each coordinate (n_c, m)."""
        own = (vectors @ self.basis) @ self.inputs.T
        return own if branch_vectors is None else own + branch_vectors @ self.branch_inputs.T

    def output_maps(self):
        """``q, q', q''`` from the coordinates: ``Re(maps[k] @ z)``, maps (3, 6, m) complex; ``q''`` without
        the generalized force's part ``B B' Q`` (``eta'' = f - D eta' - Omega^2 eta - G f_b``)."""
        p = self.basis.shape[1]
        eta, eta_d = self.outputs[:p], self.outputs[p:]
        return np.stack([self.basis @ eta, self.basis @ eta_d,
                         -self.basis @ (self.damping @ eta_d + self.stiffness[:, None] * eta
                                        + self.branch_modal @ self.branch_outputs)])

    def motion(self, z, drive, second=True):
        """``q, q', q''`` (n, 6) from the coordinates z (n, m) at the drive's output times; ``q'`` and
        ``q''`` only when ``second`` (else None)."""
        maps = self.output_maps()[:3 if second else 1]
        # Re(z @ maps.T) as one real product per output: z's real and imaginary parts interleaved, times
        # the map's real part and minus its imaginary part interleaved.
        q, qd, qdd = [z.view(float) @ _interleaved(a.T) for a in maps] + [None] * (3 - len(maps))
        if second:  # the generalized force's part of q''
            qdd += drive.columns_out @ (drive.vectors @ (self.basis @ self.basis.T))
        return q, qd, qdd

    def branch_forces(self, z):
        """The Maxwell branch forces (n, nb) [N] from the coordinates z (n, m)."""
        return z.view(float) @ _interleaved(self.branch_outputs.T)


def _interleaved(a):
    """(m, k) complex -> (2m, k) real, rows ``Re a_j, -Im a_j``: ``x.view(float) @ _interleaved(a) = Re(x @ a)``."""
    return np.stack([a.real, -a.imag], axis=1).reshape(2 * a.shape[0], a.shape[1])


def _modal_coordinates(basis, omega2, D, kept, method, all_complex=False, branches=None) -> ModalCoordinates:
    """The first-order coordinates of the kept modes, solved by ``method`` (``"real"`` or ``"complex"``); with
    Maxwell ``branches`` (complex), the modes they deform are coupled through them."""
    B = basis[:, kept]
    w2 = omega2[kept]
    Dk = D[np.ix_(kept, kept)]
    p = len(kept)
    nb = 0 if branches is None else branches.count
    G = B.T @ branches.rows.T if nb else np.zeros((p, 0))
    if method == "real":
        single, coupled = np.arange(p), np.arange(0)
        D_used = np.diag(np.diag(Dk))
    else:
        # Uncoupled coordinates are single oscillators (exact, robust when critically damped); with
        # complex modes forced, only undamped rigid ones are (their first-order form is a Jordan block).
        isolated = np.all(coupling_of(Dk) <= CLASSICAL_RTOL, axis=1)
        if nb:  # a mode that deforms a branch is coupled through it (to the branch, and maybe other modes)
            isolated &= ~np.any(G * branches.stiffness[None, :] != 0.0, axis=1)
        if all_complex:
            isolated &= (w2 == 0.0) & (np.diag(Dk) <= CLASSICAL_RTOL * max(float(np.max(np.diag(Dk))), 0.0))
        single = np.flatnonzero(isolated)
        coupled = np.flatnonzero(~isolated)
        D_used = Dk.copy()
        D_used[np.ix_(single, coupled)] = 0.0
        D_used[np.ix_(coupled, single)] = 0.0

    poles, source, inputs, outputs, initial, eigenvalues = [], [], [], [], [], []
    branch_inputs, branch_outputs = [], []
    unbranched = np.zeros(nb)

    def add(pole, feeding, to_input, to_output, from_state, to_branch=unbranched, from_branch=unbranched):
        poles.append(pole)
        source.append(feeding)
        inputs.append(to_input)
        outputs.append(to_output)
        initial.append(from_state)
        branch_inputs.append(from_branch)
        branch_outputs.append(to_branch)
        return len(poles) - 1

    unit = np.eye(2 * p)
    for j in single:
        sigma = -0.5 * Dk[j, j]
        mu = np.sqrt(complex(sigma**2 - w2[j]))  # i w_d under critical damping, real at or beyond
        first, second = sigma + mu, sigma - mu
        eigenvalues += [first, second]
        if mu.imag >= SEPARATE_MODES * np.sqrt(w2[j]) and mu.imag > 0:
            # One complex mode z = (eta' - second eta) / (first - second); eta = 2 Re z, eta' = 2 Re(first z).
            gap = first - second
            add(first, -1, unit[p + j, p:] / gap, 2 * (unit[j] + first * unit[p + j]),
                (unit[p + j] - second * unit[j]) / gap)
        else:
            # The chain u = eta' - second eta, u' = first u + f; x = eta, x' = second x + u.
            u = add(first, -1, unit[p + j, p:], unit[p + j], unit[p + j] - second * unit[j])
            add(second, u, np.zeros(p), unit[j] + second * unit[p + j], unit[j])
    if coupled.size:
        maxwell = (G[coupled], branches.stiffness, branches.tau) if nb else None
        modes = complex_modes(np.diag(w2[coupled]), D_used[np.ix_(coupled, coupled)], maxwell=maxwell,
                              remedy="use method='real' only if the damping is classical")
        lam, V, Vinv = modes.eigenvalues, modes.right, modes.left
        eigenvalues += list(lam)
        # dgeev returns real eigenvalues with exactly zero imaginary part and exact conjugate pairs.
        real = np.flatnonzero(lam.imag == 0)
        upper = np.flatnonzero(lam.imag > 0)
        n_c = len(coupled)
        if len(real) + 2 * len(upper) != 2 * n_c + nb:
            raise SolverError("complex modes: eigenvalues are not in conjugate pairs")
        rows = np.concatenate([coupled, p + coupled])  # [eta; eta'] of the coupled modes
        for k, weight in [(k, 1.0) for k in real] + [(k, 2.0) for k in upper]:
            to_output = np.zeros(2 * p, complex)
            to_output[rows] = weight * V[:2 * n_c, k]
            from_state = np.zeros(2 * p, complex)  # the branches start relaxed: only [eta; eta'] sets z(t0)
            from_state[rows] = Vinv[k, :2 * n_c]
            to_input = np.zeros(p, complex)
            to_input[coupled] = Vinv[k, n_c:2 * n_c]
            add(lam[k], -1, to_input, to_output, from_state, weight * V[2 * n_c:, k], Vinv[k, 2 * n_c:])

    eigenvalues = np.array(eigenvalues, dtype=complex)
    return ModalCoordinates(
        poles=np.array(poles, dtype=complex), source=np.array(source, dtype=np.int64),
        inputs=np.array(inputs, dtype=complex).reshape(-1, p), outputs=np.array(outputs, dtype=complex).T,
        initial=np.array(initial, dtype=complex), basis=B, damping=D_used, stiffness=w2,
        eigenvalues=eigenvalues[np.lexsort((eigenvalues.imag, np.abs(eigenvalues)))],
        branch_inputs=np.array(branch_inputs, dtype=complex).reshape(len(poles), nb),
        branch_outputs=np.array(branch_outputs, dtype=complex).reshape(len(poles), nb).T, branch_modal=G,
    )


def _divided_exp(a, b, tau):
    """``(e^{a tau} - e^{b tau}) / (a - b)``, accurate as ``a -> b`` (where it is ``tau e^{a tau}``)."""
    half = 0.5 * (a - b) * tau
    with np.errstate(all="ignore"):  # each form is kept only where it is finite and accurate
        # tau e^{(a + b) tau / 2} sinh(half) / half, with sinh(x) / x = sinc(i x / pi): no cancellation.
        near = tau * np.exp(0.5 * (a + b) * tau) * np.sinc(1j * half / np.pi)
        far = (np.exp(a * tau) - np.exp(b * tau)) / np.where(a == b, 1.0, a - b)
    return np.where(np.abs(half) < 1.0, near, far)


def run_coordinates(modal: ModalCoordinates, drive: Drive, z0) -> np.ndarray:
    """The modal coordinates at every time of the drive's grid, from ``z0`` at its start.

    ``modal`` needs ``poles``, ``source`` and ``forcing`` (:class:`ModalCoordinates`, or several side by
    side).

    Returns
    -------
    ndarray of complex, shape (n_intervals + 1, m)
    """
    lam, source = modal.poles, modal.source
    m = lam.size
    fed = source >= 0
    feeder = np.where(fed, source, 0)
    # Modal force per unit of each signal column, to each coordinate directly and through its source.
    own = modal.forcing(drive.vectors, drive.branch_vectors)  # (n_c, m)
    through = np.where(fed, own[:, feeder], 0.0)

    def kernels(tau):
        """Response at an interval's end to a unit impulse ``tau`` before it: directly and through the source."""
        tau = tau[:, None]
        return np.exp(lam * tau), np.where(fed, _divided_exp(lam[feeder], lam, tau), 0.0)

    # The coordinates at every grid time, filled first with the increments d_k at row k + 1.
    z = np.zeros((drive.n_intervals + 1, m), complex)
    z[0] = z0
    if drive.regular_values is not None:
        # Every regular interval shares one kernel: their increments are one real matrix product,
        # the kernel's real and imaginary parts interleaved so that its rows are complex numbers.
        direct, fed_through = kernels(drive.regular_tau)
        weights = (direct[:, None] * own + fed_through[:, None] * through) * drive.regular_weight[:, None, None]
        weights = np.ascontiguousarray(weights.reshape(-1, m)).view(float)  # (n_q * n_c, 2m)
        if drive.irregular.size:
            z[1:][drive.regular] = (drive.regular_values @ weights).view(complex)
        else:
            np.matmul(drive.regular_values, weights, out=z[1:].view(float))
    if drive.irregular.size:
        direct, fed_through = kernels(drive.irregular_tau)
        values = drive.irregular_values * drive.irregular_weight[:, None]
        z[1:][drive.irregular] = np.add.reduceat(direct * (values @ own) + fed_through * (values @ through),
                                                 drive.irregular_start, axis=0)
    h = drive.step if drive.step is not None else np.diff(drive.times)[:, None]  # (n_intervals, 1)
    coupling = np.where(fed, _divided_exp(lam[feeder], lam, h), 0.0)
    _recursion(lam * h, coupling, feeder, fed, z)
    return z


#: Coordinates advanced one by one by the blocked filter; more (variants side by side) advance together,
#: one step at a time: the filter's cost is per coordinate, the step's per time step.
FILTERED_COORDINATES = 48

#: Steps per block of :func:`_filter`: one (blocks, BLOCK) x (BLOCK, BLOCK) matrix product per coordinate. Its
#: cost grows with BLOCK, the scan across blocks with their number: 20,000 steps of six coordinates take
#: 0.62-0.66 ms with 8 to 16, 0.86 ms with 32.
BLOCK = 16
_LAG = np.subtract.outer(np.arange(BLOCK), np.arange(BLOCK))  # i - j


def _recursion(exponent, coupling, feeder, fed, z):
    """``z_{k+1} = e^{exponent} z_k + coupling z_k[feeder] + d_k`` (the coupling where ``fed``), in place: z
    (n_intervals + 1, m) holds ``z_0``, then the increments ``d_k``, and ends with the states.

    ``exponent`` (``lambda h``) and ``coupling`` are (m,) on a uniform grid, (n_intervals, m) otherwise.
    """
    m = z.shape[1]
    uniform = exponent.ndim == 1
    if uniform and m <= FILTERED_COORDINATES:
        # Constant coefficients: each coordinate is a first-order recursive filter. Sources first, then
        # the coordinates they feed.
        for i in np.concatenate([np.flatnonzero(~fed), np.flatnonzero(fed)]):
            x = z[1:, i] + coupling[i] * z[:-1, feeder[i]] if fed[i] else z[1:, i]
            z[1:, i] = _filter(exponent[i], z[0, i], x)
        return
    # A non-uniform grid, or many coordinates (variants side by side): one step at a time, every
    # coordinate at once (the same arithmetic).
    a = np.exp(exponent)
    chained = np.flatnonzero(fed)
    feeding = feeder[chained]
    product = np.empty(m, complex)
    for k in range(z.shape[0] - 1):
        before, after = z[k], z[k + 1]
        np.multiply(a if uniform else a[k], before, out=product)
        np.add(after, product, out=after)
        if chained.size:
            after[chained] += (coupling if uniform else coupling[k])[chained] * before[feeding]


def _filter(exponent, z0, d):
    """``z_k = e^{exponent} z_{k-1} + d_k`` for k = 1..n from ``z_0``: d (n,) complex -> z_1..z_n.

    By blocks of :data:`BLOCK` steps: within a block, one matrix product with the transition's powers;
    across blocks, the block ends by a doubling scan (log2 of the number of blocks passes). Every power is
    ``exp(exponent * j)`` itself, not a product of rounded powers, so a lightly damped mode keeps its phase
    over 10^5 steps (~1e-15 of its peak, where repeated multiplication by a rounded ``e^{lambda h}`` drifts
    to ~2e-13), and no |power| exceeds 1 for a stable coordinate.
    """
    n = d.size
    if n == 0:
        return d
    blocks = -(-n // BLOCK)
    x = np.zeros(blocks * BLOCK, complex)
    x[:n] = d
    x = x.reshape(blocks, BLOCK)
    powers = np.exp(exponent * np.arange(BLOCK + 1))
    kernel = np.where(_LAG >= 0, powers[np.maximum(_LAG, 0)], 0.0)  # kernel[i, j] = e^{exponent (i - j)}
    local = x @ kernel.T  # each block's response from a zero start
    ends = local[:, -1].copy()  # the state at each block's end: ends_b = e^{exponent BLOCK} ends_{b-1} + local
    ends[0] += powers[BLOCK] * z0
    span = 1
    while span < blocks:
        ends[span:] += np.exp(exponent * (BLOCK * span)) * ends[:-span]
        span *= 2
    starts = np.empty(blocks, complex)
    starts[0] = z0
    starts[1:] = ends[:-1]
    local += np.multiply.outer(starts, powers[1:])
    return local.reshape(-1)[:n]


# ----------------------------------------------------------------------------------------------------
# The input side: the excitation on the quadrature nodes of a time grid.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Drive:
    """The excitation on the quadrature nodes of a time grid: what every system run on that grid shares.

    The grid's intervals are the recursion's steps. An interval is *regular* when the grid is
    uniform and no breakpoint falls inside it: all regular intervals share one set of nodes (``pieces``
    equal pieces of ``nodes`` Gauss-Legendre nodes each). The others (holding breakpoints, or all of
    them on a non-uniform grid) have their own nodes, the quadrature split at every breakpoint.
    The excitation is a few scalar *columns* (the loads' signals, then the ground's ``u_g`` and
    ``v_g``), each times a generalized force vector.

    Attributes
    ----------
    times : ndarray, shape (n_intervals + 1,)
        The grid [s]: the run's start, then the output times (the start is ``t[0]`` unless a run
        continues from an earlier state).
    first : int
        Index of ``t[0]`` in ``times`` (0 or 1).
    step : float or None
        The common interval [s] of a uniform grid.
    vectors : ndarray, shape (n_c, 6)
        Generalized force per unit of each column [N, N m].
    branch_vectors : ndarray, shape (n_c, nb), or None
        Direct input to the Maxwell branch states per unit of each column [N/s] (the ground's velocity).
    regular : ndarray of int
        Indices of the regular intervals.
    regular_tau, regular_weight : ndarray, shape (n_q,)
        Time from each node to its interval's end [s] and quadrature weight [s], for the nodes of each
        piece and the piece's end (weight 0: the ends are evaluated for the outputs).
    regular_values : ndarray, shape (len(regular), n_q * n_c), or None
        The columns at the nodes of each regular interval, node after node (None on a non-uniform grid).
    irregular : ndarray of int
        Indices of the other intervals.
    irregular_start : ndarray of int
        Index of each one's first node in the irregular node arrays.
    irregular_tau, irregular_weight : ndarray, shape (N,)
        Time to the interval's end [s] and weight [s] of each irregular node.
    irregular_values : ndarray, shape (N, n_c)
    columns_out : ndarray, shape (n, n_c)
        The columns at the output times (right limits at breakpoints).
    rates_out : ndarray, shape (2, n, 6), or None
        The loads' first and second time derivatives at the output times, when asked for.
    ground_end : tuple of float
        Integrated ground displacement and velocity at the grid's end (zeros when not integrated).
    nodes_per_interval : int
        Nodes of a regular interval.
    """

    times: np.ndarray
    first: int
    step: float | None
    vectors: np.ndarray
    branch_vectors: np.ndarray | None
    regular: np.ndarray
    regular_tau: np.ndarray | None
    regular_weight: np.ndarray | None
    regular_values: np.ndarray | None
    irregular: np.ndarray
    irregular_start: np.ndarray
    irregular_tau: np.ndarray
    irregular_weight: np.ndarray
    irregular_values: np.ndarray
    columns_out: np.ndarray
    rates_out: np.ndarray | None
    ground_end: tuple
    nodes_per_interval: int

    @property
    def t(self) -> np.ndarray:
        """Output times (n,) [s]."""
        return self.times[self.first:]

    @property
    def n_intervals(self) -> int:
        return self.times.size - 1

    @property
    def force_out(self) -> np.ndarray:
        """Generalized force at the output times (n, 6) [N, N m]."""
        return self.columns_out @ self.vectors


def uniform_step(times) -> float | None:
    """The common step [s] of a grid uniform to the rounding of its times, else None.

    A grid is uniform when every time is within a few units in the last place of ``t0 + k h``: such a
    grid (``linspace``, ``start + k / rate``) is advanced with the one step ``h``, at the cost of
    sampling the response at ``t0 + k h`` rather than at the rounded ``t_k``.
    """
    n = times.size - 1
    step = (times[-1] - times[0]) / n
    ideal = times[0] + np.arange(n + 1) * step
    scale = max(abs(times[0]), abs(times[-1]))
    return float(step) if np.max(np.abs(times - ideal)) <= 8 * np.finfo(float).eps * scale else None


def make_drive(times, n_out, breakpoints, loads, ground=None, *, nodes, pieces, rates=False,
               ground_start=None) -> Drive:
    """Evaluate the excitation on the quadrature nodes of the grid ``times``.

    Parameters
    ----------
    times : ndarray, shape (n_intervals + 1,)
        The grid [s]; its last ``n_out`` times are the outputs.
    n_out : int
    breakpoints : ndarray
        Sorted times [s] where a signal or a derivative jumps.
    loads : Loads or None
    ground : GroundInput or None
    nodes, pieces : int
        Gauss-Legendre nodes per piece and pieces per (longest) interval (:func:`quadrature_size`).
    rates : bool
        Whether to evaluate the loads' first and second time derivatives at the outputs.
    ground_start : tuple of float, optional
        ``(u_g, v_g)`` at ``times[0]`` of an integrated ground (default at rest at 0).

    Returns
    -------
    Drive
    """
    n_int = times.size - 1
    step = uniform_step(times)
    # Segments: the intervals split at the breakpoints inside them; pieces: segments split further.
    inner = breakpoints[(breakpoints > times[0]) & (breakpoints < times[-1])]
    position = np.searchsorted(times, inner)
    inner, position = inner[times[position] != inner], position[times[position] != inner]  # on a grid time: no split
    points = np.insert(times, position, inner)
    segments = np.bincount(position - 1, minlength=n_int) + 1  # per interval
    length = np.diff(points)
    if inner.size == 0 and pieces == 1:  # one piece per interval
        piece_interval, piece_length, piece_start = np.arange(n_int), length, times[:-1]
        last = slice(None)  # each interval's last piece: all of them (a slice: no gathers below)
    else:
        longest = float(np.max(np.diff(times))) / pieces
        parts = np.maximum(np.ceil(length / longest * (1 - 1e-12)).astype(np.int64), 1)
        piece_interval = np.repeat(np.repeat(np.arange(n_int), segments), parts)
        piece_length = np.repeat(length / parts, parts)
        index = np.arange(piece_length.size) - np.repeat(np.cumsum(parts) - parts, parts)
        piece_start = np.repeat(points[:-1], parts) + index * piece_length
        last = np.append(np.flatnonzero(np.diff(piece_interval)), piece_interval.size - 1)  # of each interval

    # The times every signal is evaluated at, once: the grid's start when it is an output, then each
    # piece's nodes and its end (the next piece's start; the grid's time after an interval's last piece),
    # sorted; padded as signal_values pads them.
    x, w = _gauss_legendre(nodes)
    head = n_out - n_int
    count = head + piece_length.size * (nodes + 1)
    padded = np.empty(_padded_size(count))
    padded[:head] = times[0]
    grid = padded[head:count].reshape(piece_length.size, nodes + 1)
    np.add(piece_start[:, None], piece_length[:, None] * (0.5 * (1.0 + x)), out=grid[:, :nodes])
    grid[:-1, nodes] = piece_start[1:]
    grid[last, nodes] = times[1:]
    padded[count:] = times[-1]
    everywhere = padded[:count]
    columns, vectors = [], []
    if loads is not None:
        columns.append(loads.values(padded, 0)[:count])
        vectors.append(loads.vectors)
    ground_end = (0.0, 0.0)
    branch_vectors = None
    if ground is not None:
        start = (0.0, 0.0) if ground_start is None else ground_start
        u, v, ground_end = ground.motion(everywhere, head, grid.shape, piece_length, start)
        columns.append(np.stack([u, v], axis=1))
        vectors.append(np.stack([ground.k_g, ground.c_g]))
        if ground.b_g is not None:  # the ground's velocity (its second column) drives the branches
            branch_vectors = np.zeros((sum(v.shape[0] for v in vectors), ground.b_g.size))
            branch_vectors[-1] = ground.b_g
    vectors = np.vstack(vectors) if vectors else np.zeros((0, 6))
    n_c = vectors.shape[0]
    values = _side_by_side(columns, everywhere.size)
    on_grid = values[head:].reshape(grid.shape + (n_c,))  # (pieces, nodes + 1, n_c)
    columns_out = np.concatenate([values[:head], on_grid[last, nodes]])
    rates_out = None
    if rates:
        rates_out = np.stack([loads.values(times[-n_out:], order) @ loads.vectors for order in (1, 2)])

    split = segments > 1
    if step is None:
        split[:] = True
    regular, irregular = np.flatnonzero(~split), np.flatnonzero(split)
    regular_values = regular_tau = regular_weight = None
    if step is not None:
        # A regular interval: `pieces` pieces of `nodes` nodes and an end each (weight 0 at the ends).
        fraction = (np.arange(pieces)[:, None] + 0.5 * (1.0 + np.append(x, 1.0))) / pieces
        regular_tau = (step * (1.0 - fraction)).reshape(-1)
        regular_weight = np.broadcast_to(np.append(step * w / (2 * pieces), 0.0), (pieces, nodes + 1)).reshape(-1)
        rows = on_grid.reshape(piece_length.size, (nodes + 1) * n_c)
        if irregular.size:  # the pieces are grouped by interval in time order, `pieces` per regular interval
            rows = rows[(last - pieces + 1)[regular][:, None] + np.arange(pieces)]
        regular_values = rows.reshape(regular.size, pieces * (nodes + 1) * n_c)
    in_irregular = split[piece_interval]
    counts = np.bincount(piece_interval[in_irregular], minlength=n_int)[irregular] * nodes
    irregular_nodes = grid[in_irregular, :nodes].reshape(-1)
    return Drive(
        times=times, first=times.size - n_out, step=step, vectors=vectors, branch_vectors=branch_vectors,
        regular=regular, regular_tau=regular_tau, regular_weight=regular_weight, regular_values=regular_values,
        irregular=irregular, irregular_start=np.cumsum(counts) - counts,
        irregular_tau=np.repeat(times[irregular + 1], counts) - irregular_nodes,
        irregular_weight=(piece_length[in_irregular, None] * (0.5 * w)).reshape(-1),
        irregular_values=on_grid[in_irregular, :nodes].reshape(irregular_nodes.size, n_c),
        columns_out=columns_out, rates_out=rates_out, ground_end=ground_end,
        nodes_per_interval=nodes * pieces,
    )


def _side_by_side(blocks, rows):
    """Column blocks, each (rows, k), side by side (the block itself when alone)."""
    if len(blocks) == 1:
        return blocks[0]
    return np.hstack(blocks) if blocks else np.zeros((rows, 0))


@dataclass(frozen=True, eq=False)
class GroundInput:
    """Rigid ground translation ``u_g(t)`` entering as the force ``k_g u_g + c_g v_g``.

    The mounts act on the body's motion relative to the ground, so in absolute coordinates the
    ground adds ``K r u_g + C_g r v_g`` (``r``: the generalized coordinates of a unit ground
    translation). ``u_g`` and ``v_g = u_g'`` come from the signal ``s`` (vectorized, [m], [m/s] or
    [m/s^2] per ``quantity``):

    - ``"displacement"``: ``u_g = s``, ``v_g = s'`` (``rate``, exact derivative);
    - ``"velocity"``: ``v_g = s``, ``u_g = int_{t0}^t s`` (zero at the first output time);
    - ``"acceleration"``: ``v_g = int s``, ``u_g = int int s`` (ground at rest at ``t0``).

    The integrals are exact on the quadrature grid: on each piece (never straddling a breakpoint) the
    integrand's interpolating polynomial at the Gauss-Legendre nodes is integrated analytically.

    Parameters
    ----------
    quantity : {"displacement", "velocity", "acceleration"}
    signal : callable
        ``signal(times)`` -> (len(times),) [m, m/s or m/s^2], for sorted times.
    rate : callable or None
        ``d signal / dt`` with the same signature; needed for ``"displacement"`` only.
    k_g, c_g : ndarray, shape (6,)
        ``K r`` [N/m, N] and ``C_g r`` [N s/m, N s]: generalized force per unit ground
        displacement and velocity.
    b_g : ndarray, shape (nb,), or None
        ``-k_b R r`` [N/m]: the rate of each Maxwell branch force per unit ground velocity (None: no branches).
    """

    quantity: str
    signal: object
    rate: object
    k_g: np.ndarray
    c_g: np.ndarray
    b_g: np.ndarray | None = None

    def motion(self, times, head, shape, piece_length, start):
        """``u_g, v_g`` at ``times``: ``head`` (0 or 1) times at the grid's start, then the nodes and the
        end of each of consecutive pieces (``shape``: (pieces, nodes + 1)); and ``(u_g, v_g)`` at the
        grid's end, from ``start`` at its beginning."""
        s = _evaluate(self.signal, times, "ground.signal", ())
        if self.quantity == "displacement":
            return s, _evaluate(self.rate, times, "ground.signal", ()), (0.0, 0.0)
        nodes = shape[1] - 1

        def integral(values, initial):
            """Running integral of values at ``times`` (the piece ends' values are not used)."""
            on_pieces = values[head:].reshape(shape)
            inside, ends = _running_integral(np.ascontiguousarray(on_pieces[:, :nodes]), initial, piece_length)
            out = np.empty(values.size)
            out[:head] = initial
            grid = out[head:].reshape(shape)
            grid[:, :nodes], grid[:, nodes] = inside, ends
            return out, float(ends[-1])

        if self.quantity == "velocity":
            u, u_end = integral(s, start[0])
            return u, s, (u_end, 0.0)
        v, v_end = integral(s, start[1])
        u, u_end = integral(v, start[0])
        return u, v, (u_end, v_end)


def _running_integral(values, initial, lengths):
    """Integral from the first piece's start (value ``initial``) of a function known on the nodes of
    consecutive pieces (N_p, n): at those nodes (N_p, n) and at each piece's end (N_p,)."""
    to_nodes, to_end = _integration_matrices(values.shape[1])
    half = 0.5 * lengths[:, None]
    within = half * (values @ to_nodes.T)  # from each piece's start to its nodes
    across = half[:, 0] * (values @ to_end)
    ends = initial + np.cumsum(across)
    starts = np.concatenate([[initial], ends[:-1]])
    return starts[:, None] + within, ends


@cache
def _gauss_legendre(n):
    """Gauss-Legendre nodes on [-1, 1] and weights (n,) each, read-only."""
    return tuple(readonly(a) for a in np.polynomial.legendre.leggauss(n))


@cache
def _integration_matrices(n):
    """Values at n Gauss-Legendre nodes -> integral of their interpolant from -1 to each node (n, n), to 1 (n,)."""
    x, _ = _gauss_legendre(n)
    vandermonde = np.polynomial.legendre.legvander(x, n - 1)  # P_k(x_j)
    to_coefficients = np.linalg.inv(vandermonde)
    antiderivatives = np.stack(
        [np.polynomial.legendre.legint(np.eye(n)[k], lbnd=-1.0) for k in range(n)], axis=1
    )  # column k: Legendre coefficients of int_{-1}^x P_k
    at_nodes = np.polynomial.legendre.legvander(x, n) @ antiderivatives
    at_end = np.polynomial.legendre.legvander(np.array([1.0]), n)[0] @ antiderivatives
    return readonly(at_nodes @ to_coefficients), readonly(at_end @ to_coefficients)


def _evaluate(function, times, name, shape=(6,)):
    """``function`` (of a 1-D array of times, returning (n,) + ``shape``; None: zero) on times of any shape."""
    if function is None:
        return np.zeros(times.shape + shape)
    value = np.asarray(function(times.reshape(-1)), dtype=float)
    if value.shape != (times.size,) + shape:
        raise InputError(name, f"a callable returning shape {(times.size,) + shape}", f"shape {value.shape}")
    if not np.all(np.isfinite(value)):
        raise SolverError(f"{name} returned non-finite values")
    return value.reshape(times.shape + shape)


def _breakpoints(value):
    try:
        array = np.asarray(tuple(value), dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError("breakpoints", "a sequence of times in s", value) from None
    if not np.all(np.isfinite(array)):
        raise InputError("breakpoints", "finite times in s", value)
    return np.unique(array)
