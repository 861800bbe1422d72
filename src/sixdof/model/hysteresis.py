"""Hysteretic bearings: Bouc-Wen (lead-rubber, high-damping rubber) and friction pendulums.

Along each of its hysteretic axes a mount carries, on top of its static load, the force

    r = p d + q z                                      [N]

for its deflection ``d`` [m] from the static equilibrium, with a dimensionless hysteretic variable ``z``
(``|z| <= 1``, zero at rest) that follows Wen's law with ``A = 1`` and yield displacement ``d_y``:

    d_y z' = d' - |z|^n (beta sgn(d' z) + gamma) d'

- **Bouc-Wen** (``hysteresis = {law = "bouc_wen", ...}``), with ``k`` the mount's ``stiffness`` on the axis (the
  elastic stiffness), ``Fy`` the yield force and ``a`` the post-yield ratio: ``p = a k``, ``q = (1 - a) Fy``,
  ``d_y = Fy / k``. Large ``n`` tends to the bilinear loop of stiffnesses ``k`` and ``a k``.
- **Friction pendulum** (``friction_pendulum = {radius = R, mu = ...}``), with ``N`` the mount's current
  compressive load along ``w`` (zero while it has lifted off): ``p = N / R`` (the pendulum's restoring
  stiffness), ``q = mu N`` (Coulomb friction, smoothed by ``z`` over the small ``d_y``), ``n = 1`` and
  ``beta = gamma = 1/2``. ``mu`` is constant or velocity-dependent,
  ``mu(v) = mu_fast - (mu_fast - mu_slow) exp(-rate |v|)`` (Constantinou et al. 1990) with ``v`` the sliding
  speed.

**Biaxial** (Park-Wen; a friction pendulum always, a Bouc-Wen bearing with ``biaxial = true``): ``u`` and ``v``
share one circular yield surface. With ``z = (z_u, z_v)`` and ``d' = (d_u', d_v')``,

    d_y z' = d' - |z|^(n - 2) (beta sgn(z . d') + gamma) (z . d') z

which is the uniaxial law on one axis, and isotropic: the loading criterion ``z . d' > 0`` does not depend
on the direction of the motion in the plane.

Energy: the law stores ``p d^2 / 2 + q d_y |z|^2 / 2`` and dissipates at the rate
``q |z|^n (beta sgn(z . d') + gamma) (z . d') >= 0`` (for ``beta >= |gamma|``, checked), which the direct solve
integrates for the energy balance (:func:`sixdof.analysis.contact.energy_balance`).

The linear paths (modes, FRFs, superposition, steady state, the response spectrum) see each hysteretic axis
through its stated **linearization**: ``"initial"``, the elastic stiffness ``p + q / d_y`` (``k`` for
Bouc-Wen) and no damping, or ``"effective"`` at a design displacement ``D``, the secant stiffness of the
bilinear loop and its equivalent viscous damping (EN 1998-2:2005 7.5.2.3.5 and 7.5.4, AASHTO Guide
Specifications for Seismic Isolation Design 2014, 8.2):

    K_eff = p + q / D,      xi_eff = E_D / (2 pi K_eff D^2),      E_D = 4 q (D - d_y)

(zero for ``D <= d_y``), applied as a dashpot ``c = 2 xi_eff K_eff / omega`` at the circular frequency of the mode
in which the axis stores the most strain energy.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sixdof.errors import InputError, Plain, boolean, choice_check, label_check, number, number_check, readonly
from sixdof.frozen import Frozen
from sixdof.results import label, quantity

#: A mount's own axes, in the order of its 3-vectors.
AXES = ("u", "v", "w")
#: How the linear paths see a hysteretic axis.
LINEARIZATIONS = ("initial", "effective")
#: The friction pendulum's yield displacement by default [m]: the sliding starts once the dish has deflected
#: this far (OpenSees' singleFPBearing takes it as ``mu N / k_init``; 0.5 mm is a usual choice there).
FRICTION_YIELD_DISPLACEMENT = 5e-4


def _axes(value, field: str) -> tuple[str, ...]:
    expected = 'a list of distinct mount axes among "u", "v", "w"'
    if not isinstance(value, (list, tuple)) or not value or len(set(value)) != len(value):
        raise InputError(field, expected, value)
    return tuple(choice_check(AXES)(axis, field) for axis in value)


def _positive_list(value, field: str) -> np.ndarray:
    expected = "one yield force in N > 0 per listed axis"
    values = value if isinstance(value, (list, tuple, np.ndarray)) else [value]
    try:
        return readonly([number(v, field, expected, low=0.0, strict=True) for v in values])
    except InputError:
        raise InputError(field, expected, value) from None


def _linearization_check(law) -> None:
    """A design displacement given with ``linearization = "effective"``, and only then."""
    if law.linearization == "effective" and law.design_displacement is None:
        raise InputError("design_displacement", 'a design displacement in m > 0 with linearization = "effective"',
                         Plain("nothing"))
    if law.linearization == "initial" and law.design_displacement is not None:
        raise InputError("linearization", '"effective" where a design_displacement is given (the initial '
                         "linearization uses none)", law.linearization)


_DESIGN = number_check("a design displacement in m > 0", low=0.0, strict=True)


@dataclass(frozen=True, eq=False)
class BoucWen(Frozen):
    """A Bouc-Wen hysteretic law on some of a mount's axes (see the module for the formula).

    Parameters
    ----------
    mount : str
    axes : sequence of str
        Among ``"u"``, ``"v"``, ``"w"``.
    yield_force : array_like
        ``Fy`` [N] > 0, one per listed axis.
    post_yield_ratio : float
        ``a``, in [0, 1): the post-yield stiffness over the elastic one.
    exponent : float
        ``n`` >= 1 (default 1; large: the bilinear loop).
    beta, gamma : float
        Shape of the loop (default 0.5 each); ``beta > 0`` and ``|gamma| <= beta``.
    biaxial : bool
        ``u`` and ``v`` on one circular yield surface (both listed, with the same stiffness and yield force).
    linearization : str
        ``"initial"`` (default) or ``"effective"``.
    design_displacement : float, optional
        ``D`` [m] of the effective linearization.
    """

    mount: str = label(check=label_check, decode=str)
    axes: tuple[str, ...] = label(check=_axes, decode=lambda a: tuple(str(x) for x in a))
    yield_force: np.ndarray = quantity("N", ("hysteretic_axis",), check=_positive_list,
                                       description="yield force of each hysteretic axis")
    post_yield_ratio: float = quantity("1", (), decode=float, check=lambda v, f: number(
        v, f, "a post-yield stiffness ratio in [0, 1)", low=0.0, high=1.0 - 1e-15))
    exponent: float = quantity("1", (), default=1.0, decode=float,
                               check=number_check("an exponent n >= 1", low=1.0))
    beta: float = quantity("1", (), default=0.5, decode=float, check=number_check("beta > 0", low=0.0, strict=True))
    gamma: float = quantity("1", (), default=0.5, decode=float, check=number_check("a finite gamma"))
    biaxial: bool = quantity("1", (), default=False, check=boolean, encode=bool, decode=bool)
    linearization: str = label(default="initial", check=choice_check(LINEARIZATIONS))
    design_displacement: float | None = quantity("m", (), default=None, decode=float,
                                                 check=lambda v, f: None if v is None else _DESIGN(v, f))

    def __check__(self) -> None:
        if self.yield_force.size != len(self.axes):
            raise InputError("yield_force", f"{len(self.axes)} yield forces in N, one per listed axis",
                             self.yield_force.tolist())
        if abs(self.gamma) > self.beta:
            raise InputError("gamma", f"|gamma| <= beta = {self.beta:g} (Wen's loop dissipates in every cycle only "
                             "then)", self.gamma)
        if self.biaxial and not {"u", "v"} <= set(self.axes):
            raise InputError("biaxial", 'true only with both "u" and "v" among the axes', Plain(str(list(self.axes))))
        if self.biaxial and self.yield_force[self.axes.index("u")] != self.yield_force[self.axes.index("v")]:
            raise InputError("yield_force", "the same yield force on u and v (a circular yield surface)",
                             self.yield_force.tolist())
        _linearization_check(self)


def _friction(value, field: str) -> tuple[float, float, float]:
    """``mu``: a coefficient in [0, 1), or ``{slow, fast, rate}`` (rate in s/m)."""
    expected = "a friction coefficient in (0, 1), or {slow = , fast = , rate = } (rate in s/m > 0)"
    if isinstance(value, dict):
        unknown = set(value) - {"slow", "fast", "rate"}
        if unknown or len(value) != 3:
            raise InputError(field, expected, value)
        slow, fast = (number(value[k], f"{field}.{k}", "a friction coefficient in (0, 1)", low=0.0, strict=True,
                             high=1.0) for k in ("slow", "fast"))
        rate = number(value["rate"], f"{field}.rate", "a rate in s/m > 0", low=0.0, strict=True)
        return slow, fast, rate
    if isinstance(value, (tuple, list, np.ndarray)) and len(value) == 3:  # (slow, fast, rate), as stored
        slow, fast = (number(v, field, expected, low=0.0, strict=True, high=1.0) for v in value[:2])
        return slow, fast, number(value[2], field, expected, low=0.0)
    mu = number(value, field, expected, low=0.0, strict=True, high=1.0)
    return mu, mu, 0.0


@dataclass(frozen=True, eq=False)
class FrictionPendulum(Frozen):
    """A single friction pendulum bearing on a mount's ``u`` and ``v`` axes (see the module for the formula).

    Parameters
    ----------
    mount : str
    radius : float
        Radius of the sliding surface ``R`` [m] > 0 (period ``2 pi sqrt(R / g)``).
    mu : float or dict
        Friction coefficient, or ``{slow, fast, rate}``: ``(mu_slow, mu_fast, rate)`` after the check.
    axes : sequence of str
        ``["u", "v"]`` (default): the plane of the dish.
    yield_displacement : float
        ``d_y`` [m] > 0 (default :data:`FRICTION_YIELD_DISPLACEMENT`).
    linearization, design_displacement
        As :class:`BoucWen`.
    """

    mount: str = label(check=label_check, decode=str)
    radius: float = quantity("m", (), decode=float, check=number_check("a radius in m > 0", low=0.0, strict=True))
    mu: tuple[float, float, float] = quantity("1", ("friction_term",), check=_friction,
                                              decode=lambda a: tuple(float(x) for x in a),
                                              encode=lambda mu: np.asarray(mu, dtype=float),
                                              description="friction coefficient at rest, fast, and the rate [s/m]")
    axes: tuple[str, ...] = label(default=("u", "v"), check=_axes, decode=lambda a: tuple(str(x) for x in a))
    yield_displacement: float = quantity("m", (), default=FRICTION_YIELD_DISPLACEMENT, decode=float,
                                         check=number_check("a yield displacement in m > 0", low=0.0, strict=True))
    linearization: str = label(default="initial", check=choice_check(LINEARIZATIONS))
    design_displacement: float | None = quantity("m", (), default=None, decode=float,
                                                 check=lambda v, f: None if v is None else _DESIGN(v, f))

    def __check__(self) -> None:
        if set(self.axes) != {"u", "v"}:
            raise InputError("axes", '["u", "v"]: the plane of the dish (w carries the load N)',
                             Plain(str(list(self.axes))))
        _linearization_check(self)


def check_on_mount(law: BoucWen | FrictionPendulum, mount, field: str, mount_field: str) -> None:
    """Refuse a law that cannot act on ``mount`` (a :class:`~sixdof.model.parts.Mount`): on an axis that a bump stop
    or lift-off makes nonlinear already, a Bouc-Wen axis without stiffness, a biaxial law on unequal stiffnesses, a
    friction pendulum with a stiffness of its own in the dish's plane or on a mount that carries no load along
    ``w``. The error names the law's ``field.axes`` or the mount's ``mount_field.stiffness``."""
    pendulum = isinstance(law, FrictionPendulum)
    axes_field, stiffness_field = f"{field}.axes", f"{mount_field}.stiffness"
    for axis in law.axes:
        a = AXES.index(axis)
        if np.isfinite(mount.bump_clearance[a]):
            raise InputError(axes_field, f"axes of {mount.name} without a bump stop (one law per axis)", axis)
        if axis == "w" and not mount.tension:
            raise InputError(axes_field, f"axes of {mount.name} without lift-off (tension = false; one law per axis)",
                             axis)
        if not pendulum and mount.stiffness[a] <= 0:
            raise InputError(axes_field, f"axes where {mount.name} has a stiffness > 0 (the elastic stiffness of the "
                             "Bouc-Wen law)", axis)
        if pendulum and mount.stiffness[a] != 0:
            raise InputError(stiffness_field, f"0 on the friction pendulum's axis {axis} (the pendulum's N / R is "
                             "its stiffness there)", mount.stiffness.tolist())
    if not pendulum and law.biaxial and mount.stiffness[0] != mount.stiffness[1]:
        raise InputError(stiffness_field, "the same stiffness on u and v for a biaxial Bouc-Wen law (a circular "
                         "yield surface)", mount.stiffness.tolist())
    if pendulum and mount.stiffness[2] <= 0:
        raise InputError(stiffness_field, "a stiffness > 0 along w on a friction pendulum's mount: it carries the "
                         "load N that the pendulum's restoring force and friction are proportional to",
                         mount.stiffness.tolist())


@dataclass(frozen=True, eq=False)
class HystereticAxes:
    """The hysteretic mount axes of a system, one state ``z`` each.

    Attributes
    ----------
    names : tuple of str
        ``"<mount> <axis>"``.
    mount, axis : ndarray of int, shape (nh,)
    rows : ndarray, shape (nh, 6)
        The axis's deflection per unit ``q`` [m/m, m/rad].
    pendulum : ndarray of bool, shape (nh,)
        A friction pendulum's axis (else Bouc-Wen).
    stiffness, strength : ndarray, shape (nh,)
        ``p`` [N/m] and ``q`` [N] of a Bouc-Wen axis; of a pendulum, per unit load: ``1 / R`` [1/m] and the
        friction coefficient at rest ``mu_slow``.
    mu_fast, rate : ndarray, shape (nh,)
        A pendulum's friction when fast and its rate [s/m] (``mu_slow`` and 0 for Bouc-Wen).
    yield_displacement : ndarray, shape (nh,)
        ``d_y`` [m].
    exponent, beta, gamma : ndarray, shape (nh,)
    coupled : ndarray, shape (nh, nh)
        1 between the axes sharing a yield surface (each axis with itself).
    load_row : ndarray, shape (nh, 6)
        A pendulum's ``w`` deflection per unit ``q`` (zero for Bouc-Wen).
    load_stiffness, load_damping, static_load : ndarray, shape (nh,)
        A pendulum's mount along ``w``: stiffness [N/m], dashpot [N s/m] and compressive load at rest [N].
    linearization : tuple of str
    design_displacement : ndarray, shape (nh,)
        [m] (nan for the initial linearization).
    """

    names: tuple[str, ...]
    mount: np.ndarray
    axis: np.ndarray
    rows: np.ndarray
    pendulum: np.ndarray
    stiffness: np.ndarray
    strength: np.ndarray
    mu_fast: np.ndarray
    rate: np.ndarray
    yield_displacement: np.ndarray
    exponent: np.ndarray
    beta: np.ndarray
    gamma: np.ndarray
    coupled: np.ndarray
    load_row: np.ndarray
    load_stiffness: np.ndarray
    load_damping: np.ndarray
    static_load: np.ndarray
    linearization: tuple[str, ...]
    design_displacement: np.ndarray

    @property
    def count(self) -> int:
        return len(self.names)

    def coefficients(self, load=None, speed=0.0) -> tuple[np.ndarray, np.ndarray]:
        """``p`` [N/m] and ``q`` [N] of each axis (..., nh) under the pendulums' compressive loads ``load`` (..., nh)
        [N] (default: at rest) and sliding speeds ``speed`` [m/s]."""
        load = self.static_load if load is None else np.asarray(load, dtype=float)
        mu = self.mu_fast - (self.mu_fast - self.strength) * np.exp(-self.rate * np.abs(speed))
        p = np.where(self.pendulum, load * self.stiffness, self.stiffness)
        q = np.where(self.pendulum, load * mu, self.strength)
        return p, q

    def motion(self, q, qd, state) -> dict[str, np.ndarray]:
        """The arguments of :meth:`force` and :meth:`stored` (each (n, nh)) at the body's motion ``q``, ``qd`` (n, 6)
        relative to the ground [m, rad; m/s, rad/s] and the hysteretic variables ``state`` (n, nh): deflections from
        rest, the pendulums' compressive loads (zero once lifted off) and sliding speeds."""
        q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
        rate = qd @ self.rows.T
        load = np.maximum(self.static_load - self.load_stiffness * (q @ self.load_row.T)
                          - self.load_damping * (qd @ self.load_row.T), 0.0)
        return {"d": q @ self.rows.T, "z": np.asarray(state, dtype=float), "load": load,
                "speed": np.sqrt((rate * rate) @ self.coupled.T)}

    def force(self, d, z, load=None, speed=0.0) -> np.ndarray:
        """``r = p d + q z`` (..., nh) [N] at deflections ``d`` [m] from rest and hysteretic variables ``z``."""
        p, q = self.coefficients(load, speed)
        return p * np.asarray(d, dtype=float) + q * np.asarray(z, dtype=float)

    def stored(self, d, z, load=None, speed=0.0) -> np.ndarray:
        """The energy each law holds, ``p d^2 / 2 + q d_y z^2 / 2`` (..., nh) [J]."""
        p, q = self.coefficients(load, speed)
        d, z = np.asarray(d, dtype=float), np.asarray(z, dtype=float)
        return 0.5 * p * d * d + 0.5 * q * self.yield_displacement * z * z

    @property
    def initial_stiffness(self) -> np.ndarray:
        """The elastic stiffness ``p + q / d_y`` of each axis at rest (nh,) [N/m]: the initial linearization's."""
        p, q = self.coefficients()
        return p + q / self.yield_displacement

    def effective(self, D) -> tuple[np.ndarray, np.ndarray]:
        """Secant stiffness [N/m] and equivalent viscous damping ratio [1] of each axis's bilinear loop at design
        displacements ``D`` (nh,) [m] (see the module); the elastic stiffness and no damping up to ``d_y``."""
        D = np.asarray(D, dtype=float)
        p, q = self.coefficients()
        d_y = self.yield_displacement
        beyond = D > d_y
        k_eff = np.where(beyond, p + q / np.where(beyond, D, 1.0), self.initial_stiffness)
        energy = 4.0 * q * np.maximum(D - d_y, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = np.where(beyond, energy / (2 * np.pi * k_eff * D * D), 0.0)
        return k_eff, xi

    @property
    def effective_axes(self) -> np.ndarray:
        """Whether each axis's linearization is ``"effective"`` (nh,)."""
        return np.array([lin == "effective" for lin in self.linearization], dtype=bool)

    @property
    def linear_stiffness(self) -> np.ndarray:
        """The stiffness the linear paths use on each axis (nh,) [N/m]: initial or effective."""
        return self._linearization[0]

    @property
    def linear_damping_ratio(self) -> np.ndarray:
        """The equivalent viscous damping ratio of each axis in the linear paths (nh,) [1]: zero for the initial
        linearization."""
        return self._linearization[1]

    @cached_property
    def _linearization(self) -> tuple[np.ndarray, np.ndarray]:
        """(:attr:`linear_stiffness`, :attr:`linear_damping_ratio`), from :meth:`effective` where it applies."""
        effective = self.effective_axes
        k_eff, xi = self.effective(np.where(effective, self.design_displacement, 1.0))
        return readonly(np.where(effective, k_eff, self.initial_stiffness)), readonly(np.where(effective, xi, 0.0))


def hysteretic_axes(mounts, local_map: np.ndarray, bouc_wen, pendulums, static_w_load: np.ndarray) -> HystereticAxes:
    """The :class:`HystereticAxes` of ``mounts`` (deflection per unit ``q``: ``local_map`` (n, 3, 6)) with their
    ``bouc_wen`` and ``pendulums`` laws; ``static_w_load`` (n,) [N]: each mount's compressive load along ``w`` at
    rest (what a pendulum carries)."""
    index = {m.name: j for j, m in enumerate(mounts)}
    entries = []  # (mount, axis, pendulum, p, q, mu_fast, rate, d_y, n, beta, gamma, group, linearization, D)
    group = 0
    for law in bouc_wen:
        j = index[law.mount]
        for i, name in enumerate(law.axes):
            a = AXES.index(name)
            k = float(mounts[j].stiffness[a])
            fy = float(law.yield_force[i])
            joint = law.biaxial and name in ("u", "v")
            entries.append((j, a, False, law.post_yield_ratio * k, (1 - law.post_yield_ratio) * fy, 0.0, 0.0,
                            fy / k if k > 0 else np.inf, law.exponent, law.beta, law.gamma,
                            (group, "uv") if joint else (group, name), law.linearization, law.design_displacement))
        group += 1
    for law in pendulums:
        j = index[law.mount]
        slow, fast, rate = law.mu
        for name in law.axes:
            entries.append((j, AXES.index(name), True, 1.0 / law.radius, slow, fast, rate, law.yield_displacement,
                            1.0, 0.5, 0.5, (group, "uv"), law.linearization, law.design_displacement))
        group += 1
    mount = np.array([e[0] for e in entries], dtype=np.int64)
    axis = np.array([e[1] for e in entries], dtype=np.int64)
    groups = [e[11] for e in entries]
    coupled = np.array([[float(g == h) for h in groups] for g in groups]).reshape(len(entries), len(entries))
    pendulum = np.array([e[2] for e in entries], dtype=bool)
    rows = local_map[mount, axis].reshape(-1, 6)
    load_row = np.where(pendulum[:, None], local_map[mount, 2].reshape(-1, 6), 0.0)

    def column(i: int) -> np.ndarray:
        return readonly([float(e[i]) for e in entries])

    return HystereticAxes(
        names=tuple(f"{mounts[e[0]].name} {AXES[e[1]]}" for e in entries), mount=readonly(mount, None),
        axis=readonly(axis, None), rows=readonly(rows), pendulum=readonly(pendulum, bool), stiffness=column(3),
        strength=column(4), mu_fast=readonly([e[5] if e[2] else e[4] for e in entries]), rate=column(6),
        yield_displacement=column(7), exponent=column(8), beta=column(9), gamma=column(10),
        coupled=readonly(coupled), load_row=readonly(load_row),
        load_stiffness=readonly([float(mounts[e[0]].stiffness[2]) if e[2] else 0.0 for e in entries]),
        load_damping=readonly([float(mounts[e[0]].damping[2]) if e[2] else 0.0 for e in entries]),
        static_load=readonly([float(static_w_load[e[0]]) if e[2] else 0.0 for e in entries]),
        linearization=tuple(e[12] for e in entries),
        design_displacement=readonly([np.nan if e[13] is None else float(e[13]) for e in entries]))
