"""Many design variants in one vectorized computation, and the ``sixdof sweep`` command.

A batch varies the mounts of one system: stiffness factors, damping factors and position offsets,
per variant, per mount and per mount axis (:class:`Variants`). :func:`run_batch` assembles every
variant's M, K, C, natural frequencies and mode shapes in one ``jax.vmap`` of the pure assembly
functions of :mod:`sixdof.model.system` (``jnp.linalg.eigh`` of the mass-scaled stiffness), follows each
nominal mode into every variant by its shape (:func:`track_modes`: ascending order mixes modes whose
frequencies cross), then computes every variant's response, keeping only what is asked for: the peak of
``|q|`` and ``|q''|`` per DOF at the output samples, and the full :class:`~sixdof.results.TimeHistory` of a
few chosen variants.

Two engines compute the responses:

- ``"exact"`` (default): the exact linear engine of :mod:`sixdof.analysis.superposition`. The excitation
  is evaluated once on the quadrature nodes (a :class:`~sixdof.analysis.superposition.Drive` per
  window of output steps, shared by every variant); each variant contributes only its modal coordinates
  (method chosen per variant as in :func:`~sixdof.analysis.superposition.superpose`). The coordinates of
  a chunk of variants advance side by side, window by window, and only the peaks are kept. Loads,
  initial states and ground motion. With Maxwell branches each variant's coordinates are the complex modes
  of its augmented first-order system ``[eta, eta', f]``, as :func:`~sixdof.analysis.superposition.superpose`'s.
- ``"diffrax"``: ``jax.vmap`` of one diffrax solve (:func:`sixdof.analysis.direct.solve_ode` with the
  settings of :func:`~sixdof.analysis.direct.simulate`, tolerances on the state scaled by the *nominal*
  system's :func:`~sixdof.analysis.direct.state_scale`), each variant's first-order matrix ``A``
  (``12 + nb`` square with ``nb`` Maxwell branch states, :func:`~sixdof.analysis.direct.mechanical_form`)
  built once, in chunks of equal size. Loads and initial states; what nonlinear mounts will need.

Maxwell branches (measured ``dynamic_stiffness`` tables, ``loss_factor_model = "maxwell"``, and the causal
models of the loss factors that a scenario's ``time_system`` carries) follow each variant's mounts
(:func:`variant_system`): a branch scales with its mount axis's stiffness factor (a fit to that axis's loss
factor or table is linear in its stiffness; relaxation times unchanged) and moves with its mount's position
offset. :func:`run_batch` takes the frequency model (``system``: natural frequencies, tracked modes) and the time
model (``time_system``: the responses and the cross-check) apart, as ``sixdof run`` does.

A sample of the variants (``cross_check``, drawn with a seed) is also solved by
:func:`sixdof.analysis.direct.simulate` (diffrax); the worst agreement of its peaks with the engine's,
DOF by DOF, is kept in :attr:`BatchResult.cross_check`. Mode-release initial states (which depend on
each variant's modes) are not batched: they raise :class:`~sixdof.errors.InputError`.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections import namedtuple
from dataclasses import dataclass, field
from functools import partial
from importlib import import_module
from typing import Any

import numpy as np

from sixdof._jax import jax, jnp
from sixdof.analysis.compare import Agreement, compare
from sixdof.analysis.modal import pair_by_similarity, repeated_groups
from sixdof.analysis.statics import replace_with_preload
from sixdof.dofs import UNITS
from sixdof.errors import InputError, Plain, SolverError, integer, readonly
from sixdof.frozen import BriefRepr
from sixdof.model.damping import damping_matrix
from sixdof.model.kinematics import mount_local_map, mount_matrix_jax, stiffness_jax
from sixdof.model.modes import ZERO_MODE_RTOL
from sixdof.model.system import Branches, System
from sixdof.progress import meter
from sixdof.results import label, part, quantity, result_type

ENGINES = ("exact", "diffrax")
#: Memory allowed for the samples kept per chunk of variants of the diffrax engine [bytes] (``q`` and
#: ``q''``, float64).
CHUNK_BYTES = 256 * 2**20
#: Largest chunk of variants integrated together by diffrax (beyond it vectorizing gains nothing on CPU).
MAX_CHUNK = 256
#: Variants whose modal coordinates the exact engine advances side by side: enough that one time step
#: of all of them costs little more than of one, few enough that a window's arrays stay small.
EXACT_CHUNK = 64
#: Output steps per window of the exact engine: bounds its memory (the coordinates of a chunk of
#: variants over a window).
WINDOW = 2048
#: Variants solved by diffrax (:func:`sixdof.analysis.direct.simulate`) as a cross-check, by default.
CROSS_CHECK = 3


# ----------------------------------------------------------------------------------------------------
# Variants and results.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Variants:
    """Parameter variants of a system's mounts, one row per variant.

    Build with :func:`make_variants` (which broadcasts and validates).

    Attributes
    ----------
    stiffness_factor : ndarray, shape (nv, n_mounts, 3)
        Multiplies each mount's stiffness along its own axes (> 0).
    damping_factor : ndarray, shape (nv, n_mounts, 3)
        Multiplies each mount's dashpot along its own axes (>= 0).
    position_offset : ndarray, shape (nv, n_mounts, 3)
        Added to each mount's position, body axes [m].
    """

    stiffness_factor: np.ndarray = quantity("1", ("variant", "mount", "mount_axis"),
                                            description="factor on each mount's stiffness")
    damping_factor: np.ndarray = quantity("1", ("variant", "mount", "mount_axis"),
                                          description="factor on each mount's dashpot")
    position_offset: np.ndarray = quantity("m", ("variant", "mount", "axis"),
                                           description="offset added to each mount's position, body axes")

    @property
    def count(self) -> int:
        """Number of variants ``nv``."""
        return int(self.stiffness_factor.shape[0])


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
        Where a sweep's chunks ran (:data:`sixdof.tasks.BACKENDS`): ``"in-process"`` for a batch.
    workers : int
        Worker processes that computed them (at the end of the sweep).
    chunks : int
        Chunks of the sweep (:func:`sixdof.tasks.partition`; each drew its variants with its own seed):
        1 for a batch.
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
    settings: Any = part(lambda: import_module("sixdof.analysis.direct").SimulationSettings, prefix="", default=None)
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

    derived = {"count": label()}

    @property
    def count(self) -> int:
        """Number of variants."""
        return self.variants.count


def check_batchable(system: System) -> None:
    """Raise an :class:`InputError` naming the mounts unless the batch engines can run variants of ``system``:
    not with nonlinear mounts (Maxwell branches are carried)."""
    if system.nonlinear.count:
        raise InputError("mounts", "linear mounts (sweeps and batches of mounts with bump stops, lift-off or "
                         "force-deflection tables are not supported yet)",
                         Plain(f"nonlinear mount axes {', '.join(system.nonlinear.names)}"))


def make_variants(system: System, *, stiffness_factor=None, damping_factor=None,
                  position_offset=None, count: int | None = None) -> Variants:
    """Broadcast per-variant parameters to :class:`Variants` of ``system``.

    Parameters
    ----------
    system : System
    stiffness_factor, damping_factor : array_like, optional
        Shape (nv,) (every mount and axis), (nv, n_mounts) (every axis of a mount) or
        (nv, n_mounts, 3). Default 1.
    position_offset : array_like, optional
        Shape (nv, 3) (every mount moves alike) or (nv, n_mounts, 3) [m]. Default 0.
    count : int, optional
        Number of variants when no parameter gives it.

    Raises
    ------
    InputError
        Inconsistent counts, wrong shapes, stiffness factors <= 0, damping factors < 0, non-finite
        values, or a system the batch engines cannot run (:func:`check_batchable`).
    """
    check_batchable(system)
    n = len(system.mounts)
    factor_shapes = f"shape (nv,), (nv, {n}) or (nv, {n}, 3)"
    arrays = {}
    for name, value, shapes in (("stiffness_factor", stiffness_factor, factor_shapes),
                                ("damping_factor", damping_factor, factor_shapes),
                                ("position_offset", position_offset, f"shape (nv, 3) or (nv, {n}, 3) in m")):
        if value is None:
            continue
        try:
            a = np.array(value, dtype=float)
        except (TypeError, ValueError):
            raise InputError(name, "an array of finite numbers", value) from None
        if a.ndim == 0 or a.shape[0] == 0 or not np.all(np.isfinite(a)):
            raise InputError(name, "an array of finite numbers, one row per variant", value)
        if name == "position_offset" and a.shape[1:] == (3,):
            a = a[:, None, :]  # every mount moves alike
        elif name != "position_offset" and a.shape[1:] in ((), (n,)):
            a = a.reshape(a.shape + (1,) * (3 - a.ndim))  # every axis (and mount) alike
        elif a.shape[1:] != (n, 3):
            raise InputError(name, shapes, Plain(f"shape {a.shape}"))
        arrays[name] = np.broadcast_to(a, (a.shape[0], n, 3))
    counts = {a.shape[0] for a in arrays.values()}
    if count is not None:
        counts.add(integer(count, "count", "a positive integer", 1))
    if len(counts) != 1:
        raise InputError("variants", "one number of variants for every parameter",
                         Plain("counts " + ", ".join(str(c) for c in sorted(counts)) if counts else "none"))
    nv = counts.pop()
    ones = np.ones((nv, n, 3))
    k = readonly(arrays.get("stiffness_factor", ones))
    d = readonly(arrays.get("damping_factor", ones))
    x = readonly(arrays.get("position_offset", np.zeros((nv, n, 3))))
    if np.any(k <= 0):
        raise InputError("stiffness_factor", "factors > 0", Plain(f"min {k.min():.6g}"))
    if np.any(d < 0):
        raise InputError("damping_factor", "factors >= 0", Plain(f"min {d.min():.6g}"))
    return Variants(stiffness_factor=k, damping_factor=d, position_offset=x)


def variant_system(system: System, variants: Variants, index: int) -> System:
    """The :class:`~sixdof.model.system.System` of variant ``index`` (same body and global damping).

    Each mount's stiffness and dashpot are scaled along its axes and its position offset. Its Maxwell branches
    (:attr:`System.maxwell`: measured ``dynamic_stiffness`` tables, ``loss_factor_model = "maxwell"``, or the
    causal models of the loss factors that a scenario's ``time_system`` carries) scale with the mount's
    stiffness factor along each axis, relaxation times unchanged: a fit to a mount axis's loss factor or table
    is linear in its stiffness, so that of ``f k`` is ``f`` times that of ``k``. They act at the mount, so they
    move with it.
    """
    if not 0 <= index < variants.count:
        raise InputError("index", f"a variant index in [0, {variants.count})", index)
    mounts = [
        dataclasses.replace(m, position=m.position + variants.position_offset[index, j],
                            stiffness=m.stiffness * variants.stiffness_factor[index, j],
                            damping=m.damping * variants.damping_factor[index, j])
        for j, m in enumerate(system.mounts)
    ]
    number = {name: j for j, name in enumerate(system.mount_names)}
    branches = [dataclasses.replace(b, stiffness=b.stiffness * variants.stiffness_factor[index, number[b.mount]])
                for b in system.maxwell]
    return replace_with_preload(system, mounts=tuple(mounts), maxwell=tuple(branches))  # its own statics


def variant_branches(system: System, variants: Variants) -> list[Branches] | None:
    """Each variant's Maxwell branch states (:attr:`System.branches` of :func:`variant_system`, vectorized):
    the rows of the moved mounts, stiffnesses times the mount axis's stiffness factor; None without branches."""
    nominal = system.branches
    if not nominal.count:
        return None
    positions = system.positions[None] + variants.position_offset  # (nv, n, 3)
    local = mount_local_map(positions, system.axes)  # (nv, n, 3, 6)
    rows = local[:, nominal.mount, nominal.axis]  # (nv, nb, 6)
    stiffness = nominal.stiffness[None] * variants.stiffness_factor[:, nominal.mount, nominal.axis]
    return [dataclasses.replace(nominal, rows=readonly(rows[v]), stiffness=readonly(stiffness[v]))
            for v in range(variants.count)]


# ----------------------------------------------------------------------------------------------------
# Vectorized assembly.
# ----------------------------------------------------------------------------------------------------


@jax.jit
def _assemble(M, positions, stiffness, damping, axes, alpha, beta, zeta, weight):
    """K, C (nv, 6, 6), eigenvalues omega^2 (nv, 6) and mass-normalized mode shapes (nv, 6, 6) of every
    variant: the model's own assembly and damping matrix, vmapped; K with the geometric stiffness of each
    variant's own preload under the weight ``weight`` (3,) [N] (None: none)."""
    chol = jnp.linalg.cholesky(M)
    chol_inv = jnp.linalg.inv(chol)

    def one(pos, k, d):
        K = stiffness_jax(pos, k, axes, weight)
        Kt = chol_inv @ K @ chol_inv.T
        lam, V = jnp.linalg.eigh(0.5 * (Kt + Kt.T))
        lam = jnp.where(jnp.abs(lam) <= ZERO_MODE_RTOL * jnp.max(jnp.abs(lam)), 0.0, lam)
        shapes = chol_inv.T @ V  # mass-normalized: phi = L^-T V
        omega = jnp.sqrt(jnp.maximum(lam, 0.0))
        C = damping_matrix(M, K, mount_matrix_jax(pos, d, axes), alpha, beta, zeta, shapes, omega)
        return K, C, lam, shapes

    return jax.vmap(one)(positions, stiffness, damping)


#: The undamped modes of one variant, as :func:`sixdof.analysis.statespace.modal_basis` reads them.
_Modes = namedtuple("_Modes", "eigenvalues shapes")


def _assembled(system: System, variants: Variants):
    """K, C (nv, 6, 6), omega^2 (nv, 6) [rad^2/s^2] and mode shapes (nv, 6, 6) of every variant."""
    zeta = np.broadcast_to(np.asarray(system.modal_damping or 0.0, dtype=float), (6,))
    alpha, beta = (system.rayleigh.alpha, system.rayleigh.beta) if system.rayleigh is not None else (0.0, 0.0)
    out = _assemble(
        np.asarray(system.M), system.positions[None] + variants.position_offset,
        system.stiffnesses[None] * variants.stiffness_factor,
        system.dampings[None] * variants.damping_factor, system.axes, alpha, beta, zeta, system.preload_weight,
    )
    return tuple(np.asarray(a) for a in out)


def variant_matrices(system: System, variants: Variants) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness and damping matrices (nv, 6, 6) and undamped eigenvalues omega^2 (nv, 6) [rad^2/s^2]
    of every variant, in one vectorized call of the model's assembly."""
    return _assembled(system, variants)[:3]


def track_modes(system: System, frequency_hz, shapes) -> tuple[np.ndarray, np.ndarray]:
    """Follow each nominal mode of ``system`` into its variants by shape.

    Ascending order mixes modes: where two frequencies cross from one variant to the next, "f1" is one mode in
    some variants and another in the rest, and its spread is neither's. Each variant's modes are instead paired
    with the nominal modes by the mass-weighted modal assurance criterion, most alike first
    (:func:`~sixdof.analysis.modal.pair_by_similarity`): the sweep's spread of each mode's frequency.

    The modes of a repeated nominal frequency (:func:`~sixdof.analysis.modal.repeated_groups`: a symmetric layout's
    pairs, the rigid-body modes) have no shapes of their own, only a space: the group is followed as one, each
    variant's mode judged by its share in that space (the sum of its MACs with the group's modes), and the modes
    found take the group's places in ascending order.

    Parameters
    ----------
    system : System
        The nominal system (the variants share its mass).
    frequency_hz : ndarray, shape (nv, 6)
        The variants' natural frequencies, ascending [Hz].
    shapes : ndarray, shape (nv, 6, 6)
        Their mode shapes (columns), mass-normalized.

    Returns
    -------
    tracked_frequency_hz, tracked_mac : ndarray, shape (nv, 6)
        ``[v, j]``: the frequency [Hz] of variant v's mode paired with nominal mode j, and their MAC.
    """
    # Both sets mass-normalized with the same M: MAC = (phi_i' M psi_j)^2 / (phi_i' M phi_i psi_j' M psi_j) is the
    # square of the mass-weighted product alone.
    mac = np.einsum("di,de,vej->vij", system.modes.shapes, np.asarray(system.M), np.asarray(shapes)) ** 2
    groups = repeated_groups(system.modes.eigenvalues)
    for group in groups:
        mac[:, group, :] = mac[:, group, :].sum(axis=1, keepdims=True)
    paired = pair_by_similarity(mac)  # 6 x 6: every nominal mode gets a variant's mode, unless the MAC is NaN
    for group in groups:  # the variants' modes are ascending: so are their sorted indices
        paired[:, group] = np.sort(paired[:, group], axis=1)
    rows, found = np.arange(len(mac))[:, None], paired >= 0
    frequency = np.where(found, np.asarray(frequency_hz)[rows, paired], np.nan)
    return readonly(frequency), readonly(np.where(found, mac[rows, np.arange(6), paired], np.nan))


def batch_frequencies(system: System, variants: Variants) -> np.ndarray:
    """Undamped natural frequencies of every variant, shape (nv, 6), ascending [Hz]."""
    _, _, lam = variant_matrices(system, variants)
    return readonly(np.sqrt(lam) / (2.0 * np.pi))


# ----------------------------------------------------------------------------------------------------
# The engines.
# ----------------------------------------------------------------------------------------------------


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
    from sixdof.excitation import ModeRelease

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
    tracked, mac = track_modes(system, frequency, shapes)
    modal = dict(frequency_hz=readonly(frequency), tracked_frequency_hz=tracked, tracked_mac=mac)
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
    from sixdof.analysis.direct import simulate
    from sixdof.analysis.superposition import superpose

    one = variant_system(system, variants, index)
    return superpose(one, excitation, settings.times) if engine == "exact" else simulate(one, excitation, settings)


def cross_check_sample(count: int, size: int, seed: int) -> np.ndarray:
    """The ``size`` variants of ``count`` (sorted indices) that diffrax solves again, drawn with ``seed``."""
    return np.sort(np.random.default_rng(seed).choice(count, min(size, count), replace=False))


def direct_peaks(system, variants, indices, excitation, settings, progress=None) -> np.ndarray:
    """``max |q|`` and ``max |q''|`` (n, 12) of the variants ``indices`` by
    :func:`~sixdof.analysis.direct.simulate` (diffrax), one after the other."""
    from sixdof.analysis.direct import simulate

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


def _exact_peaks(system, K, C, lam, shapes, branches, excitation, settings, chunks, done) -> np.ndarray:
    """``max |q|`` and ``max |q''|`` (nv, 12) at the output samples by the exact linear engine (each variant's
    Maxwell ``branches``, None without: complex modes of its augmented first-order system, as
    :func:`~sixdof.analysis.superposition.superpose`); ``done`` receives the fraction of the work done after
    each window of each chunk."""
    from sixdof.analysis import superposition as sp

    M = np.asarray(system.M, dtype=float)
    t = settings.times
    loads, ground, omega = sp.excitation_inputs(excitation, system.K, system.C)  # each variant's ground vectors: _Stack
    q0, qd0 = excitation.initial_state(system, t[0])  # the same for every variant (no mode release)
    f0 = excitation.initial_branch_forces(system)
    plans = [sp.Plan(M, C[i], _Modes(lam[i], shapes[i]), branches=None if branches is None else branches[i])
             for i in range(len(lam))]
    # One quadrature for every variant: that of the fastest.
    nodes, pieces = sp.quadrature_for(float(np.max(np.diff(t))), max(p.fastest for p in plans), omega, ground)
    r = None if ground is None else np.asarray(excitation.ground.rigid_vector, dtype=float)
    stacks = [_Stack([plans[i].coordinates(plans[i].runs[0]) for i in index],
                     None if r is None else [np.stack([K[i] @ r, C[i] @ r]) for i in index],
                     None if r is None or branches is None else
                     [-branches[i].stiffness * (branches[i].rows @ r) for i in index]) for index in chunks]
    z = [stack.initial(M, q0, qd0, f0) for stack in stacks]
    peaks = np.zeros((len(lam), 12))
    breakpoints = np.asarray(excitation.breakpoints, dtype=float)
    ground_start = None
    for low in range(0, t.size - 1, WINDOW):  # windows of output steps, each evaluated once for all
        high = min(low + WINDOW, t.size - 1)
        drive = sp.make_drive(t[low:high + 1], high - low + (low == 0), breakpoints, loads, ground, nodes=nodes,
                              pieces=pieces, ground_start=ground_start)
        ground_start = drive.ground_end
        for k, (stack, index) in enumerate(zip(stacks, chunks)):
            coordinates = sp.run_coordinates(stack, drive, z[k])
            z[k] = coordinates[-1]
            peaks[index] = np.maximum(peaks[index], stack.peaks(coordinates[drive.first:], drive))
            done((low + (high - low) * (k + 1) / len(stacks)) / (t.size - 1))
    return peaks


class _Stack:
    """The first-order modal coordinates of several variants side by side (a block-diagonal system),
    each padded with inert coordinates to the same count so that their outputs are one batched product.

    Parameters
    ----------
    members : list of sixdof.analysis.superposition.ModalCoordinates
    ground_vectors : list of ndarray (2, 6), or None
        Each variant's ``K r`` and ``C r``: the generalized force per unit ground displacement and
        velocity (the drive's last two columns).
    branch_ground : list of ndarray (nb,), or None
        Each variant's ``-k_b R r``: the direct input to its Maxwell branch states per unit ground velocity
        (the drive's last column); None without ground motion or branches.
    """

    def __init__(self, members, ground_vectors=None, branch_ground=None):
        self.members, self.ground_vectors, self.branch_ground = members, ground_vectors, branch_ground
        self.width = max(member.poles.size for member in members)
        self.size = self.width * len(members)
        # An inert coordinate: pole 0, no input, no output, zero initially (it stays 0).
        self.poles = self._side_by_side([m.poles for m in members])
        self.source = self._side_by_side([np.where(m.source >= 0, m.source + j * self.width, -1)
                                          for j, m in enumerate(members)], fill=-1).astype(np.int64)
        # Each member's q, then q'' without B B' Q, from its coordinates' real and imaginary parts
        # interleaved: (members, 2 width, 12).
        maps = self._side_by_side([m.output_maps()[[0, 2]].reshape(12, -1) for m in members])  # (12, size)
        self.maps = np.ascontiguousarray(np.stack([maps.real, -maps.imag], axis=2).reshape(
            12, len(members), 2 * self.width).transpose(1, 0, 2))  # (members, 12, 2 width)
        self._forcing = None

    def _side_by_side(self, blocks, fill=0):
        """Per-member arrays (..., m_j) padded to the common width and put side by side (..., size)."""
        out = np.full(blocks[0].shape[:-1] + (self.size,), fill, dtype=np.result_type(*blocks))
        for j, block in enumerate(blocks):
            out[..., j * self.width:j * self.width + block.shape[-1]] = block
        return out

    def _vectors(self, vectors, j):
        return vectors if self.ground_vectors is None else np.vstack([vectors[:-2], self.ground_vectors[j]])

    def _branch_vectors(self, vectors, j):
        """Member j's direct input to its branch states per unit of each column (n_c, nb): its ground velocity's."""
        if self.branch_ground is None:
            return None
        out = np.zeros((vectors.shape[0], self.branch_ground[j].size))
        out[-1] = self.branch_ground[j]
        return out

    def forcing(self, vectors, branch_vectors=None):
        """(n_c, size): each variant's modal force per unit of each column, with its own ground vectors and input
        to its Maxwell branches (``branch_vectors``, the drive's, is None: it knows no variant's branches)."""
        if self._forcing is None or not np.array_equal(self._forcing[0], vectors):  # the same on every window
            self._forcing = (vectors, self._side_by_side([m.forcing(self._vectors(vectors, j),
                                                                    self._branch_vectors(vectors, j))
                                                          for j, m in enumerate(self.members)]),
                             np.stack([self._vectors(vectors, j) @ (m.basis @ m.basis.T)
                                       for j, m in enumerate(self.members)]))
        return self._forcing[1]

    def initial(self, M, q0, qd0, f0=None):
        """The coordinates (size,) of the state ``q0, qd0`` [m, rad; m/s, rad/s] and branch forces ``f0`` [N]."""
        return self._side_by_side([m.initial @ np.concatenate([m.basis.T @ (M @ q0), m.basis.T @ (M @ qd0)])
                                   + (m.branch_inputs @ f0 if f0 is not None and np.any(f0) else 0.0)
                                   for m in self.members])

    def peaks(self, z, drive):
        """``max |q|`` and ``max |q''|`` (n_members, 12) over the drive's outputs from the coordinates z (n, size)."""
        parts = z.view(float).reshape(z.shape[0], len(self.members), 2 * self.width).transpose(1, 2, 0)
        motion = np.matmul(self.maps, parts)  # (members, 12, n): each member's q and q'' in time
        self.forcing(drive.vectors)
        motion[:, 6:] += np.matmul(self._forcing[2].transpose(0, 2, 1), drive.columns_out.T)  # B B' Q
        return np.maximum(motion.max(axis=2), -motion.min(axis=2))


@partial(jax.jit, static_argnames=("solver", "max_steps"))
def _solve_chunk(A, B, x0, sigma, signals, ts, t0, t1, jump_ts, rtol, atol, *, solver, max_steps):
    """Peaks of |q| and |q''| at ``ts`` for a chunk of variants: A (nv, N, N), B (nv, N, nc), ``N = 12 + nb`` with
    ``nb`` Maxwell branch states (:func:`~sixdof.analysis.direct.mechanical_form`)."""
    import diffrax

    from sixdof.analysis.direct import solve_ode

    def source(t):
        return jnp.stack([s(t) for s in signals]) if signals else jnp.zeros(0)

    def one(A, B, x0):
        # Scaled state xs = x / sigma: A and B are pre-scaled, so the field is one N x N product.
        As = A * sigma[None, :] / sigma[:, None]
        Bs = B / sigma[:, None]

        def field(t, xs, args):
            return As @ xs + Bs @ source(t)

        def keep(t, xs, args):
            rate = (A @ (xs * sigma) + B @ source(t))[6:12]
            return jnp.concatenate([xs[:6] * sigma[:6], rate])

        sol = solve_ode(field, x0 / sigma, t0, t1, diffrax.SaveAt(ts=ts, fn=keep), jump_ts, rtol, atol,
                        solver=solver, max_steps=max_steps)
        peaks = jnp.max(jnp.abs(sol.ys), axis=0)
        ok = sol.result == diffrax.RESULTS.successful
        return peaks, ok, sol.stats["num_steps"], sol.stats["num_rejected_steps"]

    return jax.vmap(one)(A, B, x0)


def default_chunk_size(n_samples: int) -> int:
    """Variants per chunk of the diffrax engine so that the kept samples stay within :data:`CHUNK_BYTES`."""
    return int(max(1, min(MAX_CHUNK, CHUNK_BYTES // (max(n_samples, 1) * 12 * 8))))


def _diffrax_peaks(system, K, C, branches, excitation, settings, chunks, done):
    """``max |q|`` and ``max |q''|`` (nv, 12), steps and rejected steps (nv,) by the vmapped diffrax solve of each
    variant's first-order form with its Maxwell ``branches`` (None without); ``done`` receives the fraction of the
    variants done after each chunk."""
    from sixdof.analysis.direct import jump_times, loads_of, mechanical_form, state_scale

    if excitation.ground is not None:
        raise InputError("excitation.ground", "no ground motion in a diffrax batch (not supported yet; use "
                         "engine='exact', or sixdof.analysis.direct.simulate per variant)", Plain("a ground motion"))
    vectors, signals = loads_of(excitation, settings)
    M = np.asarray(system.M, dtype=float)
    Minv = np.linalg.inv(M)
    nv = K.shape[0]
    nb = system.branches.count
    rows = np.stack([b.rows for b in branches]) if nb else np.zeros((nv, 0, 6))
    k_b = np.stack([b.stiffness for b in branches]) if nb else np.zeros((nv, 0))
    A = mechanical_form(Minv, K, C, rows, k_b, system.branches.tau)
    B = np.zeros((nv, 12 + nb, len(signals)))
    B[:, 6:12, :] = (Minv @ vectors.T)[None]
    q0, qd0 = excitation.initial_state(system)
    x0 = np.broadcast_to(np.concatenate([q0, qd0, excitation.initial_branch_forces(system)]), (nv, 12 + nb))
    scale = state_scale(system, excitation, settings)
    sigma = np.concatenate([scale[:12], scale[14:]])  # no ground in a diffrax batch: z, w and f
    t0, t1 = settings.start, settings.start + settings.duration
    padded, _ = jump_times(excitation, t0, t1)
    size = chunks[0].size
    outputs = []
    for index in chunks:
        # One compiled shape: a chunk one short (sizes differ by one at most) repeats its last variant.
        full = np.append(index, np.full(size - index.size, index[-1]))
        out = _solve_chunk(A[full], B[full], x0[full], sigma, signals, settings.times, t0, t1, padded,
                           settings.rtol, settings.atol, solver=settings.solver, max_steps=settings.max_steps)
        outputs.append([np.asarray(o)[:index.size] for o in out])
        done(sum(o[0].shape[0] for o in outputs) / nv)
    peaks, ok, steps, rejected = (np.concatenate([o[k] for o in outputs]) for k in range(4))
    if not np.all(ok):
        bad = np.flatnonzero(~ok)
        raise SolverError(f"batch solve with {settings.solver} (rtol={settings.rtol:g}, atol={settings.atol:g}, "
                          f"max_steps={settings.max_steps}) failed for {bad.size} of {nv} variants "
                          f"(first: index {int(bad[0])})")
    return peaks, readonly(steps, int), readonly(rejected, int)
