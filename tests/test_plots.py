"""Figures: each function draws from a Results tree (live or loaded), labels axes with units, and
the whole set is written by save_all without pyplot."""

import os
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.figure import Figure

from sixdof import InputError, modal_analysis, plots, write_results
from sixdof.io.store import Dataset, build_results, load_tree
from store_cases import run_parts
from systems import bridge, four_mount
from tolerances import RTOL_DRAWN

UNIT_WORDS = ("[m]", "[kg^1/2 m]", "[mm]", "[µm]", "[mrad]", "[µrad]", "[s]", "[Hz]", "[kN]", "[N]", "[deg]", "[%]",
              "[m/N]", "[rad/(N m)]", "[1]", "[N/N]", "[m/m]", "[m/N/s^2]")


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """The full bridge run, written and read back: figures are drawn from the stored file."""
    path = tmp_path_factory.mktemp("plots") / "results.h5"
    write_results(path, **run_parts())
    return load_tree(path)


@pytest.fixture(scope="module")
def modal_only():
    system = bridge("equal")
    return build_results(system=system, modes=modal_analysis(system.M, system.K), name="bridge_beam")


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
            labels.append(ax.get_zlabel())
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


def test_mode_shapes(results):
    fig = plots.plot_mode_shapes(results)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == 6 and all(ax.name == "3d" for ax in fig.axes)
    assert labelled_axes(fig)
    freqs = results.array("modal/frequency_hz")
    for j, ax in enumerate(fig.axes):
        title = ax.get_title()
        assert f"Mode {j + 1}: {freqs[j]:.4g} Hz" in title
        assert f"dominant {results.array('modal/dominant_dof')[j]}" in title
    assert [ax.get_xlabel() for ax in fig.axes[:1]] == ["x [m]"]


def test_mode_drawing_scales_translations_and_caps_rotations():
    points = np.array([[1.0, 2.0, 3.0], [-1.0, 0.0, 0.5]])
    translation = np.array([0.0, 0.0, 2e-3, 0.0, 0.0, 0.0])
    moved = plots._drawn_mode(points, translation, largest=10.0)
    np.testing.assert_allclose(moved - points, [[0, 0, plots.MODE_SCALE * 10.0]] * 2, rtol=RTOL_DRAWN)
    rotation = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1e-3])
    moved = plots._drawn_mode(points, rotation, largest=1000.0)  # 15 % of 1000 m would need 60 rad
    angle = np.arctan2(moved[0, 1], moved[0, 0]) - np.arctan2(points[0, 1], points[0, 0])
    assert angle == pytest.approx(plots.MAX_DRAWN_ROTATION, rel=RTOL_DRAWN)
    np.testing.assert_allclose(np.linalg.norm(moved, axis=1), np.linalg.norm(points, axis=1), rtol=RTOL_DRAWN)


def test_body_box_falls_back_to_the_mount_extents():
    system = bridge("equal", dimensions=None)
    results = build_results(system=system)
    largest = 2 * 19.55
    np.testing.assert_allclose(plots.body_box(results), [0.39, largest, 2.062], rtol=RTOL_DRAWN)
    planar = build_results(system=bridge("equal", dimensions=None), extra_attrs={})
    positions = planar.array("model/mount_position") * [1.0, 1.0, 0.0]  # every mount at the CG's height
    planar = build_results(system=bridge("equal", dimensions=None), extra={
        "model/mount_position": Dataset(positions, "m", ("mount", "axis"))})
    np.testing.assert_allclose(plots.body_box(planar), [0.39, largest, plots.FLAT_SIDE * largest], rtol=RTOL_DRAWN)
    with_dims = build_results(system=bridge("equal"))
    np.testing.assert_array_equal(plots.body_box(with_dims), [1.2, 40.0, 2.0])
    fig = plots.plot_mode_shapes(build_results(system=system, modes=modal_analysis(system.M, system.K)))
    assert len(fig.axes) == 6


def test_ke_distribution_annotates_percentages(results):
    fig = plots.plot_ke_distribution(results)
    assert labelled_axes(fig, categorical=("degree of freedom",))
    ax = fig.axes[0]
    ke = 100 * results.array("modal/ke_distribution")
    texts = {(round(t.get_position()[1]), round(t.get_position()[0])): t.get_text() for t in ax.texts}
    assert len(texts) == 36
    for (i, j), text in texts.items():
        assert float(text) == pytest.approx(ke[i, j], abs=0.5 if ke[i, j] >= 9.95 else 0.05)
        assert not text.startswith("-")
    assert [t.get_text() for t in ax.get_yticklabels()] == ["x", "y", "z", "rx", "ry", "rz"]


def test_time_histories_use_readable_units_per_dof(results):
    fig = plots.plot_time_histories(results)
    assert labelled_axes(fig)
    q = results.array("time/q")
    factors = {"mm": 1e3, "µm": 1e6, "mrad": 1e3, "µrad": 1e6}
    by_label = {ax.get_ylabel().split(" ")[0]: ax for ax in fig.axes}
    for i, dof in enumerate(results.dofs):
        ax = by_label[dof]
        unit = ax.get_ylabel().split("[")[1].rstrip("]")
        assert unit in (("mm", "µm") if i < 3 else ("mrad", "µrad"))
        assert_drawn_from(ax.lines[0], results.array("time/t"), factors[unit] * q[:, i])
        assert 0.01 <= np.max(np.abs(ax.lines[0].get_ydata())) < 1e4


def test_superposition_overlay_and_difference(results):
    fig = plots.plot_superposition(results)
    assert labelled_axes(fig)
    assert len(fig.axes) == 12
    attrs = results.attrs["time/superposition"]
    assert f"{attrs['agreement_worst']:.2e}" in fig.get_suptitle()
    t, direct, modal = results.array("time/t"), results.array("time/q"), results.array("time/superposition/q")
    for i in range(6):
        right = fig.axes[2 * i + 1]
        relative = right.lines[0].get_ydata()
        # The plotted curve's peak is the stored agreement of that DOF (no DOF is quiet here).
        assert np.max(np.abs(relative)) == pytest.approx(attrs["agreement_per_dof"][i], rel=RTOL_DRAWN)
        assert_drawn_from(right.lines[0], t, (modal[:, i] - direct[:, i]) / np.max(np.abs(direct[:, i])), rtol=RTOL_DRAWN)


def test_superposition_difference_of_a_quiet_dof_is_the_stored_agreement():
    # A load along x through the CG of a symmetric body: y, z, rx, rz stay at round-off ("quiet")
    # and the agreement judges them against the largest peak; the figure must plot the same number.
    from sixdof import Excitation, HalfSine, Load, SimulationSettings, compare, simulate, superpose

    system = four_mount(100.0, (5.0, 6.0, 7.0), 0.4, 0.4, 0.3, (1e5, 1e5, 3e5), damping=[50.0, 50.0, 80.0],
                        dimensions=[1.0, 1.0, 1.0])
    excitation = Excitation(loads=(Load("push", [0.0, 0.0, 0.0], force=[100.0, 0.0, 0.0],
                                        signal=HalfSine(start=0.01, duration=0.02)),))
    response = simulate(system, excitation, SimulationSettings(duration=0.3, sample_rate_hz=1000.0))
    modal = superpose(system, excitation, response.t)
    agreement = compare(response.q, modal.q, length=0.5)
    assert set(agreement.quiet) >= {"y", "z", "rx", "rz"}
    fig = plots.plot_superposition(build_results(system=system, response=response, superposition=modal,
                                                 agreement=agreement))
    for i in range(6):
        relative = fig.axes[2 * i + 1].lines[0].get_ydata()
        assert np.max(np.abs(relative)) == pytest.approx(agreement.per_dof[i], rel=1e-9)


def test_bode_marks_natural_frequencies(results):
    fig = plots.plot_bode(results)
    assert labelled_axes(fig)
    magnitude = fig.axes[0]
    assert magnitude.get_yscale() == "log" and magnitude.get_xscale() == "log"
    marked = sorted({round(line.get_xdata()[0], 9) for line in magnitude.lines if line.get_linestyle() == ":"})
    np.testing.assert_allclose(marked, results.array("modal/frequency_hz"), rtol=1e-9)
    H = results.array("frf/receptance")
    np.testing.assert_array_equal(magnitude.lines[0].get_ydata(), np.abs(H[:, 0, 0]))


def test_point_frfs(results):
    fig = plots.plot_point_frfs(results)
    assert labelled_axes(fig)
    assert len(fig.axes) == 6


def test_mount_forces(results):
    fig = plots.plot_mount_forces(results)
    assert labelled_axes(fig)
    t, forces = results.array("time/t"), results.array("time/mount_force")
    for c, ax in enumerate(fig.axes):
        unit = ax.get_ylabel().split("[")[1].rstrip("]")
        factor = {"kN": 1e-3, "N": 1.0}[unit]
        for k in range(forces.shape[0]):
            assert_drawn_from(ax.lines[k], t, factor * forces[k, :, c])
        assert_drawn_from(ax.lines[-1], t, factor * results.array("time/foundation_force")[:, c])


def test_validation_figures(results):
    fig = plots.plot_validation_frf(results)
    assert labelled_axes(fig)
    assert len(fig.axes) == 12
    fig = plots.plot_free_decays(results)
    assert labelled_axes(fig)
    assert [ax.get_title().split(":")[0] for ax in fig.axes] == [f"mode {r}" for r in range(1, 7)]
    for r, ax in enumerate(fig.axes, start=1):
        assert_drawn_from(ax.lines[0], results.array(f"validation/decay/mode_{r}/t"),
                          results.array(f"validation/decay/mode_{r}/eta"))


def test_mount_forces_from_a_stored_history(modal_only):
    t = np.linspace(0.0, 1.0, 101)
    forces = np.stack([np.stack([5.0 * np.sin(t), 8.0 * np.sin(t), 1e5 * (k + 1) * np.cos(t)], axis=-1)
                       for k in range(4)])
    extra = {"time/t": Dataset(t, "s", ("t",)),
             "time/mount": Dataset(np.array(["1", "2", "3", "4"]), "", ("mount",)),
             "time/axis": Dataset(np.array(["x", "y", "z"]), "", ("axis",)),
             "time/mount_force": Dataset(forces, "N", ("mount", "t", "axis"))}
    results = build_results(system=bridge("equal"), extra=extra)
    fig = plots.plot_mount_forces(results)
    assert labelled_axes(fig)
    assert [ax.get_ylabel() for ax in fig.axes] == ["Fx [N]", "Fy [N]", "Fz [kN]"]
    np.testing.assert_allclose(fig.axes[2].lines[3].get_ydata(), 4e2 * np.cos(t), rtol=1e-15)


def test_long_histories_are_drawn_through_their_envelope():
    # 20001 samples (20 s at 1 kHz) with one-sample spikes: drawn decimated, spikes and extrema kept.
    t = np.linspace(0.0, 20.0, 20_001)
    forces = np.stack([np.stack([np.sin(7 * t + k), np.cos(3 * t), 1e4 * np.sin(40 * t + k)], axis=-1)
                       for k in range(4)])
    forces[2, 9_876, 0] = 5.0
    forces[1, 15_001, 2] = -3e4
    extra = {"time/t": Dataset(t, "s", ("t",)),
             "time/mount": Dataset(np.array(["1", "2", "3", "4"]), "", ("mount",)),
             "time/axis": Dataset(np.array(["x", "y", "z"]), "", ("axis",)),
             "time/mount_force": Dataset(forces, "N", ("mount", "t", "axis"))}
    fig = plots.plot_mount_forces(build_results(system=bridge("equal"), extra=extra))
    for c, ax in enumerate(fig.axes):
        factor = {"kN": 1e-3, "N": 1.0}[ax.get_ylabel().split("[")[1].rstrip("]")]
        for k in range(4):
            assert len(ax.lines[k].get_xdata()) < len(t) // 4
            assert_drawn_from(ax.lines[k], t, factor * forces[k, :, c])
    assert 5.0 in fig.axes[0].lines[2].get_ydata() and -30.0 in fig.axes[2].lines[1].get_ydata()


def test_missing_data_is_named(modal_only):
    with pytest.raises(InputError, match=r"results: expected datasets /time/t, /time/q, got results without them"):
        plots.plot_time_histories(modal_only)
    with pytest.raises(InputError, match=r"results: expected a sixdof.io.store.Results"):
        plots.plot_ke_distribution({"modal": None})


def test_save_all_draws_what_the_results_hold(results, modal_only, tmp_path):
    written = plots.save_all(results, tmp_path / "full", dpi=30)  # low resolution: only the files matter
    assert [p.name for p in written] == ["mode_shapes.png", "ke_distribution.png", "time_dofs.png",
                                         "mount_forces.png", "superposition.png", "bode.png", "point_frfs.png",
                                         "validation_frf.png", "free_decays.png"]
    for path in written:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in plots.save_all(modal_only, tmp_path / "modal", dpi=30)] == ["mode_shapes.png",
                                                                                "ke_distribution.png"]


def test_plot_from_a_file_never_loads_pyplot(modal_only, tmp_path):
    path = tmp_path / "results.h5"
    from sixdof.io.store import save_results

    save_results(modal_only, path)
    code = (
        "import sys\n"
        "from sixdof import plots\nfrom sixdof.io import store\n"
        f"files = plots.save_all(store.load_tree({str(path)!r}), {str(tmp_path / 'png')!r})\n"
        "assert len(files) == 2, files\n"
        "assert 'matplotlib.pyplot' not in sys.modules\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            env={**os.environ, "MPLBACKEND": ""})
    assert result.returncode == 0, result.stderr
