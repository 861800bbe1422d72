"""The parts of a system: the rigid body, its mounts, their Maxwell branches and Rayleigh damping.

Each is an immutable, validated model object (:class:`~sixdof.frozen.Frozen`) holding NumPy arrays in SI units;
every position is measured from the centre of gravity (CG) in body axes. :class:`~sixdof.model.system.System`
assembles them into the 6x6 matrices.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof.errors import (
    InputError,
    boolean,
    finite_array,
    label_check,
    number,
    number_check,
    optional,
    point_check,
    readonly,
    vector3,
)
from sixdof.frozen import Frozen, checked
from sixdof.results import label, quantity

# Relative tolerances for "physically possible" checks on user input.
_ORTHONORMAL_TOL = 1e-6
_TRIANGLE_TOL = 1e-9


def _inertia_tensor(value, field: str) -> np.ndarray:
    expected = "3 principal moments [Jxx, Jyy, Jzz] or a symmetric 3x3 tensor in kg m^2"
    try:
        array = np.diag(vector3(value, field, expected))
    except InputError:
        array = None  # not 3 principal moments: then a full tensor (checked outside the handler: one error)
    array = finite_array(value, field, expected, (3, 3)) if array is None else array
    scale = np.max(np.abs(array))
    if not np.allclose(array, array.T, rtol=0.0, atol=1e-12 * scale):
        raise InputError(field, "a symmetric 3x3 tensor in kg m^2", value)
    principal = np.linalg.eigvalsh(array)
    if principal[0] <= 0.0:
        raise InputError(field, "a positive definite tensor (all principal moments > 0)", value)
    # A real body's principal moments obey J1 + J2 >= J3 (equality for a flat plate).
    if principal[0] + principal[1] < principal[2] * (1.0 - _TRIANGLE_TOL):
        raise InputError(
            field,
            "principal moments that a real body can have (J1 + J2 >= J3; "
            f"here {principal[0]:.6g} + {principal[1]:.6g} < {principal[2]:.6g})",
            value,
        )
    return readonly(0.5 * (array + array.T))


def _three(expected: str, valid=lambda values: np.all(values >= 0)):
    """Check of 3 finite values that ``valid`` accepts (default: all >= 0)."""
    def check(value, field):
        values = vector3(value, field, expected)
        if not valid(values):
            raise InputError(field, expected, value)
        return values

    return check


def _orthonormal(value, field: str) -> np.ndarray:
    expected = "3 orthonormal rows (the mount's axes in body axes)"
    axes = finite_array(value, field, expected, (3, 3))
    if not np.allclose(axes @ axes.T, np.eye(3), rtol=0.0, atol=_ORTHONORMAL_TOL):
        raise InputError(field, expected + "; normalize the rows", value)
    return axes


@dataclass(frozen=True, eq=False)
class RigidBody(Frozen):
    """A rigid body described about its centre of gravity.

    Parameters
    ----------
    mass : float
        Mass [kg], > 0.
    inertia : array_like, shape (3,) or (3, 3)
        Principal moments ``[Jxx, Jyy, Jzz]`` or the full inertia tensor about the CG in body axes
        [kg m^2]. Must be symmetric, positive definite and physically possible (triangle inequality
        of the principal moments).
    dimensions : array_like, shape (3,), optional
        Size of the box drawn for the body in figures, along x, y, z [m]. Not used in the numerics.
    """

    mass: float = quantity("kg", (), decode=float, check=number_check("a positive number in kg", low=0.0, strict=True))
    inertia: np.ndarray = label(check=_inertia_tensor)
    dimensions: np.ndarray | None = quantity(
        "m", ("axis",), default=None, description="size of the box drawn for the body, centred on the CG",
        check=optional(_three("3 positive lengths [Lx, Ly, Lz] in m", lambda dims: np.all(dims > 0))))

    @property
    def inertia_box(self) -> np.ndarray:
        """Sides ``[Lx, Ly, Lz]`` [m] of the uniform box with this mass and the inertia's diagonal: what stands for
        the body's size where its ``dimensions`` are not given (``Jxx = m (Ly^2 + Lz^2) / 12``, so
        ``Lx^2 = 6 (Jyy + Jzz - Jxx) / m``; zero for a side the triangle inequality leaves none)."""
        J = np.diag(self.inertia)
        return np.sqrt(np.maximum(6.0 * (np.sum(J) - 2.0 * J) / self.mass, 0.0))


def _deflection_limits(value, field: str) -> np.ndarray:
    """A mount's deflection limit [m]: one value for its three axes, or one per axis u, v, w;
    ``inf`` means no limit."""
    expected = "a deflection limit in m > 0 (inf: none), or 3 of them for the axes u, v, w"
    values = value if isinstance(value, (list, tuple)) or np.ndim(value) == 1 else [value] * 3
    if len(values) != 3:
        raise InputError(field, expected, value)
    try:  # number() refuses strings and booleans, which np.array would turn into numbers or fail on
        limits = [number(v, field, expected, low=0.0, strict=True, allow_inf=True) for v in values]
    except InputError:
        raise InputError(field, expected, value) from None
    return readonly(limits)


def _clearances(value, field: str) -> np.ndarray:
    """A bump stop's clearance along the axes u, v, w [m], each >= 0; ``inf``: no stop on that axis."""
    expected = "3 clearances in m >= 0, one per axis u, v, w (inf: no bump stop)"
    if not isinstance(value, (list, tuple, np.ndarray)) or len(value) != 3:
        raise InputError(field, expected, value)
    try:
        return readonly([number(v, field, expected, low=0.0, allow_inf=True) for v in value])
    except InputError:
        raise InputError(field, expected, value) from None


@dataclass(frozen=True, eq=False)
class Mount(Frozen):
    """A triaxial visco-elastic mount (bearing, isolator) attached to the body.

    The mount's ``w`` axis is its normal (compression) axis, pointing from the foundation towards
    the body: the mount is compressed when its body point moves along ``-w`` relative to the ground.

    Parameters
    ----------
    name : str
        Label used in tables, files and figures.
    position : array_like, shape (3,)
        Attachment point from the CG in body axes [m].
    stiffness : array_like, shape (3,)
        Stiffness along the mount's own axes [N/m], each >= 0 and not all zero.
    damping : array_like, shape (3,), optional
        Viscous damping along the mount's own axes [N s/m], each >= 0. Default zero.
    axes : array_like, shape (3, 3), optional
        Rows are the mount's unit axes u, v, w expressed in body axes [1]; must be orthonormal. Default: body
        axes.
    loss_factor : array_like, shape (3,), optional
        Hysteretic loss factor per axis [1] (complex stiffness ``k (1 + i eta)``), used by frequency
        responses only. Default zero.
    max_deflection : float or array_like, shape (3,), optional
        Largest allowed deflection from the unloaded mount (static plus dynamic), one value for
        every axis or one per axis u, v, w [m]; ``inf`` means no limit. Default: no limit.
        A run that exceeds it warns (:mod:`sixdof.analysis.mountcheck`).
    allow_tension : bool, optional
        Whether the mount may pull on the body (normal force along its ``w`` axis below zero). Default
        True: bonded elastomer mounts, wire ropes and lateral mounts work both ways, so tension is
        reported but not warned about; False makes tension during a run a warning (the mount stays linear;
        ``tension = False`` makes it lift off instead).
    bump_clearance : array_like, shape (3,), optional
        Clearance of a bump stop along each of the mount's axes u, v, w [m], >= 0; ``inf``: no stop. Default
        none. Beyond it (total deflection, either direction) a contact spring ``bump_stiffness`` engages
        (:mod:`sixdof.model.nonlinear`).
    bump_stiffness : array_like, shape (3,), optional
        Stiffness of the bump stops [N/m], > 0 where a clearance is given. Default zero.
    tension : bool, optional
        False: the mount carries no tensile force along ``w`` from any of its parts (spring, dashpot, Maxwell
        branches) and lifts off instead (its static preload taken into account; it must be in compression at
        rest; :mod:`sixdof.model.nonlinear`). Default True.
    """

    name: str = checked(label_check)
    position: np.ndarray = quantity("m", ("axis",), check=point_check,
                                    description="mount attachment points from the CG in body axes")
    stiffness: np.ndarray = quantity("N/m", ("mount_axis",), description="stiffness along each mount's own axes",
                                     check=_three("3 values >= 0 in N/m, not all zero",
                                                  lambda k: np.all(k >= 0) and np.any(k > 0)))
    damping: np.ndarray = quantity("N s/m", ("mount_axis",), default_factory=lambda: np.zeros(3),
                                   check=_three("3 values >= 0 in N s/m"),
                                   description="viscous damping along each mount's own axes")
    axes: np.ndarray = quantity("1", ("mount_axis", "axis"), default_factory=lambda: np.eye(3), check=_orthonormal,
                                description="rows: each mount's unit axes u, v, w in body axes")
    loss_factor: np.ndarray = quantity("1", ("mount_axis",), default_factory=lambda: np.zeros(3),
                                       check=_three("3 loss factors >= 0 (dimensionless)"),
                                       description="hysteretic loss factor along each mount's own axes "
                                       "(frequency responses)")
    max_deflection: np.ndarray = quantity("m", ("mount_axis",), default_factory=lambda: np.full(3, np.inf),
                                          check=_deflection_limits,
                                          description="largest allowed deflection from the unloaded mount along "
                                          "its own axes (inf: no limit)")
    allow_tension: bool = quantity("1", (), default=True, check=boolean, encode=bool, decode=bool,
                                   description="1: the mount may pull on the body (tension along w), "
                                   "0: tension is warned about")
    bump_clearance: np.ndarray = quantity("m", ("mount_axis",), default_factory=lambda: np.full(3, np.inf),
                                          check=_clearances,
                                          description="bump stop clearance along each mount's own axes "
                                          "(inf: none)")
    bump_stiffness: np.ndarray = quantity("N/m", ("mount_axis",), default_factory=lambda: np.zeros(3),
                                          check=_three("3 bump stop stiffnesses >= 0 in N/m"),
                                          description="bump stop contact stiffness along each mount's own axes")
    tension: bool = quantity("1", (), default=True, check=boolean, encode=bool, decode=bool,
                             description="1: the mount carries tension along w; 0: it lifts off")

    def __check__(self) -> None:
        missing = np.isfinite(self.bump_clearance) & (self.bump_stiffness <= 0)
        if np.any(missing):
            raise InputError("bump_stiffness", "a stiffness > 0 in N/m on every axis with a clearance",
                             self.bump_stiffness.tolist())


def relaxation(f_hz, tau) -> np.ndarray:
    """``(i w tau) / (1 + i w tau)``, ``w = 2 pi f``: a Maxwell branch's dynamic stiffness per unit stiffness, complex,
    ``f_hz`` [Hz] and ``tau`` [s] broadcast together."""
    s_tau = 2j * np.pi * np.asarray(f_hz, dtype=float) * np.asarray(tau, dtype=float)
    return s_tau / (1 + s_tau)


@dataclass(frozen=True, eq=False)
class Maxwell(Frozen):
    """A Maxwell branch of a mount: along each of the mount's own axes, a spring in series with a dashpot.

    Along an axis with stiffness ``k`` the branch's force ``f`` follows ``f' = k d' - f / tau`` for the
    mount's deformation ``d``: its dynamic stiffness is ``k (i w tau) / (1 + i w tau)``, nothing at rest
    (statics and the undamped modes use the mount's own, long-term stiffness) and ``k`` far above
    ``1 / (2 pi tau)``. The dashpot is ``k tau``. A mount may have any number of branches.

    Parameters
    ----------
    name : str
        Label of the branch (unique).
    mount : str
        Name of the mount it belongs to (it acts along that mount's axes, at its position).
    stiffness : array_like, shape (3,)
        Branch stiffness along the mount's axes u, v, w [N/m], each >= 0 and not all zero.
    tau : float
        Relaxation time [s], > 0.
    """

    name: str = checked(label_check)
    mount: str = quantity("", (), decode=str, check=label_check, description="the mount a Maxwell branch belongs to")
    stiffness: np.ndarray = quantity("N/m", ("mount_axis",), description="Maxwell branch stiffness along the "
                                     "mount's own axes", check=_three("3 values >= 0 in N/m, not all zero",
                                                                      lambda k: np.all(k >= 0) and np.any(k > 0)))
    tau: float = quantity("s", (), decode=float, description="relaxation time of the Maxwell branch",
                          check=number_check("a relaxation time in s > 0", low=0.0, strict=True))


@dataclass(frozen=True, eq=False)
class Branches:
    """The Maxwell branches as scalar internal states, one per branch and mount axis with stiffness.

    State ``b`` is the force ``f_b`` [N] of a spring ``stiffness[b]`` in series with a dashpot
    ``stiffness[b] tau[b]`` along one mount axis: ``f_b' = stiffness_b (rows_b . z') - f_b / tau_b`` for the
    body's motion ``z`` relative to the ground; it acts on the body as the generalized force ``-rows_b f_b``.

    Attributes
    ----------
    names : tuple of str
        ``"<branch> <axis>"`` (axis u, v or w).
    rows : ndarray, shape (nb, 6)
        The mount's deformation along the axis per unit ``q`` [m/m, m/rad].
    stiffness : ndarray, shape (nb,)
        [N/m].
    tau : ndarray, shape (nb,)
        [s].
    mount, axis : ndarray of int, shape (nb,)
        The mount (index in ``System.mounts``) and its axis (0, 1, 2 for u, v, w) of each state.
    """

    names: tuple[str, ...]
    rows: np.ndarray
    stiffness: np.ndarray
    tau: np.ndarray
    mount: np.ndarray
    axis: np.ndarray

    @property
    def count(self) -> int:
        return len(self.names)

    def dynamic_stiffness(self, omega) -> np.ndarray:
        """Each state's dynamic stiffness ``k (i w tau) / (1 + i w tau)`` (nf, nb) [N/m] at ``omega`` (nf,) [rad/s]."""
        return self.stiffness[None, :] * relaxation(np.asarray(omega, dtype=float)[:, None] / (2 * np.pi), self.tau)

    def matrix(self, omega) -> np.ndarray:
        """Their generalized dynamic stiffness ``sum_b rows_b' rows_b k_b (i w tau_b) / (1 + i w tau_b)`` (nf, 6, 6)
        [N/m, N, N m/rad] at ``omega`` (nf,) [rad/s]."""
        return np.einsum("bi,fb,bj->fij", self.rows, self.dynamic_stiffness(omega), self.rows)


@dataclass(frozen=True)
class Rayleigh(Frozen):
    """Rayleigh damping ``C = alpha M + beta K``.

    Parameters
    ----------
    alpha : float
        Mass-proportional coefficient [1/s], >= 0.
    beta : float
        Stiffness-proportional coefficient [s], >= 0.
    """

    alpha: float = label(check=number_check("a finite number >= 0", low=0.0))
    beta: float = label(check=number_check("a finite number >= 0", low=0.0))

    @classmethod
    def from_ratio(cls, zeta: float, f_hz: tuple[float, float]) -> Rayleigh:
        """Rayleigh coefficients giving damping ratio ``zeta`` at the two frequencies ``f_hz`` [Hz].

        Solves ``zeta = alpha / (2 w) + beta w / 2`` at both ``w = 2 pi f``.
        """
        if not isinstance(zeta, (int, float)) or not 0 <= zeta < 1:
            raise InputError("zeta", "a damping ratio in [0, 1)", zeta)
        f = finite_array(f_hz, "f_hz", "two different positive frequencies in Hz", (2,))
        if np.any(f <= 0) or f[0] == f[1]:
            raise InputError("f_hz", "two different positive frequencies in Hz", f_hz)
        w1, w2 = 2 * np.pi * f
        return cls(alpha=float(2 * zeta * w1 * w2 / (w1 + w2)), beta=float(2 * zeta / (w1 + w2)))
