"""The ``sixdof`` command's first lines (the console script and ``python -m sixdof``): SIGINT and SIGTERM are
one line and 130 or 143 from here on, while the command's own modules load, before :func:`sixdof.cli.main`
takes them over. Only the command imports this module: a program that imports sixdof keeps its handlers."""

import os
import signal

_WORDS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated (SIGTERM)"}


def _while_loading(signum, frame):
    # Nothing has been done yet: say so and end, without unwinding an import halfway (os.write and os._exit are
    # safe in a handler; a KeyboardInterrupt here printed a traceback of the import it cut).
    os.write(2, f"sixdof: {_WORDS[signum]}; no partial results were left\n".encode())
    os._exit(128 + signum)


def main() -> int:
    """Run the ``sixdof`` command (:func:`sixdof.cli.main`) with signals handled while it loads."""
    previous = {signum: signal.signal(signum, _while_loading) for signum in _WORDS}
    from sixdof.cli import main as command  # noqa: PLC0415 (the command's modules load after its signal handlers)

    for signum, handler in previous.items():  # the command installs its own as its first step
        signal.signal(signum, handler)
    return command()
