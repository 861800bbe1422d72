"""MAC, mode pairing and the correlation verdict (sixdof.validation.correlation) against hand computations."""

import numpy as np
import pytest

from sixdof import InputError
from sixdof.io.study_report import correlation_table
from sixdof.validation import correlate_modes, mac, pair_modes
from sixdof.validation.correlation import channel_shapes
from tolerances import ATOL_UNIT_ROUNDOFF


def orthonormal(n, m, seed=0):
    return np.linalg.qr(np.random.default_rng(seed).standard_normal((n, m)))[0]


def test_mac_against_a_hand_computation():
    # (1*2 + 2*1)^2 / ((1 + 4)(4 + 1)) = 16/25.
    assert mac([1.0, 2.0], [2.0, 1.0])[0, 0] == pytest.approx(0.64, abs=ATOL_UNIT_ROUNDOFF)
    # a^H b = 1 - 1j: |.|^2 = 2, over (2)(2).
    assert mac([1.0, 1j], [1.0, 1.0])[0, 0] == pytest.approx(0.5, abs=ATOL_UNIT_ROUNDOFF)
    np.testing.assert_allclose(mac(np.eye(3), np.eye(3)[:, :2]), np.eye(3)[:, :2], atol=ATOL_UNIT_ROUNDOFF)


def test_mac_is_invariant_to_complex_scaling():
    rng = np.random.default_rng(2)
    a = rng.standard_normal((8, 3)) + 1j * rng.standard_normal((8, 3))
    b = rng.standard_normal((8, 4))
    scaled = mac(a * np.array([0.3 - 2j, -5.0, 1j]), b * np.array([-2.0, 7.0, 0.01, 1.0]))
    np.testing.assert_allclose(scaled, mac(a, b), rtol=1e-12)
    assert np.all((mac(a, b) >= 0) & (mac(a, b) <= 1))
    with pytest.raises(InputError, match=r"^b: expected shapes on the same 8 DOFs as a, got shape \(7, 4\)"):
        mac(a, b[:7])
    with pytest.raises(InputError, match=r"^a: expected shapes that are not zero, got a zero shape in column 1"):
        mac(np.column_stack([a[:, 0], np.zeros(8)]), b)


def test_pairing_follows_shapes_not_order():
    shapes = orthonormal(12, 3)
    model = shapes[:, ::-1] + 0.05 * orthonormal(12, 3, seed=1)
    f_test, f_model = np.array([5.0, 7.0, 9.0]), np.array([9.2, 7.1, 4.9])
    assert pair_modes(mac(shapes, model), f_test, f_model) == ((0, 2), (1, 1), (2, 0))


def test_two_close_modes_pair_by_shape_and_ties_by_frequency():
    a = orthonormal(10, 2)
    theta = np.radians(30.0)
    rotated = np.column_stack([np.cos(theta) * a[:, 0] + np.sin(theta) * a[:, 1],
                               -np.sin(theta) * a[:, 0] + np.cos(theta) * a[:, 1]])
    f_test = np.array([10.0, 10.15])  # 1.5 % apart
    # The model's order of frequencies is the other way round: the shapes (MAC 0.75 against 0.25) decide.
    assert pair_modes(mac(a, rotated), f_test, np.array([10.2, 10.1])) == ((0, 0), (1, 1))
    # At 45 degrees every MAC is 0.5: the nearer frequency decides.
    theta = np.radians(45.0)
    even = np.column_stack([np.cos(theta) * a[:, 0] + np.sin(theta) * a[:, 1],
                            -np.sin(theta) * a[:, 0] + np.cos(theta) * a[:, 1]])
    np.testing.assert_allclose(mac(a, even), 0.5, atol=1e-12)
    assert pair_modes(mac(a, even), f_test, np.array([10.16, 10.01]), floor=0.3) == ((0, 1), (1, 0))


def test_verdict_limits_and_unpaired_modes():
    phi = orthonormal(12, 4)
    theta = np.arccos(np.sqrt(0.89))  # MAC cos^2 = 0.89 with mode 3's own shape
    model = phi.copy()
    model[:, 2] = np.cos(theta) * phi[:, 2] + np.sin(theta) * phi[:, 3]
    f_test = np.array([4.0, 6.0, 8.0])
    f_model = np.array([4.0 * 1.049, 6.0 * 0.948, 8.0, 11.0])
    c = correlate_modes(f_test, [0.02, 0.03, 0.04], phi[:, :3], f_model, [0.01] * 4, model)
    np.testing.assert_array_equal(c.pair_test, [0, 1, 2])
    np.testing.assert_array_equal(c.pair_model, [0, 1, 2])
    np.testing.assert_allclose(c.frequency_error_percent, [4.9, -5.2, 0.0], atol=1e-9)
    np.testing.assert_allclose(c.pair_mac, [1.0, 1.0, 0.89], atol=1e-12)
    assert not c.correlated
    assert c.reasons == (
        "test mode 2 (6 Hz) with model mode 2 (5.688 Hz): frequency error -5.20 % beyond +-5 %",
        "test mode 3 (8 Hz) with model mode 3 (8 Hz): MAC 0.890 below 0.9",
    )
    np.testing.assert_array_equal(c.pair_within, [True, False, False])  # the pairs the reasons name
    relaxed = correlate_modes(f_test, [0.02, 0.03, 0.04], phi[:, :3], f_model, [0.01] * 4, model,
                              max_frequency_error_percent=5.5, min_mac=0.85)
    assert relaxed.correlated and relaxed.reasons == () and relaxed.pair_within.all()
    # A test mode no model mode resembles stays unpaired, and the verdict says so.
    lone = correlate_modes([4.0, 9.5], [0.02, 0.02], np.column_stack([phi[:, 0], phi[:, 3]]), [4.0], [0.01],
                           phi[:, :1])
    assert lone.pair_test.tolist() == [0] and not lone.correlated
    assert lone.reasons == ("test mode 2 (9.5 Hz): no model mode with MAC >= 0.5",)


def test_correlation_table_numbers_modes_from_one():
    rows = orthonormal(9, 6, seed=3)
    shapes = np.eye(6)[:, :2]
    model = channel_shapes(rows, shapes)
    c = correlate_modes([3.0, 5.0], [0.02, 0.025], model * (1 + 1j), [3.06, 5.0], [0.01, 0.01], model,
                        body_test=shapes, body_model=shapes)
    text = correlation_table(c)
    cells = [[cell.strip() for cell in line.strip("|").split("|")] for line in text.splitlines()[:4]]
    assert cells[0] == ["test", "model", "f_test [Hz]", "f_model [Hz]", "error [%]", "MAC", "MAC 6-DOF",
                        "damping test", "damping model"]
    assert cells[2] == ["1", "1", "3", "3.06", "+2.00", "1.000", "1.000", "0.0200", "0.0100"]
    assert cells[3] == ["2", "2", "5", "5", "+0.00", "1.000", "1.000", "0.0250", "0.0100"]
    lines = text.splitlines()
    assert lines[4] == "Correlated: every test mode paired, within 5 % and MAC >= 0.9."
