"""The text of a run's spectral results: random vibration and its check against a simulated record, shock response
spectra, the design response spectrum (with an isolated system's effective-linearization loop) and the
spectrum-compatible records, laid out by :func:`sixdof.io.tables.table` (the rest of a run's text:
:mod:`sixdof.io.report`)."""

from __future__ import annotations

import math

import numpy as np

from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.dofs import AXES, DOF_UNITS, DOFS, display_unit
from sixdof.io.tables import table, without_round_off, wrapped


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
