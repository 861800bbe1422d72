"""Results folders on disk: written all or nothing, never outside ``--out``, and nothing deleted that
sixdof did not write.

A run fills a staging folder ``<out>/.<name>.partial-<id>`` and swaps it into ``<out>/<name>`` once it
is complete:

* The writer holds an exclusive ``flock`` on its staging folder. The kernel releases it when the process
  ends, however it ends (SIGKILL included), so the next run into the same ``--out`` removes every staging
  folder whose lock it can take: no debris outlives a killed run.
* The swap (previous folder renamed aside, new one renamed into place, the user's files moved across,
  previous one removed) runs under an exclusive ``flock`` on ``<out>`` itself: two runs into the same
  target publish one after the other. SIGINT and SIGTERM are held back while a file is written (by its
  writer: :func:`~sixdof.interrupts.held_signals`) and while the folder is swapped, and acted on once that is
  done (after a
  swap, their exception carries ``written``: the results are complete and in place); while a run computes
  they act at once, and while a failed or stopped run removes its staging folder they are held and dropped.
  A SIGKILL in the middle of a swap leaves the previous folder as ``.<name>.old-<id>``; the next run
  finishes or undoes that swap before anything else.
* Each results folder lists the files sixdof wrote in ``.sixdof-files``. Any other file in a folder being
  replaced is the user's: it is moved into the new folder and reported, never deleted. A folder that
  exists and is not a sixdof results folder is not replaced at all (:func:`check_target`, before any
  computing).
* Files put into a folder one by one (:func:`replace_files`: ``sixdof plot``) replace only files sixdof wrote
  there; a file of the same name that it did not write is refused before anything is drawn
  (:func:`check_files`). The names written join the folder's ``.sixdof-files`` (made if missing), so that
  the next redraw may replace them.
* Folders are made with ``os.mkdir`` and files with ``open`` or h5py: both honour the umask.
* ``--out`` and its missing parents are made only when the results are written (checking them makes
  nothing), and a write that fails or is interrupted removes those it made again, if nothing else was put in
  them meanwhile: a run that stops leaves no trace of itself.

POSIX only (``fcntl``), like the command-line tool.
"""

from __future__ import annotations

import errno
import fcntl
import itertools
import os
import resource
import shutil
import signal
import uuid
import warnings
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from sixdof.errors import InputError, Plain, file_name
from sixdof.interrupts import held_signals

#: The list of files sixdof wrote into a results folder (one name per line).
MANIFEST = ".sixdof-files"
#: The results files that make a folder without a list sixdof's (written by an earlier version).
_RESULTS_FILES = frozenset({"results.h5", "sweep.h5"})
#: Files that earlier versions wrote without a manifest (``*.png`` figures are judged by the new run).
_UNLISTED = _RESULTS_FILES | {"summary.md", "validation.md"}


class KeptFilesWarning(UserWarning):
    """A results folder being replaced held files that sixdof did not write; they were kept."""


def check_output_root(out_root: str | Path) -> Path:
    """``out_root``, once sure that results can be written there: files can be made in it or, where it is
    missing, in its nearest existing parent (where :func:`write_folder` will make it). Makes nothing.

    Raises
    ------
    InputError
        If the folder could not be made or written.
    """
    root = Path(out_root)
    try:
        probe = _nearest_existing(root) / f".write-test-{uuid.uuid4().hex}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise InputError("--out", "a folder where results can be written", f"{root} ({exc.strerror})") from None
    return root


def check_target(out_root: str | Path, name: str, suffix: str = "") -> Path:
    """``<out_root>/<name><suffix>``, once sure that a run may write it: ``name`` is one safe path component
    (:func:`sixdof.errors.file_name`), ``out_root`` is writable and the target is absent or a sixdof results
    folder (anything else is the user's and is never replaced).

    Raises
    ------
    InputError
        Naming the field or the folder, before any computing.
    """
    name = file_name(name)
    target = check_output_root(out_root) / (name + suffix)
    _check_replaceable(target)
    return target


def _check_replaceable(target: Path) -> None:
    """Raise unless ``target`` is absent or a sixdof results folder."""
    if target.is_symlink() or (target.exists() and not target.is_dir()):
        raise InputError("--out", f"no file or link named {target.name} in {target.parent} (results go to a "
                         "folder there)", Plain(str(target)))
    if target.is_dir() and not _is_results_folder(target):
        found = sorted(p.name for p in target.iterdir())
        raise InputError("--out", f"{target} to be a sixdof results folder (or absent) before it is replaced; "
                         "choose another --out or scenario name",
                         Plain(f"a folder holding {len(found)} other {'entries' if len(found) > 1 else 'entry'}: "
                               f"{', '.join(found[:5])}" + (", ..." if len(found) > 5 else "")))


def check_files(directory: str | Path, names: Iterable[str]) -> None:
    """Raise unless each of the files ``names`` is absent from ``directory`` or one sixdof wrote there: what
    :func:`replace_files` may write over. Makes nothing.

    Raises
    ------
    InputError
        Naming the files sixdof did not write (``--out``), before anything is drawn.
    """
    directory = Path(directory)
    if not directory.is_dir():
        return
    names = list(names)
    ours = _sixdofs(directory, names)
    theirs = sorted(name for name in names if os.path.lexists(directory / name) and name not in ours)
    if theirs:
        raise InputError("--out", f"no file that sixdof did not write under the names it writes in {directory} "
                         "(such a file is never overwritten): choose another --out or move them elsewhere",
                         Plain(f"{len(theirs)} such file(s): {', '.join(theirs)}"))


def write_folder(target: Path, write: Callable[[Path], None], carry: Iterable[str] = ()) -> Path:
    """Have ``write(stage)`` fill a fresh staging folder, then swap it into ``target`` (see the module).

    Files of the user's found in a previous ``target`` are moved into the new one, with a
    :class:`KeptFilesWarning`. Files sixdof wrote there go with the previous folder, except those named in
    ``carry`` (an export's files of the other format) that ``write`` did not write again: they are kept
    as they were. On any failure or interruption the staging folder is removed and ``target`` is left as
    it was. Returns ``target``.
    """
    root = target.parent
    stage, stage_lock, made = _stage_in(root, target.name)
    try:
        # Not held while ``write`` computes (a long run must stop on Ctrl-C at once): the writers hold
        # signals around their own file writes (:func:`~sixdof.interrupts.held_signals`), and an interruption
        # anywhere ends here.
        write(stage)
        with held_signals(deliver=False) as received, _locked(root):
            _check_replaceable(target)  # something else may have been put there meanwhile
            _carry_over(target, stage, carry)
            _write_manifest(stage, [p.name for p in stage.iterdir()])
            kept = _swap(stage, target)
    except BaseException:
        _remove_stage(stage, made)
        raise
    finally:
        os.close(stage_lock)
    # A results folder of sixdof's inside the previous one (an export, written into it by default) is not the
    # user's but no longer matches the new results: kept all the same (nobody asked for it to go), said as such.
    stale = [name for name in kept if (target / name / MANIFEST).is_file()]
    users = [name for name in kept if name not in stale]
    if users:
        warnings.warn(f"{target} held {len(users)} file(s) that sixdof did not write; kept them: {', '.join(users)}",
                      KeptFilesWarning, stacklevel=2)
    if stale:
        warnings.warn(f"{target} held {', '.join(stale)}, written by sixdof from the results this run replaces: kept, "
                      "but made from the previous results (write it again to match the new ones)",
                      KeptFilesWarning, stacklevel=2)
    _deliver(received, target)
    return target


def _remove_stage(stage: Path, made: list[Path]) -> None:
    """Remove a staging folder (and the folders made for it) after a failure: with SIGINT and SIGTERM held back,
    so that a second Ctrl-C (a terminal's repeat, ``timeout``'s) does not cut the cleanup short and leave it."""
    with held_signals(deliver=False):  # the failure being handled already ends the command
        shutil.rmtree(stage, ignore_errors=True)
        _remove_if_empty(made)


def _deliver(received: list[int], written: Path) -> None:
    """Act on a signal held back while results were put in place, now that they are: its exception (the
    handler's: KeyboardInterrupt, or the command line's for SIGTERM) carries ``written``, the complete results,
    so that the report does not say that nothing was left."""
    if received:
        try:
            signal.raise_signal(received[0])
        except BaseException as exc:
            exc.written = written
            raise


def replace_files(directory: Path, write: Callable[[Path], list[Path]]) -> list[Path]:
    """Have ``write(stage)`` write files into a staging folder, then move them all into ``directory``.

    Each file replaces its namesake whole (no reader ever sees a truncated figure), and the set is moved
    with SIGINT and SIGTERM held back. A namesake sixdof did not write is never replaced: the caller checks
    with :func:`check_files` before writing, and the move checks again. Nothing else in ``directory`` is
    touched, except that its list of sixdof's files (made if missing) gains the new names. Returns the
    files in ``directory``.

    Raises
    ------
    InputError
        A namesake sixdof did not write, put there while ``write`` ran; nothing is moved.
    """
    stage, stage_lock, made = _stage_in(directory, "files")
    try:
        with held_signals():
            names = [p.name for p in write(stage)]
        with held_signals(deliver=False) as received, _locked(directory):
            check_files(directory, names)  # something may have been put there meanwhile
            if (directory / MANIFEST).exists():
                earlier = set(_listed(directory))
            else:  # the first list: a results folder of an earlier version's files go into it too
                earlier = _sixdofs(directory, ()) & set(os.listdir(directory))
            for name in names:
                os.replace(stage / name, directory / name)
            _write_manifest(directory, earlier | set(names))
    except BaseException:
        _remove_stage(stage, made)
        raise
    finally:
        os.close(stage_lock)
    shutil.rmtree(stage, ignore_errors=True)  # emptied by the moves, unless the writer left more
    _deliver(received, directory)
    return [directory / name for name in names]


def check_room(path: Path, nbytes: int) -> None:
    """Raise the OSError a write of ``nbytes`` to ``path`` would meet, before writing: no space left on its
    filesystem, or over the process's file-size limit (``ulimit -f``).

    Checked up front because HDF5 meets these errors deep in its own code and, once a write failed,
    repeats them in a traceback for every object it closes.
    """
    free = shutil.disk_usage(_nearest_existing(path.parent)).free
    if nbytes > free:
        raise OSError(errno.ENOSPC, f"No space left on device (needs at least {nbytes:,} bytes, {free:,} free)",
                      str(path))
    limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    if limit != resource.RLIM_INFINITY and nbytes > limit:
        raise OSError(errno.EFBIG, f"File too large (needs at least {nbytes:,} bytes, the file-size limit is "
                      f"{limit:,})", str(path))


@contextmanager
def _locked(folder: Path) -> Iterator[None]:
    """An exclusive ``flock`` on ``folder`` for the block (waits for other sixdof processes)."""
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def _missing(path: Path) -> list[Path]:
    """``path`` and those of its parents that do not exist, deepest first (none if ``path`` exists)."""
    return list(itertools.takewhile(lambda folder: not os.path.lexists(folder), (path, *path.parents)))


def _nearest_existing(path: Path) -> Path:
    """``path`` or, where it is missing, its nearest parent that exists."""
    return (path, *path.parents)[len(_missing(path))]


def _stage_in(root: Path, name: str) -> tuple[Path, int, list[Path]]:
    """A new staging folder in ``root``, made with its missing parents; the descriptor holding the staging
    folder's lock, and the folders made for it (deepest first), for :func:`_remove_if_empty`."""
    made = _missing(root)
    for _ in range(5):
        root.mkdir(parents=True, exist_ok=True)
        try:
            with _locked(root):
                _clean_debris(root)
                return (*_new_stage(root, name), made)
        except FileNotFoundError:  # another run that had made ``root`` failed and removed it meanwhile: again
            continue
    raise FileNotFoundError(errno.ENOENT, "removed by another process each time it was made", str(root))


def _remove_if_empty(folders: list[Path]) -> None:
    """Remove ``folders`` (deepest first), made for a write that failed, as long as they are empty: anything
    put in one meanwhile (another run's results, a user's file) keeps it and its parents."""
    for folder in folders:
        try:
            folder.rmdir()
        except FileNotFoundError:
            continue
        except OSError:
            return


def _new_stage(root: Path, name: str) -> tuple[Path, int]:
    """A new staging folder in ``root`` (made under ``root``'s lock) and the descriptor holding its lock."""
    stage = root / f".{name}.partial-{uuid.uuid4().hex}"
    os.mkdir(stage)
    fd = os.open(stage, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)
    return stage, fd


def _clean_debris(root: Path) -> None:
    """Remove the staging folders of dead runs and finish (or undo) their interrupted swaps; hold ``root``'s lock."""
    for entry in root.iterdir():
        if not entry.name.startswith(".") or not entry.is_dir() or entry.is_symlink():
            continue
        if ".partial-" in entry.name:
            fd = os.open(entry, os.O_RDONLY)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                continue  # a live run is filling it
            finally:
                os.close(fd)
            shutil.rmtree(entry, ignore_errors=True)
        elif ".old-" in entry.name:
            target = root / entry.name[1:].rpartition(".old-")[0]
            if target.exists():
                _keep_users_files(entry, target)
                shutil.rmtree(entry, ignore_errors=True)
            else:
                os.replace(entry, target)


def _carry_over(previous: Path, stage: Path, names: Iterable[str]) -> None:
    """Link the files ``names`` that sixdof wrote in ``previous`` into ``stage``, where it has none of that
    name; hold ``previous``'s parent's lock. Linked, not moved: ``previous`` stays whole until the swap, so
    a run killed before it loses nothing."""
    names = set(names)
    if not names or not (previous / MANIFEST).exists():
        return
    for name in sorted(names & set(_listed(previous))):
        source, destination = previous / name, stage / name
        if os.path.lexists(destination) or source.is_symlink() or not source.is_file():
            continue
        try:
            os.link(source, destination)
        except OSError:  # ``previous`` is on another filesystem (a mount point), or this one has no hard links
            shutil.copy2(source, destination)


def _swap(stage: Path, target: Path) -> list[str]:
    """Put ``stage`` in the place of ``target``; returns the names of the user's files moved across."""
    if not target.exists():
        os.replace(stage, target)
        return []
    old = target.with_name(f".{target.name}.old-{uuid.uuid4().hex}")
    os.replace(target, old)
    try:
        os.replace(stage, target)
    except BaseException:
        os.replace(old, target)
        raise
    kept = _keep_users_files(old, target)
    shutil.rmtree(old, ignore_errors=True)
    return kept


def _keep_users_files(old: Path, new: Path) -> list[str]:
    """Move the entries of ``old`` that sixdof did not write into ``new``; returns their names."""
    ours = _sixdofs(old, os.listdir(new))
    kept = []
    for entry in sorted(os.listdir(old)):
        if entry not in ours:
            destination = new / entry
            if destination.exists():
                destination = new / f"{entry}.kept-{uuid.uuid4().hex[:8]}"
            os.replace(old / entry, destination)
            kept.append(destination.name)
    return kept


def _sixdofs(folder: Path, new: Iterable[str]) -> set[str]:
    """The names in ``folder`` that are sixdof's: those of its list of sixdof's files or, in a results folder
    written by an earlier version (no list), the names sixdof writes (``new``: those a new write brings)."""
    if (folder / MANIFEST).exists():
        return {MANIFEST, *_listed(folder)}
    if set(os.listdir(folder)) & _RESULTS_FILES:
        return _UNLISTED | set(new)
    return set()


def _listed(folder: Path) -> list[str]:
    """The names in ``folder``'s list of sixdof's files."""
    return (folder / MANIFEST).read_text(encoding="utf-8").splitlines()


def _write_manifest(folder: Path, names) -> None:
    """Write ``folder``'s list of sixdof's files whole (under a temporary name, then renamed)."""
    temporary = folder / f".{MANIFEST}.{uuid.uuid4().hex}.tmp"
    temporary.write_text("".join(f"{n}\n" for n in sorted(set(names) - {MANIFEST})), encoding="utf-8")
    os.replace(temporary, folder / MANIFEST)


def _is_results_folder(folder: Path) -> bool:
    """Written by sixdof (its list of files, or a results file of an earlier version), or empty."""
    names = set(os.listdir(folder))
    return not names or MANIFEST in names or bool(names & _RESULTS_FILES)
