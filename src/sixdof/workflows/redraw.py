"""``sixdof plot``: every figure of a results file drawn again, whichever command wrote it, or of every results file
in a folder.

The kind of a file is read from its own metadata (the root attribute ``format`` that :mod:`sixdof.io.store` writes,
and for a run's file whether it holds a sweep), never from its name:

- a run's or validation's ``results.h5`` (spectrum runs included): :data:`sixdof.plots.FIGURES`;
- a sweep's ``sweep.h5``: :data:`sixdof.plots.sweep.SWEEP_FIGURES`;
- an optimization's ``design.h5``: :func:`sixdof.workflows.optimize.record_figures`;
- a correlation's ``correlation.h5``: :data:`sixdof.plots.CORRELATION_FIGURES`.
"""

from __future__ import annotations

from pathlib import Path

from sixdof.errors import InputError, Plain
from sixdof.io import output
from sixdof.io.settings import stored_figure_settings
from sixdof.io.store import load_results
from sixdof.io.store.tree import CORRELATION_FORMAT, DESIGN_FORMAT, FORMAT
from sixdof.plots import correlation_figure_names, figure_names, png, render_correlation
from sixdof.workflows.drawing import drawer

#: What ``sixdof plot`` takes, in words (its errors name it).
EXPECTED = ("a sixdof results file: the results.h5 of `sixdof run` or `sixdof validate`, the sweep.h5 of "
            "`sixdof sweep`, the design.h5 of `sixdof optimize` or the correlation.h5 of `sixdof correlate` "
            "(or a folder holding such files)")
_KINDS = {FORMAT: "run", DESIGN_FORMAT: "design", CORRELATION_FORMAT: "correlation"}


def file_kind(path: str | Path) -> str:
    """The kind of the results file ``path``, from its stored metadata: ``"run"``, ``"sweep"``, ``"design"`` or
    ``"correlation"``.

    Raises
    ------
    InputError
        A file that is missing, not HDF5, or not one sixdof writes, naming the file, what was expected and what
        was found.
    """
    import h5py

    path = Path(path)
    if not path.is_file():
        raise InputError("results", EXPECTED, Plain(f"{path}: no such file"))
    try:
        with h5py.File(path, "r") as f:
            found = f.attrs.get("format")
            sweep = "sweep" in f
    except OSError:
        raise InputError("results", EXPECTED, Plain(f"{path}: not an HDF5 file")) from None
    if isinstance(found, bytes):
        found = found.decode("utf-8", "replace")
    if found not in _KINDS:
        what = "no root attribute 'format'" if found is None else f"root attribute format = {found!r}"
        raise InputError("results", EXPECTED, Plain(f"{path}: an HDF5 file with {what}"))
    kind = _KINDS[found]
    return "sweep" if kind == "run" and sweep else kind


def redraw(results: str | Path, directory: str | Path | None = None, *,
           workers=None) -> list[Path]:
    """Draw every figure of a results file again (``sixdof plot``), or of every results file in the folder
    ``results`` (those under it, at any depth, that sixdof wrote; other files are passed over), and put them into
    ``directory`` (default: beside each file; for a folder, ``directory`` takes the place of the folder), each
    replacing its namesake and all of a file's at once (:func:`sixdof.io.output.replace_files`). A namesake that
    sixdof did not write is never replaced: it is refused before anything is drawn.

    A run's figures are written in the ``[output] formats``, at the ``dpi``, of the scenario the file was
    computed from (the text it stores), else as PNG at 150 dpi, and drawn by ``workers``
    (:class:`sixdof.plots.drawer.FigureDrawer`; the command line starts them before it reads the file); default:
    in this process. Those of the other kinds are drawn here, as PNG.

    Returns
    -------
    list of pathlib.Path
        The figures written.

    Raises
    ------
    InputError
        A ``directory`` where files cannot be written or holding a file sixdof did not write under a figure's
        name (``--out``), a file of no kind sixdof writes (:func:`file_kind`), one with nothing to draw, or a
        folder holding no results file.
    """
    if directory:  # checked as run checks its --out: before reading or drawing anything
        output.check_output_root(directory)
    results = Path(results)
    if not results.is_dir():
        return _redraw_file(results, Path(directory) if directory else results.parent, workers)
    found = []
    for path in sorted(results.rglob("*.h5")):
        try:
            found.append((path, file_kind(path)))
        except InputError:
            continue  # not sixdof's: a folder may hold other HDF5 files
    if not found:
        raise InputError("results", EXPECTED, Plain(f"{results}: a folder with no sixdof results file in it"))
    written = []
    for path, _ in found:
        target = path.parent if not directory else Path(directory) / path.parent.relative_to(results)
        written.extend(_redraw_file(path, target, workers))
    return written


def _redraw_file(path: Path, directory: Path, workers) -> list[Path]:
    """Every figure of the results file ``path`` into ``directory``."""
    kind = file_kind(path)
    if kind == "run":
        return _redraw_run(path, directory, workers)
    run = load_results(path)
    if kind == "correlation":
        names = correlation_figure_names(run)
        figures = {name: (lambda name=name: render_correlation(run, name)) for name in names}
    elif kind == "sweep":
        from sixdof.plots.sweep import draw_sweep, sweep_figure_names  # noqa: PLC0415 (matplotlib, JAX: a sweep's)

        names = sweep_figure_names(run)
        figures = {name: (lambda name=name: png(draw_sweep(run, name))) for name in names}
    else:
        from sixdof.workflows.optimize import record_figures  # noqa: PLC0415 (JAX: a design's figures only)

        drawn = record_figures(run, base_dir=(run.provenance or {}).get("scenario_folder") or ".")
        names = list(drawn)
        figures = {name: (lambda name=name: png(drawn[name])) for name in names}
    if not names:
        raise InputError("results", "a results file with something to draw", Plain(f"{path}: nothing to draw"))
    output.check_files(directory, names)

    def save(stage: Path) -> list[Path]:
        for name in names:
            (stage / name).write_bytes(figures[name]())
        return [stage / name for name in names]

    return output.replace_files(directory, save)


def _redraw_run(path: Path, directory: Path, workers) -> list[Path]:
    run = load_results(path)
    if not figure_names(run):
        raise InputError("results", "a results file with something to draw (the results.h5 of `sixdof run` or "
                         "`sixdof validate`)", Plain(f"{path}: nothing to draw"))
    formats, dpi = stored_figure_settings(run.provenance)
    output.check_files(directory, [f"{Path(name).stem}.{kind}" for name in figure_names(run) for kind in formats])
    with drawer(workers) as drawing:
        drawing.formats, drawing.dpi = formats, dpi  # the results hold no scenario for the drawer to read them from
        drawing.submit(run)
        return output.replace_files(directory, drawing.save)
