"""What nonlinear mounts did during a run, and the run's energy balance (its cross-check while they engage).

The direct solve (:mod:`sixdof.analysis.direct`) records every change of a nonlinear mount's region
(:mod:`sixdof.model.nonlinear`) as it locates it: :class:`ContactEvents`. :func:`contact_summary` turns them,
with the sampled motion, into when and where each mount engaged (contact intervals of bump stops, lift-off
times, peak penetration). :func:`energy_balance` checks the solve: the work of the loads and the ground equals
the kinetic, stored and dissipated energy, to within the integration error.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from sixdof.errors import readonly
from sixdof.results import Result, label, quantity, result_type

#: Largest acceptable energy balance residual, relative to the largest energy of the run.
ENERGY_TOLERANCE = 1e-6


@result_type
@dataclass(frozen=True, eq=False)
class ContactEvents(Result):
    """Every change of region of a nonlinear mount axis during a run, as the solver located it.

    Attributes
    ----------
    names : tuple of str
        The nonlinear axes (``"<mount> <axis>"``, :attr:`sixdof.model.system.System.nonlinear`).
    static_region : ndarray of int, shape (law,)
        Each axis's region at the static equilibrium: outside it the axis is *engaged*.
    t : ndarray, shape (event,)
        Time of each event [s].
    law : ndarray of int, shape (event,)
        The axis that changed region.
    region_from, region_to : ndarray of int, shape (event,)
    """

    names: tuple[str, ...] = quantity("", ("law",), name="law", decode=lambda a: tuple(str(n) for n in a))
    static_region: np.ndarray = quantity("1", ("law",), decode=lambda a: np.asarray(a, dtype=np.int64),
                                         description="region of each nonlinear mount axis at rest")
    t: np.ndarray = quantity("s", ("event",), name="event_t", description="time of each change of contact state")
    law: np.ndarray = quantity("1", ("event",), name="event_law", decode=lambda a: np.asarray(a, dtype=np.int64),
                               description="nonlinear mount axis of each event (index into law)")
    region_from: np.ndarray = quantity("1", ("event",), name="event_region_from",
                                       decode=lambda a: np.asarray(a, dtype=np.int64),
                                       description="region of the axis before the event")
    region_to: np.ndarray = quantity("1", ("event",), name="event_region_to",
                                     decode=lambda a: np.asarray(a, dtype=np.int64),
                                     description="region of the axis after the event")

    @property
    def count(self) -> int:
        return int(self.t.size)


def merge_events(parts) -> ContactEvents:
    """The :class:`ContactEvents` of consecutive windows joined."""
    first = parts[0]
    return ContactEvents(names=first.names, static_region=first.static_region,
                         **{name: np.concatenate([getattr(p, name) for p in parts])
                            for name in ("t", "law", "region_from", "region_to")})


@result_type
@dataclass(frozen=True, eq=False)
class ContactSummary(Result):
    """When and where each nonlinear mount axis engaged over a run.

    Attributes
    ----------
    names, kinds : tuple of str
        The nonlinear axes and what makes each nonlinear.
    engagements : ndarray of int, shape (law,)
        Times each left its static region (contact made, lift-off, table beyond the static piece).
    first_t : ndarray, shape (law,)
        First of them [s] (nan: never).
    engaged_time : ndarray, shape (law,)
        Total time outside the static region [s].
    peak_penetration : ndarray, shape (law,)
        Largest overtravel of a bump stop beyond its clearance [m] (sampled; 0: never; nan: no stop).
    peak_lift : ndarray, shape (law,)
        Largest gap of a mount lifted off [m] (sampled; 0: never; nan: cannot lift off).
    deflection_min, deflection_max : ndarray, shape (law,)
        Extremes of the total deflection (static + dynamic) [m] (sampled).
    interval_law : ndarray of int, shape (interval,)
        The axis of each engaged interval.
    interval_start, interval_end : ndarray, shape (interval,)
        Its start and end [s] (an interval still open at the end of the run ends there).
    first_engaged_t : float
        When the first axis engaged [s] (nan: none did): until then the motion is the linearized one.
    """

    names: tuple[str, ...] = quantity("", ("law",), name="law", decode=lambda a: tuple(str(n) for n in a))
    kinds: tuple[str, ...] = quantity("", ("law",), name="law_kind", decode=lambda a: tuple(str(n) for n in a),
                                      description="what makes each mount axis nonlinear")
    engagements: np.ndarray = quantity("1", ("law",), decode=lambda a: np.asarray(a, dtype=np.int64),
                                       description="times each axis left its region at rest")
    first_t: np.ndarray = quantity("s", ("law",), description="first engagement of each axis (nan: never)")
    engaged_time: np.ndarray = quantity("s", ("law",), description="total time each axis was engaged")
    peak_penetration: np.ndarray = quantity("m", ("law",), description="largest overtravel beyond a bump stop's "
                                            "clearance (sampled; nan: no stop)")
    peak_lift: np.ndarray = quantity("m", ("law",), description="largest lift-off gap (sampled; nan: cannot lift)")
    deflection_min: np.ndarray = quantity("m", ("law",), description="smallest total deflection (sampled)")
    deflection_max: np.ndarray = quantity("m", ("law",), description="largest total deflection (sampled)")
    interval_law: np.ndarray = quantity("1", ("interval",), decode=lambda a: np.asarray(a, dtype=np.int64),
                                        description="nonlinear axis of each engaged interval")
    interval_start: np.ndarray = quantity("s", ("interval",), description="start of each engaged interval")
    interval_end: np.ndarray = quantity("s", ("interval",), description="end of each engaged interval")
    first_engaged_t: float = label()


def contact_summary(system, events: ContactEvents, t: np.ndarray, deflection_min: np.ndarray,
                    deflection_max: np.ndarray) -> ContactSummary:
    """:class:`ContactSummary` of a run from its events, its span ``t`` (ending at the run's end) and the sampled
    extremes of each axis's total deflection (law,) [m] (:func:`deflection_extremes`)."""
    laws = system.nonlinear
    end = float(t[-1])
    engaged = np.zeros(laws.count, dtype=bool)  # while outside the region at rest
    since = np.full(laws.count, np.nan)
    count = np.zeros(laws.count, dtype=np.int64)
    total = np.zeros(laws.count)
    first = np.full(laws.count, np.nan)
    intervals = []
    for when, e, to in zip(events.t, events.law, events.region_to):
        now = bool(to != events.static_region[e])
        if now and not engaged[e]:
            since[e] = when
            count[e] += 1
            first[e] = when if np.isnan(first[e]) else first[e]
        elif engaged[e] and not now:
            intervals.append((e, since[e], when))
            total[e] += when - since[e]
        engaged[e] = now
    for e in np.flatnonzero(engaged):
        intervals.append((int(e), since[e], end))
        total[e] += end - since[e]
    intervals.sort(key=lambda row: (row[1], row[0]))
    stop = np.isfinite(laws.clearance)
    lift = np.array(["lift-off" in kind for kind in laws.kinds], dtype=bool)
    overtravel = np.maximum(np.maximum(deflection_max - laws.clearance, -deflection_min - laws.clearance), 0.0)
    return ContactSummary(
        names=laws.names, kinds=laws.kinds, engagements=count, first_t=readonly(first), engaged_time=readonly(total),
        peak_penetration=readonly(np.where(stop, overtravel, np.nan)),
        peak_lift=readonly(np.where(lift, np.maximum(deflection_max, 0.0), np.nan)),
        deflection_min=readonly(deflection_min), deflection_max=readonly(deflection_max),
        interval_law=readonly([row[0] for row in intervals], np.int64),
        interval_start=readonly([row[1] for row in intervals]), interval_end=readonly([row[2] for row in intervals]),
        first_engaged_t=float(np.nanmin(first)) if np.any(count) else float("nan"),
    )


def total_deflection(system, response) -> np.ndarray:
    """Each nonlinear axis's total deflection (static + dynamic) over a run (n, law) [m]."""
    laws = system.nonlinear
    return laws.static_deflection + response.q_relative @ laws.rows.T


@result_type
@dataclass(frozen=True, eq=False)
class EnergyBalance(Result):
    """The energy balance of a run: ``W = (T + V + D) - (T + V + D)(t0)``, to within the integration error.

    Attributes
    ----------
    t : ndarray, shape (n,)
        [s].
    kinetic, stored, dissipated, work : ndarray, shape (n,)
        Kinetic energy of the body ``T``, energy stored in the mounts ``V`` (springs, stops, tables, Maxwell
        branches; about the static equilibrium), energy dissipated since the start ``D``, work of the loads and
        the ground since the start ``W`` [J].
    residual : ndarray, shape (n,)
        ``T + V + D - W`` less its value at the start of the run [J].
    peak_residual : float
        ``max |residual|`` [J].
    energy_scale : float
        The largest energy of the run: ``T + V``, ``D`` or ``|W|`` [J].
    worst : float
        ``peak_residual / energy_scale``.
    tolerance : float
    ok : bool
    """

    t: np.ndarray = quantity("s", ("t",))
    kinetic: np.ndarray = quantity("J", ("t",), description="kinetic energy of the body")
    stored: np.ndarray = quantity("J", ("t",), description="energy stored in the mounts about static equilibrium")
    dissipated: np.ndarray = quantity("J", ("t",), description="energy dissipated since the start")
    work: np.ndarray = quantity("J", ("t",), description="work of the loads and the ground since the start")
    residual: np.ndarray = quantity("J", ("t",), description="T + V + D - W, less its value at the start")
    peak_residual: float = label()
    energy_scale: float = label()
    worst: float = label()
    tolerance: float = label()
    ok: bool = label(decode=bool)


def with_extremes(balance: EnergyBalance, peak: float, scale: float) -> EnergyBalance:
    """``balance`` judged on the largest residual ``peak`` [J] and the largest energy ``scale`` [J] (a run's, over
    its windows, when ``balance`` holds only some of its samples)."""
    return dataclasses.replace(balance, peak_residual=peak, energy_scale=scale, worst=peak / scale,
                               ok=peak <= balance.tolerance * scale)


def stored_energy(system, response) -> np.ndarray:
    """Energy stored in the mounts about the static equilibrium (n,) [J]: the linearized springs ``z' K z / 2``,
    the nonlinear laws' excess over their tangent, the Maxwell branches' springs ``f^2 / (2 k)``, the hysteretic
    laws' ``p d^2 / 2 + q d_y z^2 / 2`` (:meth:`~sixdof.model.hysteresis.HystereticAxes.stored`). A mount lifted off
    stores nothing in its spring (the direct solve counts what it let go of as dissipated)."""
    z = response.q_relative
    hysteretic = system.hysteretic
    # The hysteretic axes' linearization is no spring of the direct solve: their laws store what they do.
    stored = 0.5 * np.einsum("ni,ij,nj->n", z, np.asarray(system.K_direct), z)
    if hysteretic.count:
        stored = stored + hysteretic.stored(**hysteretic.motion(z, response.qd_relative,
                                                                  response.hysteretic_state)).sum(axis=1)
    laws = system.nonlinear
    branches = system.branches
    if laws.count:
        d = z @ laws.rows.T
        d_s = laws.static_deflection
        branch = 0.0 if not branches.count else (
            response.maxwell_force @ laws.branch_map(branches.mount, branches.axis).T)
        contact = laws.in_contact(d_s + d, response.qd_relative @ laws.rows.T, branch)
        excess = (contact * laws.potential(d_s + d) - laws.potential(d_s) - laws.static_force * d
                  - 0.5 * laws.tangent * d * d)
        stored = stored + excess.sum(axis=1)
    if branches.count:
        stored = stored + (response.maxwell_force ** 2 / (2 * branches.stiffness)).sum(axis=1)
    return stored


def energy_balance(system, response, tolerance: float = ENERGY_TOLERANCE, origin: float | None = None
                   ) -> EnergyBalance:
    """The :class:`EnergyBalance` of a run of ``system`` with nonlinear mounts (its ``response`` carries the
    integrated work and dissipation, :attr:`sixdof.results.TimeHistory.energy_input`).

    ``origin``: ``T + V + D - W`` at the start of the run [J], for a window after the first (default: the
    value at ``response``'s first sample).
    """
    qd = response.qd
    kinetic = 0.5 * np.einsum("ni,ij,nj->n", qd, np.asarray(system.M), qd)
    stored = stored_energy(system, response)
    work, dissipated = response.energy_input, response.energy_dissipated
    balance = kinetic + stored + dissipated - work
    residual = balance - (balance[0] if origin is None else origin)
    peak = float(np.abs(residual).max())
    scale = float(max(np.abs(kinetic + stored).max(), np.abs(dissipated).max(), np.abs(work).max(), 1e-300))
    return with_extremes(EnergyBalance(t=response.t, kinetic=readonly(kinetic), stored=readonly(stored),
                                       dissipated=readonly(dissipated), work=readonly(work),
                                       residual=readonly(residual), peak_residual=peak, energy_scale=scale,
                                       worst=0.0, tolerance=float(tolerance), ok=False), peak, scale)


__all__ = ["ENERGY_TOLERANCE", "ContactEvents", "ContactSummary", "EnergyBalance", "contact_summary",
           "energy_balance", "merge_events", "stored_energy", "total_deflection", "with_extremes"]
