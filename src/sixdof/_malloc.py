"""glibc's allocator told to keep the memory it frees, in sixdof's own process (the ``sixdof`` command's).

glibc hands memory back to the system once more than its trim threshold lies free at the top of the heap,
and serves each block above its mmap threshold with a fresh mapping; both thresholds follow the largest
block freed so far. A run's arrays of a few MB (the exact engine's temporaries, each window's samples) are
then mapped or grown anew, and touched page by page, every time: each page is a fault (~2 us on this
project's VM). Fixed thresholds keep the freed memory for the next array. Measured on the bridge traffic
scenario lengthened to 2000 s: 12.6 s with 118,000 page faults and a 640 MB peak, against 16.6 s with
199,000 faults and 693 MB with glibc's defaults; the exact engine's 20,001 samples 4.8 against 7.3 ms a call.
"""

import ctypes
import os

#: ``mallopt`` parameters (glibc's ``malloc.h``).
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
#: Free memory kept at the top of the heap [bytes].
TRIM_BYTES = 128 << 20
#: Blocks above this size get a mapping of their own [bytes]: glibc's largest (its adaptive threshold's limit).
MMAP_BYTES = 32 << 20
#: The variables that set them when the process starts: a user's choice is kept (and any ``glibc.malloc``
#: tunable in ``GLIBC_TUNABLES``).
VARIABLES = ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TOP_PAD_", "MALLOC_ARENA_MAX")


def keep_freed_memory() -> bool:
    """Fix glibc's trim and mmap thresholds at :data:`TRIM_BYTES` and :data:`MMAP_BYTES`; whether they were set.

    Process-wide: for the ``sixdof`` command's process, never for a program that calls sixdof as a library.
    Nothing is done without glibc (no ``mallopt``) or where the user set one of :data:`VARIABLES` or a malloc
    tunable.
    """
    if any(name in os.environ for name in VARIABLES) or "glibc.malloc." in os.environ.get("GLIBC_TUNABLES", ""):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError, TypeError):  # no C library by that name, no mallopt (Windows: TypeError)
        return False
    mapped, trimmed = mallopt(M_MMAP_THRESHOLD, MMAP_BYTES), mallopt(M_TRIM_THRESHOLD, TRIM_BYTES)
    return bool(mapped and trimmed)
