"""A run's time response, window by window: the direct solve, its modal-superposition cross-check, mount
forces and checks, point motions and, with nonlinear mounts, their own checks (a second solve at tighter
tolerances, the energy balance); what the figures draw is kept, the rest streamed (:func:`time_response`)."""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass
from functools import partial

import numpy as np

from sixdof.analysis.compare import QUANTITIES, compare, compare_motion, merge_agreements
from sixdof.analysis.contact import contact_summary, energy_balance, merge_events, total_deflection, with_extremes
from sixdof.analysis.direct import is_nonlinear, progress_meter, simulate_windows
from sixdof.analysis.mountcheck import MountLimitWarning, merge_mount_checks, mount_check
from sixdof.analysis.records import merge_stats, merge_superposition
from sixdof.analysis.response import mount_forces, points_motion
from sixdof.analysis.superposition import superpose
from sixdof.analysis.validity import GroundDriftWarning, RangeWarning, body_length, ground_drift
from sixdof.excitation import Excitation
from sixdof.results import Event, RunResults, envelope_samples, time_concat, time_slice

#: Time bins in which a long run keeps each drawn series' extremes: at least one per pixel column of the
#: widest figure with time axes (13 in at the default 150 dpi).
ENVELOPE_BINS = 2000
#: Output samples per window of a run too long to hold in memory: a window's arrays (~4 kB per sample with its
#: cross-check, mount forces and checks) stay near 30 MB, while a window costs ~1 ms besides its steps.
LONG_RUN_WINDOW = 8192

class AgreementWarning(UserWarning):
    """The direct solve and modal superposition disagree by more than the tolerance."""


@dataclass(frozen=True, eq=False)
class TimeResponse:
    """A run's time response as :func:`time_response` leaves it: ``drawn`` are the RunResults fields the
    figures and the summary take (every sample, or for a long run only the samples the figures draw; the
    summaries over every window), ``notes`` its warnings."""

    drawn: dict
    notes: list


def time_response(scenario, statics, stream, progress: bool, *, keep_all: bool) -> TimeResponse:
    """The direct solve and its cross-check, window by window, each window appended to ``stream`` as it is done.

    Every window of :func:`sixdof.analysis.direct.simulate_windows` gets its own modal superposition
    (continued from the previous window's end: independent of the direct solve), mount forces and checks and
    point motions; the agreement, mount checks and solver statistics are merged over the windows. With
    ``keep_all`` (a run of at most :data:`~sixdof.io.scenario.MEMORY_SAMPLES` samples) every sample stays in
    memory; otherwise only the samples that hold each drawn series' extremes per pixel column
    (:func:`envelope_samples`), so that memory is bounded whatever the run's duration.
    """

    system, settings, options = scenario.time_system, scenario.simulation, scenario.superposition
    excitation = scenario.excitation if scenario.excitation is not None else Excitation()
    points = {p.name: p.position for p in scenario.points}
    length = body_length(system)
    omega = float(np.max(system.modes.omega))  # the velocities' and accelerations' floors (compare_motion)
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
    return TimeResponse(drawn=drawn, notes=notes)


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
