"""What each of the ``sixdof`` command's process settings (:mod:`sixdof.cli._process`, the figure workers of
:mod:`sixdof.cli.figures`) gains on the run it is for, measured in pairs (issue 46, item 4).

Each setting is switched off in one run of a pair and left on in the other, the two back to back and in
alternating order (the shared 2-core machine's speed drifts by 20-50 % between sittings: only such pairs
compare). Every run is a fresh process running this checkout's ``sixdof run ... --quiet`` through a few lines
that replace the setting's function by one doing nothing before :func:`sixdof.cli.main` starts (and, for those
of the figure server, a module the server imports first). Each run's wall time is from its launch until its
output is closed, its CPU time that of every process of the run (the command's, the figure server's and its
workers': this process is their subreaper, so that each is counted once it ends).

The settings and the runs they are for:

- ``pool``: the figures drawn in worker processes while the run computes (off: in the command's process at the
  end, :class:`sixdof.plots.drawer.InProcessDrawer`): the bridge run cold and repeated, the traffic run;
- ``gc``: fewer garbage collections in the command's process and the figure server's, and what the server loaded
  frozen out of them: the bridge and traffic runs repeated;
- ``blas``: OpenBLAS on one thread: the traffic run, the long run;
- ``malloc``: glibc's allocator keeping the memory it frees: the long run;
- ``teardown``: the process ending without the interpreter's teardown: the bridge run repeated;
- ``cache``: JAX's persistent compilation cache (off: ``SIXDOF_JAX_CACHE=off``): the bridge run repeated.

Cold runs have sixdof's caches empty (a fresh ``XDG_CACHE_HOME`` each); repeated runs share caches filled by one
run of each side first. The long run is the traffic scenario lengthened to ``--long-duration`` seconds (the
2000 s run of ``bench_cli.py`` scaled down: its time is mostly per sample). Run:
``python benchmarks/bench_process.py [--pairs 5] [--only pool,gc] [--runs 'bridge cold,long'] [--long-duration 100]``; writes
``results/process.json`` (``process-<settings>.json`` with ``--only``) and prints the table ``history.md`` holds.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import common

BRIDGE = common.ROOT / "scenarios" / "bridge_beam.toml"
TRAFFIC = common.ROOT / "scenarios" / "bridge_beam_traffic.toml"
#: Setting -> the runs it is measured on, in the order they are measured.
RUNS = {
    "pool": ("bridge repeated", "bridge cold", "traffic repeated"),
    "gc": ("bridge repeated", "traffic repeated"),
    "malloc": ("long",),
    "teardown": ("bridge repeated",),
    "blas": ("long", "traffic repeated"),
    "cache": ("bridge repeated",),
}

# The command, with the settings named in its first argument switched off.
COMMAND = r"""
import os, sys
off = set(filter(None, sys.argv[1].split(",")))
from sixdof.cli import _process, figures
nothing = lambda *args: None
if "malloc" in off:
    _process.keep_freed_memory = nothing
if "gc" in off:
    _process.collect_less = nothing
if "blas" in off:
    _process.one_blas_thread = nothing
if "teardown" in off:
    _process.skip_teardown = nothing
if "pool" in off:
    from sixdof.plots.drawer import InProcessDrawer
    figures.FigureWorkers = lambda *args, **kwargs: InProcessDrawer()
if "cache" in off:
    os.environ["SIXDOF_JAX_CACHE"] = "off"
os.environ["SIXDOF_BENCH_OFF"] = ",".join(off)  # for the figure server, which the command starts
figures._PRELOAD = ["bench_process_server"]
sys.argv = ["sixdof", *sys.argv[2:]]
from sixdof._entry import main
sys.exit(main())
"""

# Imported by the figure server instead of sixdof.cli._warm, which it imports once its settings are switched off.
SERVER = r"""
import gc, os
from sixdof.cli import _process
off = os.environ["SIXDOF_BENCH_OFF"].split(",")
if "gc" in off:
    _process.collect_less = gc.freeze = lambda: None
import sixdof.cli._warm
open(os.environ["SIXDOF_BENCH_SERVED"], "a").close()  # the server imports what a failed preload would skip
"""


def become_subreaper() -> None:
    """Orphaned descendants (the figure server and workers outlive the command by a moment) become this
    process' children, so that their CPU time is counted once they are waited for (Linux)."""
    PR_SET_CHILD_SUBREAPER = 36
    if ctypes.CDLL(None).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) != 0:
        raise OSError("prctl(PR_SET_CHILD_SUBREAPER) failed: CPU times would miss the figure workers")


def reap() -> None:
    """Wait for every descendant left (each ends when the command has ended)."""
    while True:
        try:
            os.waitpid(-1, 0)
        except ChildProcessError:
            return


def measure(off: list[str], scenario: Path, env: dict, work: Path) -> dict:
    """One run with the settings ``off`` switched off: wall and CPU time [s], page faults, the largest peak memory."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    served = work / "served"
    served.unlink(missing_ok=True)
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", COMMAND, ",".join(off), "run", str(scenario), "--quiet",
                           "--out", str(work / "out")], env={**env, "SIXDOF_BENCH_SERVED": str(served)},
                          cwd=work, capture_output=True, text=True)
    wall = time.perf_counter() - start
    reap()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"sixdof run {scenario.name} with {off} off failed:\n{proc.stderr[-3000:]}")
    if "pool" not in off and not served.exists():
        raise RuntimeError("the figure server did not import bench_process_server: its settings were not switched")
    return {"wall_s": wall, "cpu_s": after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime,
            "faults": after.ru_minflt - before.ru_minflt, "peak_mb": after.ru_maxrss / 1024}


def environment(cache: Path, server: Path) -> dict:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("JAX_", "EQX_", "SIXDOF_", "XLA_", "MALLOC_", "GLIBC_TUNABLES"))
           and k not in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS", "PYTHONDONTWRITEBYTECODE")}
    env["PYTHONPATH"] = os.pathsep.join([str(common.ROOT / "src"), str(server)])
    env["XDG_CACHE_HOME"] = str(cache)
    return env


def lengthened(duration: float, work: Path) -> Path:
    """The traffic scenario lengthened to ``duration`` seconds."""
    text = TRAFFIC.read_text()
    longer = re.sub(r"^duration = [0-9.]+", f"duration = {duration}", text, count=1, flags=re.M)
    assert longer != text, "the scenario's duration line moved: update bench_process.lengthened"
    path = work / "bridge_long.toml"
    path.write_text(longer)
    return path


def pairs(setting: str, run: str, count: int, work: Path, server: Path, long: Path) -> list[dict]:
    """``count`` pairs of runs with ``setting`` on and off, in alternating order."""
    scenario = {"bridge": BRIDGE, "traffic": TRAFFIC, "long": long}[run.split()[0]]
    cold = run.endswith("cold")
    shared = environment(work / f"cache-{setting}-{run.replace(' ', '-')}", server)
    if not cold:  # the caches each side reads, filled
        for off in ([], [setting]):
            measure(off, scenario, shared, work)
    found = []
    for k in range(count):
        pair = {}
        for side in (("on", "off") if k % 2 == 0 else ("off", "on")):
            env = environment(work / f"cold-{k}-{side}", server) if cold else shared
            pair[side] = measure([setting] if side == "off" else [], scenario, env, work)
            if cold:
                shutil.rmtree(work / f"cold-{k}-{side}", ignore_errors=True)
        found.append(pair)
        print(f"  {setting:8s} {run:16s} pair {k + 1}: on {pair['on']['wall_s']:.2f} s wall, "
              f"{pair['on']['cpu_s']:.2f} s CPU; off {pair['off']['wall_s']:.2f} s, {pair['off']['cpu_s']:.2f} s",
              flush=True)
    return found


def ratios(found: list[dict], key: str) -> list[float]:
    """Each pair's on / off ratio of ``key`` (below 1: the setting gains)."""
    return [pair["on"][key] / pair["off"][key] for pair in found]


def spread(values: list[float]) -> str:
    return f"{statistics.median(values):.3f} ({min(values):.3f}-{max(values):.3f})"


def table(measured: dict, count: int) -> str:
    lines = [f"| setting | run | wall on / off, median (range of {count} pairs) | CPU on / off | median wall on, off "
             "| median CPU on, off |", "|---|---|---|---|---|---|"]
    for setting, runs in measured.items():
        for run, found in runs.items():
            wall = [statistics.median(p[side]["wall_s"] for p in found) for side in ("on", "off")]
            cpu = [statistics.median(p[side]["cpu_s"] for p in found) for side in ("on", "off")]
            lines.append(f"| {setting} | {run} | {spread(ratios(found, 'wall_s'))} | {spread(ratios(found, 'cpu_s'))} "
                         f"| {wall[0]:.2f}, {wall[1]:.2f} s | {cpu[0]:.2f}, {cpu[1]:.2f} s |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pairs", type=int, default=5, help="pairs of runs per setting and run (default 5)")
    parser.add_argument("--only", default=",".join(RUNS), help=f"settings to measure, comma-separated ({', '.join(RUNS)})")
    parser.add_argument("--runs", default="", help="measure only these runs, comma-separated (bridge cold, bridge "
                        "repeated, traffic cold, traffic repeated, long; default: every run of each setting)")
    parser.add_argument("--long-duration", type=float, default=100.0, help="the long run's duration [s] (default 100)")
    args = parser.parse_args()
    chosen = [name for name in args.only.split(",") if name]
    unknown = sorted(set(chosen) - set(RUNS))
    if unknown:
        parser.error(f"unknown settings {unknown}; choose among {list(RUNS)}")
    # One file per set of settings measured, so that sets measured side by side each keep their own.
    name = "process" if chosen == list(RUNS) else "process-" + "-".join(chosen)
    become_subreaper()
    work = Path(tempfile.mkdtemp(prefix="sixdof-bench-process-"))
    server = work / "server"
    server.mkdir()
    (server / "bench_process_server.py").write_text(SERVER)
    subprocess.run([sys.executable, "-m", "compileall", "-q", str(common.ROOT / "src")], check=True)
    long = lengthened(args.long_duration, work)
    measured: dict[str, dict[str, list[dict]]] = {}
    try:
        for setting in chosen:
            for run in RUNS[setting]:
                if not args.runs or run in args.runs.split(","):
                    measured.setdefault(setting, {})[run] = pairs(setting, run, args.pairs, work, server, long)
                    common.save(name, {"pairs": args.pairs, "long_duration_s": args.long_duration,
                                            "measured": measured})  # so far, in case the rest is stopped
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"\nThe long run: the traffic scenario lengthened to {args.long_duration:g} s.\n")
    print(table(measured, args.pairs))
    path = common.save(name, {"pairs": args.pairs, "long_duration_s": args.long_duration, "measured": measured})
    print(f"-> {path}")


if __name__ == "__main__":
    main()
