"""What the commands share: progress where someone watches, the compilation cache, --workers checked."""

from __future__ import annotations

import sys
import warnings

from sixdof.errors import integer
from sixdof.io import console
from sixdof.workflows.tasks import check_workers


def print_statics(results, no_statics: str | None = None) -> None:
    """The statics under gravity (:func:`sixdof.io.console.statics_text`), and a warning for mounts in tension."""
    print(console.statics_text(results, no_statics))
    warn_uplift(results)


def warn_uplift(results) -> None:
    """A warning naming the mounts that the statics under gravity put in tension, if any."""
    if results.statics is not None and results.statics.uplift:
        warnings.warn(f"mounts in tension (uplift): {', '.join(results.statics.uplift)}", stacklevel=2)


def check_workers_option(args) -> None:
    """``--workers`` checked before anything is read (:func:`sixdof.workflows.tasks.check_workers`)."""
    if args.workers is not None:
        check_workers(integer(args.workers, "--workers", "a number of worker processes >= 1", 1))


def progress(args) -> bool:
    """Whether to show progress: not with ``--quiet``, and only where someone watches (redirected to a log,
    a meter redrawn in place would be noise)."""
    return not args.quiet and sys.stderr.isatty()


def compile_cache() -> None:
    """Reuse compiled solvers across runs (JAX's persistent cache; SIXDOF_JAX_CACHE=off disables)."""
    from sixdof._jax import enable_compilation_cache

    enable_compilation_cache()
