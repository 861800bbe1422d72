"""The one time-history type of sixdof, whatever computed it.

The direct solve (:func:`sixdof.analysis.direct.simulate`), the modal superposition
(:func:`sixdof.analysis.superposition.superpose`), the validation's free decays and the batch
engine's kept variants all return a :class:`TimeHistory`; :func:`sixdof.analysis.compare.compare`
takes two of them. What only one method knows rides along in an optional part: the direct solver's
statistics (``stats``) or the superposition's method and truncation (``superposition``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sixdof.dofs import AXES, DOFS
from sixdof.errors import InputError, readonly


@dataclass(frozen=True, eq=False)
class TimeHistory:
    """Motion of the body's centre of gravity at a set of times.

    ``q, qd, qdd`` are the *absolute* motion (fixed frame): what an accelerometer on the body measures.
    With ground motion, ``ground_*`` hold the foundation's motion and ``q_relative`` etc. the motion
    relative to it (what the mounts feel); without it they are ``None`` and the relative motion is
    the absolute one.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times [s].
    q, qd, qdd : ndarray, shape (n, 6)
        Displacement [m, rad], velocity [m/s, rad/s], acceleration [m/s^2, rad/s^2], DOFs
        ``x, y, z, rx, ry, rz``.
    ground_displacement, ground_velocity, ground_acceleration : ndarray, shape (n, 3), or None
        Rigid translation of the foundation in body axes [m, m/s, m/s^2].
    Q : ndarray, shape (n, 6), or None
        Generalized force of the applied loads [N, N m] (ground motion not included).
    stats : sixdof.analysis.direct.SolverStats or None
        Direct solve: the solver's settings and step counts.
    superposition : sixdof.analysis.superposition.SuperpositionInfo or None
        Modal superposition: the method used, modes kept, truncation and approximation errors.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    ground_displacement: np.ndarray | None = None
    ground_velocity: np.ndarray | None = None
    ground_acceleration: np.ndarray | None = None
    Q: np.ndarray | None = None
    stats: Any = None
    superposition: Any = None

    def __post_init__(self) -> None:
        for name in ("t", "q", "qd", "qdd", "ground_displacement", "ground_velocity", "ground_acceleration", "Q"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, readonly(value))
        n = self.t.shape[0]
        for name, columns in (("q", 6), ("qd", 6), ("qdd", 6), ("Q", 6), ("ground_displacement", 3),
                              ("ground_velocity", 3), ("ground_acceleration", 3)):
            value = getattr(self, name)
            if value is not None and value.shape != (n, columns):
                raise InputError(name, f"shape ({n}, {columns})", f"shape {value.shape}")

    @property
    def has_ground(self) -> bool:
        """Whether the foundation moves."""
        return self.ground_displacement is not None

    def _relative(self, absolute: np.ndarray, ground: np.ndarray | None) -> np.ndarray:
        if ground is None:
            return absolute
        out = np.array(absolute)
        out[:, :3] -= ground
        out.flags.writeable = False
        return out

    @property
    def q_relative(self) -> np.ndarray:
        """Displacement relative to the ground, (n, 6) [m, rad] (rotations are the same)."""
        return self._relative(self.q, self.ground_displacement)

    @property
    def qd_relative(self) -> np.ndarray:
        """Velocity relative to the ground, (n, 6) [m/s, rad/s]."""
        return self._relative(self.qd, self.ground_velocity)

    @property
    def qdd_relative(self) -> np.ndarray:
        """Acceleration relative to the ground, (n, 6) [m/s^2, rad/s^2]."""
        return self._relative(self.qdd, self.ground_acceleration)

    def to_xarray(self):
        """The history as an :class:`xarray.Dataset` with dims ``t`` and ``dof`` (and ``axis`` for the
        ground), every variable carrying its ``units`` attribute. Needs xarray."""
        import xarray as xr

        dof_units = {"q": ("m", "rad"), "qd": ("m/s", "rad/s"), "qdd": ("m/s^2", "rad/s^2"), "Q": ("N", "N m")}
        variables = {}
        for name, (translation, rotation) in dof_units.items():
            value = getattr(self, name)
            if value is not None:
                variables[name] = xr.Variable(("t", "dof"), value, {
                    "units": f"{translation} (x, y, z); {rotation} (rx, ry, rz)",
                    "dof_units": [translation] * 3 + [rotation] * 3})
        for name, unit in (("ground_displacement", "m"), ("ground_velocity", "m/s"), ("ground_acceleration", "m/s^2")):
            value = getattr(self, name)
            if value is not None:
                variables[name] = xr.Variable(("t", "axis"), value, {"units": unit})
        coords = {"t": ("t", self.t, {"units": "s"}), "dof": ("dof", list(DOFS))}
        if self.has_ground:
            coords["axis"] = ("axis", list(AXES))
        return xr.Dataset(variables, coords=coords)


@dataclass(frozen=True, eq=False)
class RunResults:
    """Everything one run computed, as the library's typed objects: what ``results.h5`` holds.

    :func:`sixdof.io.store.write_results` writes it, :func:`sixdof.io.store.load_results` gives it back
    (the same types), and :func:`sixdof.plots.save_all` draws every figure it allows. Parts a run did
    not compute are ``None`` (or empty).

    Attributes
    ----------
    name, description : str
        The scenario's.
    system : sixdof.model.system.System or None
    modes : sixdof.analysis.modal.Modes or None
    damping_ratios : ndarray, shape (6,), or None
        Damping ratio of each mode (``nan`` for rigid-body modes).
    statics : sixdof.analysis.statics.Statics or None
    response : TimeHistory or None
        The direct solve.
    mount_forces : sixdof.analysis.response.MountForces or None
    points : mapping of str to sixdof.analysis.response.PointMotion
    superposition : TimeHistory or None
        The modal-superposition cross-check.
    agreement : sixdof.analysis.compare.Agreement or None
        ``superposition`` against ``response``.
    frf : sixdof.analysis.frf.FRFCrossCheck or sixdof.analysis.frf.FRF or None
    frf_extras : mapping of str to PointFRF, ForceTransmissibility or GroundTransmissibility
        Named point FRFs and transmissibilities on the frequencies of ``frf``.
    validation : sixdof.validation.ValidationReport or None
    provenance : mapping of str to str
        ``scenario_text``, ``created_utc``, ``command_line``, package versions.
    """

    name: str = ""
    description: str = ""
    system: Any = None
    modes: Any = None
    damping_ratios: np.ndarray | None = None
    statics: Any = None
    response: TimeHistory | None = None
    mount_forces: Any = None
    points: Any = field(default_factory=dict)
    superposition: TimeHistory | None = None
    agreement: Any = None
    frf: Any = None
    frf_extras: Any = field(default_factory=dict)
    validation: Any = None
    provenance: Any = field(default_factory=dict)
