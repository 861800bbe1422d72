"""Rigid-body kinematics of small motions: the one home of the point map and its transpose.

A body point ``p`` (from the centre of gravity, body axes) moves by ``u_p = u_cg + theta x p`` for
``q = [u_cg, theta]``: ``u_p = T(p) q`` with ``T(p) = [I, -skew(p)]`` (:func:`point_map`). The same map
takes velocities and accelerations. Its transpose turns a force ``F`` at ``p`` plus a moment ``M`` into
the generalized force ``Q = T(p)' F + [0, M] = [F, p x F + M]`` (virtual work, :func:`generalized_force`).
A mount's deformation along its own axes (rows of ``A``) is ``A T(p) q`` (:func:`mount_local_map`), and
a triaxial mount element assembles as ``(A T)' diag(c) (A T)`` (:func:`mount_matrix`).

Each map has a NumPy version, which the model's assembly and every result use (6x6 arrays: no JAX
dispatch, no compilation), and JAX twins for the vectorized batches and gradients under ``jit``,
``vmap`` and ``grad`` (:func:`point_map_jax`, :func:`mount_matrix_jax`), side by side so that they stay
the same formula. The twins import JAX when first called: assembling a model never loads it.
"""

from __future__ import annotations

import numpy as np


def point_map(position) -> np.ndarray:
    """Map from ``q`` to the displacement of body points: ``u = point_map(p) @ q``.

    Parameters
    ----------
    position : array_like, shape (..., 3)
        Points from the CG in body axes [m].

    Returns
    -------
    ndarray, shape (..., 3, 6)
        ``[I, -skew(p)]`` (dimensionless in its translation block, m in its rotation block).
    """
    p = np.asarray(position, dtype=float)
    eye = np.broadcast_to(np.eye(3), p.shape[:-1] + (3, 3))
    return np.concatenate([eye, np.cross(p[..., None, :], eye)], axis=-1)  # row j of -skew(p) is p x e_j


def generalized_force(point, force, moment=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Generalized force (6,) [N, N m] of a force [N] at ``point`` [m] plus a moment [N m]:
    ``[F, p x F + M]``, the transpose of :func:`point_map`."""
    force = np.asarray(force, dtype=float)
    return np.concatenate([force, np.cross(np.asarray(point, dtype=float), force) + np.asarray(moment, float)])


def unit_load(point, direction, moment: bool) -> np.ndarray:
    """Generalized force (6,) of a unit force at ``point`` along ``direction`` (unit vector), or of a
    unit moment about ``direction`` when ``moment``."""
    direction = np.asarray(direction, dtype=float)
    if moment:
        return np.concatenate([np.zeros(3), direction])
    return generalized_force(point, direction)


def response_row(point, direction, rotation: bool) -> np.ndarray:
    """Row (6,) taking ``q`` to the motion of ``point`` along ``direction`` (unit vector), or to the
    body's rotation about ``direction`` when ``rotation`` (the same at every point)."""
    direction = np.asarray(direction, dtype=float)
    if rotation:
        return np.concatenate([np.zeros(3), direction])
    return direction @ point_map(point)


def rigid_translation(direction) -> np.ndarray:
    """The influence vector ``r`` (6,) of a rigid translation of the ground along ``direction`` (3,): the
    generalized coordinates that follow a unit translation, ``[d, 0, 0, 0]`` (no rotation; every point of the body
    moves by ``d``). How ground motion enters the equations, ``M q_rel'' + C q_rel' + K q_rel = -M r u_g''``."""
    return np.concatenate([np.asarray(direction, dtype=float), np.zeros(3)])


def mount_local_map(positions, axes) -> np.ndarray:
    """Map from ``q`` to each mount's deformation along its own axes, shape (..., n, 3, 6).

    Parameters
    ----------
    positions : array_like, shape (..., n, 3)
        Mount points from the CG in body axes [m] (leading dimensions: variants of them).
    axes : array_like, shape (n, 3, 3)
        Rows are each mount's axes in body axes.
    """
    return np.einsum("nij,...njk->...nik", np.asarray(axes, dtype=float), point_map(positions))


def mount_matrix(positions, coefficients, axes) -> np.ndarray:
    """NumPy twin of :func:`mount_matrix_jax`: ``sum_n (A T)' diag(c) (A T)``, shape (6, 6).

    ``coefficients`` (n, 3) may be complex (a hysteretic stiffness ``k eta``).
    """
    local = mount_local_map(positions, axes)
    matrix = np.einsum("nia,ni,nib->ab", local, np.asarray(coefficients), local)
    return 0.5 * (matrix + matrix.T)


def point_map_jax(r):
    """:func:`point_map` in ``jax.numpy``: ``[I, -skew(r)]``, shape (..., 3, 6)."""
    from sixdof._jax import jnp

    r = jnp.asarray(r, dtype=float)
    eye = jnp.broadcast_to(jnp.eye(3), r.shape[:-1] + (3, 3))
    return jnp.concatenate([eye, jnp.cross(r[..., None, :], eye)], axis=-1)


def mount_matrix_jax(positions, coefficients, axes):
    """Assemble a 6x6 matrix from triaxial mount elements (eqs. 7-10 of the seed paper, generalized).

    A mount's tensor in body axes is ``A.T diag(c) A`` and its contribution ``T.T A.T diag(c) A T``
    with ``T = point_map(position)``.

    Parameters
    ----------
    positions : array_like, shape (n, 3)
        Mount points from the CG in body axes [m].
    coefficients : array_like, shape (n, 3)
        Coefficients along each mount's own axes: stiffness [N/m] for K, viscous damping [N s/m] for C.
    axes : array_like, shape (n, 3, 3)
        Rows are each mount's axes in body axes (orthonormal).

    Returns
    -------
    jax.Array, shape (6, 6)
        Symmetric matrix; for diagonal axes it reproduces eqs. (7)-(10) term by term.
    """
    from sixdof._jax import jnp

    local = jnp.einsum("nij,njk->nik", jnp.asarray(axes, dtype=float), point_map_jax(positions))  # (n, 3, 6)
    return jnp.einsum("nia,ni,nib->ab", local, jnp.asarray(coefficients, dtype=float), local)


def geometric_stiffness(positions, forces) -> np.ndarray:
    """Gravity's geometric stiffness: the stiffness (6, 6) [N m/rad] of static forces on the body whose points of
    application turn with it.

    A force ``F`` held fixed in space at the body point ``r`` has the moment ``(R r) x F`` about the CG once the
    body turns by ``theta`` (``R r = r + theta x r``): its change, ``(theta x r) x F = -[(F . r) I - r F'] theta``,
    is a stiffness on the rotations

        K_G = sum_j [(F_j . r_j) I - r_j F_j']

    for mounts as zero-length springs (their force follows their deflection, not their direction) and gravity as
    a dead load at the CG (no moment about it, however the body turns). At static equilibrium ``sum_j r_j x F_j
    = 0``, which makes ``sum_j r_j F_j'`` (so ``K_G``) symmetric; the symmetric part is returned. Mounts below the
    CG carrying the weight upward give ``(F . r) < 0``: they lower the rocking stiffness (``-W h`` for mounts a
    height ``h`` below the CG), mounts above it raise it (a pendulum).

    Parameters
    ----------
    positions : array_like, shape (n, 3)
        Points of application from the CG in body axes [m].
    forces : array_like, shape (n, 3)
        Static force on the body at each point, body axes [N] (the mounts' preload under gravity:
        minus :attr:`sixdof.analysis.statics.Statics.mount_forces`).

    Returns
    -------
    ndarray, shape (6, 6)
        Zero but for the rotation block.
    """
    r, f = np.asarray(positions, dtype=float), np.asarray(forces, dtype=float)
    block = np.einsum("ni,ni->", f, r) * np.eye(3) - np.einsum("ni,nj->ij", r, f)
    out = np.zeros((6, 6))
    out[3:, 3:] = 0.5 * (block + block.T)
    return out


def geometric_stiffness_jax(positions, forces):
    """:func:`geometric_stiffness` in ``jax.numpy``, shape (6, 6)."""
    from sixdof._jax import jnp

    r, f = jnp.asarray(positions, dtype=float), jnp.asarray(forces, dtype=float)
    block = jnp.einsum("ni,ni->", f, r) * jnp.eye(3) - jnp.einsum("ni,nj->ij", r, f)
    return jnp.zeros((6, 6)).at[3:, 3:].set(0.5 * (block + block.T))


#: Eigenvalues of the stiffness scaled to unit diagonal below this fraction of the largest are a mechanism in the
#: JAX statics of :func:`stiffness_jax` (the NumPy statics' ``MECHANISM_RTOL``).
_MECHANISM_RTOL = 1e-12


def stiffness_jax(positions, stiffnesses, axes, weight):
    """The stiffness matrix (6, 6) of linear mounts with gravity's geometric stiffness of their preload, in JAX:
    the one assembly of K that the batches, sweeps, sensitivities and the design optimizer trace (``jit``,
    ``vmap``, ``grad`` through the statics).

    The statics ``K_m q = [W, 0]`` (weight at the CG, ``K_m`` the mounts' :func:`mount_matrix_jax`) give each
    mount's force on the body ``-A' diag(k) A T q``, and those :func:`geometric_stiffness_jax`. The solve is the
    pseudo-inverse of ``K_m`` scaled to unit diagonal: a motion no mount resists (and gravity does not drive)
    gets no deflection, as in :func:`sixdof.analysis.statics.solve_stiffness`.

    Parameters
    ----------
    positions, stiffnesses, axes
        As :func:`mount_matrix_jax` (``stiffnesses`` [N/m]).
    weight : array_like, shape (3,), or None
        The body's weight ``m g`` in body axes [N]; None: the mounts' stiffness alone (no preload, and no statics
        traced: the batches' hot path without the option).

    Returns
    -------
    jax.Array, shape (6, 6)
        ``K_m + K_G`` [N/m, N, N m/rad].
    """
    from sixdof._jax import jnp

    local = jnp.einsum("nij,njk->nik", jnp.asarray(axes, dtype=float), point_map_jax(positions))  # (n, 3, 6)
    k = jnp.asarray(stiffnesses, dtype=float)
    K = jnp.einsum("nia,ni,nib->ab", local, k, local)
    if weight is None:
        return K
    diagonal = jnp.diagonal(K)
    scale = jnp.where(diagonal > 0, 1.0 / jnp.sqrt(jnp.where(diagonal > 0, diagonal, 1.0)), 1.0)
    load = jnp.concatenate([jnp.asarray(weight, dtype=float), jnp.zeros(3)])
    q = scale * (jnp.linalg.pinv(scale[:, None] * K * scale[None, :], rtol=_MECHANISM_RTOL, hermitian=True)
                 @ (scale * load))
    forces = -jnp.einsum("nji,nj->ni", jnp.asarray(axes, dtype=float), k * (local @ q))
    return K + geometric_stiffness_jax(positions, forces)
