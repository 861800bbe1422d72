"""The first-order form ``x' = A x + B u(t)`` of eq. (1) and the loads it is driven by."""

from __future__ import annotations

import numpy as np

from sixdof.analysis.direct.settings import SimulationSettings
from sixdof.errors import instance
from sixdof.excitation import Excitation
from sixdof.model.system import System

_GROUND_CODES = {None: 0, "displacement": 1, "velocity": 2, "acceleration": 3}


def mechanical_form(Minv, K, C, rows, k_b, tau) -> np.ndarray:
    """``A`` (..., 12 + nb, 12 + nb) of ``x' = A x`` for the state ``x = [z, w, f]`` without ground motion:
    ``z' = w``, ``M w' = -K z - C w - R' f``, ``f' = k_b R w - f / tau`` (:attr:`System.branches`).

    Broadcasts over leading dimensions (a batch of variants: :func:`sixdof.analysis.batch.run_batch`).

    Parameters
    ----------
    Minv : array_like, shape (6, 6)
        Inverse mass matrix [1/kg, 1/(kg m^2)].
    K, C : array_like, shape (..., 6, 6)
        Stiffness and damping [N/m, ...; N s/m, ...].
    rows : array_like, shape (..., nb, 6)
        Each branch state's deformation per unit ``q`` [m/m, m/rad].
    k_b : array_like, shape (..., nb)
        Branch stiffnesses [N/m].
    tau : array_like, shape (nb,)
        Relaxation times [s].
    """
    K, C, rows, k_b = (np.asarray(a, dtype=float) for a in (K, C, rows, k_b))
    tau = np.asarray(tau, dtype=float)
    nb = tau.size
    batch = np.broadcast_shapes(K.shape[:-2], C.shape[:-2], rows.shape[:-2], k_b.shape[:-1])
    A = np.zeros(batch + (12 + nb, 12 + nb))
    A[..., :6, 6:12] = np.eye(6)
    A[..., 6:12, :6] = -Minv @ K
    A[..., 6:12, 6:12] = -Minv @ C
    A[..., 6:12, 12:] = -Minv @ np.swapaxes(rows, -1, -2)
    A[..., 12:, 6:12] = k_b[..., None] * rows
    A[..., 12:, 12:] = np.diag(-1.0 / tau)
    return A


def first_order_form(system: System, excitation: Excitation) -> tuple[np.ndarray, np.ndarray]:
    """``A`` (N, N) and ``B`` (N, n_loads + 1) of ``x' = A x + B u(t)`` for the state ``x = [z, w, u_g, v_g, f, h]``
    (``N = 14 + nb + nh``, ``nb`` Maxwell branch states, ``nh`` hysteretic variables).

    With hysteretic mounts it is the linear part of the motion alone: ``K`` and ``C`` without the hysteretic
    axes' linearization (:attr:`System.K_direct`, :attr:`System.C_direct`), whose laws the direct solve
    adds (:func:`sixdof.analysis.direct.solve._solve_segment`), and zero rows for ``h``.

    The input is ``u = [s_1(t) ... s_n(t), g(t)]``: the load signals, then the ground's velocity ``v_g``
    (ground given as a displacement or a velocity) or acceleration ``a_g`` (given as an acceleration,
    whose velocity is then the state ``v_g``); ``g = 0`` without ground motion.
    """
    vectors, _ = _load_vectors(excitation)
    n = vectors.shape[0]
    Minv = np.linalg.inv(np.asarray(system.M, dtype=float))
    K, C = np.asarray(system.K_direct, dtype=float), np.asarray(system.C_direct, dtype=float)
    branches = system.branches
    R, k_b = branches.rows, branches.stiffness
    size = 14 + branches.count + system.hysteretic.count
    A = np.zeros((size, size))
    mechanical = np.r_[0:12, 14:14 + branches.count]  # z, w and f; u_g, v_g (12, 13) between, h after
    A[np.ix_(mechanical, mechanical)] = mechanical_form(Minv, K, C, R, k_b, branches.tau)
    B = np.zeros((size, n + 1))
    B[6:12, :n] = Minv @ vectors.T
    ground = excitation.ground
    if ground is not None:
        # The ground's velocity v_g enters z' = w - r v_g, the dashpots' force -C (w - r v_g) and the
        # branches' f' = k_b R (w - r v_g) - f / tau.
        r = ground.rigid_vector
        by_velocity = np.concatenate([-r, Minv @ C @ r, [0.0, 0.0], -k_b * (R @ r), np.zeros(size - 14 - k_b.size)])
        if ground.quantity == "acceleration":
            A[:, 13] += by_velocity
            A[12, 13] = 1.0  # u_g' = v_g
            B[13, n] = 1.0  # v_g' = a_g
        else:
            B[:, n] = by_velocity
            if ground.quantity == "velocity":
                B[12, n] = 1.0  # u_g' = v_g
    return A, B


def _load_vectors(excitation: Excitation) -> tuple[np.ndarray, tuple]:
    components = excitation.components()
    return np.array([v for v, _ in components]).reshape(len(components), 6), tuple(s for _, s in components)


def loads_of(excitation: Excitation, settings: SimulationSettings) -> tuple[np.ndarray, tuple]:
    """The loads of a solve, its arguments checked: generalized forces (n_loads, 6) [N, N m] and signals."""
    instance(excitation, "excitation", Excitation)
    instance(settings, "settings", SimulationSettings)
    return _load_vectors(excitation)
