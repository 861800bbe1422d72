"""The text of a run: the tables ``sixdof run`` and ``sixdof modes`` print and the run's ``summary.md``, laid out
by :func:`sixdof.io.tables.table` (the isolation summary that opens them: :mod:`sixdof.io.isolation_report`; the
spectral results: :mod:`sixdof.io.spectra_report`; a sweep's, an optimization's and a validation's text:
:mod:`sixdof.io.study_report`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sixdof.analysis.compare import QUANTITIES
from sixdof.analysis.statespace import damped_modes
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.analysis.validity import body_length
from sixdof.dofs import DOF_UNITS, DOFS, display_unit
from sixdof.io.isolation_report import ISOLATION_SUMMARY, PEAKS_WITH_TRANSIENT, isolation_summary_text
from sixdof.io.spectra_report import isolation_text, random_text, records_text, spectrum_text, srs_text
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
