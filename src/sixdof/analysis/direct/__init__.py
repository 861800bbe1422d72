"""Direct time integration of eq. (1), ``M q'' + C q' + K q = Q(t)``, with diffrax in float64.

The first-order state is ``x = [z, w, u_g, v_g, f]`` (14 values and one per Maxwell branch state):

- ``z = q - r u_g`` (6): the body's displacement *relative to the ground* [m, rad] — what the
  mounts feel;
- ``w = q'`` (6): the body's *absolute* velocity [m/s, rad/s];
- ``u_g, v_g``: displacement [m] and velocity [m/s] of the ground along its direction, integrated
  here when the ground motion is given as a velocity or an acceleration (otherwise unused);
- ``f``: the force in each Maxwell branch of a visco-elastic mount [N]
  (:attr:`sixdof.model.system.System.branches`: rows ``R``, stiffnesses ``k_b``, relaxation times ``tau_b``);

with ``r`` (6,) the generalized coordinates of a unit rigid translation of the foundation. Then

    z' = w - r v_g,    M w' = Q(t) - C (w - r v_g) - K z - R' f,    f' = k_b R (w - r v_g) - f / tau_b

which needs at most the *first* derivative of a prescribed ground displacement (a table of
displacements is handled exactly; a relative formulation with ``-M r u_g''`` would need Dirac
deltas at every knot). Without ground motion ``z = q`` and it is the plain first-order form.
All damping (mount dashpots, Rayleigh, modal) acts on the motion relative to the ground, since all of
it stands for dissipation in the mounts. It is linear, ``x' = A x + B u(t)`` with the input
``u = [s_1(t) ... s_n(t), v_g or a_g]`` (:func:`first_order_form`).

The solver steps onto every signal breakpoint (``jump_ts``). The state is divided by a per-component
scale (:func:`state_scale`), so that ``rtol`` and ``atol`` hold relative to each component's own
expected size, translations (~1e-4 m) and rotations (~1e-7 rad) alike.

A run proceeds in time windows of at most :data:`WINDOW_SAMPLES` output samples
(:func:`simulate_windows`): the solver's state at the end of a window starts the next one as it is, so
memory stays bounded whatever the duration; :func:`simulate` joins the windows. Explicit Runge-Kutta
methods run with their stages unrolled (:mod:`sixdof.analysis.unrolled`). The traced solve of one
window depends only on the problem's *structure* (solver, signal kinds, numbers of loads, window
samples and breakpoints, ground kind); matrices, signal parameters, times and tolerances are
arguments. It is traced once per process, and with the persistent JAX compilation cache on (the command
line turns it on, :func:`sixdof._jax.enable_compilation_cache`) also serialized with
:mod:`jax.export` beside it: a later process loads it without tracing and without importing diffrax.

The package's modules, each one job: :mod:`~sixdof.analysis.direct.settings` (the settings and the tolerances a
run steps with), :mod:`~sixdof.analysis.direct.scale` (the state scale), :mod:`~sixdof.analysis.direct.form` (the
first-order form), :mod:`~sixdof.analysis.direct.breakpoints` (the times stepped onto),
:mod:`~sixdof.analysis.direct.solve` (the traced solve of a window), :mod:`~sixdof.analysis.direct.cache` (its
compiled and exported forms), :mod:`~sixdof.analysis.direct.nonlinear` (windows with nonlinear mounts) and
:mod:`~sixdof.analysis.direct.windows` (the run in windows, and :func:`simulate`).
"""

from sixdof.analysis.direct.breakpoints import jump_times
from sixdof.analysis.direct.form import first_order_form, loads_of, mechanical_form
from sixdof.analysis.direct.nonlinear import MAX_STALLED_EVENTS, is_nonlinear
from sixdof.analysis.direct.scale import SCALE_FLOOR, state_scale
from sixdof.analysis.direct.settings import (
    CYCLES_PER_TOLERANCE,
    MAX_SAMPLES,
    MIN_TOLERANCE,
    SECONDS_PER_SAMPLE,
    SOLVERS,
    SimulationSettings,
    cycle_scaled,
)
from sixdof.analysis.direct.solve import REGION_HYSTERESIS, solve_ode
from sixdof.analysis.direct.windows import (
    SOLVE_BYTES_PER_SAMPLE,
    WINDOW_GRANULE,
    WINDOW_SAMPLES,
    progress_meter,
    simulate,
    simulate_windows,
    window_length,
    window_spans,
)
from sixdof.analysis.records import SolverStats, merge_stats

__all__ = ["SOLVERS", "SCALE_FLOOR", "WINDOW_SAMPLES", "SimulationSettings", "SolverStats", "first_order_form",
           "merge_stats", "simulate", "simulate_windows", "state_scale", "window_length", "CYCLES_PER_TOLERANCE",
           "cycle_scaled", "MAX_SAMPLES", "SECONDS_PER_SAMPLE", "MIN_TOLERANCE", "WINDOW_GRANULE",
           "SOLVE_BYTES_PER_SAMPLE", "MAX_STALLED_EVENTS", "REGION_HYSTERESIS", "is_nonlinear", "jump_times",
           "loads_of", "mechanical_form", "progress_meter", "solve_ode", "window_spans"]
