"""The entry points, :func:`superpose` and :func:`modal_solve`: a plan's runs on a drive, transformed back."""

from __future__ import annotations

import math

import numpy as np

from sixdof.analysis.compare import compare
from sixdof.analysis.records import SuperpositionInfo, SuperpositionState
from sixdof.analysis.superposition.drive import make_drive
from sixdof.analysis.superposition.inputs import _as_loads, _breakpoints, excitation_inputs
from sixdof.analysis.superposition.plan import Plan
from sixdof.analysis.superposition.quadrature import quadrature_for
from sixdof.analysis.superposition.recursion import run_coordinates
from sixdof.analysis.validity import warn_idle, warn_large_rotations
from sixdof.errors import (
    InputError,
    Owned,
    SolverError,
    finite_array,
    increasing_times,
    instance,
    integer,
    number,
    readonly,
)
from sixdof.excitation import Excitation
from sixdof.model.system import System
from sixdof.results import TimeHistory

METHODS = ("auto", "real", "complex")


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
    branches : sixdof.model.parts.Branches, optional
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
    return TimeHistory(t=drive.t, q=Owned(q), qd=Owned(qd), qdd=Owned(qdd),
                       maxwell_force=branch_force, superposition=info)
