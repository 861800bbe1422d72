"""End-to-end ``sixdof run`` of the bridge traffic scenario, cold and repeated (subprocesses).

Four timings, each a fresh process (``sixdof run scenarios/bridge_beam_traffic.toml --quiet``):
- cold, no persistent cache (SIXDOF_JAX_CACHE=off and no JAX cache variables);
- cold with an empty persistent JAX compilation cache (JAX_COMPILATION_CACHE_DIR + EQX_ON_ERROR=nan,
  what sixdof._jax.enable_compilation_cache sets up), which fills it;
- repeated with that cache filled (median of 3), and the number of cache files;
- repeated without a cache (median of 2): what a user gets today when the CLI does not enable it.
Also the import time of the package alone. Run: python benchmarks/bench_cli.py
"""

from __future__ import annotations

import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import common

TARGET_COLD_S, TARGET_REPEATED_S = 4.0, 2.5


def timed(args, env, cwd):
    start = time.perf_counter()
    proc = subprocess.run(args, env=env, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} failed:\n{proc.stderr[-2000:]}")
    return wall


def main(argv):
    exe = shutil.which("sixdof") or str(Path(sys.executable).with_name("sixdof"))
    work = Path(tempfile.mkdtemp(prefix="sixdof-bench-"))
    cache = work / "jax-cache"
    base = {k: v for k, v in os.environ.items() if not k.startswith(("JAX_", "EQX_", "SIXDOF_"))}
    base["SIXDOF_JAX_CACHE"] = "off"
    run = [exe, "run", str(common.SCENARIO), "--quiet", "--out", str(work / "out")]
    with_cache = {**base, "JAX_COMPILATION_CACHE_DIR": str(cache), "EQX_ON_ERROR": "nan",
                  "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": "0",
                  "JAX_PERSISTENT_CACHE_MIN_ENTRY_SIZE_BYTES": "0"}
    imp = min(timed([sys.executable, "-c", "import sixdof.analysis.direct, sixdof.workflows"], base, work) for _ in range(3))
    print(f"import sixdof.analysis.direct + sixdof.workflows: {imp:.2f} s", flush=True)
    cold = timed(run, base, work)
    print(f"cold, no cache: {cold:.2f} s", flush=True)
    cold_cache = timed(run, with_cache, work)
    files = sum(1 for p in cache.rglob("*") if p.is_file())
    print(f"cold, empty persistent cache: {cold_cache:.2f} s ({files} cache files written)", flush=True)
    warm = [timed(run, with_cache, work) for _ in range(3)]
    print(f"repeated, persistent cache: {warm}", flush=True)
    nocache = [timed(run, base, work) for _ in range(2)]
    print(f"repeated, no cache: {nocache}", flush=True)
    path = common.save("cli", {
        "command": " ".join(["sixdof", *run[1:3], "--quiet"]), "import_s": imp, "cold_s": cold,
        "cold_empty_cache_s": cold_cache, "cache_files": files,
        "repeated_cache_s": statistics.median(warm), "repeated_cache_best_s": min(warm),
        "repeated_no_cache_s": statistics.median(nocache),
        "target_cold_s": TARGET_COLD_S, "target_repeated_s": TARGET_REPEATED_S,
    })
    shutil.rmtree(work, ignore_errors=True)
    print(f"-> {path}")


if __name__ == "__main__":
    main(sys.argv[1:])
