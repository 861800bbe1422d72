"""Independent reference answers for the tests (none uses sixdof): exact responses and closed forms.

Exact responses of eq. (1), computed apart from any time integrator: the state-space system
``x = [q, q']``, ``x' = A x + B Q(t)``, is augmented with a linear generator of the forcing signal on
each smooth piece (``s = c' xi``, ``xi' = S xi``); the augmented system is autonomous, so its solution
is ``expm(F (t - ta)) [x(ta); xi(ta)]`` exactly. Harmonic signals use a two-state oscillator, pulses
use one per piece, tabulated signals (a first-order hold) use ``xi = [s, s']`` with
``S = [[0, 1], [0, 0]]`` on each segment.

Closed forms: single-DOF receptance, transmissibility and free response, damping ratios, natural
frequencies of symmetric layouts, statics; each cites its formula.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

FREE = (np.zeros((1, 1)), np.zeros(1), np.zeros(1))  # no forcing on a piece


def state_matrices(M, C, K):
    """``A`` (12, 12) and ``B`` (12, 6) of ``x' = A x + B Q``."""
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((6, 6)), np.eye(6)], [-Minv @ K, -Minv @ C]])
    B = np.vstack([np.zeros((6, 6)), Minv])
    return A, B


def oscillator(omega, phase, t_ref, amplitude=1.0):
    """Generator of ``amplitude sin(omega (t - t_ref) + phase)``: (S, xi at t_ref, c)."""
    S = np.array([[0.0, omega], [-omega, 0.0]])  # xi = [sin, cos] of the angle
    return S, np.array([np.sin(phase), np.cos(phase)]), amplitude * np.array([1.0, 0.0])


def linear(value, slope, c=(1.0, 0.0)):
    """Generator of ``xi = [value + slope (t - ta), slope]``; the signal is ``c xi``."""
    return np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([value, slope]), np.asarray(c, float)


def generator_value(generator, tau):
    """The signal ``c' e^{S tau} xi`` of an :func:`oscillator` or :func:`linear` generator, in closed
    form (the exact response itself uses the matrix exponential)."""
    S, xi, c = generator
    if S[0, 0] == 0 and S[1, 0] == 0:  # linear: xi(tau) = [value + slope tau, slope]
        return c[0] * (xi[0] + xi[1] * tau) + c[1] * xi[1]
    w = S[0, 1]  # oscillator: the angle advances by w tau
    sin, cos = xi[0] * np.cos(w * tau) + xi[1] * np.sin(w * tau), xi[1] * np.cos(w * tau) - xi[0] * np.sin(w * tau)
    return c[0] * sin + c[1] * cos


def windowed_pieces(windows, t_end, t_start=0.0):
    """Consecutive pieces for :func:`exact_response` covering ``[t_start, t_end]``, from windows
    ``(start, end, generators)`` on which the signal is the sum of the generators' outputs (``end``
    may be ``inf``), zero outside every window. The windows must not overlap."""
    pieces, t = [], t_start
    for start, end, generators in sorted(windows, key=lambda window: window[0]):
        assert start >= t, "windows overlap"
        if start > t:
            pieces.append((t, start, FREE))
        end = min(end, t_end)
        S = scipy.linalg.block_diag(*[g[0] for g in generators])
        pieces.append((start, end, (S, np.concatenate([g[1] for g in generators]),
                                    np.concatenate([g[2] for g in generators]))))
        t = end
    if t < t_end:
        pieces.append((t, t_end, FREE))
    return pieces


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
        index_out = np.flatnonzero((t_out >= ta) & ((t_out < tb) | (last & (t_out <= tb))))
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
    """``max |actual - expected| / max |expected|`` per column (6,); a column the reference leaves exactly at
    zero (a DOF decoupled from the input, to the bit with the NumPy assembly) must be exactly zero too."""
    error, peak = np.max(np.abs(actual - expected), axis=0), np.max(np.abs(expected), axis=0)
    return np.divide(error, peak, out=np.where(error > 0, np.inf, 0.0), where=peak > 0)


def sdof_receptance(m, k, c, eta, w):
    """Receptance of ``m x'' + c x' + k (1 + i eta) x = F e^{i w t}``:
    ``H(w) = 1 / (k (1 + i eta) - m w^2 + i c w)``."""
    return 1.0 / (k * (1 + 1j * eta) - m * w**2 + 1j * c * w)


def viscous_transmissibility(r, zeta):
    """Force (and absolute motion) transmissibility of a viscously damped SDOF at frequency ratio
    ``r = w / wn``: ``sqrt(1 + (2 zeta r)^2) / sqrt((1 - r^2)^2 + (2 zeta r)^2)``."""
    return np.sqrt(1 + (2 * zeta * r) ** 2) / np.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)


def relative_transmissibility(r, zeta):
    """Relative motion per ground motion of a viscously damped SDOF:
    ``r^2 / sqrt((1 - r^2)^2 + (2 zeta r)^2)``."""
    return r**2 / np.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)


def hysteretic_transmissibility(r, eta):
    """Transmissibility of an SDOF with hysteretic (structural) damping of loss factor ``eta``:
    ``sqrt(1 + eta^2) / sqrt((1 - r^2)^2 + eta^2)``."""
    return np.sqrt(1 + eta**2) / np.sqrt((1 - r**2) ** 2 + eta**2)


def displacement_resonance_hz(f_n, zeta):
    """Peak of a viscously damped SDOF's displacement receptance: ``f_n sqrt(1 - 2 zeta^2)``."""
    return f_n * np.sqrt(1 - 2 * zeta**2)


def log_decrement(zeta):
    """Logarithmic decrement of a viscously damped free decay: ``2 pi zeta / sqrt(1 - zeta^2)``."""
    return 2 * np.pi * zeta / np.sqrt(1 - zeta**2)


def released_sdof(t, x0, omega, zeta):
    """Free response of an underdamped SDOF released from ``x0`` at rest:
    ``x0 e^{-zeta w t} (cos(wd t) + zeta w / wd sin(wd t))``, ``wd = w sqrt(1 - zeta^2)``."""
    wd = omega * np.sqrt(1 - zeta**2)
    return x0 * np.exp(-zeta * omega * t) * (np.cos(wd * t) + zeta * omega / wd * np.sin(wd * t))


def rayleigh_ratio(alpha, beta, omega):
    """Damping ratio of Rayleigh damping ``C = alpha M + beta K`` at ``omega``:
    ``zeta = alpha / (2 w) + beta w / 2``."""
    return alpha / (2 * omega) + beta * omega / 2


def free_mass_with_viscous_drag(t, force, mass, alpha):
    """``x'' + alpha x' = F / m`` from rest: ``x(t) = F / (m alpha) (t - (1 - e^{-alpha t}) / alpha)``."""
    return force / (mass * alpha) * (t - (1 - np.exp(-alpha * t)) / alpha)


def harmonic_from_rest(amplitude, omega, t):
    """First and second time integrals, from rest at ``t = 0``, of ``amplitude sin(omega t)``:
    ``amplitude (1 - cos(w t)) / w`` and ``amplitude (t / w - sin(w t) / w^2)``."""
    return amplitude * (1 - np.cos(omega * t)) / omega, amplitude * (t / omega - np.sin(omega * t) / omega**2)


def steady_state_amplitude(M, C, K, Q0, omega):
    """Complex amplitude ``X = (K - w^2 M + i w C)^-1 Q0`` of the harmonic steady state."""
    return np.linalg.inv(K - omega**2 * M + 1j * omega * C) @ Q0


def ramp_response(C, K, Q0, duration):
    """Exact response to the ramp ``Q0 t / T`` when started on it: ``q(t) = static t / T - lag`` with
    ``static = K^-1 Q0`` and the damping lag ``K^-1 C K^-1 Q0 / T`` (``q'' = 0``). Returns
    ``(static, lag)``."""
    static = np.linalg.solve(K, Q0)
    lag = np.linalg.solve(K, C @ static) / duration
    return static, lag


def eigenvalue_pair(trace, det):
    """The two roots of ``lambda^2 - trace lambda + det = 0``, ascending: the eigenvalues of a 2x2
    dynamic matrix from its trace and determinant."""
    disc = np.sqrt(trace**2 - 4 * det)
    return [(trace - disc) / 2, (trace + disc) / 2]


def symmetric_four_mount_eigenvalues(m, J, a, b, h, k):
    """Eigenvalues ``w^2`` of a body on four identical mounts at ``(+-a, +-b, -h)`` (principal inertias
    ``J``, mount stiffness ``k = (kx, ky, kz)``): vertical ``4 kz / m``, yaw
    ``4 (kx b^2 + ky a^2) / Jz``, and two translation-rocking pairs (x, ry), (y, rx) with
    ``[m 0; 0 J]`` and ``[4 kt, -4 kt h; -4 kt h, 4 (kt h^2 + kz d^2)]``. Ascending."""
    (Jx, Jy, Jz), (kx, ky, kz) = J, k
    vertical = 4 * kz / m
    yaw = 4 * (kx * b**2 + ky * a**2) / Jz

    def rocking(k_t, k_r, J):
        K2 = np.array([[4 * k_t, -4 * k_t * h], [-4 * k_t * h, 4 * (k_t * h**2 + kz * k_r**2)]])
        return eigenvalue_pair(K2[0, 0] / m + K2[1, 1] / J, np.linalg.det(K2) / (m * J))

    return sorted([vertical, yaw, *rocking(kx, a, Jy), *rocking(ky, b, Jx)])


def bounce_pitch_eigenvalues(m, J, k1, k2, l1, l2):
    """Bounce-pitch eigenvalues of a body (mass ``m``, pitch inertia ``J``) on vertical springs ``k1``
    at ``-l1`` and ``k2`` at ``l2``: with ``a = (k1 + k2) / m``, ``b = (k1 l1^2 + k2 l2^2) / J``,
    ``c = (k2 l2 - k1 l1)^2 / (m J)``, the roots of ``lambda^2 - (a + b) lambda + a b - c = 0``."""
    a, b = (k1 + k2) / m, (k1 * l1**2 + k2 * l2**2) / J
    return eigenvalue_pair(a + b, a * b - (k2 * l2 - k1 * l1) ** 2 / (m * J))


def lever_rule_supports(weight, y1, y2, y_cg=0.0):
    """Reactions of two supports at ``y1`` and ``y2`` carrying ``weight`` at ``y_cg`` (lever rule):
    ``F1 = W (y2 - y_cg) / (y2 - y1)``, ``F2 = W (y_cg - y1) / (y2 - y1)``; negative is uplift."""
    return [weight * (y2 - y_cg) / (y2 - y1), weight * (y_cg - y1) / (y2 - y1)]
