"""The bundled tap test (``scenarios/machine_tap_test.uff``, issue 47 item 9): reproducible from its script, laid out
as stated, and holding the truth's accelerance, the stated flexible mode and the stated noise.

The truth's accelerance is computed here by hand from the scenario's numbers (tomllib) and the truth's stated
deviations: M, K of four springs through the point map, modal damping ``C = M Phi diag(2 zeta w) Phi' M`` from
scipy's eigenvectors, ``-w^2 (K - w^2 M + i w C)^-1`` between the nodes; none of sixdof's assembly or FRFs.
"""

import importlib.util
import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
UFF = SCENARIOS / "machine_tap_test.uff"
TRUTH = json.loads((SCENARIOS / "machine_tap_test.truth.json").read_text())
#: ASCII UFF58 single precision (E13.5) keeps 6 significant digits: each part is within half a unit of the 6th.
ROUNDING = 5e-6


@pytest.fixture(scope="module")
def script():
    spec = importlib.util.spec_from_file_location("synthesize_tap_test", ROOT / "scripts" / "synthesize_tap_test.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def synthesized(script):
    return script.synthesize()


@pytest.fixture(scope="module")
def sets():
    import pyuff

    return pyuff.UFF(str(UFF)).read_sets()


def skew(p):
    x, y, z = p
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def point_rows(p):
    """u_p = [I, -skew(p)] q: small rotations theta move p by theta x p."""
    return np.hstack([np.eye(3), -skew(p)])


def hand_model(truth: bool):
    """M, K [SI] and the modal damping ratios of the scenario, as drawn or (``truth``) as built."""
    spec = tomllib.loads((SCENARIOS / "machine_tap_test.toml").read_text())
    body = spec["body"]
    M = np.diag([body["mass"]] * 3 + body["inertia"])
    offset = np.array(TRUTH["deviations"]["cg_offset_m"]) if truth else np.zeros(3)
    K = np.zeros((6, 6))
    for mount in spec["mounts"]:
        factors = TRUTH["deviations"]["stiffness_factors"][mount["name"]] if truth else {"u": 1, "v": 1, "w": 1}
        k = np.array(mount["stiffness"]) * [factors["u"], factors["v"], factors["w"]]
        T = point_rows(np.array(mount["position"]) - offset)
        K += T.T @ np.diag(k) @ T
    return M, K, np.array(spec["damping"]["modal"]), offset


def hand_accelerance(f_hz, response, reference):
    """The truth's rigid-body accelerance [(m/s^2)/N] of a (node, body direction) pair per unit force at another,
    plus the stated torsion mode."""
    M, K, zeta, offset = hand_model(truth=True)
    lam, phi = scipy.linalg.eigh(K, M)  # phi' M phi = I
    w_r = np.sqrt(lam)
    C = M @ phi @ np.diag(2 * zeta * w_r) @ phi.T @ M
    nodes = {int(n): np.array(p) for n, p in TRUTH["nodes_body_m"].items()}
    (n_out, d_out), (n_ref, d_ref) = response, reference
    row = d_out @ point_rows(nodes[n_out] - offset)
    col = d_ref @ point_rows(nodes[n_ref] - offset)
    w = 2 * np.pi * np.asarray(f_hz)
    rigid = np.array([-wk**2 * row @ np.linalg.solve(K - wk**2 * M + 1j * wk * C, col) for wk in w])
    flex = TRUTH["flexible_mode"]
    a, b = flex["half_spans_m"]

    def phi_flex(n, d):
        return d[2] * nodes[n][0] * nodes[n][1] / (a * b)

    # At the stated ratio to the truth's highest rigid-body mode (the JSON's frequency is rounded to 0.1 mHz).
    wf, zf = flex["ratio_to_highest_rigid"] * w_r[-1], flex["damping_ratio"]
    flexible = -w**2 * phi_flex(n_out, d_out) * phi_flex(n_ref, d_ref) / (
        flex["modal_mass_kg"] * (wf**2 - w**2 + 2j * zf * wf * w))
    return rigid + flexible


def body_direction(code):
    axes = np.array(TRUTH["lab_frame"]["axes"])
    return np.sign(code) * axes[abs(code) - 1]


def frf_sets(sets):
    return [s for s in sets if s["type"] == 58]


def test_regenerating_the_test_gives_the_committed_files(script, tmp_path):
    assert script.main([str(tmp_path)]) == 0
    for name in ("machine_tap_test.uff", "machine_tap_test.truth.json"):
        assert (tmp_path / name).read_bytes() == (SCENARIOS / name).read_bytes(), name
    assert UFF.stat().st_size < 2e6


def test_the_file_holds_one_accelerance_per_channel_and_tap_and_the_nodes_in_the_lab_frame(sets):
    responses = [tuple(r) for r in TRUTH["responses"]]
    references = [tuple(r) for r in TRUTH["references"]]
    assert len(responses) == 15 and len(references) == 3
    frfs = frf_sets(sets)
    assert len(sets) == 1 + len(frfs) and len(frfs) == len(responses) * len(references)
    pairs = {((int(s["rsp_node"]), int(s["rsp_dir"])), (int(s["ref_node"]), int(s["ref_dir"]))) for s in frfs}
    assert pairs == {(o, r) for o in responses for r in references}
    for s in frfs:
        assert (s["func_type"], s["ordinate_spec_data_type"], s["orddenom_spec_data_type"]) == (4, 12, 13)
        assert (s["ordinate_axis_units_lab"], s["orddenom_axis_units_lab"], s["abscissa_axis_units_lab"]) == \
            ("m/s^2", "N", "Hz")
        assert (s["ordinate_len_unit_exp"], s["orddenom_force_unit_exp"]) == (1, 1)
        np.testing.assert_allclose(s["x"], 1.0 + 0.1 * np.arange(991), rtol=1e-12)
    (nodes,) = [s for s in sets if s["type"] == 15]
    origin, axes = np.array(TRUTH["lab_frame"]["origin_m"]), np.array(TRUTH["lab_frame"]["axes"])
    # The lab frame is the body's turned +90 deg about z: lab X along body +y, lab Y along body -x.
    np.testing.assert_array_equal(axes, [[0, 1, 0], [-1, 0, 0], [0, 0, 1]])
    for n, x, y, z in zip(nodes["node_nums"], nodes["x"], nodes["y"], nodes["z"]):
        body = origin + axes.T @ np.array([x, y, z])
        np.testing.assert_allclose(body, TRUTH["nodes_body_m"][str(int(n))], atol=1e-12)


@pytest.mark.parametrize("pair", [((104, 3), (101, -3)), ((105, 2), (103, 1)), ((102, 1), (105, 2))],
                         ids=["corner z per vertical tap", "top per lateral tap", "corner per top tap"])
def test_the_noise_free_part_is_the_truth_s_accelerance(script, synthesized, sets, pair):
    (response, reference) = pair
    (measured,) = [s["data"] for s in frf_sets(sets)
                   if (s["rsp_node"], s["rsp_dir"], s["ref_node"], s["ref_dir"]) == (*response, *reference)]
    f = 1.0 + 0.1 * np.arange(991)
    exact = hand_accelerance(f, (response[0], body_direction(response[1])),
                             (reference[0], body_direction(reference[1])))
    o = list(script.RESPONSES).index(response)
    r = list(script.REFERENCES).index(reference)
    clean = measured - synthesized["noise"][:, o, r]
    for part in (np.real, np.imag):
        bound = ROUNDING * np.abs(part(measured)) + 1e-12 * np.abs(exact).max()  # and the solves' round-off
        assert np.all(np.abs(part(clean) - part(exact)) <= bound)
    # The noise is the stated one: rms over the band sigma = 1 % of the FRF's rms plus the floor (991 draws:
    # the rms of the draws within 5 % of sigma, 3 standard errors).
    sigma = TRUTH["noise"]["relative_to_rms"] * np.sqrt(np.mean(np.abs(exact) ** 2)) + TRUTH["noise"]["floor"]
    assert np.sqrt(np.mean(np.abs(measured - exact) ** 2)) == pytest.approx(sigma, rel=0.05)


def test_the_frequencies_and_the_flexible_mode_are_the_stated_ones(sets):
    f_hz = {}
    for truth in (False, True):
        M, K, _, _ = hand_model(truth)
        f_hz[truth] = np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)) / (2 * np.pi)
    np.testing.assert_allclose(TRUTH["nominal_frequency_hz"], f_hz[False], atol=5e-5)
    np.testing.assert_allclose(TRUTH["truth_frequency_hz"], f_hz[True], atol=5e-5)
    assert 5.0 < f_hz[False][0] and f_hz[False][-1] < 30.0
    for truth, apart in ((False, 0.02), (True, 0.03)):  # the close rocking pair
        assert f_hz[truth][-1] / f_hz[truth][-2] - 1 < apart
    flex = TRUTH["flexible_mode"]["frequency_hz"]
    assert flex / f_hz[True][-1] == pytest.approx(3.0, abs=1e-5)
    # In the file: the corner's vertical accelerance per the vertical tap peaks there, above the rigid modes.
    (corner,) = [s for s in frf_sets(sets) if (s["rsp_node"], s["rsp_dir"], s["ref_node"]) == (104, 3, 101)]
    above = corner["x"] > 2 * f_hz[True][-1]
    assert corner["x"][above][np.argmax(np.abs(corner["data"][above]))] == pytest.approx(flex, abs=0.1)


def test_the_test_table_says_where_the_file_s_nodes_lie(sets):
    test = tomllib.loads((SCENARIOS / "machine_tap_test.toml").read_text())["test"]
    assert test["origin"] == TRUTH["lab_frame"]["origin_m"] and test["axes"] == TRUTH["lab_frame"]["axes"]
    (nodes,) = [s for s in sets if s["type"] == 15]
    in_file = {str(int(n)): [x, y, z] for n, x, y, z in zip(nodes["node_nums"], nodes["x"], nodes["y"], nodes["z"])}
    assert sorted(test["nodes"]) == sorted(in_file)
    for n, position in test["nodes"].items():
        np.testing.assert_allclose(position, in_file[n], atol=1e-12)


def test_the_update_varies_each_mount_axis_the_test_can_tell_and_the_centre_of_gravity():
    """The ``[[update.vary]]`` entries (the grammar of ``[[design.vary]]``) and the CG offset's bounds."""
    from sixdof.io.scenario import load_scenario

    update = load_scenario(SCENARIOS / "machine_tap_test.toml").update
    varied = update.vary
    assert update.cg_offset == ((-0.03, 0.03),) * 3
    assert [(v.mounts, v.axes, v.tied) for v in varied] == [
        (("front_left",), ("w",), False), (("front_right",), ("w",), False), (("rear_right",), ("w",), False),
        (("rear_left",), ("w",), False), (("front_left", "front_right"), ("v",), True),
        (("rear_right", "rear_left"), ("v",), True), (("front_left", "front_right", "rear_right", "rear_left"), ("u",), True)]
