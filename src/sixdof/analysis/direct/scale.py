"""The per-component scale of the state, so that the tolerances hold relative to each component's expected size."""

from __future__ import annotations

import numpy as np

from sixdof.analysis.direct.settings import SimulationSettings
from sixdof.excitation import Excitation
from sixdof.model.system import System

#: A state component's scale is at least this fraction of the largest, in energy-consistent units
#: (scale times sqrt(M_ii)): DOFs that only couple in through non-proportional damping still get a
#: finite, small tolerance instead of an infinitely tight or a meaningless one.
SCALE_FLOOR = 1e-6


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
    ndarray, shape (14 + nb + nh,)
        ``[z (6) m, rad; w (6) m/s, rad/s; u_g m; v_g m/s; f (nb) N; h (nh) 1]``, all > 0: a hysteretic variable's
        is 1, the bound of ``|h|``.
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
        return np.ones(14 + branches.count + system.hysteretic.count)

    def floored(x):
        floor = SCALE_FLOOR * np.max(x * root_m)
        return np.maximum(x, floor / root_m) if floor > 0 else np.where(x > 0, x, 1.0)

    z, w = floored(z), floored(w)
    return np.concatenate([z, w, [ground_u, ground_v], branches.stiffness * (np.abs(branches.rows) @ z),
                           np.ones(system.hysteretic.count)])


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
