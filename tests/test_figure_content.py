"""What the figures draw, inspected (issue 15, point 1): the mount-load figure (mount_forces.png) draws what
the mount check computed (each mount's total normal force in one unit, its static load, tension shaded where
and only where the mount is in tension, a zoom on the largest excursion); time_dofs.png says which DOFs are
not excited and zooms on the excitation's shock or switch-on beside the whole record; bode.png marks the
operating frequencies and numbers close modes without overprinting; random.png, srs.png and the design
figures draw the values they are given, identical curves once."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from figures import dof_of
from sixdof import (
    Excitation,
    GroundMotion,
    HalfSine,
    Harmonic,
    Load,
    RunResults,
    SimulationSettings,
    Step,
    load_results,
    mount_check,
    mount_forces,
    simulate,
    write_results,
)
from sixdof.analysis.statics import STANDARD_GRAVITY, gravity_statics
from sixdof.dofs import DOFS
from sixdof.plots import plot_mount_loads
from sixdof.plots.mount_time import TENSION_LABEL
from sixdof.plots.time import responding
from sixdof.plots.zoom import ZOOM_PERIODS, ZOOM_PULSES, event_window, zoom_window
from sixdof.results import Event
from sixdof.workflows.prepare import prepare
from systems import four_mount

MASS = 500.0


def checked(load_z, signal, duration):
    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5))
    loads = (Load("l", [0.1, 0.0, 0.0], force=[0, 0, load_z], signal=signal),)
    response = simulate(system, Excitation(loads=loads), SimulationSettings(duration=duration, sample_rate_hz=1000.0))
    check = mount_check(system, mount_forces(system, response), response.t, gravity_statics(system))
    return check, response.t


def drawn(ax):
    """The normal-force line of a panel (x, y) and the y of its horizontal lines."""
    lines = [line for line in ax.get_lines() if line.get_label() == "normal force N"]
    flat = [line.get_ydata()[0] for line in ax.get_lines() if line.get_label() == "static (gravity)"]
    return lines[0].get_xdata(), lines[0].get_ydata(), flat


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_each_mount_is_drawn_in_one_unit_with_its_static_load_and_a_zoom():
    check, t = checked(300.0, Harmonic(f_hz=7.0), 4.0)
    fig = plot_mount_loads(check, t, name="machine")
    assert len(fig.axes) == 2 * len(check.names)
    units = {ax.get_ylabel() for ax in fig.axes[::2]}
    assert units == {"normal force [kN]"}
    window = zoom_window(t, check.compression - check.compression[:, :1])
    for k in range(len(check.names)):
        whole, zoom = fig.axes[2 * k], fig.axes[2 * k + 1]
        x, y, flat = drawn(whole)
        assert y.max() == pytest.approx(check.max_compression[k] / 1e3) and y.min() == pytest.approx(
            check.min_compression[k] / 1e3)
        assert flat == [pytest.approx(-check.static_force[k, 2] / 1e3)]
        assert -check.static_force[k, 2] == pytest.approx(MASS * STANDARD_GRAVITY / 4, rel=0.3)  # the preload
        assert whole.get_xlim() == (t[0], t[-1]) and zoom.get_xlim() == pytest.approx(window[:2])
        assert not [c for c in whole.collections if c.get_label() == TENSION_LABEL and len(c.get_paths())]
    # The zoom spans ZOOM_PERIODS periods of the 7 Hz steady motion (from zero crossings) around the largest excursion.
    assert window[1] - window[0] == pytest.approx(ZOOM_PERIODS / 7.0, rel=0.1)
    worst = np.unravel_index(np.argmax(np.abs(check.compression - check.compression.mean(axis=1, keepdims=True))),
                             check.compression.shape)[1]
    assert window[0] <= t[worst] <= window[1] or window[0] == t[0]
    labels = [text.get_text() for text in fig.legends[0].get_texts()]
    assert labels == ["normal force N", "static (gravity)", "zoomed span"]  # no tension: not in the legend


def test_tension_is_shaded_exactly_where_a_mount_lifts_off():
    # A step upward of twice the weight: every mount goes into tension for part of each cycle.
    check, t = checked(2 * MASS * STANDARD_GRAVITY, Step(start=0.0), 0.3)
    fig = plot_mount_loads(check, t)
    assert len(fig.axes) == len(check.names)  # 0.3 s: too short for a zoom
    for k, ax in enumerate(fig.axes):
        shade = [c for c in ax.collections if c.get_label() == TENSION_LABEL][0]
        vertices = np.concatenate([p.vertices for p in shade.get_paths()])
        assert vertices[:, 1].min() == pytest.approx(check.min_compression[k] / 1e3)
        assert vertices[:, 1].max() == pytest.approx(0.0, abs=1e-12)
        inside = (vertices[:, 0].min(), vertices[:, 0].max())
        in_tension = t[check.compression[k] < 0]
        assert inside[0] <= in_tension[0] and inside[1] >= in_tension[-1]
        assert "TENSION first at t =" in ax.get_title(loc="left")
    assert TENSION_LABEL in [text.get_text() for text in fig.legends[0].get_texts()]


def test_time_dofs_draws_the_input_above_and_only_the_dofs_that_move():
    from sixdof.plots import plot_time_histories
    from sixdof.plots.time import RESPONDS_RTOL, notes

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(100.0, 100.0, 300.0))
    vertical = (Load("l", [0.0, 0.0, 0.0], force=[0, 0, 500.0], signal=Harmonic(f_hz=5.0)),)
    response = simulate(system, Excitation(loads=vertical), SimulationSettings(duration=1.0, sample_rate_hz=500.0))
    peaks = np.max(np.abs(response.q), axis=0)
    assert peaks[2] > 1e-5 and np.all(np.delete(peaks, 2) < 1e-12 * peaks[2])  # z alone moves
    fig = plot_time_histories(response, name="box")
    # Two rows: the applied force (the load's own signal, 500 N at 5 Hz), then z; a single DOF gets a tall panel.
    load, z = fig.axes
    assert load.get_title(loc="left") == "applied force at the centre of gravity: peak along z 500 N"
    assert load.get_ylabel() == "force [N]" and len(load.get_lines()) == 1
    force = load.get_lines()[0].get_ydata()
    np.testing.assert_allclose(force, 500.0 * np.sin(2 * np.pi * 5.0 * load.get_lines()[0].get_xdata()), atol=1e-9)
    assert z.get_ylabel().startswith("along z [") and z.get_title(loc="left").startswith("translation along z: peak")
    assert len(z.get_lines()) == 1 and not z.texts
    assert z.get_position().height * fig.get_figheight() >= 2.9  # inches
    assert load.get_position().y0 > z.get_position().y1  # the input above
    (line,) = notes(fig)
    assert line.startswith(f"not excited (peak at most {RESPONDS_RTOL:g} of the largest of its kind")
    named = line.split("): ", 1)[1]
    for dof in ("along x", "along y", "about x", "about y", "about z"):
        assert dof in named
    assert fig.get_suptitle() == "box: displacement of the centre of gravity, with the input above"
    assert_figure_texts_clear(fig)
    # The cross-check figure draws z alone too, overlay and difference, and names the others with their differences.
    from sixdof.analysis.compare import compare
    from sixdof.analysis.superposition import superpose
    from sixdof.plots import plot_superposition

    modal = superpose(system, Excitation(loads=vertical), response.t)
    fig = plot_superposition(response, modal, compare(response.q, modal.q, length=0.5))
    left, right = fig.axes
    assert left.get_ylabel().startswith("along z [") and len(left.get_lines()) == 2 and right.get_lines()
    (line,) = notes(fig)
    assert all(dof in line.split("): ", 1)[1] for dof in ("along x", "along y", "about x", "about y", "about z"))
    assert_figure_texts_clear(fig)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_time_dofs_draws_a_moment_of_its_own_and_quotes_the_moment_of_an_offset_force():
    from sixdof.plots import plot_time_histories

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(100.0, 100.0, 300.0))
    settings = SimulationSettings(duration=0.5, sample_rate_hz=500.0)
    # A force 0.2 m off the centre of gravity: its moment (0.2 m x 500 N about y) is quoted, not drawn again.
    offset = (Load("l", [0.2, 0.0, 0.0], force=[0, 0, 500.0], signal=Harmonic(f_hz=5.0)),)
    offset_fig = plot_time_histories(simulate(system, Excitation(loads=offset), settings))
    titles = [ax.get_title(loc="left") for ax in offset_fig.axes]
    # The moments on a line of their own, with room above the panel for it.
    assert titles[0].startswith("applied force at the centre of gravity: peak along z 500 N\nmoments about it (not drawn)")
    assert_figure_texts_clear(offset_fig)
    assert not any(title.startswith("applied moment") for title in titles)
    # A torque of its own beside a force: both drawn, each on its axes.
    torque = offset + (Load("engine", [0.0, 0.0, 0.0], moment=[0.0, 0.0, 40.0], signal=Harmonic(f_hz=9.0)),)
    fig = plot_time_histories(simulate(system, Excitation(loads=torque), settings))
    force, moment = fig.axes[:2]
    assert force.get_ylabel() == "force [N]" and moment.get_ylabel() == "moment [N m]"
    assert "about z 40" in moment.get_title(loc="left")
    assert {line.get_label() for line in moment.get_lines()} >= {"moment about z"}
    assert_figure_texts_clear(fig)


def test_responding_compares_each_dof_within_its_kind():
    from sixdof.plots.time import RESPONDS_RTOL, responding

    t = np.linspace(0.0, 1.0, 101)
    wave = np.sin(2 * np.pi * 3 * t)
    # x 1 mm; y just above, z just below RESPONDS_RTOL of it; rx 1 µrad (drawn: the largest rotation, however
    # small beside the translations); ry just below RESPONDS_RTOL of rx; rz round-off of the largest of all.
    peaks = np.array([1e-3, 1.01 * RESPONDS_RTOL * 1e-3, 0.99 * RESPONDS_RTOL * 1e-3, 1e-6,
                      0.99 * RESPONDS_RTOL * 1e-6, 1e-14])
    assert responding(np.outer(wave, peaks)).tolist() == [True, True, False, True, False, False]
    assert not responding(np.zeros((101, 6))).any()


def assert_figure_texts_clear(fig) -> None:
    """:func:`figures.assert_texts_clear`, and the figure's own lines of text (the not-excited line, the zoom's
    heading) clear of each other, of every title and of every legend."""
    from figures import assert_texts_clear

    assert_texts_clear(fig)
    renderer = fig.canvas.get_renderer()
    lines = [(text.get_text(), text.get_window_extent(renderer)) for text in fig.texts if text is not fig._suptitle]
    heads = [*lines, ("suptitle", fig._suptitle.get_window_extent(renderer))]
    for ax in fig.axes:
        heads += [(title.get_text(), title.get_window_extent(renderer)) for title in (ax.title, ax._left_title)
                  if title.get_text()]
    heads += [("legend", legend.get_window_extent(renderer)) for legend in fig.legends]
    for text, box in lines:
        for other, other_box in heads:
            assert other == text or not box.overlaps(other_box), (text, other)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_time_dofs_of_a_ground_shock_keeps_its_lines_of_text_apart():
    from sixdof.plots import plot_time_histories

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(100.0, 100.0, 300.0))
    excitation = Excitation(ground=GroundMotion(quantity="acceleration", direction=[0.0, 0.0, 1.0], scale=196.0,
                                                signal=HalfSine(start=0.01, duration=0.011)))
    response = simulate(system, excitation, SimulationSettings(duration=0.4, sample_rate_hz=4000.0))
    events = {name: Event(*event) for name, event in excitation.events(0.0, 0.4).items()}
    fig = plot_time_histories(response, events=events, name="electronics_box")
    # The ground's shock and the body's response, each in its zoom; a note naming what does not move.
    assert fig.axes[0].get_title(loc="left").startswith("ground and body acceleration along z")
    assert len(fig.axes[1].get_lines()) == 2
    assert_figure_texts_clear(fig)


def test_the_not_excited_line_groups_zeros_and_round_off_and_quotes_small_peaks():
    from sixdof.dofs import dof_units
    from sixdof.plots.time import not_excited_line

    values = np.outer([0.0, 1.0, -0.5], [1e-2, 0.0, 5e-7, 0.0, 1e-20, 2e-6])
    line = not_excited_line(values, [1, 2, 3, 4], dof_units(0))
    assert line.endswith("): along y, about x (exactly zero); about y (round-off only); along z (peak 500 nm)")
    difference = np.array([1e-9, 0.0, 3e-8, 0.0, 2e-12, 1e-9])
    line = not_excited_line(values, [1, 2, 3, 4], dof_units(0), difference)
    assert line.endswith("): along y, about x (exactly zero); about y (round-off only, relative difference at most "
                         "2.0e-12); "
                         "along z (peak 500 nm, relative difference 3.0e-08)")
    assert not_excited_line(values, [], dof_units(0)) == ""


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_time_dofs_of_a_ground_motion_draw_the_body_beside_the_ground():
    from sixdof.plots import plot_time_histories

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(100.0, 100.0, 300.0))
    ground = GroundMotion(quantity="acceleration", direction=[0.0, 1.0, 0.0], scale=2.0,
                          signal=Harmonic(f_hz=8.0))
    response = simulate(system, Excitation(ground=ground), SimulationSettings(duration=2.0, sample_rate_hz=1000.0))
    fig = plot_time_histories(response, "q")
    accelerations, *dofs = fig.axes
    assert accelerations.get_title(loc="left").startswith("ground and body acceleration along y, peaks: ground 2 m/s²")
    assert accelerations.get_ylabel() == "acceleration [m/s²]"
    ground_line, body_line = accelerations.get_lines()
    assert (ground_line.get_label(), body_line.get_label()) == ("ground", "body (centre of gravity, absolute)")
    t = ground_line.get_xdata()
    np.testing.assert_allclose(ground_line.get_ydata(), np.interp(t, response.t, response.ground_acceleration[:, 1]))
    np.testing.assert_allclose(body_line.get_ydata(), np.interp(t, response.t, response.qdd[:, 1]))
    ratio = np.max(np.abs(response.qdd[:, 1])) / np.max(np.abs(response.ground_acceleration[:, 1]))
    assert f"{ratio:.2f} of the ground's" in accelerations.get_title(loc="left")
    # The DOFs that move: y (the mount stroke, relative to the ground, with the absolute dashed) and what couples.
    assert dofs[0].get_ylabel().startswith("along y [")
    assert [line.get_label() for line in dofs[0].get_lines()] == ["relative to the ground", "absolute"]
    assert [dof_of(ax.get_ylabel()) for ax in dofs] == [
        DOFS[i] for i in np.flatnonzero(responding(response.q_relative) | responding(response.q))]


def test_bode_marks_the_operating_frequency_and_close_modes_stay_legible():
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from sixdof import receptance
    from sixdof.plots import plot_bode
    from systems import bridge

    system = bridge()  # modes 1 and 2 at 0.63 and 0.69 Hz
    frf = receptance(system, np.geomspace(0.1, 100.0, 400))
    fig = plot_bode(frf, system.modes, operating_hz=[2.0], name="bridge")
    FigureCanvasAgg(fig).draw()
    for ax in fig.axes:
        red = [line for line in ax.get_lines() if line.get_color() == "tab:red"]
        assert [line.get_xdata()[0] for line in red] == [2.0]
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes[:2]:  # the magnitude panels carry the labels
        numbers = [text for text in ax.texts if text.get_text().isdigit()]
        assert [text.get_text() for text in numbers] == ["1", "2", "3", "4", "5", "6"]
        boxes = [text.get_window_extent(renderer) for text in numbers]
        for a in range(len(boxes)):
            for b in range(a + 1, len(boxes)):
                assert not boxes[a].overlaps(boxes[b]), (numbers[a].get_text(), numbers[b].get_text())
        assert any(text.get_text() == " operating 2 Hz" for text in ax.texts)


def test_a_bode_title_with_a_long_name_puts_the_name_on_its_own_line():
    from sixdof import receptance
    from sixdof.plots import plot_bode
    from systems import bridge

    system = bridge()
    frf = receptance(system, np.geomspace(0.1, 100.0, 50))
    name = "equipment_snubbed_shock (linear model, exact until a nonlinear mount engaged at t = 0.02294 s)"
    fig = plot_bode(frf, system.modes, operating_hz=[2.0], name=name)
    assert fig.get_suptitle().startswith(f"{name}:\nreceptance")
    assert_figure_texts_clear(fig)  # inside the figure, clear of the panels' titles
    # The legends under the phases, where they hide neither the curves nor the mode numbers.
    for magnitude, phase in zip(fig.axes[:2], fig.axes[2:]):  # subplots(2, 2): magnitudes first
        assert magnitude.get_legend() is None and phase.get_legend() is not None
    assert plot_bode(frf, system.modes, name="bridge").get_suptitle().startswith("bridge: receptance")



@pytest.mark.parametrize(("scenario", "model"), [
    ("bridge_beam_lrb", "linear model: bearings at their effective linearization"),
    ("equipment_snubbed_shock", "linearized about the static equilibrium"),
])
def test_figures_of_the_linear_model_say_so_with_a_long_name_on_its_own_line(scenario, model):
    """Mode shapes, kinetic energy and FRFs of hysteretic or nonlinear mounts are of the linear model, and say so
    from the system alone: the command draws them before the time response (and its contacts) is in, and
    ``sixdof plot`` redraws them from the file with the same titles. The long name then takes its own line, and
    every title stays inside the figure and clear of the others (the panels' scale lines too)."""
    from types import SimpleNamespace

    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from figures import assert_texts_clear
    from sixdof import load_scenario
    from sixdof.plots import _DRAW, _linear_name, _superposition_name

    system = prepare(load_scenario(f"scenarios/{scenario}.toml")).system
    run = RunResults(name=scenario, system=system, modes=system.modes)
    energy = _DRAW["ke_distribution.png"](run)
    assert energy.axes[0].get_title().startswith(f"{scenario} ({model}):")  # on one line where it fits
    assert_texts_clear(energy)
    shapes = _DRAW["mode_shapes.png"](run)
    assert shapes.get_suptitle().startswith(f"{scenario} ({model}):\n")
    # The 3-D panels' labels have no 2-D place before projection: the titles and the key, inside and apart.
    FigureCanvasAgg(shapes).draw()
    renderer, (width, height) = shapes.canvas.get_renderer(), shapes.canvas.get_width_height()
    boxes = [artist.get_window_extent(renderer) for artist in [shapes._suptitle, *shapes.legends,
                                                                *(ax.title for ax in shapes.axes)]]
    assert all(box.x0 >= 0 and box.y0 >= 0 and box.x1 <= width and box.y1 <= height for box in boxes)
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
    # Once a mount engaged, only the superposition's title says until when the linear model was exact.
    engaged = dataclasses.replace(run, contacts=SimpleNamespace(first_engaged_t=0.02294))
    assert _linear_name(engaged) == _linear_name(run) == f"{scenario} ({model})"
    assert _superposition_name(engaged) == (scenario if system.hysteretic.count else
                                            f"{scenario} (linear model, exact until a nonlinear mount engaged at "
                                            "t = 0.02294 s)")


def test_the_phase_is_drawn_unwrapped():
    from sixdof.plots.frf import phase_deg

    w = np.geomspace(0.01, 100.0, 500)
    three_poles = 1.0 / (1.0 + 1j * w) ** 3  # from 0 to -270 deg, through -180
    phase = phase_deg(three_poles)
    np.testing.assert_allclose(phase, -3 * np.degrees(np.arctan(w)), atol=1e-9)
    assert np.all(np.abs(np.diff(phase)) < 10.0)  # no 360 deg jump
    assert -180 < phase_deg(-np.exp(1j * np.linspace(0.1, 3.0, 50)))[0] <= 180


def _drawn_rigid_motion(ax):
    """The rigid motion (translation of the CG [m], rotation vector [rad]) that takes a panel's mounts from their
    ground side to their body side, read off its mount lines (Kabsch's fit, by scipy): what the panel draws."""
    from scipy.spatial.transform import Rotation

    lines = [np.array(line.get_data_3d()).T for line in ax.get_lines()
             if line.get_color() == "tab:red" and len(line.get_xdata()) == 2]
    ground, body = np.array([line[0] for line in lines]), np.array([line[1] for line in lines])
    rotation, _ = Rotation.align_vectors(body - body.mean(axis=0), ground - ground.mean(axis=0))
    return body.mean(axis=0) - rotation.apply(ground.mean(axis=0)), rotation.as_rotvec(), rotation


@pytest.mark.parametrize("scenario", ["engine_inclined_mounts", "cabinet_earthquake"])  # V mounts at 40 degrees;
def test_mode_shapes_draw_each_mode_at_the_scale_their_title_says_with_every_mount_and_axis(scenario):
    # ... a tall cabinet whose yaw is drawn at the largest rotation
    from scipy.linalg import eigh

    from sixdof.io.scenario import load_scenario
    from sixdof.plots import plot_mode_shapes
    from sixdof.plots.modes import AXIS_LENGTH, MAX_DRAWN_ROTATION, MODE_SCALE

    system = prepare(load_scenario(f"scenarios/{scenario}.toml")).system
    inclined = not np.allclose(system.axes, np.eye(3))
    fig = plot_mode_shapes(system.modes, system)
    _, phi = eigh(system.K, system.M)  # scipy's modes, not sixdof's
    size = np.asarray(system.body.dimensions, float)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float) * size / 2
    for j, ax in enumerate(fig.axes):
        # The scale, then the turn on a line of its own (beside it, the line ran into the next panel's title).
        scale_lines = "\n".join(ax.get_title().splitlines()[2:])
        words = re.fullmatch(r"drawn: largest motion (\S+) % of body size \((\S+) m\)(?:\nturned (\S+)° about (.+))?",
                             scale_lines)
        assert words, scale_lines
        percent, of, turned = (float(v or 0.0) for v in words.groups()[:3])
        about = words.group(4)
        assert of == pytest.approx(np.max(size), rel=5e-3)
        # What is drawn is mode j itself, scaled: translation and rotation in the proportions of scipy's shape.
        t, r, rotation = _drawn_rigid_motion(ax)
        q = np.concatenate([t, r])
        factor = q @ phi[:, j] / (phi[:, j] @ phi[:, j])
        np.testing.assert_allclose(q, factor * phi[:, j], atol=1e-9 * np.max(np.abs(q)))
        # ... at the scale said: the rotation, and the largest motion of a corner or mount.
        assert np.degrees(np.linalg.norm(r)) == pytest.approx(turned, rel=0.05, abs=0.01)
        if about is not None:  # the body axis within 25 deg of the rotation's, else its direction
            direction = r / np.linalg.norm(r)
            k = int(np.argmax(np.abs(direction)))
            assert about == ("xyz"[k] if abs(direction[k]) >= np.cos(np.radians(25)) else
                             "(" + ", ".join(f"{v:.2f}" for v in direction) + ")")
        points = np.vstack([corners, system.positions])
        largest = np.max(np.linalg.norm(t + rotation.apply(points) - points, axis=1))
        assert 100 * largest / np.max(size) == pytest.approx(percent, rel=0.05)
        # MODE_SCALE of the body's size, unless the rotation reached MAX_DRAWN_ROTATION first
        if np.linalg.norm(r) < MAX_DRAWN_ROTATION * (1 - 1e-9):
            assert percent == pytest.approx(100 * MODE_SCALE)
        else:
            assert np.linalg.norm(r) == pytest.approx(MAX_DRAWN_ROTATION) and percent <= 100 * MODE_SCALE
        assert sorted(text.get_text().strip() for text in ax.texts) == sorted(system.mount_names)
        axis_lines = [line for line in ax.get_lines() if line.get_color() == "black" and len(line.get_xdata()) == 2]
        assert len(axis_lines) == (len(system.mounts) if inclined else 0)
        for line, p, w in zip(axis_lines, system.positions, system.axes[:, 2]):
            start, end = np.array(line.get_data_3d()).T
            np.testing.assert_allclose(start, p)  # from the mount's ground side, along its w axis
            np.testing.assert_allclose(end - start, AXIS_LENGTH * float(np.max(size)) * w)
    legend = [text.get_text() for text in fig.legends[0].get_texts()]
    assert legend == ["at rest", "mode shape", "mount, ground side", "mount, body side (line: deflection)",
                      *(["mount w axis"] if inclined else [])]
    assert inclined == (scenario == "engine_inclined_mounts")
    if scenario == "cabinet_earthquake":  # its yaw turns the most, 0.3 rad, moving its corners less than 15 %
        assert any(abs(_drawn_rigid_motion(ax)[1][2]) == pytest.approx(MAX_DRAWN_ROTATION) for ax in fig.axes)


def _pixels(ax, collection):
    """The corners of a drawn box (a Poly3DCollection, after drawing) in pixels, one row each; corners within 1 %
    of the panel's width of each other are one (end-on, the near and the far end)."""
    vertices = ax.transData.transform(np.concatenate([path.vertices for path in collection.get_paths()]))
    corners: list[list[np.ndarray]] = []
    for v in vertices:
        near = next((c for c in corners if np.linalg.norm(c[0] - v) < 0.01 * ax.bbox.width), None)
        corners.append([v]) if near is None else near.append(v)
    return np.array([np.mean(c, axis=0) for c in corners])


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_every_bridge_mode_moves_visibly_and_its_roll_is_seen_end_on_undistorted():
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from sixdof.plots import FIXED_TITLES, plot_mode_shapes
    from systems import bridge

    beam = bridge()  # the seed's 83 t beam, 1.2 x 40 x 2 m, on four bearings
    with matplotlib.rc_context(FIXED_TITLES):
        fig = plot_mode_shapes(beam.modes, beam)
        FigureCanvasAgg(fig).draw()
    renderer = fig.canvas.get_renderer()
    rolls = [ax for ax in fig.axes if "mostly roll about y" in ax.get_title()]
    for ax in fig.axes:
        rest, moved = (_pixels(ax, c) for c in ax.collections[:2])
        # The drawn motion: how far each moved corner lies from the nearest corner at rest, against the panel.
        shift = np.max(np.min(np.linalg.norm(moved[:, None] - rest[None], axis=2), axis=1))
        assert shift >= 0.05 * ax.bbox.width, ax.get_title()
        labels = [text.get_text() for text in ax.texts]
        # The bearings come in pairs 0.39 m apart on the 40 m beam: one label each pair, neither hidden behind the
        # other; seen end-on, the two ends' bearings fall together instead.
        assert labels == (["1, 4", "2, 3"] if ax in rolls else ["1, 2", "3, 4"])
        first, second = (text.get_window_extent(renderer) for text in ax.texts)
        assert not first.overlaps(second)
    assert len(rolls) == 1
    roll = rolls[0]
    assert "seen end-on, along y" in roll.get_title()
    # End-on, both ends of the box fall on one rectangle: at rest 1.2 m wide and 2 m high, to one scale.
    rest, moved = (_pixels(roll, c) for c in roll.collections[:2])
    assert len(rest) == len(moved) == 4
    width, height = np.ptp(rest, axis=0)
    assert width / height == pytest.approx(1.2 / 2.0, rel=1e-3)
    # Turned by the angle the title says, and still the same rectangle (no shear, no stretch).
    seen = re.search(r"seen end-on, along (\S), the axis it is turned (\S+)° about\n", roll.get_title())
    assert seen, roll.get_title()
    turned = float(seen.group(2))
    assert seen.group(1) == "y"  # the axis it is seen along, and turned about
    centre = moved.mean(axis=0)
    np.testing.assert_allclose(centre, rest.mean(axis=0), atol=1.0)  # about the CG: a pure roll
    order = np.argsort(np.arctan2(*(moved - centre).T[::-1]))
    ring = moved[order]
    edges = np.roll(ring, -1, axis=0) - ring
    lengths = np.linalg.norm(edges, axis=1)
    np.testing.assert_allclose(np.sort(lengths), np.sort([width, width, height, height]), rtol=2e-3)
    long_edge = edges[np.argmax(lengths)]
    tilt = np.degrees(np.arctan2(abs(long_edge[0]), abs(long_edge[1])))  # from the vertical
    assert tilt == pytest.approx(turned, rel=0.05)
    assert tilt > 5.0  # plainly visible


def test_the_excitation_names_its_shocks_and_switch_ons_within_the_record():
    loads = (Load("impact", [0, 0, 0], force=[0, 0, 1.0], signal=HalfSine(start=6.0, duration=0.02)),
             Load("motor", [0, 0, 0], force=[1.0, 0, 0], signal=Harmonic(f_hz=4.0, start=1.0)),
             Load("late", [0, 0, 0], force=[1.0, 0, 0], signal=Harmonic(f_hz=4.0, start=12.0)),
             Load("held", [0, 0, 0], force=[0, 1.0, 0], signal=Step(start=2.0)))
    ground = GroundMotion(direction=[0, 0, 1], signal=HalfSine(start=3.0, duration=0.1), quantity="acceleration")
    events = Excitation(loads=loads, ground=ground).events(0.0, 10.0)
    assert events == {"impact": ("shock", 6.0, 0.02), "motor": ("switch-on", 1.0, 0.25),
                      "ground motion": ("shock", 3.0, 0.1)}  # "late" starts after the record, a step has no period


def test_event_window_prefers_the_shortest_shock_and_needs_a_long_enough_record():
    t = np.linspace(0.0, 10.0, 5001)
    shock, switch_on = Event("shock", 6.0, 0.02), Event("switch-on", 0.0, 0.25)
    start, end, label = event_window({"motor": switch_on, "impact": shock}, t)
    assert (start, end) == pytest.approx((6.0 - 0.1 * ZOOM_PULSES * 0.02, 6.0 + 0.9 * ZOOM_PULSES * 0.02))
    assert label.startswith("impact (shock, 20 ms at t = 6 s")
    # A shock too long for a zoom of ZOOM_MIN_PULSES pulses within a quarter of the record: the switch-on's.
    assert event_window({"slow": Event("shock", 6.0, 1.0), "motor": switch_on}, t)[:2] == pytest.approx(
        (0.0, ZOOM_PERIODS * 0.25))
    # A longer shock gets the widest zoom, a quarter of the record.
    assert event_window({"slow": Event("shock", 6.0, 0.2)}, t)[:2] == pytest.approx((5.75, 8.25))
    assert event_window({}, t) is None and event_window({"motor": Event("switch-on", 0.0, 1.0)}, t) is None


@pytest.mark.slow  # 2 s on the 2-core machine
def test_time_dofs_zooms_on_the_shock_beside_the_whole_record_and_the_file_keeps_the_events(tmp_path):
    from sixdof.plots import plot_time_histories

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(100.0, 100.0, 300.0))
    pulse = HalfSine(start=2.0, duration=0.01)
    loads = (Load("impact", [0.2, 0.1, 0.0], force=[0, 0, 5e3], signal=pulse),)
    excitation = Excitation(loads=loads)
    response = simulate(system, excitation, SimulationSettings(duration=5.0, sample_rate_hz=2000.0))
    events = {name: Event(*event) for name, event in excitation.events(0.0, 5.0).items()}
    fig = plot_time_histories(response, events=events)
    # Per row (the applied force, then each DOF that moves): the whole record, then the zoom.
    drawn = responding(response.q)
    assert len(fig.axes) == 2 * (1 + drawn.sum())
    assert fig.axes[0].get_title(loc="left").startswith("applied force at the centre of gravity: peak along z 5 kN")
    window = event_window(events, response.t)
    assert window[:2] == pytest.approx((2.0 - 0.1 * ZOOM_PULSES * 0.01, 2.0 + 0.9 * ZOOM_PULSES * 0.01))
    assert [text for text in fig.texts if text.get_text().startswith("zoom: impact (shock, 10 ms at t = 2 s")]
    for k in range(len(fig.axes) // 2):
        whole, zoom = fig.axes[2 * k], fig.axes[2 * k + 1]
        assert whole.get_xlim() == (0.0, 5.0) and zoom.get_xlim() == pytest.approx(window[:2])
        x, y = zoom.get_lines()[0].get_xdata(), zoom.get_lines()[0].get_ydata()
        # The zoom draws its own samples, every one of them (not the whole record's per-pixel envelope).
        inside = (response.t >= window[0]) & (response.t <= window[1])
        assert np.all(np.isin(response.t[inside], x)) and x[0] <= window[0] and x[-1] >= window[1]
        assert np.max(np.abs(y)) == pytest.approx(np.max(np.abs(whole.get_lines()[0].get_ydata())), rel=1e-9)
        assert [p for p in whole.patches if p.get_facecolor()[:3] == pytest.approx((0.85,) * 3)]  # span shaded
    # The run's file keeps the events: a figure redrawn from it zooms the same way.
    back = load_results(write_results(tmp_path / "r.h5", RunResults(response=response, events=events)).path)
    assert set(back.events) == {"impact"}
    assert (back.events["impact"].kind, back.events["impact"].start, back.events["impact"].duration) == (
        "shock", 2.0, 0.01)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_time_dofs_keeps_the_last_time_label_of_a_zoom_inside_the_figure():
    from figures import assert_texts_clear
    from sixdof.plots import plot_time_histories

    # A 0.4 s record of an 11 ms shock: the zoom spans 0 to 0.1 s, "0.10" labels its right edge.
    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(100.0, 100.0, 300.0))
    excitation = Excitation(loads=(Load("impact", [0.2, 0.1, 0.0], force=[0, 0, 5e3],
                                        signal=HalfSine(start=0.01, duration=0.011)),))
    response = simulate(system, excitation, SimulationSettings(duration=0.4, sample_rate_hz=2000.0))
    fig = plot_time_histories(response, events={name: Event(*event)
                                                for name, event in excitation.events(0.0, 0.4).items()})
    zoom = fig.axes[-1]
    assert zoom.get_xlim() == pytest.approx((0.0, 0.1))
    assert_texts_clear(fig)
    assert [label.get_text() for label in zoom.get_xticklabels()][-1] == "0.10"


@pytest.mark.slow  # 2 s on the 2-core machine
def test_superposition_zooms_on_the_shock_beside_the_whole_overlay():
    from sixdof.analysis.compare import compare
    from sixdof.analysis.superposition import superpose
    from sixdof.plots import plot_superposition

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(100.0, 100.0, 300.0))
    excitation = Excitation(loads=(Load("impact", [0.2, 0.1, 0.0], force=[0, 0, 5e3],
                                        signal=HalfSine(start=2.0, duration=0.01)),))
    response = simulate(system, excitation, SimulationSettings(duration=5.0, sample_rate_hz=2000.0))
    modal = superpose(system, excitation, response.t)
    events = {name: Event(*event) for name, event in excitation.events(0.0, 5.0).items()}
    fig = plot_superposition(response, modal, compare(response.q, modal.q, length=0.5), events=events)
    window = event_window(events, response.t)
    rows = responding(response.q).sum()
    assert len(fig.axes) == 3 * rows  # per DOF that moves: the overlay, its zoom, the difference
    zooms = [ax for ax in fig.axes if ax.get_xlim() == pytest.approx(window[:2])]
    assert len(zooms) == rows and zooms[0].get_title(loc="left").startswith("zoom: impact (shock")
    drawn = [ax for ax in zooms if ax.get_lines()]
    assert len(drawn) == rows  # both solutions, over the zoom's own samples
    for ax in drawn:
        direct, superposed = ax.get_lines()[:2]
        assert direct.get_label() == "direct integration"
        assert superposed.get_label() == "modal superposition"
        x = direct.get_xdata()
        assert x[0] <= window[0] and x[-1] >= window[1] and len(x) <= 1 + (window[1] - window[0]) * 2000 + 2


def test_random_png_draws_the_input_and_each_response_with_its_rms():
    from sixdof.analysis.random import PSD, RandomInput, random_response
    from sixdof.plots import plot_random
    from systems import small_box

    psd = PSD(f_hz=[2.0, 20.0, 60.0], value=[0.01, 0.04, 0.02], unit="g^2/Hz")
    random = random_response(small_box(), RandomInput(input="ground_acceleration", direction=[0.0, 0.6, 0.8], psd=psd),
                             {"cg": [0.0, 0.0, 0.0], "corner": [0.3, 0.2, 0.1]})
    fig = plot_random(random, name="box")
    top, bottom = fig.axes
    g2 = STANDARD_GRAVITY**2
    assert top.get_title() == (f"input: ground acceleration, {random.input_rms / STANDARD_GRAVITY:.3g} grms, "
                               "PSD peak 0.04 g²/Hz")
    np.testing.assert_allclose(top.lines[0].get_ydata(), random.input_psd / g2)
    # The input spans less than a decade: its plateau's level is labelled on the axis, not only 0.01 and 0.02.
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    labels = [label.get_text() for label in top.yaxis.get_ticklabels(which="both") if label.get_text()]
    assert {"0.01", "0.02", "0.03", "0.04"} <= set(labels)
    assert "[g²/Hz]" in top.get_ylabel() and "[g²/Hz]" in bottom.get_ylabel()
    lines = {line.get_label(): line for line in bottom.lines}
    # The point at the CG moves as the CG: its curves are the CG's, drawn once with both names.
    for i, dof in enumerate("xyz"):
        rms = random.qdd_rms[i] / STANDARD_GRAVITY
        label = next(name for name in lines if name.startswith(f"centre of gravity along {dof}"))
        assert label.endswith(f": {rms:.3g} grms") and lines[label].get_linestyle() == "-"
        np.testing.assert_allclose(lines[label].get_ydata(), random.qdd_psd[:, i] / g2)
    axis = int(np.argmax(random.point_acceleration_rms[0]))
    assert any(name.startswith(f"centre of gravity along {'xyz'[axis]} = cg along {'xyz'[axis]}") for name in lines)
    corner = next(name for name in lines if name.startswith("corner "))
    assert lines[corner].get_linestyle() == "--"
    # The input under the response (the isolation), and eight decades of response shown.
    assert f"input: {random.input_rms / STANDARD_GRAVITY:.3g} grms" in lines
    peak = max(float(np.max(line.get_ydata())) for line in bottom.lines)
    assert bottom.get_ylim()[0] == pytest.approx(1e-8 * peak)


def test_srs_png_draws_the_input_and_each_excited_point_once():
    from sixdof.analysis.srs import ShockSpectra
    from sixdof.plots import plot_srs

    f = np.geomspace(10.0, 2000.0, 40)
    base = 200.0 * np.ones_like(f)
    board = np.stack([1e-3 * base, 1e-3 * base, 2.0 * base])  # only z excited beyond round-off
    spectra = ShockSpectra(f_hz=f, points=np.stack([board, board, 0.5 * board]), names=("board", "twin", "lid"),
                           q=10.0, input=base)
    fig = plot_srs(spectra, name="box")
    (ax,) = fig.axes
    assert "Q = 10" in fig.get_suptitle() and ax.get_ylabel() == "peak absolute acceleration [g]"
    assert ax.get_xlabel() == "natural frequency f [Hz]"
    labels = [line.get_label() for line in ax.lines]
    assert labels == ["base (input)", "board along z = twin along z", "lid along z"]  # x and y below 1 % of the largest: not drawn
    np.testing.assert_allclose(ax.lines[1].get_ydata(), 2.0 * base / STANDARD_GRAVITY)
    np.testing.assert_allclose(ax.lines[0].get_ydata(), base / STANDARD_GRAVITY)


def test_design_figures_draw_before_and_after_with_the_targets():
    from sixdof.analysis.design import mode_of_each_dof
    from sixdof.design.spec import Target
    from sixdof.plots.design import plot_design_decoupling, plot_design_frequencies
    from systems import small_box

    before, after = small_box().modes, four_mount().modes
    window = Target(kind="frequency", dof="z", f_hz=(8.0, 12.0))
    fig = plot_design_frequencies(before, after, [window], name="box")
    (ax,) = fig.axes
    given, optimized = ax.collections[:2]
    np.testing.assert_allclose(given.get_offsets()[:, 0], before.frequency_hz[mode_of_each_dof(before)])
    np.testing.assert_allclose(optimized.get_offsets()[:, 0], after.frequency_hz[mode_of_each_dof(after)])
    shaded = ax.collections[2].get_paths()[0].vertices
    assert shaded[:, 0].min() == pytest.approx(8.0) and shaded[:, 0].max() == pytest.approx(12.0)
    assert shaded[:, 1].min() == pytest.approx(2 - 0.35) and shaded[:, 1].max() == pytest.approx(2 + 0.35)  # z row
    assert ax.get_xlabel() == "natural frequency f [Hz]"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["given design", "optimized", "target window"]

    shares = np.array([80.0, 85.0, 99.0, 70.0, 75.0, 90.0]), np.array([90.0, 92.0, 99.5, 88.0, 91.0, 96.0])
    fig = plot_design_decoupling(*shares, covered=("rx", "ry"), minimum=85.0, coordinates="tra")
    (ax,) = fig.axes
    heights = [patch.get_height() for patch in ax.patches]
    np.testing.assert_allclose(heights, np.concatenate(shares))
    bound = [line for line in ax.lines if line.get_label() == "target ≥ 85 %"]
    assert len(bound) == 1 and len([line for line in ax.lines if line.get_ydata()[0] == 85.0]) == 2  # rx and ry
    assert "torque-roll-axis coordinates" in fig.get_suptitle()
    assert ax.get_ylabel() == "kinetic energy in the dominant coordinate [%]"


@pytest.mark.long  # over 10 s on the 2-core machine
def test_mount_shear_png_is_drawn_for_a_shear_load_and_draws_each_resultant():
    from sixdof.analysis.mountcheck import SHEAR_SHARE, carries_shear
    from sixdof.plots import plot_mount_shear

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5))
    braking = (Load("brake", [0.0, 0.0, 0.3], force=[0.0, 20000.0, 0.0], signal=HalfSine(start=0.2, duration=0.5)),)
    response = simulate(system, Excitation(loads=braking), SimulationSettings(duration=2.0, sample_rate_hz=1000.0))
    check = mount_check(system, mount_forces(system, response), response.t, gravity_statics(system))
    assert carries_shear(check)
    fig = plot_mount_shear(check, response.t, name="machine")
    whole = [ax for ax in fig.axes if ax.get_xlim() == (response.t[0], response.t[-1])]
    assert len(whole) == len(check.names)
    for k, ax in enumerate(whole):
        shear = np.hypot(check.force[k, :, 0], check.force[k, :, 1])
        assert ax.get_ylabel() == "shear force [kN]"
        np.testing.assert_allclose(ax.get_lines()[0].get_ydata().max(), shear.max() / 1e3)
        deflection = np.hypot(check.deflection[k, :, 0], check.deflection[k, :, 1])
        assert f"peak shear load {shear.max() / 1e3:.4g} kN" in ax.get_title(loc="left")
        assert f"at t = {response.t[np.argmax(deflection)]:.4g} s" in ax.get_title(loc="left")
    # Frozen ticks (what render() draws) draw the same picture.
    from figures import assert_texts_clear, frozen_tick_difference

    assert frozen_tick_difference(lambda: plot_mount_shear(check, response.t, name="machine")).max() <= 1.01 / 255
    # A sideways bump, zoomed on: each row's title (two lines) stays over its panel, clear of the zoom's heading.
    bump = Excitation(loads=(Load("trolley", [0.2, 0.1, 0.3], force=[-2500.0, 875.0, 0.0],
                                  signal=HalfSine(start=0.01, duration=0.015)),))
    response = simulate(system, bump, SimulationSettings(duration=0.6, sample_rate_hz=2000.0))
    check = mount_check(system, mount_forces(system, response), response.t, gravity_statics(system))
    fig = plot_mount_shear(check, response.t, events={name: Event(*event)
                                                      for name, event in bump.events(0.0, 0.6).items()})
    assert fig.axes[1].get_title(loc="left").startswith("zoom: trolley")
    assert_texts_clear(fig)
    renderer = fig.canvas.get_renderer()
    for whole in fig.axes[::2]:  # matplotlib keeps a left title as _left_title
        assert whole._left_title.get_window_extent(renderer).x1 <= whole.get_window_extent(renderer).x1
    # A vertical load through the middle: the shear left (rocking) is below SHEAR_SHARE of the normal swing.
    vertical, _ = checked(300.0, Harmonic(f_hz=7.0), 1.0)
    normal = np.max(np.abs(vertical.compression + vertical.static_force[:, None, 2]))
    assert np.max(np.hypot(vertical.force[..., 0], vertical.force[..., 1])) < SHEAR_SHARE * normal
    assert not carries_shear(vertical)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_time_dofs_gives_the_steady_state_amplitude_beside_the_switch_on_peak():
    from sixdof.analysis.steady import steady_state
    from sixdof.plots import plot_time_histories

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(300.0, 300.0, 600.0))
    excitation = Excitation(loads=(Load("rotor", [0.1, 0.0, 0.0], force=[0, 0, 300.0], signal=Harmonic(f_hz=7.0)),))
    response = simulate(system, excitation, SimulationSettings(duration=4.0, sample_rate_hz=1000.0))
    steady = steady_state(system, excitation)
    fig = plot_time_histories(response, steady=steady, events={
        name: Event(*event) for name, event in excitation.events(0.0, 4.0).items()})
    z = next(ax for ax in fig.axes if ax.get_ylabel().startswith("along z ["))
    scale = 1e6 if "µm" in z.get_ylabel() else 1e3
    amplitude = abs(steady.q[0, 2])
    levels = sorted(line.get_ydata()[0] for line in z.get_lines() if line.get_linestyle() == ":")
    np.testing.assert_allclose(levels, [-scale * amplitude, scale * amplitude])
    assert f"steady-state amplitude {scale * amplitude:.4g}" in z.get_title(loc="left")
    # The record ends in that steady state: its last two periods reach the amplitude, to the decay left.
    last = response.t > response.t[-1] - 2 / 7.0
    assert np.max(np.abs(response.q[last, 2])) == pytest.approx(amplitude, rel=0.02)


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_time_points_png_draws_each_point_that_moves_along_the_axes_it_moves_along():
    # A torque about z at the CG of the doubly symmetric box turns it about z alone: a point on the z axis stays at
    # rest (named, not drawn); a corner at (0.3, 0.2, 0) m moves along x and y only, a = rz'' (-0.2, 0.3, 0).
    from sixdof.analysis.response import points_motion
    from sixdof.plots import FIGURES, figure_names, plot_point_accelerations

    system = four_mount(m=MASS, k=(2e5, 3e5, 8e5), damping=(100.0, 100.0, 300.0))
    torque = (Load("motor", [0.0, 0.0, 0.0], moment=[0.0, 0.0, 40.0], signal=Harmonic(f_hz=9.0)),)
    response = simulate(system, Excitation(loads=torque), SimulationSettings(duration=1.0, sample_rate_hz=1000.0))
    points = points_motion(response, {"corner": [0.3, 0.2, 0.0], "on_axis": [0.0, 0.0, 0.2]})
    fig = plot_point_accelerations(points, response.t, name="box")
    assert fig.get_suptitle() == "box: absolute acceleration of the named body points, along the body axes"
    (line,) = [text.get_text() for text in fig.texts if text.get_text().startswith("not excited")]
    assert line.endswith("): on_axis")
    whole = fig.axes[0]
    peak = float(np.max(np.abs(response.qdd[:, 5])))
    assert whole.get_title(loc="left") == (f"point corner: peak along x {1e3 * 0.2 * peak:.4g}, along y "
                                           f"{1e3 * 0.3 * peak:.4g} mm/s² (largest {0.3 * peak / STANDARD_GRAVITY:.3g} g)")
    assert whole.get_ylabel() == "acceleration [mm/s²]"
    lines = {line.get_label(): line for line in whole.get_lines()}
    assert set(lines) == {"along x", "along y"}
    np.testing.assert_allclose(lines["along y"].get_ydata(), 1e3 * 0.3 * response.qdd[:, 5], rtol=1e-9,
                               atol=1e-9 * 1e3 * peak)
    assert len(fig.axes) == 1  # the corner's row alone (no zoom: nine periods of 1 s need none)
    assert_figure_texts_clear(fig)
    run = RunResults(name="box", system=system, response=response, points=points)
    assert "time_points.png" in figure_names(run)
    draw = next(draw for name, _, _, draw in FIGURES if name == "time_points.png")
    assert draw(run).axes[0].get_title(loc="left") == whole.get_title(loc="left")
