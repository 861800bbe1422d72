"""A sweep of 100,000 bridge variants in chunks, in this process and on local Dask clusters (issue 20).

Each configuration runs `sixdof sweep` through its Python entry (sixdof.workflows.sweep.sweep_scenario, files and all:
chunk files as they finish, the merge into sweep.h5, the cross-check of 3 variants by diffrax) in a fresh
process, the client, which reports its wall time and its peak resident memory (VmHWM; the Dask workers are
other processes, their memory is not counted). The spec is the bundled bearing_tolerance.toml (every bearing
and axis drawn uniform in [0.7, 1.3]) with its count raised; chunks of 1000 variants.

Configurations:
- "in-process, 1 thread": the chunks one after another in the client, BLAS and XLA limited to one thread (the
  work one worker does);
- "in-process": the same with the default threads (what `sixdof sweep` does without --workers);
- "dask-local, N workers": `--workers N`, a local cluster of N single-threaded worker processes (N = 1..4 on
  this 2-core machine: beyond 2 they share cores).

Compilation: the in-process configurations compile their solvers in the client (~3 s of each run; the Python
entry leaves JAX's persistent cache off, as the library does). Dask workers turn the persistent cache on
(a temporary folder shared by every configuration): the first Dask configuration ("1 workers") compiles
and fills it, the later ones load from it, as workers do after a first sweep.

Run: python benchmarks/bench_sweep.py [--count 100000] [--scaling 20000] [--workers 1 2 3 4]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import common

SPEC = common.ROOT / "scenarios" / "sweeps" / "bearing_tolerance.toml"
ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "XLA_FLAGS": "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"}


def _high_water_mb() -> float:
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def one(count: int, workers: int, out: str) -> None:
    """The client of one configuration (this process): a sweep of ``count`` variants; prints one JSON line."""
    import dataclasses

    from sixdof.io.scenario import load_scenario
    from sixdof.io.sweep import load_sweep_spec
    from sixdof.workflows.sweep import sweep_scenario

    start = time.perf_counter()
    scenario = load_scenario(common.SCENARIO)
    spec = dataclasses.replace(load_sweep_spec(SPEC), count=count)
    result, _ = sweep_scenario(scenario, spec, out, workers=workers or None)
    wall = time.perf_counter() - start
    print(json.dumps({"wall_s": wall, "client_peak_mb": _high_water_mb(), "chunks": result.chunks,
                      "backend": result.backend, "workers": result.workers,
                      "cross_check_worst": result.cross_check.worst}))


def measure(label: str, count: int, workers: int, env: dict, cache: str) -> dict:
    with tempfile.TemporaryDirectory() as out:
        run = subprocess.run([sys.executable, __file__, "--one", str(count), str(workers), out], text=True,
                             capture_output=True, env={**os.environ, **env, "SIXDOF_JAX_CACHE": cache})
        if run.returncode:
            raise SystemExit(f"{label} failed:\n{run.stderr[-3000:]}")
        found = json.loads(run.stdout.strip().splitlines()[-1])
    found.update(label=label, count=count, variants_per_s=count / found["wall_s"])
    print(f"{label:28s} {count:7d} variants  {found['wall_s']:7.1f} s  {found['variants_per_s']:6.0f} variants/s  "
          f"client peak {found['client_peak_mb']:.0f} MB", flush=True)
    return found


def main(argv) -> None:
    if "--one" in argv:
        at = argv.index("--one")
        one(int(argv[at + 1]), int(argv[at + 2]), argv[at + 3])
        return
    count = int(argv[argv.index("--count") + 1]) if "--count" in argv else 100_000
    scaling = int(argv[argv.index("--scaling") + 1]) if "--scaling" in argv else 20_000
    counts = [int(a) for a in argv[argv.index("--workers") + 1:] if a.isdigit()] if "--workers" in argv else [1, 2, 3, 4]
    with tempfile.TemporaryDirectory() as cache:
        measure("warm-up (fills the cache)", 2000, 0, {}, cache)
        curve = [measure("in-process, 1 thread", scaling, 0, ONE_THREAD, cache),
                 measure("in-process", scaling, 0, {}, cache)]
        curve += [measure(f"dask-local, {n} workers", scaling, n, {}, cache) for n in counts]
        big = [measure("in-process", count, 0, {}, cache), measure("dask-local, 2 workers", count, 2, {}, cache)]
    base = curve[0]["variants_per_s"]
    for row in curve + big:
        row["speedup_vs_one_thread"] = row["variants_per_s"] / base
    path = common.save("sweep", {"count": count, "scaling_count": scaling, "chunk_size": 1000, "curve": curve,
                                 "large": big, "cores": os.cpu_count()})
    print(f"wrote {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
