"""Exact responses of eq. (1), computed apart from any time integrator (test helper).

The state-space system ``x = [q, q']``, ``x' = A x + B Q(t)``, is augmented with a linear generator of
the forcing signal on each smooth piece (``s = c' xi``, ``xi' = S xi``); the augmented system is
autonomous, so its solution is ``expm(F (t - ta)) [x(ta); xi(ta)]`` exactly. Harmonic signals use a
two-state oscillator, pulses use one per piece, tabulated signals (a first-order hold) use
``xi = [s, s']`` with ``S = [[0, 1], [0, 0]]`` on each segment.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from sixdof.model.system import Mount, RigidBody, System

FREE = (np.zeros((1, 1)), np.zeros(1), np.zeros(1))  # no forcing on a piece


def state_matrices(M, C, K):
    """``A`` (12, 12) and ``B`` (12, 6) of ``x' = A x + B Q``."""
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((6, 6)), np.eye(6)], [-Minv @ K, -Minv @ C]])
    B = np.vstack([np.zeros((6, 6)), Minv])
    return A, B


def oscillator(omega, phase, t_ref):
    """Generator of ``sin(omega (t - t_ref) + phase)``: (S, xi at t_ref, c)."""
    S = np.array([[0.0, omega], [-omega, 0.0]])
    return S, np.array([np.sin(phase), np.cos(phase)]), np.array([1.0, 0.0])


def linear(value, slope, c=(1.0, 0.0)):
    """Generator of ``xi = [value + slope (t - ta), slope]``; the signal is ``c xi``."""
    return np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([value, slope]), np.asarray(c, float)


def exact_response(M, C, K, Q0, pieces, t_out, x0=None):
    """``q(t_out), q'(t_out)`` for ``M q'' + C q' + K q = Q0 s(t)``.

    Parameters
    ----------
    Q0 : (6,) or (6, k)
        Load vector; with k columns the signal is a k-vector ``c xi`` (``c`` of shape (k, m)).
    pieces : list of (ta, tb, (S, xi_a, c))
        Consecutive pieces covering ``[t_out[0], t_out[-1]]``; on ``[ta, tb)`` the signal is
        ``c' xi`` with ``xi' = S xi``, ``xi(ta) = xi_a``.
    x0 : (12,), optional
        State at ``pieces[0][0]``.
    """
    A, B = state_matrices(M, C, K)
    n = A.shape[0]
    x = np.zeros(n) if x0 is None else np.asarray(x0, float)
    out = np.full((len(t_out), n), np.nan)
    t_out = np.asarray(t_out, float)
    for index, (ta, tb, (S, xi, c)) in enumerate(pieces):
        m = S.shape[0]
        F = np.zeros((n + m, n + m))
        F[:n, :n] = A
        F[:n, n:] = (B @ np.reshape(Q0, (6, -1))) @ np.reshape(c, (np.size(Q0) // 6, m))
        F[n:, n:] = S
        y = np.concatenate([x, xi])
        last = index == len(pieces) - 1
        mask = (t_out >= ta) & ((t_out < tb) | (last & (t_out <= tb)))
        index_out = np.flatnonzero(mask)
        if index_out.size:
            # Uniformly spaced outputs: one propagator per spacing (round-off grows ~ n eps).
            steps = np.diff(t_out[index_out])
            y_out = scipy.linalg.expm(F * (t_out[index_out[0]] - ta)) @ y
            out[index_out[0]] = y_out[:n]
            cache = {}
            for i, h in zip(index_out[1:], steps):
                key = round(h * 1e12)
                if key not in cache:
                    cache[key] = scipy.linalg.expm(F * h)
                y_out = cache[key] @ y_out
                out[i] = y_out[:n]
        x = (scipy.linalg.expm(F * (tb - ta)) @ y)[:n]
    assert np.all(np.isfinite(out)), "pieces do not cover t_out"
    return out[:, :6], out[:, 6:]


def table_pieces(knots, values, t_end, c=(1.0, 0.0)):
    """Pieces of a first-order hold (zero outside the table) up to ``t_end``; signal ``c [s, s']``."""
    knots, values = np.asarray(knots, float), np.asarray(values, float)
    free = (np.zeros((1, 1)), np.zeros(1), np.zeros((np.size(c) // 2, 1)))
    pieces = [(0.0, knots[0], free)] if knots[0] > 0 else []
    for k in range(len(knots) - 1):
        slope = (values[k + 1] - values[k]) / (knots[k + 1] - knots[k])
        pieces.append((knots[k], knots[k + 1], linear(values[k], slope, c)))
    if t_end > knots[-1]:
        pieces.append((knots[-1], t_end, free))
    return pieces


def relative_error_per_dof(actual, expected):
    """``max |actual - expected| / max |expected|`` per column (6,)."""
    return np.max(np.abs(actual - expected), axis=0) / np.max(np.abs(expected), axis=0)


# ----------------------------------------------------------------------------------------------------
# Test systems.
# ----------------------------------------------------------------------------------------------------

BRIDGE_POSITIONS = [(-0.195, -19.55, -1.031), (0.195, -19.55, -1.031), (0.195, 19.55, -1.031),
                    (-0.195, 19.55, -1.031)]
BRIDGE_STIFFNESS = [[0.26e6, 0.26e6, 312e6]] * 2 + [[0.51e6, 0.51e6, 496e6]] * 2
# Elastomer dashpots with a different ratio per mount pair and per axis: non-proportional damping
# (modal ratios from 1.4 % to 6.3 %, and coupled modes).
BRIDGE_DAMPING = [[3800.0, 3800.0, 1.4e5]] * 2 + [[9000.0, 9000.0, 1.2e5]] * 2


def bridge(damping=True, stiffness_factor=1.0):
    """The seed paper's bridge beam, with non-proportional mount dashpots."""
    body = RigidBody(83e3, [11.105e6, 0.0491e6, 11.064e6], [1.2, 40.0, 2.0])
    mounts = [
        Mount(str(i + 1), p, np.asarray(k) * stiffness_factor,
              np.asarray(d) * np.sqrt(stiffness_factor) if damping else np.zeros(3))
        for i, (p, k, d) in enumerate(zip(BRIDGE_POSITIONS, BRIDGE_STIFFNESS, BRIDGE_DAMPING))
    ]
    return System(body, mounts)


def skewed_machine():
    """A 500 kg body with a full inertia tensor on four inclined mounts, each damped differently."""
    inertia = [[60.0, 4.0, -3.0], [4.0, 45.0, 2.0], [-3.0, 2.0, 70.0]]
    body = RigidBody(500.0, inertia)
    mounts = []
    for i, (x, y) in enumerate([(-0.4, -0.3), (0.4, -0.3), (0.4, 0.3), (-0.4, 0.3)]):
        angle = np.deg2rad(20.0 + 10.0 * i)  # inclined about the body's y axis, all different
        c, s = np.cos(angle), np.sin(angle)
        axes = [[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]]
        k = np.array([3e5, 2.5e5, 8e5]) * (1.0 + 0.1 * i)
        d = np.array([300.0, 500.0, 900.0]) * (1.0 + 0.5 * i)
        mounts.append(Mount(f"m{i + 1}", [x, y, -0.25], k, d, axes))
    return System(body, mounts)
