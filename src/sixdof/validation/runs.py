"""The validation experiment's runs: :func:`validate` simulates the free decays and the random-force runs of
:mod:`sixdof.validation.experiment` (which describes the experiment, its results and its limits) and gives the
verdict.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from sixdof.analysis.frf import parse_direction, receptance
from sixdof.analysis.statespace import damped_modes
from sixdof.dofs import DOFS
from sixdof.errors import InputError, SolverError, point, readonly
from sixdof.model.kinematics import unit_load
from sixdof.model.modes import Modes
from sixdof.model.system import System
from sixdof.progress import meter
from sixdof.results import TimeHistory
from sixdof.validation.estimation import (
    DecayEstimate,
    decay_estimate,
    estimate_frf,
    h1_random_error,
    held_model_frf,
    peak_frequency,
)
from sixdof.validation.experiment import (
    FAIL,
    H1_FLOOR,
    MODEL_CURVE_POINTS,
    PASS,
    Check,
    FreeDecay,
    ModeCheck,
    RandomRun,
    ValidationReport,
    ValidationSettings,
    integrated_model,
    mode_checks,
)


def validate(system: System, settings: ValidationSettings | None = None, *,
             model: System | None = None, progress=None) -> ValidationReport:
    """Validate the modal results of a model against simulated time histories of ``system``.

    Runs one free decay per elastic mode and one random-force simulation per elastic mode with
    :func:`sixdof.analysis.direct.simulate`, then compares damped frequencies, damping ratios
    (logarithmic decrement), FRF peaks and the H1 FRF with the modal analysis, and gives each a
    verdict against its stated limit (see the module docstring).

    Parameters
    ----------
    system : System
        The system whose time histories are simulated; with nonlinear mounts, as they are (its modal results,
        and the default ``model``, are its linearization), so that the checks fail where the motion engages a
        stop or lifts a mount.
    settings : ValidationSettings, optional
    model : System, optional
        The model whose modal results are checked (modes, damping, FRF, and the mode shapes that
        define the release states and modal coordinates). Default: ``system`` itself. Give another
        one to check, say, an updated or simplified model against the reference system's time
        histories (the same number of DOFs and the same load point apply).
    progress : None, bool, "text" or "tqdm", optional
        Show the simulations done (:func:`sixdof.progress.meter`).

    Returns
    -------
    ValidationReport
        With ``verdict`` ``PASS`` or ``FAIL``.

    Raises
    ------
    InputError
        Bad settings or model, or a model without underdamped elastic modes.
    SolverError
        From the time integration.
    """
    settings = ValidationSettings() if settings is None else settings
    if not isinstance(settings, ValidationSettings):
        raise InputError("settings", "a ValidationSettings", settings)
    model = system if model is None else model
    if not isinstance(model, System):
        raise InputError("model", "a System", model)
    notes = []
    side = _model_side(system, model, notes)
    start = time.perf_counter()
    shown = meter(progress, 2 * len(side.elastic), "runs", "validation (free decays, random-force runs)")
    runs_done = 0

    def one_more_run():
        nonlocal runs_done
        runs_done += 1
        shown.show(runs_done)

    decays = _free_decays(system, side, settings, notes, one_more_run)
    random = _random_runs(system, side, decays, settings, notes, one_more_run)
    shown.close()
    wall = time.perf_counter() - start
    return _verdict(side, decays, random, wall, notes)


@dataclass(frozen=True, eq=False)
class _ModelSide:
    """What the time histories are compared with: the model as the integration sees it, its modes and damped poles.

    ``zeta`` and ``f_d`` (the exact damping ratio and damped frequency [Hz] of each complex pole) are NaN off the
    elastic modes."""

    reference: System
    M: np.ndarray
    modes: Modes
    poles: np.ndarray
    complex_shapes: np.ndarray
    elastic: list[int]
    f_n: np.ndarray
    phi: np.ndarray
    zeta: np.ndarray
    f_d: np.ndarray


def _model_side(system: System, model: System, notes: list[str]) -> _ModelSide:
    """The model side of :func:`validate` (its notes appended to ``notes``); refuses a model without underdamped
    elastic modes."""
    field = "system" if model is system else "model"
    if system.nonlinear_axes:
        # The modal results are the linearization's; the histories stay the nonlinear model's, so that the check
        # says whether the linearization describes the motion at the release amplitude and the random force.
        notes.append(f"nonlinear mount axes ({', '.join(system.nonlinear_axes)}): the modal results are those of "
                     "the linearization about the static equilibrium, the time histories those of the nonlinear "
                     "model; they differ (and the checks fail) where a free decay (released at 1 mm or 1 mrad) or "
                     "a random-force run engages a stop or lifts a mount")
        model = system.linearized() if model is system else model
    reference, without = integrated_model(model)
    if without:
        notes.append(f"hysteretic loss factors of mount(s) {', '.join(map(repr, without))} left out of the model: a "
                     "frequency-independent complex stiffness has no time-domain form, so the time histories "
                     "cannot contain it (the frequency responses of `sixdof run` include it)")
    modes = reference.modes
    poles, complex_shapes = damped_modes(reference.C, modes, reference.branches)
    elastic = [r for r in range(6) if r not in modes.zero_modes]
    if not elastic:
        raise InputError(field, "a system with at least one elastic mode", "none")
    if not np.all(np.isfinite(poles[elastic])):
        zeta_diagonal = [float(np.einsum("i,ij,j", modes.shapes[:, r], reference.C, modes.shapes[:, r])
                               / (2 * modes.omega[r])) for r in elastic]
        raise InputError(field, "underdamped elastic modes (zeta < 1) for a free-decay validation",
                         zeta_diagonal)
    zeta = np.full(6, np.nan)
    zeta[elastic] = -poles[elastic].real / np.abs(poles[elastic])
    f_d = np.full(6, np.nan)
    f_d[elastic] = poles[elastic].imag / (2 * np.pi)
    return _ModelSide(reference=reference, M=np.asarray(reference.M), modes=modes, poles=poles,
                      complex_shapes=complex_shapes, elastic=elastic, f_n=np.asarray(modes.frequency_hz),
                      phi=np.asarray(modes.shapes), zeta=zeta, f_d=f_d)


def _free_decays(system: System, side: _ModelSide, settings: ValidationSettings, notes: list[str],
                 one_more_run) -> list[FreeDecay]:
    """Experiment 1: one free decay per elastic mode, each released in its damped shape so that it moves in that
    mode alone; same sample count, so one compiled solver."""
    from sixdof.analysis.direct import SimulationSettings, simulate  # noqa: PLC0415 (the direct solve and the excitation load JAX)
    from sixdof.excitation import Excitation, InitialState  # noqa: PLC0415 (the direct solve and the excitation load JAX)

    modes, poles, zeta, f_d = side.modes, side.poles, side.zeta, side.f_d
    decays = []
    for r in side.elastic:
        delta = 2 * np.pi * zeta[r] / math.sqrt(1 - zeta[r] ** 2)
        cycles = settings.decay_cycles if delta == 0 else min(settings.decay_cycles, max(2.0, math.log(1e3) / delta))
        rate = (settings.decay_samples - 1) * f_d[r] / cycles
        shape = side.complex_shapes[:, r]
        shape = 1e-3 * shape / shape[DOFS.index(modes.dominant_dof[r])]  # dominant DOF: 1 mm or mrad, phase 0
        # The branches start in the mode too: f = k (lambda tau) / (1 + lambda tau) R s for f' = k R q' - f / tau.
        branches = side.reference.branches
        ratio = poles[r] * branches.tau / (1 + poles[r] * branches.tau)
        release = InitialState(q=shape.real, qd=(poles[r] * shape).real,
                               maxwell_force=(branches.stiffness * ratio * (branches.rows @ shape)).real)
        run = simulate(system, Excitation(initial=release),
                       SimulationSettings(duration=_span(settings.decay_samples, rate), sample_rate_hz=rate))
        eta = run.q @ side.M @ side.phi[:, r]
        try:
            estimate = decay_estimate(run.t, eta, unit="kg^0.5 m")
        except InputError as exc:  # not a decaying oscillation (a mount lifted, a stop engaged): the check fails
            notes.append(f"mode {r + 1}: its free decay is no decaying oscillation ({exc.got}): FAIL")
            estimate = DecayEstimate(f_damped_hz=math.nan, zeta=math.nan, log_decrement=math.nan,
                                     extrema_t=np.zeros(0), extrema_value=np.zeros(0), unit="kg^0.5 m")
        decays.append(FreeDecay(mode=r + 1, history=run, eta=readonly(eta), estimate=estimate))
        one_more_run()
    return decays


@dataclass(frozen=True, eq=False)
class _RandomSide:
    """What experiment 2 gives :func:`_verdict`: the force's point [m] and direction, one row, run and set of checks
    per elastic mode, and the simulated time of all runs [s]."""

    load_point: np.ndarray
    load_direction: np.ndarray
    rows: list[ModeCheck]
    runs: list[RandomRun]
    checks: list[Check]
    total_s: float


def _random_runs(system: System, side: _ModelSide, decays: list[FreeDecay], settings: ValidationSettings,
                 notes: list[str], one_more_run) -> _RandomSide:
    """Experiment 2: a random force, one run per elastic mode (see the module docstring), and each mode's row of
    the table with the free decay's estimates and its checks."""
    M, phi, reference = side.M, side.phi, side.reference
    lp = point(settings.load_point if settings.load_point is not None else system.positions[0], "load_point")
    ld, _ = parse_direction(settings.load_direction, "load_direction", rotations=False)
    Q = unit_load(lp, ld, False)
    nperseg = settings.segment_samples
    n = nperseg + (settings.averages - 1) * (nperseg - nperseg // 2)

    def model_eta(f):
        return receptance(reference, f).H @ Q @ M @ phi  # (nf, 6): eta per unit force [sqrt(kg) m/N]

    rows, runs, checks, total_s = [], [], [], 0.0
    rng = np.random.default_rng(settings.seed)
    for r, decay in zip(side.elastic, decays):
        low, high, fs = _band(side, r, settings, notes)
        samples, run = _random_history(system, lp, ld, settings, n, fs, rng)
        one_more_run()
        total_s += run.t[-1]
        row, random_run, good = _random_mode(side, r, decay, settings, samples, run, fs, (low, high), model_eta)
        runs.append(random_run)
        rows.append(row)
        if not good:
            notes.append(f"mode {r + 1}: no bin of its band has coherence >= 0.9: its H1 cannot be checked (FAIL)")
        checks += mode_checks(row, good)
    return _RandomSide(load_point=lp, load_direction=ld, rows=rows, runs=runs, checks=checks, total_s=total_s)


def _band(side: _ModelSide, r: int, settings: ValidationSettings, notes: list[str]) -> tuple[float, float, float]:
    """Mode ``r``'s band ``(low, high)`` [Hz] and the sample rate [Hz] of its random run (its segment's note
    appended to ``notes`` where the segment cannot resolve its half-power bandwidth)."""
    f_n, zeta = side.f_n, side.zeta
    neighbours = [f_n[s] for s in side.elastic if s != r]
    width = 2 * zeta[r] * f_n[r]
    # Half-way to the neighbours, but never closer than three half-power bandwidths (a mode nearly
    # coincident with another keeps its resonance and flanks in band: its modal coordinate, and the
    # model of it, carry the neighbour's coupling alike), within 0.7 to 1.3 times its frequency.
    below = max([0.5 * (f_n[r] + f) for f in neighbours if f < f_n[r]], default=0.0)
    above = min([0.5 * (f_n[r] + f) for f in neighbours if f > f_n[r]], default=math.inf)
    low = max(min(below, f_n[r] - 3 * width), 0.7 * f_n[r])
    high = min(max(above, f_n[r] + 3 * width), 1.3 * f_n[r])
    nperseg = settings.segment_samples
    segment = max(8.0 / f_n[r], 4.0 / width if width > 0 else math.inf)
    segment = min(segment, settings.max_segment_s, nperseg / (settings.oversampling * high))
    if segment * width < 4.0 * (1 - 1e-9):
        notes.append(f"mode {r + 1}: segment {segment:.4g} s resolves {1 / segment:.3g} Hz, "
                     f"coarser than a quarter of its half-power bandwidth {width:.3g} Hz: "
                     "its H1 peak is bias-limited")
    return low, high, nperseg / segment


def _random_history(system: System, lp: np.ndarray, ld: np.ndarray, settings: ValidationSettings, n: int, fs: float,
                    rng: np.random.Generator) -> tuple[np.ndarray, TimeHistory]:
    """The white-noise force's ``n`` samples at ``fs`` [Hz] (next from ``rng``) and the run they drive."""
    from sixdof.analysis.direct import SimulationSettings, simulate  # noqa: PLC0415 (the direct solve and the excitation load JAX)
    from sixdof.excitation import Excitation, Load, Table  # noqa: PLC0415 (the direct solve and the excitation load JAX)

    samples = rng.standard_normal(n)
    samples[0] = 0.0  # start from rest without a jump
    load = Load("validation", lp, force=settings.force_rms * ld,
                signal=Table(np.arange(n) / fs, samples, outside="zero"))
    run = simulate(system, Excitation(loads=[load]),
                   SimulationSettings(duration=_span(n, fs), sample_rate_hz=fs,
                                      rtol=settings.rtol, atol=settings.atol))
    if run.t.size != n:
        raise SolverError(f"validation run returned {run.t.size} samples, expected {n}")
    return samples, run


def _random_mode(side: _ModelSide, r: int, decay: FreeDecay, settings: ValidationSettings, samples: np.ndarray,
                 run: TimeHistory, fs: float, band: tuple[float, float],
                 model_eta) -> tuple[ModeCheck, RandomRun, int]:
    """Mode ``r``'s H1 from its random run against the held model FRF ``model_eta`` gives: its table row (with
    ``decay``'s estimates), the figure-ready run, and how many bins of its band have coherence >= 0.9."""
    low, high = band
    f_n, modes = side.f_n, side.modes
    nperseg = settings.segment_samples
    est = estimate_frf(settings.force_rms * samples, run.q @ side.M @ side.phi[:, r], fs, nperseg,
                       unit="kg^0.5 m/N")
    # Aliases up to twice the highest natural frequency keep the held model exact in band.
    aliases = int(math.ceil(2.0 * f_n[-1] / fs)) + 1
    G = held_model_frf(model_eta(est.f_hz)[:, r:r + 1], est.f_hz, fs,
                       lambda f, r=r: model_eta(f)[:, r:r + 1], aliases=aliases)
    in_band = (est.f_hz >= low) & (est.f_hz <= high)
    rel = np.abs(est.H1[:, 0] - G[:, 0]) / np.abs(G[:, 0])
    good = in_band & (est.coherence[:, 0] >= 0.9)
    beyond_floor = np.maximum(rel[good] - H1_FLOOR, 0.0) / est.random_error[good, 0]
    # The model's peak on a grid 1000 times finer than the estimate's.
    fine = np.linspace(low, high, 4001)
    f_pk_model = peak_frequency(fine, np.abs(model_eta(fine)[:, r]), low, high)
    f_pk_est = peak_frequency(est.f_hz, np.abs(est.H1[:, 0]), low, high)
    k = int(np.argmin(np.abs(est.f_hz - f_pk_est))) if np.isfinite(f_pk_est) else 0
    d = decay.estimate
    curve_f = np.linspace(low, high, MODEL_CURVE_POINTS)
    curve = held_model_frf(model_eta(curve_f)[:, r:r + 1], curve_f, fs,
                           lambda f, r=r: model_eta(f)[:, r:r + 1], aliases=aliases)[:, 0]
    random_run = RandomRun(mode=r + 1, band_hz=(float(low), float(high)), estimated=est, model=readonly(G, None),
                           model_f_hz=readonly(curve_f), model_curve=readonly(curve, None))
    row = ModeCheck(
        mode=r + 1, dominant_dof=modes.dominant_dof[r], f_model_hz=float(f_n[r]), zeta_model=float(side.zeta[r]),
        f_damped_model_hz=float(side.f_d[r]), f_damped_estimated_hz=d.f_damped_hz, zeta_estimated=d.zeta,
        log_decrement_estimated=d.log_decrement, f_peak_model_hz=f_pk_model, f_peak_estimated_hz=f_pk_est,
        frequency_resolution_hz=float(est.f_hz[1]),
        h1_median_error=float(np.median(rel[good])) if np.any(good) else math.nan,
        h1_error_in_sigmas=float(np.median(beyond_floor)) if np.any(good) else math.nan,
        h1_error_at_peak=float(rel[k]),
        h1_sigma_at_peak=float(h1_random_error(est.coherence[k, 0], est.effective_averages)),
    )
    return row, random_run, int(np.count_nonzero(good))


def _verdict(side: _ModelSide, decays: list[FreeDecay], random: _RandomSide, wall: float,
             notes: list[str]) -> ValidationReport:
    """The report: each mode's verdict from its checks, the validation's from every mode's."""
    modes = side.modes
    if modes.zero_modes:
        notes.append(f"rigid-body modes {[m + 1 for m in modes.zero_modes]} "
                     f"({', '.join(modes.free_dofs)} unrestrained) are not in the table")
    checks = random.checks
    mode_verdicts = tuple(PASS if all(c.verdict == PASS for c in checks if c.mode == row.mode) else FAIL
                          for row in random.rows)
    return ValidationReport(rows=tuple(random.rows), random_runs=tuple(random.runs), decays=tuple(decays),
                            load_point=random.load_point, load_direction=random.load_direction,
                            random_duration_s=float(random.total_s), wall_time_s=float(wall),
                            notes=tuple(notes), checks=tuple(checks), mode_verdicts=mode_verdicts,
                            verdict=PASS if all(v == PASS for v in mode_verdicts) else FAIL)


def _span(samples: int, rate: float) -> float:
    """Duration [s] holding exactly ``samples`` samples at ``rate`` [Hz]: a hair over
    ``(samples - 1) / rate``, so that round-off never puts the last sample past the end."""
    return (samples - 1) / rate * (1.0 + 1e-12)

