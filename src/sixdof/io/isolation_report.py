"""The isolation summary that opens a run's text and ``summary.md``: natural frequencies against the operating ones,
transmissibility and isolation efficiency, mount loads and deflections against their limits, peak accelerations at
the named points, and the vibration severity (:mod:`sixdof.io.severity_report`) when asked."""

from __future__ import annotations

import numpy as np

from sixdof.analysis.isolation_summary import has_operating, natural_frequencies, run_isolation_summary
from sixdof.analysis.statics import STANDARD_GRAVITY
from sixdof.analysis.steady import vector_amplitude
from sixdof.dofs import display_unit, distinct_digits
from sixdof.io.severity_report import severity_part
from sixdof.io.tables import table, without_round_off, wrapped

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
    # Where the modes resonate: on Maxwell mounts the full model's poles, above the long-term stiffness' modes.
    if summary is not None:
        natural = summary.natural_hz
    elif results.system is not None:
        natural = natural_frequencies(results.system, modes)
    else:
        natural = modes.frequency_hz
    full = not np.array_equal(natural, modes.frequency_hz)
    headers = ["mode #", "f_n, full model [Hz]" if full else "f_n [Hz]", "dominant DOF",
               *(["excited"] if curves else []), *(f"r = {f:.4g} Hz / f_n" for f in operating)]
    digits = distinct_digits(natural, 4)  # close modes printed apart
    rows = [[str(j + 1), f"{f:.{digits}g}", dof, *(["yes" if j in excited else "-"] if curves else []),
             *("-" if f <= 0 else f"{f_op / f:.3g}" for f_op in operating)]
            for j, (f, dof) in enumerate(zip(natural, modes.dominant_dof))]
    if not curves:
        return ["No operating frequency (no harmonic load or ground motion without end): natural frequencies",
                table(headers, rows)]
    lines = ["Natural frequencies against the operating frequencies (r > sqrt(2) for every excited mode: isolated):",
             table(headers, rows), ""]
    headers, rows = ["at the operating frequency", *(f"{f:.4g} Hz" for f in operating)], []
    for curve in curves:
        at = dict(zip(curve.operating_hz, curve.at_operating))
        what = {"force": "force transmissibility F_foundation / F_applied [1]",
                "moment": "moment transmissibility M_foundation / M_applied [1]",
                "motion": "motion transmissibility x_body / x_ground [1]"}[curve.kind]
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


#: Said of a run's peaks when it has a steady state (printed apart): they are not the steady state's.
PEAKS_WITH_TRANSIENT = ", the switch-on transient included"
