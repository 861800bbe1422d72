"""Inputs that could crash, hang or corrupt a run: devices and symlink loops for files, tables of millions of
rows, sizes and counts far beyond what a machine can compute, values that overflow or underflow, signals while
the command starts. Each is refused up front with one line naming the file and the field (or ends with its
documented exit status), never a traceback or a hang."""

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sixdof import ScenarioError, load_scenario
from sixdof import files as input_files
from sixdof.cli import EXIT_BAD_INPUT, main
from sixdof.workflows.prepare import prepare

SCENARIOS = Path(__file__).parents[1] / "scenarios"
RECORD = 'signal = { kind = "table", file = "ground_accelerogram.csv" }'


def with_record(tmp_path: Path, file: str) -> Path:
    """The bundled earthquake scenario reading its ground record from ``file`` (relative to ``tmp_path``)."""
    text = (SCENARIOS / "cabinet_earthquake.toml").read_text()
    assert RECORD in text
    scenario = tmp_path / "case.toml"
    scenario.write_text(text.replace(RECORD, f'signal = {{ kind = "table", file = "{file}" }}'))
    return scenario


def refused(scenario: Path, field: str, expected: str) -> None:
    """Refused when read, or when the run prepares it (its first step, before anything is computed)."""
    with pytest.raises(ScenarioError, match=rf"^{re.escape(str(scenario))}: {re.escape(field)}: expected {expected}"):
        prepare(load_scenario(scenario))


# ----------------------------------------------------------------------------------------------------
# Files: checked before a byte is read.
# ----------------------------------------------------------------------------------------------------


def test_a_device_is_refused_before_it_is_read(tmp_path):
    refused(with_record(tmp_path, "/dev/zero"), "ground.signal.file",
            r"a CSV file \(a regular file\), got /dev/zero, a character device$")


def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path):
    os.mkfifo(tmp_path / "pipe.csv")  # opening it for reading would block until someone writes
    refused(with_record(tmp_path, "pipe.csv"), "ground.signal.file", r"a CSV file \(a regular file\), got .*pipe.csv, "
            r"a FIFO \(named pipe\)$")


def test_a_directory_and_a_symlink_loop_are_refused(tmp_path):
    (tmp_path / "folder.csv").mkdir()
    refused(with_record(tmp_path, "folder.csv"), "ground.signal.file", r"a CSV file \(a regular file\), got .*, a "
            "directory$")
    (tmp_path / "loop.csv").symlink_to("loop.csv")
    refused(with_record(tmp_path, "loop.csv"), "ground.signal.file", r"an existing, readable CSV file, got .*loop.csv: "
            "Too many levels of symbolic links$")


def test_a_file_beyond_the_size_limit_is_refused_unread(tmp_path):
    with open(tmp_path / "huge.csv", "wb") as handle:  # sparse: its size without its disk space
        handle.truncate(input_files.MAX_CSV_BYTES + 1)
    refused(with_record(tmp_path, "huge.csv"), "ground.signal.file", r"a CSV file of at most 64 MiB, got .*huge.csv, "
            "67,108,865 bytes$")


def test_a_table_beyond_the_row_limit_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(input_files, "MAX_CSV_ROWS", 100)
    (tmp_path / "long.csv").write_text("t, a\n" + "".join(f"{0.01 * i:.2f}, 0\n" for i in range(100)))
    refused(with_record(tmp_path, "long.csv"), "ground.signal.file", "a CSV file of at most 100 rows, got row 101 on "
            "line 101 of long.csv$")


def test_the_row_limit_is_a_thousand_seconds_at_1_khz():
    assert input_files.MAX_CSV_ROWS == 1_000_000 and input_files.MAX_CSV_BYTES == 64 * 2**20


def test_scenario_files_are_bounded_too(tmp_path, capsys):
    with pytest.raises(ScenarioError, match=r"^/dev/zero: expected a scenario file \(a regular file\), got /dev/zero, a "
                       "character device$"):
        load_scenario("/dev/zero")
    with open(tmp_path / "huge.toml", "wb") as handle:
        handle.truncate(input_files.MAX_TEXT_BYTES + 1)
    assert main(["run", str(tmp_path / "huge.toml"), "--out", str(tmp_path / "out")]) == EXIT_BAD_INPUT
    assert capsys.readouterr().err == f"sixdof: error: {tmp_path / 'huge.toml'}: expected a scenario file of at most " \
        "4 MiB, got " f"{tmp_path / 'huge.toml'}, 4,194,305 bytes\n"


def test_a_byte_order_mark_before_a_comment_is_read(tmp_path):
    record = (SCENARIOS / "ground_accelerogram.csv").read_bytes()
    (tmp_path / "bom.csv").write_bytes(b"\xef\xbb\xbf# exported by a spreadsheet\n" + record)
    bom = load_scenario(with_record(tmp_path, "bom.csv")).excitation.ground.signal
    plain = load_scenario(SCENARIOS / "cabinet_earthquake.toml").excitation.ground.signal
    assert bom.t.tolist() == plain.t.tolist() and bom.values.tolist() == plain.values.tolist()
    (tmp_path / "bom.toml").write_bytes(b"\xef\xbb\xbf" + (SCENARIOS / "machine_unbalance.toml").read_bytes())
    assert load_scenario(tmp_path / "bom.toml").name == "machine_unbalance"


@pytest.mark.parametrize(("content", "got"), [
    (b"t,a\n0,0\n1," + b"x" * 100_000 + b"\n", r"line 3 of bad.csv, field 2: 'x{37}\.\.\.'$"),
    (b"t,a\n0,0\n1,2," + b"y" * 5_000 + b"\n", r"line 3 of bad.csv: 3 fields$"),
    (b"t,a\n0,0\n1,nan\n", r"line 3 of bad.csv, field 2: 'nan'$"),
    (b"t,a\n0,0\n1,\"" + b"z" * 200_000 + b"\"\n", r"line 3 of bad.csv: field larger than field limit \(131072\)$"),
])
def test_a_bad_row_shows_no_more_than_its_offending_field(tmp_path, content, got):
    (tmp_path / "bad.csv").write_bytes(content)
    refused(with_record(tmp_path, "bad.csv"), "ground.signal.file",
            f"a UTF-8 CSV file of rows of two finite numbers: time in s, value, got {got}")


# ----------------------------------------------------------------------------------------------------
# Values that overflow or underflow: refused naming the field given, not a quantity derived from it.
# ----------------------------------------------------------------------------------------------------

MACHINE = SCENARIOS / "machine_unbalance.toml"
BOX = SCENARIOS / "electronics_box.toml"
BOX_PSD = "psd = { f_hz = [20.0, 80.0, 350.0, 2000.0], value = [0.01, 0.04, 0.04, 0.007]"


@pytest.mark.parametrize(("source", "old", "new", "field", "expected"), [
    (MACHINE, "duration = 3.0", "duration = 1e308", "simulation.duration",
     r"at most 1,000,000,000 samples .*, got 1e\+308 s at 2000 Hz, inf samples$"),
    (MACHINE, "sample_rate_hz = 2000.0", "sample_rate_hz = 1e300", "simulation.duration",
     r"at most 1,000,000,000 samples .*, got 3 s at 1e\+300 Hz, 3e\+300 samples$"),
    (MACHINE, "sample_rate_hz = 2000.0", "sample_rate_hz = 5e-324", "simulation.sample_rate_hz",
     r"a rate giving at least 2 samples over the duration of 3 s \(at least 0.333 Hz\), got 5e-324$"),
    (MACHINE, "stiffness = [2.5e5, 2.5e5, 6.0e5]", "stiffness = [1e308, 2.5e5, 6.0e5]", "mounts[0].stiffness",
     r"values small enough that the mount's stiffness and damping matrices .* stay finite, got \[1e\+308, "),
    (MACHINE, "damping = [350.0, 350.0, 750.0]", "damping = [1e308, 350.0, 750.0]", "mounts[0].damping",
     r"values small enough .* stay finite, got \[1e\+308, 350.0, 750.0\]$"),
    (MACHINE, "position = [-0.5, -0.35, -0.45]", "position = [-1e300, -0.35, -0.45]", "mounts[0].position",
     r"values small enough .* stay finite, got \[-1e\+300, "),
    (MACHINE, "stiffness = [2.5e5, 2.5e5, 6.0e5]", "stiffness = [1e300, 2.5e5, 6.0e5]", "mounts[0].stiffness",
     r"a body and mounts whose natural frequencies stay below 1e9 Hz .*, got \[1e\+300, 250000.0, 600000.0\]: "),
    (MACHINE, "mass = 500.0", "mass = 1e-300", "body.mass", r"a body and mounts whose natural frequencies stay below 1e9 Hz .*, got mass 1e-300: "),
    (MACHINE, "inertia = [60.4, 93.75, 86.7]", "inertia = [1e-300, 93.75, 86.7]", "body.inertia",
     r"principal moments that a real body can have"),
    (MACHINE, "inertia = [60.4, 93.75, 86.7]", "inertia = [1e-300, 1e-300, 1e-300]", "body.inertia",
     r"a body and mounts whose natural frequencies stay below 1e9 Hz .*, got a principal moment 1e-300: "),
    (MACHINE, "speed_rpm = 1480.0", "speed_rpm = 1e300", "loads[0].speed_rpm",
     r"a positive speed in rev/min, at most 6e10, got 1e\+300$"),
    (MACHINE, "f_hz = [1.0, 100.0]", "f_hz = [1.0, 1e300]", "frf.f_hz", r"frequencies up to 1e9 Hz, got \[1.0, 1e\+300\]$"),
    (BOX, BOX_PSD, "psd = { f_hz = [1e-300, 1e300], value = [0.01, 0.04]", "random.psd.f_hz",
     r"frequencies up to 1e9 Hz, got \[1e-300, 1e\+300\]$"),
    (BOX, "start = 0.01, duration = 0.011", "start = 0.01, duration = 1e-300", "ground.signal.duration",
     r"a positive, finite duration in s, at least 1e-9, got 1e-300$"),
])
def test_values_beyond_float_range_name_the_field_given(tmp_path, source, old, new, field, expected):
    text = source.read_text()
    assert old in text
    (tmp_path / "case.toml").write_text(text.replace(old, new, 1))
    refused(tmp_path / "case.toml", field, expected)


def test_a_run_of_an_overflowing_value_is_one_line_and_exit_2(tmp_path, capsys):
    (tmp_path / "case.toml").write_text(MACHINE.read_text().replace("duration = 3.0", "duration = 1e308"))
    assert main(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "out"), "--quiet"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"sixdof: error: {tmp_path / 'case.toml'}: simulation.duration: ")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("vary", [
    'parameter = "stiffness"\ndistribution = "grid"\nvalues = [1.0, 1e300]',
    'parameter = "damping"\ndistribution = "grid"\nvalues = [1.0, 1e300]',
    'parameter = "stiffness"\ndistribution = "normal"\nmean = 1e301\nstd = 1e300',
    'parameter = "position"\ndistribution = "normal"\nmean = 0.0\nstd = 1e300',
])
def test_sweep_draws_beyond_float_range_are_refused_before_computing(tmp_path, vary):
    from sixdof.io.sweep import load_sweep_spec

    (tmp_path / "spec.toml").write_text(("" if "grid" in vary else "count = 4\n") + f"[[vary]]\n{vary}\n")
    spec = load_sweep_spec(tmp_path / "spec.toml")
    with pytest.raises(ScenarioError, match=r"spec.toml: vary\[0\]: expected draws that keep every mount's stiffness "
                       r"and damping matrices finite and the natural frequencies below 1e9 Hz \(narrow the "
                       r"distribution\), got a draw of -?[0-9.]+e\+(299|30[01]) \(chunk 0\)$"):
        spec.check(load_scenario(SCENARIOS / "bridge_beam_traffic.toml").system)


# ----------------------------------------------------------------------------------------------------
# Worker counts; signals while the command starts.
# ----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("command", [["sweep", str(SCENARIOS / "bridge_beam_traffic.toml"), "--spec",
                                      str(SCENARIOS / "sweeps" / "bearing_tolerance.toml")],
                                     ["optimize", str(SCENARIOS / "engine_inclined_mounts.toml")]])
def test_workers_beyond_a_few_per_core_are_refused_before_anything_is_read(tmp_path, capsys, command):
    from sixdof.workflows.tasks import WORKERS_PER_CORE

    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    assert main([*command, "--out", str(tmp_path / "out"), "--workers", "100000"]) == EXIT_BAD_INPUT
    assert capsys.readouterr().err == (f"sixdof: error: --workers: expected at most {most:,} worker processes "
                                       f"({WORKERS_PER_CORE} per core of this machine's {os.cpu_count()}; each runs "
                                       "one thread), got 100000\n")
    assert not (tmp_path / "out").exists()


def test_workers_that_cannot_fit_in_memory_are_refused(monkeypatch):
    from sixdof.errors import InputError
    from sixdof.workflows import tasks

    monkeypatch.setattr(tasks, "WORKER_BYTES", 2**50)  # a PiB each
    with pytest.raises(InputError, match=r"^--workers: expected a local cluster that fits in this machine's .* GiB "
                       r"of memory, got 1 worker processes of at least 1073741824 MiB each, about 1.05e\+06 GiB$"):
        tasks.check_workers(1)


#: Start a Python command with SIGINT's default action, as a terminal starts it (a CI job started in the background
#: may ignore SIGINT, which Python then leaves ignored), by exec: a preexec_fn would fork this process, JAX's
#: threads in it.
AS_A_TERMINAL = ("import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
                 "os.execv(sys.executable, [sys.executable, *sys.argv[1:]])")


@pytest.mark.long
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_command_starts_is_one_line_and_its_status(tmp_path, signum):
    """At each delay the signal comes while the command's modules (sixdof._entry handles it from its first line),
    NumPy, JAX or the figure workers load, or the scenario is read, compiled or solved (JAX's compilation cache off: the run lasts several seconds): never a crash by a signal
    (SIGSEGV, SIGABRT: a negative status), a traceback, or a signal lost inside a finalizer (status 0)."""
    status, word = (130, "interrupted") if signum == signal.SIGINT else (143, "terminated (SIGTERM)")
    # Before sixdof._entry's first line runs (two interpreters start, then the sixdof package loads) a signal
    # gets Python's own handling, which nothing in sixdof can change: the earliest delay is twice the longest
    # of three such starts here (0.05 s on a quiet 2-core machine, more under load).
    started = []
    for _ in range(3):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", AS_A_TERMINAL, "-c", "import sixdof._entry"], check=True)
        started.append(time.perf_counter() - start)
    first = max(0.06, 2 * max(started))
    for delay in sorted({first, *(max(first, d) for d in (0.15, 0.3, 0.5, 0.8, 1.1, 1.5))}):
        process = subprocess.Popen(
            [sys.executable, "-c", AS_A_TERMINAL, "-m", "sixdof", "run", str(MACHINE), "--out", str(tmp_path / "out"),
             "--quiet"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
            env={**os.environ, "SIXDOF_JAX_CACHE": "off"})
        time.sleep(delay)
        os.killpg(process.pid, signum)
        _, err = process.communicate(timeout=120)
        assert (process.returncode, err) == (status, f"sixdof: {word}; no partial results were left\n"), delay
        assert not (tmp_path / "out").exists()


# ----------------------------------------------------------------------------------------------------
# Counts of mounts and points: refused before any of them is built.
# ----------------------------------------------------------------------------------------------------


def test_too_many_mounts_or_points_are_refused_before_they_are_read(tmp_path):
    from sixdof.io.scenario import MAX_POINTS
    from sixdof.model.system import MAX_MOUNTS

    text = MACHINE.read_text()
    mount = '[[mounts]]\nname = "m{i}"\nposition = [0.1, 0.2, -0.4]\nstiffness = [1e5, 1e5, 2e5]\n'
    (tmp_path / "mounts.toml").write_text(text + "".join(mount.format(i=i) for i in range(MAX_MOUNTS - 3)))
    refused(tmp_path / "mounts.toml", "mounts", r"at most 1,000 \[\[mounts\]\] tables, got 1,001$")
    point = '[[points]]\nname = "p{i}"\nposition = [0.1, 0.2, 0.3]\n'
    (tmp_path / "points.toml").write_text(text + "".join(point.format(i=i) for i in range(MAX_POINTS)))
    refused(tmp_path / "points.toml", "points", r"at most 1,000 \[\[points\]\] tables, got 1,001$")


def test_a_system_of_too_many_mounts_is_refused_in_the_api_too():
    from sixdof import RigidBody, System
    from sixdof.errors import InputError
    from sixdof.model.parts import Mount

    body = RigidBody(mass=500.0, inertia=[60.4, 93.75, 86.7])
    mount = Mount(name="m", position=[0.1, 0.2, -0.4], stiffness=[1e5, 1e5, 2e5])
    with pytest.raises(InputError, match=r"^mounts: expected at most 1,000 mounts, got 1,001 mounts$"):
        System(body=body, mounts=[mount] * 1001)


# ----------------------------------------------------------------------------------------------------
# What a command finds wrong in a scenario once it is read names the file as well.
# ----------------------------------------------------------------------------------------------------


def test_a_truncation_keeping_no_mode_is_refused_when_the_file_is_read(tmp_path):
    (tmp_path / "case.toml").write_text(MACHINE.read_text() + "\n[superposition]\nf_max_hz = 0.5\n")
    refused(tmp_path / "case.toml", "superposition.f_max_hz", r"at least the lowest natural frequency \(5.189 Hz\), "
            "got 0.5$")


def test_a_check_made_while_running_names_the_scenario_file(tmp_path, capsys):
    text = BOX.read_text()
    assert BOX_PSD in text
    (tmp_path / "case.toml").write_text(text.replace(BOX_PSD, "time_check = { duration = 0.01 }\n" + BOX_PSD))
    load_scenario(tmp_path / "case.toml")  # the record's length is judged against the modes, when the run starts
    assert main(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "out"), "--quiet"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.startswith(f"sixdof: error: {tmp_path / 'case.toml'}: random.time_check.duration: expected at least "
                          "3.571 s: 8 Welch segments of ") and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()


def test_importing_sixdof_leaves_the_signal_handlers_alone():
    """The command's early handlers (sixdof._entry) are the command's: a program importing the library keeps its."""
    code = ("import signal, sys; before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}; "
            "import sixdof, sixdof.cli; "
            "assert {s: signal.getsignal(s) for s in before} == before; assert 'sixdof._entry' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)
