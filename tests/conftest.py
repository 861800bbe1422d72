import jax
import matplotlib

matplotlib.use("Agg")
jax.config.update("jax_enable_x64", True)
