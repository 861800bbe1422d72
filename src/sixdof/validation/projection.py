"""Measured point motions projected onto the six rigid-body DOFs, and what the projection leaves over.

A channel measuring the motion of a body point ``p`` along a unit vector ``d`` sees ``d . (t + theta x p)
= [d, p x d] . q``: its row of the point map (:func:`sixdof.model.kinematics.response_row`). With rows
``R`` (n_channels, 6) of rank 6, the least-squares DOFs of a measured column ``m`` (a mode shape, an FRF
bin) are ``q = pinv(R) m``, and the residual ``m - R q`` is the part of the motion no rigid body makes:
a body that flexes in the band shows there, per column and per node.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.dofs import DOFS, MixedUnits, mixed_units
from sixdof.errors import InputError, Plain, readonly
from sixdof.results import Result, label, quantity, result_type

__all__ = ["BodyProjection", "project_to_body"]

#: Nodes whose spread about their centroid has a second singular value below this share of the first lie on
#: one line (within round-off of coordinates given to micrometres on metre-sized bodies).
COLLINEAR_SHARE = 1e-6
#: ``rows`` counts as rank-deficient where its smallest singular value is below this share of its largest.
RANK_SHARE = 1e-9


def _dof_units(unit: str) -> MixedUnits:
    """Units of the projected DOFs of a motion measured in ``unit``: translations in it, rotations per metre."""
    rotation = "rad" if unit == "m" else f"({unit})/m"
    return MixedUnits((("dof", (unit,) * 3 + (rotation,) * 3),), mixed_units(unit, rotation))


@result_type
@dataclass(frozen=True, eq=False)
class BodyProjection(Result):
    """Measured motions as six body DOFs, with the residual of the fit (from :func:`project_to_body`).

    The measured array's trailing axes (modes, or frequencies and references) are flattened, in C order,
    into one axis ``column``; ``column_shape`` is their shape and :meth:`unflatten` gives it back.

    Attributes
    ----------
    q : ndarray, shape (6, n_columns)
        Least-squares DOFs ``pinv(rows) motion`` (x, y, z in the motion's unit, rx, ry, rz in it per metre).
    residual : ndarray, shape (n_columns,)
        ``||motion - rows q|| / ||motion||`` over all channels, per column (0 for a rigid motion; 0 where a
        column is zero).
    node_residual : ndarray, shape (n_nodes, n_columns)
        The residual's norm over each node's channels, over the same ``||motion||``: their squares sum to
        ``residual**2``.
    channel_residual : ndarray, shape (n_channels, n_columns)
        ``|motion - rows q|`` per channel over the same ``||motion||``.
    node : ndarray, shape (n_nodes,), int
        The node numbers of ``node_residual``, ascending.
    column_shape : tuple of int
        Shape of the measured array's trailing axes.
    unit : str
        Unit of the measured motion.
    """

    node: np.ndarray = quantity("1", ("node",), description="node numbers")
    q: np.ndarray = quantity(lambda p: _dof_units(p.unit), ("dof", "column"),
                             description="least-squares rigid-body DOFs of the measured motion")
    residual: np.ndarray = quantity("1", ("column",), description="relative norm of the motion no rigid body makes")
    node_residual: np.ndarray = quantity("1", ("node", "column"), description="residual per node")
    channel_residual: np.ndarray = quantity("1", ("channel", "column"), description="residual per channel")
    column_shape: tuple = label(encode=lambda s: np.asarray(s, dtype=int), decode=lambda a: tuple(int(v) for v in a))
    unit: str = label(name="motion_unit", default="1")

    def unflatten(self, array) -> np.ndarray:
        """``array`` with its last axis (``column``) back in the measured array's trailing shape."""
        array = np.asarray(array)
        return array.reshape(array.shape[:-1] + tuple(self.column_shape))


def _unobserved(rows: np.ndarray) -> str | None:
    """The DOFs no channel sees (text), or None when ``rows`` has rank 6: those with a component in its null
    space (a null motion mixing several DOFs names all of them)."""
    _, s, vt = np.linalg.svd(rows)
    s = np.concatenate([s, np.zeros(6 - s.size)])
    null = vt[s <= RANK_SHARE * s[0]] if s[0] > 0 else np.eye(6)
    if null.size == 0:
        return None
    share = np.linalg.norm(null, axis=0)
    unseen = [d for d, v in zip(DOFS, share) if v > 1e-6]
    return f"rank {6 - len(null)}: no channel sees {', '.join(unseen)} (or a combination of them)"


def project_to_body(motion, rows, nodes, positions, unit: str = "1") -> BodyProjection:
    """Least-squares projection of measured point motions onto the six body DOFs.

    Parameters
    ----------
    motion : array_like, shape (n_channels, ...), real or complex
        The measured motion per channel (mode shapes: (n_channels, n_modes); FRFs: (n_channels, nf, n_ref)).
    rows : array_like, shape (n_channels, 6)
        Each channel's row of the point map: its motion per unit ``q`` (:meth:`TestData.response_rows`).
    nodes : array_like, shape (n_channels,), int
        The node each channel sits on.
    positions : array_like, shape (n_channels, 3)
        That node's position from the centre of gravity in body axes [m].
    unit : str
        Unit of ``motion``, kept with the result.

    Returns
    -------
    BodyProjection

    Raises
    ------
    InputError
        Fewer than 6 channels, fewer than 3 nodes or nodes on one line, a node given two positions, shapes
        that do not match, non-finite values, or rows of rank below 6 (naming the DOFs not observed).
    """
    R = np.asarray(rows, dtype=float)
    if R.ndim != 2 or R.shape[1] != 6:
        raise InputError("rows", "an array of shape (n_channels, 6)", Plain(f"shape {R.shape}"))
    n = R.shape[0]
    m = np.asarray(motion)
    if m.ndim < 1 or m.shape[0] != n:
        raise InputError("motion", f"an array of shape ({n}, ...): one row per channel", Plain(f"shape {m.shape}"))
    node = np.asarray(nodes)
    p = np.asarray(positions, dtype=float)
    if node.shape != (n,) or not np.issubdtype(node.dtype, np.integer):
        raise InputError("nodes", f"{n} integer node numbers", Plain(f"shape {node.shape}, dtype {node.dtype}"))
    if p.shape != (n, 3):
        raise InputError("positions", f"an array of shape ({n}, 3) [m]", Plain(f"shape {p.shape}"))
    for name, array in (("motion", m), ("rows", R), ("positions", p)):
        if not np.all(np.isfinite(array)):
            raise InputError(name, "finite values", Plain(f"{np.count_nonzero(~np.isfinite(array))} NaN or infinite"))
    if n < 6:
        raise InputError("rows", "at least 6 channels to determine 6 DOFs", Plain(f"{n} channels"))
    unique, first = np.unique(node, return_index=True)
    for k, number in enumerate(unique):
        spread = np.max(np.abs(p[node == number] - p[first[k]]))
        if spread > 1e-9 * max(1.0, float(np.max(np.abs(p)))):
            raise InputError("positions", f"one position per node (node {number} has channels {spread:.3g} m apart)",
                             p[node == number])
    if unique.size < 3:
        raise InputError("nodes", "at least 3 non-collinear nodes", Plain(f"{unique.size} node(s): {unique.tolist()}"))
    points = p[first]
    s = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    if s[1] <= COLLINEAR_SHARE * s[0] or s[0] == 0:
        raise InputError("nodes", "at least 3 non-collinear nodes (the rotation about their line is not observed)",
                         Plain(f"nodes {unique.tolist()} on one line"))
    deficient = _unobserved(R)
    if deficient:
        raise InputError("rows", "channels that observe all 6 DOFs", Plain(deficient))
    columns = m.reshape(n, -1)
    q = np.linalg.pinv(R) @ columns
    left = columns - R @ q
    total = np.linalg.norm(columns, axis=0)
    scale = np.where(total > 0, total, 1.0)
    channel = np.abs(left) / scale
    per_node = np.stack([np.sqrt(np.sum(channel[node == number] ** 2, axis=0)) for number in unique])
    dtype = complex if np.iscomplexobj(q) else float
    return BodyProjection(q=readonly(q, dtype), residual=readonly(np.linalg.norm(left, axis=0) / scale),
                          node_residual=readonly(per_node), channel_residual=readonly(channel),
                          node=readonly(unique, int), column_shape=tuple(int(v) for v in m.shape[1:]), unit=unit)
