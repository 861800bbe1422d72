"""How the ``sixdof`` command tunes its own process, and the figure workers' it starts (:mod:`sixdof.cli.figures`).

None of it happens on ``import sixdof``, nor for a program that calls :func:`sixdof.cli.main` with its
arguments: their process is their own. Each setting is kept for what it gains on the run it is for, measured
in pairs by ``benchmarks/bench_process.py`` (its table is in ``benchmarks/history.md``).
"""

from __future__ import annotations

import atexit
import ctypes
import gc
import os
import sys
from contextlib import suppress

#: What OpenBLAS reads for its thread count, in this order: a user who set any of them chose (:func:`one_blas_thread`).
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")

#: ``mallopt`` parameters (glibc's ``malloc.h``).
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
#: Free memory kept at the top of the heap [bytes].
TRIM_BYTES = 128 << 20
#: Blocks above this size get a mapping of their own [bytes]: glibc's largest (its adaptive threshold's limit).
MMAP_BYTES = 32 << 20
#: The variables that set them when the process starts: a user's choice is kept (and any ``glibc.malloc``
#: tunable in ``GLIBC_TUNABLES``).
MALLOC_VARIABLES = ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TOP_PAD_", "MALLOC_ARENA_MAX")

#: Allocations between two collections of the youngest objects (Python's default: 700). Garbage still goes
#: at the next collection: the 2000 s bridge run's peak memory is the same either way (640-693 MB).
COLLECT_EVERY = 50_000


#: XLA:CPU settings the command compiles with, where ``XLA_FLAGS`` does not set them already. XLA's newer CPU
#: fusion emitters take longer to compile sixdof's diffrax solve (measured on the bridge: trace and compile
#: 2.20 s without them against 2.65 s with them) and gain it back only over long runs (its execution,
#: 60 against 55 ms); the exact engine's throughput is the same either way.
XLA_DEFAULTS = {"xla_cpu_use_fusion_emitters": "false"}


def with_xla_defaults(flags: str) -> str:
    """``flags`` (an ``XLA_FLAGS`` value) with each of :data:`XLA_DEFAULTS` it does not set appended."""
    given = {item.lstrip("-").split("=", 1)[0] for item in flags.split()}
    added = [f"--{name}={value}" for name, value in XLA_DEFAULTS.items() if name not in given]
    return " ".join([flags.strip(), *added]).strip()


def compile_faster() -> None:
    """Set :data:`XLA_DEFAULTS` in ``XLA_FLAGS``, keeping what the user set there.

    Read when JAX's CPU backend starts, so before the command's first array; the figure workers and Dask's
    local workers inherit it.
    """
    os.environ["XLA_FLAGS"] = with_xla_defaults(os.environ.get("XLA_FLAGS", ""))


def one_blas_thread() -> None:
    """One BLAS thread per process, unless the user chose otherwise: for the commands that draw figures in
    worker processes while they compute (``run``, ``validate``, ``plot``).

    The workers already keep every core busy, and this process' BLAS work is chains of small matrix
    products (the exact engine, the checks) that gain nothing from more threads. OpenBLAS's threads spin
    while they wait for the next product, taking cores from the figures: 0.3-0.4 core-seconds of the bridge
    run, and 25 of the 44 core-seconds of its 2000 s version, which took 30 s either way. Set before NumPy
    loads (it reads the variable then) and before the figure server starts (it inherits it). OpenBLAS takes
    ``OMP_NUM_THREADS`` when its own variable is unset: a user's setting of either is kept.
    """
    if not any(name in os.environ for name in BLAS_THREAD_VARIABLES):
        os.environ["OPENBLAS_NUM_THREADS"] = "1"


def keep_freed_memory() -> bool:
    """Fix glibc's trim and mmap thresholds at :data:`TRIM_BYTES` and :data:`MMAP_BYTES`; whether they were set.

    glibc hands memory back to the system once more than its trim threshold lies free at the top of the heap,
    and serves each block above its mmap threshold with a fresh mapping; both thresholds follow the largest
    block freed so far. A run's arrays of a few MB (the exact engine's temporaries, each window's samples) are
    then mapped or grown anew, and touched page by page, every time: each page is a fault (~2 us on this
    project's VM). Fixed thresholds keep the freed memory for the next array. Nothing is done without glibc
    (no ``mallopt``) or where the user set one of :data:`MALLOC_VARIABLES` or a malloc tunable.
    """
    if any(name in os.environ for name in MALLOC_VARIABLES) or "glibc.malloc." in os.environ.get("GLIBC_TUNABLES", ""):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError, TypeError):  # no C library by that name, no mallopt (Windows: TypeError)
        return False
    mapped, trimmed = mallopt(M_MMAP_THRESHOLD, MMAP_BYTES), mallopt(M_TRIM_THRESHOLD, TRIM_BYTES)
    return bool(mapped and trimmed)


def collect_less() -> None:
    """Collect cyclic garbage every :data:`COLLECT_EVERY` allocations; the older generations' settings are kept.

    Importing JAX and tracing the solve, or matplotlib and drawing figures, allocate millions of objects that
    live to the end of a command. Python looks for reference cycles every 700 allocations by default, so each
    of the ~300 collections of a run searches those objects and finds almost nothing to free.
    """
    gc.set_threshold(COLLECT_EVERY, *gc.get_threshold()[1:])


def skip_teardown(status: list[int]) -> None:
    """End the process without the interpreter's teardown of every module once the command is done.

    Registered before the command imports anything, so that it runs after every exit handler registered
    since (JAX's, multiprocessing's...): what is left is freeing the modules of JAX, diffrax and
    matplotlib one by one, 0.5-0.9 s of a run, for a process whose files are all written and closed.
    ``status`` holds the exit status (the command's, or 1 when it raised: its traceback is printed by then).
    """
    def end() -> None:
        for stream in (sys.stdout, sys.stderr):
            with suppress(OSError, ValueError):  # a closed pipe or stream: nothing left to say there
                stream.flush()
        os._exit(status[0])

    atexit.register(end)
