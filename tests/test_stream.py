"""A results file written window by window holds exactly what the same run written at once holds."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sixdof.analysis.compare import compare, merge_agreements
from sixdof.analysis.direct import SimulationSettings, simulate
from sixdof.analysis.mountcheck import mount_check
from sixdof.analysis.response import mount_forces, points_motion
from sixdof.analysis.statics import try_gravity_statics
from sixdof.analysis.superposition import superpose
from sixdof.io.scenario import load_scenario, parse_scenario
from sixdof.io.store import load_tree, write_results
from sixdof.io.stream import ResultsStream
from sixdof.results import RunResults, envelope_samples, time_slice

SCENARIOS = Path(__file__).parents[1] / "scenarios"


@pytest.fixture(scope="module")
def run():
    scenario = load_scenario(SCENARIOS / "bridge_beam_traffic.toml")
    system = scenario.system
    settings = SimulationSettings(duration=0.5, sample_rate_hz=200.0)
    response = simulate(system, scenario.excitation, settings)
    statics = try_gravity_statics(system, scenario.statics.gravity, scenario.statics.direction)[0]
    forces = mount_forces(system, response)
    modal = superpose(system, scenario.excitation, response.t)
    return RunResults(name=scenario.name, system=system, modes=system.modes, statics=statics, response=response,
                      mount_forces=forces, mount_check=mount_check(system, forces, response.t, statics),
                      points=points_motion(response, {"end": [0.0, 20.0, 0.0]}), superposition=modal,
                      agreement=compare(response, modal))


@pytest.mark.slow  # the run it reads: 2 s on the 2-core machine
def test_windows_append_to_the_same_file(run, tmp_path):
    whole = write_results(tmp_path / "whole.h5", run, created_utc="then")
    n = run.response.t.size
    with ResultsStream(tmp_path / "streamed.h5", created_utc="then") as stream:
        for lo, hi in ((0, 30), (30, 31), (31, n)):
            stream.append(time_slice(run, slice(lo, hi)))
        stream.finish(run)
    streamed = load_tree(tmp_path / "streamed.h5")
    assert set(streamed.datasets) == set(whole.datasets)
    for path, dataset in whole.datasets.items():
        other = streamed[path]
        assert (other.units, other.dims) == (dataset.units, dataset.dims), path
        np.testing.assert_array_equal(other.data, dataset.data, err_msg=path)
        assert set(other.attrs) == set(dataset.attrs), path
    assert set(streamed.attrs) == set(whole.attrs)
    for group, attrs in whole.attrs.items():
        assert set(streamed.attrs[group]) == set(attrs), group
        for key, value in attrs.items():
            np.testing.assert_array_equal(streamed.attrs[group][key], value, err_msg=f"{group}: {key}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["streamed.h5", "whole.h5"]  # no temporary file left


@pytest.mark.slow  # the run it reads: 2 s on the 2-core machine
def test_an_unfinished_stream_leaves_nothing(run, tmp_path):
    (tmp_path / "results.h5").write_bytes(b"before")
    with pytest.raises(RuntimeError), ResultsStream(tmp_path / "results.h5") as stream:
        stream.append(time_slice(run, slice(0, 10)))
        raise RuntimeError("interrupted")
    assert [p.name for p in tmp_path.iterdir()] == ["results.h5"]
    assert (tmp_path / "results.h5").read_bytes() == b"before"


@pytest.mark.slow  # the run it reads: 2 s on the 2-core machine
def test_window_agreements_merge_to_the_whole_run_agreement(run):
    parts = (slice(0, 7), slice(7, 50), slice(50, None))
    merged = merge_agreements([compare(run.response.q[p], run.superposition.q[p]) for p in parts])
    whole = run.agreement
    np.testing.assert_array_equal(merged.per_dof, whole.per_dof)
    assert (merged.worst_dof, merged.worst, merged.quiet) == (whole.worst_dof, whole.worst, whole.quiet)


def test_window_envelopes_hold_every_bin_extreme_of_the_whole_run():
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 10.0, 5001)
    series = np.column_stack([np.sin(7 * t) + 0.1 * rng.standard_normal(t.size), np.zeros_like(t), t])
    bins = 40
    whole = envelope_samples(t, series, 0.0, 10.0, bins)
    parts = [(0, 1234), (1234, 1300), (1300, 5001)]
    windows = np.concatenate([lo + envelope_samples(t[lo:hi], series[lo:hi], 0.0, 10.0, bins) for lo, hi in parts])
    assert len(whole) <= 2 * bins * 3 + 2 and len(np.unique(windows)) <= len(whole) + 2 * 2 * 3 * 2 + 4
    edges = np.minimum((t / 10.0 * bins).astype(int), bins - 1)
    for kept in (whole, windows):
        for b in range(bins):
            inside = edges == b
            chosen = inside[kept]
            for column in series.T:
                assert column[kept][chosen].max() == column[inside].max()
                assert column[kept][chosen].min() == column[inside].min()
    assert len(envelope_samples(t, np.zeros((t.size, 1)), 0.0, 10.0, bins)) <= bins + 2  # flat: one per bin


@pytest.mark.long  # ~16 CPU s
def test_a_long_run_streams_its_windows_and_keeps_only_what_its_figures_draw(tmp_path, monkeypatch):
    from sixdof.workflows import run as workflows
    from sixdof.workflows import time_response
    from sixdof.workflows.run import run_scenario

    text = (SCENARIOS / "bridge_beam_traffic.toml").read_text()
    scenario = parse_scenario(text.replace("duration = 20.0", "duration = 1.5"), "traffic.toml")
    assert scenario.simulation.samples == 1501
    whole, whole_folder = run_scenario(scenario, tmp_path / "whole", progress=False)
    monkeypatch.setattr(workflows, "MEMORY_SAMPLES", 1000)
    monkeypatch.setattr(time_response, "ENVELOPE_BINS", 100)
    monkeypatch.setattr(time_response, "LONG_RUN_WINDOW", 512)
    long, long_folder = run_scenario(scenario, tmp_path / "long", progress=False)
    stored, reference = (load_tree(folder / "results.h5") for folder in (long_folder, whole_folder))
    assert stored.attrs["time"]["solver_num_windows"] == 3 and reference.attrs["time"]["solver_num_windows"] == 1
    q, q_whole = stored.array("time/q"), reference.array("time/q")
    np.testing.assert_array_equal(stored.array("time/t"), reference.array("time/t"))
    assert np.all(np.max(np.abs(q - q_whole), axis=0) <= 1e-7 * np.max(np.abs(q_whole), axis=0))
    # The superposition continues window to window on its own: its agreement with the file's direct solve,
    # recomputed from every stored sample, is the one stored.
    agreement = compare(q, stored.array("time/superposition/q"), length=long.agreement.length)
    np.testing.assert_array_equal(stored.attrs["time/superposition"]["agreement_per_dof"], agreement.per_dof)
    assert agreement.worst < 1e-6
    # In memory only the samples the figures draw, holding every peak of the run exactly.
    assert 2 < long.response.t.size < 1501 and set(long.response.t) <= set(stored.array("time/t"))
    np.testing.assert_array_equal(np.max(np.abs(long.response.q), axis=0), np.max(np.abs(q), axis=0))
    np.testing.assert_array_equal(long.mount_check.peak_force, stored.array("time/mount_check/peak_force"))
    assert sorted(p.name for p in long_folder.glob("*.png")) == sorted(p.name for p in whole_folder.glob("*.png"))
    assert (long_folder / "summary.md").read_text().count("|") == (whole_folder / "summary.md").read_text().count("|")


def test_a_run_whose_file_cannot_fit_on_the_disk_is_refused_before_it_starts(tmp_path):
    from sixdof.workflows.run import run_scenario

    text = (SCENARIOS / "bridge_beam_traffic.toml").read_text()
    # 9e8 samples (within the 1e9 a run may have), a file of about 1.1 TB: more than the disk holds.
    scenario = parse_scenario(text.replace("sample_rate_hz = 1000.0", "sample_rate_hz = 4.5e7"), "traffic.toml")
    with pytest.raises(OSError, match="No space left on device"):  # memory is bounded: windows go to the file
        run_scenario(scenario, tmp_path, progress=False)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow  # 2 s on the 2-core machine
def test_ctrl_c_stops_a_long_run_at_once_and_leaves_nothing(tmp_path, monkeypatch):
    """SIGINT is held back only while a file is written: a run interrupted while it computes stops in the window
    it is in, not after the whole run, and leaves no partial output."""
    import signal

    from sixdof.analysis import direct
    from sixdof.workflows import run as workflows
    from sixdof.workflows import time_response
    from sixdof.workflows.run import run_scenario

    text = (SCENARIOS / "bridge_beam_traffic.toml").read_text()
    scenario = parse_scenario(text.replace("duration = 20.0", "duration = 1.5"), "traffic.toml")
    monkeypatch.setattr(workflows, "MEMORY_SAMPLES", 1000)
    monkeypatch.setattr(time_response, "LONG_RUN_WINDOW", 256)  # 6 windows
    solved = []

    def interrupted_after_the_first(*args, **kwargs):
        for window in windows(*args, **kwargs):
            solved.append(window)
            if len(solved) == 1:
                signal.raise_signal(signal.SIGINT)  # as Ctrl-C: the handler runs at the next bytecode
            yield window

    windows = direct.simulate_windows
    monkeypatch.setattr(time_response, "simulate_windows", interrupted_after_the_first)
    # A test runner started in the background inherits SIGINT ignored; a user's terminal raises it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            run_scenario(scenario, tmp_path, progress=False)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert len(solved) == 1
    assert list(tmp_path.iterdir()) == []


FILLED = r"""
import resource, sys
from sixdof.io import output, store, stream

for module in (output, store, stream):  # the size estimates fall short of the real file: HDF5 meets the limit
    module.check_room = lambda path, nbytes: None
if __name__ == "__main__":
    resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[2]), resource.RLIM_INFINITY))
    from sixdof.cli import main
    sys.exit(main(["run", "scenarios/bridge_beam_traffic.toml", "--out", sys.argv[1], "--quiet"]))
"""


@pytest.mark.long  # ~12 CPU s
def test_a_disk_that_fills_while_a_long_run_streams_ends_in_one_line_and_leaves_nothing(tmp_path):
    """The file-size limit (``ulimit -f``) met in the middle of the streamed results.h5 (28 MB), as a full disk
    is: HDF5's write fails in its caches; the run ends with exit 74, one line naming the file, no staging folder,
    and the folders made for --out removed again (a real full disk, a small tmpfs, gives the same)."""
    import subprocess
    import sys

    script = tmp_path / "filled.py"
    script.write_text(FILLED)
    out = tmp_path / "out" / "deeper"
    done = subprocess.run([sys.executable, str(script), str(out), str(10_000_000)], capture_output=True, text=True,
                          timeout=300, cwd=Path(__file__).parents[1])
    assert done.returncode == 74, done.stderr
    assert done.stderr.count("\n") <= 1, done.stderr
    assert "could not write " in done.stderr and "results.h5: File too large; results already in place are " \
        "unchanged" in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["filled.py"]
