"""Results on disk: a safe folder name, nothing deleted that sixdof did not write, and previous results
left whole by real signals, SIGKILL, a file-size limit, a full filesystem and concurrent processes."""

import dataclasses
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from processes import assert_group_ends
from sixdof import InputError, load_results, parse_scenario, run_scenario
from sixdof.cli import EXIT_BAD_INPUT, EXIT_CANNOT_WRITE, EXIT_CLOSED_PIPE, EXIT_INTERRUPTED, EXIT_TERMINATED, main
from sixdof.errors import ScenarioError
from sixdof.io import output
from sixdof.workflows import run as run_module

HERE = Path(__file__).parent
# Modal results, statics and FRFs only: a run takes about a second, so real processes stay cheap.
SCENARIO = """
name = "pump"
description = "pump on four isolators"

[body]
mass = 300.0
inertia = [20.0, 30.0, 25.0]

[[mounts]]
name = "a"
position = [-0.3, -0.4, -0.3]
stiffness = [1e5, 1e5, 4e5]
damping = [150.0, 150.0, 500.0]

[[mounts]]
name = "b"
position = [0.3, -0.4, -0.3]
stiffness = [1e5, 1e5, 4e5]
damping = [150.0, 150.0, 500.0]

[[mounts]]
name = "c"
position = [0.3, 0.4, -0.3]
stiffness = [1.2e5, 1.2e5, 5e5]
damping = [100.0, 100.0, 300.0]

[[mounts]]
name = "d"
position = [-0.3, 0.4, -0.3]
stiffness = [1.2e5, 1.2e5, 5e5]
damping = [100.0, 100.0, 300.0]

[frf]
f_hz = [1.0, 100.0]
points = 50
"""


@pytest.fixture
def scenario_file(tmp_path):
    path = tmp_path / "pump.toml"
    path.write_text(SCENARIO)
    return path


@pytest.fixture
def previous(scenario_file, tmp_path):
    """A finished run in ``tmp_path/out/pump``, with a file of the user's in it: {name: bytes}."""
    results, folder = run_scenario(parse_scenario(SCENARIO, "pump.toml"), tmp_path / "out", progress=False)
    (folder / "notes.txt").write_text("mine")
    return snapshot(folder)


def snapshot(folder: Path) -> dict[str, bytes]:
    """The files in ``folder`` (not its subfolders), by name."""
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def debris(out: Path) -> list[str]:
    """Staging folders, previous folders set aside, write probes."""
    return [p.name for p in out.iterdir() if any(k in p.name for k in (".partial-", ".old-", ".write-test-"))]


def child(hook: str, *args: str, **env: str) -> subprocess.Popen:
    """A real sixdof process (tests/output_child.py) that pauses at ``hook`` for a signal."""
    return subprocess.Popen([sys.executable, str(HERE / "output_child.py"), hook, *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env={**os.environ, "SIXDOF_JAX_CACHE": "off", **env})


@pytest.fixture
def own_tmpdir():
    """``TMPDIR`` for a child that will be killed: a process ended by SIGKILL cannot remove its temporary
    folders (multiprocessing's, holding the figure workers' server socket), so they go into the test's own,
    removed after it. Short, beside the system's: a Unix socket's path holds at most 107 bytes, which
    pytest's ``tmp_path`` (under pytest-xdist, one level deeper) and multiprocessing's names exceed."""
    folder = tempfile.mkdtemp(prefix="sixdof-test-")
    yield {"TMPDIR": folder}
    shutil.rmtree(folder, ignore_errors=True)


def signal_at(process: subprocess.Popen, word: str, signum: int) -> tuple[int, str]:
    """Send ``signum`` once the process prints ``word``; its exit status and stderr."""
    for line in process.stdout:
        if line.strip() == word:
            process.send_signal(signum)
            break
    _, err = process.communicate(timeout=120)
    return process.returncode, err


@pytest.mark.parametrize("name", [".", "..", "/tmp/elsewhere", "../x", "a/b", "x" * 300, "a\0b", "", " pump",
                                  "-rf", "päd", 5, True])
def test_a_scenario_name_is_one_safe_path_component(name, tmp_path, monkeypatch):
    text = SCENARIO.replace('name = "pump"', f"name = {json.dumps(name)}")
    expected = r"pump\.toml: name: expected (a name of 1 to 100 letters, digits|a (non-empty )?string)"
    with pytest.raises(ScenarioError, match=expected):
        parse_scenario(text, "pump.toml")
    # A scenario made through the API is checked too, before any computing, and nothing is created.
    scenario = dataclasses.replace(parse_scenario(SCENARIO, "pump.toml"), name=name)
    monkeypatch.setattr(run_module, "damping_ratios", lambda *a: pytest.fail("computed anyway"))
    with pytest.raises(InputError, match=r"name: expected a name of 1 to 100 letters, digits, '\.', '_' or '-'"):
        run_scenario(scenario, tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_rerun_keeps_the_users_files_and_says_so(previous, tmp_path):
    out = tmp_path / "out"
    (out / "pump" / "drawings").mkdir()
    (out / "pump" / "drawings" / "base.dxf").write_text("plate")
    with pytest.warns(output.KeptFilesWarning, match=r"pump held 2 file\(s\) that sixdof did not write; kept them: "
                                                     r"drawings, notes.txt"):
        run_scenario(parse_scenario(SCENARIO.replace("points = 50", "points = 60"), "pump.toml"), out, progress=False)
    after = snapshot(out / "pump")
    assert after["notes.txt"] == b"mine" and (out / "pump" / "drawings" / "base.dxf").read_text() == "plate"
    assert after["results.h5"] != previous["results.h5"]
    assert debris(out) == []


@pytest.mark.slow  # 2 s on the 2-core machine
def test_an_export_inside_the_previous_results_is_kept_and_said_to_be_sixdof_s_stale_one(previous, tmp_path):
    """``sixdof export`` writes into the results folder by default: a re-run keeps that folder (nobody asked for it
    to go) and says it is sixdof's, made from the results replaced, not a file sixdof did not write."""
    from sixdof.cli import main

    out = tmp_path / "out"
    assert main(["export", str(out / "pump" / "results.h5"), "--format", "csv"]) == 0
    with pytest.warns(output.KeptFilesWarning) as caught:
        run_scenario(parse_scenario(SCENARIO.replace("points = 50", "points = 60"), "pump.toml"), out, progress=False)
    said = sorted(str(w.message) for w in caught)
    assert said == [f"{out / 'pump'} held 1 file(s) that sixdof did not write; kept them: notes.txt",
                    f"{out / 'pump'} held pump_export, written by sixdof from the results this run replaces: kept, "
                    "but made from the previous results (write it again to match the new ones)"]
    assert (out / "pump" / "pump_export" / output.MANIFEST).is_file() and debris(out) == []


@pytest.mark.slow  # 2 s on the 2-core machine
def test_files_sixdof_wrote_before_are_replaced_not_kept(previous, tmp_path):
    # A figure the previous run drew and this one does not is sixdof's own: it goes with the old folder.
    out = tmp_path / "out"
    assert "bode.png" in previous
    with pytest.warns(output.KeptFilesWarning, match="kept them: notes.txt"):
        run_scenario(parse_scenario(SCENARIO.split("[frf]")[0], "pump.toml"), out, progress=False)
    assert "bode.png" not in snapshot(out / "pump") and "notes.txt" in snapshot(out / "pump")


def test_a_folder_sixdof_did_not_write_is_never_replaced(tmp_path, monkeypatch):
    theirs = tmp_path / "out" / "pump"
    theirs.mkdir(parents=True)
    (theirs / "thesis.tex").write_text("years of work")
    monkeypatch.setattr(run_module, "damping_ratios", lambda *a: pytest.fail("computed anyway"))
    with pytest.raises(InputError, match=r"--out: expected .*pump to be a sixdof results folder \(or absent\).* "
                                         r"got a folder holding 1 other entry: thesis.tex"):
        run_scenario(parse_scenario(SCENARIO, "pump.toml"), tmp_path / "out", progress=False)
    assert snapshot(theirs) == {"thesis.tex": b"years of work"}


@pytest.mark.slow  # 3 s each on the 2-core machine
@pytest.mark.parametrize(("signum", "status", "word"), [(signal.SIGINT, EXIT_INTERRUPTED, "interrupted"),
                                                       (signal.SIGTERM, EXIT_TERMINATED, "terminated")])
def test_a_signal_during_the_write_keeps_the_previous_results(previous, scenario_file, tmp_path, signum, status,
                                                              word):
    out = tmp_path / "out"
    scenario_file.write_text(SCENARIO.replace("points = 50", "points = 60"))
    process = child("write", "run", str(scenario_file), "--out", str(out), "--quiet")
    returncode, err = signal_at(process, "WRITING", signum)
    assert returncode == status
    assert err.strip().splitlines() == [f"sixdof: {word}" + err.strip().split(word, 1)[1]]
    assert "Traceback" not in err and "Exception ignored" not in err
    assert snapshot(out / "pump") == previous
    assert debris(out) == []


@pytest.mark.long  # over 10 s on the 2-core machine
@pytest.mark.parametrize(("signum", "status", "word"), [(signal.SIGINT, EXIT_INTERRUPTED, "interrupted"),
                                                       (signal.SIGTERM, EXIT_TERMINATED, "terminated (SIGTERM)")])
def test_a_signal_during_the_swap_is_acted_on_once_the_results_are_in_place_and_said_so(
        previous, scenario_file, tmp_path, signum, status, word):
    """Held back while the new folder replaces the previous one, the signal ends the command once it has: the
    report must say the new results are complete and in place, not that nothing was left."""
    out = tmp_path / "out"
    scenario_file.write_text(SCENARIO.replace("points = 50", "points = 60"))
    returncode, err = signal_at(child("swap", "run", str(scenario_file), "--out", str(out), "--quiet"), "SWAPPING",
                                signum)
    assert returncode == status
    kept, said = err.strip().splitlines()  # the user's file kept (said as it is done), then the interruption
    assert kept.startswith("WARNING: ") and kept.endswith("kept them: notes.txt")
    assert said == f"sixdof: {word}; it came once the results were complete, and they are in place in {out / 'pump'}"
    import h5py

    with h5py.File(out / "pump" / "results.h5") as f:  # the new run's: 60 frequencies
        assert f["frf/f_hz"].shape == (60,)
    assert (out / "pump" / "notes.txt").read_text() == "mine" and debris(out) == []


def test_a_second_ctrl_c_does_not_cut_the_cleanup_short(tmp_path, monkeypatch):
    """Ctrl-C pressed twice (or ``timeout -s INT``'s repeat) lands the second while the staging folder is being
    removed: held back there, it must not leave the folder behind."""
    import shutil

    monkeypatch.setattr(signal, "signal", signal.signal)  # restored after: the handler set below too
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # a terminal's, even under a background run
    remove = shutil.rmtree

    def interrupted_rmtree(path, *args, **kwargs):
        signal.raise_signal(signal.SIGINT)
        remove(path, *args, **kwargs)

    def write(stage):
        (stage / "results.h5").write_bytes(b"partial")
        raise KeyboardInterrupt  # the first Ctrl-C, while the run computes

    monkeypatch.setattr(shutil, "rmtree", interrupted_rmtree)
    try:
        with pytest.raises(KeyboardInterrupt):
            output.write_folder(tmp_path / "out" / "pump", write)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert not (tmp_path / "out").exists()


@pytest.mark.slow  # 2 s each on the 2-core machine
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_run_stopped_before_its_results_are_in_place_leaves_no_folder_it_made(scenario_file, tmp_path, signum):
    out = tmp_path / "new" / "out"
    process = child("write", "run", str(scenario_file), "--out", str(out), "--quiet")
    returncode, err = signal_at(process, "WRITING", signum)
    assert returncode == (EXIT_INTERRUPTED if signum == signal.SIGINT else EXIT_TERMINATED), err
    assert not (tmp_path / "new").exists()


def test_checking_a_new_out_folder_makes_nothing(tmp_path):
    out = tmp_path / "a" / "b"
    assert output.check_target(out, "pump") == out / "pump"
    assert os.listdir(tmp_path) == []
    (tmp_path / "file").write_text("mine")
    with pytest.raises(InputError, match="--out.*a folder where results can be written") as error:
        output.check_target(tmp_path / "file" / "b", "pump")
    assert "Not a directory" in str(error.value)
    assert sorted(os.listdir(tmp_path)) == ["file"]


def test_a_failed_write_removes_the_folders_it_made_unless_something_was_put_in_them(tmp_path):
    def fail(stage):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        output.write_folder(tmp_path / "a" / "b" / "pump", fail)
    assert os.listdir(tmp_path) == []

    def fail_after_a_user_wrote(stage):
        (stage.parent.parent / "notes.txt").write_text("mine")  # into tmp_path/a, meanwhile
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError):
        output.write_folder(tmp_path / "a" / "b" / "pump", fail_after_a_user_wrote)
    assert os.listdir(tmp_path / "a") == ["notes.txt"]  # b, made and empty, went; a and the file stay
    with pytest.raises(KeyboardInterrupt):
        output.replace_files(tmp_path / "figures", fail)
    assert sorted(os.listdir(tmp_path)) == ["a"]


@pytest.mark.slow  # 3 s on the 2-core machine
def test_ctrl_c_reaches_the_whole_process_group_and_leaves_no_process(previous, scenario_file, tmp_path):
    """Ctrl-C at a terminal signals every process of the command's group, the figure workers and their
    server too: the main process alone reports it, in one line, and no process of the run outlives it."""
    out = tmp_path / "out"
    scenario_file.write_text(SCENARIO.replace("points = 50", "points = 60"))
    process = subprocess.Popen([sys.executable, str(HERE / "output_child.py"), "write", "run", str(scenario_file),
                                "--out", str(out), "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, env={**os.environ, "SIXDOF_JAX_CACHE": "off"}, start_new_session=True)
    for line in process.stdout:
        if line.strip() == "WRITING":
            os.killpg(process.pid, signal.SIGINT)
            break
    _, err = process.communicate(timeout=120)  # returns once every process holding its pipes has ended
    assert process.returncode == EXIT_INTERRUPTED
    assert err.strip().splitlines() == ["sixdof: interrupted; no partial results were left"]
    assert snapshot(out / "pump") == previous
    assert debris(out) == []
    assert_group_ends(process.pid, within_s=5.0)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_sigkill_debris_is_removed_by_the_next_run(previous, scenario_file, tmp_path, own_tmpdir):
    out = tmp_path / "out"
    returncode, _ = signal_at(child("write", "run", str(scenario_file), "--out", str(out), **own_tmpdir), "WRITING",
                              signal.SIGKILL)
    assert returncode == -signal.SIGKILL
    assert [name for name in debris(out) if ".pump.partial-" in name]  # the killed run's staging folder
    assert snapshot(out / "pump") == previous
    with pytest.warns(output.KeptFilesWarning):
        run_scenario(parse_scenario(SCENARIO, "pump.toml"), out, progress=False)
    assert debris(out) == []


@pytest.mark.slow  # 5 s each on the 2-core machine
@pytest.mark.parametrize("hook", ["swap", "swapped"])
def test_sigkill_in_the_middle_of_a_swap_is_settled_by_the_next_run(previous, scenario_file, tmp_path, hook,
                                                                     own_tmpdir):
    out = tmp_path / "out"
    scenario_file.write_text(SCENARIO.replace("points = 50", "points = 60"))
    returncode, _ = signal_at(child(hook, "run", str(scenario_file), "--out", str(out), **own_tmpdir), "SWAPPING",
                              signal.SIGKILL)
    assert returncode == -signal.SIGKILL
    # The previous folder, with the user's file, is still set aside; the new one is in place or not yet.
    assert [name for name in debris(out) if ".pump.old-" in name]
    assert (out / "pump").exists() == (hook == "swapped")

    def fail(stage):
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError):
        output.write_folder(out / "pump", fail)  # the next run, failing: it settles the swap first
    settled = snapshot(out / "pump")
    assert settled["notes.txt"] == b"mine"
    assert (settled == previous) == (hook == "swap")  # undone, or finished with the new results
    assert debris(out) == []


@pytest.mark.slow  # 3 s on the 2-core machine
def test_a_file_size_limit_is_one_line_and_keeps_the_previous_results(previous, scenario_file, tmp_path):
    out = tmp_path / "out"
    process = child("none", "run", str(scenario_file), "--out", str(out), SIXDOF_TEST_FSIZE="20000")
    _, err = process.communicate(timeout=120)
    assert process.returncode == EXIT_CANNOT_WRITE, err
    assert len(err.strip().splitlines()) == 1 and err.startswith("sixdof: could not write")
    assert "results already in place are unchanged" in err
    assert snapshot(out / "pump") == previous
    assert debris(out) == []


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_full_filesystem_is_one_line_and_leaves_nothing(scenario_file, tmp_path):
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=32k", "tmpfs", str(disk)], capture_output=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here: {mounted.stderr.decode().strip()}")
    try:
        process = child("none", "run", str(scenario_file), "--out", str(disk / "out"))
        _, err = process.communicate(timeout=120)
        assert process.returncode == EXIT_CANNOT_WRITE, err
        assert len(err.strip().splitlines()) == 1 and "No space left on device" in err
        assert os.listdir(disk) == []  # not even the --out folder it would have made
    finally:
        subprocess.run(["umount", str(disk)], check=True)


WRITER = """
import os, sys, time
from pathlib import Path
from sixdof.io import output

def write(stage):
    (stage / "a").write_text(str(os.getpid()))
    time.sleep(0.01)
    (stage / "b").write_text(str(os.getpid()))

for _ in range(int(sys.argv[2])):
    output.write_folder(Path(sys.argv[1]), write)
"""

# Reads both files through one handle on the folder: a folder swapped in between is not a torn one.
READER = """
import os, sys
from pathlib import Path
target, stop, torn, seen = Path(sys.argv[1]), Path(sys.argv[2]), 0, 0

def read(name, folder):
    fd = os.open(name, os.O_RDONLY, dir_fd=folder)
    with os.fdopen(fd) as f:
        return f.read()

while not stop.exists():
    try:
        folder = os.open(target, os.O_RDONLY)
    except FileNotFoundError:
        continue
    try:
        a, b = read("a", folder), read("b", folder)
    except FileNotFoundError:
        continue
    finally:
        os.close(folder)
    seen += 1
    torn += a != b
print(seen, torn)
"""


def test_concurrent_runs_into_one_target_never_corrupt_each_other(tmp_path):
    target = tmp_path / "out" / "shared"
    target.parent.mkdir()
    stop = tmp_path / "stop"
    reader = subprocess.Popen([sys.executable, "-c", READER, str(target), str(stop)], stdout=subprocess.PIPE, text=True)
    writers = [subprocess.Popen([sys.executable, "-c", WRITER, str(target), "15"], stderr=subprocess.PIPE, text=True)
               for _ in range(6)]
    for process in writers:
        _, err = process.communicate(timeout=120)
        assert process.returncode == 0, err
    stop.touch()
    seen, torn = map(int, reader.communicate(timeout=60)[0].split())
    assert seen > 0 and torn == 0
    assert sorted(os.listdir(target)) == [".sixdof-files", "a", "b"]
    assert debris(target.parent) == []


@pytest.mark.parametrize("umask", [0o022, 0o077])
def test_folders_and_files_follow_the_umask(tmp_path, umask):
    previous_umask = os.umask(umask)
    try:
        target = output.check_target(tmp_path / "out", "pump")
        output.write_folder(target, lambda stage: (stage / "results.h5").write_bytes(b""))
    finally:
        os.umask(previous_umask)
    assert target.stat().st_mode & 0o777 == 0o777 & ~umask
    assert (target / "results.h5").stat().st_mode & 0o777 == 0o666 & ~umask


@pytest.mark.slow  # 3 s on the 2-core machine
def test_a_reader_that_went_away_is_no_failed_write(scenario_file, tmp_path):
    """``sixdof run ... | head -3`` with the reader gone before the tables are printed: the results are written
    in full, and the command ends with 128 + SIGPIPE and no word of a failed write."""
    process = child("none", "run", str(scenario_file), "--out", str(tmp_path / "out"))
    process.stdout.close()
    with process.stderr:
        err = process.stderr.read()
    assert process.wait() == EXIT_CLOSED_PIPE and err == ""
    folder = tmp_path / "out" / "pump"
    assert sorted(os.listdir(folder)) == sorted([output.MANIFEST, *(folder / output.MANIFEST).read_text().split()])
    assert {"results.h5", "summary.md", "bode.png"} <= set(os.listdir(folder)) and debris(tmp_path / "out") == []
    assert load_results(folder / "results.h5").frf is not None


@pytest.mark.long  # over 10 s on the 2-core machine
def test_plot_replaces_the_figures_all_or_nothing(previous, tmp_path):
    folder = tmp_path / "out" / "pump"
    returncode, err = signal_at(child("plot", "plot", str(folder / "results.h5")), "PLOTTED", signal.SIGINT)
    assert returncode == EXIT_INTERRUPTED and "Traceback" not in err
    assert snapshot(folder) == previous
    assert debris(folder) == []
    process = child("none", "plot", str(folder / "results.h5"))
    _, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    assert set(snapshot(folder)) == set(previous) and debris(folder) == []


@pytest.mark.slow  # 4 s on the 2-core machine
def test_plot_never_overwrites_a_file_sixdof_did_not_write(previous, tmp_path, capsys):
    results = tmp_path / "out" / "pump" / "results.h5"
    theirs = tmp_path / "mine"
    theirs.mkdir()
    (theirs / "bode.png").write_bytes(b"my figure")
    assert main(["plot", str(results), "--out", str(theirs)]) == EXIT_BAD_INPUT
    assert (f"sixdof: error: --out: expected no file that sixdof did not write under the names it writes in {theirs} "
            "(such a file is never overwritten): choose another --out or move them elsewhere, got 1 such file(s): "
            "bode.png\n") in capsys.readouterr().err
    assert snapshot(theirs) == {"bode.png": b"my figure"} and debris(theirs) == []
    # A folder sixdof drew into lists what it drew: the next redraw replaces those, and only those.
    figures = tmp_path / "figures"
    assert main(["plot", str(results), "--out", str(figures)]) == 0
    drawn = {name: (figures / name).stat().st_ino for name in snapshot(figures) if name.endswith(".png")}
    assert sorted(drawn) == (figures / output.MANIFEST).read_text().split()
    (figures / "notes.txt").write_text("mine")
    assert main(["plot", str(results), "--out", str(figures)]) == 0
    assert all((figures / name).stat().st_ino != inode for name, inode in drawn.items())
    assert set(snapshot(figures)) == {output.MANIFEST, "notes.txt", *drawn}
    # A results folder of an earlier version (no list): its figures are sixdof's, and its files join the list.
    (results.parent / output.MANIFEST).unlink()
    assert main(["plot", str(results)]) == 0
    assert (results.parent / output.MANIFEST).read_text().split() == sorted({"results.h5", "summary.md", *drawn})
    assert snapshot(results.parent)["notes.txt"] == b"mine"


def test_a_file_put_in_place_while_the_figures_are_drawn_is_not_overwritten(tmp_path):
    folder = tmp_path / "figures"
    folder.mkdir()

    def draw(stage):
        (folder / "bode.png").write_bytes(b"my figure")  # saved by the user meanwhile
        (stage / "bode.png").write_bytes(b"drawn")
        return [stage / "bode.png"]

    with pytest.raises(InputError, match=r"--out: expected no file that sixdof did not write .* got 1 such file\(s\): "
                                         r"bode.png$"):
        output.replace_files(folder, draw)
    assert snapshot(folder) == {"bode.png": b"my figure"} and os.listdir(folder) == ["bode.png"]
