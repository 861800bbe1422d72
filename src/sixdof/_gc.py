"""Fewer garbage collections in sixdof's own processes: the command's, and the figure workers'.

Importing JAX and tracing the solve, or matplotlib and drawing figures, allocate millions of objects that
live to the end of a command. Python looks for reference cycles every 700 allocations by default, so each
of the ~300 collections of a run searches those objects and finds almost nothing to free: 0.14-0.28 s of
the command's process, and ~10 % of a figure worker's drawing, measured on the bridge traffic run.
"""

import gc

#: Allocations between two collections of the youngest objects (Python's default: 700). The garbage
#: waiting for a collection stays bounded, by a few MB.
COLLECT_EVERY = 50_000


def collect_less() -> None:
    """Collect cyclic garbage every :data:`COLLECT_EVERY` allocations; the older generations' settings are kept.

    Process-wide: for processes sixdof owns (the ``sixdof`` command, its figure server and workers), never
    for a program that calls sixdof as a library.
    """
    gc.set_threshold(COLLECT_EVERY, *gc.get_threshold()[1:])
