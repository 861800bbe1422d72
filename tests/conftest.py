import jax
import matplotlib

matplotlib.use("Agg")
jax.config.update("jax_enable_x64", True)

import os  # noqa: E402

# Tests never write JAX's persistent compilation cache into the user's home (the CLI enables it).
os.environ.setdefault("SIXDOF_JAX_CACHE", "off")
