"""Estimation from time histories: H1 FRFs and coherence (Welch), their random error, peak
frequencies, and damped frequency and damping of a free decay.

The linear interpolation of a sampled force between its samples is a first-order hold: between the
samples' spectrum and the force's, a factor ``sinc^2(f / fs)`` (plus aliases). :func:`held_model_frf`
gives the model FRF an H1 estimate converges to, so that estimate and model compare like with like.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sixdof.errors import InputError, Plain, readonly
from sixdof.results import Result, label, quantity, result_type


def first_column(array: np.ndarray) -> np.ndarray:
    """The single output of an (nf, 1) estimate, as stored."""
    return np.asarray(array).reshape(np.shape(array)[0], -1)[:, 0]


def as_column(array: np.ndarray) -> np.ndarray:
    """A stored single output back to the (nf, 1) shape of an estimate."""
    return np.asarray(array)[:, None]


__all__ = ["BINS_PER_BANDWIDTH", "DecayEstimate", "EstimatedFRF", "MultiReferenceFRF", "check_resolution",
           "decay_estimate", "effective_averages", "estimate_frf", "estimate_frfs", "h1_random_error", "held_model_frf",
           "peak_frequency", "resolving_segment_s", "sharpest_bandwidth"]


# ----------------------------------------------------------------------------------------------------
# FRF estimation from time histories.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class EstimatedFRF(Result):
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

    f_hz: np.ndarray = quantity("Hz", ("f_hz",), description="Welch frequency bins")
    H1: np.ndarray = quantity(lambda e: e.unit, ("f_hz",), encode=first_column, decode=as_column,
                              description="H1 estimate: output per unit input")
    coherence: np.ndarray = quantity("1", ("f_hz",), encode=first_column, decode=as_column)
    averages: int = label()
    effective_averages: float = label()
    nperseg: int = label()
    sample_rate_hz: float = label()
    unit: str = label(name="H1_unit", default="1")

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


def estimate_frf(x, y, sample_rate_hz: float, nperseg: int, window: str = "hann", unit: str = "1") -> EstimatedFRF:
    """H1 FRF and coherence between an input and one or more outputs, with Welch averaging: the
    single-reference case of :func:`estimate_frfs`.

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
    unit : str
        Unit of the FRF (output per input), kept with the result.

    Returns
    -------
    EstimatedFRF
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    if x.ndim != 1 or y.ndim != 2 or y.shape[0] != x.shape[0]:
        raise InputError("y", f"samples of shape ({x.shape[0]},) or ({x.shape[0]}, n_outputs)",
                         f"shape {y.shape}")
    est = estimate_frfs(x[:, None], y, sample_rate_hz, nperseg, window=window, unit=unit)
    return EstimatedFRF(f_hz=est.f_hz, H1=readonly(est.H[:, :, 0], None), coherence=est.coherence,
                        averages=est.averages, effective_averages=est.effective_averages, nperseg=nperseg,
                        sample_rate_hz=est.sample_rate_hz, unit=unit)


@result_type
@dataclass(frozen=True, eq=False)
class MultiReferenceFRF(Result):
    """H1 FRFs from several uncorrelated references at once, and multiple coherence (from
    :func:`estimate_frfs`).

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Frequencies of the Welch bins [Hz], 0 to ``fs / 2``.
    H : ndarray, shape (nf, n_outputs, n_references), complex
        ``H = S_yx S_xx^-1`` per bin: output per unit reference (units of output / input). Zero at a bin
        where the references' spectral matrix is singular (see :data:`SINGULAR_REFERENCES`).
    coherence : ndarray, shape (nf, n_outputs)
        Multiple coherence of each output on all references, ``S_yx S_xx^-1 S_xy / S_yy``, in [0, 1]
        (the ordinary coherence for one reference); zero where ``S_xx`` is singular.
    averages : int
        Number of Welch segments.
    effective_averages : float
        Independent averages equivalent to the overlapping segments (:func:`effective_averages`).
    nperseg : int
        Samples per segment.
    sample_rate_hz : float
        [Hz].
    window : str
        The segments' window (a :func:`scipy.signal.get_window` name).
    overlap : float
        Overlap of consecutive segments, a fraction of ``nperseg``.
    unit : str
        Unit of ``H``.
    """

    f_hz: np.ndarray = quantity("Hz", ("f_hz",), description="Welch frequency bins")
    H: np.ndarray = quantity(lambda e: e.unit, ("f_hz", "output", "reference"),
                             description="H1 estimate: output per unit reference")
    coherence: np.ndarray = quantity("1", ("f_hz", "output"), description="multiple coherence on all references")
    averages: int = label()
    effective_averages: float = label()
    nperseg: int = label()
    sample_rate_hz: float = label()
    window: str = label(default="hann")
    overlap: float = label(default=0.5)
    unit: str = label(name="H_unit", default="1")

    @property
    def df_hz(self) -> float:
        """Bin spacing [Hz]: ``sample_rate_hz / nperseg``."""
        return self.sample_rate_hz / self.nperseg


#: A bin's references count as fully correlated where the smallest eigenvalue of their coherence matrix
#: (``S_xx`` scaled to a unit diagonal; eigenvalues from 0 to ``n_ref``) is below this: round-off of a
#: rank-deficient matrix sits near 1e-16, two references of coherence 0.999999 between them at 5e-7.
SINGULAR_REFERENCES = 1e-10


def _coherence_eigenvalue_min(sxx: np.ndarray) -> np.ndarray:
    """Smallest eigenvalue (nf,) of each bin's references' coherence matrix ``D^-1/2 S_xx D^-1/2``; zero where a
    reference carries no power."""
    d = np.real(np.diagonal(sxx, axis1=1, axis2=2))
    top = np.max(d, axis=1, keepdims=True)
    dead = np.any(d <= 1e-300 + 1e-14 * top, axis=1)
    scale = 1.0 / np.sqrt(np.where(d > 0, d, 1.0))
    normal = sxx * scale[:, :, None] * scale[:, None, :]
    low = np.linalg.eigvalsh(normal)[:, 0]
    return np.where(dead, 0.0, low)


def _correlated_references(sxx: np.ndarray) -> str:
    """Which references make ``S_xx`` singular at every bin (text for the error): a reference without power, or
    the first, in column order, whose addition makes the references before it singular at every bin."""
    for j in range(sxx.shape[1]):
        if np.all(_coherence_eigenvalue_min(sxx[:, j : j + 1, j : j + 1]) < SINGULAR_REFERENCES):
            return f"input column {j} carries no power"
    for j in range(1, sxx.shape[1]):
        if np.all(_coherence_eigenvalue_min(sxx[:, : j + 1, : j + 1]) < SINGULAR_REFERENCES):
            before = ", ".join(str(i) for i in range(j))
            return (f"input column {j} fully correlated with column{'s' if j > 1 else ''} {before} at every "
                    "frequency (H1 needs references that are not linear filters of one another)")
    return "references singular at every frequency, no smaller set of them is"


def estimate_frfs(inputs, outputs, sample_rate_hz: float, nperseg: int, window: str = "hann", overlap: float = 0.5,
                  unit: str = "1") -> MultiReferenceFRF:
    """H1 FRFs of several outputs on several references at once, with multiple coherence (Welch averaging).

    Per bin, with ``S_xx[k, j] = E[conj(X_k) X_j]`` and ``S_xy[k, i] = E[conj(X_k) Y_i]`` (scipy.signal.csd):
    ``H = (S_xx^-1 S_xy)^T`` and ``gamma^2_i = sum_k conj(S_xy[k, i]) H[i, k] / S_yy[i]`` (Bendat & Piersol,
    ch. 7). Uncorrelated output noise biases neither; with one reference they are ``S_xy / S_xx`` and the
    ordinary coherence.

    Parameters
    ----------
    inputs : array_like, shape (n, n_references)
        Reference samples (for example forces [N]); not linear filters of one another.
    outputs : array_like, shape (n, n_outputs)
        Response samples (for example accelerations [m/s^2]).
    sample_rate_hz : float
        Sampling rate [Hz].
    nperseg : int
        Samples per Welch segment (resolution ``sample_rate_hz / nperseg``), 8 to ``n``.
    window : str
        Window name for :func:`scipy.signal.get_window`. Default Hann.
    overlap : float
        Overlap of consecutive segments as a fraction of ``nperseg``, in [0, 1). Default one half.
    unit : str
        Unit of the FRFs (output per input), kept with the result.

    Returns
    -------
    MultiReferenceFRF

    Raises
    ------
    InputError
        Arrays of other shapes, NaNs or infinities, fewer samples than one segment, an overlap outside
        [0, 1), or references fully correlated at every bin (naming them).
    """
    x, y = np.asarray(inputs, dtype=float), np.asarray(outputs, dtype=float)
    if x.ndim != 2 or x.shape[1] < 1:
        raise InputError("inputs", "samples of shape (n, n_references)", Plain(f"shape {x.shape}"))
    n = x.shape[0]
    if y.ndim != 2 or y.shape[0] != n:
        raise InputError("outputs", f"samples of shape ({n}, n_outputs)", Plain(f"shape {y.shape}"))
    for name, array in (("inputs", x), ("outputs", y)):
        bad = np.argwhere(~np.isfinite(array))
        if bad.size:
            raise InputError(name, "finite samples", Plain(f"{len(bad)} NaN or infinite, the first at row "
                                                                 f"{bad[0][0]}, column {bad[0][1]}"))
    if not (isinstance(nperseg, (int, np.integer)) and 8 <= nperseg <= n):
        raise InputError("nperseg", f"an integer from 8 to the number of samples {n}", nperseg)
    if not 0.0 <= overlap < 1.0:
        raise InputError("overlap", "a fraction of a segment in [0, 1)", overlap)
    import scipy.signal  # 1.1 s to import: a run that estimates nothing does not pay it

    noverlap = math.floor(overlap * nperseg)
    kw = dict(fs=sample_rate_hz, window=window, nperseg=nperseg, noverlap=noverlap, detrend=False)
    n_ref = x.shape[1]
    f, syy = scipy.signal.welch(y, axis=0, **kw)
    sxx = np.stack([scipy.signal.csd(x, x[:, j : j + 1], axis=0, **kw)[1] for j in range(n_ref)], axis=2)
    sxy = np.stack([scipy.signal.csd(x[:, k : k + 1], y, axis=0, **kw)[1] for k in range(n_ref)], axis=1)
    singular = _coherence_eigenvalue_min(sxx) < SINGULAR_REFERENCES
    if np.all(singular):
        raise InputError("inputs", "references that are not fully correlated",
                         Plain(_correlated_references(sxx)))
    H = np.zeros((f.size, y.shape[1], n_ref), dtype=complex)
    H[~singular] = np.swapaxes(np.linalg.solve(sxx[~singular], sxy[~singular]), 1, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        coherence = np.real(np.einsum("fki,fik->fi", np.conj(sxy), H)) / syy
    coherence = np.where(singular[:, None], 0.0, coherence)
    segments = 1 + (n - nperseg) // (nperseg - noverlap)
    n_eff = effective_averages(scipy.signal.get_window(window, nperseg), nperseg, noverlap, segments)
    return MultiReferenceFRF(f_hz=readonly(f), H=readonly(H, complex),
                             coherence=readonly(np.clip(np.nan_to_num(coherence, nan=0.0), 0.0, 1.0)),
                             averages=segments, effective_averages=n_eff, nperseg=nperseg,
                             sample_rate_hz=float(sample_rate_hz), window=str(window), overlap=float(overlap),
                             unit=unit)


#: Welch bins per half-power bandwidth (``2 zeta f_n``) of the sharpest mode at which an estimate resolves
#: it: the random time check's band errors hold from here (at one bin per bandwidth z was measured to scatter
#: 1.2-1.5 times wider than stated); a coarser estimate flattens the peak and overstates the damping.
BINS_PER_BANDWIDTH = 4


def sharpest_bandwidth(frequency_hz, damping_ratio) -> float:
    """Half-power bandwidth [Hz] ``min(2 zeta f_n)`` of the sharpest of the given modes (NaN when none has a
    positive frequency)."""
    f_n, zeta = np.asarray(frequency_hz, dtype=float).ravel(), np.asarray(damping_ratio, dtype=float).ravel()
    usable = f_n > 0
    return float(np.min(2 * zeta[usable] * f_n[usable])) if np.any(usable) else float("nan")


def resolving_segment_s(bandwidth_hz: float) -> float:
    """Shortest Welch segment [s] that resolves :data:`BINS_PER_BANDWIDTH` bins per half-power bandwidth
    ``bandwidth_hz`` [Hz]."""
    return BINS_PER_BANDWIDTH / bandwidth_hz


def check_resolution(resolution, frequency_hz, damping_ratio) -> str | None:
    """Whether an estimate's bins resolve the sharpest mode: a note saying why not, or None.

    Parameters
    ----------
    resolution : float or array_like
        The bin spacing ``df`` [Hz], or the estimate's uniformly spaced bins ``f_hz`` [Hz].
    frequency_hz, damping_ratio : array_like, shape (m,)
        The modes in band: natural frequencies [Hz] and damping ratios.

    Returns
    -------
    str or None
        None when ``df`` is at most the sharpest half-power bandwidth ``2 zeta f_n`` over
        :data:`BINS_PER_BANDWIDTH`; otherwise a note naming the mode and the segment that would resolve it.
    """
    spacing = np.asarray(resolution, dtype=float)
    df = float(spacing) if spacing.ndim == 0 else float(spacing[1] - spacing[0])
    f_n, zeta = np.asarray(frequency_hz, dtype=float).ravel(), np.asarray(damping_ratio, dtype=float).ravel()
    bandwidth = sharpest_bandwidth(f_n, zeta)
    if not np.isfinite(bandwidth) or df <= bandwidth / BINS_PER_BANDWIDTH * (1 + 1e-12):
        return None
    k = int(np.argmin(np.where(f_n > 0, 2 * zeta * f_n, np.inf)))
    return (f"the estimate's bins ({df:.4g} Hz) do not resolve the sharpest mode ({f_n[k]:.4g} Hz, damping ratio "
            f"{zeta[k]:.3g}: half-power bandwidth {bandwidth:.4g} Hz) with {BINS_PER_BANDWIDTH} bins per bandwidth; "
            f"its peak and damping are biased (segments of at least {resolving_segment_s(bandwidth):.4g} s resolve it)")


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
    f_hz, magnitude = np.asarray(f_hz, dtype=float), np.asarray(magnitude, dtype=float)
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

    f_damped_hz: float = label()
    zeta: float = label()
    log_decrement: float = label()
    extrema_t: np.ndarray = quantity("s", ("extremum",))
    extrema_value: np.ndarray = quantity(lambda d: d.unit, ("extremum",))
    unit: str = label(name="extrema_unit", default="1")


def decay_estimate(t, x, unit: str = "1") -> DecayEstimate:
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
    unit : str
        Its unit, kept with the result.

    Returns
    -------
    DecayEstimate

    Raises
    ------
    InputError
        If the record holds fewer than 4 extrema (less than two half cycles).
    """
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
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
    return DecayEstimate(f_damped_hz=float(omega_d / (2 * np.pi)), zeta=float(zeta),
                         log_decrement=float(2 * np.pi * sigma / omega_d), extrema_t=readonly(times),
                         extrema_value=readonly(values), unit=unit)
