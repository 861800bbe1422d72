import os

# The test process compiles as the ``sixdof`` command does (sixdof.cli._process.compile_faster): XLA's CPU
# fusion emitters make the suite's many short compilations ~20 % slower (tests/test_superposition.py: 49 s
# against 39 s). Set before JAX's CPU backend starts; the command's subprocesses inherit it.
from sixdof.cli._process import with_xla_defaults  # noqa: E402 (imports neither JAX nor NumPy)

os.environ["XLA_FLAGS"] = with_xla_defaults(os.environ.get("XLA_FLAGS", ""))

import jax  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
jax.config.update("jax_enable_x64", True)

# Tests never write JAX's persistent compilation cache into the user's home (the CLI enables it).
os.environ.setdefault("SIXDOF_JAX_CACHE", "off")
