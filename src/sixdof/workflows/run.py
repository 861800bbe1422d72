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
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from sixdof.analysis.compare import QUANTITIES, compare, compare_motion, merge_agreements
from sixdof.analysis.contact import contact_summary, energy_balance, merge_events, total_deflection, with_extremes
from sixdof.analysis.design import design_metrics
from sixdof.analysis.direct import is_nonlinear, progress_meter, simulate_windows
from sixdof.analysis.frf import cross_check, force_transmissibility, ground_transmissibility, point_frf
from sixdof.analysis.isolation import isolated_spectrum
from sixdof.analysis.matching import RecordsWarning, ec8_suite, elastic_target
from sixdof.analysis.mountcheck import MountLimitWarning, merge_mount_checks, mount_check
from sixdof.analysis.random import random_response
from sixdof.analysis.record_peaks import record_peaks
from sixdof.analysis.records import merge_stats, merge_superposition
from sixdof.analysis.response import mount_forces, points_motion
from sixdof.analysis.severity import measured_points, run_severity
from sixdof.analysis.spectrum import response_spectrum
from sixdof.analysis.srs import shock_spectra
from sixdof.analysis.statespace import damping_ratios
from sixdof.analysis.statics import try_gravity_statics
from sixdof.analysis.steady import steady_state
from sixdof.analysis.superposition import superpose
from sixdof.analysis.validity import (
    GroundDriftWarning,
    RangeWarning,
    body_length,
    fit_band_range,
    geometric_stiffness_note,
    ground_drift,
    implausible_inputs,
    static_range,
)
from sixdof.errors import InputError, Plain
from sixdof.excitation import Excitation
from sixdof.interrupts import held_signals
from sixdof.io import html_report, output, report, store
from sixdof.io.scenario import MEMORY_SAMPLES, Scenario, load_scenario
from sixdof.io.stream import ResultsStream
from sixdof.model.viscoelastic import long_term_note, loss_fit_misses
from sixdof.results import Event, RunResults, envelope_samples, time_concat, time_slice
from sixdof.schema import make
from sixdof.validation.random_time import random_time_check
from sixdof.workflows.drawing import drawer
from sixdof.workflows.prepare import prepare

#: Time bins in which a long run keeps each drawn series' extremes: at least one per pixel column of the
#: widest figure with time axes (13 in at 120 dpi).
ENVELOPE_BINS = 1600
#: Output samples per window of a run too long to hold in memory: a window's arrays (~4 kB per sample with its
#: cross-check, mount forces and checks) stay near 30 MB, while a window costs ~1 ms besides its steps.
LONG_RUN_WINDOW = 8192

#: Fewest samples per period of the highest natural frequency or excitation frequency: below it the
#: sampled peaks of a sine are off by more than 5 % (1 - cos(pi / 10)).
MIN_SAMPLES_PER_PERIOD = 10


class SamplingWarning(UserWarning):
    """The output sample rate is too low for the frequencies in the response."""


class AgreementWarning(UserWarning):
    """The direct solve and modal superposition disagree by more than the tolerance."""


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
        timed = _time_response(scenario, statics, _InMemory() if sink is None else sink, progress)
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
            write_mode_animations(results.modes, results.system, stage)
    summary = report.summary_markdown(results, figures)
    (stage / "summary.md").write_text(summary, encoding="utf-8")
    html_report.write_run_report(stage, results, summary, figures)


def _silent(*_) -> None:
    """The log of a run that prints nothing."""


class _InMemory:
    """The sink of a run held in memory: its windows are kept whole by the run itself."""

    def append(self, piece) -> None:
        pass


@dataclass(frozen=True, eq=False)
class _TimeResponse:
    """A run's time response as :func:`_time_response` leaves it: ``drawn`` are the RunResults fields the
    figures and the summary take (every sample, or for a long run only the samples the figures draw; the
    summaries over every window), ``notes`` its warnings."""

    drawn: dict
    notes: list


def _time_response(scenario, statics, stream, progress) -> _TimeResponse:
    """The direct solve and its cross-check, window by window, each window appended to ``stream`` as it is done.

    Every window of :func:`sixdof.analysis.direct.simulate_windows` gets its own modal superposition
    (continued from the previous window's end: independent of the direct solve), mount forces and checks and
    point motions; the agreement, mount checks and solver statistics are merged over the windows. A run of at
    most :data:`~sixdof.io.scenario.MEMORY_SAMPLES` samples keeps every sample in memory; a longer one keeps
    only the samples that hold each drawn series' extremes per pixel column (:func:`envelope_samples`), so its
    memory is bounded whatever its duration.
    """

    system, settings, options = scenario.time_system, scenario.simulation, scenario.superposition
    excitation = scenario.excitation if scenario.excitation is not None else Excitation()
    points = {p.name: p.position for p in scenario.points}
    length = body_length(system)
    omega = float(np.max(system.modes.omega))  # the velocities' and accelerations' floors (compare_motion)
    keep_all = settings.samples <= MEMORY_SAMPLES
    span = (settings.start, settings.start + settings.duration)
    meter = progress_meter(progress or None, settings)
    kept, stats, agreement, check, info, modal = [], None, None, None, None, None
    window_samples = {} if keep_all else {"window_samples": LONG_RUN_WINDOW}
    nonlinear = _Nonlinear(system, excitation, settings, length) if is_nonlinear(system) else None
    if nonlinear is not None:
        window_samples = {"window_samples": NONLINEAR_WINDOW}
        nonlinear.start(window_samples)
    for window in simulate_windows(system, excitation, settings, **window_samples):
        with warnings.catch_warnings():  # the cross-check would repeat the direct solve's range warnings
            warnings.simplefilter("ignore", RangeWarning)
            modal = superpose(system, excitation, window.t, method=options.method, n_modes=options.n_modes,
                              f_max_hz=options.f_max_hz, residual=options.residual,
                              start=None if modal is None else modal.superposition.end)
        forces = mount_forces(system, window)
        piece = RunResults(response=window, superposition=modal, mount_forces=forces,
                           mount_check=mount_check(system, forces, window.t, statics),
                           points=points_motion(window, points) if points else {},
                           agreement=compare_motion(window, modal, length=length, omega=omega))
        if nonlinear is not None:
            piece = nonlinear.check(piece)
        stream.append(piece)
        # Merged window by window: what is kept of the past stays bounded.
        stats = _merged(merge_stats, stats, window.stats)
        if piece.agreement is not None:  # with nonlinear mounts: only until the first engages
            agreement = _merged(merge_agreements, agreement, piece.agreement)
        check = _merged(partial(merge_mount_checks, system), check, piece.mount_check)
        info = _merged(merge_superposition, info, modal.superposition)
        kept.append(piece if keep_all else time_slice(piece, envelope_samples(
            window.t, _drawn_series(piece), *span, ENVELOPE_BINS)))
        meter.show(float(window.t[-1]))
    meter.close()
    joined = time_concat(kept)
    del kept  # the joined copy is what stays
    response = dataclasses.replace(joined.response, stats=stats)
    extra = {}
    if nonlinear is not None:
        extra = nonlinear.finish(span, joined.energy)
        response = dataclasses.replace(response, contacts=extra.pop("events"))
    drawn = dict(agreement=agreement, response=response, **extra,
                 events={name: Event(*event) for name, event in excitation.events(*span).items()},
                 superposition=dataclasses.replace(joined.superposition, superposition=info),
                 points=joined.points, mount_forces=joined.mount_forces,
                 mount_check=dataclasses.replace(check, deflection=joined.mount_check.deflection,
                                                 force=joined.mount_check.force,
                                                 compression=joined.mount_check.compression))
    notes = []
    drift = None if not response.has_ground else ground_drift(excitation.ground, response.t,
                                                              response.ground_displacement)
    if drift is not None:
        notes.append(drift)
        warnings.warn(drift, GroundDriftWarning, stacklevel=3)
    if agreement is not None and not agreement.ok:
        notes.append(f"direct and modal superposition disagree: worst DOF {agreement.worst_dof} "
                     f"({QUANTITIES[agreement.worst_quantity]}) at {agreement.worst:.3g} of its peak (tolerance "
                     f"{agreement.tolerance:.0e})")
        warnings.warn(notes[-1], AgreementWarning, stacklevel=3)
    for note in check.violations:
        notes.append(note)
        warnings.warn(note, MountLimitWarning, stacklevel=3)
    for note in [] if nonlinear is None else nonlinear.notes(extra):
        notes.append(note)
        warnings.warn(note, AgreementWarning, stacklevel=3)
    return _TimeResponse(drawn=drawn, notes=notes)


#: Output samples per window of a run with nonlinear mounts: every event restarts the solver on its window, whose
#: arrays it copies (~1 ms for 4096 samples).
NONLINEAR_WINDOW = 4096
#: The second solve of a run with nonlinear mounts has its tolerances divided by this.
REFINEMENT = 100.0


class _Nonlinear:
    """The cross-checks of a run with nonlinear mounts, window by window: a second solve at tighter tolerances,
    the energy balance, the superposition compared only until the first mount engages (never with hysteretic
    bearings), and when and where they engaged."""

    def __init__(self, system, excitation, settings, length: float) -> None:
        self.system, self.excitation, self.settings, self.length = system, excitation, settings, length
        self.events, self.balances, self.refined = [], [], None
        self.origin = None
        # Hysteretic bearings act from the start: the superposition (their linearization) is never compared.
        self.first_engaged = -np.inf if system.hysteretic.count else np.inf
        laws = system.nonlinear
        self.low, self.high = np.full(laws.count, np.inf), np.full(laws.count, -np.inf)

    def start(self, window_samples: dict) -> None:

        tight = dataclasses.replace(self.settings, rtol=self.settings.rtol / REFINEMENT,
                                    atol=self.settings.atol / REFINEMENT)
        with warnings.catch_warnings():  # its warnings are the direct solve's
            warnings.simplefilter("ignore")
            self.tight = simulate_windows(self.system, self.excitation, tight, **window_samples)

    def check(self, piece):

        window = piece.response
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tight = next(self.tight)
        refined = compare(tight.q, window.q, length=self.length)
        self.refined = refined if self.refined is None else merge_agreements([self.refined, refined])
        balance = energy_balance(self.system, window, origin=self.origin)
        if self.origin is None:
            self.origin = float(balance.kinetic[0] + balance.stored[0] + balance.dissipated[0] - balance.work[0])
        self.balances.append((balance.peak_residual, balance.energy_scale))
        self.events.append(window.contacts)
        statics = window.contacts.static_region
        engaged = window.contacts.t[window.contacts.region_to != statics[window.contacts.law]]
        if engaged.size:
            self.first_engaged = min(self.first_engaged, float(engaged.min()))
        d = total_deflection(self.system, window)
        self.low, self.high = np.minimum(self.low, d.min(axis=0)), np.maximum(self.high, d.max(axis=0))
        before = window.t <= self.first_engaged
        agreement = None
        if before.all():
            agreement = piece.agreement
        elif before.any():
            agreement = compare_motion(window, piece.superposition, length=self.length, keep=before,
                                       omega=float(np.max(self.system.modes.omega)))
        return dataclasses.replace(piece, agreement=agreement, energy=balance)

    def finish(self, span, energy) -> dict:
        """The run's events, contact summary, refined agreement and energy balance (``energy``: the kept samples'
        balance, whose extremes become the run's)."""

        events = merge_events(self.events)
        summary = contact_summary(self.system, events, np.array(span), self.low, self.high)
        energy = with_extremes(energy, *(max(values) for values in zip(*self.balances)))
        return {"events": events, "contacts": summary, "refined": self.refined, "energy": energy}

    def notes(self, extra) -> list[str]:
        notes = []
        energy = extra["energy"]
        if not energy.ok:
            notes.append(f"the energy balance of the run is off by {energy.worst:.3g} of its largest energy "
                         f"(tolerance {energy.tolerance:.0e})")
        refined = extra["refined"]
        if not refined.ok:
            notes.append(f"the direct solve and its second solve at {REFINEMENT:g}x tighter tolerances disagree: "
                         f"worst DOF {refined.worst_dof} at {refined.worst:.3g} of its peak (tolerance "
                         f"{refined.tolerance:.0e})")
        return notes


def _merged(merge, merged, new):
    """``new`` merged into what the previous windows merged to (``merge`` takes a list of two)."""
    return new if merged is None else merge([merged, new])


def _drawn_series(piece) -> np.ndarray:
    """The (n, k) series of a window that the figures and the summary show: the motion (and the motion
    relative to the ground), the superposition's difference, the mount and foundation forces."""
    response, n = piece.response, piece.response.t.size
    series = [response.q, response.qd, response.qdd, piece.superposition.q - response.q,
              np.moveaxis(piece.mount_forces.total, 0, 1).reshape(n, -1), piece.mount_forces.foundation_force]
    if response.has_ground:
        series.append(response.q_relative)
    return np.hstack(series)


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
