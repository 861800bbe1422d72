"""Shared problem definitions for the benchmarks: the bridge beam, its loads, the exact answer.

Benchmarks are not tests: they are run by hand (``python benchmarks/run_all.py``) and write
``benchmarks/results/*.json`` and the table ``benchmarks/results.md``.
"""

from __future__ import annotations

import json
import os
import platform
import time
from pathlib import Path

import numpy as np
import scipy.integrate
import scipy.linalg

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
ROOT = HERE.parent
SCENARIO = ROOT / "scenarios" / "bridge_beam_traffic.toml"

DURATION, RATE = 20.0, 1000.0
HARMONIC_HZ = 5.0
PULSE_START, PULSE_DURATION = 1.0, 0.05
# Two loads that move all six DOFs: an off-centre harmonic force and a half-sine impact near one end.
TRAFFIC = dict(point=[0.3, 10.0, 1.0], force=[5e3, 2e4, -1e5])
IMPACT = dict(point=[0.4, 19.55, 0.5], force=[2e4, -5e4, 3e4])


def bridge_system():
    """The seed's bridge beam on bearings with non-proportional dashpots (as the traffic scenario)."""
    from sixdof.io.scenario import load_scenario

    return load_scenario(SCENARIO).system


def excitation():
    from sixdof.excitation import Excitation, HalfSine, Harmonic, Load

    return Excitation(loads=(
        Load("traffic", signal=Harmonic(f_hz=HARMONIC_HZ), **TRAFFIC),
        Load("impact", signal=HalfSine(start=PULSE_START, duration=PULSE_DURATION), **IMPACT),
    ))


def settings(**kw):
    from sixdof.analysis.direct import SimulationSettings

    return SimulationSettings(duration=DURATION, sample_rate_hz=RATE, **kw)


def load_vectors():
    out = []
    for load in (TRAFFIC, IMPACT):
        p, f = np.asarray(load["point"]), np.asarray(load["force"])
        out.append(np.concatenate([f, np.cross(p, f)]))
    return np.array(out)  # (2, 6)


def state_matrices(M, C, K):
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((6, 6)), np.eye(6)], [-Minv @ K, -Minv @ C]])
    B = np.vstack([np.zeros((6, 6)), Minv])
    return A, B


def signals(t):
    """(2, n) values of the two load signals."""
    t = np.asarray(t, dtype=float)
    harmonic = np.sin(2 * np.pi * HARMONIC_HZ * t)
    inside = (t >= PULSE_START) & (t < PULSE_START + PULSE_DURATION)
    pulse = np.where(inside, np.sin(np.pi * (t - PULSE_START) / PULSE_DURATION), 0.0)
    return np.array([harmonic, pulse])


def generator(M, C, K, pulse_on: bool) -> np.ndarray:
    """F (16, 16) of y = [x (12), harmonic sin/cos (2), pulse sin/cos (2)], as in exact."""
    A, B = state_matrices(M, C, K)
    V = load_vectors()
    w, wp = 2 * np.pi * HARMONIC_HZ, np.pi / PULSE_DURATION
    F = np.zeros((16, 16))
    F[:12, :12] = A
    F[:12, 12] = B @ V[0]
    F[12:14, 12:14] = [[0.0, w], [-w, 0.0]]
    if pulse_on:
        F[:12, 14] = B @ V[1]
        F[14:16, 14:16] = [[0.0, wp], [-wp, 0.0]]
    return F


def exact(M, C, K, t_out):
    """Exact discretization: the state-space system augmented with the loads' linear generators.

    On each smooth piece ([0, 1), [1, 1.05), [1.05, 20]) the forcing is the output of a linear
    oscillator, so ``y' = F y`` is autonomous and ``y(t + h) = expm(F h) y(t)`` exactly; one
    propagator per piece and output spacing (round-off only, ~n eps).
    Returns q (n, 6).
    """

    pieces = [(0.0, PULSE_START, False), (PULSE_START, PULSE_START + PULSE_DURATION, True),
              (PULSE_START + PULSE_DURATION, t_out[-1], False)]
    y = np.zeros(16)
    y[13] = 1.0  # harmonic: sin(0) = 0, cos(0) = 1
    out = np.full((t_out.size, 12), np.nan)
    for k, (ta, tb, on) in enumerate(pieces):
        if on:
            y[14], y[15] = 0.0, 1.0  # pulse starts at sin(0)
        else:
            y[14:16] = 0.0
        F = generator(M, C, K, on)
        last = k == len(pieces) - 1
        idx = np.flatnonzero((t_out >= ta) & ((t_out < tb) | (last & (t_out <= tb))))
        if idx.size:
            z = scipy.linalg.expm(F * (t_out[idx[0]] - ta)) @ y
            out[idx[0]] = z[:12]
            step = scipy.linalg.expm(F * (t_out[1] - t_out[0]))
            for i in idx[1:]:
                z = step @ z
                out[i] = z[:12]
        y = scipy.linalg.expm(F * (tb - ta)) @ y
    assert np.all(np.isfinite(out))
    return out[:, :6]


def worst_dof_error(q, q_ref):
    """max over DOFs of max_t |q - q_ref| / max_t |q_ref| (each DOF on its own scale)."""
    return float(np.max(np.max(np.abs(q - q_ref), axis=0) / np.max(np.abs(q_ref), axis=0)))


def scipy_solve(M, C, K, t_out, method, tol, scale):
    """solve_ivp on x' = A x + B Q(t), split at the pulse edges (a fair user steps onto them).

    ``rtol = tol``, ``atol = tol * scale`` per state component (the same per-DOF scaling sixdof
    uses). Returns q (n, 6) and the number of right-hand-side evaluations.
    """
    A, B = state_matrices(M, C, K)
    BV = B @ load_vectors().T  # (12, 2)
    w, wp = 2 * np.pi * HARMONIC_HZ, np.pi / PULSE_DURATION

    def rhs_free(t, x):
        return A @ x + BV[:, 0] * np.sin(w * t)

    def rhs_pulse(t, x):
        return A @ x + BV[:, 0] * np.sin(w * t) + BV[:, 1] * np.sin(wp * (t - PULSE_START))

    edges = [0.0, PULSE_START, PULSE_START + PULSE_DURATION, t_out[-1]]
    x = np.zeros(12)
    q = np.full((t_out.size, 6), np.nan)
    nfev = 0
    for k in range(3):
        ta, tb = edges[k], edges[k + 1]
        last = k == 2
        idx = np.flatnonzero((t_out >= ta) & ((t_out < tb) | (last & (t_out <= tb))))
        # The piece's end state is the last requested output (interpolated, as the samples are).
        t_eval = t_out[idx] if last else np.append(t_out[idx], tb)
        sol = scipy.integrate.solve_ivp(rhs_pulse if k == 1 else rhs_free, (ta, tb), x,
                                        method=method, t_eval=t_eval, rtol=tol, atol=tol * scale)
        if not sol.success:
            raise RuntimeError(sol.message)
        q[idx] = sol.y[:6, :idx.size].T
        x = sol.y[:, -1]
        nfev += sol.nfev
    return q, nfev


def best(fn, repeat):
    """Smallest wall time of ``repeat`` calls [s] and the last return value."""
    times, value = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        value = fn()
        times.append(time.perf_counter() - start)
    return min(times), float(np.median(times)), value


def machine() -> dict:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return {"cpu": platform.processor() or platform.machine(), "cores": os.cpu_count(),
            "load_1min": round(load, 2), "python": platform.python_version()}


def save(name: str, data: dict) -> Path:
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / f"{name}.json"
    data = {**data, "machine": machine(), "when": time.strftime("%Y-%m-%d %H:%M:%S")}
    path.write_text(json.dumps(data, indent=2))
    return path
