"""The direct solve (sixdof.analysis.direct): speed at equal accuracy, its choices, and long runs.

1. The bridge beam, 20 s at 1 kHz, harmonic plus pulse loads moving all six DOFs, non-proportional
   mount dashpots: sixdof's default solve against scipy solve_ivp and the exact discretization. scipy's
   tolerances are tuned (once per target, cached in results/tuned_tolerances.json; --retune redoes it)
   until its worst per-DOF error is no larger than sixdof's: the timings compare equal per-DOF accuracy.
2. The choice of the default solver and tolerances: time, steps, error and compile time of candidates.
3. What the per-step machinery costs (each variant compiled apart, timed round robin in one process):
   diffrax's own stage loop instead of unrolled stages, no dense output at the 20,001 samples, no
   breakpoint clipping, windows of 4096 samples instead of one, and the progress meter.
4. simulate() in fresh processes: cold (empty caches) and repeated (the exported solve and the
   persistent compilation cache), with the import of the module.
5. A 2000 s run at 1 kHz of the bridge traffic scenario through simulate_windows, windows discarded:
   its time and peak memory (a subprocess).

Run: python benchmarks/bench_direct.py [--retune] [--skip-long]
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np

import common

TARGET_SPEEDUP = 8.0  # sixdof at least 8x faster than scipy DOP853 at equal per-DOF accuracy
TARGET_PROGRESS = 0.05  # the progress meter costs under 5 % of the solve
TARGET_LONG_RUN_S = 35.0  # the whole 2000 s run, writing included: the solve must leave room
TARGET_LONG_RUN_GB = 1.0  # peak memory of the whole 2000 s run
CANDIDATES = [("Tsit5", 1e-9), ("Tsit5", 1e-10), ("Dopri8", 1e-9), ("Dopri8", 1e-10), ("Dopri8", 1e-11)]
ROUNDS = 7


def tune(method, M, C, K, t, scale, q_ref, target, start):
    """Loosest tolerance (within a few tries) whose worst per-DOF error is <= target."""
    tol, tried = start, []
    for _ in range(7):
        q, _ = common.scipy_solve(M, C, K, t, method, tol, scale)
        err = common.worst_dof_error(q, q_ref)
        tried.append((tol, err))
        print(f"  {method} tol={tol:.3g}: worst per-DOF error {err:.3g} (target {target:.3g})", flush=True)
        if 0.6 * target <= err <= target:
            break
        # Global error ~ tol^~1 here; aim a little under the target.
        tol = tol * (0.8 * target / err) ** (1.0 if err > target else 0.9)
    ok = [(t_, e) for t_, e in tried if e <= target]
    return max(ok)[0] if ok else min(tried)[0]


def round_robin(functions: dict, rounds: int = ROUNDS) -> dict:
    """Best wall time [s] of each function, called in turn ``rounds`` times (the machine's load drifts)."""
    times = {name: [] for name in functions}
    for _ in range(rounds):
        for name, fn in functions.items():
            start = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - start)
    return {name: min(t) for name, t in times.items()}


def variant(system, excitation, settings, *, window_samples=None, unrolled=True, dense=True, clip=True):
    """A function running every window of one solve compiled with the given machinery, and the time of its first
    run (tracing and compiling included)."""
    import diffrax

    from sixdof._jax import jnp
    from sixdof.analysis import direct
    from sixdof.analysis import unrolled as unrolled_module
    from sixdof.analysis.direct import cache, solve, windows

    window_samples = window_samples or direct.WINDOW_SAMPLES
    solve_ode, solver = solve.solve_ode, unrolled_module.solver

    def patched_solve_ode(field, x0, t0, t1, saveat, jump_ts, *args, **kwargs):
        if not dense:  # save only the end, then spread it over the samples: the outputs' cost stays
            import equinox as eqx

            ts = saveat.subs.ts
            sol = solve_ode(field, x0, t0, t1, diffrax.SaveAt(t1=True), jump_ts, *args, **kwargs)
            return eqx.tree_at(lambda s: s.ys, sol, jnp.broadcast_to(sol.ys, (ts.size, x0.size)) + 0 * ts[:, None])
        return solve_ode(field, x0, t0, t1, saveat, jump_ts if clip else jump_ts[:0], *args, **kwargs)

    solve.solve_ode = patched_solve_ode
    if not unrolled:
        unrolled_module.solver = lambda name: getattr(diffrax, name)()
    cache._COMPILED.clear()
    try:
        start = time.perf_counter()
        run, xs0 = windows._prepare(system, excitation, settings, direct.window_length(settings.samples, window_samples))

        def go():
            xs, region, histories = xs0, run.region, []
            for ts, end in direct.window_spans(settings, run.window):
                history, xs, region = windows._window(run, xs, region, ts, end, settings)
                histories.append(history)
            return histories

        go()  # traced and compiled at its first call
        first_s = time.perf_counter() - start
    finally:
        solve.solve_ode, unrolled_module.solver = solve_ode, solver
        cache._COMPILED.clear()
    return go, first_s


def fresh_processes(repeats: int = 3) -> dict:
    """simulate() of the benchmark problem in fresh processes: cold (empty caches) and repeated."""
    script = textwrap.dedent(f"""
        import sys, time, json
        start = time.perf_counter()
        from sixdof._jax import enable_compilation_cache
        enable_compilation_cache()
        from sixdof.analysis.direct import simulate
        imported = time.perf_counter() - start
        sys.path.insert(0, {str(common.HERE)!r})
        import common
        system, excitation, settings = common.bridge_system(), common.excitation(), common.settings()
        start = time.perf_counter()
        simulate(system, excitation, settings)
        print(json.dumps({{"import_s": imported, "simulate_s": time.perf_counter() - start,
                          "diffrax_imported": "diffrax" in sys.modules}}))
    """)
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "SIXDOF_JAX_CACHE": cache}
        env.pop("EQX_ON_ERROR", None)
        runs = [json.loads(subprocess.run([sys.executable, "-c", script], env=env, check=True, capture_output=True,
                                          text=True).stdout.strip().splitlines()[-1]) for _ in range(repeats + 1)]
    repeated = runs[1:]
    return {"cold_s": runs[0]["simulate_s"], "cold_import_s": runs[0]["import_s"],
            "repeated_s": float(np.median([r["simulate_s"] for r in repeated])),
            "repeated_import_s": float(np.median([r["import_s"] for r in repeated])),
            "repeated_imports_diffrax": any(r["diffrax_imported"] for r in repeated)}


def long_run(duration: float = 2000.0, rate: float = 1000.0) -> dict:
    """The bridge traffic scenario for ``duration`` s through simulate_windows, windows discarded (a subprocess)."""
    script = textwrap.dedent(f"""
        import json, time
        from sixdof.analysis.direct import SimulationSettings, WINDOW_SAMPLES, simulate, simulate_windows
        from sixdof.io.scenario import load_scenario

        def peak_mb():
            for line in open("/proc/self/status"):
                if line.startswith("VmHWM"):
                    return int(line.split()[1]) / 1024

        scenario = load_scenario({str(common.SCENARIO)!r})
        # Compile first, on a run of one full window (the same structure as the long run's windows).
        start = time.perf_counter()
        simulate(scenario.system, scenario.excitation,
                 SimulationSettings(duration=(WINDOW_SAMPLES - 1) / {rate}, sample_rate_hz={rate}))
        compile_s = time.perf_counter() - start
        before = peak_mb()
        settings = SimulationSettings(duration={duration}, sample_rate_hz={rate})
        start = time.perf_counter()
        windows = samples = steps = 0
        largest = 0.0
        for window in simulate_windows(scenario.system, scenario.excitation, settings):
            windows += 1
            samples += window.t.size
            steps += window.stats.num_steps
            largest = max(largest, float(abs(window.q).max()))
        print(json.dumps({{"solve_s": time.perf_counter() - start, "compile_s": compile_s, "windows": windows,
                          "samples": samples, "steps": steps, "peak_mb_before": before, "peak_mb": peak_mb()}}))
    """)
    done = subprocess.run([sys.executable, "-c", script], check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv):
    retune = "--retune" in argv
    start = time.perf_counter()
    from sixdof.analysis import direct
    from sixdof.analysis.direct import simulate, state_scale
    import_s = time.perf_counter() - start

    system, excitation, settings = common.bridge_system(), common.excitation(), common.settings()
    M, C, K = (np.asarray(a) for a in (system.M, system.C, system.K))
    t = settings.times
    exact_best, _, q_ref = common.best(lambda: common.exact(M, C, K, t), 3)

    # 1. The default against scipy at equal per-DOF accuracy, timed round robin (the machine's load drifts).
    first = time.perf_counter()
    response = simulate(system, excitation, settings)
    compile_s = time.perf_counter() - first
    err_sixdof = common.worst_dof_error(response.q, q_ref)
    stats = response.stats
    scale = state_scale(system, excitation, settings)[:12]
    cache_file = common.RESULTS / "tuned_tolerances.json"
    cached = json.loads(cache_file.read_text()) if cache_file.exists() and not retune else {}
    tolerances, results = {}, {}
    for method in ("DOP853", "RK45"):
        entry = cached.get(method)
        if not isinstance(entry, dict) or abs(entry["target"] / err_sixdof - 1) > 0.05:
            entry = {"target": err_sixdof, "tol": tune(method, M, C, K, t, scale, q_ref, err_sixdof, 1e-9)}
            cached[method] = entry
        tolerances[method] = entry["tol"]
    common.RESULTS.mkdir(exist_ok=True)
    cache_file.write_text(json.dumps(cached, indent=2))

    def scipy(method):
        def solve():
            results[method] = common.scipy_solve(M, C, K, t, method, tolerances[method], scale)
        return solve

    best = round_robin({"sixdof": lambda: simulate(system, excitation, settings), "DOP853": scipy("DOP853")}, 5)
    best.update(round_robin({"RK45": scipy("RK45")}, 1))
    run_best = best["sixdof"]
    compile_s -= run_best
    windows = f"{stats.num_windows} window{'s' if stats.num_windows > 1 else ''}"
    print(f"sixdof ({settings.solver}, rtol=atol={settings.rtol:g}): {run_best * 1e3:.1f} ms (trace + compile "
          f"{compile_s:.2f} s), {stats.num_steps} steps in {windows}, worst per-DOF error {err_sixdof:.3g} "
          f"(today's bar: every DOF within ~1e-7 of its peak)", flush=True)
    stages = 14 if settings.solver == "Dopri8" else 7
    rows = [{"method": f"sixdof ({settings.solver}, diffrax, unrolled stages)", "tol": settings.rtol,
             "time_s": run_best, "compile_s": compile_s, "steps": stats.num_steps, "rejected": stats.num_rejected,
             "rhs_evaluations": stages * stats.num_steps, "worst_dof_error": err_sixdof, "ratio_vs_sixdof": 1.0}]
    for method in ("DOP853", "RK45"):
        q, nfev = results[method]
        err = common.worst_dof_error(q, q_ref)
        print(f"scipy {method}: {best[method] * 1e3:.0f} ms at tol {tolerances[method]:.3g}, nfev {nfev}, worst "
              f"error {err:.3g}", flush=True)
        rows.append({"method": f"scipy solve_ivp {method}", "tol": tolerances[method], "time_s": best[method],
                     "compile_s": 0.0, "rhs_evaluations": int(nfev), "worst_dof_error": err,
                     "ratio_vs_sixdof": best[method] / run_best})
    rows.append({"method": "exact discretization (expm, numpy loop)", "tol": None, "time_s": exact_best,
                 "compile_s": 0.0, "worst_dof_error": 0.0, "ratio_vs_sixdof": exact_best / run_best})
    speedup = best["DOP853"] / run_best
    print(f"speed-up vs DOP853 at equal per-DOF accuracy: {speedup:.1f}x (target >= {TARGET_SPEEDUP:g}x)", flush=True)

    # 2. Candidates for the default: each compiled apart, timed round robin.
    candidates, compiles = {}, {}
    for solver, tol in CANDIDATES:
        name = f"{solver} {tol:g}"
        candidates[name], compiles[name] = variant(system, excitation, common.settings(solver=solver, rtol=tol, atol=tol))
    best = round_robin(candidates)
    choice = []
    for (solver, tol), name in zip(CANDIDATES, candidates):
        windows = candidates[name]()
        q = np.concatenate([w.q for w in windows])
        steps = sum(w.stats.num_steps for w in windows)
        choice.append({"solver": solver, "tol": tol, "time_s": best[name], "compile_s": compiles[name], "steps": steps,
                       "worst_dof_error": common.worst_dof_error(q, q_ref)})
        print(f"candidate {name:12s}: {best[name] * 1e3:6.1f} ms, {steps:6d} steps, worst per-DOF error "
              f"{choice[-1]['worst_dof_error']:.2g}, first run (trace + compile) {compiles[name]:.2f} s", flush=True)

    # 3. What the machinery costs.
    machinery = {"default": {}, "diffrax's stage loop": {"unrolled": False}, "no dense output": {"dense": False},
                 "no breakpoint clipping": {"clip": False}, "windows of 4096 samples": {"window_samples": 4096}}
    functions = {name: variant(system, excitation, settings, **options)[0] for name, options in machinery.items()}
    quiet = io.StringIO()

    def with_progress(kind):
        def go():
            with contextlib.redirect_stderr(quiet):
                simulate(system, excitation, settings, progress=kind)
        return go

    simulate(system, excitation, settings)
    functions["simulate()"] = lambda: simulate(system, excitation, settings)
    functions["simulate(progress='text')"] = with_progress("text")
    functions["simulate(progress='tqdm')"] = with_progress("tqdm")
    with_progress("tqdm")()
    costs = round_robin(functions)
    base = costs["default"]
    for name, seconds in costs.items():
        print(f"machinery {name:28s}: {seconds * 1e3:6.1f} ms ({seconds / base:.2f}x the default)", flush=True)
    difference = max(costs["simulate(progress='text')"], costs["simulate(progress='tqdm')"]) / costs["simulate()"] - 1
    # The meter does nothing while a window is solved: its whole cost is what it does between windows.
    meter = {}
    for kind in ("text", "tqdm"):
        def draw(kind=kind):
            with contextlib.redirect_stderr(quiet):
                shown = direct.progress_meter(kind, settings)
                for ts, _ in direct.window_spans(settings, direct.window_length(settings.samples)):
                    shown.show(float(ts[-1]))
                shown.close()
        meter[kind] = common.best(draw, 20)[0]
    progress = max(meter.values()) / costs["simulate()"]
    print(f"progress meter overhead: {progress:.2%} of the solve (text {meter['text'] * 1e6:.0f} us, tqdm "
          f"{meter['tqdm'] * 1e6:.0f} us per run, target < {TARGET_PROGRESS:.0%}); difference of the timings "
          f"above {difference:+.1%} (within the machine's noise)", flush=True)

    # 4. Fresh processes.
    fresh = fresh_processes()
    print(f"fresh process: import of sixdof.analysis.direct {fresh['repeated_import_s']:.2f} s; simulate() cold "
          f"{fresh['cold_s']:.2f} s (trace + compile), repeated {fresh['repeated_s']:.2f} s (median of 3; imports "
          f"diffrax: {fresh['repeated_imports_diffrax']})", flush=True)

    # 5. 2000 s at 1 kHz.
    long = None if "--skip-long" in argv else long_run()
    if long:
        print(f"2000 s at 1 kHz: {long['samples']} samples in {long['windows']} windows, {long['steps']} steps: "
              f"solve {long['solve_s']:.1f} s (the whole run, writing included, target <= {TARGET_LONG_RUN_S:g} s), "
              f"peak memory {long['peak_mb']:.0f} MB ({long['peak_mb_before']:.0f} MB before the run; the whole "
              f"run's target < {TARGET_LONG_RUN_GB * 1024:.0f} MB)", flush=True)

    path = common.save("direct", {
        "rows": rows, "speedup_vs_dop853": speedup, "target_speedup": TARGET_SPEEDUP, "import_s": import_s,
        "samples": int(t.size), "windows": stats.num_windows, "solver": settings.solver, "tol": settings.rtol,
        "candidates": choice, "machinery": {name: s for name, s in costs.items()},
        "progress_overhead": progress, "progress_meter_s": meter, "progress_timing_difference": difference,
        "target_progress": TARGET_PROGRESS, "fresh": fresh, "long_run": long,
        "target_long_run_s": TARGET_LONG_RUN_S, "target_long_run_gb": TARGET_LONG_RUN_GB,
        "window_samples": direct.WINDOW_SAMPLES,
    })
    print(f"-> {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
