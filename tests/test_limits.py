"""Inputs that could crash, hang or corrupt a run: devices and symlink loops for files, tables of millions of
rows, sizes and counts far beyond what a machine can compute, values that overflow or underflow, signals while
the command starts. Each is refused up front with one line naming the file and the field (or ends with its
documented exit status), never a traceback or a hang."""

import os
import re
from pathlib import Path

import pytest

from sixdof import ScenarioError, load_scenario
from sixdof import files as input_files
from sixdof.cli import EXIT_BAD_INPUT, main

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
    with pytest.raises(ScenarioError, match=rf"^{re.escape(str(scenario))}: {re.escape(field)}: expected {expected}"):
        load_scenario(scenario)


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
        "16 MiB, got " f"{tmp_path / 'huge.toml'}, 16,777,217 bytes\n"


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
