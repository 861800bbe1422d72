"""The random response checked against a time history (issue 19, point 2).

The check's settings and result (:class:`~sixdof.analysis.random.TimeCheckSettings`,
:class:`~sixdof.analysis.random.RandomTimeCheck`) live with the random response that holds them.

:func:`sixdof.analysis.random.random_response` answers from the FRFs. :func:`random_time_check` answers
again, independently: it synthesizes a seeded Gaussian record with the input PSD, integrates the body's
response with the direct solve (:func:`sixdof.analysis.direct.simulate`, diffrax), and compares the
record's statistics with what the FRFs predict, each within its own statistical error.

**The record.** A Fourier series of period ``T`` (the settling time plus the analysed record) with lines
``f_k = k / T`` over the PSD's band and independent Gaussian coefficients of variance ``S(f_k) / T``: a
Gaussian process with exactly that PSD. Its values and slopes at :data:`KNOTS_PER_PERIOD` knots per
period of the band's top frequency (inverse FFTs) make a cubic Hermite table signal
(:class:`sixdof.excitation.signals.Table`): continuous in value and slope, within 1e-3 of the series at
the top of the band and far closer below. The body starts at rest; the first ``settle_s`` (the slowest
mode's transient down to 1e-3) are integrated and discarded.

**What is compared** (the model a time solve integrates, on both sides: a run passes its ``time_system``, whose
loss factors are their causal Maxwell models, so the FRF side is that model's too; loss factors still in the
system given have no causal time form, are left out of both sides and the result says so):

- the mean square of every excited response over the record: the CG's absolute displacement (less the
  ramp of a ground that starts at rest) and acceleration per DOF, each ``[[points]]`` point's acceleration
  per axis, each mount's force per axis of its own; against ``integral S df`` of its FRF-derived PSD.
  Statistical error of a record of length ``T`` of a Gaussian process (Bendat & Piersol 8.4):
  ``eps^2 = integral S^2 df / (T (integral S df)^2)``.
- the octave-band mean squares (bins inside the PSD's band) of the accelerations' Welch PSDs (Hann, 50 %
  overlap) against the expected value of that estimate, the FRF PSD convolved with the Hann spectral
  window (so leakage and resolution bias are on both sides). Error: the variance of a sum of Welch bins,
  with the Hann window's correlation of neighbouring bins and of overlapping segments, for a PSD flat
  across a bin: segments always resolve :data:`BINS_PER_BANDWIDTH` bins per half-power bandwidth.

Each is a ``z`` value: the ratio of the record's mean square to the FRFs' as a standard normal value (a
mean square scatters as chi-square; :func:`z_score`). Verdict: every ``|z|`` within
:attr:`~sixdof.analysis.random.RandomTimeCheck.z_limit`, the bound that the largest of the N values judged
passes with probability ``1 -`` :data:`FALSE_ALARM` for a correct model (Sidak: independent values; the values
are positively correlated, which makes it conservative). Quantities or bands holding less than
:data:`EXCITED_SHARE` of the largest of their kind are not excited (symmetry zeros) and not judged.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from sixdof.analysis.direct import SOLVE_BYTES_PER_SAMPLE, SimulationSettings, mechanical_form, simulate
from sixdof.analysis.random import RandomTimeCheck, TimeCheckSettings, _modal_damping, transfers
from sixdof.analysis.response import mount_forces, point_motion
from sixdof.dofs import DOFS, dof_units
from sixdof.errors import InputError, Plain, memory_check, readonly
from sixdof.excitation.loads import Excitation, GroundMotion, Load
from sixdof.excitation.signals import Table
from sixdof.validation.estimation import BINS_PER_BANDWIDTH, resolving_segment_s, sharpest_bandwidth
from sixdof.validation.experiment import integrated_model

#: Knots of the synthesized record per period of the PSD's top frequency (cubic Hermite: a sine
#: sampled 8 times per period keeps its amplitude within 1e-3).
KNOTS_PER_PERIOD = 8
#: Output samples per period of the PSD's top frequency: the 2.56 of signal analysers.
OUTPUT_OVERSAMPLING = 2.56
#: Welch segments (50 % overlap) of a default record, and the fewest a record may hold.
AVERAGES, MIN_AVERAGES = 32, 8
#: Longest default record [s] (lightly damped low modes): fewer averages beyond it, down to MIN_AVERAGES.
MAX_DEFAULT_S = 120.0
#: Probability that a correct model fails the check (the two-sided 3-sigma rate), over all values.
FALSE_ALARM = 0.0027
#: A quantity or band holding less than this share of the mean square of the largest of its kind is not
#: excited: zero by symmetry (what remains is the solver's round-off) or leakage beyond the band.
EXCITED_SHARE = 1e-6
#: The FRFs' fine frequency grid: at least this many points per Welch bin and per half-power bandwidth of the
#: sharpest resonance, at most this many points in all (75 MB of receptance).
FINE_PER_BIN, FINE_PER_BANDWIDTH, MAX_FINE_POINTS = 8, 16, 2**17
#: Half-width of the Hann spectral window kept, in bins (its power beyond 16 bins is below 1e-7 of the whole).
WINDOW_HALF_BINS = 16
PASS, FAIL = "PASS", "FAIL"


# ----------------------------------------------------------------------------------------------------
# The record.
# ----------------------------------------------------------------------------------------------------


def synthesize(psd, duration: float, seed: int):
    """A Gaussian record with PSD ``psd`` lasting ``duration`` [s] (see the module), as a cubic Hermite
    :class:`~sixdof.excitation.signals.Table` of the input in SI (m/s^2 or N), zero from ``duration`` on."""
    rate = KNOTS_PER_PERIOD * float(psd.f_hz[-1])
    n = int(math.ceil(duration * rate))
    period = n / rate
    f = np.arange(n // 2 + 1) / period
    rng = np.random.default_rng(seed)
    coefficients = np.sqrt(psd(f) / period) * (rng.standard_normal(f.size) - 1j * rng.standard_normal(f.size))
    # irfft(Y)[j] = Re sum_k (2 / n) Y_k e^{2 pi i k j / n}: Y_k = n c_k / 2 gives sum_k Re(c_k e^{2 pi i f_k t}).
    values = np.fft.irfft(n * coefficients / 2, n)
    slopes = np.fft.irfft(n * 2j * np.pi * f * coefficients / 2, n)
    knots = np.arange(n + 1) / rate  # one knot past the period closes it (periodic values)
    return Table(t=knots, values=np.append(values, values[0]), slopes=np.append(slopes, slopes[0]))


def _least_damped(system, band) -> tuple[float, float]:
    """``(half-power bandwidth [Hz] of the least damped elastic mode in band, slowest decay rate [1/s])``."""
    f_n = system.modes.frequency_hz
    zeta = _modal_damping(system)
    inside = (f_n >= band[0]) & (f_n <= band[1]) & (f_n > 0)
    bandwidth = sharpest_bandwidth(f_n[inside], zeta[inside]) if np.any(inside) else band[0]
    branches = system.branches
    state = mechanical_form(np.linalg.inv(np.asarray(system.M)), system.K, system.C, branches.rows, branches.stiffness,
                            branches.tau)
    decay = float(np.min(-np.linalg.eigvals(state).real))  # every pole's, overdamped ones and branches' included
    return bandwidth, decay


def _segment(bandwidth: float, psd, duration: float | None) -> tuple[float, float]:
    """``(record [s], Welch segment [s])`` for ``duration`` (None: the default), ``bandwidth`` [Hz] the
    half-power bandwidth of the sharpest resonance in band (:func:`_least_damped`).

    The segment always resolves :data:`BINS_PER_BANDWIDTH` bins per half-power bandwidth of the sharpest
    resonance in band: the band errors assume a PSD flat across a bin (coarser bins were measured to scatter
    z 1.2-1.8 times wider than stated). A longer record averages more segments, not shorter ones.
    """
    segment = max(resolving_segment_s(bandwidth), 4.0 / float(psd.f_hz[0]))
    shortest = (MIN_AVERAGES + 1) / 2 * segment
    if duration is None:
        duration = max(min((AVERAGES + 1) / 2 * segment, MAX_DEFAULT_S), shortest)
    elif duration < shortest * (1 - 1e-12):
        raise InputError("random.time_check.duration", f"at least {shortest:.4g} s: {MIN_AVERAGES} Welch segments of "
                         f"{segment:.4g} s, {BINS_PER_BANDWIDTH} bins per half-power bandwidth of the sharpest "
                         f"resonance in band ({bandwidth:.3g} Hz)", duration)
    return float(duration), float(segment)


# ----------------------------------------------------------------------------------------------------
# Statistics.
# ----------------------------------------------------------------------------------------------------


def z_score(ratio, sigma):
    """The standard normal value of a measured-to-expected mean-square ``ratio`` whose relative standard error
    is ``sigma``: a mean square scatters as chi-square with ``nu = 2 / sigma^2`` degrees of freedom over
    ``nu``, skewed (at sigma 0.18 a 4-sigma excess is six times likelier than for a normal value), which the
    Wilson-Hilferty cube root makes normal: ``(ratio^(1/3) - 1 + 2 / (9 nu)) / sqrt(2 / (9 nu))``."""
    spread = 2.0 / (9.0 * (2.0 / np.asarray(sigma, dtype=float) ** 2))
    return (np.cbrt(np.asarray(ratio, dtype=float)) - 1.0 + spread) / np.sqrt(spread)


def sidak_limit(count: int, false_alarm: float = FALSE_ALARM) -> float:
    """The ``|z|`` that the largest of ``count`` independent standard normal values exceeds with probability
    ``false_alarm``."""
    from scipy.stats import norm

    single = -math.expm1(math.log1p(-false_alarm) / max(count, 1))
    return float(norm.isf(single / 2))


@dataclass(frozen=True)
class Welch:
    """The Welch estimator used: Hann window of ``length`` samples, 50 % overlap, at ``rate`` [Hz]."""

    length: int
    rate: float

    @property
    def window(self) -> np.ndarray:
        from scipy.signal import get_window

        return get_window("hann", self.length)

    @property
    def bin_hz(self) -> float:
        return self.rate / self.length

    def estimate(self, x: np.ndarray, detrend: str = "constant") -> tuple[np.ndarray, np.ndarray]:
        from scipy.signal import welch

        return welch(x, fs=self.rate, window=self.window, noverlap=self.length // 2, detrend=detrend, axis=0)

    def segments(self, samples: int) -> int:
        return (samples - self.length) // (self.length - self.length // 2) + 1

    def overlap_factor(self) -> float:
        """``1 + 2 c^2``, c the correlation of the window with itself half a segment on: the variance of a
        Welch average over that of as many independent segments (Welch 1967)."""
        w = self.window
        shift = self.length - self.length // 2
        c = np.sum(w[shift:] * w[:-shift]) / np.sum(w**2)
        return 1.0 + 2.0 * c**2

    def bin_correlation(self, most: int = 3) -> np.ndarray:
        """``|rho_m|^2`` for m = 0..most: the correlation of two periodogram bins m apart (Gaussian input,
        smooth spectrum), rho_m the window's squared-magnitude DFT at m over its sum."""
        w2 = self.window**2
        rho = np.fft.fft(w2)[: most + 1] / np.sum(w2)
        return np.abs(rho) ** 2

    def band_error(self, expected: np.ndarray, samples: int) -> float:
        """Relative standard error of the sum of the Welch bins whose expected values are ``expected`` (one
        band), from a record of ``samples`` samples: ``sum_jk |rho_{j-k}|^2 E_j E_k`` over the bins (neighbours
        up to 3 apart correlate), times :meth:`overlap_factor` over the segments."""
        rho2, e = self.bin_correlation(), expected
        var = np.sum(e**2) * rho2[0] + 2 * sum(rho2[m] * np.sum(e[m:] * e[:-m])
                                                for m in range(1, min(rho2.size, e.size)))
        return float(np.sqrt(self.overlap_factor() / self.segments(samples) * var) / np.sum(expected))

    def expected(self, f_fine: np.ndarray, psd_fine: np.ndarray, bins: np.ndarray) -> np.ndarray:
        """The expected Welch estimate at ``bins`` of a process whose PSD is ``psd_fine`` (on the uniform grid
        ``f_fine``, aligned with the bins, along axis 0): the PSD convolved with the Hann spectral window
        ``|W(f)|^2 / (fs sum w^2)`` (unit area)."""
        from scipy.signal import fftconvolve

        step = f_fine[1] - f_fine[0]
        per_bin = int(round(self.bin_hz / step))
        w = self.window
        # The window's DTFT at multiples of the fine step: its FFT zero-padded to per_bin times its length.
        spectrum = np.abs(np.fft.fft(w, per_bin * self.length)) ** 2 / (self.rate * np.sum(w**2))
        half = WINDOW_HALF_BINS * per_bin
        kernel = np.concatenate([spectrum[-half:], spectrum[: half + 1]])
        smeared = fftconvolve(psd_fine, kernel.reshape(-1, *([1] * (psd_fine.ndim - 1))) * step, mode="same", axes=0)
        index = np.rint((bins - f_fine[0]) / step).astype(int)
        inside = (index >= 0) & (index < f_fine.size)
        out = np.zeros((bins.size,) + psd_fine.shape[1:])
        out[inside] = smeared[index[inside]]
        return out


def record_error(psd: np.ndarray, step: float, duration: float) -> float:
    """Relative standard error of the mean square of a record lasting ``duration`` [s] of a Gaussian process
    whose PSD is ``psd`` (one-sided, on a uniform grid of ``step`` [Hz]): ``sqrt(integral S^2 df / T) /
    integral S df`` (Bendat & Piersol, Random Data, 8.4)."""
    return float(np.sqrt(np.sum(psd**2) * step / duration) / (np.sum(psd) * step))


def fine_grid(low: float, high: float, welch: Welch, bandwidth: float) -> tuple[np.ndarray, list[str]]:
    """The FRFs' uniform frequency grid [Hz] for a PSD band ``[low, high]``: aligned with the Welch bins, at
    least :data:`FINE_PER_BIN` points per bin and :data:`FINE_PER_BANDWIDTH` per half-power ``bandwidth``
    [Hz] of the sharpest resonance (at most :data:`MAX_FINE_POINTS`, said in the notes), and reaching
    :data:`WINDOW_HALF_BINS` bins beyond the band (where the PSD is zero), so that the estimate's leakage past
    the band's edges is on the expected side too."""
    pad = WINDOW_HALF_BINS * welch.bin_hz
    per_bin = max(FINE_PER_BIN, math.ceil(FINE_PER_BANDWIDTH * welch.bin_hz / bandwidth))
    most = max(FINE_PER_BIN, int(MAX_FINE_POINTS * welch.bin_hz // (high - low + 2 * pad)))
    notes = []
    if per_bin > most:
        notes.append(f"the FRFs are integrated at {welch.bin_hz / most:.3g} Hz steps, coarser than a sixteenth of "
                     f"the sharpest half-power bandwidth ({bandwidth:.3g} Hz): at most {MAX_FINE_POINTS} points")
        per_bin = most
    step = welch.bin_hz / per_bin
    return np.arange(max(math.ceil((low - pad) / step), 1), math.floor((high + pad) / step) + 1) * step, notes


def band_mean_squares(f_fine: np.ndarray, fine: dict, edges: dict, low: float, high: float) -> dict[str, float]:
    """``integral S df`` of each PSD of ``fine`` (at ``f_fine`` [Hz]; ``edges``: at ``low`` and ``high``): the
    trapezoidal rule over the band ``[low, high]``, its ends included, outside which the PSD is zero. A sum
    over the whole grid (as the trapezoidal rule over it) counts the PSD's jump at each edge as a whole step:
    on the electronics box it put 0.12 % (z acceleration) to 0.31 % (z displacement) on the mean squares."""
    from scipy.integrate import trapezoid

    inside = (f_fine > low) & (f_fine < high)
    f = np.concatenate([[low], f_fine[inside], [high]])
    return {name: float(trapezoid(np.concatenate([edges[name][:1], psd[inside], edges[name][1:]]), f))
            for name, psd in fine.items()}


def octave_bands(f_hz: np.ndarray, low: float, high: float) -> list[tuple[float, np.ndarray]]:
    """``(centre [Hz], bins)`` of each octave band (centres 1000 * 2^k Hz) holding Welch bins ``f_hz`` inside
    the PSD's band ``[low, high]``: a bin beyond it holds only leakage, whose scatter the band errors (for a
    PSD flat across a bin) do not describe (a one-bin band below 10 Hz was measured to scatter twice as wide)."""
    k = np.arange(math.floor(math.log2(low / 1000.0) - 0.5), math.ceil(math.log2(high / 1000.0) + 0.5) + 1)
    bands = []
    for centre in 1000.0 * 2.0**k:
        bins = (f_hz >= max(centre / math.sqrt(2), low)) & (f_hz < min(centre * math.sqrt(2), high))
        if np.any(bins):
            bands.append((float(centre), bins))
    return bands


# ----------------------------------------------------------------------------------------------------
# The check.
# ----------------------------------------------------------------------------------------------------


def _series(system, random, points, response, keep) -> dict[str, tuple[np.ndarray, str]]:
    """Every response of the record's samples ``keep``, as ``name -> (samples, unit)`` (see
    :attr:`~sixdof.analysis.random.RandomTimeCheck.judged`)."""
    t = response.t[keep]
    q = response.q[keep]
    if random.input != "force":  # the ground starts at rest: its velocity carries a constant, its position a ramp
        ramp = np.polynomial.polynomial.polyfit(t - t[0], q, 1)
        q = q - np.polynomial.polynomial.polyval(t - t[0], ramp).T
    series = {}
    for i, dof in enumerate(DOFS):
        series[f"q:{dof}"] = (q[:, i], dof_units(0)[i])
    for i, dof in enumerate(DOFS):
        series[f"qdd:{dof}"] = (response.qdd[keep, i], dof_units(2)[i])
    for name, position in points.items():
        accel = point_motion(response, position).acceleration
        for j, axis in enumerate("xyz"):
            series[f"point:{name}:{axis}"] = (accel[keep, j], "m/s^2")
    forces = mount_forces(system, response)
    for m, name in enumerate(forces.names):
        for j, axis in enumerate("uvw"):
            series[f"mount_force:{name}:{axis}"] = (forces.local[m, keep, j], "N")
    return series


def _transfer_psds(system, random, points, f) -> dict[str, np.ndarray]:
    """The FRF-derived PSD of every series of :func:`_series`, at ``f`` [Hz]."""
    frf = transfers(system, random, f, points)
    s = random.psd(f)
    psd = {}
    for i, dof in enumerate(DOFS):
        psd[f"q:{dof}"] = np.abs(frf.q[:, i]) ** 2 * s
        psd[f"qdd:{dof}"] = np.abs(frf.qdd[:, i]) ** 2 * s
    for p, name in enumerate(points):
        for j, axis in enumerate("xyz"):
            psd[f"point:{name}:{axis}"] = np.abs(frf.point_acceleration[p, :, j]) ** 2 * s
    for m, mount in enumerate(system.mounts):
        for j, axis in enumerate("uvw"):
            psd[f"mount_force:{mount.name}:{axis}"] = np.abs(frf.mount_force[m, :, j]) ** 2 * s
    return psd


def _family(name: str, unit: str) -> str:
    """What a quantity's size is compared with to decide whether it is excited: its kind and unit."""
    return f"{name.split(':')[0]}[{unit}]"


def random_time_check(system, random, points=None, settings: TimeCheckSettings | None = None, *,
                      simulation=None, progress=None) -> RandomTimeCheck:
    """Check :func:`~sixdof.analysis.random.random_response` against a time history (see the module).

    Parameters
    ----------
    system : sixdof.model.system.System
        The model integrated and whose FRFs are compared: a scenario's ``time_system`` (loss factors as their
        causal Maxwell models, so the check carries their damping on both sides).
    random : sixdof.analysis.random.RandomInput
    points : mapping of str to array_like, optional
        Named body points [m] whose accelerations are compared.
    settings : TimeCheckSettings, optional
        Record length and seed. Default :class:`TimeCheckSettings()`.
    simulation : sixdof.analysis.direct.SimulationSettings, optional
        Whose solver and tolerances the direct solve uses (the scenario's ``[simulation]``); its
        duration and sample rate are the check's own.
    progress : optional
        As for :func:`sixdof.analysis.direct.simulate`.

    Returns
    -------
    RandomTimeCheck

    Raises
    ------
    InputError
        For a system with unrestrained DOFs (its random response is not stationary).
    """
    settings = settings or TimeCheckSettings()
    points = dict(points or {})
    if system.modes.zero_modes:
        raise InputError("random.time_check", "a system held in every DOF (a free body's random response "
                         "drifts, it is not stationary)", Plain(f"{', '.join(system.modes.free_dofs)} unrestrained"))
    model, hysteretic = integrated_model(system)
    psd = random.psd
    low, high = float(psd.f_hz[0]), float(psd.f_hz[-1])
    bandwidth, decay = _least_damped(model, (low, high))
    duration, segment = _segment(bandwidth, psd, settings.duration)
    settle = math.log(1000.0) / decay
    rate = OUTPUT_OVERSAMPLING * high
    welch = Welch(int(round(segment * rate)), rate)

    # The record's knots (values, slopes and the FFTs' complex spectra) and the solve's samples.
    knots = KNOTS_PER_PERIOD * high * (settle + duration)
    memory_check("random.time_check.duration", 64.0 * knots + SOLVE_BYTES_PER_SAMPLE * rate * (settle + duration),
                 "a record", f"{settle + duration:.4g} s at {KNOTS_PER_PERIOD * high:.4g} Hz")
    started = time.perf_counter()
    response = _simulate(model, random, settle + duration, rate, settings.seed, simulation, progress)
    keep = response.t >= settle
    series = _series(model, random, points, response, keep)

    f_fine, notes = fine_grid(low, high, welch, bandwidth)
    step = welch.bin_hz / round(welch.bin_hz / (f_fine[1] - f_fine[0]))
    fine = _transfer_psds(model, random, points, f_fine)
    samples = int(np.count_nonzero(keep))
    record_s = samples / rate

    # Record mean squares.
    largest: dict[str, float] = {}
    mean_square = band_mean_squares(f_fine, fine, _transfer_psds(model, random, points, np.array([low, high])),
                                    low, high)
    for name, (_, unit) in series.items():
        largest[_family(name, unit)] = max(largest.get(_family(name, unit), 0.0), mean_square[name])
    checks = _record_checks(series, mean_square, largest, fine, step, record_s)

    # Octave bands of the accelerations' Welch PSDs.
    accelerations = [n for n in series if n.startswith(("qdd:", "point:"))]
    f_bins, welch_psd = welch.estimate(np.stack([series[n][0] for n in accelerations], axis=1))
    expected = welch.expected(f_fine, np.stack([fine[n] for n in accelerations], axis=1), f_bins)
    checks += _band_checks(accelerations, series, largest, welch, f_bins, welch_psd, expected, (low, high), samples)

    judged, units, freq_ms, time_ms, sigma = (list(v) for v in zip(*checks)) if checks else ([], [], [], [], [])
    freq_ms, time_ms, sigma = (np.array(v, dtype=float) for v in (freq_ms, time_ms, sigma))
    z = z_score(time_ms / freq_ms, sigma)
    limit = sidak_limit(len(judged))
    column = {name: j for j, name in enumerate(accelerations)}
    qdd_cols = [column[f"qdd:{d}"] for d in DOFS]

    def point_array(source):
        return np.stack([source[:, [column[f"point:{p}:{a}"] for a in "xyz"]] for p in points]) if points \
            else np.zeros((0, f_bins.size, 3))

    if hysteretic:
        notes.append(f"the loss factors of {', '.join(hysteretic)} are left out of both sides: they have no causal "
                     "time form (a Maxwell model, issue 17, would keep them)")
    return RandomTimeCheck(
        judged=tuple(judged), judged_units=tuple(units), frequency_rms=readonly(np.sqrt(freq_ms)),
        time_rms=readonly(np.sqrt(time_ms)), sigma=readonly(sigma), z=readonly(z), f_hz=readonly(f_bins),
        qdd_welch=readonly(welch_psd[:, qdd_cols]), qdd_expected=readonly(expected[:, qdd_cols]),
        point_welch=readonly(point_array(welch_psd)), point_expected=readonly(point_array(expected)),
        points=tuple(points), band_hz=(low, high), z_limit=limit,
        verdict=PASS if bool(np.all(np.abs(z) <= limit)) else FAIL, seed=settings.seed, duration_s=record_s,
        settle_s=float(settle), segment_s=welch.length / rate, averages=welch.segments(samples),
        degrees_of_freedom=2.0 * welch.segments(samples) / welch.overlap_factor(), sample_rate_hz=rate,
        knot_rate_hz=KNOTS_PER_PERIOD * high, solver_steps=int(response.stats.num_steps),
        wall_time_s=time.perf_counter() - started, notes=tuple(notes))


def _simulate(model, random, duration: float, rate: float, seed: int, simulation, progress):
    """The direct solve of ``model`` [a TimeHistory] under a record of ``random``'s PSD (``seed``) lasting
    ``duration`` [s], sampled at ``rate`` [Hz] with the solver and tolerances of ``simulation``."""
    record = synthesize(random.psd, duration, seed)
    if random.input == "force":
        excitation = Excitation(loads=(Load(name="random", point=random.point, force=random.direction, signal=record),))
    else:
        excitation = Excitation(ground=GroundMotion(quantity="acceleration", direction=random.direction,
                                                    signal=record))
    given = simulation or SimulationSettings(duration=1.0, sample_rate_hz=1.0)  # its solver and tolerances
    run = SimulationSettings(duration=duration, sample_rate_hz=rate, solver=given.solver, rtol=given.rtol,
                             atol=given.atol, max_steps=given.max_steps)
    return simulate(model, excitation, run, progress=progress)


#: One quantity judged: ``(name, unit, expected mean square, measured mean square, relative standard error)``.
_Judged = tuple[str, str, float, float, float]


def _record_checks(series, mean_square: dict[str, float], largest: dict[str, float], fine: dict, step: float,
                   record_s: float) -> list[_Judged]:
    """Each excited quantity's mean square over the record (``record_s`` [s]) against the PSD's ``mean_square``
    (of the PSDs ``fine``, on a grid of ``step`` [Hz])."""
    checks = []
    for name, (x, unit) in series.items():
        ms = mean_square[name]
        if ms <= EXCITED_SHARE * largest[_family(name, unit)] or ms == 0.0:
            continue
        eps = record_error(fine[name], step, record_s)
        checks.append((f"rms:{name}", unit, ms, float(np.mean(x**2)), eps))
    return checks


def _band_checks(accelerations: list[str], series, largest: dict[str, float], welch: Welch, f_bins: np.ndarray,
                 welch_psd: np.ndarray, expected: np.ndarray, band: tuple[float, float],
                 samples: int) -> list[_Judged]:
    """Each excited acceleration's mean square in each octave band of ``band`` [Hz]: its Welch PSD ``welch_psd``
    (bins ``f_bins`` [Hz], from ``samples`` samples) against the ``expected`` one."""
    checks = []
    for centre, inside in octave_bands(f_bins, *band):
        for j, name in enumerate(accelerations):
            unit = series[name][1]
            e = expected[inside, j]
            band_ms = float(np.sum(e) * welch.bin_hz)
            if band_ms <= EXCITED_SHARE * largest[_family(name, unit)] or band_ms == 0.0:
                continue
            checks.append((f"band:{name}@{centre:.4g}Hz", unit, band_ms,
                           float(np.sum(welch_psd[inside, j]) * welch.bin_hz), welch.band_error(e, samples)))
    return checks
