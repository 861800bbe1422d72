"""The vibration severity's part of the isolation summary
(:func:`sixdof.io.isolation_report.isolation_summary_text`): each point's broadband RMS velocity, its zone with the
boundaries, and the margin to zone C (:mod:`sixdof.analysis.severity`)."""

from __future__ import annotations

from sixdof.analysis.severity import FILTER_ORDER, ZONE_MEANINGS
from sixdof.dofs import AXES
from sixdof.io.tables import table, wrapped


def _how(severity, steady) -> str:
    """Which answer the RMS comes from, and how, in words."""
    low, high = severity.band_hz
    band = f"{low:g}-{high:g} Hz"
    if severity.source == "steady":
        inside = [f for f in steady.f_hz if low <= f <= high] if steady is not None else []
        outside = [] if steady is None else [f for f in steady.f_hz if not low <= f <= high]
        listed = ", ".join(f"{f:.4g}" for f in inside) or "none"
        left = f"; outside the band, left out: {', '.join(f'{f:.4g}' for f in outside)} Hz" if outside else ""
        return (f"from the steady state, v_rms = sqrt(sum|v_k|^2/2) over the operating frequencies in {band} "
                f"({listed} Hz{left})")
    if severity.source == "random":
        return f"from the random response, its velocity PSD integrated over {band}"
    start, end = severity.window_s
    return (f"from the time history band-passed to {band} (Butterworth, order {FILTER_ORDER}, zero phase) over "
            f"{start:g}-{end:g} s")


def severity_part(severity, steady=None) -> list[str]:
    """The severity table of a :class:`~sixdof.analysis.severity.VibrationSeverity` (with the run's
    :class:`~sixdof.analysis.steady.SteadyState`, whose operating frequencies a steady-state answer lists)."""
    mm_s = 1e3
    b_ab, b_bc, b_cd = (mm_s * b for b in severity.boundaries)
    head = wrapped(f"Vibration severity: broadband RMS velocity (absolute), {_how(severity, steady)}.")
    head += "\n" + wrapped(f"Zones ({severity.basis}): A/B {b_ab:g}, B/C {b_bc:g}, C/D {b_cd:g} mm/s; each point "
                           "judged by its largest direction measured, margin to C = 1 - v / (B/C):")
    measured = set(severity.directions)
    rows = []
    for j, name in enumerate(severity.points):
        v = severity.rms_velocity[j] * mm_s
        worst = max(severity.directions, key=lambda d: v[AXES.index(d)])
        zone = severity.zones[j]
        rows.append([name, *(f"{v[i]:.3g}" if axis in measured else "-" for i, axis in enumerate(AXES)),
                     f"{severity.governing[j] * mm_s:.3g} ({worst})", f"{zone} ({ZONE_MEANINGS[zone]})",
                     f"{100 * severity.margin[j]:.0f} %" + (" EXCEEDED" if severity.margin[j] < 0 else "")])
    headers = ["point", *(f"v_rms {axis} [mm/s]" for axis in AXES), "judged [mm/s]", "zone", "margin to C"]
    return [head, table(headers, rows, "lrrrrlr")] if len(rows) else [head, "no point measured"]


__all__ = ["severity_part"]
