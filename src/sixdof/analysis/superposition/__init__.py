"""Modal superposition in time: an exact linear engine that cross-checks every direct solve.

The response of ``M q'' + C q' + K q = Q(t)`` is computed in modal coordinates, with no ODE solver:

1. the undamped modes ``Phi`` (mass-normalized, :func:`sixdof.analysis.modal.modal_analysis`) transform the
   equations to ``eta'' + D eta' + Omega^2 eta = Phi' Q(t)`` with ``D = Phi' C Phi``;
2. when ``D`` is diagonal (classical damping: Rayleigh, modal ratios, any C the real modes
   diagonalize) each mode is a single-degree-of-freedom oscillator (method ``"real"``); otherwise
   (mount dashpots) the coupled modes are solved through the complex modes of the first-order system
   ``y' = [[0, I], [-Omega^2, -D]] y + [0, Phi' Q]`` (method ``"complex"``), exact for any viscous C;
3. both give first-order coordinates ``z' = lambda z + f(t)`` (a complex mode, one per conjugate pair;
   an oscillator damped near or beyond critical, or a rigid-body mode, as a chain of two,
   ``u' = lambda_1 u + f``, ``x' = lambda_2 x + u``, exact where its modes cannot be told apart),
   each advanced over every output interval by its exact transition
   ``z_{k+1} = e^{lambda h} z_k + d_k``, ``d_k = int_{t_k}^{t_{k+1}} e^{lambda (t_{k+1} - s)} f(s) ds``.
   The recursion runs on the output intervals (blocked: a matrix product within blocks of steps, a
   doubling scan across them); the excitation's
   breakpoints (where a signal or a derivative jumps) split only the Gauss-Legendre quadrature of
   ``d_k``, never the recursion. On a uniform grid every interval without a breakpoint shares one
   kernel, so their increments are one matrix product with the signals' values on the nodes;
4. modes may be truncated (by count or frequency) with a static residual-flexibility correction for
   the modes left out.

The input side (:class:`Drive`: the excitation's signals on the quadrature nodes of a time grid) is
separate from the system side (the poles and maps of :func:`_modal_coordinates`), so that many systems
can run on one drive; and a run continues exactly from where another ended (``start``, a
:class:`SuperpositionState` carrying the modal coordinates and the ground's integrals), window after
window, without the direct solve's state.

:func:`compare` measures the agreement of two time histories DOF by DOF.

The package's modules, each one job: :mod:`~sixdof.analysis.superposition.solve` (the entry points),
:mod:`~sixdof.analysis.superposition.plan` (the method and the modes kept),
:mod:`~sixdof.analysis.superposition.coordinates` (the system side),
:mod:`~sixdof.analysis.superposition.inputs` and :mod:`~sixdof.analysis.superposition.drive` (the input side),
:mod:`~sixdof.analysis.superposition.quadrature` (the increments' quadrature) and
:mod:`~sixdof.analysis.superposition.recursion` (the coordinates advanced over the output intervals).
"""

from sixdof.analysis.superposition.coordinates import SEPARATE_MODES, ModalCoordinates
from sixdof.analysis.superposition.drive import Drive, make_drive, uniform_step
from sixdof.analysis.superposition.inputs import (
    GroundInput,
    Loads,
    excitation_inputs,
    ground_input,
    signal_loads,
    signal_values,
)
from sixdof.analysis.superposition.plan import Plan
from sixdof.analysis.superposition.quadrature import (
    MAX_NODES,
    MIN_NODES,
    QUADRATURE_RTOL,
    quadrature_for,
    quadrature_size,
)
from sixdof.analysis.superposition.recursion import BLOCK, FILTERED_COORDINATES, run_coordinates
from sixdof.analysis.superposition.solve import METHODS, modal_solve, superpose

__all__ = ["BLOCK", "Drive", "FILTERED_COORDINATES", "GroundInput", "Loads", "MAX_NODES", "METHODS", "MIN_NODES",
           "ModalCoordinates", "Plan", "QUADRATURE_RTOL", "SEPARATE_MODES", "excitation_inputs", "ground_input",
           "make_drive", "modal_solve", "quadrature_for", "quadrature_size", "run_coordinates", "signal_loads",
           "signal_values", "superpose", "uniform_step"]
