"""Modal superposition (sixdof.analysis.superposition) against independent answers.

- The exact response of the state-space system: the matrix exponential (scipy.linalg.expm) of the
  first-order system augmented with the linear generator of each signal piece (a sine is the
  output of a 2-state oscillator, a polynomial of a nilpotent chain), piece by piece.
- Closed forms for rigid-body (zero-frequency) modes.
- The direct solver (sixdof.analysis.direct.simulate, diffrax) for every signal kind and damping model.
"""

from __future__ import annotations

import math
from functools import cache
from types import SimpleNamespace

import numpy as np
import pytest

from references import (
    exact_response,
    free_mass_with_viscous_drag,
    generator_value,
    linear,
    oscillator,
    rayleigh_ratio,
    released_sdof,
    windowed_pieces,
)
from sixdof import (
    DOFS,
    InputError,
    Mount,
    Rayleigh,
    SimulationSettings,
    System,
    compare,
    modal_analysis,
    simulate,
    superpose,
)
from sixdof import excitation as ex
from sixdof.analysis.compare import (
    QUIET_RTOL,
    Agreement,
    column_peaks,
    compare_motion,
    merge_agreements,
    relative_to_ground,
)
from sixdof.analysis.superposition import QUADRATURE_RTOL, modal_solve, quadrature_size
from sixdof.analysis.superposition import solve as superposition_solve
from sixdof.errors import Owned, readonly
from sixdof.results import TimeHistory
from systems import BRIDGE_MASS, BRIDGE_POSITIONS, THREE_MOUNTS, bridge, bridge_body, four_mount
from tolerances import (
    MODAL_DAMPING_COUPLING_CLASSICAL,
    MODAL_DAMPING_COUPLING_MIN,
    MODAL_RESIDUAL_GAIN,
    RTOL_MODAL_DIRECT,
    RTOL_MODAL_EXACT,
    RTOL_QUADRATURE_NODES,
    RTOL_REPORTED_TRUNCATION,
    RTOL_WINDOWS,
)

# The seed paper's bridge beam (tests/systems.py): mounts 1, 2 and 3, 4 differ, so every mode couples
# several DOFs.
SYSTEMS = {
    "rayleigh": bridge(rayleigh=Rayleigh.from_ratio(0.02, (0.6, 38.0))),
    "modal": bridge(modal_damping=(0.01, 0.02, 0.03, 0.02, 0.05, 0.02)),
    "dashpots": bridge("two_pairs"),
    "combined": bridge("two_pairs", rayleigh=Rayleigh(0.05, 1e-4), modal_damping=0.01),
    # Over-damped low modes (zeta ~ 6 at 0.6 Hz): the real recursion's cosh/sinh branch.
    "overdamped": bridge(rayleigh=Rayleigh(50.0, 0.0)),
}
CLASSICAL = ("rayleigh", "modal", "overdamped")

# A load at a corner of the beam: it excites every DOF.
LOAD = np.array([2e3, -1e3, -8e4, 0.0, 0.0, 0.0])
LOAD[3:] = np.cross([0.4, 15.0, 1.0], LOAD[:3]) + [1e3, 2e3, -3e3]
# An initial state moving every DOF [m, rad; m/s, rad/s].
Q0, QD0 = np.array([1e-3, -2e-3, 5e-4, 1e-6, -3e-5, 2e-6]), np.array([-1e-2, 0.0, 3e-3, 0.0, 1e-4, -1e-5])


def sine(w, phase=0.0, amplitude=1.0):
    """``amplitude sin(w tau + phase)`` (tau from the window's start)."""
    return oscillator(w, phase, 0.0, amplitude)


def exact(system, pieces, q0=None, qd0=None, t=None):
    """q (n, 6) on t (default T) of ``M q'' + C q' + K q = LOAD s(t)``; s is the sum of the generators of
    each ``(start, end, generators)`` piece on ``[start, end)``, zero elsewhere."""
    t = T if t is None else t
    x0 = None if q0 is None else np.concatenate([q0, qd0])
    pieces = windowed_pieces(pieces, t[-1], t[0])
    return exact_response(system.M, system.C, system.K, LOAD, pieces, t, x0)[0]


def pieces_signal(pieces):
    """The same signal as a vectorized function of time (dimensionless), and its breakpoints."""

    def signal(times):
        out = np.zeros_like(times)
        for start, end, generators in pieces:
            inside = (times >= start) & (times < end)
            tau = times[inside] - start
            for generator in generators:
                out[inside] += generator_value(generator, tau)
        return out

    breakpoints = sorted({x for start, end, _ in pieces for x in (start, end) if np.isfinite(x)})
    return signal, breakpoints


T = np.linspace(0.0, 1.0, 1001)
INF = np.inf
CASES = {
    "harmonic": [(0.0, INF, [sine(2 * np.pi * 5.0, 0.3)])],
    "harmonic_late_start": [(0.3217, INF, [sine(2 * np.pi * 21.0)])],  # near the 21.3 Hz mode
    "step": [(0.1234, INF, [linear(1.0, 0.0)])],
    "ramp": [(0.05, 0.35, [linear(0.0, 1 / 0.3)]), (0.35, INF, [linear(1.0, 0.0)])],
    "half_sine": [(0.2005, 0.2505, [sine(np.pi / 0.05)])],
    "haversine": [(0.1, 0.4, [linear(0.5, 0.0), sine(2 * np.pi / 0.3, np.pi / 2, -0.5)])],
    # A table (piecewise linear) whose knots are off the output grid.
    "table": [(0.0105, 0.2, [linear(0.0, 1.0 / 0.1895)]), (0.2, 0.51, [linear(1.0, -2.0 / 0.31)]),
              (0.51, 0.9003, [linear(-1.0, 1.0 / 0.3903)])],
}


@cache
def exact_case(system_name, case):
    """Exact response, computed once per (system, case)."""
    return exact(SYSTEMS[system_name], CASES[case])


def solve(system, pieces, t=None, **options):
    signal, breakpoints = pieces_signal(pieces)
    return modal_solve(system.M, system.C, system.K, T if t is None else t,
                       lambda times: signal(times)[:, None] * LOAD, breakpoints, **options)


@pytest.mark.parametrize("system_name", list(SYSTEMS))
@pytest.mark.parametrize("case", list(CASES))
def test_matches_exact_response_with_the_automatic_method_reported(system_name, case):
    result = solve(SYSTEMS[system_name], CASES[case])
    agreement = compare(exact_case(system_name, case), result)
    assert agreement.worst < RTOL_MODAL_EXACT, str(agreement)
    info = result.superposition
    if system_name in CLASSICAL:
        assert info.method == "real" and info.reason.startswith("auto: damping is classical")
        assert info.coupling < MODAL_DAMPING_COUPLING_CLASSICAL
        assert len(info.eigenvalues) == 12
    else:
        assert info.method == "complex" and "non-proportional" in info.reason
        assert info.coupling > MODAL_DAMPING_COUPLING_MIN
    assert info.approximation is None
    assert info.truncation is None and info.modes_kept == tuple(range(6))


@pytest.mark.parametrize("system_name", ["rayleigh", "dashpots"])
def test_initial_conditions_and_mode_release(system_name):
    system = SYSTEMS[system_name]
    result = modal_solve(system.M, system.C, system.K, T, q0=Q0, qd0=QD0)
    assert compare(exact(system, [], Q0, QD0), result).worst < RTOL_MODAL_EXACT
    # The initial state goes through the modal transform and back: round-off only.
    np.testing.assert_allclose(result.q[0], Q0, rtol=RTOL_MODAL_EXACT, atol=0)
    np.testing.assert_allclose(result.qd[0], QD0, rtol=RTOL_MODAL_EXACT,
                               atol=RTOL_MODAL_EXACT * np.max(np.abs(QD0[QD0 != 0])))


def test_mode_release_stays_in_its_mode_under_classical_damping():
    system = SYSTEMS["rayleigh"]
    modes = modal_analysis(system.M, system.K)
    phi = modes.shapes[:, 3]
    result = modal_solve(system.M, system.C, system.K, T, q0=1e-3 * phi)
    # Classical damping: q(t) = eta(t) phi with eta the damped SDOF free response.
    zeta = rayleigh_ratio(system.rayleigh.alpha, system.rayleigh.beta, modes.omega[3])
    eta = released_sdof(T, 1e-3, modes.omega[3], zeta)
    assert compare(np.outer(eta, phi), result).worst < RTOL_MODAL_EXACT


def test_accelerations_satisfy_equation_of_motion():
    system = SYSTEMS["combined"]
    result = solve(system, CASES["haversine"])
    signal, _ = pieces_signal(CASES["haversine"])
    Q = signal(T)[:, None] * LOAD
    residual = result.qdd @ system.M + result.qd @ system.C + result.q @ system.K - Q
    scale = np.abs(result.qdd @ system.M).max(axis=0) + np.abs(Q).max(axis=0)
    assert np.max(np.abs(residual) / scale) < RTOL_MODAL_EXACT


def test_real_modes_on_nonproportional_damping_disagree_measurably():
    result = solve(SYSTEMS["dashpots"], CASES["half_sine"], method="real")
    agreement = compare(exact_case("dashpots", "half_sine"), result)
    assert agreement.worst > MODAL_DAMPING_COUPLING_MIN and not agreement.ok
    assert result.superposition.method == "real" and "approximate" in result.superposition.reason
    # The result reports that error itself, against the exact complex-mode computation.
    assert result.superposition.approximation is not None and not result.superposition.approximation.ok
    assert result.superposition.approximation.worst == pytest.approx(agreement.worst, rel=1e-6)


def test_forced_complex_on_classical_damping_agrees():
    result = solve(SYSTEMS["rayleigh"], CASES["table"], method="complex")
    assert result.superposition.method == "complex"
    assert compare(exact_case("rayleigh", "table"), result).worst < RTOL_MODAL_EXACT


def test_classical_damping_detected_within_repeated_modes():
    # A symmetric body on a symmetric mount layout: x/y translations and rx/ry rotations have equal
    # frequencies. Modal damping built on a rotated basis of those pairs is classical, but is
    # diagonal only in that basis: the detection must rotate within repeated modes.
    system = four_mount(1e3, (400.0, 400.0, 600.0), 1.0, 1.0, 0.5, (1e6, 1e6, 4e6))
    M, K = system.M, system.K
    modes = modal_analysis(M, K)
    f = modes.frequency_hz
    pairs = [(i, i + 1) for i in range(5) if abs(f[i + 1] - f[i]) < 1e-9 * f[-1]]
    assert len(pairs) == 2  # (x, ry) and (y, rx) coupled pairs, each repeated
    shapes = np.array(modes.shapes)
    c, s_ = np.cos(0.5), np.sin(0.5)
    for i, j in pairs:
        shapes[:, [i, j]] = shapes[:, [i, j]] @ np.array([[c, -s_], [s_, c]])
    zeta = np.array([0.01, 0.05, 0.02, 0.08, 0.03, 0.04])
    C = M @ shapes @ np.diag(2 * zeta * modes.omega) @ shapes.T @ M
    result = modal_solve(M, C, K, T, lambda t: np.sin(20 * t)[:, None] * LOAD)
    assert result.superposition.method == "real" and result.superposition.coupling < MODAL_DAMPING_COUPLING_CLASSICAL
    reference = exact(SimpleNamespace(M=M, C=C, K=K), [(0.0, INF, [sine(20.0)])])
    assert compare(reference, result).worst < RTOL_MODAL_EXACT


@pytest.mark.parametrize("system_name", ["rayleigh", "dashpots"])
def test_residual_correction_beats_plain_truncation(system_name):
    system = SYSTEMS[system_name]
    # A slow load (2 Hz, smooth start) under the dropped 21 and 38 Hz modes: they respond almost
    # statically, which is what the residual flexibility represents.
    pieces = [(0.0, 0.5, [linear(0.5, 0.0), sine(2 * np.pi / 1.0, np.pi / 2, -0.5)]),
              (0.5, INF, [linear(1.0, 0.0)])]
    reference = exact(system, pieces)
    with_residual = solve(system, pieces, n_modes=4)
    without = solve(system, pieces, n_modes=4, residual=False)
    error_with = compare(reference, with_residual).worst
    error_without = compare(reference, without).worst
    assert error_with < MODAL_RESIDUAL_GAIN * error_without
    assert with_residual.superposition.modes_kept == (0, 1, 2, 3) and with_residual.superposition.residual
    assert not without.superposition.residual
    # The reported truncation error is the error against the full set of modes.
    assert with_residual.superposition.truncation.worst == pytest.approx(error_with, rel=RTOL_REPORTED_TRUNCATION)
    assert without.superposition.truncation.worst == pytest.approx(error_without, rel=RTOL_REPORTED_TRUNCATION)


def test_truncation_by_frequency():
    result = solve(SYSTEMS["rayleigh"], CASES["step"], f_max_hz=10.0)
    assert result.superposition.modes_kept == (0, 1, 2, 3)
    assert np.all(result.superposition.frequency_hz <= 10.0)


T_RIGID = np.linspace(0.0, 5.0, 501)


def free_floating(horizontal_damping=0.0, vertical_damping=1e5, **damping):
    """Mounts stiff only vertically: x, y and rz are rigid-body (zero-frequency) modes."""
    mounts = [Mount(str(i + 1), p, [0.0, 0.0, 3e8],
                    damping=[horizontal_damping, horizontal_damping, vertical_damping * (1 + i)])
              for i, p in enumerate(BRIDGE_POSITIONS)]
    return System(bridge_body(), mounts, **damping)


def constant_force(system, force, **options):
    """The response over T_RIGID to a constant generalized force (6,)."""
    return modal_solve(system.M, system.C, system.K, T_RIGID, lambda s: np.ones((s.size, 1)) * force, **options)


def test_rigid_body_modes_undamped_move_as_free_mass():
    force = np.array([100.0, -50.0, 0.0, 0.0, 0.0, 0.0])
    result = constant_force(free_floating(), force, qd0=[1e-3, 0, 0, 0, 0, 0])
    expected_x = 1e-3 * T_RIGID + force[0] / BRIDGE_MASS * T_RIGID**2 / 2
    expected_y = force[1] / BRIDGE_MASS * T_RIGID**2 / 2
    np.testing.assert_allclose(result.q[:, 0], expected_x, rtol=RTOL_MODAL_EXACT, atol=0)
    np.testing.assert_allclose(result.q[1:, 1], expected_y[1:], rtol=RTOL_MODAL_EXACT, atol=0)
    assert result.superposition.method == "complex"  # the vertical dashpots are not proportional


@pytest.mark.parametrize("method", ["real", "complex"])
def test_rigid_body_modes_with_mass_proportional_damping(method):
    # eta'' + alpha eta' = F/m from rest: x(t) = F/(m alpha) (t - (1 - e^{-alpha t}) / alpha).
    alpha = 0.8
    force = np.array([100.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    result = constant_force(free_floating(vertical_damping=0.0, rayleigh=Rayleigh(alpha, 0.0)), force, method=method)
    expected = free_mass_with_viscous_drag(T_RIGID, force[0], BRIDGE_MASS, alpha)
    np.testing.assert_allclose(result.q[1:, 0], expected[1:], rtol=RTOL_MODAL_EXACT, atol=0)
    assert result.superposition.method == method


def test_rigid_body_modes_with_horizontal_dashpots_match_exact():
    system = free_floating(horizontal_damping=2e4)
    pieces = CASES["half_sine"]
    result = solve(system, pieces)
    assert result.superposition.method == "complex"
    assert compare(exact(system, pieces), result).worst < RTOL_MODAL_EXACT


def test_a_body_free_to_turn_about_one_mount_matches_exact():
    # One mount off the CG: the body turns freely about it (three rigid-body modes that mix every DOF), and
    # neither spring nor dashpot resists them. Their modal damping is round-off of the transform, which must
    # not read as a coupling (it did: complex modes of the free motion's Jordan block, refused as defective).
    system = System(bridge_body(), [Mount("only", [3.0, 0.4, -0.6], [2e8, 3e8, 6e8], damping=[1e5, 2e5, 9e5])])
    assert len(system.modes.zero_modes) == 3
    pieces = CASES["half_sine"]
    result = solve(system, pieces)
    assert result.superposition.method == "complex"  # the dashpots are not proportional to the springs
    assert compare(exact(system, pieces), result).worst < RTOL_MODAL_EXACT


def test_truncation_must_keep_rigid_body_modes():
    system = free_floating()
    with pytest.raises(InputError, match=r"n_modes: expected at least 3 \(the rigid-body modes"):
        modal_solve(system.M, system.C, system.K, T, n_modes=2)


def test_compare_each_dof_on_its_own_scale():
    t = np.linspace(0, 1, 101)
    ref = np.stack([1e-4 * np.sin(7 * t), 2e-4 * np.cos(3 * t), 1e-3 * t, 1e-7 * t, 3e-6 * t**2,
                    -2e-7 * np.sin(t)], axis=1)
    other = ref.copy()
    other[:, 3] += 1e-14  # 1e-7 of the rx peak (1e-7 rad): invisible next to x, visible on rx
    agreement = compare(ref, other, tolerance=1e-6)
    assert isinstance(agreement, Agreement)
    assert agreement.worst_dof == "rx"
    assert agreement.worst == pytest.approx(1e-7, rel=1e-6)
    assert agreement.ok and agreement.quiet == ()
    np.testing.assert_array_equal(agreement.per_dof[[0, 1, 2, 4, 5]], 0.0)
    assert not compare(ref, other, tolerance=1e-8).ok


def test_compare_judges_quiet_dofs_against_the_largest_response():
    t = np.linspace(0, 1, 101)
    ref = np.zeros((101, 6))
    ref[:, 2] = 1e-3 * np.sin(5 * t)  # only z moves
    other = ref.copy()
    other[:, 0] = 1e-18  # round-off in a DOF that does not move
    other[:, 4] = 1e-18  # ry (rad): 1 m lever arm by default
    agreement = compare(ref, other)
    assert agreement.quiet == ("x", "y", "rx", "ry", "rz")
    assert agreement.per_dof[0] == pytest.approx(1e-18 / np.abs(ref[:, 2]).max())
    assert agreement.per_dof[4] == pytest.approx(1e-18 / np.abs(ref[:, 2]).max())
    assert agreement.ok
    assert compare(np.zeros((3, 6)), np.zeros((3, 6))).worst == 0.0
    assert compare(np.zeros((3, 6)), np.full((3, 6), 1e-30)).worst == np.inf


def test_compare_errors():
    with pytest.raises(InputError, match=r"modal_q: expected shape \(10, 6\) like direct_q, got "
                                         r"'shape \(9, 6\)'"):
        compare(np.zeros((10, 6)), np.zeros((9, 6)))
    with pytest.raises(InputError, match=r"direct_q: expected an array of shape \(n, 6\)"):
        compare(np.zeros((10, 3)), np.zeros((10, 3)))
    with pytest.raises(InputError, match="tolerance: expected a positive number, got -1"):
        compare(np.zeros((10, 6)), np.zeros((10, 6)), tolerance=-1)


@pytest.mark.parametrize("options, message", [
    (dict(method="x"), "method: expected one of 'auto', 'real', 'complex', got 'x'"),
    (dict(t=[0.0, 1.0, 0.5]), r"t: expected at least 2 finite, strictly increasing times in s, "
                              r"got t\[2\] = 0.5 after t\[1\] = 1"),
    (dict(n_modes=7), "n_modes: expected an integer from 1 to 6, got 7"),
    (dict(f_max_hz=0.1), r"f_max_hz: expected at least the lowest natural frequency"),
    (dict(force=lambda s: np.zeros((s.size, 3))), r"force: expected a callable returning shape \(\d+, 6\)"),
    (dict(q0=[1.0, 2.0]), "q0: expected 6 finite values"),
])
def test_input_errors(options, message):
    system = SYSTEMS["rayleigh"]
    with pytest.raises(InputError, match=message):
        modal_solve(system.M, system.C, system.K, **(dict(t=T) | options))


def test_result_is_frozen():
    result = solve(SYSTEMS["rayleigh"], CASES["step"])
    assert isinstance(result, TimeHistory)
    with pytest.raises(AttributeError):
        result.superposition.method = "complex"
    with pytest.raises(ValueError):
        result.q[0, 0] = 1.0


SETTINGS = SimulationSettings(duration=1.0, sample_rate_hz=1000.0)
POINT, MOMENT = [0.4, 15.0, 1.0], [1e3, 2e3, -3e3]


def _loads(*signals):
    """One load per signal, at different points and in different directions, of similar size."""
    points = ([0.4, 15.0, 1.0], [-0.5, -12.0, 0.8], [0.3, 5.0, -1.0], [0.0, -18.0, 0.5])
    forces = ([2e3, -1e3, -8e4], [-1e4, 3e3, 6e4], [5e3, 1e4, -5e4], [-3e3, -2e3, 7e4])
    return ex.Excitation(loads=[
        ex.Load(f"load{k}", points[k], forces[k], MOMENT, signal=signal)
        for k, signal in enumerate(signals)
    ])


# The direct solver compiles once per combination of signal kinds, so the kinds are grouped a few
# per excitation (each load of similar size, so that none hides another's error); every kind is
# also checked alone against the exact matrix exponential above.
EXCITATIONS = {
    "harmonic_step_half_sine": _loads(
        ex.Harmonic(f_hz=5.0, phase_deg=20.0), ex.Step(start=0.1234),
        ex.HalfSine(start=0.1003, duration=0.05)),
    "sweeps_ramp": _loads(
        ex.Sweep(f0_hz=0.5, f1_hz=40.0, duration=0.9, start=0.05),
        ex.Sweep(f0_hz=0.5, f1_hz=40.0, duration=0.9, law="log"), ex.Ramp(duration=0.3, start=0.05)),
    "haversine_table_random_unbalance": ex.Excitation(loads=_loads(
        ex.Haversine(start=0.1, duration=0.3),
        ex.Table(t=[0.0105, 0.2, 0.51, 0.9003], values=[0.0, 1.0, -1.0, 0.0]),
        ex.Random(f_hz=(0.5, 50.0), rms=0.3, seed=3)).loads + (
        ex.Unbalance("rotor", POINT, unbalance=5.0, f_hz=12.0, axis=[0.0, 1.0, 0.0], start=0.05),)),
    "ground_displacement": ex.Excitation(ground=ex.GroundMotion(
        "displacement", [1.0, 0.2, 0.0], ex.Table(t=[0.1, 0.3, 0.6, 0.9],
                                                  values=[0.0, 0.01, -0.005, 0.0]))),
    "ground_velocity": ex.Excitation(ground=ex.GroundMotion(
        "velocity", [0.0, 0.3, 1.0], ex.HalfSine(start=0.1, duration=0.2), scale=0.1)),
    "ground_acceleration": ex.Excitation(ground=ex.GroundMotion(
        "acceleration", [0.3, 1.0, 0.2], ex.Random(f_hz=(0.5, 20.0), rms=1.0, seed=1), scale=0.5)),
    "initial_state": ex.Excitation(initial=ex.InitialState(q=Q0, qd=QD0)),
    "mode_release": ex.Excitation(initial=ex.ModeRelease(mode=2, amplitude=1e-3)),
}
DIRECT_SYSTEMS = ("rayleigh", "modal", "dashpots", "combined")


@cache
def direct(system_name, kind):
    """Direct solution, computed once per (system, excitation); compiled once per signal kind."""
    return simulate(SYSTEMS[system_name], EXCITATIONS[kind], SETTINGS)


@pytest.mark.long  # over 10 s on the 2-core machine
@pytest.mark.parametrize("system_name", DIRECT_SYSTEMS)
@pytest.mark.parametrize("kind", list(EXCITATIONS))
def test_agrees_with_direct_solver(system_name, kind):
    """In displacement, velocity and acceleration: the direct solve's state and its equation of motion against
    the superposition's exact derivatives."""
    reference = direct(system_name, kind)
    result = superpose(SYSTEMS[system_name], EXCITATIONS[kind], reference.t)
    omega = float(np.max(SYSTEMS[system_name].modes.omega))
    agreement = compare_motion(reference, result, tolerance=RTOL_MODAL_DIRECT, omega=omega)
    assert agreement.rates and agreement.ok, str(agreement)
    assert agreement.worst == max(max(agreement.per_dof), max(agreement.per_dof_qd), max(agreement.per_dof_qdd))
    relative = compare(*relative_to_ground(reference, result), absolute=reference.q if reference.has_ground else None)
    np.testing.assert_array_equal(agreement.per_dof, relative.per_dof)  # q: as compare judges it
    assert result.superposition.method == ("real" if system_name in CLASSICAL else "complex")


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_real_modes_on_dashpots_disagree_with_direct_solver():
    reference = direct("dashpots", "harmonic_step_half_sine")
    result = superpose(SYSTEMS["dashpots"], EXCITATIONS["harmonic_step_half_sine"], reference.t,
                       method="real")
    agreement = compare(reference, result, tolerance=RTOL_MODAL_DIRECT)
    assert agreement.worst > MODAL_DAMPING_COUPLING_MIN and not agreement.ok
    assert not result.superposition.approximation.ok


@pytest.mark.slow  # 3 s on the 2-core machine
def test_truncated_superposition_reports_error_against_full_set():
    reference = direct("combined", "sweeps_ramp")
    truncated = superpose(SYSTEMS["combined"], EXCITATIONS["sweeps_ramp"], reference.t, n_modes=5)
    actual = compare(reference, truncated).worst
    # The reported truncation error (against the full modal set) is the error against the direct
    # solution, up to the direct solver's own error.
    assert truncated.superposition.truncation.worst == pytest.approx(actual, rel=RTOL_REPORTED_TRUNCATION)
    assert truncated.superposition.truncation.worst > RTOL_MODAL_DIRECT


# ----------------------------------------------------------------------------------------------------
# The exact engine: windows, non-uniform grids, chains near critical damping, breakpoints between samples.
# ----------------------------------------------------------------------------------------------------

# Loads, a ground accelerating (integrated twice, the integrals carried across windows) and an initial state.
WINDOWED = ex.Excitation(
    loads=_loads(ex.Harmonic(f_hz=5.0, phase_deg=20.0), ex.HalfSine(start=0.2005, duration=0.05)).loads,
    ground=ex.GroundMotion("acceleration", [0.3, 1.0, 0.2], ex.Random(f_hz=(0.5, 20.0), rms=1.0, seed=1), scale=0.5),
    initial=ex.InitialState(q=Q0, qd=QD0))


def per_dof_error(actual, expected):
    """max over DOFs of max_t |actual - expected| / max_t |expected|."""
    return float(np.max(np.max(np.abs(actual - expected), axis=0) / np.max(np.abs(expected), axis=0)))


@pytest.mark.parametrize("system_name", ["rayleigh", "dashpots"])
@pytest.mark.parametrize("options", [{}, {"n_modes": 4}, {"method": "real"}], ids=["all", "truncated", "real"])
@pytest.mark.parametrize("overlap", [True, False], ids=["from_last_sample", "from_next_sample"])
def test_windows_continue_one_run_exactly(system_name, options, overlap):
    system = SYSTEMS[system_name]
    whole = superpose(system, WINDOWED, T, **options)
    histories, state, low = [], None, 0
    for high in (300, 302, 650, len(T)):  # the second window: two samples
        window = T[low - 1:high] if overlap and state is not None else T[low:high]
        history = superpose(system, WINDOWED, window, start=state, **options)
        state = history.superposition.end
        histories.append(history)
        low = high
    assert state.t == T[-1]
    for name in ("q", "qd", "qdd"):
        chained = np.concatenate([getattr(h, name)[int(overlap and k > 0):] for k, h in enumerate(histories)])
        assert per_dof_error(chained, getattr(whole, name)) < RTOL_WINDOWS, name


def test_a_window_continues_only_its_own_computation():
    state = superpose(SYSTEMS["dashpots"], WINDOWED, T[:300]).superposition.end
    with pytest.raises(InputError, match=r"start: expected the state of the same computation"):
        superpose(SYSTEMS["dashpots"], WINDOWED, T[299:400], start=state, n_modes=4)
    with pytest.raises(InputError, match=r"start: expected a state at or before t\[0\] = 0.1 s, got 'a state at "
                                         r"0.299 s'"):
        superpose(SYSTEMS["dashpots"], WINDOWED, T[100:400], start=state)


# Steps of 0.5 to 1.5 ms in random order, so that no two neighbours are equal.
T_UNEVEN = np.concatenate([[0.0], np.cumsum(np.random.default_rng(4).uniform(0.5e-3, 1.5e-3, 400))])


@pytest.mark.parametrize("system_name", ["rayleigh", "dashpots", "overdamped"])
@pytest.mark.parametrize("case", ["half_sine", "table"])
def test_non_uniform_grid_matches_exact_response(system_name, case):
    system = SYSTEMS[system_name]
    result = solve(system, CASES[case], t=T_UNEVEN)
    assert result.superposition.n_intervals == T_UNEVEN.size - 1
    assert compare(exact(system, CASES[case], t=T_UNEVEN), result).worst < RTOL_MODAL_EXACT


def modal_damping_matrix(system, zeta):
    """``C = M Phi diag(2 zeta omega) Phi' M``: exactly the ratios zeta (up to and beyond critical)."""
    modes = modal_analysis(system.M, system.K)
    return system.M @ modes.shapes @ np.diag(2 * np.asarray(zeta) * modes.omega) @ modes.shapes.T @ system.M


@pytest.mark.parametrize("zeta", [1.0, 0.99, 0.97, 3.0], ids=["critical", "near_critical", "just_under", "over"])
def test_modes_damped_near_or_beyond_critical_match_exact_response(zeta):
    # Two modes at zeta, each a defective (critical) or nearly defective first-order system: solved as
    # a chain of two coordinates (or, just under 0.968, as one complex mode), exactly either way.
    base = SYSTEMS["rayleigh"]
    system = SimpleNamespace(M=base.M, K=base.K, C=modal_damping_matrix(base, (0.02, zeta, 0.03, zeta, 0.05, 0.02)))
    for case in ("half_sine", "ramp"):
        result = solve(system, CASES[case], q0=Q0, qd0=QD0)
        assert result.superposition.method == "real"
        assert compare(exact(system, CASES[case], Q0, QD0), result).worst < RTOL_MODAL_EXACT, case


def test_a_pulse_between_two_samples_is_felt_exactly():
    # A 0.4 ms half-sine inside the output step [0.300, 0.301): the recursion keeps that step, the
    # quadrature splits it at both ends of the pulse.
    pieces = [(0.30012, 0.30052, [sine(np.pi / 0.0004)])]
    for system_name in ("rayleigh", "dashpots"):
        result = solve(SYSTEMS[system_name], pieces)
        assert result.superposition.n_intervals == T.size - 1
        assert compare(exact(SYSTEMS[system_name], pieces), result).worst < RTOL_MODAL_EXACT


@pytest.mark.parametrize("case", ["harmonic_late_start", "half_sine", "table"])
def test_the_automatic_quadrature_adds_no_error(case):
    signal_omega = 2 * np.pi * 21.0 if case == "harmonic_late_start" else 2 * np.pi * 20.0
    automatic = solve(SYSTEMS["dashpots"], CASES[case], signal_omega=signal_omega)
    many = solve(SYSTEMS["dashpots"], CASES[case], quadrature_nodes=16, max_step=3e-4)
    assert many.superposition.quadrature_nodes == 64 and automatic.superposition.quadrature_nodes < 16
    for name in ("q", "qd", "qdd"):
        assert per_dof_error(getattr(automatic, name), getattr(many, name)) < RTOL_QUADRATURE_NODES, name


@pytest.mark.parametrize("theta, theta_ground", [(0.0, 0.0), (0.37, 0.0), (0.37, 0.13), (4.0, 0.0), (300.0, 5.0)])
def test_quadrature_size_keeps_the_error_bound(theta, theta_ground):
    nodes, pieces = quadrature_size(theta, theta_ground)
    n = nodes
    gauss = math.factorial(n) ** 4 / ((2 * n + 1) * math.factorial(2 * n) ** 3) * (theta / pieces) ** (2 * n)
    interpolation = math.factorial(n) / math.factorial(2 * n) * (theta_ground / pieces) ** n
    assert gauss <= QUADRATURE_RTOL and interpolation <= QUADRATURE_RTOL
    if nodes > 3:  # the fewest nodes: one fewer breaks the bound
        n = nodes - 1
        fewer = max(math.factorial(n) ** 4 / ((2 * n + 1) * math.factorial(2 * n) ** 3) * (theta / pieces) ** (2 * n),
                    math.factorial(n) / math.factorial(2 * n) * (theta_ground / pieces) ** n)
        assert fewer > QUADRATURE_RTOL


def test_column_peaks_are_each_columns_largest_magnitude():
    values = np.random.default_rng(4).standard_normal((2001, 6)) * [1e-4, 1e-7, 3.0, 1e-9, 5e2, 1.0]
    np.testing.assert_array_equal(column_peaks(values), np.max(np.abs(values), axis=0))
    np.testing.assert_array_equal(column_peaks(values[:, 3:]), np.max(np.abs(values[:, 3:]), axis=0))
    np.testing.assert_array_equal(column_peaks(np.zeros((0, 3))), np.zeros(3))
    assert np.isnan(column_peaks(np.array([[1.0, np.nan], [2.0, 0.0]]))[1])
    for given in (np.asfortranarray(values), values[:1].copy()):  # the transposes are C-ordered views: not written
        before = given.copy()
        given.flags.writeable = False
        np.testing.assert_array_equal(column_peaks(given), np.max(np.abs(before), axis=0))
        np.testing.assert_array_equal(given, before)


def test_the_history_holds_the_engines_arrays_and_copies_anyone_elses(monkeypatch):
    # The engine hands its fresh q, q', q'' over to the history (no copies); an array anyone else holds is copied,
    # read-only or not, and whatever they do to it afterwards.
    given = {}

    def history(**fields):
        given.update(fields)
        return TimeHistory(**fields)

    monkeypatch.setattr(superposition_solve, "TimeHistory", history)
    result = solve(SYSTEMS["dashpots"], CASES["step"])
    for name in ("q", "qd", "qdd"):
        held = getattr(result, name)
        assert not held.flags.writeable and held is given[name].array, name  # the engine's own array, not a copy
    fresh = np.ones((3, 6))
    assert TimeHistory(t=np.arange(3.0), q=Owned(fresh), qd=fresh, qdd=fresh).q is fresh and not fresh.flags.writeable
    mine = np.ones((3, 6))
    view = mine[:]
    mine.flags.writeable = False  # read-only, its own memory, with a writeable view of it still about
    for given in (mine, mine[1:], np.ones((3, 6))):
        assert readonly(given) is not given and not readonly(given).flags.writeable
    history = TimeHistory(t=np.arange(3.0), q=mine, qd=mine, qdd=mine)
    view[0, 0] = 5.0
    mine.flags.writeable = True
    mine[1, 1] = 7.0
    assert np.all(history.q == 1.0) and np.all(history.t == np.arange(3.0))


def test_compare_floors_relative_motion_at_the_absolute_motion():
    """Relative to a moving ground, no DOF's error is divided by less than 1e-6 of the largest absolute motion;
    without ground motion (absolute = relative) the floor is the quiet threshold itself and nothing changes."""
    t = np.linspace(0, 1, 101)
    ref = np.stack([1e-4 * np.sin(7 * t), 2e-4 * np.cos(3 * t), 1e-3 * t, 1e-7 * t, 3e-6 * t**2,
                    -2e-10 * np.sin(t)], axis=1)
    other = ref + 1e-16
    plain = compare(ref, other)
    same = compare(ref, other, absolute=ref)
    np.testing.assert_array_equal(same.per_dof, plain.per_dof)
    assert same.quiet == plain.quiet == ("rz",)
    # Relative motion identically zero, the body 2 cm away with the ground: judged against 2e-8 m, not inf.
    absolute = np.zeros((101, 6))
    absolute[:, 2] = 0.02
    riding = compare(np.zeros((101, 6)), np.full((101, 6), 1e-17), absolute=absolute)
    assert compare(np.zeros((101, 6)), np.full((101, 6), 1e-17)).worst == np.inf  # what the floor prevents
    np.testing.assert_allclose(riding.per_dof, 1e-17 / (QUIET_RTOL * 0.02), rtol=1e-12)
    np.testing.assert_allclose(riding.denominator, QUIET_RTOL * 0.02, rtol=1e-12)
    assert riding.ok and riding.quiet == DOFS


@pytest.mark.slow  # 3 s on the 2-core machine
def test_a_body_riding_a_pre_displaced_ground_agrees_to_round_off():
    """The ground held 5 cm away from the start: the body rides it at rest on its mounts (q = the ground's
    translation, no rotation: the exact answer), the two solutions differ by round-off, and the cross-check
    says ok with a finite figure instead of "worst inf ... OVER TOLERANCE"."""
    from sixdof import parse_scenario

    lines = ['name = "ride"', "[body]", "mass = 120.0", "inertia = [4.0, 5.0, 6.0]"]
    for name, p, k in THREE_MOUNTS:
        lines += ["[[mounts]]", f'name = "{name}"', f"position = {p!r}", f"stiffness = {k!r}",
                  "damping = [50.0, 50.0, 200.0]"]
    lines += ["[ground]", 'quantity = "displacement"', "direction = [0.3, 0.2, 1.0]", "scale = 0.05",
              'signal = { kind = "table", t = [0.0, 1.0], values = [1.0, 1.0], outside = "hold" }',
              "[simulation]", "duration = 0.1", "sample_rate_hz = 2000.0"]
    scenario = parse_scenario("\n".join(lines) + "\n", "ride.toml")
    direct = simulate(scenario.system, scenario.excitation, scenario.simulation)
    modal = superpose(scenario.system, scenario.excitation, direct.t)
    offset = 0.05 * np.array([0.3, 0.2, 1.0]) / np.linalg.norm([0.3, 0.2, 1.0])
    np.testing.assert_allclose(direct.q, np.broadcast_to(np.r_[offset, 0, 0, 0], direct.q.shape), rtol=0, atol=1e-15)
    np.testing.assert_allclose(modal.q, direct.q, rtol=0, atol=1e-15)
    agreement = compare(*relative_to_ground(direct, modal), absolute=direct.q)
    assert agreement.ok and np.all(np.isfinite(agreement.per_dof)) and agreement.worst < 1e-6


def test_compare_motion_judges_velocities_and_accelerations_too():
    """Displacements that agree to 1e-9 hide accelerations 1e-5 apart (an error in a high mode is omega^2 larger
    in qdd): compare judged q alone and said ok; compare_motion gives each quantity per DOF and its verdict over
    all three."""
    t = np.linspace(0.0, 1.0, 1001)
    omega = np.array([3.0, 5.0, 7.0, 11.0, 13.0, 17.0])
    amplitude = np.array([1e-3, 2e-3, 1e-3, 1e-4, 2e-4, 1e-4])
    q = amplitude * np.sin(np.outer(t, omega))
    exact = SimpleNamespace(q=q, qd=amplitude * omega * np.cos(np.outer(t, omega)), qdd=-omega**2 * q)
    off = SimpleNamespace(q=exact.q * (1 + 1e-9), qd=exact.qd, qdd=exact.qdd.copy())
    off.qdd[:, 2] += 1e-5 * np.abs(exact.qdd[:, 2]).max() * np.sin(300.0 * t)
    assert compare(exact.q, off.q).ok
    agreement = compare_motion(exact, off)
    assert not agreement.ok and (agreement.worst_dof, agreement.worst_quantity) == ("z", "qdd")
    np.testing.assert_allclose(agreement.per_dof, 1e-9, rtol=1e-6)
    np.testing.assert_array_equal(agreement.per_dof_qd, 0.0)
    assert agreement.per_dof_qdd[2] == pytest.approx(1e-5, rel=1e-3) and agreement.worst == agreement.per_dof_qdd[2]
    assert "(z, acceleration)" in str(agreement) and "per DOF, velocity:" in str(agreement)
    merged = merge_agreements([compare_motion(exact, off, keep=t <= 0.5), compare_motion(exact, off, keep=t > 0.5)])
    np.testing.assert_allclose(merged.per_dof_qdd, agreement.per_dof_qdd, rtol=1e-12)
    # At rest in both paths but for round-off, velocities and accelerations are judged against the motion the
    # largest displacement has at omega (its floor), not called infinitely wrong.
    still = SimpleNamespace(q=np.full((5, 6), 1e-3), qd=np.zeros((5, 6)), qdd=np.zeros((5, 6)))
    noisy = SimpleNamespace(q=still.q, qd=np.full((5, 6), 1e-20), qdd=np.full((5, 6), 1e-18))
    assert compare_motion(still, noisy).worst == np.inf
    rest = compare_motion(still, noisy, omega=100.0)
    np.testing.assert_allclose(rest.per_dof_qd, 1e-20 / (QUIET_RTOL * 1e-3 * 100.0), rtol=1e-12)
    np.testing.assert_allclose(rest.per_dof_qdd, 1e-18 / (QUIET_RTOL * 1e-3 * 100.0**2), rtol=1e-12)
    with pytest.raises(InputError, match=r"omega: expected a positive angular frequency in rad/s, got -1"):
        compare_motion(still, noisy, omega=-1.0)
    with pytest.raises(InputError, match=r"modal.qd: expected shape \(5, 6\) like direct.qd, got 'shape \(4, 6\)'"):
        compare_motion(still, SimpleNamespace(q=still.q, qd=np.zeros((4, 6)), qdd=still.qdd))


def test_an_agreement_with_a_nan_is_not_ok():
    """A NaN in the differences (a solve gone wrong) is the worst value, never passed over as smaller."""
    from sixdof.analysis.compare import agreement_of

    error = np.array([1e-9, np.nan, 0.0, 0.0, 0.0, 0.0])
    found = agreement_of(np.ones(6), error)
    assert not found.ok and np.isnan(found.worst) and found.worst_dof == "y"
