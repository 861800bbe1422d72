"""Millisecond contacts in long runs: every change of contact state is root-found, not stepped over or sampled.

A body moving vertically on one mount at its centre of gravity (stiffness 4 k) with a two-sided bump stop
(clearance c, stiffness 4 k_s) is a piecewise-linear oscillator (four mounts at the corners would be too, but
round-off in the order their contacts are found would rock the body; grazing contacts amplify it). Released from equilibrium at a speed that carries it a
hair beyond the clearance, it touches each stop for a millisecond per swing, between samples 50 ms
apart. Closed form of one contact: entering at speed v_c (energy: m v_c^2 = 4 k (A^2 - c^2) for the free
amplitude A), the motion is harmonic at w2 = sqrt(4 (k + k_s) / m) about x_e = k_s c / (k + k_s); it leaves
when x - x_e is back to y0 = c - x_e, after 2 phi / w2, phi = atan2(v_c / w2, y0).
"""

from __future__ import annotations

import numpy as np
import pytest

from sixdof.analysis.direct import SimulationSettings, simulate
from sixdof.excitation import Excitation, InitialState
from sixdof.model.parts import Mount, RigidBody
from sixdof.model.system import System

MASS, K, K_STOP, CLEARANCE = 100.0, 1e5, 1e7, 0.005


def _system() -> System:
    body = RigidBody(mass=MASS, inertia=[10.0, 12.0, 15.0])
    mount = Mount(name="centre", position=[0.0, 0.0, 0.0], stiffness=[4 * K, 4 * K, 4 * K],
                  bump_clearance=[np.inf, np.inf, CLEARANCE], bump_stiffness=[0.0, 0.0, 4 * K_STOP])
    return System(body=body, mounts=[mount])


@pytest.mark.long  # ~14 CPU s
def test_sub_millisecond_contacts_in_a_20_s_run_are_each_located():
    w1, w2 = np.sqrt(4 * K / MASS), np.sqrt(4 * (K + K_STOP) / MASS)
    amplitude = 1.0006 * CLEARANCE
    v_c = w1 * np.sqrt(amplitude**2 - CLEARANCE**2)
    y0 = CLEARANCE - K_STOP * CLEARANCE / (K + K_STOP)
    contact = 2 * np.arctan2(v_c / w2, y0) / w2
    assert 1e-3 < contact < 1.1e-3  # the premise: contacts of a millisecond
    # One swing between the stops: the free arcs from c to -c, each 2 asin(c/A) / w1, and the contacts.
    half_period = 2 * np.arcsin(CLEARANCE / amplitude) / w1 + contact
    excitation = Excitation(initial=InitialState(q=np.zeros(6), qd=[0, 0, w1 * amplitude, 0, 0, 0]))
    history = simulate(_system(), excitation, SimulationSettings(duration=20.0, sample_rate_hz=20.0))

    events = history.contacts
    starts, ends = events.t[events.region_to != 1], events.t[events.region_to == 1]
    free_until = 2 * np.arcsin(CLEARANCE / amplitude) / w1 / 2  # from equilibrium to the first contact
    expected = int(np.floor((20.0 - free_until) / half_period)) + 1
    assert starts.size == expected and abs(ends.size - expected) <= 1
    durations = ends - starts[:ends.size]
    # A grazing contact magnifies the integration error: its duration goes as sqrt(A^2 - c^2), here 1.2e-3 A^2,
    # so a relative energy error e changes it by about e / 2.4e-3. 1e-5 is the solver's ~1e-8 energy error, 400 times.
    np.testing.assert_allclose(durations, contact, rtol=1e-5)
    np.testing.assert_allclose(starts, free_until + half_period * np.arange(expected), rtol=0, atol=1e-7)
    # The samples catch hardly any of them: what shows them is the events.
    assert np.count_nonzero(np.abs(history.q[:, 2]) > CLEARANCE) < 0.1 * expected
    assert history.stats.num_events == events.count == starts.size + ends.size
