"""Scenario files: declarative TOML read into frozen, validated objects.

Every error names the file, the field path (``mounts[2].stiffness``), what was expected and what was
received. Unknown keys are rejected with the closest valid key suggested. Numerics never see the raw
dictionaries: each table becomes a frozen object of the library here, at the edge.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sixdof.analysis.random import PSD, RandomInput
from sixdof.analysis.severity import SeveritySettings, chosen_source, measured_points
from sixdof.analysis.srs import SRSSettings
from sixdof.analysis.steady import operating_phasors
from sixdof.design.spec import DesignSpec, StiffnessRatio, Target, UpdateSpec, Vary, check_mounts, check_update_mounts
from sixdof.errors import InputError, Plain, boolean, choice_check, file_name, memory_check
from sixdof.files import read_table_csv
from sixdof.io.mounts import read_mount
from sixdof.io.settings import (
    FrfSettings,
    OutputSettings,
    Point,
    StaticsSettings,
    SuperpositionSettings,
    checked_vector,
    frf_settings,
    record_settings,
    spectrum_settings,
)
from sixdof.model.hysteresis import BoucWen, FrictionPendulum
from sixdof.model.parts import Rayleigh, RigidBody
from sixdof.model.system import MAX_MOUNTS, System
from sixdof.model.viscoelastic import causal_loss_factors
from sixdof.schema import Table, build, choices, make, parse, read_text, unique
from sixdof.validation.testdata import TestSetup

#: The most body points of a scenario: 1,000 took 52 s for the bundled compressor's 3 s run at 2 kHz on a busy
#: machine; each adds 216 bytes a sample to a run's results file.
MAX_POINTS = 1000


class NotPrepared(ValueError):
    """A scenario's prepared model read before :func:`sixdof.workflows.prepare.prepare` made it."""


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
    frf : sixdof.io.settings.FrfSettings or None
    superposition : sixdof.io.settings.SuperpositionSettings
    points : tuple of sixdof.io.settings.Point
    statics : sixdof.io.settings.StaticsSettings
    output : sixdof.io.settings.OutputSettings
    shock_response_spectrum : sixdof.analysis.srs.SRSSettings or None
        The ``[shock_response_spectrum]`` table (needs a ``[simulation]``).
    random : sixdof.analysis.random.RandomInput or None
        The ``[random]`` table: a base-acceleration or force PSD.
    design : sixdof.design.spec.DesignSpec
        The ``[design]`` table: torque axis, targets and variables (empty when absent).
    response_spectrum : sixdof.excitation.spectra.SpectrumSettings or None
        The ``[spectrum]`` table: a response-spectrum analysis (no ``[simulation]`` needed).
    spectrum_records : sixdof.analysis.matching.RecordSettings or None
        ``[spectrum] records``: spectrum-compatible accelerograms run beside the response-spectrum analysis.
    severity : sixdof.analysis.severity.SeveritySettings or None
        The ``[severity]`` table: RMS velocity of body points against evaluation zones.
    test : sixdof.validation.testdata.TestSetup or None
        The ``[test]`` table: the test's node coordinates, the test frame in body axes, the correlation limits.
    update : sixdof.design.spec.UpdateSpec or None
        The ``[update]`` table: what updating the model to a test may change (None when absent).
    measured : tuple of sixdof.io.mounts.MeasuredStiffness
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
    test: TestSetup | None = None  # the [test] table (issue 47): where a test's nodes are, correlation limits
    update: UpdateSpec | None = None
    response_spectrum: Any = None  # the [spectrum] table (issue 48): a SpectrumSettings
    spectrum_records: Any = None  # [spectrum] records (issue 48): a RecordSettings
    severity: Any = None  # the [severity] table (issue 49): a SeveritySettings

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

    Returns
    -------
    Scenario
        The validated scenario, its model not yet prepared (:func:`sixdof.workflows.prepare.prepare`).

    Raises
    ------
    ScenarioError
        (a ``ValueError``) naming the file, the field, what was expected and what was received.
    """
    path = Path(path)
    return parse_scenario(read_text(path, "scenario file"), source=str(path), base_dir=path.parent)


def parse_scenario(text: str, source: str = "<string>", base_dir: str | Path = ".") -> Scenario:
    """Validate scenario text (TOML). See :func:`load_scenario`.

    Parameters
    ----------
    text : str
        The scenario, as a scenario file holds it (TOML).
    source : str, optional
        The name errors give the text (a file's path). Default ``"<string>"``.
    base_dir : str or pathlib.Path, optional
        The folder relative file references (tabulated signals) are resolved against. Default: the working
        directory.

    Returns
    -------
    Scenario
        The validated scenario, its model not yet prepared.

    Raises
    ------
    ScenarioError
        Naming ``source``, the field, what was expected and what was received.
    """
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
    mounts, branches, fits, tables, laws = [], [], [], [], []
    for i, table in enumerate(mount_tables):
        mount, own_branches, own_fits, own_tables, own_laws = read_mount(table, f"mounts[{i}]", base_dir)
        mounts.append(mount)
        branches += own_branches
        fits += own_fits
        tables += own_tables
        laws += own_laws
    damping = Table(top.table("damping", default={}), "damping",
                    ("rayleigh", "modal", "loss_factor_model", "loss_factor_band_hz", "loss_factor_terms",
                     "rayleigh_excludes_hysteresis"))
    rayleigh, modal = _damping(damping)
    excludes = boolean(damping.value("rayleigh_excludes_hysteresis", True), "damping.rayleigh_excludes_hysteresis")
    system = make(System, "", body=body, mounts=mounts, rayleigh=rayleigh, modal_damping=modal, maxwell=branches,
                  force_deflection=tables, bouc_wen=[law for law in laws if isinstance(law, BoucWen)],
                  friction_pendulum=[law for law in laws if isinstance(law, FrictionPendulum)],
                  rayleigh_excludes_hysteresis=excludes)
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
    frf = None if frf is None else frf_settings(frf)
    _check_memory(system, excitation, simulation, frf)
    superposition = build(SuperpositionSettings, top.table("superposition", default={}), "superposition")
    points = tuple(build(Point, t, f"points[{i}]") for i, t in enumerate(point_tables))
    unique([p.name for p in points], "points")
    output = build(OutputSettings, top.table("output", default={}), "output")
    design = _design(top.table("design", default={}), system)
    update = top.table("update", default=None)
    update = None if update is None else _update(update, system)
    random = top.table("random", default=None)
    if random is not None:
        random = _random(random)
    spectrum = top.table("shock_response_spectrum", default=None)
    if spectrum is not None:
        spectrum = _spectrum(spectrum, simulation)
    severity = top.table("severity", default=None)
    if severity is not None:
        severity = _severity(severity, points, system, excitation, simulation, random)
    return Scenario(name=name, description=description, given_system=system, excitation=excitation,
                    simulation=simulation, frf=frf, superposition=superposition, points=points, statics=statics,
                    output=output, shock_response_spectrum=spectrum, random=random, design=design, text=text,
                    measured=tuple(fits), loss_factor_model=loss_model,
                    loss_factor_band_hz=damping.value("loss_factor_band_hz", None),
                    loss_factor_terms=damping.value("loss_factor_terms", None),
                    path=Path(source) if source != "<string>" else None, test=_test(top.table("test", default=None)),
                    update=update, severity=severity, **_response_spectrum(top, base_dir))


def _response_spectrum(top: Table, base_dir: Path) -> dict:
    """The Scenario fields of the ``[spectrum]`` table (issue 48) and its ``records`` (none without them)."""
    raw = top.table("spectrum", default=None)
    if raw is None:
        return {}
    spectrum = spectrum_settings(raw, base_dir)
    if "records" not in raw:
        return {"response_spectrum": spectrum}
    records = record_settings(raw["records"], spectrum)
    samples = round(records.duration / records.dt) + 1
    if samples > MEMORY_SAMPLES:  # each record's run is held in memory, as a [simulation] without a sink
        raise InputError("spectrum.records", f"records of at most {MEMORY_SAMPLES} samples each (duration / dt + 1)",
                         Plain(f"{samples} samples ({records.duration:g} s at {records.dt:g} s)"))
    return {"response_spectrum": spectrum, "spectrum_records": records}


# The [test] table (issue 47): a self-contained block.
def _test(raw: dict | None) -> TestSetup | None:
    """The ``[test]`` table, or None without one."""
    return None if raw is None else build(TestSetup, raw, "test")


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


def _severity(raw: dict, points, system: System, excitation, simulation, random) -> SeveritySettings:
    """The ``[severity]`` table, its points found and the answer it is computed from there (checked now: before
    anything is computed)."""
    settings = build(SeveritySettings, raw, "severity")
    make(measured_points, "severity", settings=settings, points={p.name: p.position for p in points},
         mounts={m.name: m.position for m in system.mounts})
    steady = excitation is not None and excitation.ground is None and operating_phasors(excitation)[0].size > 0
    record = None
    if simulation is not None and simulation.samples <= MEMORY_SAMPLES:  # a longer run keeps only what is drawn
        record = (simulation.start, simulation.start + simulation.duration, simulation.sample_rate_hz)
    make(chosen_source, "severity", settings=settings, steady=steady, random=random is not None, record=record)
    return settings


_DESIGN_SETTINGS = ("tolerance", "samples", "seed", "starts", "objective", "robust_samples")


def _design(raw: dict, system: System):
    table = Table(raw, "design", ("torque_axis", "target", "vary", "stiffness_ratio", *_DESIGN_SETTINGS))
    axis = table.value("torque_axis", None)
    targets = tuple(build(Target, t, f"design.target[{i}]") for i, t in enumerate(table.tables("target")))
    vary = tuple(build(Vary, t, f"design.vary[{i}]") for i, t in enumerate(table.tables("vary")))
    ratios = tuple(build(StiffnessRatio, t, f"design.stiffness_ratio[{i}]")
                   for i, t in enumerate(table.tables("stiffness_ratio")))
    settings = {k: raw[k] for k in _DESIGN_SETTINGS if k in raw}
    spec = make(DesignSpec, "design", torque_axis=None if axis is None else checked_vector(axis, "design.torque_axis"),
                target=targets, vary=vary, stiffness_ratio=ratios, **settings)
    return make(check_mounts, "design", spec=spec, mount_names=tuple(m.name for m in system.mounts))


_UPDATE_KEYS = ("vary", "mass", "inertia", "cg_offset", "starts", "seed", "objective")


def _update(raw: dict, system: System) -> UpdateSpec:
    """The ``[update]`` table (:class:`~sixdof.design.spec.UpdateSpec`): ``[[update.vary]]`` read as
    ``[[design.vary]]`` is."""
    table = Table(raw, "update", _UPDATE_KEYS)
    vary = tuple(build(Vary, t, f"update.vary[{i}]") for i, t in enumerate(table.tables("vary")))
    settings = {k: raw[k] for k in _UPDATE_KEYS if k in raw and k != "vary"}
    spec = make(UpdateSpec, "update", vary=vary, **settings)
    return make(check_update_mounts, "update", spec=spec, mount_names=tuple(m.name for m in system.mounts))


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


_TOP_LEVEL_KEYS = (
    "name", "description", "body", "mounts", "damping", "loads", "ground", "initial", "simulation",
    "frf", "superposition", "points", "statics", "output", "design", "random", "shock_response_spectrum",
    "test",
    "update",
    "spectrum",
    "severity",
)
