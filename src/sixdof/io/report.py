"""The text of a run: the tables ``sixdof run`` and ``sixdof modes`` print and the run's ``summary.md``, laid out
by :func:`sixdof.io.tables.table` (a sweep's, an optimization's and a validation's text:
:mod:`sixdof.io.study_report`)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sixdof.analysis.compare import QUANTITIES
from sixdof.analysis.isolation_summary import has_operating, run_isolation_summary
from sixdof.analysis.statespace import damped_modes
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.analysis.steady import vector_amplitude
from sixdof.analysis.validity import body_length
from sixdof.dofs import AXES, DOF_UNITS, DOFS, display_unit
from sixdof.io.severity_report import severity_part
from sixdof.io.tables import fixed, table, without_round_off, wrapped
from sixdof.model.viscoelastic import FIT_LOSS_ANGLE_ERROR_DEG, FIT_MODULUS_ERROR, long_term_note, loss_fit_misses


def modes_table(modes, damping_ratios=None, system=None) -> str:
    """Natural frequencies, dominant DOF and (optionally) damping ratio of each mode; with a ``system`` that
    has Maxwell branches, the frequency of each mode's pole in the full visco-elastic model too."""
    headers = ["mode", "f [Hz]", "omega [rad/s]", "dominant DOF", "KE in dominant [%]"]
    poles = None
    if system is not None and system.branches.count:
        poles, _ = damped_modes(system.C, modes, system.branches)
        headers.append("f full model [Hz]")
    if damping_ratios is not None:
        headers.append("zeta [%]")
    rows = []
    for j, (f, omega, dof) in enumerate(zip(modes.frequency_hz, modes.omega, modes.dominant_dof)):
        row = [j + 1, f"{f:.4f}", f"{omega:.4f}", dof, f"{100 * modes.ke_distribution[DOFS.index(dof), j]:.1f}"]
        if poles is not None:
            row.append("-" if not np.isfinite(poles[j]) else f"{abs(poles[j]) / (2 * np.pi):.4f}")
        if damping_ratios is not None:
            zeta = damping_ratios[j]
            # At or above critical a mode does not oscillate: its f is the undamped system's, not a frequency it shows.
            # inf: no oscillating pole and no single ratio (non-proportional damping), only the word.
            row.append("-" if np.isnan(zeta) else "overdamped" if np.isinf(zeta)
                       else f"{100 * zeta:.2f}" + (" overdamped" if zeta >= 1 else ""))
        rows.append(row)
    return table(headers, rows)


def damping_note(system) -> str:
    """What the printed damping ratios (zeta) include: the viscous damping models given, added together,
    and never the loss factors (hysteretic damping exists in the frequency domain only)."""
    given = [name for name, present in (("mount dashpots", np.any(system.dampings)),
                                        ("Maxwell branches", bool(system.maxwell)),
                                        ("Rayleigh damping", system.rayleigh is not None),
                                        ("modal damping ratios", system.modal_damping is not None)) if present]
    if not given:
        text = "zeta: no viscous damping is given (dashpots, Rayleigh or modal): every mode has zeta = 0"
    else:
        text = (f"zeta: the exact damping ratio of each mode (complex eigenvalues) from {' + '.join(given)}"
                + (", added together" if len(given) > 1 else ""))
    if system.maxwell:
        text += ("; f is each undamped mode of the long-term (static) stiffness, f full model the frequency "
                 "|lambda|/2pi of its pole in the full visco-elastic model (complex modes with the Maxwell branches)")
    if np.any(system.loss_factors):
        text += ("; not the mounts' loss factors, which the FRFs and the steady state take exactly, k (1 + i eta), "
                 "and the time response as their causal Maxwell models (damping.loss_factor_model)")
    hysteretic = system.hysteretic
    if hysteretic.count:
        kinds = sorted(set(hysteretic.linearization))
        text += (f"; the {hysteretic.count} hysteretic bearing axes enter the modes, damping ratios and FRFs at their "
                 + " or ".join(f"{kind} linearization" for kind in kinds)
                 + (" (the elastic stiffness, no damping)" if kinds == ["initial"] else
                    " (the secant stiffness and equivalent dashpot at the design displacement where effective)"))
    if system.nonlinear.count:
        text += ("; modes, damping ratios and FRFs are those of the linearization about the static equilibrium "
                 "(each nonlinear mount axis at its slope there), exact only while no stop engages and no mount "
                 "lifts off")
    return wrapped(text + ".")


#: Contact intervals listed in the text report (all are in the results file).
LISTED_INTERVALS = 12


def hysteresis_table(system, response, forces) -> str:
    """Each hysteretic mount axis over a direct solve: its law, peak deflection from rest and force (sampled),
    their ratio (the loop's secant stiffness at its peak) beside the linear paths' stiffness, and the peak of
    ``|z|`` (1: fully yielded)."""
    h = system.hysteretic
    d = response.q_relative @ h.rows.T
    force = forces.local[h.mount, :, h.axis].T
    linear = h.linear_stiffness
    rows = []
    moved = np.abs(d).max(axis=0) > 1e-9 * max(np.abs(d).max(), 1e-300)  # not round-off alone
    for e, name in enumerate(h.names):
        peak = int(np.argmax(np.abs(d[:, e])))
        secant = force[peak, e] / d[peak, e] if moved[e] else float("nan")
        rows.append([name, "friction pendulum" if h.pendulum[e] else "Bouc-Wen",
                     f"{1e3 * np.abs(d[:, e]).max():.4g}" if moved[e] else "0",
                     f"{1e-3 * np.abs(force[:, e]).max():.4g}" if moved[e] else "0",
                     f"{1e-3 * secant:.4g}" if moved[e] else "-",
                     f"{1e-3 * linear[e]:.4g} ({h.linearization[e]})",
                     f"{np.abs(response.hysteretic_state[:, e]).max():.3f}"])
    return table(["mount axis", "law", "peak deflection [mm]", "peak force [kN]", "secant at peak [kN/m]",
                  "linear paths' stiffness [kN/m]", "peak |z|"], rows)


def nonlinear_text(contacts, energy, refined, agreement, stats) -> str:
    """When and where the nonlinear mounts engaged, and the run's cross-checks while they did: the energy
    balance and the second solve at tighter tolerances (:class:`~sixdof.analysis.contact.ContactSummary`).
    ``agreement`` None: a run with hysteretic bearings, which are never compared with the superposition."""
    if agreement is None:
        return "\n".join([
            "Hysteretic bearings act from the start: the modal superposition (their linearization) is not compared; "
            "these check the run instead.", _energy_line(energy),
            f"Second solve at 100x tighter tolerances: {refined}"])
    mm = 1e3
    rows = []
    for e, name in enumerate(contacts.names):
        count = int(contacts.engagements[e])
        rows.append([name, contacts.kinds[e], str(count), "never" if not count else f"{contacts.first_t[e]:.6g}",
                     f"{contacts.engaged_time[e]:.4g}",
                     "-" if np.isnan(contacts.peak_penetration[e]) else f"{mm * contacts.peak_penetration[e]:.4g}",
                     "-" if np.isnan(contacts.peak_lift[e]) else f"{mm * contacts.peak_lift[e]:.4g}",
                     f"{mm * contacts.deflection_min[e]:.4g} to {mm * contacts.deflection_max[e]:.4g}"])
    lines = [f"{stats.num_events} changes of contact state, each located by root finding ({stats.num_accepted} "
             "steps); deflections are totals (static + dynamic), peaks sampled.",
             table(["mount axis", "nonlinear", "engaged", "first at [s]", "engaged for [s]", "peak penetration [mm]",
                    "peak lift [mm]", "deflection [mm]"], rows)]
    n = contacts.interval_start.size
    if n:
        shown = [f"{contacts.names[e]} {a:.6g}-{b:.6g} s" for e, a, b in
                 zip(contacts.interval_law[:LISTED_INTERVALS], contacts.interval_start, contacts.interval_end)]
        more = f" (and {n - LISTED_INTERVALS} more, in results.h5)" if n > LISTED_INTERVALS else ""
        lines.append("Engaged intervals: " + "; ".join(shown) + more)
    first = contacts.first_engaged_t
    lines.append("Modal superposition (the linearization): " + (
        f"compared until the first mount engaged, t = {first:.6g} s" if np.isfinite(first)
        else "no mount engaged, compared over the whole run") + f": {agreement}")
    lines.append(_energy_line(energy))
    lines.append(f"Second solve at 100x tighter tolerances: {refined}")
    return "\n".join(lines)


def _energy_line(energy) -> str:
    return (f"Energy balance (work of loads and ground = kinetic + stored + dissipated): worst residual "
            f"{energy.worst:.2e} of the largest energy ({energy.energy_scale:.4g} J) vs tolerance "
            f"{energy.tolerance:.0e}: {'ok' if energy.ok else 'FAILED'}")


def viscoelastic_table(fits) -> str:
    """Each Maxwell fit: what it models, its data, its long-term stiffness, branches and worst errors; and a
    note naming the fits that miss what they model by more than a measured table's fit may."""
    headers = ["mount axis", "fitted to", "band [Hz]", "long-term k0 [N/m]", "branches", "max |K*| error [%]",
               "max loss angle error [deg]", "max loss factor error [%]"]
    rows = [[fit.name, fit.source, f"{fit.f_hz[0]:.3g}-{fit.f_hz[-1]:.3g}", f"{fit.long_term:.4g}",
             str(int(np.count_nonzero(fit.stiffness))), f"{100 * fit.modulus_error:.2f}",
             f"{fit.loss_angle_error_deg:.2f}", f"{100 * fit.loss_factor_error:.2f}"] for fit in fits]
    loose = [fit for fit in fits if not fit.source.startswith("loss factor ")
             and (fit.modulus_error > FIT_MODULUS_ERROR or fit.loss_angle_error_deg > FIT_LOSS_ANGLE_ERROR_DEG)]
    notes = [] if not loose else [
        f"Note: {', '.join(fit.name for fit in loose)} miss what they model by up to "
        f"{100 * max(fit.modulus_error for fit in loose):.3g} % in |K*| and "
        f"{max(fit.loss_angle_error_deg for fit in loose):.3g} deg in loss angle (beyond the "
        f"{100 * FIT_MODULUS_ERROR:g} % and {FIT_LOSS_ANGLE_ERROR_DEG:g} deg a measured table's fit must meet): "
        "the time run, the FRFs and validate model these mounts as fitted, that far from their table."]
    notes += [f"Note: {miss[0].upper()}{miss[1:]}." for miss in loss_fit_misses(fits)]
    if not notes:
        return table(headers, rows)
    return table(headers, rows) + "".join("\n\n" + wrapped(note) for note in notes)  # a blank line: not a row


def ke_table(modes) -> str:
    """Kinetic-energy distribution [%]: rows are DOFs, columns are modes (the decoupling table)."""
    headers = ["DOF"] + [f"mode {j + 1} ({f:.3g} Hz)" for j, f in enumerate(modes.frequency_hz)]
    rows = [[dof] + [fixed(100 * v, 1) for v in modes.ke_distribution[i]] for i, dof in enumerate(DOFS)]
    return table(headers, rows)


def subsystems_text(modes) -> str:
    """One line per group of coupled DOFs."""
    lines = [f"  {i + 1}: ({', '.join(group)})" for i, group in enumerate(modes.subsystems)]
    text = "Decoupled subsystems (DOFs coupled through M and K):\n" + "\n".join(lines)
    if modes.zero_modes:
        text += (f"\nUnrestrained: {len(modes.zero_modes)} zero-frequency mode(s); "
                 f"involving {', '.join(modes.free_dofs)}")
    return text


#: The heading of what ``sixdof modes`` prints after the modes table (:func:`decoupling_text`).
DECOUPLING = "Decoupling and torque-roll axis"


def decoupling_text(modes, metrics) -> str:
    """What ``sixdof modes`` prints after the modes and ``sixdof run`` after its isolation summary: the kinetic-energy
    distribution, the decoupled subsystems and the design metrics (:func:`design_text`)."""
    return "\n".join(["Kinetic energy distribution [%] (share of each mode's kinetic energy in each DOF):",
                      ke_table(modes), "", subsystems_text(modes), "", design_text(metrics)])


def _markdown(text: str) -> str:
    """Lines of :func:`subsystems_text` or :func:`design_text` as Markdown: a paragraph each, indented lines
    as list items."""
    blocks: list[list[str]] = []  # paragraphs, and lists of consecutive items
    for line in text.splitlines():
        item = line.startswith("  ")
        if item and blocks and blocks[-1][0].startswith("- "):
            blocks[-1].append(f"- {line.strip()}")
        else:
            blocks.append([f"- {line.strip()}" if item else line])
    return "\n\n".join("\n".join(block) for block in blocks)


def design_text(metrics) -> str:
    """Decoupling per mode, the torque-roll axis and the elastic centre (a design.DesignMetrics)."""
    modes = "  ".join(f"{j + 1}: {p:.1f} % {d}" for j, (p, d) in enumerate(zip(metrics.decoupling_percent,
                                                                               metrics.dominant_dof)))
    lines = [f"Decoupling (kinetic-energy share of each mode's dominant DOF):\n  {modes}"]
    if metrics.torque_roll_axis is not None:
        tra = ", ".join(f"{c:.4f}" for c in metrics.torque_roll_axis)
        shares = "  ".join(f"{j + 1}: {p:.1f} %" for j, p in enumerate(metrics.decoupling_tra_percent))
        lines += [f"Torque-roll axis (torque about [{', '.join(f'{c:.4g}' for c in metrics.torque_axis)}]): [{tra}]; "
                  f"roll mode {metrics.roll_mode + 1} at {metrics.roll_mode_tra_angle_deg:.2f} deg from it",
                  f"Decoupling in TRA coordinates:\n  {shares}"]
    else:
        lines.append("Torque-roll axis: none ([design] torque_axis names the exciting torque's axis)")
    centre = metrics.elastic_center
    lines.append("Elastic centre: none (no point decouples the mount stiffness)" if centre is None else
                 f"Elastic centre: [{', '.join(f'{c:.4g}' for c in centre)}] m from the CG")
    return "\n".join(lines)


def statics_table(statics, system) -> str:
    """Static deflection of the CG and the force in each mount under gravity; a deflection at round-off of the
    largest (rotations times the body's length) is 0 (a layout symmetric about a DOF leaves ~1e-19 rad there)."""
    length = body_length(system)
    q = without_round_off(statics.q, scale=np.array([1.0, 1.0, 1.0, length, length, length]))
    rows = []
    for i, (dof, unit) in enumerate(zip(DOFS, DOF_UNITS)):
        factor, shown = display_unit(q[i], unit)
        rows.append([dof, f"{q[i] * factor:.5g} {shown}"])
    deflection = table(["DOF", "static deflection"], rows)
    factor, unit = display_unit(statics.mount_forces, "N")  # one unit for the table: kN, or N for a light body
    rows = [[name, *(fixed(v * factor, 3) for v in force), fixed(support * factor, 3),
             "TENSION (uplift)" if name in statics.uplift else "compression"]
            for name, force, support in zip(system.mount_names, statics.mount_forces, statics.support)]
    forces = table(["mount", f"Fx [{unit}]", f"Fy [{unit}]", f"Fz [{unit}]", f"carried [{unit}]", "state"], rows,
                   "lrrrrl")
    return (deflection + "\n\n" + wrapped("Load on each mount (force of the body on it, passed to the foundation; "
                                           "body axes; carried: along gravity, > 0 compression):") + "\n" + forces)


#: How every mount table states its signs.
MOUNT_SIGNS = wrapped("Loads are the force of the body on each mount (passed to the foundation), static under "
                      "gravity plus dynamic, along the mount's axes u, v, w; the normal force is along w (from the "
                      "foundation towards the body): > 0 compression, < 0 tension (uplift). Deflections are from "
                      "the unloaded mount.")


def mount_loads_table(check) -> str:
    """Normal force of each mount over a run (static, extremes, tension) and its peak shear loads."""
    forces = without_round_off(np.column_stack([-check.static_force[:, 2], check.max_compression,
                                                check.min_compression, check.peak_force[:, :2]]))
    factor, unit = display_unit(forces, "N")  # one unit for the table: kN, or N for a light body
    rows = []
    for j, name in enumerate(check.names):
        tension = ("none" if not np.isfinite(check.tension_start_t[j]) else
                   f"TENSION {-check.min_compression[j] * factor:.4g} {unit}, "
                   f"from t = {check.tension_start_t[j]:.4g} s")
        static, most, least, shear_u, shear_v = forces[j] * factor
        rows.append([name, f"{static:.4g}", f"{most:.4g}", f"{check.max_compression_t[j]:.4g}",
                     f"{least:.4g}", f"{check.min_compression_t[j]:.4g}", f"{shear_u:.4g}", f"{shear_v:.4g}", tension])
    return table(["mount", f"static N [{unit}]", f"max N [{unit}]", "at t [s]", f"min N [{unit}]", "at t [s]",
                  f"peak Fu [{unit}]", f"peak Fv [{unit}]", "tension"], rows, "lrrrrrrrl")


def mount_deflections_table(check, limits=None) -> str:
    """Peak total deflection of each mount per axis, when, and its limit (``limits``: (m, 3) [m], inf none)."""
    peaks = without_round_off(check.peak_deflection)
    scale, unit = display_unit(peaks, "m")
    rows = []
    for j, name in enumerate(check.names):
        cells = [f"{peaks[j, i] * scale:.4g} @ {check.peak_deflection_t[j, i]:.4g} s"
                 for i in range(3)]
        if limits is not None:
            shown = [f"{v * scale:.4g}" if np.isfinite(v) else "-" for v in limits[j]]
            cells.append(", ".join(shown) if len(set(shown)) > 1 else shown[0])
        rows.append([name, *cells])
    headers = ["mount", f"peak u [{unit}]", f"peak v [{unit}]", f"peak w [{unit}]"]
    return table(headers + ([f"max_deflection [{unit}]"] if limits is not None else []), rows)


def mount_check_text(check, limits=None) -> str:
    """The mount checks of a run: sign convention, loads, deflections and the limits exceeded."""
    if limits is not None and not np.isfinite(limits).any():
        limits = None  # no mount has one: no column of dashes
    parts = [MOUNT_SIGNS, "", mount_loads_table(check), "", mount_deflections_table(check, limits)]
    if not check.preload:
        parts += ["", "No static preload: the mounts cannot carry the weight, only the dynamic part is shown."]
    return "\n".join(parts)


# ----------------------------------------------------------------------------------------------------
# The isolation summary: what an engineer asks of a run first (sixdof run's first table, summary.md's top).
# ----------------------------------------------------------------------------------------------------

#: The heading of the isolation summary.
ISOLATION_SUMMARY = "Isolation summary"


def _efficiency_cell(value: float) -> str:
    return "n/a (no force applied)" if not np.isfinite(value) else f"{100 * value:.1f} %" + (
        " (amplified)" if value < 0 else "")


def _frequencies_part(results, summary) -> list[str]:
    """Natural frequencies against the operating ones (frequency ratio), and the isolation at each."""
    modes, steady = results.modes, results.steady_state
    curves = () if summary is None else summary.curves
    operating = np.unique(np.concatenate([c.operating_hz for c in curves])) if curves else np.zeros(0)
    excited = {r for c in curves for r in c.excited_modes}
    headers = ["mode #", "f_n [Hz]", "dominant DOF", *(["excited"] if curves else []),
               *(f"r = {f:.4g} Hz / f_n" for f in operating)]
    digits = next((d for d in range(4, 9) if len({f"{f:.{d}g}" for f in modes.frequency_hz})
                   == len(set(modes.frequency_hz))), 9)  # close modes printed apart
    rows = [[str(j + 1), f"{f:.{digits}g}", dof, *(["yes" if j in excited else "-"] if curves else []),
             *("-" if f <= 0 else f"{f_op / f:.3g}" for f_op in operating)]
            for j, (f, dof) in enumerate(zip(modes.frequency_hz, modes.dominant_dof))]
    if not curves:
        return ["No operating frequency (no harmonic load or ground motion without end): natural frequencies",
                table(headers, rows)]
    lines = ["Natural frequencies against the operating frequencies (r > sqrt(2) for every excited mode: isolated):",
             table(headers, rows), ""]
    headers, rows = ["at the operating frequency", *(f"{f:.4g} Hz" for f in operating)], []
    for curve in curves:
        at = dict(zip(curve.operating_hz, curve.at_operating))
        what = {"force": "force transmissibility F_foundation / F_applied [-]",
                "moment": "moment transmissibility M_foundation / M_applied [-]",
                "motion": "motion transmissibility x_body / x_ground [-]"}[curve.kind]
        rows.append([what, *(f"{at[f]:.3g}" if f in at else "-" for f in operating)])
        rows.append([f"isolation efficiency ({curve.kind})",
                     *(_efficiency_cell(1.0 - at[f]) if f in at else "-" for f in operating)])
        rows.append([f"isolation region from [Hz] ({curve.kind})",
                     *(f"{curve.isolation_hz:.4g}" + (" (in it)" if f >= curve.isolation_hz else " (below)")
                       if f in at else "-" for f in operating)])
    if steady is not None:
        factor, unit = display_unit(np.concatenate([steady.applied_force, steady.transmitted_force]), "N")
        at = dict(zip(steady.f_hz, zip(steady.applied_force, steady.transmitted_force)))
        rows.append([f"applied force [{unit}]", *(f"{at[f][0] * factor:.4g}" if f in at else "-" for f in operating)])
        rows.append([f"force on the foundation [{unit}]",
                     *(f"{at[f][1] * factor:.4g}" if f in at else "-" for f in operating)])
        if any(curve.kind == "moment" for curve in curves):  # a torque: its moments too
            moments = dict(zip(steady.f_hz, zip(vector_amplitude(steady.applied[:, 3:]),
                                                vector_amplitude(steady.transmitted[:, 3:]))))
            rows.append(["applied moment [N m]", *(f"{moments[f][0]:.4g}" if f in moments else "-" for f in operating)])
            rows.append(["moment on the foundation [N m]",
                         *(f"{moments[f][1]:.4g}" if f in moments else "-" for f in operating)])
    return [*lines, table(headers, rows, "l" + "r" * len(operating))]


def _mounts_part(check, mounts) -> list[str]:
    """Peak mount loads and deflections against their limits (``mounts``' ``max_deflection`` and
    ``allow_tension``), with the margins."""
    limits = np.stack([m.max_deflection for m in mounts])
    factor, unit = display_unit(np.concatenate([check.max_compression, check.min_compression]), "N")
    peaks = np.abs(without_round_off(check.peak_deflection))  # signed: magnitudes against the limits
    scale, length = display_unit(peaks, "m")
    rows = []
    for j, name in enumerate(check.names):
        finite = np.isfinite(limits[j])
        axis = int(np.argmax(np.where(finite, peaks[j] / np.where(finite, limits[j], 1.0), -np.inf))) \
            if finite.any() else int(np.argmax(peaks[j]))
        use = peaks[j, axis] / limits[j, axis] if finite.any() else None
        tension = ("none" if not (check.min_compression[j] < 0 and np.isfinite(check.tension_start_t[j]))
                   else "yes (allowed)" if mounts[j].allow_tension else "TENSION (not allowed)")
        rows.append([name, f"{check.max_compression[j] * factor:.4g}", f"{check.min_compression[j] * factor:.4g}",
                     tension, f"{peaks[j, axis] * scale:.4g} ({'uvw'[axis]})",
                     "-" if use is None else f"{limits[j, axis] * scale:.4g}",
                     "-" if use is None else f"{100 * (1 - use):.0f} %" + (" EXCEEDED" if use > 1 else "")])
    headers = ["mount", f"max N [{unit}]", f"min N [{unit}]", "tension",
               f"peak deflection [{length}]", f"limit [{length}]", "margin"]
    return [wrapped("Mounts (total loads, static included; N > 0 compression; deflection from the unloaded mount "
                    "along the axis nearest its limit, margin = 1 - peak / limit):"), table(headers, rows, "lrrlrrr")]


def _points_part(points, steady: bool) -> list[str]:
    """Peak accelerations at the named points (said to include the switch-on transient with a ``steady`` state)."""
    rows = []
    for name, motion in points.items():
        peaks = np.max(np.abs(motion.acceleration), axis=0)
        rows.append([name, *(f"{a:.4g}" for a in peaks), f"{peaks.max() / STANDARD_GRAVITY:.3g}"])
    return [f"Peak accelerations at the named points over the run (absolute{PEAKS_WITH_TRANSIENT if steady else ''}):",
            table(["point", "peak ax [m/s^2]", "peak ay [m/s^2]", "peak az [m/s^2]", "peak a [g]"], rows)]


def isolation_summary_text(results) -> str:
    """The isolation summary of a run's :class:`~sixdof.results.RunResults`, in one screen: natural frequencies
    against the operating frequencies (the frequency ratio), the force (and ground motion) transmissibility,
    isolation efficiency and force on the foundation at each (:mod:`sixdof.analysis.isolation_summary`), the peak
    mount loads and deflections against their limits with margins, the peak accelerations at the named points and,
    with ``[severity]``, the vibration severity. What ``sixdof run`` prints first and what ``summary.md`` starts
    with; the solver checks follow."""
    if results.modes is None:
        return ""
    summary = run_isolation_summary(results) if has_operating(results) else None
    parts = _frequencies_part(results, summary)
    if results.mount_check is not None and results.system is not None:
        parts += ["", *_mounts_part(results.mount_check, results.system.mounts)]
    if results.points:
        parts += ["", *_points_part(results.points, results.steady_state is not None)]
    if results.severity is not None:
        parts += ["", *severity_part(results.severity, results.steady_state)]
    return "\n".join(parts)


# ----------------------------------------------------------------------------------------------------
# summary.md: the tables of a run, with links to its figures.
# ----------------------------------------------------------------------------------------------------


def summary_markdown(results, figures=()) -> str:
    """The run summary as Markdown text: a run's :class:`~sixdof.results.RunResults` (as
    :func:`sixdof.workflows.run.run` returns them: with their scenario, notes and geometric-stiffness line) and
    the names of its ``figures``."""
    scenario, notes, stiffness_note = results.scenario, results.notes, results.stiffness_note
    modes, statics, damping_ratios, response = results.modes, results.statics, results.damping_ratios, results.response
    forces, agreement, superposition, frf = results.mount_forces, results.agreement, results.superposition, results.frf
    mount_check, steady, points = results.mount_check, results.steady_state, results.points
    random, srs = results.random, results.srs
    nonlinear = None if results.contacts is None else (results.contacts, results.energy, results.refined)
    parts = [f"# {scenario.name}", "", scenario.description, ""]
    summary = isolation_summary_text(results)
    if summary:
        parts += [f"## {ISOLATION_SUMMARY}", "", summary.replace(":\n|", ":\n\n|"), ""]
    if results.design is not None:
        parts += [f"## {DECOUPLING}", "", "### Kinetic energy distribution [%]", "",
                  "Share of each mode's kinetic energy in each DOF:", "", ke_table(modes), "",
                  _markdown(subsystems_text(modes)), "", _markdown(design_text(results.design)), ""]
    if notes:
        parts += ["## Warnings", "", *(f"- {n}" for n in notes), ""]
    parts += ["## Natural frequencies", "", modes_table(modes, damping_ratios, scenario.system), "",
              damping_note(scenario.system), ""]
    if stiffness_note is not None:
        parts += [stiffness_note[0].upper() + stiffness_note[1:] + ".", ""]
    if scenario.viscoelastic:
        parts += ["## Visco-elastic mounts", "", viscoelastic_table(scenario.viscoelastic), ""]
    if results.design is None:  # a run's decoupling is in its engineering section, above
        parts += ["## Kinetic energy distribution [%]", "", ke_table(modes), ""]
        parts += [subsystems_text(modes).replace("\n  ", "\n- ").replace(":\n", ":\n\n", 1), ""]
    if statics is not None:
        line = long_term_note(scenario.viscoelastic)
        parts += ["## Statics under gravity", "", statics_table(statics, scenario.system), ""] + ([line, ""] if line
                                                                                                  else [])
    if steady is not None:
        parts += ["## Steady state", "", steady_state_text(steady), ""]
    if random is not None:
        parts += ["## Random vibration", "", random_text(random), ""]
    if srs is not None:
        parts += ["## Shock response spectra", "", srs_text(srs), ""]
    if results.spectrum is not None:
        parts += ["## Response spectrum", "", spectrum_text(results.spectrum), ""]
        if results.isolation is not None:
            parts += [isolation_text(results.isolation), ""]
    if results.record_peaks is not None:
        parts += ["### Spectrum-compatible records", "", records_text(results.spectrum, results.spectrum_records,
                                                                      results.records_check, results.record_peaks,
                                                                      results.damping_ratios), ""]
    if response is not None:
        transient = PEAKS_WITH_TRANSIENT if steady is not None else ""
        parts += ["## Time response", ""]
        ground = scenario.excitation.ground if scenario.excitation is not None else None
        if ground is not None and ground.baseline != "none":
            parts += [baseline_text(ground), ""]
        parts += [f"Peaks over the whole run{transient}.", "", peaks_text(response), ""]
        stats = response.stats
        parts += [f"Solver: {stats.solver}, rtol {stats.rtol:g}, atol {stats.atol:g} (per-DOF scaled), "
                  f"{stats.num_accepted} accepted and {stats.num_rejected} rejected steps", ""]
        if mount_check is not None:
            limits = np.stack([m.max_deflection for m in scenario.system.mounts])
            parts += ["### Mount checks", "", mount_check_text(mount_check, limits), ""]
        if points:
            parts += ["### Body points", "", points_table(points, moving_ground(scenario), steady is not None,
                                                          ground=response), ""]
        parts += ["### Peak mount forces (dynamic part, about static equilibrium; body axes)", "",
                  _mount_peaks_table(forces), ""]
        if nonlinear is not None:
            parts += ["### Nonlinear mounts", "", nonlinear_text(*nonlinear, agreement, stats).replace("\n", "\n\n"),
                      ""]
        if scenario.system.hysteretic.count:
            parts += ["### Hysteretic bearings", "", hysteresis_table(results.system, response, forces), ""]
        if agreement is not None:
            parts += ["### Direct solve vs modal superposition" + (" (until the first mount engaged)" if nonlinear
                                                                   else ""),
                      "", _agreement_table(agreement, superposition.superposition), ""]
    if frf is not None:
        f_hz = frf.direct.f_hz
        linearized = (" Nonlinear mounts enter at their slope at the static equilibrium (the linearization)."
                      if scenario.system.nonlinear.count else "")
        parts += ["## Frequency response", "", f"{len(f_hz)} frequencies from {f_hz[0]:g} to {f_hz[-1]:g} Hz; direct "
                  f"and modal receptances agree to {frf.max_relative_difference:.1e} (relative, worst entry)."
                  + linearized, ""]
    if figures:
        parts += ["## Figures", "", *(f"![{Path(f).stem}]({Path(f).name})" for f in figures), ""]
    return "\n".join(parts)


def peaks_text(response) -> str:
    """The peaks of each DOF over a run (:class:`~sixdof.results.TimeHistory`): where the ground moves, those
    relative to it first (what the mounts feel, free of the ground's drift), then the absolute ones."""
    if not ground_in_motion(response):
        return _peaks_table(response.t, response.q, response.qd, response.qdd)
    return ("Relative to the ground (what the mounts feel):\n\n"
            + _peaks_table(response.t, response.q_relative, response.qd_relative, response.qdd_relative)
            + "\n\nAbsolute (fixed frame, the ground's own motion included):\n\n"
            + _peaks_table(response.t, response.q, response.qd, response.qdd))


def baseline_text(ground) -> str:
    """What the baseline correction of a ground record changed (a :class:`~sixdof.excitation.GroundMotion` with
    ``baseline`` set): the largest change of acceleration, and where the record as given ended."""
    change, peak, (v, d), degree = ground.baseline_effect
    how = ("a straight line off the acceleration, the one that brings it to rest at its end" if degree == 2 else
           "the least-squares fit to its velocity, brought to rest at its end")
    return wrapped(f"Ground record baseline-corrected ({ground.baseline} of degree {degree} in velocity: {how}; "
                   "Boore 2001, Boore, Stephens & Joyner 2002): "
                   f"acceleration changed by at most {change:.3g} m/s² ({100 * change / peak:.3g} % of its peak "
                   f"{peak:.3g} m/s²); as given, the record ended at {v:.3g} m/s and {d:.3g} m, corrected "
                   "at rest.")


def ground_in_motion(response) -> bool:
    """Whether the ground under a run (:class:`~sixdof.results.TimeHistory`) moves: present and not all zero."""
    return response.has_ground and bool(np.any(response.ground_displacement) or np.any(response.ground_acceleration))


def _peaks_table(t, q, qd, qdd) -> str:
    """Peak ``q`` (signed, with its time), ``|q'|`` and ``|q''|`` of each DOF, arrays (n, 6) at times ``t``."""
    rows = []
    for i, (dof, unit) in enumerate(zip(DOFS, DOF_UNITS)):
        k = int(np.argmax(np.abs(q[:, i])))
        cells = []
        for order, values in enumerate((q[:, i], qd[:, i], qdd[:, i])):
            scale, shown = display_unit(values, unit + ("", "/s", "/s^2")[order])
            cells.append(f"{scale * (values[k] if order == 0 else np.max(np.abs(values))):.5g} {shown}")
        rows.append([dof, cells[0], f"{t[k]:.3f}", cells[1], cells[2]])
    return table(["DOF", "peak q", "at t [s]", "peak |q'|", "peak |q''|"], rows)


def srs_text(srs) -> str:
    """The peak of each shock response spectrum and where it lies (:class:`~sixdof.analysis.srs.ShockSpectra`)."""
    rows = []
    if srs.input is not None:
        k = int(np.argmax(srs.input))
        rows.append(["base (input)", "along the ground", f"{srs.input[k] / STANDARD_GRAVITY:.4g}",
                     f"{srs.f_hz[k]:.4g}"])
    largest = float(np.max(srs.points)) if srs.points.size else 0.0
    for name, spectra in zip(srs.names, srs.points):
        for axis, spectrum in zip("xyz", spectra):
            k = int(np.argmax(spectrum))
            if spectrum[k] > 1e-9 * largest:  # an axis the shock does not reach is left out
                rows.append([name, axis, f"{spectrum[k] / STANDARD_GRAVITY:.4g}", f"{srs.f_hz[k]:.4g}"])
    return (f"Maximax absolute-acceleration SRS, Q = {srs.q:g}, {srs.f_hz[0]:g} to {srs.f_hz[-1]:g} Hz:\n"
            + table(["signal", "axis", "peak SRS [g]", "at f [Hz]"], rows))


def isolation_text(loop) -> str:
    """The effective-linearization loop of an isolated system
    (:class:`~sixdof.analysis.isolation.EffectiveLinearization`): each iteration's design displacements, effective
    stiffnesses and damping, the system's damping and T_eff."""
    rows = [[str(i + 1), f"{1e3 * loop.design_displacement[i].min():.4g}-{1e3 * loop.design_displacement[i].max():.4g}",
             f"{1e-3 * loop.stiffness[i].min():.4g}-{1e-3 * loop.stiffness[i].max():.4g}",
             f"{100 * loop.system_damping[i]:.3g}", f"{loop.effective_period[i]:.4g}",
             "-" if not np.isfinite(loop.change[i]) else f"{loop.change[i]:.2e}"]
            for i in range(loop.change.size)]
    return (f"Effective linearization (EN 1998-2 7.5.4) of {len(loop.axes)} isolator axes, converged in "
            f"{loop.change.size} iterations (relative change < {loop.rtol:g}); modes of T >= 0.8 T_eff take the "
            f"system's damping:\n" + table(["iteration", "D [mm]", "K_eff [kN/m]", "xi_eff [%]", "T_eff [s]",
                                            "change"], rows))


def spectrum_text(spectrum) -> str:
    """The response-spectrum analysis (:class:`~sixdof.analysis.spectrum.ResponseSpectrum`): the spectrum, each
    mode's period, spectral value and effective masses, the combined peaks of the DOFs, mounts and base, in blocks
    apart (Markdown as it is)."""
    directions = spectrum.direction
    head = (f"{spectrum.spectrum}; {spectrum.combination.upper()} over the modes (damping "
            f"{100 * spectrum.damping:g} %), {spectrum.directional.upper()} over the directions "
            f"{', '.join(directions)}:")
    modes = [[str(j + 1), f"{spectrum.period[j]:.4g}", f"{100 * spectrum.mode_damping[j]:.3g}",
              *(f"{spectrum.spectral_acceleration[i, j]:.4g}" for i in range(len(directions))),
              *(f"{spectrum.effective_mass[i, j]:.4g}" for i in range(len(directions)))] for j in range(6)]
    modes.append(["sum", "", "", *[""] * len(directions),
                  *(f"{100 * share:.1f} %" for share in spectrum.mass_share)])
    lines = [head, table(["mode", "T [s]", "xi [%]", *(f"Sa {d} [m/s²]" for d in directions),
                          *(f"m_eff {d} [kg]" for d in directions)], modes)]
    rows = []
    for k, dof in enumerate(DOFS):
        factor, unit = display_unit(spectrum.combined_q[k], DOF_UNITS[k])
        rows.append([dof, *(f"{factor * v:.4g}" for v in spectrum.peak_q[:, k]),
                     f"{factor * spectrum.combined_q[k]:.4g} {unit}"])
    lines += ["Peak displacement relative to the ground:",
              table(["DOF", *directions, spectrum.directional], rows)]
    factor, unit = display_unit(spectrum.combined_mount_deflection, "m")
    mounts = [[name, *(f"{factor * d:.4g}" for d in deflection), *(f"{f:.4g}" for f in force)]
              for name, deflection, force in zip(spectrum.mounts, spectrum.combined_mount_deflection,
                                                 spectrum.combined_mount_force)]
    lines += [f"Mounts ({spectrum.directional} of the directions):",
              table(["mount", *(f"defl {a} [{unit}]" for a in "uvw"), *(f"force {a} [N]" for a in "uvw")], mounts)]
    lines.append("Base shear [N] " + ", ".join(f"{a} {v:.4g}" for a, v in zip("xyz", spectrum.combined_base_shear))
                 + "; base moment about the CG [N m] "
                 + ", ".join(f"{a} {v:.4g}" for a, v in zip("xyz", spectrum.combined_base_moment)))
    lines += [f"Note: {note}" for note in spectrum.notes]
    return "\n\n".join(lines)  # blocks apart: a Markdown table needs a blank line before it


def records_text(spectrum, records, check, peaks, damping_ratios=None) -> str:
    """The spectrum-compatible records of ``[spectrum] records`` beside the response-spectrum analysis ``spectrum``:
    how they were made (:class:`~sixdof.analysis.matching.SpectrumCompatibleRecords`), their EN 1998-1 3.2.3.1.2
    checks (:class:`~sixdof.analysis.matching.RecordCheck`) and the design value of their peak responses
    (:class:`~sixdof.analysis.record_peaks.RecordPeaks`) beside the spectrum's peaks along the records' direction
    (modes combined, that direction alone); ``damping_ratios`` (6,) the model's, which the records run with."""
    direction = AXES[int(np.argmax(np.abs(peaks.direction)))]
    row = spectrum.direction.index(direction)
    mode = spectrum.dominant_mode(direction)
    count, dt = records.acceleration.shape[0], float(records.t[1] - records.t[0])
    head = (f"{count} accelerograms of {records.t[-1]:g} s at {dt:g} s along {direction}: "
            f"{records.method}; seed {records.seed}, {records.iterations} iterations, envelope rising "
            f"{records.rise:g} s, stationary {records.stationary:g} s, decaying {records.decay:g} s. Target: "
            f"{records.target_source or 'as given'}.")
    if records.scale > 1.0:
        head += f" Scaled by {records.scale:.4g} so that their mean peak reaches ag S."
    lo, hi = check.band
    clauses = [("(3) stationary part [s]", f"{check.stationary:g}", ">= 10", check.stationary >= 10.0),
               ("(4)a accelerograms", str(check.count), ">= 3", check.count >= 3),
               ("(4)b mean peak ground acceleration [m/s²]", f"{check.pga_mean:.4g}", f">= ag S = {check.ag_s:.4g}",
                check.pga_mean >= check.ag_s * (1 - 1e-12)),
               (f"(4)c mean / target Sa over {lo:.4g}-{hi:.4g} s [1]",
                f"{check.min_ratio:.4f} (at {check.min_ratio_period:.4g} s) to {check.max_ratio:.4f}", ">= 0.9",
                check.min_ratio >= 0.9)]
    lines = [wrapped(head),
             f"EN 1998-1 3.2.3.1.2, T1 = {hi / 2:.4g} s (mode {mode + 1}, the largest effective mass along "
             f"{direction}): " + ("met." if check.passed else "NOT met: " + "; ".join(check.failures)),
             table(["clause", "value", "limit", "met"], [[*c[:3], "yes" if c[3] else "NO"] for c in clauses])]
    if peaks.rule == "mean":
        rule = f"the mean of the {count} records' peaks (EN 1998-1 4.3.3.4.3(3): at least 7 records)"
    else:
        rule = f"the most unfavourable of the {count} records' peaks (EN 1998-1 4.3.3.4.3(3): fewer than 7 records)"
    zeta = None if damping_ratios is None else float(damping_ratios[mode])
    damping = ("" if zeta is None or not np.isfinite(zeta) else
               f"; the records run the model's own damping ({100 * zeta:.3g} % in mode {mode + 1}), the spectrum "
               f"{100 * spectrum.damping:g} %")
    t1 = hi / 2
    analysed = float(spectrum.spectral_acceleration[row, mode])
    matched = float(np.exp(np.interp(np.log(t1), np.log(records.periods), np.log(records.target))))
    if not math.isclose(analysed, matched, rel_tol=1e-6):  # a design spectrum (q), or another damping ratio
        lines.append(wrapped(f"At T1 the analysis's spectrum gives {analysed:.4g} m/s² (ratio "
                             f"{100 * spectrum.mode_damping[mode]:g} %) and the records' target {matched:.4g} m/s² "
                             "(the 5 %-damped elastic spectrum, EN 1998-1 3.2.3.1.2(4)c): their peaks differ by as "
                             "much."))
    lines.append(wrapped(f"Peaks along {direction}: the spectrum's ({spectrum.combination.upper()} of the modes, "
                         f"{direction} alone) and the records' design value, {rule}{damping}. Relative to the ground; "
                         "records min and max: the spread over the suite."))
    reference = spectrum.peak_q[row]
    columns = np.stack([reference, peaks.design_q, peaks.peak_q.min(axis=0), peaks.peak_q.max(axis=0)], axis=1)
    columns = np.concatenate([without_round_off(columns[:3]), without_round_off(columns[3:])])  # m and rad apart
    rows = []
    for k, dof in enumerate(DOFS):
        factor, unit = display_unit(columns[k], DOF_UNITS[k])
        rows.append([dof, unit, *(f"{factor * v:.4g}" for v in columns[k]),
                     _ratio(columns[k, 1], columns[k, 0])])
    lines.append(table(["DOF", "unit", "spectrum", "records", "records min", "records max", "records / spectrum"],
                       rows))
    deflection = without_round_off(np.stack([spectrum.mount_deflection[row], peaks.design_deflection]))
    force = without_round_off(np.stack([spectrum.mount_force[row], peaks.design_force]))
    factor, unit = display_unit(deflection, "m")
    mounts = [[name, axis, f"{factor * deflection[0, i, a]:.4g}", f"{factor * deflection[1, i, a]:.4g}",
               f"{force[0, i, a]:.4g}", f"{force[1, i, a]:.4g}", _ratio(force[1, i, a], force[0, i, a])]
              for i, name in enumerate(spectrum.mounts) for a, axis in enumerate("uvw")]
    lines += [wrapped("Mounts (deflection and load along their own axes; the spectrum's load is the spring's, the "
                      "records' the mount's whole dynamic load):"),
              table(["mount", "axis", f"spectrum defl [{unit}]", f"records defl [{unit}]", "spectrum force [N]",
                     "records force [N]", "records / spectrum"], mounts)]
    base_force = without_round_off(np.stack([spectrum.base_shear[row], peaks.design_base_force]))
    base_moment = without_round_off(np.stack([spectrum.base_moment[row], peaks.design_base_moment]))
    base = [[axis, f"{base_force[0, a]:.4g}", f"{base_force[1, a]:.4g}", f"{base_moment[0, a]:.4g}",
             f"{base_moment[1, a]:.4g}"] for a, axis in enumerate(AXES)]
    lines += [wrapped(f"Base (on the foundation, body axes; the records' peak shear in the x-y plane "
                      f"{peaks.design_base_shear:.4g} N):"),
              table(["axis", "spectrum force [N]", "records force [N]", "spectrum moment [N m]",
                     "records moment [N m]"], base)]
    return "\n\n".join(lines)  # blocks apart: a Markdown table needs a blank line before it


def _ratio(value: float, reference: float) -> str:
    """``value / reference`` to 3 decimals, "-" where the reference is 0 (shown so: round-off of its table)."""
    return f"{value / reference:.3f}" if reference else "-"


def random_text(random) -> str:
    """The random response: RMS and 3-sigma of each DOF, of the points' accelerations and of the mount forces,
    and Miles' estimate beside the exact RMS per mode (:class:`~sixdof.analysis.random.RandomResponse`)."""
    unit = "N" if random.input_kind == "force" else "m/s² (" + f"{random.input_rms / STANDARD_GRAVITY:.3g} g)"
    lines = [f"Input: {random.input_kind.replace('_', ' ')}, RMS {random.input_rms:.4g} {unit}"]
    rows = []
    for i, dof in enumerate(DOFS):
        factor, label = display_unit(random.q_rms[i], DOF_UNITS[i])
        accel_unit = "m/s²" if i < 3 else "rad/s²"
        rows.append([dof, f"{factor * random.q_rms[i]:.4g} {label}", f"{3 * factor * random.q_rms[i]:.4g} {label}",
                     f"{random.qdd_rms[i]:.4g} {accel_unit}"])
    lines.append(table(["DOF", "displacement RMS", "3 sigma", "acceleration RMS"], rows))
    if len(random.points):
        lines.append(table(["point", "acceleration RMS x, y, z [m/s²]", "3 sigma [g]"],
                           [[name, ", ".join(f"{v:.4g}" for v in rms),
                             ", ".join(f"{3 * v / STANDARD_GRAVITY:.3g}" for v in rms)]
                            for name, rms in zip(random.points, random.point_acceleration_rms)]))
    lines.append(table(["mount", "force RMS u, v, w [N]", "deflection RMS u, v, w [mm]"],
                       [[mount, ", ".join(f"{v:.4g}" for v in force), ", ".join(f"{1e3 * v:.3g}" for v in defl)]
                        for mount, force, defl in zip(random.mounts, random.mount_force_rms,
                                                      random.mount_deflection_rms)]))
    modes = [[str(j + 1), random.dominant_dof[j], f"{m:.4g}", f"{e:.4g}", f"{e / m:.3f}"]
             for j, (m, e) in enumerate(zip(random.miles_rms, random.exact_rms)) if np.isfinite(m) and m > 0]
    if modes:
        lines.append("Miles' equation per mode (its dominant DOF's acceleration RMS, that mode alone) against the "
                     "exact RMS (every mode):\n" + table(["mode", "DOF", "Miles", "exact", "exact / Miles"], modes))
    if random.time_check is not None:
        lines.append(random_check_text(random.time_check))
    return "\n\n".join(lines)


def random_check_text(check) -> str:
    """The random response against a time history (:class:`~sixdof.analysis.random.RandomTimeCheck`):
    the record, the verdict and the RMS values side by side."""
    worst = check.worst
    head = (f"Checked against a time history: a {check.duration_s:.4g} s Gaussian record with the PSD (seed "
            f"{check.seed}, after {check.settle_s:.3g} s of settling) through the direct solve "
            f"({check.solver_steps} steps, {check.wall_time_s:.3g} s); Welch PSDs of {check.averages} Hann segments "
            f"of {check.segment_s:.3g} s.\n"
            f"{check.verdict}: {len(check.judged)} values judged (RMS of every excited response, octave bands of the "
            f"accelerations), largest |z| {abs(check.z[worst]):.2f} ({check.judged[worst]}) against a limit of "
            f"{check.z_limit:.2f} (a correct model exceeds it with probability 0.27 %)")
    rows = [[name.removeprefix("rms:"), f"{f:.4g} {unit}", f"{t:.4g} {unit}", f"{100 * s / 2:.2g} %", f"{z:+.2f}"]
            for name, unit, f, t, s, z in zip(check.judged, check.judged_units, check.frequency_rms, check.time_rms,
                                              check.sigma, check.z) if name.startswith("rms:")]
    notes = "".join(f"\nNote: {n}" for n in check.notes)
    return head + notes + "\n" + table(["response", "RMS from the FRFs", "RMS of the record", "1 sigma", "z"], rows)


def steady_state_text(steady) -> str:
    """The steady-state amplitude of each DOF and the isolation at each operating frequency
    (:class:`sixdof.analysis.steady.SteadyState`)."""
    amplitude = np.abs(steady.q)
    rows = []
    for dof, unit, values in zip(DOFS, DOF_UNITS, amplitude.T):
        scale, shown = display_unit(values, unit)
        rows.append([dof, *(f"{scale * v:.4g} {shown}" for v in values)])
    headers = ["DOF", *(f"{f:.4g} Hz" for f in steady.f_hz)]
    motion = table(headers, rows)

    def shown(value, text):  # NaN: the loads at that frequency are moments only
        return "n/a (no force applied)" if not np.isfinite(value) else text

    factor, unit = display_unit(steady.applied_force, "N")
    rows = [[f"applied force amplitude [{unit}]", *(f"{v * factor:.4g}" for v in steady.applied_force)],
            [f"force on the foundation [{unit}]", *(f"{v * factor:.4g}" for v in steady.transmitted_force)],
            ["force transmissibility", *(shown(v, f"{v:.3g}") for v in steady.transmissibility)],
            ["isolation efficiency", *(shown(v, f"{100 * v:.1f} %") for v in steady.isolation_efficiency)]]
    isolation = table(["", *headers[1:]], rows, "l" + "r" * len(steady.f_hz))
    return (wrapped("Steady state at the operating frequencies (harmonic loads without end, once the switch-on "
                    "transient has died out; from the frequency response, loss factors included): amplitude "
                    "of each DOF of the CG:") + "\n" + motion + "\n\n" + isolation)


def moving_ground(scenario) -> bool:
    """Whether the scenario's ground moves (its body points' motion is then absolute: :func:`points_table`)."""
    return scenario.excitation is not None and scenario.excitation.ground is not None


#: Said of a run's peaks when it has a steady state (printed apart): they are not the steady state's.
PEAKS_WITH_TRANSIENT = ", the switch-on transient included"


def points_table(points, ground_moves: bool = False, steady: bool = False, ground=None) -> str:
    """Peak motion of each body point over the run (:class:`sixdof.analysis.response.PointMotion` by name),
    per body axis: displacement and acceleration, and the largest acceleration in g. Absolute motion is said to
    be absolute when ``ground_moves`` (the ground's own displacement, maybe a drift far larger than the mounts',
    is in it); given the run's ``ground`` (its :class:`~sixdof.results.TimeHistory`, at the points' times), the
    displacement relative to the ground comes first. Said to include the switch-on transient when the run has
    a ``steady`` state."""
    relative = any(motion.relative for motion in points.values())
    beside = None  # the displacement relative to the ground, before the absolute one
    if ground is not None and not relative and ground_moves and ground.has_ground:
        beside = {name: np.max(np.abs(m.displacement - ground.ground_displacement), axis=0)
                  for name, m in points.items()}
    displacements = {name: np.max(np.abs(m.displacement), axis=0) for name, m in points.items()}
    accelerations = {name: np.max(np.abs(m.acceleration), axis=0) for name, m in points.items()}
    scale, shown = display_unit(np.concatenate(list(displacements.values()) + list((beside or {}).values())), "m")
    rows = [[name, ", ".join(f"{v:.4g}" for v in motion.position),
             *(f"{scale * v:.4g}" for v in (beside[name] if beside else ())),
             *(f"{scale * v:.4g}" for v in displacements[name]), *(f"{a:.4g}" for a in accelerations[name]),
             f"{accelerations[name].max() / STANDARD_GRAVITY:.3g}"] for name, motion in points.items()]
    headers = ["point", "position [m]", *(f"peak {a} rel [{shown}]" for a in ("xyz" if beside else "")),
               *(f"peak {a}{' abs' if beside else ''} [{shown}]" for a in "xyz"),
               *(f"peak a{a} [m/s^2]" for a in "xyz"), "peak a [g]"]
    frame = ("Motion relative to the ground. " if relative else
             "Displacement relative to the ground (rel: what the mounts feel) first, then absolute (abs: fixed "
             "frame, the ground's own motion included); accelerations absolute (what the body feels). " if beside else
             "Absolute motion (fixed frame), the ground's own motion included; the mounts' deflections are "
             "relative to it. " if ground_moves else "")
    return (frame + f"Peaks over the run{PEAKS_WITH_TRANSIENT if steady else ''}:\n"
            + table(headers, rows, "ll" + "r" * (len(headers) - 2)))


def _mount_peaks_table(forces) -> str:
    peaks = [(name, np.max(np.abs(force), axis=0))
             for name, force in [*zip(forces.names, forces.total), ("foundation (total)", forces.foundation_force)]]
    factor, unit = display_unit([p for _, p in peaks], "N")
    rows = [[name, *(f"{v * factor:.4g}" for v in p)] for name, p in peaks]
    return table(["mount", f"peak |Fx| [{unit}]", f"peak |Fy| [{unit}]", f"peak |Fz| [{unit}]"], rows)


def _agreement_table(agreement, superposition) -> str:
    if agreement.rates:  # displacement, velocity and acceleration, each on its own peak
        rows = [[d, *(f"{v:.2e}" for v in values)]
                for d, *values in zip(DOFS, agreement.per_dof, agreement.per_dof_qd, agreement.per_dof_qdd)]
        headers = ["DOF", "q: max |direct - modal| / peak |direct|", "q'", "q''"]
        where = f"{agreement.worst_dof}, {QUANTITIES[agreement.worst_quantity]}"
    else:
        rows = [[d, f"{v:.2e}"] for d, v in zip(DOFS, agreement.per_dof)]
        headers, where = ["DOF", "max |q_direct - q_modal| / peak |q_direct|"], agreement.worst_dof
    text = table(headers, rows) + (
        f"\n\nWorst: {agreement.worst:.2e} ({where}), {'within' if agreement.ok else 'OVER'} the "
        f"tolerance {agreement.tolerance:.0e}. Superposition used {superposition.method} modes: {superposition.reason}")
    if superposition.truncation is None:
        return text
    return (text + f"\n\nTruncated to modes {', '.join(str(j + 1) for j in superposition.modes_kept)} (residual "
            f"correction: {superposition.residual}); error against all modes: worst "
            f"{superposition.truncation.worst:.2e} ({superposition.truncation.worst_dof}).")
