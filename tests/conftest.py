import gc
import os

# The test process compiles as the ``sixdof`` command does (sixdof.cli._process.compile_faster): XLA's CPU
# fusion emitters make the suite's many short compilations ~20 % slower (tests/test_superposition.py: 49 s
# against 39 s). Set before JAX's CPU backend starts; the command's subprocesses inherit it.
from sixdof.cli._process import with_xla_defaults  # noqa: E402 (imports neither JAX nor NumPy)

os.environ["XLA_FLAGS"] = with_xla_defaults(os.environ.get("XLA_FLAGS", ""))

import jax  # noqa: E402
import matplotlib  # noqa: E402
import pytest  # noqa: E402

matplotlib.use("Agg")
jax.config.update("jax_enable_x64", True)

# Tests never write JAX's persistent compilation cache into the user's home (the CLI enables it).
os.environ.setdefault("SIXDOF_JAX_CACHE", "off")


@pytest.hookimpl(tryfirst=True)  # before pytest's own hook deselects by -m
def pytest_collection_modifyitems(config, items):
    """A ``long`` test (over 10 s) is ``slow`` too: the quick loop, ``-m "not slow"``, leaves out both."""
    for item in items:
        if item.get_closest_marker("long") is not None:
            item.add_marker("slow")


def pytest_collection_finish(session):
    """Freeze what the collected modules imported out of the garbage collector's sight.

    ``sixdof`` collects garbage when a command fails (:func:`sixdof.cli._cleanup_errors`), and a test process
    holds JAX, diffrax, SciPy and matplotlib: ~220,000 long-lived objects that every full collection walks,
    0.1 s each time. Frozen (:func:`gc.freeze`), a collection walks only what the tests made: the 813 tests of
    test_bad_inputs.py take 7.5 s instead of 64 s. Only the collector's work changes; nothing frozen is freed
    later by it (modules and the functions they hold, which live as long as the process anyway).
    """
    import diffrax  # noqa: F401 (imported by the solves the tests run, frozen with the rest)
    import matplotlib.pyplot  # noqa: F401
    import scipy.integrate  # noqa: F401
    import scipy.signal  # noqa: F401

    import sixdof.workflows.run  # noqa: F401

    gc.collect()
    gc.freeze()
