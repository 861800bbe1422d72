"""``sixdof optimize``: a scenario's mount design optimized and its robustness studied (:func:`design_run`,
without files), then written into ``<out>/<name>_design/`` (:func:`save_design`): ``optimized.toml`` (the
scenario with the optimized mounts, which ``sixdof run`` accepts as it is), ``design.h5`` (history, variables,
targets, robustness), ``summary.md`` and figures. All or nothing, as every run (:mod:`sixdof.io.output`)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sixdof.analysis.batch import make_variants, run_batch
from sixdof.analysis.design import design_metrics, mode_of_each_dof
from sixdof.analysis.statics import replace_with_preload
from sixdof.design.optimize import DesignResult, Robustness, optimize, robustness
from sixdof.design.problem import DesignProblem
from sixdof.design.record import design_record
from sixdof.design.scenario_text import scenario_text
from sixdof.errors import readonly
from sixdof.io import html_report, output, report, study_report
from sixdof.io.scenario import parse_scenario
from sixdof.io.store import write_results
from sixdof.plots import png
from sixdof.plots.design import plot_design_decoupling, plot_design_frequencies
from sixdof.progress import meter
from sixdof.schema import naming
from sixdof.workflows.prepare import prepare
from sixdof.workflows.tasks import task_runner


@dataclass(frozen=True, eq=False)
class DesignRun:
    """What :func:`design_run` computed.

    Attributes
    ----------
    scenario : sixdof.io.scenario.Scenario
        Prepared.
    problem : DesignProblem
        The targets and variables on the given design.
    result : DesignResult
        The optimization, evaluated on the design as written.
    robustness : Robustness
    system : sixdof.model.system.System
        The optimized system, as written (:func:`written_design`).
    peaks : tuple of ndarray or None
        Peak responses of the given and the optimized design (with a ``[simulation]``).
    tables : str
        The report's tables (:func:`sixdof.io.study_report.design_tables`).
    """

    scenario: object
    problem: DesignProblem
    result: DesignResult
    robustness: Robustness
    system: object
    peaks: object
    tables: str

    @property
    def met(self) -> bool:
        """Whether the optimized design meets every target."""
        return bool(np.all(self.result.met))


#: The files a design's folder holds, figures last.
DESIGN_FILES = ("optimized.toml", "design.h5", "summary.md", "report.html", "frequencies.png", "decoupling.png")


def optimized_toml(scenario, system) -> str:
    """The scenario's text with the mounts of ``system``, the name ``<name>_optimized`` and a description and
    first line that say so (:func:`sixdof.design.scenario_text.scenario_text`: comments and layout kept,
    relative file references made absolute)."""
    source = scenario.path.name if scenario.path is not None else "the scenario"
    return scenario_text(
        scenario, system, name=f"{scenario.name}_optimized", note=OPTIMIZED_NOTE.format(name=scenario.name),
        header=(f"# Written by `sixdof optimize` from {source}: its [[mounts]] position, stiffness and axes are the\n"
                f"# optimized design's; the comments below are the original's and may describe the mounts before.\n"))


#: The optimized scenario's description says what it is (``sixdof run`` prints it as its title).
OPTIMIZED_NOTE = "mounts optimized by sixdof optimize for the [design] targets of {name}"


def design_run(scenario, *, progress: bool = False, log=None, runner=None, problem=None) -> DesignRun:
    """Optimize ``scenario``'s mounts for its ``[design]`` targets and study the design's robustness, writing
    nothing.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario or str or pathlib.Path
        With ``[[design.target]]`` and ``[[design.vary]]`` entries.
    progress : bool
        Show the starts done.
    log : callable, optional
        Receives the terminal's tables (default: nothing printed).
    runner : optional
        Where the robustness study's chunks run (:func:`sixdof.workflows.tasks.task_runner`): default this process.
    problem : DesignProblem, optional
        The scenario's design problem, when the caller has built it already (to refuse a bad ``[design]`` early).

    Returns
    -------
    DesignRun
    """
    scenario = prepare(scenario)
    problem = _problem(scenario) if problem is None else problem
    shown = meter(progress, scenario.design.starts, "starts", "optimize")
    result = optimize(problem, progress=shown)
    shown.close()
    # What is reported, studied and written is the design as written, with the digits that matter.
    system = written_design(scenario.system, problem.system_at(result.x))
    as_written = DesignProblem(system, scenario.design, scenario.statics.gravity, scenario.statics.direction)
    result = _evaluated(result, as_written)
    spread = robustness(as_written, as_written.initial, runner, scenario.excitation, scenario.simulation,
                        progress, time_model=scenario.time_model)
    peaks = None if spread.peak_percentiles is None else tuple(
        _peaks(s, scenario) for s in (scenario.system, system))
    tables = study_report.design_tables(problem, result, spread, peaks, report.moving_ground(scenario), system)
    if log is not None:
        log(tables)
    return DesignRun(scenario=scenario, problem=problem, result=result, robustness=spread, system=system,
                     peaks=peaks, tables=tables)


def save_design(run: DesignRun, out_root: str | Path = "outputs") -> Path:
    """Write a design (:func:`design_run`) into ``<out_root>/<name>_design/`` (:data:`DESIGN_FILES`), all or
    nothing. Returns the folder."""
    target = output.check_target(out_root, run.scenario.name, "_design")
    return output.write_folder(target, lambda stage: _save_into(stage, run))


def optimize_scenario(scenario, out_root: str | Path = "outputs", *, progress: bool = True, log=print,
                      workers: int | None = None, scheduler: str | None = None,
                      client=None) -> tuple[DesignRun, Path]:
    """:func:`design_run`, then :func:`save_design`: what ``sixdof optimize`` does, the folder and the place to run
    (``workers``, ``scheduler``, ``client``: :func:`sixdof.workflows.tasks.task_runner`) checked before the
    optimization.

    Parameters
    ----------
    scenario : sixdof.io.scenario.Scenario or str or pathlib.Path
        With ``[[design.target]]`` and ``[[design.vary]]`` entries.
    out_root : str or pathlib.Path, optional
        The folder the ``<name>_design/`` folder is written into. Default ``"outputs"``.
    progress : bool, optional
        Show the starts done. Default True.
    log : callable, optional
        Receives the terminal's tables. Default ``print``.
    workers : int, optional
        Run the robustness study on a local Dask cluster of that many worker processes.
    scheduler : str, optional
        Address of an existing Dask scheduler to run it on.
    client : distributed.Client, optional
        An existing Dask client to run it with (left open).

    Returns
    -------
    tuple of (DesignRun, pathlib.Path)
        The design and the folder written.

    Raises
    ------
    InputError
        Before the optimization: a scenario name that is not one safe path component, an ``out_root``
        that cannot be written, or a target that is a file, a link, or a folder sixdof did not write
        (:func:`sixdof.io.output.check_target`).
        Or a bad ``[design]`` table, or ``workers``, ``scheduler`` and ``client`` that
        :func:`sixdof.workflows.tasks.task_runner` refuses.
    """
    scenario = prepare(scenario)
    problem = _problem(scenario)  # its refusals before a cluster is started
    target = output.check_target(out_root, scenario.name, "_design")
    with task_runner(workers, scheduler, client) as runner:  # a bad address fails before the optimization
        run = design_run(scenario, progress=progress, log=log, runner=runner, problem=problem)
    return run, output.write_folder(target, lambda stage: _save_into(stage, run))


def _problem(scenario) -> DesignProblem:
    """The design problem of the given design; refusals of the scenario's mounts and ``[design]`` named like the
    file's own errors."""
    with naming(scenario.path):
        return DesignProblem(scenario.system, scenario.design, scenario.statics.gravity, scenario.statics.direction)


def design_figures(scenario, problem: DesignProblem, system) -> dict:
    """The figures of a design (file name -> :class:`matplotlib.figure.Figure`): the given design's modes
    (``scenario.system``) against the optimized ``system``'s, frequencies and decoupling."""
    decoupling = next((t for t in problem.targets if t.kind == "decoupling"), None)
    coordinates = "body" if decoupling is None else decoupling.coordinates
    before, after = (_decoupling(s, scenario.design.torque_axis, coordinates) for s in (scenario.system, system))
    return {
        "frequencies.png": plot_design_frequencies(scenario.system.modes, system.modes, problem.targets,
                                                   name=scenario.name),
        "decoupling.png": plot_design_decoupling(
            before, after, coordinates=coordinates, name=scenario.name,
            minimum=None if decoupling is None else decoupling.min_percent,
            covered=None if decoupling is None or decoupling.dof is None else [decoupling.dof]),
    }


def record_figures(record, base_dir: str | Path = ".") -> dict:
    """:func:`design_figures` of a stored design (a ``design.h5``'s :class:`~sixdof.design.record.DesignRecord`):
    its scenario rebuilt from the text it stores (files it names read from ``base_dir``), the optimized design
    from its variables ``x`` as the optimization wrote it (:func:`written_design`)."""
    scenario = prepare(parse_scenario((record.provenance or {}).get("scenario_text", ""),
                                      f"{record.name} (scenario text of design.h5)", base_dir=base_dir))
    problem = _problem(scenario)
    return design_figures(scenario, problem, written_design(scenario.system, problem.system_at(record.x)))


def _save_into(stage: Path, run: DesignRun) -> None:
    scenario, problem, system = run.scenario, run.problem, run.system
    figures = design_figures(scenario, problem, system)
    (stage / "optimized.toml").write_text(optimized_toml(scenario, system), encoding="utf-8")
    write_results(stage / "design.h5", design_record(problem, run.result, run.robustness, scenario, run.peaks))
    for file_name, fig in figures.items():
        (stage / file_name).write_bytes(png(fig))
    heading = f"# {scenario.name}: mount design\n\n"
    images = "".join(f"![{n[:-4]}]({n})\n\n" for n in figures)
    (stage / "summary.md").write_text(heading + run.tables + "\n\n" + images, encoding="utf-8")
    html_report.write_report(stage, f"{scenario.name}: mount design", heading + run.tables,
                             figures=[stage / name for name in figures], system=system, scenario_text=scenario.text)


#: Significant figures of an optimized stiffness [N/m] as written and reported: 4 change it by at most 5e-5 of
#: itself, and a natural frequency by 2.5e-5, far inside the 1 % margin the optimizer keeps within each target
#: (:data:`sixdof.design.problem.MARGIN`) and the +-15 % a catalogue mount's stiffness scatters by.
STIFFNESS_DIGITS = 4
#: Resolution [m] of an optimized mount position as written and reported: 0.1 mm, a drawing's.
POSITION_RESOLUTION = 1e-4
#: Decimals of an optimized mount's axes (direction cosines) as written and reported: a turn of 1e-9 rad at
#: most, and rows orthonormal to 1e-9, well within the 1e-6 a scenario's axes are checked to.
AXES_DECIMALS = 9


def written_design(given, optimized):
    """``optimized`` (a :class:`~sixdof.model.system.System`) with each mount stiffness the optimization changed
    rounded to :data:`STIFFNESS_DIGITS` significant figures, each position it changed to
    :data:`POSITION_RESOLUTION` and axes it turned to :data:`AXES_DECIMALS`; what ``given`` had stays as it
    was, with its own preload."""
    mounts = []
    for before, after in zip(given.mounts, optimized.mounts):
        stiffness = [k if k == k0 else float(f"{k:.{STIFFNESS_DIGITS}g}")
                     for k, k0 in zip(after.stiffness.tolist(), before.stiffness.tolist())]
        position = [p if p == p0 else round(round(p / POSITION_RESOLUTION) * POSITION_RESOLUTION, 10)
                    for p, p0 in zip(after.position.tolist(), before.position.tolist())]
        axes = after.axes if np.array_equal(after.axes, before.axes) else np.round(after.axes, AXES_DECIMALS) + 0.0
        mounts.append(dataclasses.replace(after, stiffness=stiffness, position=position, axes=axes))
    return replace_with_preload(optimized, mounts=mounts)


def _evaluated(result: DesignResult, problem: DesignProblem) -> DesignResult:
    """``result`` with the target values and violations of ``problem``'s given design (the design as written)."""
    values = np.asarray(problem.values(problem.initial))
    return dataclasses.replace(result, values=readonly(values),
                               violations=readonly(np.asarray(problem.violations(values))))


def _peaks(system, scenario) -> np.ndarray:
    """Peak ``|q|`` and ``|q''|`` (12,) of ``system`` under the scenario's loads, by the exact batch engine
    that computes the robustness samples."""
    found = run_batch(system, make_variants(system, count=1), scenario.excitation, scenario.simulation,
                      time_system=scenario.time_model(system), cross_check=0)
    return np.concatenate([found.peak_q[0], found.peak_qdd[0]])


def _decoupling(system, torque_axis, coordinates: str) -> np.ndarray:
    """Decoupling [%] of the mode each DOF dominates, in DOF order."""
    metrics = design_metrics(system, torque_axis)
    shares = metrics.decoupling_percent if coordinates == "body" else metrics.decoupling_tra_percent
    return shares[mode_of_each_dof(system.modes)]
