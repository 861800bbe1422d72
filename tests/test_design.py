"""Mount-system design metrics (issue 16, points 1-2): torque-roll axis, decoupling, elastic centre, and the
sensitivities of frequencies and decoupling to each mount axis' stiffness, against closed forms and finite
differences."""

from __future__ import annotations

import json

import numpy as np
import pytest

from sixdof import InputError, Mount, RigidBody, System, parse_scenario, prepare
from sixdof.analysis.design import design_metrics, elastic_center, sensitivities
from sixdof.cli import main
from sixdof.io.scenario import load_scenario
from sixdof.io.tables import SHOWN_AS_ZERO_RTOL
from sixdof.model.kinematics import mount_matrix
from sixdof.model.modes import modal_analysis
from systems import bridge, skewed_box

#: Relative step of the central differences, and their agreement with the exact derivative (measured:
#: 5e-9 to 9e-6 of each parameter's largest derivative at this step; 1e-6 loses digits to round-off).
FD_STEP = 1e-4
FD_RTOL = 1e-4


def isotropic(positions, k=1e5, J=(40.0, 60.0, 80.0), m=500.0) -> System:
    """A body on mounts as stiff along every axis (k [N/m]) at ``positions`` [m]."""
    return System(RigidBody(m, J), [Mount(f"m{i}", p, [k, k, k]) for i, p in enumerate(positions)])


def test_torque_roll_axis_is_the_inverse_inertia_times_the_torque_axis():
    # J with a product of inertia in the x-y plane: J^-1 e_x = [Jyy, c, 0] / (Jxx Jyy - c^2) by hand.
    Jxx, Jyy, Jzz, c = 40.0, 90.0, 100.0, 12.0
    inertia = [[Jxx, -c, 0.0], [-c, Jyy, 0.0], [0.0, 0.0, Jzz]]
    system = System(RigidBody(300.0, inertia), [Mount(f"m{i}", p, [2e5, 2e5, 6e5]) for i, p in enumerate(
        [(0.3, 0.4, -0.2), (-0.3, 0.4, -0.2), (-0.3, -0.4, -0.2), (0.3, -0.4, -0.2)])])
    metrics = design_metrics(system, [2.0, 0.0, 0.0])
    expected = np.array([Jyy, c, 0.0]) / np.hypot(Jyy, c)
    np.testing.assert_allclose(metrics.torque_roll_axis, expected, rtol=1e-14, atol=1e-15)
    np.testing.assert_array_equal(metrics.torque_axis, [1.0, 0.0, 0.0])


def test_elastic_centre_of_isotropic_mounts_is_their_centroid_and_a_skewed_set_has_none():
    # For mounts equally stiff along every axis, K about the CG has B = -n k S(mean position): the elastic
    # centre is the centroid of the mounts, wherever they are.
    positions = np.array([(0.5, 0.2, -0.3), (-0.4, 0.6, -0.25), (-0.1, -0.5, -0.35), (0.35, -0.3, 0.1)])
    np.testing.assert_allclose(elastic_center(isotropic(positions).K), positions.mean(axis=0), rtol=1e-12, atol=1e-15)
    assert elastic_center(skewed_box().K) is None  # unequal anisotropic mounts: no point decouples K


def test_a_focalized_layout_has_its_roll_mode_on_the_tra_and_every_mode_decoupled():
    # Isotropic mounts whose centroid is the CG: K is block diagonal about the CG, its rotational block
    # diagonal by the layout's symmetry, J diagonal: every mode is a pure translation or a rotation about a
    # body axis, the roll mode is about x, the TRA of a torque about x.
    system = isotropic([(0.4, 0.6, 0.0), (-0.4, 0.6, 0.0), (-0.4, -0.6, 0.0), (0.4, -0.6, 0.0)], J=(30.0, 60.0, 80.0))
    metrics = design_metrics(system, [1.0, 0.0, 0.0])
    np.testing.assert_allclose(metrics.elastic_center, 0.0, atol=1e-15)
    np.testing.assert_allclose(metrics.decoupling_percent, 100.0, rtol=1e-12)
    np.testing.assert_allclose(metrics.decoupling_tra_percent, 100.0, rtol=1e-12)
    assert system.modes.dominant_dof[metrics.roll_mode] == "rx"
    assert metrics.roll_mode_tra_angle_deg == pytest.approx(0.0, abs=1e-6)


def test_decoupling_is_the_dominant_kinetic_energy_share():
    system = bridge()
    metrics = design_metrics(system)
    np.testing.assert_array_equal(metrics.decoupling_percent, 100 * system.modes.ke_distribution.max(axis=0))
    assert metrics.torque_roll_axis is None and metrics.roll_mode is None and metrics.decoupling_tra_percent is None
    # The principal elastic axes diagonalize the translational stiffness.
    axes = metrics.elastic_axes
    np.testing.assert_allclose(axes @ system.K[:3, :3] @ axes.T, np.diag(metrics.principal_stiffness),
                               atol=1e-9 * metrics.principal_stiffness.max())


def _finite_differences(system):
    """Central differences of the frequencies [Hz] and decoupling [%] per mount-axis stiffness, (6, n, 3) each."""
    k = np.array(system.stiffnesses)
    frequency, decoupling = np.zeros((6, *k.shape)), np.zeros((6, *k.shape))
    for index in np.ndindex(k.shape):
        h = FD_STEP * k[index]
        up, down = k.copy(), k.copy()
        up[index] += h
        down[index] -= h
        plus, minus = (modal_analysis(system.M, mount_matrix(system.positions, s, system.axes)) for s in (up, down))
        frequency[(slice(None), *index)] = (plus.frequency_hz - minus.frequency_hz) / (2 * h)
        decoupling[(slice(None), *index)] = 100 * (plus.ke_distribution.max(0) - minus.ke_distribution.max(0)) / (2 * h)
    return frequency, decoupling


@pytest.mark.slow  # 1-2 s each on the 2-core machine
@pytest.mark.parametrize("system", [bridge(), skewed_box()], ids=["bridge", "skewed_box"])
def test_sensitivities_match_finite_differences(system):
    found = sensitivities(system)
    frequency, decoupling = _finite_differences(system)
    assert found.repeated_modes == () and not np.ma.is_masked(found.frequency)
    assert not np.ma.is_masked(found.decoupling)
    for exact, estimate in ((found.frequency.data, frequency), (found.decoupling.data, decoupling)):
        scale = np.max(np.abs(exact), axis=0, keepdims=True)  # per parameter
        assert np.max(np.abs(exact - estimate) / scale) < FD_RTOL


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_repeated_frequencies_get_the_group_mean_derivative_and_no_nan():
    # Isotropic mounts on a square around the CG, Jxx = Jyy: x, y, z translations share one frequency, rx and
    # ry another.
    system = isotropic([(0.5, 0.5, 0.0), (-0.5, 0.5, 0.0), (-0.5, -0.5, 0.0), (0.5, -0.5, 0.0)], J=(50.0, 50.0, 70.0))
    found = sensitivities(system)
    groups = [set(system.modes.dominant_dof[j] for j in g) for g in found.repeated_modes]
    assert sorted(map(sorted, groups)) == [["rx", "ry"], ["x", "y", "z"]]
    # Never a NaN: every frequency derivative is given; the decoupling of a repeated mode, whose shape is not
    # unique, has none and is masked.
    assert not np.ma.is_masked(found.frequency)
    assert not np.isnan(found.frequency.data).any() and not np.isnan(found.decoupling.data).any()
    frequency, _ = _finite_differences(system)
    for group in found.repeated_modes:
        mean = frequency[list(group)].mean(axis=0)  # the group mean's derivative (each member's is not unique)
        for j in group:
            np.testing.assert_allclose(found.frequency[j], mean, rtol=FD_RTOL, atol=FD_RTOL * np.abs(mean).max())
        assert found.decoupling.mask[list(group)].all()
    assert not found.decoupling.mask[[j for j in range(6) if not any(j in g for g in found.repeated_modes)]].any()


def test_a_zero_frequency_mode_has_no_frequency_derivative_masked_not_nan():
    # Mounts stiff only along z: x, y and rz are free (zero frequency, f = sqrt(l) / 2 pi has no finite
    # derivative there); the elastic modes' derivatives are given and match finite differences.
    system = System(RigidBody(500.0, (40.0, 60.0, 80.0)), [Mount(f"m{i}", p, [0.0, 0.0, 1e5]) for i, p in enumerate(
        [(0.5, 0.5, 0.0), (-0.5, 0.3, 0.0), (-0.4, -0.5, 0.0), (0.5, -0.4, 0.0)])])
    found = sensitivities(system)
    rigid = system.modes.eigenvalues <= system.modes.eigenvalues.max() * 1e-10
    assert rigid.sum() == 3
    for values in (found.frequency, found.decoupling):
        assert values.mask[rigid].all() and not values.mask[~rigid].any()
        assert np.isfinite(values.data).all()
    k = np.array(system.stiffnesses)
    for mount in range(4):  # central differences of the elastic frequencies per mount's w stiffness
        h = FD_STEP * k[mount, 2]
        up, down = k.copy(), k.copy()
        up[mount, 2] += h
        down[mount, 2] -= h
        plus, minus = (modal_analysis(system.M, mount_matrix(system.positions, s, system.axes)).frequency_hz
                       for s in (up, down))
        np.testing.assert_allclose(found.frequency[~rigid, mount, 2], ((plus - minus) / (2 * h))[~rigid],
                                   rtol=FD_RTOL)


def test_modes_json_carries_the_design_metrics_and_sensitivities(tmp_path, capsys):
    from test_run import SCENARIO

    path = tmp_path / "small.toml"
    path.write_text(SCENARIO + "\n[design]\ntorque_axis = [1.0, 0.0, 0.0]\n")
    assert main(["modes", str(path), "--json", "--sensitivity"]) == 0
    out = json.loads(capsys.readouterr().out)
    system = parse_scenario(path.read_text()).system
    metrics = design_metrics(system, [1.0, 0.0, 0.0])
    np.testing.assert_allclose(out["torque_roll_axis"], metrics.torque_roll_axis)
    assert out["roll_mode_tra_angle_deg"] == pytest.approx(metrics.roll_mode_tra_angle_deg)
    assert len(out["decoupling_percent"]) == 6 and out["elastic_center"] is None
    assert np.shape(out["frequency_sensitivity"]) == (6, 4, 3)  # mode, mount, axis: Hz per N/m
    exact = sensitivities(system).frequency  # printed: its round-off of a mode's largest as 0 (the next test)
    np.testing.assert_allclose(out["frequency_sensitivity"], exact, atol=SHOWN_AS_ZERO_RTOL * np.abs(exact).max())
    assert main(["modes", str(path)]) == 0
    assert "Torque-roll axis (torque about [1, 0, 0])" in capsys.readouterr().out
    assert main(["modes", str(path), "--sensitivity"]) == 2
    assert "--sensitivity: expected --json as well" in capsys.readouterr().err


def test_modes_json_prints_a_sensitivity_zero_by_symmetry_as_zero(capsys):
    """A mode of a decoupled subsystem moves no mount along an axis whose DOFs it lacks (x: x, ry, rz; y: y, rz,
    rx; z: z, rx, ry): the derivatives of its frequency and decoupling by that axis' stiffness are exactly 0, not
    the 1e-36 that automatic differentiation leaves; every other derivative is printed as it is."""
    scenario = "scenarios/equipment_elastomer.toml"
    system = prepare(load_scenario(scenario)).system
    assert all(np.array_equal(axes, np.eye(3)) for axes in system.axes)  # u, v, w: the body's x, y, z
    assert main(["modes", scenario, "--json", "--sensitivity"]) == 0
    out = json.loads(capsys.readouterr().out)
    moving = ({"x", "ry", "rz"}, {"y", "rz", "rx"}, {"z", "rx", "ry"})
    found = sensitivities(system)
    for name, exact in (("frequency_sensitivity", found.frequency), ("decoupling_sensitivity", found.decoupling)):
        printed = np.array(out[name], dtype=float)
        for mode, dof in enumerate(system.modes.dominant_dof):
            (subsystem,) = [set(group) for group in system.modes.subsystems if dof in group]
            still = [axis for axis in range(3) if not subsystem & moving[axis]]
            assert still and np.all(printed[mode][:, still] == 0.0), (name, mode, printed[mode])
            others = [axis for axis in range(3) if axis not in still]
            np.testing.assert_allclose(printed[mode][:, others], exact[mode][:, others], rtol=1e-12)


def test_a_zero_torque_axis_is_refused_naming_the_field():
    from test_run import SCENARIO

    with pytest.raises(InputError, match=r"design\.torque_axis: expected a non-zero 3-vector in body axes, got \[0\.0, 0\.0, 0\.0\]"):
        parse_scenario(SCENARIO + "\n[design]\ntorque_axis = [0.0, 0.0, 0.0]\n")
