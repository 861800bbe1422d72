"""What ``design.h5`` holds (``sixdof optimize``): the optimization's history, variables, targets and robustness
study as a described result (:class:`DesignRecord`), written and read back by the results store like a run's
(:func:`sixdof.io.store.write_results`, :func:`sixdof.io.store.load_results`).

Every axis is labelled by a dataset of the root (``variable``, ``target``, ``iteration``, ``start``, ``sample``,
``percentile``; with peak responses ``response``; with the batch engine's samples ``dof``, ``mode``, ``mount``,
``mount_axis``): each is a field of its own, declared before the arrays along it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sixdof.dofs import DOFS, MOUNT_AXES, PEAK_RESPONSES, UNITS, MixedUnits
from sixdof.frozen import Frozen
from sixdof.results import Result, label, part, quantity, result_type

#: Units of each kind of variable and target (pint-parseable).
VARIABLE_UNITS = {"stiffness": "1", "position": "m", "angle": "degree"}
TARGET_UNITS = {"frequency": "Hz", "decoupling": "percent", "static_deflection": "m", "tra_angle": "degree"}
#: Units of the :data:`~sixdof.design.optimize.PEAK_RESPONSES`.
PEAK_UNITS = MixedUnits((("response", tuple(unit for _, unit in PEAK_RESPONSES)),),
                        "peak |q| m, rad (x ... rz), then peak |q''| m/s^2, rad/s^2")


def _per_variable(record) -> MixedUnits:
    return MixedUnits((("variable", record.variable_units),), "stiffness factors 1, position offsets m, angles degree")


def _per_target(record) -> MixedUnits:
    return MixedUnits((("target", record.target_units),),
                      "frequency Hz, decoupling percent, static deflection m, TRA angle degree")


def _objective(record) -> str:
    return "sum of squared relative violations (optimizer's margin)" + (
        "" if record.objective == "nominal" else f", averaged over the {record.robust_samples} samples of the "
        "robust objective")


@result_type
@dataclass(frozen=True, eq=False)
class DesignRobustness(Frozen, Result):
    """The robustness study's settings and verdict (the attributes of ``/robustness``).

    Attributes
    ----------
    tolerance : float
        The stiffness scatter [1] (+- this share of each mount-axis stiffness).
    samples, samples_all_met : int
        How many samples were drawn, and how many meet every target at once.
    seed : int
    engine : str
        What computed the samples' responses.
    cross_check_worst, cross_check_tolerance : float or None
        The diffrax cross-check of a few samples: its worst relative difference and tolerance.
    cross_check_ok : bool or None
    cross_check_definition : str or None
        What the cross-check's per-DOF differences measure (the description of ``cross_check_per_dof``).
    """

    tolerance: float = label(decode=float)
    samples: int = label(decode=int)
    samples_all_met: int = label(decode=int)
    seed: int = label(decode=int)
    engine: str = label(decode=str)
    cross_check_worst: float | None = label(default=None)
    cross_check_tolerance: float | None = label(default=None)
    cross_check_ok: bool | None = label(default=None, decode=bool)
    cross_check_definition: str | None = label(default=None)


@result_type
@dataclass(frozen=True, eq=False, kw_only=True)  # keywords only: each axis' label comes first, optional or not
class DesignRecord(Frozen, Result):
    """The outcome of ``sixdof optimize`` as ``design.h5`` stores it (:func:`design_record` builds one).

    Attributes
    ----------
    variable, target : ndarray of str, shape (n_var,), (n_target,)
        The variables' names and the targets' labels.
    iteration, start, sample : ndarray of int
        Numbers of the optimizer's iterations, of its starts and of the robustness samples.
    percentile : ndarray, shape (3,)
        5, 50, 95 [percent].
    response, dof, mode, mount, mount_axis : ndarray of str or None
        Labels of the peak responses (with a simulation) and of the batch engine's arrays (``mode``: numbers
        1-6).
    starts, x_initial, x, lower_bound, upper_bound : ndarray
        Starting points, the given and the optimized variables, their bounds (units: :attr:`variable_units`).
    values_initial, values, violations_initial, violations, met : ndarray, shape (n_target,)
        Target values (units: :attr:`target_units`) and shortfalls [1] of the given and the optimized design;
        whether each target is met.
    peaks_initial, peaks : ndarray, shape (12,), or None
        Peak responses of the given and the optimized design (units: :data:`PEAK_UNITS`).
    history_start_index, history_objective, history_x, history_values, history_violations : ndarray
        Each iteration's start, objective [1], variables, target values and shortfalls (``/history``).
    robustness_probability : ndarray, shape (n_target,)
        Share of the samples meeting each target [1].
    robustness_percentiles : ndarray, shape (n_target, 3)
        The 5th, 50th and 95th percentiles of each target's value over the samples (units: :attr:`target_units`).
    robustness_values : ndarray, shape (n_sample, n_target)
        Each sample's target values (units: :attr:`target_units`).
    robustness_peak_percentiles : ndarray, shape (12, 3), or None
        Percentiles of the peak responses over the samples (units: :data:`PEAK_UNITS`).
    robustness_stiffness_factor : ndarray, shape (n_sample, n_mount, 3), or None
        Each sample's factor [1] on each mount axis' stiffness (from the batch engine).
    robustness_frequency_hz : ndarray, shape (n_sample, 6), or None
        Each sample's natural frequencies [Hz].
    robustness_peak_q, robustness_peak_qdd : ndarray, shape (n_sample, 6), or None
        Each sample's peak displacement [m, rad] and acceleration [m/s^2, rad/s^2] per DOF.
    robustness_checked_sample : ndarray of int or None
        Indices of the samples the batch engine's results were cross-checked on by the direct solve.
    robustness_cross_check_peak_q, robustness_cross_check_peak_qdd : ndarray, shape (n_checked, 6), or None
        Their peaks from the direct solve [m, rad], [m/s^2, rad/s^2].
    robustness_cross_check_per_dof : ndarray, shape (6,), or None
        The cross-check's difference per DOF [1] (what it measures: ``robustness.cross_check_definition``).
    robustness : DesignRobustness
    name : str
        The scenario's.
    all_met : bool
    objective : str
        ``"nominal"`` or ``"robust"``.
    robust_samples : int
        Samples of the robust objective (0 for the nominal one).
    variable_units, target_units : tuple of str
        The unit of each variable and of each target.
    provenance : mapping of str to str
        ``scenario_text``, and once read back every root attribute (versions, creation time).
    """

    variable: np.ndarray = quantity("", ("variable",))
    target: np.ndarray = quantity("", ("target",))
    iteration: np.ndarray = quantity("1", ("iteration",))
    start: np.ndarray = quantity("1", ("start",))
    sample: np.ndarray = quantity("1", ("sample",))
    percentile: np.ndarray = quantity("percent", ("percentile",))
    response: np.ndarray | None = quantity("", ("response",), default=None)
    dof: np.ndarray | None = quantity("", ("dof",), default=None)
    mode: np.ndarray | None = quantity("1", ("mode",), default=None)
    mount: np.ndarray | None = quantity("", ("mount",), default=None)
    mount_axis: np.ndarray | None = quantity("", ("mount_axis",), default=None)
    history_start_index: np.ndarray = quantity("1", ("iteration",), name="history/start_index")
    history_objective: np.ndarray = quantity("1", ("iteration",), name="history/objective", description=_objective)
    history_x: np.ndarray = quantity(_per_variable, ("iteration", "variable"), name="history/x")
    history_values: np.ndarray = quantity(_per_target, ("iteration", "target"), name="history/values")
    history_violations: np.ndarray = quantity("1", ("iteration", "target"), name="history/violations",
                                              description="the constraints: shortfall relative to each target's "
                                              "bound, 0 where met")
    starts: np.ndarray = quantity(_per_variable, ("start", "variable"))
    x_initial: np.ndarray = quantity(_per_variable, ("variable",))
    x: np.ndarray = quantity(_per_variable, ("variable",))
    lower_bound: np.ndarray = quantity(_per_variable, ("variable",))
    upper_bound: np.ndarray = quantity(_per_variable, ("variable",))
    values_initial: np.ndarray = quantity(_per_target, ("target",))
    values: np.ndarray = quantity(_per_target, ("target",))
    violations_initial: np.ndarray = quantity("1", ("target",))
    violations: np.ndarray = quantity("1", ("target",), description="shortfall relative to each target's bound; 0: met")
    met: np.ndarray = quantity("1", ("target",))
    peaks_initial: np.ndarray | None = quantity(PEAK_UNITS, ("response",), description="given design", default=None)
    peaks: np.ndarray | None = quantity(PEAK_UNITS, ("response",), description="optimized design", default=None)
    robustness_probability: np.ndarray = quantity("1", ("target",), name="robustness/probability")
    robustness_percentiles: np.ndarray = quantity(_per_target, ("target", "percentile"),
                                                  name="robustness/percentiles")
    robustness_values: np.ndarray = quantity(_per_target, ("sample", "target"), name="robustness/values")
    robustness_peak_percentiles: np.ndarray | None = quantity(PEAK_UNITS, ("response", "percentile"), default=None,
                                                              name="robustness/peak_percentiles")
    robustness_stiffness_factor: np.ndarray | None = quantity("1", ("sample", "mount", "mount_axis"), default=None,
                                                              name="robustness/stiffness_factor")
    robustness_frequency_hz: np.ndarray | None = quantity("Hz", ("sample", "mode"), default=None,
                                                          name="robustness/frequency_hz")
    robustness_peak_q: np.ndarray | None = quantity(UNITS["q"], ("sample", "dof"), default=None,
                                                    name="robustness/peak_q")
    robustness_peak_qdd: np.ndarray | None = quantity(UNITS["qdd"], ("sample", "dof"), default=None,
                                                      name="robustness/peak_qdd")
    robustness_checked_sample: np.ndarray | None = quantity("1", ("checked_sample",), default=None,
                                                            name="robustness/checked_sample")
    robustness_cross_check_peak_q: np.ndarray | None = quantity(UNITS["q"], ("checked_sample", "dof"), default=None,
                                                                name="robustness/cross_check_peak_q")
    robustness_cross_check_peak_qdd: np.ndarray | None = quantity(
        UNITS["qdd"], ("checked_sample", "dof"), default=None, name="robustness/cross_check_peak_qdd")
    robustness_cross_check_per_dof: np.ndarray | None = quantity(
        "1", ("dof",), default=None, name="robustness/cross_check_per_dof",
        description=lambda record: record.robustness.cross_check_definition)
    robustness: DesignRobustness = part(DesignRobustness, group="robustness")
    name: str = label(name="scenario_name", default="")
    all_met: bool = label(decode=bool)
    objective: str = label(decode=str)
    robust_samples: int = label(decode=int)
    variable_units: tuple[str, ...] = label()
    target_units: tuple[str, ...] = label()
    provenance: Any = field(default_factory=dict)


def design_record(problem, result, spread, scenario, peaks=None) -> DesignRecord:
    """The :class:`DesignRecord` of an optimization.

    Parameters
    ----------
    problem : sixdof.design.problem.DesignProblem
    result : sixdof.design.optimize.DesignResult
    spread : sixdof.design.optimize.Robustness
    scenario : sixdof.io.scenario.Scenario
    peaks : tuple of ndarray, optional
        Peak responses (12,) of the given and of the optimized design.
    """
    from sixdof._jax import jax

    history, n_var = result.history, len(problem.variables)
    batch = spread.responses
    check = None if batch is None else batch.cross_check
    robust = problem.spec.objective == "robust"
    return DesignRecord(
        variable=np.array([v.name for v in problem.variables]), target=np.array([t.label for t in problem.targets]),
        iteration=np.arange(len(history)), start=np.arange(len(result.starts)), sample=np.arange(len(spread.values)),
        percentile=np.array([5.0, 50.0, 95.0]),
        response=None if peaks is None else np.array([name for name, _ in PEAK_RESPONSES]),
        dof=None if batch is None else np.array(DOFS), mode=None if batch is None else np.arange(1, 7),
        mount=None if batch is None else np.array(problem.names),
        mount_axis=None if batch is None else np.array(MOUNT_AXES),
        history_start_index=history[:, 0].astype(int), history_objective=history[:, 1],
        history_x=history[:, 2:2 + n_var], history_values=history[:, 2 + n_var:],
        history_violations=np.asarray(jax.vmap(problem.violations)(history[:, 2 + n_var:])),
        starts=result.starts, x_initial=result.x_initial, x=result.x, lower_bound=problem.bounds[:, 0],
        upper_bound=problem.bounds[:, 1], values_initial=result.values_initial, values=result.values,
        violations_initial=result.violations_initial, violations=result.violations, met=result.met,
        peaks_initial=None if peaks is None else peaks[0], peaks=None if peaks is None else peaks[1],
        robustness_probability=spread.probability, robustness_percentiles=spread.percentiles,
        robustness_values=spread.values, robustness_peak_percentiles=None if peaks is None else spread.peak_percentiles,
        robustness_stiffness_factor=None if batch is None else batch.variants.stiffness_factor,
        robustness_frequency_hz=None if batch is None else batch.frequency_hz,
        robustness_peak_q=None if batch is None else batch.peak_q,
        robustness_peak_qdd=None if batch is None else batch.peak_qdd,
        robustness_checked_sample=None if check is None else batch.cross_check_variants,
        robustness_cross_check_peak_q=None if check is None else batch.cross_check_peak_q,
        robustness_cross_check_peak_qdd=None if check is None else batch.cross_check_peak_qdd,
        robustness_cross_check_per_dof=None if check is None else check.per_dof,
        robustness=DesignRobustness(
            tolerance=spread.tolerance, samples=len(spread.values), samples_all_met=spread.all_met,
            seed=problem.spec.seed, engine="exact batch", cross_check_worst=None if check is None else check.worst,
            cross_check_tolerance=None if check is None else check.tolerance,
            cross_check_ok=None if check is None else bool(check.ok),
            cross_check_definition=None if check is None else check.definition),
        name=scenario.name, all_met=bool(np.all(result.met)), objective=problem.spec.objective,
        robust_samples=problem.spec.robust_samples if robust else 0,
        variable_units=tuple(VARIABLE_UNITS[v.parameter] for v in problem.variables),
        target_units=tuple(TARGET_UNITS[t.kind] for t in problem.targets),
        # Where the scenario's relative file references (CSV tables) are read from, for `sixdof plot` to rebuild
        # it: a redraw from another folder would not find them.
        provenance={"scenario_text": scenario.text,
                    **({"scenario_folder": str(scenario.path.resolve().parent)} if scenario.path else {})})
