"""The two engines of a batch's responses: the exact linear engine and diffrax, in chunks of variants."""

from __future__ import annotations

from functools import partial

import numpy as np

from sixdof._jax import jax, jnp
from sixdof.analysis import superposition as sp
from sixdof.analysis.batch.variants import _Modes
from sixdof.analysis.direct import jump_times, loads_of, mechanical_form, solve_ode, state_scale
from sixdof.errors import InputError, Plain, SolverError, readonly

#: Memory allowed for the samples kept per chunk of variants of the diffrax engine [bytes] (``q`` and
#: ``q''``, float64).
CHUNK_BYTES = 256 * 2**20


#: Largest chunk of variants integrated together by diffrax (beyond it vectorizing gains nothing on CPU).
MAX_CHUNK = 256


#: Variants whose modal coordinates the exact engine advances side by side: enough that one time step
#: of all of them costs little more than of one, few enough that a window's arrays stay small.
EXACT_CHUNK = 64


#: Output steps per window of the exact engine: bounds its memory (the coordinates of a chunk of
#: variants over a window).
WINDOW = 2048


def _exact_peaks(system, K, C, lam, shapes, branches, excitation, settings, chunks, done) -> np.ndarray:
    """``max |q|`` and ``max |q''|`` (nv, 12) at the output samples by the exact linear engine (each variant's
    Maxwell ``branches``, None without: complex modes of its augmented first-order system, as
    :func:`~sixdof.analysis.superposition.superpose`); ``done`` receives the fraction of the work done after
    each window of each chunk."""
    M = np.asarray(system.M, dtype=float)
    t = settings.times
    loads, ground, omega = sp.excitation_inputs(excitation, system.K, system.C)  # each variant's ground vectors: _Stack
    q0, qd0 = excitation.initial_state(system, t[0])  # the same for every variant (no mode release)
    f0 = excitation.initial_branch_forces(system)
    plans = [sp.Plan(M, C[i], _Modes(lam[i], shapes[i]), branches=None if branches is None else branches[i])
             for i in range(len(lam))]
    # One quadrature for every variant: that of the fastest.
    nodes, pieces = sp.quadrature_for(float(np.max(np.diff(t))), max(p.fastest for p in plans), omega, ground)
    r = None if ground is None else np.asarray(excitation.ground.rigid_vector, dtype=float)
    stacks = [_Stack([plans[i].coordinates(plans[i].runs[0]) for i in index],
                     None if r is None else [np.stack([K[i] @ r, C[i] @ r]) for i in index],
                     None if r is None or branches is None else
                     [-branches[i].stiffness * (branches[i].rows @ r) for i in index]) for index in chunks]
    z = [stack.initial(M, q0, qd0, f0) for stack in stacks]
    peaks = np.zeros((len(lam), 12))
    breakpoints = np.asarray(excitation.breakpoints, dtype=float)
    ground_start = None
    for low in range(0, t.size - 1, WINDOW):  # windows of output steps, each evaluated once for all
        high = min(low + WINDOW, t.size - 1)
        drive = sp.make_drive(t[low:high + 1], high - low + (low == 0), breakpoints, loads, ground, nodes=nodes,
                              pieces=pieces, ground_start=ground_start)
        ground_start = drive.ground_end
        for k, (stack, index) in enumerate(zip(stacks, chunks)):
            coordinates = sp.run_coordinates(stack, drive, z[k])
            z[k] = coordinates[-1]
            peaks[index] = np.maximum(peaks[index], stack.peaks(coordinates[drive.first:], drive))
            done((low + (high - low) * (k + 1) / len(stacks)) / (t.size - 1))
    return peaks


class _Stack:
    """The first-order modal coordinates of several variants side by side (a block-diagonal system),
    each padded with inert coordinates to the same count so that their outputs are one batched product.

    Parameters
    ----------
    members : list of sixdof.analysis.superposition.ModalCoordinates
    ground_vectors : list of ndarray (2, 6), or None
        Each variant's ``K r`` and ``C r``: the generalized force per unit ground displacement and
        velocity (the drive's last two columns).
    branch_ground : list of ndarray (nb,), or None
        Each variant's ``-k_b R r``: the direct input to its Maxwell branch states per unit ground velocity
        (the drive's last column); None without ground motion or branches.
    """

    def __init__(self, members, ground_vectors=None, branch_ground=None):
        self.members, self.ground_vectors, self.branch_ground = members, ground_vectors, branch_ground
        self.width = max(member.poles.size for member in members)
        self.size = self.width * len(members)
        # An inert coordinate: pole 0, no input, no output, zero initially (it stays 0).
        self.poles = self._side_by_side([m.poles for m in members])
        self.source = self._side_by_side([np.where(m.source >= 0, m.source + j * self.width, -1)
                                          for j, m in enumerate(members)], fill=-1).astype(np.int64)
        # Each member's q, then q'' without B B' Q, from its coordinates' real and imaginary parts
        # interleaved: (members, 2 width, 12).
        maps = self._side_by_side([m.output_maps()[[0, 2]].reshape(12, -1) for m in members])  # (12, size)
        self.maps = np.ascontiguousarray(np.stack([maps.real, -maps.imag], axis=2).reshape(
            12, len(members), 2 * self.width).transpose(1, 0, 2))  # (members, 12, 2 width)
        self._forcing = None

    def _side_by_side(self, blocks, fill=0):
        """Per-member arrays (..., m_j) padded to the common width and put side by side (..., size)."""
        out = np.full(blocks[0].shape[:-1] + (self.size,), fill, dtype=np.result_type(*blocks))
        for j, block in enumerate(blocks):
            out[..., j * self.width:j * self.width + block.shape[-1]] = block
        return out

    def _vectors(self, vectors, j):
        return vectors if self.ground_vectors is None else np.vstack([vectors[:-2], self.ground_vectors[j]])

    def _branch_vectors(self, vectors, j):
        """Member j's direct input to its branch states per unit of each column (n_c, nb): its ground velocity's."""
        if self.branch_ground is None:
            return None
        out = np.zeros((vectors.shape[0], self.branch_ground[j].size))
        out[-1] = self.branch_ground[j]
        return out

    def forcing(self, vectors, branch_vectors=None):
        """(n_c, size): each variant's modal force per unit of each column, with its own ground vectors and input
        to its Maxwell branches (``branch_vectors``, the drive's, is None: it knows no variant's branches)."""
        if self._forcing is None or not np.array_equal(self._forcing[0], vectors):  # the same on every window
            self._forcing = (vectors, self._side_by_side([m.forcing(self._vectors(vectors, j),
                                                                    self._branch_vectors(vectors, j))
                                                          for j, m in enumerate(self.members)]),
                             np.stack([self._vectors(vectors, j) @ (m.basis @ m.basis.T)
                                       for j, m in enumerate(self.members)]))
        return self._forcing[1]

    def initial(self, M, q0, qd0, f0=None):
        """The coordinates (size,) of the state ``q0, qd0`` [m, rad; m/s, rad/s] and branch forces ``f0`` [N]."""
        return self._side_by_side([m.initial @ np.concatenate([m.basis.T @ (M @ q0), m.basis.T @ (M @ qd0)])
                                   + (m.branch_inputs @ f0 if f0 is not None and np.any(f0) else 0.0)
                                   for m in self.members])

    def peaks(self, z, drive):
        """``max |q|`` and ``max |q''|`` (n_members, 12) over the drive's outputs from the coordinates z (n, size)."""
        parts = z.view(float).reshape(z.shape[0], len(self.members), 2 * self.width).transpose(1, 2, 0)
        motion = np.matmul(self.maps, parts)  # (members, 12, n): each member's q and q'' in time
        self.forcing(drive.vectors)
        motion[:, 6:] += np.matmul(self._forcing[2].transpose(0, 2, 1), drive.columns_out.T)  # B B' Q
        return np.maximum(motion.max(axis=2), -motion.min(axis=2))


@partial(jax.jit, static_argnames=("solver", "max_steps"))
def _solve_chunk(A, B, x0, sigma, signals, ts, t0, t1, jump_ts, rtol, atol, *, solver, max_steps):
    """Peaks of |q| and |q''| at ``ts`` for a chunk of variants: A (nv, N, N), B (nv, N, nc), ``N = 12 + nb`` with
    ``nb`` Maxwell branch states (:func:`~sixdof.analysis.direct.mechanical_form`)."""
    import diffrax  # noqa: PLC0415 (diffrax, which the exact engine never loads)

    def source(t):
        return jnp.stack([s(t) for s in signals]) if signals else jnp.zeros(0)

    def one(A, B, x0):
        # Scaled state xs = x / sigma: A and B are pre-scaled, so the field is one N x N product.
        As = A * sigma[None, :] / sigma[:, None]
        Bs = B / sigma[:, None]

        def field(t, xs, args):
            return As @ xs + Bs @ source(t)

        def keep(t, xs, args):
            rate = (A @ (xs * sigma) + B @ source(t))[6:12]
            return jnp.concatenate([xs[:6] * sigma[:6], rate])

        sol = solve_ode(field, x0 / sigma, t0, t1, diffrax.SaveAt(ts=ts, fn=keep), jump_ts, rtol, atol,
                        solver=solver, max_steps=max_steps)
        peaks = jnp.max(jnp.abs(sol.ys), axis=0)
        ok = sol.result == diffrax.RESULTS.successful
        return peaks, ok, sol.stats["num_steps"], sol.stats["num_rejected_steps"]

    return jax.vmap(one)(A, B, x0)


def default_chunk_size(n_samples: int) -> int:
    """Variants per chunk of the diffrax engine so that the kept samples stay within :data:`CHUNK_BYTES`."""
    return int(max(1, min(MAX_CHUNK, CHUNK_BYTES // (max(n_samples, 1) * 12 * 8))))


def _diffrax_peaks(system, K, C, branches, excitation, settings, chunks, done):
    """``max |q|`` and ``max |q''|`` (nv, 12), steps and rejected steps (nv,) by the vmapped diffrax solve of each
    variant's first-order form with its Maxwell ``branches`` (None without); ``done`` receives the fraction of the
    variants done after each chunk."""
    if excitation.ground is not None:
        raise InputError("excitation.ground", "no ground motion in a diffrax batch (not supported yet; use "
                         "engine='exact', or sixdof.analysis.direct.simulate per variant)", Plain("a ground motion"))
    vectors, signals = loads_of(excitation, settings)
    M = np.asarray(system.M, dtype=float)
    Minv = np.linalg.inv(M)
    nv = K.shape[0]
    nb = system.branches.count
    rows = np.stack([b.rows for b in branches]) if nb else np.zeros((nv, 0, 6))
    k_b = np.stack([b.stiffness for b in branches]) if nb else np.zeros((nv, 0))
    A = mechanical_form(Minv, K, C, rows, k_b, system.branches.tau)
    B = np.zeros((nv, 12 + nb, len(signals)))
    B[:, 6:12, :] = (Minv @ vectors.T)[None]
    q0, qd0 = excitation.initial_state(system)
    x0 = np.broadcast_to(np.concatenate([q0, qd0, excitation.initial_branch_forces(system)]), (nv, 12 + nb))
    scale = state_scale(system, excitation, settings)
    sigma = np.concatenate([scale[:12], scale[14:]])  # no ground in a diffrax batch: z, w and f
    t0, t1 = settings.start, settings.start + settings.duration
    padded, _ = jump_times(excitation, t0, t1)
    size = chunks[0].size
    outputs = []
    for index in chunks:
        # One compiled shape: a chunk one short (sizes differ by one at most) repeats its last variant.
        full = np.append(index, np.full(size - index.size, index[-1]))
        out = _solve_chunk(A[full], B[full], x0[full], sigma, signals, settings.times, t0, t1, padded,
                           settings.rtol, settings.atol, solver=settings.solver, max_steps=settings.max_steps)
        outputs.append([np.asarray(o)[:index.size] for o in out])
        done(sum(o[0].shape[0] for o in outputs) / nv)
    peaks, ok, steps, rejected = (np.concatenate([o[k] for o in outputs]) for k in range(4))
    if not np.all(ok):
        bad = np.flatnonzero(~ok)
        raise SolverError(f"batch solve with {settings.solver} (rtol={settings.rtol:g}, atol={settings.atol:g}, "
                          f"max_steps={settings.max_steps}) failed for {bad.size} of {nv} variants "
                          f"(first: index {int(bad[0])})")
    return peaks, readonly(steps, int), readonly(rejected, int)
