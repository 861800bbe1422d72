"""The excitation as the engine's inputs: load signals times vectors (:class:`Loads`) and the ground motion
(:class:`GroundInput`)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np

from sixdof._jax import jax
from sixdof.analysis.superposition.quadrature import _integration_matrices
from sixdof.errors import InputError, SolverError


@dataclass(frozen=True, eq=False)
class Loads:
    """Generalized forces as scalar signals times fixed vectors: ``Q(t) = sum_c g_c(t) vectors[c]``.

    Parameters
    ----------
    vectors : ndarray, shape (n_c, 6)
        Generalized force per unit of each signal [N, N m].
    values : callable
        ``values(times, order)`` for a sorted 1-D array of times [s] and ``order`` 0, 1 or 2 returns
        the signals or their time derivatives, one column per signal, shape (len(times), n_c).
    rates : bool
        Whether ``values`` knows the derivatives (orders 1 and 2).
    """

    vectors: np.ndarray
    values: object
    rates: bool = True


def excitation_inputs(excitation, K, C, branches=None):
    """An :class:`~sixdof.excitation.Excitation` as the engine's inputs for the stiffness and damping K, C (and
    the Maxwell branches, :class:`~sixdof.model.parts.Branches`, that the ground's velocity also drives).

    Returns
    -------
    loads : Loads or None
        One column per load component.
    ground : GroundInput or None
        The ground motion, entering as ``K r u_g + C r v_g``.
    omega : float
        Highest circular frequency [rad/s] the signals carry (0 for piecewise-linear ones).
    """
    components = excitation.components()
    signals = [signal for _, signal in components]
    ground = None
    if excitation.ground is not None:
        r = np.asarray(excitation.ground.rigid_vector, dtype=float)
        b_g = None if branches is None else -branches.stiffness * (branches.rows @ r)
        ground = ground_input(excitation.ground, np.asarray(K) @ r, np.asarray(C) @ r, b_g)
        signals.append(excitation.ground.signal)
    return signal_loads(components), ground, 2 * np.pi * max((s.max_frequency_hz for s in signals), default=0.0)


def signal_loads(components) -> Loads | None:
    """Load components ``(Q, signal)`` (:meth:`~sixdof.excitation.Excitation.components`) as :class:`Loads`,
    one column per component (None without any)."""
    if not components:
        return None
    vectors = np.array([np.asarray(vector, dtype=float) for vector, _ in components]).reshape(-1, 6)
    signals = [signal for _, signal in components]

    def values(times, order=0):
        if len(signals) == 1:
            return signal_values(signals[0], times, order)[:, None]
        out = np.empty((times.size, len(signals)))
        for c, signal in enumerate(signals):
            out[:, c] = signal_values(signal, times, order)
        return out

    return Loads(vectors=vectors, values=values)


def ground_input(motion, k_g, c_g, b_g=None) -> GroundInput:
    """A :class:`~sixdof.excitation.GroundMotion` as the :class:`GroundInput` of a system (``k_g = K r``,
    ``c_g = C r``, ``b_g = -k_b R r``: Maxwell branches)."""
    scale, signal = float(motion.scale), motion.signal
    return GroundInput(
        quantity=motion.quantity,
        signal=lambda times: scale * signal_values(signal, times, 0),
        rate=lambda times: scale * signal_values(signal, times, 1),
        k_g=np.asarray(k_g, dtype=float), c_g=np.asarray(c_g, dtype=float),
        b_g=None if b_g is None else np.asarray(b_g, dtype=float),
    )


@partial(jax.jit, static_argnums=2)
def _compiled_signal(signal, times, order):
    """A signal (order 0) or its derivative; signals are pytrees: one compilation per kind and length."""
    return signal(times) if order == 0 else signal.derivative(times, order)


def signal_values(signal, times, order=0) -> np.ndarray:
    """A signal (``order`` 0) or its time derivative (1, 2) at sorted ``times`` (1-D) [s], in one compiled call.

    Only the times inside the signal's support are evaluated (a short pulse costs little); they are
    padded to a size with four significant bits (at most 1/8 wasted), so that new grids reuse a few
    compilations per signal kind.
    """
    low, high = np.searchsorted(times, signal.support)  # zero outside [first, end)
    if low > 0 or high < times.size:
        values = np.zeros(times.size)
        if high > low:
            values[low:high] = signal_values(signal, times[low:high], order)
        return values
    n = times.size
    size = _padded_size(n)
    padded = times if size == n else np.concatenate([times, np.full(size - n, times[-1] if n else 0.0)])
    return np.asarray(_compiled_signal(signal, padded, order), dtype=float)[:n]


def _padded_size(n: int) -> int:
    """At least n and 1024, with four significant bits."""
    size = max(1024, n)
    step = 1 << max(size.bit_length() - 4, 0)
    return -(-size // step) * step


def _as_loads(force, force_rates) -> Loads | None:
    """``force`` (None, :class:`Loads` or a callable of (n, 6) with its optional rates) as :class:`Loads`."""
    if force is None or isinstance(force, Loads):
        return force
    functions = (force,) + (tuple(force_rates) if force_rates is not None else ())

    def values(times, order=0):
        return _evaluate(functions[order], times, "force" if order == 0 else f"force_rates[{order - 1}]")

    return Loads(vectors=np.eye(6), values=values, rates=force_rates is not None)


@dataclass(frozen=True, eq=False)
class GroundInput:
    """Rigid ground translation ``u_g(t)`` entering as the force ``k_g u_g + c_g v_g``.

    The mounts act on the body's motion relative to the ground, so in absolute coordinates the
    ground adds ``K r u_g + C_g r v_g`` (``r``: the generalized coordinates of a unit ground
    translation). ``u_g`` and ``v_g = u_g'`` come from the signal ``s`` (vectorized, [m], [m/s] or
    [m/s^2] per ``quantity``):

    - ``"displacement"``: ``u_g = s``, ``v_g = s'`` (``rate``, exact derivative);
    - ``"velocity"``: ``v_g = s``, ``u_g = int_{t0}^t s`` (zero at the first output time);
    - ``"acceleration"``: ``v_g = int s``, ``u_g = int int s`` (ground at rest at ``t0``).

    The integrals are exact on the quadrature grid: on each piece (never straddling a breakpoint) the
    integrand's interpolating polynomial at the Gauss-Legendre nodes is integrated analytically.

    Parameters
    ----------
    quantity : {"displacement", "velocity", "acceleration"}
    signal : callable
        ``signal(times)`` -> (len(times),) [m, m/s or m/s^2], for sorted times.
    rate : callable or None
        ``d signal / dt`` with the same signature; needed for ``"displacement"`` only.
    k_g, c_g : ndarray, shape (6,)
        ``K r`` [N/m, N] and ``C_g r`` [N s/m, N s]: generalized force per unit ground
        displacement and velocity.
    b_g : ndarray, shape (nb,), or None
        ``-k_b R r`` [N/m]: the rate of each Maxwell branch force per unit ground velocity (None: no branches).
    """

    quantity: str
    signal: object
    rate: object
    k_g: np.ndarray
    c_g: np.ndarray
    b_g: np.ndarray | None = None

    def motion(self, times, head, shape, piece_length, start):
        """``u_g, v_g`` at ``times``: ``head`` (0 or 1) times at the grid's start, then the nodes and the
        end of each of consecutive pieces (``shape``: (pieces, nodes + 1)); and ``(u_g, v_g)`` at the
        grid's end, from ``start`` at its beginning."""
        s = _evaluate(self.signal, times, "ground.signal", ())
        if self.quantity == "displacement":
            return s, _evaluate(self.rate, times, "ground.signal", ()), (0.0, 0.0)
        nodes = shape[1] - 1

        def integral(values, initial):
            """Running integral of values at ``times`` (the piece ends' values are not used)."""
            on_pieces = values[head:].reshape(shape)
            inside, ends = _running_integral(np.ascontiguousarray(on_pieces[:, :nodes]), initial, piece_length)
            out = np.empty(values.size)
            out[:head] = initial
            grid = out[head:].reshape(shape)
            grid[:, :nodes], grid[:, nodes] = inside, ends
            return out, float(ends[-1])

        if self.quantity == "velocity":
            u, u_end = integral(s, start[0])
            return u, s, (u_end, 0.0)
        v, v_end = integral(s, start[1])
        u, u_end = integral(v, start[0])
        return u, v, (u_end, v_end)


def _running_integral(values, initial, lengths):
    """Integral from the first piece's start (value ``initial``) of a function known on the nodes of
    consecutive pieces (N_p, n): at those nodes (N_p, n) and at each piece's end (N_p,)."""
    to_nodes, to_end = _integration_matrices(values.shape[1])
    half = 0.5 * lengths[:, None]
    within = half * (values @ to_nodes.T)  # from each piece's start to its nodes
    across = half[:, 0] * (values @ to_end)
    ends = initial + np.cumsum(across)
    starts = np.concatenate([[initial], ends[:-1]])
    return starts[:, None] + within, ends


def _evaluate(function, times, name, shape=(6,)):
    """``function`` (of a 1-D array of times, returning (n,) + ``shape``; None: zero) on times of any shape."""
    if function is None:
        return np.zeros(times.shape + shape)
    value = np.asarray(function(times.reshape(-1)), dtype=float)
    if value.shape != (times.size,) + shape:
        raise InputError(name, f"a callable returning shape {(times.size,) + shape}", f"shape {value.shape}")
    if not np.all(np.isfinite(value)):
        raise SolverError(f"{name} returned non-finite values")
    return value.reshape(times.shape + shape)


def _breakpoints(value):
    try:
        array = np.asarray(tuple(value), dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError("breakpoints", "a sequence of times in s", value) from None
    if not np.all(np.isfinite(array)):
        raise InputError("breakpoints", "finite times in s", value)
    return np.unique(array)
