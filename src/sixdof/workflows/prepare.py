"""A loaded scenario made ready to compute: the fits, statics and checks that loading leaves out.

Loading a scenario (:func:`sixdof.io.scenario.load_scenario`) parses and validates its file only. What needs
computing before a run can start happens here, once, at the start of every workflow: the Maxwell models of
measured dynamic stiffness, the static equilibrium nonlinear mounts are linearized about, gravity's preload
(geometric stiffness), the causal models of loss factors, and the checks that need the modes (a frequency
grid point on an undamped resonance, a superposition truncation that keeps no mode). Its errors name the
scenario's fields as loading's do.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from sixdof.analysis.frf import check_resonances
from sixdof.analysis.statics import at_equilibrium, gravity_statics, with_gravity_preload
from sixdof.analysis.superposition import Plan
from sixdof.errors import InputError, Plain
from sixdof.io.scenario import PreparedModel, Scenario, causal_model, load_scenario
from sixdof.model.viscoelastic import fit_maxwell, with_fits
from sixdof.schema import naming


def prepare(scenario: Scenario | str | Path) -> Scenario:
    """``scenario`` with its model prepared (:class:`~sixdof.io.scenario.PreparedModel`); a path is loaded first.

    A scenario prepared already is returned as it is.

    Parameters
    ----------
    scenario : Scenario or str or pathlib.Path
        A scenario, or the path of a scenario file.

    Returns
    -------
    Scenario
        The same scenario with its ``model`` set: the systems the frequency and time paths take
        (measured dynamic stiffness and loss factors as Maxwell models, gravity's preload, nonlinear
        mounts at their static equilibrium).

    Raises
    ------
    sixdof.errors.ScenarioError
        Naming the file and the field: a measured dynamic stiffness the Maxwell model cannot fit within its
        limits, mounts that cannot carry the weight with ``geometric_stiffness``, a loss factor band without
        a natural frequency, a frequency grid point on an undamped resonance, a truncation keeping no mode.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if scenario.model is not None:
        return scenario
    with naming(scenario.path or "<string>"):  # as loading names a scenario read from text
        return dataclasses.replace(scenario, model=_model(scenario))


def _model(scenario: Scenario) -> PreparedModel:
    system = scenario.given_system
    fits = [(m.mount, m.axis, _fitted(m)) for m in scenario.measured]
    system = with_fits(system, fits) if fits else system
    statics = scenario.statics
    # Linearized about its static equilibrium, which the nonlinear statics find; a friction pendulum carries the load
    # it has there.
    if system.nonlinear.count or system.friction_pendulum:
        system = at_equilibrium(system, gravity_statics(system, statics.gravity, statics.direction))
    if statics.geometric_stiffness:  # before any computation: mounts that cannot carry the weight have no preload
        system = _preloaded(system, statics.vector)
    time_system, causal = system, ()
    lossy = scenario.loss_factor_model != "hysteretic" and bool(np.any(system.loss_factors))
    if lossy:
        time_system, causal = causal_model(system, scenario.excitation, scenario.loss_factor_band_hz,
                                           scenario.loss_factor_terms)
        if system.geometric_stiffness:  # the preload of the long-term stiffnesses that replaced the mounts' own
            time_system = with_gravity_preload(time_system, system.gravity_preload)
    if scenario.loss_factor_model == "maxwell":
        system = time_system
    if scenario.frf is not None:  # before any computation: a grid point on an undamped resonance has no response
        check_resonances(system, scenario.frf.grid(), "frf.f_hz")
    settings = scenario.superposition
    if settings.n_modes is not None or settings.f_max_hz is not None:
        _check_truncation(system, settings)
    return PreparedModel(system=system, time_system=time_system,
                         viscoelastic=tuple(fit for _, _, fit in fits) + causal)


def _fitted(measured):
    """The Maxwell model of a mount axis's measured dynamic stiffness, within the table's limits."""
    fit = fit_maxwell(measured.f_hz, measured.storage, measured.loss, measured.terms, field=measured.field)
    if fit.modulus_error > measured.max_modulus_error or fit.loss_angle_error_deg > measured.max_loss_angle_error_deg:
        raise InputError(measured.field, f"a Maxwell fit within {100 * measured.max_modulus_error:g} % in |K*| and "
                         f"{measured.max_loss_angle_error_deg:g} deg in loss angle over the data (raise terms, or the "
                         "limits max_modulus_error and max_loss_angle_error_deg)",
                         Plain(f"{100 * fit.modulus_error:.3g} % and {fit.loss_angle_error_deg:.3g} deg with "
                               f"{fit.stiffness.size} terms over {fit.f_hz[0]:g}-{fit.f_hz[-1]:g} Hz of "
                               f"{measured.file}"))
    return dataclasses.replace(fit, name=f"{measured.mount} {measured.axis}", source=measured.file)


def _preloaded(system, vector):
    """``system`` carrying gravity's preload, checked for a stiffness that still carries the weight."""
    system = with_gravity_preload(system, vector)
    try:
        system.modes  # noqa: B018 (K raises InputError naming statics.geometric_stiffness; the modes, field K)
    except InputError as exc:
        if exc.field != "K":
            raise
        raise InputError("statics.geometric_stiffness", "false, or mounts whose rocking stiffness carries the "
                         "weight above them (K + K_G positive semi-definite)",
                         Plain("K + K_G with a negative eigenvalue: the body would tip over on these mounts")) from None
    return system


def _check_truncation(system, settings) -> None:
    """A truncation (``n_modes``, ``f_max_hz``) that keeps no mode, or with Maxwell branches, refused before the
    run as the superposition would refuse it after the direct solve (the same checks: its plan)."""
    try:
        Plan(system.M, system.C, system.modes, settings.method, settings.n_modes, settings.f_max_hz,
             system.branches if system.branches.count else None)
    except InputError as error:
        raise error.within("superposition") from None
