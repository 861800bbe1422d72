"""The one damping matrix C of eq. (1): mount dashpots, Rayleigh and modal damping, summed.

Written with array operators only, so that the same formula serves a :class:`~sixdof.model.system.System`
(NumPy) and the vectorized batches (``jax.vmap`` over variants).
"""

from __future__ import annotations


def damping_matrix(M, K, C_mounts, alpha, beta, zeta, shapes, omega):
    """``C = C_mounts + alpha M + beta K + M Phi diag(2 zeta_r omega_r) Phi' M``, symmetrized.

    Each term is optional (zero coefficients). The modal term gives mode r exactly the ratio ``zeta_r``
    on top of what the others give (nothing for rigid-body modes, whose ``omega_r`` is 0).

    Parameters
    ----------
    M, K, C_mounts : array, shape (6, 6)
        Mass [kg, kg m^2], stiffness [N/m ...] and the mounts' dashpots [N s/m ...].
    alpha, beta : float
        Rayleigh coefficients [1/s], [s].
    zeta : array, shape (6,)
        Modal damping ratio added to each mode (ascending frequency).
    shapes : array, shape (6, 6)
        Mass-normalized undamped mode shapes (columns).
    omega : array, shape (6,)
        Natural circular frequencies [rad/s].

    Returns
    -------
    array, shape (6, 6)
        [N s/m, N s, N m s/rad].
    """
    mass_shapes = M @ shapes
    C = C_mounts + alpha * M + beta * K + (mass_shapes * (2.0 * zeta * omega)[None, :]) @ mass_shapes.T
    return 0.5 * (C + C.T)
