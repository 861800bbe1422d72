"""The processes a test started in a process group of their own (as a terminal runs a command), found in /proc:
whether any is still running once the command ended."""

from __future__ import annotations

import time
from pathlib import Path


def living_in_group(pgid: int) -> list[str]:
    """Command lines of the processes of group ``pgid`` that still run (zombies aside: whether a container's
    init reaps them is not the run's doing); empty where /proc is missing."""
    living = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rpartition(")")[2].split()  # after "pid (name)": state, ppid, pgrp...
            if int(fields[2]) == pgid and fields[0] != "Z":
                living.append((stat.parent / "cmdline").read_text().replace("\0", " "))
        except (OSError, IndexError, ValueError):
            continue  # ended meanwhile
    return living


def assert_group_ends(pgid: int, within_s: float) -> None:
    """Every process of group ``pgid`` has ended within ``within_s`` [s]: one that closed its pipes (the
    command's end, as the test saw it) may still be ending."""
    deadline = time.monotonic() + within_s
    while living_in_group(pgid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert living_in_group(pgid) == []
