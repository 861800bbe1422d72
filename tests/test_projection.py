"""Measured point motions projected onto the six body DOFs (sixdof.validation.projection): a rigid motion
is recovered to round-off, a flexible pattern leaves its closed-form residual, and too few or collinear
nodes are refused."""

import numpy as np
import pytest

from sixdof import InputError
from sixdof.model.kinematics import response_row
from sixdof.validation import project_to_body
from tolerances import ATOL_PROJECTION_ROUNDOFF

#: Four nodes of a machine frame, not coplanar [m].
NODES = {11: [0.4, 0.3, -0.2], 12: [-0.4, 0.3, -0.2], 13: [-0.4, -0.3, 0.1], 14: [0.5, -0.3, -0.2]}


def triaxial(nodes=NODES):
    """Rows, node numbers and positions of a triaxial accelerometer (x, y, z) on every node."""
    numbers = np.repeat(list(nodes), 3)
    positions = np.repeat(np.array(list(nodes.values())), 3, axis=0)
    rows = np.array([response_row(p, np.eye(3)[k % 3], False) for k, p in enumerate(positions)])
    return rows, numbers, positions


def test_rigid_motion_projects_exactly():
    rows, numbers, positions = triaxial()
    rng = np.random.default_rng(0)
    q0 = rng.standard_normal((6, 2, 3)) + 1j * rng.standard_normal((6, 2, 3))  # e.g. 2 bins x 3 references
    p = project_to_body(np.einsum("cd,d...->c...", rows, q0), rows, numbers, positions, unit="m")
    assert p.column_shape == (2, 3)
    np.testing.assert_allclose(p.unflatten(p.q), q0, rtol=0, atol=ATOL_PROJECTION_ROUNDOFF)
    assert np.max(p.residual) <= ATOL_PROJECTION_ROUNDOFF
    assert np.max(p.node_residual) <= ATOL_PROJECTION_ROUNDOFF
    np.testing.assert_array_equal(p.node, [11, 12, 13, 14])


def test_a_flexible_pattern_leaves_its_closed_form_residual():
    rows, numbers, positions = triaxial()
    rng = np.random.default_rng(1)
    q0 = rng.standard_normal((6, 4))
    # A pattern no rigid motion makes: anything orthogonal to the range of the rows.
    flexible = rng.standard_normal((12, 4))
    flexible -= rows @ np.linalg.lstsq(rows, flexible, rcond=None)[0]
    motion = rows @ q0 + flexible
    p = project_to_body(motion, rows, numbers, positions)
    total = np.sqrt(np.sum((rows @ q0) ** 2, axis=0) + np.sum(flexible**2, axis=0))  # Pythagoras
    np.testing.assert_allclose(p.q, q0, rtol=0, atol=ATOL_PROJECTION_ROUNDOFF)
    np.testing.assert_allclose(p.residual, np.linalg.norm(flexible, axis=0) / total, rtol=1e-12)
    per_node = np.linalg.norm(flexible.reshape(4, 3, 4), axis=1) / total
    np.testing.assert_allclose(p.node_residual, per_node, rtol=1e-12)
    # A channel's share is a difference of unit-sized motions over their norm: round-off is absolute there, a few
    # ulps of 1 (1.3e-16 on a share of 1.3e-4 seen with one BLAS), not relative to a small share.
    np.testing.assert_allclose(p.channel_residual, np.abs(flexible) / total, rtol=1e-12,
                               atol=ATOL_PROJECTION_ROUNDOFF)
    np.testing.assert_allclose(np.sum(p.node_residual**2, axis=0), p.residual**2, rtol=1e-12)


def test_too_few_channels_collinear_nodes_and_unobserved_dofs_are_refused():
    rows, numbers, positions = triaxial()
    with pytest.raises(InputError, match=r"^rows: expected at least 6 channels to determine 6 DOFs, got 5 channels"):
        project_to_body(np.ones(5), rows[:5], numbers[:5], positions[:5])
    line = {1: [0.0, 0.0, 0.0], 2: [0.5, 0.0, 0.0], 3: [1.5, 0.0, 0.0]}
    r, n, p = triaxial(line)
    with pytest.raises(InputError, match=r"^nodes: expected at least 3 non-collinear nodes \(the rotation about "
                                         r"their line is not observed\), got nodes \[1, 2, 3\] on one line"):
        project_to_body(np.ones(9), r, n, p)
    with pytest.raises(InputError, match=r"^nodes: expected at least 3 non-collinear nodes, got 2 node\(s\): "
                                         r"\[11, 12\]"):
        project_to_body(np.ones(6), rows[:6], numbers[:6], positions[:6])
    # Only vertical channels: the plane's own motions (x, y, rz) are not seen.
    vertical = rows[2::3]
    z_only = np.vstack([vertical, vertical])
    with pytest.raises(InputError, match=r"^rows: expected channels that observe all 6 DOFs, got rank 3: no channel "
                                         r"sees x, y, rz \(or a combination of them\)"):
        project_to_body(np.ones(8), z_only, np.tile(numbers[2::3], 2), np.tile(positions[2::3].T, 2).T)
    moved = positions.copy()
    moved[1, 0] += 0.01
    with pytest.raises(InputError, match=r"^positions: expected one position per node \(node 11 has channels "
                                         r"0.01 m apart\)"):
        project_to_body(np.ones(12), rows, numbers, moved)
    with pytest.raises(InputError, match=r"^motion: expected an array of shape \(12, ...\)"):
        project_to_body(np.ones(11), rows, numbers, positions)
