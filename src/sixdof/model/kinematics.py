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


def mount_local_map(positions, axes) -> np.ndarray:
    """Map from ``q`` to each mount's deformation along its own axes, shape (n, 3, 6).

    Parameters
    ----------
    positions : array_like, shape (n, 3)
        Mount points from the CG in body axes [m].
    axes : array_like, shape (n, 3, 3)
        Rows are each mount's axes in body axes.
    """
    return np.einsum("nij,njk->nik", np.asarray(axes, dtype=float), point_map(positions))


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
