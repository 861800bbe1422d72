"""Import JAX with 64-bit floats enabled.

Every module that uses JAX imports it from here, so that float64 is switched on before any array is
made: without it JAX silently computes in float32 and still reports success.
"""

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402

__all__ = ["jax", "jnp"]
