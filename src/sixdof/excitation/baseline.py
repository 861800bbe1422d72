"""Baseline correction of an accelerogram: the record's integrated velocity and displacement end at rest.

A small offset in a recorded acceleration (instrument tilt, digitization, a record cut from a longer one)
integrates into a velocity that ends away from zero and a displacement that drifts without bound: 0.1 % of
a 0.25 g peak over 20 s ends 0.05 m/s and 0.5 m away. The standard remedy (Boore 2001; Boore, Stephens &
Joyner 2002; the USGS BAP program, Converse & Brady 1992) is a least-squares polynomial fit to the velocity
integrated from the record, whose derivative is removed from the acceleration.

Everything here is exact for the record as sixdof uses it, a table interpolated linearly between its samples
(a first-order hold): the velocity and displacement are its exact integrals, and the correction is sampled
at the record's times so that the corrected table integrates to zero end velocity and displacement to
round-off.

References
----------
D. M. Boore (2001), Effect of baseline corrections on displacements and response spectra for several
recordings of the 1999 Chi-Chi, Taiwan, earthquake, Bull. Seismol. Soc. Am. 91(5), 1199-1211.
D. M. Boore, C. D. Stephens and W. B. Joyner (2002), Comments on baseline correction of digital
strong-motion data: examples from the 1999 Hector Mine, California, earthquake, Bull. Seismol. Soc. Am.
92(4), 1543-1560.
A. G. Converse and A. G. Brady (1992), BAP: basic strong-motion accelerogram processing software, version
1.0, U.S. Geological Survey Open-File Report 92-296A.
"""

from __future__ import annotations

import numpy as np

#: The ``[ground] baseline`` methods: ``"none"`` (the record as given) or ``"polynomial"``
#: (:func:`polynomial_baseline`).
BASELINE_METHODS = ("none", "polynomial")

#: Default degree of the velocity polynomial of :func:`polynomial_baseline`: 2, Boore's quadratic in velocity (a
#: straight line removed from the acceleration), whose two coefficients the end conditions fix. Of all
#: corrections that bring a record to rest, it is the smallest in mean-square acceleration (in the continuous
#: limit: minimizing the integral of the correction squared under the two end conditions gives a straight line),
#: so it keeps the record's own long-period motion; a higher degree fits the rest of the drift by least squares,
#: and with it part of that motion.
BASELINE_DEGREE = 2
#: Highest degree accepted: beyond it the powers of time are nearly dependent and the fit ill-conditioned.
MAX_BASELINE_DEGREE = 6


def integrate_record(t, a) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and displacement of a linearly interpolated acceleration record, from rest at its first sample.

    Exact for the first-order hold: on each interval ``h`` the velocity gains ``h (a_k + a_k+1) / 2`` and
    the displacement ``v_k h + h^2 (2 a_k + a_k+1) / 6``.

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times [s], increasing.
    a : array_like, shape (n,) or (n, k)
        Accelerations [m/s^2] (or any unit: the results are in it times s and s^2); columns integrate apart.

    Returns
    -------
    v, d : ndarray, shape of ``a``
        Velocity [m/s] and displacement [m] at the sample times.
    """
    t, a = np.asarray(t, dtype=float), np.asarray(a, dtype=float)
    h = np.diff(t).reshape((-1,) + (1,) * (a.ndim - 1))
    gain_v = h * (a[:-1] + a[1:]) / 2
    v = np.concatenate([np.zeros_like(a[:1]), np.cumsum(gain_v, axis=0)])
    gain_d = v[:-1] * h + h**2 * (2 * a[:-1] + a[1:]) / 6
    d = np.concatenate([np.zeros_like(a[:1]), np.cumsum(gain_d, axis=0)])
    return v, d


def polynomial_baseline(t, a, degree: int = BASELINE_DEGREE) -> np.ndarray:
    """The record ``a`` less the derivative of the polynomial fitted to its velocity.

    The velocity ``v`` integrated from the record (from rest at its first sample) is fitted, by least squares
    over the samples, with ``P(tau) = sum_j c_j tau^j`` (``j = 1..degree``, ``tau = (t - t_0) / (t_n - t_0)``:
    zero at the start, where the ground is at rest), constrained so that the corrected velocity ``v - P`` and
    displacement ``d - int P`` are zero at the last sample. ``P'`` is removed from the acceleration, sampled at
    the record's times: the least-squares fit to the velocity of Boore (2001) and Boore, Stephens & Joyner
    (2002), with the record brought to rest where it ends. The correction is linear in ``a`` and removes any
    drift whose velocity is such a polynomial exactly: ``correction(a + P') = correction(a)``.

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times [s], increasing, ``n >= degree + 2``.
    a : array_like, shape (n,)
        Accelerations [m/s^2, or the record's unit].
    degree : int, optional
        Degree of ``P``, from 2 to :data:`MAX_BASELINE_DEGREE`. Default :data:`BASELINE_DEGREE`, which the two
        end conditions fix alone.

    Returns
    -------
    ndarray, shape (n,)
        The corrected accelerations, same unit; integrated as a first-order hold they end at zero velocity
        and displacement (to round-off).
    """
    t, a = np.asarray(t, dtype=float), np.asarray(a, dtype=float)
    tau = (t - t[0]) / (t[-1] - t[0])
    powers = np.arange(1, degree + 1)
    # Each basis drift's acceleration, sampled, then integrated exactly like the record: the constraints hold
    # for the table the solver integrates, not for the polynomial between its samples.
    drifts = powers * tau[:, None] ** (powers - 1) / (t[-1] - t[0])
    basis_v, basis_d = integrate_record(t, drifts)
    v, d = integrate_record(t, a)
    ends = np.stack([basis_v[-1], basis_d[-1]])  # (2, degree): the end velocity and displacement of each
    # Least squares with equality constraints, by its KKT system (scaled: velocity columns of unit size).
    norm = np.linalg.norm(basis_v, axis=0)
    gram = (basis_v / norm).T @ (basis_v / norm)
    kkt = np.block([[gram, (ends / norm).T], [ends / norm, np.zeros((2, 2))]])
    rhs = np.concatenate([(basis_v / norm).T @ v, [v[-1], d[-1]]])
    coefficients = np.linalg.solve(kkt, rhs)[:degree] / norm
    return a - drifts @ coefficients
