"""The text of the studies beside a run: a sweep's percentiles, tracked modes and cross-check, an optimization's
verdict and tables, a validation's table and checks (tables laid out by :func:`sixdof.io.tables.table`)."""

from __future__ import annotations

import numpy as np

from sixdof.analysis.modal import repeated_groups
from sixdof.dofs import DOF_UNITS, DOFS, PEAK_RESPONSES, display_unit
from sixdof.io.tables import table


def _target_value(target, value: float) -> str:
    """A target's value in its unit: Hz, %, mm or deg."""
    if target.kind == "static_deflection":
        return f"{value * 1e3:.3g} mm"
    unit = {"frequency": " Hz", "decoupling": " %", "tra_angle": " deg"}[target.kind]
    return f"{value:.4g}{unit}"


def share_percent(count: int, total: int) -> str:
    """``count`` of ``total`` as a percentage with the digits that keep it honest: never "100 %" unless all,
    never "0 %" unless none (999 of 1000 is "99.9 %", not "100 %")."""
    percent = 100.0 * count / total
    for decimals in range(0, 7):
        shown = f"{percent:.{decimals}f}"
        if (float(shown) == 100.0) == (count == total) and (float(shown) == 0.0) == (count == 0):
            return f"{shown} %"
    return f"{percent:g} %"


def design_verdict(met: bool, samples_met: int, samples: int, tolerance: float) -> str:
    """The first line of ``sixdof optimize``'s report: whether the nominal (optimized) design meets every
    target, and in how many of the ``samples`` with every mount-axis stiffness scattered by +-``tolerance``
    [1] every target holds (``samples_met``)."""
    nominal = "All targets met by the nominal design" if met else "NOT MET by the nominal design"
    return (f"{nominal}; met in {share_percent(samples_met, samples)} of the scattered samples ({samples_met} of "
            f"{samples}, every mount-axis stiffness +-{100 * tolerance:g} %).")


def design_tables(problem, result, spread, peaks=None, ground_moves: bool = False, system=None) -> str:
    """The optimization's verdict (the nominal design's, and the share of the robustness study's samples
    meeting every target), its targets before and after (with the robustness study) and its variables, each
    with the rule it acts by; with ``peaks`` (the given and the optimized design's peak ``|q|`` and ``|q''|``,
    (12,) each) and the samples' peak responses, their table too (said to be absolute, the ground's drift
    included, when ``ground_moves``); with stiffness-ratio constraints, each constrained mount's ratios in
    the given design and in ``system`` (the optimized design as written; default the optimizer's)."""
    short = [f"{t.label}: {_target_value(t, v)} (short by {100 * s:.3g} % of the bound)"
             for t, v, s in zip(problem.targets, result.values, result.violations) if s > 0]
    samples = len(spread.values)
    verdict = design_verdict(not short, spread.all_met, samples, spread.tolerance)
    if short:
        verdict += "\nThe best compromise found:\n" + "\n".join(f"  {line}" for line in short)
    tolerance = f"+-{100 * spread.tolerance:g} %"
    if problem.spec.objective == "robust":
        verdict += (f"\nObjective: robust, the squared shortfalls averaged over {problem.spec.robust_samples} "
                    f"designs with every mount-axis stiffness scattered uniformly {tolerance}.")
    met_counts = np.count_nonzero(spread.met, axis=0)
    targets = table(
        ["target", "given design", "optimized", "met", f"5 / 50 / 95 % at stiffness {tolerance}", "P(met)"],
        [[t.label, _target_value(t, a), _target_value(t, b), "yes" if s == 0 else "NO",
          " / ".join(_target_value(t, p) for p in spread.percentiles[k]), share_percent(met_counts[k], samples)]
         for k, (t, a, b, s) in enumerate(zip(problem.targets, result.values_initial, result.values,
                                              result.violations))], "lrrlrr")
    units = {"stiffness": "x", "position": "m", "angle": "deg"}
    variables = table(["variable", "acts", "bounds", "given", "optimized"],
                      [[v.name, v.rule, f"[{v.bounds[0]:g}, {v.bounds[1]:g}] {units[v.parameter]}", f"{x0:.4g}",
                        f"{x:.4g}"] for v, x0, x in zip(problem.variables, result.x_initial, result.x)], "llrrr")
    text = (f"{verdict}\n\nTargets ({samples} samples with every mount-axis stiffness scattered "
            f"uniformly {tolerance}):\n{targets}\n\nVariables (stiffness as factors; acts: how a tied "
            f"variable moves its mounts):\n{variables}")
    if problem.spec.stiffness_ratio:
        text += "\n\n" + _ratio_table(problem, system if system is not None else problem.system_at(result.x))
    if peaks is None or spread.peak_percentiles is None:
        return text
    return text + "\n\n" + _design_peaks(spread, peaks, ground_moves)


def _ratio_table(problem, system) -> str:
    """Shear over compression stiffness (``k_u / k_w``, ``k_v / k_w``) of each mount a
    ``[[design.stiffness_ratio]]`` constrains, given and optimized (``system``), with its bounds."""
    rows = []
    for entry in problem.spec.stiffness_ratio:
        bounds = f"[{'-' if entry.min is None else f'{entry.min:g}'}, {'-' if entry.max is None else f'{entry.max:g}'}]"
        for name in entry.mounts:
            j = problem.names.index(name)
            ratios = [k[:2] / k[2] for k in (problem.system.stiffnesses[j], system.stiffnesses[j])]
            rows.append([name, bounds, *(" / ".join(f"{r:.4g}" for r in pair) for pair in ratios)])
    return ("Stiffness ratios, shear over compression (k_u / k_w and k_v / k_w):\n"
            + table(["mount", "bounds", "given", "optimized"], rows, "llrr"))


def _design_peaks(spread, peaks, ground_moves: bool) -> str:
    """The scenario's peak responses at the CG: the given and optimized designs, and their spread over the
    robustness samples (exact batch engine), with the diffrax cross-check's agreement."""
    tolerance = f"+-{100 * spread.tolerance:g} %"
    given, optimized = peaks
    rows = []
    for j, (quantity, unit) in enumerate(PEAK_RESPONSES):
        values = [given[j], optimized[j], *spread.peak_percentiles[j]]
        factor, shown = display_unit(values, unit)
        rows.append([f"peak {quantity}", *(f"{v * factor:.4g} {shown}" for v in values[:2]),
                     " / ".join(f"{v * factor:.4g}" for v in values[2:]) + f" {shown}"])
    check = cross_check_text(spread.responses, "samples")
    note = f"\n{check}" if check else ""
    absolute = " (absolute: the ground moves, its drift included)" if ground_moves else ""
    return (f"Peak responses at the CG{absolute} to the scenario's excitation (exact batch engine):\n"
            + table(["quantity", "given design", "optimized", f"5 / 50 / 95 % at stiffness {tolerance}"],
                    rows, "lrrr") + note)


def summary_table(frequency_hz, peak_q=None, ground_moves: bool = False) -> str:
    """Percentiles (5, 50, 95 %) of each natural frequency (nv, 6) [Hz] and each DOF's peak (nv, 6) over a
    batch of variants; read one column at a time (they may be HDF5 datasets too large to hold whole). With the
    ground moving, the peaks are said to be of the absolute motion (its drift included), not the mounts'."""
    rows = [[f"f{j + 1} [Hz]", *(f"{v:.5g}" for v in np.percentile(frequency_hz[:, j], [5, 50, 95]))]
            for j in range(6)]
    for j, (dof, unit) in enumerate(zip(DOFS, DOF_UNITS) if peak_q is not None else ()):
        values = np.percentile(peak_q[:, j], [5, 50, 95])
        scale, shown = display_unit(values, unit)
        rows.append([f"peak {dof}{' (absolute)' if ground_moves else ''} [{shown}]",
                     *(f"{scale * v:.4g}" for v in values)])
    text = f"{len(frequency_hz)} variants\n\n" + table(["quantity", "p5", "p50", "p95"], rows)
    if peak_q is not None and ground_moves:
        text += ("\n\nThe ground moves: the peaks are of the body's absolute motion, the ground's drift included, "
                 "not of the mounts' deflection.")
    return text


#: A mode paired with a nominal one by a MAC below this is not clearly that mode (the usual threshold of test-analysis
#: correlation for "the same mode shape").
SAME_SHAPE_MAC = 0.9


def tracked_modes_table(modes, tracked_hz, mac) -> str:
    """Percentiles (5, 50, 95 %) of each nominal mode's frequency over a batch of variants, followed by its shape
    (``tracked_hz`` and ``mac``, (nv, 6): :func:`sixdof.analysis.batch.track_modes`), with the lowest MAC of the
    pairing; read one column at a time, as :func:`summary_table`. ``modes``: the nominal system's."""
    labels = [f"{j + 1} ({dof})" for j, dof in enumerate(modes.dominant_dof)]
    for group in repeated_groups(modes.eigenvalues):  # no shape of its own: one of the group, in ascending order
        for j in group:
            labels[j] = f"{j + 1} (of {group[0] + 1}-{group[-1] + 1}, repeated)"
    rows, unclear = [], []
    for j, (f, name) in enumerate(zip(modes.frequency_hz, labels)):
        alike = np.asarray(mac[:, j])
        spread = np.percentile(tracked_hz[:, j], [5, 50, 95])
        rows.append([name, f"{f:.5g}", *(f"{v:.5g}" for v in spread), f"{np.min(alike):.3f}"])
        below = int(np.count_nonzero(alike < SAME_SHAPE_MAC))
        if below:
            unclear.append(f"mode {j + 1} in {below} variant{'s' if below > 1 else ''}")
    text = ("Each mode followed by its shape (the variant's mode most alike the nominal one, by mass-weighted MAC; "
            "f1..f6 above are each variant's frequencies in ascending order, which mixes modes whose frequencies "
            "cross; a repeated nominal frequency is followed as the space of its modes, their MACs summed):\n\n"
            + table(["mode (dominant DOF)", "nominal [Hz]", "p5 [Hz]", "p50 [Hz]", "p95 [Hz]", "lowest MAC"], rows))
    if unclear:
        text += (f"\n\nMAC below {SAME_SHAPE_MAC}: {', '.join(unclear)}. There the variant's mode shape has changed "
                 "so much that it is not clearly the nominal mode: its frequency spread mixes shapes.")
    return text


def cross_check_text(result, solved: str = "variants") -> str:
    """The cross-check of a batch engine by diffrax (:class:`~sixdof.analysis.batch.BatchResult`: a sweep's
    variants, or an optimization's robustness ``solved="samples"``): those solved and the worst agreement of
    their peaks; "" without one."""
    if result.cross_check is None:
        return ""
    checked = ", ".join(str(i) for i in result.cross_check_variants)
    return (f"Cross-check of the {result.engine} engine: diffrax solved {solved} {checked}; peak agreement "
            f"{result.cross_check}")


def validation_text(report) -> str:
    """The validation of a :class:`sixdof.validation.ValidationReport`: its table with each mode's
    verdict, each check against its limit, the thresholds, the notes and the overall verdict."""
    from sixdof.validation import experiment  # noqa: PLC0415 (it loads scipy.signal)

    headers, rows = report.table()
    cells = [[fmt.format(v) for (_, _, fmt), v in zip(experiment.COLUMNS, row)] for row in rows]
    verdicts = report.mode_verdicts
    if len(verdicts) == len(cells):
        headers, cells = (*headers, "verdict"), [[*row, v] for row, v in zip(cells, verdicts)]
    parts = [table(headers, cells),
             f"{len(report.random_runs)} random runs ({report.random_duration_s:.4g} s simulated) and "
             f"{len(report.decays)} free decays in {report.wall_time_s:.3g} s", *report.notes]
    if not report.checks:
        return "\n".join(parts)
    checks = [[c.mode, c.name, f"{c.value:.3g}", f"{c.limit:.3g}", c.unit, c.verdict] for c in report.checks]
    limits = "\n".join(f"  {name}: {rule}" for name, _, rule in experiment.CHECKS)
    failed = [f"mode {c.mode} {c.name}" for c in report.checks if c.verdict != experiment.PASS]
    parts += ["", "Checks (measured disagreement against its limit):",
              table(["mode", "check", "measured", "limit", "unit", "verdict"], checks, "llrrlr"),
              f"Limits: K_SIGMA = {experiment.K_SIGMA:g} standard errors, DECAY_RTOL = {experiment.DECAY_RTOL:g}, "
              f"DECAY_ZETA_ATOL = {experiment.DECAY_ZETA_ATOL:g}, PEAK_BINS = {experiment.PEAK_BINS:g}, "
              f"H1_FLOOR = {experiment.H1_FLOOR:g}, RAYLEIGH_MEDIAN = {experiment.RAYLEIGH_MEDIAN:.4f}, "
              f"MEDIAN_SPREAD = {experiment.MEDIAN_SPREAD:.4f}, BINS_PER_INDEPENDENT = "
              f"{experiment.BINS_PER_INDEPENDENT:g} (N: bins of the band with coherence >= 0.9; eps: the random "
              f"error of H1; G: the model FRF with the force's first-order hold):\n{limits}",
              f"Verdict: {report.verdict}" + (f" ({', '.join(failed)} beyond the limit)" if failed else
                                              f" (all {len(report.checks)} checks of {len(verdicts)} modes within "
                                              "their limits)")]
    return "\n".join(parts)


def correlation_table(correlation) -> str:
    """The pairs of a :class:`sixdof.validation.correlation.Correlation` (modes numbered from 1), then its verdict."""
    c = correlation
    has_body = c.mac_body is not None
    headers = ["test", "model", "f_test [Hz]", "f_model [Hz]", "error [%]", "MAC",
               *(["MAC 6-DOF"] if has_body else []), "damping test", "damping model"]
    numbers = np.arange(1, len(c.f_test) + 1) if c.test_number is None else c.test_number
    rows = [[numbers[t], m + 1, f"{c.f_test[t]:.4g}", f"{c.f_model[m]:.4g}", f"{c.frequency_error_percent[k]:+.2f}",
             f"{c.mac[t, m]:.3f}", *([f"{c.mac_body[t, m]:.3f}"] if has_body else []),
             f"{c.damping_test[t]:.4f}", f"{c.damping_model[m]:.4f}"]
            for k, (t, m) in enumerate(zip(c.pair_test, c.pair_model))]
    verdict = (f"Correlated: every test mode paired, within {c.max_frequency_error_percent:g} % and MAC >= "
               f"{c.min_mac:g}."
               if c.correlated else "NOT correlated:\n" + "\n".join(f"  {r}" for r in c.reasons))
    return table(headers, rows) + "\n" + verdict


def correlation_text(run) -> str:
    """A correlation run's report (:class:`sixdof.design.correlation.CorrelationRun`): the test, its identified
    modes, the pairs against the model and the verdict, and after an update its variables and the pairs again."""
    test, found = run.test, run.identification.modes
    low, high = run.identification.band_hz
    kind = ("FRFs" if test.kind == "frf" else
            f"time histories ({len(test.t)} samples at {test.sample_rate_hz:g} Hz; H1 from "
            f"{run.estimate.averages} Welch averages of {run.estimate.nperseg} samples, {run.estimate.window} "
            f"window, {100 * run.estimate.overlap:g} % overlap)")
    parts = [f"Test: {test.source}: {kind}, {test.n_outputs} response channels on "
             f"{len(set(test.out_nodes.tolist()))} nodes, {test.n_references} references, {low:.4g}-{high:.4g} Hz.",
             "", "Identified modes (poly-reference LSCF and LSFD, orders up to "
             f"{run.identification.stability.max_order}):",
             table(["test mode", "f [Hz]", "damping", "not rigid [%]", "correlated"],
                   [[j + 1, f"{f:.4g}", f"{z:.4f}", f"{100 * r:.1f}", "yes" if ok else "no (not rigid)"]
                    for j, (f, z, r, ok) in enumerate(zip(found.frequency_hz, found.damping_ratio,
                                                          run.projection.residual, run.rigid))]),
             "", "Motion no rigid body makes, per node [% of each mode's motion over all channels]:",
             table(["node", *(f"mode {j + 1}" for j in range(len(found.frequency_hz)))],
                   [[node, *(f"{100 * r:.1f}" for r in residuals)]
                    for node, residuals in zip(run.projection.node, run.projection.node_residual)]),
             "", "Against the model:", correlation_table(run.correlation)]
    if run.update is not None:
        u = run.update
        parts += ["", f"Update ({len(u.start)} starts; objective {u.objective_initial:.3g} -> "
                  f"{u.objective_final:.3g}):",
                  table(["variable", "unit", "given", "updated", "standard error", "determined"],
                        [[name, unit, f"{a:.5g}", f"{b:.5g}", f"{s:.3g}", "yes" if ok else "NO"]
                         for name, unit, a, b, s, ok in zip(u.variable, u.variable_units, u.initial, u.updated,
                                                            u.standard_error, u.determined)], "llrrrl"),
                  "", "Against the updated model:", correlation_table(run.correlation_updated)]
    if run.notes:
        parts += ["", *(f"Note: {n}" for n in run.notes)]
    return "\n".join(parts)
