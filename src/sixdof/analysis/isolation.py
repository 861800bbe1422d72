"""The effective-linearization loop of isolated systems (issue 48, point 4; EN 1998-2:2005 7.5.4 and 7.5.5,
AASHTO Guide Specifications for Seismic Isolation Design, 2014, 7.1).

A hysteretic isolator is replaced, at its design displacement D, by its secant (effective) stiffness
``K_eff(D)`` and the equivalent viscous damping ratio ``xi_eff(D)`` of its loop; the response spectrum then gives
new design displacements. The loop iterates until the effective stiffnesses and damping agree from one
iteration to the next (relative change below ``rtol``, 1e-3 by default), refusing loudly after ``max_iterations``
(30).

:func:`isolated_spectrum` runs it for a system's hysteretic axes whose ``linearization`` is ``"effective"``
(:mod:`sixdof.model.hysteresis`), from their ``design_displacement``. More generally, what the isolators are is the
caller's: :func:`effective_linearization_loop` takes a callable
``linearize(D) -> (system, xi_eff)`` that, for the design displacements ``D`` [m] of the hysteretic mount axes
(one per entry of ``axes``, each a (mount index, axis index) pair), returns the system with those axes'
effective stiffnesses (read back from :attr:`~sixdof.model.system.System.stiffnesses`) and each axis's effective
damping ratio. The model layer's ``effective_linearization(law, D) -> (k_eff, xi_eff)`` of each hysteretic
law makes one.

Damping of the modes (EN 1998-2 7.5.5(4)): the isolation system's effective damping
``xi_eff = sum_k E_D,k / (2 pi sum_k K_eff,k D_k^2)``, with ``E_D,k = 2 pi xi_k K_eff,k D_k^2`` the energy each axis
dissipates per cycle (EN 1998-2 eq. (7.9)), is given to the modes of period ``T >= 0.8 T_eff``, ``T_eff`` being
the period of the mode carrying the largest effective mass in each direction analysed (the fundamental mode of
7.5.4), the shortest over the directions; the other modes keep the analysis's ``damping``. The spectrum of an
isolation mode is corrected by ``eta(xi_eff)`` (EN 1998-1 eq. (3.6)), and the CQC uses each mode's ratio. The
design displacement of each axis is its combined peak deflection over the directions.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from sixdof.analysis.spectrum import ResponseSpectrum, response_spectrum
from sixdof.errors import InputError, Plain, SolverError, readonly
from sixdof.results import Result, label, part, quantity, result_type

#: Relative change of every effective stiffness and of the effective damping at which the loop has converged.
LINEARIZATION_RTOL = 1e-3
#: The most iterations of the loop.
LINEARIZATION_ITERATIONS = 30
#: Modes of period at least this times T_eff get the isolators' effective damping (EN 1998-2 7.5.5(4)).
ISOLATION_PERIOD_SHARE = 0.8


@result_type
@dataclass(frozen=True, eq=False)
class EffectiveLinearization(Result):
    """Result of :func:`effective_linearization_loop`: its iterations and the final analysis.

    Attributes
    ----------
    axes : tuple of str
        The hysteretic mount axes, ``"<mount> <u|v|w>"``.
    design_displacement : ndarray, shape (iteration, axis)
        The design displacement each iteration linearized at [m] (the first: the starting guess).
    stiffness, damping : ndarray, shape (iteration, axis)
        The effective stiffness [N/m] and damping ratio [1] of each axis there.
    system_damping : ndarray, shape (iteration,)
        The isolation system's effective damping ratio [1] (EN 1998-2 eq. (7.9)).
    effective_period : ndarray, shape (iteration,)
        T_eff [s].
    change : ndarray, shape (iteration,)
        The largest relative change [1] of a stiffness or of the system's damping from the iteration before (inf
        for the first).
    response : ResponseSpectrum
        The analysis of the converged system.
    rtol : float
        The convergence tolerance on ``change`` [1].
    """

    axes: tuple[str, ...] = quantity("", ("isolator_axis",), name="isolator_axis",
                                     decode=lambda a: tuple(str(x) for x in a))
    design_displacement: np.ndarray = quantity("m", ("iteration", "isolator_axis"))
    stiffness: np.ndarray = quantity("N/m", ("iteration", "isolator_axis"))
    damping: np.ndarray = quantity("1", ("iteration", "isolator_axis"))
    system_damping: np.ndarray = quantity("1", ("iteration",))
    effective_period: np.ndarray = quantity("s", ("iteration",))
    change: np.ndarray = quantity("1", ("iteration",))
    response: ResponseSpectrum = part(ResponseSpectrum, group="converged")
    rtol: float = label(decode=float)


def system_damping(stiffness, displacement, damping) -> float:
    """EN 1998-2 eq. (7.9): ``sum_k xi_k K_k D_k^2 / sum_k K_k D_k^2`` [1] of the axes' effective stiffnesses
    [N/m], design displacements [m] and damping ratios [1]."""
    energy = np.asarray(stiffness, dtype=float) * np.asarray(displacement, dtype=float) ** 2
    total = float(energy.sum())
    return float(np.dot(damping, energy) / total) if total > 0 else float(np.mean(damping))


def isolation_damping(response: ResponseSpectrum, xi_eff: float, damping: float) -> tuple[np.ndarray, float]:
    """Each mode's damping ratio (EN 1998-2 7.5.5(4), see the module) and T_eff [s], from an analysis
    ``response`` of the linearized system: ``xi_eff`` for the modes of period >= 0.8 T_eff, ``damping`` else."""
    fundamental = np.argmax(response.effective_mass, axis=1)  # per direction
    t_eff = float(np.min(response.period[fundamental]))
    ratios = np.where(response.period >= ISOLATION_PERIOD_SHARE * t_eff, xi_eff, damping)
    return ratios, t_eff


def effective_linearization_loop(linearize: Callable, settings, axes: Sequence[tuple[int, int]], start, *,
                                 rtol: float = LINEARIZATION_RTOL,
                                 max_iterations: int = LINEARIZATION_ITERATIONS) -> EffectiveLinearization:
    """Iterate the design displacements of the hysteretic axes until their effective stiffness and damping
    agree (see the module).

    Parameters
    ----------
    linearize : callable
        ``linearize(D) -> (system, xi_eff)``: for design displacements ``D`` (n_axes,) [m], the
        :class:`~sixdof.model.system.System` with the effective stiffnesses on ``axes`` and the effective damping
        ratio of each axis (n_axes,) [1].
    settings : sixdof.excitation.spectra.SpectrumSettings
        The spectrum; its ``damping`` is the other modes'.
    axes : sequence of (int, int)
        (mount index, axis index 0-2 for u, v, w) of each hysteretic axis.
    start : array_like, shape (n_axes,)
        The first design displacements [m], > 0.
    rtol : float
        Convergence: the relative change [1] of every stiffness and of the system's damping.
    max_iterations : int

    Returns
    -------
    EffectiveLinearization

    Raises
    ------
    InputError
        For no axes or a ``start`` that is not one positive displacement per axis.
    SolverError
        When the loop has not converged after ``max_iterations``, with its last changes.
    """
    axes = [(int(m), int(a)) for m, a in axes]
    D = np.asarray(start, dtype=float)
    if not axes or D.shape != (len(axes),) or not np.all(D > 0):
        raise InputError("start", f"{len(axes)} design displacements > 0 in m, one per hysteretic axis (at least one)",
                         Plain(str(np.asarray(start).tolist())))
    rows = {"D": [], "k": [], "xi": [], "system": [], "period": [], "change": []}
    previous, response = None, None
    for _ in range(max_iterations):
        system, xi = linearize(D)
        xi = np.asarray(xi, dtype=float)
        k = np.asarray([system.stiffnesses[m, a] for m, a in axes])
        xi_system = system_damping(k, D, xi)
        change = np.inf if previous is None else max(
            float(np.max(np.abs(k - previous[0]) / previous[0])),
            abs(xi_system - previous[1]) / max(previous[1], np.finfo(float).tiny))
        # T_eff and the isolation modes from the linearized system's own modes, at the analysis's damping.
        ratios, t_eff = isolation_damping(response_spectrum(system, settings), xi_system, settings.damping)
        response = response_spectrum(system, settings, mode_damping=ratios)
        for key, value in (("D", D), ("k", k), ("xi", xi), ("system", xi_system), ("period", t_eff),
                           ("change", change)):
            rows[key].append(value)
        if change < rtol:
            break
        previous = (k, xi_system)
        D = np.array([response.combined_mount_deflection[m, a] for m, a in axes])
    else:
        raise SolverError(f"the effective linearization did not converge in {max_iterations} iterations: the last "
                          f"relative changes of the effective stiffness or damping were "
                          f"{', '.join(f'{c:.3g}' for c in rows['change'][-3:])} (tolerance {rtol:g})")
    names = tuple(f"{response.mounts[m]} {'uvw'[a]}" for m, a in axes)
    return EffectiveLinearization(
        axes=names, design_displacement=readonly(rows["D"]), stiffness=readonly(rows["k"]),
        damping=readonly(rows["xi"]), system_damping=readonly(rows["system"]),
        effective_period=readonly(rows["period"]), change=readonly(rows["change"]), response=response, rtol=rtol)


def isolated_spectrum(system, settings) -> EffectiveLinearization | None:
    """The effective-linearization loop (:func:`effective_linearization_loop`) of ``system``'s hysteretic axes with
    ``linearization = "effective"`` (:attr:`~sixdof.model.system.System.hysteretic`), from their design
    displacements; ``None`` for a system without any (its analysis is :func:`response_spectrum` of its
    linearization). The other axes keep the linearization they state; damping enters through the modes
    (:func:`isolation_damping`), not through the equivalent dashpots of :attr:`System.dampings`."""
    h = system.hysteretic
    effective = h.effective_axes
    if not effective.any():
        return None
    base = system.linearized()
    chosen = np.flatnonzero(effective)

    def linearize(D):
        k_eff, xi = h.effective(np.where(effective, _spread(D, chosen, h.count), 1.0))
        stiffness = np.array(base.stiffnesses)
        stiffness[h.mount[chosen], h.axis[chosen]] = k_eff[chosen]
        mounts = [dataclasses.replace(m, stiffness=k) for m, k in zip(base.mounts, stiffness)]
        return dataclasses.replace(base, mounts=mounts), xi[chosen]

    axes = [(int(h.mount[e]), int(h.axis[e])) for e in chosen]
    return effective_linearization_loop(linearize, settings, axes, h.design_displacement[chosen])


def _spread(values, where: np.ndarray, size: int) -> np.ndarray:
    full = np.ones(size)
    full[where] = values
    return full
