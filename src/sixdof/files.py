"""Bounded reading of the user's input files: scenario and sweep TOML, CSV tables.

Every input file is read here, so that each gets the same checks before a byte of it is read: the path
is a regular file (not ``/dev/zero``, a FIFO that would block, a directory or a symlink loop) no larger
than its limit, read whole in one go (a file that grows while read stops at the limit), decoded as UTF-8
with or without a byte-order mark. A CSV table has at most :data:`MAX_CSV_ROWS` data rows; an error about
a row names its line and the offending field, never echoing more of the file than that field (shortened).
"""

from __future__ import annotations

import csv
import io
import os
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from sixdof.errors import InputError, Plain

#: The largest scenario or sweep specification file [bytes]: the bundled ones are 2-6 kB, 1000 mounts 110 kB;
#: tomllib reads about 1.7 MiB/s (20,000 mounts, 2.1 MiB, in 1.3 s), so 4 MiB in under 3 s.
MAX_TEXT_BYTES = 4 * 2**20
#: The largest CSV table [bytes]: a million rows of two numbers in full precision (25 digits each) fit.
MAX_CSV_BYTES = 64 * 2**20
#: The most rows of a CSV table (a header included): a 1000 s record at 1 kHz. Each row of a table signal is a
#: breakpoint of the direct solve's step control; 3 million rows took 46 s to read and run before this limit.
MAX_CSV_ROWS = 1_000_000
#: The most characters of a CSV field an error shows.
SHOWN_CHARACTERS = 40

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


def _mib(size: float) -> str:
    return f"{size / 2**20:.3g} MiB"


def read_text(path: str | Path, field: str, what: str, limit: int = MAX_TEXT_BYTES) -> str:
    """The text of the regular file ``path`` of at most ``limit`` bytes, decoded as UTF-8 (a leading
    byte-order mark dropped).

    Parameters
    ----------
    path : str or pathlib.Path
        The file (a symlink is followed).
    field : str
        Field named by the errors (``"ground.signal.file"``; ``""`` for a scenario file itself).
    what : str
        What the file is, for the errors (``"CSV file"``).
    limit : int
        The largest size accepted [bytes].

    Raises
    ------
    InputError
        Naming ``field``: a missing or unreadable file, a symlink loop, anything but a regular file, a file
        larger than ``limit``, or one that is not UTF-8; before anything is read from it.
    """
    path = Path(path)
    try:
        # O_NONBLOCK: opening a FIFO would wait for a writer; fstat then checks the file opened, not a name
        # that could be replaced between a check and the open.
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise InputError(field, f"an existing, readable {what}", str(path)) from None
    except OSError as exc:  # a symlink loop (ELOOP), permissions, a path through a file (ENOTDIR)
        raise InputError(field, f"an existing, readable {what}", Plain(f"{path}: {exc.strerror or exc}")) from None
    try:
        info = os.fstat(fd)
        kind = next((name for test, name in _KINDS if test(info.st_mode)), None)
        if kind is not None or not stat.S_ISREG(info.st_mode):
            raise InputError(field, f"a {what} (a regular file)", Plain(f"{path}, {kind or 'not a regular file'}"))
        if info.st_size > limit:
            raise InputError(field, f"a {what} of at most {_mib(limit)}", Plain(f"{path}, {info.st_size:,} bytes"))
        with os.fdopen(fd, "rb", closefd=False) as handle:
            data = handle.read(limit + 1)
    except OSError as exc:
        raise InputError(field, f"a readable {what}", Plain(f"{path}: {exc.strerror or exc}")) from None
    finally:
        os.close(fd)
    if len(data) > limit:  # it grew while it was read
        raise InputError(field, f"a {what} of at most {_mib(limit)}", Plain(f"{path}, larger"))
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise InputError(field, f"a UTF-8 {what}", Plain(f"{path}: 'utf-8' codec can't decode byte "
                                                          f"0x{data[exc.start]:02x} on line {line}")) from None


def csv_rows(path: str | Path, field: str, expected: str, name: str | None = None) -> Iterator[tuple[int, list[str]]]:
    """``(line number, fields)`` of each row of the CSV file ``path`` that is neither blank nor a ``#``
    comment (:func:`read_text` first, with :data:`MAX_CSV_BYTES`).

    Parameters
    ----------
    path : str or pathlib.Path
    field : str
        Field named by the errors.
    expected : str
        What the file should hold, for the errors about its content.
    name : str, optional
        The file as the errors name it (default: ``path``).

    Raises
    ------
    InputError
        As :func:`read_text`; more than :data:`MAX_CSV_ROWS` rows; a line the csv module cannot read
        (a field beyond its 131,072 characters).
    """
    name = str(path) if name is None else name
    reader = csv.reader(io.StringIO(read_text(path, field, "CSV file", MAX_CSV_BYTES), newline=""))
    rows = 0
    try:
        for row in reader:
            if not row or row[0].lstrip().startswith("#"):
                continue
            rows += 1
            if rows > MAX_CSV_ROWS:
                raise InputError(field, f"a CSV file of at most {MAX_CSV_ROWS:,} rows",
                                 Plain(f"row {rows:,} on line {reader.line_num:,} of {name}"))
            yield reader.line_num, row
    except csv.Error as exc:
        raise InputError(field, expected, Plain(f"line {reader.line_num} of {name}: {exc}")) from None


def shown(text: str) -> str:
    """A CSV field as an error shows it: quoted, cut to :data:`SHOWN_CHARACTERS` characters."""
    return repr(text if len(text) <= SHOWN_CHARACTERS else text[:SHOWN_CHARACTERS - 3] + "...")


def csv_numbers(row: list[str], count: int, line: int, name: str, field: str, expected: str) -> list[float]:
    """The ``count`` fields of ``row`` (line ``line`` of ``name``) as finite floats.

    Raises
    ------
    InputError
        Naming the line and, for a field that is not a finite number, that field alone (:func:`shown`).
    """
    if len(row) != count:  # a column more is a mistake, not something to ignore
        raise InputError(field, expected, Plain(f"line {line} of {name}: {len(row)} field{'s' * (len(row) != 1)}"))
    values = []
    for j, cell in enumerate(row):
        try:
            value = float(cell)
        except ValueError:
            value = None
        if value is None or value - value != 0:  # not a number, or an infinity or NaN
            raise InputError(field, expected, Plain(f"line {line} of {name}, field {j + 1}: {shown(cell)}"))
        values.append(value)
    return values


def read_table_csv(file: Any, base_dir: Path, field: str, columns: tuple[str, str] = ("time in s", "value"),
                   increasing: bool = False) -> tuple[list[float], list[float]]:
    """Read a two-column CSV (default time [s], value) with an optional header line and ``#`` comment lines;
    with ``increasing``, its first column must increase strictly (checked here, where each row's line is known)."""
    if not isinstance(file, str) or not file:
        raise InputError(field, "a CSV file name (relative to the scenario file)", file)
    expected = f"a UTF-8 CSV file of rows of two finite numbers: {', '.join(columns)}"
    pairs, lines, first = [], [], True
    for line, row in csv_rows(base_dir / file, field, expected, name=file):
        try:
            pair = csv_numbers(row, 2, line, file, field, expected)
        except InputError:
            if first:  # only the first row may be a header
                first = False
                continue
            raise
        first = False
        pairs.append(pair)
        lines.append(line)
    if len(pairs) < 2:
        raise InputError(field, f"at least 2 rows of {', '.join(columns)}", f"{len(pairs)} rows in {file}")
    first = [x for x, _ in pairs]
    back = next((k for k in range(1, len(first)) if first[k] <= first[k - 1]), None) if increasing else None
    if back is not None:
        raise InputError(field, f"{expected}, the first column ({columns[0]}) strictly increasing",
                         Plain(f"{first[back]:g} on line {lines[back]} of {file}, after {first[back - 1]:g} on line "
                               f"{lines[back - 1]}"))
    return first, [value for _, value in pairs]
