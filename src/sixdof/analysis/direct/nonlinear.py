"""Windows with nonlinear mounts: solved region by region, each change of region an event."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from sixdof._jax import jax
from sixdof.analysis.contact import ContactEvents
from sixdof.analysis.direct.settings import SimulationSettings
from sixdof.analysis.direct.solve import REGION_HYSTERESIS, _window_args
from sixdof.analysis.statics import check_pendulum_loads
from sixdof.errors import SolverError, readonly
from sixdof.excitation import Excitation
from sixdof.model.system import System

if TYPE_CHECKING:  # the windows' module imports this one
    from sixdof.analysis.direct.windows import _Run


def is_nonlinear(system: System) -> bool:
    """Whether a mount of ``system`` has a kink in its force law (a bump stop, lift-off or a table that is not
    linear) or a hysteretic law (Bouc-Wen, friction pendulum): then only the direct solve answers it exactly."""
    return bool(np.isfinite(system.nonlinear.knots).any()) or system.hysteretic.count > 0


def _nonlinear_params(system: System, excitation: Excitation, sigma: np.ndarray, settings: SimulationSettings) -> dict:
    """The arrays :func:`_solve_segment` needs besides the linear solve's."""
    check_pendulum_loads(system)
    laws, branches = system.nonlinear, system.branches
    M = np.asarray(system.M, dtype=float)
    K, C = np.asarray(system.K_direct, dtype=float), np.asarray(system.C_direct, dtype=float)
    h = system.hysteretic
    ground = excitation.ground
    scale_d = np.abs(laws.rows) @ sigma[:6]
    energy = 0.5 * float(np.sum(np.diag(M) * sigma[6:12] ** 2))
    return {"laws": {"rows": laws.rows, "knots": laws.knots, "slope": laws.slope, "intercept": laws.intercept,
                     "static": laws.static_deflection, "force": laws.static_force, "tangent": laws.tangent,
                     "hysteresis": REGION_HYSTERESIS * scale_d, "contact": laws.contact, "damping": laws.damping,
                     "lifts": laws.lifts, "lifted_region": laws.lifted_region, "stiffness_scale": laws.stiffness_scale,
                     "branches": laws.branch_map(branches.mount, branches.axis)},
            "hysteresis": {"rows": h.rows, "pendulum": h.pendulum.astype(float), "stiffness": h.stiffness,
                           "strength": h.strength, "mu_fast": h.mu_fast, "rate": h.rate,
                           "yield_displacement": h.yield_displacement, "exponent": h.exponent, "beta": h.beta,
                           "gamma": h.gamma, "coupled": h.coupled, "load_row": h.load_row,
                           "load_stiffness": h.load_stiffness, "load_damping": h.load_damping,
                           "static_load": h.static_load},
            "Minv": np.linalg.inv(M), "C": C, "K": K, "R": branches.rows.reshape(-1, 6),
            "k_b": branches.stiffness, "tau": branches.tau,
            "r": np.zeros(6) if ground is None else ground.rigid_vector, "energy_scale": np.full(2, energy),
            # Steps capped so that no contact lasting min_contact_s is missed; hysteretic laws alone are smooth, with
            # no event to miss: the step control alone sets their steps.
            "dtmax": np.float64(settings.min_contact_s / 2 if laws.count else np.inf)}


#: Consecutive events a window may have without the solve moving on (a contact chattering on a knot).
MAX_STALLED_EVENTS = 100


def _segments(run: _Run, xs0: np.ndarray, region: np.ndarray, saves: np.ndarray, end: float, jumps: np.ndarray,
              settings: SimulationSettings):
    """A window with nonlinear mounts: solved region by region (:func:`_solve_segment`), each from the event
    that ended the previous one. Returns what the linear window solve does, and the work, dissipation and
    :class:`~sixdof.analysis.contact.ContactEvents` of the window, and the regions at its end."""
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
    nb = params["k_b"].size
    return d, rate, params["laws"]["branches"] @ x[14:14 + nb]


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
