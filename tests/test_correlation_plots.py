"""The figures of a test against the model (issue 47): each drawn from the bundled tap test's typed results, its
content checked against the numbers it draws (poles per stability class, the selected frequencies, the MAC
matrix's cells, each channel's FRFs, the update's history), and the correlation figures rendered by name."""

import types
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

import sixdof
from sixdof import InputError, load_scenario, load_test, plots
from sixdof.plots.correlation import UpdateHistory, frf_unit, update_history, wrapped_phase_deg
from sixdof.validation.correlation import channel_shapes, correlate_modes
from sixdof.validation.identify import identify_modes

SCENARIOS = Path(sixdof.__file__).parent / "scenarios"
BAND_HZ = (2.0, 40.0)
ORDER = 24  # a modest order: the six modes are stable from order 5 (the default, 40, is not the point here)


@pytest.fixture(scope="module")
def scenario():
    """The bundled scenario (its ``[test]`` table: the nodes in the lab frame)."""
    return load_scenario(SCENARIOS / "machine_tap_test.toml")


@pytest.fixture(scope="module")
def test(scenario):
    return load_test(SCENARIOS / "machine_tap_test.uff", scenario)


@pytest.fixture(scope="module")
def identification(test):
    return identify_modes(test.f_hz, test.H, test.quantity, band_hz=BAND_HZ, max_order=ORDER)


@pytest.fixture(scope="module")
def model_H(scenario, test):
    """The drawn model's accelerance on the test's channels, ``-w^2 rows (K - w^2 M + i w C)^-1 cols``."""
    system = scenario.system
    w = 2 * np.pi * test.f_hz[:, None, None]
    receptance = np.linalg.inv(system.K - w**2 * system.M + 1j * w * system.C)
    return -w**2 * (test.response_rows() @ receptance @ test.load_columns())


@pytest.fixture(scope="module")
def correlation(scenario, test, identification):
    modes = scenario.system.modes
    return correlate_modes(identification.modes.frequency_hz, identification.modes.damping_ratio,
                           identification.modes.shapes, modes.frequency_hz, np.full(6, 0.02),
                           channel_shapes(test.response_rows(), modes.shapes))


def history() -> UpdateHistory:
    """Two starts (the second the best), the polish after it; three factors and a CG offset given as 0."""
    start = np.array([0, 0, 0, 1, 1, 1, 1, -1, -1])
    objective = np.array([1.0, 0.3, 0.2, 2.0, 0.1, 0.01, 0.005, 0.006, 0.004])
    x = np.column_stack([np.linspace(1.0, 0.85, 9), np.linspace(1.2, 1.0, 9), np.full(9, 2.0),
                         np.linspace(0.0, 0.006, 9)])
    return UpdateHistory(start, objective, x, ("front_left w", "rear v", "mass", "cg_offset x"),
                         [1.0, 1.2, 2.0, 0.0], ("1", "1", "1", "m"), "modal objective")


def drawn_text(fig: Figure):
    FigureCanvasAgg(fig).draw()
    return fig.canvas.get_renderer()


def test_the_stability_diagram_draws_every_pole_by_class_and_the_selected_modes(test, identification):
    fig = plots.plot_stability(identification, H=test.H, f_hz=test.f_hz, unit="(m/s^2)/N", name="tap")
    assert fig._suptitle.get_text().startswith(f"tap: stability diagram: poly-reference LSCF poles of orders 1-{ORDER}")
    ax, twin = fig.axes
    assert ax.get_xlabel() == "natural frequency f [Hz]" and ax.get_ylabel() == "model order p [1]"
    assert twin.get_ylabel() == "sum of |H| over outputs and references [(m/s²)/N]"
    diagram = identification.stability
    low, high = identification.band_hz
    inside = (diagram.frequency_hz >= low) & (diagram.frequency_hz <= high)
    by_label = {line.get_label(): line for line in ax.lines}
    words = ("new pole", "stable in frequency", "stable in frequency and damping",
             "stable in frequency, damping and vector")
    for code, word in enumerate(words):
        count = int(np.sum(inside & (diagram.stability == code)))
        line = by_label[f"{word} ({count})"]
        np.testing.assert_array_equal(line.get_ydata(), diagram.order[inside & (diagram.stability == code)])
    assert sum(len(by_label[key].get_xdata()) for key in by_label if key.startswith(words)) == inside.sum()
    f_modes = identification.modes.frequency_hz
    assert f_modes.size == 6
    verticals = sorted(line.get_xdata()[0] for line in ax.lines if line.get_color() == "tab:red"
                       and len(line.get_xdata()) == 2 and line.get_xdata()[0] == line.get_xdata()[1])
    np.testing.assert_allclose(verticals, f_modes, rtol=1e-12)
    ringed = by_label["pole of a selected mode"]
    np.testing.assert_allclose(ringed.get_xdata(), f_modes, rtol=1e-12)
    labels = [t for t in ax.texts if t.get_text().endswith(" Hz")]
    assert [t.get_text() for t in labels] == [f"{j + 1}: {f:.4g} Hz" for j, f in enumerate(f_modes)]
    # The mode indicator: the sum over every output and reference, summed here channel by channel.
    keep = (test.f_hz >= BAND_HZ[0]) & (test.f_hz <= BAND_HZ[1])
    total = sum(np.abs(test.H[:, o, j]) for o in range(test.H.shape[1]) for j in range(test.H.shape[2]))
    np.testing.assert_allclose(twin.lines[0].get_ydata(), total[keep], rtol=1e-12)
    # Modes 5 and 6 are 2.9 % apart: their labels sit on different rows, no two labels overlap.
    renderer = drawn_text(fig)
    boxes = [t.get_window_extent(renderer) for t in labels]
    assert not any(a.overlaps(b) for k, a in enumerate(boxes) for b in boxes[k + 1:])


def test_the_stability_diagram_draws_on_given_axes_and_wants_h_with_its_frequencies(test, identification):
    fig = Figure()
    ax = fig.add_subplot()
    assert plots.plot_stability(identification, ax=ax) is fig and fig.axes == [ax] and fig._suptitle is None
    with pytest.raises(InputError, match=r"f_hz: expected the FRFs H and their frequencies f_hz together, got only one"):
        plots.plot_stability(identification, H=test.H)
    with pytest.raises(InputError, match=r"H: expected FRFs of shape \(nf, n_out, n_ref\) with nf = 991.*\(991, 15\)"):
        plots.plot_stability(identification, H=test.H[:, :, 0], f_hz=test.f_hz)


def test_the_mac_matrix_writes_each_cell_and_outlines_the_pairs(correlation):
    fig = plots.plot_mac(correlation, name="tap")
    ax, bar = fig.axes
    matrix = correlation.mac
    cells = [[None] * matrix.shape[1] for _ in range(matrix.shape[0])]
    for text in ax.texts:
        x, y = text.get_position()
        cells[int(y)][int(x)] = text.get_text()
    assert cells == [[f"{v:.2f}" for v in row] for row in matrix]
    outlines = {(int(round(p.get_y() + 0.5)), int(round(p.get_x() + 0.5))): p for p in ax.patches
                if isinstance(p, Rectangle) and not p.get_fill()}
    assert sorted(outlines) == sorted(zip(correlation.pair_test.tolist(), correlation.pair_model.tolist()))
    # Green where the pair meets both limits (from the frequencies and the channels' MAC), red dashed where not.
    from matplotlib.colors import to_rgba

    for (t, m), patch in outlines.items():
        error = 100 * abs(correlation.f_model[m] - correlation.f_test[t]) / correlation.f_test[t]
        ok = error <= correlation.max_frequency_error_percent and matrix[t, m] >= correlation.min_mac
        assert patch.get_edgecolor() == to_rgba("tab:green" if ok else "tab:red")
        assert patch.get_linestyle() == ("-" if ok else "--")
        assert ok or not correlation.correlated
    assert [t.get_text() for t in ax.get_yticklabels()] == [f"{i + 1}: {f:.4g} Hz"
                                                            for i, f in enumerate(correlation.f_test)]
    assert [t.get_text() for t in ax.get_xticklabels()] == [f"{j + 1}\n{f:.4g} Hz"
                                                            for j, f in enumerate(correlation.f_model)]
    assert ax.get_xlabel() == "model mode (natural frequency)" and ax.get_ylabel() == "test mode (identified frequency)"
    assert bar.get_ylabel() == "MAC on the measured channels [1]" and bar.get_ylim() == (0.0, 1.0)
    verdict = "correlated" if correlation.correlated else "not correlated"
    assert f"MAC on the measured channels: {verdict}; pairs outlined, green within the limits" in fig._suptitle.get_text()
    with pytest.raises(InputError, match=r"correlation.mac_body: expected a MAC on the six body DOFs"):
        plots.plot_mac(correlation, body=True)


def test_the_frf_overlay_draws_every_channel_and_reference(test, model_H):
    updated = 1.1 * model_H
    fig = plots.plot_frf_overlay(test, model_H, H_updated=updated, name="tap")
    n_out, n_ref = test.H.shape[1:]
    assert len(fig.axes) == 2 * n_out  # a magnitude and a phase per response channel
    magnitudes, phases = fig.axes[0::2], fig.axes[1::2]
    assert [ax.get_title() for ax in magnitudes] == [f"response {label}" for label in test.out_labels]
    assert {ax.get_ylabel() for ax in magnitudes} == {"|H| [(m/s²)/N]"}
    assert {ax.get_ylabel() for ax in phases} == {"phase\n[deg]"}
    assert [ax.get_xlabel() for ax in phases[-3:]] == ["frequency f [Hz]"] * 3
    positive = test.f_hz > 0
    for o in (0, 7, 14):
        drawn = [line for line in magnitudes[o].lines if len(line.get_xdata())]
        assert len(drawn) == 3 * n_ref
        for j in range(n_ref):
            test_line, model_line, updated_line = drawn[3 * j:3 * j + 3]
            assert (test_line.get_linestyle(), model_line.get_linestyle(), updated_line.get_linestyle()) == (
                "-", "--", ":")
            np.testing.assert_array_equal(test_line.get_ydata(), np.abs(test.H[positive, o, j]))
            np.testing.assert_array_equal(model_line.get_ydata(), np.abs(model_H[positive, o, j]))
            np.testing.assert_array_equal(updated_line.get_ydata(), np.abs(updated[positive, o, j]))
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == [f"reference {label}" for label in test.ref_labels] + [
        "test", "model", "updated model"]
    assert "against the model (dashed) and the updated model (dotted): 15 response channels, 3 references" in (
        fig._suptitle.get_text())
    with pytest.raises(InputError, match=r"H_model: expected FRFs on the test's channels, shape \(991, 15, 3\)"):
        plots.plot_frf_overlay(test, model_H[:, :3])


def test_the_overlay_takes_test_data_only():
    timed = types.SimpleNamespace(kind="time", H=None)
    with pytest.raises(InputError, match=r"test: expected a sixdof.validation.testdata.TestData"):
        plots.plot_frf_overlay(timed, None)


def test_wrapped_phase_breaks_at_the_wrap():
    f = np.array([1.0, 2.0, 3.0, 4.0])
    values = np.exp(1j * np.radians([170.0, 179.0, -179.0, -170.0]))
    f_drawn, phase = wrapped_phase_deg(f, values)
    np.testing.assert_allclose(f_drawn, [1.0, 2.0, np.nan, 3.0, 4.0])
    np.testing.assert_allclose(phase, [170.0, 179.0, np.nan, -179.0, -170.0])


def test_frf_units_follow_the_quantity_and_the_channel_kinds():
    assert frf_unit("accelerance", False, False) == "(m/s²)/N"
    assert frf_unit("mobility", True, True) == "(rad/s)/(N m)"
    assert frf_unit("receptance", False, True) == "m/(N m)"
    assert frf_unit("receptance", True, False) == "rad/N"


def test_the_update_history_draws_each_start_and_the_best_start_s_variables():
    fig = plots.plot_update_history(history(), name="tap")
    objective_ax, factors_ax, zero_ax = fig.axes
    assert "the variables of the best start (start 2)" in fig._suptitle.get_text()
    assert objective_ax.get_yscale() == "log" and objective_ax.get_ylabel() == "modal objective [1]"
    assert objective_ax.get_xlabel() == "iteration within the start [1]"
    first, second, polish = objective_ax.lines
    assert (first.get_label(), second.get_label()) == ("start 1", "start 2 (best)")
    np.testing.assert_array_equal(first.get_ydata(), [1.0, 0.3, 0.2])
    np.testing.assert_array_equal(second.get_xdata(), [0, 1, 2, 3])
    np.testing.assert_array_equal(polish.get_xdata(), [4, 5])  # counted on from the best start's end
    np.testing.assert_array_equal(polish.get_ydata(), [0.006, 0.004])
    assert factors_ax.get_ylabel() == "x / x0 (over the given value) [1]"
    curves = [line for line in factors_ax.lines if len(line.get_xdata()) == 6]
    assert [line.get_label() for line in curves] == ["front_left w (given 1)", "rear v (given 1.2)", "mass (given 2)"]
    x = history().x[3:]
    np.testing.assert_allclose(curves[1].get_ydata(), x[:, 1] / 1.2, rtol=1e-15)
    np.testing.assert_allclose(curves[2].get_ydata(), np.ones(6))
    assert zero_ax.get_ylabel() == "value [m]" and zero_ax.lines[0].get_label() == "cg_offset x [m]"
    np.testing.assert_array_equal(zero_ax.lines[0].get_ydata(), x[:, 3])
    assert zero_ax.get_xlabel() == "iteration of start 2 and the polish [1]"


def test_the_update_history_reads_an_update_result_s_fields():
    h = history()
    result = types.SimpleNamespace(history_start_index=h.start_index, history_objective=h.objective,
                                   history_x=h.x, variable=np.array(h.variables), initial=h.initial,
                                   variable_units=h.units, objective="modal")
    read = update_history(result)
    assert read.variables == h.variables and read.objective_name == "modal objective"
    np.testing.assert_array_equal(read.x, h.x)
    with pytest.raises(InputError, match=r"update: expected a sixdof.design.update.UpdateResult or an UpdateHistory, "
                                         r"got a SimpleNamespace without history_x"):
        update_history(types.SimpleNamespace(**{k: v for k, v in vars(result).items() if k != "history_x"}))
    with pytest.raises(InputError, match=r"history.x: expected \(9 iterations, 4 variables\)"):
        UpdateHistory(h.start_index, h.objective, h.x[:, :2], h.variables, h.initial, h.units)


def test_the_correlation_figures_render_by_name(test, identification, correlation, model_H):
    run = types.SimpleNamespace(name="tap", measured=test, identification=identification, correlation=correlation,
                                model_H=model_H, updated_H=None, update=None)
    assert plots.correlation_figure_names(run) == ["stability.png", "mac.png", "frf_overlay.png"]
    assert plots.correlation_figure_names(types.SimpleNamespace(**{**vars(run), "update": history()}))[-1] == (
        "update_history.png")
    assert [name for name, _, _ in plots.CORRELATION_FIGURES] == ["stability.png", "mac.png", "frf_overlay.png",
                                                                   "update_history.png"]
    for name in ("stability.png", "mac.png"):
        assert plots.render_correlation(run, name, dpi=40).startswith(b"\x89PNG\r\n\x1a\n")


def test_the_figures_draw_onto_the_caller_s(test, model_H, correlation):
    fig = Figure(figsize=(8, 6))
    ax = fig.add_subplot()
    assert plots.plot_mac(correlation, ax=ax) is fig and len(fig.axes) == 2 and fig._suptitle is None
    fig = Figure(figsize=(15, 18))
    assert plots.plot_frf_overlay(test, model_H, fig=fig) is fig and len(fig.axes) == 30 and fig._suptitle is None
    fig = Figure(figsize=(12, 6))
    assert plots.plot_update_history(history(), fig=fig) is fig and len(fig.axes) == 3 and fig._suptitle is None
