"""Sweep specifications (``sixdof sweep --spec``): which mount parameters vary, and how, as TOML.

Read with the one TOML reader (:mod:`sixdof.io.toml`): unknown keys are rejected with the closest valid
key suggested, every error names the file and the field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sixdof.analysis.batch import Variants, make_variants
from sixdof.dofs import AXES, MOUNT_AXES
from sixdof.errors import InputError, Plain, integer
from sixdof.io.toml import parse, read_text, reject_unknown
from sixdof.model.system import System

PARAMETERS = ("stiffness", "damping", "position")
DISTRIBUTIONS = ("uniform", "normal", "grid")




@dataclass(frozen=True)
class Vary:
    """One varied parameter of a sweep (a ``[[vary]]`` table of the spec).

    Parameters
    ----------
    parameter : {"stiffness", "damping", "position"}
        Stiffness and damping are multiplied by the drawn factor; ``position`` gets the drawn offset
        added [m].
    distribution : {"uniform", "normal", "grid"}
        ``uniform`` on ``[low, high]``; ``normal`` with ``mean`` and ``std``; ``grid`` over ``values``
        (grids combine as a full factorial design).
    mounts : tuple of str
        Names of the mounts varied; empty: all.
    axes : tuple of str
        Axes varied: the mount's own ``u, v, w`` for stiffness and damping, body ``x, y, z`` for
        positions; empty: all three.
    independent : bool
        ``True``: one draw per mount and axis; ``False`` (default): one draw per variant shared by
        every selected mount and axis.
    low, high, mean, std : float
    values : tuple of float
    """

    parameter: str
    distribution: str
    mounts: tuple[str, ...] = ()
    axes: tuple[str, ...] = ()
    independent: bool = False
    low: float | None = None
    high: float | None = None
    mean: float | None = None
    std: float | None = None
    values: tuple[float, ...] = ()


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep specification (see :func:`parse_sweep_spec`).

    Attributes
    ----------
    count : int
        Number of random variants (the product of the grid sizes when there are grids).
    seed : int
        Seed of :func:`numpy.random.default_rng`.
    vary : tuple of Vary
    chunk_size : int or None
    """

    count: int
    seed: int
    vary: tuple[Vary, ...]
    chunk_size: int | None = None

    def variants(self, system: System) -> Variants:
        """Draw the variants for ``system`` (deterministic for a given seed)."""
        names = system.mount_names
        n = len(names)
        rng = np.random.default_rng(self.seed)
        k, d, x = np.ones((self.count, n, 3)), np.ones((self.count, n, 3)), np.zeros((self.count, n, 3))
        target = {"stiffness": k, "damping": d, "position": x}
        grids = [i for i, v in enumerate(self.vary) if v.distribution == "grid"]
        grid_index = (np.indices([len(self.vary[i].values) for i in grids]).reshape(len(grids), -1)
                      if grids else np.zeros((0, self.count), dtype=int))
        for i, v in enumerate(self.vary):
            field = f"vary[{i}]"
            for m in v.mounts:
                if m not in names:
                    raise InputError(f"{field}.mounts", f"mount names among {', '.join(names)}", m)
            mounts = [names.index(m) for m in v.mounts] if v.mounts else list(range(n))
            labels = AXES if v.parameter == "position" else MOUNT_AXES
            for a in v.axes:
                if a not in labels:
                    raise InputError(f"{field}.axes", f"axes among {', '.join(labels)}", a)
            axes = [labels.index(a) for a in v.axes] if v.axes else [0, 1, 2]
            shape = (self.count, len(mounts), len(axes)) if v.independent else (self.count, 1, 1)
            if v.distribution == "uniform":
                draw = rng.uniform(v.low, v.high, shape)
            elif v.distribution == "normal":
                draw = rng.normal(v.mean, v.std, shape)
            else:
                g = grids.index(i)
                draw = np.asarray(v.values)[grid_index[g]][:, None, None]
            block = np.broadcast_to(draw, (self.count, len(mounts), len(axes)))
            sub = target[v.parameter][:, mounts][:, :, axes]
            sub = sub + block if v.parameter == "position" else sub * block
            target[v.parameter][np.ix_(range(self.count), mounts, axes)] = sub
            if v.parameter == "stiffness" and np.any(sub <= 0):
                raise InputError(field, "stiffness factors > 0 (narrow the distribution)",
                                 Plain(f"a draw of {sub.min():.6g}"))
            if v.parameter == "damping" and np.any(sub < 0):
                raise InputError(field, "damping factors >= 0 (narrow the distribution)",
                                 Plain(f"a draw of {sub.min():.6g}"))
        return make_variants(system, stiffness_factor=k, damping_factor=d, position_offset=x)


_SPEC_KEYS = ("count", "seed", "chunk_size", "vary")
_VARY_KEYS = ("parameter", "distribution", "mounts", "axes", "independent", "low", "high", "mean",
              "std", "values")
_NEEDS = {"uniform": ("low", "high"), "normal": ("mean", "std"), "grid": ("values",)}


def parse_sweep_spec(text: str, source: str = "<string>") -> SweepSpec:
    """Validate a sweep specification (TOML).

    Example::

        count = 1000                 # random variants (grids: the product of their sizes)
        seed = 1
        [[vary]]
        parameter = "stiffness"      # stiffness | damping | position
        distribution = "uniform"     # uniform (low, high) | normal (mean, std) | grid (values)
        low = 0.7
        high = 1.3
        mounts = ["1", "2"]          # optional, default all
        axes = ["w"]                 # optional: u, v, w (mount axes) or x, y, z (positions)
        independent = true           # one draw per mount and axis (default: one shared draw)

    Raises
    ------
    InputError
        ``field: expected ..., got ...`` prefixed with ``source``.
    """
    return parse(text, source, _spec)


def load_sweep_spec(path: str | Path) -> SweepSpec:
    """Read and validate a sweep specification file (see :func:`parse_sweep_spec`)."""
    return parse_sweep_spec(read_text(path, "sweep specification (TOML)"), str(path))


def _spec(raw: dict) -> SweepSpec:
    reject_unknown(raw, _SPEC_KEYS, "")
    vary_raw = raw.get("vary")
    if not isinstance(vary_raw, list) or not vary_raw or not all(isinstance(v, dict) for v in vary_raw):
        raise InputError("vary", "at least one [[vary]] table", vary_raw if vary_raw is not None
                         else Plain("nothing"))
    vary = tuple(_vary(v, f"vary[{i}]") for i, v in enumerate(vary_raw))
    seed = raw.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError("seed", "an integer >= 0", seed)
    chunk = raw.get("chunk_size")
    if chunk is not None and (isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 1):
        raise InputError("chunk_size", "a positive integer", chunk)
    grid_count = math.prod(len(v.values) for v in vary if v.distribution == "grid")
    has_grid = any(v.distribution == "grid" for v in vary)
    count = raw.get("count")
    if count is None:
        if not has_grid:
            raise InputError("count", "a positive integer (number of random variants)", Plain("nothing"))
        count = grid_count
    count = integer(count, "count", "a positive integer", 1)
    if has_grid and count != grid_count:
        raise InputError("count", f"the product of the grid sizes, {grid_count} (or no count)", count)
    return SweepSpec(count=count, seed=seed, vary=vary, chunk_size=chunk)


def _vary(raw: dict, path: str) -> Vary:
    reject_unknown(raw, _VARY_KEYS, path)
    parameter = raw.get("parameter")
    if parameter not in PARAMETERS:
        raise InputError(f"{path}.parameter", f"one of {', '.join(PARAMETERS)}",
                         parameter if parameter is not None else Plain("nothing"))
    distribution = raw.get("distribution")
    if distribution not in DISTRIBUTIONS:
        raise InputError(f"{path}.distribution", f"one of {', '.join(DISTRIBUTIONS)}",
                         distribution if distribution is not None else Plain("nothing"))
    for key in _VARY_KEYS[5:]:
        if key in raw and key not in _NEEDS[distribution]:
            raise InputError(f"{path}.{key}", f"only {', '.join(_NEEDS[distribution])} with a "
                             f"{distribution} distribution", raw[key])
    numbers = {}
    for key in _NEEDS[distribution]:
        if key not in raw:
            raise InputError(f"{path}.{key}", "a value (required key)", Plain("nothing"))
        value = raw[key]
        if key == "values":
            if (not isinstance(value, list) or not value
                    or not all(_finite(v) for v in value)):
                raise InputError(f"{path}.values", "a non-empty list of finite numbers", value)
            numbers[key] = tuple(float(v) for v in value)
        elif not _finite(value):
            raise InputError(f"{path}.{key}", "a finite number", value)
        else:
            numbers[key] = float(value)
    if distribution == "uniform" and not numbers["low"] < numbers["high"]:
        raise InputError(f"{path}.high", f"a number > low = {numbers['low']:g}", raw["high"])
    if distribution == "normal" and not numbers["std"] > 0:
        raise InputError(f"{path}.std", "a standard deviation > 0", raw["std"])
    for key in ("mounts", "axes"):
        value = raw.get(key, [])
        if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
            raise InputError(f"{path}.{key}", "a list of names", value)
    independent = raw.get("independent", False)
    if not isinstance(independent, bool):
        raise InputError(f"{path}.independent", "true or false", independent)
    if independent and distribution == "grid":
        raise InputError(f"{path}.independent", "false for a grid (one grid value per variant)",
                         independent)
    return Vary(parameter=parameter, distribution=distribution, mounts=tuple(raw.get("mounts", [])),
                axes=tuple(raw.get("axes", [])), independent=independent, **numbers)


def _finite(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
