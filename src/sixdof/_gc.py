"""Fewer garbage collections in sixdof's own processes: the command's, and the figure workers'.

Importing JAX and tracing the solve, or matplotlib and drawing figures, allocate millions of objects that
live to the end of a command. Python looks for reference cycles every 700 allocations by default, so each
of the ~300 collections of a run searches those objects and finds almost nothing to free: 0.15-0.23 s of
the command's process (0.06-0.09 s with this module's setting, for ~20 MB more peak memory), and ~8 % of a
figure worker's drawing, measured on the bridge traffic run.
"""

import gc

#: Allocations between two collections of the youngest objects (Python's default: 700). Garbage still goes
#: at the next collection: the 2000 s bridge run's peak memory is the same either way (640-693 MB).
COLLECT_EVERY = 50_000


def collect_less() -> None:
    """Collect cyclic garbage every :data:`COLLECT_EVERY` allocations; the older generations' settings are kept.

    Process-wide: for processes sixdof owns (the ``sixdof`` command, its figure server and workers), never
    for a program that calls sixdof as a library.
    """
    gc.set_threshold(COLLECT_EVERY, *gc.get_threshold()[1:])
