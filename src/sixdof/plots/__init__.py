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
allows (a live run, or a stored one from :func:`sixdof.io.store.load_results`) and writes each in the
scenario's ``[output] formats`` (PNG, SVG, PDF) at its ``dpi``, and :func:`render` draws one of them to PNG
bytes (:func:`render_files`, to each format's) (what the command line's figure workers do,
:mod:`sixdof.cli.figures`); :mod:`~sixdof.plots.drawer` draws a run's figures as the workflows submit them.

Figures are built as :class:`matplotlib.figure.Figure` objects without pyplot: no backend, no display
and no global figure list are involved (they render with Agg when saved, work headless, and show in
Jupyter), and nothing needs closing. Importing this package loads no matplotlib: each name is imported
from its module on first use, so that a process can decide which figures a run allows (:data:`FIGURES`)
and leave the drawing to worker processes (:mod:`sixdof.cli.figures`).

Modules: :mod:`~sixdof.plots.common` (display units, envelope decimation, margins, panel grid,
titles), :mod:`~sixdof.plots.modes`, :mod:`~sixdof.plots.time` (its zooms: :mod:`~sixdof.plots.zoom`;
:mod:`~sixdof.plots.superposition`, :mod:`~sixdof.plots.mount_time`),
:mod:`~sixdof.plots.frf`, :mod:`~sixdof.plots.validation`; a test against the model (``sixdof correlate``):
:mod:`~sixdof.plots.correlation`, drawn by :func:`render_correlation` (:data:`CORRELATION_FIGURES`).
"""

from __future__ import annotations

import io
import sys
from collections.abc import Callable, Mapping
from pathlib import Path

from sixdof._lazy import lazy_names

#: Public name -> module of this package that defines it, imported when the name is first used.
_PUBLIC = {
    "DPI": "common",
    "MAX_POINTS": "common",
    "PNG_COMPRESS_LEVEL": "common",
    "envelope_indices": "common",
    "FLAT_SIDE": "modes",
    "MAX_DRAWN_ROTATION": "modes",
    "MIN_ASPECT": "modes",
    "MODE_SCALE": "modes",
    "body_box": "modes",
    "plot_ke_distribution": "modes",
    "plot_mode_shapes": "modes",
    "plot_mount_forces": "mount_time",
    "plot_mount_loads": "mount_time",
    "plot_mount_shear": "mount_time",
    "plot_point_accelerations": "point_time",
    "plot_superposition": "superposition",
    "plot_time_histories": "time",
    "plot_bode": "frf",
    "plot_point_frfs": "frf",
    "plot_transmissibility": "transmissibility",
    "plot_free_decays": "validation",
    "plot_validation_frf": "validation",
    "plot_random": "random",
    "plot_random_check": "random",
    "plot_srs": "srs",
    "plot_spectrum": "spectrum",
    "plot_hysteresis": "hysteresis",
    "plot_records": "records",
    "plot_dynamic_stiffness": "viscoelastic",
    "plot_mount_fits": "viscoelastic",
    "UpdateHistory": "correlation",
    "plot_frf_overlay": "correlation",
    "plot_mac": "correlation",
    "plot_stability": "correlation",
    "plot_update_history": "correlation",
    "update_history": "correlation",
}

__all__ = sorted([*_PUBLIC, "CORRELATION_FIGURES", "FIGURES", "FIXED_TITLES", "FORMATS", "correlation_figure_names",
                  "figure_files", "figure_names", "file_settings", "png", "render", "render_correlation",
                  "render_correlation_files", "render_files", "save_all"])


__getattr__, __dir__ = lazy_names(__name__, _PUBLIC, __all__)


# Drawing calls the plot functions through the module object, whose __getattr__ imports them: deciding
# which figures a run allows loads no matplotlib.
_plots = sys.modules[__name__]


def _carries_shear(check) -> bool:
    from sixdof.analysis.mountcheck import carries_shear  # noqa: PLC0415 (loads NumPy: the command's figure workers start first)

    return carries_shear(check)


def _has_operating(run) -> bool:
    from sixdof.analysis.isolation_summary import has_operating  # noqa: PLC0415 (loads NumPy: the command's figure workers start first)

    return has_operating(run)


def _isolation_summary(run):
    from sixdof.analysis.isolation_summary import run_isolation_summary  # noqa: PLC0415 (loads NumPy: the command's figure workers start first)

    return run_isolation_summary(run)


def _superposition_name(run) -> str:
    """The run's name in superposition.png's title. Hysteretic bearings: the figure's heading names them (against
    their linearization). Nonlinear mounts: the linear model is exact until one engaged, when one did."""
    system = run.system
    if system is None or system.hysteretic.count or not system.nonlinear.count:
        return run.name
    first = None if run.contacts is None else run.contacts.first_engaged_t
    if first is not None and first == first:  # not nan: a mount engaged
        return f"{run.name} (linear model, exact until a nonlinear mount engaged at t = {first:.4g} s)"
    return _linear_name(run)


def _linear_name(run) -> str:
    """The run's name in the title of a figure of its linear model (modes, FRFs), saying so when its mounts are
    nonlinear or hysteretic. From the system alone: these figures are drawn before the time response is in."""
    if run.system is None:
        return run.name
    if run.system.hysteretic.count:  # the bearings' linearization, which the run does not compare with
        kinds = " or ".join(sorted(set(run.system.hysteretic.linearization)))
        return f"{run.name} (linear model: bearings at their {kinds} linearization)"
    if run.system.nonlinear.count:
        return f"{run.name} (linearized about the static equilibrium)"
    return run.name


def _file_order(extras: Mapping[str, object]) -> dict[str, object]:
    """``extras`` in the results file's order: a live and a loaded run draw alike."""
    from sixdof.analysis.frf import in_file_order  # noqa: PLC0415 (loads NumPy: the command's figure workers start first)

    return dict(in_file_order(extras))


#: Each figure of a run: its file name, the fields of :class:`~sixdof.results.RunResults` it draws
#: from, whether a run allows it, and how it is drawn (returns a :class:`matplotlib.figure.Figure`).
FIGURES: tuple[tuple[str, tuple[str, ...], Callable[[object], bool], Callable[[object], object]], ...] = (
    ("mode_shapes.png", ("modes", "system"), lambda run: run.modes is not None,
     lambda run: _plots.plot_mode_shapes(run.modes, run.system, name=_linear_name(run))),
    ("ke_distribution.png", ("modes", "system"), lambda run: run.modes is not None,
     lambda run: _plots.plot_ke_distribution(run.modes, name=_linear_name(run))),
    ("time_dofs.png", ("response", "events", "steady_state"), lambda run: run.response is not None,
     lambda run: _plots.plot_time_histories(run.response, name=run.name, events=run.events,
                                            steady=run.steady_state)),
    ("time_points.png", ("response", "points", "events"), lambda run: run.response is not None and bool(run.points),
     lambda run: _plots.plot_point_accelerations(run.points, run.response.t, name=run.name, events=run.events)),
    ("mount_forces.png", ("response", "mount_check", "events"),
     lambda run: run.response is not None and run.mount_check is not None,
     lambda run: _plots.plot_mount_loads(run.mount_check, run.response.t, name=run.name, events=run.events)),
    ("mount_shear.png", ("response", "mount_check", "events"),
     lambda run: run.response is not None and run.mount_check is not None and _carries_shear(run.mount_check),
     lambda run: _plots.plot_mount_shear(run.mount_check, run.response.t, name=run.name, events=run.events)),
    ("hysteresis.png", ("system", "response", "mount_forces"),
     lambda run: run.response is not None and run.response.hysteretic_state is not None,
     lambda run: _plots.plot_hysteresis(run.system, run.response, run.mount_forces, name=run.name)),
    ("superposition.png", ("response", "superposition", "agreement", "events", "system", "contacts"),
     lambda run: run.response is not None and run.superposition is not None,
     lambda run: _plots.plot_superposition(run.response, run.superposition, run.agreement,
                                           name=_superposition_name(run), events=run.events, contacts=run.contacts)),
    ("bode.png", ("frf", "modes", "steady_state", "system"), lambda run: run.frf is not None,
     lambda run: _plots.plot_bode(run.frf, run.modes, name=_linear_name(run),
                                  operating_hz=None if run.steady_state is None else run.steady_state.f_hz)),
    ("transmissibility.png", ("system", "modes", "frf", "steady_state"), lambda run: _has_operating(run),
     lambda run: _plots.plot_transmissibility(_isolation_summary(run), run.modes, name=_linear_name(run))),
    ("point_frfs.png", ("frf", "frf_extras", "modes", "system"), lambda run: bool(run.frf_extras),
     lambda run: _plots.plot_point_frfs(_file_order(run.frf_extras), run.modes, name=_linear_name(run))),
    ("validation_frf.png", ("validation",), lambda run: run.validation is not None and bool(run.validation.random_runs),
     lambda run: _plots.plot_validation_frf(run.validation, name=run.name)),
    ("free_decays.png", ("validation",), lambda run: run.validation is not None and bool(run.validation.decays),
     lambda run: _plots.plot_free_decays(run.validation, name=run.name)),
    ("random.png", ("random",), lambda run: run.random is not None,
     lambda run: _plots.plot_random(run.random, name=run.name)),
    ("random_check.png", ("random",), lambda run: run.random is not None and run.random.time_check is not None,
     lambda run: _plots.plot_random_check(run.random.time_check, name=run.name)),
    ("srs.png", ("srs",), lambda run: run.srs is not None, lambda run: _plots.plot_srs(run.srs, name=run.name)),
    ("spectrum.png", ("spectrum",), lambda run: run.spectrum is not None,
     lambda run: _plots.plot_spectrum(run.spectrum, name=run.name)),
    ("records.png", ("spectrum", "spectrum_records", "records_check"), lambda run: run.spectrum_records is not None,
     lambda run: _plots.plot_records(run.spectrum_records, run.records_check, name=run.name)),
    ("dynamic_stiffness.png", ("viscoelastic",), lambda run: bool(run.viscoelastic),
     lambda run: _plots.plot_mount_fits(run.viscoelastic, name=run.name)),
)
_DRAW = {name: draw for name, _, _, draw in FIGURES}


def _frf_unit(test) -> str:
    """The unit of a test's FRFs for the mode indicator's label when one unit holds for every channel, else ``""``."""
    from sixdof.plots.correlation import frf_unit  # noqa: PLC0415 (loads matplotlib: the command's figure workers start first)

    units = {frf_unit(test.quantity, bool(o), bool(r)) for o in test.out_rotation for r in test.ref_rotation}
    return units.pop() if len(units) == 1 else ""


#: Each figure of a correlation run (``sixdof correlate``): its file name, whether the run allows it, and how it
#: is drawn (returns a :class:`matplotlib.figure.Figure`). The run is any object with ``name`` (str), ``measured``
#: (:class:`~sixdof.validation.testdata.TestData` of FRFs: those correlated), ``identification``
#: (:class:`~sixdof.validation.identify.Identification`), ``correlation``
#: (:class:`~sixdof.validation.correlation.Correlation`), ``model_H`` (the model's FRFs on the test's channels,
#: shape of ``measured.H``), and ``updated_H`` and ``update`` (:class:`~sixdof.design.update.UpdateResult`), both
#: ``None`` without an update.
CORRELATION_FIGURES: tuple[tuple[str, Callable[[object], bool], Callable[[object], object]], ...] = (
    ("stability.png", lambda run: run.identification is not None,
     lambda run: _plots.plot_stability(run.identification, H=None if run.measured is None else run.measured.H,
                                       f_hz=None if run.measured is None else run.measured.f_hz,
                                       unit="" if run.measured is None else _frf_unit(run.measured), name=run.name)),
    ("mac.png", lambda run: run.correlation is not None,
     lambda run: _plots.plot_mac(run.correlation, name=run.name)),
    ("frf_overlay.png", lambda run: run.measured is not None and run.measured.H is not None and run.model_H is not None,
     lambda run: _plots.plot_frf_overlay(run.measured, run.model_H, H_updated=run.updated_H, name=run.name)),
    ("update_history.png", lambda run: run.update is not None,
     lambda run: _plots.plot_update_history(run.update, name=run.name)),
)
_DRAW_CORRELATION = {name: draw for name, _, draw in CORRELATION_FIGURES}
#: matplotlib settings :func:`render` draws with: titles at their fixed height. matplotlib's automatic
#: placement measures every axes' tick labels at each draw to clear labels above the axes, which none of
#: these figures has (8 % of their drawing time); they look the same either way.
FIXED_TITLES = {"axes.titley": 1.0}


def figure_names(run) -> list[str]:
    """File names of the figures a :class:`~sixdof.results.RunResults` allows, in the order of
    :data:`FIGURES`."""
    from sixdof.errors import InputError  # noqa: PLC0415 (loads NumPy: the command's figure workers start first)
    from sixdof.results import RunResults  # noqa: PLC0415 (loads NumPy: the command's figure workers start first)

    if not isinstance(run, RunResults):
        raise InputError("run", "a sixdof.results.RunResults", run)
    return [name for name, _, drawable, _ in FIGURES if drawable(run)]


def render(run, file_name: str, dpi: int | None = None) -> bytes:
    """Draw the figure ``file_name`` of :data:`FIGURES` from a :class:`~sixdof.results.RunResults` and
    return it as PNG bytes, ``dpi`` dots per inch (default :data:`DPI`).

    One draw per figure (no layout engine), unlabelled ticks drawn as collections
    (:func:`~sixdof.plots.common.freeze_unlabelled_ticks`) and fast PNG writing (:func:`png`).
    """
    return render_files(run, file_name, ("png",), dpi)[file_name]


def render_files(run, file_name: str, formats=("png",), dpi: int | None = None) -> dict[str, bytes]:
    """Draw the figure ``file_name`` of :data:`FIGURES` from a :class:`~sixdof.results.RunResults` once and
    return it in each of ``formats`` (:func:`figure_files`): what every saved figure of a run goes through."""
    import matplotlib

    with matplotlib.rc_context(FIXED_TITLES):
        return figure_files(_DRAW[file_name](run), file_name, formats, dpi)


def correlation_figure_names(run) -> list[str]:
    """File names of the figures a correlation run allows, in the order of :data:`CORRELATION_FIGURES`."""
    return [name for name, drawable, _ in CORRELATION_FIGURES if drawable(run)]


def render_correlation(run, file_name: str, dpi: int | None = None) -> bytes:
    """Draw the figure ``file_name`` of :data:`CORRELATION_FIGURES` from a correlation run and return it as PNG
    bytes, ``dpi`` dots per inch (default :data:`DPI`), as :func:`render` does."""
    return render_correlation_files(run, file_name, ("png",), dpi)[file_name]


def render_correlation_files(run, file_name: str, formats=("png",), dpi: int | None = None) -> dict[str, bytes]:
    """:func:`render_files` for the figure ``file_name`` of :data:`CORRELATION_FIGURES`."""
    import matplotlib

    with matplotlib.rc_context(FIXED_TITLES):
        return figure_files(_DRAW_CORRELATION[file_name](run), file_name, formats, dpi)


#: File formats a figure can be written in (``[output] formats``; the scenario loader checks them against
#: :data:`sixdof.io.settings.FIGURE_FORMATS`).
FORMATS = ("png", "svg", "pdf")


def file_settings(run) -> tuple[tuple[str, ...], int | None]:
    """The formats and resolution [dots per inch] a run's figures are written in: its scenario's ``[output]``
    ``formats`` and ``dpi``, or PNG at :data:`DPI` for results without their scenario (a loaded file's)."""
    settings = getattr(getattr(run, "scenario", None), "output", None)
    return tuple(getattr(settings, "formats", ("png",))), getattr(settings, "dpi", None)


def figure_files(figure, file_name: str, formats=("png",), dpi: int | None = None) -> dict[str, bytes]:
    """A finished figure as files: ``{name: bytes}``, one per format of ``formats`` (from :data:`FORMATS`),
    each named ``file_name`` with the format's suffix, in the order of ``formats``.

    PNG is written by :func:`png` at ``dpi`` dots per inch (default :data:`DPI`); SVG and PDF by matplotlib,
    as vectors (``dpi`` then sets the resolution of any image inside them).
    """
    from sixdof.plots.common import freeze_unlabelled_ticks  # noqa: PLC0415 (loads matplotlib: the command's figure workers start first)

    unknown = [f for f in formats if f not in FORMATS]
    if unknown or not formats:
        from sixdof.errors import InputError  # noqa: PLC0415 (loads NumPy: the command's figure workers start first)

        raise InputError("formats", f"a non-empty list from {', '.join(FORMATS)}", list(formats))
    freeze_unlabelled_ticks(figure)  # once: every format draws the same ticks
    stem = Path(file_name).stem
    files = {}
    for kind in dict.fromkeys(formats):
        if kind == "png":
            files[f"{stem}.png"] = png(figure, dpi)
        else:
            buffer = io.BytesIO()
            figure.savefig(buffer, format=kind, dpi=dpi or _plots.DPI)
            files[f"{stem}.{kind}"] = buffer.getvalue()
    return files


def png(figure, dpi: int | None = None) -> bytes:
    """A figure as PNG bytes, the way :func:`render` draws it: the pixels ``figure.savefig`` draws, written
    by :func:`~sixdof.plots.common.png_bytes`."""
    import numpy as np  # noqa: PLC0415 (drawing only: importing sixdof.plots loads nothing)
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from sixdof.plots.common import freeze_unlabelled_ticks, png_bytes  # noqa: PLC0415 (loads matplotlib: the command's figure workers start first)

    freeze_unlabelled_ticks(figure)
    dpi = dpi or _plots.DPI
    # As savefig draws: on an Agg canvas of its own at the file's resolution, in the figure's own face colour;
    # the figure's canvas (a notebook's, say) and resolution given back after.
    shown, drawn_at = figure.canvas, figure.dpi
    canvas = FigureCanvasAgg(figure)
    figure.dpi = dpi
    try:
        canvas.draw()
        return png_bytes(np.asarray(canvas.buffer_rgba()), dpi)
    finally:
        figure.dpi = drawn_at
        figure.set_canvas(shown)


def save_all(run, directory: str | Path, dpi: int | None = None, formats=None) -> list[Path]:
    """Draw every figure the run allows, in this process, and write each in ``directory``, once per format.

    Titles start with the run's name.

    Parameters
    ----------
    run : sixdof.results.RunResults
        A live run's results, or a stored one from :func:`sixdof.io.store.load_results`.
    directory : str or pathlib.Path
        Created when missing.
    dpi : int, optional
        Resolution of the PNG files [dots per inch]; default the scenario's ``[output] dpi``
        (:func:`file_settings`), else :data:`DPI`.
    formats : sequence of str, optional
        From :data:`FORMATS`; default the scenario's ``[output] formats``, else PNG only.

    Returns
    -------
    list of pathlib.Path
        The files written, in the order of :data:`FIGURES` (each figure's in the order of ``formats``).
    """
    names = figure_names(run)
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    given_formats, given_dpi = file_settings(run)
    written = []
    for name in names:
        for file, content in render_files(run, name, formats or given_formats, dpi or given_dpi).items():
            path = directory / file
            path.write_bytes(content)
            written.append(path)
    return written
