"""The steady state at the excitation's operating frequencies, and the isolation it gives.

A load whose signal is a harmonic that lasts for ever (:class:`~sixdof.excitation.Harmonic` without a
``duration``, and the rotating :class:`~sixdof.excitation.Unbalance`) drives, once the switch-on transient
has died out, a response at its own frequency. Component ``k`` is ``Q_k sin(w (t - t0_k) + phi_k)``,
``Im(Q_k p_k e^{i w t})`` with the phasor ``p_k = e^{i (phi_k - w t0_k)}``; the components at one frequency
add up to ``Q = sum_k Q_k p_k`` and the body's motion is ``q(t) = Im(q e^{i w t})``, ``q = H(w) Q``, with
the receptance :func:`~sixdof.analysis.frf.receptance` (the frequency-domain model: loss factors
included). The foundation receives :func:`~sixdof.analysis.frf.foundation_forces` of ``q``.

Amplitudes are the largest value over a period: ``|q_i|`` per DOF, and for a vector (a force in three
components out of phase, such as a rotating unbalance's) the largest singular value of
``[Re v, Im v]``. The force transmissibility is the transmitted force's amplitude over the applied one's,
and the isolation efficiency ``1 - transmissibility`` (negative where the mounts amplify).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof import results as schema
from sixdof.analysis.frf import check_resonances, foundation_forces, receptance
from sixdof.dofs import UNITS
from sixdof.errors import InputError, instance, readonly
from sixdof.model.system import System

#: Operating frequencies closer than this (relative) are one frequency: their components add up.
SAME_FREQUENCY_RTOL = 1e-12
#: An applied force below this fraction of its components' sum is none (they cancel to round-off).
CANCELLED_RTOL = 1e-12


@schema.result_type
@dataclass(frozen=True, eq=False)
class SteadyState(schema.Result):
    """Steady-state amplitudes at each operating frequency (:func:`steady_state`).

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Operating frequencies [Hz], ascending.
    q : ndarray, shape (nf, 6), complex
        Motion phasors of the CG [m, rad]: ``q(t) = Im(q e^{i w t})``; ``abs(q)`` is each DOF's amplitude.
    applied : ndarray, shape (nf, 6), complex
        Generalized force phasors of the loads at the CG [N, N m].
    transmitted : ndarray, shape (nf, 6), complex
        Resultant force and moment on the foundation about the CG's rest position [N, N m].
    mount_forces : ndarray, shape (nf, n_mounts, 3), complex
        Each mount's force on the foundation in body axes [N].
    applied_force, transmitted_force : ndarray, shape (nf,)
        Amplitudes of the applied and transmitted force vectors [N] (largest over a period).
    transmissibility : ndarray, shape (nf,)
        ``transmitted_force / applied_force``; NaN where no force is applied (a pure moment, or forces that
        cancel).
    isolation_efficiency : ndarray, shape (nf,)
        ``1 - transmissibility`` (a fraction; negative where the mounts amplify).
    loss_factors : bool
        Whether the mounts' loss factors are in it: a time response (which cannot hold them) then tends to
        another steady state.
    """

    f_hz: np.ndarray = schema.quantity("Hz", ("f_hz",))
    q: np.ndarray = schema.quantity(UNITS["q"], ("f_hz", "dof"),
                                    description="steady-state motion phasors of the CG, q(t) = Im(q e^(i w t))")
    applied: np.ndarray = schema.quantity(UNITS["Q"], ("f_hz", "load"), description="applied load phasors at the CG")
    transmitted: np.ndarray = schema.quantity(UNITS["Q"], ("f_hz", "load"),
                                              description="resultant on the foundation about the CG rest position")
    mount_forces: np.ndarray = schema.quantity("N", ("f_hz", "mount", "axis"), name="mount_force",
                                               description="each mount's force on the foundation, body axes")
    applied_force: np.ndarray = schema.quantity("N", ("f_hz",), description="amplitude of the applied force")
    transmitted_force: np.ndarray = schema.quantity("N", ("f_hz",),
                                                    description="amplitude of the force on the foundation")
    transmissibility: np.ndarray = schema.quantity("1", ("f_hz",), description="transmitted / applied force")
    isolation_efficiency: np.ndarray = schema.quantity("1", ("f_hz",), description="1 - transmissibility")
    loss_factors: bool = schema.label(default=False, encode=bool, decode=bool)

    group = "steady_state"


def vector_amplitude(v) -> np.ndarray:
    """Largest ``|Im(v e^{i w t})|`` over a period for complex vectors ``v`` (..., k): the largest singular
    value of ``[Re v, Im v]``."""
    v = np.asarray(v, dtype=complex)
    return np.linalg.svd(np.stack([v.real, v.imag], axis=-1), compute_uv=False)[..., 0]


def operating_phasors(excitation) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The operating frequencies [Hz] (ascending) of ``excitation``'s loads, their generalized force phasors
    (nf, 6) [N, N m] (the components whose signal is a harmonic without end, added up per frequency), and
    the sum of the components' force magnitudes per frequency (nf,) [N]: the scale against which a sum of
    forces that cancel is zero."""
    from sixdof.excitation import Harmonic  # noqa: PLC0415 (excitation loads JAX, which a steady state never needs)

    found = []
    for vector, signal in excitation.components():
        if isinstance(signal, Harmonic) and np.isinf(signal.duration):
            w = 2 * np.pi * signal.f_hz
            found.append((signal.f_hz, np.asarray(vector, dtype=float)
                          * np.exp(1j * (np.deg2rad(signal.phase_deg) - w * signal.start))))
    frequencies, phasors, gross = [], [], []
    for f, phasor in sorted(found, key=lambda item: item[0]):
        if not (frequencies and abs(f - frequencies[-1]) <= SAME_FREQUENCY_RTOL * f):
            frequencies.append(f)
            phasors.append(np.zeros(6, complex))
            gross.append(0.0)
        phasors[-1] = phasors[-1] + phasor
        gross[-1] += float(np.linalg.norm(phasor[:3]))
    return np.array(frequencies), np.array(phasors, dtype=complex).reshape(-1, 6), np.array(gross)


def steady_state(system, excitation) -> SteadyState | None:
    """The steady state of ``system`` at the operating frequencies of ``excitation`` (see the module).

    None when there is none to give: no harmonic load without end; a ground motion (its own steady state
    is not part of this one, which would then be wrong); or an operating frequency at the resonance of a
    mode that no damping acts on (the response grows without bound).

    Raises
    ------
    InputError
        For a ``system`` that is not a System or an ``excitation`` that is not an Excitation.
    """
    from sixdof.excitation import Excitation  # noqa: PLC0415 (excitation loads JAX, which a steady state never needs)

    instance(system, "system", System)
    instance(excitation, "excitation", Excitation)
    f_hz, applied, gross = operating_phasors(excitation)
    if not f_hz.size or excitation.ground is not None:
        return None
    try:
        check_resonances(system, f_hz)
    except InputError:
        return None
    frf = receptance(system, f_hz)
    q = np.einsum("fij,fj->fi", frf.H, applied)
    forces, _, transmitted = foundation_forces(system, frf.omega, q)
    applied_force, transmitted_force = vector_amplitude(applied[:, :3]), vector_amplitude(transmitted[:, :3])
    applies = applied_force > CANCELLED_RTOL * gross  # else a pure moment, or forces that cancel
    ratio = np.full(f_hz.size, np.nan)
    ratio[applies] = transmitted_force[applies] / applied_force[applies]
    return SteadyState(f_hz=readonly(f_hz), q=readonly(q, complex), applied=readonly(applied, complex),
                       transmitted=readonly(transmitted, complex), mount_forces=readonly(forces, complex),
                       applied_force=readonly(applied_force), transmitted_force=readonly(transmitted_force),
                       transmissibility=readonly(ratio), isolation_efficiency=readonly(1.0 - ratio),
                       loss_factors=bool(np.any(system.loss_factors)))


__all__ = ["CANCELLED_RTOL", "SAME_FREQUENCY_RTOL", "SteadyState", "operating_phasors", "steady_state",
           "vector_amplitude"]
