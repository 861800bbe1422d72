"""The system side: first-order modal coordinates (:class:`ModalCoordinates`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.analysis.statespace import CLASSICAL_RTOL, complex_modes
from sixdof.analysis.statespace import coupling as coupling_of
from sixdof.errors import SolverError

#: A single oscillator is one complex mode (one coordinate per conjugate pair) while its damped
#: frequency is at least this fraction of its natural frequency (damping ratio <= 0.968): the
#: transform to that mode and back then amplifies round-off at most ~2x. Closer to critical damping,
#: and for rigid-body modes, the two modes cannot be told apart: it is a chain of two coordinates.
SEPARATE_MODES = 0.25


@dataclass(frozen=True, eq=False)
class ModalCoordinates:
    """First-order modal coordinates ``z`` (m of them) of ``eta'' + D eta' + Omega^2 eta = f(t)`` (p modes).

    ``z_i' = poles_i z_i + inputs_i . f + [z_{source_i}]`` (the bracket when ``source_i >= 0``: the
    second coordinate of a chain), ``[eta; eta'] = Re(outputs @ z)``, ``z(t0) = initial @ [eta; eta']``.

    Attributes
    ----------
    poles : ndarray, shape (m,), complex
        [1/s].
    source : ndarray, shape (m,), int
        The coordinate feeding each one (-1: none); a source is never fed itself.
    inputs : ndarray, shape (m, p), complex
        Modal force to each coordinate.
    outputs : ndarray, shape (2p, m), complex
        Coordinates to ``[eta; eta']`` (conjugate pairs weighted 2).
    initial : ndarray, shape (m, 2p), complex
        ``[eta; eta']`` to the coordinates.
    basis : ndarray, shape (6, p)
        The modes' shapes (mass-normalized).
    damping, stiffness : ndarray, shape (p, p), (p,)
        Modal damping used and ``omega^2`` [1/s, 1/s^2].
    eigenvalues : ndarray, shape (2p + nb,), complex
        Every eigenvalue of the first-order system [1/s].
    branch_inputs : ndarray, shape (m, nb), complex
        Each Maxwell branch state to each coordinate: what a direct input to the branches (the ground's
        velocity) drives, and how their initial forces start the coordinates.
    branch_outputs : ndarray, shape (nb, m), complex
        Coordinates to the branch forces ``f`` [N] (conjugate pairs weighted 2).
    branch_modal : ndarray, shape (p, nb)
        ``G = B' R'``: the branches' modal force per unit branch force (``eta'' = ... - G f``).
    """

    poles: np.ndarray
    source: np.ndarray
    inputs: np.ndarray
    outputs: np.ndarray
    initial: np.ndarray
    basis: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    eigenvalues: np.ndarray
    branch_inputs: np.ndarray
    branch_outputs: np.ndarray
    branch_modal: np.ndarray

    def forcing(self, vectors, branch_vectors=None):
        """Modal force per unit of each column (generalized force ``vectors`` (n_c, 6), and direct input to the
        Maxwell branch states ``branch_vectors`` (n_c, nb)) to each coordinate (n_c, m)."""
        own = (vectors @ self.basis) @ self.inputs.T
        return own if branch_vectors is None else own + branch_vectors @ self.branch_inputs.T

    def output_maps(self):
        """``q, q', q''`` from the coordinates: ``Re(maps[k] @ z)``, maps (3, 6, m) complex; ``q''`` without
        the generalized force's part ``B B' Q`` (``eta'' = f - D eta' - Omega^2 eta - G f_b``)."""
        p = self.basis.shape[1]
        eta, eta_d = self.outputs[:p], self.outputs[p:]
        return np.stack([self.basis @ eta, self.basis @ eta_d,
                         -self.basis @ (self.damping @ eta_d + self.stiffness[:, None] * eta
                                        + self.branch_modal @ self.branch_outputs)])

    def motion(self, z, drive, second=True):
        """``q, q', q''`` (n, 6) from the coordinates z (n, m) at the drive's output times; ``q'`` and
        ``q''`` only when ``second`` (else None)."""
        maps = self.output_maps()[:3 if second else 1]
        # Re(z @ maps.T) as one real product per output: z's real and imaginary parts interleaved, times
        # the map's real part and minus its imaginary part interleaved.
        q, qd, qdd = [z.view(float) @ _interleaved(a.T) for a in maps] + [None] * (3 - len(maps))
        if second:  # the generalized force's part of q''
            qdd += drive.columns_out @ (drive.vectors @ (self.basis @ self.basis.T))
        return q, qd, qdd

    def branch_forces(self, z):
        """The Maxwell branch forces (n, nb) [N] from the coordinates z (n, m)."""
        return z.view(float) @ _interleaved(self.branch_outputs.T)


def _interleaved(a):
    """(m, k) complex -> (2m, k) real, rows ``Re a_j, -Im a_j``: ``x.view(float) @ _interleaved(a) = Re(x @ a)``."""
    return np.stack([a.real, -a.imag], axis=1).reshape(2 * a.shape[0], a.shape[1])


def _modal_coordinates(basis, omega2, D, kept, method, all_complex=False, branches=None) -> ModalCoordinates:
    """The first-order coordinates of the kept modes, solved by ``method`` (``"real"`` or ``"complex"``); with
    Maxwell ``branches`` (complex), the modes they deform are coupled through them."""
    B = basis[:, kept]
    w2 = omega2[kept]
    Dk = D[np.ix_(kept, kept)]
    p = len(kept)
    nb = 0 if branches is None else branches.count
    G = B.T @ branches.rows.T if nb else np.zeros((p, 0))
    if method == "real":
        single, coupled = np.arange(p), np.arange(0)
        D_used = np.diag(np.diag(Dk))
    else:
        # Uncoupled coordinates are single oscillators (exact, robust when critically damped); with
        # complex modes forced, only undamped rigid ones are (their first-order form is a Jordan block).
        isolated = np.all(coupling_of(Dk) <= CLASSICAL_RTOL, axis=1)
        if nb:  # a mode that deforms a branch is coupled through it (to the branch, and maybe other modes)
            isolated &= ~np.any(G * branches.stiffness[None, :] != 0.0, axis=1)
        if all_complex:
            isolated &= (w2 == 0.0) & (np.diag(Dk) <= CLASSICAL_RTOL * max(float(np.max(np.diag(Dk))), 0.0))
        single = np.flatnonzero(isolated)
        coupled = np.flatnonzero(~isolated)
        D_used = Dk.copy()
        D_used[np.ix_(single, coupled)] = 0.0
        D_used[np.ix_(coupled, single)] = 0.0

    poles, source, inputs, outputs, initial, eigenvalues = [], [], [], [], [], []
    branch_inputs, branch_outputs = [], []
    unbranched = np.zeros(nb)

    def add(pole, feeding, to_input, to_output, from_state, to_branch=unbranched, from_branch=unbranched):
        poles.append(pole)
        source.append(feeding)
        inputs.append(to_input)
        outputs.append(to_output)
        initial.append(from_state)
        branch_inputs.append(from_branch)
        branch_outputs.append(to_branch)
        return len(poles) - 1

    unit = np.eye(2 * p)
    for j in single:
        sigma = -0.5 * Dk[j, j]
        mu = np.sqrt(complex(sigma**2 - w2[j]))  # i w_d under critical damping, real at or beyond
        first, second = sigma + mu, sigma - mu
        eigenvalues += [first, second]
        if mu.imag >= SEPARATE_MODES * np.sqrt(w2[j]) and mu.imag > 0:
            # One complex mode z = (eta' - second eta) / (first - second); eta = 2 Re z, eta' = 2 Re(first z).
            gap = first - second
            add(first, -1, unit[p + j, p:] / gap, 2 * (unit[j] + first * unit[p + j]),
                (unit[p + j] - second * unit[j]) / gap)
        else:
            # The chain u = eta' - second eta, u' = first u + f; x = eta, x' = second x + u.
            u = add(first, -1, unit[p + j, p:], unit[p + j], unit[p + j] - second * unit[j])
            add(second, u, np.zeros(p), unit[j] + second * unit[p + j], unit[j])
    if coupled.size:
        maxwell = (G[coupled], branches.stiffness, branches.tau) if nb else None
        modes = complex_modes(np.diag(w2[coupled]), D_used[np.ix_(coupled, coupled)], maxwell=maxwell,
                              remedy="use method='real' only if the damping is classical")
        lam, V, Vinv = modes.eigenvalues, modes.right, modes.left
        eigenvalues += list(lam)
        # dgeev returns real eigenvalues with exactly zero imaginary part and exact conjugate pairs.
        real = np.flatnonzero(lam.imag == 0)
        upper = np.flatnonzero(lam.imag > 0)
        n_c = len(coupled)
        if len(real) + 2 * len(upper) != 2 * n_c + nb:
            raise SolverError("complex modes: eigenvalues are not in conjugate pairs")
        rows = np.concatenate([coupled, p + coupled])  # [eta; eta'] of the coupled modes
        for k, weight in [(k, 1.0) for k in real] + [(k, 2.0) for k in upper]:
            to_output = np.zeros(2 * p, complex)
            to_output[rows] = weight * V[:2 * n_c, k]
            from_state = np.zeros(2 * p, complex)  # the branches start relaxed: only [eta; eta'] sets z(t0)
            from_state[rows] = Vinv[k, :2 * n_c]
            to_input = np.zeros(p, complex)
            to_input[coupled] = Vinv[k, n_c:2 * n_c]
            add(lam[k], -1, to_input, to_output, from_state, weight * V[2 * n_c:, k], Vinv[k, 2 * n_c:])

    eigenvalues = np.array(eigenvalues, dtype=complex)
    return ModalCoordinates(
        poles=np.array(poles, dtype=complex), source=np.array(source, dtype=np.int64),
        inputs=np.array(inputs, dtype=complex).reshape(-1, p), outputs=np.array(outputs, dtype=complex).T,
        initial=np.array(initial, dtype=complex), basis=B, damping=D_used, stiffness=w2,
        eigenvalues=eigenvalues[np.lexsort((eigenvalues.imag, np.abs(eigenvalues)))],
        branch_inputs=np.array(branch_inputs, dtype=complex).reshape(len(poles), nb),
        branch_outputs=np.array(branch_outputs, dtype=complex).reshape(len(poles), nb).T, branch_modal=G,
    )
