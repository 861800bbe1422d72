"""Sweeps in chunks, in this process and on a local two-worker Dask cluster (sixdof.workflows.sweep, sixdof.analysis.sweep,
sixdof.chunks, sixdof.workflows.tasks).

What must hold whatever runs the chunks: the same variants and bit-identical results (each chunk draws
with its own seed), every variant once in sweep.h5 even when a worker is killed mid-chunk, a resumed sweep
equal to an uninterrupted one, and the robustness study of a design likewise. The in-process sweep itself
is checked against the one-variant library calls (diffrax) and the unchunked batch.
"""

import contextlib
import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time

import h5py
import numpy as np
import pytest

import sixdof.analysis.sweep
import sixdof.workflows.sweep
from processes import assert_group_ends, living_in_group
from sixdof import InputError, parse_scenario, simulate
from sixdof.analysis.batch import run_batch, variant_system
from sixdof.chunks import chunk_rng, partition
from sixdof.io.scenario import load_scenario
from sixdof.io.sweep import load_sweep_spec, parse_sweep_spec
from sixdof.workflows.prepare import prepare
from sixdof.workflows.sweep import CHUNKS_SUFFIX, sweep, sweep_scenario, sweep_tables
from sixdof.workflows.tasks import task_runner
from systems import BRIDGE_LOADS_TOML, bridge_toml
from tolerances import RTOL_BATCH_DIRECT

distributed = pytest.importorskip("distributed")

SCENARIO = parse_scenario('name = "beam"\n' + bridge_toml("elastomer") + BRIDGE_LOADS_TOML + """[simulation]
duration = 4.0
sample_rate_hz = 500.0
""")
# Every bearing and axis its own stiffness factor, and a damping factor shared by all.
SPEC = parse_sweep_spec("""
count = 120
seed = 11
chunk_size = 25
cross_check = 4
[[vary]]
parameter = "stiffness"
distribution = "uniform"
low = 0.7
high = 1.3
independent = true
[[vary]]
parameter = "damping"
distribution = "normal"
mean = 1.0
std = 0.1
""")
PER_VARIANT = ("stiffness_factor", "damping_factor", "position_offset", "frequency_hz", "peak_q", "peak_qdd")


@pytest.fixture(scope="module")
def cluster():
    """The client of a local cluster of two single-threaded worker processes, as ``--workers 2`` starts."""
    with task_runner(workers=2) as runner:
        yield runner.client


@pytest.fixture(scope="module")
def in_process():
    return sweep(SCENARIO, SPEC)


def _file(path):
    with h5py.File(path, "r") as f:
        found = {}
        f.visititems(lambda name, node: found.setdefault(name, node[()]) if isinstance(node, h5py.Dataset) else None)
        return found, {key: dict(f[key].attrs) for key in ("sweep",)}


def _same_file(a, b):
    (data_a, attrs_a), (data_b, attrs_b) = _file(a), _file(b)
    assert sorted(data_a) == sorted(data_b)
    for name in data_a:
        np.testing.assert_array_equal(data_a[name], data_b[name], err_msg=name)
    return attrs_a["sweep"], attrs_b["sweep"]


def test_partition_and_chunk_seeds():
    assert [len(r) for r in partition(10, 4)] == [3, 3, 4]
    assert [len(r) for r in partition(8, 4)] == [4, 4] and [len(r) for r in partition(3, 10)] == [3]
    assert [r.start for r in partition(1000, 7)][:3] == [0, 6, 13]  # consecutive, no gap
    assert sum(len(r) for r in partition(1001, 10)) == 1001
    draws = [chunk_rng(3, i).uniform(size=4) for i in range(3)]
    assert not np.allclose(draws[0], draws[1]) and np.array_equal(draws[2], chunk_rng(3, 2).uniform(size=4))


def test_chunks_draw_their_own_variants_and_grids_span_the_chunks():
    system = SCENARIO.system
    whole = SPEC.variants(system)
    assert whole.count == 120 and len(SPEC.chunks()) == 5
    second = SPEC.variants(system, 1)
    np.testing.assert_array_equal(second.stiffness_factor, whole.stiffness_factor[24:48])
    assert not np.allclose(whole.stiffness_factor[:24], second.stiffness_factor)  # each chunk its own draws
    grid = parse_sweep_spec("chunk_size = 4\n[[vary]]\nparameter = 'stiffness'\ndistribution = 'grid'\n"
                            "values = [0.5, 1.0, 2.0]\n[[vary]]\nparameter = 'position'\ndistribution = 'grid'\n"
                            "values = [0.0, 0.1, 0.2]\naxes = ['x']\n")
    v = grid.variants(system)
    pairs = [(float(k), float(x)) for k, x in zip(v.stiffness_factor[:, 0, 0], v.position_offset[:, 0, 0])]
    assert pairs == [(a, b) for a in (0.5, 1.0, 2.0) for b in (0.0, 0.1, 0.2)]  # the factorial, in order
    assert len(grid.chunks()) == 3


@pytest.mark.slow  # 3 s on the 2-core machine
def test_in_process_sweep_against_diffrax_and_the_unchunked_batch(in_process):
    system = SCENARIO.system
    variants = SPEC.variants(system)
    assert in_process.count == 120 and in_process.chunks == 5 and in_process.backend == "in-process"
    np.testing.assert_array_equal(in_process.variants.stiffness_factor, variants.stiffness_factor)
    # The same variants in one batch: the chunks only group the work.
    whole = run_batch(system, variants, SCENARIO.excitation, SCENARIO.simulation, cross_check=0)
    np.testing.assert_allclose(in_process.peak_q, whole.peak_q, rtol=1e-10)
    np.testing.assert_array_equal(in_process.frequency_hz, whole.frequency_hz)
    # A variant of the last chunk by the one-variant direct solve.
    direct = simulate(variant_system(system, variants, 110), SCENARIO.excitation, SCENARIO.simulation)
    expected = np.max(np.abs(direct.q), axis=0)
    assert np.all(np.abs(in_process.peak_q[110] - expected) / expected < RTOL_BATCH_DIRECT)
    # The cross-check sample spans chunks; its diffrax peaks are stored and agree.
    checked = in_process.cross_check_variants
    assert checked.size == 4 and len({i // 24 for i in checked}) > 1
    assert in_process.cross_check.ok and in_process.cross_check.worst < 1e-6
    one = checked[0]
    again = simulate(variant_system(system, variants, int(one)), SCENARIO.excitation, SCENARIO.simulation)
    np.testing.assert_allclose(in_process.cross_check_peak_q[0], np.max(np.abs(again.q), axis=0), rtol=1e-12)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_two_workers_give_the_in_process_result_bit_for_bit(cluster, in_process):
    on_dask = sweep(SCENARIO, SPEC, scheduler=cluster.scheduler.address)  # as --scheduler ADDRESS connects
    assert on_dask.backend == "dask" and on_dask.workers == 2 and on_dask.chunks == 5
    for name in PER_VARIANT[3:]:
        np.testing.assert_array_equal(getattr(on_dask, name), getattr(in_process, name), err_msg=name)
    for name in PER_VARIANT[:3]:
        np.testing.assert_array_equal(getattr(on_dask.variants, name), getattr(in_process.variants, name))
    np.testing.assert_array_equal(on_dask.cross_check_variants, in_process.cross_check_variants)
    np.testing.assert_array_equal(on_dask.cross_check.per_dof, in_process.cross_check.per_dof)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_workers_run_single_threaded_with_the_compilation_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SIXDOF_JAX_CACHE", str(tmp_path / "cache"))
    with task_runner(workers=2) as runner:
        assert runner.backend == "dask-local" and runner.workers == 2

        def settings():
            import jax

            return (os.environ.get("XLA_FLAGS"), os.environ.get("OPENBLAS_NUM_THREADS"),
                    jax.config.jax_compilation_cache_dir, os.environ.get("MALLOC_TRIM_THRESHOLD_"))

        found = runner.client.run(settings)
        assert len(found) == 2
        for flags, blas, cache, trim in found.values():
            assert "--xla_cpu_multi_thread_eigen=false" in flags and blas == "1"
            assert cache == str(tmp_path / "cache")
            assert trim is None  # glibc's adaptive mmap threshold (see sixdof.workflows.tasks)
        assert sum(runner.client.nthreads().values()) == 2
        # The workers fill the shared cache: the assembly's compiled code, and the cross-check's diffrax solve
        # exported (another worker, or the next sweep's, loads it without tracing).
        sweep(SCENARIO, dataclasses.replace(SPEC, count=30, cross_check=1), client=runner.client)
    assert any((tmp_path / "cache").glob("jit_*")) and any((tmp_path / "cache" / "sixdof_solves").glob("*.jaxexport"))


@pytest.mark.long  # 8-10 s: a sweep in process and on a two-worker cluster
def test_files_equal_in_process_and_on_two_workers(tmp_path, cluster):
    a, a_folder = sweep_scenario(SCENARIO, SPEC, tmp_path / "a")
    _, b_folder = sweep_scenario(SCENARIO, SPEC, tmp_path / "b", client=cluster, progress="text")
    attrs_a, attrs_b = _same_file(a_folder / "sweep.h5", b_folder / "sweep.h5")
    assert (attrs_a["backend"], attrs_b["backend"], attrs_b["workers"], attrs_b["chunks"]) == (
        "in-process", "dask", 2, 5)
    assert attrs_a["count"] == attrs_b["count"] == 120
    with h5py.File(a_folder / "sweep.h5", "r") as f:
        np.testing.assert_array_equal(f["sweep/variant"][()], np.arange(120))  # every variant once, in order
    assert not (tmp_path / "a" / ("beam_sweep" + CHUNKS_SUFFIX)).exists()  # the chunks are merged and gone
    assert "120 variants" in sweep_tables(a_folder / "sweep.h5", prepare(SCENARIO)) and a.resumed == 0


def test_progress_over_chunks_shows_variants_per_second(tmp_path, capsys):
    sweep(SCENARIO, dataclasses.replace(SPEC, count=50, cross_check=0), progress="text")
    err = capsys.readouterr().err
    assert "2 / 2 chunks (100%)" in err and "variants/s" in err


@pytest.mark.long  # over 10 s on the 2-core machine
def test_a_killed_worker_costs_only_its_chunk(tmp_path):
    """SIGKILL of a worker mid-sweep while it holds chunks: they run again, nothing is lost or doubled."""
    long = dataclasses.replace(SCENARIO, simulation=dataclasses.replace(SCENARIO.simulation, duration=40.0))
    spec = dataclasses.replace(SPEC, count=400, chunk_size=50)  # chunks of ~0.2 s each
    _, reference = sweep_scenario(long, spec, tmp_path / "reference")
    chunks = tmp_path / "killed" / ("beam_sweep" + CHUNKS_SUFFIX)
    killed = []

    with task_runner(workers=2) as runner:
        client = runner.client
        pids = client.run(os.getpid)

        def kill_a_busy_worker_mid_sweep():
            deadline = time.monotonic() + 120
            while not killed and time.monotonic() < deadline:
                busy = [(w, keys) for w, keys in client.processing().items() if keys]
                if busy and any(chunks.glob("chunk-*.h5")):  # one chunk written, others being computed
                    address, keys = busy[0]
                    os.kill(pids[address], signal.SIGKILL)
                    killed.extend(keys)
                time.sleep(0.01)

        killer = threading.Thread(target=kill_a_busy_worker_mid_sweep)
        killer.start()
        try:
            _, survived = sweep_scenario(long, spec, tmp_path / "killed", client=client)
        finally:
            killer.join()
        assert killed, "no worker was holding a chunk to be killed"
        # The scheduler gave each lost chunk to a worker again after the kill.
        for key in killed:
            # Entries (who, key, from, to, ...): the scheduler's transitions of the chunk's task.
            moves = [entry[3] for entry in client.story(key) if entry[1] == key]
            assert moves.count("processing") >= 2, (key, moves)
    attrs = _same_file(reference / "sweep.h5", survived / "sweep.h5")[1]
    assert attrs["count"] == 400 and not chunks.exists()


@pytest.mark.slow  # 10-14 s on the 2-core machine, with the cluster's start (a module fixture)
def test_an_interrupted_sweep_resumes_from_its_chunks(tmp_path, monkeypatch, cluster):
    _, reference = sweep_scenario(SCENARIO, SPEC, tmp_path / "reference")
    computed = []
    original = sixdof.analysis.sweep.sweep_chunk

    def interrupted(scenario, spec, index, checked=()):
        if index == 3:
            raise KeyboardInterrupt
        computed.append(index)
        return original(scenario, spec, index, checked)

    monkeypatch.setattr(sixdof.analysis.sweep, "sweep_chunk", interrupted)
    with pytest.raises(KeyboardInterrupt):
        sweep_scenario(SCENARIO, SPEC, tmp_path / "out")
    chunks = tmp_path / "out" / ("beam_sweep" + CHUNKS_SUFFIX)
    assert sorted(p.name for p in chunks.glob("chunk-*.h5")) == ["chunk-00000.h5", "chunk-00001.h5", "chunk-00002.h5"]
    assert not (tmp_path / "out" / "beam_sweep").exists()  # no sweep.h5 of an unfinished sweep
    monkeypatch.setattr(sixdof.analysis.sweep, "sweep_chunk", original)
    # Without --resume: one error, nothing computed, nothing removed.
    with pytest.raises(InputError, match=r"--resume: expected a fresh start, or --resume to continue the "
                                         r"interrupted sweep whose 3 finished chunks are in .*beam_sweep\.chunks"):
        sweep_scenario(SCENARIO, SPEC, tmp_path / "out")
    # Another spec, or the same scenario file with another load, cannot resume these chunks.
    with pytest.raises(InputError, match=r"--resume: expected the scenario and sweep spec that the chunks in .* "
                                         r"were computed from, got a different spec"):
        sweep_scenario(SCENARIO, dataclasses.replace(SPEC, seed=12), tmp_path / "out", resume=True)
    louder = parse_scenario(SCENARIO.text.replace("force = [5e3, 2e4, -1e5]", "force = [5e3, 2e4, -1.1e5]"))
    with pytest.raises(InputError, match=r"got a different scenario"):
        sweep_scenario(louder, SPEC, tmp_path / "out", resume=True)
    # Resumed on the two workers: only chunks 3 and 4 are computed, and the file is the uninterrupted one's.
    resumed, folder = sweep_scenario(SCENARIO, SPEC, tmp_path / "out", resume=True, client=cluster)
    assert resumed.resumed == 3 and resumed.chunks == 5
    _same_file(reference / "sweep.h5", folder / "sweep.h5")
    assert not chunks.exists()


@pytest.mark.slow  # 5 s on the 2-core machine
def test_robustness_chunks_on_two_workers(cluster):
    from sixdof._jax import jax
    from sixdof.chunks import InProcess
    from sixdof.design.optimize import ROBUSTNESS_CHUNK, robustness
    from sixdof.design.problem import DesignProblem
    from sixdof.workflows.tasks import OnDask

    scenario = prepare(load_scenario("scenarios/engine_inclined_mounts.toml"))
    spec = dataclasses.replace(scenario.design, samples=ROBUSTNESS_CHUNK + 300)
    problem = DesignProblem(scenario.system, spec)
    here = robustness(problem, problem.initial, InProcess())
    there = robustness(problem, problem.initial, OnDask(cluster, "dask"))
    np.testing.assert_array_equal(here.values, there.values)
    assert here.values.shape == (1300, len(problem.targets))
    np.testing.assert_array_equal(here.responses.frequency_hz, there.responses.frequency_hz)
    assert there.responses.backend == "dask" and there.responses.chunks == 2
    # The second chunk is drawn with its own seed: its values are that chunk's alone.
    scale = np.random.default_rng([spec.seed, 1]).uniform(1 - spec.tolerance, 1 + spec.tolerance, (650, 3, 3))
    expected = jax.vmap(lambda s: problem.values(problem.initial, s))(scale)
    np.testing.assert_allclose(here.values[650:], expected, rtol=1e-12)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_where_the_chunks_run_is_checked_before_computing(tmp_path, monkeypatch):
    with pytest.raises(InputError, match=r"--workers: expected a number of worker processes >= 1, got 0"):
        sweep(SCENARIO, SPEC, workers=0)
    with pytest.raises(InputError, match=r"--scheduler: expected one place to run the chunks \(not with "
                                         r"--workers\), got both given"):
        sweep(SCENARIO, SPEC, workers=2, scheduler="tcp://127.0.0.1:1")
    monkeypatch.setattr("sixdof.workflows.tasks.CONNECT_TIMEOUT_S", 1)
    with pytest.raises(InputError, match=r"--scheduler: expected the address of a running Dask scheduler, got "
                                         r"tcp://127\.0\.0\.1:9 \("):
        sweep_scenario(SCENARIO, SPEC, tmp_path, scheduler="tcp://127.0.0.1:9")
    assert list(tmp_path.iterdir()) == []  # nothing left behind, no chunk folder


@pytest.mark.slow  # 2 s on the 2-core machine
def test_the_command_line_says_where_the_chunks_of_an_interrupted_sweep_are(tmp_path, monkeypatch, capsys):
    from sixdof.cli import main

    scenario, spec = tmp_path / "beam.toml", tmp_path / "spec.toml"
    scenario.write_text(SCENARIO.text)
    spec.write_text("count = 60\nseed = 1\nchunk_size = 20\ncross_check = 0\n[[vary]]\nparameter = 'stiffness'\n"
                    "distribution = 'uniform'\nlow = 0.8\nhigh = 1.2\n")
    original = sixdof.analysis.sweep.sweep_chunk

    def interrupted(scenario, spec, index, checked=()):
        if index == 2:
            raise KeyboardInterrupt
        return original(scenario, spec, index, checked)

    monkeypatch.setattr(sixdof.analysis.sweep, "sweep_chunk", interrupted)
    command = ["sweep", str(scenario), "--spec", str(spec), "--out", str(tmp_path / "out"), "--quiet"]
    assert main(command) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and re.fullmatch(r"sixdof: interrupted; the 2 chunks finished are kept in .*beam_sweep\.chunks: "
                                          r"the same command with --resume computes only the others", err[0]), err
    monkeypatch.setattr(sixdof.analysis.sweep, "sweep_chunk", original)
    assert main(command) == 2  # not without --resume
    assert "--resume: expected a fresh start, or --resume" in capsys.readouterr().err
    assert main([*command, "--resume"]) == 0
    out = capsys.readouterr().out
    assert "60 variants, exact engine, 3 chunks, 2 of them resumed, in-process with 1 worker," in out


@pytest.mark.slow  # 2 s on the 2-core machine
def test_the_command_line_runs_the_chunks_on_a_scheduler(tmp_path, cluster, capsys):
    from sixdof.cli import main

    scenario, spec = tmp_path / "beam.toml", tmp_path / "spec.toml"
    scenario.write_text(SCENARIO.text)
    spec.write_text("count = 40\nseed = 1\nchunk_size = 20\ncross_check = 1\n[[vary]]\nparameter = 'stiffness'\n"
                    "distribution = 'uniform'\nlow = 0.8\nhigh = 1.2\n")
    assert main(["sweep", str(scenario), "--spec", str(spec), "--out", str(tmp_path), "--quiet",
                 "--scheduler", cluster.scheduler.address]) == 0
    out = capsys.readouterr().out
    assert "40 variants, exact engine, 2 chunks, dask with 2 workers," in out and "Cross-check of the exact" in out
    with h5py.File(tmp_path / "beam_sweep" / "sweep.h5", "r") as f:
        assert (f["sweep"].attrs["backend"], f["sweep"].attrs["workers"]) == ("dask", 2)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_sweep_s_fingerprint_is_the_same_in_another_process():
    """--resume runs in a new process: the fingerprint of the same files must be the same bytes there."""
    import json
    import subprocess
    import sys

    from sixdof.workflows.sweep import fingerprint

    code = ("import json; from sixdof.io.scenario import load_scenario; from sixdof.io.sweep import load_sweep_spec; "
            "from sixdof.workflows.sweep import fingerprint; print(json.dumps(fingerprint(load_scenario("
            "'scenarios/cabinet_earthquake.toml'), load_sweep_spec('scenarios/sweeps/bearing_tolerance.toml'))))")
    there = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
                       .stdout.strip().splitlines()[-1])
    scenario = load_scenario("scenarios/cabinet_earthquake.toml")  # reads an accelerogram file
    here = fingerprint(scenario, load_sweep_spec("scenarios/sweeps/bearing_tolerance.toml"))
    assert here == there



def _sweep_command(tmp_path, count):
    """The command line of a sweep of the beam on two workers, without progress, as a subprocess runs it."""
    import sys

    scenario, spec = tmp_path / "beam.toml", tmp_path / "spec.toml"
    scenario.write_text(SCENARIO.text)
    spec.write_text(f"count = {count}\nseed = 1\nchunk_size = 20\ncross_check = 0\n[[vary]]\nparameter = 'stiffness'\n"
                    "distribution = 'uniform'\nlow = 0.8\nhigh = 1.2\n")
    return [sys.executable, "-m", "sixdof", "sweep", str(scenario), "--spec", str(spec), "--workers", "2",
            "--out", str(tmp_path / "out"), "--quiet"]


def _interrupted(command, ready):
    """``command`` run in its own process group, as a terminal runs it, and Ctrl-C'd there (SIGINT to the whole
    group) once ``ready(pgid)``: its exit status and stderr lines, once no process of the group is left."""
    import subprocess

    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env={**os.environ, "SIXDOF_JAX_CACHE": "off"}, start_new_session=True)
    deadline = time.monotonic() + 120
    while not ready(process.pid) and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert process.poll() is None, "the sweep ended before it could be interrupted"
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert_group_ends(process.pid, within_s=10.0)  # workers that closed their pipes may still be ending
    return process.returncode, err.strip().splitlines()


@pytest.mark.long  # over 10 s on the 2-core machine
@pytest.mark.skipif(not os.path.isdir("/proc"), reason="finds the process group's processes in /proc")
def test_ctrl_c_at_a_sweep_on_two_workers_is_one_line_and_its_chunks_are_kept(tmp_path):
    """Ctrl-C at a terminal signals the Dask workers too: they ignore it (a worker's event loop stopped by it
    printed some 30 lines of traceback), the main process says it in its one line and closes the cluster."""
    chunks = tmp_path / "out" / ("beam_sweep" + CHUNKS_SUFFIX)
    status, err = _interrupted(_sweep_command(tmp_path, 400), lambda pgid: any(chunks.glob("chunk-*.h5")))
    assert status == 130 and len(err) == 1, err
    assert re.fullmatch(r"sixdof: interrupted; the (\d+ chunks finished are|chunk finished is) kept in "
                        r".*beam_sweep\.chunks: the same "
                        r"command with --resume computes only the others", err[0]), err


@pytest.mark.slow  # 3 s on the 2-core machine
@pytest.mark.skipif(not os.path.isdir("/proc"), reason="finds the process group's processes in /proc")
def test_ctrl_c_while_the_workers_start_is_one_line(tmp_path):
    """Ctrl-C while the worker processes import (before Dask runs their setup): they are started with SIGINT
    blocked, so none dies of it (which failed the cluster's start with some 100 lines of tracebacks), and the
    main process, which held it back meanwhile, says it in one line."""
    def starting(pgid):
        return any("spawn_main" in command for command in living_in_group(pgid))

    status, err = _interrupted(_sweep_command(tmp_path, 40), starting)
    assert status == 130 and err == ["sixdof: interrupted; no partial results were left"], err


@pytest.mark.slow  # 2 s on the 2-core machine
def test_the_workers_of_a_local_cluster_log_nothing(capfd):
    """A worker's heartbeat in flight as the scheduler closes is logged as an error by Dask ("Failed to communicate
    with scheduler during heartbeat", about 30 lines with its traceback) on a loaded machine, after a run that
    went well: a race of Dask's own shutdown that cannot be timed here, so the worker logs it on request."""
    import logging

    def log_a_heartbeat_failure():
        logging.getLogger("distributed.worker").error("Failed to communicate with scheduler during heartbeat.")

    with task_runner(workers=1) as runner:
        runner.client.run(log_a_heartbeat_failure)
    assert "heartbeat" not in capfd.readouterr().err


KILLED_WRITING_A_CHUNK = r"""
import os, signal, sys
from sixdof.io.store import writer
from sixdof.io.scenario import parse_scenario
from sixdof.io.sweep import parse_sweep_spec
from sixdof.workflows.sweep import sweep_scenario

real = writer._write


def killed(f, results, written=frozenset()):
    if results.attrs[""].get("scenario_name") == "chunk 1":  # its temporary file is open: SIGKILL now
        os.kill(os.getpid(), signal.SIGKILL)
    return real(f, results, written)


writer._write = killed
if __name__ == "__main__":
    scenario, spec, out = sys.argv[1:]
    with open(scenario) as a, open(spec) as b:
        sweep_scenario(parse_scenario(a.read()), parse_sweep_spec(b.read()), out, workers=2)
"""

SMALL_SPEC = ("count = 30\nseed = 3\nchunk_size = 10\ncross_check = 0\n[[vary]]\nparameter = 'stiffness'\n"
              "distribution = 'uniform'\nlow = 0.8\nhigh = 1.2\n")


@pytest.mark.long  # over 10 s on the 2-core machine
def test_a_sweep_killed_while_it_writes_a_chunk_leaves_debris_the_next_run_removes(tmp_path):
    """SIGKILL of ``sweep --workers 2`` in the middle of a chunk file: its ``.chunk-00001.h5.<id>.tmp`` goes with
    the next --resume, which removes no other file; while a live sweep holds the folder, nothing is removed."""
    import fcntl

    scenario, spec, script = tmp_path / "beam.toml", tmp_path / "spec.toml", tmp_path / "killed.py"
    scenario.write_text(SCENARIO.text)
    spec.write_text(SMALL_SPEC)
    script.write_text(KILLED_WRITING_A_CHUNK)
    child = subprocess.Popen([sys.executable, str(script), str(scenario), str(spec), str(tmp_path / "out")],
                             cwd=tmp_path, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        child.communicate(timeout=300)
        assert child.returncode == -signal.SIGKILL
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(child.pid, signal.SIGKILL)  # the orphaned Dask workers, if they have not ended yet
    chunks = tmp_path / "out" / f"beam_sweep{CHUNKS_SUFFIX}"
    debris = [p.name for p in chunks.glob(".chunk-00001.h5.*.tmp")]
    assert len(debris) == 1 and re.fullmatch(r"\.chunk-00001\.h5\.[0-9a-f]{32}\.tmp", debris[0])
    users = [".chunk-00002.h5.mine.tmp", "notes.tmp"]  # a user's files, near the pattern: kept
    for name in users:
        (chunks / name).write_text("mine")
    fd = os.open(chunks, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_SH)  # as a live sweep writing there holds it
    try:
        opened = sixdof.workflows.sweep.ChunkFolder(chunks, json.loads((chunks / "sweep.json").read_text()), resume=True)
        assert (chunks / debris[0]).exists()
        opened.release()
    finally:
        os.close(fd)
    small = parse_sweep_spec(SMALL_SPEC)
    _, done = sweep_scenario(parse_scenario(SCENARIO.text), small, tmp_path / "out", resume=True)  # as the child read it
    assert _file(done / "sweep.h5")[1]["sweep"]["count"] == 30
    assert sorted(p.name for p in chunks.iterdir()) == sorted(users)  # the chunks and the debris went, not theirs
