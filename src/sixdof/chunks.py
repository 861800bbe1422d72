"""A study of many independent variants cut into chunks, and their seeds.

A study of many variants (a sweep, the robustness samples of a design) is cut into chunks of equal size
(:func:`partition`). Chunk ``i`` draws its random numbers from ``numpy.random.default_rng([seed, i])``
(:func:`chunk_rng`), so a result depends on the seed and the partition only, never on where the chunks
ran, how many workers ran them or in which order they finished.

The chunks run one after the other in this process (:class:`InProcess`), or as tasks of a Dask cluster
(:mod:`sixdof.workflows.tasks`, which gives the place they run): either yields each chunk's result as a
:class:`Finished`. :func:`check_count` refuses up front a study too large to compute.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from sixdof.errors import InputError, Plain

#: Where a study's chunks ran: this process, a local Dask cluster started for it, an existing Dask cluster.
BACKENDS = ("in-process", "dask-local", "dask")

#: The most variants a sweep or a robustness study may ask for (:func:`check_count`): 10^7 take 6 min of the
#: exact engine for frequencies alone and about 10 h with the bundled bridge's 20,001-sample simulation
#: (3.5 ms a variant), in 10^4 chunk files; more is a typo or a job for several runs.
MAX_VARIANTS = 10**7
#: The least one variant costs the exact batch engine [s]: its natural frequencies alone (no simulation);
#: measured 34-54 us on the bundled engine_inclined_mounts scenario in chunks of 1000 (2 shared cores).
SECONDS_PER_VARIANT = 30e-6


def duration_text(seconds: float) -> str:
    """``seconds`` in the unit that reads best: "50 µs", "40 s", "3.2 h", "12 days", "3.2e+04 years"."""
    for unit, size in (("years", 365.25 * 86400), ("days", 86400), ("h", 3600), ("min", 60), ("s", 1.0),
                       ("ms", 1e-3)):
        if seconds >= 2 * size or unit in ("s", "ms") and seconds >= size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds * 1e6:.3g} µs"


def check_count(count: int, field: str, what: str = "variants", limit: int = MAX_VARIANTS,
                seconds_each: float = SECONDS_PER_VARIANT) -> None:
    """Refuse up front a study of more than ``limit`` ``what``, with the time they would take at
    ``seconds_each`` [s] each (default: a sweep's variants on the exact engine, :data:`SECONDS_PER_VARIANT`).

    Raises
    ------
    InputError
        ``field: expected at most <limit> <what>, got <count> (at least <time> at <seconds_each> each)``.
    """
    if count > limit:
        raise InputError(field, f"at most {limit:,} {what}",
                         Plain(f"{count:,} (at least {duration_text(count * seconds_each)} of computing at "
                               f"{duration_text(seconds_each)} each)"))


def partition(count: int, size: int) -> list[range]:
    """``range(count)`` cut into ``ceil(count / size)`` chunks whose sizes differ by one at most."""
    chunks = -(-count // size)
    bounds = [i * count // chunks for i in range(chunks + 1)]
    return [range(low, high) for low, high in zip(bounds[:-1], bounds[1:])]


def chunk_rng(seed: int, index: int) -> np.random.Generator:
    """The random numbers of chunk ``index`` of a study seeded with ``seed``."""
    return np.random.default_rng([seed, index])


@dataclass(frozen=True)
class Finished:
    """A chunk's result, as it arrives."""

    index: int
    result: Any


class InProcess:
    """Chunks computed one after the other in this process."""

    backend = "in-process"
    workers = 1

    def run(self, task: Callable, jobs: Iterable[tuple[int, tuple]]) -> Iterator[Finished]:
        """``task(*args)`` for each ``(index, args)`` of ``jobs``, yielded as each finishes."""
        for index, args in jobs:
            yield Finished(index, task(*args))


__all__ = ["BACKENDS", "Finished", "InProcess", "MAX_VARIANTS", "SECONDS_PER_VARIANT", "check_count", "chunk_rng",
           "duration_text", "partition"]
