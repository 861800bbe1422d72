"""Model updating: the mounts, body and centre of gravity of a model adjusted within bounds until its modes meet a
test's, with how well the test determines each change.

The variables are the design layer's (:func:`sixdof.design.problem.variables` of the ``[[update.vary]]`` entries,
mapped to the mounts by :func:`sixdof.design.problem.mount_arrays`), then the body's from the
:class:`~sixdof.design.spec.UpdateSpec`:

- ``mass``: a factor on the mass;
- ``inertia``: three factors on the body's second moments of mass ``S = tr(J) / 2 I - J`` along its given
  principal axes (``S = R diag(s) R^T``); the tensor is ``J = tr(S) I - S``, so its principal moments are
  ``s2 + s3``, ``s1 + s3``, ``s1 + s2``: for positive factors it is positive definite and keeps the triangle
  inequality (``J1 <= J2 + J3``) whatever the factors, without a constraint; the principal axes stay the given
  ones (a modal test rarely tells them);
- ``cg_offset``: where the centre of gravity lies from the given one [m, body axes]: every mount position and
  every measured channel's point moves by ``-cg_offset`` relative to it.

**The objective** (``objective = "modal"``) is the test modes' eigen-equation residual, with no pairing of
model and test modes: each test shape is projected onto the six body DOFs by least squares through the channel
map (``phi_j = rows^+ psi_j``, moved to the model's CG), and the model must satisfy
``(K - w_j^2 M) phi_j = 0`` at each test frequency ``w_j``. In the mass-weighted form, with ``M = L L^T``,
``A = L^-1 K L^-T`` and ``u_j = L^T phi_j``, the residual of mode ``j`` is ``(A u_j - w_j^2 u_j) / (w_j^2 |u_j|)``
(dimensionless: a relative eigenvalue error along the test shape), and the objective the sum of their squares
over the test modes. Why this, and not the weighted frequency errors and ``1 - MAC`` of paired modes: it
involves neither an eigen-solution nor a pairing, so (1) it does not jump when two model modes within 2 % swap
order during the search, (2) its exact gradient (JAX) needs no eigenvector derivatives, which grow as
``1 / (l_i - l_j)`` at a near-repeated pair, and (3) it is zero at the truth for exact test data, so the
minimum is the true model. Its price: it needs the test to tell all six body DOFs (the channel map of rank 6,
which the rigid-body projection needs anyway), and shape noise enters it (a bias of second order in the noise).
It is minimized in the variables scaled to [0, 1] within their bounds by the design optimizer's bounded
quasi-Newton search (:func:`sixdof.design.optimize.bounded_minimize`) from ``spec.starts`` points
(:func:`sixdof.design.optimize.start_points`: the given model first), the best kept.

**The polish.** The eigen-residual weighs its six components alike, not by the test's noise, so with noisy data
its minimum scatters more than the test allows (measured: up to 5 of the standard errors below on the bundled
compressor at 0.1 % / 1 % noise). From its best point, the same search minimizes the sum of squares of the
noise-scaled observation residuals below (the output-error, maximum-likelihood estimate for Gaussian noise), with
the pairing fixed by MAC at its start and renewed between rounds (:data:`MAX_PAIRING_ROUNDS`) until it holds: the
pairing cannot jump within a round, and the search has already put the model near the test, where pairs by MAC
are right even for modes within 2 %.

**How well the test determines each variable** is judged apart from the objective, on what a test measures:
at the optimum the model modes are paired with the test modes once by MAC on the measured channels (a
one-to-one assignment), and the residuals are each paired mode's frequency error over the frequency noise and
its shape on the channels (scaled to the test shape by least squares) minus the test shape, over the shape
noise (:class:`TestNoise`). With ``J`` their exact Jacobian (JAX) with respect to the variables, the covariance
is ``(J^T J)^-1`` (the Gauss-Newton approximation at the test's noise), giving each variable's standard error and
the correlation matrix. A direction the residuals do not see (an exactly singular ``J^T J``) gives its variables
an infinite standard error. A variable is **not determined by the test** when its standard error exceeds
:data:`DETERMINED_RTOL` (10 %) of its scale (its value for a factor, the width of its bounds for an offset or an
angle, whose value may be 0) or it correlates above :data:`CORRELATION_LIMIT` (0.95) with another.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sixdof.analysis.statics import replace_with_preload
from sixdof.design.optimize import bounded_minimize, start_points
from sixdof.design.problem import Variable, initial_values, mount_arrays, variable_bounds, variables
from sixdof.design.record import VARIABLE_UNITS
from sixdof.design.scenario_text import scenario_text
from sixdof.dofs import AXES, MixedUnits
from sixdof.errors import InputError, Plain, readonly
from sixdof.frozen import Frozen
from sixdof.model.kinematics import stiffness_jax
from sixdof.results import Result, label, quantity, result_type
from sixdof.validation.correlation import mac, pair_modes

#: A variable whose standard error exceeds this share of its scale is not determined by the test.
DETERMINED_RTOL = 0.10
#: A variable correlating above this with another is not determined by the test.
CORRELATION_LIMIT = 0.95
#: An eigenvalue of the (unit-diagonal) information matrix ``J^T J`` below this fraction of the largest is a
#: direction the test does not see at all: its variables get an infinite standard error.
SINGULAR_RTOL = 1e-12
#: The most rounds of the output-error polish, each with the pairing of the round before (renewed between rounds).
MAX_PAIRING_ROUNDS = 3
#: The units and names of the body's variables.
BODY_UNITS = {"mass": "1", "inertia": "1", "cg_offset": "m"}
#: Variables whose scale (for the 10 % rule) is their value; the others' is the width of their bounds.
FACTORS = ("stiffness", "mass", "inertia")


@dataclass(frozen=True, eq=False)
class TestModes:
    """The test side of an update: identified modes on the measured channels.

    Parameters
    ----------
    frequency_hz : array_like, shape (m,)
        Natural frequencies [Hz], > 0.
    shapes : array_like, shape (n_out, m)
        Mode shapes on the measured channels (complex or real, any scale per mode).
    rows : array_like, shape (n_out, 6)
        The channel map: row ``i`` takes the six body DOFs at the given CG (x, y, z [m], rx, ry, rz [rad]) to
        channel ``i`` (for a translation channel along unit ``e`` at point ``r``: ``[e, r x e]``). Rank 6.
    damping_ratio : array_like, shape (m,), optional
        Damping ratios [1] (kept for reports; updating uses frequencies and shapes).
    """

    __test__ = False  # not a pytest test class

    frequency_hz: Any
    shapes: Any
    rows: Any
    damping_ratio: Any = None

    def __post_init__(self) -> None:
        f = np.asarray(self.frequency_hz, dtype=float)
        if f.ndim != 1 or not len(f) or not np.all(np.isfinite(f) & (f > 0)):
            raise InputError("frequency_hz", "positive finite frequencies [Hz], shape (m,)", self.frequency_hz)
        shapes = np.asarray(self.shapes)
        if not np.iscomplexobj(shapes):
            shapes = shapes.astype(float)
        if shapes.ndim != 2 or shapes.shape[1] != len(f) or not np.all(np.isfinite(shapes)):
            raise InputError("shapes", f"finite shapes of shape (n_out, {len(f)})", Plain(f"shape {shapes.shape}"))
        norms = np.linalg.norm(shapes, axis=0)
        if np.any(norms == 0):
            raise InputError("shapes", "no zero shape", Plain(f"mode {int(np.argmin(norms)) + 1} zero"))
        rows = np.asarray(self.rows, dtype=float)
        if rows.shape != (shapes.shape[0], 6) or not np.all(np.isfinite(rows)):
            raise InputError("rows", f"a finite channel map of shape ({shapes.shape[0]}, 6)",
                             Plain(f"shape {rows.shape}"))
        rank = np.linalg.matrix_rank(rows)
        if rank < 6:
            raise InputError("rows", "a channel map of rank 6 (the channels tell all six body DOFs: at least three "
                             "non-collinear points)", Plain(f"rank {rank}"))
        damping = None if self.damping_ratio is None else np.asarray(self.damping_ratio, dtype=float)
        if damping is not None and damping.shape != f.shape:
            raise InputError("damping_ratio", f"shape ({len(f)},)", Plain(f"shape {damping.shape}"))
        for name, value in (("frequency_hz", f), ("shapes", shapes), ("rows", rows), ("damping_ratio", damping)):
            object.__setattr__(self, name, None if value is None else readonly(value, value.dtype))

    @property
    def real_shapes(self) -> np.ndarray:
        """The shapes made real (n_out, m): each turned by the phase of its largest channel, then its real part."""
        shapes = self.shapes
        if not np.iscomplexobj(shapes):
            return shapes
        largest = shapes[np.argmax(np.abs(shapes), axis=0), np.arange(shapes.shape[1])]
        return readonly(np.real(shapes * np.conj(largest / np.abs(largest))))


@dataclass(frozen=True)
class TestNoise:
    """The noise of a test's modes, for the standard errors of an update.

    Parameters
    ----------
    frequency : float
        Standard deviation of each identified frequency relative to itself [1].
    shape : float
        Standard deviation of each channel's shape value relative to the shape's RMS over the channels [1].
    """

    __test__ = False  # not a pytest test class

    frequency: float = 1e-3
    shape: float = 0.02

    def __post_init__(self) -> None:
        for name in ("frequency", "shape"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise InputError(name, "a relative standard deviation > 0", value)


# ----------------------------------------------------------------------------------------------------
# The model as a function of the variables.
# ----------------------------------------------------------------------------------------------------


class UpdateModel:
    """``system``'s mounts and body as functions of the variables of ``spec``
    (:class:`~sixdof.design.spec.UpdateSpec`): the mount variables of the design layer, then ``mass``,
    ``inertia`` (3) and ``cg_offset`` (3), see the module's description. :meth:`matrices` is JAX-traceable.

    Raises
    ------
    sixdof.errors.InputError
        For nonlinear mounts.
    """

    def __init__(self, system, spec) -> None:
        if system.nonlinear_axes:
            raise InputError("mounts", "linear mounts (updating mounts with bump stops, lift-off or force-deflection "
                             "tables or hysteretic bearings is not supported yet)",
                             Plain(f"nonlinear mount axes {', '.join(system.nonlinear_axes)}"))
        self.system, self.spec = system, spec
        self.names = tuple(m.name for m in system.mounts)
        self.mount_variables = variables(spec, self.names, system.positions)
        body = []
        if spec.mass is not None:
            body.append(Variable("mass", (), 0, spec.mass, 1.0, "mass (factor)", ()))
        if spec.inertia is not None:
            body += [Variable("inertia", (), i, spec.inertia, 1.0,
                              f"inertia: second moment along principal axis {i + 1} (factor)", ()) for i in range(3)]
        if spec.cg_offset is not None:
            body += [Variable("cg_offset", (), i, spec.cg_offset[i], 0.0, f"cg_offset {axis}", ())
                     for i, axis in enumerate(AXES)]
        self.variables = self.mount_variables + tuple(body)
        inertia = np.asarray(system.body.inertia, dtype=float)
        self._moments, self._axes = np.linalg.eigh(np.trace(inertia) / 2 * np.eye(3) - inertia)
        self._moments = np.maximum(self._moments, 0.0)  # round-off of a planar body's zero second moment
        gravity = system.gravity_preload
        self._gravity = None if gravity is None else np.asarray(gravity, dtype=float)

    @property
    def initial(self) -> np.ndarray:
        return initial_values(self.variables)

    @property
    def bounds(self) -> np.ndarray:
        """(n, 2) lower and upper bounds."""
        return variable_bounds(self.variables)

    @property
    def units(self) -> tuple[str, ...]:
        return tuple(VARIABLE_UNITS.get(v.parameter) or BODY_UNITS[v.parameter] for v in self.variables)

    def arrays(self, x):
        """Mount positions from the model's CG (n_mounts, 3) [m], stiffnesses (n_mounts, 3) [N/m], axes
        (n_mounts, 3, 3), mass [kg], inertia tensor (3, 3) [kg m^2] and CG offset (3,) [m] at ``x``."""
        from sixdof._jax import jnp

        n = len(self.mount_variables)
        positions, stiffness, axes = mount_arrays(self.system, self.mount_variables, x[:n])
        mass, moments, offset = self.system.body.mass, jnp.asarray(self._moments), jnp.zeros(3)
        k = n
        if self.spec.mass is not None:
            mass, k = mass * x[k], k + 1
        if self.spec.inertia is not None:
            moments, k = moments * x[k:k + 3], k + 3
        if self.spec.cg_offset is not None:
            offset = x[k:k + 3]
        if self.spec.inertia is None:  # the given tensor as it is, not rebuilt from its moments (round-off)
            inertia = jnp.asarray(self.system.body.inertia, dtype=float)
        else:
            R = jnp.asarray(self._axes)
            inertia = R @ jnp.diag(jnp.sum(moments) - moments) @ R.T
            inertia = (inertia + inertia.T) / 2
        return positions - offset, stiffness, axes, mass, inertia, offset

    def matrices(self, x):
        """Stiffness (6, 6), mass matrix (6, 6) about the model's CG and CG offset (3,) [m] at ``x``."""
        from sixdof._jax import jnp

        positions, stiffness, axes, mass, inertia, offset = self.arrays(x)
        weight = None if self._gravity is None else mass * jnp.asarray(self._gravity)
        K = stiffness_jax(positions, stiffness, axes, weight)
        M = jnp.zeros((6, 6)).at[:3, :3].set(mass * jnp.eye(3)).at[3:, 3:].set(inertia)
        return K, M, offset

    def system_at(self, x):
        """The :class:`~sixdof.model.system.System` at ``x`` (mount positions from its own CG), and the CG offset
        (3,) [m]."""
        positions, stiffness, axes, mass, inertia, offset = (np.asarray(a, dtype=float)
                                                              for a in self.arrays(np.asarray(x, dtype=float)))
        mounts = [dataclasses.replace(m, position=positions[i], stiffness=stiffness[i], axes=axes[i])
                  for i, m in enumerate(self.system.mounts)]
        body = dataclasses.replace(self.system.body, mass=float(mass), inertia=inertia)
        return replace_with_preload(self.system, body=body, mounts=mounts), offset


def _cross(d):
    """``S(d)`` (3, 3) with ``S(d) v = d x v``."""
    from sixdof._jax import jnp

    return jnp.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])


def moved_rows(rows, offset):
    """The channel map ``rows`` (n_out, 6) of DOFs at the given CG made one of DOFs at a CG moved by ``offset``
    (3,) [m]: a point's motion ``t + theta x r`` from the old CG is ``t' + theta x (r - offset)`` from the new, so
    ``rows' = rows [[I, S(offset)], [0, I]]`` (``S(d) v = d x v``)."""
    from sixdof._jax import jnp

    rows = jnp.asarray(rows)
    return jnp.hstack([rows[:, :3], rows[:, :3] @ _cross(offset) + rows[:, 3:]])


def eigen_residuals(model: UpdateModel, test: TestModes, x):
    """The objective's residuals (m * 6,) [1] at ``x``: per test mode, ``(A u - w^2 u) / (w^2 |u|)`` (see the
    module's description). JAX-traceable."""
    from sixdof._jax import jnp

    K, M, offset = model.matrices(x)
    # The test shapes on the six DOFs at the model's CG: phi' = [[I, -S(d)], [0, I]] phi (the inverse of moved_rows).
    phi0 = jnp.asarray(np.linalg.lstsq(test.rows, test.real_shapes, rcond=None)[0])
    phi = jnp.vstack([phi0[:3] - _cross(offset) @ phi0[3:], phi0[3:]])
    L = jnp.linalg.cholesky(M)
    u = L.T @ phi
    omega2 = (2 * jnp.pi * jnp.asarray(test.frequency_hz)) ** 2
    residual = (jnp.linalg.solve(L, K @ phi) - omega2 * u) / (omega2 * jnp.linalg.norm(u, axis=0))
    return residual.T.ravel()


def model_modes(model: UpdateModel, x):
    """Natural frequencies (6,) [Hz], ascending, and mass-normalized shapes (6, 6) at ``x`` (JAX)."""
    from sixdof._jax import jnp

    K, M, _ = model.matrices(x)
    L_inv = jnp.linalg.inv(jnp.linalg.cholesky(M))
    eigenvalues, vectors = jnp.linalg.eigh(L_inv @ K @ L_inv.T)
    return jnp.sqrt(jnp.maximum(eigenvalues, 0.0)) / (2 * jnp.pi), L_inv.T @ vectors


def pairs(model: UpdateModel, test: TestModes, x) -> tuple[np.ndarray, np.ndarray]:
    """The model mode (index from 0) paired with each test mode at ``x`` by MAC on the measured channels (the
    one-to-one assignment of the largest total MAC), and each pair's MAC."""
    frequency_hz, shapes = model_modes(model, np.asarray(x, dtype=float))
    offset = model.matrices(np.asarray(x, dtype=float))[2]
    on_channels = np.asarray(moved_rows(test.rows, offset) @ shapes)
    found = mac(test.shapes, on_channels)  # (m, 6)
    paired = pair_modes(found, test.frequency_hz, np.asarray(frequency_hz), floor=0.0)  # every test mode paired
    model_index = np.array([m for _, m in sorted(paired)], dtype=int)
    return model_index, found[np.arange(len(model_index)), model_index]


def observation_residuals(model: UpdateModel, test: TestModes, noise: TestNoise, paired, x):
    """What a test measures, against the model at ``x`` with the pairing ``paired`` (m,), over the noise (JAX):
    each pair's relative frequency error over ``noise.frequency``, then each test mode's channels: the model
    shape scaled to it by least squares minus it, over ``noise.shape`` times its RMS."""
    from sixdof._jax import jnp

    frequency, shapes = model_modes(model, x)
    offset = model.matrices(x)[2]
    paired = np.asarray(paired)
    measured = jnp.asarray(test.real_shapes)
    on_channels = moved_rows(test.rows, offset) @ shapes[:, paired]
    scale = jnp.sum(measured * on_channels, axis=0) / jnp.sum(on_channels**2, axis=0)
    rms = np.sqrt(np.mean(np.asarray(test.real_shapes) ** 2, axis=0))
    f_test = jnp.asarray(test.frequency_hz)
    frequency_error = (frequency[paired] - f_test) / (noise.frequency * f_test)
    shape_error = (scale * on_channels - measured) / (noise.shape * rms)
    return jnp.concatenate([frequency_error, shape_error.T.ravel()])


def covariance(jacobian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Standard errors (n,) and correlation matrix (n, n) of variables whose noise-scaled residuals have the
    Jacobian ``jacobian`` (r, n): covariance ``(J^T J)^-1``, solved on the unit-diagonal form; a variable in a
    direction the residuals do not see (an eigenvalue below :data:`SINGULAR_RTOL`) gets an infinite standard
    error, and its correlations those of the limit of ``(J^T J + e I)^-1`` as ``e -> 0`` (+-1 between the
    variables of one unseen direction)."""
    J = np.asarray(jacobian, dtype=float)
    F = J.T @ J
    scale = np.sqrt(np.diag(F))
    unseen_alone = scale == 0
    D = np.where(unseen_alone, 1.0, scale)
    F_unit = F / np.outer(D, D)
    values, vectors = np.linalg.eigh(F_unit)
    singular = values < SINGULAR_RTOL * max(values.max(), np.finfo(float).tiny)
    seen = ~singular
    C_unit = (vectors[:, seen] / values[seen]) @ vectors[:, seen].T
    std = np.sqrt(np.maximum(np.diag(C_unit), 0.0)) / D
    in_null = np.any(np.abs(vectors[:, singular]) > 1e-6, axis=1) | unseen_alone
    std = np.where(in_null, np.inf, std)
    # Correlations: those of the covariance where it is finite; within the unseen directions, their projector's.
    null = vectors[:, singular] @ vectors[:, singular].T
    C = np.where(np.outer(in_null, in_null), null, C_unit)
    d = np.sqrt(np.abs(np.diag(C)))
    d = np.where(d == 0, 1.0, d)
    correlation = C / np.outer(d, d)
    mixed = np.logical_xor.outer(in_null, in_null)  # a finite and an unbounded variable: no correlation told
    correlation = np.where(mixed, 0.0, correlation)
    np.fill_diagonal(correlation, 1.0)
    return std, np.clip(correlation, -1.0, 1.0)


# ----------------------------------------------------------------------------------------------------
# The result.
# ----------------------------------------------------------------------------------------------------


def _per_variable(result) -> MixedUnits:
    return MixedUnits((("variable", result.variable_units),),
                      "stiffness, mass and inertia factors 1, position and CG offsets m, angles degree")


@result_type
@dataclass(frozen=True, eq=False)
class UpdateResult(Frozen, Result):
    """What :func:`update` found.

    Attributes
    ----------
    variable, other_variable : ndarray of str, shape (n_variables,)
        The variables' names (the second labels the correlation matrix's columns).
    iteration, start, test_mode, mode : ndarray of int
        Axis labels: iterations of every start, starts, test modes and model modes (from 1).
    initial, updated, lower_bound, upper_bound : ndarray, shape (n_variables,)
        The given model's variables, the update's, and their bounds (units: ``variable_units``).
    standard_error : ndarray, shape (n_variables,)
        At the test's noise (``inf``: a direction the test does not see).
    correlation : ndarray, shape (n_variables, n_variables)
    determined : ndarray of bool, shape (n_variables,)
        Whether the test determines each variable (see :mod:`sixdof.design.update`).
    history_start_index, history_objective, history_x : ndarray
        Per iteration of every start: the start (from 0; -1: the output-error polish), the objective (the
        eigen-equation residual's) [1], the variables.
    starts : ndarray, shape (n_starts, n_variables)
    test_frequency_hz : ndarray, shape (m,)
    frequency_hz_initial, frequency_hz : ndarray, shape (6,)
        The given and the updated model's natural frequencies [Hz].
    paired_mode_initial, paired_mode : ndarray of int, shape (m,)
        The model mode (from 1) paired with each test mode by MAC, for the given and the updated model.
    mac_initial, mac : ndarray, shape (m,)
        Their MAC on the measured channels.
    cg_offset : ndarray, shape (3,)
        The updated model's CG from the given one [m] (zeros without a ``cg_offset`` variable).
    objective_initial, objective_final : float
        The objective (the eigen-equation residual's) at the given and the updated model.
    objective : str
    frequency_noise, shape_noise : float
        The test noise the standard errors are for (:class:`TestNoise`).
    variable_units : tuple of str
    """

    variable: np.ndarray = quantity("", ("variable",))
    other_variable: np.ndarray = quantity("", ("other_variable",))
    iteration: np.ndarray = quantity("1", ("iteration",))
    start: np.ndarray = quantity("1", ("start",))
    test_mode: np.ndarray = quantity("1", ("test_mode",))
    mode: np.ndarray = quantity("1", ("mode",))
    initial: np.ndarray = quantity(_per_variable, ("variable",))
    updated: np.ndarray = quantity(_per_variable, ("variable",))
    lower_bound: np.ndarray = quantity(_per_variable, ("variable",))
    upper_bound: np.ndarray = quantity(_per_variable, ("variable",))
    standard_error: np.ndarray = quantity(_per_variable, ("variable",), description="at the test's noise")
    correlation: np.ndarray = quantity("1", ("variable", "other_variable"))
    determined: np.ndarray = quantity("1", ("variable",), description="whether the test determines the variable")
    history_start_index: np.ndarray = quantity("1", ("iteration",), name="history/start_index")
    history_objective: np.ndarray = quantity("1", ("iteration",), name="history/objective",
                                             description="sum of squared eigen-equation residuals of the test modes")
    history_x: np.ndarray = quantity(_per_variable, ("iteration", "variable"), name="history/x")
    starts: np.ndarray = quantity(_per_variable, ("start", "variable"))
    test_frequency_hz: np.ndarray = quantity("Hz", ("test_mode",))
    frequency_hz_initial: np.ndarray = quantity("Hz", ("mode",), description="given model")
    frequency_hz: np.ndarray = quantity("Hz", ("mode",), description="updated model")
    paired_mode_initial: np.ndarray = quantity("1", ("test_mode",), description="model mode (from 1), given model")
    paired_mode: np.ndarray = quantity("1", ("test_mode",), description="model mode (from 1), updated model")
    mac_initial: np.ndarray = quantity("1", ("test_mode",), description="given model")
    mac: np.ndarray = quantity("1", ("test_mode",), description="updated model")
    cg_offset: np.ndarray = quantity("m", ("axis",), description="updated CG from the given one")
    objective_initial: float = label(decode=float)
    objective_final: float = label(decode=float)
    objective: str = label(decode=str)
    frequency_noise: float = label(decode=float)
    shape_noise: float = label(decode=float)
    variable_units: tuple[str, ...] = label()
    provenance: Any = field(default_factory=dict)

    @property
    def undetermined(self) -> tuple[str, ...]:
        """The names of the variables the test does not determine."""
        return tuple(str(n) for n, ok in zip(self.variable, self.determined) if not ok)


def update(problem_or_scenario, test_modes: TestModes, spec=None, *, noise: TestNoise | None = None,
           progress=None) -> UpdateResult:
    """The model within the bounds of ``spec`` whose modes best meet ``test_modes`` (see the module's description).

    Parameters
    ----------
    problem_or_scenario : UpdateModel or sixdof.io.scenario.Scenario
        The model; a scenario gives its ``system`` (prepared where it needs preparing) and, without ``spec``,
        its ``[update]`` table.
    test_modes : TestModes
    spec : sixdof.design.spec.UpdateSpec, optional
        The variables (default: the scenario's ``update``).
    noise : TestNoise, optional
        The test's noise for the standard errors (default :class:`TestNoise` ``()``: 0.1 % on frequencies, 2 %
        on shapes).
    progress : sixdof.progress.Meter, optional
        Shown the number of starts done.

    Returns
    -------
    UpdateResult

    Raises
    ------
    sixdof.errors.InputError
        No ``[update]`` to update with, or a test or model the update cannot take.
    """
    from sixdof._jax import jax, jnp

    model = _model(problem_or_scenario, spec)
    if not isinstance(test_modes, TestModes):
        test_modes = TestModes(test_modes.frequency_hz, test_modes.shapes, test_modes.rows,
                               getattr(test_modes, "damping_ratio", None))
    noise = TestNoise() if noise is None else noise
    bounds = model.bounds
    low, width = bounds[:, 0], bounds[:, 1] - bounds[:, 0]

    def objective(u):  # in the variables scaled to [0, 1] within their bounds
        return jnp.sum(eigen_residuals(model, test_modes, low + width * u) ** 2)

    value_and_grad = jax.jit(jax.value_and_grad(objective))
    unit = np.tile([0.0, 1.0], (len(low), 1))
    starts = start_points((model.initial - low) / width, unit, model.spec.starts, model.spec.seed)
    history, best = [], None
    for index, start in enumerate(starts):
        def record(u, index=index):
            history.append(np.concatenate([[index, float(value_and_grad(jnp.asarray(u))[0])], low + width * u]))

        record(start)
        found = np.clip(np.asarray(bounded_minimize(value_and_grad, start, unit, record), dtype=float), 0.0, 1.0)
        score = float(value_and_grad(jnp.asarray(found))[0])
        if best is None or score < best[0]:
            best = (score, found)
        if progress is not None:
            progress.show(index + 1)
    # The polish: the observation residuals (noise-weighted output error, the estimate whose covariance is
    # reported) from the search's best, the pairing fixed by MAC and renewed between rounds until it holds.
    u = best[1]
    paired = pairs(model, test_modes, low + width * u)[0]
    for _ in range(MAX_PAIRING_ROUNDS):
        def output_error(v, paired=paired):
            return jnp.sum(observation_residuals(model, test_modes, noise, paired, low + width * v) ** 2)

        def record_polish(v):
            history.append(np.concatenate([[-1, float(value_and_grad(jnp.asarray(v))[0])], low + width * v]))

        u = np.clip(np.asarray(bounded_minimize(jax.jit(jax.value_and_grad(output_error)), u, unit, record_polish),
                               dtype=float), 0.0, 1.0)
        renewed = pairs(model, test_modes, low + width * u)[0]
        if np.array_equal(renewed, paired):
            break
        paired = renewed
    x = low + width * u
    initial = model.initial
    paired_initial, mac_initial = pairs(model, test_modes, initial)
    paired, mac_updated = pairs(model, test_modes, x)
    jacobian = np.asarray(jax.jacfwd(lambda v: observation_residuals(model, test_modes, noise, paired, v))(
        jnp.asarray(x)))
    std, correlation = covariance(jacobian)
    factor = np.array([v.parameter in FACTORS for v in model.variables])
    scale = np.where(factor, np.abs(x), width)
    off_diagonal = np.abs(correlation) - np.eye(len(x))
    determined = (std <= DETERMINED_RTOL * scale) & ~np.any(off_diagonal > CORRELATION_LIMIT, axis=1)
    history = np.array(history)
    names = np.array([v.name for v in model.variables])
    frequency_initial, frequency = (np.asarray(model_modes(model, jnp.asarray(v))[0]) for v in (initial, x))
    return UpdateResult(
        variable=names, other_variable=names, iteration=np.arange(1, len(history) + 1),
        start=np.arange(1, len(starts) + 1), test_mode=np.arange(1, len(test_modes.frequency_hz) + 1),
        mode=np.arange(1, 7), initial=readonly(initial), updated=readonly(x), lower_bound=readonly(bounds[:, 0]),
        upper_bound=readonly(bounds[:, 1]), standard_error=readonly(std), correlation=readonly(correlation),
        determined=readonly(determined, bool), history_start_index=readonly(history[:, 0].astype(int), int),
        history_objective=readonly(history[:, 1]), history_x=readonly(history[:, 2:]),
        starts=readonly(low + width * np.array(starts)), test_frequency_hz=test_modes.frequency_hz,
        frequency_hz_initial=readonly(frequency_initial), frequency_hz=readonly(frequency),
        paired_mode_initial=readonly(paired_initial + 1, int), paired_mode=readonly(paired + 1, int),
        mac_initial=readonly(mac_initial), mac=readonly(mac_updated),
        cg_offset=readonly(np.asarray(model.matrices(jnp.asarray(x))[2])),
        objective_initial=float(jnp.sum(eigen_residuals(model, test_modes, jnp.asarray(initial)) ** 2)),
        objective_final=float(value_and_grad(jnp.asarray(u))[0]), objective=model.spec.objective,
        frequency_noise=float(noise.frequency), shape_noise=float(noise.shape), variable_units=model.units)


def _model(problem_or_scenario, spec) -> UpdateModel:
    if isinstance(problem_or_scenario, UpdateModel):
        if spec is not None and spec is not problem_or_scenario.spec:
            return UpdateModel(problem_or_scenario.system, spec)
        return problem_or_scenario
    spec = getattr(problem_or_scenario, "update", None) if spec is None else spec
    if spec is None:
        raise InputError("update", "an [update] table saying what to vary (or an UpdateSpec)", Plain("none"))
    return UpdateModel(problem_or_scenario.system, spec)


#: The updated scenario's description says what it is (``sixdof run`` prints it as its title).
UPDATED_NOTE = "model updated to a test by sixdof correlate, from the [update] variables of {name}"


def updated_scenario_text(scenario, result: UpdateResult) -> str:
    """A complete scenario (TOML) of ``scenario`` with the model of ``result``: its mounts, body and CG (every
    position from the CG moved), named ``<name>_updated``; what ``sixdof run`` takes as it is. Written by the
    writer of optimized designs (:func:`sixdof.design.scenario_text.scenario_text`), at full precision, so
    its modes are ``result.frequency_hz``.

    Raises
    ------
    sixdof.errors.InputError
        ``result``'s variables are not those of ``scenario``'s ``[update]``.
    """
    model = _model(scenario, None)
    names = tuple(v.name for v in model.variables)
    if names != tuple(str(n) for n in result.variable):
        raise InputError("result.variable", f"the variables of the scenario's [update]: {', '.join(names)}",
                         Plain(", ".join(str(n) for n in result.variable)))
    system, offset = model.system_at(result.updated)
    source = scenario.path.name if scenario.path is not None else "the scenario"
    header = (f"# Written by model updating from {source}: its [[mounts]] and [body] are the updated model's"
              + (", and every position is measured from the updated centre of gravity" if np.any(offset) else "")
              + ";\n# the comments below are the original's and may describe the model before.\n")
    return scenario_text(scenario, system, name=f"{scenario.name}_updated",
                         note=UPDATED_NOTE.format(name=scenario.name), header=header, cg_offset=offset)
