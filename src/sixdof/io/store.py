"""The results file (HDF5): its layout, an atomic writer, and the reader.

A run's results are first collected into a :class:`Results` tree (:func:`build_results`): a flat
mapping from HDF5 paths (``"time/q"``) to :class:`Dataset` objects (array, units, named axes,
attributes) plus the attributes of each group. The same tree is written to the file
(:func:`save_results`) and read back from it (:func:`load_results`), so a loaded file and a live run
look alike: the figures of :mod:`sixdof.plots` take either.

Layout conventions (the file opens in ``xarray`` through ``h5netcdf``):

- every dataset has a ``units`` attribute: SI units, ``"1"`` for dimensionless numbers, ``""`` for
  text labels. Arrays mixing translations and rotations say which unit goes with which DOF
  (``"m (x, y, z); rad (rx, ry, rz)"``) and carry a machine-readable ``dof_units`` attribute;
- every axis of every dataset is named by an HDF5 dimension scale (a 1-D dataset of the same name in
  the same group or a parent group: ``/time/t``, ``/time/dof``, ``/modal/mode``...);
- complex arrays are HDF5 compound ``(r, i)`` (h5py's convention). h5py and h5netcdf (checked with
  1.8, and tested) read them back as complex, so no real/imaginary copies are stored; older netCDF
  readers without complex support see a compound type;
- the root holds the provenance: scenario text, package versions, creation time, command line.

Only this module imports h5py, and only inside the functions that read or write a file, so that
``import sixdof`` stays light.
"""

from __future__ import annotations

import datetime as _dt
import os
import shlex
import sys
import uuid
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from sixdof.dofs import AXES, DOF_UNITS, DOFS, LOADS, MOUNT_AXES
from sixdof.errors import InputError, Plain

#: Identifies the file layout; bump FORMAT_VERSION when a fixed name changes meaning.
FORMAT = "sixdof-results"
FORMAT_VERSION = 1

#: ``units`` of dimensionless numbers and of text labels.
UNITS_ONE = "1"
UNITS_LABEL = ""


#: Packages whose versions are recorded in every file.
PROVENANCE_PACKAGES: tuple[str, ...] = (
    "sixdof", "numpy", "scipy", "jax", "jaxlib", "diffrax", "equinox", "h5py",
)

# HDF5 / netCDF bookkeeping attributes that are not user attributes.
_RESERVED_ATTRS = frozenset(
    {"units", "CLASS", "NAME", "DIMENSION_LIST", "REFERENCE_LIST", "_Netcdf4Dimid",
     "_Netcdf4Coordinates", "_NCProperties"}
)


# ----------------------------------------------------------------------------------------------------
# The in-memory tree.
# ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Dataset:
    """One array of a results file.

    Attributes
    ----------
    data : ndarray
        Read-only array (float, int, complex, or str for labels).
    units : str
        SI units; ``"1"`` dimensionless, ``""`` text labels.
    dims : tuple of str
        Name of each axis; each name is a dimension-scale dataset of the same group or a parent.
    attrs : mapping
        Other attributes (str, int, float, tuple of str, or read-only arrays).
    """

    data: np.ndarray
    units: str
    dims: tuple[str, ...]
    attrs: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        data = np.asarray(self.data)
        if data.dtype.kind in "OSU":
            data = np.array(data, dtype=str)
        elif data.dtype.kind == "b":
            data = data.astype(np.int8)  # netCDF has no boolean type
        else:
            data = np.array(data)
        data.flags.writeable = False
        object.__setattr__(self, "data", data)
        if not isinstance(self.units, str):
            raise InputError("units", "a string", self.units)
        dims = tuple(self.dims)
        if len(dims) != data.ndim or not all(isinstance(d, str) and d for d in dims):
            raise InputError("dims", f"{data.ndim} non-empty axis names for shape {data.shape}", dims)
        object.__setattr__(self, "dims", dims)
        object.__setattr__(self, "attrs", _attributes(self.attrs))

    def __repr__(self) -> str:
        return f"Dataset(shape={self.data.shape}, dtype={self.data.dtype}, units={self.units!r}, dims={self.dims})"


@dataclass(frozen=True, eq=False)
class Results:
    """The content of a results file: datasets by path and the attributes of every group.

    ``results["time/q"]`` is the :class:`Dataset` at ``/time/q``; ``"time" in results`` tells whether
    the group exists; :attr:`attrs` maps each group path (``""`` for the root) to its attributes.
    Build one with :func:`build_results`, read one with :func:`load_results`.

    Attributes
    ----------
    datasets : mapping of str to Dataset
        Keys are paths without the leading slash (``"modal/frequency_hz"``).
    attrs : mapping of str to mapping
        Attributes of each group, keyed by group path (``""``, ``"time"``, ``"time/superposition"``).
    path : pathlib.Path or None
        The file it was read from or written to.
    """

    datasets: Mapping[str, Dataset]
    attrs: Mapping[str, Mapping[str, Any]]
    path: Path | None = None

    def __post_init__(self) -> None:
        datasets = {str(k).strip("/"): v for k, v in self.datasets.items()}
        for key, value in datasets.items():
            if not isinstance(value, Dataset):
                raise InputError(f"datasets[{key!r}]", "a Dataset", value)
        groups = {""}
        for key in datasets:
            parts = key.split("/")[:-1]
            groups.update("/".join(parts[:i]) for i in range(1, len(parts) + 1))
        attrs = {str(k).strip("/"): _attributes(v) for k, v in self.attrs.items()}
        groups.update(attrs)
        attrs = {g: attrs.get(g, MappingProxyType({})) for g in sorted(groups)}
        object.__setattr__(self, "datasets", MappingProxyType(dict(sorted(datasets.items()))))
        object.__setattr__(self, "attrs", MappingProxyType(attrs))
        _check_dims(self.datasets)

    # Mapping-like access ---------------------------------------------------------------------------
    def __getitem__(self, path: str) -> Dataset:
        try:
            return self.datasets[path.strip("/")]
        except KeyError:
            raise KeyError(f"no dataset {path!r} in the results; have: {', '.join(self.datasets)}") from None

    def __contains__(self, path: str) -> bool:
        path = path.strip("/")
        return path in self.datasets or path in self.attrs

    def get(self, path: str, default: Any = None) -> Dataset | Any:
        """The dataset at ``path``, or ``default`` when there is none."""
        return self.datasets.get(path.strip("/"), default)

    def array(self, path: str) -> np.ndarray:
        """The data of the dataset at ``path`` (read-only)."""
        return self[path].data

    @property
    def groups(self) -> tuple[str, ...]:
        """Paths of every group, the root ``""`` first."""
        return tuple(self.attrs)

    # Shortcuts used by figures and reports -----------------------------------------------------------
    @property
    def name(self) -> str:
        """The scenario name (``""`` when not recorded)."""
        return str(self.attrs[""].get("scenario_name", ""))

    @property
    def dofs(self) -> tuple[str, ...]:
        """DOF names in array order."""
        for path in ("model/dof", "modal/dof", "time/dof", "frf/dof"):
            if path in self.datasets:
                return tuple(self.datasets[path].data.tolist())
        return DOFS

    @property
    def mount_names(self) -> tuple[str, ...]:
        """Mount names, in the order of every per-mount array."""
        return tuple(self.array("model/mount").tolist()) if "model/mount" in self.datasets else ()

    @property
    def mount_positions(self) -> np.ndarray:
        """Mount positions from the CG in body axes, shape (n_mounts, 3) [m]."""
        return self.array("model/mount_position") if "model/mount_position" in self.datasets else np.zeros((0, 3))

    @property
    def body_dimensions(self) -> np.ndarray | None:
        """Box drawn for the body, [Lx, Ly, Lz] [m], or ``None`` when the scenario gave none."""
        dims = self.get("model/body_dimensions")
        return None if dims is None else dims.data


# ----------------------------------------------------------------------------------------------------
# Building the tree from the library's result objects.
# ----------------------------------------------------------------------------------------------------


class _Tree:
    """Collects datasets and group attributes; checks names while building."""

    def __init__(self) -> None:
        self.datasets: dict[str, Dataset] = {}
        self.attrs: dict[str, dict[str, Any]] = {"": {}}

    def add(self, path: str, data, units: str, dims, **attrs) -> None:
        if path in self.datasets:
            raise InputError(path, "a dataset path used once", Plain("a second dataset"))
        self.datasets[path] = Dataset(data, units, tuple(dims), attrs)

    def labels(self, group: str, name: str, values) -> None:
        """A dimension scale of text labels (``/group/name``)."""
        self.add(f"{group}/{name}", np.asarray(list(values), dtype=str), UNITS_LABEL, (name,))

    def set_attrs(self, group: str, **attrs) -> None:
        self.attrs.setdefault(group, {}).update({k: v for k, v in attrs.items() if v is not None})


def dof_units(order: int = 0) -> tuple[str, ...]:
    """Unit of each DOF of ``q`` (order 0), ``q'`` (1) or ``q''`` (2)."""
    suffix = ("", "/s", "/s^2")[order]
    return tuple(u + suffix for u in DOF_UNITS)


def _mixed(translation: str, rotation: str) -> str:
    """Units string of an array whose DOF axis mixes translations and rotations."""
    return f"{translation} (x, y, z); {rotation} (rx, ry, rz)"


#: ``units`` strings of the mixed-DOF quantities, one place for all.
UNITS = MappingProxyType({
    "q": _mixed("m", "rad"),
    "qd": _mixed("m/s", "rad/s"),
    "qdd": _mixed("m/s^2", "rad/s^2"),
    "Q": _mixed("N", "N m"),
    "M": "kg (translation block); kg m (coupling blocks); kg m^2 (rotation block)",
    "C": "N s/m (translation block); N s/rad and N s (coupling blocks); N m s/rad (rotation block)",
    "K": "N/m (translation block); N/rad and N (coupling blocks); N m/rad (rotation block)",
    "receptance": "m/N (x, y, z per Fx, Fy, Fz); rad/N and m/(N m) (coupling); rad/(N m) (rx, ry, rz per Mx, My, Mz)",
    "shapes": _mixed("kg^-1/2", "kg^-1/2 m^-1") + " (mass-normalized)",
    "effective_mass": _mixed("kg", "kg m^2"),
})


def build_results(
    *,
    system=None,
    modes=None,
    damping_ratios=None,
    statics=None,
    response=None,
    mount_forces=None,
    points: Mapping[str, Any] | None = None,
    superposition=None,
    agreement=None,
    frf=None,
    frf_extras: Mapping[str, Any] | None = None,
    validation=None,
    scenario_text: str | None = None,
    name: str | None = None,
    description: str | None = None,
    command_line: str | None = None,
    created_utc: str | None = None,
    extra: Mapping[str, Dataset] | None = None,
    extra_attrs: Mapping[str, Mapping[str, Any]] | None = None,
) -> Results:
    """Collect a run's results into a :class:`Results` tree (nothing is written).

    Every part is optional: a modal-only run passes ``system`` and ``modes`` and gets no ``/time``.

    Parameters
    ----------
    system : sixdof.model.system.System, optional
        Gives ``/model``: M, C, K (6, 6), the mounts (names, positions [m], stiffness [N/m],
        damping [N s/m], loss factors, axes) and the body (mass [kg], box dimensions [m]).
    modes : sixdof.analysis.modal.Modes, optional
        Gives ``/modal``.
    damping_ratios : array_like, shape (6,), optional
        Modal damping ratio of each mode (``nan`` for rigid-body modes), ``/modal/damping_ratio``.
    statics : sixdof.analysis.statics.Statics, optional
        Gives ``/statics``: deflection under gravity and each mount's force (needs ``system``).
    response : sixdof.results.TimeHistory, optional
        Gives ``/time``.
    superposition : sixdof.results.TimeHistory, optional
        The modal-superposition history (with its ``superposition`` information).
        Gives ``/time/superposition``.
    agreement : sixdof.analysis.superposition.Agreement, optional
        Stored as attributes of ``/time/superposition``.
    frf : sixdof.analysis.frf.FRF or sixdof.analysis.frf.FRFCrossCheck, optional
        Gives ``/frf``: frequencies and the 6x6 receptance (the direct one of a cross-check, whose
        differences go beside it).
    frf_extras : mapping of str to PointFRF, ForceTransmissibility or GroundTransmissibility
        Named point FRFs and transmissibilities on the same frequencies, under
        ``/frf/point/<name>``, ``/frf/force_transmissibility/<name>``,
        ``/frf/ground_transmissibility/<name>``.
    validation : sixdof.validation.ValidationReport, optional
        Gives ``/validation``.
    scenario_text, name, description : str, optional
        The scenario file's text, name and description (root attributes).
    command_line : str, optional
        Default: this process's command line.
    created_utc : str, optional
        ISO 8601 creation time; default: now (UTC).
    extra : mapping of str to Dataset, optional
        More datasets, by path; their axes must name existing or added dimension scales.
    extra_attrs : mapping of str to mapping, optional
        More attributes, by group path (``""`` is the root).

    Returns
    -------
    Results

    Raises
    ------
    sixdof.errors.InputError
        When a dataset's axes name no dimension scale, or lengths disagree.
    """
    tree = _Tree()
    _provenance(tree, scenario_text, name, description, command_line, created_utc)
    if system is not None:
        _model(tree, system)
    if modes is not None:
        _modal(tree, modes, damping_ratios)
    if statics is not None:
        if system is None:
            raise InputError("statics", "the system it belongs to", Plain("none"))
        _statics(tree, statics, system.mount_names)
    if response is not None:
        _time(tree, response)
    if (mount_forces is not None or points) and response is None:
        raise InputError("mount_forces" if mount_forces is not None else "points",
                         "the time response they come from", Plain("none"))
    if mount_forces is not None:
        _mount_forces(tree, mount_forces)
    if points:
        _points(tree, points)
    if superposition is not None or agreement is not None:
        if response is None:
            raise InputError("superposition", "a direct response to compare with", Plain("none"))
        _superposition(tree, superposition, agreement)
    if frf is not None:
        _frf(tree, frf, frf_extras)
    elif frf_extras:
        raise InputError("frf_extras", "a receptance (frf) whose frequencies they share", Plain("none"))
    if validation is not None:
        _validation(tree, validation)
    for path, dataset in (extra or {}).items():
        if not isinstance(dataset, Dataset):
            raise InputError(f"extra[{path!r}]", "a sixdof.io.store.Dataset", dataset)
        tree.datasets[path.strip("/")] = dataset
    for group, attrs in (extra_attrs or {}).items():
        tree.set_attrs(group.strip("/"), **attrs)
    return Results(tree.datasets, tree.attrs)


def _provenance(tree: _Tree, text, name, description, command_line, created_utc) -> None:
    if command_line is None:
        command_line = shlex.join([Path(sys.argv[0]).name, *sys.argv[1:]]) if sys.argv else ""
    if created_utc is None:
        created_utc = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    tree.set_attrs(
        "",
        format=FORMAT,
        format_version=FORMAT_VERSION,
        scenario_name=name or "",
        scenario_description=description or "",
        scenario_text=text or "",
        created_utc=created_utc,
        command_line=command_line,
        python_version=sys.version.split()[0],
        **{f"version_{p}": _version(p) for p in PROVENANCE_PACKAGES},
    )


def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


def _model(tree: _Tree, system) -> None:
    g = "model"
    tree.labels(g, "dof", DOFS)
    tree.labels(g, "load", LOADS)
    tree.labels(g, "mount", system.mount_names)
    tree.labels(g, "axis", AXES)
    tree.labels(g, "mount_axis", MOUNT_AXES)
    dofs = {"dof_units": DOF_UNITS}
    tree.add(f"{g}/M", system.M, UNITS["M"], ("load", "dof"), **dofs)
    tree.add(f"{g}/C", system.C, UNITS["C"], ("load", "dof"), **dofs)
    tree.add(f"{g}/K", system.K, UNITS["K"], ("load", "dof"), **dofs)
    tree.add(f"{g}/C_mounts", system.C_mounts, UNITS["C"], ("load", "dof"), **dofs,
             description="damping of the mounts' dashpots alone")
    tree.add(f"{g}/mount_position", system.positions, "m", ("mount", "axis"),
             description="mount attachment points from the CG in body axes")
    tree.add(f"{g}/mount_stiffness", system.stiffnesses, "N/m", ("mount", "mount_axis"),
             description="stiffness along each mount's own axes")
    tree.add(f"{g}/mount_damping", system.dampings, "N s/m", ("mount", "mount_axis"),
             description="viscous damping along each mount's own axes")
    tree.add(f"{g}/mount_loss_factor", system.loss_factors, UNITS_ONE, ("mount", "mount_axis"),
             description="hysteretic loss factor along each mount's own axes (frequency responses)")
    tree.add(f"{g}/mount_axes", system.axes, UNITS_ONE, ("mount", "mount_axis", "axis"),
             description="rows: each mount's unit axes u, v, w in body axes")
    tree.add(f"{g}/body_mass", np.float64(system.body.mass), "kg", ())
    if system.body.dimensions is not None:
        tree.add(f"{g}/body_dimensions", system.body.dimensions, "m", ("axis",),
                 description="size of the box drawn for the body, centred on the CG")
    rayleigh = system.rayleigh
    modal = system.modal_damping
    tree.set_attrs(
        g,
        rayleigh_alpha=None if rayleigh is None else rayleigh.alpha,
        rayleigh_beta=None if rayleigh is None else rayleigh.beta,
        modal_damping=None if modal is None else np.atleast_1d(np.asarray(modal, dtype=float)),
    )


def _modal(tree: _Tree, modes, damping_ratios) -> None:
    g = "modal"
    n = len(modes.frequency_hz)
    tree.labels(g, "dof", DOFS)
    tree.add(f"{g}/mode", np.arange(1, n + 1), UNITS_ONE, ("mode",),
             description="mode number, ascending frequency")
    tree.add(f"{g}/frequency_hz", modes.frequency_hz, "Hz", ("mode",))
    tree.add(f"{g}/omega", modes.omega, "rad/s", ("mode",))
    tree.add(f"{g}/eigenvalues", modes.eigenvalues, "rad^2/s^2", ("mode",))
    tree.add(f"{g}/shapes", modes.shapes, UNITS["shapes"], ("dof", "mode"),
             description="column j is mode j, mass-normalized: shapes.T @ M @ shapes = I")
    tree.add(f"{g}/ke_distribution", modes.ke_distribution, UNITS_ONE, ("dof", "mode"),
             description="share of each mode's kinetic energy in each DOF; columns sum to 1")
    tree.add(f"{g}/effective_mass", modes.effective_mass, UNITS["effective_mass"], ("dof", "mode"),
             dof_units=("kg", "kg", "kg", "kg m^2", "kg m^2", "kg m^2"))
    tree.add(f"{g}/dominant_dof", np.asarray(modes.dominant_dof, dtype=str), UNITS_LABEL, ("mode",),
             description="DOF holding the largest kinetic-energy share of each mode")
    if damping_ratios is not None:
        zeta = np.asarray(damping_ratios, dtype=float)
        if zeta.shape != (n,):
            raise InputError("damping_ratios", f"{n} damping ratios", zeta.shape)
        tree.add(f"{g}/damping_ratio", zeta, UNITS_ONE, ("mode",),
                 description="modal damping ratio (nan for rigid-body modes)")
    tree.set_attrs(
        g,
        subsystems=tuple(",".join(s) for s in modes.subsystems),
        rigid_body_modes=np.asarray([j + 1 for j in modes.zero_modes], dtype=np.int64),
        free_dofs=tuple(modes.free_dofs),
    )


def _statics(tree: _Tree, statics, mount_names) -> None:
    g = "statics"
    tree.labels(g, "dof", DOFS)
    tree.labels(g, "axis", AXES)
    tree.labels(g, "mount", mount_names)
    tree.labels(g, "mount_axis", MOUNT_AXES)
    tree.add(f"{g}/gravity", statics.gravity, "m/s^2", ("axis",), description="gravity in body axes")
    tree.add(f"{g}/q", statics.q, _mixed("m", "rad"), ("dof",), dof_units=dof_units(0),
             description="static deflection under gravity from the unloaded state")
    tree.add(f"{g}/mount_force", statics.mount_forces, "N", ("mount", "axis"),
             description="force of each mount on the body, body axes")
    tree.add(f"{g}/mount_force_local", statics.mount_forces_local, "N", ("mount", "mount_axis"),
             description="force of each mount on the body, along the mount's own axes")
    tree.add(f"{g}/support", statics.support, "N", ("mount",),
             description="force against gravity: > 0 compression, < 0 tension (uplift)")
    tree.set_attrs(g, uplift=tuple(statics.uplift))


def _time(tree: _Tree, response) -> None:
    g = "time"
    tree.add(f"{g}/t", response.t, "s", ("t",))
    tree.labels(g, "dof", DOFS)
    for order, key in enumerate(("q", "qd", "qdd")):
        tree.add(f"{g}/{key}", getattr(response, key), UNITS[key], ("t", "dof"), dof_units=dof_units(order),
                 description="absolute motion of the centre of gravity (fixed frame)")
    ground = [getattr(response, f"ground_{k}", None) for k in ("displacement", "velocity", "acceleration")]
    # Relative motion and the ground's own only when the ground moves (otherwise they repeat q or are 0).
    if any(a is not None and np.any(np.asarray(a) != 0) for a in ground):
        tree.labels(g, "axis", AXES)
        for order, key in enumerate(("q", "qd", "qdd")):
            tree.add(f"{g}/{key}_relative", getattr(response, f"{key}_relative"), UNITS[key], ("t", "dof"),
                     dof_units=dof_units(order), description="motion of the centre of gravity relative to the ground")
        for key, values, unit in zip(("displacement", "velocity", "acceleration"), ground, ("m", "m/s", "m/s^2")):
            tree.add(f"{g}/ground_{key}", values, unit, ("t", "axis"),
                     description=f"foundation {key} in body axes")
    if getattr(response, "Q", None) is not None:
        tree.labels(g, "load", LOADS)
        tree.add(f"{g}/Q", response.Q, UNITS["Q"], ("t", "load"),
                 description="generalized force of the applied loads (ground motion not included)")
    stats = getattr(response, "stats", None)
    if stats is not None:
        tree.set_attrs(g, **{k if k == "solver" else f"solver_{k}": v for k, v in _fields(stats).items()})


def _mount_forces(tree: _Tree, forces) -> None:
    g = "time"
    tree.labels(g, "mount", forces.names)
    if f"{g}/axis" not in tree.datasets:
        tree.labels(g, "axis", AXES)
    tree.labels(g, "mount_axis", MOUNT_AXES)
    dims = ("mount", "t", "axis")
    on = "exerted by each mount on the foundation, body axes (dynamic part about static equilibrium)"
    tree.add(f"{g}/mount_force", forces.total, "N", dims, description=f"force {on}")
    tree.add(f"{g}/mount_force_elastic", forces.elastic, "N", dims, description=f"spring force {on}")
    tree.add(f"{g}/mount_force_damping", forces.damping, "N", dims, description=f"dashpot force {on}")
    tree.add(f"{g}/mount_force_local", forces.local, "N", ("mount", "t", "mount_axis"),
             description="mount_force along each mount's own axes u, v, w")
    tree.add(f"{g}/mount_deformation", forces.deformation, "m", dims,
             description="displacement of each mount's body point relative to the ground, body axes")
    if f"{g}/load" not in tree.datasets:
        tree.labels(g, "load", LOADS)
    tree.add(f"{g}/other_damping_force", forces.other_damping, UNITS["Q"], ("t", "load"),
             description="generalized force of Rayleigh and modal damping (C - C_mounts) q_rel'")
    tree.add(f"{g}/foundation_force", forces.foundation_force, "N", ("t", "axis"),
             description="total force on the foundation, body axes")
    tree.add(f"{g}/foundation_moment", forces.foundation_moment, "N m", ("t", "axis"),
             description="total moment on the foundation about the CG rest position, body axes")


def _points(tree: _Tree, points: Mapping[str, Any]) -> None:
    g = "time"
    motions = list(points.values())
    tree.labels(g, "point", points.keys())
    if f"{g}/axis" not in tree.datasets:
        tree.labels(g, "axis", AXES)
    tree.add(f"{g}/point_position", np.stack([m.position for m in motions]), "m", ("point", "axis"),
             description="body points from the CG, body axes")
    tree.add(f"{g}/point_relative", np.array([bool(m.relative) for m in motions]), UNITS_ONE, ("point",),
             description="1: the point's motion is relative to the ground, 0: absolute")
    for key, unit in (("displacement", "m"), ("velocity", "m/s"), ("acceleration", "m/s^2")):
        tree.add(f"{g}/point_{key}", np.stack([getattr(m, key) for m in motions]), unit, ("point", "t", "axis"),
                 description=f"{key} of each body point, body axes")


def _fields(obj) -> dict[str, Any]:
    """Public fields of a (data)class instance, for attributes."""
    import dataclasses

    if dataclasses.is_dataclass(obj):
        return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}
    return {k: v for k, v in vars(obj).items() if not k.startswith("_")}


def _agreement_attrs(prefix: str, agreement) -> dict[str, Any]:
    """Attributes of a :class:`sixdof.analysis.superposition.Agreement`, names starting with ``prefix``."""
    if agreement is None:
        return {}
    values = {
        "per_dof": np.asarray(agreement.per_dof, dtype=float),
        "worst_dof": str(agreement.worst_dof),
        "worst": float(agreement.worst),
        "tolerance": float(agreement.tolerance),
        "ok": int(bool(agreement.ok)),
        "peak": getattr(agreement, "peak", None),
        "quiet": tuple(getattr(agreement, "quiet", ())),
        "length": getattr(agreement, "length", None),
    }
    return {f"{prefix}_{k}": v for k, v in values.items() if v is not None}


def _superposition(tree: _Tree, modal, agreement) -> None:
    g = "time/superposition"
    if modal is not None:
        for order, key in enumerate(("q", "qd", "qdd")):
            tree.add(f"{g}/{key}", getattr(modal, key), UNITS[key], ("t", "dof"), dof_units=dof_units(order))
        modal = modal.superposition
        tree.set_attrs(
            g,
            method=getattr(modal, "method", None),
            method_reason=getattr(modal, "reason", None),
            damping_coupling=getattr(modal, "coupling", None),
            modes_kept=None if getattr(modal, "modes_kept", None) is None
            else np.asarray([j + 1 for j in modal.modes_kept], dtype=np.int64),
            residual_correction=getattr(modal, "residual", None),
            residual_rates=getattr(modal, "residual_rates", None),
            frame="absolute",  # like /time/q
            n_intervals=getattr(modal, "n_intervals", None),
            quadrature_nodes=getattr(modal, "quadrature_nodes", None),
            **_agreement_attrs("truncation", getattr(modal, "truncation", None)),
            **_agreement_attrs("approximation", getattr(modal, "approximation", None)),
        )
    if agreement is not None:
        tree.set_attrs(
            g,
            **_agreement_attrs("agreement", agreement),
            agreement_definition="per DOF: max_t |q_direct - q_modal| / max_t |q_direct| "
            "(quiet DOFs: / the largest peak, rotations times agreement_length)",
        )


def _frf(tree: _Tree, frf, extras) -> None:
    g = "frf"
    check = None
    if hasattr(frf, "direct") and hasattr(frf, "modal"):  # an FRFCrossCheck: store the direct one
        check, frf = frf, frf.direct
    tree.add(f"{g}/f_hz", frf.f_hz, "Hz", ("f_hz",))
    tree.labels(g, "dof", DOFS)
    tree.labels(g, "load", LOADS)
    tree.add(f"{g}/receptance", frf.H, UNITS["receptance"], ("f_hz", "dof", "load"),
             description="[f, i, j]: q_i per generalized force Q_j, H = (K + i K_h - w^2 M + i w C)^-1",
             method=getattr(frf, "method", None), basis=getattr(frf, "basis", None))
    if check is not None:
        tree.add(f"{g}/cross_check_relative_difference", check.relative_difference, UNITS_ONE, ("dof", "load"),
                 description="direct vs modal receptance: max_f |H_direct - H_modal| / max_f sqrt(|H_ii H_jj|)")
        tree.set_attrs(g, cross_check_max_relative_difference=float(check.max_relative_difference),
                       cross_check_modal_basis=check.modal.basis)
    for name, item in (extras or {}).items():
        _frf_extra(tree, g, name, item, len(frf.f_hz))


def _frf_extra(tree: _Tree, g: str, name: str, item, nf: int) -> None:
    """A named point FRF or transmissibility, in its own group under ``/frf``."""
    if "/" in name or not name:
        raise InputError(f"frf_extras[{name!r}]", "a name without '/'", name)
    if len(item.f_hz) != nf or not np.array_equal(item.f_hz, tree.datasets[f"{g}/f_hz"].data):
        raise InputError(f"frf_extras[{name!r}].f_hz", "the frequencies of the receptance",
                             Plain(f"{len(item.f_hz)} other frequencies"))
    kind = type(item).__name__
    if hasattr(item, "values"):  # PointFRF
        sub = f"{g}/point/{name}"
        tree.add(f"{sub}/values", item.values, item.unit, ("f_hz",), quantity=item.quantity)
        tree.set_attrs(sub, kind=kind, quantity=item.quantity, load_point=item.load_point,
                       load_direction=item.load_direction, load_kind=item.load_kind,
                       response_point=item.response_point, response_direction=item.response_direction,
                       response_kind=item.response_kind, method=item.method)
    elif hasattr(item, "mount_forces"):  # ForceTransmissibility
        sub = f"{g}/force_transmissibility/{name}"
        if f"{g}/mount" not in tree.datasets:
            tree.labels(g, "mount", item.mount_names)
            tree.labels(g, "axis", AXES)
        per = "N/(N m)" if item.load_kind == "moment" else "N/N"
        tree.add(f"{sub}/mount_forces", item.mount_forces, per, ("f_hz", "mount", "axis"),
                 description="each mount's force on the foundation in body axes per unit load")
        tree.add(f"{sub}/total", item.total, f"{per} (Fx, Fy, Fz); {per} m (Mx, My, Mz)", ("f_hz", "load"),
                 description="resultant force and moment (about the CG rest position) on the foundation")
        tree.add(f"{sub}/transmissibility", item.transmissibility, per, ("f_hz",),
                 description="|resultant foundation force| per unit load")
        tree.set_attrs(sub, kind=kind, load_point=item.load_point, load_direction=item.load_direction,
                       load_kind=item.load_kind, method=item.method)
    elif hasattr(item, "relative"):  # GroundTransmissibility
        sub = f"{g}/ground_transmissibility/{name}"
        if f"{g}/axis" not in tree.datasets:
            tree.labels(g, "axis", AXES)
        tree.add(f"{sub}/q", item.q, _mixed("m/m", "rad/m"), ("f_hz", "dof"),
                 description="absolute generalized motion per unit ground displacement")
        tree.add(f"{sub}/absolute", item.absolute, "m/m", ("f_hz", "axis"))
        tree.add(f"{sub}/relative", item.relative, "m/m", ("f_hz", "axis"))
        tree.add(f"{sub}/transmissibility", item.transmissibility, "m/m", ("f_hz",),
                 description="|absolute motion along the ground direction| per unit ground motion")
        tree.set_attrs(sub, kind=kind, ground_direction=item.ground_direction,
                       response_point=item.response_point, method=item.method)
    else:
        raise InputError(f"frf_extras[{name!r}]", "a PointFRF, ForceTransmissibility or GroundTransmissibility", item)


def _validation(tree: _Tree, report) -> None:
    """``/validation``: the modal results against time histories (free decays, H1 estimates).

    The table's columns are stored generically (every field of its rows, one dataset per column
    over the ``mode`` axis; ``*_hz`` in Hz, the rest dimensionless), so new columns follow.
    """
    g = "validation"
    rows = tuple(report.rows)
    tree.add(f"{g}/mode", np.array([r.mode for r in rows], dtype=np.int64), UNITS_ONE, ("mode",),
             description="elastic modes checked (mode numbers of /modal/mode)")
    for key in _fields(rows[0]) if rows else ():
        if key == "mode":
            continue
        values = [getattr(r, key) for r in rows]
        if all(isinstance(v, str) for v in values):
            tree.add(f"{g}/{key}", np.array(values, dtype=str), UNITS_LABEL, ("mode",))
        else:
            tree.add(f"{g}/{key}", np.array(values, dtype=float), "Hz" if key.endswith("_hz") else UNITS_ONE,
                     ("mode",))
    tree.set_attrs(
        g, load_point=report.load_point, load_direction=report.load_direction,
        random_duration_s=float(report.random_duration_s), wall_time_s=float(report.wall_time_s),
        notes=tuple(report.notes),
    )
    per_force = "kg^1/2 m/N"
    for run in getattr(report, "random_runs", ()):
        sub = f"{g}/random/mode_{run.mode}"
        est = run.estimated
        tree.add(f"{sub}/f_hz", est.f_hz, "Hz", ("f_hz",), description="Welch frequency bins")
        tree.add(f"{sub}/H1", np.asarray(est.H1).reshape(len(est.f_hz), -1)[:, 0], per_force, ("f_hz",),
                 description=f"H1 estimate of modal coordinate eta_{run.mode} per unit random force")
        tree.add(f"{sub}/coherence", np.asarray(est.coherence).reshape(len(est.f_hz), -1)[:, 0], UNITS_ONE,
                 ("f_hz",))
        tree.add(f"{sub}/model", np.asarray(run.model).reshape(len(est.f_hz), -1)[:, 0], per_force, ("f_hz",),
                 description="model FRF of the same, with the first-order hold of the sampled force")
        tree.set_attrs(sub, mode=int(run.mode), band_hz=np.asarray(run.band_hz, dtype=float),
                       averages=int(est.averages), effective_averages=float(est.effective_averages),
                       nperseg=int(est.nperseg), sample_rate_hz=float(est.sample_rate_hz))
    if report.decays:
        tree.labels(g, "dof", DOFS)
    for decay in report.decays:
        sub = f"{g}/decay/mode_{decay.mode}"
        tree.add(f"{sub}/t", decay.history.t, "s", ("t",))
        tree.add(f"{sub}/eta", decay.eta, "kg^1/2 m", ("t",), description="modal coordinate phi_r' M q")
        tree.add(f"{sub}/q", decay.history.q, UNITS["q"], ("t", "dof"), dof_units=dof_units(0))
        est = decay.estimate
        tree.add(f"{sub}/extremum", np.arange(len(est.extrema_t)), UNITS_ONE, ("extremum",))
        tree.add(f"{sub}/extrema_t", est.extrema_t, "s", ("extremum",))
        tree.add(f"{sub}/extrema_value", est.extrema_value, "kg^1/2 m", ("extremum",))
        tree.set_attrs(sub, mode=int(decay.mode), f_damped_hz=float(est.f_damped_hz), zeta=float(est.zeta),
                       log_decrement=float(est.log_decrement))


# ----------------------------------------------------------------------------------------------------
# Checks and normalization shared by building and reading.
# ----------------------------------------------------------------------------------------------------


def _attributes(attrs: Mapping[str, Any]) -> Mapping[str, Any]:
    """Attributes in the form they come back from a file (so that round trips compare equal)."""
    out = {}
    for key, value in dict(attrs).items():
        if value is None:
            continue
        if not isinstance(key, str) or not key or key in _RESERVED_ATTRS:
            raise InputError("attrs", "attribute names other than units and HDF5's own", key)
        out[key] = _attribute(key, value)
    return MappingProxyType(out)


def _attribute(key: str, value: Any) -> Any:
    if isinstance(value, (str, np.str_)):
        return str(value)
    if isinstance(value, (bool, np.bool_)):
        return int(value)  # netCDF has no boolean attribute
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, (list, tuple)) and any(isinstance(v, str) for v in value) and not all(
        isinstance(v, str) for v in value
    ):
        # NumPy would turn the numbers into text silently.
        raise InputError(f"attrs[{key!r}]", "a string, a number or an array of numbers or strings", value)
    array = np.asarray(value)
    if array.ndim == 0 and array.dtype.kind in "biufcUS":
        return _attribute(key, array.item())
    if array.dtype.kind in "OSU" or (array.size == 0 and isinstance(value, tuple)):
        if array.ndim != 1 or not all(isinstance(v, (str, np.str_)) for v in array.tolist()):
            raise InputError(f"attrs[{key!r}]", "a string, a number or an array of numbers or strings", value)
        return tuple(str(v) for v in array.tolist())
    if array.dtype.kind == "b":
        array = array.astype(np.int8)
    if array.dtype.kind not in "iuf":
        raise InputError(f"attrs[{key!r}]", "a string, a number or an array of numbers or strings", value)
    array = np.array(array)
    array.flags.writeable = False
    return array


def _check_dims(datasets: Mapping[str, Dataset]) -> None:
    """Every axis names a 1-D dimension scale of its length in its group or a parent group."""
    for path, dataset in datasets.items():
        for axis, (dim, length) in enumerate(zip(dataset.dims, dataset.data.shape)):
            scale = _scale_path(datasets, path, dim)
            if scale is None:
                raise InputError(
                    f"{path}.dims[{axis}]",
                    f"the name of a dimension-scale dataset '{dim}' in its group or a parent group",
                    dim,
                )
            if datasets[scale].data.shape != (length,):
                raise InputError(
                    f"{path}.dims[{axis}]", f"scale '{scale}' of length {length}", datasets[scale].data.shape
                )


def _scale_path(datasets: Mapping[str, Dataset], path: str, dim: str) -> str | None:
    """Path of the dimension scale ``dim`` seen from dataset ``path`` (nearest group first)."""
    parts = path.split("/")[:-1]
    for i in range(len(parts), -1, -1):
        candidate = "/".join([*parts[:i], dim])
        found = datasets.get(candidate)
        if found is not None and found.dims == (dim,):
            return candidate
    return None


def _is_scale(path: str, dataset: Dataset) -> bool:
    return dataset.dims == (path.rsplit("/", 1)[-1],)


# ----------------------------------------------------------------------------------------------------
# Writing (atomic) and reading.
# ----------------------------------------------------------------------------------------------------


def write_results(path: str | os.PathLike, **parts) -> Results:
    """Build the results of a run (see :func:`build_results`) and write them atomically to ``path``.

    Parameters
    ----------
    path : str or path-like
        The results file (``outputs/<name>/results.h5``); its folder is created when missing.
    **parts
        The keyword arguments of :func:`build_results` (``system``, ``modes``, ``response``, ...).

    Returns
    -------
    Results
        What was written, with :attr:`Results.path` set: hand it to :func:`sixdof.plots.save_all`
        so that live figures and figures redrawn from the file come from the same data.
    """
    results = build_results(**parts)
    written = save_results(results, path)
    return Results(results.datasets, results.attrs, written)


def save_results(results: Results, path: str | os.PathLike) -> Path:
    """Write a :class:`Results` tree to ``path`` atomically.

    The file is written under a temporary name in the same folder, flushed to disk (fsync) and
    renamed over ``path`` in one step (:func:`os.replace`). On any failure, including
    ``KeyboardInterrupt``, the temporary file is removed and an existing ``path`` is left untouched:
    a reader never sees a half-written results file.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    import h5py

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        with h5py.File(temporary, "x") as f:
            _write(f, results)
        # h5py has closed the file: force its bytes to disk before the rename makes it visible.
        with open(temporary, "rb+") as handle:
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    _fsync_directory(path.parent)
    return path


def _fsync_directory(directory: Path) -> None:
    """Make the rename itself durable (POSIX); silently skipped where folders cannot be opened."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _write(f, results: Results) -> None:
    for group, attrs in results.attrs.items():
        node = f.require_group(group) if group else f
        for key, value in attrs.items():
            _write_attribute(node, key, value)
    created = {}
    for path, dataset in results.datasets.items():
        created[path] = _write_dataset(f, path, dataset)
    # Scales first, then attach: h5py refuses to attach a dataset that is not yet a scale.
    for path, dataset in results.datasets.items():
        if _is_scale(path, dataset):
            created[path].make_scale(dataset.dims[0])
    for path, dataset in results.datasets.items():
        if _is_scale(path, dataset):
            continue
        for axis, dim in enumerate(dataset.dims):
            created[path].dims[axis].attach_scale(created[_scale_path(results.datasets, path, dim)])


def _write_dataset(f, path: str, dataset: Dataset):
    import h5py

    data = dataset.data
    if data.dtype.kind == "U":
        node = f.create_dataset(path, data=data.astype(object), dtype=h5py.string_dtype())
    else:
        node = f.create_dataset(path, data=data)
    node.attrs["units"] = dataset.units
    for key, value in dataset.attrs.items():
        _write_attribute(node, key, value)
    return node


def _write_attribute(node, key: str, value: Any) -> None:
    import h5py

    if isinstance(value, tuple):
        node.attrs[key] = np.asarray(value, dtype=object).astype(h5py.string_dtype()) if value else np.array(
            [], dtype=h5py.string_dtype()
        )
    else:
        node.attrs[key] = value


def load_results(path: str | os.PathLike) -> Results:
    """Read a results file written by :func:`write_results`.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    Results
        Every dataset (read-only arrays with units and axis names) and every group's attributes.

    Raises
    ------
    sixdof.errors.InputError
        If the file is missing or is not a sixdof results file.
    """
    import h5py

    path = Path(path)
    if not path.is_file():
        raise InputError("results", "an existing results file (.h5)", str(path))
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise InputError("results", "an HDF5 results file written by sixdof", Plain(f"{path} ({exc})")) from None
    with f:
        if f.attrs.get("format") != FORMAT:
            raise InputError("results", f"an HDF5 file with format = {FORMAT!r}", Plain(f"{path} without it"))
        datasets: dict[str, Dataset] = {}
        attrs: dict[str, dict[str, Any]] = {"": _read_attributes(f.attrs)}

        def visit(name: str, node) -> None:
            if isinstance(node, h5py.Group):
                attrs[name] = _read_attributes(node.attrs)
                return
            if node.dtype.kind == "O" or h5py.check_string_dtype(node.dtype) is not None:
                data = np.array(node.asstr()[()], dtype=str)
            else:
                data = node[()]
            if node.is_scale:
                dims = (name.rsplit("/", 1)[-1],)
            else:
                dims = tuple(node.dims[i][0].name.rsplit("/", 1)[-1] for i in range(node.ndim))
            units = node.attrs.get("units", UNITS_LABEL)
            datasets[name] = Dataset(data, str(units), dims, _read_attributes(node.attrs))

        f.visititems(visit)
    return Results(datasets, attrs, path)


def _read_attributes(attrs) -> dict[str, Any]:
    out = {}
    for key, value in attrs.items():
        if key in _RESERVED_ATTRS:
            continue
        if isinstance(value, bytes):
            value = value.decode()
        elif isinstance(value, np.ndarray) and value.dtype.kind == "O":
            value = tuple(v.decode() if isinstance(v, bytes) else str(v) for v in value.tolist())
        out[key] = value
    return out


# ----------------------------------------------------------------------------------------------------
# Sweeps of design variants (sixdof.analysis.batch), ``outputs/<name>/sweep.h5``.
# ----------------------------------------------------------------------------------------------------


def write_sweep(path: str | os.PathLike, result, *, system=None, scenario_text: str | None = None,
                name: str | None = None, description: str | None = None) -> Results:
    """Write a :class:`sixdof.analysis.batch.BatchResult` atomically under ``/sweep`` (and ``/model``).

    Layout: ``/sweep/frequency_hz`` (variant, mode) [Hz]; ``/sweep/stiffness_factor`` and
    ``/sweep/damping_factor`` (variant, mount, mount_axis) [1]; ``/sweep/position_offset``
    (variant, mount, axis) [m]; with a simulation also ``/sweep/peak_q`` (variant, dof) [m, rad],
    ``/sweep/peak_qdd`` [m/s^2, rad/s^2] and ``/sweep/num_steps`` (variant). Every dataset has
    ``units``; ``/sweep`` holds the count and the solver settings as attributes.

    Returns
    -------
    Results
        What was written (path set).
    """
    tree = _Tree()
    g = "sweep"
    variants = result.variants
    nv, n_mounts = variants.stiffness_factor.shape[:2]
    mount_names = system.mount_names if system is not None else tuple(str(i + 1) for i in range(n_mounts))
    tree.add(f"{g}/variant", np.arange(nv), UNITS_ONE, ("variant",), description="variant index")
    tree.add(f"{g}/mode", np.arange(1, 7), UNITS_ONE, ("mode",),
             description="mode number, ascending frequency")
    tree.labels(g, "dof", DOFS)
    tree.labels(g, "mount", mount_names)
    tree.labels(g, "axis", AXES)
    tree.labels(g, "mount_axis", MOUNT_AXES)
    tree.add(f"{g}/frequency_hz", result.frequency_hz, "Hz", ("variant", "mode"),
             description="undamped natural frequencies of each variant")
    tree.add(f"{g}/stiffness_factor", variants.stiffness_factor, UNITS_ONE,
             ("variant", "mount", "mount_axis"), description="factor on each mount's stiffness")
    tree.add(f"{g}/damping_factor", variants.damping_factor, UNITS_ONE,
             ("variant", "mount", "mount_axis"), description="factor on each mount's dashpot")
    tree.add(f"{g}/position_offset", variants.position_offset, "m", ("variant", "mount", "axis"),
             description="offset added to each mount's position, body axes")
    attrs: dict[str, Any] = {"count": int(nv), "wall_time_s": float(result.wall_time_s)}
    if result.peak_q is not None:
        tree.add(f"{g}/peak_q", result.peak_q, UNITS["q"], ("variant", "dof"),
                 dof_units=dof_units(0), description="max |q| over the output samples")
        tree.add(f"{g}/peak_qdd", result.peak_qdd, UNITS["qdd"], ("variant", "dof"),
                 dof_units=dof_units(2), description="max |q''| over the output samples")
        tree.add(f"{g}/num_steps", np.asarray(result.num_steps, dtype=np.int64), UNITS_ONE,
                 ("variant",), description="solver steps attempted")
        s = result.settings
        attrs.update(solver=s.solver, rtol=s.rtol, atol=s.atol, duration=s.duration,
                     sample_rate_hz=s.sample_rate_hz, chunk_size=int(result.chunk_size))
    tree.set_attrs(g, **attrs)
    results = build_results(system=system, scenario_text=scenario_text, name=name,
                            description=description, extra=tree.datasets, extra_attrs=tree.attrs)
    written = save_results(results, path)
    return Results(results.datasets, results.attrs, written)
