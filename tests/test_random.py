"""Random vibration from the FRF matrix (issue 19, point 1), against closed forms integrated independently
(scipy.integrate.quad of the single-DOF transfer functions) and Miles' equation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from sixdof import InputError
from sixdof.analysis.random import PSD, RandomInput, random_response
from systems import sdof

M, K, C = 120.0, 4e5, 200.0  # z alone is restrained: m z'' + c z' + k z
F_N = np.sqrt(K / M) / (2 * np.pi)
G = 9.80665
#: Simpson on the log grid (20 points per half-power band, breakpoint to breakpoint) against adaptive
#: quadrature: measured up to 9.2e-7 (trapezoids: 3.6e-5, and 5e-4 on a flank of a resonance).
RTOL_GRID = 1e-5


def _rms(transfer, psd: PSD) -> float:
    """RMS of ``transfer(f) * input`` by adaptive quadrature of |transfer|^2 PSD over the PSD's band."""
    # Relative tolerance only: the integrands are ~1e-11 (m^2/Hz), far below quad's default absolute one.
    value, _ = quad(lambda f: abs(transfer(f)) ** 2 * float(psd(f)), psd.f_hz[0], psd.f_hz[-1],
                    points=[F_N, *psd.f_hz[1:-1]], limit=1000, epsabs=0.0, epsrel=1e-10)
    return float(np.sqrt(value))


def _w(f):
    return 2 * np.pi * f


def test_a_base_excited_oscillator_matches_its_closed_form_and_miles():
    psd = PSD(f_hz=[2.0, 20.0, 100.0], value=[0.02, 0.04, 0.01], unit="g^2/Hz")
    random = RandomInput(input="ground_acceleration", direction="z", psd=psd)
    response = random_response(sdof(M, K, C), random, {"top": [0.1, 0.0, 0.3]})
    # Absolute acceleration per unit base acceleration, (k + i w c) / (k - m w^2 + i w c).
    base = lambda f: (K + 1j * _w(f) * C) / (K - M * _w(f) ** 2 + 1j * _w(f) * C)  # noqa: E731
    assert response.qdd_rms[2] == pytest.approx(_rms(base, psd), rel=RTOL_GRID)
    assert response.point_acceleration_rms[0, 2] == pytest.approx(_rms(base, psd), rel=RTOL_GRID)
    # The mount's force: its stiffness and dashpot times the deflection relative to the ground.
    force = lambda f: (K + 1j * _w(f) * C) * M / (K - M * _w(f) ** 2 + 1j * _w(f) * C)  # noqa: E731
    assert response.mount_force_rms[0, 2] == pytest.approx(_rms(force, psd), rel=RTOL_GRID)
    deflection = lambda f: M / (K - M * _w(f) ** 2 + 1j * _w(f) * C)  # noqa: E731
    assert response.mount_deflection_rms[0, 2] == pytest.approx(_rms(deflection, psd), rel=RTOL_GRID)
    # Miles: sqrt(pi/2 f_n Q S(f_n)), Q = 1/(2 zeta); the exact RMS is within 1 % of it here (light damping,
    # a PSD varying slowly across the resonance).
    zeta = C / (2 * np.sqrt(K * M))
    z_mode = response.dominant_dof.index("z")
    miles = np.sqrt(np.pi / 2 * F_N / (2 * zeta) * float(psd(F_N)))
    assert response.miles_rms[z_mode] == pytest.approx(miles, rel=1e-12)
    assert response.exact_rms[z_mode] == pytest.approx(miles, rel=0.01)
    assert np.all(np.isnan(np.delete(response.miles_rms, z_mode)))  # the rigid-body modes have none


@pytest.mark.parametrize("psd", [
    PSD(f_hz=[20.0, 80.0, 350.0, 2000.0], value=[0.01, 0.04, 0.04, 0.007], unit="g^2/Hz"),
    PSD(f_hz=[10.0, 1000.0], value=[0.01, 0.01], unit="g^2/Hz"),
])
def test_the_grid_holds_the_whole_band(psd):
    """exp(log(20)) is a rounding below 20 Hz, where the PSD is zero, and exp(log(10)) a rounding above 10 Hz,
    beside the breakpoint (Simpson's weights then err by 2.9e-4): the grid runs from breakpoint to breakpoint,
    exactly, an even number of steps each."""
    from sixdof.analysis.random import frequency_grid

    grid = frequency_grid(sdof(M, K, C), psd)
    assert grid[0] == psd.f_hz[0] and grid[-1] == psd.f_hz[-1]
    at = np.searchsorted(grid, psd.f_hz)
    np.testing.assert_array_equal(grid[at], psd.f_hz)
    assert np.all(at % 2 == 0) and np.min(np.diff(np.log(grid))) > 0.5 * np.max(np.diff(np.log(grid)))
    response = random_response(sdof(M, K, C), RandomInput(input="ground_acceleration", direction="z", psd=psd))
    base = lambda f: (K + 1j * _w(f) * C) / (K - M * _w(f) ** 2 + 1j * _w(f) * C)  # noqa: E731
    assert response.qdd_rms[2] == pytest.approx(_rms(base, psd), rel=RTOL_GRID)


def test_a_force_on_the_oscillator_with_a_loss_factor_matches_its_closed_form():
    eta = 0.1
    psd = PSD(f_hz=[1.0, 200.0], value=[4.0, 4.0], unit="N^2/Hz")
    random = RandomInput(input="force", direction=[0.0, 0.0, 1.0], point=[0.0, 0.0, 0.0], psd=psd)
    response = random_response(sdof(M, K, C, eta=eta), random)
    receptance = lambda f: 1 / (K * (1 + 1j * eta) - M * _w(f) ** 2 + 1j * _w(f) * C)  # noqa: E731
    assert response.q_rms[2] == pytest.approx(_rms(receptance, psd), rel=RTOL_GRID)
    acceleration = lambda f: -_w(f) ** 2 * receptance(f)  # noqa: E731
    assert response.qdd_rms[2] == pytest.approx(_rms(acceleration, psd), rel=RTOL_GRID)
    assert response.input_rms == pytest.approx(np.sqrt(4.0 * 199.0), rel=1e-12)


def test_the_psd_is_log_log_between_breakpoints_and_its_rms_exact():
    psd = PSD(f_hz=[10.0, 40.0, 200.0], value=[0.01, 0.04, 0.04], unit="g^2/Hz")
    assert float(psd(20.0)) == pytest.approx(0.02 * G**2, rel=1e-12)  # log-log slope 1 from 10 to 40 Hz: S ~ f
    assert float(psd(5.0)) == 0.0 and float(psd(300.0)) == 0.0
    reference = quad(lambda f: float(psd(f)), 10.0, 200.0, points=[40.0], limit=200, epsabs=0.0, epsrel=1e-12)[0]
    assert psd.rms == pytest.approx(np.sqrt(reference), rel=1e-9)
    flat = PSD(f_hz=[20.0, 2000.0], value=[0.04, 0.04], unit="g^2/Hz")
    assert flat.rms / G == pytest.approx(np.sqrt(0.04 * 1980.0), rel=1e-12)  # grms = sqrt(S (f2 - f1))


@pytest.mark.parametrize("slope", [-1.0, -1.0 + 9e-6, -1.0 - 3e-9, -1.0 + 1e-13])
def test_the_rms_of_a_segment_near_the_slope_minus_one_is_exact(slope, recwarn):
    """At slope -1 the integral is s0 f0 ln(f1 / f0); near it, the closed form s0 f0 ((f1/f0)^(b+1) - 1) / (b + 1)
    must not be switched for that limit within a tolerance (which was off by 1.2e-5 at b = -1 + 9e-6)."""
    f0, f1, s0 = 10.0, 2000.0, 0.01
    psd = PSD(f_hz=[f0, f1], value=[s0, s0 * (f1 / f0) ** slope], unit="(m/s^2)^2/Hz")
    reference = quad(lambda f: s0 * (f / f0) ** slope, f0, f1, limit=200, epsabs=0.0, epsrel=1e-13)[0]
    assert psd.rms**2 == pytest.approx(reference, rel=1e-12)
    assert not recwarn.list  # no division by zero on the way


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"f_hz": [20.0, 10.0], "value": [1.0, 1.0]}, r"f_hz: expected increasing frequencies \[Hz\] > 0, at least 2"),
    ({"f_hz": [20.0], "value": [1.0]}, r"f_hz: expected increasing frequencies"),
    ({"f_hz": [10.0, 20.0], "value": [1.0, -1.0]}, r"value: expected 2 PSD values > 0"),
    ({"f_hz": [10.0, 20.0], "value": [1.0, 1.0], "unit": "g2/Hz"}, r"unit: expected 'g\^2/Hz'"),
])
def test_bad_psd_input_is_one_clear_error(kwargs, message):
    with pytest.raises(InputError, match=message):
        PSD(**kwargs)


def test_the_input_and_its_psd_unit_must_agree():
    g_psd = PSD(f_hz=[10.0, 20.0], value=[1.0, 1.0], unit="g^2/Hz")
    with pytest.raises(InputError, match=r"psd\.unit: expected N\^2/Hz for a force"):
        RandomInput(input="force", point=[0.0, 0.0, 0.0], psd=g_psd)
    with pytest.raises(InputError, match=r"point: expected the force's point"):
        RandomInput(input="force", psd=PSD(f_hz=[10.0, 20.0], value=[1.0, 1.0], unit="N^2/Hz"))
    with pytest.raises(InputError, match=r"input: expected 'ground_acceleration' or 'force'"):
        RandomInput(input="pressure", psd=g_psd)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_a_run_with_a_random_table_stores_prints_and_draws_it(tmp_path, capsys):
    from sixdof import load_results
    from sixdof.cli import main
    from sixdof.io.store import load_tree

    text = Path("scenarios/machine_unbalance.toml").read_text() + """
[random]
input = "ground_acceleration"
direction = "z"
psd = { f_hz = [5.0, 20.0, 200.0, 500.0], value = [0.001, 0.01, 0.01, 0.002], unit = "g^2/Hz" }
"""
    path = tmp_path / "machine.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "Random vibration:" in out and "Miles' equation per mode" in out
    folder = tmp_path / "machine_unbalance"
    assert (folder / "random.png").exists() and "## Random vibration" in (folder / "summary.md").read_text()
    tree = load_tree(folder / "results.h5")
    for name in ("f_hz", "input_psd", "q_psd", "q_rms", "point_acceleration_rms", "mount_force_rms"):
        assert f"random/{name}" in tree.datasets, name
    assert tree["random/q_psd"].dims == ("f_hz", "dof") and tree["random/mount_force_rms"].dims == ("mount",
                                                                                                    "mount_axis")
    back = load_results(folder / "results.h5").random
    assert back.points == ("top_corner",) and back.mounts[0] == "front_left"
    assert back.input_rms == pytest.approx(PSD(f_hz=[5.0, 20.0, 200.0, 500.0], value=[0.001, 0.01, 0.01, 0.002]).rms)


@pytest.mark.parametrize(("table", "message"), [
    ('input = "ground_acceleration"\npsd = { f_hz = [5.0], value = [0.01] }',
     r"random\.psd\.f_hz: expected increasing frequencies"),
    ('input = "force"\ndirection = "z"\npsd = { f_hz = [5.0, 50.0], value = [1.0, 1.0], unit = "N^2/Hz" }',
     r"random\.point: expected the force's point"),
    ('input = "ground_acceleration"\npsd = { f_hz = [5.0, 50.0], value = [0.01, 0.01], unit = "g^2/Hz" }\n'
     'colour = "red"', r"random\.colour: expected one of the keys direction, input, point, psd"),
])
def test_bad_random_tables_are_one_clear_error(table, message):
    from sixdof import parse_scenario

    text = Path("scenarios/machine_unbalance.toml").read_text() + f"\n[random]\n{table}\n"
    with pytest.raises(InputError, match=message):
        parse_scenario(text)
