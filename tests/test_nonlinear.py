"""Nonlinear mounts (bump stops, lift-off, force-deflection tables) against independent answers: closed forms of
piecewise-linear single-DOF oscillators (a bilinear spring, a mass dropped onto a stop), an event-driven
integration written here with scipy (its own mount laws and its own assembly, restarted at every change of
contact), the linear solve for a table that is linear, the static equilibrium checked by hand, the energy
balance, and bad input."""

import dataclasses

import numpy as np
import pytest
import scipy.integrate

from sixdof import Maxwell, Mount, Rayleigh, RigidBody, System
from sixdof.analysis.contact import ENERGY_TOLERANCE, contact_summary, energy_balance, total_deflection
from sixdof.analysis.direct import SimulationSettings, is_nonlinear, simulate
from sixdof.analysis.response import mount_forces
from sixdof.analysis.statics import STANDARD_GRAVITY, at_equilibrium, gravity_statics
from sixdof.errors import InputError, ScenarioError
from sixdof.excitation import Excitation, GroundMotion, InitialState, Load
from sixdof.excitation.signals import HalfSine
from sixdof.io.scenario import load_scenario, parse_scenario
from sixdof.model.nonlinear import ForceDeflection
from sixdof.workflows.prepare import prepare
from systems import FOUR_MOUNT_CORNERS
from tolerances import RTOL_DIRECT_EXACT, RTOL_STATICS

# Event times of the direct solve against closed forms, relative to the period of the motion: the events are
# root-found on the solver's dense output a hysteresis of 1e-10 of the deflection scale past the knot, and inherit
# the solve's global error (rtol = atol = 1e-9 on the scaled state). Measured <= 7e-10 over four cycles.
RTOL_EVENT_TIME = 1e-8
# Zero crossings of the sampled response (cubic Hermite interpolation of z and z' between the two samples
# around each crossing) against the closed form, relative to the period: z''' jumps at the crossing (the
# stiffness changes there), so the interpolant is good to ~(omega h)^3 h; measured 2.5e-7 at omega h <= 0.084.
RTOL_ZERO_CROSSING = 1e-6
# Amplitude invariants of a linear piece (z^2 + (z'/omega)^2 about its centre) sampled from the direct solve,
# relative to the amplitude: the solve's global error, measured <= 9e-9.
RTOL_AMPLITUDE = 1e-7
# Event times of the direct solve against scipy's event-located DOP853 (rtol 1e-12), relative to the duration
# of the run: both locate the same crossings to their integration error, measured <= 6e-10.
RTOL_EVENT_REFERENCE = 1e-7
# Two solves of identical matrices and loads (a linear table, the linear mount): the same arithmetic, measured
# equal to the last bit; relative to each DOF's peak.
RTOL_SAME_SOLVE = 1e-13


def corners(a, b, h):
    """Mount points at the corners of a 2a x 2b rectangle, a height h below the CG."""
    return [np.array([sx * a, sy * b, -h]) for sx, sy in FOUR_MOUNT_CORNERS]


def rows_of(position, axes):
    """Each axis's deflection per unit q, written here: the point moves by t + theta x p, so the deflection
    along e is e . t + theta . (p x e)."""
    return np.array([np.concatenate([e, np.cross(position, e)]) for e in axes])


def hermite_roots(t, z, zd):
    """The zero crossings of z between samples, from the cubic Hermite interpolant of (z, z') on each interval
    that changes sign; each with its direction (+1 upward)."""
    crossings = []
    for k in np.flatnonzero(np.sign(z[:-1]) * np.sign(z[1:]) < 0):
        h = t[k + 1] - t[k]
        p0, p1, m0, m1 = z[k], z[k + 1], zd[k] * h, zd[k + 1] * h
        # p(s) = (2s^3 - 3s^2 + 1) p0 + (s^3 - 2s^2 + s) m0 + (-2s^3 + 3s^2) p1 + (s^3 - s^2) m1
        cubic = [2 * p0 + m0 - 2 * p1 + m1, -3 * p0 - 2 * m0 + 3 * p1 - m1, m0, p0]
        roots = [r.real for r in np.roots(cubic) if abs(r.imag) < 1e-9 and -1e-9 <= r.real <= 1 + 1e-9]
        assert len(roots) == 1, roots
        crossings.append((t[k] + roots[0] * h, np.sign(z[k + 1] - z[k])))
    return crossings


# ----------------------------------------------------------------------------------------------------
# 1. A bilinear spring: free vibration in closed form.
# ----------------------------------------------------------------------------------------------------

BI_MASS, BI_K1, BI_K2, BI_V0 = 100.0, 1.0e5, 4.0e5, 0.1  # kg; N/m per mount in extension, compression; m/s


def bilinear_system() -> System:
    """A body on four mounts whose w tables have slope BI_K2 in compression (d < 0) and BI_K1 in extension:
    symmetric, so an initial vertical velocity moves z alone."""
    tables = [ForceDeflection(mount=f"m{i}", axis="w", deflection=[-1.0, 0.0, 1.0], force=[-BI_K2, 0.0, BI_K1])
              for i in range(4)]
    mounts = [Mount(f"m{i}", p, [2e5, 2e5, 3e5]) for i, p in enumerate(corners(0.5, 0.3, 0.0))]
    return System(RigidBody(BI_MASS, [10.0, 12.0, 14.0]), mounts, force_deflection=tables)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_bilinear_free_vibration_period_and_peaks():
    system = bilinear_system()
    w1, w2 = np.sqrt(4 * BI_K1 / BI_MASS), np.sqrt(4 * BI_K2 / BI_MASS)  # extension (up), compression (down)
    period = np.pi / w1 + np.pi / w2
    settings = SimulationSettings(duration=4.25 * period, sample_rate_hz=1500.0)
    excitation = Excitation(initial=InitialState(qd=[0.0, 0.0, BI_V0, 0.0, 0.0, 0.0]))
    history = simulate(system, excitation, settings)
    assert is_nonlinear(system)
    np.testing.assert_array_equal(system.stiffnesses[:, 2], BI_K2)  # at rest on the knot: the compression side

    # Closed form: half a sine at w1 above the rest position, half a sine at w2 below it.
    tau = np.mod(history.t, period)
    up = tau < np.pi / w1
    s = tau - np.pi / w1
    z = np.where(up, BI_V0 / w1 * np.sin(w1 * tau), -BI_V0 / w2 * np.sin(w2 * s))
    zd = np.where(up, BI_V0 * np.cos(w1 * tau), -BI_V0 * np.cos(w2 * s))
    assert np.max(np.abs(history.q[:, 2] - z)) <= RTOL_DIRECT_EXACT * BI_V0 / w1
    assert np.max(np.abs(history.qd[:, 2] - zd)) <= RTOL_DIRECT_EXACT * BI_V0
    assert np.max(np.abs(history.q[:, [0, 1, 3, 4, 5]])) <= RTOL_DIRECT_EXACT * BI_V0 / w1

    # Events: every law leaves compression at n T and enters it at n T + pi / w1 (n = 0 to 4).
    events = history.contacts
    assert events.names == ("m0 w", "m1 w", "m2 w", "m3 w")
    cycles = np.arange(5)
    for law in range(4):
        mine = events.law == law
        rising = events.t[mine & (events.region_from == 0) & (events.region_to == 1)]
        falling = events.t[mine & (events.region_from == 1) & (events.region_to == 0)]
        np.testing.assert_allclose(rising, period * cycles, rtol=0, atol=RTOL_EVENT_TIME * period)
        np.testing.assert_allclose(falling, period * cycles[:4] + np.pi / w1, rtol=0, atol=RTOL_EVENT_TIME * period)
        np.testing.assert_allclose(np.diff(rising), period, rtol=RTOL_EVENT_TIME)
    assert history.stats.num_events == events.count == 4 * 9

    # The period again from the sampled motion: its zero crossings.
    crossings = hermite_roots(history.t, history.q[:, 2], history.qd[:, 2])
    upward = np.array([t for t, sign in crossings if sign > 0])
    downward = np.array([t for t, sign in crossings if sign < 0])
    assert upward.size == downward.size == 4  # the one at t = 0 lies on a sample, not between two
    np.testing.assert_allclose(np.diff(upward), period, rtol=RTOL_ZERO_CROSSING)
    np.testing.assert_allclose(upward, period * cycles[1:], rtol=0, atol=RTOL_ZERO_CROSSING * period)
    np.testing.assert_allclose(downward, period * cycles[:4] + np.pi / w1, rtol=0, atol=RTOL_ZERO_CROSSING * period)

    # Peaks: v0 / w1 above, v0 / w2 below, from the amplitude of each side's samples ...
    q, qd = history.q[:, 2], history.qd[:, 2]
    above, below = q > 0, q < 0
    np.testing.assert_allclose(np.hypot(q[above], qd[above] / w1), BI_V0 / w1, rtol=RTOL_AMPLITUDE)
    np.testing.assert_allclose(np.hypot(q[below], qd[below] / w2), BI_V0 / w2, rtol=RTOL_AMPLITUDE)
    # ... and the sampled extremes, which reach them to within the sampling (cos(w h / 2) of the peak).
    h = 1.0 / settings.sample_rate_hz
    assert BI_V0 / w1 * np.cos(w1 * h / 2) <= q.max() <= BI_V0 / w1 * (1 + RTOL_AMPLITUDE)
    assert BI_V0 / w2 * np.cos(w2 * h / 2) <= -q.min() <= BI_V0 / w2 * (1 + RTOL_AMPLITUDE)


# ----------------------------------------------------------------------------------------------------
# 2. A mass dropped onto a bump stop: the impact in closed form.
# ----------------------------------------------------------------------------------------------------

DROP_MASS, DROP_K, DROP_KS, DROP_C, DROP_V0 = 100.0, 2.5e4, 1.0e6, 0.015, 0.5  # kg, N/m, N/m, m, m/s


def drop_system() -> System:
    """A body on four mounts soft in w (DROP_K each) with bump stops on w (DROP_C, DROP_KS), at rest under
    gravity (9.8 mm down, inside the clearance): symmetric, so a vertical velocity moves z alone."""
    mounts = [Mount(f"m{i}", p, [2e5, 2e5, DROP_K], bump_clearance=[np.inf, np.inf, DROP_C],
                    bump_stiffness=[0.0, 0.0, DROP_KS]) for i, p in enumerate(corners(0.4, 0.3, 0.1))]
    system = System(RigidBody(DROP_MASS, [10.0, 12.0, 14.0]), mounts)
    return at_equilibrium(system, gravity_statics(system))


def drop_closed_form(t):
    """z, z' of the body released downwards at DROP_V0 from rest under gravity, about the static equilibrium, and
    the impact's characteristics, derived by hand for the piecewise-linear oscillator

        m z'' = -K z - K_s min(z - z_c, 0),   K = 4 k, K_s = 4 k_s,  z_c = -(c - m g / K):

    free at w = sqrt(K / m) above the contact point z_c (where the stops' clearance is taken up); in contact at
    W = sqrt((K + K_s) / m) about the centre z* = K_s z_c / (K + K_s)."""
    K, KS = 4 * DROP_K, 4 * DROP_KS
    w, W = np.sqrt(K / DROP_MASS), np.sqrt((K + KS) / DROP_MASS)
    zc = -(DROP_C - DROP_MASS * STANDARD_GRAVITY / K)
    t1 = np.arcsin(-zc * w / DROP_V0) / w  # z = -v0 / w sin(w t) reaches z_c
    v1 = -np.sqrt(DROP_V0**2 - (w * zc) ** 2)  # the velocity there
    centre = KS * zc / (K + KS)
    y1 = zc - centre  # y = z - z* = y1 cos(W s) + v1 / W sin(W s) = B sin(W s + theta)
    B = np.hypot(y1, v1 / W)
    theta = np.arctan2(y1, v1 / W)  # third quadrant: y1 < 0, v1 < 0
    contact = (-np.pi - 2 * theta) / W  # back at y1, with y' = -v1
    psi = np.arcsin(zc * w / DROP_V0)  # free flight z = v0 / w sin(w u + psi) from z_c up and back to z_c
    flight = (np.pi - 2 * psi) / w
    cycle = contact + flight
    s = np.mod(t - t1, cycle)
    inside = s < contact
    u = s - contact
    z = np.where(t < t1, -DROP_V0 / w * np.sin(w * t),
                 np.where(inside, centre + y1 * np.cos(W * s) + v1 / W * np.sin(W * s),
                          zc * np.cos(w * u) - v1 / w * np.sin(w * u)))
    zd = np.where(t < t1, -DROP_V0 * np.cos(w * t),
                  np.where(inside, -y1 * W * np.sin(W * s) + v1 * np.cos(W * s),
                           -zc * w * np.sin(w * u) - v1 * np.cos(w * u)))
    impact = dict(start=t1, duration=contact, cycle=cycle, penetration=y1 + B, rebound=-v1, zc=zc, centre=centre,
                  amplitude=B, w=w, W=W)
    return z, zd, impact


@pytest.mark.slow  # 2 s on the 2-core machine
def test_drop_onto_a_bump_stop():
    system = drop_system()
    settings = SimulationSettings(duration=0.26, sample_rate_hz=1500.0)
    excitation = Excitation(initial=InitialState(qd=[0.0, 0.0, -DROP_V0, 0.0, 0.0, 0.0]))
    history = simulate(system, excitation, settings)
    z, zd, impact = drop_closed_form(history.t)
    # The equilibrium the motion is about: the weight on the mounts' linear springs, inside the clearance.
    np.testing.assert_allclose(system.equilibrium[2], -DROP_MASS * STANDARD_GRAVITY / (4 * DROP_K), rtol=RTOL_STATICS)
    np.testing.assert_array_equal(system.stiffnesses[:, 2], DROP_K)

    peak = DROP_V0 / impact["w"]
    assert np.max(np.abs(history.q[:, 2] - z)) <= RTOL_DIRECT_EXACT * peak
    assert np.max(np.abs(history.qd[:, 2] - zd)) <= RTOL_DIRECT_EXACT * DROP_V0
    assert np.max(np.abs(history.q[:, [0, 1, 3, 4, 5]])) <= RTOL_DIRECT_EXACT * peak

    # Contact starts and ends, per stop: two impacts in the run.
    starts = impact["start"] + impact["cycle"] * np.arange(2)
    ends = starts + impact["duration"]
    assert ends[-1] < settings.duration < starts[-1] + impact["cycle"]
    events = history.contacts
    for law in range(4):
        mine = events.law == law
        np.testing.assert_allclose(events.t[mine & (events.region_from == 1) & (events.region_to == 0)], starts,
                                   rtol=0, atol=RTOL_EVENT_TIME * impact["cycle"])
        np.testing.assert_allclose(events.t[mine & (events.region_from == 0) & (events.region_to == 1)], ends,
                                   rtol=0, atol=RTOL_EVENT_TIME * impact["cycle"])
    assert events.count == 16 and np.all(events.region_to <= 1)  # never onto the stops above

    # In contact the motion is a sine about the shifted centre: its amplitude gives the peak penetration.
    q, qd = history.q[:, 2], history.qd[:, 2]
    touching = q < impact["zc"]
    assert touching.sum() >= 2 * 8  # a few samples of each impact
    amplitude = np.hypot(q[touching] - impact["centre"], qd[touching] / impact["W"])
    np.testing.assert_allclose(amplitude, impact["amplitude"], rtol=RTOL_AMPLITUDE)
    # Rebound: free again, the velocity it left the stop with, from each free sample's energy.
    free = (history.t > ends[0]) & (history.t < starts[1])
    rebound = np.sqrt(qd[free] ** 2 + impact["w"] ** 2 * (q[free] ** 2 - impact["zc"] ** 2))
    np.testing.assert_allclose(rebound, impact["rebound"], rtol=RTOL_AMPLITUDE)
    assert impact["rebound"] < DROP_V0  # the mounts' springs took some of the drop's speed before the contact

    # The contact summary: intervals, time engaged, sampled peak penetration (within the sampling).
    deflection = total_deflection(system, history)
    summary = contact_summary(system, events, history.t, deflection.min(axis=0), deflection.max(axis=0))
    np.testing.assert_array_equal(summary.engagements, 2)
    on_time = RTOL_EVENT_TIME * impact["cycle"]
    np.testing.assert_allclose(summary.engaged_time, 2 * impact["duration"], rtol=0, atol=4 * on_time)
    np.testing.assert_allclose(summary.interval_start, np.repeat(starts, 4), rtol=0, atol=on_time)
    np.testing.assert_allclose(summary.interval_end, np.repeat(ends, 4), rtol=0, atol=on_time)
    h = 1.0 / settings.sample_rate_hz
    sampling = impact["amplitude"] * (1 - np.cos(impact["W"] * h / 2))
    penetration = impact["penetration"]
    assert np.all(summary.peak_penetration <= penetration * (1 + RTOL_AMPLITUDE))
    assert np.all(summary.peak_penetration >= penetration - sampling)
    assert 0.1 * DROP_C < penetration < DROP_C  # a real impact, not a graze


# ----------------------------------------------------------------------------------------------------
# 3. Lift-off and bump stops under an uplift pulse: an event-driven integration written here.
# ----------------------------------------------------------------------------------------------------

LIFT_MASS, LIFT_INERTIA = 200.0, np.array([20.0, 30.0, 40.0])  # kg, kg m^2
LIFT_KUV, LIFT_KW, LIFT_KS, LIFT_C = 1.5e5, 4.0e5, 4.0e6, 2.0e-3  # N/m, N/m, N/m, m
LIFT_ALPHA = 3.0  # 1/s: Rayleigh C = alpha M (about 2 % at the bounce, 14 Hz)
LIFT_POSITIONS = corners(0.4, 0.3, 0.2)
LIFT_POINT = np.array([0.4, 0.3, 0.1])  # m: above mount m2
LIFT_PULSE = (0.01, 0.04)  # s: start, duration of the half-sine
LIFT_SETTINGS = SimulationSettings(duration=0.3, sample_rate_hz=1500.0)


def lift_system() -> System:
    """A body resting under gravity on four mounts that lift off (tension = False), with bump stops on w
    0.77 mm beyond their static compression (1.23 mm)."""
    mounts = [Mount(f"m{i}", p, [LIFT_KUV, LIFT_KUV, LIFT_KW], bump_clearance=[np.inf, np.inf, LIFT_C],
                    bump_stiffness=[0.0, 0.0, LIFT_KS], tension=False) for i, p in enumerate(LIFT_POSITIONS)]
    system = System(RigidBody(LIFT_MASS, LIFT_INERTIA), mounts, rayleigh=Rayleigh(LIFT_ALPHA, 0.0))
    return at_equilibrium(system, gravity_statics(system))


def uplift(peak: float) -> tuple[Excitation, np.ndarray]:
    """A half-sine force, mostly upwards, at LIFT_POINT; and its generalized force, written here."""
    force = peak * np.array([0.3, -0.2, 1.0])
    start, duration = LIFT_PULSE
    load = Load("uplift", LIFT_POINT, force=force, signal=HalfSine(start=start, duration=duration))
    return Excitation(loads=[load]), np.concatenate([force, np.cross(LIFT_POINT, force)])


def stop_and_lift_law(region: int) -> tuple[float, float]:
    """Intercept [N] and slope [N/m] of the w law written here, by region: the stop engaged (d < -c), the
    mount's spring (-c <= d <= 0), lifted off (d > 0)."""
    return [(LIFT_KS * LIFT_C, LIFT_KW + LIFT_KS), (0.0, LIFT_KW), (0.0, 0.0)][region]


LIFT_KNOTS = (-LIFT_C, 0.0)


def event_driven_reference(Q_load, times):
    """The lift-off system integrated with scipy's DOP853 region by region, restarted at every change of a
    mount's region (located by solve_ivp's events), from rest in static equilibrium:

        M q'' + C q' + sum_j L_j' r_j(L_j (q_s + q)) = W + Q(t)

    with the rows L_j, the weight W, the equilibrium q_s and the laws r_j all written here. Two more states
    integrate the loads' work Q(t) . q' and the dissipation q' C q'. Returns the states at ``times`` (n, 14)
    and the events (t, mount, region before, region after)."""
    rows = np.concatenate([rows_of(p, np.eye(3)) for p in LIFT_POSITIONS])  # (12, 6): u, v, w of each mount
    k = np.tile([LIFT_KUV, LIFT_KUV, LIFT_KW], 4)
    w_rows = rows[2::3]
    M = np.diag(np.concatenate([[LIFT_MASS] * 3, LIFT_INERTIA]))
    C, M_inv = LIFT_ALPHA * M, np.linalg.inv(M)
    W = np.array([0.0, 0.0, -LIFT_MASS * STANDARD_GRAVITY, 0.0, 0.0, 0.0])
    q_s = np.linalg.solve(rows.T @ (k[:, None] * rows), W)  # every mount in its spring's region at rest
    assert np.all((w_rows @ q_s > -LIFT_C) & (w_rows @ q_s < 0))
    start, duration = LIFT_PULSE

    def load(t):
        return Q_load * np.sin(np.pi * (t - start) / duration) if start <= t < start + duration else 0.0 * Q_load

    def field(t, x, regions):
        q, v = x[:6], x[6:12]
        d = rows @ (q_s + q)
        r = k * d
        for j, region in enumerate(regions):
            intercept, slope = stop_and_lift_law(region)
            r[3 * j + 2] = intercept + slope * d[3 * j + 2]
        Q = load(t)
        a = M_inv @ (W + Q - C @ v - rows.T @ r)
        return np.concatenate([v, a, [Q @ v, v @ C @ v]])

    def crossing(j, knot, direction):
        def event(t, x, regions):
            return w_rows[j] @ (q_s + x[:6]) - knot
        event.terminal, event.direction = True, direction
        return event

    edges = (-np.inf, *LIFT_KNOTS, np.inf)
    x, t, regions = np.zeros(14), 0.0, [1, 1, 1, 1]
    out, events = np.full((times.size, 14), np.nan), []
    ends = sorted({start, start + duration, times[-1]})
    while t < times[-1]:
        stop = min(e for e in ends if e > t)
        watched = [(j, s) for j in range(4) for s in (0, 1) if np.isfinite(edges[regions[j] + s])]
        solution = scipy.integrate.solve_ivp(
            field, (t, stop), x, method="DOP853", rtol=1e-12, atol=1e-15, args=(regions,), dense_output=True,
            events=[crossing(j, edges[regions[j] + s], 1 if s else -1) for j, s in watched])
        assert solution.success
        end = solution.t[-1]
        inside = (times >= t) & (times <= end)
        if inside.any():
            out[inside] = solution.sol(times[inside]).T
        x, t = solution.y[:, -1], end
        if solution.status == 1:  # a mount reached a knot: across it into the next region
            for (j, s), found in zip(watched, solution.t_events):
                if found.size:
                    events.append((end, j, regions[j], regions[j] + (1 if s else -1)))
                    regions = list(regions)
                    regions[j] += 1 if s else -1
    return out, events


@pytest.fixture(scope="module")
def lifting():
    """The lift-off system under a 500 N uplift pulse: sixdof's run and the reference."""
    system = lift_system()
    excitation, Q_load = uplift(500.0)
    history = simulate(system, excitation, LIFT_SETTINGS)
    reference, events = event_driven_reference(Q_load, history.t)
    return system, history, reference, events


@pytest.mark.slow  # 4 s on the 2-core machine
def test_lift_off_matches_an_event_driven_reference(lifting):
    system, history, reference, events = lifting
    assert system.nonlinear.names == ("m0 w", "m1 w", "m2 w", "m3 w")
    np.testing.assert_array_equal(system.nonlinear.static_region, 1)  # all four on their springs at rest
    # Per DOF, relative to each DOF's peak (every DOF moves: the force has all three components).
    for name, columns in (("q", slice(0, 6)), ("qd", slice(6, 12))):
        exact = reference[:, columns]
        error = np.max(np.abs(getattr(history, name) - exact), axis=0) / np.max(np.abs(exact), axis=0)
        assert np.all(error <= RTOL_DIRECT_EXACT), (name, error)
    # The same changes of contact, in the same order, at the same times.
    library = list(zip(history.contacts.law.tolist(), history.contacts.region_from.tolist(),
                       history.contacts.region_to.tolist()))
    assert library == [(j, a, b) for _, j, a, b in events]
    np.testing.assert_allclose(history.contacts.t, [e[0] for e in events], rtol=0,
                               atol=RTOL_EVENT_REFERENCE * LIFT_SETTINGS.duration)
    # Lift-off per mount: m2, under the load, lifts off (and comes down onto its stop); the others never do.
    for j in range(4):
        lifts = [t for t, mount, a, b in events if mount == j and (a, b) == (1, 2)]
        mine = history.contacts.t[(history.contacts.law == j) & (history.contacts.region_to == 2)]
        np.testing.assert_allclose(mine, lifts, rtol=0, atol=RTOL_EVENT_REFERENCE * LIFT_SETTINGS.duration)
        assert (len(lifts) > 0) == (j == 2)
    assert any(mount == 2 and b == 0 for _, mount, _, b in events)  # onto the stop


@pytest.mark.slow  # 4 s on the 2-core machine
def test_contacts_changing_within_one_step_are_located_in_time_order():
    """A stronger pulse: m2 lifts off 44 us before m0 reaches its stop, inside one step of the solve. Both are
    found, the earlier first: a solve that root-finds only one change per step records the lift-off late, at
    m0's contact, and misses the motion by ~1e-5 of its peaks."""
    system = lift_system()
    excitation, Q_load = uplift(700.0)
    history = simulate(system, excitation, LIFT_SETTINGS)
    reference, events = event_driven_reference(Q_load, history.t)
    np.testing.assert_allclose(history.contacts.t, [e[0] for e in events], rtol=0,
                               atol=RTOL_EVENT_REFERENCE * LIFT_SETTINGS.duration)
    exact = reference[:, :6]
    error = np.max(np.abs(history.q - exact), axis=0) / np.max(np.abs(exact), axis=0)
    assert np.all(error <= RTOL_DIRECT_EXACT), error


# ----------------------------------------------------------------------------------------------------
# 3b. A unilateral spring and dashpot: the whole mount carries no tension (issue 45).
# ----------------------------------------------------------------------------------------------------

KV_MASS, KV_K, KV_C, KV_V0 = 100.0, 2.5e4, 300.0, 0.5  # kg; N/m, N s/m per mount along w; m/s upwards
KV_TAU = 0.01  # s: relaxation time of a Maxwell branch


def kelvin_voigt_system(branch: float) -> System:
    """A body on four mounts along w that lift off (spring KV_K and dashpot KV_C in parallel, and a Maxwell branch
    of stiffness ``branch`` [N/m] and KV_TAU if ``branch`` > 0), at rest under gravity: symmetric, so a vertical
    velocity moves z alone, m z'' = -m g - min(K d + C d' + F_b, 0) (K = 4 k, C = 4 c, zeta = 0.19, F_b the
    branches' force) while the mounts touch (d < 0), nothing else while they have lifted off."""
    mounts = [Mount(f"m{i}", p, [2e5, 2e5, KV_K], damping=[0.0, 0.0, KV_C], tension=False)
              for i, p in enumerate(corners(0.4, 0.3, 0.1))]
    branches = [Maxwell(f"b{i}", f"m{i}", [0.0, 0.0, branch], KV_TAU) for i in range(4)] if branch else []
    system = System(RigidBody(KV_MASS, [10.0, 12.0, 14.0]), mounts, maxwell=branches)
    return at_equilibrium(system, gravity_statics(system))


def kelvin_voigt_reference(times, branch: float):
    """The total deflection d and its rate of the body thrown upwards at KV_V0 from rest, integrated here with
    scipy's DOP853 phase by phase: in contact until the load K d + C d' + F_b reaches zero (it pulls from then on),
    in flight (d'' = -g) until d < 0 and K d + C d' + F_b < 0 both hold. The branches' force follows
    F_b' = 4 k_b d' - F_b / tau in contact, F_b' = -F_b / tau (unloaded) in flight. Returns (n, 3) and the events
    (t, "lift"/"touch", d)."""
    K, C, KB, g = 4 * KV_K, 4 * KV_C, 4 * branch, STANDARD_GRAVITY

    def contact(t, y):
        return [y[1], -g - (K * y[0] + C * y[1] + y[2]) / KV_MASS, KB * y[1] - y[2] / KV_TAU]

    def flight(t, y):
        return [y[1], -g, -y[2] / KV_TAU]

    def lifts(t, y):
        return K * y[0] + C * y[1] + y[2]

    def touches(t, y):
        return max(y[0], lifts(t, y) / K)

    lifts.terminal = touches.terminal = True
    lifts.direction, touches.direction = 1, -1
    y, t, touching = np.array([-KV_MASS * g / K, KV_V0, 0.0]), 0.0, True
    out, events = np.full((times.size, 3), np.nan), []
    while t < times[-1]:
        solution = scipy.integrate.solve_ivp(contact if touching else flight, (t, times[-1]), y, method="DOP853",
                                             rtol=1e-12, atol=1e-15, events=lifts if touching else touches,
                                             dense_output=True)
        assert solution.success
        inside = (times >= t) & (times <= solution.t[-1])
        out[inside] = solution.sol(times[inside]).T
        y, t = solution.y[:, -1], solution.t[-1]
        if solution.status == 1:
            events.append((t, "lift" if touching else "touch", y[0]))
            touching = not touching
    return out, events


@pytest.mark.slow  # 3 s each on the 2-core machine
@pytest.mark.parametrize("branch", [0.0, 2.0e4], ids=["spring and dashpot", "with a Maxwell branch"])
def test_a_spring_and_dashpot_that_cannot_pull_lift_off_where_their_load_turns(branch):
    system = kelvin_voigt_system(branch)
    settings = SimulationSettings(duration=0.5, sample_rate_hz=2000.0)
    history = simulate(system, Excitation(initial=InitialState(qd=[0.0, 0.0, KV_V0, 0.0, 0.0, 0.0])), settings)
    reference, events = kelvin_voigt_reference(history.t, branch)
    static = system.equilibrium[2]
    np.testing.assert_allclose(static, -KV_MASS * STANDARD_GRAVITY / (4 * KV_K), rtol=RTOL_STATICS)
    for mine, exact in ((static + history.q[:, 2], reference[:, 0]), (history.qd[:, 2], reference[:, 1])):
        assert np.max(np.abs(mine - exact)) <= RTOL_DIRECT_EXACT * np.max(np.abs(exact))
    if branch:
        force = history.maxwell_force.sum(axis=1)
        assert np.max(np.abs(force - reference[:, 2])) <= RTOL_DIRECT_EXACT * np.max(np.abs(reference[:, 2]))
    # One lift-off and one touch-down, per mount, at the reference's times: the lift-off 5 or 7 mm below the unloaded
    # mount (the dashpot would pull from there), not where the spring's deflection crosses zero.
    assert [kind for _, kind, _ in events] == ["lift", "touch"]
    lift, touch = events[0][0], events[1][0]
    assert events[0][2] < -2e-3 and abs(events[1][2]) < 1e-12
    contacts = history.contacts
    np.testing.assert_array_equal(contacts.law, np.repeat(np.arange(4)[None], 2, axis=0).ravel())
    np.testing.assert_array_equal(contacts.region_to, [1] * 4 + [0] * 4)  # lifted, then in contact again
    np.testing.assert_allclose(contacts.t, np.repeat([lift, touch], 4), rtol=0,
                               atol=RTOL_EVENT_TIME * settings.duration)
    # No mount ever pulls: the w load of each, static included, is <= 0 but for round-off, and 0 while lifted.
    forces = mount_forces(system, history)
    w = system.nonlinear.static_force[:, None] + forces.local[:, :, 2]
    assert w.max() <= 1e-12 * np.abs(w).max()
    flying = (history.t > lift) & (history.t < touch)
    assert flying.sum() > 100 and np.all(w[:, flying] == 0.0)
    balance = energy_balance(system, history)  # the spring's 0.5 J let go of at lift-off counted as dissipated
    assert balance.ok, balance.worst


GROUND_DROP, GROUND_PULSE = -0.02, (0.01, 0.02)  # m; s: start, duration of the half-sine ground displacement


def dropping_ground_reference(times):
    """The body of :func:`kelvin_voigt_system` (no branch) at rest when the ground drops GROUND_DROP and comes back
    in a half-sine, integrated here with scipy's DOP853 in the body's absolute displacement y about its rest
    position, piece by piece of the ground's motion (its velocity jumps at the pulse's ends) and phase by phase of
    the contact: d = d_s + y - u_g, d' = y' - v_g, y'' = -g - min(K d + C d', 0) / m while in contact (until the
    load reaches zero, or jumps past it at a piece's start), y'' = -g in flight (until d < 0 and the load < 0).
    Returns y, y' (n, 2) and the times of the events with their kinds."""
    K, C, g = 4 * KV_K, 4 * KV_C, STANDARD_GRAVITY
    start, duration = GROUND_PULSE
    d_s = -KV_MASS * g / K

    def ground(t, pulse):  # u_g, v_g, on a piece of the motion (the pulse's or not) up to its ends included
        if pulse:
            phase = np.pi * (t - start) / duration
            return GROUND_DROP * np.sin(phase), GROUND_DROP * np.pi / duration * np.cos(phase)
        return 0.0, 0.0

    def load(t, y, pulse):
        u, v = ground(t, pulse)
        return K * (d_s + y[0] - u) + C * (y[1] - v)

    def contact(t, y, pulse):
        return [y[1], -g - load(t, y, pulse) / KV_MASS]

    def flight(t, y, pulse):
        return [y[1], -g]

    def lifts(t, y, pulse):
        return load(t, y, pulse)

    def touches(t, y, pulse):
        return max(d_s + y[0] - ground(t, pulse)[0], load(t, y, pulse) / K)

    lifts.terminal = touches.terminal = True
    lifts.direction, touches.direction = 1, -1
    y, t, touching = np.zeros(2), 0.0, True
    out, events = np.full((times.size, 2), np.nan), []
    ends = [start, start + duration, times[-1]]
    while t < times[-1]:
        pulse = start <= t < start + duration
        if touching and lifts(t, y, pulse) > 0 or not touching and touches(t, y, pulse) < 0:  # jumped past zero
            events.append((t, "lift" if touching else "touch"))
            touching = not touching
        stop = min(e for e in ends if e > t)
        solution = scipy.integrate.solve_ivp(contact if touching else flight, (t, stop), y, method="DOP853",
                                             rtol=1e-12, atol=1e-15, events=lifts if touching else touches,
                                             dense_output=True, args=(pulse,))
        assert solution.success
        inside = (times >= t) & (times <= solution.t[-1])
        out[inside] = solution.sol(times[inside]).T
        y, t = solution.y[:, -1], solution.t[-1]
        if solution.status == 1:
            events.append((t, "lift" if touching else "touch"))
            touching = not touching
    return out, events


@pytest.mark.long  # over 10 s on the 2-core machine
def test_lift_off_when_the_ground_drops_away_with_a_jump_in_its_velocity():
    """The ground's velocity jumps at the pulse's ends: the mounts' dashpot load jumps past zero there, which no step
    brackets (it changes between one step's end and the next one's start). The body lifts off at the pulse's start,
    and the ground comes back up into it 16 ms later."""
    system = kelvin_voigt_system(0.0)
    signal = HalfSine(start=GROUND_PULSE[0], duration=GROUND_PULSE[1])
    excitation = Excitation(ground=GroundMotion(quantity="displacement", direction=[0.0, 0.0, 1.0], signal=signal,
                                                scale=GROUND_DROP))
    settings = SimulationSettings(duration=0.3, sample_rate_hz=2000.0)
    history = simulate(system, excitation, settings)
    reference, events = dropping_ground_reference(history.t)
    for mine, exact in ((history.q[:, 2], reference[:, 0]), (history.qd[:, 2], reference[:, 1])):
        assert np.max(np.abs(mine - exact)) <= RTOL_DIRECT_EXACT * np.max(np.abs(exact))
    assert [kind for _, kind in events] == ["lift", "touch"] and events[0][0] == GROUND_PULSE[0]
    contacts = history.contacts
    for law in range(4):
        mine = contacts.law == law
        np.testing.assert_array_equal(contacts.region_to[mine], [1 if kind == "lift" else 0 for _, kind in events])
        np.testing.assert_allclose(contacts.t[mine], [t for t, _ in events], rtol=0,
                                   atol=RTOL_EVENT_TIME * settings.duration)
    w = system.nonlinear.static_force[:, None] + mount_forces(system, history).local[:, :, 2]
    assert w.max() <= 1e-12 * np.abs(w).max()
    assert energy_balance(system, history).ok


@pytest.mark.long  # ~30 s on 2 cores: 4 s of the bridge at a 0.5 ms step cap
def test_bridge_bearings_that_cannot_pull_never_pull():
    """bridge_beam_uplift: bearings 3 and 4 lift off, and none of the four, all tension = false, ever pulls (its
    largest w load, static included, is <= 0 but for round-off; the dashpots used to pull 0.82 kN first)."""
    scenario = prepare(load_scenario("scenarios/bridge_beam_uplift.toml"))
    system = scenario.system
    history = simulate(system, scenario.excitation, scenario.simulation)
    w = system.nonlinear.static_force[:, None] + mount_forces(system, history).local[:, :, 2]
    assert not any(mount.tension for mount in system.mounts)
    assert np.all(w.max(axis=1) <= 1e-12 * np.abs(w).max())
    lifted = np.unique(history.contacts.law[history.contacts.region_to == system.nonlinear.lifted_region[0]])
    assert system.nonlinear.names[0] == "1 w" and lifted.tolist() == [2, 3]  # bearings 3 and 4
    assert np.all(w[2:].max(axis=1) == 0.0)  # and carried nothing while lifted
    assert energy_balance(system, history).ok


# ----------------------------------------------------------------------------------------------------
# 6. The energy balance of a damped, loaded run with contacts.
# ----------------------------------------------------------------------------------------------------


def stored_by_hand(q):
    """Energy stored about the static equilibrium at the states ``q`` (n, 6) [J]: the laws' integrals
    sum_j int_0^d r_j minus the weight's work, less their value at rest, written here."""
    rows = np.concatenate([rows_of(p, np.eye(3)) for p in LIFT_POSITIONS])
    k = np.tile([LIFT_KUV, LIFT_KUV, LIFT_KW], 4)
    W = np.array([0.0, 0.0, -LIFT_MASS * STANDARD_GRAVITY, 0.0, 0.0, 0.0])
    q_s = np.linalg.solve(rows.T @ (k[:, None] * rows), W)

    def potential(q):
        d = (q_s + q) @ rows.T  # (n, 12)
        linear = 0.5 * k * d**2
        w = d[:, 2::3]
        lift = np.where(w > 0, 0.0, linear[:, 2::3] + 0.5 * LIFT_KS * np.minimum(w + LIFT_C, 0.0) ** 2)
        linear[:, 2::3] = lift
        return linear.sum(axis=1) - (q_s + q) @ W

    return potential(q) - potential(np.zeros((1, 6)))


@pytest.mark.slow  # the run it reads: 2-4 s on the 2-core machine
def test_energy_balance_of_a_run_with_contacts(lifting):
    system, history, reference, _ = lifting
    assert np.any(history.contacts.region_to == 0)  # a stop took part, as well as the lift-off
    balance = energy_balance(system, history)
    assert balance.ok and balance.worst <= ENERGY_TOLERANCE == balance.tolerance
    # Its parts against the reference and the stored energy written here.
    for mine, exact in ((history.energy_input, reference[:, 12]), (history.energy_dissipated, reference[:, 13])):
        assert np.max(np.abs(mine - exact)) <= RTOL_DIRECT_EXACT * np.max(np.abs(exact))
    stored = stored_by_hand(history.q)
    assert np.max(np.abs(balance.stored - stored)) <= RTOL_STATICS * np.max(stored)
    assert reference[-1, 13] > 0.3 * reference[-1, 12] > 0  # the damping took a good part of the work
    # The check can fail: the same run balanced with stops twice as stiff, or mounts that do not lift off.
    for change in (dict(bump_stiffness=[0.0, 0.0, 2 * LIFT_KS]), dict(tension=True)):
        wrong = dataclasses.replace(system, mounts=tuple(dataclasses.replace(m, **change) for m in system.mounts))
        assert energy_balance(wrong, history).worst > 1e3 * ENERGY_TOLERANCE


# ----------------------------------------------------------------------------------------------------
# 4. A force-deflection table that is linear is the linear mount.
# ----------------------------------------------------------------------------------------------------

# Mount stiffnesses whose values at +-0.125 m are exact in binary: a linear table's slopes are then exact too.
TABLE_K = [[3.0e5, 2.0e5, 4.0e5], [2.0e5, 3.0e5, 5.0e5], [3.0e5, 3.0e5, 6.0e5], [2.0e5, 2.0e5, 7.0e5]]


def linear_pair():
    """A body on four inclined, damped mounts (everything coupled), once with linear stiffnesses and once with
    linear tables in place of the w stiffness of every mount and the u stiffness of the first."""
    mounts = []
    for i, (p, k) in enumerate(zip(corners(0.5, 0.35, 0.25), TABLE_K)):
        angle = np.deg2rad(15.0 + 10.0 * i)
        c, s = np.cos(angle), np.sin(angle)
        mounts.append(Mount(f"m{i}", p + [0.05 * i, 0.0, 0.0], k, damping=[200.0, 300.0, 900.0],
                            axes=[[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]]))
    body = RigidBody(300.0, [[25.0, 2.0, -1.0], [2.0, 30.0, 1.5], [-1.0, 1.5, 40.0]])
    plain = System(body, mounts, rayleigh=Rayleigh(1.0, 1e-4))
    span = np.array([-0.125, 0.0, 0.125])
    tables = [ForceDeflection(mount=m.name, axis="w", deflection=span, force=m.stiffness[2] * span) for m in mounts]
    tables.append(ForceDeflection(mount="m0", axis="u", deflection=span, force=mounts[0].stiffness[0] * span))
    # The tables' mounts state a different stiffness on those axes: the tables replace it.
    replaced = [dataclasses.replace(m, stiffness=[1.0 if i == 0 else m.stiffness[0], m.stiffness[1], 1.0])
                for i, m in enumerate(mounts)]
    return plain, System(body, replaced, rayleigh=Rayleigh(1.0, 1e-4), force_deflection=tables)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_a_linear_table_is_the_linear_mount():
    plain, tabled = linear_pair()
    assert tabled.nonlinear.count == 5 and not is_nonlinear(tabled)
    assert not np.isfinite(tabled.nonlinear.knots).any()
    np.testing.assert_array_equal(tabled.stiffnesses, plain.stiffnesses)
    np.testing.assert_array_equal(tabled.K, plain.K)
    # Statics: Newton on the tables, a linear solve on the springs.
    statics = gravity_statics(tabled), gravity_statics(plain)
    np.testing.assert_allclose(statics[0].q, statics[1].q, rtol=0, atol=RTOL_STATICS * np.abs(statics[1].q).max())
    np.testing.assert_allclose(statics[0].mount_forces, statics[1].mount_forces, rtol=0,
                               atol=RTOL_STATICS * LIFT_MASS * STANDARD_GRAVITY)
    tabled, plain = at_equilibrium(tabled, statics[0]), at_equilibrium(plain, statics[1])
    np.testing.assert_array_equal(tabled.K, plain.K)
    np.testing.assert_array_equal(tabled.C, plain.C)
    load = Load("kick", [0.3, -0.2, 0.1], force=[400.0, -300.0, 1200.0], moment=[50.0, 0.0, -80.0],
                signal=HalfSine(start=0.005, duration=0.02))
    settings = SimulationSettings(duration=0.3, sample_rate_hz=1500.0)
    runs = [simulate(system, Excitation(loads=[load]), settings) for system in (tabled, plain)]
    assert runs[0].contacts is None and runs[0].energy_input is None  # the linear solve
    for name in ("q", "qd", "qdd"):
        a, b = getattr(runs[0], name), getattr(runs[1], name)
        error = np.max(np.abs(a - b), axis=0) / np.max(np.abs(b), axis=0)
        assert np.all(error <= RTOL_SAME_SOLVE), (name, error)


# ----------------------------------------------------------------------------------------------------
# 5. Statics with stiffening tables: Newton's equilibrium checked by hand.
# ----------------------------------------------------------------------------------------------------

# A progressive elastomer: 1e5 N/m up to 10 mm of compression, then 3e5, then 1e6 N/m (and 1e5 in extension).
STIFFENING = (np.array([-0.03, -0.02, -0.01, 0.0, 0.01]), np.array([-14000.0, -4000.0, -1000.0, 0.0, 1000.0]))


def stiffening_system() -> System:
    """An 800 kg body whose CG is off the centre of its four table mounts: each compresses differently, all past
    the first knot."""
    deflection, force = STIFFENING
    positions = [np.array(p) for p in ([-0.45, -0.3, -0.2], [0.55, -0.3, -0.2], [0.55, 0.35, -0.2],
                                       [-0.45, 0.35, -0.2])]
    mounts = [Mount(f"m{i}", p, [2e5, 2.5e5, 1e5]) for i, p in enumerate(positions)]
    tables = [ForceDeflection(mount=f"m{i}", axis="w", deflection=deflection, force=force) for i in range(4)]
    return System(RigidBody(800.0, [60.0, 80.0, 110.0]), mounts, force_deflection=tables)


def test_newton_statics_with_stiffening_tables():
    system = stiffening_system()
    statics = gravity_statics(system)
    weight = 800.0 * STANDARD_GRAVITY
    deflection, force = STIFFENING
    # By hand: each axis's deflection, its load (np.interp in the table on w, k d on u and v), their sum.
    rows = np.stack([rows_of(m.position, np.eye(3)) for m in system.mounts])  # (4, 3, 6)
    d = rows @ statics.q  # (4, 3)
    assert np.all((d[:, 2] > deflection[0]) & (d[:, 2] < -0.01))  # inside the table, past its first knot
    load = system.given_stiffnesses * d
    load[:, 2] = np.interp(d[:, 2], deflection, force)
    residual = np.einsum("nai,na->i", rows, load) - np.array([0.0, 0.0, -weight, 0.0, 0.0, 0.0])
    assert np.all(np.abs(residual[:3]) <= RTOL_STATICS * weight)
    assert np.all(np.abs(residual[3:]) <= RTOL_STATICS * weight * 0.55)  # moments: the weight times the lever
    np.testing.assert_allclose(statics.mount_forces_local, load, rtol=0, atol=RTOL_STATICS * weight)
    assert len(set(np.round(d[:, 2], 6))) == 4  # the four mounts carry different loads
    # A linear solve with the tables' slope at zero would sit far off: the tables stiffen.
    linear = np.linalg.solve(np.einsum("nai,na,naj->ij", rows, np.array([[2e5, 2.5e5, 1e5]] * 4), rows),
                             [0.0, 0.0, -weight, 0.0, 0.0, 0.0])
    assert linear[2] < 1.3 * statics.q[2] < 0
    # Linearized about it: each table's slope at its static deflection, in the stiffnesses and in K.
    at_rest = at_equilibrium(system, statics)
    k = np.diff(force) / np.diff(deflection)
    slope = k[np.searchsorted(deflection, d[:, 2]) - 1]
    np.testing.assert_allclose(at_rest.stiffnesses[:, 2], slope, rtol=RTOL_STATICS)
    np.testing.assert_array_equal(at_rest.stiffnesses[:, :2], system.given_stiffnesses[:, :2])
    stiffness = system.given_stiffnesses.copy()
    stiffness[:, 2] = slope
    K = np.einsum("nai,na,naj->ij", rows, stiffness, rows)
    np.testing.assert_allclose(at_rest.K, K, rtol=0, atol=RTOL_STATICS * np.abs(K).max())
    np.testing.assert_array_equal(system.stiffnesses[:, 2], 1e5)  # unloaded: the slope at zero (compression side)


# ----------------------------------------------------------------------------------------------------
# 7. Bad input: one error naming the field.
# ----------------------------------------------------------------------------------------------------

# Four mounts around the CG; the last layout puts m0 far behind it, where a linear mount would pull (the
# other three carry the body alone).
AROUND = ((0.4, 0.3, -0.1), (-0.4, 0.3, -0.1), (-0.4, -0.3, -0.1), (0.4, -0.3, -0.1))
BEHIND = ((-1.0, 0.0, -0.1), (-0.2, 0.3, -0.1), (-0.2, -0.3, -0.1), (0.2, 0.0, -0.1))


def scenario_text(first: str, positions=AROUND) -> str:
    """A scenario of a 100 kg body on four mounts, with ``first`` added to the first mount's table."""
    text = 'name = "bad"\n[body]\nmass = 100.0\ninertia = [10.0, 12.0, 14.0]\n'
    for i, p in enumerate(positions):
        text += f'[[mounts]]\nname = "m{i}"\nposition = {list(p)}\nstiffness = [1e5, 1e5, 2e5]\n'
        text += first if i == 0 else ""
    return text


TABLE = 'force_deflection = {file = "table.csv", axis = "w"}\n'


@pytest.mark.parametrize(("first", "csv", "positions", "field", "says"), [
    pytest.param('bump_stop = {clearance = [0.01, inf, -0.002], stiffness = [1e6, 0.0, 1e6]}\n', None, AROUND,
                 "mounts[0].bump_stop.clearance", "clearances in m >= 0", id="negative clearance"),
    pytest.param('bump_stop = {clearance = [inf, inf, 0.01]}\n', None, AROUND, "mounts[0].bump_stop.stiffness",
                 "required key", id="clearance without stiffness"),
    pytest.param('bump_stop = {clearance = [inf, inf, 0.01], stiffness = [1e6, 0.0, 0.0]}\n', None, AROUND,
                 "mounts[0].bump_stop.stiffness", "stiffness > 0 in N/m on every axis with a clearance",
                 id="clearance without stiffness on its axis"),
    pytest.param(TABLE, "deflection,force\n-0.02,-3000\n-0.01,-1000\n0,0\n0.01,500\n0.02,400\n", AROUND,
                 "mounts[0].force_deflection.force", "500 N at 0.01 m, then 400 N at 0.02 m (rows 4-5 of table.csv)",
                 id="force decreasing"),
    pytest.param(TABLE, "-0.02,-3000\n-0.01,-1000\n0,0\n0.01,500\n0.01,700\n", AROUND,
                 "mounts[0].force_deflection.deflection", "0.01 then 0.01 m (rows 4-5 of table.csv)",
                 id="deflection not increasing"),
    pytest.param(TABLE, "-0.02,-3000\n-0.01,-1000\n0,50\n0.01,1000\n", AROUND, "mounts[0].force_deflection.force",
                 "zero force at zero deflection", id="force at zero deflection"),
    pytest.param("tension = false\n", None, BEHIND, "mounts[0].tension", "m0 is in tension at rest",
                 id="tension = false on a mount in tension at rest"),
])
def test_bad_nonlinear_mounts_are_refused_naming_the_field(tmp_path, first, csv, positions, field, says):
    if csv is not None:
        (tmp_path / "table.csv").write_text(csv)
    with pytest.raises(ScenarioError) as error:  # read, then prepared (the statics find a mount in tension)
        prepare(parse_scenario(scenario_text(first, positions), source="bad.toml", base_dir=tmp_path))
    assert error.value.field == field
    assert str(error.value).startswith(f"bad.toml: {field}: expected ")
    assert says in str(error.value)


def test_good_nonlinear_mounts_are_accepted(tmp_path):
    """The same scenarios, corrected, parse: the refusals above are for the faults alone."""
    (tmp_path / "table.csv").write_text("deflection,force\n-0.02,-3000\n-0.01,-1000\n0,0\n0.01,500\n0.02,700\n")
    first = ('bump_stop = {clearance = [0.01, inf, 0.004], stiffness = [1e6, 0.0, 1e6]}\n' + TABLE
             + "tension = false\n")
    system = prepare(parse_scenario(scenario_text(first), source="good.toml", base_dir=tmp_path)).system
    assert system.nonlinear.names == ("m0 u", "m0 w")
    assert system.nonlinear.kinds == ("bump stop", "table + bump stop + lift-off")
    assert system.equilibrium[2] < 0 and system.nonlinear.static_deflection[1] < 0
    with pytest.raises(InputError) as error:  # and the API refuses the same as the file
        ForceDeflection(mount="m0", axis="w", deflection=[-0.01, 0.0, 0.01], force=[-1000.0, 0.0, -500.0])
    assert error.value.field == "force"
