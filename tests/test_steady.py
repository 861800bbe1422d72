"""Steady state at the operating frequencies and isolation efficiency (issue 15, point 2), against the
textbook SDOF transmissibility, phasor sums worked by hand, and the exact time response once its transient
has died out."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from references import hysteretic_transmissibility, sdof_receptance, viscous_transmissibility
from sixdof.analysis.steady import steady_state, vector_amplitude
from sixdof.analysis.superposition import superpose
from sixdof.excitation import Excitation, HalfSine, Harmonic, Load, Unbalance
from sixdof.io.report import points_table, steady_state_text
from systems import four_mount, sdof
from tolerances import RTOL_LINALG

MASS, STIFFNESS = 120.0, 4.0e5
OMEGA_N = math.sqrt(STIFFNESS / MASS)


def vertical(f_hz, amplitude=1e3, name="f", **signal):
    return Load(name, point=[0.0, 0.0, 0.0], force=[0.0, 0.0, amplitude], signal=Harmonic(f_hz=f_hz, **signal))


@pytest.mark.parametrize("r", [0.5, 1.0, math.sqrt(2.0), 3.0])
@pytest.mark.parametrize(("zeta", "eta"), [(0.05, 0.0), (0.0, 0.1)])
def test_an_isolated_sdof_has_the_textbook_amplitude_and_transmissibility(r, zeta, eta):
    c = 2 * zeta * math.sqrt(STIFFNESS * MASS)
    f_hz = r * OMEGA_N / (2 * math.pi)
    steady = steady_state(sdof(MASS, STIFFNESS, c, eta), Excitation(loads=(vertical(f_hz),)))
    w = 2 * math.pi * f_hz
    assert steady.f_hz.tolist() == [f_hz]
    assert abs(steady.q[0, 2]) == pytest.approx(1e3 * abs(sdof_receptance(MASS, STIFFNESS, c, eta, w)), rel=RTOL_LINALG)
    assert np.abs(np.delete(steady.q[0], 2)).max() == 0.0
    expected = viscous_transmissibility(r, zeta) if eta == 0 else hysteretic_transmissibility(r, eta)
    assert steady.transmissibility[0] == pytest.approx(expected, rel=RTOL_LINALG)
    assert steady.isolation_efficiency[0] == pytest.approx(1 - expected, rel=RTOL_LINALG, abs=RTOL_LINALG)
    assert steady.applied_force[0] == pytest.approx(1e3, rel=RTOL_LINALG)
    assert steady.loss_factors == (eta > 0)  # said: a time response, without them, tends to another state
    # Below sqrt(2) the mounts amplify (efficiency < 0), above it they isolate.
    if abs(r - math.sqrt(2)) > 1e-6:  # at sqrt(2) exactly 1 (efficiency 0 to round-off)
        assert (steady.isolation_efficiency[0] > 0) == (r > math.sqrt(2))


def test_components_at_one_frequency_add_with_their_phases_and_switch_on_times():
    system = sdof(MASS, STIFFNESS, 100.0)
    # Switched on half a period later: the same as a phase of 180 degrees; together with the first, nothing.
    cancelling = (vertical(7.0), vertical(7.0, name="later", start=0.5 / 7.0))
    steady = steady_state(system, Excitation(loads=cancelling))
    assert steady.applied_force[0] < 1e-12 * 1e3 and np.abs(steady.q).max() < 1e-12 * 1e3 / STIFFNESS
    assert np.isnan(steady.transmissibility[0])  # no force applied: no ratio
    isolation = steady_state_text(steady).split("force transmissibility")[1]
    assert "nan" not in isolation and isolation.count("n/a (no force applied)") == 2  # said, not printed as nan
    # Two frequencies stay apart (ascending); a harmonic that ends and a pulse have no steady state.
    loads = (vertical(9.0, phase_deg=90.0), vertical(3.0, name="g"), vertical(5.0, name="h", duration=1.0),
             Load("hit", point=[0, 0, 0], force=[0, 0, 1.0], signal=HalfSine(start=0.1, duration=0.01)))
    steady = steady_state(system, Excitation(loads=loads))
    assert steady.f_hz.tolist() == [3.0, 9.0]
    np.testing.assert_allclose(steady.applied[:, 2], [1e3, 1e3j], rtol=RTOL_LINALG)  # sin, then cos = Im(i e^{iwt})
    assert steady_state(system, Excitation(loads=loads[2:])) is None


def test_no_steady_state_is_given_where_there_is_none_or_it_would_be_wrong():
    from sixdof.excitation import GroundMotion

    # Undamped, driven at its natural frequency: the response grows without bound.
    assert steady_state(sdof(MASS, STIFFNESS), Excitation(loads=(vertical(OMEGA_N / (2 * math.pi)),))) is None
    # With a ground motion the loads' steady state is not the body's.
    shaken = Excitation(loads=(vertical(7.0),),
                        ground=GroundMotion("acceleration", direction=[0.0, 0.0, 1.0], signal=Harmonic(f_hz=3.0)))
    assert steady_state(sdof(MASS, STIFFNESS, 100.0), shaken) is None


def test_a_rotating_force_has_a_constant_amplitude():
    # m e Omega^2 turning in the y-z plane: the force vector's largest value over a period is its magnitude.
    unbalance = Unbalance("rotor", point=[0.2, 0.0, 0.25], unbalance=0.005, speed_rpm=1480.0, axis=[1.0, 0.0, 0.0])
    steady = steady_state(four_mount(damping=(60.0, 80.0, 150.0)), Excitation(loads=(unbalance,)))
    assert steady.applied_force[0] == pytest.approx(unbalance.force_amplitude, rel=RTOL_LINALG)
    assert vector_amplitude([[1.0, 1j, 0.0]])[0] == pytest.approx(1.0)
    assert vector_amplitude([[3.0, 4.0, 0.0]])[0] == pytest.approx(5.0)


def test_the_time_response_settles_on_the_steady_state():
    """The exact modal time response of a machine on damped mounts, after ~14 time constants of its slowest
    mode: least-squares sine and cosine parts of each DOF over its last 10 periods are the phasors."""
    system = four_mount(damping=(600.0, 800.0, 1500.0))  # 5 % to 20 % of critical
    unbalance = Unbalance("rotor", point=[0.2, 0.1, 0.25], unbalance=0.005, speed_rpm=1480.0, axis=[1.0, 0.0, 0.0])
    excitation = Excitation(loads=(unbalance, vertical(11.0, amplitude=40.0, phase_deg=30.0)))
    steady = steady_state(system, excitation)
    modes = system.modes
    slowest = min(abs(p.real) for p in np.linalg.eigvals(
        np.block([[np.zeros((6, 6)), np.eye(6)], [-np.linalg.solve(system.M, system.K),
                                                   -np.linalg.solve(system.M, system.C)]])))
    settle = 14.0 / slowest
    assert modes.frequency_hz.max() < 30.0 and settle < 10.0
    rate = 40 * steady.f_hz.max()
    t = np.arange(0.0, settle + 10.0 / steady.f_hz.min(), 1.0 / rate)
    q = superpose(system, excitation, t).q
    late = t >= settle
    # Both frequencies' sine and cosine parts, least squares over the last periods.
    columns = [np.sin(2 * np.pi * f * t[late]) for f in steady.f_hz] + [np.cos(2 * np.pi * f * t[late]) for f in steady.f_hz]
    coefficients = np.linalg.lstsq(np.stack(columns, axis=1), q[late], rcond=None)[0]
    n = steady.f_hz.size
    fitted = coefficients[:n] + 1j * coefficients[n:]  # q(t) = Im(phasor e^{iwt}) = Re sin + Im cos
    for k in range(n):  # each DOF relative to its own amplitude at that frequency
        np.testing.assert_allclose(fitted[k], steady.q[k], rtol=1e-6, atol=1e-6 * np.abs(steady.q[k]).max())


@pytest.mark.slow  # 2 s on the 2-core machine
def test_a_run_stores_prints_and_summarizes_its_steady_state(tmp_path, capsys):
    from pathlib import Path

    from sixdof.cli import main
    from sixdof.io.scenario import load_scenario
    from sixdof.io.store import load_results

    text = Path("scenarios/machine_unbalance.toml").read_text().replace("duration = 3.0", "duration = 0.2")
    scenario = tmp_path / "machine.toml"
    scenario.write_text(text)
    assert main(["run", str(scenario), "--out", str(tmp_path), "--quiet"]) == 0
    out = capsys.readouterr().out
    run = load_results(tmp_path / "machine_unbalance" / "results.h5")
    stored = run.steady_state
    expected = steady_state(run.system, load_scenario(scenario).excitation)
    np.testing.assert_array_equal(stored.q, expected.q)
    assert stored.f_hz.tolist() == [pytest.approx(1480.0 / 60.0)]
    efficiency = f"{100 * stored.isolation_efficiency[0]:.1f} %"
    summary = (tmp_path / "machine_unbalance" / "summary.md").read_text()
    assert "## Steady state" in summary and efficiency in summary
    assert "isolation efficiency" in out and efficiency in out and "Statics under gravity" in out
    assert "Peaks over the whole run, the switch-on transient included." in summary


@pytest.mark.slow  # 2 s on the 2-core machine
def test_the_run_shows_its_body_points(tmp_path, capsys):
    from sixdof.analysis.response import point_motion
    from sixdof.cli import main
    from sixdof.io.store import load_results

    assert main(["run", "scenarios/bridge_beam_traffic.toml", "--out", str(tmp_path), "--quiet"]) == 0
    out = capsys.readouterr().out
    run = load_results(tmp_path / "bridge_beam_traffic" / "results.h5")
    edge = point_motion(run.response, run.points["midspan_edge"].position)
    az = np.max(np.abs(edge.acceleration[:, 2]))
    lines = out.splitlines()
    table = lines[next(i for i, line in enumerate(lines) if line.startswith("Body points")):]  # not the summary's
    row = next(line for line in table if line.startswith("| midspan_edge"))
    assert f"{az:.4g}" in row.split("|")[8]
    summary = (tmp_path / "bridge_beam_traffic" / "summary.md").read_text()
    assert "### Body points" in summary and row in summary
    assert "Absolute motion" not in summary  # the ground does not move: nothing to say of the frame
    # Where it moves, absolute points are said to be so (a base shock's drift would pass for the mounts' stroke).
    text = points_table(run.points, ground_moves=True)
    assert text.startswith("Absolute motion (fixed frame), the ground's own motion included")
    relative = {name: dataclasses.replace(motion, relative=True) for name, motion in run.points.items()}
    assert points_table(relative, ground_moves=True).startswith("Motion relative to the ground. Peaks over")
    assert "Peaks over the run, the switch-on transient included:" in points_table(run.points, steady=True)
