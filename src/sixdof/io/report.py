"""Plain-text tables of results, shared by the command line and the run summary (Markdown)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sixdof.dofs import DOF_UNITS, DOFS


def table(headers: Sequence[str], rows: Sequence[Sequence[object]], align: str | None = None) -> str:
    """A Markdown pipe table, columns padded so it also reads well in a terminal.

    ``align`` gives one character per column: ``l`` left, ``r`` right (default: first column left,
    others right).
    """
    cells = [[str(h) for h in headers]] + [[str(c) for c in row] for row in rows]
    align = align or "l" + "r" * (len(headers) - 1)
    widths = [max(len(row[i]) for row in cells) for i in range(len(headers))]

    def line(row):
        padded = (c.ljust(w) if a == "l" else c.rjust(w) for c, w, a in zip(row, widths, align))
        return "| " + " | ".join(padded) + " |"

    rule = "|" + "|".join(("-" * (w + 1) + ":") if a == "r" else ("-" * (w + 2)) for w, a in zip(widths, align)) + "|"
    return "\n".join([line(cells[0]), rule, *(line(r) for r in cells[1:])])


def modes_table(modes, damping_ratios=None) -> str:
    """Natural frequencies, dominant DOF and (optionally) damping ratio of each mode."""
    headers = ["mode", "f [Hz]", "omega [rad/s]", "dominant DOF", "KE in dominant [%]"]
    if damping_ratios is not None:
        headers.append("zeta [%]")
    rows = []
    for j in range(len(modes.frequency_hz)):
        dominant = DOFS.index(modes.dominant_dof[j])
        row = [
            j + 1,
            f"{modes.frequency_hz[j]:.4f}",
            f"{modes.omega[j]:.4f}",
            modes.dominant_dof[j],
            f"{100 * modes.ke_distribution[dominant, j]:.1f}",
        ]
        if damping_ratios is not None:
            zeta = damping_ratios[j]
            row.append("-" if not np.isfinite(zeta) else f"{100 * zeta:.2f}")
        rows.append(row)
    return table(headers, rows)


def ke_table(modes) -> str:
    """Kinetic-energy distribution [%]: rows are DOFs, columns are modes (the decoupling table)."""
    headers = ["DOF"] + [f"mode {j + 1} ({f:.3g} Hz)" for j, f in enumerate(modes.frequency_hz)]
    rows = [[dof] + [f"{100 * v:.1f}" for v in modes.ke_distribution[i]] for i, dof in enumerate(DOFS)]
    return table(headers, rows)


def subsystems_text(modes) -> str:
    """One line per group of coupled DOFs."""
    lines = [f"  {i + 1}: ({', '.join(group)})" for i, group in enumerate(modes.subsystems)]
    text = "Decoupled subsystems (DOFs coupled through M and K):\n" + "\n".join(lines)
    if modes.zero_modes:
        text += (
            f"\nUnrestrained: {len(modes.zero_modes)} zero-frequency mode(s); "
            f"free DOFs: {', '.join(modes.free_dofs)}"
        )
    return text


def statics_table(statics, mount_names: Sequence[str]) -> str:
    """Static deflection of the CG and the force in each mount under gravity."""
    scale = {"m": (1e3, "mm"), "rad": (1e3, "mrad")}
    deflection = table(
        ["DOF", "static deflection"],
        [[d, f"{statics.q[i] * scale[u][0]:.5g} {scale[u][1]}"] for i, (d, u) in enumerate(zip(DOFS, DOF_UNITS))],
    )
    rows = []
    for name, force, support in zip(mount_names, statics.mount_forces, statics.support):
        state = "TENSION (uplift)" if name in statics.uplift else "compression"
        rows.append([name, *(f"{v / 1e3:.3f}" for v in force), f"{support / 1e3:.3f}", state])
    forces = table(["mount", "Fx [kN]", "Fy [kN]", "Fz [kN]", "carried [kN]", "state"], rows, "lrrrrl")
    return deflection + "\n\nForce of each mount on the body (body axes):\n" + forces


def summary_table(result) -> str:
    """Percentiles (5, 50, 95 %) of each frequency and each DOF's peak, as text."""
    lines = [f"{result.variants.count} variants", "", "quantity          p5           p50          p95"]
    for j in range(6):
        p = np.percentile(result.frequency_hz[:, j], [5, 50, 95])
        lines.append(f"f{j + 1} [Hz]      " + "  ".join(f"{v:11.5g}" for v in p))
    if result.peak_q is not None:
        for j, (dof, unit) in enumerate(zip(DOFS, DOF_UNITS)):
            p = np.percentile(result.peak_q[:, j], [5, 50, 95])
            lines.append(f"peak {dof:<2} [{unit:<3}] " + "  ".join(f"{v:11.4g}" for v in p))
    return "\n".join(lines)
