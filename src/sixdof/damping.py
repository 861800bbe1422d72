"""The viscous damping matrix C: mount dashpots, Rayleigh and modal damping, combined."""

from __future__ import annotations

import numpy as np

from .modal import modal_analysis


def damping_matrix(system) -> np.ndarray:
    """Total damping matrix of a :class:`~sixdof.model.System` (6, 6) [N s/m, N s, N m s/rad].

    ``C = C_mounts + alpha M + beta K + M Phi diag(2 zeta_r omega_r) Phi' M``: the mounts'
    dashpots, the Rayleigh term and the modal term, each optional, summed. The modal term gives mode
    r exactly the ratio ``zeta_r`` on top of what the others give (zero for rigid-body modes).
    """
    C = np.array(system.C_mounts, dtype=float)
    if system.rayleigh is not None:
        C += system.rayleigh.alpha * system.M + system.rayleigh.beta * system.K
    if system.modal_damping is not None:
        modes = modal_analysis(system.M, system.K)
        zeta = np.broadcast_to(np.asarray(system.modal_damping, dtype=float), (6,))
        mphi = system.M @ modes.shapes
        C += mphi @ np.diag(2.0 * zeta * modes.omega) @ mphi.T
    return 0.5 * (C + C.T)


def modal_damping_ratios(C: np.ndarray, modes) -> np.ndarray:
    """Damping ratio of each undamped mode, ``phi_r' C phi_r / (2 omega_r)`` (6,).

    Exact for classical (proportional) damping; for non-proportional damping it is the usual
    diagonal approximation (the complex modes of :mod:`sixdof.superposition` give the exact ones).
    Rigid-body modes get ``nan``.
    """
    diag = np.einsum("ir,ij,jr->r", modes.shapes, np.asarray(C, dtype=float), modes.shapes)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(modes.omega > 0, diag / (2.0 * modes.omega), np.nan)
