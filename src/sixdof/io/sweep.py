"""Sweep specifications (``sixdof sweep --spec``): which mount parameters vary, and how, as TOML.

Read with the one TOML reader (:mod:`sixdof.schema`): unknown keys are rejected with the closest valid
key suggested, every error names the file and the field.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.analysis.batch import CROSS_CHECK, ENGINES, Variants, check_batchable, make_variants
from sixdof.dofs import AXES, MOUNT_AXES
from sixdof.errors import (
    MAX_FREQUENCY_HZ,
    InputError,
    Plain,
    boolean,
    integer,
    integer_check,
    number_check,
    optional,
    short,
)
from sixdof.frozen import Frozen, checked
from sixdof.model.system import System
from sixdof.schema import Table, build, is_number, naming, parse, read_text
from sixdof.tasks import check_count, chunk_rng, partition

PARAMETERS = ("stiffness", "damping", "position")
DISTRIBUTIONS = ("uniform", "normal", "grid")
_NEEDS = {"uniform": ("low", "high"), "normal": ("mean", "std"), "grid": ("values",)}
#: A normal distribution of stiffness or damping factors has its mean at least this many standard deviations
#: above 0 (a tolerance band of +-3 sigma that stays positive).
NORMAL_MARGIN = 3


def _one_of(names: tuple[str, ...]):
    def check(value: Any, field: str) -> str:
        if value not in names:
            raise InputError(field, f"one of {', '.join(names)}", Plain("nothing") if value is None else value)
        return value

    return check


def _names(value: Any, field: str) -> tuple[str, ...]:
    if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) and v for v in value):
        raise InputError(field, "a list of names", value)
    return tuple(value)


def _values(value: Any, field: str) -> tuple[float, ...]:
    if isinstance(value, tuple) and not value:  # the default: not given (a list given may not be empty)
        return value
    if not isinstance(value, (list, tuple)) or not value or not all(is_number(v) for v in value):
        raise InputError(field, "a non-empty list of finite numbers", value)
    return tuple(float(v) for v in value)


_FINITE = optional(number_check("a finite number"))


@dataclass(frozen=True)
class Vary(Frozen):
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

    parameter: str = checked(_one_of(PARAMETERS))
    distribution: str = checked(_one_of(DISTRIBUTIONS))
    mounts: tuple[str, ...] = checked(_names, default=())
    axes: tuple[str, ...] = checked(_names, default=())
    independent: bool = checked(boolean, default=False)
    low: float | None = checked(_FINITE, default=None)
    high: float | None = checked(_FINITE, default=None)
    mean: float | None = checked(_FINITE, default=None)
    std: float | None = checked(_FINITE, default=None)
    values: tuple[float, ...] = checked(_values, default=())

    def __check__(self) -> None:
        needs = _NEEDS[self.distribution]
        for key in ("low", "high", "mean", "std", "values"):
            value = getattr(self, key)
            given = value is not None and value != ()
            if given and key not in needs:
                raise InputError(key, f"only {', '.join(needs)} with a {self.distribution} distribution", value)
            if key in needs and not given:
                raise InputError(key, "a value (required key)", Plain("nothing"))
        if self.distribution == "uniform" and not self.low < self.high:
            raise InputError("high", f"a number > low = {self.low:g}", self.high)
        if self.distribution == "normal" and not self.std > 0:
            raise InputError("std", "a standard deviation > 0", self.std)
        if self.independent and self.distribution == "grid":
            raise InputError("independent", "false for a grid (one grid value per variant)", self.independent)
        if self.parameter != "position":
            self._check_factors()

    def _check_factors(self) -> None:
        """Refuse, when the spec is read, a distribution of factors that would draw stiffness factors <= 0 or
        damping factors < 0. A normal one reaches any value: its mean must be :data:`NORMAL_MARGIN` standard
        deviations above 0 (a draw further out, at most one in 740, is still refused when drawn, before any
        computing)."""
        stiffness = self.parameter == "stiffness"
        valid = f"{self.parameter} factors {'> 0' if stiffness else '>= 0'}"
        allowed = (lambda x: x > 0) if stiffness else (lambda x: x >= 0)
        if self.distribution == "uniform" and not allowed(self.low):
            raise InputError("low", valid, self.low)
        if self.distribution == "grid" and not all(map(allowed, self.values)):
            raise InputError("values", valid, list(self.values))
        if self.distribution == "normal" and not self.mean > 0:
            raise InputError("mean", f"a mean > 0 ({valid})", self.mean)
        if self.distribution == "normal" and not self.mean > NORMAL_MARGIN * self.std:
            raise InputError("std", f"a standard deviation < mean / {NORMAL_MARGIN} = {self.mean / NORMAL_MARGIN:.3g} "
                             f"({valid}: the mean at least {NORMAL_MARGIN} standard deviations above 0)", self.std)


#: Variants per chunk of a sweep when the spec does not say (:attr:`SweepSpec.chunk_size`): a few seconds of
#: the exact engine on the bundled bridge scenario, few enough files for 10^6 variants.
CHUNK_SIZE = 1000


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep specification (see :func:`parse_sweep_spec`).

    Attributes
    ----------
    count : int
        Number of random variants (the product of the grid sizes when there are grids).
    seed : int
        Seed of the random draws: chunk ``i`` draws from ``numpy.random.default_rng([seed, i])``
        (:func:`sixdof.tasks.chunk_rng`).
    vary : tuple of Vary
    chunk_size : int or None
        Variants per chunk (one task, one seed, one file; default :data:`CHUNK_SIZE`): the chunks of
        :func:`sixdof.tasks.partition`. With the seed it fixes the variants drawn.
    engine : {"exact", "diffrax"}
        How the responses are computed (:func:`sixdof.analysis.batch.run_batch`).
    cross_check : int
        Variants also solved by diffrax (drawn with ``seed``).
    path : pathlib.Path or None
        The file it was read from (named by the errors of :meth:`check`); not part of the sweep.
    """

    count: int
    seed: int
    vary: tuple[Vary, ...]
    chunk_size: int | None = None
    engine: str = "exact"
    cross_check: int = CROSS_CHECK
    path: Path | None = dataclasses.field(default=None, compare=False)

    def chunks(self) -> list[range]:
        """The variant indices of each chunk."""
        return partition(self.count, CHUNK_SIZE if self.chunk_size is None else self.chunk_size)

    def variants(self, system: System, chunk: int | None = None) -> Variants:
        """The variants of chunk ``chunk`` for ``system``, or of every chunk in order (deterministic).

        Raises
        ------
        InputError
            A mount or axis that ``system`` lacks, or draws of stiffness factors <= 0 or damping factors
            < 0 (naming the ``vary`` entry).
        """
        k, d, x = self.factors(system, chunk)
        return make_variants(system, stiffness_factor=k, damping_factor=d, position_offset=x)

    def factors(self, system: System, chunk: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The stiffness factors, damping factors and position offsets [m] (count, n_mounts, 3) of chunk
        ``chunk``'s variants, or of every chunk's in order: what :meth:`variants` gives
        :func:`~sixdof.analysis.batch.make_variants` (which refuses what the batch engine cannot run).

        Raises
        ------
        InputError
            As :meth:`variants`.
        """
        if chunk is None:
            parts = [self.factors(system, i) for i in range(len(self.chunks()))]
            return tuple(np.concatenate(found) for found in zip(*parts))
        rows = self.chunks()[chunk]
        names = system.mount_names
        n = len(names)
        rng = chunk_rng(self.seed, chunk)
        count = len(rows)
        k, d, x = np.ones((count, n, 3)), np.ones((count, n, 3)), np.zeros((count, n, 3))
        target = {"stiffness": k, "damping": d, "position": x}
        grids = [i for i, v in enumerate(self.vary) if v.distribution == "grid"]
        # The grids' full factorial, numbered over the whole sweep: this chunk's rows of it.
        grid_index = np.stack(np.unravel_index(np.asarray(rows), [len(self.vary[i].values) for i in grids])) \
            if grids else np.zeros((0, count), dtype=int)
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
            shape = (count, len(mounts), len(axes)) if v.independent else (count, 1, 1)
            if v.distribution == "uniform":
                draw = rng.uniform(v.low, v.high, shape)
            elif v.distribution == "normal":
                draw = rng.normal(v.mean, v.std, shape)
            else:
                draw = np.asarray(v.values)[grid_index[grids.index(i)]][:, None, None]
            block = np.broadcast_to(draw, (count, len(mounts), len(axes)))
            sub = target[v.parameter][:, mounts][:, :, axes]
            sub = sub + block if v.parameter == "position" else sub * block
            target[v.parameter][np.ix_(range(count), mounts, axes)] = sub
            if v.parameter == "stiffness" and np.any(sub <= 0):
                raise InputError(field, "stiffness factors > 0 (narrow the distribution)",
                                 Plain(f"a draw of {sub.min():.6g} (chunk {chunk})"))
            if v.parameter == "damping" and np.any(sub < 0):
                raise InputError(field, "damping factors >= 0 (narrow the distribution)",
                                 Plain(f"a draw of {sub.min():.6g} (chunk {chunk})"))
            _check_range(system, k, d, x, field, block, chunk)
        return k, d, x

    def check(self, system: System) -> None:
        """Draw every chunk's variants once, one chunk at a time, so that a bad draw fails before any
        computing (see :meth:`variants`). A ``system`` the batch engines cannot run is refused first, naming
        its mounts; then what the spec asks of it, naming the spec's file (:attr:`path`) and field."""
        check_batchable(system)
        with naming(self.path):
            for chunk in range(len(self.chunks())):
                self.variants(system, chunk)


def _check_range(system: System, k: np.ndarray, d: np.ndarray, x: np.ndarray, field: str, block: np.ndarray,
                 chunk: int) -> None:
    """Refuse variants whose mount matrices leave float64 or whose natural frequencies pass
    :data:`~sixdof.errors.MAX_FREQUENCY_HZ`, as :class:`~sixdof.model.system.System` refuses a given design: each
    mount's largest coefficient times its lever arm squared, over the body's least mass or moment of inertia
    (an upper bound of the variant's stiffness over mass, within the mount count)."""
    least = min(system.body.mass, float(np.linalg.eigvalsh(system.body.inertia).min()))
    with np.errstate(over="ignore", invalid="ignore"):
        coefficient = np.maximum(system.given_stiffnesses * k, system.dampings * d).max(axis=2)
        lever = (1.0 + np.abs(system.positions + x).max(axis=2)) ** 2
        ratio = coefficient * lever / least
        bad = ~(ratio <= (2 * np.pi * MAX_FREQUENCY_HZ) ** 2)  # NaN and inf too
    if np.any(bad):
        drawn = block.ravel()[np.argmax(np.abs(block.ravel()))]
        raise InputError(field, f"draws that keep every mount's stiffness and damping matrices finite and the natural "
                         f"frequencies below {short(MAX_FREQUENCY_HZ)} Hz (narrow the distribution)",
                         Plain(f"a draw of {drawn:.6g} (chunk {chunk})"))


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

    Optional top-level keys: ``engine`` (``"exact"``, default, or ``"diffrax"``), ``cross_check``
    (variants also solved by diffrax, default 3), ``chunk_size`` (variants per chunk, default
    :data:`CHUNK_SIZE`; with ``seed`` it fixes the variants drawn).

    Raises
    ------
    InputError
        ``field: expected ..., got ...`` prefixed with ``source``.
    """
    spec = parse(text, source, _spec)
    return spec if source == "<string>" else dataclasses.replace(spec, path=Path(source))


def load_sweep_spec(path: str | Path) -> SweepSpec:
    """Read and validate a sweep specification file (see :func:`parse_sweep_spec`)."""
    return parse_sweep_spec(read_text(path, "sweep specification (TOML)"), str(path))


def _refuse_duplicates(vary) -> None:
    """Refuse a ``[[vary]]`` table that varies the same parameter of the same mounts and axes as an earlier one:
    their draws would compound (two stiffness scatters of +-15 % make one of +-32 %), a copy that slipped in.
    Tables that overlap in part compose, as a scatter of every mount and a study of one mount's do."""
    seen: dict[tuple, int] = {}
    for i, v in enumerate(vary):
        key = (v.parameter, tuple(sorted(set(v.mounts))), tuple(sorted(set(v.axes))))
        if key in seen:
            where = (f"{v.parameter} of {', '.join(key[1]) or 'every mount'}, "
                     f"axes {', '.join(key[2]) or 'all'}")
            raise InputError(f"vary[{i}]", "a parameter, mounts and axes that no earlier [[vary]] varies (their "
                             "draws would compound)", Plain(f"{where}, as vary[{seen[key]}] already"))
        seen[key] = i


def _spec(raw: dict) -> SweepSpec:
    top = Table(raw, "", ("count", "seed", "chunk_size", "engine", "cross_check", "vary"))
    # A missing parameter or distribution is None, named in field order like a wrong one.
    vary = tuple(build(Vary, {"parameter": None, "distribution": None, **v}, f"vary[{i}]")
                 for i, v in enumerate(top.tables("vary", required=True)))
    _refuse_duplicates(vary)
    seed = integer(top.value("seed", 0), "seed", "an integer >= 0", 0)
    chunk = optional(integer_check("a positive integer", 1))(top.value("chunk_size", None), "chunk_size")
    engine = top.value("engine", "exact")
    if engine not in ENGINES:
        raise InputError("engine", "one of " + ", ".join(ENGINES), engine)
    cross_check = integer(top.value("cross_check", CROSS_CHECK), "cross_check", "a number of variants >= 0", 0)
    grids = [len(v.values) for v in vary if v.distribution == "grid"]
    if grids:  # before the count that must equal it, which would name an impossible product as expected
        check_count(math.prod(grids), "vary", "variants in the grids' full factorial")
    count = top.value("count", math.prod(grids) if grids else None)
    if count is None:
        raise InputError("count", "a positive integer (number of random variants)", Plain("nothing"))
    count = integer(count, "count", "a positive integer", 1)
    check_count(count, "count")
    if grids and count != math.prod(grids):
        raise InputError("count", f"the product of the grid sizes, {math.prod(grids)} (or no count)", count)
    return SweepSpec(count=count, seed=seed, vary=vary, chunk_size=chunk, engine=engine, cross_check=cross_check)
