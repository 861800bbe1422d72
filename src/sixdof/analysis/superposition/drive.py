"""The input side: the excitation on the quadrature nodes of a time grid (:class:`Drive`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.analysis.superposition.inputs import _padded_size
from sixdof.analysis.superposition.quadrature import _gauss_legendre


@dataclass(frozen=True, eq=False)
class Drive:
    """The excitation on the quadrature nodes of a time grid: what every system run on that grid shares.

    The grid's intervals are the recursion's steps. An interval is *regular* when the grid is
    uniform and no breakpoint falls inside it: all regular intervals share one set of nodes (``pieces``
    equal pieces of ``nodes`` Gauss-Legendre nodes each). The others (holding breakpoints, or all of
    them on a non-uniform grid) have their own nodes, the quadrature split at every breakpoint.
    The excitation is a few scalar *columns* (the loads' signals, then the ground's ``u_g`` and
    ``v_g``), each times a generalized force vector.

    Attributes
    ----------
    times : ndarray, shape (n_intervals + 1,)
        The grid [s]: the run's start, then the output times (the start is ``t[0]`` unless a run
        continues from an earlier state).
    first : int
        Index of ``t[0]`` in ``times`` (0 or 1).
    step : float or None
        The common interval [s] of a uniform grid.
    vectors : ndarray, shape (n_c, 6)
        Generalized force per unit of each column [N, N m].
    branch_vectors : ndarray, shape (n_c, nb), or None
        Direct input to the Maxwell branch states per unit of each column [N/s] (the ground's velocity).
    regular : ndarray of int
        Indices of the regular intervals.
    regular_tau, regular_weight : ndarray, shape (n_q,)
        Time from each node to its interval's end [s] and quadrature weight [s], for the nodes of each
        piece and the piece's end (weight 0: the ends are evaluated for the outputs).
    regular_values : ndarray, shape (len(regular), n_q * n_c), or None
        The columns at the nodes of each regular interval, node after node (None on a non-uniform grid).
    irregular : ndarray of int
        Indices of the other intervals.
    irregular_start : ndarray of int
        Index of each one's first node in the irregular node arrays.
    irregular_tau, irregular_weight : ndarray, shape (N,)
        Time to the interval's end [s] and weight [s] of each irregular node.
    irregular_values : ndarray, shape (N, n_c)
    columns_out : ndarray, shape (n, n_c)
        The columns at the output times (right limits at breakpoints).
    rates_out : ndarray, shape (2, n, 6), or None
        The loads' first and second time derivatives at the output times, when asked for.
    ground_end : tuple of float
        Integrated ground displacement and velocity at the grid's end (zeros when not integrated).
    nodes_per_interval : int
        Nodes of a regular interval.
    """

    times: np.ndarray
    first: int
    step: float | None
    vectors: np.ndarray
    branch_vectors: np.ndarray | None
    regular: np.ndarray
    regular_tau: np.ndarray | None
    regular_weight: np.ndarray | None
    regular_values: np.ndarray | None
    irregular: np.ndarray
    irregular_start: np.ndarray
    irregular_tau: np.ndarray
    irregular_weight: np.ndarray
    irregular_values: np.ndarray
    columns_out: np.ndarray
    rates_out: np.ndarray | None
    ground_end: tuple
    nodes_per_interval: int

    @property
    def t(self) -> np.ndarray:
        """Output times (n,) [s]."""
        return self.times[self.first:]

    @property
    def n_intervals(self) -> int:
        return self.times.size - 1

    @property
    def force_out(self) -> np.ndarray:
        """Generalized force at the output times (n, 6) [N, N m]."""
        return self.columns_out @ self.vectors


def uniform_step(times) -> float | None:
    """The common step [s] of a grid uniform to the rounding of its times, else None.

    A grid is uniform when every time is within a few units in the last place of ``t0 + k h``: such a
    grid (``linspace``, ``start + k / rate``) is advanced with the one step ``h``, at the cost of
    sampling the response at ``t0 + k h`` rather than at the rounded ``t_k``.
    """
    n = times.size - 1
    step = (times[-1] - times[0]) / n
    ideal = times[0] + np.arange(n + 1) * step
    scale = max(abs(times[0]), abs(times[-1]))
    return float(step) if np.max(np.abs(times - ideal)) <= 8 * np.finfo(float).eps * scale else None


def make_drive(times, n_out, breakpoints, loads, ground=None, *, nodes, pieces, rates=False,
               ground_start=None) -> Drive:
    """Evaluate the excitation on the quadrature nodes of the grid ``times``.

    Parameters
    ----------
    times : ndarray, shape (n_intervals + 1,)
        The grid [s]; its last ``n_out`` times are the outputs.
    n_out : int
    breakpoints : ndarray
        Sorted times [s] where a signal or a derivative jumps.
    loads : Loads or None
    ground : GroundInput or None
    nodes, pieces : int
        Gauss-Legendre nodes per piece and pieces per (longest) interval (:func:`quadrature_size`).
    rates : bool
        Whether to evaluate the loads' first and second time derivatives at the outputs.
    ground_start : tuple of float, optional
        ``(u_g, v_g)`` at ``times[0]`` of an integrated ground (default at rest at 0).

    Returns
    -------
    Drive
    """
    n_int = times.size - 1
    step = uniform_step(times)
    segments, piece_interval, piece_length, piece_start, last = _pieces(times, breakpoints, pieces)

    # The times every signal is evaluated at, once: the grid's start when it is an output, then each
    # piece's nodes and its end (the next piece's start; the grid's time after an interval's last piece),
    # sorted; padded as signal_values pads them.
    x, w = _gauss_legendre(nodes)
    head = n_out - n_int
    count = head + piece_length.size * (nodes + 1)
    padded = np.empty(_padded_size(count))
    padded[:head] = times[0]
    grid = padded[head:count].reshape(piece_length.size, nodes + 1)
    np.add(piece_start[:, None], piece_length[:, None] * (0.5 * (1.0 + x)), out=grid[:, :nodes])
    grid[:-1, nodes] = piece_start[1:]
    grid[last, nodes] = times[1:]
    padded[count:] = times[-1]
    values, vectors, branch_vectors, ground_end = _columns(loads, ground, padded, count, head, grid.shape,
                                                          piece_length, ground_start)
    n_c = vectors.shape[0]
    on_grid = values[head:].reshape(grid.shape + (n_c,))  # (pieces, nodes + 1, n_c)
    columns_out = np.concatenate([values[:head], on_grid[last, nodes]])
    rates_out = None
    if rates:
        rates_out = np.stack([loads.values(times[-n_out:], order) @ loads.vectors for order in (1, 2)])

    split = segments > 1
    if step is None:
        split[:] = True
    regular, irregular = np.flatnonzero(~split), np.flatnonzero(split)
    regular_values = regular_tau = regular_weight = None
    if step is not None:
        # A regular interval: `pieces` pieces of `nodes` nodes and an end each (weight 0 at the ends).
        fraction = (np.arange(pieces)[:, None] + 0.5 * (1.0 + np.append(x, 1.0))) / pieces
        regular_tau = (step * (1.0 - fraction)).reshape(-1)
        regular_weight = np.broadcast_to(np.append(step * w / (2 * pieces), 0.0), (pieces, nodes + 1)).reshape(-1)
        rows = on_grid.reshape(piece_length.size, (nodes + 1) * n_c)
        if irregular.size:  # the pieces are grouped by interval in time order, `pieces` per regular interval
            rows = rows[(last - pieces + 1)[regular][:, None] + np.arange(pieces)]
        regular_values = rows.reshape(regular.size, pieces * (nodes + 1) * n_c)
    in_irregular = split[piece_interval]
    counts = np.bincount(piece_interval[in_irregular], minlength=n_int)[irregular] * nodes
    irregular_nodes = grid[in_irregular, :nodes].reshape(-1)
    return Drive(
        times=times, first=times.size - n_out, step=step, vectors=vectors, branch_vectors=branch_vectors,
        regular=regular, regular_tau=regular_tau, regular_weight=regular_weight, regular_values=regular_values,
        irregular=irregular, irregular_start=np.cumsum(counts) - counts,
        irregular_tau=np.repeat(times[irregular + 1], counts) - irregular_nodes,
        irregular_weight=(piece_length[in_irregular, None] * (0.5 * w)).reshape(-1),
        irregular_values=on_grid[in_irregular, :nodes].reshape(irregular_nodes.size, n_c),
        columns_out=columns_out, rates_out=rates_out, ground_end=ground_end,
        nodes_per_interval=nodes * pieces,
    )


def _pieces(times, breakpoints, pieces):
    """The quadrature pieces of the grid ``times``: the intervals split at the ``breakpoints`` inside them
    (segments), the segments split further to at most 1 / ``pieces`` of the longest interval. Returns the
    segments per interval, each piece's interval, length [s] and start [s], and the index of each interval's
    last piece (a slice of all of them when every interval is one piece)."""
    n_int = times.size - 1
    inner = breakpoints[(breakpoints > times[0]) & (breakpoints < times[-1])]
    position = np.searchsorted(times, inner)
    inner, position = inner[times[position] != inner], position[times[position] != inner]  # on a grid time: no split
    points = np.insert(times, position, inner)
    segments = np.bincount(position - 1, minlength=n_int) + 1  # per interval
    length = np.diff(points)
    if inner.size == 0 and pieces == 1:  # one piece per interval
        # Each interval's last piece: all of them (a slice: no gathers below).
        return segments, np.arange(n_int), length, times[:-1], slice(None)
    longest = float(np.max(np.diff(times))) / pieces
    parts = np.maximum(np.ceil(length / longest * (1 - 1e-12)).astype(np.int64), 1)
    piece_interval = np.repeat(np.repeat(np.arange(n_int), segments), parts)
    piece_length = np.repeat(length / parts, parts)
    index = np.arange(piece_length.size) - np.repeat(np.cumsum(parts) - parts, parts)
    piece_start = np.repeat(points[:-1], parts) + index * piece_length
    last = np.append(np.flatnonzero(np.diff(piece_interval)), piece_interval.size - 1)  # of each interval
    return segments, piece_interval, piece_length, piece_start, last


def _columns(loads, ground, padded, count, head, shape, piece_length, ground_start):
    """The input columns at the first ``count`` times of ``padded`` (:func:`make_drive`'s; ``head`` and
    ``shape`` as :meth:`GroundInput.motion` takes them), their generalized force vectors (n_c, 6), their direct
    input to the Maxwell branches (None without), and the integrated ground's ``(u_g, v_g)`` at the end."""
    everywhere = padded[:count]
    columns, vectors = [], []
    if loads is not None:
        columns.append(loads.values(padded, 0)[:count])
        vectors.append(loads.vectors)
    ground_end = (0.0, 0.0)
    branch_vectors = None
    if ground is not None:
        start = (0.0, 0.0) if ground_start is None else ground_start
        u, v, ground_end = ground.motion(everywhere, head, shape, piece_length, start)
        columns.append(np.stack([u, v], axis=1))
        vectors.append(np.stack([ground.k_g, ground.c_g]))
        if ground.b_g is not None:  # the ground's velocity (its second column) drives the branches
            branch_vectors = np.zeros((sum(v.shape[0] for v in vectors), ground.b_g.size))
            branch_vectors[-1] = ground.b_g
    vectors = np.vstack(vectors) if vectors else np.zeros((0, 6))
    return _side_by_side(columns, everywhere.size), vectors, branch_vectors, ground_end


def _side_by_side(blocks, rows):
    """Column blocks, each (rows, k), side by side (the block itself when alone)."""
    if len(blocks) == 1:
        return blocks[0]
    return np.hstack(blocks) if blocks else np.zeros((rows, 0))
