"""Frequency-response functions of the mounted rigid body, by direct solution and by modal summation.

Everything here is a pure function of a :class:`~sixdof.model.system.System` and an array of frequencies in
Hz, returning a frozen result object. Steady-state harmonic motion ``q(t) = Re(q_hat e^{i w t})`` of

    (K + i K_h - w^2 M + i w C) q_hat = Q_hat                      (w = 2 pi f [rad/s], f >= 0)

where ``K_h`` is the hysteretic stiffness: every mount's stiffness times its loss factor, assembled
like ``K`` (complex stiffness ``k (1 + i eta)``, frequency independent; defined for ``f >= 0``).
``C`` is the total viscous damping (mount dashpots + Rayleigh + modal, :attr:`System.C`).

Two independent computations of the 6x6 receptance ``H = Z^-1``:

* ``method="direct"``, the default and the reference: a batched LU solve of the dynamic stiffness at
  every frequency (LAPACK through NumPy; no Python loop per frequency).
* ``method="modal"``, the fast path (~5x faster at 10,000 frequencies): summation over modes. When
  both ``C`` and ``K_h`` are diagonal in the undamped mass-normalized modes (classical damping:
  Rayleigh, modal, or proportional dashpots) the sum runs over the real modes,
  ``H = sum_r phi_r phi_r' / (w_r^2 (1 + i eta_r) - w^2 + i w c_r)``; otherwise over the complex modes
  of the first-order state-space system (complex ``K + i K_h`` included). Rigid-body (zero-frequency)
  modes contribute their mass line ``-phi phi' / w^2`` (or their damped form when ``C`` acts on them).
  It refuses (SolverError) nearly defective complex modes, e.g. a critically damped mode, which the
  direct method handles.

:func:`cross_check` computes both and reports their largest relative difference.

Zero frequency: ``f_hz = 0`` gives the static compliance ``(K + i K_h)^-1`` (mobility and accelerance
0) when every DOF is restrained. When the mounts leave a DOF unrestrained (zero-frequency modes), the
static response is unbounded and ``f_hz = 0`` raises :class:`~sixdof.errors.InputError`; every
positive frequency works, with either method.

Units: receptance entry ``[i, j]`` is DOF i's unit per generalized force j's unit (m/N, rad/(N m),
m/(N m) = 1/N, rad/N); :meth:`FRF.units` spells them out. Mobility multiplies by ``i w`` (per s),
accelerance by ``-w^2`` (per s^2).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sixdof import results as schema
from sixdof.analysis.response import global_damping
from sixdof.analysis.statespace import complex_modes, is_classical, modal_basis, modal_damping_ratios
from sixdof.dofs import AXES, DOF_UNITS, DOFS, FORCE_UNITS, UNITS, per_load_units
from sixdof.errors import InputError, Plain, SolverError, choice_check, direction_check, instance, point, readonly
from sixdof.model.kinematics import mount_matrix, point_map, response_row, unit_load
from sixdof.model.system import System

__all__ = [
    "FRF", "FRFCrossCheck", "ForceTransmissibility", "GroundTransmissibility", "PointFRF", "QUANTITIES",
    "cross_check", "check_resonances", "dynamic_stiffness", "force_transmissibility", "foundation_forces",
    "frf_difference",
    "ground_transmissibility", "hysteretic_stiffness", "point_frf", "receptance",
]

#: FRF quantities and the power of ``i w`` that turns receptance into each.
QUANTITIES: dict[str, int] = {"receptance": 0, "mobility": 1, "accelerance": 2}
_QUANTITY_SUFFIX = {"receptance": "", "mobility": "/s", "accelerance": "/s^2"}

#: A rigid-body mode counts as undamped when its modal damping is below this fraction of the
#: system's frequency scale (largest natural circular frequency or modal damping term); an elastic
#: mode when its damping ratio (viscous plus hysteretic) is below it.
RIGID_DAMPING_RTOL = 1e-12
#: A frequency this close (relative) to an undamped mode's natural frequency is refused: the dynamic
#: stiffness is singular there to round-off (direct and modal receptances of the undamped bridge
#: differ by ~1e-7 at 1e-9 off, by up to 87 % exactly on it).
UNDAMPED_RESONANCE_RTOL = 1e-9
#: Multiply-adds per row block of the modal sum's matrix product (see :meth:`_ModalTerms.evaluate`).
_BLOCK_MACS = 200_000


def _load_unit(load_kind: str) -> str:
    """Unit of an applied load: a force, or a moment."""
    return "N m" if load_kind == "moment" else "N"


def _per_load(load_kind: str) -> str:
    """Unit of a force per unit applied load (a force, or a moment)."""
    return "N/(N m)" if load_kind == "moment" else "N/N"


@dataclass(frozen=True, eq=False)
class FRF(schema.Result):
    """Generalized 6x6 receptance of a system at a set of frequencies (from :func:`receptance`).

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Frequencies [Hz], >= 0.
    H : ndarray, shape (nf, 6, 6), complex
        Receptance ``q_hat / Q_hat``: ``H[k, i, j]`` is DOF i (``x .. rz``, m or rad) per unit
        generalized force j (N or N m) at ``f_hz[k]``; see :meth:`units`.
    method : str
        ``"direct"`` or ``"modal"``.
    basis : str
        ``"dynamic stiffness"`` for the direct method, ``"real modes"`` or ``"complex modes"`` for the
        modal one.
    """

    f_hz: np.ndarray = schema.quantity("Hz", ("f_hz",))
    H: np.ndarray = schema.quantity(UNITS["receptance"], ("f_hz", "dof", "load"), name="receptance",
                                    description="[f, i, j]: q_i per generalized force Q_j, "
                                    "H = (K + i K_h - w^2 M + i w C)^-1")
    method: str = schema.label()
    basis: str = schema.label()

    @property
    def omega(self) -> np.ndarray:
        """Circular frequencies [rad/s], shape (nf,)."""
        return 2.0 * np.pi * self.f_hz

    def quantity(self, name: str = "receptance") -> np.ndarray:
        """Receptance, mobility (``i w H``) or accelerance (``-w^2 H``), shape (nf, 6, 6)."""
        return (1j * self.omega)[:, None, None] ** QUANTITIES[_check_quantity(name, "quantity")] * self.H

    def mobility(self) -> np.ndarray:
        """Mobility ``i w H``, shape (nf, 6, 6): velocity per generalized force [m/(s N), ...]."""
        return self.quantity("mobility")

    def accelerance(self) -> np.ndarray:
        """Accelerance ``-w^2 H``, shape (nf, 6, 6): acceleration per force [m/(s^2 N), ...]."""
        return self.quantity("accelerance")

    def units(self, name: str = "receptance") -> np.ndarray:
        """Unit of each entry of the (6, 6) matrix for ``name``, e.g. ``"m/N"``, ``"(rad/s)/(N m)"``."""
        suffix = _QUANTITY_SUFFIX[_check_quantity(name, "quantity")]
        return np.array([[_ratio_unit(dof + suffix, load) for load in FORCE_UNITS] for dof in DOF_UNITS])


@schema.result_type
@dataclass(frozen=True, eq=False)
class FRFCrossCheck(schema.Result):
    """Direct and modal receptances of one system and their agreement (from :func:`cross_check`).

    Attributes
    ----------
    direct, modal : FRF
    relative_difference : ndarray, shape (6, 6)
        Per entry, ``max_f |H_direct - H_modal| / scale_ij`` with ``scale_ij = max_f sqrt(|H_ii|
        |H_jj|)`` (each entry measured against its own size; dimensionally consistent).
    max_relative_difference : float
        The largest entry of ``relative_difference``.
    """

    direct: FRF = schema.part(lambda: FRF, prefix="")
    modal: FRF = schema.part(lambda: FRF, prefix="modal_")
    relative_difference: np.ndarray = schema.quantity(
        "1", ("dof", "load"), name="cross_check_relative_difference",
        description="direct vs modal receptance: max_f |H_direct - H_modal| / max_f sqrt(|H_ii H_jj|)")
    max_relative_difference: float = schema.label(name="cross_check_max_relative_difference")

    derived = {"modal_basis": schema.label(name="cross_check_modal_basis")}

    @property
    def modal_basis(self) -> str:
        """Basis of the modal receptance (``"real modes"`` or ``"complex modes"``)."""
        return self.modal.basis


@schema.result_type
@dataclass(frozen=True, eq=False)
class PointFRF(schema.Result):
    """Response at one point and direction per unit load at another (from :func:`point_frf`).

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Frequencies [Hz].
    values : ndarray, shape (nf,), complex
        The FRF in ``unit``.
    quantity : str
        ``"receptance"``, ``"mobility"`` or ``"accelerance"``.
    unit : str
        For example ``"m/N"`` (force in, translation out), ``"(rad/s)/(N m)"`` (moment in, rotational
        velocity out).
    load_point, load_direction, response_point, response_direction : ndarray, shape (3,)
        Points [m] from the CG in body axes; unit direction vectors in body axes.
    load_kind, response_kind : str
        ``"force"`` or ``"moment"``; ``"translation"`` or ``"rotation"``.
    method : str
        Method of the underlying receptance.
    """

    f_hz: np.ndarray = schema.quantity("Hz", ("f_hz",))
    values: np.ndarray = schema.quantity(lambda frf: frf.unit, ("f_hz",))
    quantity: str = schema.label()
    unit: str = schema.label()
    load_point: np.ndarray = schema.label()
    load_direction: np.ndarray = schema.label()
    response_point: np.ndarray = schema.label()
    response_direction: np.ndarray = schema.label()
    load_kind: str = schema.label()
    response_kind: str = schema.label()
    method: str = schema.label()

    group = "point"  # stored under /frf/point/<name>
    # ``values`` also as ``frf``: xarray's Dataset.values (a method) shadows a variable named "values".
    derived = {"frf": schema.quantity(lambda frf: frf.unit, ("f_hz",),
                                      description="the point FRF (the same as values, under a name xarray does "
                                      "not shadow)")}

    @property
    def frf(self) -> np.ndarray:
        """``values``, shape (nf,), complex, in ``unit``."""
        return self.values

    @property
    def magnitude(self) -> np.ndarray:
        """``|values|`` in ``unit``, shape (nf,)."""
        return np.abs(self.values)

    @property
    def phase_deg(self) -> np.ndarray:
        """Phase of the response relative to the load [deg] in (-180, 180], shape (nf,)."""
        return np.degrees(np.angle(self.values))


@schema.result_type
@dataclass(frozen=True, eq=False)
class ForceTransmissibility(schema.Result):
    """Forces the mounts pass to the foundation per unit applied load (from
    :func:`force_transmissibility`).

    A mount's force is the one it exerts on the foundation, ``A' diag(k (1 + i eta) + i w c) A u``,
    with ``u`` the displacement of its attachment point and ``A`` its axes: stiffness, hysteretic and
    dashpot parts. Global damping (Rayleigh, modal) acts on the motion relative to the ground like the
    dashpots and reaches the foundation too, as ``other_damping``, not attributed to a mount
    (:func:`sixdof.analysis.response.global_damping`: the same force as the time domain's).

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Frequencies [Hz].
    mount_names : tuple of str
    mount_forces : ndarray, shape (nf, n_mounts, 3), complex
        Each mount's force on the foundation in body axes, per unit applied load [N/N, or N/(N m)
        for an applied moment].
    total : ndarray, shape (nf, 6), complex
        Resultant of all forces on the foundation: force [N/N] and moment about the CG's rest
        position [N m/N], in body axes (``sum_j T_j' F_j + other_damping``).
    other_damping : ndarray, shape (nf, 6), complex
        Generalized force of the Rayleigh and modal damping on the foundation, ``i w (C - C_mounts) q``,
        per unit load (zero without them).
    load_point, load_direction : ndarray, shape (3,)
    load_kind : str
        ``"force"`` or ``"moment"``.
    method : str
    """

    f_hz: np.ndarray = schema.quantity("Hz", ("f_hz",))
    mount_names: tuple[str, ...] = schema.quantity("", ("mount",), name="mount",
                                                   decode=lambda a: tuple(str(n) for n in a))
    mount_forces: np.ndarray = schema.quantity(
        lambda ft: _per_load(ft.load_kind), ("f_hz", "mount", "axis"),
        description="each mount's force on the foundation in body axes per unit load")
    total: np.ndarray = schema.quantity(
        lambda ft: per_load_units(_load_unit(ft.load_kind)), ("f_hz", "load"),
        description="resultant force and moment (about the CG rest position) on the foundation")
    other_damping: np.ndarray = schema.quantity(
        lambda ft: per_load_units(_load_unit(ft.load_kind)), ("f_hz", "load"), name="other_damping_force",
        description="generalized force of Rayleigh and modal damping on the foundation, i w (C - C_mounts) q")
    load_point: np.ndarray = schema.label()
    load_direction: np.ndarray = schema.label()
    load_kind: str = schema.label()
    method: str = schema.label()

    group = "force_transmissibility"  # stored under /frf/force_transmissibility/<name>
    derived = {"transmissibility": schema.quantity(lambda ft: _per_load(ft.load_kind), ("f_hz",),
                                                   description="|resultant foundation force| per unit load")}

    @property
    def total_force(self) -> np.ndarray:
        """Resultant foundation force per unit load, shape (nf, 3), complex [N/N]."""
        return self.total[:, :3]

    @property
    def transmissibility(self) -> np.ndarray:
        """Force transmissibility ``|F_total|`` (Euclidean norm of the complex resultant) per unit
        applied force, shape (nf,) [N/N]; 1 at f = 0 for a restrained system."""
        return np.sqrt(np.sum(np.abs(self.total_force) ** 2, axis=-1))

    @property
    def along_load(self) -> np.ndarray:
        """Resultant foundation force along the load direction per unit load, shape (nf,), complex."""
        return self.total_force @ self.load_direction


@schema.result_type
@dataclass(frozen=True, eq=False)
class GroundTransmissibility(schema.Result):
    """Body motion per unit rigid translation of the ground under every mount (from
    :func:`ground_transmissibility`).

    The ground (foundation) translates rigidly by ``u_g = d`` (unit vector); every mount's relative
    displacement is that of its body point minus ``d``. All damping (dashpots, Rayleigh, modal,
    hysteretic) acts on the motion relative to the ground, the usual base-excitation convention:
    ``Z(w) q_hat = (K + i K_h + i w C) q_g`` with ``q_g = [d, 0, 0, 0]``.

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Frequencies [Hz].
    q : ndarray, shape (nf, 6), complex
        Absolute generalized motion per unit ground displacement [m/m, rad/m].
    absolute : ndarray, shape (nf, 3), complex
        Absolute displacement of the response point in body axes per unit ground displacement
        [m/m] (the same ratio holds for velocities and accelerations).
    relative : ndarray, shape (nf, 3), complex
        Displacement of the response point relative to the ground, ``absolute - d`` [m/m].
    ground_direction, response_point : ndarray, shape (3,)
    method : str
    """

    f_hz: np.ndarray = schema.quantity("Hz", ("f_hz",))
    q: np.ndarray = schema.quantity(UNITS["ground_transmissibility"], ("f_hz", "dof"),
                                    description="absolute generalized motion per unit ground displacement")
    absolute: np.ndarray = schema.quantity("m/m", ("f_hz", "axis"))
    relative: np.ndarray = schema.quantity("m/m", ("f_hz", "axis"))
    ground_direction: np.ndarray = schema.label()
    response_point: np.ndarray = schema.label()
    method: str = schema.label()

    group = "ground_transmissibility"  # stored under /frf/ground_transmissibility/<name>
    derived = {"transmissibility": schema.quantity(
        "m/m", ("f_hz",), description="|absolute motion along the ground direction| per unit ground motion")}

    @property
    def transmissibility(self) -> np.ndarray:
        """Absolute motion transmissibility along the ground direction, ``|d . u_abs|``, (nf,)."""
        return np.abs(self.absolute @ self.ground_direction)


def _frequencies(f_hz) -> np.ndarray:
    try:
        f = np.atleast_1d(readonly(f_hz))
    except (TypeError, ValueError):
        f = None
    if f is None or f.ndim > 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise InputError("f_hz", "finite frequencies >= 0 in Hz (a number or a 1-D array)", f_hz)
    return f


_check_quantity = choice_check(tuple(QUANTITIES))
_check_method = choice_check(("direct", "modal"))
_check_basis = choice_check(("auto", "real", "complex"))


def parse_direction(value, field: str, rotations: bool = True) -> tuple[np.ndarray, bool]:
    """Unit vector in body axes and whether it is rotational ('rx', 'ry', 'rz')."""
    names = ", ".join(f"'{d}'" for d in (DOFS if rotations else AXES))
    expected = f"one of {names} or a nonzero 3-vector in body axes"
    if isinstance(value, str):
        rotational = rotations and value in DOFS[3:]
        axis = value[1:] if rotational else value
        if axis not in AXES:
            raise InputError(field, expected, value)
        return np.eye(3)[AXES.index(axis)], rotational
    return direction_check(expected)(value, field), False


def _ratio_unit(numerator: str, denominator: str) -> str:
    """``numerator`` per ``denominator``, each in parentheses where it is a compound: ``"m/N"``,
    ``"(m/s^2)/(N m)"`` (a unit library reads it as written)."""
    def grouped(unit):
        return f"({unit})" if " " in unit or "/" in unit else unit

    return f"{grouped(numerator)}/{grouped(denominator)}"


def hysteretic_stiffness(system: System) -> np.ndarray:
    """Hysteretic stiffness ``K_h`` (6, 6) [N/m, N, N m/rad]: mount stiffness times loss factor.

    The complex stiffness of the mounts is ``K + i K_h``.
    """
    eta = system.loss_factors
    if not np.any(eta):
        return np.zeros((6, 6))  # no hysteresis (the common case): exactly zero
    # NumPy, not the JAX assembly: a JAX dispatch costs ~1 ms, a third of the fast receptance's budget.
    return mount_matrix(system.positions, system.stiffnesses * eta, system.axes)


def support_stiffness(system: System, omega) -> np.ndarray:
    """What acts on the body's motion relative to the ground, ``K + i K_h + i w C + K_b(w)``, (nf, 6, 6) complex
    [N/m, N, N m/rad] at ``omega`` (nf,) [rad/s]: springs, loss factors, all viscous damping and the Maxwell
    branches' ``K_b(w) = sum_b R_b' R_b k_b (i w tau_b) / (1 + i w tau_b)``."""
    w = np.asarray(omega, dtype=float)[:, None, None]
    static = np.asarray(system.K, dtype=complex) + 1j * hysteretic_stiffness(system)
    Z = static[None] + (1j * w) * np.asarray(system.C)[None]
    if system.branches.count:
        Z = Z + system.branches.matrix(omega)
    return Z


def dynamic_stiffness(system: System, f_hz) -> np.ndarray:
    """Dynamic stiffness ``Z = K + i K_h - w^2 M + i w C + K_b(w)`` at every frequency, (nf, 6, 6) complex
    (:func:`support_stiffness`, less the inertia).

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz], >= 0.
    """
    omega = 2.0 * np.pi * _frequencies(f_hz)
    return support_stiffness(system, omega) - omega[:, None, None] ** 2 * np.asarray(system.M)[None]


def check_resonances(system: System, f_hz, field: str = "f_hz") -> None:
    """Refuse a frequency on the natural frequency of a mode no damping acts on (its response is infinite).

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    field : str
        Named in the error.

    Raises
    ------
    InputError
        Naming the first such frequency and the mode, when a frequency is within
        :data:`UNDAMPED_RESONANCE_RTOL` (relative) of the natural frequency of an elastic mode whose
        damping ratio, viscous plus hysteretic, is below :data:`RIGID_DAMPING_RTOL`.
    """
    f = _frequencies(f_hz)
    modes = system.modes
    # zeta_r = phi_r' C phi_r / (2 w_r) + phi_r' K_h phi_r / (2 w_r^2); nan for rigid-body modes (never hit).
    hysteretic = modal_damping_ratios(hysteretic_stiffness(system), modes)
    with np.errstate(invalid="ignore"):
        zeta = modal_damping_ratios(system.C, modes) + hysteretic / modes.omega
    if system.branches.count:  # a Maxwell branch damps every mode it deforms: Im(phi' K_b(w_r) phi) > 0
        shapes = np.asarray(modes.shapes)
        zeta = zeta + np.einsum("ir,rij,jr->r", shapes, system.branches.matrix(modes.omega).imag, shapes)
    for r in np.flatnonzero(zeta <= RIGID_DAMPING_RTOL):
        f_r = float(modes.frequency_hz[r])
        hit = np.flatnonzero(np.abs(f - f_r) <= UNDAMPED_RESONANCE_RTOL * f_r)
        if hit.size:
            i = int(hit[0])
            raise InputError(field, f"frequencies off the natural frequency of mode {r + 1} ({f_r:.12g} Hz) by more "
                             f"than {UNDAMPED_RESONANCE_RTOL:.0e} of it: no damping acts on that mode, so its "
                             "response there is infinite (add damping or move the frequency)",
                             Plain(f"{f[i]:.12g} Hz (frequency {i + 1} of {f.size})"))


def receptance(system: System, f_hz, method: str = "direct", basis: str = "auto") -> FRF:
    """Generalized 6x6 receptance ``H(w) = (K + i K_h - w^2 M + i w C)^-1``.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz], finite and >= 0 (> 0 for a system with unrestrained DOFs).
    method : {"direct", "modal"}
        Batched solve of the dynamic stiffness (the reference; works for every system), or
        summation over modes (the fast path, ~5x faster at many frequencies; raises SolverError
        for nearly defective complex modes, e.g. a critically damped mode).
    basis : {"auto", "real", "complex"}
        Modal method only: ``"auto"`` uses real modes when damping and hysteresis are classical and
        complex modes otherwise; ``"complex"`` forces complex modes (always exact); ``"real"``
        insists on real modes and raises if damping is not classical.

    Returns
    -------
    FRF
        ``H`` (nf, 6, 6) complex [m/N, rad/(N m), 1/N]; see :meth:`FRF.units`.

    Raises
    ------
    InputError
        A ``system`` that is not a System; bad frequencies (negative, non-finite; zero for an
        unrestrained system; on the natural frequency of an undamped mode, :func:`check_resonances`),
        method or basis.
    SolverError
        The dynamic stiffness is singular at a requested frequency, or the complex modes are nearly
        defective.
    """
    instance(system, "system", System)  # the FRFs of points and transmissibilities come through here
    f = _frequencies(f_hz)
    check_resonances(system, f)
    _check_method(method, "method")
    _check_basis(basis, "basis")
    if np.any(f == 0.0) and system.modes.zero_modes:
        free = ", ".join(system.modes.free_dofs) or "some DOFs"
        raise InputError("f_hz", f"frequencies > 0 Hz: the mounts leave {free} unrestrained, so the static "
                         "response (f = 0) is unbounded", f.tolist())
    if method == "direct":
        try:
            # Batched LAPACK LU (getrf/getri) with partial pivoting: one call for all frequencies.
            H, used = np.linalg.inv(dynamic_stiffness(system, f)), "dynamic stiffness"
        except np.linalg.LinAlgError:
            raise SolverError("receptance (direct): the dynamic stiffness is singular at a requested frequency "
                              "(an undamped natural frequency hit exactly)") from None
    else:
        terms = _modal_terms(system, basis)
        with np.errstate(divide="ignore", invalid="ignore"):
            H, used = terms.evaluate(2.0 * np.pi * f), terms.basis
    if not np.isfinite(H.view(float)).all():  # the float view: half the cost of complex isfinite
        raise SolverError(f"receptance ({method}): non-finite values; a requested frequency sits exactly on an "
                          "undamped natural frequency")
    H.flags.writeable = False
    return FRF(f_hz=f, H=H, method=method, basis=used)


@dataclass(frozen=True, eq=False)
class _ModalTerms:
    """``H(w) = sum_r R_r / (a_r + i w b_r - w^2) + sum_k S_k / (i w - lambda_k)``: real and complex modes."""

    basis: str
    real_residues: np.ndarray
    a: np.ndarray
    b: np.ndarray
    complex_residues: np.ndarray
    eigenvalues: np.ndarray

    @cached_property
    def _stacked(self) -> np.ndarray:
        """Residues ``S' + i S''`` (P, 36) as the real ``[[S', S''], [-S'', S']]`` (2 P, 72), Re/Im interleaved."""
        S = np.concatenate([self.real_residues.reshape(-1, 36), self.complex_residues.reshape(-1, 36)])
        p = S.shape[0]
        out = np.empty((2 * p, 36, 2))
        out[:p, :, 0], out[:p, :, 1] = S.real, S.imag
        out[p:, :, 0], out[p:, :, 1] = -S.imag, S.real
        return out.reshape(2 * p, 72)

    def evaluate(self, omega: np.ndarray) -> np.ndarray:
        """Receptance (nf, 6, 6) at ``omega`` [rad/s]."""
        # One real (nf, 2 P) x (2 P, 72) product written in place, whose rows are complex results'
        # memory layout: no complex division and no temporary of the result's size.
        w = np.asarray(omega, dtype=float)[:, None]
        nr, nc = self.a.size, self.eigenvalues.size
        # Pole factors g[:, 0] + i g[:, 1] in real arithmetic: NumPy's complex division rescales against
        # overflow, at several times the cost, and these denominators are far from overflow.
        g = np.empty((w.shape[0], 2, nr + nc))
        if nr:
            x = self.a.real - w * w  # x + i y = a_r - w^2 + i w b_r
            y = w * self.b
            y += self.a.imag
            _reciprocal(x, y, g[:, 0, :nr], g[:, 1, :nr])
        if nc:
            x = np.broadcast_to(-self.eigenvalues.real, (w.shape[0], nc))  # x + i y = i w - lambda_k
            y = w - self.eigenvalues.imag
            _reciprocal(x, y, g[:, 0, nr:], g[:, 1, nr:])
        g = g.reshape(w.shape[0], -1)
        stacked = self._stacked
        out = np.empty((g.shape[0], 72))
        # Row blocks below OpenBLAS's threading threshold stay on one thread and in cache: on a busy
        # 2-core machine a threaded product waits a scheduler tick for its second thread (8 ms, not 2).
        step = max(1, _BLOCK_MACS // stacked.size)
        for start in range(0, g.shape[0], step):
            np.matmul(g[start : start + step], stacked, out=out[start : start + step])
        return out.view(complex).reshape(-1, 6, 6)


def _reciprocal(x: np.ndarray, y: np.ndarray, re: np.ndarray, im: np.ndarray) -> None:
    """Write ``1 / (x + i y)`` into ``re + i im`` (real arrays of one shape)."""
    inv = x * x
    inv += y * y
    np.divide(1.0, inv, out=inv)
    np.multiply(x, inv, out=re)
    np.multiply(y, inv, out=im)
    np.negative(im, out=im)


def _modal_terms(system, basis: str) -> _ModalTerms:
    C = np.asarray(system.C, dtype=float)
    modes = system.modes
    phi, _ = modal_basis(modes, C)
    cm = phi.T @ C @ phi
    khm = phi.T @ hysteretic_stiffness(system) @ phi
    km = phi.T @ np.asarray(system.K, dtype=float) @ phi
    # Rayleigh quotients: the eigen-solver's eigenvalues carry absolute errors ~eps * lambda_max,
    # large at the low, lightly damped modes' peaks; the quotients are accurate to ~eps * lambda_r.
    lam = np.where(np.array(modes.eigenvalues) > 0, np.diag(km), 0.0)
    branches = system.branches
    G = phi.T @ branches.rows.T  # (6, nb): each mode's deformation of each Maxwell branch
    scale = max(float(np.max(modes.omega)), float(np.max(np.abs(cm))), np.finfo(float).tiny)
    undamped_rigid = [r for r in modes.zero_modes
                      if cm[r, r] <= RIGID_DAMPING_RTOL * scale and not np.any(G[r] * branches.stiffness)]
    rest = [r for r in range(6) if r not in undamped_rigid]
    classical = is_classical(cm, khm) and not branches.count
    if basis == "real" and not classical:
        raise InputError("basis", "'auto' or 'complex' (damping, hysteresis or Maxwell branches are not diagonal "
                         "in the real modes, so real modes cannot represent them)", basis)
    if classical and basis != "complex":
        return _ModalTerms(basis="real modes", real_residues=np.einsum("ir,jr->rij", phi, phi).astype(complex),
                           a=lam + 1j * np.diag(khm), b=np.diag(cm).copy(),
                           complex_residues=np.zeros((0, 6, 6), dtype=complex), eigenvalues=np.zeros(0, dtype=complex))

    # Complex modes of the coordinates in `rest`; undamped rigid-body modes stay real mass lines -phi phi'/w^2
    # (in first-order form a Jordan block: a double zero eigenvalue, one eigenvector, no eigenvector sum).
    n = len(rest)
    ix = np.ix_(rest, rest)
    stiffness = np.where(lam[rest] > 0, km[ix], 0.0) + 1j * khm[ix]
    maxwell = (G[rest], branches.stiffness, branches.tau) if branches.count else None
    modes_c = complex_modes(stiffness, cm[ix], remedy="use method='direct'", maxwell=maxwell)
    phi_s = phi[:, rest]
    out = phi_s @ modes_c.right[:n, :]  # (6, 2n + nb): q per unit state-mode amplitude
    inp = modes_c.left[:, n:2 * n] @ phi_s.T  # (2n + nb, 6): the generalized force drives eta''
    u = phi[:, undamped_rigid]
    return _ModalTerms(basis="complex modes", real_residues=np.einsum("ir,jr->rij", u, u).astype(complex),
                       a=np.zeros(len(undamped_rigid), dtype=complex), b=np.zeros(len(undamped_rigid)),
                       complex_residues=np.einsum("ik,kj->kij", out, inp), eigenvalues=modes_c.eigenvalues)


def frf_difference(a: FRF, b: FRF) -> np.ndarray:
    """Relative difference of two receptances of one system, per entry, shape (6, 6).

    ``max_f |a_ij - b_ij| / max_f sqrt(|a_ii| |a_jj|)``: every entry is measured against the size of
    the responses it connects (translations ~1e-4 m and rotations ~1e-7 rad each on their own
    scale), and entries that vanish by symmetry do not divide by their own round-off.

    Raises
    ------
    InputError
        If the two were computed at different frequencies.
    """
    if a.f_hz.shape != b.f_hz.shape or not np.array_equal(a.f_hz, b.f_hz):
        raise InputError("f_hz", "the same frequencies for both FRFs", b.f_hz.tolist())
    diag = np.abs(np.diagonal(a.H, axis1=1, axis2=2))  # (nf, 6)
    scale = np.max(np.sqrt(diag[:, :, None] * diag[:, None, :]), axis=0)
    scale = np.where(scale > 0, scale, np.finfo(float).tiny)
    return np.max(np.abs(a.H - b.H), axis=0) / scale


def cross_check(system: System, f_hz) -> FRFCrossCheck:
    """Receptance by both methods and their largest relative difference (see :func:`frf_difference`).

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].

    Returns
    -------
    FRFCrossCheck
    """
    direct = receptance(system, f_hz, method="direct")
    modal = receptance(system, f_hz, method="modal")
    diff = readonly(frf_difference(direct, modal))
    return FRFCrossCheck(direct=direct, modal=modal, relative_difference=diff,
                         max_relative_difference=float(diff.max()))


def point_frf(system: System, f_hz, load_point, load_direction, response_point, response_direction,
              quantity: str = "receptance", method: str = "direct") -> PointFRF:
    """FRF between a load at one body point and the motion of another.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    load_point : array_like, shape (3,)
        Where the load acts, from the CG in body axes [m].
    load_direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a nonzero 3-vector (normalized): a unit force along it; or
        ``"rx"``, ``"ry"``, ``"rz"``: a unit moment about that body axis.
    response_point : array_like, shape (3,)
        Where the motion is observed, from the CG in body axes [m].
    response_direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a 3-vector: the point's translation along it; or ``"rx"``,
        ``"ry"``, ``"rz"``: the body's rotation about that axis (the same at every point).
    quantity : {"receptance", "mobility", "accelerance"}
        Displacement, velocity or acceleration per load.
    method : {"direct", "modal"}

    Returns
    -------
    PointFRF
        ``values`` in m/N, m/(s N), m/(s^2 N) for force in, translation out (``unit`` says which).
    """
    _check_quantity(quantity, "quantity")
    lp = point(load_point, "load_point")
    ld, moment = parse_direction(load_direction, "load_direction")
    rp = point(response_point, "response_point")
    rd, rotation = parse_direction(response_direction, "response_direction")
    frf = receptance(system, f_hz, method=method)
    values = (frf.quantity(quantity) @ unit_load(lp, ld, moment)) @ response_row(rp, rd, rotation)
    unit = _ratio_unit(("rad" if rotation else "m") + _QUANTITY_SUFFIX[quantity], "N m" if moment else "N")
    return PointFRF(f_hz=frf.f_hz, values=readonly(values, complex), quantity=quantity, unit=unit,
                    load_point=lp, load_direction=ld, response_point=rp, response_direction=rd,
                    load_kind="moment" if moment else "force",
                    response_kind="rotation" if rotation else "translation", method=method)


def force_transmissibility(system: System, f_hz, load_point, load_direction,
                           method: str = "direct") -> ForceTransmissibility:
    """Forces passed to the foundation by each mount, and their resultant, per unit applied load.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    load_point : array_like, shape (3,)
        Where the load acts, from the CG in body axes [m].
    load_direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a nonzero 3-vector (unit force), or ``"rx"``, ``"ry"``,
        ``"rz"`` (unit moment).
    method : {"direct", "modal"}
        How the body's receptance is computed.

    Returns
    -------
    ForceTransmissibility
        Mount forces (nf, n_mounts, 3) and resultant (nf, 6) per unit load, complex: the mounts'
        stiffness, loss factor and dashpots, and the global (Rayleigh, modal) damping's force.
    """

    lp = point(load_point, "load_point")
    ld, moment = parse_direction(load_direction, "load_direction")
    frf = receptance(system, f_hz, method=method)
    forces, other, total = foundation_forces(system, frf.omega, frf.H @ unit_load(lp, ld, moment))
    return ForceTransmissibility(f_hz=frf.f_hz, mount_names=system.mount_names, mount_forces=readonly(forces, complex),
                                 total=readonly(total, complex), other_damping=readonly(other, complex),
                                 load_point=lp, load_direction=ld,
                                 load_kind="moment" if moment else "force", method=method)


def mount_impedances(system: System, omega) -> np.ndarray:
    """Each mount's complex stiffness along its own axes, ``k (1 + i eta) + i w c`` plus its Maxwell branches',
    (nf, n_mounts, 3) [N/m] at ``omega`` (nf,) [rad/s]."""
    omega = np.asarray(omega, dtype=float)
    local = system.stiffnesses * (1.0 + 1j * system.loss_factors) + 1j * omega[:, None, None] * system.dampings
    branches = system.branches
    if branches.count:
        np.add.at(local, (slice(None), branches.mount, branches.axis), branches.dynamic_stiffness(omega))
    return local


def foundation_forces(system: System, omega, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What the mounts and the global damping pass to the foundation for the complex motion amplitudes ``q``
    (nf, 6) at the circular frequencies ``omega`` (nf,) [rad/s], the ground at rest.

    Returns each mount's force in body axes, ``A' diag(k (1 + i eta) + i w c + K_b) A u`` (nf, n_mounts, 3), the
    global damping's generalized force ``i w (C - C_mounts) q`` (nf, 6), and their resultant about the CG's
    rest position (nf, 6); complex, in the units of ``q`` times stiffness.
    """
    t = point_map(system.positions)  # (n, 3, 6)
    u = np.einsum("nij,fj->fni", t, q)  # mount point displacements (nf, n, 3)
    # Each mount's complex stiffness in body axes, A' diag(k (1 + i eta) + i w c + K_b) A: (nf, n, 3, 3).
    local = mount_impedances(system, omega)
    impedances = np.einsum("nai,fna,naj->fnij", system.axes, local, system.axes)
    forces = np.einsum("fnij,fnj->fni", impedances, u)
    other = 1j * omega[:, None] * (q @ global_damping(system).T)
    return forces, other, np.einsum("nia,fni->fa", t, forces) + other


def ground_transmissibility(system: System, f_hz, ground_direction, response_point,
                            method: str = "direct") -> GroundTransmissibility:
    """Motion of a body point per unit rigid translation of the ground under every mount.

    Parameters
    ----------
    system : System
    f_hz : array_like, shape (nf,)
        Frequencies [Hz].
    ground_direction : str or array_like, shape (3,)
        ``"x"``, ``"y"``, ``"z"`` or a nonzero 3-vector (normalized): the ground's translation.
    response_point : array_like, shape (3,)
        Body point observed, from the CG in body axes [m].
    method : {"direct", "modal"}

    Returns
    -------
    GroundTransmissibility
        Absolute and relative point motion per unit ground motion [m/m] (also the ratio of
        velocities or of accelerations), and the generalized motion ``q`` per unit ground motion.
    """
    d, _ = parse_direction(ground_direction, "ground_direction", rotations=False)
    rp = point(response_point, "response_point")
    frf = receptance(system, f_hz, method=method)
    qg = np.concatenate([d, np.zeros(3)])
    # All damping acts on the motion relative to the ground: Z q = (K + i K_h + i w C + K_b(w)) q_g.
    drive = support_stiffness(system, frf.omega) @ qg
    q = np.einsum("fij,fj->fi", frf.H, drive)
    absolute = q @ point_map(rp).T
    return GroundTransmissibility(f_hz=frf.f_hz, q=readonly(q, complex), absolute=readonly(absolute, complex),
                                  relative=readonly(absolute - d[None, :], complex), ground_direction=d,
                                  response_point=rp, method=method)
