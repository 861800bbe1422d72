"""Gravity's geometric stiffness (``[statics] geometric_stiffness``, issue 45): the closed form of a block rocking
on springs below its CG, symmetry at equilibrium, and every path that takes K (FRF, batches, gradients, files)."""

import dataclasses
import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from sixdof import RigidBody, System, gravity_statics, modal_analysis, receptance
from sixdof.analysis.batch import batch_frequencies, make_variants, variant_matrices, variant_system
from sixdof.analysis.design import sensitivities
from sixdof.analysis.statics import replace_with_preload, with_gravity_preload
from sixdof.analysis.validity import geometric_stiffness_note, geometric_stiffness_shifts
from sixdof.cli import main
from sixdof.errors import ScenarioError
from sixdof.io.scenario import load_scenario, parse_scenario
from sixdof.io.store import load_results, write_results
from sixdof.model.kinematics import mount_matrix
from sixdof.model.parts import Mount
from sixdof.results import RunResults
from sixdof.workflows.prepare import prepare
from systems import four_mount, skewed_machine
from tolerances import RTOL_FREQUENCY, RTOL_FRF_CLOSED_FORM, RTOL_GEOMETRIC_GRADIENT, RTOL_LINALG

G = 9.80665
DOWN = np.array([0.0, 0.0, -G])
SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


def preloaded(system: System, gravity=DOWN) -> System:
    return with_gravity_preload(system, gravity)


def by_hand(system: System, gravity=DOWN) -> np.ndarray:
    """``sum_j (F_j . r_j) I - r_j F_j'`` (3, 3, not symmetrized) from the statics' mount forces, written out."""
    forces = -gravity_statics(system, np.linalg.norm(gravity), gravity).mount_forces  # of the mounts on the body
    block = np.zeros((3, 3))
    for r, f in zip(system.positions, forces):
        block += np.dot(f, r) * np.eye(3) - np.outer(r, f)
    return block


def rocking_pair(m, J, k_sway, k_rock, k_couple):
    """Both roots omega^2 of the sway-rocking pair ``det([[k_s - w^2 m, k_c], [k_c, k_r - w^2 J]]) = 0``."""
    b = k_sway * J + k_rock * m
    disc = np.sqrt(b * b - 4 * m * J * (k_sway * k_rock - k_couple**2))
    return (b - disc) / (2 * m * J), (b + disc) / (2 * m * J)


def test_a_block_rocking_on_springs_below_its_cg_loses_w_h_of_rocking_stiffness():
    m, J, a, b, h, (kx, ky, kz) = 500.0, (40.0, 60.0, 80.0), 0.4, 0.6, 0.3, (2e5, 3e5, 8e5)
    system = preloaded(four_mount(m, J, a, b, h, (kx, ky, kz)))
    W = m * G
    np.testing.assert_allclose(system.K_geometric[3:, 3:], np.diag([-W * h, -W * h, 0.0]), rtol=0,
                               atol=RTOL_LINALG * W * h)
    assert not system.K_geometric[:3].any() and not system.K_geometric[:, :3].any()
    # Sway along x couples with rocking ry, along y with rx (the mounts' lever h); bounce and yaw stay alone.
    for preload, candidate in ((W, system), (0.0, four_mount(m, J, a, b, h, (kx, ky, kz)))):
        x_ry = rocking_pair(m, J[1], 4 * kx, 4 * (kx * h**2 + kz * a**2) - preload * h, -4 * kx * h)
        y_rx = rocking_pair(m, J[0], 4 * ky, 4 * (ky * h**2 + kz * b**2) - preload * h, 4 * ky * h)
        expected = np.sort([*x_ry, *y_rx, 4 * kz / m, 4 * (kx * b**2 + ky * a**2) / J[2]])
        np.testing.assert_allclose(candidate.modes.eigenvalues, expected, rtol=RTOL_FREQUENCY)
    # Without it (the seed's tables, Nastran, OpenSees): the classical rocking stiffness alone.
    assert not candidate.geometric_stiffness and not candidate.K_geometric.any()


def test_mounts_above_the_cg_raise_the_rocking_stiffness_as_a_pendulum():
    # Hung from four mounts 0.3 m above its CG (carrying the weight upward: the same forces, r_z = +h).
    system = preloaded(four_mount(h=-0.3))
    W = 500.0 * G
    np.testing.assert_allclose(np.diag(system.K_geometric)[3:], [W * 0.3, W * 0.3, 0.0], rtol=RTOL_LINALG)


@pytest.mark.parametrize("gravity", [DOWN, np.array([1.2, -0.7, -9.7])], ids=["down", "tilted"])
def test_the_geometric_stiffness_of_an_asymmetric_layout_is_symmetric_at_equilibrium(gravity):
    # Four inclined mounts, all different, under gravity along -z and tilted: the static forces balance the weight
    # and its moment about the CG (zero), which makes sum_j r_j F_j' symmetric without symmetrizing it.
    system = skewed_machine()
    block = by_hand(system, gravity)
    assert np.max(np.abs(block - block.T)) <= RTOL_LINALG * np.max(np.abs(block))
    assert np.max(np.abs(block - np.diag(np.diag(block)))) > 1e-3 * np.max(np.abs(block))  # coupled: not a diagonal
    on = preloaded(system, gravity)
    np.testing.assert_allclose(on.K_geometric[3:, 3:], block, rtol=0, atol=RTOL_LINALG * np.max(np.abs(block)))
    np.testing.assert_array_equal(on.K, on.K_mounts + on.K_geometric)
    np.testing.assert_array_equal(on.K_mounts, system.K)


def test_the_low_frequency_receptance_is_the_inverse_of_k_plus_k_g():
    system = preloaded(skewed_machine())
    K = mount_matrix(system.positions, system.stiffnesses, system.axes)
    K[3:, 3:] += by_hand(system)  # symmetric at equilibrium (the test above)
    H = receptance(system, [0.0]).H[0]
    np.testing.assert_allclose(H, np.linalg.inv(K), rtol=0, atol=RTOL_FRF_CLOSED_FORM * np.abs(H).max())
    without = receptance(skewed_machine(), [0.0]).H[0]
    assert np.abs(H - without).max() > 1e3 * RTOL_FRF_CLOSED_FORM * np.abs(H).max()  # it matters here


def test_each_batch_variant_has_the_geometric_stiffness_of_its_own_statics():
    system = preloaded(four_mount())
    variants = make_variants(system, stiffness_factor=[1.0, 0.5, 2.0],
                             position_offset=[[0.0, 0.0, 0.0], [0.05, 0.0, -0.1], [0.0, -0.1, 0.15]])
    K, _, lam = variant_matrices(system, variants)
    frequency = batch_frequencies(system, variants)
    W = 500.0 * G
    for v, h in enumerate([0.3, 0.4, 0.15]):  # the mounts' height below the CG, moved by the offset
        one = variant_system(system, variants, v)
        assert one.geometric_stiffness
        np.testing.assert_allclose(K[v], one.K, rtol=0, atol=RTOL_LINALG * np.abs(one.K).max())
        np.testing.assert_allclose(frequency[v], one.modes.frequency_hz, rtol=RTOL_FREQUENCY)
        # Its own K_G: -W h of its own height, not the nominal one.
        np.testing.assert_allclose(np.diag(K[v] - one.K_mounts)[3:], [-W * h, -W * h, 0.0], rtol=0,
                                   atol=RTOL_LINALG * np.abs(one.K).max())


@pytest.mark.slow  # 3 s on the 2-core machine
def test_frequency_gradients_flow_through_each_designs_statics():
    # Four inclined mounts: statically indeterminate, so each mount's preload, and K_G, depends on the stiffnesses.
    system = preloaded(skewed_machine())
    exact = sensitivities(system).frequency.data  # (6, n, 3)
    K_G = system.K_geometric
    full, frozen = np.zeros_like(exact), np.zeros_like(exact)
    step = 1e-4
    for index in np.ndindex(system.stiffnesses.shape):
        h = step * system.stiffnesses[index]
        found = []
        for sign in (1, -1):
            k = np.array(system.stiffnesses)
            k[index] += sign * h
            mounts = [dataclasses.replace(mt, stiffness=k[j]) for j, mt in enumerate(system.mounts)]
            variant = replace_with_preload(system, mounts=mounts)  # its own statics
            found.append((variant.modes.frequency_hz, modal_analysis(variant.M, variant.K_mounts + K_G).frequency_hz))
        full[(slice(None), *index)] = (found[0][0] - found[1][0]) / (2 * h)
        frozen[(slice(None), *index)] = (found[0][1] - found[1][1]) / (2 * h)
    scale = np.max(np.abs(exact), axis=0, keepdims=True)
    assert np.max(np.abs(exact - full) / scale) < RTOL_GEOMETRIC_GRADIENT
    # The statics' share is resolved: the nominal K_G held fixed gives other derivatives.
    assert np.max(np.abs(exact - frozen) / scale) > 10 * RTOL_GEOMETRIC_GRADIENT


def test_the_bundled_cabinet_is_told_that_its_sway_modes_would_drop():
    cabinet = load_scenario(SCENARIOS / "cabinet_earthquake.toml")
    shifts = geometric_stiffness_shifts(cabinet.system, cabinet.statics.vector)
    # An independent nonlinear rigid-body model (Exudyn) puts them 3.7 % and 1.7 % lower.
    np.testing.assert_allclose(100 * shifts[:2], [-3.674, -1.707], atol=0.001)
    assert geometric_stiffness_note(cabinet.system, cabinet.statics.vector) == (
        "gravity's geometric stiffness would lower mode 1 (y) by 3.7 %; [statics] geometric_stiffness = true "
        "includes it")
    bridge = load_scenario(SCENARIOS / "bridge_beam.toml")
    shifts = geometric_stiffness_shifts(bridge.system, bridge.statics.vector)
    assert bridge.system.modes.dominant_dof[3] == "ry" and round(100 * shifts[3], 2) == -0.67  # Exudyn: 0.67 %
    assert geometric_stiffness_note(bridge.system, bridge.statics.vector) is None  # under 1 %: nothing said


def test_a_body_the_preload_would_tip_over_is_told_so():
    # Soft mounts 0.5 m below the CG of 100 kg: rocking stiffness 4 (250 0.4^2 + 100 0.5^2) = 260 N m/rad < W h = 490.
    system = four_mount(100.0, (5.0, 5.0, 5.0), 0.4, 0.4, 0.5, (100.0, 100.0, 250.0))
    assert geometric_stiffness_note(system, DOWN).startswith(
        "gravity's geometric stiffness would leave K + K_G with a negative eigenvalue: the body would tip over")


def test_modes_command_prints_the_line_off_and_on(tmp_path, capsys):
    main(["modes", str(SCENARIOS / "cabinet_earthquake.toml")])
    lines = capsys.readouterr().out.splitlines()
    assert sum("geometric stiffness would lower mode 1 (y) by 3.7 %" in line for line in lines) == 1
    text = (SCENARIOS / "cabinet_earthquake.toml").read_text()
    assert "[statics]" not in text
    on = tmp_path / "cabinet.toml"
    on.write_text(text + "\n[statics]\ngeometric_stiffness = true\n")
    (tmp_path / "ground_accelerogram.csv").write_text((SCENARIOS / "ground_accelerogram.csv").read_text())
    main(["modes", str(on)])
    out = capsys.readouterr().out
    assert "K includes gravity's geometric stiffness ([statics] geometric_stiffness = true): it moves mode 1 (y) " \
           "most, by -3.7 %" in out
    main(["modes", str(on), "--json"])
    assert json.loads(capsys.readouterr().out)["geometric_stiffness"] is True


SCENARIO = """name = "block"
[body]
mass = 500.0
inertia = [40.0, 60.0, 80.0]
[[mounts]]
name = "a"
position = [0.4, 0.6, -0.3]
stiffness = [2e5, 3e5, 8e5]
[[mounts]]
name = "b"
position = [-0.4, 0.6, -0.3]
stiffness = [2e5, 3e5, 8e5]
[[mounts]]
name = "c"
position = [-0.4, -0.6, -0.3]
stiffness = [2e5, 3e5, 8e5]
[[mounts]]
name = "d"
position = [0.4, -0.6, -0.3]
stiffness = [2e5, 3e5, 8e5]
"""


def test_the_scenario_key_and_its_errors():
    assert not parse_scenario(SCENARIO).system.geometric_stiffness
    on = prepare(parse_scenario(SCENARIO + "[statics]\ngravity = 9.81\ngeometric_stiffness = true\n")).system
    np.testing.assert_allclose(np.diag(on.K_geometric)[3:], [-500 * 9.81 * 0.3] * 2 + [0.0], rtol=RTOL_LINALG)
    with pytest.raises(ScenarioError, match=r"statics\.geometric_stiffness: expected true or false, got 1"):
        parse_scenario(SCENARIO + "[statics]\ngeometric_stiffness = 1\n")
    with pytest.raises(ScenarioError, match=r"statics\.geometric_stifness: expected one of the keys .*; did you mean 'geometric_stiffness'\?"):
        parse_scenario(SCENARIO + "[statics]\ngeometric_stifness = true\n")
    # Mounts that cannot carry the weight have no preload: said when the run prepares the model, naming the key.
    free = SCENARIO.replace("[2e5, 3e5, 8e5]", "[2e5, 3e5, 0.0]")
    with pytest.raises(ScenarioError, match=r"statics\.geometric_stiffness: expected false, or mounts that carry"):
        prepare(parse_scenario(free + "[statics]\ngeometric_stiffness = true\n"))
    with pytest.raises(ValueError, match=r"gravity_preload: expected a gravity vector"):
        System(RigidBody(1.0, [1.0, 1.0, 1.0]), [Mount("a", [0, 0, 0], [1.0, 1.0, 1.0])], gravity_preload=[0, 0, 0])


def test_results_file_says_whether_k_holds_it(tmp_path):
    for system, held in ((four_mount(), False), (preloaded(four_mount()), True)):
        path = tmp_path / f"{held}.h5"
        write_results(path, RunResults(name="block", system=system, modes=system.modes))
        with h5py.File(path) as f:
            assert bool(f["model"].attrs["geometric_stiffness"]) is held
            assert ("geometric stiffness K_geometric" in f["model/K"].attrs["description"]) is held
            np.testing.assert_array_equal(f["model/K"][()], system.K)
            np.testing.assert_array_equal(f["model/K_geometric"][()], system.K_geometric)
        loaded = load_results(path).system
        assert loaded.geometric_stiffness is held
        np.testing.assert_allclose(loaded.K, system.K, rtol=0, atol=RTOL_LINALG * np.abs(system.K).max())


def test_the_modal_analysis_guide_gives_the_formula_and_the_key():
    guide = (Path(__file__).resolve().parents[1] / "docs" / "guides" / "modal-analysis.md").read_text(encoding="utf-8")
    assert "K_G = sum_j [(F_j . r_j) I - r_j F_j^T]" in guide
    assert "geometric_stiffness = true" in guide


def test_a_tall_body_with_the_option_on_is_refused_naming_it():
    """Prepared with [statics] geometric_stiffness = true, a body the preload would tip over is one line naming the
    setting (the modes' own message named only K)."""
    from sixdof import parse_scenario, prepare
    from sixdof.errors import ScenarioError

    mounts = "".join(f'[[mounts]]\nname = "m{i}"\nposition = [{x}, {y}, -0.5]\nstiffness = [100.0, 100.0, 250.0]\n'
                     for i, (x, y) in enumerate([(-0.4, -0.4), (0.4, -0.4), (0.4, 0.4), (-0.4, 0.4)]))
    text = f'name = "tall"\n[body]\nmass = 100.0\ninertia = [5.0, 5.0, 5.0]\n{mounts}[statics]\ngeometric_stiffness = true\n'
    with pytest.raises(ScenarioError, match=r"^tall.toml: statics.geometric_stiffness: expected false, or mounts "
                       r"whose rocking stiffness carries the weight .* got K \+ K_G with a negative eigenvalue: the "
                       r"body would tip over on these mounts$"):
        prepare(parse_scenario(text, "tall.toml"))


def test_mounts_that_cannot_carry_the_weight_get_no_geometric_note():
    """No static equilibrium (one mount off the CG: gravity tips the body): no preload, so no line, never an error
    naming a setting the user did not turn on."""
    from sixdof import Mount

    system = System(RigidBody(10.0, [1.0, 1.0, 1.0]), [Mount("a", [0.3, 0.0, -0.2], [1e4, 1e4, 1e4])])
    assert geometric_stiffness_shifts(system, DOWN) is None
    assert geometric_stiffness_note(system, DOWN) is None


def test_a_linearized_copy_keeps_the_nonlinear_preload_in_its_K():
    """K of the linearized system is its mounts' K plus the nonlinear equilibrium's K_G, exactly."""
    from sixdof import parse_scenario, prepare

    text = (SCENARIOS / "bridge_beam_uplift.toml").read_text() + "\n[statics]\ngeometric_stiffness = true\n"
    system = prepare(parse_scenario(text)).system
    linear = system.linearized()
    np.testing.assert_array_equal(linear.K_geometric, system.K_geometric)
    np.testing.assert_array_equal(linear.K, linear.K_mounts + system.K_geometric)


def test_a_copy_with_moved_mounts_is_refused_until_its_preload_is_solved_again():
    """The model is given its preload (it solves no statics): a copy with moved mounts keeps a preload that no longer
    balances the weight's moment, and is refused; replace_with_preload solves the copy's own."""
    system = preloaded(four_mount())
    moved = [dataclasses.replace(m, position=m.position + [0.05, 0.0, 0.0]) for m in system.mounts[:2]]
    mounts = (*moved, *system.mounts[2:])
    with pytest.raises(ValueError, match=r"mount_preload: expected the static loads of these mounts under "
                       r"gravity_preload, .* got loads off balance by .* N and .* N m"):
        dataclasses.replace(system, mounts=mounts)
    np.testing.assert_allclose(replace_with_preload(system, mounts=mounts).mount_preload,
                               preloaded(dataclasses.replace(four_mount(), mounts=mounts)).mount_preload, rtol=0,
                               atol=RTOL_LINALG * 500.0 * G)
    with pytest.raises(ValueError, match=r"mount_preload: expected a value with gravity_preload"):
        dataclasses.replace(system, mount_preload=None)
