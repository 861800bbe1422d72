"""Every figure of sixdof, drawn from the library's typed result objects.

Compute returns data, plot takes data (as in python-control: ``response = frequency_response(sys);
bode_plot(response)``)::

    from sixdof import receptance
    from sixdof.plots import plot_bode

    fig = plot_bode(receptance(system, f_hz), modes=system.modes)

Each function takes the objects it draws (:class:`~sixdof.analysis.modal.Modes`,
:class:`~sixdof.results.TimeHistory`, :class:`~sixdof.analysis.frf.FRF`,
:class:`~sixdof.validation.ValidationReport`...) and returns its figure so that tests and users can
inspect or restyle it; :func:`save_all` draws every figure a :class:`~sixdof.results.RunResults`
allows (a live run, or a stored one from :func:`sixdof.io.store.load_results`) and writes each as PNG.

Figures are built as :class:`matplotlib.figure.Figure` objects without pyplot: no backend, no display
and no global figure list are involved (they render with Agg when saved, work headless, and show in
Jupyter), and nothing needs closing.

Modules: :mod:`~sixdof.plots.common` (display units, envelope decimation, margins, panel grid,
titles), :mod:`~sixdof.plots.modes`, :mod:`~sixdof.plots.time`, :mod:`~sixdof.plots.frf`,
:mod:`~sixdof.plots.validation`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path

from matplotlib.figure import Figure

from sixdof.analysis.frf import ForceTransmissibility, GroundTransmissibility, PointFRF
from sixdof.plots.common import DPI, MAX_POINTS, PNG_COMPRESS_LEVEL, envelope_indices, require
from sixdof.plots.frf import plot_bode, plot_point_frfs
from sixdof.plots.modes import (
    FLAT_SIDE,
    MAX_DRAWN_ROTATION,
    MIN_ASPECT,
    MODE_SCALE,
    body_box,
    plot_ke_distribution,
    plot_mode_shapes,
)
from sixdof.plots.time import plot_mount_forces, plot_superposition, plot_time_histories
from sixdof.plots.validation import plot_free_decays, plot_validation_frf
from sixdof.results import RunResults

__all__ = [
    "DPI",
    "FIGURES",
    "FLAT_SIDE",
    "MAX_DRAWN_ROTATION",
    "MAX_POINTS",
    "MIN_ASPECT",
    "MODE_SCALE",
    "PNG_COMPRESS_LEVEL",
    "body_box",
    "envelope_indices",
    "plot_bode",
    "plot_free_decays",
    "plot_ke_distribution",
    "plot_mode_shapes",
    "plot_mount_forces",
    "plot_point_frfs",
    "plot_superposition",
    "plot_time_histories",
    "plot_validation_frf",
    "save_all",
]


def _file_order(extras: Mapping[str, object]) -> dict[str, object]:
    """``extras`` in the results file's order (by kind, then name): a live and a loaded run draw alike."""
    kinds = (ForceTransmissibility, GroundTransmissibility, PointFRF)

    def key(item):
        kind = next((k for k, cls in enumerate(kinds) if isinstance(item[1], cls)), len(kinds))
        return kind, item[0]

    return dict(sorted(extras.items(), key=key))


#: File name of each figure of a run, whether the run allows it, and how it is drawn.
FIGURES: tuple[tuple[str, Callable[[RunResults], bool], Callable[[RunResults], Figure]], ...] = (
    ("mode_shapes.png", lambda run: run.modes is not None,
     lambda run: plot_mode_shapes(run.modes, run.system, name=run.name)),
    ("ke_distribution.png", lambda run: run.modes is not None,
     lambda run: plot_ke_distribution(run.modes, name=run.name)),
    ("time_dofs.png", lambda run: run.response is not None,
     lambda run: plot_time_histories(run.response, name=run.name)),
    ("mount_forces.png", lambda run: run.response is not None and run.mount_forces is not None,
     lambda run: plot_mount_forces(run.mount_forces, run.response.t, name=run.name)),
    ("superposition.png", lambda run: run.response is not None and run.superposition is not None,
     lambda run: plot_superposition(run.response, run.superposition, run.agreement, name=run.name)),
    ("bode.png", lambda run: run.frf is not None,
     lambda run: plot_bode(run.frf, run.modes, name=run.name)),
    ("point_frfs.png", lambda run: bool(run.frf_extras),
     lambda run: plot_point_frfs(_file_order(run.frf_extras), run.modes, name=run.name)),
    ("validation_frf.png", lambda run: run.validation is not None and bool(run.validation.random_runs),
     lambda run: plot_validation_frf(run.validation, name=run.name)),
    ("free_decays.png", lambda run: run.validation is not None and bool(run.validation.decays),
     lambda run: plot_free_decays(run.validation, name=run.name)),
)


def save_all(run: RunResults, directory: str | Path, dpi: int = DPI) -> list[Path]:
    """Draw every figure the run allows and write each as a PNG in ``directory``.

    Titles start with the run's name.

    Parameters
    ----------
    run : sixdof.results.RunResults
        A live run's results, or a stored one from :func:`sixdof.io.store.load_results`.
    directory : str or pathlib.Path
        Created when missing.
    dpi : int
        Resolution of the PNG files [dots per inch].

    Returns
    -------
    list of pathlib.Path
        The files written, in the order of :data:`FIGURES`.
    """
    require(run, "run", RunResults, "a sixdof.results.RunResults")
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for file_name, drawable, draw in FIGURES:
        if drawable(run):
            path = directory / file_name
            # One draw per figure (no layout engine), fast zlib: see PNG_COMPRESS_LEVEL.
            draw(run).savefig(path, dpi=dpi, pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
            written.append(path)
    return written
