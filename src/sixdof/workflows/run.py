"""One run of a scenario, end to end: modal analysis and statics, the time response by the direct
solver cross-checked by modal superposition, frequency responses; results, figures and a summary
written under ``<out>/<scenario name>/``.

Everything is written through :mod:`sixdof.io.output`: all or nothing, never outside ``out``, and nothing
deleted that sixdof did not write.
"""

from __future__ import annotations

import contextlib
import dataclasses
import warnings
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np

from sixdof.analysis.compare import QUANTITIES
from sixdof.analysis.statespace import damping_ratios
from sixdof.analysis.statics import try_gravity_statics
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
from sixdof.io import output
from sixdof.plots.drawer import FigureDrawer, InProcessDrawer
from sixdof.results import Event, RunResults, envelope_samples, time_concat, time_slice

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


@dataclass(frozen=True, eq=False)
class RunOutcome:
    """What :func:`run_scenario` computed and where it wrote it.

    Attributes
    ----------
    directory : pathlib.Path
        ``<out>/<scenario name>``.
    results_path : pathlib.Path
        The HDF5 results file.
    figures : tuple of pathlib.Path
    summary_path : pathlib.Path
    modes, statics, damping_ratios, response, superposition, agreement, frf :
        The computed objects (``None`` for parts the scenario does not ask for).
    warnings : tuple of str
        Warnings raised during the run (sampling, agreement, mount limits), also shown in the summary.
    mount_check : sixdof.analysis.mountcheck.MountCheck or None
        Total mount loads and deflections, tension and limits (runs with a simulation).
    steady_state : sixdof.analysis.steady.SteadyState or None
        Amplitudes and isolation at the operating frequencies (harmonic loads without end).
    points : dict of str to sixdof.analysis.response.PointMotion
        The motion of the scenario's ``[[points]]`` (what the figures and the summary show of a long run).
    random : sixdof.analysis.random.RandomResponse or None
        The response to the scenario's ``[random]`` PSD.
    srs : sixdof.analysis.srs.ShockSpectra or None
        The shock response spectra of the scenario's ``[shock_response_spectrum]``.
    contacts, energy, refined :
        Runs with nonlinear mounts: when and where they engaged, the energy balance and the agreement with a
        second solve at tighter tolerances (:mod:`sixdof.analysis.contact`).
    """

    directory: Path
    results_path: Path
    figures: tuple[Path, ...]
    summary_path: Path
    modes: object
    statics: object
    damping_ratios: np.ndarray
    response: object
    superposition: object
    agreement: object
    frf: object
    warnings: tuple[str, ...]
    mount_check: object = None
    steady_state: object = None
    points: dict = field(default_factory=dict)
    random: object = None
    srs: object = None
    contacts: object = None
    energy: object = None
    refined: object = None


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


def run_scenario(scenario, out_root: str | Path = "outputs", *, progress: bool = True,
                 log=print, command_line: str | None = None, workers: FigureDrawer | None = None) -> RunOutcome:
    """Run everything a scenario asks for and write results, figures and summary.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario
    out_root : str or pathlib.Path
        Results go to ``out_root/<scenario.name>/``, replaced as a whole when the run succeeds (files
        there that sixdof did not write are kept: :mod:`sixdof.io.output`).
    progress : bool
        Show the solver's progress (long runs).
    log : callable
        Receives the text printed along the way (tables, agreement, warnings).
    command_line : str, optional
        Stored as provenance.
    workers : sixdof.plots.drawer.FigureDrawer, optional
        What draws the figures, submitted as the run's parts appear (the command line's draws them in worker
        processes while the run computes); default: drawn in this process when they are saved.

    Returns
    -------
    RunOutcome
    """
    from sixdof.analysis.random import random_response
    from sixdof.analysis.srs import shock_spectra
    from sixdof.analysis.steady import steady_state
    from sixdof.io import report, store
    from sixdof.io.stream import ResultsStream

    target = output.check_target(out_root, scenario.name)
    with InProcessDrawer() if workers is None else contextlib.nullcontext(workers) as drawing:
        system, timed = scenario.system, scenario.time_system
        modes = system.modes
        statics, no_statics = try_gravity_statics(timed, scenario.statics.gravity, scenario.statics.direction)
        zeta = damping_ratios(system.C, modes, system.branches)
        notes = sampling_warnings(scenario, modes)
        for note in notes:
            warnings.warn(note, SamplingWarning, stacklevel=2)
        loss_notes, statics_line = loss_factor_notes(scenario, scenario.simulation is not None)
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
            from sixdof.validation.random_time import random_time_check

            # The time model on both sides: the loss factors' causal models damp the record and its FRFs alike.
            random = dataclasses.replace(random, time_check=random_time_check(
                scenario.time_system, scenario.random, points, scenario.random.time_check,
                simulation=scenario.simulation, progress=progress))
        run = RunResults(name=scenario.name, description=scenario.description, system=system, modes=modes,
                         damping_ratios=zeta, statics=statics, frf=frf, frf_extras=frf_extras, steady_state=steady,
                         random=random, viscoelastic=scenario.viscoelastic, provenance=_provenance(scenario),
                         **_loss_factor_labels(scenario, statics_line if statics is not None else ""))
        drawing.submit(run)  # the modal and FRF figures are drawn while the solve runs

        timed = None

        def write(stage: Path) -> None:
            nonlocal run, timed
            if scenario.simulation is None:
                store.write_results(stage / "results.h5", run, command_line=command_line)
            else:
                with ResultsStream(stage / "results.h5", command_line=command_line,
                                   omit=scenario.output.omitted) as stream:
                    timed = _time_response(scenario, statics, stream, progress)
                    run = dataclasses.replace(run, **timed.drawn)
                    if scenario.shock_response_spectrum is not None:  # every sample is kept (checked on loading)
                        ground = scenario.excitation.ground if scenario.excitation is not None else None
                        run = dataclasses.replace(run, srs=shock_spectra(
                            run.response, run.points, scenario.shock_response_spectrum,
                            None if ground is None else ground.direction))
                    drawing.submit(run)
                    stream.finish(run)
                notes.extend(timed.notes)
            figures.extend(drawing.save(stage))
            text = report.summary_markdown(scenario, modes, statics, zeta, run.response, run.mount_forces,
                                            run.agreement, run.superposition, frf, figures, notes,
                                            mount_check=run.mount_check, steady=steady, points=run.points,
                                            random=random, srs=run.srs, stiffness_note=stiffness_note,
                                            nonlinear=None if run.contacts is None else (run.contacts, run.energy,
                                                                                         run.refined))
            (stage / "summary.md").write_text(text, encoding="utf-8")

        figures = []
        if scenario.simulation is not None:
            output.check_room(target, file_bytes(scenario))
        output.write_folder(target, write)
    return RunOutcome(
        directory=target,
        results_path=target / "results.h5",
        figures=tuple(target / p.name for p in figures),
        summary_path=target / "summary.md",
        modes=modes,
        statics=statics,
        damping_ratios=zeta,
        response=run.response,
        superposition=run.superposition,
        agreement=run.agreement,
        frf=frf,
        warnings=tuple(notes),
        mount_check=run.mount_check,
        steady_state=steady,
        points=run.points,
        random=random,
        srs=run.srs,
        contacts=run.contacts,
        energy=run.energy,
        refined=run.refined,
    )


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
    from sixdof.analysis.compare import compare_motion, merge_agreements
    from sixdof.analysis.direct import is_nonlinear, progress_meter, simulate_windows
    from sixdof.analysis.mountcheck import MountLimitWarning, merge_mount_checks, mount_check
    from sixdof.analysis.records import merge_stats, merge_superposition
    from sixdof.analysis.response import mount_forces, points_motion
    from sixdof.analysis.superposition import superpose
    from sixdof.excitation import Excitation
    from sixdof.io.scenario import MEMORY_SAMPLES

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
    if not agreement.ok:
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
    the energy balance, the superposition compared only until the first mount engages, and when and where
    they engaged."""

    def __init__(self, system, excitation, settings, length: float) -> None:
        self.system, self.excitation, self.settings, self.length = system, excitation, settings, length
        self.events, self.balances, self.refined = [], [], None
        self.origin = None
        self.first_engaged = np.inf
        laws = system.nonlinear
        self.low, self.high = np.full(laws.count, np.inf), np.full(laws.count, -np.inf)

    def start(self, window_samples: dict) -> None:
        from sixdof.analysis.direct import simulate_windows

        tight = dataclasses.replace(self.settings, rtol=self.settings.rtol / REFINEMENT,
                                    atol=self.settings.atol / REFINEMENT)
        with warnings.catch_warnings():  # its warnings are the direct solve's
            warnings.simplefilter("ignore")
            self.tight = simulate_windows(self.system, self.excitation, tight, **window_samples)

    def check(self, piece):
        from sixdof.analysis.compare import compare, compare_motion, merge_agreements
        from sixdof.analysis.contact import energy_balance, total_deflection

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
        from sixdof.analysis.contact import contact_summary, merge_events, with_extremes

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
    from sixdof.analysis.frf import cross_check, force_transmissibility, ground_transmissibility, point_frf

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


def _provenance(scenario) -> dict[str, str]:
    """What a run records about where it came from (the file adds the command line, creation time and
    versions)."""
    return {"scenario_text": scenario.text or ""}


def loss_factor_notes(scenario, timed: bool = True) -> tuple[list[str], str]:
    """What a run says of its mounts' loss factors in the time paths: warnings (a causal model that misses its
    targets, :func:`~sixdof.model.viscoelastic.loss_fit_misses`; loss factors left out with
    ``loss_factor_model = "hysteretic"``, when ``timed``: a time path runs) and the statics line
    (:func:`~sixdof.model.viscoelastic.long_term_note`, "" without causal models)."""
    from sixdof.model.viscoelastic import long_term_note, loss_fit_misses

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


def validate_scenario(scenario, out_root: str | Path = "outputs", *, command_line: str | None = None,
                      workers: FigureDrawer | None = None, progress=None):
    """Validate a scenario's modal results against simulated time histories (issue 5).

    Runs :func:`sixdof.validation.validate` (free decays released from each mode shape, random-force
    runs with H1 estimates) and writes ``results.h5``, figures and ``validation.md`` to
    ``out_root/<name>_validation/``, all or nothing, whatever the report's verdict (PASS or FAIL).

    The figures are drawn by ``workers`` (a :class:`sixdof.plots.drawer.FigureDrawer`), the modal ones
    while the validation runs; default: in this process. ``progress`` shows the validation's simulations
    (:func:`sixdof.progress.meter`).

    Returns
    -------
    tuple of (sixdof.validation.ValidationReport, pathlib.Path)
        The report and the folder written.
    """
    from sixdof.io import store
    from sixdof.io.report import validation_text
    from sixdof.validation import validate

    target = output.check_target(out_root, scenario.name, "_validation")
    with InProcessDrawer() if workers is None else contextlib.nullcontext(workers) as drawing:
        system = scenario.time_system  # the model the simulations integrate: the loss factors' causal models
        modes = system.modes
        for note in loss_factor_notes(scenario)[0]:
            warnings.warn(note, RangeWarning, stacklevel=2)
        run = RunResults(name=scenario.name, description=scenario.description, system=system, modes=modes,
                         damping_ratios=damping_ratios(system.C, modes, system.branches),
                         viscoelastic=scenario.viscoelastic, provenance=_provenance(scenario),
                         loss_factor_model=scenario.loss_factor_model if scenario.viscoelastic
                         or np.any(scenario.system.loss_factors) else "")
        drawing.submit(run)  # the modal figures are drawn while the validation experiment runs
        report = validate(system, progress=progress)
        run = dataclasses.replace(run, validation=report)
        drawing.submit(run)

        def write(stage: Path) -> None:
            store.write_results(stage / "results.h5", run, command_line=command_line)
            figures = drawing.save(stage)
            links = "\n".join(f"![{p.stem}]({p.name})" for p in figures)
            text = (f"# {scenario.name}: modal results against time histories\n\n{validation_text(report)}\n\n"
                    f"{links}\n")
            (stage / "validation.md").write_text(text, encoding="utf-8")

        return report, output.write_folder(target, write)


def redraw(results: str | Path, directory: str | Path | None = None, *,
           workers: FigureDrawer | None = None) -> list[Path]:
    """Draw every figure of a results file again (``sixdof plot``) and put them into ``directory``
    (default: beside the file), each replacing its namesake and all of them at once
    (:func:`sixdof.io.output.replace_files`). A namesake that sixdof did not write is never replaced: it is
    refused before anything is drawn.

    The figures are drawn by ``workers`` (a :class:`sixdof.plots.drawer.FigureDrawer`; the command line
    starts them before it reads the file); default: in this process.

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
    from sixdof.io.store import load_results
    from sixdof.plots import figure_names

    if directory:  # checked as run checks its --out: before reading or drawing anything
        output.check_output_root(directory)
    run = load_results(results)
    if not figure_names(run):
        what = "a sweep's results (`sixdof sweep`): no figures" if run.sweep is not None else "nothing to draw"
        raise InputError("results", "a results file with something to draw (the results.h5 of `sixdof run` or "
                         "`sixdof validate`)", Plain(f"{results}: {what}"))
    directory = Path(directory) if directory else Path(results).parent
    output.check_files(directory, figure_names(run))
    with InProcessDrawer() if workers is None else contextlib.nullcontext(workers) as drawing:
        drawing.submit(run)
        return output.replace_files(directory, drawing.save)
