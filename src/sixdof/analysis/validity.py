"""Where a time solve leaves the model's range, said as warnings: loads that never act in the simulated
time, and rotations beyond small-angle theory; statics no mount could give (:func:`static_range`); and a ground
record whose integrated displacement drifts (:func:`ground_drift`).

Both time paths (:func:`sixdof.analysis.direct.simulate`, :func:`sixdof.analysis.superposition.superpose`)
call the first two, so a notebook user of either one is told; the results are computed all the same. The drift
is judged by a run (:func:`sixdof.workflows.run.run_scenario`) over its whole span, once: not by the inner solves of
the checks that synthesize records of their own (a random record's displacement wanders by nature).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from sixdof.analysis.compare import column_peaks
from sixdof.analysis.statics import STANDARD_GRAVITY, with_gravity_preload
from sixdof.dofs import DOFS, display_unit
from sixdof.errors import InputError
from sixdof.model.modes import modal_analysis
from sixdof.model.viscoelastic import LOSS_FACTOR_TARGET, LOSS_MODULUS_TARGET, maxwell_stiffness

#: Largest rotation [rad] for which eq. (1) holds: it linearizes the rotations (sin theta ~ theta,
#: cos theta ~ 1), whose error grows as theta^2 / 2, 0.5 % at 0.1 rad (5.7 deg).
SMALL_ANGLE_RAD = 0.1


class RangeWarning(UserWarning):
    """The input or the response leaves the range where the model means something."""


def warn_idle(excitation, t0: float, t1: float) -> None:
    """One :class:`RangeWarning` per load (or ground motion) that is zero over the whole run ``[t0, t1]`` [s]."""
    for what in excitation.idle(t0, t1):
        warnings.warn(f"{what}, so it never acts in the simulated time [{t0:.6g}, {t1:.6g}] s", RangeWarning,
                      stacklevel=3)


def warn_large_rotations(t: np.ndarray, q: np.ndarray) -> None:
    """A :class:`RangeWarning` naming every rotation beyond :data:`SMALL_ANGLE_RAD`, with its peak and time.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Times [s].
    q : ndarray, shape (n, 6)
        Displacements [m, rad] (the rotations are the last three columns).
    """
    rotations = np.asarray(q)[:, 3:]
    peaks = column_peaks(rotations)
    beyond = [
        f"|{DOFS[3 + j]}| reaches {peaks[j]:.3g} rad ({math.degrees(peaks[j]):.3g} deg) at "
        f"t = {t[int(np.argmax(np.abs(rotations[:, j])))]:.6g} s"
        for j in np.flatnonzero(peaks > SMALL_ANGLE_RAD)
    ]
    if beyond:
        warnings.warn(
            f"rotations beyond small-angle theory: {'; '.join(beyond)}. Eq. (1) is linear in the rotations, "
            f"valid to |theta| <= {SMALL_ANGLE_RAD:g} rad ({math.degrees(SMALL_ANGLE_RAD):.3g} deg, error "
            f"theta^2/2 = {SMALL_ANGLE_RAD**2 / 2:.1%}); the response computed is that of the linear model",
            RangeWarning, stacklevel=3,
        )


def body_length(system) -> float:
    """A length [m] for the body: half its box diagonal when its ``dimensions`` are given; else the larger of
    the farthest mount from the CG and half the diagonal of the uniform box of the body's mass and inertia
    (:attr:`~sixdof.model.parts.RigidBody.inertia_box`, ``sqrt(1.5 trace(J) / m)``)."""
    body = system.body
    if body.dimensions is not None:
        return float(np.linalg.norm(body.dimensions) / 2)
    # The mounts alone can be arbitrarily near the CG (one mount under it): the inertia says the body's size.
    return float(max(np.linalg.norm(system.positions, axis=1).max(), np.linalg.norm(body.inertia_box) / 2))


def static_range(statics, system) -> list[str]:
    """What is out of range in a static equilibrium under gravity (``statics``, or None): a rotation beyond
    :data:`SMALL_ANGLE_RAD`, or a sag of the CG larger than :func:`body_length` (no mount is linear over
    such a stroke: typically stiffness given in N/mm where N/m is meant). One message each; none: []."""
    if statics is None:
        return []
    messages = []
    sag, tilt = float(np.linalg.norm(statics.q[:3])), float(np.max(np.abs(statics.q[3:])))
    length = body_length(system)
    if sag > length:
        messages.append(f"the static deflection under gravity, {1e3 * sag:.4g} mm at the CG, exceeds the body's "
                        f"half-size ({1e3 * length:.4g} mm): no mount is linear over such a stroke. Are the "
                        "stiffnesses in N/m (not N/mm)?")
    if tilt > SMALL_ANGLE_RAD:
        messages.append(f"the static rotation under gravity, {tilt:.3g} rad ({math.degrees(tilt):.3g} deg), is "
                        f"beyond small-angle theory (|theta| <= {SMALL_ANGLE_RAD:g} rad): the body would tip far "
                        "over on these mounts; the results are those of the linear model")
    return messages


def variants_fit_range(fits, f_hz) -> list[str]:
    """What a sweep's variants' natural frequencies ``f_hz`` [Hz] (their lowest and highest, say) reach that the
    scenario's Maxwell fits do not vouch for: the variants share the nominal's fits, scaled with their stiffness.
    A measured table's fit beyond its table's band (:func:`fit_band_range`); a loss factor's causal model at a
    frequency beyond those it was checked at where it misses ``k (1 + i eta)`` by more than its targets
    (:data:`~sixdof.model.viscoelastic.LOSS_MODULUS_TARGET` in ``|K*|``,
    :data:`~sixdof.model.viscoelastic.LOSS_FACTOR_TARGET` in loss factor). One message each; none: []."""
    advice = ("the variants share the nominal's models, scaled with their stiffness; a variant of interest run as a "
              "scenario of its own has models checked at its own frequencies")
    causal = [fit for fit in fits if fit.source.startswith("loss factor ")]
    messages = fit_band_range([fit for fit in fits if fit not in causal], f_hz,
                              "the variants' natural frequencies reach", advice)
    missing: dict[tuple, list[str]] = {}  # the same miss (a loss factor's models alike but for k): one message
    for fit in causal:
        outside = np.array([f for f in np.atleast_1d(f_hz) if not fit.f_hz[0] <= f <= fit.f_hz[-1]], dtype=float)
        if not outside.size:
            continue
        k = maxwell_stiffness(outside, fit.long_term, fit.stiffness, fit.tau)
        eta = fit.loss_factor[0]
        modulus = np.abs(np.abs(k) / (fit.storage[0] * math.hypot(1.0, eta)) - 1)
        loss = np.abs(k.imag / k.real / eta - 1)
        missed = (modulus > LOSS_MODULUS_TARGET) | (loss > LOSS_FACTOR_TARGET)
        if np.any(missed):
            at = "; ".join(f"{100 * m:.3g} % in |K*| and {100 * e:.3g} % in loss factor at {f:.4g} Hz"
                           for f, m, e in zip(outside[missed], modulus[missed], loss[missed]))
            missing.setdefault((fit.source, f"{fit.f_hz[0]:.4g}-{fit.f_hz[-1]:.4g}", at), []).append(fit.name)
    for (source, band, at), names in missing.items():
        messages.append(f"the variants' natural frequencies reach beyond the {band} Hz where the causal Maxwell "
                        f"model of {source} ({', '.join(names)}) was checked; its time responses there miss "
                        f"k (1 + i eta) by {at} (targets {100 * LOSS_MODULUS_TARGET:g} % and "
                        f"{100 * LOSS_FACTOR_TARGET:g} %): {advice}")
    return messages


#: A body's inertia is at most that of a uniform box sqrt(3) times its own (all its mass in the corners): one whose
#: inertia is that of a box this many times larger or smaller than its ``dimensions`` has its mass, inertia or
#: dimensions in other units (mass in t with inertia in kg m^2: 31.6 times).
INERTIA_BOX_RATIO = 3.0
#: Bulk densities [kg/m^3] of a body's ``dimensions`` box that a body can have: from 5 (four times air, an empty
#: enclosure's sheet metal) to 25,000 (past osmium, 22,590); the bundled bodies lie at 320-1,070.
DENSITY_RANGE = (5.0, 25e3)
#: The mean density [kg/m^3] of a mounted body, for naming the likely slip of one outside :data:`DENSITY_RANGE`.
_TYPICAL_DENSITY = 800.0
#: A mount, point or load this many times the body's half-size away from the CG is not on the body: positions in
#: mm where m are meant (1000 times), or a body far smaller than its mounts say.
REACH_RATIO = 10.0
#: A rotating unbalance loads the body with at most a few times its weight (vibrating screens and feeders, made to
#: shake, reach 5); this many times is a speed in rev/min given as Hz (3600 times the force) or m e in g mm.
UNBALANCE_WEIGHT_RATIO = 10.0
#: The unit slips the magnitude checks name, as the factor by which the value given is too small (a mass in t
#: typed where kg are meant is 1000 times too small), recognized within a factor 3 either way.
_SLIPS = ((1e3, "tonnes"), (1e-3, "grams"))


def _slip(factor: float, slips) -> str | None:
    """The slip of ``slips`` (factor, name) whose factor lies within a factor 3 of ``factor``, or None."""
    return next((name for size, name in slips if abs(math.log10(factor / size)) < math.log10(3.0)), None)


def _vector(values) -> str:
    return "[" + ", ".join(f"{v:.4g}" for v in values) + "]"


def _newtons(value: float) -> str:
    factor, unit = display_unit(value, "N")
    return f"{value * factor:.4g} {unit}"


def _body_magnitudes(body) -> str | None:
    """What in a body's mass, inertia and dimensions cannot be one body's, with the likely slip; or None."""
    if body.dimensions is None:
        return None
    box, dimensions = body.inertia_box, np.asarray(body.dimensions, dtype=float)
    ratio = float(np.linalg.norm(box) / np.linalg.norm(dimensions))
    if not 1 / INERTIA_BOX_RATIO <= ratio <= INERTIA_BOX_RATIO:
        # The inertia's box scales as sqrt(J / m): a mass k times too small makes it sqrt(k) times too large.
        slip = _slip(ratio**2, _SLIPS)
        likely = (f" Is the mass in {slip}? {body.mass * ratio**2:.4g} kg would match the dimensions" if slip else
                  " Check the units of mass [kg], inertia [kg m^2] and dimensions [m]")
        return (f"body: the inertia {_vector(np.diag(body.inertia))} kg m^2 with the mass {body.mass:.4g} kg is that "
                f"of a uniform {' x '.join(f'{v:.3g}' for v in box)} m box, {ratio:.3g} times the body's dimensions "
                f"{_vector(dimensions)} m (no spread of its mass makes it more than {math.sqrt(3):.2f} times).{likely}")
    density = body.mass / float(np.prod(dimensions))
    low, high = DENSITY_RANGE
    if not low <= density <= high:
        slip = _slip(_TYPICAL_DENSITY / density, _SLIPS)
        likely = (f" Is the mass in {slip}?" if slip else
                  " Check the units of mass [kg] and dimensions [m] (in mm they make a box 10^9 times larger)")
        return (f"body: the mass {body.mass:.4g} kg in its {' x '.join(f'{v:.4g}' for v in dimensions)} m box is a "
                f"mean density of {density:.3g} kg/m^3, outside the {low:g}-{high:g} kg/m^3 a body can have.{likely}")
    return None


def implausible_inputs(system, excitation=None, points=None) -> list[str]:
    """What in a model's magnitudes looks like a slip of units, with the numbers and the likely slip: a mass
    that does not match the body's inertia and dimensions (given in t, or g), positions far off the body (in mm),
    a rotating unbalance that would shake the body with many times its weight (a speed in rev/min given as Hz),
    and a mount set that leaves a motion unresisted (a mechanism). The N/mm check of the stiffnesses is
    :func:`static_range`'s. One message each; none: [].

    Parameters
    ----------
    system : sixdof.model.system.System
    excitation : sixdof.excitation.Excitation, optional
        Its loads' points and unbalances are checked.
    points : mapping of str to array_like, optional
        Named body points [m] from the CG (the scenario's ``[[points]]``).
    """
    body = system.body
    body_message = _body_magnitudes(body)
    messages = [body_message] if body_message else []
    if body.dimensions is not None:
        half, size = float(np.linalg.norm(body.dimensions) / 2), "its dimensions"
    else:
        half, size = float(np.linalg.norm(body.inertia_box) / 2), "the uniform box of its mass and inertia"
    loads = () if excitation is None else excitation.loads
    located = [(f"mounts[{j}] ({name})", p) for j, (name, p) in enumerate(zip(system.mount_names, system.positions))]
    located += [(f"points ({name})", p) for name, p in (points or {}).items()]
    located += [(f"loads[{i}] ({load.name})", load.point) for i, load in enumerate(loads)]
    far = [(what, np.asarray(p, dtype=float)) for what, p in located
           if half > 0 and np.linalg.norm(p) > REACH_RATIO * half]
    if far:
        what, p = max(far, key=lambda item: np.linalg.norm(item[1]))
        reach = float(np.linalg.norm(p))
        likely = (f" Are the positions in mm? In m this one would be {_vector(p / 1e3)}"
                  if _slip(reach / half, ((1e3, "mm"),)) else " Check that positions are in m from the CG")
        messages.append(f"{len(far)} position(s) lie more than {REACH_RATIO:g} times the body's half-size "
                        f"({half:.4g} m, from {size}) from the CG, farthest {what} at {_vector(p)} m, "
                        f"{reach:.4g} m away ({reach / half:.3g} times).{likely}")
    reach = float(np.linalg.norm(system.positions, axis=1).max())
    if body.dimensions is None and not far and 0 < REACH_RATIO * reach < half:  # all at the CG: a mechanism, said
        # Mounts hold the body where it is: all of them deep inside its inertia's box is a mass too small for it.
        body_message = (f"body: the mounts all lie within {reach:.4g} m of the CG, {half / reach:.3g} times less than "
                        f"the half-size of the uniform box of the mass {body.mass:.4g} kg and inertia "
                        f"{_vector(np.diag(body.inertia))} kg m^2 ({half:.4g} m). Is the mass in tonnes with the "
                        "inertia in kg m^2? (Give the body's dimensions to have it checked against them)")
        messages.append(body_message)
    weight = body.mass * STANDARD_GRAVITY
    for i, load in enumerate(loads):
        # A mass in other units already said so: the weight the force is measured against is wrong with it.
        if body_message or load.kind != "unbalance" or load.force_amplitude <= UNBALANCE_WEIGHT_RATIO * weight:
            continue
        f, force = load.frequency_hz, load.force_amplitude
        likely = (f" Is {f:g} a speed in rev/min? That is {f / 60:.4g} Hz and {_newtons(force / 3600)} (give it as "
                  "speed_rpm)" if load.f_hz is not None else
                  " Is the unbalance in g mm? m e is in kg m (1 g mm = 1e-6 kg m)")
        messages.append(f"loads[{i}] ({load.name}): the unbalance force m e Omega^2 is {_newtons(force)} at {f:.4g} "
                        f"Hz, {force / weight:.3g} times the body's weight ({_newtons(weight)}); a machine's "
                        f"unbalance shakes it with at most a few times its weight.{likely}")
    modes = system.modes
    if modes.zero_modes:
        messages.append(f"the mounts leave the body unrestrained (a mechanism): {len(modes.zero_modes)} "
                        f"zero-frequency mode(s), motions no mount resists, involving {', '.join(modes.free_dofs)}")
    return messages


#: What :func:`fit_band_range` advises by default.
_FIT_ADVICE = ("a band (loss_factor_band_hz) or a table (dynamic_stiffness) reaching it models the mount there as "
               "given")


def fit_band_range(fits, f_hz, what: str = "steady state at", advice: str = _FIT_ADVICE) -> list[str]:
    """What lies outside the band of a Maxwell fit (:class:`~sixdof.model.viscoelastic.MaxwellFit`) among the
    frequencies ``f_hz`` [Hz] (``what`` says which: by default the steady state's operating frequencies): there the
    mount is the fit's extrapolation, which neither its table nor its loss factor vouches for. One message per
    band and source, ending with ``advice``; none: []."""
    groups: dict[tuple, list] = {}
    for fit in fits:
        groups.setdefault((fit.f_hz[0], fit.f_hz[-1], fit.source), []).append(fit)
    messages = []
    for (low, high, source), members in groups.items():
        outside = [float(f) for f in np.atleast_1d(f_hz) if not low <= f <= high]
        if not outside:
            continue
        first = members[0]
        k = maxwell_stiffness(np.array(outside), first.long_term, first.stiffness, first.tau)
        at = "; ".join(f"K' {kf.real / 1e3:.4g} kN/m and loss factor {kf.imag / kf.real:.3g} at {f:.4g} Hz"
                       for f, kf in zip(outside, k))
        messages.append(f"{what} {', '.join(f'{f:.4g}' for f in outside)} Hz, outside the "
                        f"{low:.3g}-{high:.3g} Hz band of the Maxwell fit of {', '.join(m.name for m in members)} "
                        f"(fitted to {source}): there the mount is the fit's extrapolation ({first.name}: {at}); "
                        + advice)
    return messages


#: A ground displacement integrated from a velocity or an acceleration drifts when its value at the end of a
#: run is beyond this share of its peak over the run (once the record is over): a record that ends at rest
#: ends near zero; a baseline offset ends near the peak (0.1 % of a 0.25 g peak over 20 s: 0.5 m).
GROUND_DRIFT_SHARE = 0.1


class GroundDriftWarning(RangeWarning):
    """The ground displacement integrated from the record drifts (see :data:`GROUND_DRIFT_SHARE`)."""


def ground_drift(ground, t, displacement) -> str | None:
    """What drifts in a run's recorded ground motion (a :class:`~sixdof.excitation.GroundMotion`), or None.

    A ground recorded as a velocity or an acceleration (a ``table`` signal) is integrated from rest; it drifts
    when its displacement at the run's end is beyond :data:`GROUND_DRIFT_SHARE` of its peak over the run, which
    in a record is a baseline error. Judged once the record is over (one that runs past the end of the run is
    still moving there), or for one held without end. Signals given by formula are left alone: a shock pulse's
    change of velocity, and the drift it makes, is the motion asked for.

    Parameters
    ----------
    ground : GroundMotion
    t : ndarray, shape (n,)
        The run's output times [s], increasing.
    displacement : ndarray, shape (n, 3)
        The ground's displacement [m], body axes (:attr:`sixdof.results.TimeHistory.ground_displacement`).

    Returns
    -------
    str or None
        The message: the end value, its share of the peak and the advice to use ``[ground] baseline``.
    """
    if ground.quantity == "displacement" or ground.signal.kind != "table" or len(t) == 0:
        return None
    over = ground.signal.support[1]
    if math.isfinite(over) and over > t[-1]:  # the record goes on after the run: the ground is still moving
        return None
    along = np.asarray(displacement) @ ground.direction
    peak, end = float(np.max(np.abs(along))), float(along[-1])
    if peak == 0.0 or abs(end) <= GROUND_DRIFT_SHARE * peak:
        return None
    factor, unit = display_unit([peak, end], "m")
    # A corrected accelerogram ends at rest (to round-off), so the advice is always one of these.
    advice = ("Correct the velocity record's baseline before use ([ground] baseline corrects accelerograms)"
              if ground.quantity == "velocity" else
              'Set [ground] baseline = "polynomial" to bring the record to rest at its end')
    return (f"ground motion: its displacement, integrated from the {ground.quantity} from rest, ends at "
            f"{end * factor:.4g} {unit} at t = {t[-1]:.6g} s, {100 * abs(end) / peak:.3g} % of its peak "
            f"{peak * factor:.4g} {unit} (a drift: beyond {100 * GROUND_DRIFT_SHARE:g} %), most likely a baseline "
            "error of the record; the body's absolute motion drifts with it, the mounts feel only the motion "
            f"relative to the ground. {advice}")


#: A natural frequency that gravity's geometric stiffness moves by more than this share is worth a line when K
#: leaves it out (:func:`geometric_stiffness_note`).
GEOMETRIC_SHIFT = 0.01


def geometric_stiffness_shifts(system, gravity) -> np.ndarray | None:
    """How much gravity's geometric stiffness (:attr:`sixdof.model.system.System.K_geometric`) moves each natural
    frequency: ``f_with / f_without - 1`` (6,) per mode in ascending order (NaN for a zero-frequency mode), under
    ``gravity`` (3,) [m/s^2, body axes] unless ``system`` already holds its own. The modes without it are those of
    :attr:`~sixdof.model.system.System.K_mounts`. None when the mounts cannot carry the weight (no preload).

    Raises
    ------
    InputError
        (field ``K``) When ``K + K_G`` is not positive semi-definite: the body would tip over.
    """

    try:  # the preload's statics: mounts that cannot carry the weight have none
        preloaded = system if system.geometric_stiffness else with_gravity_preload(system, gravity)
        K = preloaded.K
    except InputError as exc:
        if exc.field == "K":
            raise
        return None
    with_, without = (modal_analysis(system.M, k).frequency_hz for k in (K, system.K_mounts))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(without > 0, with_ / np.where(without > 0, without, 1.0) - 1.0, np.nan)


def geometric_stiffness_note(system, gravity) -> str | None:
    """One line on gravity's geometric stiffness: with it in K, that it is and the largest shift of a mode it
    makes; without it, only when it would move a mode by more than :data:`GEOMETRIC_SHIFT`, which mode and how
    much (:func:`geometric_stiffness_shifts`). None otherwise."""
    try:
        shifts = geometric_stiffness_shifts(system, gravity)
    except InputError as exc:  # K + K_G not positive semi-definite: the preload tips the body over
        if exc.field != "K":
            raise
        return ("gravity's geometric stiffness would leave K + K_G with a negative eigenvalue: the body would tip "
                "over on these mounts (mounts below the CG too soft in rocking for the weight they carry)")
    if shifts is None or not np.any(np.isfinite(shifts)):
        return None
    j = int(np.nanargmax(np.abs(shifts)))
    shift = float(shifts[j])
    mode = f"mode {j + 1} ({system.modes.dominant_dof[j]})"
    if system.geometric_stiffness:
        return (f"K includes gravity's geometric stiffness ([statics] geometric_stiffness = true): it moves "
                f"{mode} most, by {100 * shift:+.2g} %")
    if abs(shift) <= GEOMETRIC_SHIFT:
        return None
    return (f"gravity's geometric stiffness would {'lower' if shift < 0 else 'raise'} {mode} by "
            f"{100 * abs(shift):.2g} %; [statics] geometric_stiffness = true includes it")


__all__ = ["DENSITY_RANGE", "GEOMETRIC_SHIFT", "GROUND_DRIFT_SHARE", "INERTIA_BOX_RATIO", "REACH_RATIO",
           "SMALL_ANGLE_RAD", "UNBALANCE_WEIGHT_RATIO", "GroundDriftWarning", "RangeWarning", "body_length",
           "fit_band_range", "geometric_stiffness_note", "geometric_stiffness_shifts", "ground_drift",
           "implausible_inputs", "static_range", "variants_fit_range", "warn_idle", "warn_large_rotations"]
