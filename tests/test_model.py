"""Assembly of M and K against closed forms and invariants (issue 2)."""

import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from references import (
    bounce_pitch_eigenvalues,
    lever_rule_supports,
    rayleigh_ratio,
    state_matrices,
    symmetric_four_mount_eigenvalues,
)
from sixdof import InputError, Mount, Rayleigh, RigidBody, System, gravity_statics, modal_analysis
from sixdof._jax import jax, jnp
from sixdof.analysis.statespace import damping_ratios, modal_damping_ratios
from sixdof.model.kinematics import generalized_force, mount_matrix_jax, point_map
from systems import four_mount, heavily_damped_box
from tolerances import (
    RTOL_COMPLEX_DAMPING_RATIO,
    RTOL_DAMPING_RATIO,
    RTOL_FREQUENCY,
    RTOL_ILL_CONDITIONED_STATICS,
    RTOL_LINALG,
    RTOL_STATICS,
    RTOL_ZERO_ENTRY,
)


def test_symmetric_four_mount_layout_closed_forms():
    layout = 500.0, (40.0, 60.0, 80.0), 0.4, 0.6, 0.3, (2e5, 3e5, 8e5)  # m, J, a, b, h, k
    system = four_mount(*layout)
    modes = modal_analysis(system.M, system.K)
    assert modes.eigenvalues == pytest.approx(symmetric_four_mount_eigenvalues(*layout), rel=RTOL_FREQUENCY)
    assert modes.subsystems == (("x", "ry"), ("y", "rx"), ("z",), ("rz",))


def test_two_spring_bounce_pitch_and_free_dofs():
    # Vertical springs k1 at y = -l1 and k2 at y = l2: the classic bounce-pitch pair; every other DOF
    # is unrestrained and must come out as a zero-frequency mode, named, not as an error.
    m, J, k1, k2, l1, l2 = 1200.0, 1800.0, 3e4, 4e4, 1.2, 1.5
    mounts = [Mount("front", [0, -l1, 0], [0, 0, k1]), Mount("rear", [0, l2, 0], [0, 0, k2])]
    system = System(RigidBody(m, [J, J, 2 * J]), mounts)
    modes = modal_analysis(system.M, system.K)
    assert modes.zero_modes == (0, 1, 2, 3)
    assert np.all(modes.frequency_hz[:4] == 0.0)
    assert modes.eigenvalues[4:] == pytest.approx(bounce_pitch_eigenvalues(m, J, k1, k2, l1, l2), rel=RTOL_FREQUENCY)
    assert set(modes.free_dofs) == {"x", "y", "ry", "rz"}


def bounce_pitch_stiffness(x_share: float):
    """The two-spring bounce-pitch system's M, K and largest eigenvalue [rad^2/s^2], with K[x, x] set so that x,
    free, has ``x_share`` times that largest eigenvalue as its own."""
    mounts = [Mount("front", [0, -1.2, 0], [0, 0, 3e4]), Mount("rear", [0, 1.5, 0], [0, 0, 4e4])]
    system = System(RigidBody(1200.0, [1800.0, 1800.0, 3600.0]), mounts)
    largest = modal_analysis(system.M, system.K).eigenvalues[-1]
    K = np.array(system.K)
    K[0, 0] = x_share * largest * system.M[0, 0]
    return system.M, K, largest


def test_round_off_negative_eigenvalues_of_free_dofs_are_zero_modes():
    # A free-free system's zero eigenvalues come out of the solve with either sign, ~1e-12 of the largest.
    M, K, _ = bounce_pitch_stiffness(-1e-12)
    modes = modal_analysis(M, K)
    assert modes.zero_modes == (0, 1, 2, 3)
    assert np.all(modes.frequency_hz[:4] == 0.0) and "x" in modes.free_dofs


def test_a_stiffness_matrix_that_is_not_positive_semidefinite_is_named():
    with pytest.raises(InputError, match=r"^K: expected a symmetric positive semi-definite stiffness matrix: "
                                         r"eigenvalues lambda of K v = lambda M v >= -1e-10 times the largest "
                                         r"\|lambda\| \(round-off of zero\), got lambda = -1 rad\^2/s\^2, the largest "
                                         r"\|lambda\| being 1$"):
        modal_analysis(np.eye(6), -np.eye(6))
    # Beyond round-off: a negative eigenvalue a millionth of the largest is a sign mistake, not a zero.
    M, K, largest = bounce_pitch_stiffness(-1e-6)
    with pytest.raises(InputError, match=rf"^K: .* got lambda = {-1e-6 * largest:.6g} rad\^2/s\^2, the largest "
                                         rf"\|lambda\| being {largest:.6g}$"):
        modal_analysis(M, K)


@pytest.mark.parametrize(("M", "K", "match"), [
    (np.eye(3), np.eye(3), r"^M: expected a symmetric positive definite \(6, 6\) mass matrix in kg, kg m\^2, got an "
                           r"array of shape \(3, 3\)$"),
    (np.eye(6), np.eye(3), r"^K: expected a symmetric positive semi-definite \(6, 6\) stiffness matrix in N/m, N, "
                           r"N m/rad, got an array of shape \(3, 3\)$"),
    (np.eye(6), np.ones(6), r"^K: .* got an array of shape \(6,\)$"),
    (np.eye(6), "K", r"^K: .* got 'K'$"),
    (np.eye(6), np.diag([1.0, 1.0, np.nan, 1.0, 1.0, 1.0]), r"^K: .* got K\[2, 2\] = nan$"),
    (np.eye(6), np.triu(np.ones((6, 6))), r"^K: expected a symmetric .* got K\[0, 1\] = 1 and K\[1, 0\] = 0$"),
    (-np.eye(6), np.eye(6), r"^M: expected a symmetric positive definite .* got eigenvalues \[-1.0, "),
])
def test_modal_analysis_names_a_matrix_it_cannot_take(M, K, match):
    with pytest.raises(InputError, match=match):
        modal_analysis(M, K)


@pytest.mark.parametrize("seed", range(5))
def test_modes_are_scipys_generalized_eigenpairs(seed):
    """modal_analysis reduces K v = l M v by M's Cholesky factor in NumPy: the eigenpairs of scipy.linalg.eigh(K, M),
    for a full inertia tensor (M's rotational block coupled, kg beside kg m^2) and stiffnesses over two decades."""
    import scipy.linalg

    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=rng).as_matrix()
    body = RigidBody(rng.uniform(100, 10_000), R @ np.diag(rng.uniform(100.0, 190.0, 3)) @ R.T)  # J1 + J2 > J3
    mounts = [Mount(str(i), rng.uniform(-2, 2, 3), rng.uniform(1e4, 1e6, 3)) for i in range(4)]
    system = System(body, mounts)
    modes = modal_analysis(system.M, system.K)
    eigenvalues, shapes = scipy.linalg.eigh(system.K, system.M)
    np.testing.assert_allclose(modes.eigenvalues, eigenvalues, rtol=1e-12)
    signs = np.sign(np.sum(shapes * modes.shapes, axis=0))  # the sign of a shape is a convention
    np.testing.assert_allclose(modes.shapes, shapes * signs, rtol=0.0, atol=1e-10 * np.abs(shapes).max())
    np.testing.assert_allclose(modes.shapes.T @ system.M @ modes.shapes, np.eye(6), rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("seed", range(5))
def test_stiffness_symmetric_positive_semidefinite_and_rotation_invariant(seed):
    rng = np.random.default_rng(seed)
    J, R = rng.uniform(1.0, 3.0, 3), Rotation.random(random_state=rng).as_matrix()
    mounts = [Mount(str(i), rng.uniform(-1, 1, 3), rng.uniform(1e4, 1e6, 3), damping=rng.uniform(0, 1e3, 3),
                    axes=Rotation.random(random_state=rng).as_matrix()) for i in range(4)]
    system = System(RigidBody(rng.uniform(10, 100), R @ np.diag(J) @ R.T), mounts)
    K = system.K
    scale = np.abs(K).max()
    assert np.allclose(K, K.T, rtol=0, atol=RTOL_ZERO_ENTRY * scale)
    assert np.linalg.eigvalsh(K).min() >= -1e-12 * scale
    # Rotate the whole layout: inertia tensor, mount positions and mount axes.
    R = Rotation.random(random_state=rng).as_matrix()
    rotated = System(RigidBody(system.body.mass, R @ system.body.inertia @ R.T),
                     [Mount(m.name, R @ m.position, m.stiffness, axes=m.axes @ R.T) for m in system.mounts])
    f0 = modal_analysis(system.M, system.K).frequency_hz
    f1 = modal_analysis(rotated.M, rotated.K).frequency_hz
    assert f1 == pytest.approx(f0, rel=1e-9)


def test_rotated_mount_equals_its_stiffness_tensor():
    rng = np.random.default_rng(7)
    A = Rotation.random(random_state=rng).as_matrix()
    k, r = np.array([1e5, 3e5, 9e5]), np.array([0.3, -0.2, 0.5])
    tensor = A.T @ np.diag(k) @ A  # stiffness in body axes
    T = np.hstack([np.eye(3), -np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])])
    expected = T.T @ tensor @ T
    K = np.asarray(mount_matrix_jax(r[None], k[None], A[None]))
    assert np.allclose(K, expected, rtol=0, atol=RTOL_LINALG * np.abs(expected).max())


def test_kinematics_and_virtual_work():
    # u_point = T q with T = [I, -skew(r)]; a force F at r gives Q = T' F (virtual work).
    rng = np.random.default_rng(3)
    r, q, F, Mo = rng.normal(size=3), rng.normal(size=6), rng.normal(size=3), rng.normal(size=3)
    u = np.asarray(point_map(r)) @ q
    assert u == pytest.approx(q[:3] + np.cross(q[3:], r), rel=RTOL_LINALG)
    Q = np.asarray(generalized_force(r, F, Mo))
    assert Q @ q == pytest.approx(F @ u + Mo @ q[3:], rel=RTOL_LINALG)


def test_plane_of_symmetry_gives_the_papers_block_structure():
    # Mirror-symmetric in x (pairs at +-x with equal stiffness), unequal ends in y: eqs. (11)-(12).
    system = System(
        RigidBody(900.0, [120.0, 30.0, 140.0]),
        [
            Mount("1", [-0.3, -1.0, -0.4], [1e5, 2e5, 6e5]),
            Mount("2", [0.3, -1.0, -0.4], [1e5, 2e5, 6e5]),
            Mount("3", [0.3, 1.4, -0.4], [3e5, 1e5, 9e5]),
            Mount("4", [-0.3, 1.4, -0.4], [3e5, 1e5, 9e5]),
        ],
    )
    K = system.K
    sub1, sub2 = [0, 4, 5], [1, 2, 3]
    assert np.abs(K[np.ix_(sub1, sub2)]).max() <= RTOL_ZERO_ENTRY * np.abs(K).max()
    assert modal_analysis(system.M, K).subsystems == (("x", "ry", "rz"), ("y", "z", "rx"))


def test_assembly_runs_under_jit_vmap_and_grad():
    system = four_mount()
    args = (system.positions, system.stiffnesses, system.axes)
    # The JAX twin against the model's NumPy assembly: entries that vanish are round-off of the largest.
    scale = RTOL_ZERO_ENTRY * np.abs(system.K).max()
    K = np.asarray(jax.jit(mount_matrix_jax)(*args))
    assert K == pytest.approx(system.K, rel=RTOL_LINALG, abs=scale)
    factors = jnp.linspace(0.5, 2.0, 7)
    batch = jax.vmap(lambda f: mount_matrix_jax(args[0], args[1] * f, args[2]))(factors)
    assert batch.shape == (7, 6, 6)
    assert np.asarray(batch[-1]) == pytest.approx(2.0 * system.K, rel=RTOL_LINALG, abs=2.0 * scale)
    # d K_zz / d kz of mount 0 = 1 (K_zz = sum of vertical stiffnesses).
    grad = jax.grad(lambda k: mount_matrix_jax(args[0], k, args[2])[2, 2])(jnp.asarray(args[1]))
    assert np.asarray(grad)[:, 2] == pytest.approx(np.ones(4))
    assert np.asarray(K).dtype == np.float64


def test_statics_closed_form_and_uplift():
    system = four_mount()
    statics = gravity_statics(system)
    assert statics.q[2] == pytest.approx(-500 * 9.80665 / (4 * 8e5), rel=RTOL_LINALG)
    assert statics.support == pytest.approx(np.full(4, 500 * 9.80665 / 4), rel=RTOL_LINALG)
    assert statics.uplift == ()
    # CG beyond the first support: the lever rule gives F1 = 1.5 W and F2 = -0.5 W (uplift).
    W = 100 * 9.81
    overhang = System(RigidBody(100.0, [5.0, 5.0, 5.0]),
                      [Mount("near", [0, 0.5, 0], [1e5, 1e5, 1e6]), Mount("far", [0, 1.5, 0], [1e5, 1e5, 1e6])])
    statics = gravity_statics(overhang, g=9.81)
    assert statics.support == pytest.approx(lever_rule_supports(W, 0.5, 1.5), rel=RTOL_STATICS)
    assert statics.uplift == ("far",)


def exact_solve(A, b):
    """``A x = b`` by Gaussian elimination in exact rational arithmetic (no rounding at all)."""
    from fractions import Fraction

    n = len(b)
    rows = [[Fraction(float(v)) for v in A[i]] + [Fraction(float(b[i]))] for i in range(n)]
    for i in range(n):
        pivot = next(r for r in range(i, n) if rows[r][i] != 0)
        rows[i], rows[pivot] = rows[pivot], rows[i]
        for r in range(n):
            if r != i and rows[r][i] != 0:
                factor = rows[r][i] / rows[i][i]
                rows[r] = [a - factor * c for a, c in zip(rows[r], rows[i])]
    return np.array([float(rows[i][n] / rows[i][i]) for i in range(n)])


@pytest.mark.parametrize("stops", [False, True], ids=["linear", "bump stops never reached (Newton)"])
def test_statics_of_an_ill_conditioned_layout(stops):
    """One mount of 1e12 N/m and three of 1e4 N/m: K is non-singular (condition 2e8), the body sags about the stiff
    mount as about a pin. Against the exact (rational) solution of K q = W, with K assembled here."""
    stiffness = [1e12, 1e4, 1e4, 1e4]
    positions = [np.array([sx * 0.5, sy * 0.5, -0.5]) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    stop = dict(bump_clearance=[np.inf, np.inf, 0.5], bump_stiffness=[0.0, 0.0, 1e5]) if stops else {}
    system = System(RigidBody(500.0, [40.0, 60.0, 80.0]),
                    [Mount(f"m{i}", p, [k] * 3, **stop) for i, (p, k) in enumerate(zip(positions, stiffness))])
    assert bool(system.nonlinear.count) == stops
    rows = [np.concatenate([e, np.cross(p, e)]) for p in positions for e in np.eye(3)]  # deflection per unit q
    K = sum(k * np.outer(r, r) for k, r in zip(np.repeat(stiffness, 3), rows))
    W = np.array([0.0, 0.0, -500.0 * 9.80665, 0.0, 0.0, 0.0])
    exact = exact_solve(K, W)
    statics = gravity_statics(system)
    assert np.abs(statics.q - exact).max() <= RTOL_ILL_CONDITIONED_STATICS * np.abs(exact).max()
    assert exact[2] == pytest.approx(-0.0817, abs=1e-4) and np.linalg.norm(exact[3:]) == pytest.approx(0.1156, abs=1e-4)
    # The stiff mount's 5 nm deflection is a difference of rotations and translations of ~0.08: its load, 1e12 N/m
    # times that, keeps ~4e-9 of the weight's digits (measured 3.6e-9).
    assert statics.support.sum() == pytest.approx(500.0 * 9.80665, rel=RTOL_ILL_CONDITIONED_STATICS)


def test_statics_of_a_free_motion_that_gravity_does_not_drive():
    """Two mounts on a line under the CG: rolling about that line is free, but the weight does not drive it; each
    mount carries half the weight and nothing rolls."""
    system = System(RigidBody(10.0, [1.0, 1.0, 1.0]),
                    [Mount("a", [0.0, -1.0, -0.3], [1e3, 1e3, 1e4]), Mount("b", [0.0, 1.0, -0.3], [1e3, 1e3, 1e4])])
    statics = gravity_statics(system)
    assert statics.support == pytest.approx([49.0332500, 49.0332500], rel=RTOL_STATICS)
    assert statics.q[2] == pytest.approx(-98.0665 / 2e4, rel=RTOL_STATICS)
    assert np.abs(statics.q[[0, 1, 3, 4, 5]]).max() <= RTOL_STATICS * abs(statics.q[2])


@pytest.mark.parametrize("mounts", [[Mount("one", [0, 0, 0], [1e3, 1e3, 0])],  # nothing vertical: it falls
                                    [Mount("one", [0.3, 0.2, -0.5], [1e3, 1e3, 1e4])],  # off the CG: it tips over
                                    # on a line beside the CG: it rolls about the line
                                    [Mount("a", [0.1, -1.0, -0.3], [1e3, 1e3, 1e4]),
                                     Mount("b", [0.1, 1.0, -0.3], [1e12, 1e12, 1e12])]])
def test_statics_refuses_a_body_that_cannot_carry_its_weight(mounts):
    system = System(RigidBody(1.0, [1.0, 1.0, 1.0]), mounts)
    with pytest.raises(InputError, match=r"mounts: expected mounts that can carry the body's weight and its moment, "
                                         r"got 'a layout that leaves a motion gravity drives unresisted"):
        gravity_statics(system)


@pytest.mark.parametrize(
    "make, match",
    [
        (lambda: RigidBody(0.0, [1, 1, 1]), r"mass: expected a positive number in kg, got 0.0"),
        (lambda: RigidBody(1.0, [1, 1, 3]), r"inertia: expected principal moments that a real body can have"),
        (lambda: RigidBody(1.0, [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]), r"inertia: expected a symmetric 3x3"),
        (lambda: RigidBody(1.0, [1, -1, 1]), r"inertia: expected a positive definite tensor"),
        (lambda: Mount("a", [0, 0], [1, 1, 1]), r"position: expected 3 coordinates \[x, y, z\] in m from the CG in body axes, got \[0, 0\]"),
        (lambda: Mount("a", [0, 0, 0], [1, -1, 1]), r"stiffness: expected 3 values >= 0 in N/m"),
        (lambda: Mount("a", [0, 0, 0], [1, 1, 1], axes=[[1, 0, 0], [0, 2, 0], [0, 0, 1]]), r"axes: expected 3 orthonormal rows"),
        (lambda: Mount("a", [0, 0, 0], [1, 1, 1], damping=[0, 0, -1]), r"damping: expected 3 values >= 0 in N s/m"),
        (lambda: System(RigidBody(1.0, [1, 1, 1]), []), r"mounts: expected at least one mount"),
    ],
)
def test_model_errors_name_the_field(make, match):
    with pytest.raises(InputError, match=match):
        make()


def test_damping_models_give_their_ratios():
    base = four_mount()
    body, mounts = base.body, base.mounts
    modes = modal_analysis(base.M, base.K)
    w = modes.omega
    # Modal: exactly the ratio asked for, one for all or one per mode.
    per_mode = (0.01, 0.02, 0.03, 0.04, 0.05, 0.06)
    for zeta in (0.03, per_mode):
        system = System(body, mounts, modal_damping=zeta)
        assert modal_damping_ratios(system.C, modes) == pytest.approx(np.broadcast_to(zeta, 6), rel=RTOL_DAMPING_RATIO)
    # Rayleigh: zeta = alpha / (2 w) + beta w / 2, and from_ratio hits the target at both frequencies.
    r = Rayleigh(alpha=0.8, beta=2e-4)
    system = System(body, mounts, rayleigh=r)
    assert modal_damping_ratios(system.C, modes) == pytest.approx(rayleigh_ratio(0.8, 2e-4, w), rel=RTOL_DAMPING_RATIO)
    r = Rayleigh.from_ratio(0.02, (modes.frequency_hz[0], modes.frequency_hz[-1]))
    zeta = modal_damping_ratios(System(body, mounts, rayleigh=r).C, modes)
    assert zeta[[0, -1]] == pytest.approx([0.02, 0.02], rel=RTOL_DAMPING_RATIO)
    assert np.all(zeta[1:-1] < 0.02)  # Rayleigh damps less between its two frequencies
    # Models add up: dashpots + Rayleigh + modal.
    damped = [Mount(m.name, m.position, m.stiffness, damping=[100.0, 200.0, 300.0]) for m in mounts]
    combined = System(body, damped, rayleigh=r, modal_damping=0.01)
    expected = System(body, damped).C + r.alpha * base.M + r.beta * base.K
    expected += base.M @ modes.shapes @ np.diag(2 * 0.01 * w) @ modes.shapes.T @ base.M
    assert combined.C == pytest.approx(expected, rel=1e-12, abs=1e-9 * np.abs(expected).max())


def test_exact_damping_ratios_of_non_proportional_damping():
    base = four_mount()
    modes = modal_analysis(base.M, base.K)
    # Classical damping: the exact ratios are the diagonal ones.
    classical = System(base.body, base.mounts, rayleigh=Rayleigh(alpha=0.5, beta=3e-4))
    assert damping_ratios(classical.C, modes) == pytest.approx(
        modal_damping_ratios(classical.C, modes), rel=RTOL_COMPLEX_DAMPING_RATIO)
    # Dashpots on two mounts only: non-proportional. The exact ratios are -Re(lambda)/|lambda| of
    # the six oscillating roots of det(lambda^2 M + lambda C + K) = 0, one per mode.
    damped = [Mount(m.name, m.position, m.stiffness, damping=[900.0, 600.0, 3000.0] if i < 2 else [0, 0, 0])
              for i, m in enumerate(base.mounts)]
    system = System(base.body, damped)
    zeta = damping_ratios(system.C, modes)
    approx = modal_damping_ratios(system.C, modes)
    assert not np.allclose(zeta, approx, rtol=1e-3)  # the coupling matters here
    assert zeta == pytest.approx(approx, rel=0.2)    # ... but only as a correction
    roots = np.linalg.eigvals(state_matrices(system.M, system.C, system.K)[0])
    from_roots = np.sort(-roots.real[roots.imag > 0] / np.abs(roots[roots.imag > 0]))
    assert np.sort(zeta) == pytest.approx(from_roots, rel=RTOL_COMPLEX_DAMPING_RATIO)


def test_modes_without_an_oscillating_pole_are_overdamped_not_their_diagonal_ratio():
    """Heavy non-proportional dashpots: the state matrix (scipy) has four complex pairs and four real eigenvalues,
    so two of the six modes do not oscillate. They are overdamped (inf), not the 83 % and 90 % of the diagonal
    approximation; the other four are -Re(lambda)/|lambda| of the four pairs."""
    from scipy.linalg import eigvals

    system = heavily_damped_box()
    roots = eigvals(state_matrices(system.M, system.C, system.K)[0])
    oscillating = roots[roots.imag > 1e-9 * np.abs(roots).max()]
    assert oscillating.size == 4 and np.sum(np.abs(roots.imag) <= 1e-9 * np.abs(roots).max()) == 4
    zeta = damping_ratios(system.C, system.modes)
    approx = modal_damping_ratios(system.C, system.modes)
    overdamped = np.isinf(zeta)
    assert overdamped.sum() == 2 and np.all(approx[overdamped] < 1)  # the approximation would call them underdamped
    assert np.sort(zeta[~overdamped]) == pytest.approx(np.sort(-oscillating.real / np.abs(oscillating)),
                                                       rel=RTOL_COMPLEX_DAMPING_RATIO)


@pytest.mark.parametrize(("mass", "inertia", "field", "got"), [
    (5e-324, (40.0, 60.0, 80.0), "body.mass", "mass 4.94e-324"),  # stiffness over mass overflows
    (1.7e308, (40.0, 60.0, 80.0), "body.mass", "mass 1.7e+308"),  # its square does
    (500.0, (1e160, 1e160, 1e160), "body.inertia", "a principal moment 1e+160"),
])
def test_a_body_beyond_floating_point_for_its_modes_is_named(mass, inertia, field, got):
    with pytest.raises(InputError, match=rf"^{field}: expected a mass in kg and moments of inertia in kg m\^2 whose "
                                         rf"squares, .* got {re.escape(got)}$"):
        four_mount(mass, inertia)


def test_reprs_are_one_line_with_arrays_by_shape():
    """A notebook's echo of a result: small vectors whole, long arrays by shape and type, nested results by class
    (the dataclasses' own repr printed every sample: an FRF of 500 frequencies ran to 60,000 characters)."""
    from sixdof import receptance

    system = four_mount()
    assert repr(system.mounts[0]).startswith("Mount(name='m0', position=[-0.4, -0.6, -0.3], stiffness=[200000.0, ")
    frf = receptance(system, np.geomspace(1.0, 100.0, 500))
    assert repr(frf) == "FRF(f_hz=<array (500,) float64>, H=<array (500, 6, 6) complex128>, method='direct', " \
                        "basis='dynamic stiffness')"
    text = repr(system)
    assert "\n" not in text and "mounts=<4 x Mount>" in text and len(text) < 300
    assert "shapes=<array (6, 6) float64>" in repr(system.modes)
