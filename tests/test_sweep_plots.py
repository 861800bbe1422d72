"""The figures of a design sweep (issue 49, item 2): each drawn from a small sweep of the bundled bridge, its
content checked against the numbers it draws (one box per mode or DOF at the variants' median, the nominal design
marked, one tornado bar per parameter of the fitted effect); the decoupling and the fit checked against
independent answers (each variant's own design metrics; the exact derivatives of the nominal frequencies); and
``sixdof sweep`` and ``sixdof plot`` writing them by name."""

from pathlib import Path

import h5py
import numpy as np
import pytest

import sixdof
from sixdof.analysis.batch import variant_system
from sixdof.analysis.design import design_metrics, sensitivities
from sixdof.analysis.sweep import Study
from sixdof.analysis.sweep_fit import sweep_sensitivity, swept_parameters
from sixdof.cli import main
from sixdof.dofs import DOFS, display_unit
from sixdof.io.store import load_results
from sixdof.io.sweep import parse_sweep_spec
from sixdof.plots.sweep import (
    TORNADO_BARS,
    plot_sweep_decoupling,
    plot_sweep_frequencies,
    plot_sweep_peaks,
    plot_sweep_sensitivity,
)
from sixdof.workflows.prepare import prepare
from sixdof.workflows.sweep import sweep, sweep_scenario

SCENARIOS = Path(sixdof.__file__).parent / "scenarios"
FIGURES = ["sweep_decoupling.png", "sweep_frequencies.png", "sweep_peaks.png", "sweep_sensitivity.png"]
SPEC = """count = 30
seed = 3
cross_check = 1
[[vary]]
parameter = "stiffness"
distribution = "uniform"
low = 0.7
high = 1.3
independent = true
"""


@pytest.fixture(scope="module")
def scenario():
    return prepare(SCENARIOS / "bridge_beam_traffic.toml")


@pytest.fixture(scope="module")
def written(scenario, tmp_path_factory):
    """A sweep of 30 variants (+-30 % on every bearing axis) as ``sixdof sweep`` writes it."""
    _, folder = sweep_scenario(scenario, parse_sweep_spec(SPEC), tmp_path_factory.mktemp("sweep"))
    return folder


@pytest.fixture(scope="module")
def run(written):
    return load_results(written / "sweep.h5")


def _medians(ax) -> list[float]:
    """The median lines of an axes' boxes (drawn 2 points wide), left to right."""
    return [float(line.get_ydata()[0]) for line in ax.lines if line.get_linewidth() == 2]


@pytest.mark.slow  # 2 s on the 2-core machine
def test_the_sweep_writes_its_figures_and_its_report_shows_them(written):
    assert sorted(p.name for p in written.glob("*.png")) == FIGURES
    page = (written / "report.html").read_text(encoding="utf-8")
    for name in FIGURES:
        assert f"<code>{name}</code>" in page


@pytest.mark.slow  # the sweep it reads: 3 s on the 2-core machine
def test_frequencies_one_box_per_mode_at_the_variants_median(run):
    fig = plot_sweep_frequencies(run.sweep, run.system.modes, name=run.name)
    axes = fig.axes
    assert len(axes) == 6
    assert axes[0].get_ylabel() == "natural frequency [Hz]"
    assert fig._suptitle.get_text() == "bridge_beam_traffic: natural frequency of each mode over 30 variants"
    for j, ax in enumerate(axes):
        assert len(ax.patches) == 1  # one box
        assert ax.get_xticklabels()[0].get_text() == f"mode {j + 1} ({run.system.modes.dominant_dof[j]})"
        np.testing.assert_allclose(_medians(ax), [np.median(run.sweep.tracked_frequency_hz[:, j])], rtol=1e-12)
        nominal = [line for line in ax.lines if line.get_linestyle() == "--"]
        np.testing.assert_allclose(nominal[0].get_ydata(), run.system.modes.frequency_hz[j], rtol=1e-12)


@pytest.mark.slow  # the sweep it reads: 3 s on the 2-core machine
def test_decoupling_is_each_variants_own_and_drawn_one_box_per_mode(run, scenario):
    shares = run.sweep.tracked_decoupling_percent
    # Independent: each variant built as a system of its own, its decoupling by the design metrics. The tracked
    # modes are the variant's own, in the nominal modes' order.
    for v in (0, 17):
        own = design_metrics(variant_system(scenario.system, run.sweep.variants, v)).decoupling_percent
        np.testing.assert_allclose(np.sort(shares[v]), np.sort(own), rtol=1e-9)
    fig = plot_sweep_decoupling(run.sweep, run.system.modes, name=run.name)
    (ax,) = fig.axes
    assert len(ax.patches) == 6
    assert ax.get_ylabel() == "kinetic energy in the dominant DOF [%]"
    np.testing.assert_allclose(_medians(ax), np.median(shares, axis=0), rtol=1e-12)
    nominal = ax.collections[0].get_offsets()[:, 1]
    np.testing.assert_allclose(nominal, design_metrics(scenario.system).decoupling_percent, rtol=1e-9)


@pytest.mark.slow  # the sweep it reads: 3 s on the 2-core machine
def test_decoupling_needs_the_decoupling(run):
    import dataclasses

    older = dataclasses.replace(run.sweep, tracked_decoupling_percent=None)
    with pytest.raises(ValueError, match="result.tracked_decoupling_percent: expected the decoupling"):
        plot_sweep_decoupling(older, run.system.modes)


@pytest.mark.slow  # the sweep it reads: 3 s on the 2-core machine
def test_peaks_one_panel_per_dof_and_quantity_in_display_units(run):
    fig = plot_sweep_peaks(run.sweep, name=run.name)
    assert len(fig.axes) == 12
    for row, peaks in enumerate((run.sweep.peak_q, run.sweep.peak_qdd)):
        for j, ax in enumerate(fig.axes[6 * row:6 * row + 6]):
            assert ax.get_xticklabels()[0].get_text() == DOFS[j] and len(ax.patches) == 1
            scale, unit = display_unit(peaks[:, j], ("m", "m", "m", "rad", "rad", "rad")[j] + ("", "/s^2")[row])
            assert ax.get_ylabel().endswith(f"[{unit}]")
            np.testing.assert_allclose(_medians(ax), [scale * np.median(peaks[:, j])], rtol=1e-12)
    assert fig.axes[0].get_ylabel().startswith("peak displacement")
    assert fig.axes[6].get_ylabel().startswith("peak acceleration")
    import dataclasses

    with pytest.raises(ValueError, match="result.peak_q: expected the peaks"):
        plot_sweep_peaks(dataclasses.replace(run.sweep, peak_q=None))


@pytest.mark.slow  # the sweep it reads: 3 s on the 2-core machine
def test_tornado_one_bar_per_parameter_of_the_fitted_effect(run):
    fit = sweep_sensitivity(run.sweep, run.system)
    assert len(fit.parameters) == 12 and fit.parameters[0] == "stiffness of mount 1 (u)"
    assert np.all(fit.r_squared > 0.95)  # f ~ sqrt(k): near linear over +-30 %
    fig = plot_sweep_sensitivity(fit, run.system.modes, name=run.name)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 6
    for k, ax in enumerate(visible):
        assert ax.get_xlabel() == "change of natural frequency [Hz]"
        assert len(ax.patches) == 2 * TORNADO_BARS  # a low and a high bar per parameter shown
        drawn = {t.get_text(): [] for t in ax.get_yticklabels()}
        names = [t.get_text() for t in ax.get_yticklabels()]
        for patch in ax.patches:
            drawn[names[round(patch.get_y() + patch.get_height() / 2)]].append(patch.get_x() + patch.get_width())
        for name, ends in drawn.items():
            i = fit.parameters.index(name)
            np.testing.assert_allclose(sorted(ends), sorted([fit.effect_low_hz[k, i], fit.effect_high_hz[k, i]]),
                                       rtol=1e-12, atol=1e-15)
        shown = [fit.parameters.index(n) for n in names]
        effect = np.abs(fit.effect_high_hz[k] - fit.effect_low_hz[k])
        assert effect[shown[-1]] == effect.max()  # the largest on top
        assert "4 smaller effects not shown" in ax.get_title()


def test_the_fit_gives_the_exact_derivatives_of_the_frequencies(scenario):
    """Over +-1 % the frequencies are linear in each bearing axis's stiffness factor: the fitted slopes are the
    exact derivatives by automatic differentiation, times the nominal stiffness: to 1 %, or for the slopes near 0
    (a bearing's stiffness across a mode's motion) to 0.1 % of the mode's largest, the second-order terms left in
    the fit's residual (measured: 2e-4 of it)."""
    spec = parse_sweep_spec(SPEC.replace("count = 30", "count = 400").replace("0.7", "0.99").replace("1.3", "1.01"))
    result = sweep(Study(scenario.system), spec)
    fit = sweep_sensitivity(result, scenario.system)
    exact = sensitivities(scenario.system).frequency * scenario.system.stiffnesses[None]  # Hz per factor
    names = [f"stiffness of mount {m} ({a})" for m in scenario.system.mount_names for a in "uvw"]
    for k, j in enumerate(fit.modes):
        for i, name in enumerate(names):
            slope = fit.slope[k, fit.parameters.index(name)]
            assert slope == pytest.approx(exact[j].ravel()[i], rel=1e-2, abs=1e-3 * np.abs(exact[j]).max())


def test_a_shared_draw_is_one_parameter(scenario):
    spec = parse_sweep_spec(SPEC.replace("independent = true", 'mounts = ["1", "2"]\naxes = ["w"]'))
    result = sweep(Study(scenario.system), spec)
    values, parameters, units = swept_parameters(result.variants, scenario.system.mount_names)
    assert parameters == ("stiffness of mounts 1, 2 (w)",) and units == ("factor",)
    np.testing.assert_array_equal(values[:, 0], result.variants.stiffness_factor[:, 0, 2])
    fit = sweep_sensitivity(result, scenario.system)
    fig = plot_sweep_sensitivity(fit, scenario.system.modes)
    assert all(len(ax.patches) == 2 for ax in fig.axes if ax.get_visible())


@pytest.mark.slow  # 3 s on the 2-core machine
def test_sixdof_plot_redraws_a_sweep_and_a_folder(written, tmp_path, capsys):
    assert main(["plot", str(written / "sweep.h5"), "--out", str(tmp_path / "one")]) == 0
    assert sorted(p.name for p in (tmp_path / "one").glob("*.png")) == FIGURES
    for name in FIGURES:  # the same figures the sweep drew
        assert (tmp_path / "one" / name).read_bytes() == (written / name).read_bytes()
    with h5py.File(written.parent / "theirs.h5", "w") as f:  # not sixdof's: passed over in a folder
        f.attrs["format"] = "someone-else"
    assert main(["plot", str(written.parent), "--out", str(tmp_path / "all")]) == 0
    assert sorted(p.name for p in (tmp_path / "all" / written.name).glob("*.png")) == FIGURES


@pytest.mark.slow  # 2 s on the 2-core machine
def test_sixdof_plot_refuses_a_file_of_no_known_kind(tmp_path, capsys):
    theirs = tmp_path / "theirs.h5"
    with h5py.File(theirs, "w") as f:
        f.attrs["format"] = "someone-else"
    text = tmp_path / "notes.h5"
    text.write_text("not HDF5")
    empty = tmp_path / "empty"
    empty.mkdir()
    for path, found in ((theirs, "an HDF5 file with root attribute format = 'someone-else'"),
                        (text, "not an HDF5 file"), (empty, "a folder with no sixdof results file in it")):
        assert main(["plot", str(path)]) == 2
        err = capsys.readouterr().err
        assert err.startswith("sixdof: error: results: expected a sixdof results file: the results.h5 of")
        assert f"got {path}: {found}" in err, err
    assert list(tmp_path.rglob("*.png")) == []


@pytest.mark.slow  # the sweep it reads: 3 s on the 2-core machine
def test_each_sweep_figure_draws_into_the_given_figure_or_axes(run):
    # As tests/test_plot_api.py holds for the run's figures: a caller's figure (or axes) is drawn into and returned.
    from matplotlib.figure import Figure

    fit = sweep_sensitivity(run.sweep, run.system)
    for draw in (lambda fig: plot_sweep_frequencies(run.sweep, run.system.modes, fig=fig),
                 lambda fig: plot_sweep_peaks(run.sweep, fig=fig),
                 lambda fig: plot_sweep_sensitivity(fit, run.system.modes, fig=fig)):
        given = Figure()
        assert draw(given) is given and given.axes
    given = Figure()
    ax = given.add_subplot()
    assert plot_sweep_decoupling(run.sweep, run.system.modes, ax=ax) is given and len(ax.patches) > 0
