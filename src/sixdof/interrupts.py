"""Signals held back during a block: the one mechanism behind the atomic writes and the command's imports.

Standard library only, so that the command can hold signals while it imports NumPy and JAX: an interruption
raised inside an extension module's start (XLA's) crashed the process (SIGSEGV, SIGABRT) or left a half-made
module that cannot be imported again ("cannot load module more than once per process").
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

_HELD_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextmanager
def held_signals(deliver: bool = True) -> Iterator[list[int]]:
    """Hold SIGINT and SIGTERM back during the block, then deliver the first one received.

    A KeyboardInterrupt raised inside h5py's or matplotlib's C code can be swallowed there ("Exception
    ignored in ..."), and the write would then go on as if nothing happened; held back, it is raised
    where the caller can still clean up. Outside the main thread (where Python cannot handle signals)
    the block runs as it is.

    The block gets the list of the signals received; with ``deliver=False`` they are left to the caller
    (to act on once the results are in place, or not at all while a failure is being handled).
    """
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return
    previous = {s: signal.signal(s, lambda signum, frame: received.append(signum)) for s in _HELD_SIGNALS}
    try:
        yield received
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        if received and deliver:
            signal.raise_signal(received[0])


__all__ = ["held_signals"]
