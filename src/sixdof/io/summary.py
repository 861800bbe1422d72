"""``summary.md``: the tables of a run, ready to drop into a report, with links to its figures."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sixdof.dofs import DOF_UNITS, DOFS
from sixdof.io import report

_DISPLAY = {"m": (1e3, "mm"), "rad": (1e3, "mrad")}


def summary_markdown(scenario, modes, statics, damping_ratios, response, forces, agreement,
                     superposition, frf, figures, notes) -> str:
    """The run summary as Markdown text (see :func:`sixdof.workflows.run_scenario`)."""
    parts = [f"# {scenario.name}", "", scenario.description, ""]
    if notes:
        parts += ["## Warnings", "", *(f"- {n}" for n in notes), ""]
    parts += ["## Natural frequencies", "", report.modes_table(modes, damping_ratios), ""]
    parts += ["## Kinetic energy distribution [%]", "", report.ke_table(modes), ""]
    parts += [report.subsystems_text(modes).replace("\n  ", "\n- ").replace(":\n", ":\n\n", 1), ""]
    if statics is not None:
        parts += ["## Statics under gravity", "", report.statics_table(statics, scenario.system.mount_names), ""]
    if response is not None:
        parts += ["## Time response", "", _peaks_table(response), ""]
        parts += [f"Solver: {_stats_line(response.stats)}", ""]
        parts += ["### Peak mount forces", "", _mount_peaks_table(forces), ""]
        parts += ["### Direct solve vs modal superposition", "",
                  _agreement_table(agreement, superposition.superposition), ""]
    if frf is not None:
        parts += [
            "## Frequency response",
            "",
            f"{len(frf.direct.f_hz)} frequencies from {frf.direct.f_hz[0]:g} to {frf.direct.f_hz[-1]:g} Hz; "
            f"direct and modal receptances agree to {frf.max_relative_difference:.1e} (relative, worst entry).",
            "",
        ]
    if figures:
        parts += ["## Figures", "", *(f"![{Path(f).stem}]({Path(f).name})" for f in figures), ""]
    return "\n".join(parts)


def _peaks_table(response) -> str:
    rows = []
    for i, (dof, unit) in enumerate(zip(DOFS, DOF_UNITS)):
        scale, shown = _DISPLAY[unit]
        k = int(np.argmax(np.abs(response.q[:, i])))
        rows.append([dof, f"{scale * response.q[k, i]:.5g} {shown}", f"{response.t[k]:.3f}",
                     f"{scale * np.max(np.abs(response.qd[:, i])):.5g} {shown}/s",
                     f"{scale * np.max(np.abs(response.qdd[:, i])):.5g} {shown}/s^2"])
    return report.table(["DOF", "peak q", "at t [s]", "peak |q'|", "peak |q''|"], rows)


def _mount_peaks_table(forces) -> str:
    rows = []
    for j, name in enumerate(forces.names):
        peaks = np.max(np.abs(forces.total[j]), axis=0)
        rows.append([name, *(f"{p / 1e3:.4g}" for p in peaks)])
    rows.append(["foundation (total)", *(f"{p / 1e3:.4g}" for p in np.max(np.abs(forces.foundation_force), axis=0))])
    return report.table(["mount", "peak |Fx| [kN]", "peak |Fy| [kN]", "peak |Fz| [kN]"], rows)


def _agreement_table(agreement, superposition) -> str:
    rows = [[d, f"{v:.2e}"] for d, v in zip(DOFS, agreement.per_dof)]
    verdict = "within" if agreement.ok else "OVER"
    return (
        report.table(["DOF", "max |q_direct - q_modal| / peak |q_direct|"], rows)
        + f"\n\nWorst: {agreement.worst:.2e} ({agreement.worst_dof}), {verdict} the tolerance "
        f"{agreement.tolerance:.0e}. Superposition used {superposition.method} modes: {superposition.reason}"
        + _truncation_line(superposition)
    )


def _truncation_line(superposition) -> str:
    if superposition.truncation is None:
        return ""
    kept = ", ".join(str(j + 1) for j in superposition.modes_kept)
    return (f"\n\nTruncated to modes {kept} (residual correction: {superposition.residual}); "
            f"error against all modes: worst {superposition.truncation.worst:.2e} "
            f"({superposition.truncation.worst_dof}).")


def _stats_line(stats) -> str:
    return (f"{stats.solver}, rtol {stats.rtol:g}, atol {stats.atol:g} (per-DOF scaled), "
            f"{stats.num_accepted} accepted and {stats.num_rejected} rejected steps")
