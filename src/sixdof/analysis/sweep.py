"""A sweep of a system's mount variants: what varies and how (:class:`SweepSpec`, :class:`Vary`), the variants
of each chunk, and the sweep computed chunk by chunk on a runner, in memory (:func:`sweep_on`).

The sweep's variants are cut into chunks of equal size (:meth:`SweepSpec.chunks`); each chunk is one task
(:func:`sweep_chunk`): it draws its variants with its own seed (:func:`sixdof.chunks.chunk_rng`), computes them
with the batch engine (:func:`sixdof.analysis.batch.run_batch`) and solves those of the cross-check sample that
fall in it by diffrax. Where the tasks run is the runner's business (:class:`sixdof.chunks.InProcess`, or
:func:`sixdof.workflows.tasks.task_runner` on Dask); the results are the same wherever they ran. A spec file is
read by :mod:`sixdof.io.sweep`; :mod:`sixdof.workflows.sweep` writes a sweep to disk as it goes.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from sixdof.analysis.batch import (
    CROSS_CHECK,
    Variants,
    check_batchable,
    cross_check_fields,
    cross_check_sample,
    direct_peaks,
    make_variants,
    run_batch,
)
from sixdof.chunks import chunk_rng, partition
from sixdof.dofs import AXES, MOUNT_AXES
from sixdof.errors import MAX_FREQUENCY_HZ, InputError, Plain, SolverError, boolean, number_check, optional, short
from sixdof.frozen import Frozen, checked
from sixdof.model.system import System
from sixdof.progress import meter
from sixdof.results import axis_concat, axis_slice
from sixdof.schema import is_number, naming

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
    """A validated sweep specification (read by :func:`sixdof.io.sweep.parse_sweep_spec`).

    Attributes
    ----------
    count : int
        Number of random variants (the product of the grid sizes when there are grids).
    seed : int
        Seed of the random draws: chunk ``i`` draws from ``numpy.random.default_rng([seed, i])``
        (:func:`sixdof.chunks.chunk_rng`).
    vary : tuple of Vary
    chunk_size : int or None
        Variants per chunk (one task, one seed, one file; default :data:`CHUNK_SIZE`): the chunks of
        :func:`sixdof.chunks.partition`. With the seed it fixes the variants drawn.
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


class Study(NamedTuple):
    """What a sweep needs of a scenario (a :class:`~sixdof.io.scenario.Scenario` will do): the nominal
    system, the excitation and simulation settings of its responses (``None``: frequencies only), and the model
    of those time responses (``None``: ``system``; a scenario's ``time_system`` carries its loss factors as
    causal Maxwell models)."""

    system: Any
    excitation: Any = None
    simulation: Any = None
    time_system: Any = None


def time_system_of(scenario):
    """The model of a sweep's time responses and cross-checks: the scenario's ``time_system`` (the loss factors'
    causal Maxwell models, ``[damping] loss_factor_model``), else its ``system``."""
    timed = getattr(scenario, "time_system", None)
    return scenario.system if timed is None else timed


def sweep_chunk(scenario, spec, index: int, checked: tuple[int, ...] = ()):
    """Chunk ``index`` of ``spec``'s sweep of ``scenario`` (or :class:`Study`), one task: its variants'
    frequencies and peaks, and the diffrax peaks of those among ``checked`` (indices in the whole sweep), as
    a :class:`~sixdof.analysis.batch.BatchResult` whose cross-check fields hold only those peaks.

    The frequencies and tracked modes are those of the scenario's ``system`` (the mounts' stiffness ``k``, as
    ``sixdof modes`` reports them); the peaks and their diffrax cross-check those of its ``time_system`` (each
    loss factor as its causal Maxwell model, scaled with its mount axis's stiffness factor, as ``sixdof run``
    simulates)."""
    system, excitation, settings = scenario.system, scenario.excitation, scenario.simulation
    timed = time_system_of(scenario)
    variants = spec.variants(system, index)
    result = run_batch(system, variants, excitation, settings, time_system=timed, engine=spec.engine, cross_check=0)
    if not checked or result.peak_q is None:
        return result
    rows = spec.chunks()[index]
    direct = direct_peaks(timed, variants, [i - rows.start for i in checked], excitation, settings)
    return dataclasses.replace(result, cross_check_variants=np.asarray(checked, dtype=int),
                               cross_check_peak_q=direct[:, :6], cross_check_peak_qdd=direct[:, 6:])


class ChunkedSweep:
    """What every chunk shares and how they merge: the partition, the cross-check sample, the merged parts."""

    def __init__(self, scenario, spec) -> None:
        self.scenario, self.spec = scenario, spec
        self.chunks = spec.chunks()
        simulated = scenario.excitation is not None and scenario.simulation is not None
        self.checked = cross_check_sample(spec.count, spec.cross_check if simulated else 0, spec.seed)
        self.start = time.perf_counter()

    def jobs(self, skip=frozenset()) -> Iterator[tuple[int, tuple]]:
        """``(index, arguments of sweep_chunk)`` of every chunk not in ``skip``."""
        for index, rows in enumerate(self.chunks):
            if index not in skip:
                checked = tuple(int(i) for i in self.checked if i in rows)
                yield index, (self.scenario, self.spec, index, checked)

    def run(self, runner, skip=frozenset(), progress=None) -> Iterator[tuple[int, object]]:
        """Each chunk not in ``skip`` computed by ``runner`` (:class:`~sixdof.chunks.InProcess`,
        :func:`sixdof.workflows.tasks.task_runner`), as it finishes, with a meter over the chunks showing variants
        per second."""
        where = "" if runner.backend == "in-process" else f" on {runner.workers} Dask workers"
        shown = meter(progress, len(self.chunks), "chunks", "sweep" + where)
        shown.show(len(skip))
        done, variants, began = len(skip), 0, time.perf_counter()
        rate = ""
        for finished in runner.run(sweep_chunk, self.jobs(skip)):
            done += 1
            variants += len(self.chunks[finished.index])
            rate = f"{variants / (time.perf_counter() - began):.4g} variants/s"
            shown.show(done, rate)
            yield finished.index, finished.result
        shown.close(rate)

    def merged(self, results: Iterable, where: dict, sink=None):
        """The sweep's :class:`~sixdof.analysis.batch.BatchResult` from its chunks' results in order, cut to no
        variants, with the cross-check and the provenance ``where`` (:func:`where_ran`); ``sink`` receives each
        chunk (to keep or write it)."""
        first, direct, engine, width, count = None, [], [], 0, 0
        for index, result in enumerate(results):
            rows = self.chunks[index]
            if result.count != len(rows):  # never seen: the check that no variant is lost or doubled
                raise SolverError(f"chunk {index} holds {result.count} variants, not {len(rows)}")
            if first is None:
                first = axis_slice(result, slice(0, 0), "variant")
            width = max(width, result.chunk_size)
            count += result.count
            if result.cross_check_variants is not None:
                local = result.cross_check_variants - rows.start
                direct.append(np.hstack([result.cross_check_peak_q, result.cross_check_peak_qdd]))
                engine.append(np.hstack([result.peak_q[local], result.peak_qdd[local]]))
            if sink is not None:
                sink(result)
        if count != self.spec.count:
            raise SolverError(f"the chunks hold {count} variants, not {self.spec.count}")
        checks = {} if not direct else cross_check_fields(self.checked, np.vstack(direct), np.vstack(engine))
        fields = ("cross_check_variants", "cross_check_peak_q", "cross_check_peak_qdd", "cross_check")
        return dataclasses.replace(first, **{name: checks.get(name) for name in fields}, chunk_size=width,
                                   wall_time_s=time.perf_counter() - self.start, chunks=len(self.chunks), **where)


def where_ran(runner) -> dict:
    """Where the chunks ran: the backend and its worker processes now."""
    return {"backend": runner.backend, "workers": runner.workers}


def sweep_on(runner, scenario, spec, progress=None):
    """Every variant of ``spec``'s sweep of ``scenario`` (or :class:`Study`), in order, as one
    :class:`~sixdof.analysis.batch.BatchResult`: computed on an open ``runner`` (:class:`~sixdof.chunks.InProcess`,
    or :func:`sixdof.workflows.tasks.task_runner`'s), ``spec`` already checked (:meth:`SweepSpec.check`)."""
    run = ChunkedSweep(scenario, spec)
    found = dict(run.run(runner, progress=progress))
    kept = []
    merged = run.merged((found.pop(i) for i in range(len(run.chunks))), where_ran(runner), kept.append)
    # The merged result has no variants but every other field of the sweep: the chunks' variants join it.
    return axis_concat([merged, *kept], "variant")


__all__ = ["CHUNK_SIZE", "ChunkedSweep", "Study", "SweepSpec", "Vary", "sweep_chunk", "sweep_on", "time_system_of",
           "where_ran"]
