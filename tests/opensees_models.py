"""OpenSeesPy models of Bouc-Wen bearings: the independent reference of issue 48, items 7 and 8 (none uses sixdof).

Used by tests/test_opensees_reference.py and benchmarks/bench_opensees.py; needs ``openseespy`` (the ``test``
extra). OpenSees keeps one global model per process: these functions wipe it on entry and are not thread-safe.

OpenSees' ``uniaxialMaterial BoucWen`` (SRC/material/uniaxial/BoucWenMaterial.cpp, Haukaas; unchanged in its
constitutive part since 2011, the same in 3.7.1 and on master in 2026), with its degradation switched off
(``deltaA = deltaNu = deltaEta = 0``, so ``nu = eta = 1``), is

    sigma = alpha ko eps + (1 - alpha) ko z_os,
    z_os' = eps' (Ao - |z_os|^n (gamma_os + beta_os sgn(eps' z_os))),

``z_os`` in units of the strain (a displacement [m] in a zeroLength element), integrated by backward Euler along
the strain path, ``z_{i+1} = z_i + (Ao - |z_{i+1}|^n Psi) (eps_{i+1} - eps_i)``, solved by Newton's method to an
absolute tolerance on ``z_os`` (argument 10, default 1e-8 m).

sixdof's law (issue 48, item 1) is ``r = a k d + (1 - a) Fy z``, ``z' = (d' / d_y) (1 - |z|^n (b sgn(d' z) + g))``,
``d_y = Fy / k``, ``z`` dimensionless. Put ``z_os = d_y z``; then, as ``sgn(d' z_os) = sgn(d' z)`` (d_y > 0),

    z_os' = d_y z' = d' (1 - |z|^n (b sgn(d' z) + g)) = d' (1 - |z_os|^n (b / d_y^n sgn(d' z_os) + g / d_y^n)),
    (1 - alpha) ko z_os = (1 - a) k d_y z = (1 - a) Fy z,

so the two are the same law with

    alpha = a,   ko = k,   Ao = 1,   beta_os = b / d_y^n,   gamma_os = g / d_y^n,   d_y = Fy / k.

The command's positional order is ``alpha ko n gamma beta Ao deltaA deltaNu deltaEta tol maxIter``: ``gamma``
(the constant term) comes before ``beta`` (the sign term), the reverse of the usual reading, which is easy to
swap by mistake. OpenSees' ``signum(0)`` is -1 where ours is 0; the two differ only where ``d' z = 0``, where
the ``|z|^n`` term vanishes (z = 0) or the increment does (d' = 0).

Time integration: Newmark's average acceleration (gamma = 1/2, beta = 1/4, second order, no numerical damping),
Newton iterations (Krylov-accelerated) to a displacement increment of 1e-12, the ground acceleration a Path time
series (a first-order hold of its samples) through UniformExcitation, so the displacements are relative to the
ground. The backward Euler update of z makes the whole first order in the time step (tests/test_opensees_reference.py
measures it).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

#: Newton tolerance of the BoucWen material's z update, relative to the yield deflection (the default 1e-8 m is
#: 1e-6 of a 1 cm yield deflection: not tight enough to see the time-step error converge).
Z_TOLERANCE = 1e-12
#: Newton iterations of the material update and of each time step.
MAX_ITERATIONS = 50
#: Convergence test of each time step: the displacement increment's norm [m, rad].
DISPLACEMENT_TOLERANCE = 1e-12


def bouc_wen_parameters(k, fy, alpha, n, beta, gamma):
    """The arguments after the tag of ``uniaxialMaterial BoucWen`` for sixdof's law (see the module).

    Returns ``[alpha, ko, n, gamma_os, beta_os, Ao, deltaA, deltaNu, deltaEta, tol, maxIter]``.
    """
    d_y = fy / k
    return [alpha, k, n, gamma / d_y**n, beta / d_y**n, 1.0, 0.0, 0.0, 0.0, Z_TOLERANCE * d_y, MAX_ITERATIONS]


def _ops():
    import openseespy.opensees as ops

    return ops


def _uniform_step(t) -> float:
    t = np.asarray(t, float)
    dt = np.diff(t)
    if t[0] != 0.0 or not np.allclose(dt, dt[0], rtol=1e-9, atol=0.0):
        raise ValueError(f"t: expected uniform samples from 0, got t[0] = {t[0]}, steps {dt.min()} to {dt.max()} s")
    return float(dt[0])


def _transient(ops, substeps, dt):
    """Newmark average acceleration, Krylov-accelerated Newton iterations, a small dense system.

    KrylovNewton rather than full Newton: the same answer (4e-15 apart on the bridge, both to the displacement
    tolerance) in 0.57 of the time (measured on the bridge benchmark, 16,000 steps; BandGeneral, UmfPack or
    ProfileSPD instead of FullGeneral changed nothing measurable on the 6 equations left after the constraints).
    """
    ops.constraints("Transformation")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", DISPLACEMENT_TOLERANCE, MAX_ITERATIONS)
    ops.algorithm("KrylovNewton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    return dt / substeps


def _step(ops, substeps, h, at):
    if ops.analyze(substeps, h) != 0:
        raise RuntimeError(f"OpenSees did not converge in the step ending at t = {at} s (dt = {h} s)")


@dataclass(frozen=True)
class SdofHistory:
    """OpenSees' single-mass history at the record's samples.

    Attributes
    ----------
    t : (t,) [s];  d : (t,) displacement relative to the ground [m];  force : (t,) the hysteretic force r [N];
    z : (t,) sixdof's dimensionless z = (r - a k d) / ((1 - a) Fy);  dt : the analysis step [s]
    """

    t: np.ndarray
    d: np.ndarray
    force: np.ndarray
    z: np.ndarray
    dt: float


def bouc_wen_sdof(mass, k, fy, alpha, n, beta, gamma, t, ground_acc, *, substeps=10, damping=0.0) -> SdofHistory:
    """A mass on a zeroLength Bouc-Wen element under a uniform base acceleration.

    Parameters
    ----------
    mass : float
        [kg].
    k, fy : float
        Elastic stiffness [N/m] and yield force [N] of sixdof's law (see the module).
    alpha, n, beta, gamma : float
        Post-yield stiffness ratio a, exponent n, b and g of sixdof's law [1] (converted by
        :func:`bouc_wen_parameters`).
    t : array_like, shape (t,)
        Uniform sample times from 0 [s]; the outputs are at these times.
    ground_acc : array_like, shape (t,)
        Ground acceleration [m/s^2], linear between samples.
    substeps : int
        Analysis steps per sample interval: the step is ``(t[1] - t[0]) / substeps``.
    damping : float
        A dashpot [N s/m] beside the bearing (an Elastic material with E = 0, eta = c).

    Returns
    -------
    SdofHistory
    """
    ops = _ops()
    t, ag = np.asarray(t, float), np.asarray(ground_acc, float)
    dt = _uniform_step(t)
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    ops.node(1, 0.0)
    ops.node(2, 0.0)
    ops.fix(1, 1)
    ops.mass(2, mass)
    ops.uniaxialMaterial("BoucWen", 1, *bouc_wen_parameters(k, fy, alpha, n, beta, gamma))
    mats, dirs = [1], [1]
    if damping > 0:
        ops.uniaxialMaterial("Elastic", 2, 0.0, damping)
        mats, dirs = [1, 2], [1, 1]
    ops.element("zeroLength", 1, 1, 2, "-mat", *mats, "-dir", *dirs)
    ops.timeSeries("Path", 1, "-dt", dt, "-values", *ag)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    h = _transient(ops, substeps, dt)
    d, r = np.zeros(t.size), np.zeros(t.size)
    for i in range(1, t.size):
        _step(ops, substeps, h, t[i])
        d[i] = ops.nodeDisp(2, 1)
        r[i] = ops.eleResponse(1, "basicForce")[0]
    ops.wipe()
    z = (r - alpha * k * d) / ((1.0 - alpha) * fy) if alpha < 1 else np.zeros_like(r)
    return SdofHistory(t, d, r, z, h)


@dataclass(frozen=True)
class RigidBodyHistory:
    """OpenSees' rigid-body history at the record's samples.

    Attributes
    ----------
    t : (t,) [s];  q : (t, 6) CG displacement relative to the ground, body axes [m, rad] (x, y, z, rx, ry, rz)
    deflection : (t, mount, 3) mount deflections along body axes [m]
    hysteretic_force : (t, mount, 3) the Bouc-Wen force r of each hysteretic axis [N], NaN on the elastic ones
    dt : the analysis step [s]
    """

    t: np.ndarray
    q: np.ndarray
    deflection: np.ndarray
    hysteretic_force: np.ndarray
    dt: float


def _principal_frame(inertia):
    """(J principal (3,), R (3, 3)) with ``J = R diag(Jp) R'``; R = I for a diagonal (or (3,)) inertia."""
    J = np.asarray(inertia, float)
    if J.ndim == 1:
        return J, np.eye(3)
    if np.count_nonzero(J - np.diag(np.diag(J))) == 0:
        return np.diag(J).copy(), np.eye(3)
    Jp, R = np.linalg.eigh(J)
    if np.linalg.det(R) < 0:  # a right-handed frame, as OpenSees' rotations are
        R[:, 0] *= -1
    return Jp, R


def rigid_body_on_bearings(mass, inertia, positions, stiffness, damping, hysteresis, t, ground_acc, direction, *,
                           substeps=10) -> RigidBodyHistory:
    """A 6-DOF rigid body on bearings along body axes under a uniform base acceleration.

    The CG is one node carrying the mass and rotational inertia; each mount is a node tied to it by a rigid
    beam link (``rigidLink beam``, linear small-rotation kinematics ``u_p = u + theta x p``), and a zeroLength
    element from it to a fixed ground node at the same point, with one material per axis: Elastic (k, eta = c)
    on the elastic axes, BoucWen (see the module) beside an Elastic (0, eta = c) dashpot on the hysteretic ones.
    A full inertia tensor is handled by building the model in its principal frame (zeroLength orientations and
    the excitation rotated into it) and turning the results back into body axes.

    Parameters
    ----------
    mass : float
        [kg].
    inertia : array_like, shape (3,) or (3, 3)
        Principal moments or the inertia tensor about the CG in body axes [kg m^2].
    positions : array_like, shape (mount, 3)
        Mount points from the CG in body axes [m].
    stiffness, damping : array_like, shape (mount, 3)
        Elastic stiffness [N/m] and dashpot [N s/m] per mount along body axes x, y, z (the mount's u, v, w).
    hysteresis : sequence of dict, one per mount, or None
        ``{axis: (fy, alpha, n, beta, gamma)}`` with ``axis`` in ``"u"``, ``"v"``, ``"w"`` (or 0, 1, 2): the
        axes that follow sixdof's Bouc-Wen law with that axis' stiffness as k (uncoupled uniaxial laws).
    t : array_like, shape (t,)
        Uniform sample times from 0 [s].
    ground_acc : array_like, shape (t,)
        Ground acceleration [m/s^2] along ``direction``, linear between samples.
    direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a vector in body axes.
    substeps : int
        Analysis steps per sample interval.

    Returns
    -------
    RigidBodyHistory
    """
    from hysteresis_references import direction_vector, hysteretic_axes_table, point_map

    ops = _ops()
    t, ag = np.asarray(t, float), np.asarray(ground_acc, float)
    dt = _uniform_step(t)
    positions = np.asarray(positions, float)
    k, c = np.asarray(stiffness, float), np.asarray(damping, float)
    mounts = positions.shape[0]
    mask, fy, alpha, n, beta, gamma = hysteretic_axes_table(hysteresis, mounts)
    Jp, R = _principal_frame(inertia)  # model frame = principal frame; body vector v -> R' v

    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    cg = 1
    ops.node(cg, 0.0, 0.0, 0.0)
    ops.mass(cg, mass, mass, mass, *Jp)
    local_x, local_y = R.T @ np.array([1.0, 0.0, 0.0]), R.T @ np.array([0.0, 1.0, 0.0])
    tag = 0
    hysteretic = []  # (mount, axis, element, index of the material in the element)
    for j in range(mounts):
        body, ground = 10 + 2 * j, 11 + 2 * j
        p = R.T @ positions[j]
        ops.node(body, *p)
        ops.node(ground, *p)
        ops.fix(ground, 1, 1, 1, 1, 1, 1)
        ops.rigidLink("beam", cg, body)
        mats, dirs = [], []
        for a in range(3):
            if mask[j, a]:
                tag += 1
                ops.uniaxialMaterial("BoucWen", tag, *bouc_wen_parameters(
                    k[j, a], fy[j, a], alpha[j, a], n[j, a], beta[j, a], gamma[j, a]))
                hysteretic.append((j, a, 1 + j, len(mats)))
                mats.append(tag)
                dirs.append(a + 1)
                if c[j, a] > 0:
                    tag += 1
                    ops.uniaxialMaterial("Elastic", tag, 0.0, c[j, a])
                    mats.append(tag)
                    dirs.append(a + 1)
            elif k[j, a] > 0 or c[j, a] > 0:
                tag += 1
                ops.uniaxialMaterial("Elastic", tag, k[j, a], c[j, a])
                mats.append(tag)
                dirs.append(a + 1)
        ops.element("zeroLength", 1 + j, ground, body, "-mat", *mats, "-dir", *dirs,
                    "-orient", *local_x, *local_y)

    e = R.T @ direction_vector(direction)
    for axis in range(3):
        if e[axis] != 0.0:
            ops.timeSeries("Path", 1 + axis, "-dt", dt, "-values", *ag, "-factor", float(e[axis]))
            ops.pattern("UniformExcitation", 1 + axis, 1 + axis, "-accel", 1 + axis)
    h = _transient(ops, substeps, dt)

    q_model = np.zeros((t.size, 6))
    force = np.full((t.size, mounts, 3), np.nan)
    force[0, mask] = 0.0
    for i in range(1, t.size):
        _step(ops, substeps, h, t[i])
        q_model[i] = ops.nodeDisp(cg)
        for j, a, element, index in hysteretic:
            force[i, j, a] = ops.eleResponse(element, "basicForce")[index]
    ops.wipe()
    q = np.hstack([q_model[:, :3] @ R.T, q_model[:, 3:] @ R.T])  # back to body axes
    deflection = np.einsum("jab,tb->tja", point_map(positions), q)
    return RigidBodyHistory(t, q, deflection, force, h)


def moving_dofs(q_ref, length) -> np.ndarray:
    """(6,) bool: the DOFs whose peak ``max_t |q_ref|`` is at least 1e-6 of the largest, rotations counted as
    displacements at ``length`` [m] (the body's half size); a DOF decoupled by symmetry sits at round-off."""
    scale = np.max(np.abs(q_ref), axis=0) * np.array([1, 1, 1, length, length, length])
    return scale > 1e-6 * scale.max()


def peak_change(q, q_ref, length) -> float:
    """Largest change of the per-DOF peaks ``max_t |q|`` relative to ``q_ref``'s, over the :func:`moving_dofs`."""
    moving = moving_dofs(q_ref, length)
    peak, peak_ref = np.max(np.abs(q[:, moving]), axis=0), np.max(np.abs(q_ref[:, moving]), axis=0)
    return float(np.max(np.abs(peak - peak_ref) / peak_ref))


def worst_error(q, q_ref, length) -> float:
    """``max_t |q - q_ref| / max_t |q_ref|``, the largest over the :func:`moving_dofs` (each on its own scale)."""
    moving = moving_dofs(q_ref, length)
    return float(np.max(np.max(np.abs(q[:, moving] - q_ref[:, moving]), axis=0)
                        / np.max(np.abs(q_ref[:, moving]), axis=0)))


@dataclass(frozen=True)
class Timing:
    """:func:`time_opensees`'s answer.

    Attributes
    ----------
    wall_s : wall time of the run at ``dt`` [s];  dt : the analysis step reached [s];  substeps : per sample
    change : the peak change from the previous halving [1];  history : that run's RigidBodyHistory
    tries : ((dt, wall_s, change), ...) every run made (change NaN for the first)
    """

    wall_s: float
    dt: float
    substeps: int
    change: float
    history: RigidBodyHistory
    tries: tuple


def time_opensees(*args, rtol=1e-3, substeps=1, max_halvings=10, **kwargs) -> Timing:
    """Halve the step of :func:`rigid_body_on_bearings` until the per-DOF peak CG displacements change by less
    than ``rtol`` (:func:`peak_change`); the wall time of that last run.

    ``args`` and ``kwargs`` are those of :func:`rigid_body_on_bearings`; ``substeps`` is the first try's.
    """
    positions = np.asarray(args[2] if len(args) > 2 else kwargs["positions"], float)
    length = float(np.max(np.abs(positions)))
    tries, previous = [], None
    for _ in range(max_halvings + 1):
        start = time.perf_counter()
        history = rigid_body_on_bearings(*args, substeps=substeps, **kwargs)
        wall = time.perf_counter() - start
        change = np.nan if previous is None else peak_change(history.q, previous.q, length)
        tries.append((history.dt, wall, change))
        if change < rtol:
            return Timing(wall, history.dt, substeps, change, history, tuple(tries))
        previous, substeps = history, 2 * substeps
    raise RuntimeError(f"the peaks still changed by {change:.3g} > {rtol:g} at dt = {history.dt:g} s")
