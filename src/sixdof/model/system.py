"""The system: a rigid body on its mounts, and the assembly of the 6x6 mass, stiffness and damping matrices.

Coordinates ``q = [x, y, z, rx, ry, rz]`` (see :mod:`sixdof.dofs`): translations of the centre of
gravity (CG) in m and small rotations about the central body axes in rad. Every position is measured
from the CG in body axes. The parts (body, mounts, Maxwell branches, Rayleigh damping) are in
:mod:`sixdof.model.parts`.

The model objects hold validated NumPy arrays and are immutable; their 6x6 matrices are assembled in
NumPy (:func:`sixdof.model.kinematics.mount_matrix`, :func:`mass_matrix`), so that building a model
never imports JAX. The vectorized batches and gradients use the JAX twin of the same formula
(:func:`sixdof.model.kinematics.mount_matrix_jax`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sixdof.dofs import UNITS
from sixdof.errors import (
    MAX_FREQUENCY_HZ,
    InputError,
    Plain,
    finite_array,
    optional,
    readonly,
    real_array,
    short,
    tuple_check,
    tuple_of,
    vector3,
)
from sixdof.frozen import Frozen
from sixdof.model.damping import damping_matrix
from sixdof.model.hysteresis import BoucWen, FrictionPendulum, HystereticAxes, check_on_mount, hysteretic_axes
from sixdof.model.kinematics import geometric_stiffness, mount_local_map, mount_matrix
from sixdof.model.modes import Modes, modal_analysis
from sixdof.model.nonlinear import ForceDeflection, ForceLaws, force_laws
from sixdof.model.parts import Branches, Maxwell, Mount, Rayleigh, RigidBody
from sixdof.results import label, part, quantity, result_type, sequence, stacked


def mass_matrix(mass, inertia) -> np.ndarray:
    """Inertia matrix about the CG (eq. 6 of the seed paper, full tensor allowed).

    Parameters
    ----------
    mass : float
        Body mass [kg].
    inertia : array_like, shape (3, 3)
        Inertia tensor about the CG in body axes [kg m^2].

    Returns
    -------
    numpy.ndarray, shape (6, 6)
        ``blockdiag(m I3, J)`` in SI units.
    """
    M = np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[3:, 3:] = inertia
    return M


def _gravity(value, field: str) -> np.ndarray:
    expected = "a gravity vector [gx, gy, gz] in m/s^2 in body axes, not zero"
    gravity = vector3(value, field, expected)
    if not np.any(gravity):
        raise InputError(field, expected, value)
    return gravity


def _modal_ratios(value, field: str):
    if value is None:
        return None
    ratios = np.atleast_1d(real_array(value, "damping.modal", "one damping ratio in [0, 1) or 6 of them", 1))
    if ratios.shape not in ((1,), (6,)) or not np.all((ratios >= 0) & (ratios < 1)):  # NaN fails too
        raise InputError("damping.modal", "one damping ratio in [0, 1) or 6 of them", value)
    return float(ratios[0]) if ratios.shape == (1,) else tuple(float(r) for r in ratios)


def _stacked(name: str, doc: str) -> cached_property:
    """A :class:`System` property: the mounts' field ``name`` stacked along a first axis (computed once)."""
    def stack(system) -> np.ndarray:
        return np.stack([getattr(mount, name) for mount in system.mounts])

    stack.__doc__ = doc
    return cached_property(stack)


#: A given mount preload balances the weight when its residual force and moment about the CG are within this fraction
#: of the loads summed (their magnitudes; times their levers for the moment): the statics leave round-off there,
#: a preload solved for mounts elsewhere or another body percents.
PRELOAD_BALANCE_RTOL = 1e-6

#: The most mounts of a system: 1,000 took 1.1 s to read from a scenario file and over 2 min for the bundled
#: compressor's 3 s run at 2 kHz on a busy machine; each adds 176 bytes a sample to a run's results file.
MAX_MOUNTS = 1000


@result_type
@dataclass(frozen=True, eq=False)
class System(Frozen):
    """A rigid body on mounts, with optional global damping models.

    The damping matrix is the sum of the mounts' dashpots, the Rayleigh term and the modal term
    (see :func:`sixdof.model.damping.damping_matrix`).

    Parameters
    ----------
    body : RigidBody
    mounts : sequence of Mount
        At least one mount; names must be unique.
    rayleigh : Rayleigh, optional
    modal_damping : float or sequence of 6 floats, optional
        Modal damping ratio for every mode, or one per mode in ascending frequency order.
    maxwell : sequence of Maxwell, optional
        Maxwell branches of the mounts (visco-elastic mounts); names must be unique. Default none.
    force_deflection : sequence of ForceDeflection, optional
        Force-deflection tables of mount axes (nonlinear mounts, :mod:`sixdof.model.nonlinear`), at most one per
        mount axis; each replaces the linear stiffness of its axis. Default none.
    equilibrium : array_like, shape (6,), optional
        The static equilibrium ``q`` [m, rad] from the unloaded state: where the mounts' total deflection is
        static plus dynamic (the motion is measured from it) and about which nonlinear mounts are linearized
        (:func:`sixdof.analysis.statics.at_equilibrium` sets it). Default zero: unloaded.
    gravity_preload : array_like, shape (3,), optional
        Gravity [m/s^2] in body axes whose preload of the mounts adds its geometric stiffness to :attr:`K`
        (:attr:`K_geometric`, ``[statics] geometric_stiffness = true``), given with ``mount_preload``. Default
        ``None``: K is the mounts' alone.
    mount_preload : array_like, shape (n_mounts, 3), optional
        The static load on each mount under ``gravity_preload`` [N], body axes: the force of the body on it
        (:attr:`sixdof.analysis.statics.Statics.mount_forces`). The model does not solve its statics:
        :func:`sixdof.analysis.statics.with_gravity_preload` gives both fields, and
        :func:`~sixdof.analysis.statics.replace_with_preload` solves them again for a copy with other mounts
        (``dataclasses.replace`` keeps the preload it was given). Default ``None``.
    bouc_wen : sequence of BoucWen, optional
        Bouc-Wen hysteretic laws of mount axes (lead-rubber, high-damping rubber bearings;
        :mod:`sixdof.model.hysteresis`): the time paths integrate the hysteresis, the linear paths take its
        stated linearization. Default none.
    friction_pendulum : sequence of FrictionPendulum, optional
        Friction pendulum bearings on mounts' ``u`` and ``v`` axes (:mod:`sixdof.model.hysteresis`).
        Default none.
    rayleigh_excludes_hysteresis : bool, optional
        True (default): the Rayleigh term ``beta K`` leaves out the hysteretic axes' stiffness (their
        damping is the hysteresis'); False keeps it in.
    """

    body: RigidBody = part(lambda: RigidBody, prefix="body_")
    mounts: tuple[Mount, ...] = stacked(lambda: Mount, dim="mount", prefix="mount_", key="name",
                                        check=tuple_check("a sequence of Mount"))
    rayleigh: Rayleigh | None = part(lambda: Rayleigh, prefix="rayleigh_", default=None)
    modal_damping: float | tuple[float, ...] | None = label(
        default=None, check=_modal_ratios, encode=lambda ratios: np.atleast_1d(np.asarray(ratios, dtype=float)))
    maxwell: tuple[Maxwell, ...] = stacked(lambda: Maxwell, dim="branch", prefix="maxwell_", key="name", default=(),
                                           check=tuple_check("a sequence of Maxwell"))
    force_deflection: tuple[ForceDeflection, ...] = sequence(lambda: ForceDeflection, group="force_deflection",
                                                             key=lambda table: f"{table.mount}_{table.axis}",
                                                             default=())
    equilibrium: np.ndarray = quantity(UNITS["q"], ("dof",), default_factory=lambda: np.zeros(6),
                                       check=lambda value, field: readonly(finite_array(
                                           value, field, "6 finite values [m, rad]", (6,))),
                                       description="static equilibrium from the unloaded state about which "
                                       "nonlinear mounts are linearized (zero for linear mounts: their statics "
                                       "under gravity are /statics)")
    gravity_preload: np.ndarray | None = quantity(
        "m/s^2", ("axis",), default=None,
        check=optional(lambda value, field: _gravity(value, field)),
        description="gravity whose preload of the mounts adds its geometric stiffness K_geometric to K")
    mount_preload: np.ndarray | None = quantity(
        "N", ("mount", "axis"), default=None,
        check=optional(lambda value, field: finite_array(value, field, "the static load of each mount, shape "
                                                         "(n_mounts, 3) in N, body axes", (-1, 3))),
        description="static load on each mount under gravity_preload (force of the body on it), body axes: the "
        "preload whose geometric stiffness K_geometric is")
    bouc_wen: tuple[BoucWen, ...] = sequence(lambda: BoucWen, group="bouc_wen", key=lambda law: law.mount, default=())
    friction_pendulum: tuple[FrictionPendulum, ...] = sequence(lambda: FrictionPendulum, group="friction_pendulum",
                                                               key=lambda law: law.mount, default=())
    rayleigh_excludes_hysteresis: bool = quantity("1", (), default=True, encode=bool, decode=bool,
                                                  description="1: the Rayleigh term beta K leaves out the hysteretic "
                                                  "axes' stiffness")

    #: Stored beside the fields (not read back: the system recomputes them).
    derived = {
        "M": quantity(UNITS["M"], ("load", "dof")),
        "C": quantity(UNITS["C"], ("load", "dof")),
        "K": quantity(UNITS["K"], ("load", "dof"), description=lambda system: (
            "stiffness: the mounts' and gravity's geometric stiffness K_geometric" if system.geometric_stiffness
            else "stiffness of the mounts alone (gravity's geometric stiffness left out)")),
        "K_geometric": quantity(UNITS["K"], ("load", "dof"), description="gravity's geometric stiffness of the mount "
                                "preload, sum_j (F_j . r_j) I - r_j F_j' on the rotations (in K only when "
                                "geometric_stiffness)"),
        "geometric_stiffness": label(),
        "C_mounts": quantity(UNITS["C"], ("load", "dof"),
                             description="damping of the mounts' dashpots alone"),
    }

    def __check__(self) -> None:
        if not isinstance(self.body, RigidBody):
            raise InputError("body", "a RigidBody", self.body)
        mounts = self.mounts
        if not mounts:
            raise InputError("mounts", "at least one mount", self.mounts)
        if len(mounts) > MAX_MOUNTS:
            raise InputError("mounts", f"at most {MAX_MOUNTS:,} mounts", Plain(f"{len(mounts):,} mounts"))
        for i, mount in enumerate(mounts):
            if not isinstance(mount, Mount):
                raise InputError(f"mounts[{i}]", "a Mount", mount)
            coefficient = max(mount.stiffness.max(), mount.damping.max())
            with np.errstate(over="ignore"):  # moments of a mount's forces go as its coefficients x position^2
                lever = (1.0 + np.abs(mount.position).max()) ** 2
                finite = np.isfinite(coefficient * lever)
            if not finite:
                # Named: whichever of the two brings more decades to the product.
                if np.log10(lever) > np.log10(coefficient):
                    field, got = "position", mount.position
                else:
                    field = "stiffness" if mount.stiffness.max() >= mount.damping.max() else "damping"
                    got = getattr(mount, field)
                raise InputError(f"mounts[{i}].{field}", "values small enough that the mount's stiffness and damping "
                                 "matrices (coefficients x position^2) stay finite", got)
        names = [m.name for m in mounts]
        duplicated = sorted({n for n in names if names.count(n) > 1})
        if duplicated:
            raise InputError("mounts", "unique mount names", f"{', '.join(duplicated)} repeated")
        self._check_maxwell(names)
        self._check_tables(names)
        self._check_hysteresis(names)
        self._check_preload()
        self._check_modal_range()
        if self.rayleigh is not None and not isinstance(self.rayleigh, Rayleigh):
            raise InputError("damping.rayleigh", "a Rayleigh", self.rayleigh)

    def _check_maxwell(self, mounts: list[str]) -> None:
        for i, branch in enumerate(self.maxwell):
            if not isinstance(branch, Maxwell):
                raise InputError(f"maxwell[{i}]", "a Maxwell", branch)
            if branch.mount not in mounts:
                raise InputError(f"maxwell[{i}].mount", f"the name of a mount ({', '.join(mounts)})", branch.mount)
        names = [b.name for b in self.maxwell]
        duplicated = sorted({n for n in names if names.count(n) > 1})
        if duplicated:
            raise InputError("maxwell", "unique branch names", f"{', '.join(duplicated)} repeated")

    def _check_tables(self, mounts: list[str]) -> None:
        self._derive(force_deflection=tuple_of(self.force_deflection, "force_deflection",
                                               "a sequence of ForceDeflection"))
        for i, table in enumerate(self.force_deflection):
            if not isinstance(table, ForceDeflection):
                raise InputError(f"force_deflection[{i}]", "a ForceDeflection", table)
            if table.mount not in mounts:
                raise InputError(f"force_deflection[{i}].mount", f"the name of a mount ({', '.join(mounts)})",
                                 table.mount)
        names = [t.name for t in self.force_deflection]
        duplicated = sorted({n for n in names if names.count(n) > 1})
        if duplicated:
            raise InputError("force_deflection", "one table per mount axis", f"{', '.join(duplicated)} repeated")

    def _check_hysteresis(self, mounts: list[str]) -> None:
        """Each hysteretic law on a mount of the system, able to act there
        (:func:`~sixdof.model.hysteresis.check_on_mount`), on axes no table or other law takes."""
        self._derive(bouc_wen=tuple_of(self.bouc_wen, "bouc_wen", "a sequence of BoucWen"),
                     friction_pendulum=tuple_of(self.friction_pendulum, "friction_pendulum",
                                                "a sequence of FrictionPendulum"))
        taken = {(t.mount, t.axis) for t in self.force_deflection}
        for key, kind in (("bouc_wen", BoucWen), ("friction_pendulum", FrictionPendulum)):
            for i, law in enumerate(getattr(self, key)):
                field = f"{key}[{i}]"
                if not isinstance(law, kind):
                    raise InputError(field, f"a {kind.__name__}", law)
                if law.mount not in mounts:
                    raise InputError(f"{field}.mount", f"the name of a mount ({', '.join(mounts)})", law.mount)
                j = mounts.index(law.mount)
                check_on_mount(law, self.mounts[j], field, f"mounts[{j}]")
                for axis in law.axes:
                    if (law.mount, axis) in taken:
                        raise InputError(f"{field}.axes", f"axes of {law.mount} that no force_deflection table or "
                                         "other hysteretic law takes (one law per axis)", axis)
                    taken.add((law.mount, axis))

    def _check_preload(self) -> None:
        """``mount_preload`` is given with ``gravity_preload``, one load per mount, and balances the weight and its
        zero moment about the CG: a copy with moved mounts or another body, whose preload was not solved again,
        is refused (a check, not the statics: :func:`sixdof.analysis.statics.with_gravity_preload` solves them)."""
        if (self.gravity_preload is None) != (self.mount_preload is None):
            given, missing = (("gravity_preload", "mount_preload") if self.mount_preload is None
                              else ("mount_preload", "gravity_preload"))
            raise InputError(missing, f"a value with {given} (sixdof.analysis.statics.with_gravity_preload gives "
                             "both)", None)
        if self.mount_preload is None:
            return
        forces = self.mount_preload
        if forces.shape != (len(self.mounts), 3):
            raise InputError("mount_preload", f"the static load of each of the {len(self.mounts)} mounts, shape "
                             f"({len(self.mounts)}, 3) in N", Plain(f"an array of shape {forces.shape}"))
        weight = self.body.mass * self.gravity_preload
        force_off = np.linalg.norm(forces.sum(axis=0) - weight)
        moment_off = np.linalg.norm(np.cross(self.positions, forces).sum(axis=0))
        force_scale = np.linalg.norm(weight) + np.linalg.norm(forces, axis=1).sum()
        moment_scale = (np.linalg.norm(self.positions, axis=1) * np.linalg.norm(forces, axis=1)).sum()
        if force_off > PRELOAD_BALANCE_RTOL * force_scale or moment_off > PRELOAD_BALANCE_RTOL * moment_scale:
            raise InputError("mount_preload", "the static loads of these mounts under gravity_preload, which balance "
                             "the weight and its moment about the CG (sixdof.analysis.statics.replace_with_preload "
                             "solves them for a copy with other mounts)",
                             Plain(f"loads off balance by {force_off:.4g} N and {moment_off:.4g} N m"))

    def _check_modal_range(self) -> None:
        """The modal analysis normalizes the shapes by the mass (``phi' M phi = 1``, effective masses go as
        its square) and its frequencies go as stiffness over mass: the body's mass and moments of inertia
        must keep both within floating point (a mass of 5e-324 kg or 1.8e308 kg does not)."""
        inertias = np.concatenate([[self.body.mass], np.linalg.eigvalsh(self.body.inertia)])
        with np.errstate(over="ignore", divide="ignore"):
            too_light = not np.isfinite(np.abs(self.K_mounts).max() / inertias.min())
            too_heavy = not np.isfinite(inertias.max() ** 2)
        if too_light or too_heavy:
            k = int(np.argmin(inertias) if too_light else np.argmax(inertias))
            raise InputError("body.mass" if k == 0 else "body.inertia",
                             "a mass in kg and moments of inertia in kg m^2 whose squares, and the mounts' stiffness "
                             "over them, stay within floating point (for the modal analysis)",
                             Plain(f"{'mass' if k == 0 else 'a principal moment'} {inertias[k]:.3g}"))
        # Beyond it, the eigen-solution loses the softer modes to round-off and a solve cannot step through a
        # period (a stiffness of 1e300 N/m, a mass of 1e-300 kg: 4 zero modes, then the step limit after 20 s).
        ceiling = (2 * np.pi * MAX_FREQUENCY_HZ) ** 2
        stiffest = np.abs(self.K).max()
        if stiffest / inertias.min() > ceiling:
            k = int(np.argmin(inertias))
            # Named: the stiffness if it is further above 1e6 N/m than the mass or inertia below 1 kg (m^2).
            if np.log10(stiffest) - 6 > -np.log10(inertias[k]):
                i = int(np.argmax([max(m.stiffness.max(), m.damping.max()) for m in self.mounts]))
                field, got = f"mounts[{i}].stiffness", Plain(str(self.mounts[i].stiffness.tolist()))
            else:
                field = "body.mass" if k == 0 else "body.inertia"
                got = Plain(f"{'mass' if k == 0 else 'a principal moment'} {inertias[k]:.3g}")
            raise InputError(field, f"a body and mounts whose natural frequencies stay below "
                             f"{short(MAX_FREQUENCY_HZ)} Hz (stiffness over mass or inertia up to {ceiling:.3g} s^-2)",
                             Plain(f"{got}: {stiffest:.3g} over {inertias[k]:.3g}"))

    # Arrays of mount parameters, stacked for the pure assembly functions.
    @cached_property
    def mount_names(self) -> tuple[str, ...]:
        return tuple(m.name for m in self.mounts)

    positions = _stacked("position", "Mount positions, shape (n, 3) [m].")
    given_stiffnesses = _stacked("stiffness", "The mounts' own stiffnesses along their axes, shape (n, 3) [N/m].")

    @cached_property
    def stiffnesses(self) -> np.ndarray:
        """Mount stiffnesses along their own axes, shape (n, 3) [N/m]: each mount's ``stiffness``, with a nonlinear
        axis's slope at the static equilibrium (the linearization every linear path uses)."""
        laws, hysteretic = self.nonlinear, self.hysteretic
        if not laws.count and not hysteretic.count:
            return self.given_stiffnesses
        stiffness = np.array(self.given_stiffnesses)
        stiffness[laws.mount, laws.axis] = laws.tangent
        stiffness[hysteretic.mount, hysteretic.axis] = hysteretic.linear_stiffness
        return readonly(stiffness)

    @cached_property
    def hysteretic(self) -> HystereticAxes:
        """The hysteretic mount axes (Bouc-Wen, friction pendulums; :class:`~sixdof.model.hysteresis.HystereticAxes`,
        none without them). A pendulum carries its mount's compressive load along ``w`` at :attr:`equilibrium`."""
        local = mount_local_map(self.positions, self.axes)
        deflection = local[:, 2] @ np.asarray(self.equilibrium, dtype=float)  # (n,) along w
        load = -self.given_stiffnesses[:, 2] * deflection
        laws = self.nonlinear
        on_w = laws.axis == 2
        load[laws.mount[on_w]] = -laws.static_force[on_w]
        return hysteretic_axes(self.mounts, local, self.bouc_wen, self.friction_pendulum, load)

    @property
    def nonlinear_axes(self) -> tuple[str, ...]:
        """The mount axes only the direct solve answers exactly: nonlinear laws (:attr:`nonlinear`) and hysteretic
        bearings (:attr:`hysteretic`), ``"<mount> <axis>"``."""
        return self.nonlinear.names + self.hysteretic.names

    @cached_property
    def K_hysteretic(self) -> np.ndarray:
        """The part of :attr:`K` the hysteretic axes' linearization makes (6, 6) [N/m, N, N m/rad]: what the direct
        solve replaces by their laws."""
        h = self.hysteretic
        return readonly(h.rows.T @ (h.linear_stiffness[:, None] * h.rows))

    @cached_property
    def K_direct(self) -> np.ndarray:
        """The stiffness (6, 6) of the direct solve's linear part [N/m, N, N m/rad]: :attr:`K` less the hysteretic
        axes' linearization (:attr:`K_hysteretic`), whose laws the solve adds; :attr:`K` without them."""
        return readonly(self.K - self.K_hysteretic) if self.hysteretic.count else self.K

    @cached_property
    def C_direct(self) -> np.ndarray:
        """The damping (6, 6) of the direct solve's linear part [N s/m, N s, N m s/rad]: :attr:`C` less the
        hysteretic axes' equivalent dashpots (:attr:`C_equivalent`); :attr:`C` without them."""
        return readonly(self.C - self.C_equivalent) if self.hysteretic.count else self.C

    @cached_property
    def equivalent_dampings(self) -> np.ndarray:
        """The equivalent viscous dashpots of the hysteretic axes' effective linearization (n, 3) [N s/m]: ``2 xi_eff
        K_eff / omega``, ``omega`` the circular frequency of the undamped mode whose strain energy the axis holds the
        largest share of (zero for the initial linearization)."""
        h = self.hysteretic
        c = np.zeros((len(self.mounts), 3))
        xi = h.linear_damping_ratio
        if not np.any(xi > 0):
            return readonly(c)
        modes = self.modes
        k = h.linear_stiffness
        omega = np.asarray(modes.omega, dtype=float)
        elastic = omega > 0  # rigid-body modes (a mechanism) store nothing
        strain = k[:, None] * (h.rows @ np.asarray(modes.shapes)) ** 2 / np.where(elastic, omega, 1.0) ** 2
        w = omega[np.argmax(np.where(elastic, strain, -1.0), axis=1)]
        c[h.mount, h.axis] = np.where(xi > 0, 2.0 * xi * k / np.maximum(w, 1e-300), 0.0)
        return readonly(c)

    @cached_property
    def nonlinear(self) -> ForceLaws:
        """The nonlinear mount axes (bump stops, lift-off, tables) as force laws (:class:`ForceLaws`; none when
        every mount is linear)."""
        return force_laws(self.mounts, mount_local_map(self.positions, self.axes), self.force_deflection,
                          self.equilibrium)
    given_dampings = _stacked("damping", "The mounts' own dashpots along their axes, shape (n, 3) [N s/m].")

    @cached_property
    def dampings(self) -> np.ndarray:
        """Mount viscous damping along their own axes, shape (n, 3) [N s/m]: each mount's ``damping``, with the
        equivalent dashpot of an effectively linearized hysteretic axis (what every linear path uses)."""
        if not self.hysteretic.count:
            return self.given_dampings
        return readonly(self.given_dampings + self.equivalent_dampings)

    @cached_property
    def C_equivalent(self) -> np.ndarray:
        """The equivalent dashpots' part of :attr:`C` (6, 6): what the direct solve leaves out (the laws dissipate)."""
        return readonly(mount_matrix(self.positions, self.equivalent_dampings, self.axes))
    loss_factors = _stacked("loss_factor", "Mount hysteretic loss factors, shape (n, 3).")
    axes = _stacked("axes", "Mount axes (rows, in body axes), shape (n, 3, 3).")

    @cached_property
    def branches(self) -> Branches:
        """The Maxwell branches as scalar internal states (:class:`Branches`; none without branches)."""
        index = {name: j for j, name in enumerate(self.mount_names)}
        local = mount_local_map(self.positions, self.axes)  # (n, 3, 6)
        states = [(f"{b.name} {'uvw'[a]}", index[b.mount], a, float(b.stiffness[a]), b.tau)
                  for b in self.maxwell for a in range(3) if b.stiffness[a] > 0]
        mount = np.array([s[1] for s in states], dtype=np.int64)
        axis = np.array([s[2] for s in states], dtype=np.int64)
        return Branches(names=tuple(s[0] for s in states), rows=readonly(local[mount, axis].reshape(-1, 6)),
                        stiffness=readonly([s[3] for s in states]), tau=readonly([s[4] for s in states]),
                        mount=readonly(mount, None), axis=readonly(axis, None))

    def linearized(self) -> System:
        """This system with every mount linear at its slope at the static equilibrium (no bump stop, lift-off or
        table) and every hysteretic axis at its linearization (stiffness and equivalent dashpot): what the modes and
        FRFs describe, for the analyses that need a linear model of it. (Rayleigh damping then acts on the whole
        linearized K.)"""
        if not self.nonlinear.count and not self.hysteretic.count:
            return self
        mounts = [dataclasses.replace(m, stiffness=k, damping=c, bump_clearance=np.full(3, np.inf),
                                      bump_stiffness=np.zeros(3), tension=True)
                  for m, k, c in zip(self.mounts, self.stiffnesses, self.dampings)]
        # The copy keeps the preload it is given: the nonlinear mounts' at their equilibrium, not the linear statics'
        # of their slopes.
        return dataclasses.replace(self, mounts=mounts, force_deflection=(), equilibrium=np.zeros(6), bouc_wen=(),
                                   friction_pendulum=())

    @cached_property
    def M(self) -> np.ndarray:
        """Mass matrix (6, 6) [kg, kg m^2]."""
        return readonly(mass_matrix(self.body.mass, self.body.inertia))

    @cached_property
    def K_mounts(self) -> np.ndarray:
        """The mounts' stiffness matrix (6, 6) [N/m, N, N m/rad]: what the statics solve with."""
        return readonly(mount_matrix(self.positions, self.stiffnesses, self.axes))

    @property
    def geometric_stiffness(self) -> bool:
        """Whether :attr:`K` holds gravity's geometric stiffness (:attr:`gravity_preload` and :attr:`mount_preload`
        given)."""
        return self.mount_preload is not None

    @property
    def preload_weight(self) -> np.ndarray | None:
        """The weight ``m g`` (3,) [N] in body axes whose mount preload's geometric stiffness :attr:`K` holds; None
        without :attr:`gravity_preload` (what :func:`sixdof.model.kinematics.stiffness_jax` takes)."""
        gravity = self.gravity_preload
        return None if gravity is None else self.body.mass * np.asarray(gravity, dtype=float)

    @cached_property
    def K_geometric(self) -> np.ndarray:
        """Gravity's geometric stiffness (6, 6) [N m/rad] of the mounts' static preload :attr:`mount_preload`
        (:func:`sixdof.model.kinematics.geometric_stiffness` of the forces of the mounts on the body); zero
        without it."""
        if self.mount_preload is None:
            return readonly(np.zeros((6, 6)))
        return readonly(geometric_stiffness(self.positions, -self.mount_preload))

    @cached_property
    def K(self) -> np.ndarray:
        """Stiffness matrix (6, 6) [N/m, N, N m/rad]: :attr:`K_mounts`, plus :attr:`K_geometric` when
        :attr:`geometric_stiffness`."""
        return readonly(self.K_mounts + self.K_geometric) if self.geometric_stiffness else self.K_mounts

    @cached_property
    def C_mounts(self) -> np.ndarray:
        """Damping matrix of the mounts' dashpots alone (6, 6) [N s/m, N s, N m s/rad]."""
        return readonly(mount_matrix(self.positions, self.dampings, self.axes))

    @cached_property
    def C(self) -> np.ndarray:
        """Total viscous damping matrix (6, 6): dashpots + Rayleigh + modal
        (:func:`sixdof.model.damping.damping_matrix`) [N s/m, N s, N m s/rad]."""
        alpha, beta = (self.rayleigh.alpha, self.rayleigh.beta) if self.rayleigh is not None else (0.0, 0.0)
        zeta = np.broadcast_to(np.asarray(self.modal_damping or 0.0, dtype=float), (6,))
        modes = self.modes
        K = self.K - self.K_hysteretic if self.rayleigh_excludes_hysteresis and self.hysteretic.count else self.K
        return readonly(damping_matrix(self.M, K, self.C_mounts, alpha, beta, zeta, modes.shapes, modes.omega))

    @cached_property
    def modes(self) -> Modes:
        """The undamped modes of (M, K), computed once (:func:`sixdof.model.modes.modal_analysis`): what the modal
        damping of :attr:`C` and the mode releases are of."""
        return modal_analysis(self.M, self.K)
