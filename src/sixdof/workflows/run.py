"""One run of a scenario, end to end: modal analysis and statics, the time response by the direct
solver cross-checked by modal superposition, frequency responses; results, figures and a summary
written under ``<out>/<scenario name>/``.

Everything is written through :mod:`sixdof.io.output`: all or nothing, never outside ``out``, and nothing
deleted that sixdof did not write.
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import warnings
from pathlib import Path

import numpy as np

from sixdof.analysis.design import design_metrics
from sixdof.analysis.frf import cross_check, force_transmissibility, ground_transmissibility, point_frf
from sixdof.analysis.isolation import isolated_spectrum
from sixdof.analysis.matching import RecordsWarning, ec8_suite, elastic_target
from sixdof.analysis.random import random_response
from sixdof.analysis.record_peaks import record_peaks
from sixdof.analysis.severity import measured_points, run_severity
from sixdof.analysis.spectrum import response_spectrum
from sixdof.analysis.srs import shock_spectra
from sixdof.analysis.statespace import damping_ratios
from sixdof.analysis.statics import try_gravity_statics
from sixdof.analysis.steady import steady_state
from sixdof.analysis.validity import (
    RangeWarning,
    fit_band_range,
    geometric_stiffness_note,
    implausible_inputs,
    static_range,
)
from sixdof.errors import InputError, Plain
from sixdof.interrupts import held_signals
from sixdof.io import html_report, output, report, store
from sixdof.io.scenario import MEMORY_SAMPLES, Scenario, load_scenario
from sixdof.io.stream import ResultsStream
from sixdof.model.viscoelastic import long_term_note, loss_fit_misses
from sixdof.results import RunResults
from sixdof.schema import make
from sixdof.validation.random_time import random_time_check
from sixdof.workflows.drawing import drawer
from sixdof.workflows.prepare import prepare
from sixdof.workflows.time_response import time_response

#: Fewest samples per period of the highest natural frequency or excitation frequency: below it the
#: sampled peaks of a sine are off by more than 5 % (1 - cos(pi / 10)).
MIN_SAMPLES_PER_PERIOD = 10


class SamplingWarning(UserWarning):
    """The output sample rate is too low for the frequencies in the response."""


def sampling_warnings(scenario, modes) -> list[str]:
    """Messages for frequencies the output sample rate cannot resolve (see MIN_SAMPLES_PER_PERIOD)."""
    if scenario.simulation is None:
        return []
    rate = scenario.simulation.sample_rate_hz
    wanted = [("highest natural frequency", float(modes.frequency_hz.max()))]
    wanted += excitation_frequencies(scenario.excitation)
    messages = []
    for label, f in wanted:
        if f > 0 and rate < MIN_SAMPLES_PER_PERIOD * f:
            messages.append(
                f"simulation.sample_rate_hz: {rate:g} Hz gives {rate / f:.1f} samples per period of the "
                f"{label} ({f:.4g} Hz); use at least {MIN_SAMPLES_PER_PERIOD * f:.4g} Hz to resolve it"
                + (" (below 2 per period it aliases)" if rate < 2 * f else "")
            )
    return messages


def excitation_frequencies(excitation) -> list[tuple[str, float]]:
    """Highest frequency [Hz] of each signal of the excitation that has one, with a label."""
    if excitation is None:
        return []
    found = []
    sources = [(f"loads[{i}] ({load.name})", load) for i, load in enumerate(excitation.loads)]
    if excitation.ground is not None:
        sources.append(("ground motion", excitation.ground))
    for label, source in sources:
        if getattr(source, "kind", None) == "unbalance":
            speed_hz = source.f_hz if source.f_hz is not None else source.speed_rpm / 60.0
            found.append((f"{label} rotation", float(speed_hz)))
            continue
        if source.signal.max_frequency_hz > 0:
            what = "pulse (1/duration)" if source.signal.kind in ("half_sine", "haversine") else "signal"
            found.append((f"{label} {source.signal.kind} {what}", source.signal.max_frequency_hz))
    return found


def run(scenario: Scenario | str | Path, *, sink=None, progress: bool = False, log=None, drawing=None) -> RunResults:
    """Compute everything a scenario asks for, writing nothing: modes, statics, damping, steady state, FRFs,
    random response, response-spectrum analysis, and with a ``[simulation]`` the time response with its
    cross-check, mount checks, point motions and shock response spectra.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario or str or pathlib.Path
        Loaded (and prepared: :func:`sixdof.workflows.prepare.prepare`) if a path.
    sink : optional
        Where a long run's windows go as they are computed (a :class:`sixdof.io.stream.ResultsStream`:
        ``append(window results)``, then ``finish(results)``): the results then hold every sample only in the
        sink, and in memory only those the figures draw. Without one, a run of more than
        :data:`~sixdof.io.scenario.MEMORY_SAMPLES` output samples is refused before computing.
    progress : bool
        Show the solver's progress (long runs).
    log : callable, optional
        Receives the lines a run prints along the way (the statics of causal loss-factor models).
    drawing : optional
        Receives the results as they grow (``drawing.submit(results)``: the modal and FRF figures can be drawn
        while the solve runs; see :func:`save`).

    Returns
    -------
    sixdof.results.RunResults
        With ``notes`` (the warnings raised, also in the summary) and ``scenario`` set.

    Raises
    ------
    sixdof.errors.InputError
        A run too long to hold in memory without a ``sink``, or a ``sink`` for a scenario without a
        ``[simulation]``: before anything is computed.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    simulation = scenario.simulation
    # Refused before anything is computed (the preparation's fits and statics included).
    if simulation is not None and sink is None and simulation.samples > MEMORY_SAMPLES:
        raise InputError("sink", f"a sink for a run of more than {MEMORY_SAMPLES:,} output samples, which is not "
                         "held in memory (with sixdof.ResultsStream(path) as sink: sixdof.run(scenario, sink=sink); "
                         "or sixdof.run_scenario, which streams into its results folder)",
                         Plain(f"{simulation.samples:,} samples and no sink"))
    if sink is not None and simulation is None:
        raise InputError("sink", "a scenario with a [simulation], whose time response the sink takes",
                         Plain("no [simulation]"))
    scenario = prepare(scenario)
    log = log or _silent
    system, timed = scenario.system, scenario.time_system
    modes = system.modes
    statics, no_statics = try_gravity_statics(timed, scenario.statics.gravity, scenario.statics.direction)
    zeta = damping_ratios(system.C, modes, system.branches)
    notes = sampling_warnings(scenario, modes)
    for note in notes:
        warnings.warn(note, SamplingWarning, stacklevel=2)
    loss_notes, statics_line = loss_factor_notes(scenario, simulation is not None)
    if statics_line and statics is not None:
        log(statics_line)
    steady = None if scenario.excitation is None else steady_state(system, scenario.excitation)
    points = {p.name: p.position for p in scenario.points}
    out_of_range = (([no_statics] if no_statics else []) + loss_notes + static_range(statics, timed)
                    + implausible_inputs(system, scenario.excitation, points))
    if steady is not None:
        out_of_range += fit_band_range(scenario.viscoelastic, steady.f_hz)
    for note in out_of_range:
        notes.append(note)
        warnings.warn(note, RangeWarning, stacklevel=2)
    # A choice of the model, not a range it leaves: said beside the modes, not among the warnings.
    stiffness_note = geometric_stiffness_note(system, scenario.statics.vector)
    frf, frf_extras = _frequency_responses(scenario)
    random = None if scenario.random is None else random_response(system, scenario.random, points)
    if random is not None and scenario.random.time_check is not None:
        # The time model on both sides: the loss factors' causal models damp the record and its FRFs alike.
        random = dataclasses.replace(random, time_check=random_time_check(
            scenario.time_system, scenario.random, points, scenario.random.time_check,
            simulation=simulation, progress=progress))
    spectrum, isolation = _spectrum(system, scenario.response_spectrum)
    if spectrum is not None:
        notes.extend(spectrum.notes)
    records = {} if scenario.spectrum_records is None else _spectrum_records(scenario, spectrum, notes)
    results = RunResults(name=scenario.name, description=scenario.description, system=system, modes=modes,
                         design=design_metrics(system, scenario.design.torque_axis), damping_ratios=zeta,
                         statics=statics, frf=frf, frf_extras=frf_extras, steady_state=steady,
                         random=random, spectrum=spectrum, isolation=isolation, **records,
                         viscoelastic=scenario.viscoelastic,
                         provenance=provenance(scenario), scenario=scenario, stiffness_note=stiffness_note,
                         **_loss_factor_labels(scenario, statics_line if statics is not None else ""))
    if drawing is not None:
        drawing.submit(results)  # the modal and FRF figures are drawn while the solve runs
    if simulation is not None:
        timed = time_response(scenario, statics, _InMemory() if sink is None else sink, progress,
                              keep_all=simulation.samples <= MEMORY_SAMPLES)
        results = dataclasses.replace(results, **timed.drawn)
        if scenario.shock_response_spectrum is not None:  # every sample is kept (checked on loading)
            ground = scenario.excitation.ground if scenario.excitation is not None else None
            results = dataclasses.replace(results, srs=shock_spectra(
                results.response, results.points, scenario.shock_response_spectrum,
                None if ground is None else ground.direction))
        notes.extend(timed.notes)
    if scenario.severity is not None:  # before the sink finishes the file
        results = dataclasses.replace(results, severity=_severity(scenario, results))
    if simulation is not None:
        if drawing is not None:
            drawing.submit(results)
        if sink is not None:
            sink.finish(results)
    return dataclasses.replace(results, notes=tuple(notes))


def _severity(scenario, results):
    """The ``[severity]`` of a run's results (:func:`sixdof.analysis.severity.run_severity`); a time history only
    where the run holds every sample."""
    settings, system = scenario.severity, results.system
    positions = measured_points(settings, {p.name: p.position for p in scenario.points},
                                {m.name: m.position for m in system.mounts})
    whole = scenario.simulation is not None and scenario.simulation.samples <= MEMORY_SAMPLES
    return make(run_severity, "severity", settings=settings, system=system, positions=positions,
                steady=results.steady_state, random=results.random, random_input=scenario.random,
                response=results.response if whole else None)


def _spectrum(system, settings):
    """The response-spectrum analysis of ``[spectrum]`` (None without one), and for an isolated system (hysteretic
    axes linearized ``"effective"``) the EN 1998-2 effective-linearization loop whose converged analysis it is."""
    if settings is None:
        return None, None
    loop = isolated_spectrum(system, settings)
    return (response_spectrum(system, settings), None) if loop is None else (loop.response, loop)
def _spectrum_records(scenario, spectrum, notes: list) -> dict:
    """The RunResults fields of ``[spectrum] records`` (issue 48, point 5): the suite matched to the elastic spectrum
    (:func:`~sixdof.analysis.matching.elastic_target`, T1 the period of the mode with the largest effective mass
    along the records' direction), its EN 1998-1 3.2.3.1.2 checks, whose failures are warned of and added to
    ``notes``, and the time system's peaks under each record (:func:`~sixdof.analysis.record_peaks.record_peaks`),
    sought at :data:`MIN_SAMPLES_PER_PERIOD` samples per period of the highest natural frequency at least."""
    settings = scenario.spectrum_records
    t1 = float(spectrum.period[spectrum.dominant_mode(settings.direction)])
    try:  # what the file cannot show before the modes are known: a step too long for T1, a table too short
        target = elastic_target(scenario.response_spectrum.spectrum, settings.direction, t1, settings.dt)
        suite, check = ec8_suite(target.periods, target.sa, settings, ag_s=target.ag_s, fundamental_period=t1,
                                 source=target.source)
    except InputError as exc:
        raise exc if exc.field.startswith("spectrum.") else exc.within("spectrum.records") from None
    for failure in check.failures:
        notes.append(f"spectrum.records: {failure}")
        warnings.warn(notes[-1], RecordsWarning, stacklevel=3)
    system = scenario.time_system
    f_max = float(np.max(system.modes.frequency_hz))
    wanted = int(np.ceil(MIN_SAMPLES_PER_PERIOD * f_max * settings.dt - 1e-9))
    steps = max(1, min(wanted, (MEMORY_SAMPLES - 1) // (suite.t.size - 1)))  # each run held in memory
    if steps < wanted:
        notes.append(f"spectrum.records: the peaks under each record are sought at {steps / settings.dt:g} Hz, "
                     f"{steps / (settings.dt * f_max):.1f} samples per period of the highest natural frequency "
                     f"({f_max:.4g} Hz; {MEMORY_SAMPLES} samples a run at most): they may read low there")
        warnings.warn(notes[-1], SamplingWarning, stacklevel=3)
    peaks = record_peaks(system, suite.records, settings.direction, sample_rate_hz=steps / settings.dt)
    return {"spectrum_records": suite, "records_check": check, "record_peaks": peaks}


def save(results: RunResults, out_root: str | Path = "outputs", *, sink=None, drawing=None,
         command_line: str | None = None) -> Path:
    """Write a run's results (:func:`run`) into ``out_root/<name>/``: ``results.h5``, every figure and
    ``summary.md``, all or nothing (:mod:`sixdof.io.output`: a staged folder swapped into place; files there
    that sixdof did not write are kept).

    Parameters
    ----------
    results : sixdof.results.RunResults
        As :func:`run` returns them.
    out_root : str or pathlib.Path
    sink : sixdof.io.stream.ResultsStream, optional
        The sink the run streamed into: its finished file becomes ``results.h5`` (linked, or copied across
        filesystems: the sink's file stays where it is), instead of one written from ``results`` (which hold only
        what the figures draw). Its command line is the one it was opened with.
    drawing : optional
        What draws the figures (``submit(results)``, ``save(folder) -> list of paths``); default
        :class:`sixdof.plots.drawer.InProcessDrawer`.
    command_line : str, optional
        Stored as provenance.

    Returns
    -------
    pathlib.Path
        The folder written.

    Raises
    ------
    InputError
        Before anything is written: ``results`` without their scenario (not from :func:`run`), a run's
        results thinned for the figures without the ``sink`` that holds them whole, a scenario name that is
        not one safe path component, an ``out_root`` that cannot be written, or a target that is a file, a
        link, or a folder sixdof did not write (:func:`sixdof.io.output.check_target`).
    """
    _check_saveable(results, sink)
    target = output.check_target(out_root, results.name)
    with drawer(drawing) as drawing:
        return output.write_folder(target, lambda stage: _save_into(stage, results, sink, drawing, command_line))


def run_scenario(scenario, out_root: str | Path = "outputs", *, progress: bool = True, log=print,
                 command_line: str | None = None, workers=None) -> tuple[RunResults, Path]:
    """:func:`run`, then :func:`save` into ``out_root/<name>/``: what ``sixdof run`` does. The folder is checked
    first (before any computing) and a run with a ``[simulation]`` streams every window into its staged
    ``results.h5`` as it goes (:class:`~sixdof.io.stream.ResultsStream`), so memory stays bounded however long
    it runs.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario or str or pathlib.Path
    out_root : str or pathlib.Path
    progress, log :
        As :func:`run`'s (``log`` defaults to ``print``).
    command_line : str, optional
        Stored as provenance.
    workers : optional
        What draws the figures (:func:`save`'s ``drawing``; the command line passes worker processes started
        before it loaded the scenario, which draw the modal figures while the solve runs).

    Returns
    -------
    tuple of (sixdof.results.RunResults, pathlib.Path)
        The results and the folder written.

    Raises
    ------
    InputError
        Before anything is computed: a scenario name that is not one safe path component, an ``out_root``
        that cannot be written, or a target that is a file, a link, or a folder sixdof did not write
        (:func:`sixdof.io.output.check_target`).
        Or what :func:`load_scenario`, :func:`~sixdof.workflows.prepare.prepare` and :func:`run` raise
        (:class:`~sixdof.errors.ScenarioError` among them).
    OSError
        Before the solve: no room on the disk (``ENOSPC``) or a file-size limit (``EFBIG``) too small for
        the run's time series.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    target = output.check_target(out_root, scenario.name)
    scenario = prepare(scenario)
    computed = []

    def write(stage: Path) -> None:
        if scenario.simulation is None:
            computed.append(run(scenario, progress=progress, log=log, drawing=drawing))
            _save_into(stage, computed[0], None, drawing, command_line)
            return
        with ResultsStream(stage / "results.h5", command_line=command_line, omit=scenario.output.omitted) as sink:
            computed.append(run(scenario, sink=sink, progress=progress, log=log, drawing=drawing))
        _save_into(stage, computed[0], sink, drawing, command_line)

    with drawer(workers) as drawing:
        if scenario.simulation is not None:
            output.check_room(target, file_bytes(scenario))
        output.write_folder(target, write)
    return computed[0], target


def _check_saveable(results: RunResults, sink) -> None:
    """``results`` as :func:`run` returns them (with their scenario), and whole unless their ``sink`` comes too."""
    scenario = results.scenario
    if scenario is None:
        raise InputError("results", "the RunResults of sixdof.run (they carry the scenario their summary is made "
                         "of); a results file is redrawn by sixdof.workflows.redraw.redraw",
                         Plain("results without their scenario"))
    simulation = scenario.simulation
    if sink is None and simulation is not None and results.response.t.size != simulation.samples:
        raise InputError("sink", "the sink the run streamed into (its results hold only the samples the figures "
                         "draw)", Plain(f"{results.response.t.size:,} of {simulation.samples:,} samples and no sink"))


def _save_into(stage: Path, results: RunResults, sink, drawing, command_line: str | None) -> None:
    """``results.h5`` (the sink's, or written from ``results``), the figures, ``summary.md`` and ``report.html``
    into ``stage``.
    A sink's file elsewhere is linked (copied across filesystems), never moved: it stays the user's."""
    if sink is None:
        timed = results.scenario.simulation is not None  # what [output] leaves out is derived from the time response
        store.write_results(stage / "results.h5", results, command_line=command_line,
                            omit=results.scenario.output.omitted if timed else ())
    elif Path(sink.path) != stage / "results.h5":
        try:
            os.link(sink.path, stage / "results.h5")
        except OSError:  # another filesystem, or one without hard links
            shutil.copyfile(sink.path, stage / "results.h5")
    drawing.submit(results)
    figures = drawing.save(stage)
    if results.scenario.output.animate_modes and results.modes is not None:
        from sixdof.plots.modes import write_mode_animations  # noqa: PLC0415 (loads matplotlib: only when asked)

        with held_signals():  # matplotlib's C code can swallow a KeyboardInterrupt
            figures = [*figures, *write_mode_animations(results.modes, results.system, stage)]
    summary = report.summary_markdown(results, html_report.embeddable(figures))  # one image per figure
    (stage / "summary.md").write_text(summary, encoding="utf-8")
    html_report.write_run_report(stage, results, summary, figures)


def _silent(*_) -> None:
    """The log of a run that prints nothing."""


class _InMemory:
    """The sink of a run held in memory: its windows are kept whole by the run itself."""

    def append(self, piece) -> None:
        pass


def file_bytes(scenario) -> int:
    """About the smallest size [bytes] of a run's results file: its time series (float64), for the disk check
    made before a run starts."""
    simulation = scenario.simulation
    per_sample = 64 + 22 * len(scenario.system.mounts) + 27 * len(scenario.points)
    return int(8 * per_sample * simulation.samples)


def _frequency_responses(scenario) -> tuple[object, dict[str, object]]:
    """The receptance cross-check and the named point FRFs and transmissibilities a scenario asks for
    (``None`` and ``{}`` without an ``[frf]`` table)."""
    if scenario.frf is None:
        return None, {}

    system, f_hz = scenario.system, scenario.frf.grid()
    receptance = cross_check(system, f_hz)
    extras = {}
    for r in scenario.frf.point:
        extras[r.name] = point_frf(system, f_hz, r.load_point, r.load_direction, r.response_point,
                                   r.response_direction, quantity=r.quantity)
    for r in scenario.frf.force_transmissibility:
        extras[r.name] = force_transmissibility(system, f_hz, r.load_point, r.load_direction)
    for r in scenario.frf.ground_transmissibility:
        extras[r.name] = ground_transmissibility(system, f_hz, r.ground_direction, r.response_point)
    return receptance, extras


def provenance(scenario) -> dict[str, str]:
    """What a run records about where it came from (the file adds the command line, creation time and
    versions)."""
    return {"scenario_text": scenario.text or ""}


def loss_factor_notes(scenario, timed: bool = True) -> tuple[list[str], str]:
    """What a run says of its mounts' loss factors in the time paths: warnings (a causal model that misses its
    targets, :func:`~sixdof.model.viscoelastic.loss_fit_misses`; loss factors left out with
    ``loss_factor_model = "hysteretic"``, when ``timed``: a time path runs) and the statics line
    (:func:`~sixdof.model.viscoelastic.long_term_note`, "" without causal models)."""

    notes = loss_fit_misses(scenario.viscoelastic)
    lossy = [m.name for m in scenario.time_system.mounts if np.any(m.loss_factor)]
    if lossy and timed:
        notes.append(f'damping.loss_factor_model = "hysteretic": the time paths (direct solve, superposition, '
                     f"validate) leave out the loss factors of mount(s) {', '.join(lossy)}, so their time response "
                     "is not damped by them (a switch-on transient does not decay as the frequency responses say); "
                     'the default "causal" carries them as causal Maxwell models')
    return notes, long_term_note(scenario.viscoelastic)


def _loss_factor_labels(scenario, statics_line: str) -> dict:
    """The RunResults fields of a run's loss factors: the model, the time system where it differs, the statics
    line."""
    if not np.any(scenario.system.loss_factors) and not scenario.causal_loss_fits:
        return {}
    timed = scenario.time_system if scenario.time_system is not scenario.system else None
    return {"loss_factor_model": scenario.loss_factor_model, "time_system": timed,
            "loss_factor_statics": statics_line}
