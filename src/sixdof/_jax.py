"""Import JAX with 64-bit floats enabled, and the optional persistent compilation cache.

Every module that uses JAX imports it from here, so that float64 is switched on before any array is
made: without it JAX silently computes in float32 and still reports success. JAX's other settings, and
``XLA_FLAGS``, are left as the program set them (the ``sixdof`` command sets its own: :mod:`sixdof.cli._process`).
"""

import os
import sys
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402

__all__ = ["jax", "jnp", "compilation_cache_dir", "enable_compilation_cache"]

# ----------------------------------------------------------------------------------------------------
# Persistent compilation cache (command line only).
# ----------------------------------------------------------------------------------------------------


def compilation_cache_dir() -> Path | None:
    """Folder of the persistent JAX compilation cache, or ``None`` when disabled.

    ``$SIXDOF_JAX_CACHE`` names it (``0``, ``off`` or empty disable it); default
    ``$XDG_CACHE_HOME/sixdof/jax`` (``~/.cache/sixdof/jax``).
    """
    value = os.environ.get("SIXDOF_JAX_CACHE")
    if value is not None:
        return None if value.strip().lower() in ("", "0", "off", "false", "no") else Path(value)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "sixdof" / "jax"


def enable_compilation_cache() -> Path | None:
    """Turn on JAX's persistent compilation cache for this process (for the command line).

    Compiled solvers are then reused across processes (a repeated ``sixdof run`` skips XLA
    compilation; tracing still happens). Equinox's runtime checks compile to host callbacks, which
    JAX refuses to cache; with ``EQX_ON_ERROR=nan`` (set here only when equinox is not imported yet
    and the user has not chosen) they become NaNs instead, which the solvers' finiteness checks
    turn into :class:`~sixdof.errors.SolverError`. Not called on ``import sixdof``: library users
    and tests keep JAX's defaults.

    Returns
    -------
    pathlib.Path or None
        The cache folder, or ``None`` when disabled (``SIXDOF_JAX_CACHE=off``).
    """
    path = compilation_cache_dir()
    if path is None:
        return None
    if "equinox" not in sys.modules:
        os.environ.setdefault("EQX_ON_ERROR", "nan")
    jax.config.update("jax_compilation_cache_dir", str(path))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
    return path
