"""The one TOML reader of sixdof: scenario files and sweep specifications alike.

A file's text is parsed with the standard library's :mod:`tomllib`; its tables are read through
:class:`Table`, which tracks the field path (``mounts[2].stiffness``) and rejects unknown keys with the
closest valid key suggested ("did you mean"); :func:`build` turns a table into a frozen object whose
field names are its keys. Every error is an :class:`~sixdof.errors.InputError` naming the field, and
:func:`parse` puts the file name in front (:class:`~sixdof.errors.ScenarioError`), as :func:`naming` does for
the checks made once a file is read.
"""

from __future__ import annotations

import dataclasses
import difflib
import tomllib
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.errors import InputError, Plain, ScenarioError
from sixdof.files import read_text as read

_MISSING = object()


def parse(text: str, source: str, read: Callable[[dict], Any]) -> Any:
    """``read(table)`` of the TOML ``text``, every error prefixed with ``source`` (a file name)."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(source, InputError("", "valid TOML", str(exc))) from None
    except RecursionError:  # tomllib recurses once per level of nested arrays or inline tables
        raise ScenarioError(source, InputError("", "valid TOML", Plain("arrays or tables nested too deep to "
                                                                       "read"))) from None
    with naming(source):
        return read(raw)


@contextmanager
def naming(source: str | Path | None) -> Iterator[None]:
    """An :class:`~sixdof.errors.InputError` raised in the block gets the file name ``source`` put in front
    (:class:`~sixdof.errors.ScenarioError`), as :func:`parse` does: for the checks of a file's content made
    once it is read (a sweep spec's draws against the scenario's mounts, the checks a run makes). ``None`` (text
    read from no file), an error that names its file already and one about a command-line option (``--out``)
    leave the error as it is."""
    try:
        yield
    except ScenarioError:
        raise
    except InputError as exc:
        if source is None or exc.field.startswith("--"):
            raise
        raise ScenarioError(str(source), exc) from None


def read_text(path: str | Path, what: str) -> str:
    """The UTF-8 text of ``path`` (a byte-order mark dropped); a missing or unreadable file, anything but a
    regular file and a file beyond :data:`sixdof.files.MAX_TEXT_BYTES` are errors naming it (``what``:
    "scenario file", "sweep specification"), before anything is read."""
    try:
        return read(path, "", what)
    except InputError as exc:
        raise ScenarioError(str(path), exc) from None


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


class Table:
    """Reads the keys of one TOML table, tracking its path; unknown keys are rejected up front."""

    def __init__(self, raw: Any, path: str, keys: tuple[str, ...]) -> None:
        if not isinstance(raw, dict):
            raise InputError(path or "(top level)", "a table", raw)
        reject_unknown(raw, keys, path)
        self.raw = raw
        self.path = path

    def value(self, key: str, default: Any = _MISSING) -> Any:
        if key in self.raw:
            return self.raw[key]
        if default is _MISSING:
            raise InputError(_join(self.path, key), "a value (required key)", Plain("nothing"))
        return default

    def string(self, key: str, default: Any = _MISSING) -> str:
        value = self.value(key, default)
        if not isinstance(value, str) or (default is _MISSING and not value):
            raise InputError(_join(self.path, key), "a non-empty string", value)
        return value

    def table(self, key: str, default: Any = _MISSING) -> Any:
        value = self.value(key, default)
        if value is not default and not isinstance(value, dict):
            raise InputError(_join(self.path, key), f"a table [{key}]", value)
        return value

    def tables(self, key: str, required: bool = False) -> list[dict]:
        value = self.raw.get(key, Plain("nothing") if required else [])
        if not isinstance(value, list) or any(not isinstance(v, dict) for v in value) or (required and not value):
            expected = f"at least one [[{key}]] table" if required else f"an array of tables [[{key}]]"
            raise InputError(_join(self.path, key), expected, value)
        return value


def reject_unknown(raw: dict, known, path: str) -> None:
    for key in raw:
        if key not in known:
            close = difflib.get_close_matches(key, list(known), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise InputError(_join(path, key), f"one of the keys {choices(known)}", Plain(f"an unknown key{hint}"))


def build(cls, table: Any, path: str):
    """``cls(**table)`` for a frozen dataclass whose field names are the table's keys."""
    if not isinstance(table, dict):
        raise InputError(path, "a table", table)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    reject_unknown(table, fields, path)
    for name, f in fields.items():
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        if required and name not in table:
            raise InputError(_join(path, name), "a value (required key)", Plain("nothing"))
    return make(cls, path, **table)


def make(factory, path: str, **kwargs):
    """Call a constructor, putting ``path`` before the field of any :class:`InputError`."""
    try:
        return factory(**kwargs)
    except InputError as exc:
        raise exc.within(path) if path else exc from None


def unique(names: list[str], path: str) -> None:
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise InputError(path, "unique names", f"{', '.join(repeated)} repeated")


def choices(keys) -> str:
    return ", ".join(sorted(keys))


def is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)


def boolean(value: Any, field: str) -> bool:
    """Check of ``true`` or ``false`` (a field check, see :func:`sixdof.frozen.checked`)."""
    if not isinstance(value, bool):
        raise InputError(field, "true or false", value)
    return value
