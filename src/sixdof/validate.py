"""Modal results validated against time histories.

Two experiments on the time-domain solver (:func:`sixdof.direct.simulate`), each compared with what
the modal analysis predicts:

1. **Free decay.** Released from rest in mode r's shape (:class:`~sixdof.excitation.ModeRelease`),
   the body oscillates in that mode alone (exactly for classical damping). Its modal coordinate
   ``eta_r = phi_r' M q`` is a damped sinusoid ``A e^{-sigma t} cos(w_d t + p)``, whose extrema are
   spaced by exactly half the damped period and shrink by ``e^{-sigma pi / w_d}`` from one to the
   next. :func:`decay_estimate` locates the extrema (3-point parabolic interpolation), fits their times
   (damped frequency) and log magnitudes (decay rate) by least squares and returns the damping ratio
   ``zeta = sigma / sqrt(sigma^2 + w_d^2)`` and the logarithmic decrement ``delta = 2 pi sigma /
   w_d``. Model: ``f_r sqrt(1 - zeta_r^2)`` and ``zeta_r`` from
   :func:`sixdof.damping.modal_damping_ratios` (exact for classical damping, the usual diagonal
   approximation otherwise).
2. **Random excitation.** A force at a body point, Gaussian white noise sampled at ``fs`` and
   linearly interpolated (a tabulated signal), drives the body; :func:`estimate_frf` estimates the
   H1 FRF and the coherence (Welch averages, :func:`scipy.signal.csd`) of every modal coordinate per
   unit force. Each mode's resonance peak is located on the estimate and on the model, and compared
   with the natural frequency (the receptance of a classically damped mode peaks at
   ``f_r sqrt(1 - 2 zeta_r^2)``).

The linear interpolation of the force between its samples is a first-order hold: between the
samples' spectrum and the force's, a factor ``sinc^2(f / fs)`` (plus aliases). The model FRF the
estimate is compared with includes it (:func:`held_model_frf`), so the comparison is of like with like.

Runtime: one random run per elastic mode, each ``averages`` Welch segments of ``segment_samples``
samples with 50 % overlap; a mode's segment lasts ``4 / (2 zeta_r f_r)`` (its bins a quarter of its
half-power bandwidth), at least 8 periods, at most ``max_segment_s``, and its sample rate is
``segment_samples / segment`` (at least ``oversampling`` times the top of the mode's band). Every run
has the same sample count, so the solver compiles once. Runtime grows with the duration of the lowest,
lightest damped modes. Measured on 2 shared cores: the seed paper's bridge with 2 % Rayleigh damping
(six runs, 1979 s simulated) about 17 s, two solver compilations included; a 120 kg box with
modes at 10-49 Hz about 12 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.signal

from .damping import modal_damping_ratios
from .errors import InputError, SolverError
from .frf import parse_direction, _load, _point, receptance
from .modal import modal_analysis

__all__ = [
    "DecayEstimate",
    "EstimatedFRF",
    "FreeDecay",
    "ModeCheck",
    "ValidationReport",
    "ValidationSettings",
    "decay_estimate",
    "effective_averages",
    "estimate_frf",
    "h1_random_error",
    "held_model_frf",
    "peak_frequency",
    "validate",
]


# ----------------------------------------------------------------------------------------------------
# FRF estimation from time histories.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class EstimatedFRF:
    """H1 FRF estimate and coherence from sampled input and outputs (from :func:`estimate_frf`).

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Frequencies of the Welch bins [Hz], 0 to ``fs / 2``.
    H1 : ndarray, shape (nf, n_outputs), complex
        ``S_xy / S_xx``: output per unit input (units of output / input).
    coherence : ndarray, shape (nf, n_outputs)
        Ordinary coherence ``|S_xy|^2 / (S_xx S_yy)``, in [0, 1].
    averages : int
        Number of Welch segments.
    effective_averages : float
        Independent averages equivalent to the overlapping segments (:func:`effective_averages`).
    nperseg : int
        Samples per segment.
    sample_rate_hz : float
        [Hz].
    """

    f_hz: np.ndarray
    H1: np.ndarray
    coherence: np.ndarray
    averages: int
    effective_averages: float
    nperseg: int
    sample_rate_hz: float

    @property
    def random_error(self) -> np.ndarray:
        """Normalized random error of ``|H1|`` (:func:`h1_random_error`), shape (nf, n_outputs)."""
        return h1_random_error(self.coherence, self.effective_averages)


def effective_averages(window: np.ndarray, nperseg: int, noverlap: int, segments: int) -> float:
    """Number of independent averages equivalent to ``segments`` overlapping windowed segments.

    Welch (1967): the variance of the averaged spectrum is ``(1 + 2 sum_k (1 - k/K) rho_k^2) / K``
    times that of one segment (Gaussian data), with ``rho_k = sum_n w_n w_{n+kS} / sum_n w_n^2``
    the overlap correlation of segments ``k`` steps ``S = nperseg - noverlap`` apart (Harris 1978:
    16.7 % for Hann at 50 %). Hann with 50 % overlap: ``K / 1.056`` for large K.
    """
    w = np.asarray(window, dtype=float)
    step = nperseg - noverlap
    total = 1.0
    for k in range(1, segments):
        shift = k * step
        if shift >= nperseg:
            break
        rho = float(np.sum(w[: nperseg - shift] * w[shift:]) / np.sum(w**2))
        total += 2.0 * (1.0 - k / segments) * rho**2
    return segments / total


def h1_random_error(coherence, n_averages: float) -> np.ndarray:
    """Normalized random error of an H1 magnitude estimate (Bendat & Piersol, eq. 9.90).

    ``eps = sqrt(1 - gamma^2) / (|gamma| sqrt(2 n_d))``: the standard deviation of ``|H1|`` relative
    to ``|H|`` (and, in radians, of its phase), for ``n_d`` independent averages. Valid for
    ``eps`` small (say < 0.2).
    """
    g2 = np.clip(np.asarray(coherence, dtype=float), 1e-300, 1.0)
    return np.sqrt(1.0 - g2) / (np.sqrt(g2) * np.sqrt(2.0 * n_averages))


def estimate_frf(x, y, sample_rate_hz: float, nperseg: int, window: str = "hann") -> EstimatedFRF:
    """H1 FRF and coherence between an input and one or more outputs, with Welch averaging.

    Parameters
    ----------
    x : array_like, shape (n,)
        Input samples (for example a force [N]).
    y : array_like, shape (n,) or (n, n_outputs)
        Output samples (for example displacements [m]).
    sample_rate_hz : float
        Sampling rate [Hz].
    nperseg : int
        Samples per Welch segment (frequency resolution ``sample_rate_hz / nperseg``); segments
        overlap by half.
    window : str
        Window name for :func:`scipy.signal.get_window`. Default Hann.

    Returns
    -------
    EstimatedFRF
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    if x.ndim != 1 or y.ndim != 2 or y.shape[0] != x.shape[0]:
        raise InputError("y", f"samples of shape ({x.shape[0]},) or ({x.shape[0]}, n_outputs)",
                         f"shape {y.shape}")
    if not (isinstance(nperseg, (int, np.integer)) and 8 <= nperseg <= x.shape[0]):
        raise InputError("nperseg", f"an integer from 8 to the number of samples {x.shape[0]}",
                         nperseg)
    noverlap = nperseg // 2
    kw = dict(fs=sample_rate_hz, window=window, nperseg=nperseg, noverlap=noverlap, detrend=False)
    f, pxx = scipy.signal.welch(x, **kw)
    _, pyy = scipy.signal.welch(y, axis=0, **kw)
    _, pxy = scipy.signal.csd(x[:, None], y, axis=0, **kw)  # conj(X) Y
    with np.errstate(divide="ignore", invalid="ignore"):
        H1 = pxy / pxx[:, None]
        coherence = np.abs(pxy) ** 2 / (pxx[:, None] * pyy)
    coherence = np.nan_to_num(coherence, nan=0.0)
    H1 = np.nan_to_num(H1, nan=0.0)
    segments = 1 + (x.shape[0] - nperseg) // (nperseg - noverlap)
    n_eff = effective_averages(scipy.signal.get_window(window, nperseg), nperseg, noverlap, segments)
    for a in (f, H1, coherence):
        a.flags.writeable = False
    return EstimatedFRF(f_hz=f, H1=H1, coherence=np.clip(coherence, 0.0, 1.0), averages=segments,
                        effective_averages=n_eff, nperseg=nperseg, sample_rate_hz=float(sample_rate_hz))


def held_model_frf(H: np.ndarray, f_hz: np.ndarray, sample_rate_hz: float, model, aliases: int = 2):
    """The FRF an H1 estimate from linearly interpolated input samples converges to.

    ``G(f) = sum_k H(f - k fs) sinc^2((f - k fs) / fs)``, ``|k| <= aliases``: the first-order hold
    of the input between its samples, and the aliases of the sampled output.

    Parameters
    ----------
    H : ndarray, shape (nf, ...)
        The model FRF at ``f_hz`` (the ``k = 0`` term).
    f_hz : ndarray, shape (nf,)
        [Hz].
    sample_rate_hz : float
        [Hz].
    model : callable
        ``model(f_hz) -> ndarray`` like ``H`` for other frequencies (>= 0); ``H(-f) = conj(H(f))``.
    aliases : int
        Alias orders included on each side.
    """
    fs = float(sample_rate_hz)
    shape = (-1,) + (1,) * (H.ndim - 1)
    G = H * np.sinc(f_hz / fs).reshape(shape) ** 2
    for k in range(1, aliases + 1):
        for fk in (f_hz - k * fs, f_hz + k * fs):
            Hk = model(np.abs(fk))
            Hk = np.where((fk < 0).reshape(shape), np.conj(Hk), Hk)
            G = G + Hk * np.sinc(fk / fs).reshape(shape) ** 2
    return G


def peak_frequency(f_hz: np.ndarray, magnitude: np.ndarray, low: float, high: float) -> float:
    """Frequency [Hz] of the largest ``magnitude`` in ``[low, high]``, refined by fitting a parabola
    to the log magnitude of the bin and its two neighbours. NaN when the band holds no bin."""
    f_hz = np.asarray(f_hz, dtype=float)
    magnitude = np.asarray(magnitude, dtype=float)
    inside = np.flatnonzero((f_hz >= low) & (f_hz <= high) & (magnitude > 0))
    if inside.size == 0:
        return float("nan")
    k = int(inside[np.argmax(magnitude[inside])])
    if 0 < k < f_hz.size - 1 and np.all(magnitude[k - 1 : k + 2] > 0):
        a, b, c = np.log(magnitude[k - 1 : k + 2])
        denominator = a - 2 * b + c
        if denominator < 0:
            shift = 0.5 * (a - c) / denominator
            return float(f_hz[k] + np.clip(shift, -1.0, 1.0) * (f_hz[k + 1] - f_hz[k]))
    return float(f_hz[k])


# ----------------------------------------------------------------------------------------------------
# Free decay.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class DecayEstimate:
    """Damped frequency and damping of a free decay (from :func:`decay_estimate`).

    Attributes
    ----------
    f_damped_hz : float
        Damped natural frequency [Hz].
    zeta : float
        Damping ratio.
    log_decrement : float
        ``ln(a_k / a_{k+2})``: decay per full cycle.
    extrema_t : ndarray, shape (m,)
        Times of the interpolated extrema [s].
    extrema_value : ndarray, shape (m,)
        Values there (alternating signs).
    """

    f_damped_hz: float
    zeta: float
    log_decrement: float
    extrema_t: np.ndarray
    extrema_value: np.ndarray


def decay_estimate(t, x) -> DecayEstimate:
    """Damped frequency and damping ratio of a free decay ``x(t)`` from its extrema.

    The extrema of ``A e^{-sigma t} cos(w_d t + p)`` are exactly ``pi / w_d`` apart and shrink by
    ``e^{-sigma pi / w_d}`` each: least-squares lines through their times and their log magnitudes
    give ``w_d`` and ``sigma``. Extrema are located by a parabola through each local extreme sample
    and its neighbours (sample at 30 or more points per cycle for 1e-4 accuracy).

    Parameters
    ----------
    t : array_like, shape (n,)
        Uniformly spaced times [s].
    x : array_like, shape (n,)
        The decaying signal (any unit).

    Returns
    -------
    DecayEstimate

    Raises
    ------
    InputError
        If the record holds fewer than 4 extrema (less than two half cycles).
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    dt = t[1] - t[0]
    interior = np.arange(1, x.size - 1)
    is_max = (x[interior] > x[interior - 1]) & (x[interior] >= x[interior + 1])
    is_min = (x[interior] < x[interior - 1]) & (x[interior] <= x[interior + 1])
    k = interior[is_max | is_min]
    if k.size < 4:
        raise InputError("x", "a free decay with at least 4 extrema (2 cycles)",
                         f"{k.size} extrema in {t[-1] - t[0]:.6g} s")
    a, b, c = x[k - 1], x[k], x[k + 1]
    denominator = a - 2 * b + c
    shift = np.where(denominator != 0, 0.5 * (a - c) / np.where(denominator != 0, denominator, 1), 0)
    times = t[k] + shift * dt
    values = b - 0.25 * (a - c) * shift
    # Keep strictly alternating extrema (round-off can make a flat top look like two).
    keep = np.concatenate([[True], np.sign(values[1:]) != np.sign(values[:-1])])
    times, values = times[keep], values[keep]
    index = np.arange(times.size)
    half_period = np.polyfit(index, times, 1)[0]
    sigma = -np.polyfit(times, np.log(np.abs(values)), 1)[0]
    omega_d = np.pi / half_period
    zeta = sigma / math.hypot(sigma, omega_d)
    return DecayEstimate(
        f_damped_hz=float(omega_d / (2 * np.pi)),
        zeta=float(zeta),
        log_decrement=float(2 * np.pi * sigma / omega_d),
        extrema_t=_ro(times),
        extrema_value=_ro(values),
    )


# ----------------------------------------------------------------------------------------------------
# The validation run.
# ----------------------------------------------------------------------------------------------------


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
        Sample rate of each run at least this many times the upper end of its mode's band.
        Default 4.
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
        Solver tolerances of the random runs (the free decays use the solver's defaults). Default
        1e-5 each, relative to each DOF's scale: far below the estimates' statistical errors
        (~1e-2), and about half the steps of 1e-7.
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
    t : ndarray, shape (n,)
        Times [s].
    eta : ndarray, shape (n,)
        Modal coordinate ``phi_r' M q`` [sqrt(kg) m].
    q : ndarray, shape (n, 6)
        The body's motion [m, rad].
    estimate : DecayEstimate
    """

    mode: int
    t: np.ndarray
    eta: np.ndarray
    q: np.ndarray
    estimate: DecayEstimate


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

    mode: int
    dominant_dof: str
    f_model_hz: float
    zeta_model: float
    f_damped_model_hz: float
    f_damped_estimated_hz: float
    zeta_estimated: float
    log_decrement_estimated: float
    f_peak_model_hz: float
    f_peak_estimated_hz: float
    frequency_resolution_hz: float
    h1_median_error: float
    h1_error_in_sigmas: float
    h1_error_at_peak: float
    h1_sigma_at_peak: float

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

    mode: int
    band_hz: tuple[float, float]
    estimated: EstimatedFRF
    model: np.ndarray


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

    rows: tuple[ModeCheck, ...]
    random_runs: tuple[RandomRun, ...]
    decays: tuple[FreeDecay, ...]
    load_point: np.ndarray
    load_direction: np.ndarray
    random_duration_s: float
    wall_time_s: float
    notes: tuple[str, ...] = field(default=())

    def table(self) -> tuple[tuple[str, ...], tuple[tuple, ...]]:
        """``(headers, rows)`` of raw values, one row per mode, columns as :data:`COLUMNS`."""
        headers = tuple(h for _, h, _ in COLUMNS)
        return headers, tuple(tuple(getattr(r, a) for a, _, _ in COLUMNS) for r in self.rows)

    def format(self) -> str:
        """The table as aligned text, followed by the notes."""
        headers, rows = self.table()
        cells = [list(headers)] + [[fmt.format(v) for (_, _, fmt), v in zip(COLUMNS, row)]
                                   for row in rows]
        widths = [max(len(c[i]) for c in cells) for i in range(len(headers))]
        lines = ["  ".join(c.rjust(w) for c, w in zip(line, widths)) for line in cells]
        lines.append(f"{len(self.random_runs)} random runs ({self.random_duration_s:.4g} s "
                     f"simulated) and {len(self.decays)} free decays in {self.wall_time_s:.3g} s")
        lines.extend(self.notes)
        return "\n".join(lines)


def validate(system, settings: ValidationSettings | None = None) -> ValidationReport:
    """Validate the modal results of ``system`` against simulated time histories.

    Runs one free decay per elastic mode and one random-force simulation with
    :func:`sixdof.direct.simulate`, then compares damped frequencies, damping ratios (logarithmic
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

    from .direct import SimulationSettings, simulate
    from .excitation import Excitation, Load, ModeRelease, Table

    settings = ValidationSettings() if settings is None else settings
    if not isinstance(settings, ValidationSettings):
        raise InputError("settings", "a ValidationSettings", settings)
    M = np.asarray(system.M)
    modes = modal_analysis(M, system.K)
    zeta = modal_damping_ratios(system.C, modes)
    elastic = [r for r in range(6) if r not in modes.zero_modes]
    if not elastic:
        raise InputError("system", "a system with at least one elastic mode", "none")
    f_n = np.asarray(modes.frequency_hz)
    phi = np.asarray(modes.shapes)
    notes = []
    if any(z >= 1 for z in zeta[elastic]):
        raise InputError("system", "underdamped elastic modes (zeta < 1) for a free-decay "
                         "validation", zeta[elastic].tolist())
    f_d = f_n * np.sqrt(1.0 - np.where(np.isnan(zeta), 0.0, zeta) ** 2)
    start = time.perf_counter()

    # 1. Free decays, one per elastic mode; same sample count, so one compiled solver.
    decays = []
    for r in elastic:
        delta = 2 * np.pi * zeta[r] / math.sqrt(1 - zeta[r] ** 2)
        cycles = settings.decay_cycles if delta == 0 else min(settings.decay_cycles,
                                                              max(2.0, math.log(1e3) / delta))
        rate = (settings.decay_samples - 1) * f_d[r] / cycles
        run = simulate(system, Excitation(initial=ModeRelease(r + 1, 1e-3)),
                       SimulationSettings(duration=_span(settings.decay_samples, rate),
                                          sample_rate_hz=rate))
        eta = run.q @ M @ phi[:, r]
        decays.append(FreeDecay(mode=r + 1, t=run.t, eta=_ro(eta), q=run.q,
                                estimate=decay_estimate(run.t, eta)))

    # 2. Random force, one run per elastic mode: white Gaussian samples at a rate fitted to the
    # mode, linearly interpolated. Every run has the same sample count (one compiled solver); its
    # segment resolves the mode's half-power bandwidth.
    lp = _point(settings.load_point if settings.load_point is not None else system.positions[0],
                "load_point")
    ld, _ = parse_direction(settings.load_direction, "load_direction", rotations=False)
    Q = _load(lp, ld, False)
    nperseg = settings.segment_samples
    n = nperseg + (settings.averages - 1) * (nperseg - nperseg // 2)

    def model_eta(f):
        return receptance(system, f).H @ Q @ M @ phi  # (nf, 6): eta per unit force [sqrt(kg) m/N]

    rows, runs, total_s = [], [], 0.0
    rng = np.random.default_rng(settings.seed)
    for i, r in enumerate(elastic):
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
        est = estimate_frf(settings.force_rms * samples, run.q @ M @ phi[:, r], fs, nperseg)
        # Aliases up to twice the highest natural frequency keep the held model exact in band.
        aliases = int(math.ceil(2.0 * f_n[-1] / fs)) + 1
        G = held_model_frf(model_eta(est.f_hz)[:, r:r + 1], est.f_hz, fs,
                           lambda f: model_eta(f)[:, r:r + 1], aliases=aliases)
        in_band = (est.f_hz >= low) & (est.f_hz <= high)
        rel = np.abs(est.H1[:, 0] - G[:, 0]) / np.abs(G[:, 0])
        good = in_band & (est.coherence[:, 0] >= 0.9)
        # The model's peak on a grid 1000 times finer than the estimate's.
        fine = np.linspace(low, high, 4001)
        f_pk_model = peak_frequency(fine, np.abs(model_eta(fine)[:, r]), low, high)
        f_pk_est = peak_frequency(est.f_hz, np.abs(est.H1[:, 0]), low, high)
        k = int(np.argmin(np.abs(est.f_hz - f_pk_est))) if np.isfinite(f_pk_est) else 0
        d = decays[i].estimate
        G.flags.writeable = False
        runs.append(RandomRun(mode=r + 1, band_hz=(float(low), float(high)), estimated=est,
                              model=G))
        rows.append(ModeCheck(
            mode=r + 1, dominant_dof=modes.dominant_dof[r], f_model_hz=float(f_n[r]),
            zeta_model=float(zeta[r]), f_damped_model_hz=float(f_d[r]),
            f_damped_estimated_hz=d.f_damped_hz, zeta_estimated=d.zeta,
            log_decrement_estimated=d.log_decrement, f_peak_model_hz=f_pk_model,
            f_peak_estimated_hz=f_pk_est, frequency_resolution_hz=float(est.f_hz[1]),
            h1_median_error=float(np.median(rel[good])) if np.any(good) else float("nan"),
            h1_error_in_sigmas=float(np.median(rel[good] / est.random_error[good, 0]))
            if np.any(good) else float("nan"),
            h1_error_at_peak=float(rel[k]),
            h1_sigma_at_peak=float(h1_random_error(est.coherence[k, 0], est.effective_averages)),
        ))
    wall = time.perf_counter() - start
    if modes.zero_modes:
        notes.append(f"rigid-body modes {[m + 1 for m in modes.zero_modes]} "
                     f"({', '.join(modes.free_dofs)} unrestrained) are not in the table")
    return ValidationReport(
        rows=tuple(rows), random_runs=tuple(runs), decays=tuple(decays), load_point=lp,
        load_direction=ld, random_duration_s=float(total_s), wall_time_s=float(wall),
        notes=tuple(notes),
    )


def _span(samples: int, rate: float) -> float:
    """Duration [s] holding exactly ``samples`` samples at ``rate`` [Hz]: a hair over
    ``(samples - 1) / rate``, so that round-off never puts the last sample past the end."""
    return (samples - 1) / rate * (1.0 + 1e-12)


def _ro(array) -> np.ndarray:
    out = np.array(array, dtype=float)
    out.flags.writeable = False
    return out

