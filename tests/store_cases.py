"""A small but complete run of the bridge beam, shared by tests/test_store.py and tests/test_plots.py: built
from the library's own result objects, so that the store and the figures are tested on what ``sixdof run``
hands them."""

from __future__ import annotations

import dataclasses
from functools import cache

import numpy as np

from sixdof import (
    Excitation,
    Harmonic,
    Load,
    SimulationSettings,
    compare,
    force_transmissibility,
    ground_transmissibility,
    modal_analysis,
    mount_forces,
    point_frf,
    simulate,
)
from sixdof.analysis import frf as frf_module
from sixdof.analysis.mountcheck import mount_check
from sixdof.analysis.response import points_motion
from sixdof.analysis.statespace import modal_damping_ratios
from sixdof.analysis.statics import gravity_statics
from sixdof.analysis.superposition import modal_solve
from sixdof.model.kinematics import generalized_force
from sixdof.results import TimeHistory
from sixdof.validation import (
    FreeDecay,
    ModeCheck,
    RandomRun,
    ValidationReport,
    decay_estimate,
    estimate_frf,
)
from systems import BRIDGE_POSITIONS, bridge

SCENARIO_TEXT = 'name = "bridge_beam"\n# a scenario text with "quotes", unicode µ and\nnewlines\n'


@cache
def run_parts() -> dict:
    """Keyword arguments of ``build_results`` for a full run of the bridge with equal dashpots on
    every bearing (cached: built once per session)."""
    system = bridge("equal")
    modes = modal_analysis(system.M, system.K)
    zeta = modal_damping_ratios(system.C, modes)
    excitation = Excitation(loads=(
        Load("traffic", [0.3, 10.0, 1.0], force=[2e3, 5e3, -100e3], signal=Harmonic(f_hz=5.0)),
    ))
    settings = SimulationSettings(duration=2.0, sample_rate_hz=200.0)
    direct = simulate(system, excitation, settings)
    Q = np.asarray(generalized_force([0.3, 10.0, 1.0], [2e3, 5e3, -100e3]))

    def force(times):
        return np.asarray(Harmonic(f_hz=5.0)(np.asarray(times)))[:, None] * Q[None, :]

    modal = modal_solve(system.M, system.C, system.K, direct.t, force, signal_omega=2 * np.pi * 5.0)
    agreement = compare(direct.q, modal.q, length=20.0)
    f = np.geomspace(0.2, 60.0, 300)
    extras = {
        "deck_vertical": point_frf(system, f, [0.0, 10.0, 1.0], "z", [0.0, -10.0, 1.0], "z",
                                   quantity="accelerance"),
        "vertical_load": force_transmissibility(system, f, [0.0, 10.0, 1.0], "z"),
        "ground_y": ground_transmissibility(system, f, "y", [0.0, 20.0, 1.0]),
    }
    forces = mount_forces(system, direct)
    return dict(
        validation=validation_report(modes, zeta),
        system=system,
        modes=modes,
        damping_ratios=zeta,
        response=direct,
        mount_forces=forces,
        mount_check=mount_check(system, forces, direct.t, gravity_statics(system)),
        points=points_motion(direct, {"deck_end": [0.0, 20.0, 1.0], "bearing_1": BRIDGE_POSITIONS[0]}),
        superposition=modal,
        agreement=agreement,
        frf=frf_module.cross_check(system, f),
        frf_extras=extras,
        scenario_text=SCENARIO_TEXT,
        name="bridge_beam",
        description="83 t bridge beam on four elastomeric bearings",
        command_line="sixdof run scenarios/bridge_beam.toml",
    )


def validation_report(modes, zeta) -> ValidationReport:
    """A ValidationReport built from the real result types on synthetic signals (fast: running
    :func:`sixdof.validation.validate` takes tens of seconds; its numbers are tested in its own tests)."""
    rng = np.random.default_rng(1)
    decays, rows, runs = [], [], []
    for r in range(6):
        f_d = modes.frequency_hz[r] * np.sqrt(1 - zeta[r] ** 2)
        t = np.linspace(0.0, 8.0 / f_d, 512)
        sigma = zeta[r] * 2 * np.pi * modes.frequency_hz[r]
        eta = np.exp(-sigma * t) * np.cos(2 * np.pi * f_d * t)
        estimate = decay_estimate(t, eta)
        q = eta[:, None] * modes.shapes[:, r][None, :]
        history = TimeHistory(t=t, q=q, qd=np.zeros_like(q), qdd=np.zeros_like(q))
        decays.append(FreeDecay(mode=r + 1, history=history, eta=eta, estimate=estimate))
        values = dict(mode=r + 1, dominant_dof=modes.dominant_dof[r], f_model_hz=float(modes.frequency_hz[r]),
                      zeta_model=float(zeta[r]), f_damped_model_hz=float(f_d),
                      f_damped_estimated_hz=estimate.f_damped_hz, zeta_estimated=estimate.zeta,
                      log_decrement_estimated=estimate.log_decrement)
        # Columns this test does not know get a recognisable number.
        rows.append(ModeCheck(**{f.name: values.get(f.name, 0.125 * (r + 1)) for f in dataclasses.fields(ModeCheck)}))
        fs = 8.0 * modes.frequency_hz[r]
        x = rng.normal(size=2048)
        kernel = np.exp(-np.arange(24) * sigma / fs) * np.cos(2 * np.pi * f_d / fs * np.arange(24))
        y = np.convolve(x, kernel)[:2048] + 0.01 * rng.normal(size=2048)
        estimated = estimate_frf(x, y, fs, 256)
        model = np.polyval(kernel[::-1], np.exp(-2j * np.pi * estimated.f_hz / fs))[:, None]
        runs.append(RandomRun(mode=r + 1, band_hz=(0.7 * modes.frequency_hz[r], 1.3 * modes.frequency_hz[r]),
                              estimated=estimated, model=model))
    return ValidationReport(
        rows=tuple(rows), random_runs=tuple(runs), decays=tuple(decays),
        load_point=np.array(BRIDGE_POSITIONS[0]), load_direction=np.ones(3) / np.sqrt(3),
        random_duration_s=120.0, wall_time_s=1.0, notes=("a synthetic report for the storage tests",),
    )
