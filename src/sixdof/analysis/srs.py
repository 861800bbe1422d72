"""Shock response spectra (issue 19, point 3): the maximax absolute-acceleration SRS of a base shock and of
the body points' accelerations, what the isolators let through.

For each natural frequency f of a grid, a single-DOF oscillator of quality factor Q (damping 1/(2Q)) is
driven at its base by the sampled acceleration; its absolute acceleration is computed with Smallwood's
ramp-invariant digital filter (D. O. Smallwood, "An improved recursive formula for calculating shock
response spectra", Shock and Vibration Bulletin 51, 1981), exact for an input varying linearly between
samples; the SRS is the largest magnitude over the record (maximax: during and after the shock).

The largest magnitude is sought at :data:`PEAK_STEPS_PER_PERIOD` steps per period of each oscillator at
least: where the record is sampled coarser (above a tenth of its rate, the usual limit), the filter runs
on the input linearly interpolated between the samples, as it already takes it, at a step that divides
the record's. At the record's own steps, a peak falling between two samples would read up to
``1 - cos(pi f dt)`` low: 19 % at a fifth of the sample rate.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from sixdof.errors import InputError, Plain, frequency_band, integer_check, number, number_check, readonly
from sixdof.frozen import Frozen, checked
from sixdof.results import Result, label, quantity, result_type

#: Steps per period of an oscillator at which :func:`srs` seeks its peak: one between two steps reads at most
#: ``1 - cos(pi / 40)`` = 0.31 % low.
PEAK_STEPS_PER_PERIOD = 40
#: Steps per period of an oscillator at which :func:`pseudo_acceleration_spectrum` seeks its peak: a peak between two
#: steps reads at most ``1 - cos(pi / 100)`` = 0.05 % low (a design spectrum is matched to a few per cent, and
#: the records' mean is checked against 90 % of it: the check should not lose 0.3 % to sampling).
SPECTRUM_STEPS_PER_PERIOD = 100

@dataclass(frozen=True)
class SRSSettings(Frozen):
    """The ``[shock_response_spectrum]`` table: natural frequencies ``f_hz = [lo, hi]`` [Hz], ``points``
    of them on a log grid (default 100), quality factor ``q`` (default 10)."""

    f_hz: tuple[float, float] = checked(frequency_band)
    points: int = checked(integer_check("an integer >= 2", 2), default=100)
    q: float = checked(number_check("a positive quality factor Q (10 by custom)", low=0.0, strict=True), default=10.0)

    def grid(self) -> np.ndarray:
        return np.geomspace(*self.f_hz, self.points)


@result_type
@dataclass(frozen=True, eq=False)
class ShockSpectra(Result):
    """Result of :func:`shock_spectra` (stored in ``/srs``).

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Natural frequencies of the oscillators [Hz].
    input : ndarray, shape (nf,), or None
        SRS of the base acceleration along the ground's direction [m/s^2]; None without ground motion.
    points : ndarray, shape (n_points, 3, nf)
        SRS of each body point's absolute acceleration along x, y, z [m/s^2].
    names : tuple of str
        The body points.
    q : float
    """

    f_hz: np.ndarray = quantity("Hz", ("f_hz",))
    points: np.ndarray = quantity("m/s^2", ("point", "axis", "f_hz"), name="point_srs",
                                  description="maximax absolute-acceleration SRS of each body point")
    names: tuple[str, ...] = quantity("", ("point",), name="point", decode=lambda a: tuple(str(n) for n in a))
    q: float = label(decode=float)
    input: np.ndarray | None = quantity("m/s^2", ("f_hz",), default=None,
                                        description="maximax absolute-acceleration SRS of the base acceleration")


def _substeps(per_period: int, periods_per_sample: float) -> int:
    """Steps per sample of a record that give an oscillator at least ``per_period`` steps per period, for
    ``periods_per_sample`` of its periods in one sample step (at least 1)."""
    return max(1, math.ceil(per_period * periods_per_sample))


def _linear_between(x: np.ndarray, steps: int) -> np.ndarray:
    """Samples ``x`` (n,) linear between each two, ``steps`` per interval ((n - 1) steps + 1 values): the input
    as the filters take it, so that the response there is the same response's exact values in between."""
    return np.interp(np.arange((x.size - 1) * steps + 1) / steps, np.arange(x.size), x)


def srs(t, acceleration, f_hz, q: float = 10.0) -> np.ndarray:
    """Maximax absolute-acceleration SRS of a base acceleration sampled uniformly.

    Parameters
    ----------
    t : array_like, shape (n,)
        Uniform times [s].
    acceleration : array_like, shape (n,)
        Base acceleration [any unit; the SRS is in the same].
    f_hz : array_like, shape (nf,)
        Natural frequencies [Hz], each below half the sample rate.
    q : float
        Quality factor, damping ratio 1/(2q).

    Returns
    -------
    ndarray, shape (nf,)
    """
    from scipy.signal import lfilter  # only when spectra are asked for: scipy.signal pulls in scipy.stats

    t, x, f = np.asarray(t, float), np.asarray(acceleration, float), np.asarray(f_hz, float)
    dt = float(t[1] - t[0])
    if not np.allclose(np.diff(t), dt, rtol=1e-9, atol=0):
        raise InputError("t", "uniform sample times", "non-uniform times")
    if np.any(f >= 0.5 / dt):
        raise InputError("f_hz", f"natural frequencies below half the sample rate ({0.5 / dt:.6g} Hz)",
                         float(f.max()))
    zeta = 1.0 / (2.0 * q)
    out = np.empty(f.size)
    for k, fn in enumerate(f):
        steps = _substeps(PEAK_STEPS_PER_PERIOD, fn * dt)
        # From 0 one sample before the first (the filter's start from rest).
        fine = _linear_between(np.append(0.0, x), steps)
        h = dt / steps
        a = 2 * np.pi * fn * zeta * h  # Smallwood's A and B
        b = 2 * np.pi * fn * np.sqrt(1 - zeta**2) * h
        e, sinc = np.exp(-a), np.sin(b) / b
        num = [1 - e * sinc, 2 * e * (sinc - np.cos(b)), e**2 - e * sinc]
        den = [1.0, -2 * e * np.cos(b), e**2]
        out[k] = np.max(np.abs(lfilter(num, den, fine)[steps:]))
    return out


def shock_spectra(response, points: dict, settings: SRSSettings, ground_direction=None) -> ShockSpectra:
    """The SRS of the base acceleration (along ``ground_direction``, when the ground moves) and of every body
    point's absolute acceleration in ``points`` (name -> PointMotion) over the run's record ``response``."""
    f = settings.grid()
    t = response.t
    base = None
    if ground_direction is not None and response.ground_acceleration is not None:
        d = np.asarray(ground_direction, float) / np.linalg.norm(ground_direction)
        base = readonly(srs(t, response.ground_acceleration @ d, f, settings.q))
    spectra = [[srs(t, motion.acceleration[:, axis], f, settings.q) for axis in range(3)]
               for motion in points.values()]
    return ShockSpectra(f_hz=readonly(f), input=base, names=tuple(points), q=settings.q,
                        points=readonly(np.array(spectra).reshape(len(points), 3, f.size)))


def _foh_recurrence(omega: float, zeta: float, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The exact step ``x_k+1 = Phi x_k + B0 a_k + B1 a_k+1`` of ``u'' + 2 zeta omega u' + omega^2 u = -a(t)``
    over ``h`` for ``a`` linear between the two samples (a first-order hold), ``x = [u, u']``.

    The recurrence of Nigam & Jennings (1969), computed as the matrix exponential of the system augmented with
    the input and its slope (Van Loan 1978; scipy's ``cont2discrete(..., "foh")`` does the same): exact, with no
    closed-form coefficients to mistype.
    """
    from scipy.linalg import expm  # only when spectra are asked for

    block = np.zeros((4, 4))
    block[:2, :2] = [[0.0, 1.0], [-omega * omega, -2.0 * zeta * omega]]
    block[1, 2] = -1.0  # the input a enters u'' with a minus sign (base acceleration)
    block[2, 3] = 1.0 / h  # a(t) = a_k + (a_k+1 - a_k) s / h
    e = expm(block * h)
    phi, gamma0, gamma1 = e[:2, :2], e[:2, 2], e[:2, 3]
    return phi, gamma0 - gamma1, gamma1


def relative_displacement(t, acceleration, period: float, damping: float = 0.05) -> np.ndarray:
    """Relative displacement of a single-DOF oscillator from rest under a base acceleration record.

    Solves ``u'' + 2 xi omega u' + omega^2 u = -a(t)`` (``omega = 2 pi / period``) with ``u = u' = 0`` at the
    record's first time, exactly for the record linear between its samples (the first-order hold sixdof
    gives every table): the step of :func:`_foh_recurrence` run as a second-order recursive filter.

    Parameters
    ----------
    t : array_like, shape (n,)
        Uniform times [s].
    acceleration : array_like, shape (n,)
        Base acceleration [m/s^2].
    period : float
        Natural period [s], > 0.
    damping : float, optional
        Damping ratio xi, in [0, 1). Default 0.05.

    Returns
    -------
    ndarray, shape (n,)
        ``u`` at the record's times [m].
    """
    from scipy.signal import lfilter, lfiltic  # only when spectra are asked for

    t, a = np.asarray(t, float), np.asarray(acceleration, float)
    num, den, back = _displacement_filter(2.0 * np.pi / float(period), float(damping), float(t[1] - t[0]))
    state = lfiltic(num, den, [back[0] * a[0], back[1] * a[0]], [0.0, 0.0])
    return lfilter(num, den, a, zi=state)[0]


@functools.lru_cache(maxsize=4096)
def _displacement_filter(omega: float, zeta: float, h: float) -> tuple[tuple, tuple, tuple]:
    """The recursive filter of :func:`relative_displacement` for one oscillator and step: numerator, denominator
    and the filter's past outputs per unit first sample (tuples of floats). Cached: matching a record computes the
    same oscillators' spectra again at every iteration, and the matrix exponential of each costs more than its
    filter (up to 8 ms where BLAS threads wait for a busy machine's cores)."""
    phi, b0, b1 = _foh_recurrence(omega, zeta, h)
    # u_k as a filter of a: c adj(zI - Phi) (B0 + B1 z) / det(zI - Phi), c = [1, 0].
    num = (b1[0], b0[0] - phi[1, 1] * b1[0] + phi[0, 1] * b1[1], -phi[1, 1] * b0[0] + phi[0, 1] * b0[1])
    den = (1.0, -np.trace(phi), np.linalg.det(phi))
    # The filter's past (two outputs, zero inputs before the record) set so that x_0 = 0: stepping back from rest,
    # x_-1 = -Phi^-1 B1 a_0, x_-2 = Phi^-1 x_-1 (linear in a_0: given per unit a_0).
    back1 = -np.linalg.solve(phi, b1)
    back2 = np.linalg.solve(phi, back1)
    return tuple(map(float, num)), tuple(map(float, den)), (float(back1[0]), float(back2[0]))


def pseudo_acceleration_spectrum(t, acceleration, periods, damping: float = 0.05) -> np.ndarray:
    """Pseudo-acceleration response spectrum ``Sa(T) = omega^2 max |u|`` of a base acceleration record.

    ``u`` is the relative displacement of the oscillator of period ``T`` and damping ratio ``damping`` from rest
    (:func:`relative_displacement`: exact for the record linear between its samples), its largest magnitude
    sought over the record's span at :data:`SPECTRUM_STEPS_PER_PERIOD` points per period at least (the input
    linearly interpolated between the samples, as it is taken: exact values of the same response in between);
    free vibration after the record's last sample is not looked at. The spectrum that the design codes give
    (EN 1998-1 3.2.2.2: the elastic response spectrum at 5 % damping) is this quantity.

    Parameters
    ----------
    t : array_like, shape (n,)
        Uniform times [s], n >= 2.
    acceleration : array_like, shape (n,)
        Base acceleration [m/s^2].
    periods : array_like, shape (nT,)
        Natural periods [s], > 0 (any, also below two samples: the recurrence is exact).
    damping : float, optional
        Damping ratio, in [0, 1). Default 0.05.

    Returns
    -------
    ndarray, shape (nT,)
        ``Sa`` [m/s^2].

    Raises
    ------
    InputError
        For non-uniform times, a period <= 0 or a damping ratio outside [0, 1).
    """
    t, x = np.asarray(t, float), np.asarray(acceleration, float)
    periods = np.atleast_1d(np.asarray(periods, float))
    if t.ndim != 1 or t.size < 2 or x.shape != t.shape:
        raise InputError("acceleration", f"{t.size} values, one per time (at least 2)", Plain(f"shape {x.shape}"))
    dt = float(t[1] - t[0])
    if not dt > 0 or not np.allclose(np.diff(t), dt, rtol=1e-9, atol=0):
        raise InputError("t", "uniform increasing sample times", "non-uniform times")
    if not np.all(np.isfinite(periods) & (periods > 0)):
        raise InputError("periods", "natural periods > 0 in s", periods)
    number(damping, "damping", "a damping ratio in [0, 1)", low=0.0, high=1.0 - 1e-12)
    out = np.empty(periods.size)
    for k, period in enumerate(periods):
        steps = _substeps(SPECTRUM_STEPS_PER_PERIOD, dt / period)
        if steps == 1:
            fine_t, fine = t, x
        else:
            fine_t, fine = t[0] + np.arange((x.size - 1) * steps + 1) / steps * dt, _linear_between(x, steps)
        omega = 2.0 * np.pi / period
        out[k] = omega * omega * np.max(np.abs(relative_displacement(fine_t, fine, period, damping)))
    return out
