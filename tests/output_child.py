"""A real ``sixdof`` process for tests/test_output.py, stopped where a test wants to hit it.

Usage: ``python output_child.py HOOK sixdof-arguments...``; with SIXDOF_TEST_FSIZE set, the process
first limits the size of the files it writes to that many bytes (as ``ulimit -f`` does). HOOK says where the process prints a word on
stdout and pauses for a signal: ``write`` (inside the results write), ``swap`` (between the two renames
of a results folder), ``plot`` (after the figures are drawn, before they are moved into place) or
``swapped`` (after the new folder is in place, before the user's files are moved across) or ``none``.
"""

import faulthandler
import os
import resource
import signal
import sys
import time
from pathlib import Path

from sixdof import cli
from sixdof.cli.figures import FigureWorkers
from sixdof.io import output, store

PAUSE_S = 1.5


def pause(word: str) -> None:
    print(word, flush=True)
    time.sleep(PAUSE_S)


def hook(name: str) -> None:
    if name == "write":
        write = store.write_results

        def paused_write(*args, **kwargs):
            write(*args, **kwargs)
            pause("WRITING")

        store.write_results = paused_write
    elif name in ("swap", "swapped"):
        replace = os.replace

        def paused_replace(source, destination):
            replace(source, destination)
            if ".old-" in str(destination) if name == "swap" else ".partial-" in Path(source).name:
                pause("SWAPPING")

        output.os.replace = paused_replace
    elif name == "plot":
        save = FigureWorkers.save

        def paused_save(*args, **kwargs):
            written = save(*args, **kwargs)
            pause("PLOTTED")
            return written

        FigureWorkers.save = paused_save


if __name__ == "__main__":
    # A user at a terminal: Ctrl-C raises KeyboardInterrupt even where the test runner was started in the
    # background, whose children inherit SIGINT ignored (and rightly keep ignoring it, as under nohup).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    if "SIXDOF_TEST_FSIZE" in os.environ:
        limit = int(os.environ["SIXDOF_TEST_FSIZE"])
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    hook(sys.argv[1])
    # A child that hangs prints where each thread stands and ends, before the test's own timeout (120 s).
    faulthandler.dump_traceback_later(100, exit=True)
    sys.exit(cli.main(sys.argv[2:]))
