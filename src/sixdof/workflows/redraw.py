"""``sixdof plot``: every figure of a results file drawn again."""

from __future__ import annotations

from pathlib import Path

from sixdof.errors import InputError, Plain
from sixdof.io import output
from sixdof.io.settings import stored_figure_settings
from sixdof.io.store import load_results
from sixdof.plots import figure_names
from sixdof.workflows.drawing import drawer


def redraw(results: str | Path, directory: str | Path | None = None, *,
           workers=None) -> list[Path]:
    """Draw every figure of a results file again (``sixdof plot``) and put them into ``directory``
    (default: beside the file), each replacing its namesake and all of them at once
    (:func:`sixdof.io.output.replace_files`). A namesake that sixdof did not write is never replaced: it is
    refused before anything is drawn.

    Each figure is written in the ``[output] formats``, at the ``dpi``, of the scenario the file was computed
    from (the text it stores), else as PNG at 150 dpi. The figures are drawn by ``workers``
    (:class:`sixdof.plots.drawer.FigureDrawer`; the command line starts them before it reads the file); default:
    in this process.

    Returns
    -------
    list of pathlib.Path
        The figures written.

    Raises
    ------
    InputError
        A ``directory`` where files cannot be written or holding a file sixdof did not write under a figure's
        name (``--out``), or a results file with nothing to draw.
    """

    if directory:  # checked as run checks its --out: before reading or drawing anything
        output.check_output_root(directory)
    run = load_results(results)
    if not figure_names(run):
        what = "a sweep's results (`sixdof sweep`): no figures" if run.sweep is not None else "nothing to draw"
        raise InputError("results", "a results file with something to draw (the results.h5 of `sixdof run` or "
                         "`sixdof validate`)", Plain(f"{results}: {what}"))
    directory = Path(directory) if directory else Path(results).parent
    formats, dpi = stored_figure_settings(run.provenance)
    output.check_files(directory, [f"{Path(name).stem}.{kind}" for name in figure_names(run) for kind in formats])
    with drawer(workers) as drawing:
        drawing.formats, drawing.dpi = formats, dpi  # the results hold no scenario for the drawer to read them from
        drawing.submit(run)
        return output.replace_files(directory, drawing.save)
