"""Independent references for hysteretic (Bouc-Wen) bearings: scipy ``solve_ivp`` of the ODEs (none uses sixdof).

The law is the one of issue 48, item 1, on each hysteretic axis (Wen's model with A = 1):

    r = a k d + (1 - a) Fy z,    z' = (d' / d_y) (1 - |z|^n (b sgn(d' z) + g)),    d_y = Fy / k,

with ``d`` the axis' deflection [m], ``k`` its elastic stiffness [N/m], ``Fy`` its yield force [N], ``a`` the
post-yield stiffness ratio, ``z`` dimensionless (|z| <= 1 on the loop's envelope when b + g = 1), z(0) = 0.

The ground acceleration is a first-order hold of its samples (``np.interp``), as OpenSees' Path time series
interpolates them, so both sides solve the same problem; each solve runs piece by piece between the samples, so
that the integrator never steps over the input's kinks (the only other non-smooth points, where d' or z changes
sign, have a continuous right-hand side: the step control handles them with a few rejected steps).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.integrate

#: Default tolerances of the reference solves: DOP853 at rtol 1e-11 is ~1e-9 from converged on these problems
#: (measured against rtol 1e-13 in tests/test_opensees_reference.py), far below the OpenSees time-step errors.
RTOL, ATOL_SCALE = 1e-11, 1e-11


def bouc_wen_rate(v, z, d_y, n, beta, gamma):
    """z' [1/s] of the law above for deflection rate ``v`` [m/s] and yield deflection ``d_y`` = Fy / k [m]."""
    return v / d_y * (1.0 - np.abs(z) ** n * (beta * np.sign(v * z) + gamma))


def skew(p):
    """The cross-product matrix: ``skew(p) @ x == np.cross(p, x)``."""
    return np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])


def point_map(positions):
    """(n, 3, 6): T_j = [I, -skew(p_j)], q = [x, y, z, rx, ry, rz] to point j's displacement (small rotations)."""
    return np.array([np.hstack([np.eye(3), -skew(p)]) for p in np.asarray(positions, float)])


def rigid_body_matrices(mass, inertia, positions, stiffness, damping):
    """M, K, C (6, 6) of a rigid body on mounts along body axes: ``K = sum_j T_j' diag(k_j) T_j``, the same for C.

    ``inertia`` (3,) principal or (3, 3) about the CG [kg m^2]; ``stiffness``, ``damping`` (n, 3) [N/m], [N s/m].
    """
    J = np.asarray(inertia, float)
    J = np.diag(J) if J.ndim == 1 else J
    M = np.zeros((6, 6))
    M[:3, :3], M[3:, 3:] = mass * np.eye(3), J
    T = point_map(positions)
    K = sum(Tj.T @ np.diag(kj) @ Tj for Tj, kj in zip(T, np.asarray(stiffness, float)))
    C = sum(Tj.T @ np.diag(cj) @ Tj for Tj, cj in zip(T, np.asarray(damping, float)))
    return M, K, C


def _piecewise(rhs, t, y0, rtol, atol, method):
    """Solve from sample to sample of ``t``; returns the states (t, state) at the samples and the evaluations."""
    out = np.empty((t.size, y0.size))
    out[0], y, nfev = y0, y0, 0
    for i in range(t.size - 1):
        sol = scipy.integrate.solve_ivp(rhs, (t[i], t[i + 1]), y, method=method, rtol=rtol, atol=atol)
        if not sol.success:
            raise RuntimeError(f"solve_ivp on [{t[i]}, {t[i + 1]}]: {sol.message}")
        y = out[i + 1] = sol.y[:, -1]
        nfev += sol.nfev
    return out, nfev


@dataclass(frozen=True)
class SdofSolution:
    """A single-mass Bouc-Wen oscillator's history at the record's samples.

    Attributes
    ----------
    t : (t,) times [s]; d, v : (t,) displacement [m] and velocity [m/s] relative to the ground;
    z : (t,) the hysteretic variable [1]; force : (t,) the hysteretic force r [N]; nfev : right-hand sides.
    """

    t: np.ndarray
    d: np.ndarray
    v: np.ndarray
    z: np.ndarray
    force: np.ndarray
    nfev: int


def bouc_wen_sdof_ivp(mass, k, fy, alpha, n, beta, gamma, t, ground_acc, *, damping=0.0, rtol=RTOL,
                      method="DOP853") -> SdofSolution:
    """``m d'' + c d' + r(d, z) = -m a_g(t)`` by solve_ivp, with the law of the module.

    Parameters
    ----------
    mass : float  [kg];  k : float  elastic stiffness [N/m];  fy : float  yield force [N]
    alpha, n, beta, gamma : float  post-yield ratio a, exponent, b, g of the law [1]
    t : (t,) sample times [s], from 0;  ground_acc : (t,) ground acceleration at ``t`` [m/s^2]
    damping : float  a dashpot c [N s/m] beside the bearing
    rtol : float  relative tolerance; the absolute ones scale with d_y, d_y omega and 1 on d, v, z
    """
    t, ag = np.asarray(t, float), np.asarray(ground_acc, float)
    d_y = fy / k
    omega = np.sqrt(k / mass)

    def rhs(time, y):
        d, v, z = y
        r = alpha * k * d + (1.0 - alpha) * fy * z
        return [v, -np.interp(time, t, ag) - (r + damping * v) / mass, bouc_wen_rate(v, z, d_y, n, beta, gamma)]

    atol = ATOL_SCALE * np.array([d_y, d_y * omega, 1.0])
    y, nfev = _piecewise(rhs, t, np.zeros(3), rtol, atol, method)
    d, v, z = y.T
    return SdofSolution(t, d, v, z, alpha * k * d + (1.0 - alpha) * fy * z, nfev)


@dataclass(frozen=True)
class RigidBodySolution:
    """A rigid body on Bouc-Wen bearings at the record's samples.

    Attributes
    ----------
    t : (t,) [s];  q : (t, 6) CG displacement relative to the ground [m, rad] (x, y, z, rx, ry, rz)
    deflection : (t, mount, 3) mount deflections along body axes [m]
    hysteretic_force : (t, mount, 3) r of each hysteretic axis [N], NaN on the elastic ones
    z : (t, mount, 3) the hysteretic variables [1], NaN on the elastic axes;  nfev : right-hand sides
    """

    t: np.ndarray
    q: np.ndarray
    deflection: np.ndarray
    hysteretic_force: np.ndarray
    z: np.ndarray
    nfev: int


def hysteretic_axes_table(hysteresis, mounts):
    """(mount, 3) arrays mask, fy, alpha, n, beta, gamma from ``[{axis: (fy, alpha, n, beta, gamma)}, ...]``
    (``axis`` 0, 1, 2 or ``"u"``, ``"v"``, ``"w"``; elastic axes: mask False)."""
    mask = np.zeros((mounts, 3), bool)
    params = np.zeros((5, mounts, 3))
    for j, axes in enumerate(hysteresis or [{}] * mounts):
        for axis, values in axes.items():
            a = "uvw".index(axis) if isinstance(axis, str) else int(axis)
            mask[j, a] = True
            params[:, j, a] = values
    return (mask, *params)


def direction_vector(direction):
    """A unit vector in body axes from ``"x"``, ``"y"``, ``"z"`` or 3 components."""
    if isinstance(direction, str):
        return np.eye(3)["xyz".index(direction)]
    e = np.asarray(direction, float)
    return e / np.linalg.norm(e)


def rigid_body_ivp(mass, inertia, positions, stiffness, damping, hysteresis, t, ground_acc, direction, *,
                   rtol=RTOL, method="DOP853") -> RigidBodySolution:
    """``M q'' + sum_j T_j' f_j(T_j q, T_j q', z_j) = -M [e; 0] a_g(t)`` by solve_ivp (see the module).

    ``f_j`` per axis: ``k d + c d'`` on the elastic axes, ``a k d + (1 - a) Fy z + c d'`` on the hysteretic
    ones, with ``k`` the axis' stiffness; the arguments as :func:`opensees_models.rigid_body_on_bearings`.
    """
    t, ag = np.asarray(t, float), np.asarray(ground_acc, float)
    positions = np.asarray(positions, float)
    k, c = np.asarray(stiffness, float), np.asarray(damping, float)
    M, K, _ = rigid_body_matrices(mass, inertia, positions, k, c)
    mounts = positions.shape[0]
    mask, fy, alpha, n, beta, gamma = hysteretic_axes_table(hysteresis, mounts)
    T = point_map(positions).reshape(3 * mounts, 6)
    k, c, mask = k.ravel(), c.ravel(), mask.ravel()
    fy, alpha, n, beta, gamma = (p.ravel()[mask] for p in (fy, alpha, n, beta, gamma))
    d_y = fy / k[mask]
    k_elastic = np.where(mask, 0.0, k)
    k_elastic[mask] = alpha * k[mask]
    Minv = np.linalg.inv(M)
    load = -np.concatenate([direction_vector(direction), np.zeros(3)])  # M^-1 (-M [e; 0]) a_g

    def rhs(time, y):
        q, qd, z = y[:6], y[6:12], y[12:]
        d, v = T @ q, T @ qd
        f = k_elastic * d + c * v
        f[mask] += (1.0 - alpha) * fy * z
        return np.concatenate([qd, load * np.interp(time, t, ag) - Minv @ (T.T @ f),
                               bouc_wen_rate(v[mask], z, d_y, n, beta, gamma)])

    # Absolute tolerances: translations on the larger yield deflection, rotations on it over the body's size,
    # velocities on those times the highest natural frequency, z on 1.
    length = np.max(np.abs(positions))
    scale_q = np.max(d_y, initial=1e-3) * np.array([1, 1, 1, 1 / length, 1 / length, 1 / length])
    omega = np.sqrt(np.max(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    atol = ATOL_SCALE * np.concatenate([scale_q, scale_q * omega, np.ones(int(mask.sum()))])
    y, nfev = _piecewise(rhs, t, np.zeros(12 + int(mask.sum())), rtol, atol, method)
    q = y[:, :6]
    deflection = np.einsum("ij,tj->ti", T, q).reshape(t.size, mounts, 3)
    z = np.full((t.size, 3 * mounts), np.nan)
    z[:, mask] = y[:, 12:]
    force = np.full((t.size, 3 * mounts), np.nan)
    force[:, mask] = alpha * k[mask] * deflection.reshape(t.size, -1)[:, mask] + (1.0 - alpha) * fy * y[:, 12:]
    return RigidBodySolution(t, q, deflection, force.reshape(t.size, mounts, 3), z.reshape(t.size, mounts, 3),
                             nfev)
