"""What the commands print: plain text of typed results, built from the tables of :mod:`sixdof.io.report`."""

from __future__ import annotations

import numpy as np

from sixdof.io import isolation_report, report, spectra_report


def title(results) -> str:
    """The first line a command prints of its scenario (or of results, which carry its name and description): the
    name and the description (the name alone without one)."""
    return f"{results.name}: {results.description}" if results.description else results.name


def modes_text(run) -> str:
    """``sixdof modes``: the modes table, damping, kinetic energy, subsystems and design metrics of a
    :class:`~sixdof.workflows.modes.ModalRun` (the statics follow: :func:`statics_text`)."""
    results = run.results
    system, modes, zeta = results.system, results.modes, results.damping_ratios
    return "\n".join([
        f"{title(results)}\n",
        report.modes_table(modes, zeta if system.C.any() or system.maxwell else None, system),
        report.damping_note(system), f"\n{report.decoupling_text(modes, run.metrics)}"])


def statics_text(results, no_statics: str | None = None) -> str:
    """The statics under gravity (or why there are none) and what gravity's geometric stiffness does to the
    modes (the results' ``stiffness_note``)."""
    settings = results.scenario.statics
    head = f"\nStatics under gravity ({settings.gravity} m/s^2 along {list(settings.direction)}):"
    if results.statics is None:
        return f"{head}\n{no_statics}"
    lines = [head, report.statics_table(results.statics, results.system)]
    if results.stiffness_note is not None:
        lines.append(results.stiffness_note)
    return "\n".join(lines)


def run_text(results) -> str:
    """``sixdof run``: what a run (:func:`sixdof.workflows.run.run`) found, after its title: modes, visco-elastic
    fits, statics, steady state, random vibration, shock spectra, the cross-check, mount checks, body points
    and the FRF cross-check."""
    scenario, system = results.scenario, results.system
    lines = [f"{title(results)}\n"]
    summary = isolation_report.isolation_summary_text(results)
    if summary:
        lines.append(f"{isolation_report.ISOLATION_SUMMARY}:\n{summary}")
    if results.design is not None:  # what `sixdof modes` prints after the modes
        lines.append(f"\n{report.DECOUPLING}:\n{report.decoupling_text(results.modes, results.design)}")
    if summary:
        lines.append("\nDetails and solver checks:")
    lines += [report.modes_table(results.modes, results.damping_ratios, system), report.damping_note(system)]
    if scenario.viscoelastic:
        lines.append(f"\nVisco-elastic mounts (Maxwell fits):\n{report.viscoelastic_table(scenario.viscoelastic)}")
    if results.statics is not None:
        lines.append(statics_text(results))
    if results.steady_state is not None:
        lines.append(f"\n{report.steady_state_text(results.steady_state)}")
    if results.random is not None:
        lines.append(f"\nRandom vibration:\n{spectra_report.random_text(results.random)}")
    if results.srs is not None:
        lines.append(f"\n{spectra_report.srs_text(results.srs)}")
    if results.spectrum is not None:
        lines.append(f"\nResponse spectrum: {spectra_report.spectrum_text(results.spectrum)}")
        if results.isolation is not None:
            lines.append(spectra_report.isolation_text(results.isolation))
    if results.record_peaks is not None:
        lines.append("\nSpectrum-compatible records: " + spectra_report.records_text(
            results.spectrum, results.spectrum_records, results.records_check, results.record_peaks,
            results.damping_ratios))
    if results.response is not None and results.response.stats is not None:  # a direct solve
        lines += _time_text(results)
    if results.frf is not None:
        lines.append(f"FRF direct vs modal: {results.frf.max_relative_difference:.1e} (worst relative difference)")
    return "\n".join(lines)


def _time_text(results) -> list[str]:
    """The time response's lines of :func:`run_text`."""
    scenario = results.scenario
    info = results.superposition.superposition
    until = " until the first nonlinear mount engaged" if results.contacts is not None else ""
    lines = [] if results.agreement is None else [
        f"\nDirect solve vs modal superposition ({info.method} modes){until}: {results.agreement}"]
    truncation = info.truncation
    if truncation is not None:
        kept = ", ".join(str(j + 1) for j in info.modes_kept)
        lines.append(f"Truncated to modes {kept}; against all modes: {truncation}")
    ground = scenario.excitation.ground if scenario.excitation is not None else None
    if ground is not None and ground.baseline != "none":
        lines.append(report.baseline_text(ground))
    stats = results.response.stats
    lines.append(f"Solver {stats.solver}: {stats.num_accepted} steps, {stats.num_rejected} rejected, "
                 f"{stats.wall_time_s:.2f} s")
    if results.contacts is not None:
        checks = report.nonlinear_text(results.contacts, results.energy, results.refined, results.agreement, stats)
        lines.append(f"\nNonlinear mounts:\n{checks}")
    if results.system.hysteretic.count:
        table = report.hysteresis_table(results.system, results.response, results.mount_forces)
        lines.append(f"\nHysteretic bearings (sampled):\n{table}")
    limits = np.stack([m.max_deflection for m in results.system.mounts])
    lines.append(f"\nMount checks:\n{report.mount_check_text(results.mount_check, limits)}")
    if results.points:
        steady = results.steady_state is not None
        points = report.points_table(results.points, report.moving_ground(scenario), steady, ground=results.response)
        lines.append(f"\nBody points: {points}")
    return lines
