"""Figures: each function draws the library's typed result objects (Modes, TimeHistory, MountForces,
FRF, ValidationReport...), labels axes with units, and save_all writes the set a RunResults allows,
without pyplot."""

import dataclasses
import os
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.figure import Figure

import sixdof
from figures import dof_of
from sixdof import plots
from sixdof.analysis.compare import relative_to_ground
from sixdof.analysis.response import MountForces
from sixdof.cli.figures import FigureError, FigureWorkers
from sixdof.dofs import DOFS
from sixdof.errors import InputError
from sixdof.model.modes import modal_analysis
from sixdof.model.system import System
from sixdof.plots.common import DOF_DIRECTIONS, DOF_NAMES
from sixdof.plots.modes import drawn_mode, write_mode_animations
from sixdof.plots.time import responding
from sixdof.results import RunResults, TimeHistory
from store_cases import run_parts
from systems import bridge, four_mount
from tolerances import RTOL_DRAWN

UNIT_WORDS = ("[m]", "[kg^1/2 m]", "[mm]", "[µm]", "[nm]", "[mrad]", "[µrad]", "[nrad]", "[s]", "[Hz]", "[kN]", "[N]", "[deg]", "[%]",
              "[m/N]", "[rad/(N m)]", "[1]", "[N/N]", "[m/m]", "[(m/s^2)/N]")
FIGURE_NAMES = ["mode_shapes.png", "ke_distribution.png", "time_dofs.png", "time_points.png", "mount_forces.png", "superposition.png",
                "bode.png", "point_frfs.png", "validation_frf.png", "free_decays.png"]


@pytest.fixture(scope="module")
def parts():
    """The full bridge run's typed objects (as sixdof run computes them)."""
    return run_parts()


@pytest.fixture(scope="module")
def run(parts):
    fields = {f.name for f in dataclasses.fields(RunResults)}
    return RunResults(**{k: v for k, v in parts.items() if k in fields})


@pytest.fixture(scope="module")
def modal_only():
    system = bridge("equal")
    return RunResults(name="bridge_beam", system=system, modes=modal_analysis(system.M, system.K))


def labelled_axes(fig: Figure, categorical=()):
    """Every axes has x and y labels (3-D: and z) with a unit in brackets, except the ``categorical``
    labels (axes of names, which have no unit); shared x axes are labelled once, at the bottom."""
    for ax in fig.axes:
        if ax.get_label() == "<colorbar>":
            assert any(w in ax.get_ylabel() for w in UNIT_WORDS), ax.get_ylabel()
            continue
        labels = [ax.get_ylabel()]
        if ax.get_xlabel() or not ax.get_shared_x_axes().get_siblings(ax)[1:]:
            labels.append(ax.get_xlabel())
        if hasattr(ax, "get_zlabel"):
            # 3-D: the axes with ticks (an end-on view's line of sight has none, nor a label)
            labels = [getattr(ax, f"get_{a}label")() for a in "xyz" if len(getattr(ax, f"get_{a}ticks")())]
            assert len(labels) >= 2, ax.get_title()
        for label in labels:
            assert label, ax.get_title()
            if label not in categorical:
                assert "[" in label and "]" in label.split("[", 1)[1], (label, ax.get_title())
    return True


def assert_drawn_from(line, t, y, rtol=1e-15):
    """The line is the series (t, y) itself or its envelope: every drawn point is a sample (same
    time, same value) in time order, and the series' extrema are drawn exactly."""
    x, drawn = line.get_xdata(), line.get_ydata()
    k = np.searchsorted(t, x)
    assert np.all(np.diff(k) > 0)
    np.testing.assert_array_equal(t[k], x)
    np.testing.assert_allclose(drawn, y[k], rtol=rtol)
    assert np.max(drawn) == pytest.approx(np.max(y), rel=rtol) and np.min(drawn) == pytest.approx(np.min(y), rel=rtol)
    assert len(drawn) <= plots.MAX_POINTS + 2


def test_envelope_keeps_each_slices_extrema():
    rng = np.random.default_rng(7)
    values = rng.standard_normal(20_001)
    values[12_345] = 50.0  # a one-sample spike must survive
    keep = plots.envelope_indices(values, max_points=400)
    assert len(keep) <= 402 and keep[0] == 0 and keep[-1] == len(values) - 1
    assert np.all(np.diff(keep) > 0)
    assert 12_345 in keep
    width = -(-len(values) // 200)
    kept = set(keep.tolist())
    for start in range(0, len(values), width):
        piece = values[start:start + width]
        assert start + int(np.argmin(piece)) in kept and start + int(np.argmax(piece)) in kept
    # Short series are drawn whole; a constant one keeps its ends.
    np.testing.assert_array_equal(plots.envelope_indices(values[:400], max_points=400), np.arange(400))
    assert set(plots.envelope_indices(np.ones(1001), max_points=10).tolist()) >= {0, 1000}


#: The bridge's DOFs in words, by hand: its length (40 m) is along y, z is up.
BRIDGE_WORDS = {"x": "lateral motion along x", "y": "longitudinal motion along y", "z": "vertical bounce along z",
                "rx": "pitch about x", "ry": "roll about y", "rz": "yaw about z"}


def test_mode_shapes(parts):
    from scipy.linalg import eigh

    modes, system = parts["modes"], parts["system"]
    fig = plots.plot_mode_shapes(modes, system)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == 6 and all(ax.name == "3d" for ax in fig.axes)
    assert labelled_axes(fig)
    # Every panel large enough to read: 2 columns of at least 4 inches.
    width, height = fig.get_size_inches()
    assert {round(ax.get_position().x0, 2) for ax in fig.axes} == {round(fig.axes[0].get_position().x0, 2),
                                                                   round(fig.axes[1].get_position().x0, 2)}
    assert all(ax.get_position().width * width >= 4.0 for ax in fig.axes)
    # The dominant DOF and its kinetic-energy share, from scipy's own eigenvectors: T_i = phi_i (M phi)_i / 2.
    _, phi = eigh(system.K, system.M)
    ke = phi * (system.M @ phi)
    ke /= ke.sum(axis=0)
    freqs = modes.frequency_hz
    for j, ax in enumerate(fig.axes):
        title = ax.get_title()
        i = int(np.argmax(ke[:, j]))
        assert title.startswith(f"Mode {j + 1}: {freqs[j]:.4g} Hz\n")
        assert f"mostly {BRIDGE_WORDS[DOFS[i]]} ({100 * ke[i, j]:.0f} % of kinetic energy)" in title
        assert "×" not in title and "mass-normalized" not in title  # the scale in words, no factor to decode
    assert fig.axes[0].get_xlabel() == "x [m]"


def test_coupled_modes_name_their_two_largest_shares():
    from scipy.linalg import eigh

    # Every DOF coupled to every other: modes with no DOF holding half of the kinetic energy.
    A = np.random.default_rng(3).normal(size=(6, 6))
    M, K = np.diag([100.0, 100.0, 100.0, 10.0, 10.0, 10.0]), A @ A.T * 1e5 + 1e4 * np.eye(6)
    fig = plots.plot_mode_shapes(modal_analysis(M, K))  # no system: a 1 m cube, z up, x taken as longitudinal
    words = {"x": "longitudinal motion along x", "y": "lateral motion along y", "z": "vertical bounce along z",
             "rx": "roll about x", "ry": "pitch about y", "rz": "yaw about z"}
    _, phi = eigh(K, M)
    ke = phi * (M @ phi)
    coupled = 0
    for j, ax in enumerate(fig.axes):
        first, second = np.argsort(ke[:, j])[::-1][:2]
        share = 100 * ke[:, j]
        if ke[first, j] >= 0.5:
            assert f"mostly {words[DOFS[first]]} ({share[first]:.0f} % of kinetic energy)" in ax.get_title()
            continue
        coupled += 1
        assert (f"coupled: {words[DOFS[first]]} {share[first]:.0f} %\nand {words[DOFS[second]]} {share[second]:.0f} % "
                "of kinetic energy") in ax.get_title()
    assert coupled == 2


def test_mode_shapes_draw_into_a_given_figure_or_subfigure(parts):
    modes, system = parts["modes"], parts["system"]
    fig = Figure(figsize=(14, 9))
    left, right = fig.subfigures(1, 2, width_ratios=[1, 2])
    assert plots.plot_mode_shapes(modes, system, fig=right) is fig
    assert not left.axes and len(right.axes) == 6 and len(fig.axes) == 6
    assert all(right.bbox.x0 <= ax.bbox.x0 and ax.bbox.x1 <= right.bbox.x1 + 1e-6 for ax in fig.axes)
    assert fig.get_size_inches().tolist() == [14, 9] and fig.get_suptitle() == ""
    # Two columns, mode 1 top left, row by row.
    x0, y0 = (np.array([getattr(ax.get_position(), k) for ax in fig.axes]) for k in ("x0", "y0"))
    assert x0[0] == x0[2] == x0[4] < x0[1] == x0[3] == x0[5] and y0[0] == y0[1] > y0[2] == y0[3] > y0[4]
    plain = Figure()
    assert plots.plot_mode_shapes(modes, system, fig=plain) is plain and len(plain.axes) == 6


def test_mode_animations_want_at_least_two_frames(parts, tmp_path):
    for frames in (1, 2.5, True):
        with pytest.raises(InputError, match="frames: expected an integer number of frames per period, at least 2"):
            write_mode_animations(parts["modes"], parts["system"], tmp_path, frames=frames)
    assert not list(tmp_path.iterdir())


def test_mode_drawing_scales_translations_and_caps_rotations():
    points = np.array([[1.0, 2.0, 3.0], [-1.0, 0.0, 0.5]])
    translation = np.array([0.0, 0.0, 2e-3, 0.0, 0.0, 0.0])
    moved = drawn_mode(points, translation, largest=10.0)
    np.testing.assert_allclose(moved - points, [[0, 0, plots.MODE_SCALE * 10.0]] * 2, rtol=RTOL_DRAWN)
    rotation = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1e-3])
    moved = drawn_mode(points, rotation, largest=1000.0)  # 15 % of 1000 m would need 60 rad
    angle = np.arctan2(moved[0, 1], moved[0, 0]) - np.arctan2(points[0, 1], points[0, 0])
    assert angle == pytest.approx(plots.MAX_DRAWN_ROTATION, rel=RTOL_DRAWN)
    np.testing.assert_allclose(np.linalg.norm(moved, axis=1), np.linalg.norm(points, axis=1), rtol=RTOL_DRAWN)


def test_finite_rotations_are_scipys():
    from scipy.spatial.transform import Rotation

    from sixdof.plots.modes import finite_rotation

    rng = np.random.default_rng(7)
    for vector in [np.zeros(3), [0.0, 0.0, 1e-9], *(rng.normal(size=(5, 3)) * [[0.01], [0.3], [1.0], [2.5], [3.1]])]:
        R = finite_rotation(np.asarray(vector))
        np.testing.assert_allclose(R, Rotation.from_rotvec(vector).as_matrix(), rtol=0.0, atol=1e-15)


def test_body_box_falls_back_to_the_mount_extents_or_the_inertia_s_box():
    system = bridge("equal", dimensions=None)
    # The uniform box of the beam's mass and inertia: Lx^2 = 6 (Jyy + Jzz - Jxx) / m, ...
    J, m = np.diag(system.body.inertia), system.body.mass
    inertial = np.sqrt(6 * (J.sum() - 2 * J) / m)
    np.testing.assert_allclose(inertial, [0.7652, 39.988, 2.5521], rtol=1e-4)
    np.testing.assert_allclose(plots.body_box(system), inertial, rtol=RTOL_DRAWN)  # beyond the mounts' [0.39, 39.1, 2.06]
    # Mounts reaching further than that box: the box reaching the mounts.
    spread = System(system.body, [dataclasses.replace(m, position=m.position * 10.0) for m in system.mounts])
    np.testing.assert_allclose(plots.body_box(spread), [3.9, 391.0, 20.62], rtol=RTOL_DRAWN)
    # Every mount at the CG's height, or one mount under the CG: the inertia's box, not a flat slab.
    planar = System(system.body, [dataclasses.replace(m, position=m.position * [1.0, 1.0, 0.0]) for m in system.mounts])
    np.testing.assert_allclose(plots.body_box(planar), inertial, rtol=RTOL_DRAWN)
    single = System(system.body, [dataclasses.replace(system.mounts[0], position=[0.0, 0.0, 0.0])])
    np.testing.assert_allclose(plots.body_box(single), inertial, rtol=RTOL_DRAWN)
    np.testing.assert_array_equal(plots.body_box(bridge("equal")), [1.2, 40.0, 2.0])
    fig = plots.plot_mode_shapes(modal_analysis(system.M, system.K), system)
    assert len(fig.axes) == 6


def test_ke_distribution_annotates_percentages(parts):
    modes = parts["modes"]
    fig = plots.plot_ke_distribution(modes)
    assert labelled_axes(fig, categorical=("degree of freedom",))
    ax = fig.axes[0]
    ke = 100 * modes.ke_distribution
    texts = {(round(t.get_position()[1]), round(t.get_position()[0])): t.get_text() for t in ax.texts}
    assert len(texts) == 36
    for (i, j), text in texts.items():
        assert float(text) == pytest.approx(ke[i, j], abs=0.5 if ke[i, j] >= 9.95 else 0.05)
        assert not text.startswith("-")
    assert [t.get_text() for t in ax.get_yticklabels()] == list(DOF_NAMES)


def test_ke_distribution_draws_into_given_axes(parts):
    fig = Figure()
    ax = fig.add_subplot()
    assert plots.plot_ke_distribution(parts["modes"], ax=ax, name="bridge_beam") is fig
    assert len(ax.texts) == 36 and ax.get_title() == "bridge_beam: kinetic-energy distribution [%]"
    assert len(fig.axes) == 2  # the given axes and the colour bar


def test_time_histories_use_readable_units_per_dof(parts):
    response = parts["response"]
    fig = plots.plot_time_histories(response)
    assert labelled_axes(fig)
    q = response.q
    factors = {"mm": 1e3, "µm": 1e6, "nm": 1e9, "mrad": 1e3, "µrad": 1e6, "nrad": 1e9}
    by_label = {dof_of(ax.get_ylabel()): ax for ax in fig.axes}
    # The DOFs that move, each on its own axes (the others named in one line).
    drawn = responding(q)
    assert [dof for dof in by_label if dof in DOFS] == [dof for i, dof in enumerate(DOFS) if drawn[i]]
    for i, dof in enumerate(DOFS):
        if not drawn[i]:
            continue
        ax = by_label[dof]
        unit = ax.get_ylabel().split("[")[1].rstrip("]")
        assert unit in (("mm", "µm", "nm") if i < 3 else ("mrad", "µrad", "nrad"))
        assert_drawn_from(ax.lines[0], response.t, factors[unit] * q[:, i])
        # The peak shown between 1 and 1000 of its unit (the smallest unit may go below 1).
        assert np.max(np.abs(ax.lines[0].get_ydata())) < 1000
        assert np.max(np.abs(ax.lines[0].get_ydata())) >= 1 or unit in ("nm", "nrad")


def test_time_histories_show_the_motion_relative_to_a_moving_ground():
    t = np.linspace(0.0, 1.0, 201)
    q = np.outer(np.sin(2 * np.pi * t), [1e-3, 2e-3, 3e-3, 1e-4, 2e-4, 3e-4])
    ground = np.outer(np.sin(2 * np.pi * t), [0.0, 1.5e-3, 0.0])
    history = TimeHistory(t=t, q=q, qd=q, qdd=q, ground_displacement=ground, ground_velocity=ground,
                          ground_acceleration=ground)
    fig = plots.plot_time_histories(history)
    assert labelled_axes(fig)
    y = {ax.get_ylabel(): ax for ax in fig.axes}["along y [mm]"]
    # Displacements: the mount stroke, relative to the ground, first; the absolute dashed on the same scale.
    assert [line.get_label() for line in y.lines] == ["relative to the ground", "absolute"]
    assert_drawn_from(y.lines[0], t, 1e3 * (q[:, 1] - ground[:, 1]))
    assert y.get_title(loc="left") == "translation along y: peak relative to the ground 0.5 mm, absolute 2 mm"
    # Accelerations: what the body feels, absolute, first.
    y = {ax.get_ylabel(): ax for ax in plots.plot_time_histories(history, "qdd").axes}["along y [mm/s²]"]
    assert [line.get_label() for line in y.lines] == ["absolute", "relative to the ground"]
    # A ground that moves away (after a shock) would flatten the stroke: its peak is quoted, not drawn.
    away = TimeHistory(t=t, q=q + np.outer(t, [0.0, 0.5, 0.0, 0, 0, 0]), qd=q, qdd=q,
                       ground_displacement=ground + np.outer(t, [0.0, 0.5, 0.0]), ground_velocity=ground,
                       ground_acceleration=ground)
    y = {ax.get_ylabel(): ax for ax in plots.plot_time_histories(away).axes}["along y [µm]"]  # the stroke's own scale
    assert [line.get_label() for line in y.lines] == ["relative to the ground"]
    assert y.get_title(loc="left") == "translation along y: peak relative to the ground 500 µm, absolute 500 mm (not drawn)"
    # A ground that does not move draws no relative motion.
    still = TimeHistory(t=t, q=q, qd=q, qdd=q, ground_displacement=0 * ground, ground_velocity=0 * ground,
                        ground_acceleration=0 * ground)
    assert all(len(ax.lines) == 1 for ax in plots.plot_time_histories(still).axes)


def drawn_relative(ax) -> np.ndarray:
    """The relative difference a superposition panel draws, in the unit its y label gives (``[×10⁻⁹]``)."""
    label = ax.get_ylabel()
    digits = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
    power = int(label.rsplit("[×10", 1)[1].rstrip("]").translate(digits)) if "[×10" in label else 0
    return ax.lines[0].get_ydata() * 10.0**power


def test_superposition_overlay_and_difference(parts):
    direct, modal, agreement = parts["response"], parts["superposition"], parts["agreement"]
    fig = plots.plot_superposition(direct, modal, agreement)
    assert labelled_axes(fig)
    drawn = np.flatnonzero(responding(relative_to_ground(direct, modal)[0]))
    assert len(fig.axes) == 2 * len(drawn)  # per DOF that moves: the overlay and the difference
    worst = DOF_NAMES[DOFS.index(agreement.worst_dof)]  # in words, never the code ("rx")
    assert f"worst relative difference {agreement.worst:.2e} in {worst}" in fig.get_suptitle()
    for row, i in enumerate(drawn):
        assert fig.axes[2 * row].get_ylabel().startswith(f"{DOF_DIRECTIONS[i]} [")
        right = fig.axes[2 * row + 1]
        relative = drawn_relative(right)
        # The plotted curve's peak is the agreement of that DOF (no DOF is quiet here).
        assert np.max(np.abs(relative)) == pytest.approx(agreement.per_dof[i], rel=RTOL_DRAWN)
        assert 1.0 <= np.max(np.abs(right.lines[0].get_ydata())) < 10.0  # the power of ten is in the label
        unit = np.max(np.abs(relative)) / np.max(np.abs(right.lines[0].get_ydata()))
        assert_drawn_from(right.lines[0], direct.t,
                          (modal.q[:, i] - direct.q[:, i]) / np.max(np.abs(direct.q[:, i])) / unit, rtol=RTOL_DRAWN)


def test_superposition_difference_of_a_quiet_dof_is_the_agreement():
    # A load along x through the CG of a symmetric body: y, z, rx, rz stay at round-off ("quiet")
    # and the agreement judges them against the largest peak; the figure must plot the same number.
    from sixdof.analysis.compare import compare
    from sixdof.analysis.direct import SimulationSettings, simulate
    from sixdof.analysis.superposition import superpose
    from sixdof.excitation import Excitation, HalfSine, Load

    system = four_mount(100.0, (5.0, 6.0, 7.0), 0.4, 0.4, 0.3, (1e5, 1e5, 3e5), damping=[50.0, 50.0, 80.0],
                        dimensions=[1.0, 1.0, 1.0])
    excitation = Excitation(loads=(Load("push", [0.0, 0.0, 0.0], force=[100.0, 0.0, 0.0],
                                        signal=HalfSine(start=0.01, duration=0.02)),))
    response = simulate(system, excitation, SimulationSettings(duration=0.3, sample_rate_hz=1000.0))
    modal = superpose(system, excitation, response.t)
    agreement = compare(response.q, modal.q, length=0.5)
    assert set(agreement.quiet) >= {"y", "z", "rx", "rz"}
    fig = plots.plot_superposition(response, modal, agreement)
    # Round-off against round-off: not drawn, named in one line with the agreement's largest number.
    (line,) = [text.get_text() for text in fig.texts if text.get_text().startswith("not excited")]
    quiet = [agreement.per_dof[i] for i in range(6) if DOFS[i] in agreement.quiet and agreement.per_dof[i] > 0]
    assert (f"(round-off only, relative difference at most {max(quiet):.1e})" in line if quiet
            else line.endswith(f": {', '.join(DOF_DIRECTIONS[DOFS.index(dof)] for dof in agreement.quiet)} (exactly zero)"))
    rows = {dof_of(ax.get_ylabel()): k for k, ax in enumerate(fig.axes[::2])}
    for i in range(6):
        if DOFS[i] in agreement.quiet:
            assert DOFS[i] not in rows
            assert DOF_DIRECTIONS[i] in line.split("): ", 1)[1]
            continue
        ax = fig.axes[2 * rows[DOFS[i]] + 1]
        assert np.max(np.abs(drawn_relative(ax))) == pytest.approx(agreement.per_dof[i], rel=1e-9)


def contact_at(first: float):
    """A ContactSummary of one bump stop that engaged first at ``first`` [s]."""
    from sixdof.analysis.contact import ContactSummary

    one = np.ones(1)
    return ContactSummary(names=("m0 w",), kinds=("bump stop",), engagements=np.ones(1, np.int64), first_t=first * one,
                          engaged_time=0.1 * one, peak_penetration=1e-4 * one, peak_lift=np.nan * one,
                          deflection_min=-1e-3 * one, deflection_max=1e-3 * one, interval_law=np.zeros(1, np.int64),
                          interval_start=first * one, interval_end=(first + 0.1) * one, first_engaged_t=first)


def test_superposition_of_a_nonlinear_run_draws_the_differences_until_the_first_engagement():
    # Until a mount engages at 0.4 s the two agree to 1e-12; after it, by design, x differs by half its peak and z
    # (at rest until then) moves in the direct solve alone. The run's agreement covers t <= 0.4 s.
    from sixdof.analysis.compare import compare

    first = 0.4
    t = np.linspace(0.0, 1.0, 1001)
    wave, after = np.sin(2 * np.pi * 3 * t), t > first
    q = np.zeros((len(t), 6))
    q[:, 0], q[:, 3] = 1e-3 * wave, 2e-3 * wave
    q[after, 2] = 2e-3 * np.sin(2 * np.pi * 5 * (t[after] - first))
    q_modal = q.copy()
    q_modal[:, [0, 3]] += np.outer(np.where(after, 0.5e-3, 1e-15) * np.cos(2 * np.pi * 7 * t), [1.0, 2.0])
    q_modal[:, 2] = 0.0
    direct, modal = (TimeHistory(t=t, q=values, qd=values, qdd=values) for values in (q, q_modal))
    agreement = compare(q[~after], q_modal[~after], length=0.5)
    assert agreement.quiet == ("y", "z", "ry", "rz") and agreement.ok
    run = RunResults(name="snubbed", response=direct, superposition=modal, agreement=agreement,
                     contacts=contact_at(first))
    draw = next(draw for name, _, _, draw in plots.FIGURES if name == "superposition.png")
    fig = draw(run)  # as sixdof run and sixdof plot draw it: the run's contacts given
    assert f"t = {first:.4g} s; the superposition is not valid after it" in fig.get_suptitle()
    # x, z and rx move (z only after the engagement): a row each; y, ry and rz, at rest, are named in one line.
    assert [dof_of(ax.get_ylabel()) for ax in fig.axes[::2]] == ["x", "z", "rx"]
    assert [text.get_text() for text in fig.texts if text.get_text().startswith("not excited")][0].endswith(
        ": along y, about y, about z (exactly zero)")
    for row, i in enumerate((0, 2, 3)):
        left, right = fig.axes[2 * row], fig.axes[2 * row + 1]
        assert right.get_xlim() == (0.0, first) and left.get_xlim() == (0.0, 1.0)
        title = right.get_title()
        assert "round-off" not in title
        if i in (0, 3):  # drawn until the engagement, its peak the agreement's
            line = right.lines[0]
            assert line.get_xdata()[-1] <= first
            assert np.max(np.abs(drawn_relative(right))) == pytest.approx(agreement.per_dof[i], rel=1e-9)
            assert title == f"{DOF_NAMES[i]}: max|Δ| / peak for t ≤ 0.4 s = {agreement.per_dof[i]:.2e}"
            assert [line.get_label() for line in left.get_lines()] == ["direct integration", "modal superposition",
                                                                       "first engagement"]
            assert left.get_lines()[2].get_xdata()[0] == first
        else:  # z, at rest until the engagement: said so, its difference only until then (it moves after)
            assert not right.lines
            assert title == "translation along z: not excited for t ≤ 0.4 s"
    # Without contacts (a linear run) the whole record is compared.
    whole = plots.plot_superposition(direct, modal, compare(q, q_modal, length=0.5))
    assert whole.axes[1].get_xlim() == (0.0, 1.0) and "first engagement" not in whole.get_suptitle()


def test_bode_marks_natural_frequencies(parts):
    fig = plots.plot_bode(parts["frf"], parts["modes"])
    assert labelled_axes(fig)
    magnitude = fig.axes[0]
    assert magnitude.get_yscale() == "log" and magnitude.get_xscale() == "log"
    marked = sorted({round(line.get_xdata()[0], 9) for line in magnitude.lines if line.get_linestyle() == ":"})
    np.testing.assert_allclose(marked, parts["modes"].frequency_hz, rtol=1e-9)
    H = parts["frf"].direct.H
    np.testing.assert_array_equal(magnitude.lines[0].get_ydata(), np.abs(H[:, 0, 0]))


def test_bode_of_a_receptance_and_into_given_axes():
    system = bridge("equal")
    f = np.geomspace(0.2, 60.0, 200)
    frf = sixdof.receptance(system, f)
    fig = plots.plot_bode(frf)
    assert isinstance(fig, Figure) and labelled_axes(fig)
    translations, rotations = fig.axes[:2]
    for ax, block in ((translations, range(3)), (rotations, range(3, 6))):
        assert len(ax.lines) == 3  # no modes given: nothing marked
        for line, i in zip(ax.lines, block):
            np.testing.assert_array_equal(line.get_xdata(), f)
            np.testing.assert_array_equal(line.get_ydata(), np.abs(frf.H[:, i, i]))
    assert "dotted" not in fig.get_suptitle()

    mine = Figure()
    axes = mine.subplots(2, 2, sharex=True)
    assert plots.plot_bode(frf, system.modes, ax=axes) is mine
    assert len(mine.axes) == 4 and mine.get_suptitle() == ""
    np.testing.assert_array_equal(axes[0, 1].lines[2].get_ydata(), np.abs(frf.H[:, 5, 5]))
    np.testing.assert_array_equal(axes[1, 0].lines[0].get_ydata(), np.degrees(np.angle(frf.H[:, 0, 0])))
    assert axes[0, 0].get_ylabel() == "|H| [m/N]" and axes[0, 1].get_ylabel() == "|H| [rad/(N m)]"
    assert sum(line.get_linestyle() == ":" for line in axes[0, 0].lines) == np.count_nonzero(system.modes.frequency_hz)
    with pytest.raises(InputError, match=r"ax: expected Axes of shape \(2, 2\).*got shape \(2,\)"):
        plots.plot_bode(frf, ax=axes[0])


def test_point_frfs(parts):
    fig = plots.plot_point_frfs(parts["frf_extras"], parts["modes"])
    assert labelled_axes(fig)
    assert len(fig.axes) == 6


def test_point_frf_that_is_zero_by_symmetry_is_said_so_on_a_linear_axis():
    system = four_mount()  # symmetric: a moment about z turns the body about z alone
    f = np.linspace(1.0, 30.0, 50)
    frf = sixdof.point_frf(system, f, np.zeros(3), "rz", np.zeros(3), "rx")
    assert not np.any(np.abs(frf.values) > 0)
    fig = plots.plot_point_frfs({"turn": frf}, system.modes)
    mag = fig.axes[0]
    assert mag.get_yscale() == "linear"
    assert "zero at every frequency: the load does not excite this response" in [t.get_text() for t in mag.texts]


def test_mount_forces(parts):
    forces, t = parts["mount_forces"], parts["response"].t
    fig = plots.plot_mount_forces(forces, t)
    assert labelled_axes(fig)
    for c, ax in enumerate(fig.axes):
        factor = {"kN": 1e-3, "N": 1.0}[ax.get_ylabel().split("[")[1].rstrip("]")]
        for k in range(forces.total.shape[0]):
            assert_drawn_from(ax.lines[k], t, factor * forces.total[k, :, c])
        assert_drawn_from(ax.lines[-1], t, factor * forces.foundation_force[:, c])


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_validation_figures(parts):
    report = parts["validation"]
    fig = plots.plot_validation_frf(report)
    assert labelled_axes(fig)
    assert len(fig.axes) == 12
    fig = plots.plot_free_decays(report)
    assert labelled_axes(fig)
    assert [ax.get_title().split(",")[0] for ax in fig.axes] == [f"mode {r}" for r in range(1, 7)]
    assert all(ax.get_title().split(":")[0].endswith("fitted") for ax in fig.axes)  # not the model's values
    decays = sorted(report.decays, key=lambda d: d.mode)
    for r, (ax, decay) in enumerate(zip(fig.axes, decays), start=1):
        assert decay.mode == r
        label = ax.get_ylabel()  # the power of ten the curve is drawn in, e.g. "[10$^{-3}$ kg$^{1/2}$ m]"
        power = int(label.split("[10$^{", 1)[1].split("}", 1)[0]) if "[10$^{" in label else 0
        assert_drawn_from(ax.lines[0], decay.history.t, decay.eta / 10.0**power)
        assert 1 <= np.max(np.abs(ax.lines[0].get_ydata())) < 1000
        # Greek letters as mathtext, drawn as symbols, not spelled out as "eta_1" and "zeta".
        assert ax.get_ylabel().startswith(f"$\\eta_{{{r}}}$") and "$\\zeta$" in ax.get_title()
    assert "$\\eta_r = \\phi_r^T M q$" in fig.get_suptitle()


def _mount_forces(total: np.ndarray) -> MountForces:
    """Mount forces of the given totals (n_mounts, n, 3) [N] only, without a foundation total."""
    return MountForces(names=tuple(str(k + 1) for k in range(len(total))), deformation=None, elastic=None,
                       damping=None, total=total, local=None, other_damping=None, foundation_force=None,
                       foundation_moment=None)


def test_mount_forces_of_given_arrays():
    t = np.linspace(0.0, 1.0, 101)
    forces = np.stack([np.stack([5.0 * np.sin(t), 8.0 * np.sin(t), 1e5 * (k + 1) * np.cos(t)], axis=-1)
                       for k in range(4)])
    fig = plots.plot_mount_forces(_mount_forces(forces), t)
    assert labelled_axes(fig)
    assert [ax.get_ylabel() for ax in fig.axes] == ["force along x [N]", "force along y [N]", "force along z [kN]"]
    np.testing.assert_allclose(fig.axes[2].lines[3].get_ydata(), 4e2 * np.cos(t), rtol=1e-15)


def test_long_histories_are_drawn_through_their_envelope():
    # 20001 samples (20 s at 1 kHz) with one-sample spikes: drawn decimated, spikes and extrema kept.
    t = np.linspace(0.0, 20.0, 20_001)
    forces = np.stack([np.stack([np.sin(7 * t + k), np.cos(3 * t), 1e4 * np.sin(40 * t + k)], axis=-1)
                       for k in range(4)])
    forces[2, 9_876, 0] = 5.0
    forces[1, 15_001, 2] = -3e4
    fig = plots.plot_mount_forces(_mount_forces(forces), t)
    for c, ax in enumerate(fig.axes):
        factor = {"kN": 1e-3, "N": 1.0}[ax.get_ylabel().split("[")[1].rstrip("]")]
        for k in range(4):
            assert len(ax.lines[k].get_xdata()) < len(t) // 4
            assert_drawn_from(ax.lines[k], t, factor * forces[k, :, c])
    assert 5.0 in fig.axes[0].lines[2].get_ydata() and -30.0 in fig.axes[2].lines[1].get_ydata()


def test_wrong_or_missing_data_is_named(parts, modal_only):
    with pytest.raises(InputError, match=r"history: expected a sixdof.results.TimeHistory, got "):
        plots.plot_time_histories(modal_only.modes)
    with pytest.raises(InputError, match=r"history.Q: expected an \(n, 6\) array, got None"):
        plots.plot_time_histories(dataclasses.replace(parts["response"], Q=None), key="Q")
    with pytest.raises(InputError, match=r"key: expected one of q, qd, qdd, Q, got 'q_relative'"):
        plots.plot_time_histories(parts["response"], key="q_relative")
    with pytest.raises(InputError, match=r"modes: expected a sixdof.model.modes.Modes"):
        plots.plot_ke_distribution({"modal": None})
    with pytest.raises(InputError, match=r"frf: expected a sixdof.analysis.frf.FRF or FRFCrossCheck"):
        plots.plot_bode(parts["frf"].direct.H)
    with pytest.raises(InputError, match=r"extras: expected at least one point FRF or transmissibility, got none"):
        plots.plot_point_frfs({})
    with pytest.raises(InputError, match=r"forces.total: expected shape \(4, 3, 3\)"):
        plots.plot_mount_forces(parts["mount_forces"], parts["response"].t[:3])
    with pytest.raises(InputError, match=r"report.decays: expected at least one free decay, got none"):
        plots.plot_free_decays(dataclasses.replace(parts["validation"], decays=()))
    with pytest.raises(InputError, match=r"run: expected a sixdof.results.RunResults"):
        plots.save_all({"modal": None}, "unused")


@pytest.mark.slow  # 3 s on the 2-core machine
def test_save_all_draws_what_the_run_holds(run, modal_only, tmp_path):
    written = plots.save_all(run, tmp_path / "full", dpi=30)  # low resolution: only the files matter
    assert [p.name for p in written] == FIGURE_NAMES
    for path in written:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in plots.save_all(modal_only, tmp_path / "modal", dpi=30)] == ["mode_shapes.png",
                                                                                "ke_distribution.png"]


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_drawers_write_the_formats_and_dpi_of_the_run_scenario(modal_only, tmp_path):
    """In this process and in worker processes, a run's figures are written in its scenario's ``[output]``
    formats at its dpi, byte for byte alike."""
    from PIL import Image

    from sixdof.plots.drawer import InProcessDrawer
    from systems import heavily_damped_box_toml

    scenario = sixdof.parse_scenario('name = "box"\n' + heavily_damped_box_toml()
                                     + '[output]\nformats = ["svg", "png"]\ndpi = 50\n')
    asked = dataclasses.replace(modal_only, scenario=scenario)
    expected = [f"{stem}.{kind}" for stem in ("mode_shapes", "ke_distribution") for kind in ("svg", "png")]
    for drawer, folder in ((InProcessDrawer(), tmp_path / "here"), (FigureWorkers(processes=1), tmp_path / "workers")):
        folder.mkdir()
        with drawer:
            drawer.submit(asked)
            assert [p.name for p in drawer.save(folder)] == expected
        with Image.open(folder / "ke_distribution.png") as image:
            size = plots.plot_ke_distribution(modal_only.modes, name=modal_only.name).get_size_inches()
            assert image.size == tuple(round(v * 50) for v in size)
    assert (tmp_path / "here" / "mode_shapes.png").read_bytes() == (tmp_path / "workers" / "mode_shapes.png").read_bytes()
    # Without a scenario (a loaded file's results): PNG only, at the default resolution.
    assert plots.file_settings(modal_only) == (("png",), None)
    with pytest.raises(InputError, match=r"formats: expected a non-empty list from png, svg, pdf, got \['gif'\]"):
        plots.render_files(modal_only, "ke_distribution.png", ("gif",))


@pytest.mark.slow  # 2 s on the 2-core machine
def test_save_all_titles_start_with_the_run_name(run, monkeypatch, tmp_path):
    drawn = []
    monkeypatch.setattr(plots, "png", lambda fig, dpi=None: drawn.append(fig) or b"")
    plots.save_all(run, tmp_path, dpi=30)
    assert len(drawn) == len(FIGURE_NAMES)
    for fig in drawn:
        heading = fig.get_suptitle() or fig.axes[0].get_title()  # the heatmap has one axes title
        assert heading.startswith("bridge_beam: "), heading


def runs_without_pyplot(code: str) -> None:
    """``code`` runs in a fresh interpreter with no backend chosen, and never imports pyplot."""
    code = f"import sys\n{code}assert 'matplotlib.pyplot' not in sys.modules\n"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            env={**os.environ, "MPLBACKEND": ""})
    assert result.returncode == 0, result.stderr


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_save_all_never_loads_pyplot(tmp_path):
    runs_without_pyplot(
        "from sixdof import Mount, RigidBody, System, modal_analysis, plots\n"
        "from sixdof.results import RunResults\n"
        "system = System(RigidBody(100.0, [5.0, 6.0, 7.0]),\n"
        "                [Mount(str(i), [x, y, -0.3], [1e5, 1e5, 3e5]) for i, (x, y) in\n"
        "                 enumerate([(-0.4, -0.4), (0.4, -0.4), (0.4, 0.4), (-0.4, 0.4)])])\n"
        "run = RunResults(name='box', system=system, modes=modal_analysis(system.M, system.K))\n"
        f"files = plots.save_all(run, {str(tmp_path / 'png')!r})\n"
        "assert len(files) == 2, files\n"
    )


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_plot_from_a_file_never_loads_pyplot(modal_only, tmp_path):
    path = tmp_path / "results.h5"
    from sixdof.io.store import write_results

    write_results(path, modal_only)
    runs_without_pyplot(
        "from sixdof import plots\nfrom sixdof.io import store\n"
        f"files = plots.save_all(store.load_results({str(path)!r}), {str(tmp_path / 'png')!r})\n"
        "assert len(files) == 2, files\n"
    )


@pytest.mark.long  # over 10 s on the 2-core machine
def test_workers_draw_what_save_all_draws(run, tmp_path):
    """The figures drawn in worker processes, submitted as the run's parts appear, are the files save_all
    draws in this process, byte for byte."""
    modal = RunResults(name=run.name, system=run.system, modes=run.modes, frf=run.frf, frf_extras=run.frf_extras)
    with FigureWorkers(dpi=30) as workers:
        workers.submit(modal)  # the modal and FRF figures start first
        workers.submit(run)  # then the rest; nothing is drawn twice
        (tmp_path / "workers").mkdir()
        written = workers.save(tmp_path / "workers")
    assert [p.name for p in written] == FIGURE_NAMES
    for path in plots.save_all(run, tmp_path / "here", dpi=30):
        assert (tmp_path / "workers" / path.name).read_bytes() == path.read_bytes(), path.name


def test_a_figure_failing_in_a_worker_fails_loudly(parts, tmp_path):
    """The worker's error comes back, named, from save: a run that cannot draw a figure writes nothing."""
    short = dataclasses.replace(parts["mount_check"], compression=parts["mount_check"].compression[:, :3])
    broken = RunResults(name="bridge_beam", response=parts["response"], mount_check=short)
    with FigureWorkers(processes=1, dpi=30) as workers:
        workers.submit(broken)
        with pytest.raises(FigureError, match=r"mount_forces.png: InputError: check.compression: expected shape \(4, "):
            workers.save(tmp_path)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_png_files_hold_the_pixels_savefig_draws(run):
    """plots.png writes the figure's pixels itself (unfiltered rows, Pillow's filter search skipped): every
    figure decodes to the pixels matplotlib's own PNG holds, at the resolution it says, and the figure keeps
    its canvas and dpi."""
    import io

    from PIL import Image

    for name, _, drawable, draw in plots.FIGURES:
        if drawable(run):
            figure = draw(run)
            canvas, dpi = figure.canvas, figure.dpi
            mine = Image.open(io.BytesIO(plots.png(figure, dpi=50)))
            assert figure.canvas is canvas and figure.dpi == dpi, name
            buffer = io.BytesIO()
            figure.savefig(buffer, format="png", dpi=50)
            theirs = Image.open(io.BytesIO(buffer.getvalue()))
            assert mine.mode == theirs.mode == "RGBA" and mine.info["dpi"] == theirs.info["dpi"], name
            np.testing.assert_array_equal(np.asarray(mine), np.asarray(theirs), err_msg=name)


@pytest.mark.long  # over 10 s on the 2-core machine
def test_fixed_titles_draw_the_same_pixels(run):
    """render() draws with titles at a fixed height (plots.FIXED_TITLES): every figure is the one matplotlib's
    automatic title placement draws (a 3-D panel's title once sat on its legend)."""
    import matplotlib

    from figures import pixels

    for name, _, drawable, draw in plots.FIGURES:
        if drawable(run):
            with matplotlib.rc_context(plots.FIXED_TITLES):
                fixed = draw(run)
            np.testing.assert_array_equal(pixels(fixed), pixels(draw(run)), err_msg=name)


def test_frozen_y_ticks_draw_over_the_x_axis_as_matplotlib_orders_them():
    """On a log axis of 2-60 Hz the x minor ticks are labelled (kept) and the y minor ticks are frozen: a y tick
    mark crosses the x grid line at the 2 Hz limit, and the two blend in matplotlib's order (x axis, then y axis),
    so the picture is the same to the last level."""
    from matplotlib.figure import Figure

    from figures import frozen_tick_difference

    def draw():
        fig = Figure(figsize=(4, 3))
        ax = fig.subplots()
        ax.loglog()
        ax.axvspan(2, 60, color="0.9", lw=0)
        ax.set(xlim=(2, 60), ylim=(1e-3, 1e2))
        ax.grid(True, which="both", alpha=0.25)
        return fig

    assert frozen_tick_difference(draw).max() == 0


@pytest.mark.long  # over 10 s on the 2-core machine
def test_frozen_ticks_draw_the_same_pixels(run):
    """render() draws unlabelled ticks (minor log ticks, the time ticks of panels above a shared time
    axis) as two collections per axis (fast): at the resolution of the files, every figure is the one
    matplotlib's own tick objects draw, but for one level in 255 where grid lines cross (blending
    round-off)."""
    from figures import frozen_tick_difference, pixels

    drawn = [(name, draw) for name, _, drawable, draw in plots.FIGURES if drawable(run)]
    # Every figure but the random, random-check, shock-spectrum, response-spectrum, records, hysteresis, mount-shear,
    # dynamic-stiffness and transmissibility ones (test_random_time, test_figure_content, test_spectrum,
    # test_records_run, test_hysteresis and test_transmissibility draw the first six and the last; this run has no
    # shear worth a figure, no visco-elastic mount and no operating frequency).
    assert len(drawn) >= len(plots.FIGURES) - 9
    for name, draw in drawn:
        assert frozen_tick_difference(lambda draw=draw: draw(run)).max() <= 1.01 / 255, name
    frozen = plots.plot_superposition(run.response, run.superposition, run.agreement)
    plots.common.freeze_unlabelled_ticks(frozen)
    pixels(frozen)
    top, bottom = frozen.axes[0], frozen.axes[-1]
    assert len(top.xaxis.get_major_ticks()) == 0 and len(bottom.xaxis.get_major_ticks()) > 3  # labelled: kept
