"""The Gauss-Legendre quadrature of the increments: how many nodes an interval needs, and the rules."""

from __future__ import annotations

import math
from functools import cache

import numpy as np

from sixdof.errors import readonly

# Gauss-Legendre with n nodes on a piece of length l integrates f with the error
#     l^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^3) f^(2n)(xi)                      (Abramowitz & Stegun 25.4.30).
# An increment's integrand e^{lambda (t_{k+1} - s)} g(s), with g carrying circular frequencies up to
# omega, has |f^(2n)| <= (|lambda| + omega)^(2n) max|f|: relative to l max|f| the error is at most
#     (n!)^4 / ((2n+1) ((2n)!)^3) theta^(2n),    theta = (|lambda| + omega) l.
# The running integral of a ground velocity or acceleration integrates the polynomial interpolating
# the n nodes; with |prod (y - y_j)| <= 2^n (n!)^2 / (2n)! on [-1, 1] at the Legendre roots it errs,
# relative to l max|f|, by at most
#     n! / (2n)! theta^n,    theta = omega l.
# The nodes per piece are the fewest that keep both below QUADRATURE_RTOL, far below float64
# round-off (2^-53 = 1.1e-16): the quadrature adds no error of its own. Measured on the bridge (20 s at
# 1 kHz, theta = 0.37 rad): the error against the exact discretization stops changing from 4 nodes on,
# the bound asks for 6; with 3 it is 3e-10 where the bound says 2e-10.
#: Largest relative error allowed to the quadrature of one piece (see the bound above).
QUADRATURE_RTOL = 1e-18


#: Fewest Gauss-Legendre nodes per piece (exact for the piecewise-linear signals, whose omega is 0,
#: and the quadratic ground displacement of a piecewise-linear acceleration).
MIN_NODES = 3


#: Most Gauss-Legendre nodes per piece; a longer phase splits an interval's quadrature into pieces.
MAX_NODES = 24


def _largest_phases(n: int) -> tuple[float, float]:
    """The largest ``theta`` [rad] for which n nodes meet :data:`QUADRATURE_RTOL`: quadrature, interpolation."""
    log_rtol = math.log(QUADRATURE_RTOL)
    log_gauss = 4 * math.lgamma(n + 1) - math.log(2 * n + 1) - 3 * math.lgamma(2 * n + 1)
    log_interpolation = math.lgamma(n + 1) - math.lgamma(2 * n + 1)
    return math.exp((log_rtol - log_gauss) / (2 * n)), math.exp((log_rtol - log_interpolation) / n)


_PHASES = {n: _largest_phases(n) for n in range(MIN_NODES, MAX_NODES + 1)}


def quadrature_size(theta: float, theta_ground: float = 0.0) -> tuple[int, int]:
    """Gauss-Legendre nodes per piece and pieces per interval so that the error bound holds.

    Parameters
    ----------
    theta : float
        ``(|lambda|_max + omega) h`` [rad]: the phase an interval's increment spans.
    theta_ground : float
        ``omega h`` [rad] of a ground velocity or acceleration integrated on the nodes (0 without).

    Returns
    -------
    nodes, pieces : int
    """
    most = _PHASES[MAX_NODES]
    pieces = max(1, math.ceil(theta / most[0]), math.ceil(theta_ground / most[1]))
    nodes = next(n for n, (q, i) in _PHASES.items() if theta / pieces <= q and theta_ground / pieces <= i)
    return nodes, pieces


def quadrature_for(step, fastest, omega, ground) -> tuple[int, int]:
    """:func:`quadrature_size` for intervals of at most ``step`` [s], the fastest pole ``|lambda|`` and
    the highest signal frequency ``omega`` [rad/s], and a ground motion (a :class:`GroundInput` or None,
    integrated on the nodes unless given as a displacement)."""
    integrated = ground is not None and ground.quantity != "displacement"
    return quadrature_size((fastest + omega) * step, omega * step if integrated else 0.0)


@cache
def _gauss_legendre(n):
    """Gauss-Legendre nodes on [-1, 1] and weights (n,) each, read-only."""
    return tuple(readonly(a) for a in np.polynomial.legendre.leggauss(n))


@cache
def _integration_matrices(n):
    """Values at n Gauss-Legendre nodes -> integral of their interpolant from -1 to each node (n, n), to 1 (n,)."""
    x, _ = _gauss_legendre(n)
    vandermonde = np.polynomial.legendre.legvander(x, n - 1)  # P_k(x_j)
    to_coefficients = np.linalg.inv(vandermonde)
    antiderivatives = np.stack(
        [np.polynomial.legendre.legint(np.eye(n)[k], lbnd=-1.0) for k in range(n)], axis=1
    )  # column k: Legendre coefficients of int_{-1}^x P_k
    at_nodes = np.polynomial.legendre.legvander(x, n) @ antiderivatives
    at_end = np.polynomial.legendre.legvander(np.array([1.0]), n)[0] @ antiderivatives
    return readonly(at_nodes @ to_coefficients), readonly(at_end @ to_coefficients)
