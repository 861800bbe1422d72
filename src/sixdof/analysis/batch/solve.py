"""A batch's run (:func:`run_batch`), its result (:class:`BatchResult`) and the cross-check of its peaks."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sixdof.analysis.batch.engines import EXACT_CHUNK, _diffrax_peaks, _exact_peaks, default_chunk_size
from sixdof.analysis.batch.variants import (
    Variants,
    _assembled,
    check_batchable,
    decoupling_percent,
    track_modes,
    variant_branches,
    variant_system,
)
from sixdof.analysis.compare import Agreement, compare
from sixdof.analysis.direct import SimulationSettings, simulate
from sixdof.analysis.superposition import superpose
from sixdof.dofs import UNITS
from sixdof.errors import InputError, Plain, SolverError, integer, readonly
from sixdof.excitation import ModeRelease
from sixdof.frozen import BriefRepr
from sixdof.model.system import System
from sixdof.progress import meter
from sixdof.results import label, part, quantity, result_type

ENGINES = ("exact", "diffrax")


#: Variants solved by diffrax (:func:`sixdof.analysis.direct.simulate`) as a cross-check, by default.
CROSS_CHECK = 3


@result_type
@dataclass(frozen=True, eq=False)
class BatchResult(BriefRepr):
    """Result of :func:`run_batch`.

    Attributes
    ----------
    variants : Variants
    frequency_hz : ndarray, shape (nv, 6)
        Undamped natural frequencies of each variant, ascending [Hz].
    tracked_frequency_hz : ndarray, shape (nv, 6), or None
        ``[v, j]``: natural frequency of variant v's mode that has the shape of the nominal mode j [Hz]
        (:func:`track_modes`); ``None`` in files written before it was kept.
    tracked_mac : ndarray, shape (nv, 6), or None
        ``[v, j]``: how alike the shapes of that mode and nominal mode j are (mass-weighted MAC: 1 the same
        shape, 0 orthogonal); a low value means mode j is not clearly found in variant v.
    tracked_decoupling_percent : ndarray, shape (nv, 6), or None
        ``[v, j]``: the decoupling of that mode, the kinetic-energy share of its dominant DOF [%] (as
        :attr:`sixdof.analysis.design.DesignMetrics.decoupling_percent`); ``None`` in files written before it was kept.
    peak_q : ndarray, shape (nv, 6) or None
        ``max |q|`` over the output samples per DOF [m, rad]; ``None`` without a simulation.
    peak_qdd : ndarray, shape (nv, 6) or None
        ``max |q''|`` over the output samples per DOF [m/s^2, rad/s^2].
    num_steps, num_rejected : ndarray, shape (nv,), int, or None
        Solver steps attempted and rejected per variant (diffrax engine).
    histories : dict of int to sixdof.results.TimeHistory
        Full time responses of the variants asked for (by index), by the engine's method.
    settings : sixdof.analysis.direct.SimulationSettings or None
    engine : str
        ``"exact"`` or ``"diffrax"`` (see the module).
    chunk_size : int
        Variants computed together.
    cross_check_variants : ndarray of int, shape (n_check,), or None
        The variants also solved by :func:`sixdof.analysis.direct.simulate` (diffrax).
    cross_check_peak_q, cross_check_peak_qdd : ndarray, shape (n_check, 6), or None
        Their peaks by :func:`sixdof.analysis.direct.simulate`.
    cross_check : sixdof.analysis.compare.Agreement or None
        Those peaks against the engine's: the worst of ``peak_q`` and ``peak_qdd``, each DOF relative
        to its largest peak over the sample (:func:`cross_check_fields`).
    wall_time_s : float
        Wall-clock time of the whole batch [s], compilation and cross-check included.
    backend : str
        Where a sweep's chunks ran (:data:`sixdof.chunks.BACKENDS`): ``"in-process"`` for a batch.
    workers : int
        Worker processes that computed them (at the end of the sweep).
    chunks : int
        Chunks of the sweep (:func:`sixdof.chunks.partition`; each drew its variants with its own seed):
        1 for a batch.
    resumed : int
        Chunks of a resumed sweep found finished and not computed again (not stored).
    """

    variants: Variants = part(lambda: Variants, prefix="")
    frequency_hz: np.ndarray = quantity("Hz", ("variant", "mode"), description="undamped natural frequencies of each "
                                        "variant")
    tracked_frequency_hz: np.ndarray | None = quantity(
        "Hz", ("variant", "mode"), default=None,
        description="natural frequency of each variant's mode with the shape of nominal mode j (mass-weighted MAC)")
    tracked_mac: np.ndarray | None = quantity(
        "1", ("variant", "mode"), default=None,
        description="mass-weighted MAC of that mode with nominal mode j (1: the same shape)")
    tracked_decoupling_percent: np.ndarray | None = quantity(
        "percent", ("variant", "mode"), default=None,
        description="kinetic-energy share of the dominant DOF of each variant's mode with the shape of nominal mode j")
    settings: Any = part(lambda: SimulationSettings, prefix="", default=None)
    peak_q: np.ndarray | None = quantity(UNITS["q"], ("variant", "dof"), default=None,
                                         description="max |q| over the output samples")
    peak_qdd: np.ndarray | None = quantity(UNITS["qdd"], ("variant", "dof"), default=None,
                                           description="max |q''| over the output samples")
    num_steps: np.ndarray | None = quantity("1", ("variant",), default=None, description="solver steps attempted")
    num_rejected: np.ndarray | None = quantity("1", ("variant",), default=None, description="solver steps rejected")
    engine: str = label(default="diffrax")  # what files written before the exact engine used
    chunk_size: int = label(default=0)
    cross_check_variants: np.ndarray | None = quantity(
        "1", ("checked_variant",), default=None, description="variants also solved by sixdof.simulate (diffrax)")
    cross_check_peak_q: np.ndarray | None = quantity(UNITS["q"], ("checked_variant", "dof"), default=None,
                                                     description="max |q| of the checked variants by diffrax")
    cross_check_peak_qdd: np.ndarray | None = quantity(UNITS["qdd"], ("checked_variant", "dof"), default=None,
                                                       description="max |q''| of the checked variants by diffrax")
    cross_check: Agreement | None = part(lambda: Agreement, prefix="cross_check_", default=None)
    wall_time_s: float = label(default=0.0)
    backend: str = label(default="in-process")
    workers: int = label(default=1)
    chunks: int = label(default=1)
    histories: dict = field(default_factory=dict)
    resumed: int = 0

    derived = {"count": label()}

    @property
    def count(self) -> int:
        """Number of variants."""
        return self.variants.count


def run_batch(system: System, variants: Variants, excitation=None, settings=None, *, time_system: System | None = None,
              histories=(), chunk_size: int | None = None, engine: str = "exact", cross_check: int = CROSS_CHECK,
              seed: int = 0, progress=None) -> BatchResult:
    """Natural frequencies and peak responses of many variants of ``system`` in one vectorized call.

    Parameters
    ----------
    system : System
        The nominal system; :class:`Variants` scale and move its mounts.
    variants : Variants
        From :func:`make_variants` (or :func:`load_sweep_spec`).
    excitation : sixdof.excitation.Excitation, optional
        Loads, ground motion (exact engine) and an optional :class:`~sixdof.excitation.InitialState`
        (no mode release). Without it (or without ``settings``) only frequencies are computed.
    settings : sixdof.analysis.direct.SimulationSettings, optional
        The same settings as :func:`sixdof.analysis.direct.simulate` (the exact engine uses its output
        times only).
    time_system : System, optional
        The model of the time responses, their histories and the cross-check, with the mounts of ``system``
        (names, positions, axes): a scenario's ``time_system``, whose mount axes with loss factors carry their
        causal Maxwell models (long-term stiffness and branches). The frequencies and tracked modes stay those
        of ``system``. Default ``system``. Each variant scales and moves its branches with their mounts
        (:func:`variant_system`).
    histories : sequence of int, optional
        Indices of variants whose full :class:`~sixdof.results.TimeHistory` is wanted (computed by the
        engine's method: :func:`sixdof.analysis.superposition.superpose` or
        :func:`sixdof.analysis.direct.simulate` on :func:`variant_system`).
    chunk_size : int, optional
        Variants computed together; default :data:`EXACT_CHUNK` (exact) or :func:`default_chunk_size`
        (diffrax, memory bound). The variants are split into chunks of equal size.
    engine : {"exact", "diffrax"}
        See the module.
    cross_check : int
        Number of variants also solved by :func:`sixdof.analysis.direct.simulate` (default
        :data:`CROSS_CHECK`; 0 for none), drawn with ``seed``.
    seed : int
        Seed of :func:`numpy.random.default_rng` drawing the cross-checked variants.
    progress : None, bool, "text" or "tqdm", optional
        Show the variants done on stderr (:func:`sixdof.progress.meter`), then the cross-check's.

    Returns
    -------
    BatchResult

    Raises
    ------
    InputError
        Unsupported excitation (mode release; ground motion with the diffrax engine), bad ``histories``,
        ``chunk_size``, ``engine`` or ``cross_check``.
    SolverError
        When the solve of any variant fails (its index is named) or gives non-finite values.
    """
    if not isinstance(variants, Variants):
        raise InputError("variants", "a Variants (see make_variants)", variants)
    if variants.stiffness_factor.shape[1] != len(system.mounts):
        raise InputError("variants", f"parameters for {len(system.mounts)} mounts",
                         Plain(f"{variants.stiffness_factor.shape[1]} mounts"))
    histories = tuple(histories)
    for i in histories:
        if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or not 0 <= i < variants.count:
            raise InputError("histories", f"variant indices in [0, {variants.count})", list(histories))
    if engine not in ENGINES:
        raise InputError("engine", "one of 'exact', 'diffrax'", engine)
    cross_check = integer(cross_check, "cross_check", "a number of variants >= 0", 0)
    timed = system if time_system is None else _same_mounts(system, time_system)
    start = time.perf_counter()
    K, C, lam, shapes = _assembled(system, variants)
    frequency = np.sqrt(lam) / (2.0 * np.pi)
    tracked, mac, decoupling = track_modes(system, frequency, shapes, decoupling_percent(system, shapes))
    modal = dict(frequency_hz=readonly(frequency), tracked_frequency_hz=tracked, tracked_mac=mac,
                 tracked_decoupling_percent=decoupling)
    if excitation is None or settings is None:
        return BatchResult(variants=variants, **modal, engine=engine, wall_time_s=time.perf_counter() - start)
    if isinstance(excitation.initial, ModeRelease):
        raise InputError("excitation.initial", "an InitialState in a batch (a mode release depends "
                         "on each variant's modes)", Plain("a ModeRelease"))
    if timed is not system:  # the time model's own stiffness (long-term along the causal models' axes)
        K, C, lam, shapes = _assembled(timed, variants)
    branches = variant_branches(timed, variants)
    nv = variants.count
    if chunk_size is None:
        chunk_size = EXACT_CHUNK if engine == "exact" else default_chunk_size(settings.times.size)
    chunk_size = min(integer(chunk_size, "chunk_size", "a positive integer", 1), nv)
    chunks = np.array_split(np.arange(nv), math.ceil(nv / chunk_size))  # sizes differ by one at most
    steps = rejected = None
    shown = meter(progress, nv, "variants", f"sweep ({engine} engine)")

    def done(fraction):  # of the variants' work
        shown.show(nv * fraction)

    if engine == "exact":
        peaks = _exact_peaks(timed, K, C, lam, shapes, branches, excitation, settings, chunks, done)
    else:
        peaks, steps, rejected = _diffrax_peaks(timed, K, C, branches, excitation, settings, chunks, done)
    shown.close()
    if not np.all(np.isfinite(peaks)):
        bad = np.flatnonzero(~np.all(np.isfinite(peaks), axis=1))
        raise SolverError(f"batch ({engine}) produced non-finite values for variant {int(bad[0])}")
    kept = {int(i): _history(timed, variants, int(i), excitation, settings, engine) for i in histories}
    checked = cross_check_sample(nv, cross_check, seed)
    direct = direct_peaks(timed, variants, checked, excitation, settings, progress)
    return BatchResult(variants=variants, **modal, peak_q=readonly(peaks[:, :6]),
                       peak_qdd=readonly(peaks[:, 6:]), num_steps=steps, num_rejected=rejected, histories=kept,
                       settings=settings, engine=engine, chunk_size=int(chunks[0].size),
                       **cross_check_fields(checked, direct, peaks[checked]), wall_time_s=time.perf_counter() - start)


def _same_mounts(system: System, time_system: System) -> System:
    """``time_system``, checked to have the mounts of ``system`` (the variants apply to both) and to be batchable."""
    if not isinstance(time_system, System):
        raise InputError("time_system", "a System", time_system)
    same = (time_system.mount_names == system.mount_names and np.array_equal(time_system.positions, system.positions)
            and np.array_equal(time_system.axes, system.axes) and np.array_equal(time_system.M, system.M))
    if not same:
        raise InputError("time_system", f"the body and mounts of system ({', '.join(system.mount_names)}, same "
                         "positions and axes)", Plain(f"mounts {', '.join(time_system.mount_names)}"))
    check_batchable(time_system)
    return time_system


def _history(system, variants, index, excitation, settings, engine):
    """The full response of one variant by the engine's method."""
    one = variant_system(system, variants, index)
    return superpose(one, excitation, settings.times) if engine == "exact" else simulate(one, excitation, settings)


def cross_check_sample(count: int, size: int, seed: int) -> np.ndarray:
    """The ``size`` variants of ``count`` (sorted indices) that diffrax solves again, drawn with ``seed``."""
    return np.sort(np.random.default_rng(seed).choice(count, min(size, count), replace=False))


def direct_peaks(system, variants, indices, excitation, settings, progress=None) -> np.ndarray:
    """``max |q|`` and ``max |q''|`` (n, 12) of the variants ``indices`` by
    :func:`~sixdof.analysis.direct.simulate` (diffrax), one after the other."""
    shown = meter(progress if len(indices) else None, len(indices), "variants", "cross-check (diffrax)")
    direct = np.zeros((len(indices), 12))
    for row, i in enumerate(indices):
        response = simulate(variant_system(system, variants, int(i)), excitation, settings)
        direct[row] = np.concatenate([np.max(np.abs(response.q), axis=0), np.max(np.abs(response.qdd), axis=0)])
        shown.show(row + 1)
    shown.close()
    return direct


def cross_check_fields(checked, direct, engine) -> dict:
    """The cross-check fields of a :class:`BatchResult`: the variants ``checked``, their peaks (n, 12) by
    diffrax (``direct``) and by the engine, and their agreement: the worse of ``|q|`` and ``|q''|``, each
    DOF relative to its largest peak over the sample."""
    if not len(checked):
        return {}
    agreement = max((compare(direct[:, part], engine[:, part]) for part in (slice(0, 6), slice(6, 12))),
                    key=lambda found: found.worst)
    return {"cross_check_variants": readonly(checked, int), "cross_check_peak_q": readonly(direct[:, :6]),
            "cross_check_peak_qdd": readonly(direct[:, 6:]), "cross_check": agreement}
