"""One run, computed without files and saved apart: ``sixdof.run``, ``sixdof.save`` and what loading leaves to them."""

import os
import re
from pathlib import Path

import numpy as np
import pytest

import sixdof
from html_pages import check_report
from sixdof.io.scenario import NotPrepared
from sixdof.io.store import load_tree
from sixdof.io.stream import ResultsStream
from test_run import SCENARIO

SCENARIOS = Path(sixdof.__file__).parent / "scenarios"


def _listing(folder: Path) -> dict:
    """Every file under ``folder`` with its size."""
    return {str(p.relative_to(folder)): p.stat().st_size for p in folder.rglob("*")}


def _same_datasets(a: Path, b: Path) -> None:
    """Two results files hold the same datasets with the same values, and the same attributes but the time they
    were written, the command line and the wall times."""
    one, two = load_tree(a), load_tree(b)
    assert set(one.datasets) == set(two.datasets)
    for path, dataset in one.datasets.items():
        np.testing.assert_array_equal(dataset.data, two.datasets[path].data, err_msg=path)
    def skipped(key: str) -> bool:
        return key in ("created_utc", "command_line") or "wall_time" in key

    assert set(one.attrs) == set(two.attrs)
    for group, attrs in one.attrs.items():
        kept = {k: v for k, v in attrs.items() if not skipped(k)}
        assert kept.keys() == {k for k in two.attrs[group] if not skipped(k)}, group
        for key, value in kept.items():
            np.testing.assert_array_equal(value, two.attrs[group][key], err_msg=f"{group}@{key}")


@pytest.mark.slow  # 8 s on the 2-core machine
def test_run_writes_nothing_and_save_writes_what_run_scenario_writes(tmp_path, monkeypatch):
    scenario = sixdof.parse_scenario(SCENARIO, "small.toml")
    monkeypatch.chdir(tmp_path)
    results = sixdof.run(scenario)
    assert _listing(tmp_path) == {}  # nothing written, anywhere it could have been
    assert isinstance(results, sixdof.RunResults) and results.agreement.ok and results.response.t.size == 601
    assert results.frf is not None and results.mount_check is not None and "top" in results.points
    folder = sixdof.save(results, tmp_path / "saved")
    assert folder == tmp_path / "saved" / "small"
    _, written = sixdof.run_scenario(scenario, tmp_path / "direct", progress=False)
    assert sorted(p.name for p in folder.iterdir()) == sorted(p.name for p in written.iterdir())
    _same_datasets(folder / "results.h5", written / "results.h5")
    assert (folder / "summary.md").read_text() == (written / "summary.md").read_text()


def test_run_takes_a_path_and_reports_its_warnings(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SCENARIO.replace("sample_rate_hz = 1000.0", "sample_rate_hz = 100.0"))
    with pytest.warns(UserWarning, match="samples per period"):
        results = sixdof.run(path)
    assert any("samples per period" in note for note in results.notes)
    assert results.scenario.path == path


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_run_too_long_for_memory_needs_a_sink_and_streams_into_it(tmp_path, monkeypatch):
    from sixdof.workflows import run as run_module
    from sixdof.workflows import time_response

    text = (SCENARIOS / "bridge_beam_traffic.toml").read_text().replace("duration = 20.0", "duration = 1.5")
    scenario = sixdof.parse_scenario(text, "traffic.toml", base_dir=SCENARIOS)
    monkeypatch.setattr(run_module, "MEMORY_SAMPLES", 1000)  # as if this run's 1501 samples were too many to hold
    monkeypatch.setattr(time_response, "LONG_RUN_WINDOW", 512)
    monkeypatch.setattr(time_response, "ENVELOPE_BINS", 100)
    with pytest.raises(sixdof.InputError, match=r"sink: expected a sink for a run of more than 1,000 output samples"):
        sixdof.run(scenario)
    with ResultsStream(tmp_path / "stream" / "results.h5") as sink:
        results = sixdof.run(scenario, sink=sink)
    # In memory only what the figures draw; every sample in the sink's file.
    stored = load_tree(sink.path)
    assert stored.array("time/t").size == scenario.simulation.samples > results.response.t.size
    with pytest.raises(sixdof.InputError, match=r"sink: expected the sink the run streamed into .* got [0-9,]+ of 1,501 samples and no sink"):
        sixdof.save(results, tmp_path / "out")  # the results alone are the figures' samples: refused
    folder = sixdof.save(results, tmp_path / "out", sink=sink)
    assert (folder / "results.h5").is_file() and sink.path.is_file()  # the user's file stays theirs
    assert load_tree(folder / "results.h5").array("time/t").size == scenario.simulation.samples
    assert "## Time response" in (folder / "summary.md").read_text()


def test_a_sink_without_a_simulation_and_results_without_a_scenario_are_refused(tmp_path):
    scenario = sixdof.parse_scenario(SCENARIO.split("[simulation]")[0], "small.toml")
    with pytest.raises(sixdof.InputError, match=r"sink: expected a scenario with a \[simulation\]"):
        sixdof.run(scenario, sink=object())
    folder = sixdof.save(sixdof.run(scenario), tmp_path)
    with pytest.raises(sixdof.InputError, match=r"results: expected the RunResults of sixdof.run"):
        sixdof.save(sixdof.load_results(folder / "results.h5"), tmp_path / "again")
    assert not (tmp_path / "again").exists()


def test_loading_a_scenario_computes_nothing(monkeypatch):
    """Fits, statics and resonance checks wait for the workflow: a loaded scenario's model is as given."""
    from sixdof.model import viscoelastic
    from sixdof.workflows import prepare as prepare_module

    def computed(*args, **kwargs):
        raise AssertionError("computed while loading")

    for module, name in [(prepare_module, "fit_maxwell"), (prepare_module, "gravity_statics"),
                         (prepare_module, "check_resonances"), (viscoelastic, "causal_loss_factors")]:
        monkeypatch.setattr(module, name, computed)
    for name in ("equipment_elastomer", "engine_inclined_mounts", "equipment_snubbed_shock", "bridge_beam_uplift"):
        scenario = sixdof.load_scenario(SCENARIOS / f"{name}.toml")
        assert scenario.model is None and scenario.needs_preparing
        with pytest.raises(NotPrepared, match=r"call sixdof.prepare\(scenario\)"):
            scenario.system  # noqa: B018
    monkeypatch.undo()
    prepared = sixdof.prepare(SCENARIOS / "equipment_elastomer.toml")
    assert prepared.viscoelastic and prepared.system.maxwell
    assert sixdof.prepare(prepared) is prepared


def test_a_scenario_that_needs_no_preparing_reads_as_given():
    scenario = sixdof.parse_scenario(SCENARIO, "small.toml")
    assert not scenario.needs_preparing
    assert scenario.system is scenario.given_system is scenario.time_system and scenario.viscoelastic == ()


def test_preparing_errors_name_the_file_and_field(tmp_path):
    path = tmp_path / "tilt.toml"
    path.write_text(SCENARIO.replace("[simulation]", "[statics]\ngeometric_stiffness = true\n\n[simulation]")
                    .replace("mass = 300.0", "mass = 3e6"))
    scenario = sixdof.load_scenario(path)  # read and checked: the tipping is found by preparing it
    with pytest.raises(sixdof.ScenarioError, match=rf"{path}: statics.geometric_stiffness: expected false, or"):
        sixdof.prepare(scenario)
    assert os.listdir(tmp_path) == ["tilt.toml"]


def _same_folder(a: Path, b: Path, results: str) -> None:
    """Two folders hold the same files: the results file's datasets alike, every other file the same bytes (the
    text's wall times aside)."""
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    _same_datasets(a / results, b / results)
    timed = re.compile(rb"in [0-9.e+-]+ s\b")
    for name in names:
        if name != results:
            assert timed.sub(b"", (a / name).read_bytes()) == timed.sub(b"", (b / name).read_bytes()), name


@pytest.mark.long  # over 10 s on the 2-core machine
def test_a_validation_computed_then_saved_is_what_validate_scenario_writes(tmp_path):
    from sixdof.workflows.validate import save_validation, validate_scenario, validation_run

    scenario = sixdof.parse_scenario(SCENARIO.split("[[loads]]")[0], "small.toml")
    results = validation_run(scenario)
    assert results.validation.verdict == "PASS" and results.modes is not None
    folder = save_validation(results, tmp_path / "saved")
    report, written = validate_scenario(scenario, tmp_path / "direct")
    assert folder.name == written.name == "small_validation" and report.verdict == results.validation.verdict
    _same_folder(folder, written, "results.h5")


@pytest.mark.slow  # 3 s on the 2-core machine
def test_a_sweep_computed_then_saved_is_what_sweep_scenario_writes(tmp_path):
    from sixdof.io.sweep import parse_sweep_spec
    from sixdof.workflows.sweep import save_sweep, sweep, sweep_scenario

    scenario = sixdof.parse_scenario(SCENARIO, "small.toml")
    spec = parse_sweep_spec('count = 6\nseed = 2\ncross_check = 1\n[[vary]]\nparameter = "stiffness"\n'
                            'distribution = "uniform"\nlow = 0.8\nhigh = 1.2\n')
    result = sweep(scenario, spec)
    assert result.count == 6 and result.cross_check is not None
    folder = save_sweep(result, scenario, tmp_path / "saved")
    merged, written = sweep_scenario(scenario, spec, tmp_path / "direct")
    assert merged.count == 0 and merged.resumed == 0 and merged.cross_check.worst == result.cross_check.worst
    names = sorted(p.name for p in folder.iterdir())
    assert names == sorted(p.name for p in written.iterdir()) and "sweep.h5" in names
    one, two = load_tree(folder / "sweep.h5"), load_tree(written / "sweep.h5")
    assert set(one.datasets) == set(two.datasets)
    for path, dataset in one.datasets.items():
        np.testing.assert_array_equal(dataset.data, two.datasets[path].data, err_msg=path)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_design_computed_then_saved_is_what_optimize_scenario_writes(tmp_path):
    from sixdof.workflows.optimize import DESIGN_FILES, design_run, optimize_scenario, save_design
    from test_optimize import THETA0, _v_pair

    scenario = sixdof.parse_scenario(_v_pair(THETA0, """
[design]
starts = 2
samples = 200
[[design.target]]
kind = "frequency"
dof = "z"
f_hz = [6.0, 9.0]
[[design.vary]]
parameter = "stiffness"
axes = ["w"]
bounds = [0.5, 2.0]
"""), "v.toml")
    run = design_run(scenario, progress=False, log=lambda text: None)
    assert run.system is not run.scenario.system and run.result.x.size == 2
    folder = save_design(run, tmp_path / "saved")
    assert sorted(p.name for p in folder.iterdir() if not p.name.startswith(".")) == sorted(DESIGN_FILES)
    check_report(folder)  # self-contained, both figures in it
    again, written = optimize_scenario(scenario, tmp_path / "direct", progress=False, log=lambda text: None)
    assert again.met == run.met and (folder / "optimized.toml").read_text() == (written / "optimized.toml").read_text()
    assert (folder / "summary.md").read_text() == (written / "summary.md").read_text()
