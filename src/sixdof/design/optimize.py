"""Find a mount design that meets its targets, and how robust it is.

:func:`optimize` minimizes :meth:`DesignProblem.objective` (the squared violations) within the variables'
bounds with scipy's L-BFGS-B, given exact gradients by JAX (``jax.value_and_grad``, compiled once): a
bounded, smooth, small problem (a few to a few tens of variables) for which a quasi-Newton method with
exact gradients converges in tens of iterations; optimistix and optax add nothing there and have no
simple bounds. It starts from the given design and from ``spec.starts - 1`` points drawn uniformly within
the bounds (seeded), stops a start once every target is met with its margin, and keeps the best design.
With ``[[design.stiffness_ratio]]`` constraints (linear in the stiffness factors) it uses scipy's SLSQP
instead, the same search with those inequalities, each kept with the margin
:data:`~sixdof.design.problem.RATIO_MARGIN`; a design within them beats any outside.
With ``objective = "robust"`` the same search minimizes the squared shortfalls averaged over a fixed
sample of scattered designs (:meth:`DesignProblem.objective`).

:func:`robustness` scatters every mount-axis stiffness of a design by independent factors uniform in
``1 +- tolerance``: a sweep of the design on the exact batch engine (frequencies and peak responses, some
checked by diffrax), with the targets of each sample evaluated exactly (the same function, ``jax.vmap``-ed).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.analysis.batch import BatchResult
from sixdof.analysis.sweep import Study, SweepSpec, Vary, sweep_on
from sixdof.chunks import InProcess
from sixdof.design.problem import MARGIN, RATIO_MARGIN, DesignProblem
from sixdof.errors import readonly

#: How far a stiffness-ratio constraint, in units of the mount's compression stiffness, may be broken by an
#: SLSQP iterate's round-off and still count as kept (its bound has the relative margin RATIO_MARGIN, 1e-3).
RATIO_SLACK_ATOL = 1e-9


@dataclass(frozen=True, eq=False)
class DesignResult:
    """What :func:`optimize` found.

    Attributes
    ----------
    x, x_initial : ndarray, shape (n_variables,)
        The best design's variables and the given design's.
    values, values_initial : ndarray, shape (n_targets,)
        Each target's value for them (see :mod:`sixdof.design.problem`).
    violations, violations_initial : ndarray, shape (n_targets,)
        Each target's shortfall relative to its bound (0: met), without the optimizer's margin.
    history : ndarray, shape (n_iterations, 2 + n_variables + n_targets)
        Per iteration of every start: start index, objective, variables, target values.
    starts : ndarray, shape (n_starts, n_variables)
        The starting points.
    """

    x: np.ndarray
    x_initial: np.ndarray
    values: np.ndarray
    values_initial: np.ndarray
    violations: np.ndarray
    violations_initial: np.ndarray
    history: np.ndarray
    starts: np.ndarray

    @property
    def met(self) -> np.ndarray:
        """Whether each target is met by the best design (bool, (n_targets,))."""
        return self.violations == 0


def optimize(problem: DesignProblem, *, progress=None) -> DesignResult:
    """The design within bounds that best meets ``problem``'s targets (see the module's description).

    Parameters
    ----------
    problem : DesignProblem
    progress : sixdof.progress.Meter, optional
        Shown the number of starts done.

    Returns
    -------
    DesignResult
    """
    import scipy.optimize

    from sixdof._jax import jax, jnp

    bounds = problem.bounds
    starts = start_points(problem.initial, bounds, problem.spec.starts, problem.spec.seed)
    value_and_grad = jax.jit(jax.value_and_grad(problem.objective))
    values = jax.jit(problem.values)
    robust = jax.jit(problem.objective) if problem.spec.objective == "robust" else None
    history = []
    fun = _numpy_objective(value_and_grad)

    rows, offsets = problem.ratio_constraints(RATIO_MARGIN)
    constrained = len(offsets) > 0

    def kept(x) -> bool:  # the stiffness ratios within their bounds (round-off of SLSQP's iterates allowed)
        return not constrained or bool(np.all(rows @ x + offsets >= -RATIO_SLACK_ATOL))

    best = None
    for index, start in enumerate(starts):
        def record(x, index=index):
            found = np.asarray(values(jnp.asarray(x)))
            if robust is None:  # the objective from them: no second solve, no gradient
                objective = float(np.sum(np.asarray(problem.violations(found, MARGIN)) ** 2))
            else:
                objective = float(robust(jnp.asarray(x)))
            history.append(np.concatenate([[index, objective], x, found]))
            if objective == 0.0 and kept(x):
                raise StopIteration  # every target met with its margin

        found = start
        try:
            record(start)
        except StopIteration:
            pass  # the start meets every target already
        else:  # scipy ends a minimization whose callback raises StopIteration, with that iterate
            # Tolerances far below the defaults: the objective is a sum of squared relative shortfalls, ~1e-6
            # when a target is missed by 0.1 %, which the defaults (relative to max(|f|, 1)) call converged.
            if constrained:  # linear inequalities: SLSQP, the bounded quasi-Newton method that takes them
                found = scipy.optimize.minimize(
                    fun, start, jac=True, method="SLSQP", bounds=bounds, callback=record,
                    constraints=[{"type": "ineq", "fun": lambda x: rows @ x + offsets, "jac": lambda x: rows}],
                    options={"maxiter": 500, "ftol": 1e-15}).x
            else:
                found = bounded_minimize(value_and_grad, start, bounds, record)
        found = np.clip(np.asarray(found, dtype=float), bounds[:, 0], bounds[:, 1])
        score = (not kept(found), float(value_and_grad(jnp.asarray(found))[0]))  # a design within the ratios first
        if best is None or score < best[0]:
            best = (score, found)
        if progress is not None:
            progress.show(index + 1)
        if score == (False, 0.0):
            break
    x = best[1]
    # The given design's values even where its variables lie outside the bounds (its start is clipped).
    final, initial = (np.asarray(values(jnp.asarray(v))) for v in (x, problem.initial))
    return DesignResult(
        x=readonly(x), x_initial=readonly(problem.initial), values=readonly(final), values_initial=readonly(initial),
        violations=readonly(np.asarray(problem.violations(final))),
        violations_initial=readonly(np.asarray(problem.violations(initial))),
        history=readonly(np.array(history)), starts=readonly(np.array(starts)))


def start_points(initial, bounds, count: int, seed: int) -> list[np.ndarray]:
    """The optimizer's ``count`` starting points: ``initial`` clipped to ``bounds`` (n, 2), then points drawn
    uniformly within them (``numpy.random.default_rng(seed)``)."""
    bounds = np.asarray(bounds, dtype=float)
    rng = np.random.default_rng(seed)
    starts = [np.clip(np.asarray(initial, dtype=float), bounds[:, 0], bounds[:, 1])]
    return starts + [rng.uniform(bounds[:, 0], bounds[:, 1]) for _ in range(count - 1)]


def _numpy_objective(value_and_grad):
    """``value_and_grad`` (JAX) as scipy's ``fun(x) -> (f, g)`` in float64."""
    from sixdof._jax import jnp

    def fun(x):
        f, g = value_and_grad(jnp.asarray(x))
        g = np.asarray(g, dtype=float)
        # A gradient through a repeated eigenvalue's shapes is undefined (inf/nan): treat as flat there.
        return float(f), np.where(np.isfinite(g), g, 0.0)

    return fun


def bounded_minimize(value_and_grad, start, bounds, callback=None, maxiter: int = 500) -> np.ndarray:
    """The minimum within ``bounds`` (n, 2) from ``start`` of the function whose value and exact gradient
    ``value_and_grad`` (JAX, e.g. ``jax.jit(jax.value_and_grad(f))``) gives, by scipy's L-BFGS-B; ``callback(x)``
    sees every iterate (raising StopIteration ends the search there). The design's and the model update's
    one search."""
    import scipy.optimize

    # Tolerances far below the defaults: the objective is a sum of squared relative shortfalls, ~1e-6
    # when a target is missed by 0.1 %, which the defaults (relative to max(|f|, 1)) call converged.
    return scipy.optimize.minimize(_numpy_objective(value_and_grad), start, jac=True, method="L-BFGS-B",
                                   bounds=bounds, callback=callback,
                                   options={"maxiter": maxiter, "ftol": 1e-15, "gtol": 1e-12}).x


@dataclass(frozen=True, eq=False)
class Robustness:
    """What :func:`robustness` found: per target, the probability of meeting it and the 5th, 50th and 95th
    percentiles of its value over the samples; and, with a simulation, the samples' peak responses by the
    exact batch engine.

    Attributes
    ----------
    met : ndarray of bool, shape (samples, n_targets)
        Whether each sample meets each target.
    percentiles : ndarray, shape (n_targets, 3)
        5th, 50th, 95th percentile of each target's value.
    values : ndarray, shape (samples, n_targets)
    tolerance : float
    responses : sixdof.analysis.batch.BatchResult or None
        The samples (their stiffness factors, in order) run by the batch engine: natural frequencies always,
        with a simulation the peak ``|q|`` and ``|q''|`` per DOF and the diffrax cross-check of a few
        samples.
    """

    met: np.ndarray
    percentiles: np.ndarray
    values: np.ndarray
    tolerance: float
    responses: BatchResult | None = None

    @property
    def probability(self) -> np.ndarray:
        """Share of the samples meeting each target [1], shape (n_targets,)."""
        return readonly(self.met.mean(axis=0))

    @property
    def all_met(self) -> int:
        """How many samples meet every target at once."""
        return int(np.count_nonzero(self.met.all(axis=1)))

    @property
    def peak_percentiles(self) -> np.ndarray | None:
        """5th, 50th, 95th percentile of each of the :data:`~sixdof.dofs.PEAK_RESPONSES`, shape (12, 3), or None without
        peak responses."""
        if self.responses is None or self.responses.peak_q is None:
            return None
        peaks = np.hstack([self.responses.peak_q, self.responses.peak_qdd])
        return readonly(np.percentile(peaks, [5, 50, 95], axis=0).T)


#: Samples per chunk of the robustness study (one task each, with its own seed: :mod:`sixdof.chunks`).
ROBUSTNESS_CHUNK = 1000


def scatter_spec(spec) -> SweepSpec:
    """The robustness study of a :class:`~sixdof.design.spec.DesignSpec` as a sweep
    (:class:`~sixdof.analysis.sweep.SweepSpec`): ``spec.samples`` variants, every mount-axis stiffness scaled by
    an independent factor uniform in ``1 +- spec.tolerance`` (none at zero tolerance), seed ``spec.seed``,
    in chunks of :data:`ROBUSTNESS_CHUNK` on the exact engine."""
    scatter = () if spec.tolerance == 0 else (
        Vary(parameter="stiffness", distribution="uniform", independent=True, low=1 - spec.tolerance,
             high=1 + spec.tolerance),)
    return SweepSpec(count=spec.samples, seed=spec.seed, vary=scatter, chunk_size=ROBUSTNESS_CHUNK, engine="exact")


def robustness(problem: DesignProblem, x, runner=None, excitation=None, settings=None, progress=None,
               time_model=None) -> Robustness:
    """How often each target of design ``x`` holds when every mount-axis stiffness scatters
    (:func:`scatter_spec`), and how its responses spread.

    The samples are a sweep of the design's system (:func:`sixdof.analysis.sweep.sweep_on`): the exact batch engine
    gives each sample's frequencies and, with ``excitation`` and ``settings``, its peak responses, a few
    of them checked by diffrax; the targets of each sample are evaluated exactly at its stiffness factors
    by the problem's own function (``jax.vmap``-ed).

    Parameters
    ----------
    problem : DesignProblem
    x : array_like, shape (n_variables,)
    runner : optional
        Where the chunks run (:func:`sixdof.workflows.tasks.task_runner`; default this process).
    excitation, settings : optional
        The scenario's excitation and :class:`~sixdof.analysis.direct.SimulationSettings`; without them,
        frequencies and targets only.
    progress : optional
        Show the chunks done (:func:`sixdof.progress.meter`).
    time_model : callable, optional
        The system the responses integrate for the design's (a scenario's
        :meth:`~sixdof.io.scenario.Scenario.time_model`: its loss factors as causal Maxwell models); default
        the design's own.

    Returns
    -------
    Robustness
    """
    from sixdof._jax import jax, jnp

    x = np.asarray(x, dtype=float)
    system = problem.system_at(x)
    spec = scatter_spec(problem.spec)
    timed = None if time_model is None else time_model(system)
    responses = sweep_on(runner or InProcess(), Study(system, excitation, settings, timed), spec, progress)
    scale = responses.variants.stiffness_factor
    values = np.asarray(jax.jit(jax.vmap(lambda s: problem.values(jnp.asarray(x), s)))(jnp.asarray(scale)))
    met = np.asarray(jax.vmap(problem.violations)(jnp.asarray(values))) == 0
    return Robustness(met=readonly(met, bool),
                      percentiles=readonly(np.percentile(values, [5, 50, 95], axis=0).T),
                      values=readonly(values), tolerance=problem.spec.tolerance, responses=responses)
