"""Many design variants in one vectorized computation, and the ``sixdof sweep`` command.

A batch varies the mounts of one system: stiffness factors, damping factors and position offsets,
per variant, per mount and per mount axis (:class:`Variants`). :func:`run_batch` assembles every
variant's M, K, C and its natural frequencies in one ``jax.vmap`` of the pure assembly functions of
:mod:`sixdof.model.system` (``jnp.linalg.eigh`` of the mass-scaled stiffness), then integrates all variants
together with ``jax.vmap`` of one diffrax solve, in chunks of variants that bound memory, keeping only
what is asked for: the peak of ``|q|`` and ``|q''|`` per DOF at the output samples, and the full
:class:`~sixdof.results.TimeHistory` of a few chosen variants.

The solve is :func:`sixdof.analysis.direct.solve_ode` with the settings of
:func:`~sixdof.analysis.direct.simulate` (tolerances on the state scaled by the *nominal* system's
:func:`~sixdof.analysis.direct.state_scale`: it only weights the error control). Unlike ``simulate``,
which keeps the 14-value state, loads and ground motion at every sample (4.6 MB per variant for 20 s
at 1 kHz), it builds each variant's first-order matrix ``A`` (12x12) once and keeps only ``q`` and
``q''``: half the time per variant and the memory per chunk. Ground motion and mode-release initial
states (which depend on each variant's modes) are not batched yet: they raise
:class:`~sixdof.errors.InputError`; run those variants through ``simulate``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import partial
from importlib import import_module
from typing import Any

import numpy as np

from sixdof._jax import jax, jnp
from sixdof.analysis.modal import ZERO_MODE_RTOL
from sixdof.dofs import UNITS, dof_units
from sixdof.errors import InputError, Plain, SolverError, integer, readonly
from sixdof.model.damping import damping_matrix
from sixdof.model.kinematics import mount_matrix_jax
from sixdof.model.system import Mount, System
from sixdof.results import label, part, quantity

#: Memory allowed for the samples kept per chunk of variants [bytes] (``q`` and ``q''``, float64).
CHUNK_BYTES = 256 * 2**20
#: Largest chunk of variants integrated together (beyond it vectorizing gains nothing on CPU).
MAX_CHUNK = 256


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


@dataclass(frozen=True, eq=False)
class BatchResult:
    """Result of :func:`run_batch`.

    Attributes
    ----------
    variants : Variants
    frequency_hz : ndarray, shape (nv, 6)
        Undamped natural frequencies of each variant, ascending [Hz].
    peak_q : ndarray, shape (nv, 6) or None
        ``max |q|`` over the output samples per DOF [m, rad]; ``None`` without a simulation.
    peak_qdd : ndarray, shape (nv, 6) or None
        ``max |q''|`` over the output samples per DOF [m/s^2, rad/s^2].
    num_steps, num_rejected : ndarray, shape (nv,), int, or None
        Solver steps attempted and rejected per variant.
    histories : dict of int to sixdof.results.TimeHistory
        Full time responses of the variants asked for (by index).
    settings : sixdof.analysis.direct.SimulationSettings or None
    chunk_size : int
        Variants integrated together.
    wall_time_s : float
        Wall-clock time of the whole batch [s], compilation included when it happened.
    """

    variants: Variants = part(lambda: Variants, prefix="")
    frequency_hz: np.ndarray = quantity("Hz", ("variant", "mode"), description="undamped natural frequencies of each "
                                        "variant")
    settings: Any = part(lambda: import_module("sixdof.analysis.direct").SimulationSettings, prefix="", default=None)
    peak_q: np.ndarray | None = quantity(UNITS["q"], ("variant", "dof"), dof_units=dof_units(0), default=None,
                                         description="max |q| over the output samples")
    peak_qdd: np.ndarray | None = quantity(UNITS["qdd"], ("variant", "dof"), dof_units=dof_units(2), default=None,
                                           description="max |q''| over the output samples")
    num_steps: np.ndarray | None = quantity("1", ("variant",), default=None, description="solver steps attempted")
    num_rejected: np.ndarray | None = quantity("1", ("variant",), default=None, description="solver steps rejected")
    chunk_size: int = label(default=0)
    wall_time_s: float = label(default=0.0)
    histories: dict = field(default_factory=dict)

    derived = {"count": label()}

    @property
    def count(self) -> int:
        """Number of variants."""
        return self.variants.count


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
        values.
    """
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
    """The :class:`~sixdof.model.system.System` of variant ``index`` (same body and global damping)."""
    if not 0 <= index < variants.count:
        raise InputError("index", f"a variant index in [0, {variants.count})", index)
    mounts = [
        Mount(m.name, m.position + variants.position_offset[index, j],
              m.stiffness * variants.stiffness_factor[index, j],
              m.damping * variants.damping_factor[index, j], m.axes, m.loss_factor)
        for j, m in enumerate(system.mounts)
    ]
    return System(system.body, mounts, system.rayleigh, system.modal_damping)


# ----------------------------------------------------------------------------------------------------
# Vectorized assembly.
# ----------------------------------------------------------------------------------------------------


@jax.jit
def _assemble(M, positions, stiffness, damping, axes, alpha, beta, zeta):
    """K, C (nv, 6, 6) and eigenvalues omega^2 (nv, 6) of every variant: the model's own assembly
    and damping matrix, vmapped."""
    chol = jnp.linalg.cholesky(M)
    chol_inv = jnp.linalg.inv(chol)

    def one(pos, k, d):
        K = mount_matrix_jax(pos, k, axes)
        Kt = chol_inv @ K @ chol_inv.T
        lam, V = jnp.linalg.eigh(0.5 * (Kt + Kt.T))
        lam = jnp.where(jnp.abs(lam) <= ZERO_MODE_RTOL * jnp.max(jnp.abs(lam)), 0.0, lam)
        shapes = chol_inv.T @ V  # mass-normalized: phi = L^-T V
        omega = jnp.sqrt(jnp.maximum(lam, 0.0))
        C = damping_matrix(M, K, mount_matrix_jax(pos, d, axes), alpha, beta, zeta, shapes, omega)
        return K, C, lam

    return jax.vmap(one)(positions, stiffness, damping)


def variant_matrices(system: System, variants: Variants) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness and damping matrices (nv, 6, 6) and undamped eigenvalues omega^2 (nv, 6) [rad^2/s^2]
    of every variant, in one vectorized call of the model's assembly."""
    zeta = np.broadcast_to(np.asarray(system.modal_damping or 0.0, dtype=float), (6,))
    alpha, beta = (system.rayleigh.alpha, system.rayleigh.beta) if system.rayleigh is not None else (0.0, 0.0)
    K, C, lam = _assemble(
        np.asarray(system.M), system.positions[None] + variants.position_offset,
        system.stiffnesses[None] * variants.stiffness_factor,
        system.dampings[None] * variants.damping_factor, system.axes, alpha, beta, zeta,
    )
    return np.asarray(K), np.asarray(C), np.asarray(lam)


def batch_frequencies(system: System, variants: Variants) -> np.ndarray:
    """Undamped natural frequencies of every variant, shape (nv, 6), ascending [Hz]."""
    _, _, lam = variant_matrices(system, variants)
    return readonly(np.sqrt(lam) / (2.0 * np.pi))


# ----------------------------------------------------------------------------------------------------
# Vectorized time integration.
# ----------------------------------------------------------------------------------------------------


@partial(jax.jit, static_argnames=("solver", "max_steps"))
def _solve_chunk(A, B, x0, sigma, signals, ts, t0, t1, jump_ts, rtol, atol, *, solver, max_steps):
    """Peaks of |q| and |q''| at ``ts`` for a chunk of variants: A (nb, 12, 12), B (nb, 12, nc)."""
    import diffrax

    from sixdof.analysis.direct import solve_ode

    def source(t):
        return jnp.stack([s(t) for s in signals]) if signals else jnp.zeros(0)

    def one(A, B, x0):
        # Scaled state xs = x / sigma: A and B are pre-scaled, so the field is one 12x12 product.
        As = A * sigma[None, :] / sigma[:, None]
        Bs = B / sigma[:, None]

        def field(t, xs, args):
            return As @ xs + Bs @ source(t)

        def keep(t, xs, args):
            rate = (A @ (xs * sigma) + B @ source(t))[6:]
            return jnp.concatenate([xs[:6] * sigma[:6], rate])

        sol = solve_ode(field, x0 / sigma, t0, t1, diffrax.SaveAt(ts=ts, fn=keep), jump_ts, rtol, atol,
                        solver=solver, max_steps=max_steps)
        peaks = jnp.max(jnp.abs(sol.ys), axis=0)
        ok = sol.result == diffrax.RESULTS.successful
        return peaks, ok, sol.stats["num_steps"], sol.stats["num_rejected_steps"]

    return jax.vmap(one)(A, B, x0)


def default_chunk_size(n_samples: int) -> int:
    """Variants per chunk so that the kept samples stay within :data:`CHUNK_BYTES`."""
    return int(max(1, min(MAX_CHUNK, CHUNK_BYTES // (max(n_samples, 1) * 12 * 8))))


def run_batch(system: System, variants: Variants, excitation=None, settings=None, *,
              histories=(), chunk_size: int | None = None) -> BatchResult:
    """Natural frequencies and peak responses of many variants of ``system`` in one vectorized call.

    Parameters
    ----------
    system : System
        The nominal system; :class:`Variants` scale and move its mounts.
    variants : Variants
        From :func:`make_variants` (or :func:`load_sweep_spec`).
    excitation : sixdof.excitation.Excitation, optional
        Loads and an optional :class:`~sixdof.excitation.InitialState` (no ground motion, no mode
        release). Without it (or without ``settings``) only frequencies are computed.
    settings : sixdof.analysis.direct.SimulationSettings, optional
        The same settings as :func:`sixdof.analysis.direct.simulate`.
    histories : sequence of int, optional
        Indices of variants whose full :class:`~sixdof.results.TimeHistory` is wanted (computed
        with :func:`sixdof.analysis.direct.simulate` on :func:`variant_system`).
    chunk_size : int, optional
        Variants integrated together; default :func:`default_chunk_size` (memory bound).

    Returns
    -------
    BatchResult

    Raises
    ------
    InputError
        Unsupported excitation (ground motion, mode release), bad ``histories`` or ``chunk_size``.
    SolverError
        When the solve of any variant fails (its index is named) or gives non-finite values.
    """
    from sixdof.analysis.direct import jump_times, loads_of, simulate, state_scale
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
    start = time.perf_counter()
    K, C, lam = variant_matrices(system, variants)
    frequency = readonly(np.sqrt(lam) / (2.0 * np.pi))
    if excitation is None or settings is None:
        return BatchResult(variants=variants, frequency_hz=frequency, wall_time_s=time.perf_counter() - start)
    vectors, signals = loads_of(excitation, settings)
    if excitation.ground is not None:
        raise InputError("excitation.ground", "no ground motion in a batch (not supported yet; "
                         "use sixdof.analysis.direct.simulate per variant)", Plain("a ground motion"))
    if isinstance(excitation.initial, ModeRelease):
        raise InputError("excitation.initial", "an InitialState in a batch (a mode release depends "
                         "on each variant's modes)", Plain("a ModeRelease"))
    ts = settings.times
    if chunk_size is None:
        chunk_size = default_chunk_size(ts.size)
    chunk_size = min(integer(chunk_size, "chunk_size", "a positive integer", 1), variants.count)

    M = np.asarray(system.M, dtype=float)
    Minv = np.linalg.inv(M)
    nv = variants.count
    A = np.zeros((nv, 12, 12))
    A[:, :6, 6:] = np.eye(6)
    A[:, 6:, :6] = -Minv[None] @ K
    A[:, 6:, 6:] = -Minv[None] @ C
    B = np.zeros((nv, 12, len(signals)))
    B[:, 6:, :] = (Minv @ vectors.T)[None]
    q0, qd0 = excitation.initial_state(system)
    x0 = np.broadcast_to(np.concatenate([q0, qd0]), (nv, 12))
    sigma = state_scale(system, excitation, settings)[:12]
    t0, t1 = settings.start, settings.start + settings.duration
    padded, _ = jump_times(excitation, t0, t1)

    chunks = []
    for first in range(0, nv, chunk_size):
        # The last chunk is padded with copies of the last variant: one compiled shape for all chunks.
        index = np.minimum(np.arange(first, first + chunk_size), nv - 1)
        chunks.append(_solve_chunk(A[index], B[index], x0[index], sigma, signals, ts, t0, t1, padded,
                                   settings.rtol, settings.atol, solver=settings.solver,
                                   max_steps=settings.max_steps))
    peaks, ok, steps, rejected = (np.concatenate([np.asarray(out[k]) for out in chunks])[:nv] for k in range(4))
    if not np.all(ok):
        bad = np.flatnonzero(~ok)
        raise SolverError(f"batch solve with {settings.solver} (rtol={settings.rtol:g}, atol={settings.atol:g}, "
                          f"max_steps={settings.max_steps}) failed for {bad.size} of {nv} variants "
                          f"(first: index {int(bad[0])})")
    if not np.all(np.isfinite(peaks)):
        bad = np.flatnonzero(~np.all(np.isfinite(peaks), axis=1))
        raise SolverError(f"batch solve produced non-finite values for variant {int(bad[0])}")
    kept = {int(i): simulate(variant_system(system, variants, int(i)), excitation, settings)
            for i in histories}
    return BatchResult(variants=variants, frequency_hz=frequency, peak_q=readonly(peaks[:, :6]),
                       peak_qdd=readonly(peaks[:, 6:]), num_steps=readonly(steps, int),
                       num_rejected=readonly(rejected, int), histories=kept, settings=settings,
                       chunk_size=chunk_size, wall_time_s=time.perf_counter() - start)
