"""Nonlinear mounts (bump stops, lift-off, force-deflection tables) against independent answers: closed forms of
piecewise-linear single-DOF oscillators (a bilinear spring, a mass dropped onto a stop), an event-driven
integration written here with scipy (its own mount laws and its own assembly, restarted at every change of
contact), the linear solve for a table that is linear, the static equilibrium checked by hand, the energy
balance, and bad input."""

import dataclasses

import numpy as np
import pytest
import scipy.integrate

from sixdof import Mount, Rayleigh, RigidBody, System
from sixdof.analysis.contact import ENERGY_TOLERANCE, contact_summary, energy_balance, total_deflection
from sixdof.analysis.direct import SimulationSettings, is_nonlinear, simulate
from sixdof.analysis.statics import STANDARD_GRAVITY, at_equilibrium, gravity_statics
from sixdof.errors import InputError, ScenarioError
from sixdof.excitation import Excitation, InitialState, Load
from sixdof.excitation.signals import HalfSine
from sixdof.io.scenario import parse_scenario
from sixdof.model.nonlinear import ForceDeflection
from systems import FOUR_MOUNT_CORNERS
from tolerances import RTOL_DIRECT_EXACT, RTOL_STATICS

# Event times of the direct solve against closed forms, relative to the period of the motion: the events are
# root-found on the solver's dense output (Newton to 1e-12) a hysteresis of 1e-10 of the deflection scale away
# from the knot, and inherit the solve's global error (rtol = atol = 1e-9 on the scaled state). Measured
# <= 2e-10 over four cycles.
RTOL_EVENT_TIME = 1e-8
# Zero crossings of the sampled response (cubic Hermite interpolation of z and z' between the two samples
# around each crossing) against the closed form, relative to the period: the interpolation error of a C2
# motion ~ (omega h)^3 h / 384 at omega h <= 0.09, measured ~2e-8.
RTOL_ZERO_CROSSING = 1e-6
# Amplitude invariants of a linear piece (z^2 + (z'/omega)^2 about its centre) sampled from the direct solve,
# relative to the amplitude: the solve's global error, measured ~1e-9.
RTOL_AMPLITUDE = 1e-7
# Event times of the direct solve against scipy's event-located DOP853 (rtol 1e-12), relative to the duration
# of the run: both locate the same crossings to their integration error, measured ~5e-10.
RTOL_EVENT_REFERENCE = 1e-7


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


def test_bilinear_free_vibration_period_and_peaks():
    system = bilinear_system()
    w1, w2 = np.sqrt(4 * BI_K1 / BI_MASS), np.sqrt(4 * BI_K2 / BI_MASS)  # extension (up), compression (down)
    period = np.pi / w1 + np.pi / w2
    settings = SimulationSettings(duration=4 * period, sample_rate_hz=1500.0)
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

    # Events: every law leaves compression at n T and enters it at n T + pi / w1.
    events = history.contacts
    assert events.names == ("m0 w", "m1 w", "m2 w", "m3 w")
    n = int(np.floor(settings.duration / period))
    for law in range(4):
        mine = events.law == law
        rising = events.t[mine & (events.region_from == 0) & (events.region_to == 1)]
        falling = events.t[mine & (events.region_from == 1) & (events.region_to == 0)]
        np.testing.assert_allclose(rising, period * np.arange(n + 1), rtol=0, atol=RTOL_EVENT_TIME * period)
        np.testing.assert_allclose(falling, period * np.arange(n) + np.pi / w1, rtol=0,
                                   atol=RTOL_EVENT_TIME * period)
        np.testing.assert_allclose(np.diff(rising), period, rtol=RTOL_EVENT_TIME)
    assert history.stats.num_events == events.count == 4 * (2 * n + 1)

    # The period again from the sampled motion: its zero crossings.
    crossings = hermite_roots(history.t, history.q[:, 2], history.qd[:, 2])
    upward = np.array([t for t, sign in crossings if sign > 0])
    downward = np.array([t for t, sign in crossings if sign < 0])
    assert upward.size == n and downward.size == n  # t = 0 lies on a sample, not between two
    np.testing.assert_allclose(np.diff(upward), period, rtol=RTOL_ZERO_CROSSING)
    np.testing.assert_allclose(downward - np.pi / w1, period * np.arange(n), rtol=0, atol=RTOL_ZERO_CROSSING * period)
    np.testing.assert_allclose(upward, period * np.arange(1, n + 1), rtol=0, atol=RTOL_ZERO_CROSSING * period)

    # Peaks: v0 / w1 above, v0 / w2 below, from the amplitude of each side's samples ...
    q, qd = history.q[:, 2], history.qd[:, 2]
    above, below = q > 0, q < 0
    np.testing.assert_allclose(np.hypot(q[above], qd[above] / w1), BI_V0 / w1, rtol=RTOL_AMPLITUDE)
    np.testing.assert_allclose(np.hypot(q[below], qd[below] / w2), BI_V0 / w2, rtol=RTOL_AMPLITUDE)
    # ... and the sampled extremes, which reach them to within the sampling (cos(w h / 2) of the peak).
    h = 1.0 / settings.sample_rate_hz
    assert BI_V0 / w1 * np.cos(w1 * h / 2) <= q.max() <= BI_V0 / w1 * (1 + RTOL_AMPLITUDE)
    assert BI_V0 / w2 * np.cos(w2 * h / 2) <= -q.min() <= BI_V0 / w2 * (1 + RTOL_AMPLITUDE)
