"""The frequency-response results: receptance (:class:`FRF`), its cross-check, point FRFs and transmissibilities."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sixdof import results as schema
from sixdof.dofs import DOF_UNITS, FORCE_UNITS, UNITS, per_load_units
from sixdof.errors import choice_check

#: FRF quantities and the power of ``i w`` that turns receptance into each.
QUANTITIES: dict[str, int] = {"receptance": 0, "mobility": 1, "accelerance": 2}


_QUANTITY_SUFFIX = {"receptance": "", "mobility": "/s", "accelerance": "/s^2"}


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
        Where the load acts, from the CG in body axes [m], and its unit direction [1].
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
        The ground's unit direction of translation [1] and the response point, from the CG in body axes [m].
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


_check_quantity = choice_check(tuple(QUANTITIES))


def _ratio_unit(numerator: str, denominator: str) -> str:
    """``numerator`` per ``denominator``, each in parentheses where it is a compound: ``"m/N"``,
    ``"(m/s^2)/(N m)"`` (a unit library reads it as written)."""
    def grouped(unit):
        return f"({unit})" if " " in unit or "/" in unit else unit

    return f"{grouped(numerator)}/{grouped(denominator)}"


def in_file_order(extras) -> list[tuple[str, object]]:
    """The ``[frf]`` requests' results (name to result) by kind (force, then ground transmissibilities, then
    point FRFs) and name, as the results file keeps them: a live and a loaded run draw and export alike."""
    kinds = (ForceTransmissibility, GroundTransmissibility, PointFRF)

    def key(item):
        return next((k for k, cls in enumerate(kinds) if isinstance(item[1], cls)), len(kinds)), item[0]

    return sorted(dict(extras).items(), key=key)
