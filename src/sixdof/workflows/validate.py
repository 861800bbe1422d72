"""``sixdof validate``: a scenario's modal results checked against simulated time histories.

:func:`validation_run` computes (:func:`sixdof.validation.validate`: free decays released from each mode shape,
random-force runs with H1 estimates) and writes nothing; :func:`save_validation` writes ``results.h5``, the
figures and ``validation.md``; :func:`validate_scenario` is the two in a row, as the command runs them.
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np

from sixdof.analysis.statespace import damping_ratios
from sixdof.analysis.validity import RangeWarning
from sixdof.io import html_report, output, store
from sixdof.io.scenario import Scenario, load_scenario
from sixdof.io.study_report import validation_text
from sixdof.results import RunResults
from sixdof.validation import validate
from sixdof.workflows.drawing import drawer
from sixdof.workflows.prepare import prepare
from sixdof.workflows.run import loss_factor_notes, provenance


def validation_run(scenario, *, progress=None, drawing=None) -> RunResults:
    """The validation experiment of a scenario's model, computed without files.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario or str or pathlib.Path
    progress : optional
        Shows the validation's simulations (:func:`sixdof.progress.meter`).
    drawing : optional
        Receives the results as they grow (``submit``): the modal figures can be drawn while the experiment runs.

    Returns
    -------
    sixdof.results.RunResults
        The model, its modes and damping, and ``validation`` (:class:`sixdof.validation.ValidationReport`).
    """
    scenario = prepare(scenario)
    system = scenario.time_system  # the model the simulations integrate: the loss factors' causal models
    modes = system.modes
    for note in loss_factor_notes(scenario)[0]:
        warnings.warn(note, RangeWarning, stacklevel=2)
    results = RunResults(name=scenario.name, description=scenario.description, system=system, modes=modes,
                         damping_ratios=damping_ratios(system.C, modes, system.branches),
                         viscoelastic=scenario.viscoelastic, provenance=provenance(scenario), scenario=scenario,
                         loss_factor_model=scenario.loss_factor_model if scenario.viscoelastic
                         or np.any(scenario.system.loss_factors) else "")
    if drawing is not None:
        drawing.submit(results)  # the modal figures are drawn while the validation experiment runs
    return dataclasses.replace(results, validation=validate(system, progress=progress))


def save_validation(results: RunResults, out_root: str | Path = "outputs", *, drawing=None,
                    command_line: str | None = None) -> Path:
    """Write a validation (:func:`validation_run`) into ``out_root/<name>_validation/``: ``results.h5``, figures
    ``validation.md`` and ``report.html``, all or nothing, whatever its verdict (PASS or FAIL). Returns the folder."""
    target = output.check_target(out_root, results.name, "_validation")
    with drawer(drawing) as drawing:
        return output.write_folder(target, lambda stage: _save_into(stage, results, drawing, command_line))


def validate_scenario(scenario, out_root: str | Path = "outputs", *, command_line: str | None = None,
                      workers=None, progress=None):
    """:func:`validation_run`, then :func:`save_validation` (the folder checked before any computing): what
    ``sixdof validate`` does. ``workers`` draw the figures (:func:`sixdof.workflows.run.save`'s ``drawing``).

    Returns
    -------
    tuple of (sixdof.validation.ValidationReport, pathlib.Path)
        The report and the folder written.
    """
    scenario = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    target = output.check_target(out_root, scenario.name, "_validation")
    scenario = prepare(scenario)
    with drawer(workers) as drawing:
        results = validation_run(scenario, progress=progress, drawing=drawing)
        output.write_folder(target, lambda stage: _save_into(stage, results, drawing, command_line))
    return results.validation, target


def _save_into(stage: Path, results: RunResults, drawing, command_line: str | None) -> None:
    store.write_results(stage / "results.h5", results, command_line=command_line)
    drawing.submit(results)
    figures = drawing.save(stage)
    links = "\n".join(f"![{p.stem}]({p.name})" for p in html_report.embeddable(figures))
    text = (f"# {results.name}: modal results against time histories\n\n{validation_text(results.validation)}\n\n"
            f"{links}\n")
    (stage / "validation.md").write_text(text, encoding="utf-8")
    html_report.write_run_report(stage, results, text, figures, title=f"{results.name}: validation")
