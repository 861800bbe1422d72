"""The compiled solve of a window, per problem structure: traced once per process, exported across them."""

from __future__ import annotations

import hashlib
import importlib.util
import json
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from sixdof._jax import jax
from sixdof.analysis.direct.solve import _solve_segment, _solve_window

#: Compiled window solves of this process, by structure key.
_COMPILED: dict[str, Callable] = {}


#: The files whose code the traced solve runs besides this package's (all of which count, as when it was one
#: module): a change to any of them makes exported solves stale.
_TRACED_SOURCES = ("analysis/unrolled.py", "excitation/signals.py")


def _export_dir() -> Path | None:
    """Folder of the exported solves, or ``None`` when they are not kept.

    They are kept beside the persistent JAX compilation cache, when that is on (it holds the compiled code
    they need), when equinox's runtime checks compile to NaNs (``EQX_ON_ERROR=nan`` or ``off``, as the
    command line sets: the default checks are host callbacks, which cannot be exported) and when
    flatbuffers, which :mod:`jax.export` writes with, is installed.
    """
    cache = jax.config.jax_compilation_cache_dir
    if not cache or os.environ.get("EQX_ON_ERROR") not in ("nan", "off") or not importlib.util.find_spec("flatbuffers"):
        return None
    return Path(cache) / "sixdof_solves"


def _installed(module: str) -> str:
    """Where ``module`` is installed and when, without importing it (part of the structure key)."""
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return "absent"
    stat = os.stat(spec.origin)
    return f"{spec.origin}:{stat.st_mtime_ns}:{stat.st_size}"


def _structure_key(treedef, specs, statics: dict) -> str:
    """Everything the traced solve depends on besides its arguments' values."""
    here = Path(__file__).resolve().parent
    files = [*sorted(here.glob("*.py")), *(here.parent.parent / name for name in _TRACED_SOURCES)]
    sources = hashlib.sha256(b"".join(path.read_bytes() for path in files)).hexdigest()
    return json.dumps({
        "statics": statics, "treedef": str(treedef), "arguments": [f"{s.dtype}{list(s.shape)}" for s in specs],
        "sources": sources, "jax": jax.__version__, "backend": jax.default_backend(),
        "x64": bool(jax.config.jax_enable_x64), "eqx_on_error": os.environ.get("EQX_ON_ERROR", "raise"),
        "diffrax": _installed("diffrax"), "equinox": _installed("equinox"),
    }, sort_keys=True)


def _load_exported(path: Path, key: str, specs) -> Callable | None:
    """The exported solve stored at ``path`` for ``key``, compiled; ``None`` when it is absent, for another
    key, damaged or unusable (then the solve is traced anew)."""
    try:
        header, payload = path.read_bytes().split(b"\n", 1)
        meta = json.loads(header)
        if meta["key"] != key or meta["sha256"] != hashlib.sha256(payload).hexdigest():
            return None
        exported = jax.export.deserialize(bytearray(payload))
        if [(a.shape, a.dtype) for a in exported.in_avals] != [(s.shape, s.dtype) for s in specs]:
            return None
        solve = jax.jit(exported.call)
        solve.lower(*specs)  # what can fail before a call fails here
        return solve
    except Exception:  # noqa: BLE001 - a cache entry of any damage is ignored; the solve is traced instead
        return None


def _save_exported(path: Path, key: str, traced, specs) -> Callable:
    """Export ``traced`` and store it for ``key`` (atomically); the exported solve, or ``traced`` when it cannot
    be exported (the cache is then left alone: a run never fails for its cache)."""
    try:
        exported = jax.export.export(traced)(*specs)
        payload = bytes(exported.serialize())
    except Exception:  # noqa: BLE001 - e.g. host callbacks after all: compile it without exporting
        return traced
    header = json.dumps({"key": key, "sha256": hashlib.sha256(payload).hexdigest()}).encode()
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary.write_bytes(header + b"\n" + payload)
        os.replace(temporary, path)
    except OSError:
        temporary.unlink(missing_ok=True)
    return jax.jit(exported.call)


def _compiled_window(args: tuple, *, solver: str, code: int, max_steps: int, nonlinear: bool = False) -> Callable:
    """The jitted :func:`_solve_window` for the structure of ``args``, called with ``jax.tree.leaves(args)`` (a
    jitted function, not an ahead-of-time compiled one: its calls take JAX's fast path, ~1 ms less each)."""
    leaves, treedef = jax.tree.flatten(args)
    specs = [jax.ShapeDtypeStruct(np.shape(leaf), np.asarray(leaf).dtype) for leaf in leaves]
    statics = {"solver": solver, "code": code, "max_steps": max_steps}
    traced = _solve_segment if nonlinear else _solve_window
    key = _structure_key(treedef, specs, {**statics, "nonlinear": nonlinear})
    compiled = _COMPILED.get(key)
    if compiled is not None:
        return compiled
    folder = _export_dir()
    path = None if folder is None else folder / f"{hashlib.sha256(key.encode()).hexdigest()[:32]}.jaxexport"
    compiled = None if path is None else _load_exported(path, key, specs)
    if compiled is None:

        def _solve(*leaves):
            return traced(*jax.tree.unflatten(treedef, leaves), **statics)

        compiled = jax.jit(_solve)  # compiled at its first call
        if path is not None:
            compiled = _save_exported(path, key, compiled, specs)
    _COMPILED[key] = compiled
    return compiled
