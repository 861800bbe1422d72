"""Results that describe themselves, and the one time-history type of sixdof.

Every stored field of a result class says, once, where it goes and what it is: :func:`quantity`
(an array with its units and named axes), :func:`label` (a scalar or text kept as an attribute),
:func:`part` (a nested result) and :func:`parts` (named nested results). The HDF5 store
(:mod:`sixdof.io.store`) writes and reads every result generically from these descriptions, so a
field added to a result is stored and read back without touching the store.

The direct solve (:func:`sixdof.analysis.direct.simulate`), the modal superposition
(:func:`sixdof.analysis.superposition.superpose`), the validation's free decays and the batch
engine's kept variants all return a :class:`TimeHistory`; :func:`sixdof.analysis.compare.compare`
takes two of them. What only one method knows rides along in an optional part: the direct solver's
statistics (``stats``) or the superposition's method and truncation (``superposition``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import MISSING, dataclass, field
from typing import Any

import numpy as np

from sixdof.dofs import AXES, DOFS, LOADS, MOUNT_AXES, UNITS, MixedUnits, motion_units, unit_attrs
from sixdof.errors import InputError, Plain, readonly
from sixdof.frozen import BriefRepr, Frozen

# ----------------------------------------------------------------------------------------------------
# Field descriptions.
# ----------------------------------------------------------------------------------------------------


#: The registered result classes, by name (see :func:`result_type`).
_RESULT_TYPES: dict[str, type] = {}


def result_type(cls: type) -> type:
    """Register the result class ``cls`` under its name (a class decorator), so that fields of results in this
    and lower layers can name it (:func:`part` ``("Modes")``) without importing its layer, and the store can
    read it back. The name is also the ``kind`` attribute of :func:`parts` in the file: it must stay stable."""
    known = _RESULT_TYPES.setdefault(cls.__name__, cls)
    if known is not cls:
        raise TypeError(f"result type {cls.__name__!r}: registered already by {known.__module__}, "
                        f"not also by {cls.__module__}")
    return cls


def result_class(ref: type | str | Callable[[], type]) -> type:
    """The class a field names: a class, the name of a registered one (:func:`result_type`), or a function
    returning a class (a class defined later in its module)."""
    if isinstance(ref, type):
        return ref
    if isinstance(ref, str):
        try:
            return _RESULT_TYPES[ref]
        except KeyError:
            raise LookupError(f"no result type {ref!r} is registered: the module defining it is not imported "
                              "(sixdof.io.store imports every one a results file holds)") from None
    return ref()


def _same(value: Any) -> Any:
    """The stored form of a field that needs no converter."""
    return value


def _field(store: dict, default: Any, default_factory: Any, check: Callable | None = None) -> Any:
    """A dataclass field with its storage description and its check (see :mod:`sixdof.frozen`)."""
    return field(default=default, default_factory=default_factory, metadata={"store": store, "check": check})


def quantity(units: str | MixedUnits | Callable, dims: tuple[str, ...], *, name: str | None = None,
             description: str = "", default: Any = MISSING, default_factory: Any = MISSING,
             encode: Callable | None = None, decode: Callable | None = None, check: Callable | None = None) -> Any:
    """A dataclass field holding an array: its ``units`` (SI, ``"1"`` dimensionless, ``""`` text
    labels, :class:`~sixdof.dofs.MixedUnits` where translations and rotations mix, or a function of the
    result returning one of these), the name of each axis (``dims``), and optionally its stored ``name``,
    a ``description`` (text, or a function of the result returning it), converters to and from the stored
    array, and the field's validation ``check`` (see :mod:`sixdof.frozen`)."""
    return _field({"kind": "quantity", "units": units, "dims": tuple(dims), "name": name,
                   "description": description, "encode": encode or _same,
                   "decode": decode or _same}, default, default_factory, check)


def label(*, name: str | None = None, default: Any = MISSING, encode: Callable | None = None,
          decode: Callable | None = None, check: Callable | None = None) -> Any:
    """A dataclass field holding a number, a string, a tuple of strings or a small vector, stored as an
    attribute of its group (under ``name``, default the field's name)."""
    return _field({"kind": "label", "name": name, "encode": encode or _same, "decode": decode or _same}, default,
                  MISSING, check)


def part(cls: type | str | Callable[[], type], *, group: str | None = None, prefix: str | None = None,
         default: Any = MISSING, check: Callable | None = None) -> Any:
    """A dataclass field holding a nested result of the class ``cls`` (see :func:`result_class`: a class of a
    higher layer is named by its registered name), stored in the subgroup ``group`` or, with ``prefix``,
    flattened into attributes of the same group named ``prefix + field``."""
    return _field({"kind": "part", "cls": cls, "group": group, "prefix": prefix}, default, MISSING, check)


def parts(classes: tuple[str, ...], *, group: str, default_factory: Any = MISSING,
          default: Any = MISSING) -> Any:
    """A dataclass field holding named nested results (a mapping name -> result), each in the
    subgroup ``group/<its class's group>/<name>`` with its class's name as the ``kind`` attribute;
    ``classes`` are the names of the registered classes (:func:`result_type`) it may hold."""
    return _field({"kind": "parts", "classes": classes, "group": group}, default, default_factory)


def stacked(cls: type | str | Callable[[], type], *, dim: str, prefix: str = "", key: str | None = None,
            group: str | None = None, default: Any = MISSING, default_factory: Any = MISSING,
            check: Callable | None = None) -> Any:
    """A dataclass field holding several results of one class ``cls`` (see :func:`part`): a mapping name ->
    result, or a tuple of results named by their attribute ``key``, stored as one array per field with a
    leading axis ``dim`` whose labels are the names, under ``prefix + field`` (in the subgroup
    ``group`` when given)."""
    return _field({"kind": "stacked", "cls": cls, "dim": dim, "prefix": prefix, "key": key, "group": group}, default,
                  default_factory, check)


def sequence(cls: type | str | Callable[[], type], *, group: str, key: Callable[[Any], str],
             default: Any = MISSING) -> Any:
    """A dataclass field holding a tuple of results of one class ``cls`` (see :func:`part`), each in the subgroup
    ``group/<key(result)>``, read back in the natural order of those names."""
    return _field({"kind": "sequence", "cls": cls, "group": group, "key": key}, default, MISSING)


def descriptions(cls: type, result: Any = None) -> list[tuple[str, dict]]:
    """(name, storage description) of each described field of ``cls``, then, given a ``result`` of it,
    of each derived quantity that ``result`` stores."""
    described = [(f.name, f.metadata["store"]) for f in dataclasses.fields(cls) if "store" in f.metadata]
    if result is not None:
        stores = getattr(result, "stores", lambda _: True)
        described += [(name, f.metadata["store"]) for name, f in getattr(cls, "derived", {}).items() if stores(name)]
    return described


def _motion(order: int, description: str = "absolute motion of the centre of gravity (fixed frame)") -> Any:
    """The (t, dof) quantity of the centre of gravity's motion differentiated ``order`` times: q, qd or qdd."""
    return quantity(motion_units(order), ("t", "dof"), description=description)


class Result(BriefRepr):
    """Base of the described result classes: ``result.to_xarray()`` (see :func:`to_xarray`), and a one-line
    repr (:class:`sixdof.frozen.BriefRepr`)."""

    def to_xarray(self):
        """This result as an :class:`xarray.Dataset`: named dims, coordinates and units (needs xarray)."""
        return to_xarray(self)


@result_type
@dataclass(frozen=True, eq=False)
class TimeHistory(Frozen, Result):
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
        ``x, y, z, rx, ry, rz``. Each is copied, unless given as :class:`~sixdof.errors.Owned` by the
        computation that made it (then held as it is).
    ground_displacement, ground_velocity, ground_acceleration : ndarray, shape (n, 3), or None
        Rigid translation of the foundation in body axes [m, m/s, m/s^2].
    Q : ndarray, shape (n, 6), or None
        Generalized force of the applied loads [N, N m] (ground motion not included).
    maxwell_force : ndarray, shape (n, nb), or None
        Force in each Maxwell branch state [N] (:attr:`sixdof.model.system.System.branches`), as the
        mount's spring force: it acts on the body as ``-R' f``. ``None`` without visco-elastic mounts.
    hysteretic_state : ndarray, shape (n, nh), or None
        The hysteretic variable ``z`` of each hysteretic mount axis [1] (:attr:`sixdof.model.system.System.hysteretic`),
        ``None`` without hysteretic mounts (and from the linear paths, which use their linearization).
    energy_input, energy_dissipated : ndarray, shape (n,), or None
        Runs with nonlinear mounts: the work done on the body by the loads and the ground since the start, and the
        energy dissipated since the start [J] (integrated with the motion, for the energy balance of
        :func:`sixdof.analysis.contact.energy_balance`).
    contacts : sixdof.analysis.contact.ContactEvents or None
        Runs with nonlinear mounts: every change of a mount's contact state, located by the solver.
    stats : sixdof.analysis.records.SolverStats or None
        Direct solve: the solver's settings and step counts.
    superposition : sixdof.analysis.records.SuperpositionInfo or None
        Modal superposition: the method used, modes kept, truncation and approximation errors.
    """

    t: np.ndarray = quantity("s", ("t",))
    q: np.ndarray = _motion(0)
    qd: np.ndarray = _motion(1)
    qdd: np.ndarray = _motion(2)
    ground_displacement: np.ndarray | None = quantity("m", ("t", "axis"), default=None,
                                                      description="foundation displacement in body axes")
    ground_velocity: np.ndarray | None = quantity("m/s", ("t", "axis"), default=None,
                                                  description="foundation velocity in body axes")
    ground_acceleration: np.ndarray | None = quantity("m/s^2", ("t", "axis"), default=None,
                                                      description="foundation acceleration in body axes")
    Q: np.ndarray | None = quantity(UNITS["Q"], ("t", "load"), default=None,
                                    description="generalized force of the applied loads (ground motion not included)")
    maxwell_force: np.ndarray | None = quantity("N", ("t", "branch_state"), default=None,
                                                description="force in each Maxwell branch state along its mount "
                                                "axis (resisting the mount's deformation)")
    hysteretic_state: np.ndarray | None = quantity("1", ("t", "hysteretic_axis"), default=None,
                                                   description="hysteretic variable z of each hysteretic mount axis "
                                                   "(direct solve)")
    energy_input: np.ndarray | None = quantity("J", ("t",), default=None,
                                               description="work done on the body by the loads and, through the "
                                               "mounts, by the ground since the start (runs with nonlinear mounts)")
    energy_dissipated: np.ndarray | None = quantity("J", ("t",), default=None,
                                                    description="energy dissipated by the dashpots, damping models, "
                                                    "Maxwell branches and hysteretic bearings since the start "
                                                    "(runs with nonlinear mounts)")
    stats: Any = part("SolverStats", prefix="solver_", default=None)
    superposition: Any = part("SuperpositionInfo", prefix="", default=None)
    contacts: Any = part("ContactEvents", group="contact_events", default=None)

    #: Stored beside the fields when the ground moves (read back through the properties).
    derived = {f"{key}_relative": _motion(order, "motion of the centre of gravity relative to the ground")
               for order, key in enumerate(("q", "qd", "qdd"))}

    def stores(self, name: str) -> bool:
        """Whether the derived quantity ``name`` is stored (relative motion only with ground motion)."""
        return self.has_ground

    def __check__(self) -> None:
        self._derive(t=readonly(self.t))
        n = self.t.shape[0]
        for name, columns in (("q", 6), ("qd", 6), ("qdd", 6), ("Q", 6), ("ground_displacement", 3),
                              ("ground_velocity", 3), ("ground_acceleration", 3)):
            value = getattr(self, name)
            if value is not None:
                value = readonly(value)
                if value.shape != (n, columns):
                    raise InputError(name, f"shape ({n}, {columns})", f"shape {value.shape}")
                self._derive(**{name: value})
        if self.maxwell_force is not None:
            force = readonly(self.maxwell_force)
            if force.ndim != 2 or force.shape[0] != n:
                raise InputError("maxwell_force", f"shape ({n}, nb)", f"shape {force.shape}")
            self._derive(maxwell_force=force)
        if self.hysteretic_state is not None:
            state = readonly(self.hysteretic_state)
            if state.ndim != 2 or state.shape[0] != n:
                raise InputError("hysteretic_state", f"shape ({n}, nh)", f"shape {state.shape}")
            self._derive(hysteretic_state=state)

    @property
    def has_ground(self) -> bool:
        """Whether the foundation moves."""
        return self.ground_displacement is not None

    def _relative(self, absolute: np.ndarray, ground: np.ndarray | None) -> np.ndarray:
        if ground is None:
            return absolute
        return readonly(np.hstack([absolute[:, :3] - ground, absolute[:, 3:]]))

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


#: Derived quantities a run may leave out of its file (``[output] derived``): each is computed again, to the
#: same numbers, from what the file always keeps (the model, the statics and the response) when it is read
#: back (:func:`sixdof.io.store.load_results`). ``mount_forces``: every mount's deformation, elastic, damping,
#: total and local forces and the foundation's force and moment; ``mount_check``: the total mount loads and
#: deflections, their peaks, tension and limit checks.
DERIVED: tuple[str, ...] = ("mount_forces", "mount_check")


#: Kinds of :class:`Event`.
EVENT_KINDS = ("shock", "switch-on")


@result_type
@dataclass(frozen=True, eq=False)
class Event(Frozen, Result):
    """A moment of the excitation worth a closer look than the whole record gives: a shock pulse, or a
    load switched on (a harmonic, a sweep, an unbalance, a step), where the transient starts.

    Attributes
    ----------
    kind : {"shock", "switch-on"}
    start : float
        When it starts [s].
    duration : float
        The pulse's length [s] for a shock; the forcing's period for a switch-on (0 for a step).
    """

    kind: str = quantity("", (), decode=str, description="shock or switch-on")
    start: float = quantity("s", (), decode=float, description="start of the event")
    duration: float = quantity("s", (), decode=float,
                               description="a shock's pulse length; a switch-on's forcing period (0: a step)")

    def __check__(self) -> None:
        if self.kind not in EVENT_KINDS:
            raise InputError("kind", " or ".join(EVENT_KINDS), self.kind)
        if not (np.isfinite(self.start) and np.isfinite(self.duration) and self.duration >= 0):
            raise InputError("duration", "a finite start and a duration >= 0 [s]", (self.start, self.duration))


@result_type
@dataclass(frozen=True, eq=False)
class RunResults(Frozen):
    """Everything one run computed, as the library's typed objects: what ``results.h5`` holds.

    :func:`sixdof.io.store.write_results` writes it, :func:`sixdof.io.store.load_results` gives it back
    (the same types), and :func:`sixdof.plots.save_all` draws every figure it allows. Parts a run did
    not compute are ``None`` (or empty).

    Attributes
    ----------
    name, description : str
        The scenario's.
    system : sixdof.model.system.System or None
    modes : sixdof.model.modes.Modes or None
    design : sixdof.analysis.design.DesignMetrics or None
        The modes' decoupling, the torque-roll axis (with ``[design] torque_axis``) and the elastic centre: what
        ``sixdof modes`` prints beside the modes (``/design``).
    damping_ratios : ndarray, shape (6,), or None
        Damping ratio of each mode (``nan`` for rigid-body modes).
    statics : sixdof.analysis.statics.Statics or None
    response : TimeHistory or None
        The direct solve.
    mount_forces : sixdof.analysis.response.MountForces or None
    mount_check : sixdof.analysis.mountcheck.MountCheck or None
        Total (static + dynamic) mount loads and deflections, tension and limits.
    points : mapping of str to sixdof.analysis.response.PointMotion
    events : mapping of str to Event
        The excitation's shocks and switch-ons within the record, by load name (figures zoom on them).
    superposition : TimeHistory or None
        The modal-superposition cross-check.
    agreement : sixdof.analysis.compare.Agreement or None
        ``superposition`` against ``response`` (with nonlinear mounts: until the first engages).
    contacts : sixdof.analysis.contact.ContactSummary or None
        Runs with nonlinear mounts: when and where each engaged.
    energy : sixdof.analysis.contact.EnergyBalance or None
        Runs with nonlinear mounts: the energy balance, their cross-check while they engage.
    refined : sixdof.analysis.compare.Agreement or None
        Runs with nonlinear mounts: ``response`` against a second solve at 100 times tighter tolerances.
    frf : sixdof.analysis.frf.FRFCrossCheck or sixdof.analysis.frf.FRF or None
    frf_extras : mapping of str to PointFRF, ForceTransmissibility or GroundTransmissibility
        Named point FRFs and transmissibilities on the frequencies of ``frf``.
    steady_state : sixdof.analysis.steady.SteadyState or None
        Amplitudes and isolation at the excitation's operating frequencies (harmonic loads without end).
    random : sixdof.analysis.random.RandomResponse or None
        The stationary random response to the ``[random]`` PSD.
    srs : sixdof.analysis.srs.ShockSpectra or None
        Shock response spectra of the base and of the body points (``[shock_response_spectrum]``).
    severity : sixdof.analysis.severity.VibrationSeverity or None
        Broadband RMS velocity of body points against the evaluation zones (``[severity]``).
    spectrum : sixdof.analysis.spectrum.ResponseSpectrum or None
        The response-spectrum analysis (``[spectrum]``).
    isolation : sixdof.analysis.isolation.EffectiveLinearization or None
        An isolated system's effective-linearization loop (EN 1998-2 7.5.4), whose converged analysis ``spectrum``
        is (``/spectrum/linearization``).
    spectrum_records : sixdof.analysis.matching.SpectrumCompatibleRecords or None
        The accelerograms of ``[spectrum] records``, matched to the elastic spectrum (``/spectrum/records``).
    records_check : sixdof.analysis.matching.RecordCheck or None
        Their checks against EN 1998-1 3.2.3.1.2 (``/spectrum/records_check``).
    record_peaks : sixdof.analysis.record_peaks.RecordPeaks or None
        The peak responses under each record and their design values (``/spectrum/record_peaks``).
    viscoelastic : tuple of sixdof.model.viscoelastic.MaxwellFit
        The Maxwell models fitted to the mounts' measured dynamic stiffness or loss factors.
    validation : sixdof.validation.ValidationReport or None
    sweep : sixdof.analysis.batch.BatchResult or None
        A design sweep's frequencies and peaks per variant (``sixdof sweep``).
    time_system : sixdof.model.system.System or None
        The system the time response and the statics integrate, where it is not ``system``: the mounts' loss
        factors as causal Maxwell models (``[damping] loss_factor_model = "causal"``).
    loss_factor_model : str
        ``"causal"``, ``"maxwell"`` or ``"hysteretic"``: what the loss factors are in the time paths ("" without).
    loss_factor_statics : str
        With causal models of the loss factors: the line saying that the statics use their long-term
        stiffness, with their worst errors.
    provenance : mapping of str to str
        ``scenario_text``, ``created_utc``, ``command_line``, package versions.
    notes : tuple of str
        The warnings a run raised (sampling, ranges, agreement, mount limits), which its summary lists (not stored).
    stiffness_note : str or None
        The line on gravity's geometric stiffness the summary shows beside the modes (not stored).
    scenario : sixdof.io.scenario.Scenario or None
        The scenario a run computed (not stored: the file keeps its text in ``provenance``).
    """

    name: str = label(name="scenario_name", default="")
    description: str = label(name="scenario_description", default="")
    system: Any = part("System", group="model", default=None)
    time_system: Any = part("System", group="time_model", default=None)
    loss_factor_model: str = label(default="")
    loss_factor_statics: str = label(default="")
    modes: Any = part("Modes", group="modal", default=None)
    design: Any = part("DesignMetrics", group="design", default=None)
    damping_ratios: np.ndarray | None = quantity("1", ("mode",), name="modal/damping_ratio", default=None,
                                                 description="modal damping ratio (nan for rigid-body modes, inf for "
                                                 "overdamped modes: no oscillating pole)")
    statics: Any = part("Statics", group="statics", default=None)
    response: TimeHistory | None = part(TimeHistory, group="time", default=None)
    mount_forces: Any = part("MountForces", group="time", default=None)
    mount_check: Any = part("MountCheck", group="time/mount_check", default=None)
    points: Any = stacked("PointMotion", dim="point", prefix="point_", group="time", default_factory=dict)
    events: Any = stacked(Event, dim="event", prefix="event_", group="time", default_factory=dict)
    superposition: TimeHistory | None = part(TimeHistory, group="time/superposition", default=None)
    agreement: Any = part("Agreement", group="time/superposition", prefix="agreement_", default=None)
    contacts: Any = part("ContactSummary", group="time/contacts", default=None)
    energy: Any = part("EnergyBalance", group="time/energy", default=None)
    refined: Any = part("Agreement", group="time/refined", prefix="agreement_", default=None)
    frf: Any = part("FRFCrossCheck", group="frf", default=None)
    frf_extras: Any = parts(("PointFRF", "ForceTransmissibility", "GroundTransmissibility"), group="frf",
                            default_factory=dict)
    steady_state: Any = part("SteadyState", group="steady_state", default=None)
    random: Any = part("RandomResponse", group="random", default=None)
    srs: Any = part("ShockSpectra", group="srs", default=None)
    severity: Any = part("VibrationSeverity", group="severity", default=None)
    spectrum: Any = part("ResponseSpectrum", group="spectrum", default=None)
    isolation: Any = part("EffectiveLinearization", group="spectrum/linearization", default=None)
    spectrum_records: Any = part("SpectrumCompatibleRecords", group="spectrum/records", default=None)
    records_check: Any = part("RecordCheck", group="spectrum/records_check", default=None)
    record_peaks: Any = part("RecordPeaks", group="spectrum/record_peaks", default=None)
    validation: Any = part("ValidationReport", group="validation", default=None)
    viscoelastic: tuple = sequence("MaxwellFit", group="viscoelastic", key=lambda fit: fit.name, default=())
    sweep: Any = part("BatchResult", group="sweep", default=None)
    provenance: Any = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    stiffness_note: str | None = None
    scenario: Any = field(default=None, repr=False)

    def __check__(self) -> None:
        if (self.mount_forces is not None or self.mount_check is not None or self.points) and self.response is None:
            raise InputError(next(n for n in ("mount_forces", "mount_check", "points") if getattr(self, n)),
                             "the time response they come from", Plain("none"))
        if (self.superposition is not None or self.agreement is not None) and self.response is None:
            raise InputError("superposition", "a direct response to compare with", Plain("none"))
        if self.statics is not None and self.system is None:
            raise InputError("statics", "the system it belongs to", Plain("none"))
        for name in ("spectrum_records", "records_check", "record_peaks"):
            if getattr(self, name) is not None and self.spectrum is None:
                raise InputError(name, "the response-spectrum analysis (spectrum) the records belong to", Plain("none"))
        if self.frf is not None and not hasattr(self.frf, "modal"):
            raise InputError("frf", "an FRFCrossCheck (sixdof.analysis.frf.cross_check: direct and modal)", self.frf)
        if self.frf_extras and self.frf is None:
            raise InputError("frf_extras", "a receptance (frf) whose frequencies they share", Plain("none"))
        for name, item in dict(self.frf_extras).items():
            if not np.array_equal(item.f_hz, self.frf.direct.f_hz):
                raise InputError(f"frf_extras[{name!r}].f_hz", "the frequencies of the receptance",
                                 Plain(f"{len(item.f_hz)} other frequencies"))


#: Labels of the axes that are the same in every result (xarray coordinates, HDF5 dimension scales).
FIXED_SCALES: dict[str, tuple[str, ...]] = {"dof": DOFS, "load": LOADS, "axis": AXES, "mount_axis": MOUNT_AXES}


def to_xarray(result):
    """Any described result (its :func:`quantity` fields) as an :class:`xarray.Dataset`.

    Each quantity becomes a variable with its named dims, its units as in the file (``units``, or for
    mixed DOFs ``units_description`` and ``<axis>_units``, see :class:`~sixdof.dofs.MixedUnits`) and its
    ``description``; a quantity that is its own axis (``t``, ``f_hz``, mount names) becomes a
    coordinate; ``dof``, ``load``, ``axis`` and ``mount_axis`` get their labels; scalar attributes
    (:func:`label` fields) go to the dataset's attributes. Needs xarray (``pip install xarray``).

    Parameters
    ----------
    result : Result
        A result whose fields are described (:class:`~sixdof.results.RunResults`,
        :class:`~sixdof.model.modes.Modes`, a receptance, ...).

    Returns
    -------
    xarray.Dataset
        One variable per quantity, with its dims, ``units`` (SI, as in the results file) and
        ``description`` attributes.

    Raises
    ------
    ModuleNotFoundError
        xarray is not installed.

    Examples
    --------
    >>> sixdof.to_xarray(sixdof.receptance(system, f_hz))["receptance"].sel(dof="z", load="Fz")
    """
    import xarray as xr

    variables, coords, attrs = {}, {}, {}
    for name, meta in descriptions(type(result), result):
        value = getattr(result, name)
        if value is None:
            continue
        if meta["kind"] == "quantity":
            stored = meta["name"] or name
            units = meta["units"](result) if callable(meta["units"]) else meta["units"]
            text = meta["description"](result) if callable(meta["description"]) else meta["description"]
            extra = {**unit_attrs(units), **({"description": text} if text else {})}
            if tuple(meta["dims"]) == (stored,):
                coords[stored] = (stored, np.asarray(value), extra)
            else:
                variables[stored] = xr.Variable(meta["dims"], np.asarray(value), extra)
        elif meta["kind"] == "label" and isinstance(value, (str, int, float, np.ndarray, tuple)):
            attrs[meta["name"] or name] = value
    dims = {d for v in variables.values() for d in v.dims}
    for dim, labels in FIXED_SCALES.items():
        if dim in dims and dim not in coords:
            coords[dim] = (dim, list(labels))
    return xr.Dataset(variables, coords=coords, attrs=attrs)


def time_slice(result, index):
    """``result`` with every quantity that has a time axis ``t`` cut to ``index`` (a slice or an array of
    sample indices) along that axis, nested results likewise: a window of a run, or the samples a figure
    draws."""
    return axis_slice(result, index, "t")


def axis_slice(result, index, dim: str):
    """``result`` with every quantity that has the axis ``dim`` cut to ``index`` (a slice or an array of
    indices) along it, nested results likewise (:func:`time_slice` for the time axis)."""
    changes = {}
    for f in dataclasses.fields(result):
        meta, value = f.metadata.get("store"), getattr(result, f.name)
        if meta is None or value is None:
            continue
        if meta["kind"] == "quantity" and dim in meta["dims"]:
            where = [slice(None)] * np.ndim(value)
            where[meta["dims"].index(dim)] = index
            changes[f.name] = np.asarray(value)[tuple(where)]
        elif meta["kind"] == "part" and _has_axis(value, dim):
            changes[f.name] = axis_slice(value, index, dim)
        elif meta["kind"] == "stacked" and isinstance(value, Mapping) and value:
            changes[f.name] = {name: axis_slice(item, index, dim) for name, item in value.items()}
    return dataclasses.replace(result, **changes) if changes else result


def _has_axis(result, dim: str) -> bool:
    """Whether ``result`` or a result nested in it (:func:`part`) has a quantity with the axis ``dim``."""
    for f in dataclasses.fields(result):
        meta, value = f.metadata.get("store"), getattr(result, f.name)
        if meta is None or value is None:
            continue
        if (meta["kind"] == "quantity" and dim in meta["dims"]) or (meta["kind"] == "part" and _has_axis(value, dim)):
            return True
    return False


def time_concat(results, **changes):
    """Consecutive windows of a run joined: every quantity with a time axis ``t`` concatenated along it, the
    other fields those of the first window unless given in ``changes`` (the inverse of :func:`time_slice`)."""
    return axis_concat(results, "t", **changes)


def axis_concat(results, dim: str, **changes):
    """``results`` joined along the axis ``dim``: every quantity with that axis concatenated along it, nested
    results likewise, the other fields those of the first unless given in ``changes`` (the inverse of
    :func:`axis_slice`: a run's windows, a sweep's chunks)."""
    first = results[0]
    if len(results) == 1 and not changes:
        return first
    for f in dataclasses.fields(first):
        meta = f.metadata.get("store")
        values = [getattr(result, f.name) for result in results]
        if f.name in changes or meta is None or values[0] is None:
            continue
        if meta["kind"] == "quantity" and dim in meta["dims"]:
            changes[f.name] = np.concatenate(values, axis=meta["dims"].index(dim))
        elif meta["kind"] == "part" and _has_axis(values[0], dim):
            changes[f.name] = axis_concat(values, dim)
        elif meta["kind"] == "stacked" and isinstance(values[0], Mapping) and values[0]:
            changes[f.name] = {name: axis_concat([v[name] for v in values], dim) for name in values[0]}
    return dataclasses.replace(first, **changes)


def envelope_samples(t, series, start: float, stop: float, bins: int) -> np.ndarray:
    """Indices of the samples that hold each series' minimum and maximum in each of ``bins`` equal time bins
    of ``[start, stop]``, with the first and last sample.

    The bins are fixed by the whole run's span, not by ``t``: the windows of a long run each keep their own
    extremes per bin, and together they draw every series exactly as the whole run would on an axis of
    ``bins`` pixel columns or fewer (see :func:`sixdof.plots.common.envelope_indices`), in memory bounded by
    ``bins`` whatever the run's length.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Increasing times [s] within ``[start, stop]``.
    series : ndarray, shape (n, k)
        The series drawn, one per column (any units).
    start, stop : float
        The span of the whole run [s].
    bins : int

    Returns
    -------
    ndarray of int
        Sorted sample indices, at most ``2 bins k + 2`` of them.
    """
    t, series = np.asarray(t, dtype=float), np.asarray(series, dtype=float).reshape(len(t), -1)
    n = len(t)
    if n == 0:
        return np.arange(0)
    width = max(stop - start, np.finfo(float).tiny)
    bin_of = np.clip(((t - start) / width * bins).astype(np.int64), 0, bins - 1)
    first = np.flatnonzero(np.diff(bin_of, prepend=-1))  # first sample of every non-empty bin
    segment = np.repeat(np.arange(len(first)), np.diff(np.append(first, n)))
    index = np.arange(n)[:, None]
    kept = [[0, n - 1]]
    for extreme in (np.maximum, np.minimum):
        at = series == extreme.reduceat(series, first, axis=0)[segment]
        # The first sample at each bin's extreme: a flat series keeps one sample per bin, not all.
        kept.append(np.minimum.reduceat(np.where(at, index, n), first, axis=0).ravel())
    return np.unique(np.concatenate(kept))
