"""``sixdof correlate``: the bundled tap test (synthesized from a known as-built truth by
scripts/synthesize_tap_test.py) identified without the model, correlated, and updated back to the truth; time
histories through H1; what the command writes and prints."""

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from html_pages import check_report, section
from sixdof.io.scenario import load_scenario, parse_scenario
from sixdof.io.store import load_results
from sixdof.io.testfile import load_test
from sixdof.workflows.correlate import correlation_json, correlation_run, save_correlation

SCENARIOS = Path(__file__).resolve().parents[1] / "src" / "sixdof" / "scenarios"
SCENARIO, TEST = SCENARIOS / "machine_tap_test.toml", SCENARIOS / "machine_tap_test.uff"
TRUTH = json.loads((SCENARIOS / "machine_tap_test.truth.json").read_text())
#: Identified against the truth's frequencies at the file's 1 % noise: measured within 0.01 %.
RTOL_TEST_FREQUENCY = 1e-3
#: Identified against the truth's damping ratios: measured within 1.5 % (0.0203 for 0.0200, the mode the
#: 0.1 Hz lines resolve worst).
RTOL_TEST_DAMPING = 0.05


@pytest.fixture(scope="module")
def run():
    return correlation_run(SCENARIO, TEST)


def test_the_tap_test_s_modes_come_from_the_data_alone(run):
    """Six rigid-body modes at the truth's frequencies and damping, and the body's torsion at three times the
    highest one found and set apart: it is not rigid-body motion."""
    found = run.identification.modes
    assert run.rigid.tolist() == [True] * 6 + [False]
    np.testing.assert_allclose(found.frequency_hz[:6], TRUTH["truth_frequency_hz"], rtol=RTOL_TEST_FREQUENCY)
    np.testing.assert_allclose(found.damping_ratio[:6], TRUTH["modal_damping"], rtol=RTOL_TEST_DAMPING)
    assert found.frequency_hz[6] == pytest.approx(TRUTH["flexible_mode"]["frequency_hz"], rel=RTOL_TEST_FREQUENCY)
    assert run.projection.residual[6] > 0.9 and np.all(run.projection.residual[:6] < 0.05)
    assert any("test mode 7 at 60.7" in note for note in run.notes)


def test_the_given_model_is_not_correlated_and_says_which_pairs_fail(run):
    """The as-built deviations move modes 4 to 6 beyond the scenario's 3 % and swap the rocking pair (MAC)."""
    c = run.correlation
    assert not c.correlated
    assert c.test_number.tolist() == [1, 2, 3, 4, 5, 6]
    assert (c.pair_test.tolist(), c.pair_model.tolist()) == ([0, 1, 2, 3, 4, 5], [0, 1, 2, 3, 5, 4])
    errors = 100 * (np.asarray(TRUTH["nominal_frequency_hz"])[[0, 1, 2, 3, 5, 4]]
                    - np.asarray(TRUTH["truth_frequency_hz"])) / np.asarray(TRUTH["truth_frequency_hz"])
    np.testing.assert_allclose(c.frequency_error_percent, errors, atol=0.02)
    assert [r.split(" (")[0] for r in c.reasons] == ["test mode 4", "test mode 5", "test mode 6"]
    document = correlation_json(run)
    assert [m["frequency_hz"] for m in document["test_modes"]] == pytest.approx(
        run.identification.modes.frequency_hz)
    assert document["pairs"][4] == {"test_mode": 5, "model_mode": 6, "mac": pytest.approx(c.mac[4, 5]),
                                    "frequency_error_percent": pytest.approx(c.frequency_error_percent[4]),
                                    "f_test_hz": pytest.approx(c.f_test[4]), "f_model_hz": pytest.approx(c.f_model[5])}
    assert document["correlated"] is False


def test_the_model_s_frf_on_the_channels_is_the_file_s_without_its_noise_and_deviations(run):
    """The model's accelerance on the test's channels equals the truth's where the deviations do not act: above
    the rigid modes and below the torsion the two FRFs differ by the deviations only, so at 1 Hz (mass line)
    the vertical tap's driving point agrees within the noise."""
    f = run.measured.f_hz
    assert run.model_H.shape == run.measured.H.shape == (991, 15, 3)
    k = np.searchsorted(f, 40.0)  # between the rigid modes and the torsion: mass-like, the deviations small
    ratio = np.abs(run.model_H[k]) / np.abs(run.measured.H[k])
    assert np.median(ratio) == pytest.approx(1.0, abs=0.05)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_saved_correlation_reads_back_as_it_was(run, tmp_path):
    folder = save_correlation(run, tmp_path)
    assert folder == tmp_path / "machine_tap_test_correlation"
    assert {"correlation.h5", "summary.md", "stability.png", "mac.png", "frf_overlay.png"} <= {
        p.name for p in folder.iterdir()}
    assert not (folder / "updated.toml").exists() and not (folder / "update_history.png").exists()
    back = load_results(folder / "correlation.h5")
    assert type(back) is type(run)
    np.testing.assert_array_equal(back.model_H, run.model_H)
    np.testing.assert_array_equal(back.correlation.mac, run.correlation.mac)
    np.testing.assert_array_equal(back.identification.modes.shapes, run.identification.modes.shapes)
    assert back.rigid.tolist() == run.rigid.tolist() and back.notes == run.notes
    summary = (folder / "summary.md").read_text()
    assert "NOT correlated" in summary and "![mac](mac.png)" in summary
    assert "Motion no rigid body makes, per node" in summary
    check_report(folder)  # self-contained, every figure in it
    cells = section(folder, "checks").texts["td"]
    assert cells[cells.index("model against the test") + 2] == "FAIL"


@pytest.mark.slow  # 3 s on the 2-core machine
def test_sixdof_plot_redraws_a_correlation_by_its_metadata_not_its_name(run, tmp_path):
    from sixdof.cli import main

    folder = save_correlation(run, tmp_path / "saved")
    renamed = tmp_path / "anything.h5"  # the kind is the file's own, not its name's
    renamed.write_bytes((folder / "correlation.h5").read_bytes())
    assert main(["plot", str(renamed), "--out", str(tmp_path / "redrawn")]) == 0
    names = ["frf_overlay.png", "mac.png", "stability.png"]
    assert sorted(p.name for p in (tmp_path / "redrawn").glob("*.png")) == names
    for name in names:  # what the correlation drew
        assert (tmp_path / "redrawn" / name).read_bytes() == (folder / name).read_bytes()


def _time_test(seconds: float, rate_hz: float, seed: int):
    """Time histories of the tap test's channels under three uncorrelated random forces at its references,
    computed exactly for forces linear between samples (the first-order-hold discretization of the nominal
    model's state-space form by scipy, a matrix exponential), not by sixdof's solvers. Not a zero-order hold:
    its half-sample delay acts on the response's state part and not on its direct (force) part of the
    accelerations, which turns the FRF's phase by up to 0.17 rad at 7 Hz, sampled at 128 Hz."""
    from scipy import signal

    scenario = load_scenario(SCENARIO)
    system, frf = scenario.system, load_test(TEST, scenario)
    M, C, K = system.M, system.C, system.K
    Minv = np.linalg.inv(M)
    loads, rows = frf.load_columns(), frf.response_rows()
    A = np.block([[np.zeros((6, 6)), np.eye(6)], [-Minv @ K, -Minv @ C]])
    B = np.vstack([np.zeros((6, 3)), Minv @ loads])
    out_C = rows @ np.hstack([-Minv @ K, -Minv @ C])  # accelerations on the channels
    out_D = rows @ Minv @ loads
    discrete = signal.cont2discrete((A, B, out_C, out_D), 1 / rate_hz, method="foh")
    n = int(seconds * rate_hz)
    forces = np.random.default_rng(seed).standard_normal((n, 3)) * 100.0
    _, y, _ = signal.dlsim(discrete[:4] + (1 / rate_hz,), forces)
    return scenario, dataclasses.replace(frf, kind="time", quantity="acceleration", f_hz=None, H=None,
                                         t=np.arange(n) / rate_hz, inputs=forces, responses=y,
                                         sample_rate_hz=rate_hz)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_time_histories_are_correlated_through_their_h1_estimate():
    """Random forces into the model itself: the H1 estimate (several references at once) identifies its modes
    (frequencies measured within 0.01 %, shapes at MAC 0.9999; the Hann window's leakage adds ~4 % to the
    damping ratios), the model correlates, and the estimate is kept with its averaging."""
    scenario, test = _time_test(600.0, 128.0, seed=5)
    run = correlation_run(scenario, test)
    assert run.estimate is not None and run.estimate.averages >= 8 and run.estimate.H.shape[1:] == (15, 3)
    assert run.measured.kind == "frf" and run.measured.quantity == "accelerance"
    assert run.correlation.correlated, run.correlation.reasons
    np.testing.assert_allclose(run.correlation.f_test, scenario.system.modes.frequency_hz, rtol=RTOL_TEST_FREQUENCY)
    assert np.min(run.correlation.pair_mac) > 0.999  # measured 0.9999
    assert np.min(run.estimate.coherence[(run.estimate.f_hz > 5) & (run.estimate.f_hz < 30)]) > 0.9


@pytest.mark.long  # the update compiles its JAX objective (~10-20 s on the 2-core machine)
def test_the_command_updates_the_model_back_to_the_as_built_truth(tmp_path):
    """``sixdof correlate --update --json``: the deviations the test was synthesized with come back (the
    stiffness factors within 1 %, the CG within 1 mm), every variable determined, the updated model correlated
    (exit 0), and ``updated.toml`` a scenario whose modes are the updated model's."""
    result = subprocess.run([sys.executable, "-m", "sixdof", "correlate", str(SCENARIO), "--test", str(TEST), "--update",
                             "--out", str(tmp_path), "--json", "--quiet"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    document = json.loads(result.stdout)
    found = {v["name"]: v for v in document["update"]["variables"]}
    truth = TRUTH["deviations"]
    assert found["stiffness w: front_left"]["updated"] == pytest.approx(truth["stiffness_factors"]["front_left"]["w"],
                                                                      abs=0.01)
    assert found["stiffness v: rear_right, rear_left"]["updated"] == pytest.approx(1.2, abs=0.01)
    for name in ("stiffness w: front_right", "stiffness w: rear_right", "stiffness w: rear_left",
                 "stiffness v: front_left, front_right"):
        assert found[name]["updated"] == pytest.approx(1.0, abs=0.01)
    offset = [found[f"cg_offset {axis}"]["updated"] for axis in "xyz"]
    np.testing.assert_allclose(offset, truth["cg_offset_m"], atol=1e-3)
    assert all(v["determined"] for v in document["update"]["variables"])
    assert all(abs(p["frequency_error_percent"]) < 0.05 and p["mac"] > 0.99 for p in document["update"]["pairs"])
    folder = tmp_path / "machine_tap_test_correlation"
    assert {"updated.toml", "update_history.png"} <= {p.name for p in folder.iterdir()}
    updated = parse_scenario((folder / "updated.toml").read_text(), source="updated.toml", base_dir=SCENARIOS)
    back = load_results(folder / "correlation.h5")
    np.testing.assert_allclose(updated.system.modes.frequency_hz, back.update.frequency_hz, rtol=1e-9)


@pytest.mark.slow  # 4 s on the 2-core machine
def test_the_command_says_not_correlated_with_status_3_and_writes_its_results(tmp_path):
    result = subprocess.run([sys.executable, "-m", "sixdof", "correlate", str(SCENARIO), "--test", str(TEST),
                             "--out", str(tmp_path), "--quiet"], capture_output=True, text=True)
    assert result.returncode == 3, result.stderr
    assert "NOT correlated" in result.stdout and "Wrote " in result.stdout
    assert result.stderr.splitlines()[-1].startswith("sixdof: the model and the test are NOT correlated")
    assert (tmp_path / "machine_tap_test_correlation" / "correlation.h5").exists()


@pytest.mark.slow  # 2 s on the 2-core machine
def test_update_without_an_update_table_is_refused_before_anything_is_computed(tmp_path):
    text = SCENARIO.read_text()
    bare = tmp_path / "bare.toml"
    bare.write_text(text[:text.index("[update]")])
    result = subprocess.run([sys.executable, "-m", "sixdof", "correlate", str(bare), "--test", str(TEST), "--update",
                             "--out", str(tmp_path / "out")], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr == (f"sixdof: error: {bare}: update: expected an [update] table saying what the update may vary "
                             "(its [[update.vary]] entries), got no [update] table\n")
    assert not (tmp_path / "out").exists()
