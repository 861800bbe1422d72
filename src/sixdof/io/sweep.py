"""Sweep specifications (``sixdof sweep --spec``): which mount parameters vary, and how, as TOML, read into a
:class:`~sixdof.analysis.sweep.SweepSpec` (which draws and computes the variants).

Read with the one TOML reader (:mod:`sixdof.schema`): unknown keys are rejected with the closest valid
key suggested, every error names the file and the field.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from sixdof.analysis.batch import CROSS_CHECK, ENGINES
from sixdof.analysis.sweep import SweepSpec, Vary
from sixdof.chunks import check_count
from sixdof.errors import InputError, Plain, integer, integer_check, optional
from sixdof.schema import Table, build, parse, read_text


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
    :data:`~sixdof.analysis.sweep.CHUNK_SIZE`; with ``seed`` it fixes the variants drawn).

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
