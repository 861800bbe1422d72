"""Modal superposition in time: an independent path that cross-checks every direct solve.

The response of ``M q'' + C q' + K q = Q(t)`` is computed in modal coordinates, with no ODE solver:

1. the undamped modes ``Phi`` (mass-normalized, :func:`sixdof.analysis.modal.modal_analysis`) transform the
   equations to ``eta'' + D eta' + Omega^2 eta = Phi' Q(t)`` with ``D = Phi' C Phi``;
2. when ``D`` is diagonal (classical damping: Rayleigh, modal ratios, any C the real modes
   diagonalize) each mode is a single-degree-of-freedom oscillator (method ``"real"``); otherwise
   (mount dashpots) the coupled modes are solved through the complex modes of the first-order system
   ``y' = [[0, I], [-Omega^2, -D]] y + [0, Phi' Q]`` (method ``"complex"``), exact for any viscous C;
3. every decoupled equation is advanced by its exact state-transition recursion
   ``z(t + h) = e^{A h} z(t) + int_0^h e^{A (h - s)} b g(t + s) ds``, the Duhamel integral being
   evaluated by Gauss-Legendre quadrature on intervals split at every breakpoint of the excitation
   (where a signal or its derivatives jump): spectrally accurate for smooth signals, exact to
   round-off for piecewise-polynomial ones (tables, steps, ramps). The recursion over intervals is
   a parallel (associative) scan, vectorized across modes and intervals with NumPy;
4. modes may be truncated (by count or frequency) with a static residual-flexibility correction for
   the modes left out.

:func:`compare` measures the agreement of two time histories DOF by DOF.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from sixdof._jax import jax
from sixdof.analysis.compare import Agreement, compare
from sixdof.analysis.modal import modal_analysis
from sixdof.analysis.statespace import CLASSICAL_RTOL, complex_modes, modal_basis
from sixdof.analysis.statespace import coupling as coupling_of
from sixdof.analysis.validity import warn_idle, warn_large_rotations
from sixdof.errors import InputError, SolverError, finite_array, increasing_times, integer, number, readonly
from sixdof.excitation import Excitation
from sixdof.results import TimeHistory, label, part, quantity

if TYPE_CHECKING:
    from sixdof.model.system import System

#: Default Gauss-Legendre nodes per interval.
QUADRATURE_NODES = 16
#: Largest phase ``(|lambda| + omega_signal) h`` [rad] an interval may span: with 16 nodes the
#: quadrature error of ``int e^{i theta s}`` over 4 rad is far below round-off.
PHASE_PER_INTERVAL = 4.0

METHODS = ("auto", "real", "complex")
_CHUNK = 4096  # intervals processed at once: bounds memory to a few tens of MB


@dataclass(frozen=True, eq=False)
class SuperpositionInfo:
    """How a modal-superposition history was computed (:attr:`sixdof.results.TimeHistory.superposition`).

    The history's ``q`` is the absolute motion (fixed frame), like the direct solver's. With
    truncation, ``q`` includes the static residual correction; ``qd`` and ``qdd`` include it too when
    the force's time derivatives are known (``residual_rates``).

    Attributes
    ----------
    method : str
        ``"real"`` (decoupled undamped modes) or ``"complex"`` (complex modes of the first-order
        system).
    reason : str
        Why that method was used (automatic choice, or forced by the caller, and what it neglects).
    coupling : float
        Largest damping coupling ``|D_ij| / sqrt(D_ii D_jj)`` between distinct real modes (0 for
        classical damping, up to 1).
    modes_kept : tuple of int
        Indices (ascending frequency order of :func:`sixdof.analysis.modal.modal_analysis`) of the modes used.
    frequency_hz : ndarray, shape (len(modes_kept),)
        Undamped natural frequencies of the kept modes [Hz].
    eigenvalues : ndarray of complex, shape (2 len(modes_kept),)
        Eigenvalues of the first-order system actually solved [1/s]: ``-zeta w +- i w_d`` per mode
        for ``"real"``, the complex modes for ``"complex"``.
    residual : bool
        Whether the static residual correction for the dropped modes was added.
    residual_rates : bool
        Whether that correction also entered ``qd`` and ``qdd``.
    truncation : Agreement or None
        This response against the same computation with all modes kept (None when all are kept).
    approximation : Agreement or None
        When ``method="real"`` was forced on non-classical damping: this response against the
        exact complex-mode one, so the error of neglecting the coupling is reported. Else None.
    n_intervals : int
        Number of quadrature intervals (output steps split at breakpoints and for accuracy).
    quadrature_nodes : int
        Gauss-Legendre nodes per interval.
    """

    method: str = label()
    reason: str = label(name="method_reason")
    coupling: float = label(name="damping_coupling")
    modes_kept: tuple[int, ...] = label(encode=lambda kept: np.asarray([j + 1 for j in kept], dtype=np.int64),
                                        decode=lambda kept: tuple(int(j) - 1 for j in kept))
    frequency_hz: np.ndarray = label(name="frequency_hz_kept")
    eigenvalues: np.ndarray = quantity("1/s", ("pole",), name="eigenvalues",
                                       description="eigenvalues of the first-order system solved")
    residual: bool = label(name="residual_correction", decode=bool)
    residual_rates: bool = label(decode=bool)
    n_intervals: int = label()
    quadrature_nodes: int = label()
    truncation: Agreement | None = part(lambda: Agreement, prefix="truncation_", default=None)
    approximation: Agreement | None = part(lambda: Agreement, prefix="approximation_", default=None)
    #: What the history's q measures: the absolute motion, like the direct solver's.
    frame: str = label(default="absolute")


def superpose(
    system: System,
    excitation,
    t,
    *,
    method: str = "auto",
    n_modes: int | None = None,
    f_max_hz: float | None = None,
    residual: bool = True,
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
    **options
        Passed to :func:`modal_solve` (``quadrature_nodes``, ``max_step``).

    Returns
    -------
    sixdof.results.TimeHistory
        With the method, modes kept and truncation error in ``superposition``.

    Raises
    ------
    InputError
        On bad times or options.
    SolverError
        If the complex modes cannot be computed reliably.

    Warns
    -----
    sixdof.analysis.validity.RangeWarning
        For a load that never acts from ``t[0]`` to ``t[-1]``, and for rotations beyond
        :data:`~sixdof.analysis.validity.SMALL_ANGLE_RAD`.
    """
    if excitation is None:
        excitation = Excitation()
    components = excitation.components()
    t = increasing_times(t, "t")
    q0, qd0 = excitation.initial_state(system, t[0])  # in equilibrium with a ground displaced at t[0]
    warn_idle(excitation, t[0], t[-1])

    force = force_rates = None
    if components:
        vectors = np.stack([np.asarray(vector, dtype=float) for vector, _ in components])

        def derivative(order):
            return lambda times: np.stack([_padded(s, times, order) for _, s in components]).T @ vectors

        force, force_rates = derivative(0), (derivative(1), derivative(2))

    ground = None
    omegas = [2 * np.pi * s.max_frequency_hz for _, s in components]
    if excitation.ground is not None:
        motion = excitation.ground
        r = np.asarray(motion.rigid_vector, dtype=float)
        scale, signal = float(motion.scale), motion.signal
        ground = GroundInput(
            quantity=motion.quantity,
            signal=lambda times: scale * _padded(signal, times, 0),
            rate=lambda times: scale * _padded(signal, times, 1),
            k_g=np.asarray(system.K) @ r,
            c_g=np.asarray(system.C) @ r,
        )
        omegas.append(2 * np.pi * signal.max_frequency_hz)
        force_rates = None  # the residual's rates would need the ground's too: q only

    history = modal_solve(
        system.M, system.C, system.K, t, force, excitation.breakpoints, q0, qd0,
        method=method, n_modes=n_modes, f_max_hz=f_max_hz, residual=residual,
        force_rates=force_rates, signal_omega=max(omegas, default=0.0), ground=ground, **options,
    )
    warn_large_rotations(history.t, history.q)
    return history


@partial(jax.jit, static_argnums=2)
def _compiled_signal(signal, times, order):
    """A signal (order 0) or its derivative; signals are pytrees: one compilation per kind and length."""
    return signal(times) if order == 0 else signal.derivative(times, order)


def _padded(signal, times, order):
    """:func:`_compiled_signal` on ``times`` padded to a power of two: new grids reuse a few compilations."""
    n = times.size
    size = max(1024, 1 << (n - 1).bit_length())
    padded = np.concatenate([times, np.full(size - n, times[-1] if n else 0.0)])
    return np.asarray(_compiled_signal(signal, padded, order), dtype=float)[:n]


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
    signal_omega: float = 0.0,
    quadrature_nodes: int = QUADRATURE_NODES,
    ground=None,
) -> TimeHistory:
    """Response of ``M q'' + C q' + K q = Q(t)`` by modal superposition.

    Parameters
    ----------
    M, C, K : array_like, shape (6, 6)
        Mass [kg, kg m^2], viscous damping [N s/m, ...] (symmetric positive semi-definite) and
        stiffness [N/m, ...] (symmetric positive semi-definite) matrices.
    t : array_like, shape (n,)
        Output times [s], strictly increasing, n >= 2. The initial state is given at ``t[0]``.
    force : callable, optional
        ``force(times)`` for a 1-D array of times [s] returns the generalized force, shape
        (len(times), 6) [N, N m]. Default: no force (free response).
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
        ``(dQ/dt, d2Q/dt2)`` with the signature of ``force``: the residual correction then enters
        ``qd`` and ``qdd`` as well.
    max_step : float, optional
        Longest quadrature interval [s]. By default intervals are the output steps split at the
        breakpoints and further so that ``(|lambda|_max + signal_omega) h <= 4`` rad.
    signal_omega : float
        Highest circular frequency [rad/s] in the force (0 when unknown); bounds the interval.
    quadrature_nodes : int
        Gauss-Legendre nodes per interval (default 16).
    ground : GroundInput, optional
        Motion of the foundation, adding ``Q_g = k_g u_g(t) + c_g v_g(t)`` to the force, with the
        ground displacement and velocity obtained from the signal exactly on the quadrature grid
        (see :class:`GroundInput`).

    Returns
    -------
    sixdof.results.TimeHistory
        With the method, modes kept and truncation error in ``superposition``.

    Raises
    ------
    InputError
        On malformed arrays, times, options or a truncation that drops rigid-body modes.
    SolverError
        If the complex modes cannot be computed reliably or the result is not finite.
    """
    M, C, K = (finite_array(m, name, "a finite 6x6 matrix", (6, 6)) for m, name in ((M, "M"), (C, "C"), (K, "K")))
    t = increasing_times(t, "t")
    if method not in METHODS:
        raise InputError("method", "one of 'auto', 'real', 'complex'", method)
    if integer(quadrature_nodes, "quadrature_nodes", "an integer in [1, 64]", 1) > 64:
        raise InputError("quadrature_nodes", "an integer in [1, 64]", quadrature_nodes)
    q0, qd0 = (np.zeros(6) if x is None else finite_array(x, name, "6 finite values", (6,))
               for x, name in ((q0, "q0"), (qd0, "qd0")))
    breakpoints = _breakpoints(breakpoints)

    basis, omega2 = modal_basis(modal_analysis(M, K), C)
    D = basis.T @ C @ basis
    D = 0.5 * (D + D.T)
    coupling = float(np.max(coupling_of(D), initial=0.0))
    classical = coupling <= CLASSICAL_RTOL
    kept = _select(omega2, n_modes, f_max_hz)

    chosen = "real" if method == "real" or (method == "auto" and classical) else "complex"
    if method == "auto" and classical:
        reason = (f"auto: damping is classical (largest modal coupling {coupling:.1e} <= {CLASSICAL_RTOL:.0e}): "
                  "real modes")
    elif method == "auto":
        reason = (f"auto: damping couples the real modes (largest coupling |D_ij|/sqrt(D_ii D_jj) = {coupling:.2e} > "
                  f"{CLASSICAL_RTOL:.0e}, non-proportional damping): complex modes")
    elif method == "real" and classical:
        reason = f"forced real modes; damping is classical (coupling {coupling:.1e})"
    elif method == "real":
        reason = (f"forced real modes on non-classical damping (coupling {coupling:.2e}): the off-diagonal modal "
                  "damping is neglected, the result is approximate (see approximation)")
    else:
        reason = f"forced complex modes (damping coupling {coupling:.1e})"

    # |lambda| <= omega + d for every kept mode: bounds the phase an interval may span.
    fastest = float(np.sqrt(np.max(omega2[kept], initial=0.0)) + np.max(np.diag(D)[kept], initial=0.0))
    grid = _Grid(t, breakpoints, quadrature_nodes, max_step, PHASE_PER_INTERVAL / max(fastest + signal_omega, 1e-300))
    Q_nodes = _evaluate(force, grid.quadrature_times, "force")  # (n_int, n_g, 6)
    Q_out = _evaluate(force, t, "force")  # (n, 6)
    if ground is not None:
        u_nodes, v_nodes, u_out, v_out = ground.motion(grid)
        Q_nodes = Q_nodes + u_nodes[..., None] * ground.k_g + v_nodes[..., None] * ground.c_g
        Q_out = Q_out + u_out[:, None] * ground.k_g + v_out[:, None] * ground.c_g

    def run(kept_modes, solve_method):
        return _superpose_kept(
            basis, omega2, D, kept_modes, solve_method, grid, Q_nodes, Q_out, M, q0, qd0,
            all_complex=method == "complex",
        )

    eta, eta_d, eta_dd, eigenvalues = run(kept, chosen)
    Bk = basis[:, kept]
    q, qd, qdd = eta @ Bk.T, eta_d @ Bk.T, eta_dd @ Bk.T

    dropped = np.setdiff1d(np.arange(6), kept)
    residual_rates = False
    if dropped.size and residual:
        Bd = basis[:, dropped]
        R = Bd @ np.diag(1.0 / omega2[dropped]) @ Bd.T  # static flexibility of the dropped modes
        q = q + Q_out @ R.T
        if force_rates is not None and force is not None:
            rate, acceleration = force_rates
            qd = qd + _evaluate(rate, t, "force_rates[0]") @ R.T
            qdd = qdd + _evaluate(acceleration, t, "force_rates[1]") @ R.T
            residual_rates = True

    truncation = approximation = None
    eta_full = eta
    if dropped.size:
        eta_full = run(np.arange(6), chosen)[0]
        truncation = compare(eta_full @ basis.T, q)
    if chosen == "real" and not classical:
        approximation = compare(run(np.arange(6), "complex")[0] @ basis.T, eta_full @ basis.T)

    for name, value in (("q", q), ("qd", qd), ("qdd", qdd)):
        if not np.all(np.isfinite(value)):
            raise SolverError(f"modal superposition produced non-finite values in {name}")

    info = SuperpositionInfo(
        method=chosen, reason=reason, coupling=coupling, modes_kept=tuple(int(i) for i in kept),
        frequency_hz=readonly(np.sqrt(omega2[kept]) / (2 * np.pi)), eigenvalues=readonly(eigenvalues, complex),
        residual=bool(residual and dropped.size > 0), residual_rates=residual_rates, truncation=truncation,
        approximation=approximation, n_intervals=grid.n_intervals, quadrature_nodes=quadrature_nodes,
    )
    return TimeHistory(t=t, q=q, qd=qd, qdd=qdd, superposition=info)


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


def _superpose_kept(basis, omega2, D, kept, method, grid, Q_nodes, Q_out, M, q0, qd0, all_complex=False):
    """Modal coordinates of the kept modes: ``eta, eta', eta''`` (n, m) and the eigenvalues."""
    B = basis[:, kept]
    w2 = omega2[kept]
    Dk = D[np.ix_(kept, kept)]
    g_nodes = Q_nodes @ B  # modal forces at the quadrature nodes (n_int, n_g, m)
    eta0, etad0 = (B.T @ (M @ x) for x in (q0, qd0))  # Phi^-1 = Phi' M for mass-normalized modes
    eta, eta_d = np.zeros((2, len(grid.t), len(kept)))

    if method == "real":
        single, coupled = np.arange(len(kept)), np.arange(0)
        D_used = np.diag(np.diag(Dk))
    else:
        # Uncoupled coordinates are single oscillators (exact, robust when critically damped); with
        # complex modes forced, only undamped rigid ones are (their first-order form is a Jordan block).
        isolated = np.all(coupling_of(Dk) <= CLASSICAL_RTOL, axis=1)
        if all_complex:
            isolated &= (w2 == 0.0) & (np.diag(Dk) <= CLASSICAL_RTOL * max(float(np.max(np.diag(Dk))), 0.0))
        single = np.flatnonzero(isolated)
        coupled = np.flatnonzero(~isolated)
        D_used = Dk.copy()
        D_used[np.ix_(single, coupled)] = 0.0
        D_used[np.ix_(coupled, single)] = 0.0

    eigenvalues = []
    if single.size:
        d = np.diag(Dk)[single]
        eta[:, single], eta_d[:, single] = _oscillators(w2[single], d, grid, g_nodes[..., single], eta0[single],
                                                        etad0[single])
        disc = np.sqrt((d**2 / 4 - w2[single]).astype(complex))
        eigenvalues += list(-d / 2 + disc) + list(-d / 2 - disc)
    if coupled.size:
        eta[:, coupled], eta_d[:, coupled], lam = _complex_modes(
            w2[coupled], D_used[np.ix_(coupled, coupled)], grid, g_nodes[..., coupled], eta0[coupled], etad0[coupled])
        eigenvalues += list(lam)
    eta_dd = Q_out @ B - eta_d @ D_used.T - eta * w2
    eigenvalues = np.array(eigenvalues, dtype=complex)
    eigenvalues = eigenvalues[np.lexsort((eigenvalues.imag, np.abs(eigenvalues)))]
    return eta, eta_d, eta_dd, eigenvalues


def _oscillators(w2, d, grid, g, x0, v0):
    """Exact recursion of decoupled oscillators ``x'' + d x' + w2 x = g(t)``: x, x' (n, m)."""
    transition = _sdof_transition(w2, d, grid.h[:, None])  # (n_int, m, 2, 2)
    increments = np.zeros((grid.n_intervals, len(w2), 2))
    sigma = -0.5 * d
    for lo in range(0, grid.n_intervals, _CHUNK):
        hi = lo + _CHUNK
        # Response to a unit impulse of g at each node, seen at the interval's end: column 1 of
        # exp(A tau), i.e. e^{sigma tau} [S, C + sigma S].
        cosh, sinhc, decay = _sdof_functions(w2, d, grid.tau[lo:hi, :, None])  # (c, n_g, m)
        weighted = grid.weights[lo:hi, :, None] * g[lo:hi] * decay
        increments[lo:hi, :, 0] = np.sum(sinhc * weighted, axis=1)
        increments[lo:hi, :, 1] = np.sum((cosh + sigma * sinhc) * weighted, axis=1)
    z0 = np.stack([x0, v0], axis=-1)
    states = grid.at_outputs(_scan(transition, increments, z0), z0)
    return states[..., 0], states[..., 1]


def _sdof_functions(w2, d, tau):
    """``cosh(mu tau)``, ``sinh(mu tau)/mu`` (1, tau when mu = 0), ``e^{sigma tau}``; ``mu^2 = d^2/4 - w2``."""
    sigma = -0.5 * d
    mu2 = sigma**2 - w2
    shape = np.broadcast_shapes(np.shape(tau), w2.shape)
    tau = np.broadcast_to(tau, shape)
    cosh = np.ones(shape)
    sinhc = np.array(tau, dtype=float)
    # Under-damped modes (mu imaginary) take cos and sin of the damped frequency.
    for index, root, cos, sin in ((np.flatnonzero(mu2 < 0), -mu2, np.cos, np.sin),
                                  (np.flatnonzero(mu2 > 0), mu2, np.cosh, np.sinh)):
        if index.size:
            r = np.sqrt(root[index])
            x = tau[..., index] * r
            cosh[..., index] = cos(x)
            sinhc[..., index] = sin(x) / r
    return cosh, sinhc, np.exp(sigma * tau)


def _sdof_transition(w2, d, tau):
    """``exp(A tau)`` of ``A = [[0, 1], [-w2, -d]]``: ``e^{sigma tau} (cosh(mu tau) + sinhc(mu tau) (A - sigma))``."""
    sigma = -0.5 * d
    cosh, sinhc, decay = _sdof_functions(w2, d, tau)
    out = np.empty(cosh.shape + (2, 2))
    out[..., 0, 0] = decay * (cosh - sigma * sinhc)
    out[..., 0, 1] = decay * sinhc
    out[..., 1, 0] = -decay * w2 * sinhc
    out[..., 1, 1] = decay * (cosh + sigma * sinhc)
    return out


def _complex_modes(w2, D, grid, g, x0, v0):
    """x, x' (n, p) and the 2p eigenvalues by the complex modes of ``y' = [[0, I], [-W2, -D]] y + [0, g]``."""
    p = len(w2)
    modes = complex_modes(np.diag(w2), D, remedy="use method='real' only if the damping is classical")
    lam, V, Vinv = modes.eigenvalues, modes.right, modes.left
    # dgeev returns real eigenvalues with exactly zero imaginary part and exact conjugate pairs.
    real = np.flatnonzero(lam.imag == 0)
    upper = np.flatnonzero(lam.imag > 0)
    if len(real) + 2 * len(upper) != 2 * p:
        raise SolverError("complex modes: eigenvalues are not in conjugate pairs")
    use = np.concatenate([real, upper])  # one of each conjugate pair: y = sum_real v z + 2 Re sum_{Im > 0} v z
    weight = np.repeat([1.0, 2.0], [len(real), len(upper)])
    lam_u = lam[use]
    W = Vinv[use][:, p:]  # modal participation of the forces (r, p)
    z0 = Vinv[use] @ np.concatenate([x0, v0])

    transition = np.exp(lam_u * grid.h[:, None])[..., None, None]  # (n_int, r, 1, 1)
    increments = np.zeros((grid.n_intervals, len(use), 1), dtype=complex)
    for lo in range(0, grid.n_intervals, _CHUNK):
        hi = lo + _CHUNK
        kernel = np.exp(lam_u * grid.tau[lo:hi, :, None])  # (c, n_g, r)
        forcing = (grid.weights[lo:hi, :, None] * g[lo:hi]) @ W.T  # (c, n_g, r)
        increments[lo:hi, :, 0] = np.sum(kernel * forcing, axis=1)
    z = grid.at_outputs(_scan(transition, increments, z0[:, None]), z0[:, None])[..., 0]  # (n, r)
    y = ((z * weight) @ V[:, use].T).real
    return y[:, :p], y[:, p:], lam


def _scan(a, d, z0):
    """States (n_int, m, k) after each interval of ``z_{i+1} = a_i z_i + d_i`` (k = 1 or 2)."""
    # Hillis-Steele scan: log2 n vectorized passes; products of transitions cannot overflow (stable modes).
    a, d = a.copy(), d.copy()
    offset = 1
    while offset < a.shape[0]:
        later, earlier = slice(offset, None), slice(None, -offset)
        d[later] = _matvec(a[later], d[earlier]) + d[later]
        a[later] = _matmul(a[later], a[earlier])
        offset *= 2
    return _matvec(a, np.broadcast_to(z0, d.shape)) + d


def _matmul(a, b):
    """Batched product of 1x1 or 2x2 matrices, written out (einsum is slow on tiny matrices)."""
    product = a[..., :, :1] * b[..., :1, :]
    return product if a.shape[-1] == 1 else product + a[..., :, 1:] * b[..., 1:, :]


def _matvec(a, v):
    return _matmul(a, v[..., None])[..., 0]


class _Grid:
    """Quadrature intervals: the output steps, split at breakpoints and to at most ``longest`` or ``max_step`` [s]."""

    def __init__(self, t, breakpoints, n_nodes, max_step, longest):
        if max_step is not None:
            longest = min(number(max_step, "max_step", "a positive duration in s", low=0.0, strict=True), longest)
        nodes = np.union1d(t, breakpoints[(breakpoints > t[0]) & (breakpoints < t[-1])])
        h = np.diff(nodes)
        parts = np.maximum(np.ceil(h / longest).astype(np.int64), 1)
        if np.any(parts > 1):
            if int(np.sum(parts)) > 50_000_000:
                raise InputError("max_step", "a step giving at most 5e7 intervals", max_step)
            start = np.repeat(nodes[:-1], parts)
            index = np.arange(len(start)) - np.repeat(np.cumsum(parts) - parts, parts)
            nodes = np.append(start + index * np.repeat(h / parts, parts), nodes[-1])
            h = np.diff(nodes)
        self.t, self.h, self.n_intervals = t, h, len(h)
        self.x, w = np.polynomial.legendre.leggauss(n_nodes)
        s = 0.5 * (1.0 + self.x)  # node position as a fraction of the interval
        self.quadrature_times = nodes[:-1, None] + h[:, None] * s  # (n_int, n_g)
        self.tau = h[:, None] * (1.0 - s)  # time left to the interval's end
        self.weights = 0.5 * h[:, None] * w
        self.output_index = np.searchsorted(nodes, t)  # exact: t is a subset of nodes

    def integrate(self, values, initial):
        """Running integral from ``initial`` at ``t[0]`` of ``values`` (n_int, n_g): at the nodes and the ends."""
        to_nodes, to_end = _integration_matrices(len(self.x))
        half = 0.5 * self.h[:, None]
        within = half * (values @ to_nodes.T)  # from each interval's start to its nodes
        across = half[:, 0] * (values @ to_end)
        ends = initial + np.cumsum(across)
        starts = np.concatenate([[initial], ends[:-1]])
        return starts[:, None] + within, ends

    def at_outputs(self, states, initial):
        """States at the output times from states after each interval and the initial state."""
        return np.concatenate([np.asarray(initial)[None], states], axis=0)[self.output_index]


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

    The integrals are exact on the quadrature grid: on each interval (never straddling a breakpoint) the
    integrand's interpolating polynomial at the Gauss-Legendre nodes is integrated analytically.

    Parameters
    ----------
    quantity : {"displacement", "velocity", "acceleration"}
    signal : callable
        ``signal(times)`` -> (len(times),) [m, m/s or m/s^2].
    rate : callable or None
        ``d signal / dt`` with the same signature; needed for ``"displacement"`` only.
    k_g, c_g : ndarray, shape (6,)
        ``K r`` [N/m, N] and ``C_g r`` [N s/m, N s]: generalized force per unit ground
        displacement and velocity.
    """

    quantity: str
    signal: object
    rate: object
    k_g: np.ndarray
    c_g: np.ndarray

    def motion(self, grid):
        """``u_g, v_g`` at the quadrature nodes (n_int, n_g) and at the output times (n,)."""
        s_nodes, s_out = (_evaluate(self.signal, x, "ground.signal", ()) for x in (grid.quadrature_times, grid.t))
        if self.quantity == "displacement":
            v_nodes, v_out = (_evaluate(self.rate, x, "ground.signal", ()) for x in (grid.quadrature_times, grid.t))
            return s_nodes, v_nodes, s_out, v_out
        if self.quantity == "velocity":
            u_nodes, u_ends = grid.integrate(s_nodes, 0.0)
            return u_nodes, s_nodes, grid.at_outputs(u_ends, 0.0), s_out
        v_nodes, v_ends = grid.integrate(s_nodes, 0.0)
        u_nodes, u_ends = grid.integrate(v_nodes, 0.0)
        return u_nodes, v_nodes, grid.at_outputs(u_ends, 0.0), grid.at_outputs(v_ends, 0.0)


def _integration_matrices(n):
    """Values at n Gauss-Legendre nodes -> integral of their interpolant from -1 to each node (n, n), to 1 (n,)."""
    x, _ = np.polynomial.legendre.leggauss(n)
    vandermonde = np.polynomial.legendre.legvander(x, n - 1)  # P_k(x_j)
    to_coefficients = np.linalg.inv(vandermonde)
    antiderivatives = np.stack(
        [np.polynomial.legendre.legint(np.eye(n)[k], lbnd=-1.0) for k in range(n)], axis=1
    )  # column k: Legendre coefficients of int_{-1}^x P_k
    at_nodes = np.polynomial.legendre.legvander(x, n) @ antiderivatives
    at_end = np.polynomial.legendre.legvander(np.array([1.0]), n)[0] @ antiderivatives
    return at_nodes @ to_coefficients, at_end @ to_coefficients


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
