"""The exact recursion of the modal coordinates over the output intervals, blocked."""

from __future__ import annotations

import numpy as np

from sixdof.analysis.superposition.coordinates import ModalCoordinates
from sixdof.analysis.superposition.drive import Drive


def _divided_exp(a, b, tau):
    """``(e^{a tau} - e^{b tau}) / (a - b)``, accurate as ``a -> b`` (where it is ``tau e^{a tau}``)."""
    half = 0.5 * (a - b) * tau
    with np.errstate(all="ignore"):  # each form is kept only where it is finite and accurate
        # tau e^{(a + b) tau / 2} sinh(half) / half, with sinh(x) / x = sinc(i x / pi): no cancellation.
        near = tau * np.exp(0.5 * (a + b) * tau) * np.sinc(1j * half / np.pi)
        far = (np.exp(a * tau) - np.exp(b * tau)) / np.where(a == b, 1.0, a - b)
    return np.where(np.abs(half) < 1.0, near, far)


def run_coordinates(modal: ModalCoordinates, drive: Drive, z0) -> np.ndarray:
    """The modal coordinates at every time of the drive's grid, from ``z0`` at its start.

    ``modal`` needs ``poles``, ``source`` and ``forcing`` (:class:`ModalCoordinates`, or several side by
    side).

    Returns
    -------
    ndarray of complex, shape (n_intervals + 1, m)
    """
    lam, source = modal.poles, modal.source
    m = lam.size
    fed = source >= 0
    feeder = np.where(fed, source, 0)
    # Modal force per unit of each signal column, to each coordinate directly and through its source.
    own = modal.forcing(drive.vectors, drive.branch_vectors)  # (n_c, m)
    through = np.where(fed, own[:, feeder], 0.0)

    def kernels(tau):
        """Response at an interval's end to a unit impulse ``tau`` before it: directly and through the source."""
        tau = tau[:, None]
        return np.exp(lam * tau), np.where(fed, _divided_exp(lam[feeder], lam, tau), 0.0)

    # The coordinates at every grid time, filled first with the increments d_k at row k + 1.
    z = np.zeros((drive.n_intervals + 1, m), complex)
    z[0] = z0
    if drive.regular_values is not None:
        # Every regular interval shares one kernel: their increments are one real matrix product,
        # the kernel's real and imaginary parts interleaved so that its rows are complex numbers.
        direct, fed_through = kernels(drive.regular_tau)
        weights = (direct[:, None] * own + fed_through[:, None] * through) * drive.regular_weight[:, None, None]
        weights = np.ascontiguousarray(weights.reshape(-1, m)).view(float)  # (n_q * n_c, 2m)
        if drive.irregular.size:
            z[1:][drive.regular] = (drive.regular_values @ weights).view(complex)
        else:
            np.matmul(drive.regular_values, weights, out=z[1:].view(float))
    if drive.irregular.size:
        direct, fed_through = kernels(drive.irregular_tau)
        values = drive.irregular_values * drive.irregular_weight[:, None]
        z[1:][drive.irregular] = np.add.reduceat(direct * (values @ own) + fed_through * (values @ through),
                                                 drive.irregular_start, axis=0)
    h = drive.step if drive.step is not None else np.diff(drive.times)[:, None]  # (n_intervals, 1)
    coupling = np.where(fed, _divided_exp(lam[feeder], lam, h), 0.0)
    _recursion(lam * h, coupling, feeder, fed, z)
    return z


#: Coordinates advanced one by one by the blocked filter; more (variants side by side) advance together,
#: one step at a time: the filter's cost is per coordinate, the step's per time step.
FILTERED_COORDINATES = 48


#: Steps per block of :func:`_filter`: one (blocks, BLOCK) x (BLOCK, BLOCK) matrix product per coordinate. Its
#: cost grows with BLOCK, the scan across blocks with their number: 20,000 steps of six coordinates take
#: 0.62-0.66 ms with 8 to 16, 0.86 ms with 32.
BLOCK = 16


_LAG = np.subtract.outer(np.arange(BLOCK), np.arange(BLOCK))  # i - j


def _recursion(exponent, coupling, feeder, fed, z):
    """``z_{k+1} = e^{exponent} z_k + coupling z_k[feeder] + d_k`` (the coupling where ``fed``), in place: z
    (n_intervals + 1, m) holds ``z_0``, then the increments ``d_k``, and ends with the states.

    ``exponent`` (``lambda h``) and ``coupling`` are (m,) on a uniform grid, (n_intervals, m) otherwise.
    """
    m = z.shape[1]
    uniform = exponent.ndim == 1
    if uniform and m <= FILTERED_COORDINATES:
        # Constant coefficients: each coordinate is a first-order recursive filter. Sources first, then
        # the coordinates they feed.
        for i in np.concatenate([np.flatnonzero(~fed), np.flatnonzero(fed)]):
            x = z[1:, i] + coupling[i] * z[:-1, feeder[i]] if fed[i] else z[1:, i]
            z[1:, i] = _filter(exponent[i], z[0, i], x)
        return
    # A non-uniform grid, or many coordinates (variants side by side): one step at a time, every
    # coordinate at once (the same arithmetic).
    a = np.exp(exponent)
    chained = np.flatnonzero(fed)
    feeding = feeder[chained]
    product = np.empty(m, complex)
    for k in range(z.shape[0] - 1):
        before, after = z[k], z[k + 1]
        np.multiply(a if uniform else a[k], before, out=product)
        np.add(after, product, out=after)
        if chained.size:
            after[chained] += (coupling if uniform else coupling[k])[chained] * before[feeding]


def _filter(exponent, z0, d):
    """``z_k = e^{exponent} z_{k-1} + d_k`` for k = 1..n from ``z_0``: d (n,) complex -> z_1..z_n.

    By blocks of :data:`BLOCK` steps: within a block, one matrix product with the transition's powers;
    across blocks, the block ends by a doubling scan (log2 of the number of blocks passes). Every power is
    ``exp(exponent * j)`` itself, not a product of rounded powers, so a lightly damped mode keeps its phase
    over 10^5 steps (~1e-15 of its peak, where repeated multiplication by a rounded ``e^{lambda h}`` drifts
    to ~2e-13), and no |power| exceeds 1 for a stable coordinate.
    """
    n = d.size
    if n == 0:
        return d
    blocks = -(-n // BLOCK)
    x = np.zeros(blocks * BLOCK, complex)
    x[:n] = d
    x = x.reshape(blocks, BLOCK)
    powers = np.exp(exponent * np.arange(BLOCK + 1))
    kernel = np.where(_LAG >= 0, powers[np.maximum(_LAG, 0)], 0.0)  # kernel[i, j] = e^{exponent (i - j)}
    local = x @ kernel.T  # each block's response from a zero start
    ends = local[:, -1].copy()  # the state at each block's end: ends_b = e^{exponent BLOCK} ends_{b-1} + local
    ends[0] += powers[BLOCK] * z0
    span = 1
    while span < blocks:
        ends[span:] += np.exp(exponent * (BLOCK * span)) * ends[:-span]
        span *= 2
    starts = np.empty(blocks, complex)
    starts[0] = z0
    starts[1:] = ends[:-1]
    local += np.multiply.outer(starts, powers[1:])
    return local.reshape(-1)[:n]
