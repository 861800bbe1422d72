"""``report.html``: one self-contained page that a results folder hands on (a client, a design review).

The page holds the summary (the folder's Markdown summary, converted here: :func:`markdown_html`), the model
(its body and mounts as tables, ``mode_shapes.png`` as its picture), every figure of the folder with one
sentence on what it shows (:data:`FIGURE_CAPTIONS`), the checks with their verdicts and the scenario file
itself. Everything is inside the file: figures as ``data:`` URIs (PNG, or SVG where no PNG was drawn), the
style inline, no script, no font and no link to anything outside it, so that it opens the same offline, mailed
or archived.

This module draws nothing (no matplotlib): it takes the figure files the drawing wrote.
"""

from __future__ import annotations

import base64
import html
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sixdof.dofs import display_unit
from sixdof.io.tables import table

#: The file name of the report in a results folder.
REPORT = "report.html"

#: One sentence per figure file name (its stem: any format) on what the figure shows.
FIGURE_CAPTIONS = {
    "mode_shapes": "The body on its mounts in each mode of vibration, the deformed shape drawn over the rest "
                   "position, with the mode's natural frequency, dominant motion and decoupling in its title.",
    "ke_distribution": "How each mode's kinetic energy is shared among the six degrees of freedom: a mode "
                       "with nearly all of it in one degree of freedom is decoupled.",
    "time_dofs": "The motion of the centre of gravity over time, one panel per degree of freedom that "
                 "responds, with a zoom on the start or the shock.",
    "time_points": "The acceleration of each named body point over time, one panel per point that responds, "
                   "with its peak along each body axis and in g.",
    "mount_forces": "The total normal force on each mount over time, the static preload included; tension "
                    "(uplift) is shaded.",
    "mount_shear": "The shear load on each mount over time, with its peak shear deflection.",
    "hysteresis": "The force-deflection loops of the hysteretic bearings: the area of a loop is the energy "
                  "it dissipates.",
    "superposition": "The direct time integration against the independent modal superposition, and their "
                     "difference: the cross-check of the solver.",
    "bode": "The frequency response (receptance) of the centre of gravity, magnitude and phase, with the "
            "natural frequencies marked.",
    "point_frfs": "The frequency responses at the named body points, and the force and motion "
                  "transmissibilities asked for.",
    "transmissibility": "Force and motion transmissibility against frequency, the operating frequencies "
                        "marked and the isolation region shaded.",
    "validation_frf": "The FRFs estimated from simulated random-excitation time histories against the modal "
                      "model's, mode by mode.",
    "free_decays": "Simulated free decays of each mode against the modal model's frequency and damping.",
    "random": "The power spectral densities of the response to the random input, and their RMS values.",
    "random_check": "The random response's PSDs from a simulated time history against those from the FRFs, "
                    "within their statistical errors.",
    "srs": "The shock response spectra of the response: the peak response of single-degree-of-freedom "
           "oscillators tuned across frequency.",
    "spectrum": "The design response spectrum with the natural periods of the modes and their peak responses.",
    "records": "The spectrum-compatible accelerograms and their response spectra against the target.",
    "dynamic_stiffness": "The measured or given dynamic stiffness and loss factor of the mounts against "
                         "their fitted causal (Maxwell) models.",
    "stability": "The stability diagram of the test data: the poles identified at each model order, the "
                 "stable ones chosen as the test's modes.",
    "mac": "The modal assurance criterion between the test's modes and the model's: 1 on the diagonal for a "
           "model that matches.",
    "frf_overlay": "The measured FRFs against the model's (and the updated model's) on the test's channels.",
    "update_history": "How the updated variables and the frequency errors moved over the iterations of the "
                      "model update.",
    "frequencies": "The natural frequencies of the design before and after optimization, against the "
                   "targets.",
    "decoupling": "The decoupling (kinetic energy in the dominant DOF) of each mode before and after "
                  "optimization.",
    "sweep_frequencies": "Each mode's natural frequency over the sweep's variants (box: quartiles and median, "
                         "whiskers: 5th and 95th percentiles), the nominal design dashed.",
    "sweep_decoupling": "Each mode's decoupling (kinetic energy in its dominant DOF) over the sweep's variants, "
                        "the nominal design marked.",
    "sweep_peaks": "Each degree of freedom's peak displacement and acceleration over the sweep's variants.",
    "sweep_sensitivity": "Which swept parameter moves each natural frequency most: the change of the frequency "
                         "as the parameter goes across its range, from a linear fit over the variants.",
}

#: Markdown heading lines of the summary that the report shows in a section of its own.
_FIGURE_HEADING = re.compile(r"^#+\s+Figures\s*$")
_IMAGE_LINE = re.compile(r"^\s*!\[[^\]]*\]\([^)]*\)\s*$")

_STYLE = """
body { font-family: sans-serif; margin: 2em auto; max-width: 1200px; padding: 0 1em; color: #222; }
h1 { border-bottom: 2px solid #446; }
h2 { border-bottom: 1px solid #99a; margin-top: 2em; }
nav a { margin-right: 1em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; display: block; max-width: 100%;
        overflow-x: auto; }
th, td { border: 1px solid #bbc; padding: 0.2em 0.6em; }
th { background: #eef; }
td.r, th.r { text-align: right; }
tr:nth-child(even) td { background: #f7f7fb; }
figure { margin: 1.5em 0; }
figure img { max-width: 100%; border: 1px solid #ccd; }
figcaption { font-style: italic; margin-top: 0.3em; }
pre { background: #f4f4f8; border: 1px solid #ccd; padding: 0.8em; overflow-x: auto; font-size: 0.85em; }
.PASS { color: #161; font-weight: bold; }
.FAIL, .warning { color: #a11; font-weight: bold; }
"""


@dataclass(frozen=True)
class Check:
    """One check of a run and its verdict: ``what`` is checked, the ``result`` measured (against its limit), and
    the ``verdict`` (``PASS``, ``FAIL``, ``warning``, or ``reported`` where the library sets no limit)."""

    what: str
    result: str
    verdict: str


def figure_caption(name: str) -> str:
    """The sentence on what the figure file ``name`` shows (:data:`FIGURE_CAPTIONS`; a plain one when unknown)."""
    stem = Path(name).stem
    animated = re.fullmatch(r"mode_(\d+)", stem)
    if animated:  # sixdof.plots.modes.write_mode_animations
        return f"Mode {animated.group(1)} oscillating through one period, as drawn in mode_shapes (animated)."
    return FIGURE_CAPTIONS.get(stem, f"The figure {stem.replace('_', ' ')} of this run.")


# ----------------------------------------------------------------------------------------------------
# Markdown (as sixdof writes it: headings, pipe tables, lists, paragraphs, code) to HTML.
# ----------------------------------------------------------------------------------------------------


def markdown_html(text: str, heading_shift: int = 0) -> str:
    """The HTML of the Markdown that sixdof writes (:mod:`sixdof.io.report`, :mod:`sixdof.io.study_report`):
    ATX headings (``heading_shift`` levels lower, at most ``h6``), pipe tables (a table may follow a line of
    prose without a blank line between), ``-`` lists, fenced code, paragraphs, and inline ``code`` and
    ``**bold**``. Every character of the text is escaped; images are left out (the report shows the figures
    in a section of its own)."""
    lines = text.splitlines()
    out: list[str] = []
    paragraph: list[str] = []
    items: list[str] = []

    def flush() -> None:
        if paragraph:
            out.append("<p>" + "<br>\n".join(_inline(p) for p in _joined(paragraph)) + "</p>")
            paragraph.clear()
        if items:
            out.append("<ul>\n" + "\n".join(f"<li>{_inline(i)}</li>" for i in items) + "\n</ul>")
            items.clear()

    i = 0
    while i < len(lines):
        line = lines[i]
        stripped = line.strip()
        if stripped.startswith("```"):
            flush()
            end = next((j for j in range(i + 1, len(lines)) if lines[j].strip().startswith("```")), len(lines))
            out.append("<pre>" + html.escape("\n".join(lines[i + 1:end])) + "</pre>")
            i = end + 1
            continue
        heading = re.match(r"^(#{1,6})\s+(.*)$", line)
        if heading:
            flush()
            level = min(6, len(heading.group(1)) + heading_shift)
            out.append(f"<h{level}>{_inline(heading.group(2).strip())}</h{level}>")
        elif stripped.startswith("|"):
            flush()
            rows, i = _table_lines(lines, i)
            out.append(_table_html(rows))
            continue
        elif not stripped or _IMAGE_LINE.match(line):
            flush()
        elif re.match(r"^\s*[-*]\s+", line):
            if paragraph:
                flush()
            items.append(re.sub(r"^\s*[-*]\s+", "", line))
        elif items and line.startswith(" "):  # a list item's continuation
            items[-1] += " " + stripped
        else:
            if items:  # prose after a list: the list ends first
                flush()
            paragraph.append(line)
        i += 1
    flush()
    return "\n".join(out)


def _table_lines(lines: Sequence[str], start: int) -> tuple[list[str], int]:
    """The rows of the pipe table starting at ``lines[start]``, and the index after it. Rows set apart by blank
    lines stay one table (a summary that doubles its line breaks: the nonlinear mounts' text) unless a row
    followed by a rule line starts a table of its own."""
    rows, i = [], start
    while i < len(lines):
        if lines[i].strip().startswith("|"):
            rows.append(lines[i])
            i += 1
            continue
        after = next((j for j in range(i, len(lines)) if lines[j].strip()), len(lines))
        if lines[i].strip() or after == len(lines) or not lines[after].strip().startswith("|"):
            break
        following = next((j for j in range(after + 1, len(lines)) if lines[j].strip()), None)
        if following is not None and _RULE.fullmatch(lines[following].strip()) and len(rows) >= 2:
            break  # a header and its rule: another table
        i = after
    return rows, i


_RULE = re.compile(r"\|(\s*:?-+:?\s*\|)+")


def _joined(lines: Sequence[str]) -> list[str]:
    """A paragraph's lines: prose wrapped at :data:`~sixdof.io.tables.LINE` joined again, an indented line (a
    detail printed under the line above) kept on a line of its own."""
    joined: list[str] = []
    for line in lines:
        if joined and not line.startswith(" "):
            joined[-1] += " " + line.strip()
        else:
            joined.append(line.strip())
    return joined


def _inline(text: str) -> str:
    """``text`` escaped, with ``code`` and ``**bold**`` marked up."""
    parts = re.split(r"(`[^`]+`)", text)
    shown = []
    for part in parts:
        if len(part) > 1 and part.startswith("`") and part.endswith("`"):
            shown.append(f"<code>{html.escape(part[1:-1])}</code>")
        else:
            shown.append(re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", html.escape(part)))
    return "".join(shown)


def _table_html(lines: Sequence[str]) -> str:
    """A pipe table as HTML. The columns are cut where the rule line (``|---|--:|``) has its pipes when every
    row has a pipe there (:func:`sixdof.io.tables.table` pads its columns, and a cell may hold a pipe:
    ``peak |q'|``); otherwise at every pipe."""
    if len(lines) < 2 or not _RULE.fullmatch(lines[1].strip()):
        return "<pre>" + html.escape("\n".join(lines)) + "</pre>"
    rule = lines[1].strip()
    cuts = [k for k, c in enumerate(rule) if c == "|"]
    right = [cell.strip().endswith(":") for cell in rule[1:-1].split("|")]

    def cells(line: str) -> list[str]:
        line = line.strip()
        if len(line) == len(rule) and all(line[k] == "|" for k in cuts):
            return [line[a + 1:b].strip() for a, b in zip(cuts, cuts[1:])]
        return [c.strip() for c in line[1:-1 if line.endswith("|") else None].split("|")]

    def row(line: str, tag: str) -> str:
        found = cells(line)
        return "<tr>" + "".join(f'<{tag}{" class=r" if k < len(right) and right[k] else ""}>{_inline(c)}</{tag}>'
                                for k, c in enumerate(found)) + "</tr>"

    body = "\n".join(row(line, "td") for line in lines[2:])
    return f"<table>\n<thead>{row(lines[0], 'th')}</thead>\n<tbody>\n{body}\n</tbody>\n</table>"


# ----------------------------------------------------------------------------------------------------
# The model and the checks of a run.
# ----------------------------------------------------------------------------------------------------


def model_markdown(system) -> str:
    """The body and the mounts of a :class:`~sixdof.model.system.System` as Markdown tables (SI units shown
    readable: :func:`~sixdof.dofs.display_unit`)."""
    body = system.body
    inertia = np.asarray(body.inertia, dtype=float)
    rows = [["mass", f"{body.mass:.6g} kg"],
            ["inertia about the CG, Jxx Jyy Jzz", " ".join(f"{v:.6g}" for v in np.diag(inertia)) + " kg m^2"]]
    off = inertia[np.triu_indices(3, 1)]
    if np.any(off):
        rows.append(["products of inertia, Jxy Jxz Jyz", " ".join(f"{v:.6g}" for v in off) + " kg m^2"])
    if body.dimensions is not None:
        rows.append(["size drawn, Lx Ly Lz", " ".join(f"{v:.4g}" for v in body.dimensions) + " m"])
    mounts = system.mounts
    k_scale, k_unit = display_unit(np.array([m.stiffness for m in mounts]), "N/m")
    c_scale, c_unit = display_unit(np.array([m.damping for m in mounts]), "N s/m")
    mount_rows = []
    for m in mounts:
        axes = np.asarray(m.axes, dtype=float)
        w_axis = "body axes" if np.allclose(axes, np.eye(3)) else "w along " + ", ".join(f"{v:.3g}" for v in axes[2])
        limit = np.atleast_1d(m.max_deflection) * np.ones(3)
        mount_rows.append([m.name, ", ".join(f"{v:.4g}" for v in m.position),
                           ", ".join(f"{v * k_scale:.4g}" for v in m.stiffness),
                           ", ".join(f"{v * c_scale:.4g}" for v in m.damping),
                           ", ".join(f"{v:.3g}" for v in m.loss_factor), w_axis,
                           ", ".join(f"{v * 1e3:.4g}" for v in limit) if np.isfinite(limit).any() else "-"])
    headers = ["mount", "position x, y, z [m]", f"stiffness u, v, w [{k_unit}]", f"damping u, v, w [{c_unit}]",
               "loss factor u, v, w", "axes", "max deflection [mm]"]
    parts = ["### Body", "", table(["property", "value"], rows, "ll"), "", "### Mounts", "",
             table(headers, mount_rows, "lllllll")]
    nonlinear, hysteretic = system.nonlinear, system.hysteretic
    if nonlinear.count:
        parts += ["", "Nonlinear mount axes: "
                  + ", ".join(f"{n} ({k})" for n, k in zip(nonlinear.names, nonlinear.kinds)) + "."]
    if hysteretic.count:
        parts += ["", "Hysteretic mount axes: " + ", ".join(
            f"{n} ({'friction pendulum' if p else 'Bouc-Wen'})" for n, p in zip(hysteretic.names, hysteretic.pendulum))
                  + "."]
    return "\n".join(parts)


def run_checks(results) -> list[Check]:
    """The checks of a :class:`~sixdof.results.RunResults` and their verdicts, as the run judged them: the
    solver's cross-check by modal superposition, with nonlinear mounts the energy balance and the second solve
    at tighter tolerances, the FRFs' direct against modal (reported: no limit is set),
    the mount limits, the random response's time check, the records' clauses, a validation's checks, and
    every warning of the run."""
    checks = []
    agreement = results.agreement
    if agreement is not None:
        until = " (until the first mount engaged)" if results.contacts is not None else ""
        checks.append(Check("direct solve against modal superposition" + until,
                            f"worst {agreement.worst:.2e} ({agreement.worst_dof}) against the tolerance "
                            f"{agreement.tolerance:.0e}", "PASS" if agreement.ok else "FAIL"))
    energy, refined = results.energy, results.refined
    if energy is not None:
        checks.append(Check("energy balance (work of loads and ground = kinetic + stored + dissipated)",
                            f"worst residual {energy.worst:.2e} of the largest energy against the tolerance "
                            f"{energy.tolerance:.0e}", "PASS" if energy.ok else "FAIL"))
    if refined is not None:
        checks.append(Check("second solve at 100x tighter tolerances",
                            f"worst {refined.worst:.2e} ({refined.worst_dof}) against the tolerance "
                            f"{refined.tolerance:.0e}", "PASS" if refined.ok else "FAIL"))
    if results.frf is not None:
        checks.append(Check("FRF direct against modal", f"{results.frf.max_relative_difference:.1e} (worst "
                            "relative difference)", "reported"))
    if results.mount_check is not None:
        violations = results.mount_check.violations
        checks.append(Check("mount limits (max_deflection, allow_tension)",
                            "; ".join(violations) if violations else "no mount beyond its limits",
                            "FAIL" if violations else "PASS"))
    random = results.random
    if random is not None and random.time_check is not None:
        check = random.time_check
        worst = float(np.max(np.abs(check.z))) if np.size(check.z) else 0.0
        checks.append(Check("random response: time record against the FRFs",
                            f"largest |z| {worst:.3g} against {check.z_limit:.3g}", check.verdict))
    if results.records_check is not None:
        failures = results.records_check.failures
        checks.append(Check("spectrum-compatible records (EN 1998-1 3.2.3.1.2)",
                            "; ".join(failures) if failures else "every clause met", "FAIL" if failures else "PASS"))
    if results.validation is not None:
        checks += [Check(f"mode {c.mode}: {c.name.replace('_', ' ')}", f"{c.value:.3g} against {c.limit:.3g}"
                         + ("" if c.unit == "1" else f" {c.unit}"), c.verdict) for c in results.validation.checks]
    checks += [Check("warning", note, "warning") for note in results.notes or ()]
    return checks


def correlation_checks(run) -> list[Check]:
    """The verdict of a correlation run (``sixdof correlate``: a
    :class:`~sixdof.design.correlation.CorrelationRun`): the model against the test, and after an update the
    updated model (which the verdict then judges), with their reasons; then every note of the run."""
    judged = [("model against the test", run.correlation)]
    if run.correlation_updated is not None:
        judged.append(("updated model against the test", run.correlation_updated))
    checks = [Check(what, "; ".join(c.reasons) if c.reasons else "every test mode paired within the limits",
                    "PASS" if c.correlated else "FAIL") for what, c in judged if c is not None]
    return checks + [Check("note", note, "warning") for note in run.notes or ()]


# ----------------------------------------------------------------------------------------------------
# The page.
# ----------------------------------------------------------------------------------------------------


def figure_uri(path: str | Path) -> str:
    """A figure file as a ``data:`` URI (PNG, SVG or an animated GIF)."""
    path = Path(path)
    kind = {".png": "image/png", ".svg": "image/svg+xml", ".gif": "image/gif"}[path.suffix.lower()]
    return f"data:{kind};base64,{base64.b64encode(path.read_bytes()).decode('ascii')}"


def embeddable(figures: Iterable[str | Path]) -> list[Path]:
    """One file per figure of ``figures`` that a page can show: its PNG, else its SVG, else its GIF (a mode's
    animation; a PDF alone is left out), in the order given."""
    by_stem: dict[str, list[Path]] = {}
    for figure in map(Path, figures):
        by_stem.setdefault(figure.stem, []).append(figure)
    chosen = []
    for files in by_stem.values():
        order = (".png", ".svg", ".gif")
        shown = sorted((f for f in files if f.suffix.lower() in order), key=lambda f: order.index(f.suffix.lower()))
        chosen += shown[:1]
    return chosen


def report_html(title: str, summary: str, *, figures: Sequence[str | Path] = (), system=None,
                checks: Sequence[Check] = (), scenario_text: str | None = None) -> str:
    """The report page (see the module).

    Parameters
    ----------
    title : str
        The page's title and first heading (the run's name and what it is).
    summary : str
        The folder's Markdown summary; its first heading (the run's name) is left out, the title stands for it.
    figures : sequence of path
        The figure files of the folder (PNG or SVG; one per stem is shown, see :func:`embeddable`).
    system : sixdof.model.system.System, optional
        The model shown under "Model", with ``mode_shapes`` as its picture.
    checks : sequence of Check
    scenario_text : str, optional
        The scenario file, shown as it is.
    """
    shown = embeddable(figures)
    lines = summary.splitlines()
    if lines and re.match(r"^#\s", lines[0]):
        lines = lines[1:]
    lines = _without_figures(lines)
    sections = [("summary", "Summary", markdown_html("\n".join(lines), heading_shift=1))]
    model_picture = next((f for f in shown if f.stem == "mode_shapes"), None)
    if system is not None:
        picture = _figure_html(model_picture) if model_picture is not None else ""
        sections.append(("model", "Model", markdown_html(model_markdown(system)) + picture))
    others = [f for f in shown if not (system is not None and f == model_picture)]
    if others:
        sections.append(("figures", "Figures", "\n".join(_figure_html(f) for f in others)))
    if checks:
        rows = "\n".join(f"<tr><td>{html.escape(c.what)}</td><td>{html.escape(c.result)}</td>"
                         f'<td class="{html.escape(c.verdict.split()[0])}">{html.escape(c.verdict)}</td></tr>'
                         for c in checks)
        sections.append(("checks", "Checks", "<table>\n<thead><tr><th>check</th><th>result</th><th>verdict</th>"
                                             f"</tr></thead>\n<tbody>\n{rows}\n</tbody>\n</table>"))
    if scenario_text is not None:
        sections.append(("scenario", "Scenario", f"<pre>{html.escape(scenario_text)}</pre>"))
    nav = " ".join(f'<a href="#{key}">{heading}</a>' for key, heading, _ in sections)
    body = "\n".join(f'<section id="{key}">\n<h2>{heading}</h2>\n{content}\n</section>'
                     for key, heading, content in sections)
    return (f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{html.escape(title)}"
            f"</title>\n<style>{_STYLE}</style>\n</head>\n<body>\n<h1>{html.escape(title)}</h1>\n<nav>{nav}</nav>\n"
            f"{body}\n</body>\n</html>\n")


def _without_figures(lines: list[str]) -> list[str]:
    """The summary's lines without its "Figures" heading and image links (the report embeds the figures)."""
    return [line for line in lines if not (_FIGURE_HEADING.match(line) or _IMAGE_LINE.match(line))]


def _figure_html(path: Path) -> str:
    name = html.escape(path.name)
    return (f'<figure id="{html.escape(path.stem)}"><img src="{figure_uri(path)}" alt="{name}">\n'
            f"<figcaption><code>{name}</code>: {html.escape(figure_caption(path.name))}</figcaption></figure>")


def write_report(folder: str | Path, title: str, summary: str, *, figures: Sequence[str | Path] = (),
                 system=None, checks: Sequence[Check] = (), scenario_text: str | None = None) -> Path:
    """Write :func:`report_html` as ``folder/report.html`` (a results folder being staged: it is put in place
    with the rest, :mod:`sixdof.io.output`). Returns the file."""
    path = Path(folder) / REPORT
    path.write_text(report_html(title, summary, figures=figures, system=system, checks=checks,
                                scenario_text=scenario_text), encoding="utf-8")
    return path


def write_run_report(folder: str | Path, results, summary: str, figures: Sequence[str | Path] = (),
                     title: str | None = None) -> Path:
    """:func:`write_report` for a :class:`~sixdof.results.RunResults` (a run's or a validation's): its model as
    the scenario file gives it (``results.scenario.given_system``: no fits, no linearization), checks
    (:func:`run_checks`) and scenario file (``results.scenario.text``)."""
    scenario = results.scenario
    system = results.system if scenario is None else scenario.given_system
    return write_report(folder, title or results.name, summary,
                        figures=figures, system=system, checks=run_checks(results),
                        scenario_text=None if scenario is None else scenario.text)
