"""``sixdof correlate``: a model against a test, and with ``--update`` the model updated to it.

:func:`correlation_run` computes without files: the test read (:func:`sixdof.io.testfile.load_test`), H1 FRFs
estimated from time histories (:func:`sixdof.validation.estimation.estimate_frfs`), its modes identified with
no help from the model (:func:`sixdof.validation.identify.identify_modes`), projected onto the six body DOFs
(:func:`sixdof.validation.projection.project_to_body`), paired with the model's by MAC
(:func:`sixdof.validation.correlation.correlate_modes`) and, asked to, the ``[update]`` variables fitted to them
(:func:`sixdof.design.update.update`) and the updated model correlated again. :func:`save_correlation` writes
``<out>/<name>_correlation/``: ``correlation.h5``, ``summary.md``, the figures and ``updated.toml``, all or
nothing; :func:`correlate_scenario` is the two in a row, as the command runs them.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from sixdof.analysis.frf import receptance
from sixdof.analysis.statespace import damping_ratios
from sixdof.design.correlation import CorrelationRun
from sixdof.errors import InputError, Plain
from sixdof.io import html_report, output
from sixdof.io.scenario import Scenario, load_scenario, parse_scenario
from sixdof.io.store import write_results
from sixdof.io.study_report import correlation_text
from sixdof.io.testfile import load_test
from sixdof.plots import correlation_figure_names, render_correlation_files
from sixdof.progress import meter
from sixdof.validation.correlation import channel_shapes, correlate_modes
from sixdof.validation.estimation import check_resolution, estimate_frfs, resolving_segment_s, sharpest_bandwidth
from sixdof.validation.identify import identify_modes
from sixdof.validation.projection import project_to_body
from sixdof.validation.testdata import FRF_QUANTITIES, TestData, TestSetup
from sixdof.workflows.prepare import prepare

__all__ = ["CORRELATION_FILES", "correlate_scenario", "correlation_json", "correlation_run", "save_correlation"]

#: An identified mode is correlated with the rigid-body model when at most this share of its motion (the
#: relative norm over the channels) is not rigid-body motion; above it, it is a mode of the body's own
#: (a flexible mode in the band), reported and left unpaired. Measured on the bundled tap test: 1-4 % for its
#: rigid modes at 1 % noise, 98 % for its torsion mode.
RIGID_RESIDUAL = 0.3
#: The least Welch averages an H1 estimate of time data is made of (its segment is shortened to reach them).
MIN_AVERAGES = 8
#: The files a correlation's folder holds besides its figures.
CORRELATION_FILES = ("correlation.h5", "summary.md", "report.html")


def correlation_run(scenario, test, *, update: bool = False, progress=None) -> CorrelationRun:
    """A test correlated with a scenario's model, and with ``update`` the model updated to it; no files.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario or str or pathlib.Path
        The model; its ``[test]`` table places the test's nodes and sets the verdict's limits, its ``[update]``
        table says what an update may vary.
    test : sixdof.validation.testdata.TestData or str or pathlib.Path
        The measured data, or its file (UFF58 FRFs or time histories, or CSV as ``sixdof export`` writes it).
    update : bool, optional
        Update the model to the test (needs an ``[update]`` table).
    progress : optional
        Shows the update's starts (a :func:`sixdof.progress.meter` kind: None, False, True, "text" or "tqdm").

    Returns
    -------
    CorrelationRun

    Raises
    ------
    sixdof.errors.InputError
        A file or table that cannot be read, ``update`` without an ``[update]`` table, a test whose channels
        do not tell the six body DOFs, no mode identified.
    """
    scenario = prepare(scenario if isinstance(scenario, Scenario) else load_scenario(scenario))
    if update and scenario.update is None:
        raise InputError("update", "an [update] table saying what the update may vary "
                         "(its [[update.vary]] entries)", Plain("no [update] table"))
    test = test if isinstance(test, TestData) else load_test(test, scenario)
    system = scenario.system
    modes = system.modes
    damping = damping_ratios(system.C, modes, system.branches)
    notes = []
    measured, estimate = test, None
    if test.kind == "time":
        measured, estimate = _estimated(test, modes.frequency_hz, damping)
    identification = identify_modes(measured.f_hz, measured.H, measured.quantity)
    found = identification.modes
    if not len(found.frequency_hz):
        raise InputError(test.source, "a test in which modes can be identified", Plain("no stable pole in its band"))
    note = check_resolution(measured.f_hz, found.frequency_hz, found.damping_ratio)
    if note:
        notes.append(note)
    rows = test.response_rows()
    projection = project_to_body(found.shapes, rows, test.out_nodes, test.out_positions)
    rigid = projection.residual <= RIGID_RESIDUAL
    notes += [f"test mode {j + 1} at {found.frequency_hz[j]:.3f} Hz: {100 * projection.residual[j]:.1f} % of its "
              "motion is not rigid-body motion (a mode of the body itself); not correlated"
              for j in np.flatnonzero(~rigid)]
    setup = scenario.test or TestSetup()
    correlation = _correlated(found, rigid, projection, system, damping, rows, setup)
    run = CorrelationRun(name=scenario.name, test=test, measured=measured, estimate=estimate,
                         identification=identification, projection=projection, rigid=rigid,
                         rigid_residual=RIGID_RESIDUAL, correlation=correlation,
                         model_H=model_frf(system, measured), provenance={"scenario_text": scenario.text},
                         notes=tuple(notes))
    return _updated(run, scenario, found, rigid, rows, progress) if update else run


def model_frf(system, measured: TestData) -> np.ndarray:
    """``system``'s FRF on the channels of ``measured`` at its frequencies, in its quantity: ``rows H(w) cols``,
    shape (nf, n_out, n_ref)."""
    H = receptance(system, measured.f_hz).quantity(measured.quantity)
    return np.einsum("oi,fij,jr->for", measured.response_rows(), H, measured.load_columns())


def save_correlation(run: CorrelationRun, out_root: str | Path = "outputs", *, command_line: str | None = None) -> Path:
    """Write a correlation (:func:`correlation_run`) into ``out_root/<name>_correlation/``: ``correlation.h5``,
    ``summary.md``, the figures and, after an update, ``updated.toml``; all or nothing, whatever the verdict.

    Parameters
    ----------
    run : CorrelationRun
        What :func:`correlation_run` returned.
    out_root : str or pathlib.Path, optional
        The folder the ``<name>_correlation/`` folder is written into. Default ``"outputs"``.
    command_line : str, optional
        Stored as provenance.

    Returns
    -------
    pathlib.Path
        The folder written.

    Raises
    ------
    InputError
        Before anything is written: a scenario name that is not one safe path component, an ``out_root``
        that cannot be written, or a target that is a file, a link, or a folder sixdof did not write
        (:func:`sixdof.io.output.check_target`).
    """
    target = output.check_target(out_root, run.name, "_correlation")
    return output.write_folder(target, lambda stage: _save_into(stage, run, command_line))


def correlate_scenario(scenario, test, out_root: str | Path = "outputs", *, update: bool = False,
                       command_line: str | None = None, progress=None) -> tuple[CorrelationRun, Path]:
    """:func:`correlation_run`, then :func:`save_correlation` (the folder checked before any computing): what
    ``sixdof correlate`` does. Returns the run and the folder written."""
    scenario = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    output.check_target(out_root, scenario.name, "_correlation")
    run = correlation_run(scenario, test, update=update, progress=progress)
    return run, save_correlation(run, out_root, command_line=command_line)


# ----------------------------------------------------------------------------------------------------
# Steps.
# ----------------------------------------------------------------------------------------------------


def _estimated(test: TestData, frequency_hz, damping) -> tuple[TestData, object]:
    """H1 FRFs of time data, on its channels. The Welch segment resolves the model's sharpest mode
    (:func:`~sixdof.validation.estimation.resolving_segment_s`; the identified modes are checked against the
    estimate's resolution afterwards), shortened where the record holds fewer than :data:`MIN_AVERAGES`."""
    n = len(test.t)
    wanted = int(2 ** np.ceil(np.log2(resolving_segment_s(sharpest_bandwidth(frequency_hz, damping))
                                      * test.sample_rate_hz)))
    nperseg = max(16, min(wanted, 2 * n // (MIN_AVERAGES + 1)))
    estimate = estimate_frfs(test.inputs, test.responses, test.sample_rate_hz, nperseg)
    keep = estimate.f_hz > 0  # an FRF's 0 Hz bin carries nothing an identification uses
    quantity = {response: frf for frf, response in FRF_QUANTITIES.items()}[test.quantity]
    measured = dataclasses.replace(test, kind="frf", quantity=quantity, f_hz=estimate.f_hz[keep],
                                   H=estimate.H[keep], t=None, inputs=None, responses=None, sample_rate_hz=None)
    return measured, estimate


def _correlated(found, rigid, projection, system, damping, rows, setup: TestSetup, modes=None):
    """The rigid identified modes against ``system``'s modes."""
    modes = system.modes if modes is None else modes
    return correlate_modes(
        found.frequency_hz[rigid], found.damping_ratio[rigid], found.shapes[:, rigid], modes.frequency_hz, damping,
        channel_shapes(rows, modes.shapes), body_test=projection.q[:, rigid], body_model=modes.shapes,
        max_frequency_error_percent=setup.max_frequency_error_percent, min_mac=setup.min_mac,
        test_numbers=np.flatnonzero(rigid) + 1)


def _updated(run: CorrelationRun, scenario: Scenario, found, rigid, rows, progress) -> CorrelationRun:
    """``run`` with the update to its rigid test modes, the updated scenario and its correlation."""
    from sixdof.design.update import TestModes, update, updated_scenario_text  # noqa: PLC0415 (JAX: only to update)

    shown = meter(progress, scenario.update.starts, "starts", "update")
    result = update(scenario, TestModes(found.frequency_hz[rigid], found.shapes[:, rigid], rows,
                                        found.damping_ratio[rigid]), progress=shown)
    shown.close()
    text = updated_scenario_text(scenario, result)
    updated = prepare(parse_scenario(text, source=f"{scenario.name}_updated.toml",
                                     base_dir=scenario.path.parent if scenario.path is not None else "."))
    system = updated.system
    damping = damping_ratios(system.C, system.modes, system.branches)
    test = load_test(run.test.source, updated) if _moved(result) else run.test
    rows = test.response_rows()
    correlation = _correlated(found, rigid, run.projection, system, damping, rows, updated.test or TestSetup())
    measured = run.measured if test is run.test else dataclasses.replace(
        run.measured, out_positions=test.out_positions, ref_positions=test.ref_positions)
    notes = run.notes + tuple(f"{name}: not determined by the test (standard error or correlation with another "
                              "variable too large)" for name in result.undetermined)
    return dataclasses.replace(run, update=result, updated_text=text, correlation_updated=correlation,
                               updated_H=model_frf(system, measured), notes=notes)


def _moved(result) -> bool:
    """Whether the update moved the CG (the test's nodes then lie elsewhere from it)."""
    return bool(np.any(np.asarray(result.cg_offset) != 0))


def _save_into(stage: Path, run: CorrelationRun, command_line: str | None) -> None:
    write_results(stage / "correlation.h5", run, command_line=command_line)
    figures = correlation_figure_names(run)
    for name in figures:
        for file, content in render_correlation_files(run, name).items():
            (stage / file).write_bytes(content)
    if run.updated_text:
        (stage / "updated.toml").write_text(run.updated_text, encoding="utf-8")
    links = "\n".join(f"![{Path(name).stem}]({name})" for name in figures)
    summary = f"# {run.name}: model against test\n\n{correlation_text(run)}\n\n{links}\n"
    (stage / "summary.md").write_text(summary, encoding="utf-8")
    html_report.write_report(stage, f"{run.name}: model against test", summary, figures=[stage / n for n in figures],
                             checks=html_report.correlation_checks(run),
                             scenario_text=(run.provenance or {}).get("scenario_text"))



def correlation_json(run: CorrelationRun) -> dict:
    """What ``sixdof correlate --json`` prints: the test's modes, the pairs (modes numbered from 1, MAC on the
    measured channels, ``frequency_error_percent`` = 100 (f_model - f_test) / f_test), the verdict, and after
    an update its variables and the pairs against the updated model (which the verdict then judges)."""
    found = run.identification.modes

    def pairs(correlation):
        return [{"test_mode": int(correlation.test_number[t]), "model_mode": int(m) + 1,
                 "mac": float(correlation.mac[t, m]), "frequency_error_percent": float(e),
                 "f_test_hz": float(correlation.f_test[t]), "f_model_hz": float(correlation.f_model[m])}
                for t, m, e in zip(correlation.pair_test, correlation.pair_model, correlation.frequency_error_percent)]

    document = {
        "name": run.name, "test": run.test.source,
        "test_modes": [{"frequency_hz": float(f), "damping_ratio": float(z), "rigid": bool(r),
                        "not_rigid_share": float(s)}
                       for f, z, r, s in zip(found.frequency_hz, found.damping_ratio, run.rigid,
                                             run.projection.residual)],
        "pairs": pairs(run.correlation), "correlated": bool(run.final.correlated),
        "limits": {"max_frequency_error_percent": run.correlation.max_frequency_error_percent,
                   "min_mac": run.correlation.min_mac},
        "notes": list(run.notes)}
    if run.update is not None:
        u = run.update
        document["update"] = {
            "variables": [{"name": str(n), "unit": unit, "initial": float(a), "updated": float(b),
                           "standard_error": float(s) if np.isfinite(s) else None, "determined": bool(ok)}
                          for n, unit, a, b, s, ok in zip(u.variable, u.variable_units, u.initial, u.updated,
                                                          u.standard_error, u.determined)],
            "pairs": pairs(run.correlation_updated)}
    return document
