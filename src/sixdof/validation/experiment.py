"""The validation experiment: the modal results of a system checked against simulated time histories.

Two experiments on the time-domain solver, each compared with what the modal analysis predicts (the
estimators are in :mod:`sixdof.validation.estimation`):

1. **Free decay.** Released from rest in mode r's shape, the body oscillates in that mode alone
   (exactly for classical damping); :func:`~sixdof.validation.estimation.decay_estimate` gives its
   damped frequency and damping ratio, compared with ``f_r sqrt(1 - zeta_r^2)`` and ``zeta_r``.
2. **Random excitation.** A force at a body point, Gaussian white noise sampled at ``fs`` and
   linearly interpolated (a tabulated signal), drives the body; the H1 FRF and coherence of the
   mode's modal coordinate per unit force are estimated and compared with the model FRF including
   the first-order hold of the sampled force (:func:`~sixdof.validation.estimation.held_model_frf`).

Runtime: one random run per elastic mode, each ``averages`` Welch segments of ``segment_samples``
samples with 50 % overlap; a mode's segment lasts ``4 / (2 zeta_r f_r)`` (its bins a quarter of its
half-power bandwidth), at least 8 periods, at most ``max_segment_s``, and its sample rate is
``segment_samples / segment`` (at least ``oversampling`` times the top of the mode's band). Every run
has the same sample count, so the solver compiles once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from sixdof.analysis.frf import parse_direction, receptance
from sixdof.analysis.statespace import modal_damping_ratios
from sixdof.errors import InputError, SolverError, point, readonly
from sixdof.model.kinematics import unit_load
from sixdof.results import TimeHistory, label, part, quantity, sequence, stacked
from sixdof.validation.estimation import (
    DecayEstimate,
    EstimatedFRF,
    as_column,
    decay_estimate,
    estimate_frf,
    first_column,
    h1_random_error,
    held_model_frf,
    peak_frequency,
)

if TYPE_CHECKING:
    from sixdof.model.system import System


@dataclass(frozen=True)
class ValidationSettings:
    """How :func:`validate` excites and samples the system. Every default adapts to the system.

    Parameters
    ----------
    load_point : array_like, shape (3,), optional
        Where the random force acts [m from the CG]. Default: the first mount's position, which
        sits off every plane of symmetry of usual layouts.
    load_direction : str or array_like, shape (3,), optional
        Direction of the random force. Default ``[1, 1, 1]``: every DOF is driven.
    force_rms : float
        RMS of the random force [N] (linear system: scale only). Default 1000.
    segment_samples : int
        Samples per Welch segment, the same in every run. Default 2048.
    oversampling : float
        Sample rate of each run at least this many times the top of its mode's band. Default 4.
    max_segment_s : float
        Longest Welch segment [s] (undamped or very lightly damped modes). Default 120.
    averages : int
        Welch segments (50 % overlap) per run. Default 8.
    decay_cycles : float
        Damped cycles simulated per free decay, fewer when the amplitude would fall below 1e-3 of
        its start. Default 8.
    decay_samples : int
        Samples per free decay (one compiled solver serves all modes). Default 512.
    seed : int
        Seed of the random force. Default 0.
    rtol, atol : float
        Solver tolerances of the random runs (free decays: the solver's defaults). Default 1e-5 each, relative
        to each DOF's scale: far below the estimates' statistical errors (~1e-2), half the steps of 1e-7.
    """

    load_point: tuple | None = None
    load_direction: object = (1.0, 1.0, 1.0)
    force_rms: float = 1000.0
    segment_samples: int = 2048
    oversampling: float = 4.0
    max_segment_s: float = 120.0
    averages: int = 8
    decay_cycles: float = 8.0
    decay_samples: int = 512
    seed: int = 0
    rtol: float = 1e-5
    atol: float = 1e-5


@dataclass(frozen=True, eq=False)
class FreeDecay:
    """One free-decay run (figure-ready): the modal coordinate and its estimate.

    Attributes
    ----------
    mode : int
        1-based mode number.
    history : sixdof.results.TimeHistory
        The body's motion after release from the mode shape.
    eta : ndarray, shape (n,)
        Modal coordinate ``phi_r' M q`` at ``history.t`` [sqrt(kg) m].
    estimate : DecayEstimate
    """

    mode: int = label()
    history: TimeHistory = part(lambda: TimeHistory, prefix="")
    eta: np.ndarray = quantity("kg^1/2 m", ("t",), description="modal coordinate phi_r' M q")
    estimate: DecayEstimate = part(lambda: DecayEstimate, prefix="")


@dataclass(frozen=True)
class ModeCheck:
    """One row of the validation table (one elastic mode).

    Attributes
    ----------
    mode : int
        1-based, ascending frequency.
    dominant_dof : str
    f_model_hz : float
        Undamped natural frequency [Hz].
    zeta_model : float
        Modal damping ratio ``phi' C phi / (2 w)``.
    f_damped_model_hz : float
        ``f_model_hz sqrt(1 - zeta_model^2)`` [Hz].
    f_damped_estimated_hz : float
        From the free decay [Hz].
    zeta_estimated : float
        From the free decay (logarithmic decrement).
    log_decrement_estimated : float
    f_peak_model_hz : float
        Peak of the model FRF of the mode's modal coordinate, on a fine grid [Hz].
    f_peak_estimated_hz : float
        Peak of the H1 estimate of the same FRF [Hz].
    frequency_resolution_hz : float
        Bin width of the estimate [Hz].
    h1_median_error : float
        Median of ``|H1 - G| / |G|`` over the mode's band where the coherence is >= 0.9 (``G`` the
        held model FRF, :func:`held_model_frf`).
    h1_error_in_sigmas : float
        Median over the same bins of ``|H1 - G| / (|G| eps)``, ``eps`` the random error
        (:func:`h1_random_error`): about 1.2 when the estimate is right within its statistics (the
        median of a complex Gaussian error's magnitude).
    h1_error_at_peak : float
        ``|H1 - G| / |G|`` at the peak bin.
    h1_sigma_at_peak : float
        The random error of ``|H1|`` there (:func:`h1_random_error`).
    """

    mode: int = quantity("1", (), description="elastic modes checked (mode numbers of /modal/mode)")
    dominant_dof: str = quantity("", (), decode=str)
    f_model_hz: float = quantity("Hz", (), decode=float)
    zeta_model: float = quantity("1", (), decode=float)
    f_damped_model_hz: float = quantity("Hz", (), decode=float)
    f_damped_estimated_hz: float = quantity("Hz", (), decode=float)
    zeta_estimated: float = quantity("1", (), decode=float)
    log_decrement_estimated: float = quantity("1", (), decode=float)
    f_peak_model_hz: float = quantity("Hz", (), decode=float)
    f_peak_estimated_hz: float = quantity("Hz", (), decode=float)
    frequency_resolution_hz: float = quantity("Hz", (), decode=float)
    h1_median_error: float = quantity("1", (), decode=float)
    h1_error_in_sigmas: float = quantity("1", (), decode=float)
    h1_error_at_peak: float = quantity("1", (), decode=float)
    h1_sigma_at_peak: float = quantity("1", (), decode=float)

    @property
    def f_damped_error(self) -> float:
        """Relative error of the free decay's damped frequency."""
        return self.f_damped_estimated_hz / self.f_damped_model_hz - 1.0

    @property
    def zeta_error(self) -> float:
        """``zeta_estimated - zeta_model`` (absolute: zeta may be 0)."""
        return self.zeta_estimated - self.zeta_model

    @property
    def f_peak_error(self) -> float:
        """Relative error of the estimated FRF peak against the model's peak."""
        return self.f_peak_estimated_hz / self.f_peak_model_hz - 1.0


#: Columns of :meth:`ValidationReport.table`: (attribute, header, format).
COLUMNS = (
    ("mode", "mode", "{:d}"),
    ("dominant_dof", "dof", "{}"),
    ("f_model_hz", "f_model_hz", "{:.5g}"),
    ("f_damped_model_hz", "fd_model_hz", "{:.6g}"),
    ("f_damped_estimated_hz", "fd_decay_hz", "{:.6g}"),
    ("f_damped_error", "fd_err", "{:+.1e}"),
    ("zeta_model", "zeta_model", "{:.5f}"),
    ("zeta_estimated", "zeta_decay", "{:.5f}"),
    ("zeta_error", "zeta_err", "{:+.1e}"),
    ("f_peak_model_hz", "fpk_model_hz", "{:.5g}"),
    ("f_peak_estimated_hz", "fpk_h1_hz", "{:.5g}"),
    ("f_peak_error", "fpk_err", "{:+.1e}"),
    ("frequency_resolution_hz", "df_hz", "{:.2g}"),
    ("h1_median_error", "h1_err_med", "{:.1e}"),
    ("h1_error_in_sigmas", "h1_err/sigma", "{:.2f}"),
    ("h1_error_at_peak", "h1_err_pk", "{:.1e}"),
    ("h1_sigma_at_peak", "h1_sigma_pk", "{:.1e}"),
)


@dataclass(frozen=True, eq=False)
class RandomRun:
    """One random-force run (figure-ready): H1 of one mode's modal coordinate and its model.

    Attributes
    ----------
    mode : int
        1-based mode number.
    band_hz : (float, float)
        The mode's band (half-way to its neighbours, within 0.7 to 1.3 times its frequency) [Hz].
    estimated : EstimatedFRF
        H1 and coherence of ``eta_r`` per unit force [sqrt(kg) m/N].
    model : ndarray, shape (nf, 1), complex
        The held model FRF at ``estimated.f_hz`` (:func:`held_model_frf`).
    """

    mode: int = label()
    band_hz: tuple[float, float] = label(encode=lambda band: np.asarray(band, dtype=float),
                                         decode=lambda band: (float(band[0]), float(band[1])))
    estimated: EstimatedFRF = part(lambda: EstimatedFRF, prefix="")
    model: np.ndarray = quantity(lambda run: run.estimated.unit, ("f_hz",), encode=first_column, decode=as_column,
                                 description="model FRF of the same, with the first-order hold of the sampled force")


@dataclass(frozen=True, eq=False)
class ValidationReport:
    """Result of :func:`validate`: one row per elastic mode, and the runs behind them.

    Attributes
    ----------
    rows : tuple of ModeCheck
        The table (see :meth:`table`, :meth:`format`).
    random_runs : tuple of RandomRun
        One per elastic mode.
    decays : tuple of FreeDecay
        One per elastic mode.
    load_point, load_direction : ndarray, shape (3,)
        The random force's point [m] and unit direction.
    random_duration_s : float
        Simulated time of all random runs together [s].
    wall_time_s : float
        Wall-clock time of all simulations and estimates [s].
    notes : tuple of str
    """

    rows: tuple[ModeCheck, ...] = stacked(lambda: ModeCheck, dim="mode", key="mode")
    random_runs: tuple[RandomRun, ...] = sequence(lambda: RandomRun, group="random", key=lambda run: f"mode_{run.mode}")
    decays: tuple[FreeDecay, ...] = sequence(lambda: FreeDecay, group="decay", key=lambda decay: f"mode_{decay.mode}")
    load_point: np.ndarray = label()
    load_direction: np.ndarray = label()
    random_duration_s: float = label()
    wall_time_s: float = label()
    notes: tuple[str, ...] = label(default=())

    def table(self) -> tuple[tuple[str, ...], tuple[tuple, ...]]:
        """``(headers, rows)`` of raw values, one row per mode, columns as :data:`COLUMNS`."""
        headers = tuple(h for _, h, _ in COLUMNS)
        return headers, tuple(tuple(getattr(r, a) for a, _, _ in COLUMNS) for r in self.rows)


def validate(system: System, settings: ValidationSettings | None = None) -> ValidationReport:
    """Validate the modal results of ``system`` against simulated time histories.

    Runs one free decay per elastic mode and one random-force simulation with
    :func:`sixdof.analysis.direct.simulate`, then compares damped frequencies, damping ratios (logarithmic
    decrement) and FRF peaks with the modal analysis (see the module docstring).

    Parameters
    ----------
    system : System
    settings : ValidationSettings, optional

    Returns
    -------
    ValidationReport

    Raises
    ------
    InputError
        Bad settings, or a system without elastic modes.
    SolverError
        From the time integration.
    """
    import time

    from sixdof.analysis.direct import SimulationSettings, simulate
    from sixdof.excitation import Excitation, Load, ModeRelease, Table

    settings = ValidationSettings() if settings is None else settings
    if not isinstance(settings, ValidationSettings):
        raise InputError("settings", "a ValidationSettings", settings)
    M = np.asarray(system.M)
    modes = system.modes
    zeta = modal_damping_ratios(system.C, modes)
    elastic = [r for r in range(6) if r not in modes.zero_modes]
    if not elastic:
        raise InputError("system", "a system with at least one elastic mode", "none")
    f_n = np.asarray(modes.frequency_hz)
    phi = np.asarray(modes.shapes)
    notes = []
    if np.any(zeta[elastic] >= 1):
        raise InputError("system", "underdamped elastic modes (zeta < 1) for a free-decay "
                         "validation", zeta[elastic].tolist())
    f_d = f_n * np.sqrt(1.0 - np.where(np.isnan(zeta), 0.0, zeta) ** 2)
    start = time.perf_counter()

    # 1. Free decays, one per elastic mode; same sample count, so one compiled solver.
    decays = []
    for r in elastic:
        delta = 2 * np.pi * zeta[r] / math.sqrt(1 - zeta[r] ** 2)
        cycles = settings.decay_cycles if delta == 0 else min(settings.decay_cycles, max(2.0, math.log(1e3) / delta))
        rate = (settings.decay_samples - 1) * f_d[r] / cycles
        run = simulate(system, Excitation(initial=ModeRelease(r + 1, 1e-3)),
                       SimulationSettings(duration=_span(settings.decay_samples, rate), sample_rate_hz=rate))
        eta = run.q @ M @ phi[:, r]
        decays.append(FreeDecay(mode=r + 1, history=run, eta=readonly(eta),
                                estimate=decay_estimate(run.t, eta, unit="kg^1/2 m")))

    # 2. Random force, one run per elastic mode (see the module docstring).
    lp = point(settings.load_point if settings.load_point is not None else system.positions[0], "load_point")
    ld, _ = parse_direction(settings.load_direction, "load_direction", rotations=False)
    Q = unit_load(lp, ld, False)
    nperseg = settings.segment_samples
    n = nperseg + (settings.averages - 1) * (nperseg - nperseg // 2)

    def model_eta(f):
        return receptance(system, f).H @ Q @ M @ phi  # (nf, 6): eta per unit force [sqrt(kg) m/N]

    rows, runs, total_s = [], [], 0.0
    rng = np.random.default_rng(settings.seed)
    for r, decay in zip(elastic, decays):
        neighbours = [f_n[s] for s in elastic if s != r]
        low = max([0.5 * (f_n[r] + f) for f in neighbours if f < f_n[r]] + [0.7 * f_n[r]])
        high = min([0.5 * (f_n[r] + f) for f in neighbours if f > f_n[r]] + [1.3 * f_n[r]])
        width = 2 * (0.0 if np.isnan(zeta[r]) else zeta[r]) * f_n[r]
        segment = max(8.0 / f_n[r], 4.0 / width if width > 0 else math.inf)
        segment = min(segment, settings.max_segment_s, nperseg / (settings.oversampling * high))
        if segment * width < 4.0 * (1 - 1e-9):
            notes.append(f"mode {r + 1}: segment {segment:.4g} s resolves {1 / segment:.3g} Hz, "
                         f"coarser than a quarter of its half-power bandwidth {width:.3g} Hz: "
                         "its H1 peak is bias-limited")
        fs = nperseg / segment
        samples = rng.standard_normal(n)
        samples[0] = 0.0  # start from rest without a jump
        load = Load("validation", lp, force=settings.force_rms * ld,
                    signal=Table(np.arange(n) / fs, samples, outside="zero"))
        run = simulate(system, Excitation(loads=[load]),
                       SimulationSettings(duration=_span(n, fs), sample_rate_hz=fs,
                                          rtol=settings.rtol, atol=settings.atol))
        if run.t.size != n:
            raise SolverError(f"validation run returned {run.t.size} samples, expected {n}")
        total_s += run.t[-1]
        est = estimate_frf(settings.force_rms * samples, run.q @ M @ phi[:, r], fs, nperseg, unit="kg^1/2 m/N")
        # Aliases up to twice the highest natural frequency keep the held model exact in band.
        aliases = int(math.ceil(2.0 * f_n[-1] / fs)) + 1
        G = held_model_frf(model_eta(est.f_hz)[:, r:r + 1], est.f_hz, fs,
                           lambda f, r=r: model_eta(f)[:, r:r + 1], aliases=aliases)
        in_band = (est.f_hz >= low) & (est.f_hz <= high)
        rel = np.abs(est.H1[:, 0] - G[:, 0]) / np.abs(G[:, 0])
        good = in_band & (est.coherence[:, 0] >= 0.9)
        # The model's peak on a grid 1000 times finer than the estimate's.
        fine = np.linspace(low, high, 4001)
        f_pk_model = peak_frequency(fine, np.abs(model_eta(fine)[:, r]), low, high)
        f_pk_est = peak_frequency(est.f_hz, np.abs(est.H1[:, 0]), low, high)
        k = int(np.argmin(np.abs(est.f_hz - f_pk_est))) if np.isfinite(f_pk_est) else 0
        d = decay.estimate
        runs.append(RandomRun(mode=r + 1, band_hz=(float(low), float(high)), estimated=est, model=readonly(G, None)))
        rows.append(ModeCheck(
            mode=r + 1, dominant_dof=modes.dominant_dof[r], f_model_hz=float(f_n[r]), zeta_model=float(zeta[r]),
            f_damped_model_hz=float(f_d[r]), f_damped_estimated_hz=d.f_damped_hz, zeta_estimated=d.zeta,
            log_decrement_estimated=d.log_decrement, f_peak_model_hz=f_pk_model, f_peak_estimated_hz=f_pk_est,
            frequency_resolution_hz=float(est.f_hz[1]),
            h1_median_error=float(np.median(rel[good])) if np.any(good) else math.nan,
            h1_error_in_sigmas=float(np.median(rel[good] / est.random_error[good, 0])) if np.any(good) else math.nan,
            h1_error_at_peak=float(rel[k]),
            h1_sigma_at_peak=float(h1_random_error(est.coherence[k, 0], est.effective_averages)),
        ))
    wall = time.perf_counter() - start
    if modes.zero_modes:
        notes.append(f"rigid-body modes {[m + 1 for m in modes.zero_modes]} "
                     f"({', '.join(modes.free_dofs)} unrestrained) are not in the table")
    return ValidationReport(rows=tuple(rows), random_runs=tuple(runs), decays=tuple(decays), load_point=lp,
                            load_direction=ld, random_duration_s=float(total_s), wall_time_s=float(wall),
                            notes=tuple(notes))


def _span(samples: int, rate: float) -> float:
    """Duration [s] holding exactly ``samples`` samples at ``rate`` [Hz]: a hair over
    ``(samples - 1) / rate``, so that round-off never puts the last sample past the end."""
    return (samples - 1) / rate * (1.0 + 1e-12)

