"""Response-spectrum analysis (issue 48, point 4): the peak response of the body on its mounts to a ground
motion given by its response spectrum, mode by mode, combined.

For a ground translation along the unit vector ``d`` (body axes), with the influence vector
``r = [d, 0, 0, 0]`` (:func:`sixdof.model.kinematics.rigid_translation`, the one ground motion enters by), mode i of
the undamped modes ``(omega_i, phi_i)`` of the system (:attr:`sixdof.model.system.System.modes`) has

- the participation factor ``Gamma_i = phi_i' M r / (phi_i' M phi_i)`` and the effective mass
  ``(phi_i' M r)^2 / (phi_i' M phi_i)``, summing over the six modes to the body's mass;
- the peak displacement relative to the ground ``Gamma_i S_De(T_i) phi_i``, ``S_De = S_a (T_i / 2 pi)^2``, with
  ``S_a`` the spectrum's pseudo-acceleration at the mode's period ``T_i = 2 pi / omega_i`` and damping ratio.

Every response quantity is formed per mode from that peak (a linear map of it: the DOFs, each mount's
deflection along its own axes u, v, w and its spring force ``k`` times that deflection, with the stiffness the
linear paths use (:attr:`~sixdof.model.system.System.stiffnesses`), the base shear (the mounts' forces on the
foundation summed, body axes) and the base moment (their moment about the CG, body axes, as
:class:`~sixdof.analysis.response.MountForces` gives it)) and then combined over the modes, never derived from
combined displacements:

- CQC (complete quadratic combination): ``R = sqrt(sum_ij rho_ij R_i R_j)`` with Der Kiureghian's coefficients
  (A. Der Kiureghian, "A response spectrum method for random vibration analysis of MDF systems", Earthquake
  Engineering and Structural Dynamics 9, 1981, 419-435), for damping ratios xi_i, xi_j and ``r = omega_j / omega_i``:
  ``rho_ij = 8 sqrt(xi_i xi_j) (xi_i + r xi_j) r^1.5 / ((1 - r^2)^2 + 4 xi_i xi_j r (1 + r^2) + 4 (xi_i^2 + xi_j^2)
  r^2)``, which for equal damping is ``8 xi^2 (1 + r) r^1.5 / ((1 - r^2)^2 + 4 xi^2 r (1 + r)^2)``;
- SRSS: ``rho_ij`` the identity (EN 1998-1 4.3.3.3.2(2) allows it when the periods are apart by more than 10 %).

The directions' combined peaks then combine by SRSS, or by the 100-30 rule of EN 1998-1 4.3.3.5.1(3) (two
horizontal directions) and 4.3.3.5.2(4) (with the vertical): the largest, over which direction leads, of the
leading direction's peak plus 0.30 times each other's.

EN 1998-1 4.3.3.3.1(3) asks for the modes whose effective masses make up 90 % of the total mass in each
direction: with all six modes of a rigid body, they make up all of it; an analysis with fewer (none today) notes
a direction below 90 %.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sixdof.dofs import AXES, UNITS, MixedUnits
from sixdof.errors import InputError, Plain, instance, readonly
from sixdof.model.kinematics import mount_local_map, rigid_translation
from sixdof.model.system import System
from sixdof.results import Result, label, quantity, result_type

#: The share of the total mass the modes' effective masses reach in each direction (EN 1998-1 4.3.3.3.1(3)).
MASS_SHARE = 0.90
#: The 100-30 rule's factor on the other directions (EN 1998-1 eqs. (4.18)-(4.22)).
COMBINATION_30 = 0.30
#: Points of the spectrum's curve stored for its figure.
CURVE_POINTS = 400

_PARTICIPATION = MixedUnits((("direction", ("kg^0.5",) * 3),), "kg^0.5 (mass-normalized shapes)")


def _labels(a) -> tuple[str, ...]:
    return tuple(str(x) for x in a)


@result_type
@dataclass(frozen=True, eq=False)
class ResponseSpectrum(Result):
    """Result of :func:`response_spectrum` (stored in ``/spectrum``). Peaks are magnitudes (combined); the
    per-mode peaks ``modal_q`` keep their signs.

    Attributes
    ----------
    direction : tuple of str
        The ground directions analysed (``"x"``, ``"y"``, ``"z"``, body axes).
    period : ndarray, shape (6,)
        The modes' periods [s].
    mode_damping : ndarray, shape (6,)
        The damping ratio of each mode in the spectrum and the combination [1].
    spectral_acceleration, spectral_displacement : ndarray, shape (direction, 6)
        The spectrum's pseudo-acceleration S_a [m/s^2] and ``S_De = S_a (T / 2 pi)^2`` [m] at each mode.
    participation : ndarray, shape (direction, 6)
        ``Gamma_i`` of the mass-normalized shapes [kg^0.5].
    effective_mass : ndarray, shape (direction, 6)
        The modes' effective masses in each direction [kg].
    mass_share : ndarray, shape (direction,)
        Their sum over the total mass [1].
    modal_q : ndarray, shape (direction, 6, 6)
        ``Gamma_i S_De(T_i) phi_i`` per direction and mode [m, rad], relative to the ground.
    peak_q : ndarray, shape (direction, 6)
        Combined over the modes [m, rad].
    combined_q : ndarray, shape (6,)
        Combined over the modes and the directions [m, rad].
    mounts : tuple of str
    mount_deflection, mount_force : ndarray, shape (direction, mount, 3)
        Along each mount's u, v, w [m], [N] (spring force).
    combined_mount_deflection, combined_mount_force : ndarray, shape (mount, 3)
        The same combined over the directions too [m], [N].
    base_shear, base_moment : ndarray, shape (direction, 3)
        Force of the mounts on the foundation [N] and its moment about the CG [N m], body axes.
    combined_base_shear, combined_base_moment : ndarray, shape (3,)
        The same combined over the directions too [N], [N m].
    curve_period, curve : ndarray, shape (p,), (direction, p)
        The spectrum at the analysis's damping ratio [s], [m/s^2] (its figure).
    spectrum, combination, directional : str
        What the spectrum is (one line), ``"cqc"`` or ``"srss"``, ``"srss"`` or ``"100-30"``.
    damping : float
        The analysis's damping ratio [1].
    notes : tuple of str
        Modes beyond the periods the code states its spectrum for; directions below 90 % of the mass.
    """

    direction: tuple[str, ...] = quantity("", ("direction",), decode=_labels)
    period: np.ndarray = quantity("s", ("mode",))
    mode_damping: np.ndarray = quantity("1", ("mode",))
    spectral_acceleration: np.ndarray = quantity("m/s^2", ("direction", "mode"),
                                                 description="the spectrum's pseudo-acceleration at each mode")
    spectral_displacement: np.ndarray = quantity("m", ("direction", "mode"),
                                                 description="S_De = S_a (T / 2 pi)^2 at each mode")
    participation: np.ndarray = quantity(_PARTICIPATION, ("direction", "mode"),
                                         description="Gamma_i = phi_i' M r of the mass-normalized shapes")
    effective_mass: np.ndarray = quantity("kg", ("direction", "mode"))
    mass_share: np.ndarray = quantity("1", ("direction",),
                                      description="the modes' effective masses summed over the total mass")
    modal_q: np.ndarray = quantity(MixedUnits((("dof", UNITS["q"].factors[0][1]),), UNITS["q"].description),
                                   ("direction", "mode", "dof"),
                                   description="peak displacement of each mode relative to the ground, signed")
    peak_q: np.ndarray = quantity(UNITS["q"], ("direction", "dof"),
                                  description="peak displacement relative to the ground, modes combined")
    combined_q: np.ndarray = quantity(UNITS["q"], ("dof",), description="peak_q, directions combined")
    mounts: tuple[str, ...] = quantity("", ("mount",), name="mount", decode=_labels)
    mount_deflection: np.ndarray = quantity("m", ("direction", "mount", "mount_axis"))
    mount_force: np.ndarray = quantity("N", ("direction", "mount", "mount_axis"), description="spring force")
    combined_mount_deflection: np.ndarray = quantity("m", ("mount", "mount_axis"))
    combined_mount_force: np.ndarray = quantity("N", ("mount", "mount_axis"))
    base_shear: np.ndarray = quantity("N", ("direction", "axis"), description="force of the mounts on the "
                                      "foundation, body axes")
    base_moment: np.ndarray = quantity("N m", ("direction", "axis"), description="moment of the mounts' forces "
                                       "on the foundation about the CG, body axes")
    combined_base_shear: np.ndarray = quantity("N", ("axis",))
    combined_base_moment: np.ndarray = quantity("N m", ("axis",))
    curve_period: np.ndarray = quantity("s", ("curve_period",))
    curve: np.ndarray = quantity("m/s^2", ("direction", "curve_period"),
                                 description="the spectrum at the analysis's damping ratio")
    spectrum: str = label(name="spectrum_source")
    combination: str = label()
    directional: str = label()
    damping: float = label(decode=float)
    notes: tuple[str, ...] = label(default=())

    def dominant_mode(self, direction: str) -> int:
        """The mode (index, ascending frequency) with the largest effective mass along ``direction``, one of
        :attr:`direction`: its period is the T1 of EN 1998-1 3.2.3.1.2(4)c for records along it."""
        if direction not in self.direction:
            raise InputError("direction", f"one of the analysed directions {', '.join(self.direction)}", direction)
        return int(np.argmax(self.effective_mass[self.direction.index(direction)]))


def cqc_coefficients(omega, xi) -> np.ndarray:
    """Der Kiureghian's (1981) correlation coefficients ``rho_ij`` of modes of circular frequencies ``omega``
    [rad/s] (> 0) and damping ratios ``xi`` [1] (see the module), shape (n, n); 1 on the diagonal."""
    w = np.asarray(omega, dtype=float)
    z = np.broadcast_to(np.asarray(xi, dtype=float), w.shape)
    r = w[None, :] / w[:, None]
    zi, zj = z[:, None], z[None, :]
    numerator = 8.0 * np.sqrt(zi * zj) * (zi + r * zj) * r**1.5
    denominator = (1 - r**2) ** 2 + 4 * zi * zj * r * (1 + r**2) + 4 * (zi**2 + zj**2) * r**2
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.where(denominator > 0, numerator / denominator, 1.0)  # undamped, equal frequencies: one mode
    np.fill_diagonal(rho, 1.0)
    return rho


def combine_modes(per_mode, rho) -> np.ndarray:
    """``sqrt(sum_ij rho_ij R_i R_j)`` of per-mode peaks ``per_mode`` (n, ...) [any unit]: the combined peak
    (...,); SRSS for ``rho`` the identity."""
    R = np.asarray(per_mode, dtype=float)
    square = np.einsum("ij,i...,j...->...", rho, R, R)
    return np.sqrt(np.maximum(square, 0.0))  # CQC's quadratic form is >= 0: rho is a correlation matrix


def combine_directions(peaks, rule: str) -> np.ndarray:
    """The directions' combined peaks ``peaks`` (direction, ...) combined over the directions: ``"srss"``, or
    ``"100-30"``, the largest over the leading direction of its peak plus 0.30 times each other's
    (EN 1998-1 4.3.3.5.1(3), 4.3.3.5.2(4))."""
    E = np.abs(np.asarray(peaks, dtype=float))
    if rule == "srss":
        return np.sqrt(np.sum(E**2, axis=0))
    if rule != "100-30":
        raise InputError("directional", "'srss' or '100-30'", rule)
    total = np.sum(E, axis=0)
    return np.max(E + COMBINATION_30 * (total[None] - E), axis=0)


def response_spectrum(system: System, settings, *, mode_damping=None) -> ResponseSpectrum:
    """The response-spectrum analysis of ``system`` (see the module).

    Parameters
    ----------
    system : sixdof.model.system.System
        Restrained in every DOF (no zero-frequency mode).
    settings : sixdof.excitation.spectra.SpectrumSettings
        The spectrum, directions, damping ratio and combinations.
    mode_damping : array_like, shape (6,), optional
        The damping ratio of each mode (ascending frequency) [1], for the spectrum and the CQC coefficients;
        default ``settings.damping`` for every mode (the effective linearization gives the isolation modes
        their own: :func:`sixdof.analysis.isolation.effective_linearization_loop`).

    Returns
    -------
    ResponseSpectrum

    Raises
    ------
    InputError
        For a system with a zero-frequency mode, a ``mode_damping`` that is not 6 ratios in [0, 1), or a mode
        outside a tabulated spectrum's periods.
    """
    from sixdof.excitation.spectra import SpectrumSettings  # noqa: PLC0415 (the excitation package loads JAX: reading a results file must not)

    instance(system, "system", System)
    instance(settings, "settings", SpectrumSettings)
    modes = system.modes
    if modes.zero_modes:
        raise InputError("system", "a body restrained in every DOF (a response spectrum needs each mode's period)",
                         Plain(f"zero-frequency modes in {', '.join(modes.free_dofs)}"))
    xi = _mode_damping(mode_damping, settings.damping)
    M, phi, omega = np.asarray(system.M), np.asarray(modes.shapes), np.asarray(modes.omega)
    period = 2 * np.pi / omega
    generalized_mass = np.einsum("ij,ik,kj->j", phi, M, phi)
    rho = cqc_coefficients(omega, xi) if settings.combination == "cqc" else np.eye(6)
    local = mount_local_map(system.positions, system.axes)  # (n_mounts, 3, 6)
    k, axes, positions = np.asarray(system.stiffnesses), np.asarray(system.axes), np.asarray(system.positions)
    spectrum = settings.spectrum
    out = {name: [] for name in ("sa", "sd", "gamma", "meff", "modal", "q", "defl", "force", "shear", "moment")}
    for d in settings.directions:
        r = rigid_translation(np.eye(3)[AXES.index(d)])
        L = phi.T @ M @ r
        gamma = L / generalized_mass
        sa = np.asarray(spectrum.pseudo_acceleration(period, xi, d), dtype=float)
        sd = sa / omega**2
        modal = (gamma * sd)[:, None] * phi.T  # (mode, dof)
        deflection = np.einsum("nij,mj->mni", local, modal)  # (mode, mount, axis)
        force = k[None] * deflection
        on_foundation = np.einsum("nij,mni->mnj", axes, force)  # body axes
        shear = on_foundation.sum(axis=1)
        moment = np.cross(positions[None], on_foundation).sum(axis=1)
        for name, value in (("sa", sa), ("sd", sd), ("gamma", gamma), ("meff", L**2 / generalized_mass),
                            ("modal", modal)):
            out[name].append(value)
        for name, value in (("q", modal), ("defl", deflection), ("force", force), ("shear", shear),
                            ("moment", moment)):
            out[name].append(combine_modes(value, rho))
    stacked = {name: np.array(values) for name, values in out.items()}
    rule = settings.directional
    total_mass = float(system.body.mass)
    share = stacked["meff"].sum(axis=1) / total_mass
    curve_period, curve = _curve(spectrum, settings, period)
    return ResponseSpectrum(
        direction=tuple(settings.directions), period=readonly(period), mode_damping=readonly(xi),
        spectral_acceleration=readonly(stacked["sa"]), spectral_displacement=readonly(stacked["sd"]),
        participation=readonly(stacked["gamma"]), effective_mass=readonly(stacked["meff"]),
        mass_share=readonly(share), modal_q=readonly(stacked["modal"]), peak_q=readonly(stacked["q"]),
        combined_q=readonly(combine_directions(stacked["q"], rule)), mounts=tuple(system.mount_names),
        mount_deflection=readonly(stacked["defl"]), mount_force=readonly(stacked["force"]),
        combined_mount_deflection=readonly(combine_directions(stacked["defl"], rule)),
        combined_mount_force=readonly(combine_directions(stacked["force"], rule)),
        base_shear=readonly(stacked["shear"]), base_moment=readonly(stacked["moment"]),
        combined_base_shear=readonly(combine_directions(stacked["shear"], rule)),
        combined_base_moment=readonly(combine_directions(stacked["moment"], rule)),
        curve_period=readonly(curve_period), curve=readonly(curve), spectrum=spectrum.describe(),
        combination=settings.combination, directional=rule, damping=float(settings.damping),
        notes=_notes(spectrum, period, settings.directions, share))


def _mode_damping(value, damping: float) -> np.ndarray:
    if value is None:
        return np.full(6, float(damping))
    expected = "6 damping ratios in [0, 1), one per mode in ascending frequency"
    try:
        xi = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError("mode_damping", expected, value) from None
    if xi.shape != (6,) or not np.all((xi >= 0) & (xi < 1)):  # NaN fails too
        raise InputError("mode_damping", expected, Plain(str(np.asarray(value).tolist())))
    return xi


def _curve(spectrum, settings, period) -> tuple[np.ndarray, np.ndarray]:
    """The spectrum along each direction at the analysis's damping ratio, on periods from 0 (or a table's first)
    past the longest mode's, with the corner periods on the grid (the figure's kinks drawn sharp)."""
    low = float(getattr(spectrum, "periods", [0.0])[0])
    high = min(spectrum.period_limit, 1.25 * float(period.max())) if hasattr(spectrum, "periods") \
        else max(spectrum.period_limit, 1.25 * float(period.max()))
    corners = [c for d in settings.directions for c in spectrum.corner_periods(d)]
    grid = np.unique(np.concatenate([np.linspace(low, high, CURVE_POINTS), [c for c in corners if low < c < high]]))
    curve = np.array([spectrum.pseudo_acceleration(grid, settings.damping, d) for d in settings.directions])
    return grid, curve


def _notes(spectrum, period, directions, share) -> tuple[str, ...]:
    notes = []
    limit = spectrum.period_limit
    beyond = [j + 1 for j, T in enumerate(period) if T > limit and not hasattr(spectrum, "periods")]
    if beyond:
        notes.append(f"mode(s) {', '.join(map(str, beyond))} beyond {limit:g} s, past the periods EN 1998-1 states "
                     f"its spectrum for (3.2.2.2(1)P, Annex A beyond): eqs. (3.5) and (3.11) used as written")
    for d, s in zip(directions, share):
        if s < MASS_SHARE and not math.isclose(s, MASS_SHARE):
            notes.append(f"direction {d}: the modes' effective masses make up {100 * s:.1f} % of the mass, below "
                         f"the {100 * MASS_SHARE:g} % of EN 1998-1 4.3.3.3.1(3)")
    return tuple(notes)
