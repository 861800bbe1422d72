"""How a time history was computed, stored with it: the direct solve's :class:`SolverStats` and the modal
superposition's :class:`SuperpositionInfo` (with the :class:`SuperpositionState` a windowed run continues
from), and how each merges over a run's windows.

Apart from the solvers, and free of JAX, so that reading a results file (``sixdof plot``) does not
import it.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from sixdof.analysis.compare import Agreement, merge_agreements
from sixdof.results import label, part, quantity, result_type


@result_type
@dataclass(frozen=True)
class SolverStats:
    """Statistics of one solve (stored with the results); of a window, or of a run's windows together.

    Attributes
    ----------
    solver : str
    rtol, atol : float
        As given (``atol`` is relative to ``scale``).
    scale : ndarray, shape (14,)
        Per-component scale of the state ``[z (6), w (6), u_g, v_g]`` [m, rad, m/s, rad/s].
    num_steps, num_accepted, num_rejected : int
        Steps attempted, accepted, rejected.
    max_steps : int
        The step limit per window.
    num_jumps : int
        Breakpoints (discontinuities) inside the run the solver stepped onto.
    wall_time_s : float
        Wall-clock time of the solve calls [s] (includes compilation when it was the first call of
        its structure in the process).
    num_windows : int
        Time windows the run proceeded in.
    num_events : int
        Changes of a nonlinear mount's contact state located as events (each restarts the solver there).
    """

    solver: str = label(name="solver")
    rtol: float = label()
    atol: float = label()
    scale: np.ndarray = label()
    num_steps: int = label()
    num_accepted: int = label()
    num_rejected: int = label()
    max_steps: int = label()
    num_jumps: int = label()
    wall_time_s: float = label()
    num_windows: int = label(default=1)
    num_events: int = label(default=0)


def merge_stats(stats) -> SolverStats:
    """One :class:`SolverStats` for consecutive windows of a run: counts and times add up."""
    first = stats[0]
    return SolverStats(
        solver=first.solver, rtol=first.rtol, atol=first.atol, scale=first.scale,
        num_steps=sum(s.num_steps for s in stats), num_accepted=sum(s.num_accepted for s in stats),
        num_rejected=sum(s.num_rejected for s in stats), max_steps=first.max_steps,
        num_jumps=sum(s.num_jumps for s in stats), wall_time_s=sum(s.wall_time_s for s in stats),
        num_windows=sum(s.num_windows for s in stats), num_events=sum(s.num_events for s in stats),
    )


@dataclass(frozen=True, eq=False)
class SuperpositionState:
    """Where a modal-superposition run ended: what the next window starts from (see ``start``).

    Attributes
    ----------
    t : float
        Time of the state [s].
    coordinates : tuple of ndarray of complex
        First-order modal coordinates of each run (the response, and the all-mode and complex-mode
        references when they are computed), in the order of ``runs``.
    runs : tuple
        ``(method, modes kept)`` of each run: a state continues only the same computation.
    ground : tuple of float
        ``(u_g, v_g)`` at ``t`` [m, m/s]: the ground's integrated displacement and velocity (signal
        units times ``scale``; zero when they are not integrated).
    """

    t: float
    coordinates: tuple
    runs: tuple
    ground: tuple = (0.0, 0.0)


@result_type
@dataclass(frozen=True, eq=False)
class SuperpositionInfo:
    """How a modal-superposition history was computed (:attr:`sixdof.results.TimeHistory.superposition`).

    The history's ``q`` is the absolute motion (fixed frame), like the direct solver's. With
    truncation, ``q`` includes the static residual correction; ``qd`` and ``qdd`` include it too when
    the force's time derivatives are known (``residual_rates``).

    Attributes
    ----------
    method : str
        ``"real"`` (decoupled undamped modes) or ``"complex"`` (complex modes of the first-order
        system).
    reason : str
        Why that method was used (automatic choice, or forced by the caller, and what it neglects).
    coupling : float
        Largest damping coupling ``|D_ij| / sqrt(D_ii D_jj)`` between distinct real modes (0 for
        classical damping, up to 1).
    modes_kept : tuple of int
        Indices (ascending frequency order of :func:`sixdof.model.modes.modal_analysis`) of the modes used.
    frequency_hz : ndarray, shape (len(modes_kept),)
        Undamped natural frequencies of the kept modes [Hz].
    eigenvalues : ndarray of complex, shape (2 len(modes_kept),)
        Eigenvalues of the first-order system actually solved [1/s]: ``-zeta w +- i w_d`` per mode
        for ``"real"``, the complex modes for ``"complex"``.
    residual : bool
        Whether the static residual correction for the dropped modes was added.
    residual_rates : bool
        Whether that correction also entered ``qd`` and ``qdd``.
    truncation : Agreement or None
        This response against the same computation with all modes kept (None when all are kept).
    approximation : Agreement or None
        When ``method="real"`` was forced on non-classical damping: this response against the
        exact complex-mode one, so the error of neglecting the coupling is reported. Else None.
    n_intervals : int
        Number of recursion intervals (the output steps, and the step from ``start`` to the first
        output time when a run continues).
    quadrature_nodes : int
        Gauss-Legendre nodes per output interval (pieces times nodes per piece); an interval holding
        a breakpoint has that many on each side of it.
    end : SuperpositionState or None
        Where the run ended, to continue it (``start`` of the next window); not stored.
    """

    method: str = label()
    reason: str = label(name="method_reason")
    coupling: float = label(name="damping_coupling")
    modes_kept: tuple[int, ...] = label(encode=lambda kept: np.asarray([j + 1 for j in kept], dtype=np.int64),
                                        decode=lambda kept: tuple(int(j) - 1 for j in kept))
    frequency_hz: np.ndarray = label(name="frequency_hz_kept")
    eigenvalues: np.ndarray = quantity("1/s", ("pole",), name="eigenvalues",
                                       description="eigenvalues of the first-order system solved")
    residual: bool = label(name="residual_correction", decode=bool)
    residual_rates: bool = label(decode=bool)
    n_intervals: int = label()
    quadrature_nodes: int = label()
    truncation: Agreement | None = part(lambda: Agreement, prefix="truncation_", default=None)
    approximation: Agreement | None = part(lambda: Agreement, prefix="approximation_", default=None)
    #: What the history's q measures: the absolute motion, like the direct solver's.
    frame: str = label(default="absolute")
    end: SuperpositionState | None = field(default=None, repr=False)


def merge_superposition(infos) -> SuperpositionInfo:
    """One :class:`SuperpositionInfo` over consecutive windows: intervals add up,
    truncation and approximation errors merge, the end is the last window's."""
    def agreements(name):
        found = [getattr(info, name) for info in infos]
        return None if found[0] is None else merge_agreements(found)

    return dataclasses.replace(infos[-1], n_intervals=sum(info.n_intervals for info in infos),
                               truncation=agreements("truncation"), approximation=agreements("approximation"))


__all__ = ["SolverStats", "SuperpositionInfo", "SuperpositionState", "merge_stats", "merge_superposition"]
