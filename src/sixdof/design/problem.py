"""A mount-system design as a differentiable function: the design variables of a :class:`DesignSpec` mapped to
mount stiffnesses, positions and axes, and from them (assembly, eigen-solution, statics, all in JAX) to the
value of every target and its violation.

Each target's value: ``"frequency"``, the natural frequency [Hz] of the mode with the largest kinetic-energy
share in its DOF; ``"decoupling"``, the smallest kinetic-energy share [%] of a mode's dominant coordinate over
the modes it covers (every elastic mode, or the one dominated by its DOF), in body or TRA coordinates;
``"static_deflection"``, the largest static deflection [m] of any mount under gravity; ``"tra_angle"``, the
angle [deg] between the roll mode's rotation axis and the torque-roll axis. A violation is the shortfall
relative to the target's bound (0 when met); the optimizer minimizes the sum of their squares, with each
bound tightened by :data:`MARGIN` so that a design it finds meets the targets with room to spare.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from sixdof.analysis.design import modes_jax, torque_roll_axis, tra_frame
from sixdof.analysis.statics import STANDARD_GRAVITY, replace_with_preload
from sixdof.chunks import chunk_rng
from sixdof.dofs import AXES, DOFS, MOUNT_AXES
from sixdof.errors import InputError, Plain
from sixdof.model.kinematics import mount_matrix_jax, point_map_jax, stiffness_jax
from sixdof.model.modes import inverse_cholesky

#: Relative margin inside each target's bounds that the optimizer aims for.
MARGIN = 0.01
#: Relative margin inside each stiffness ratio's bounds that the optimizer keeps to: wider than the change of
#: a ratio by the written design's rounding (2 x 5e-5 at 4 significant figures,
#: :data:`sixdof.workflows.optimize.STIFFNESS_DIGITS`), so the design as written keeps within the bounds too.
RATIO_MARGIN = 1e-3
#: The random stream of the robust objective's samples (:attr:`DesignProblem.robust_scatter`): the robustness
#: study's chunk ``i`` draws from ``[seed, i]``, so this one is out of their reach.
ROBUST_STREAM = 2**32 - 1


@dataclass(frozen=True)
class Variable:
    """One scalar design variable: what it changes (``parameter``, the mounts by index, the axis index:
    a mount axis for a stiffness, a body axis for a position or an angle's rotation axis), its bounds, its
    value in the given design, a name for tables (``"stiffness w: left, right"``), the sign it acts with on
    each of its mounts and the rule that gave them, for tables (see :func:`variables`)."""

    parameter: str
    mounts: tuple[int, ...]
    axis: int
    bounds: tuple[float, float]
    initial: float
    name: str
    signs: tuple[float, ...]
    rule: str = ""


#: The body axis across whose plane a tied group must be mirrored for an offset or a rotation to act
#: mirror-symmetrically, per offset or rotation axis (x, y, z): an offset along x keeps a pair at +-x
#: symmetric by moving the mount at -x the other way; a turn about y (in the x-z plane) or about z does so by
#: turning the mount at -x the other way, a turn about x the mount at -y.
_MIRROR_AXIS = {"position": (0, 1, 2), "angle": (1, 0, 0)}
#: Two mount coordinates [m] closer than this are the same (mirror images of each other when of opposite sign).
MIRROR_ATOL = 1e-9


def mirrored(coordinates) -> bool:
    """Whether mounts at ``coordinates`` [m] along one body axis are mirror images across that axis' plane
    through the CG: none on the plane, and each at c matched by one at -c (positions, not the axis' name,
    decide: four mounts all below the CG are not mirrored across z = 0)."""
    c = np.sort(np.asarray(coordinates, dtype=float))
    return bool(len(c) > 1 and np.all(np.abs(c) > MIRROR_ATOL) and np.allclose(c, -c[::-1], rtol=0, atol=MIRROR_ATOL))


def _signs(parameter: str, group: tuple[int, ...], axis: int, positions: np.ndarray) -> tuple[tuple[float, ...], str]:
    """The signs a tied variable acts with on the mounts of ``group`` and the rule, said for tables."""
    if parameter == "stiffness":
        return (1.0,) * len(group), "alike" if len(group) > 1 else ""
    mirror = _MIRROR_AXIS[parameter][axis]
    plane = f"{AXES[mirror]} = 0"
    coordinates = positions[list(group), mirror]
    if len(group) > 1 and mirrored(coordinates):
        return tuple(float(np.sign(c)) for c in coordinates), f"mirrored across {plane}"
    if parameter == "position":
        return (1.0,) * len(group), f"along +{AXES[axis]}"
    return (1.0,) * len(group), f"alike (not mirrored across {plane})" if len(group) > 1 else "right-handed"


def variables(spec, mount_names: tuple[str, ...], positions) -> tuple[Variable, ...]:
    """The scalar variables of ``spec.vary``: per axis, one shared by the listed mounts when ``tied``, else one
    per mount (an angle has one axis, ``about``). An offset moves each mount along +axis and a turn is
    right-handed about its axis, except on a tied group mirrored across the plane of :data:`_MIRROR_AXIS`
    (:func:`mirrored`, from ``positions`` (n_mounts, 3) [m]: for an offset along an axis, that axis'; for a
    turn about y or z, x = 0; about x, y = 0): there the mounts on the negative side move or turn the other
    way, which keeps the pair mirror-symmetric. Stiffness factors act alike on every tied mount."""
    positions = np.asarray(positions, dtype=float)
    found = []
    for entry in spec.vary:
        indices = tuple(mount_names.index(m) for m in entry.mounts)
        groups = [indices] if entry.tied else [(i,) for i in indices]
        if entry.parameter == "angle":
            axes = [(AXES.index(entry.about), f"about {entry.about}")]
        else:
            names = MOUNT_AXES if entry.parameter == "stiffness" else AXES
            axes = [(names.index(a), a) for a in entry.axes]
        initial = 1.0 if entry.parameter == "stiffness" else 0.0
        for group in groups:
            for axis, axis_name in axes:
                label = f"{entry.parameter} {axis_name}: {', '.join(mount_names[i] for i in group)}"
                signs, rule = _signs(entry.parameter, group, axis, positions)
                found.append(Variable(entry.parameter, group, axis, entry.bounds, initial, label, signs, rule))
    return tuple(found)


def initial_values(variables: tuple[Variable, ...]) -> np.ndarray:
    """The variables' starting values (n,), each in its own unit."""
    return np.array([v.initial for v in variables])


def variable_bounds(variables: tuple[Variable, ...]) -> np.ndarray:
    """The variables' lower and upper bounds (n, 2), each in its own unit."""
    return np.array([v.bounds for v in variables], dtype=float).reshape(-1, 2)


def mount_arrays(system, variables: tuple[Variable, ...], x, stiffness_scale=None):
    """Positions (n_mounts, 3) [m], stiffnesses (n_mounts, 3) [N/m] and axes (n_mounts, 3, 3) of ``system``'s
    mounts with the ``variables`` (:func:`variables`) at ``x`` (n,), JAX-traceable; ``stiffness_scale``
    (n_mounts, 3) multiplies every mount-axis stiffness. The design's and the model update's one map."""
    from sixdof._jax import jnp

    positions = jnp.asarray(system.positions, dtype=float)
    stiffness = jnp.asarray(system.stiffnesses, dtype=float)
    axes = jnp.asarray(system.axes, dtype=float)
    for k, variable in enumerate(variables):
        rows = jnp.array(variable.mounts)
        if variable.parameter == "stiffness":
            stiffness = stiffness.at[rows, variable.axis].multiply(x[k], unique_indices=True)  # mounts listed once
        elif variable.parameter == "position":
            positions = positions.at[rows, variable.axis].add(x[k] * jnp.array(variable.signs))
        else:  # the rows of each mount's axes turned about a body axis by +-x[k] degrees
            for mount, sign in zip(variable.mounts, variable.signs):
                turn = _rotation(variable.axis, jnp.deg2rad(sign * x[k]))
                axes = axes.at[mount].set(axes[mount] @ turn.T)
    if stiffness_scale is not None:
        stiffness = stiffness * stiffness_scale
    return positions, stiffness, axes


class DesignProblem:
    """The targets of ``spec`` as functions of its variables, for ``system`` under gravity ``gravity``
    [m/s^2] along ``direction`` (body axes). :meth:`values`, :meth:`violations` and :meth:`objective` take
    the variables (n,) and are JAX-traceable (jit, grad, vmap); ``stiffness_scale`` (n_mounts, 3) multiplies
    every mount-axis stiffness (the robustness study's scatter).

    Raises
    ------
    sixdof.errors.InputError
        For nonlinear mounts, or a ``spec`` without targets or variables.
    """

    def __init__(self, system, spec, gravity: float = STANDARD_GRAVITY, direction=(0.0, 0.0, -1.0)) -> None:
        if system.nonlinear_axes:
            raise InputError("mounts", "linear mounts (designing mounts with bump stops, lift-off or force-deflection "
                             "tables or hysteretic bearings is not supported yet)",
                             Plain(f"nonlinear mount axes {', '.join(system.nonlinear_axes)}"))
        self.system, self.spec = system, spec
        self.names = tuple(m.name for m in system.mounts)
        self.variables = variables(spec, self.names, system.positions)
        self.targets = spec.target
        if not self.targets or not self.variables:
            raise InputError("design", "at least one [[design.target]] and one [[design.vary]]",
                             Plain(f"{len(self.targets)} targets, {len(self.variables)} variables"))
        self.M = np.asarray(system.M, dtype=float)
        self._L_inv = inverse_cholesky(self.M)
        weight = system.body.mass * gravity * np.asarray(direction, dtype=float) / np.linalg.norm(direction)
        self._gravity = np.concatenate([weight, np.zeros(3)])  # at the CG
        self._preload = system.preload_weight  # gravity's geometric stiffness (None: left out)
        self.ratio_constraints = _ratio_constraints(spec, self.names, self.variables,
                                                    np.asarray(system.stiffnesses, dtype=float))
        self._tra_frame = None
        if spec.torque_axis is not None:
            tra = torque_roll_axis(self.M, np.asarray(spec.torque_axis) / np.linalg.norm(spec.torque_axis))
            self._tra = tra
            self._tra_frame = np.kron(np.eye(2), tra_frame(tra))

    def ratio_slack(self, x, margin: float = RATIO_MARGIN) -> np.ndarray:
        """How far each stiffness-ratio constraint of design ``x`` is inside its bound (>= 0 where kept), in
        units of the mount's compression stiffness [1]; bounds tightened by the relative ``margin``. Linear in
        ``x`` (stiffness factors scale the stiffness), shape (n_constraints,): see :func:`_ratio_constraints`."""
        rows, offsets = self.ratio_constraints(margin)
        return rows @ np.asarray(x, dtype=float) + offsets

    @property
    def initial(self) -> np.ndarray:
        return initial_values(self.variables)

    @property
    def bounds(self) -> np.ndarray:
        """(n, 2) lower and upper bounds."""
        return variable_bounds(self.variables)

    def mounts(self, x, stiffness_scale=None):
        """Positions (n_mounts, 3) [m], stiffnesses (n_mounts, 3) [N/m] and axes (n_mounts, 3, 3) of design ``x``."""
        return mount_arrays(self.system, self.variables, x, stiffness_scale)

    def system_at(self, x):
        """The :class:`~sixdof.model.system.System` with the mounts of design ``x`` (and its own preload)."""
        positions, stiffness, axes = (np.asarray(a) for a in self.mounts(np.asarray(x, dtype=float)))
        mounts = [dataclasses.replace(m, position=positions[i], stiffness=stiffness[i], axes=axes[i])
                  for i, m in enumerate(self.system.mounts)]
        return replace_with_preload(self.system, mounts=mounts)

    def values(self, x, stiffness_scale=None):
        """The value of every target at design ``x`` (see the module's list), shape (n_targets,)."""
        from sixdof._jax import jnp

        positions, stiffness, axes = self.mounts(x, stiffness_scale)
        K = stiffness_jax(positions, stiffness, axes, self._preload)  # each design with its own preload
        eigenvalues, shapes, body = modes_jax(self.M, self._L_inv, K)
        frequency = jnp.sqrt(jnp.maximum(eigenvalues, 0.0)) / (2 * jnp.pi)
        tra = None
        if self._tra_frame is not None:
            p = self._tra_frame.T @ shapes
            tra = p * ((self._tra_frame.T @ self.M @ self._tra_frame) @ p)
        elastic = eigenvalues > 1e-10 * jnp.max(eigenvalues)
        found = []
        for target in self.targets:
            if target.kind == "frequency":
                found.append(frequency[jnp.argmax(body[DOFS.index(target.dof)])])
            elif target.kind == "decoupling":
                shares = body if target.coordinates == "body" else tra
                if target.dof is not None:  # the mode dominated by dof (in body axes), its dominant share
                    found.append(100.0 * jnp.max(shares[:, jnp.argmax(body[DOFS.index(target.dof)])]))
                else:
                    found.append(100.0 * jnp.min(jnp.where(elastic, jnp.max(shares, axis=0), 1.0)))
            elif target.kind == "static_deflection":
                q = jnp.linalg.solve(mount_matrix_jax(positions, stiffness, axes), self._gravity)
                deflection = jnp.einsum("mij,j->mi", point_map_jax(positions), q)
                found.append(jnp.sqrt(jnp.max(jnp.sum(deflection**2, axis=1)) + 1e-300))
            else:  # tra_angle
                roll = jnp.argmax(tra[3])
                rotation = shapes[3:, roll]
                cosine = jnp.abs(rotation @ self._tra) / jnp.sqrt(rotation @ rotation)
                sine = jnp.sqrt(jnp.maximum(1.0 - cosine**2, 0.0) + 1e-300)
                found.append(jnp.rad2deg(jnp.arctan2(sine, cosine)))
        return jnp.stack(found) if found else jnp.zeros(0)

    def violations(self, values, margin: float = 0.0):
        """Shortfall of each target's ``values`` relative to its bound, 0 where met; bounds tightened by the
        relative ``margin``."""
        from sixdof._jax import jnp

        found = []
        for target, value in zip(self.targets, values):
            if target.kind == "frequency":
                low, high = target.f_hz
                inset = margin * (high - low)
                below, above = jnp.maximum(low + inset - value, 0.0), jnp.maximum(value - high + inset, 0.0)
                found.append(below / low + above / high)
            elif target.kind == "decoupling":
                bound = target.min_percent * (1 + margin) if target.min_percent < 100 else 100.0
                found.append(jnp.maximum(jnp.minimum(bound, 100.0) - value, 0.0) / 100.0)
            else:
                bound = target.max if target.kind == "static_deflection" else target.max_deg
                found.append(jnp.maximum(value - bound * (1 - margin), 0.0) / bound)
        return jnp.stack(found) if found else jnp.zeros(0)

    def objective(self, x):
        """What the optimizer minimizes. ``spec.objective == "nominal"``: the sum of the squared violations
        (with :data:`MARGIN`) of design ``x``, 0 when every target is met with room to spare. ``"robust"``:
        that sum averaged over the :attr:`robust_scatter` samples of ``x`` (a sample-average approximation
        of the expected squared shortfall under the stiffness tolerance, with the same samples at every
        ``x``, so that it stays smooth), 0 when every sample meets every target with room to spare."""
        from sixdof._jax import jax, jnp

        def squared(scale=None):
            return jnp.sum(self.violations(self.values(x, scale), MARGIN) ** 2)

        if self.spec.objective == "nominal":
            return squared()
        return jnp.mean(jax.vmap(squared)(jnp.asarray(self.robust_scatter)))

    @property
    def robust_scatter(self) -> np.ndarray:
        """The stiffness factors (robust_samples, n_mounts, 3) of the robust objective: independent, uniform in
        ``1 +- spec.tolerance``, drawn from :func:`sixdof.chunks.chunk_rng` ``(spec.seed, ROBUST_STREAM)`` (a
        stream of their own, apart from the robustness study's chunks)."""
        spec = self.spec
        return chunk_rng(spec.seed, ROBUST_STREAM).uniform(
            1 - spec.tolerance, 1 + spec.tolerance, (spec.robust_samples, len(self.names), 3))


def _ratio_constraints(spec, names: tuple[str, ...], variables: tuple[Variable, ...], stiffness: np.ndarray):
    """The stiffness-ratio constraints of ``spec`` (:class:`~sixdof.design.spec.StiffnessRatio`) as a function
    of the relative margin (bounds tightened by it) giving ``rows`` (n_constraints, n_variables) and
    ``offsets`` (n_constraints,), kept where ``rows @ x + offsets >= 0``. A mount-axis stiffness is ``k0`` times the one
    stiffness factor acting on it (or 1), so ``k_s / k_w >= r`` reads ``(k0_s f_s - r k0_w f_w) / k0_w >= 0``,
    linear in the factors; ``<= r`` the other way.

    Raises
    ------
    InputError
        A mount with no compression stiffness, or a constraint that no variable can change and the given
        design breaks.
    """
    factor = {}  # (mount, mount axis) -> the variable scaling it
    for k, variable in enumerate(variables):
        if variable.parameter == "stiffness":
            for mount in variable.mounts:
                factor[mount, variable.axis] = k
    terms = []  # per constraint: [(variable or None, coefficient)], its sign and bound, where it came from
    for i, entry in enumerate(spec.stiffness_ratio):
        field = f"stiffness_ratio[{i}]"
        for name in entry.mounts:
            mount = names.index(name)
            k0 = stiffness[mount]
            if not k0[2] > 0:
                raise InputError(f"{field}.mounts", "mounts with a compression stiffness k_w > 0", name)
            for shear in (0, 1):
                for sign, bound in ((1.0, entry.min), (-1.0, entry.max)):
                    if bound is not None:
                        terms.append((mount, shear, sign, bound, field, name))

    def assembled(margin: float):
        rows, offsets = np.zeros((len(terms), len(variables))), np.zeros(len(terms))
        for c, (mount, shear, sign, bound, _, _) in enumerate(terms):
            k0 = stiffness[mount]
            bound = bound * (1 + sign * margin)  # min raised, max lowered
            for axis, coefficient in ((shear, sign * k0[shear] / k0[2]), (2, -sign * bound)):
                k = factor.get((mount, axis))
                if k is None:
                    offsets[c] += coefficient
                else:
                    rows[c, k] += coefficient
        return rows, offsets

    rows, offsets = assembled(0.0)
    for c, (mount, shear, sign, bound, field, name) in enumerate(terms):
        if not rows[c].any() and offsets[c] < 0:
            ratio = stiffness[mount, shear] / stiffness[mount, 2]
            raise InputError(field, f"{'>=' if sign > 0 else '<='} {bound:g} for k_{MOUNT_AXES[shear]} / k_w of mount "
                             f"{name}, or a [[design.vary]] of its stiffness", Plain(f"{ratio:.4g}, fixed"))
    return assembled


def _rotation(axis: int, angle):
    """Rotation matrix (3, 3) by ``angle`` [rad] about body axis ``axis`` (0, 1, 2): right-handed."""
    from sixdof._jax import jnp

    c, s = jnp.cos(angle), jnp.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    turn = jnp.eye(3)
    turn = turn.at[i, i].set(c).at[j, j].set(c)
    return turn.at[i, j].set(-s).at[j, i].set(s)

