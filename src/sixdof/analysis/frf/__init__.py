"""Frequency-response functions of the mounted rigid body, by direct solution and by modal summation.

Everything here is a pure function of a :class:`~sixdof.model.system.System` and an array of frequencies in
Hz, returning a frozen result object. Steady-state harmonic motion ``q(t) = Re(q_hat e^{i w t})`` of

    (K + i K_h - w^2 M + i w C) q_hat = Q_hat                      (w = 2 pi f [rad/s], f >= 0)

where ``K_h`` is the hysteretic stiffness: every mount's stiffness times its loss factor, assembled
like ``K`` (complex stiffness ``k (1 + i eta)``, frequency independent; defined for ``f >= 0``).
``C`` is the total viscous damping (mount dashpots + Rayleigh + modal, :attr:`System.C`).

Two independent computations of the 6x6 receptance ``H = Z^-1``:

* ``method="direct"``, the default and the reference: a batched LU solve of the dynamic stiffness at
  every frequency (LAPACK through NumPy; no Python loop per frequency).
* ``method="modal"``, the fast path (~5x faster at 10,000 frequencies): summation over modes. When
  both ``C`` and ``K_h`` are diagonal in the undamped mass-normalized modes (classical damping:
  Rayleigh, modal, or proportional dashpots) the sum runs over the real modes,
  ``H = sum_r phi_r phi_r' / (w_r^2 (1 + i eta_r) - w^2 + i w c_r)``; otherwise over the complex modes
  of the first-order state-space system (complex ``K + i K_h`` included). Rigid-body (zero-frequency)
  modes contribute their mass line ``-phi phi' / w^2`` (or their damped form when ``C`` acts on them).
  It refuses (SolverError) nearly defective complex modes, e.g. a critically damped mode, which the
  direct method handles.

:func:`cross_check` computes both and reports their largest relative difference.

Zero frequency: ``f_hz = 0`` gives the static compliance ``(K + i K_h)^-1`` (mobility and accelerance
0) when every DOF is restrained. When the mounts leave a DOF unrestrained (zero-frequency modes), the
static response is unbounded and ``f_hz = 0`` raises :class:`~sixdof.errors.InputError`; every
positive frequency works, with either method.

Units: receptance entry ``[i, j]`` is DOF i's unit per generalized force j's unit (m/N, rad/(N m),
m/(N m) = 1/N, rad/N); :meth:`FRF.units` spells them out. Mobility multiplies by ``i w`` (per s),
accelerance by ``-w^2`` (per s^2).

The package's modules: :mod:`~sixdof.analysis.frf.records` (the result objects),
:mod:`~sixdof.analysis.frf.receptance` (the receptance, both ways, and their cross-check) and
:mod:`~sixdof.analysis.frf.points` (between points: point FRFs and transmissibilities).
"""

from sixdof.analysis.frf.points import (
    force_transmissibility,
    foundation_forces,
    ground_transmissibility,
    mount_impedances,
    parse_direction,
    point_frf,
)
from sixdof.analysis.frf.receptance import (
    RIGID_DAMPING_RTOL,
    UNDAMPED_RESONANCE_RTOL,
    check_resonances,
    cross_check,
    dynamic_stiffness,
    frf_difference,
    hysteretic_stiffness,
    receptance,
    support_stiffness,
)
from sixdof.analysis.frf.records import (
    FRF,
    QUANTITIES,
    ForceTransmissibility,
    FRFCrossCheck,
    GroundTransmissibility,
    PointFRF,
    in_file_order,
)

__all__ = [
    "FRF", "FRFCrossCheck", "ForceTransmissibility", "GroundTransmissibility", "PointFRF", "QUANTITIES",
    "cross_check", "check_resonances", "dynamic_stiffness", "force_transmissibility", "foundation_forces",
    "frf_difference", "in_file_order",
    "ground_transmissibility", "hysteretic_stiffness", "point_frf", "receptance",
    "RIGID_DAMPING_RTOL", "UNDAMPED_RESONANCE_RTOL", "mount_impedances", "parse_direction", "support_stiffness",
]
