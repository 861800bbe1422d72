"""1000 mount-stiffness variants of the bridge beam in one vectorized call against a scipy loop.

sixdof.analysis.batch.run_batch on its exact engine (vmapped assembly and eigh, the excitation evaluated
once per window and shared, every variant's modal coordinates side by side, keeping only peaks and
frequencies) against scipy DOP853 at the tuned tolerance of bench_direct.py (at least sixdof's per-DOF
accuracy) looped over variants: the loop is timed on a subset and extrapolated. The engine is timed
without its cross-check; the cross-check (the default 3 variants solved by sixdof.simulate) is timed
apart, and the diffrax engine (the vmapped solve) on a smaller batch, for comparison.
Peak memory: the batch alone runs again in a subprocess (python bench_batch.py --memory) that
reports its peak resident set size (VmHWM) (XLA's buffers included; tracemalloc would not see them).
Run: python benchmarks/bench_batch.py [--count 1000] [--scipy 20] [--diffrax 64]
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time

import numpy as np

import common

TARGET_THROUGHPUT = 150.0  # batch at least 150x the scipy loop's variants per second
TARGET_MEMORY_GB = 2.0


def variants_for(system, count, seed=1):
    from sixdof.analysis.batch import make_variants

    rng = np.random.default_rng(seed)
    # Every mount, every axis: an independent factor in [0.7, 1.3].
    return make_variants(system, stiffness_factor=rng.uniform(0.7, 1.3, (count, len(system.mounts), 3)))


def _high_water_mb():
    """Peak resident memory of this process [MB]: VmHWM (Linux), else ru_maxrss.

    ru_maxrss of a child started by subprocess can report the parent's size at fork time on
    Linux; VmHWM belongs to the child's own address space.
    """
    try:
        for line in open("/proc/self/status"):
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def memory_run(count):
    from sixdof.analysis.batch import run_batch

    system, excitation, settings = common.bridge_system(), common.excitation(), common.settings()
    before = _high_water_mb()
    start = time.perf_counter()
    result = run_batch(system, variants_for(system, count), excitation, settings, cross_check=0)
    wall = time.perf_counter() - start
    peak = _high_water_mb()
    print(json.dumps({"maxrss_mb": peak, "before_batch_mb": before, "wall_s": wall,
                      "chunk_size": result.chunk_size}))


def timed(fn):
    start = time.perf_counter()
    value = fn()
    return time.perf_counter() - start, value


def main(argv):
    count = int(argv[argv.index("--count") + 1]) if "--count" in argv else 1000
    if "--memory" in argv:
        memory_run(count)
        return
    n_scipy = int(argv[argv.index("--scipy") + 1]) if "--scipy" in argv else 20
    n_diffrax = int(argv[argv.index("--diffrax") + 1]) if "--diffrax" in argv else 64
    from sixdof.analysis.batch import make_variants, run_batch, variant_system
    from sixdof.analysis.direct import state_scale

    system, excitation, settings = common.bridge_system(), common.excitation(), common.settings()
    variants = variants_for(system, count)

    # The first call compiles (the vmapped assembly for this count, the signals); then the batch is timed.
    first_s, _ = timed(lambda: run_batch(system, variants, excitation, settings, cross_check=0))
    batch_s, result = timed(lambda: run_batch(system, variants, excitation, settings, cross_check=0))
    compile_s = max(first_s - batch_s, 0.0)
    print(f"sixdof batch (exact engine): {count} variants in {batch_s:.2f} s ({batch_s / count * 1e3:.2f} ms per "
          f"variant, chunks of {result.chunk_size}), first call +{compile_s:.1f} s", flush=True)
    # The cross-check of a sweep: three variants by sixdof.simulate (diffrax), compiled once per process.
    sample = make_variants(system, stiffness_factor=variants.stiffness_factor[:3])
    run_batch(system, make_variants(system, count=1), excitation, settings, cross_check=1)  # compile simulate
    checked_s, checked = timed(lambda: run_batch(system, sample, excitation, settings))
    cross_check_s = checked_s - timed(lambda: run_batch(system, sample, excitation, settings, cross_check=0))[0]
    print(f"cross-check of 3 variants by diffrax: {cross_check_s:.2f} s, worst peak agreement "
          f"{checked.cross_check.worst:.2g} ({checked.cross_check.worst_dof})", flush=True)
    # The diffrax engine (vmapped solve), for comparison, on fewer variants: one chunk shape compiled first.
    few = make_variants(system, stiffness_factor=variants.stiffness_factor[:n_diffrax])
    run_batch(system, few, excitation, settings, engine="diffrax", cross_check=0)
    diffrax_s, slow = timed(lambda: run_batch(system, few, excitation, settings, engine="diffrax", cross_check=0))
    print(f"sixdof batch (diffrax engine): {n_diffrax} variants in {diffrax_s:.2f} s "
          f"({diffrax_s / n_diffrax * 1e3:.1f} ms per variant)", flush=True)
    diffrax_agreement = float(np.max(np.abs(slow.peak_q - result.peak_q[:n_diffrax]) / result.peak_q[:n_diffrax]))

    tol_file = common.RESULTS / "tuned_tolerances.json"
    tol = json.loads(tol_file.read_text())["DOP853"]["tol"] if tol_file.exists() else 3e-10  # bench_direct's tuning
    t = settings.times
    errors = []
    start = time.perf_counter()
    for i in range(n_scipy):
        one = variant_system(system, variants, i)
        M, C, K = (np.asarray(a) for a in (one.M, one.C, one.K))
        scale = state_scale(one, excitation, settings)[:12]
        q, _ = common.scipy_solve(M, C, K, t, "DOP853", tol, scale)
        peak = np.max(np.abs(q), axis=0)
        errors.append(float(np.max(np.abs(peak - result.peak_q[i]) / peak)))
    scipy_s = (time.perf_counter() - start) / n_scipy
    throughput_ratio = (count / batch_s) / (1.0 / scipy_s)
    with_check = (count / (batch_s + cross_check_s)) / (1.0 / scipy_s)
    print(f"scipy DOP853 loop: {scipy_s:.3f} s per variant (on {n_scipy}); batch throughput "
          f"{throughput_ratio:.0f}x (target >= {TARGET_THROUGHPUT:g}x: "
          + ("met" if throughput_ratio >= TARGET_THROUGHPUT else f"MISSED by {TARGET_THROUGHPUT / throughput_ratio:.1f}x")
          + f"), {with_check:.0f}x with the cross-check; diffrax engine "
          f"{(n_diffrax / diffrax_s) / (1.0 / scipy_s):.0f}x; peak agreement with scipy {max(errors):.2g}, "
          f"diffrax engine with exact {diffrax_agreement:.2g}", flush=True)

    mem = subprocess.run([sys.executable, __file__, "--memory", "--count", str(count)],
                         capture_output=True, text=True, check=True)
    memory = json.loads(mem.stdout.strip().splitlines()[-1])
    print(f"peak memory (subprocess, maxrss): {memory['maxrss_mb']:.0f} MB", flush=True)
    path = common.save("batch", {
        "count": count, "engine": result.engine, "chunk_size": result.chunk_size, "batch_s": batch_s,
        "compile_s": compile_s, "batch_per_variant_s": batch_s / count, "scipy_subset": n_scipy,
        "scipy_per_variant_s": scipy_s, "scipy_extrapolated_s": scipy_s * count,
        "throughput_ratio": throughput_ratio, "throughput_ratio_with_cross_check": with_check,
        "target_throughput": TARGET_THROUGHPUT, "cross_check_s": cross_check_s,
        "cross_check_worst": checked.cross_check.worst, "diffrax_count": n_diffrax, "diffrax_s": diffrax_s,
        "diffrax_per_variant_s": diffrax_s / n_diffrax, "diffrax_vs_exact_peaks": diffrax_agreement,
        "max_steps_in_diffrax_batch": int(slow.num_steps.max()), "peak_agreement_vs_scipy": max(errors),
        "scipy_tol": tol, "memory": memory, "target_memory_gb": TARGET_MEMORY_GB,
    })
    print(f"-> {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
