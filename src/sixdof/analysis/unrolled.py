"""diffrax's explicit Runge-Kutta methods with their stages written out: the same method, half the time.

diffrax runs the stages of every Runge-Kutta step in a ``while`` loop (one loop serves explicit,
implicit and IMEX tableaus). On the CPU each trip of that inner loop costs about 1 us of
dispatch, several times the work of a stage on sixdof's 14 states, so a 14-stage Dopri8 step spends most
of its time looping. :class:`UnrolledERK` evaluates the stages of an explicit tableau as straight-line
code, with diffrax's own tableau coefficients, error estimate, first-same-as-last reuse and dense
interpolation: results agree with diffrax's solver to round-off, and the bridge beam solve takes
about half the time (measured: benchmarks/bench_direct.py).

Imported only when a solve is traced (diffrax and equinox take ~0.65 s to import).
"""

from __future__ import annotations

from typing import ClassVar

import diffrax
import jax
import jax.numpy as jnp


class UnrolledERK(diffrax.AbstractAdaptiveSolver):
    """An explicit Runge-Kutta solver of diffrax (``Tsit5()``, ``Dopri8()``...) with unrolled stages.

    Parameters
    ----------
    method : diffrax.AbstractERK
        The method whose tableau, order and interpolation are used.
    """

    method: diffrax.AbstractERK
    term_structure: ClassVar = diffrax.AbstractTerm

    @property
    def interpolation_cls(self):  # the dense output of the method: its stages are the same
        return self.method.interpolation_cls

    def order(self, terms):
        return self.method.order(terms)

    def error_order(self, terms):
        return self.method.error_order(terms)

    def func(self, terms, t0, y0, args):
        return terms.vf(t0, y0, args)

    def init(self, terms, t0, t1, y0, args):
        # First same as last: the state holds the field at the start of the next step.
        return terms.vf(t0, y0, args) if self.method.tableau.fsal else None

    def step(self, terms, t0, t1, y0, args, solver_state, made_jump):
        tableau = self.method.tableau
        dt = terms.contr(t0, t1)
        if tableau.fsal:
            # After a jump of the field (a breakpoint) the stored last stage is the left limit: evaluate anew.
            f0 = jax.lax.cond(made_jump, lambda: terms.vf(t0, y0, args), lambda: solver_state)
        else:
            f0 = terms.vf(t0, y0, args)
        fs = [f0]
        ks = [terms.prod(f0, dt)]
        y_stage = y0
        for a_row, c in zip(tableau.a_lower, tableau.c):
            y_stage = y0 + _combine(a_row, ks)
            fs.append(terms.vf(t0 + float(c) * (t1 - t0), y_stage, args))
            ks.append(terms.prod(fs[-1], dt))
        # First same as last: the last stage is evaluated at (t1, y1).
        y1 = y_stage if tableau.ssal else y0 + _combine(tableau.b_sol, ks)
        y_error = _combine(tableau.b_error, ks)
        state = fs[-1] if tableau.fsal else None
        dense_info = dict(y0=y0, y1=y1, k=jnp.stack(ks))
        return y1, y_error, dense_info, state, diffrax.RESULTS.successful


def _combine(coefficients, ks):
    """``sum_j coefficients[j] ks[j]`` over the nonzero coefficients (tableau constants)."""
    total = None
    for a, k in zip(coefficients, ks):
        if a != 0:
            total = float(a) * k if total is None else total + float(a) * k
    return total


def solver(name: str) -> diffrax.AbstractSolver:
    """The diffrax solver called ``name``; explicit Runge-Kutta methods with unrolled stages."""
    method = getattr(diffrax, name)()
    return UnrolledERK(method) if isinstance(method, diffrax.AbstractERK) else method


__all__ = ["UnrolledERK", "solver"]
