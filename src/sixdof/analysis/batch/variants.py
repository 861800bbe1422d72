"""The variants of a batch and their vectorized assembly: M, K, C, natural frequencies and tracked modes."""

from __future__ import annotations

import dataclasses
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from sixdof._jax import jax, jnp
from sixdof.analysis.modal import pair_by_similarity, repeated_groups
from sixdof.analysis.statics import replace_with_preload
from sixdof.errors import InputError, Plain, integer, readonly
from sixdof.model.damping import damping_matrix
from sixdof.model.kinematics import mount_local_map, mount_matrix_jax, stiffness_jax
from sixdof.model.modes import ZERO_MODE_RTOL
from sixdof.model.parts import Branches
from sixdof.model.system import System
from sixdof.results import quantity


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


def check_batchable(system: System) -> None:
    """Raise an :class:`InputError` naming the mounts unless the batch engines can run variants of ``system``:
    not with nonlinear mounts (Maxwell branches are carried)."""
    if system.nonlinear_axes:
        raise InputError("mounts", "linear mounts (sweeps and batches of mounts with bump stops, lift-off or "
                         "force-deflection tables or hysteretic bearings are not supported yet)",
                         Plain(f"nonlinear mount axes {', '.join(system.nonlinear_axes)}"))


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


def decoupling_percent(system: System, shapes) -> np.ndarray:
    """Each variant's decoupling of each mode, shape (nv, 6) [%]: the kinetic-energy share of its dominant DOF,
    ``100 max_d phi_d (M phi)_d`` of the mass-normalized shapes (nv, 6, 6) (the shares of a mode sum to 1), as
    :func:`sixdof.analysis.design.design_metrics` defines it for one system."""
    shapes = np.asarray(shapes)
    shares = shapes * np.einsum("de,vej->vdj", np.asarray(system.M), shapes)
    return 100.0 * shares.max(axis=1)


def track_modes(system: System, frequency_hz, shapes,
                decoupling=None) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
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
    decoupling : ndarray, shape (nv, 6), optional
        Their decoupling [%] (:func:`decoupling_percent`), in the order of ``frequency_hz``.

    Returns
    -------
    tracked_frequency_hz, tracked_mac : ndarray, shape (nv, 6)
        ``[v, j]``: the frequency [Hz] of variant v's mode paired with nominal mode j, and their MAC.
    tracked_decoupling_percent : ndarray, shape (nv, 6), or None
        ``[v, j]``: that mode's decoupling [%]; ``None`` without ``decoupling``.
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
    shares = None if decoupling is None else readonly(np.where(found, np.asarray(decoupling)[rows, paired], np.nan))
    return readonly(frequency), readonly(np.where(found, mac[rows, np.arange(6), paired], np.nan)), shares


def batch_frequencies(system: System, variants: Variants) -> np.ndarray:
    """Undamped natural frequencies of every variant, shape (nv, 6), ascending [Hz]."""
    _, _, lam = variant_matrices(system, variants)
    return readonly(np.sqrt(lam) / (2.0 * np.pi))
