"""Ground records that drift: the baseline correction, the drift warning, and relative motion first."""

from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import null_space

from sixdof.analysis.validity import GROUND_DRIFT_SHARE, GroundDriftWarning, ground_drift
from sixdof.cli import main
from sixdof.dofs import display_unit
from sixdof.errors import ScenarioError
from sixdof.excitation import GroundMotion, Table
from sixdof.excitation.baseline import BASELINE_DEGREE, integrate_record, polynomial_baseline
from sixdof.files import read_table_csv
from sixdof.io.report import baseline_text, peaks_text, points_table
from sixdof.io.scenario import load_scenario, parse_scenario
from sixdof.results import TimeHistory
from sixdof.workflows.run import run_scenario
from tolerances import RTOL_BASELINE, RTOL_RECORD_INTEGRAL

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
G = 9.80665


@pytest.fixture(scope="module")
def record():
    """The bundled accelerogram [s, m/s^2] (peak 0.1 g, 20 s at 100 Hz)."""
    t, a = read_table_csv("ground_accelerogram.csv", SCENARIOS, "file")
    return np.array(t), G * np.array(a)


def test_a_record_integrates_exactly_as_a_first_order_hold():
    t = np.sort(np.random.default_rng(1).uniform(0.0, 3.0, 2001))  # uneven steps
    t = t - t[0]
    a = 0.7 - 1.3 * t  # a straight line: its first-order hold is itself
    v, d = integrate_record(t, a)
    v_exact, d_exact = 0.7 * t - 0.65 * t**2, 0.35 * t**2 - 1.3 * t**3 / 6
    assert np.max(np.abs(v - v_exact)) <= RTOL_RECORD_INTEGRAL * np.max(np.abs(v_exact))
    assert np.max(np.abs(d - d_exact)) <= RTOL_RECORD_INTEGRAL * np.max(np.abs(d_exact))


@pytest.mark.parametrize("degree", [2, 3, 4, 6])
def test_a_corrected_record_ends_at_rest(record, degree):
    t, a = record
    drifting = a + 0.01 * G * (1 + 0.3 * np.sin(t))  # an offset of 10 % of the peak, not a polynomial
    v, d = integrate_record(t, drifting)
    corrected = polynomial_baseline(t, drifting, degree)
    v_c, d_c = integrate_record(t, corrected)
    assert abs(v_c[-1]) <= RTOL_BASELINE * np.max(np.abs(v))
    assert abs(d_c[-1]) <= RTOL_BASELINE * np.max(np.abs(d))
    assert abs(d[-1]) > 10.0  # the drift it removed: ~20 m


@pytest.mark.parametrize("degree", [2, 3, 4])
def test_a_polynomial_drift_added_to_a_record_is_removed_exactly(record, degree):
    """The correction removes any drift whose velocity is a polynomial of its degree (zero at the start): the
    record with it corrects to the record without it."""
    t, a = record
    tau = t / t[-1]
    coefficients = np.array([0.3, -0.2, 0.05, 0.01])[:degree]  # m/s at tau = 1
    drift = sum(c * (j + 1) * tau**j / t[-1] for j, c in enumerate(coefficients))  # d/dt sum c_j tau^(j+1)
    restored = polynomial_baseline(t, a + drift, degree)
    assert np.max(np.abs(restored - polynomial_baseline(t, a, degree))) <= RTOL_BASELINE * np.max(np.abs(a))


def test_the_default_correction_restores_a_record_that_ends_at_rest(record):
    """Degree 2 (the default) is fixed by the two end conditions alone: a record already at rest at its end
    with an offset and a linear trend added comes back as it was."""
    assert BASELINE_DEGREE == 2
    t, a = record
    at_rest = polynomial_baseline(t, a)  # the bundled record, brought exactly to rest (it is within 4e-6 m/s)
    assert np.max(np.abs(at_rest - a)) <= 1e-5 * np.max(np.abs(a))
    drifting = at_rest + 0.004 * G - 0.0002 * G * t
    assert np.max(np.abs(polynomial_baseline(t, drifting) - at_rest)) <= RTOL_BASELINE * np.max(np.abs(a))


def test_a_higher_degree_is_the_constrained_least_squares_fit_of_the_velocity(record):
    """Against the same fit solved another way: the end conditions' null space, then unconstrained least squares."""
    t, a = record
    drifting = a + 0.002 * G * np.cos(0.2 * t)
    degree = 4
    tau = t / t[-1]
    drifts = np.stack([j * tau ** (j - 1) / t[-1] for j in range(1, degree + 1)], axis=1)
    basis_v, basis_d = integrate_record(t, drifts)
    v, d = integrate_record(t, drifting)
    ends = np.stack([basis_v[-1], basis_d[-1]])
    particular = np.linalg.lstsq(ends, np.array([v[-1], d[-1]]), rcond=None)[0]
    free = null_space(ends)
    z = np.linalg.lstsq(basis_v @ free, v - basis_v @ particular, rcond=None)[0]
    expected = drifting - drifts @ (particular + free @ z)
    corrected = polynomial_baseline(t, drifting, degree)
    assert np.max(np.abs(corrected - expected)) <= RTOL_BASELINE * np.max(np.abs(a))


def _ground(t, a, **keys):
    return GroundMotion(quantity="acceleration", direction=[1.0, 0.0, 0.0],
                        signal=Table(t=t, values=a / G), scale=G, **keys)


def _integrated(ground, t_end):
    """The ground's displacement (n, 3) [m] at the record's samples and ``t_end`` after it, exact for the table."""
    signal = ground.signal
    t = np.append(signal.t, t_end)
    v, d = integrate_record(signal.t, ground.scale * np.asarray(signal.values))
    u = np.append(d, d[-1] + v[-1] * (t_end - signal.t[-1]))  # at rest in acceleration after the record
    return t, u[:, None] * ground.direction


def test_a_drifting_record_warns_with_its_numbers_and_the_advice(record):
    t, a = record
    ground = _ground(t, a + 0.001 * G)  # 1 % of the peak: a typical baseline offset
    times, u = _integrated(ground, 25.0)
    message = ground_drift(ground, times, u)
    end, peak = u[-1, 0], np.max(np.abs(u[:, 0]))
    assert end > 2.9 and peak == end  # 1 mg: 1.96 m over the 20 s, then 5 s at 0.196 m/s: 2.94 m
    assert f"ends at {1e3 * end:.4g} mm at t = 25 s, 100 % of its peak {1e3 * peak:.4g} mm" in message
    assert f"beyond {100 * GROUND_DRIFT_SHARE:g} %" in message and 'baseline = "polynomial"' in message
    corrected = _ground(t, a + 0.001 * G, baseline="polynomial")
    assert ground_drift(corrected, *_integrated(corrected, 25.0)) is None
    assert ground_drift(_ground(t, a), *_integrated(_ground(t, a), 25.0)) is None  # the bundled record: 0.08 %


def test_the_drift_is_judged_at_its_stated_share_once_the_record_is_over():
    t = np.linspace(0.0, 1.0, 101)
    ground = _ground(t, np.sin(2 * np.pi * t))  # one cycle: ends at rest, but 1/(2 pi) m away, its farthest
    times, u = _integrated(ground, 1.5)
    share = abs(u[-1, 0]) / np.max(np.abs(u[:, 0]))
    assert share == pytest.approx(1.0)
    assert ground_drift(ground, times, u) is not None
    peak = np.max(np.abs(u[:, 0]))
    for factor, warns in ((1.0001, True), (0.9999, False)):  # an end just beyond and just within the share
        ended = u.copy()
        ended[-1, 0] = factor * GROUND_DRIFT_SHARE * peak
        assert (ground_drift(ground, times, ended) is not None) == warns
    assert ground_drift(ground, times[:50], u[:50]) is None  # the record goes on after the run
    velocity = GroundMotion(quantity="velocity", direction=[1, 0, 0], signal=Table(t=[0.0, 1.0], values=[1.0, 1.0]))
    ramp = np.outer([0.0, 0.5, 1.0], [1.0, 0.0, 0.0])  # its exact integral
    assert "Correct the velocity record's baseline before use" in ground_drift(velocity, [0.0, 0.5, 1.0], ramp)
    shock = GroundMotion(quantity="acceleration", direction=[1, 0, 0],
                         signal={"kind": "half_sine", "start": 0.0, "duration": 0.1})
    assert ground_drift(shock, times, u) is None  # a pulse's change of velocity is the motion asked for


SCENARIO = (SCENARIOS / "cabinet_earthquake.toml").read_text()


def _scenario_file(tmp_path, ground_keys="", offset=0.0, duration=25.0) -> Path:
    """The bundled cabinet scenario with its record offset by ``offset`` g, and ``ground_keys`` in ``[ground]``."""
    t, a = read_table_csv("ground_accelerogram.csv", SCENARIOS, "file")
    np.savetxt(tmp_path / "record.csv", np.column_stack([t, np.array(a) + offset]), delimiter=",")
    text = (SCENARIO.replace("ground_accelerogram.csv", "record.csv").replace("[ground]\n", f"[ground]\n{ground_keys}")
            .replace("duration = 25.0", f"duration = {duration}"))
    (tmp_path / "cabinet.toml").write_text(text)
    return tmp_path / "cabinet.toml"


def _scenario(tmp_path, ground_keys="", offset=0.0, duration=25.0):
    return load_scenario(_scenario_file(tmp_path, ground_keys, offset, duration))


def test_the_baseline_key_corrects_the_record_and_keeps_the_one_given(tmp_path):
    t, a = (np.array(column) for column in read_table_csv("ground_accelerogram.csv", SCENARIOS, "file"))
    scenario = _scenario(tmp_path, 'baseline = "polynomial"\nbaseline_degree = 3\n', offset=0.001)
    ground = scenario.excitation.ground
    assert np.array_equal(ground.recorded.values, a + 0.001)
    assert np.array_equal(ground.signal.values, polynomial_baseline(t, a + 0.001, 3))
    # What the default correction changed, against the closed form of the offset (the bundled record ends at rest
    # within 1e-5 m/s and 1e-6 m): 1 mg times the scale, over the 20 s record.
    default = _scenario(tmp_path, 'baseline = "polynomial"\n', offset=0.001).excitation.ground
    offset = 0.001 * default.scale
    text = baseline_text(default).replace("\n", " ")
    assert "(polynomial of degree 2 in velocity: " in text and f"changed by at most {offset:.3g} m/s²" in text
    assert f"ended at {offset * 20:.3g} m/s and {offset * 20**2 / 2:.3g} m, corrected at rest" in text
    plain = _scenario(tmp_path).excitation.ground
    assert plain.baseline == "none" and plain.signal is plain.recorded


@pytest.mark.parametrize("keys, match", [
    ('baseline = "bap"\n', r"cabinet.toml: ground.baseline: expected 'none' or 'polynomial', got 'bap'"),
    ("baseline_degree = 3\n", r"cabinet.toml: ground.baseline_degree: expected baseline = 'polynomial'.*got 3"),
    ('baseline = "polynomial"\nbaseline_degree = 7\n',
     r"cabinet.toml: ground.baseline_degree: expected an integer from 2 to 6, got 7"),
    ('baseline = "polynomial"\nbaseline_degree = 1\n',
     r"cabinet.toml: ground.baseline_degree: expected an integer from 2 to 6, got 1"),
])
def test_a_bad_baseline_is_one_error_naming_file_and_field(tmp_path, keys, match):
    with pytest.raises(ScenarioError, match=match):
        _scenario(tmp_path, keys)


def test_a_baseline_needs_an_accelerogram(tmp_path):
    text = SCENARIO.replace('quantity = "acceleration"', 'quantity = "velocity"').replace(
        "[ground]\n", '[ground]\nbaseline = "polynomial"\n')
    with pytest.raises(ScenarioError, match=r"cabinet.toml: ground.baseline: expected 'none' unless the ground is "
                       r"an accelerogram .*got 'polynomial' for a velocity table signal"):
        parse_scenario(text, "cabinet.toml", SCENARIOS)


def test_peaks_relative_to_a_moving_ground_come_first():
    t = np.linspace(0.0, 1.0, 11)
    q = np.zeros((11, 6))
    q[:, 0] = 5.0 * t + 0.001 * np.sin(3 * t)  # drifting with the ground
    q[:, 4] = 0.002 * np.sin(3 * t)
    ground = np.zeros((11, 3))
    ground[:, 0] = 5.0 * t
    history = TimeHistory(t=t, q=q, qd=np.gradient(q, t, axis=0), qdd=np.zeros((11, 6)),
                          ground_displacement=ground, ground_velocity=np.gradient(ground, t, axis=0),
                          ground_acceleration=np.zeros((11, 3)))
    text = peaks_text(history)
    relative, absolute = text.split("Absolute (fixed frame")
    assert relative.startswith("Relative to the ground (what the mounts feel)")
    for part, peak, at in ((relative, 0.001 * np.sin(1.5), "0.500"), (absolute, q[-1, 0], "1.000")):
        row = next(line for line in part.splitlines() if line.startswith("| x "))
        factor, unit = display_unit(peak, "m")
        assert [c.strip() for c in row.split("|")[2:4]] == [f"{factor * peak:.5g} {unit}", at]
    still = TimeHistory(t=t, q=q, qd=np.zeros((11, 6)), qdd=np.zeros((11, 6)))
    assert not peaks_text(still).startswith("Relative")


@pytest.mark.long  # over 10 s on the 2-core machine
def test_a_run_on_a_drifting_record_warns_and_puts_relative_motion_first(tmp_path):
    scenario = _scenario(tmp_path, offset=0.001, duration=20.0)
    with pytest.warns(GroundDriftWarning, match=r"ends at .* mm at t = 20 s, 100 % of its peak"):
        results, folder = run_scenario(scenario, tmp_path / "out", progress=False)
    summary = (folder / "summary.md").read_text()
    assert "## Warnings" in summary and "set [ground] baseline" in summary.lower()
    response = results.response
    assert summary.index("Relative to the ground") < summary.index("Absolute (fixed frame")
    table = points_table(results.points, True, ground=response)
    assert table in summary
    lines = table.splitlines()
    headers = [c.strip() for c in lines[1].split("|")[3:9]]
    cells = [c.strip() for c in next(line for line in lines if line.startswith("| top_corner")).split("|")[3:9]]
    motion = results.points["top_corner"]
    relative = np.max(np.abs(motion.displacement - response.ground_displacement), axis=0)
    absolute = np.max(np.abs(motion.displacement), axis=0)
    factor, unit = display_unit(np.concatenate([relative, absolute]), "m")
    assert headers[0] == f"peak x rel [{unit}]" and headers[3] == f"peak x abs [{unit}]"
    assert cells[0] == f"{factor * relative[0]:.4g}" and cells[3] == f"{factor * absolute[0]:.4g}"
    assert absolute[0] > 50 * relative[0]  # the drift: metres against the mounts' millimetres


@pytest.mark.slow  # 4 s on the 2-core machine
def test_a_run_on_the_corrected_record_does_not_warn_and_says_what_it_changed(tmp_path, capsys):
    path = _scenario_file(tmp_path, 'baseline = "polynomial"\n', offset=0.001, duration=20.0)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    printed = capsys.readouterr()
    assert "WARNING" not in printed.err
    text = baseline_text(load_scenario(path).excitation.ground)
    summary = (tmp_path / "out" / "cabinet_earthquake" / "summary.md").read_text()
    assert text in printed.out and text in summary and "## Warnings" not in summary
    # Gravity's geometric stiffness left out: said beside the modes, once, and printed with the statics.
    line = "Gravity's geometric stiffness would lower mode 1 (y) by 3.7 %; [statics] geometric_stiffness = true"
    assert summary.count(line) == 1 and line[1:] in printed.out
    assert summary.index(text) < summary.index("Relative to the ground") < summary.index("Absolute (fixed frame")
