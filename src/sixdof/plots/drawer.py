"""What draws a run's figures for the workflows (:mod:`sixdof.workflows.run`): an object with ``submit`` and
``save``, and the one the library uses, which draws in this process.

A run submits its results as their parts appear (the modal and FRF figures first, the time figures once the
solve is done), then saves them all at once. The ``sixdof`` command hands the workflows its own drawer, which
draws in worker processes while the run computes (:mod:`sixdof.cli.figures`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from sixdof.interrupts import held_signals
from sixdof.plots import FIGURES, file_settings, render_files

if TYPE_CHECKING:
    from sixdof.results import RunResults


class FigureDrawer(Protocol):
    """Draws the figures of a run (:data:`sixdof.plots.FIGURES`) and writes them in the formats and at the
    resolution of its scenario's ``[output]`` (:func:`sixdof.plots.file_settings`), unless its ``formats``
    (sequence of str) and ``dpi`` (int [dots per inch]) are set before the first ``submit``."""

    formats: tuple[str, ...] | None
    dpi: int | None

    def submit(self, run: RunResults) -> None:
        """Take every figure ``run`` allows that was not submitted before."""

    def save(self, directory: Path) -> list[Path]:
        """Write the submitted figures into ``directory``; the files, in the order of :data:`~sixdof.plots.FIGURES`."""


class InProcessDrawer:
    """A :class:`FigureDrawer` that draws in this process, when the figures are saved: one run's figures (the first
    results submitted for a figure are the ones it is drawn from; a new run takes a new drawer).

    Parameters
    ----------
    dpi : int, optional
        Resolution of the PNG files [dots per inch]; default the first run's ``[output] dpi``
        (:func:`sixdof.plots.file_settings`).
    formats : sequence of str, optional
        The files each figure is written as (:data:`sixdof.plots.FORMATS`); default the first run's
        ``[output] formats``.
    """

    def __init__(self, dpi: int | None = None, formats=None) -> None:
        self.dpi, self.formats = dpi, formats
        self._runs: dict[str, RunResults] = {}  # each figure's name -> the run to draw it from

    def submit(self, run: RunResults) -> None:
        if not self._runs:
            formats, dpi = file_settings(run)
            self.formats, self.dpi = self.formats or formats, self.dpi or dpi
        self._runs.update((name, run) for name, _, drawable, _ in FIGURES
                          if name not in self._runs and drawable(run))

    def save(self, directory: Path) -> list[Path]:
        written = []
        for name in [name for name, *_ in FIGURES if name in self._runs]:
            with held_signals():  # matplotlib's C code can swallow a KeyboardInterrupt
                files = render_files(self._runs[name], name, self.formats or ("png",), self.dpi)
            for file, content in files.items():
                path = directory / file
                path.write_bytes(content)
                written.append(path)
        return written

    def __enter__(self) -> InProcessDrawer:
        return self

    def __exit__(self, kind, error, traceback) -> None:
        pass
