"""The example scenarios bundled with sixdof: the repository's ``scenarios/`` folder, installed with the
package as ``sixdof/scenarios`` (a link to it in the source tree). :func:`copy_examples` puts them where a
user can run and adapt them (``sixdof examples FOLDER``)."""

from __future__ import annotations

import os
import shutil
from importlib import resources
from pathlib import Path

from sixdof.errors import InputError, Plain

#: What a bundled example is made of: scenarios, the tables they read, a test file (UFF) and its truth (JSON).
EXTENSIONS = (".toml", ".csv", ".uff", ".json")


def _folder():
    """The installed examples (a :class:`importlib.resources.abc.Traversable`)."""
    return resources.files("sixdof") / "scenarios"


def example_files() -> list[str]:
    """The bundled files, as paths relative to their folder (scenarios, the data they read, sweeps, tests)."""
    found = []

    def walk(folder, prefix=""):
        for item in sorted(folder.iterdir(), key=lambda i: i.name):
            if item.is_dir():
                walk(item, f"{prefix}{item.name}/")
            elif item.name.endswith(EXTENSIONS):
                found.append(f"{prefix}{item.name}")

    walk(_folder())
    return found


def copy_examples(folder: str | os.PathLike) -> list[Path]:
    """Copy every bundled example into ``folder`` (created when missing), keeping their relative layout.

    Nothing is overwritten: when any of the files already exists there, nothing is copied and an
    :class:`~sixdof.errors.InputError` names them. Returns the files written.
    """
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError("folder", "a folder to copy the examples into", Plain(f"{folder}, which is a file"))
    names = example_files()
    taken = [name for name in names if (folder / name).exists()]
    if taken:
        raise InputError("folder", "a folder without the example files (none is overwritten)",
                         Plain(f"{folder}, which already holds {', '.join(taken)}"))
    written = []
    for name in names:
        target = folder / name
        target.parent.mkdir(parents=True, exist_ok=True)
        with resources.as_file(_folder().joinpath(*name.split("/"))) as source:
            shutil.copyfile(source, target)
        written.append(target)
    return written


__all__ = ["copy_examples", "example_files"]
