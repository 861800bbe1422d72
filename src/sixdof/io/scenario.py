"""Scenario files: declarative TOML read into frozen, validated objects.

Every error names the file, the field path (``mounts[2].stiffness``), what was expected and what was
received. Unknown keys are rejected with the closest valid key suggested. Numerics never see the raw
dictionaries: each table becomes a frozen object of the library here, at the edge.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.analysis.frf import parse_direction
from sixdof.analysis.random import PSD, RandomInput
from sixdof.analysis.srs import SRSSettings
from sixdof.design.spec import DesignSpec, StiffnessRatio, Target, Vary, check_mounts
from sixdof.errors import (
    InputError,
    Plain,
    boolean,
    check_frequencies,
    choice_check,
    direction_check,
    file_name,
    finite_array,
    integer_check,
    label_check,
    memory_check,
    number_check,
    optional,
    point,
)
from sixdof.files import csv_numbers, csv_rows
from sixdof.frozen import Frozen, checked
from sixdof.model import viscoelastic
from sixdof.model.nonlinear import ForceDeflection
from sixdof.model.system import MAX_MOUNTS, Maxwell, Mount, Rayleigh, RigidBody, System
from sixdof.model.viscoelastic import AXES, causal_loss_factors, read_dynamic_stiffness
from sixdof.results import DERIVED
from sixdof.schema import Table, build, choices, make, parse, read_text, reject_unknown, unique

#: The most body points of a scenario: 1,000 took 52 s for the bundled compressor's 3 s run at 2 kHz on a busy
#: machine; each adds 216 bytes a sample to a run's results file.
MAX_POINTS = 1000


def _checked_direction(value: Any, field: str, rotations: bool = True):
    parse_direction(value, field, rotations)  # raises InputError naming the field
    return tuple(value) if isinstance(value, list) else value


def _checked_point(value: Any, field: str) -> tuple[float, float, float]:
    return tuple(point(value, field).tolist())


def _checked_vector(value: Any, field: str) -> tuple[float, float, float]:
    direction_check("a non-zero 3-vector in body axes")(value, field)  # kept as given, not normalized
    return tuple(float(v) for v in value)


def _check_name(name: Any, field: str = "name") -> str:
    if not isinstance(name, str) or not name or "/" in name:
        raise InputError(field, "a non-empty string without '/'", name)
    return name


@dataclass(frozen=True)
class Point(Frozen):
    """A named body point whose motion is reported. ``position`` from the CG in body axes [m]."""

    name: str = checked(label_check)
    position: tuple[float, float, float] = checked(_checked_point)


@dataclass(frozen=True)
class StaticsSettings(Frozen):
    """Gravity for the static deflection: ``gravity`` [m/s^2] along ``direction`` (body axes); with
    ``geometric_stiffness``, the geometric stiffness of the mounts' preload under it is part of K
    (:attr:`sixdof.model.system.System.K_geometric`)."""

    gravity: float = checked(number_check("a positive acceleration in m/s^2", low=0.0, strict=True), default=9.80665)
    direction: tuple[float, float, float] = checked(_checked_vector, default=(0.0, 0.0, -1.0))
    geometric_stiffness: bool = checked(boolean, default=False)

    @property
    def vector(self) -> np.ndarray:
        """Gravity in body axes (3,) [m/s^2]."""
        direction = np.asarray(self.direction, dtype=float)
        return self.gravity * direction / np.linalg.norm(direction)


@dataclass(frozen=True)
class PointFrfRequest(Frozen):
    """A point FRF to compute and store (``[[frf.point]]``): the response at ``response_point``
    along ``response_direction`` per unit load at ``load_point`` along ``load_direction``.
    Directions are ``"x"`` .. ``"rz"`` (``r*``: a moment in, a rotation out) or 3-vectors.
    ``quantity`` is ``"receptance"``, ``"mobility"`` or ``"accelerance"``."""

    name: str = checked(_check_name)
    load_point: tuple[float, float, float] = checked(_checked_point)
    load_direction: Any = checked(_checked_direction)
    response_point: tuple[float, float, float] = checked(_checked_point)
    response_direction: Any = checked(_checked_direction)
    quantity: str = checked(choice_check(("receptance", "mobility", "accelerance")), default="receptance")


@dataclass(frozen=True)
class ForceTransmissibilityRequest(Frozen):
    """Forces passed to the foundation per unit load at ``load_point`` along ``load_direction``
    (``[[frf.force_transmissibility]]``)."""

    name: str = checked(_check_name)
    load_point: tuple[float, float, float] = checked(_checked_point)
    load_direction: Any = checked(_checked_direction)


@dataclass(frozen=True)
class GroundTransmissibilityRequest(Frozen):
    """Motion of ``response_point`` per unit ground translation along ``ground_direction``
    (``[[frf.ground_transmissibility]]``)."""

    name: str = checked(_check_name)
    ground_direction: Any = checked(lambda value, field: _checked_direction(value, field, rotations=False))
    response_point: tuple[float, float, float] = checked(_checked_point)


_FRF_REQUESTS = {"point": PointFrfRequest, "force_transmissibility": ForceTransmissibilityRequest,
                 "ground_transmissibility": GroundTransmissibilityRequest}


def _frequency_range(value: Any, field: str) -> tuple[float, float]:
    expected = "two frequencies [low, high] in Hz with 0 <= low < high"
    low, high = finite_array(value, field, expected, (2,)).tolist()
    if not 0 <= low < high:
        raise InputError(field, expected, value)
    check_frequencies(high, field, value)
    return low, high


@dataclass(frozen=True)
class FrfSettings(Frozen):
    """Frequency grid of the frequency responses: ``points`` frequencies over ``f_hz`` [Hz], and
    the point FRFs and transmissibilities to compute beside the 6x6 receptance."""

    f_hz: tuple[float, float] = checked(_frequency_range, default=(0.1, 100.0))
    points: int = checked(integer_check("an integer >= 2", 2), default=2000)
    spacing: str = checked(choice_check(("log", "linear")), default="log")
    point: tuple[PointFrfRequest, ...] = ()
    force_transmissibility: tuple[ForceTransmissibilityRequest, ...] = ()
    ground_transmissibility: tuple[GroundTransmissibilityRequest, ...] = ()

    def __check__(self) -> None:
        if self.spacing == "log" and self.f_hz[0] == 0:
            raise InputError("f_hz", "a positive low frequency for log spacing", self.f_hz)

    def grid(self) -> np.ndarray:
        """The frequencies [Hz], shape (points,)."""
        return (np.geomspace if self.spacing == "log" else np.linspace)(*self.f_hz, self.points)


@dataclass(frozen=True)
class SuperpositionSettings(Frozen):
    """How ``sixdof run`` computes its modal-superposition cross-check (``[superposition]``).

    ``method`` is ``"auto"`` (real modes for classical damping, complex otherwise), ``"real"`` or
    ``"complex"``; ``n_modes`` or ``f_max_hz`` [Hz] truncate the modal basis, with the static
    ``residual`` correction for the modes left out. Truncation is for studying which modes carry a
    response: the cross-check then measures the truncation error, and warns when it is over 1e-6.
    """

    method: str = checked(choice_check(("auto", "real", "complex")), default="auto")
    n_modes: int | None = checked(optional(integer_check("an integer from 1 to 6", 1)), default=None)
    f_max_hz: float | None = checked(optional(number_check("a positive frequency in Hz", low=0.0, strict=True)),
                                     default=None)
    residual: bool = checked(boolean, default=True)

    def __check__(self) -> None:
        if self.n_modes is not None and self.n_modes > 6:
            raise InputError("n_modes", "an integer from 1 to 6", self.n_modes)
        if self.n_modes is not None and self.f_max_hz is not None:
            raise InputError("n_modes", "either n_modes or f_max_hz, not both", self.n_modes)




def _derived_check(value, field):
    if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
        raise InputError(field, f"a list of names from {', '.join(DERIVED)} (or [] for none)", value)
    for i, name in enumerate(value):
        choice_check(DERIVED)(name, f"{field}[{i}]")
    return tuple(dict.fromkeys(value))


@dataclass(frozen=True)
class OutputSettings(Frozen):
    """What ``sixdof run`` stores in ``results.h5`` (``[output]``): ``derived`` names the derived quantities
    written (default all of :data:`DERIVED`, today's file); those left out are derived again on reading."""

    derived: tuple[str, ...] = checked(_derived_check, default=DERIVED)

    @property
    def omitted(self) -> tuple[str, ...]:
        """The derived quantities left out of the file."""
        return tuple(name for name in DERIVED if name not in self.derived)


class NotPrepared(ValueError):
    """A scenario's prepared model read before :func:`sixdof.workflows.prepare.prepare` made it."""


@dataclass(frozen=True, eq=False)
class MeasuredStiffness:
    """A ``dynamic_stiffness`` table of a mount, read and checked (the fit is made by
    :func:`sixdof.workflows.prepare.prepare`).

    Attributes
    ----------
    mount, axis : str
    field : str
        Its place in the file (``mounts[0].dynamic_stiffness``), for the errors of its fit.
    f_hz, storage, loss : ndarray
        The data [Hz, N/m, N/m] (:func:`~sixdof.model.viscoelastic.read_dynamic_stiffness`).
    terms : int or None
    max_modulus_error, max_loss_angle_error_deg : float
        The worst fit accepted [1, deg].
    file : str
        As the scenario names it.
    """

    mount: str
    axis: str
    field: str
    f_hz: np.ndarray
    storage: np.ndarray
    loss: np.ndarray
    terms: Any
    max_modulus_error: float
    max_loss_angle_error_deg: float
    file: str


@dataclass(frozen=True, eq=False)
class PreparedModel:
    """The systems a scenario's computations use, made by :func:`sixdof.workflows.prepare.prepare`.

    Attributes
    ----------
    system : sixdof.model.system.System
        The frequency paths' and the modes': measured dynamic stiffness as Maxwell models, nonlinear mounts at
        their static equilibrium, gravity's preload where ``[statics] geometric_stiffness``.
    time_system : sixdof.model.system.System
        The system the time paths integrate (the direct solve and its superposition, the statics, `validate`):
        ``system`` with each loss factor replaced by its causal Maxwell model (``loss_factor_model``
        ``"causal"``, the default, or ``"maxwell"``); ``system`` itself without loss factors or with
        ``"hysteretic"`` (which leaves them out of the time paths).
    viscoelastic : tuple of sixdof.model.viscoelastic.MaxwellFit
        The Maxwell models fitted to the mounts' measured dynamic stiffness (in ``system``) and, unless
        ``loss_factor_model = "hysteretic"``, the causal models of their loss factors (in ``time_system``, and in
        ``system`` too with ``"maxwell"``).
    """

    system: System
    time_system: System
    viscoelastic: tuple = ()


@dataclass(frozen=True, eq=False)
class Scenario:
    """A validated scenario: one system, the excitations acting together, and what to compute.

    Attributes
    ----------
    name, description : str
    system : sixdof.model.system.System
    excitation : sixdof.excitation.Excitation or None
        Loads, ground motion and initial conditions; ``None`` when the file has none.
    simulation : sixdof.analysis.direct.SimulationSettings or None
        Present when the file has a ``[simulation]`` table.
    frf : FrfSettings or None
    superposition : SuperpositionSettings
    points : tuple of Point
    statics : StaticsSettings
    output : OutputSettings
    shock_response_spectrum : sixdof.analysis.srs.SRSSettings or None
        The ``[shock_response_spectrum]`` table (needs a ``[simulation]``).
    random : sixdof.analysis.random.RandomInput or None
        The ``[random]`` table: a base-acceleration or force PSD.
    design : sixdof.design.spec.DesignSpec
        The ``[design]`` table: torque axis, targets and variables (empty when absent).
    measured : tuple of MeasuredStiffness
        The mounts' measured dynamic stiffness tables, read and checked: fitted by
        :func:`sixdof.workflows.prepare.prepare`, which puts their Maxwell models in ``system``.
    model : PreparedModel or None
        What :func:`~sixdof.workflows.prepare.prepare` made of ``given_system`` (``None`` until then).
    given_system : sixdof.model.system.System
        The model as the file gives it: no fits, no static equilibrium, no preload.
    system, time_system, viscoelastic
        The prepared model's (:class:`PreparedModel`): reading them from a scenario that is only loaded, whose
        model needs preparing (fits, a nonlinear equilibrium, gravity's preload, causal loss factors), raises
        :class:`NotPrepared`; without such needs, ``system`` and ``time_system`` are ``given_system``.
    loss_factor_model : str
        ``"causal"``, ``"maxwell"`` or ``"hysteretic"`` (``[damping] loss_factor_model``).
    loss_factor_band_hz, loss_factor_terms
        ``[damping] loss_factor_band_hz`` and ``loss_factor_terms`` as given (checked), or None: what
        :meth:`time_model` fits with.
    text : str
        The file's text (stored in results for provenance).
    path : pathlib.Path or None
    """

    name: str
    description: str
    given_system: System
    excitation: Any
    simulation: Any
    frf: FrfSettings | None
    superposition: SuperpositionSettings
    points: tuple[Point, ...]
    statics: StaticsSettings
    output: OutputSettings
    shock_response_spectrum: Any
    random: Any
    design: Any
    text: str
    path: Path | None
    measured: tuple = ()
    loss_factor_model: str = "causal"
    loss_factor_band_hz: Any = None
    loss_factor_terms: Any = None
    model: Any = None

    @property
    def needs_preparing(self) -> tuple[str, ...]:
        """What :func:`~sixdof.workflows.prepare.prepare` changes of ``given_system`` (empty: nothing)."""
        given = self.given_system
        needs = [("measured dynamic stiffness to fit", bool(self.measured)),
                 ("the static equilibrium of nonlinear mounts", bool(given.nonlinear.count)),
                 ("gravity's geometric stiffness", self.statics.geometric_stiffness),
                 ("causal models of the loss factors",
                  self.loss_factor_model != "hysteretic" and bool(np.any(given.loss_factors)))]
        return tuple(what for what, needed in needs if needed)

    def _prepared(self, name: str):
        if self.model is not None:
            return getattr(self.model, name)
        if self.needs_preparing:
            raise NotPrepared(f"Scenario.{name} of {self.name!r}: its model needs preparing first "
                              f"({', '.join(self.needs_preparing)}); call sixdof.prepare(scenario), or sixdof.run")
        return () if name == "viscoelastic" else self.given_system

    @property
    def system(self) -> System:
        """The system of the frequency paths and the modes (:class:`PreparedModel`)."""
        return self._prepared("system")

    @property
    def time_system(self) -> System:
        """The system the time paths integrate (:class:`PreparedModel`)."""
        return self._prepared("time_system")

    @property
    def viscoelastic(self) -> tuple:
        """The Maxwell models fitted to measured data and loss factors (:class:`PreparedModel`)."""
        return self._prepared("viscoelastic")

    def time_model(self, system: System) -> System:
        """The system the time paths integrate for ``system`` (a design or variant of this scenario's): its loss
        factors made causal Maxwell models as :attr:`time_system`'s are (the same ``loss_factor_*`` settings,
        checked at ``system``'s own natural frequencies and the operating frequencies); ``system`` itself when
        it has no loss factor or with ``loss_factor_model = "hysteretic"``."""
        if system is self.system:
            return self.time_system
        if self.loss_factor_model == "hysteretic" or not np.any(system.loss_factors):
            return system
        return causal_model(system, self.excitation, self.loss_factor_band_hz, self.loss_factor_terms)[0]

    @property
    def causal_loss_fits(self) -> tuple:
        """The causal Maxwell models of the mounts' loss factors that ``time_system`` carries (none with
        ``loss_factor_model = "hysteretic"``)."""
        return tuple(fit for fit in self.viscoelastic if fit.source.startswith("loss factor "))


# ----------------------------------------------------------------------------------------------------


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario file.

    Parameters
    ----------
    path : str or pathlib.Path
        A TOML scenario file. Relative file references inside it (tabulated signals) are resolved
        against its folder.

    Raises
    ------
    ScenarioError
        (a ``ValueError``) naming the file, the field, what was expected and what was received.
    """
    path = Path(path)
    return parse_scenario(read_text(path, "scenario file"), source=str(path), base_dir=path.parent)


def parse_scenario(text: str, source: str = "<string>", base_dir: str | Path = ".") -> Scenario:
    """Validate scenario text (TOML). See :func:`load_scenario`."""
    return parse(text, source, lambda raw: _scenario(raw, text, Path(base_dir), source))


def _scenario(raw: dict, text: str, base_dir: Path, source: str) -> Scenario:
    top = Table(raw, "", _TOP_LEVEL_KEYS)
    name = file_name(top.string("name"))
    description = top.string("description", default="")
    mount_tables, point_tables = top.tables("mounts", required=True), top.tables("points")
    # Counted before anything is built: 20,000 [[mounts]] took 54 s to read into mounts.
    for key, found, most in (("mounts", mount_tables, MAX_MOUNTS), ("points", point_tables, MAX_POINTS)):
        if len(found) > most:
            raise InputError(key, f"at most {most:,} [[{key}]] tables", Plain(f"{len(found):,}"))
    body = build(RigidBody, top.table("body"), "body")
    mounts, branches, fits, tables = [], [], [], []
    for i, table in enumerate(mount_tables):
        mount, own_branches, own_fits, own_tables = _mount(table, f"mounts[{i}]", base_dir)
        mounts.append(mount)
        branches += own_branches
        fits += own_fits
        tables += own_tables
    damping = Table(top.table("damping", default={}), "damping",
                    ("rayleigh", "modal", "loss_factor_model", "loss_factor_band_hz", "loss_factor_terms"))
    rayleigh, modal = _damping(damping)
    system = make(System, "", body=body, mounts=mounts, rayleigh=rayleigh, modal_damping=modal, maxwell=branches,
                  force_deflection=tables)
    statics = build(StaticsSettings, top.table("statics", default={}), "statics")

    loads = tuple(_load(t, f"loads[{i}]", base_dir) for i, t in enumerate(top.tables("loads")))
    ground, initial = top.table("ground", default=None), top.table("initial", default=None)
    excitation = None
    if loads or ground is not None or initial is not None:
        from sixdof.excitation import Excitation, GroundMotion, InitialState, ModeRelease  # noqa: PLC0415 (excitation and the solver's settings load JAX)

        if ground is not None:
            ground = build(GroundMotion, _with_file(ground, "ground", base_dir), "ground")
        if initial is not None:
            release = "mode" in initial or "amplitude" in initial
            initial = build(ModeRelease if release else InitialState, initial, "initial")
        excitation = make(Excitation, "", loads=loads, ground=ground, initial=initial)
    loss_model = _loss_factor_model(system, damping)
    simulation = top.table("simulation", default=None)
    if simulation is not None:
        from sixdof.analysis.direct import SimulationSettings  # noqa: PLC0415 (excitation and the solver's settings load JAX)

        simulation = build(SimulationSettings, simulation, "simulation")
    frf = top.table("frf", default=None)
    frf = None if frf is None else _frf(frf)
    _check_memory(system, excitation, simulation, frf)
    superposition = build(SuperpositionSettings, top.table("superposition", default={}), "superposition")
    points = tuple(build(Point, t, f"points[{i}]") for i, t in enumerate(point_tables))
    unique([p.name for p in points], "points")
    output = build(OutputSettings, top.table("output", default={}), "output")
    design = _design(top.table("design", default={}), system)
    random = top.table("random", default=None)
    if random is not None:
        random = _random(random)
    spectrum = top.table("shock_response_spectrum", default=None)
    if spectrum is not None:
        spectrum = _spectrum(spectrum, simulation)
    return Scenario(name=name, description=description, given_system=system, excitation=excitation,
                    simulation=simulation, frf=frf, superposition=superposition, points=points, statics=statics,
                    output=output, shock_response_spectrum=spectrum, random=random, design=design, text=text,
                    measured=tuple(fits), loss_factor_model=loss_model,
                    loss_factor_band_hz=damping.value("loss_factor_band_hz", None),
                    loss_factor_terms=damping.value("loss_factor_terms", None),
                    path=Path(source) if source != "<string>" else None)


def _spectrum(raw: dict, simulation):
    spectrum = build(SRSSettings, raw, "shock_response_spectrum")
    if simulation is None:
        raise InputError("shock_response_spectrum", "a [simulation] whose record it is computed from",
                         Plain("no [simulation]"))
    if simulation.samples > MEMORY_SAMPLES:
        raise InputError("shock_response_spectrum", f"a [simulation] of at most {MEMORY_SAMPLES} samples (a "
                         "longer run keeps only what its figures draw)", Plain(f"{simulation.samples} samples"))
    nyquist = simulation.sample_rate_hz / 2
    if spectrum.f_hz[1] >= nyquist:
        raise InputError("shock_response_spectrum.f_hz", f"a band below half the sample rate ({nyquist:g} Hz)",
                         list(spectrum.f_hz))
    return spectrum


def _random(raw: dict):
    table = Table(raw, "random", ("input", "direction", "point", "psd", "time_check"))
    psd = build(PSD, table.table("psd"), "random.psd")
    return make(RandomInput, "random", input=table.value("input"), direction=table.value("direction", "z"),
                point=table.value("point", None), psd=psd, time_check=table.value("time_check", True))


_DESIGN_SETTINGS = ("tolerance", "samples", "seed", "starts", "objective", "robust_samples")


def _design(raw: dict, system: System):
    table = Table(raw, "design", ("torque_axis", "target", "vary", "stiffness_ratio", *_DESIGN_SETTINGS))
    axis = table.value("torque_axis", None)
    targets = tuple(build(Target, t, f"design.target[{i}]") for i, t in enumerate(table.tables("target")))
    vary = tuple(build(Vary, t, f"design.vary[{i}]") for i, t in enumerate(table.tables("vary")))
    ratios = tuple(build(StiffnessRatio, t, f"design.stiffness_ratio[{i}]")
                   for i, t in enumerate(table.tables("stiffness_ratio")))
    settings = {k: raw[k] for k in _DESIGN_SETTINGS if k in raw}
    spec = make(DesignSpec, "design", torque_axis=None if axis is None else _checked_vector(axis, "design.torque_axis"),
                target=targets, vary=vary, stiffness_ratio=ratios, **settings)
    return make(check_mounts, "design", spec=spec, mount_names=tuple(m.name for m in system.mounts))


#: Peak memory of ``sixdof run`` per output sample [bytes], with its superposition cross-check and figures:
#: 3.5 kB measured (engine scenario: 3 mounts, 1 point, 1.6e6 samples). A random signal adds an (n, components)
#: array of sines.
RUN_BYTES_PER_SAMPLE = 4000
#: A run holds at most this many output samples in memory: a longer one proceeds in windows written to its
#: file as they are done, keeping only what its figures draw (:mod:`sixdof.workflows.run`).
MEMORY_SAMPLES = 1 << 16
#: Complex values kept per frequency and per (load DOF, response) pair, counting the modal cross-check's copy.
FRF_COPIES = 4


def _check_memory(system, excitation, simulation, frf) -> None:
    if simulation is not None:
        samples = simulation.duration * simulation.sample_rate_hz
        sources = (*excitation.loads, excitation.ground) if excitation else ()
        sines = sum(getattr(getattr(source, "signal", None), "components", 0) for source in sources)
        memory_check("simulation.sample_rate_hz", min(samples, MEMORY_SAMPLES) * (RUN_BYTES_PER_SAMPLE + 8 * sines),
                     "a number of output samples", f"{samples:.3g} samples")
    if frf is not None:  # per frequency: the 6x6 receptance and every mount's 3 forces per load DOF
        per_frequency = 16 * 6 * (6 + 3 * len(system.mounts)) * FRF_COPIES
        memory_check("frf.points", frf.points * per_frequency, "a number of frequencies", f"{frf.points} frequencies")


def _frf(table: dict) -> FrfSettings:
    frf = Table(table, "frf", tuple(table))  # keys checked by build(FrfSettings) below
    requests = {key: tuple(build(cls, t, f"frf.{key}[{i}]") for i, t in enumerate(frf.tables(key)))
                for key, cls in _FRF_REQUESTS.items()}
    unique([r.name for group in requests.values() for r in group], "frf")
    return build(FrfSettings, {**table, **requests}, "frf")


#: The keys of a ``bump_stop`` table and the :class:`~sixdof.model.system.Mount` fields they fill.
_BUMP_STOP = {"clearance": "bump_clearance", "stiffness": "bump_stiffness"}
#: The keys of a ``[[mounts]]`` table (the README's): the Mount's fields, ``bump_stop`` in place of the two it
#: fills, and the tables read beside the mount. Its unknown keys are checked against this list alone.
_MOUNT_KEYS = (*(f.name for f in dataclasses.fields(Mount) if f.init and f.name not in _BUMP_STOP.values()),
              "bump_stop", "maxwell", "dynamic_stiffness", "force_deflection")


def _mount(raw: Any, path: str, base_dir: Path) -> tuple[Mount, list[Maxwell], list, list]:
    """A ``[[mounts]]`` table: the mount, its ``[[mounts.maxwell]]`` branches, its ``dynamic_stiffness`` fits
    (mount name, axis, :class:`~sixdof.model.viscoelastic.MaxwellFit`) and its ``force_deflection`` tables
    (:class:`~sixdof.model.nonlinear.ForceDeflection`)."""
    if not isinstance(raw, dict):
        raise InputError(path, "a table", raw)
    for key in _BUMP_STOP.values():  # the model's names of bump_stop's keys
        if key in raw:
            raise InputError(f"{path}.{key}", "bump_stop = {clearance = [...], stiffness = [...]}", Plain(key))
    reject_unknown(raw, _MOUNT_KEYS, path)
    table = dict(raw)
    maxwell, measured = table.pop("maxwell", []), table.pop("dynamic_stiffness", [])
    stop, curves = table.pop("bump_stop", None), table.pop("force_deflection", [])
    if stop is not None:
        keys = Table(stop, f"{path}.bump_stop", tuple(_BUMP_STOP))
        table.update({model: keys.value(key) for key, model in _BUMP_STOP.items()})
    try:
        mount = build(Mount, table, path)
    except InputError as error:  # named as the file names them
        for key, model in _BUMP_STOP.items():
            if error.field.endswith(f".{model}"):
                raise InputError(error.field.replace(model, f"bump_stop.{key}"), error.expected, error.got) from None
        raise
    tables = Table({"maxwell": maxwell}, path, ("maxwell",)).tables("maxwell")
    branches = []
    for j, branch in enumerate(tables):
        field = f"{path}.maxwell[{j}]"
        keys = Table(branch, field, ("stiffness", "tau"))
        branches.append(make(Maxwell, field, name=f"{mount.name} {j + 1}", mount=mount.name,
                             stiffness=keys.value("stiffness"), tau=keys.value("tau")))
    fits = []
    for j, data in enumerate([measured] if isinstance(measured, dict) else measured):
        field = f"{path}.dynamic_stiffness" + (f"[{j}]" if isinstance(measured, list) else "")
        fits.append(_fit(mount, data, field, base_dir))
    axes = [fit.axis for fit in fits]
    if len(set(axes)) < len(axes):
        raise InputError(f"{path}.dynamic_stiffness", "one table per axis", Plain(f"axes {', '.join(axes)}"))
    tables = []
    for j, curve in enumerate([curves] if isinstance(curves, dict) else curves):
        field = f"{path}.force_deflection" + (f"[{j}]" if isinstance(curves, list) else "")
        keys = Table(curve, field, ("file", "axis"))
        file = keys.string("file")
        deflection, force = read_table_csv(file, base_dir, f"{field}.file", ("deflection in m", "force in N"))
        tables.append(make(ForceDeflection, field, mount=mount.name, axis=keys.value("axis"), deflection=deflection,
                           force=force, source=file))
    axes = [t.axis for t in tables]
    if len(set(axes)) < len(axes):
        raise InputError(f"{path}.force_deflection", "one table per axis", Plain(f"axes {', '.join(axes)}"))
    if set(axes) & {fit.axis for fit in fits}:
        raise InputError(f"{path}.force_deflection", "axes without a dynamic_stiffness fit (each replaces the "
                         "axis's stiffness)", Plain(f"axes {', '.join(sorted(set(axes)))}"))
    return mount, branches, fits, tables


def _fit(mount: Mount, raw: Any, field: str, base_dir: Path) -> MeasuredStiffness:
    """One ``dynamic_stiffness`` table: the measured data of ``file`` along ``axis``, read and checked."""
    table = Table(raw, field, ("file", "axis", "terms", "max_modulus_error", "max_loss_angle_error_deg"))
    axis = choice_check(tuple(AXES))(table.value("axis"), f"{field}.axis")
    if mount.loss_factor[AXES.index(axis)] > 0:
        raise InputError(f"{field}.axis", "an axis without a loss_factor (the measured loss factor replaces it)",
                         axis)
    file = table.string("file")
    f_hz, storage, loss = read_dynamic_stiffness((base_dir / file).resolve(), f"{field}.file")
    limits = [number_check(expected, low=0.0, strict=True)(table.value(key, default), f"{field}.{key}")
              for key, default, expected in (
                  ("max_modulus_error", viscoelastic.FIT_MODULUS_ERROR, "a relative error > 0"),
                  ("max_loss_angle_error_deg", viscoelastic.FIT_LOSS_ANGLE_ERROR_DEG, "an angle in deg > 0"))]
    return MeasuredStiffness(mount=mount.name, axis=axis, field=field, f_hz=f_hz, storage=storage, loss=loss,
                             terms=table.value("terms", None), max_modulus_error=limits[0],
                             max_loss_angle_error_deg=limits[1], file=file)


#: The values of ``[damping] loss_factor_model``: what the mounts' loss factors are in the time paths and in the
#: frequency paths.
LOSS_FACTOR_MODELS = ("causal", "maxwell", "hysteretic")


def _loss_factor_model(system: System, damping: Table) -> str:
    """``loss_factor_model``, checked against the mounts' loss factors and the ``loss_factor_*`` keys given: what
    the loss factors are in the time paths and in the frequency paths (:func:`sixdof.workflows.prepare.prepare`
    makes their causal Maxwell models): ``"causal"`` in the time system only, ``"maxwell"`` in both,
    ``"hysteretic"`` nowhere (the time paths leave the loss factors out)."""
    model = choice_check(LOSS_FACTOR_MODELS)(damping.value("loss_factor_model", "causal"),
                                              "damping.loss_factor_model")
    lossy = bool(np.any(system.loss_factors))
    if model == "hysteretic" or (not lossy and "loss_factor_model" not in damping.raw):
        for key in ("loss_factor_band_hz", "loss_factor_terms"):
            if key in damping.raw:
                raise InputError(f"damping.{key}", 'loss_factor_model = "causal" or "maxwell" (it sets the Maxwell '
                                 "model of the loss factors) and a mount with a loss_factor",
                                 Plain(f'loss_factor_model = "{model}"' if lossy or model == "hysteretic"
                                       else "no loss factor"))
        return model
    if not lossy:
        raise InputError("damping.loss_factor_model", f'a mount with a loss_factor for "{model}" to model',
                         Plain("no loss factor"))
    return model


def causal_model(system: System, excitation, band_hz, terms):
    """``system`` with its loss factors' causal Maxwell models, and the models
    (:func:`~sixdof.model.viscoelastic.causal_loss_factors`, checked at the natural frequencies and the
    operating frequencies of ``excitation``); errors name the ``[damping] loss_factor_*`` keys."""
    try:
        return causal_loss_factors(system, band_hz=band_hz, terms=terms, operating_hz=operating_frequencies(excitation))
    except InputError as exc:  # the function's arguments are the scenario's loss_factor_* keys
        key = f"loss_factor_{exc.field}" if exc.field in ("band_hz", "terms") else exc.field
        raise InputError(f"damping.{key}", exc.expected, exc.got) from None


def operating_frequencies(excitation) -> np.ndarray:
    """The frequencies [Hz] of the harmonic signals of ``excitation`` (unbalance, harmonic loads and ground
    motion), sorted; none without an excitation."""
    from sixdof.excitation import Harmonic  # noqa: PLC0415 (excitation and the solver's settings load JAX)

    if excitation is None:
        return np.zeros(0)
    found = [signal.f_hz for _, signal in excitation.components() if isinstance(signal, Harmonic)]
    if excitation.ground is not None and isinstance(getattr(excitation.ground, "signal", None), Harmonic):
        found.append(excitation.ground.signal.f_hz)
    return np.unique(np.asarray(found, dtype=float))


def _damping(damping: Table) -> tuple[Rayleigh | None, Any]:
    rayleigh = damping.table("rayleigh", default=None)
    if rayleigh is not None:
        keys = set(rayleigh)
        if keys <= {"zeta", "f_hz"} and keys:
            r = Table(rayleigh, "damping.rayleigh", ("zeta", "f_hz"))
            rayleigh = make(Rayleigh.from_ratio, "damping.rayleigh", zeta=r.value("zeta"), f_hz=r.value("f_hz"))
        elif keys <= {"alpha", "beta"} and keys:
            rayleigh = build(Rayleigh, rayleigh, "damping.rayleigh")
        else:
            raise InputError("damping.rayleigh", "either {zeta, f_hz} or {alpha, beta}", sorted(rayleigh))
    return rayleigh, damping.value("modal", default=None)


def _load(table: dict, path: str, base_dir: Path):
    from sixdof.excitation import LOAD_KINDS  # noqa: PLC0415 (excitation and the solver's settings load JAX)

    table = dict(table)
    kind = table.pop("kind", "force")
    if not isinstance(kind, str) or kind not in LOAD_KINDS:
        raise InputError(f"{path}.kind", f"one of {choices(LOAD_KINDS)}", kind)
    return build(LOAD_KINDS[kind], _with_file(table, path, base_dir), path)


def _with_file(table: dict, path: str, base_dir: Path) -> dict:
    """The table with its table signal's ``file`` (relative to ``base_dir``) read into ``t`` and ``values``."""
    signal = table.get("signal")
    if not (isinstance(signal, dict) and signal.get("kind") == "table" and "file" in signal):
        return table
    field = f"{path}.signal.file"
    signal = dict(signal)
    file = signal.pop("file")
    if "t" in signal or "values" in signal:
        raise InputError(field, "either a file or inline t and values, not both", file)
    signal["t"], signal["values"] = read_table_csv(file, base_dir, field, increasing=True)
    return {**table, "signal": signal}


def read_table_csv(file: Any, base_dir: Path, field: str, columns: tuple[str, str] = ("time in s", "value"),
                   increasing: bool = False) -> tuple[list[float], list[float]]:
    """Read a two-column CSV (default time [s], value) with an optional header line and ``#`` comment lines;
    with ``increasing``, its first column must increase strictly (checked here, where each row's line is known)."""
    if not isinstance(file, str) or not file:
        raise InputError(field, "a CSV file name (relative to the scenario file)", file)
    expected = f"a UTF-8 CSV file of rows of two finite numbers: {', '.join(columns)}"
    pairs, lines, first = [], [], True
    for line, row in csv_rows(base_dir / file, field, expected, name=file):
        try:
            pair = csv_numbers(row, 2, line, file, field, expected)
        except InputError:
            if first:  # only the first row may be a header
                first = False
                continue
            raise
        first = False
        pairs.append(pair)
        lines.append(line)
    if len(pairs) < 2:
        raise InputError(field, f"at least 2 rows of {', '.join(columns)}", f"{len(pairs)} rows in {file}")
    first = [x for x, _ in pairs]
    back = next((k for k in range(1, len(first)) if first[k] <= first[k - 1]), None) if increasing else None
    if back is not None:
        raise InputError(field, f"{expected}, the first column ({columns[0]}) strictly increasing",
                         Plain(f"{first[back]:g} on line {lines[back]} of {file}, after {first[back - 1]:g} on line "
                               f"{lines[back - 1]}"))
    return first, [value for _, value in pairs]


_TOP_LEVEL_KEYS = (
    "name", "description", "body", "mounts", "damping", "loads", "ground", "initial", "simulation",
    "frf", "superposition", "points", "statics", "output", "design", "random", "shock_response_spectrum",
)
