"""Modal superposition (the exact linear engine) against the fast exact discretization of the same problem.

The bridge beam of common.py (20 s at 1 kHz, 20,001 samples, harmonic + pulse loads moving all six
DOFs, non-proportional mount dashpots: complex modes). Both compute every output (q, q', q'') at the
samples, timed alternately in this process, best of several runs after a warm-up (the signals'
compilation):

- ``sixdof.superpose`` (modal coordinates, exact recursion, Gauss-Legendre increments);
- the exact discretization by blocked powers of the transition matrix (numpy): the state-space system
  augmented with the loads' linear generators is autonomous on each smooth piece, so
  ``y_{k+j} = Phi^j y_k`` with ``Phi = expm(F h)``; the states of a block of samples are one product
  with the stacked powers ``Phi^0 .. Phi^(L-1)``, and ``q''`` is a row block of ``F y``.

Both are timed twice in this process: first with glibc's allocator as a program calling sixdof has it (the
target's figure; each call's page faults are counted: fresh memory from the system costs ~2 us a page on this
project's VM), then as the ``sixdof`` command sets it, keeping the memory it frees (:func:`sixdof.cli._process.keep_freed_memory`).

Accuracy: the worst per-DOF error of q against common.exact (each DOF relative to its own peak), and
of q' and q'' against the blocked discretization. Where the ratio misses its target, the profile of the
engine (cProfile, internal time) is printed: it shows where the time goes.
Run: python benchmarks/bench_superposition.py [--repeat 30]. On a shared 2-core machine, run it with
OPENBLAS_NUM_THREADS=1: both computations are chains of small matrix products that gain nothing from
BLAS threads and lose several times over when the other core is busy.
"""

from __future__ import annotations

import cProfile
import io
import pstats
import resource
import sys
import time

import numpy as np
import scipy.linalg

import common
from sixdof.cli._process import keep_freed_memory

TARGET_RATIO = 3.0  # the engine within 3x of the exact discretization's time
TARGET_ERROR = 1e-9  # each DOF within 1e-9 of its own peak
BLOCK = 128  # samples per block of the fast discretization


def powers(step: np.ndarray, count: int) -> np.ndarray:
    """``step^0 .. step^(count-1)`` (count, 16, 16), by doubling."""
    P = np.eye(step.shape[0])[None]
    while P.shape[0] < count:
        P = np.concatenate([P, P @ np.linalg.matrix_power(step, P.shape[0])])
    return P[:count]


def blocked_states(step: np.ndarray, y0: np.ndarray, count: int) -> np.ndarray:
    """``y0, step y0, ..., step^(count-1) y0`` (count, 16): one product per block of BLOCK samples."""
    P = powers(step, BLOCK)
    stacked = P.transpose(2, 0, 1).reshape(16, BLOCK * 16)  # column block j: (step^j)'
    jump = P[-1] @ step
    starts = np.empty((-(-count // BLOCK), 16))
    starts[0] = y0
    for b in range(1, starts.shape[0]):
        starts[b] = jump @ starts[b - 1]
    return (starts @ stacked).reshape(-1, 16)[:count]


def fast_exact(M, C, K, t):
    """q, q', q'' (n, 6) at the uniform samples t of the exact discretization, by blocked powers."""
    off, on = common.generator(M, C, K, False), common.generator(M, C, K, True)
    h = t[1] - t[0]
    end = common.PULSE_START + common.PULSE_DURATION
    pieces = [(0.0, common.PULSE_START, off), (common.PULSE_START, end, on), (end, t[-1], off)]
    y = np.zeros(16)
    y[13] = 1.0  # harmonic: sin(0) = 0, cos(0) = 1
    q, qd, qdd = (np.empty((t.size, 6)) for _ in range(3))
    for k, (ta, tb, F) in enumerate(pieces):
        y[14:16] = (0.0, 1.0) if F is on else (0.0, 0.0)  # the pulse starts at sin(0)
        last = k == len(pieces) - 1
        index = np.flatnonzero((t >= ta) & ((t < tb) | (last & (t <= tb))))
        states = blocked_states(scipy.linalg.expm(F * h), scipy.linalg.expm(F * (t[index[0]] - ta)) @ y, index.size)
        q[index], qd[index], qdd[index] = states[:, :6], states[:, 6:12], states @ F[6:12].T
        y = scipy.linalg.expm(F * (tb - ta)) @ y
    return q, qd, qdd


def main(argv):
    repeat = int(argv[argv.index("--repeat") + 1]) if "--repeat" in argv else 30
    from sixdof.analysis.superposition import superpose

    system, excitation, settings = common.bridge_system(), common.excitation(), common.settings()
    M, C, K = (np.asarray(a) for a in (system.M, system.C, system.K))
    t = settings.times

    start = time.perf_counter()
    modal = superpose(system, excitation, t)
    first_s = time.perf_counter() - start
    fast_exact(M, C, K, t)

    def timed_alternately():
        """Best and median of each, timed alternately so that both see the same load on the machine; the
        page faults per call of each (fresh memory from the system)."""
        times, faults = ([], []), [0, 0]
        for _ in range(repeat):
            for k, compute in enumerate((lambda: superpose(system, excitation, t), lambda: fast_exact(M, C, K, t))):
                before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
                start = time.perf_counter()
                result = compute()
                times[k].append(time.perf_counter() - start)
                faults[k] += resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
                del result
        return [(min(x), float(np.median(x)), f / repeat) for x, f in zip(times, faults)]

    # First with glibc's allocator as a program calling sixdof has it; then as the sixdof command sets it,
    # keeping the memory it frees (sixdof.cli._process), both computations again in this process.
    (engine_s, engine_median, engine_faults), (reference_s, reference_median, reference_faults) = timed_alternately()
    kept = keep_freed_memory()
    timed_alternately()  # the heap grows to what both keep
    (kept_engine_s, kept_engine_median, _), (kept_reference_s, kept_reference_median, _) = timed_alternately()
    ratio = engine_s / reference_s
    kept_ratio = kept_engine_s / kept_reference_s
    modal = superpose(system, excitation, t)
    fast = fast_exact(M, C, K, t)

    q_ref = common.exact(M, C, K, t)
    error_q = common.worst_dof_error(modal.q, q_ref)
    error_fast = common.worst_dof_error(fast[0], q_ref)
    error_qd = common.worst_dof_error(modal.qd, fast[1])
    error_qdd = common.worst_dof_error(modal.qdd, fast[2])
    info = modal.superposition
    print(f"superpose ({info.method} modes, {info.n_intervals} intervals, {info.quadrature_nodes} nodes each): "
          f"{engine_s * 1e3:.1f} ms (median {engine_median * 1e3:.1f}; first call {first_s:.2f} s; "
          f"{engine_faults:.0f} page faults a call)", flush=True)
    print(f"exact discretization (numpy blocked powers, {BLOCK} per block): {reference_s * 1e3:.1f} ms "
          f"(median {reference_median * 1e3:.1f}; {reference_faults:.0f} page faults a call), worst per-DOF error "
          f"{error_fast:.2g}", flush=True)
    print(f"ratio {ratio:.2f}x (target <= {TARGET_RATIO:g}x): "
          + ("met" if ratio <= TARGET_RATIO else f"MISSED by {ratio / TARGET_RATIO - 1:.0%}"), flush=True)
    if kept:
        print(f"with the allocator keeping freed memory, as the sixdof command sets it: superpose "
              f"{kept_engine_s * 1e3:.1f} ms (median {kept_engine_median * 1e3:.1f}), exact discretization "
              f"{kept_reference_s * 1e3:.1f} ms (median {kept_reference_median * 1e3:.1f}), ratio {kept_ratio:.2f}x",
              flush=True)
    if ratio > TARGET_RATIO:
        profile = cProfile.Profile()
        profile.runcall(lambda: [superpose(system, excitation, t) for _ in range(10)])
        text = io.StringIO()
        pstats.Stats(profile, stream=text).sort_stats("tottime").print_stats(12)
        # Taken after the allocator was set to keep freed memory: the page faults counted above are not in it.
        print("profile of 10 calls (internal time" + (", freed memory kept" if kept else "") + "):\n"
              + text.getvalue().split("\n\n", 1)[-1].strip())
    print(f"worst per-DOF error of q vs common.exact {error_q:.2g} (target <= {TARGET_ERROR:g}): "
          f"{'met' if error_q <= TARGET_ERROR else 'MISSED'}; q' {error_qd:.2g}, q'' {error_qdd:.2g} "
          "vs the blocked discretization")
    path = common.save("superposition", {
        "samples": int(t.size), "method": info.method, "quadrature_nodes": info.quadrature_nodes,
        "engine_s": engine_s, "engine_median_s": engine_median, "first_call_s": first_s,
        "exact_s": reference_s, "exact_median_s": reference_median, "ratio": ratio,
        "engine_faults": engine_faults, "exact_faults": reference_faults,
        "kept": {"engine_s": kept_engine_s, "engine_median_s": kept_engine_median, "exact_s": kept_reference_s,
                 "exact_median_s": kept_reference_median, "ratio": kept_ratio} if kept else None,
        "target_ratio": TARGET_RATIO, "worst_dof_error_q": error_q, "worst_dof_error_qd": error_qd,
        "worst_dof_error_qdd": error_qdd, "exact_blocked_error": error_fast, "target_error": TARGET_ERROR,
        "repeat": repeat,
    })
    print(f"-> {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
