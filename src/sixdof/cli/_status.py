"""The ``sixdof`` command's exit statuses, its SIGTERM exception, and the one line a failed command prints."""

import sys
import traceback

EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_VALIDATION_FAILED = 3  # validate's FAIL; correlate's model and test not correlated
EXIT_TARGETS_NOT_MET = 3  # optimize: the best compromise is written, as validate writes a failed validation
EXIT_CANNOT_WRITE = 74  # EX_IOERR of sysexits.h
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports a process killed by it
EXIT_CLOSED_PIPE = 141  # 128 + SIGPIPE: as a shell reports a command killed by writing to a closed pipe (`yes | head`)
EXIT_TERMINATED = 143  # 128 + SIGTERM


class Terminated(BaseException):
    """SIGTERM, raised like KeyboardInterrupt so that a run cleans up after itself."""


def fail(args, message: str, status: int) -> int:
    """``message`` as the command's one line on stderr (with the traceback under ``--debug``); ``status``."""
    if args.debug:
        traceback.print_exc()
    print(f"sixdof: {message}", file=sys.stderr)
    return status
