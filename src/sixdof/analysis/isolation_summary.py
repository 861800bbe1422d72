"""Vibration isolation at the operating frequencies: force and motion transmissibility curves, the isolation
region and the isolation efficiency read off at each operating frequency (not EN 1998-2 seismic isolation:
:mod:`sixdof.analysis.isolation`).

The force transmissibility of a load pattern ``Q`` (the generalized force phasor at the CG of the harmonic
loads at one operating frequency, :attr:`~sixdof.analysis.steady.SteadyState.applied`) is, at every frequency
``f``, the amplitude of the force the mounts pass to the foundation, :func:`~sixdof.analysis.frf.foundation_forces`
of ``H(f) Q``, over the amplitude of the applied force (a torque without a force: the moment on the foundation
about the CG's rest position over the applied moment; both the largest over a period,
:func:`~sixdof.analysis.steady.vector_amplitude`): dimensionless, and at the operating frequency the
steady state's :attr:`~sixdof.analysis.steady.SteadyState.transmissibility`. The motion transmissibility of a
ground moving along ``d`` is the amplitude of the CG's absolute translation per unit ground translation
(:func:`~sixdof.analysis.frf.ground_transmissibility`). The isolation efficiency is ``1 - |T|`` (negative where
the mounts amplify).

The isolation region of a pattern starts at ``sqrt(2)`` times the highest natural frequency of the modes it
excites: above it every excited mode's single-DOF transmissibility is below 1, whatever its damping. A mode's
natural frequency is where it resonates (:func:`natural_frequencies`): its undamped frequency, or, on mounts
with Maxwell branches (an elastomer stiffer at its resonances than at rest), its pole in the full model. A mode
is excited when it holds at least :data:`EXCITED_FRACTION` of the pattern's participation
``e_r = |phi_r' Q|^2 / (Q^H M^-1 Q)`` (mass-normalized modes; the shares sum to 1 over all modes, and for
``Q = M r`` of a rigid translation ``r`` they are the modal effective-mass fractions along it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.analysis.frf import foundation_forces, ground_transmissibility, receptance
from sixdof.analysis.statespace import damped_modes
from sixdof.analysis.steady import CANCELLED_RTOL, vector_amplitude
from sixdof.errors import InputError, readonly

#: A mode holding at least this share of a load pattern's participation is excited by it (see the module).
EXCITED_FRACTION = 0.05
#: Patterns whose phasors are parallel to this (relative) are one curve.
SAME_PATTERN_RTOL = 1e-9


@dataclass(frozen=True, eq=False)
class TransmissibilityCurve:
    """The transmissibility of one load pattern (or of the ground's motion) and its isolation.

    Attributes
    ----------
    kind : {"force", "moment", "motion"}
        Force on the foundation over the applied force; moment on the foundation (about the CG's rest position)
        over the applied moment, for a pattern without a force; or absolute CG translation over the ground's.
    f_hz : ndarray, shape (nf,)
        Frequencies of ``values`` [Hz].
    values : ndarray, shape (nf,)
        ``|T|`` [-].
    operating_hz : ndarray, shape (no,)
        The operating frequencies of this pattern [Hz].
    at_operating : ndarray, shape (no,)
        ``|T|`` at each of them [-].
    efficiency : ndarray, shape (no,)
        ``1 - at_operating`` (a fraction; negative where the mounts amplify).
    excited_modes : tuple of int
        Indices of the modes the pattern excites (participation >= :data:`EXCITED_FRACTION`).
    participation : ndarray, shape (6,)
        Each mode's share of the pattern's participation (sums to 1).
    isolation_hz : float
        Where the isolation region starts: ``sqrt(2)`` times the highest natural frequency of the excited
        modes [Hz].
    """

    kind: str
    f_hz: np.ndarray
    values: np.ndarray
    operating_hz: np.ndarray
    at_operating: np.ndarray
    efficiency: np.ndarray
    excited_modes: tuple[int, ...]
    participation: np.ndarray
    isolation_hz: float


@dataclass(frozen=True, eq=False)
class IsolationSummary:
    """What :func:`isolation_summary` finds: the load curves (one per load pattern) and the motion curve.

    Attributes
    ----------
    loads : tuple of TransmissibilityCurve
        One per distinct load pattern at the operating frequencies (empty without harmonic loads): of kind
        ``"force"``, or ``"moment"`` for a pattern without a force (a torque).
    motion : TransmissibilityCurve or None
        The ground's (None without a ground motion at an operating frequency).
    natural_hz : ndarray, shape (6,)
        The natural frequency of each mode that the isolation regions are reckoned from [Hz]
        (:func:`natural_frequencies`).
    """

    loads: tuple[TransmissibilityCurve, ...]
    motion: TransmissibilityCurve | None
    natural_hz: np.ndarray

    @property
    def curves(self) -> tuple[TransmissibilityCurve, ...]:
        """Every curve, the loads' first."""
        return self.loads + (() if self.motion is None else (self.motion,))


def participation(modes, M, Q) -> np.ndarray:
    """Each mode's share of the participation of the generalized force phasor ``Q`` (6,) [N, N m], complex:
    ``|phi_r' Q|^2 / (Q^H M^-1 Q)`` (real and imaginary parts alike), summing to 1 over the 6 modes."""
    Q = np.asarray(Q, dtype=complex)
    modal = np.abs(modes.shapes.T @ Q) ** 2
    total = float(np.real(np.conj(Q) @ np.linalg.solve(np.asarray(M, dtype=float), Q)))
    if not total > 0:
        raise InputError("Q", "a nonzero load pattern", Q)
    return modal / total


def natural_frequencies(system, modes) -> np.ndarray:
    """The frequency each of ``modes`` (the undamped modes of ``system``) resonates at [Hz] (6,): its undamped
    frequency; on mounts with Maxwell branches, whose stiffness rises with frequency, the magnitude of its pole in
    the full visco-elastic model, ``|lambda| / 2 pi`` (:func:`~sixdof.analysis.statespace.damped_modes`: 12-18 %
    above the long-term stiffness' modes for ``equipment_elastomer``), where the peaks of its FRFs are. A mode
    without an oscillating pole keeps its undamped frequency."""
    undamped = np.asarray(modes.frequency_hz, dtype=float)
    if not system.branches.count:
        return readonly(undamped.copy())
    poles, _ = damped_modes(system.C, modes, system.branches)
    full = np.abs(poles) / (2 * np.pi)
    return readonly(np.where(np.isfinite(full), full, undamped))


def _boundary(natural_hz, shares) -> tuple[tuple[int, ...], float]:
    excited = tuple(int(r) for r in np.flatnonzero(shares >= EXCITED_FRACTION))
    return excited, float(np.sqrt(2.0) * np.max(natural_hz[list(excited)]))


def _load_values(system, f_hz, Q, part: slice) -> np.ndarray:
    """``|T|`` of the load pattern ``Q`` at ``f_hz``: the ``part`` (forces or moments) of what the foundation
    receives over that of ``Q``."""
    frf = receptance(system, f_hz)
    _, _, total = foundation_forces(system, frf.omega, frf.H @ Q)
    return vector_amplitude(total[:, part]) / vector_amplitude(Q[part])[()]


def _patterns(operating_hz, applied) -> list[tuple[np.ndarray, list[float]]]:
    """The distinct load patterns (normalized phasors) and their operating frequencies."""
    found: list[tuple[np.ndarray, list[float]]] = []
    for f, Q in zip(operating_hz, applied):
        scale = np.linalg.norm(Q)
        if not scale > 0:
            continue
        Q = Q / scale
        for pattern, frequencies in found:
            # Parallel up to a complex factor: |<p, Q>| = |p| |Q|.
            if abs(abs(np.vdot(pattern, Q)) - np.linalg.norm(pattern) * np.linalg.norm(Q)) \
                    <= SAME_PATTERN_RTOL * np.linalg.norm(pattern) * np.linalg.norm(Q):
                frequencies.append(float(f))
                break
        else:
            found.append((Q, [float(f)]))
    return found


def isolation_summary(system, modes, f_hz, operating_hz=(), applied=None, ground_direction=None,
                      ground_hz=()) -> IsolationSummary:
    """Force and motion transmissibility of the operating loads and ground motion of a system (see the module).

    Parameters
    ----------
    system : sixdof.model.system.System
    modes : sixdof.model.modes.Modes
        The system's undamped modes.
    f_hz : array_like, shape (nf,)
        Frequencies of the curves [Hz], > 0.
    operating_hz : array_like, shape (no,)
        Operating frequencies of the harmonic loads [Hz] (:attr:`~sixdof.analysis.steady.SteadyState.f_hz`).
    applied : array_like, shape (no, 6), complex, optional
        Their generalized force phasors at the CG [N, N m] (:attr:`~sixdof.analysis.steady.SteadyState.applied`).
    ground_direction : array_like, shape (3,), optional
        Direction of a ground translation, in body axes.
    ground_hz : array_like
        Operating frequencies of the ground motion [Hz].

    Returns
    -------
    IsolationSummary
    """
    f_hz = readonly(np.asarray(f_hz, dtype=float))
    if f_hz.ndim != 1 or not f_hz.size or not np.all(f_hz > 0):
        raise InputError("f_hz", "frequencies > 0 in Hz (a 1-D array)", f_hz)
    operating_hz = np.atleast_1d(np.asarray(operating_hz, dtype=float))
    applied = np.zeros((0, 6), complex) if applied is None else np.asarray(applied, dtype=complex).reshape(-1, 6)
    if applied.shape[0] != operating_hz.size:
        raise InputError("applied", f"one load phasor (6,) per operating frequency ({operating_hz.size})",
                         applied.shape)
    natural_hz = natural_frequencies(system, modes)
    loads = []
    for Q, frequencies in _patterns(operating_hz, applied):
        at = np.array(frequencies)
        shares = participation(modes, system.M, Q)
        excited, boundary = _boundary(natural_hz, shares)
        # A pattern without a force (a torque, or forces that cancel) passes a moment: its ratio is the moments'.
        force = vector_amplitude(Q[:3])[()] > CANCELLED_RTOL * np.linalg.norm(Q)
        part = slice(0, 3) if force else slice(3, 6)
        at_operating = _load_values(system, at, Q, part)
        loads.append(TransmissibilityCurve("force" if force else "moment", f_hz,
                                           readonly(_load_values(system, f_hz, Q, part)), readonly(at),
                                           readonly(at_operating), readonly(1.0 - at_operating), excited,
                                           readonly(shares), boundary))
    motion = None
    ground_hz = np.atleast_1d(np.asarray(ground_hz, dtype=float))
    if ground_direction is not None and ground_hz.size:
        d = np.asarray(ground_direction, dtype=float)
        d = d / np.linalg.norm(d)
        shares = participation(modes, system.M, np.asarray(system.M) @ np.concatenate([d, np.zeros(3)]))
        excited, boundary = _boundary(natural_hz, shares)
        values = vector_amplitude(ground_transmissibility(system, f_hz, d, np.zeros(3)).absolute)
        at_operating = vector_amplitude(ground_transmissibility(system, ground_hz, d, np.zeros(3)).absolute)
        motion = TransmissibilityCurve("motion", f_hz, readonly(values), readonly(ground_hz), readonly(at_operating),
                                       readonly(1.0 - at_operating), excited, readonly(shares), boundary)
    return IsolationSummary(tuple(loads), motion, natural_hz)


def ground_operating(run) -> tuple[np.ndarray | None, np.ndarray]:
    """The direction and operating frequencies [Hz] of a run's ground motion when its signal is a harmonic
    without end (``None`` and none otherwise, and for a stored run, which keeps no excitation)."""
    excitation = None if run.scenario is None else run.scenario.excitation
    ground = None if excitation is None else excitation.ground
    if ground is None:  # before the import: a stored run's figures load no JAX
        return None, np.zeros(0)
    from sixdof.excitation import Harmonic  # noqa: PLC0415 (loads JAX, already there where a ground motion is)

    if not (isinstance(ground.signal, Harmonic) and np.isinf(ground.signal.duration)):
        return None, np.zeros(0)
    return np.asarray(ground.direction, dtype=float), np.array([ground.signal.f_hz])


def has_operating(run) -> bool:
    """Whether a :class:`~sixdof.results.RunResults` has operating frequencies: a steady state, or a ground
    motion that is a harmonic without end."""
    if run.system is None or run.modes is None:
        return False
    return run.steady_state is not None or ground_operating(run)[0] is not None


def run_isolation_summary(run) -> IsolationSummary:
    """:func:`isolation_summary` of a :class:`~sixdof.results.RunResults` with operating frequencies
    (:func:`has_operating`): on the frequencies of its FRF when it has one, else :func:`default_frequencies`."""
    steady = run.steady_state
    operating = np.zeros(0) if steady is None else steady.f_hz
    direction, ground_hz = ground_operating(run)
    if run.frf is not None:
        f_hz = run.frf.direct.f_hz
        f_hz = f_hz[f_hz > 0]
    else:
        f_hz = default_frequencies(run.modes, np.concatenate([operating, ground_hz]))
    return isolation_summary(run.system, run.modes, f_hz, operating, None if steady is None else steady.applied,
                             direction, ground_hz)


def default_frequencies(modes, operating_hz, points: int = 800) -> np.ndarray:
    """A log-spaced grid [Hz] from a tenth of the lowest elastic natural frequency (or operating frequency) to ten
    times the highest (operating frequencies included)."""
    f = np.concatenate([modes.frequency_hz[modes.frequency_hz > 0], np.atleast_1d(operating_hz)])
    return np.geomspace(0.1 * f.min(), 10.0 * f.max(), points)


__all__ = ["EXCITED_FRACTION", "IsolationSummary", "SAME_PATTERN_RTOL", "TransmissibilityCurve",
           "default_frequencies", "ground_operating", "has_operating", "isolation_summary", "participation",
           "run_isolation_summary"]
