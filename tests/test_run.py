"""``sixdof run`` / ``run_scenario`` end to end: what is written, and that failures leave nothing behind."""


import re

import numpy as np
import pytest

from sixdof import InputError, ScenarioError, load_scenario, modal_analysis, parse_scenario, run_scenario
from sixdof.cli import EXIT_BAD_INPUT, main
from sixdof.io.store import load_tree
from sixdof.plots import figure_names
from sixdof.workflows import run as run_module
from sixdof.workflows.run import sampling_warnings
from tolerances import RTOL_FRF_CLOSED_FORM, RTOL_REPORTED_TRUNCATION, RTOL_STATICS

SCENARIO = """
name = "small"
description = "compressor on two inclined and two plain isolators"

[body]
mass = 300.0
inertia = [20.0, 30.0, 25.0]
dimensions = [0.8, 1.0, 0.6]

[[mounts]]
name = "a"
position = [-0.3, -0.4, -0.3]
stiffness = [1e5, 1e5, 4e5]
damping = [150.0, 150.0, 500.0]
axes = [[0.8, 0.0, 0.6], [0.0, 1.0, 0.0], [-0.6, 0.0, 0.8]]

[[mounts]]
name = "b"
position = [0.3, -0.4, -0.3]
stiffness = [1e5, 1e5, 4e5]
damping = [150.0, 150.0, 500.0]
axes = [[0.8, 0.0, -0.6], [0.0, 1.0, 0.0], [0.6, 0.0, 0.8]]

[[mounts]]
name = "c"
position = [0.3, 0.4, -0.3]
stiffness = [1.2e5, 1.2e5, 5e5]
damping = [100.0, 100.0, 300.0]

[[mounts]]
name = "d"
position = [-0.3, 0.4, -0.3]
stiffness = [1.2e5, 1.2e5, 5e5]
damping = [100.0, 100.0, 300.0]

[[loads]]
name = "hit"
point = [0.4, 0.5, 0.3]
force = [200.0, -300.0, 1000.0]
signal = { kind = "half_sine", start = 0.05, duration = 0.02 }

[simulation]
duration = 0.6
sample_rate_hz = 1000.0

[frf]
f_hz = [1.0, 100.0]
points = 50

[[frf.point]]
name = "drive"
load_point = [0.4, 0.5, 0.3]
load_direction = "z"
response_point = [0.4, 0.5, 0.3]
response_direction = "z"
quantity = "mobility"

[[frf.force_transmissibility]]
name = "to_floor"
load_point = [0.4, 0.5, 0.3]
load_direction = [0.0, 0.0, 1.0]

[[points]]
name = "top"
position = [0.4, 0.5, 0.3]
"""


@pytest.fixture(scope="module")
def scenario():
    return parse_scenario(SCENARIO, "small.toml")


@pytest.fixture(scope="module")
def outcome(scenario, tmp_path_factory):
    return run_scenario(scenario, tmp_path_factory.mktemp("out"), progress=False)


@pytest.mark.slow  # 2 s on the 2-core machine
def test_run_writes_results_figures_and_summary(outcome):
    computed, folder = outcome
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        [".sixdof-files", "results.h5", "summary.md", "report.html", *figure_names(computed)]
    )
    listed = (folder / ".sixdof-files").read_text().splitlines()
    assert listed == sorted(["results.h5", "summary.md", "report.html", *figure_names(computed)])
    assert not [p for p in folder.parent.iterdir() if p.name.startswith(".")]
    results = load_tree(folder / "results.h5")
    q = results.array("time/q")
    assert q.shape == (601, 6)
    assert results.array("time/superposition/q").shape == (601, 6)
    assert results.attrs["time/superposition"]["agreement_worst"] == pytest.approx(computed.agreement.worst)
    assert computed.agreement.ok
    assert results.array("statics/support").sum() == pytest.approx(300 * 9.80665, rel=RTOL_STATICS)
    assert results.array("frf/receptance").shape == (50, 6, 6)
    # The requested point FRF is the receptance seen through the point maps, times i w (mobility).
    H = results.array("frf/receptance")
    T = np.hstack([np.eye(3), -np.array([[0, -0.3, 0.5], [0.3, 0, -0.4], [-0.5, 0.4, 0]])])
    w = 2 * np.pi * results.array("frf/f_hz")
    expected = 1j * w * np.einsum("i,fij,j->f", T[2], H, T[2])
    np.testing.assert_allclose(results.array("frf/point/drive/values"), expected, rtol=RTOL_FRF_CLOSED_FORM)
    assert "frf/force_transmissibility/to_floor/total" in results.datasets
    summary = (folder / "summary.md").read_text()
    for text in ["## Natural frequencies", "## Kinetic energy distribution", "Peak mount forces",
                 "Direct solve vs modal superposition", "![mode_shapes](mode_shapes.png)"]:
        assert text in summary
    # A pulse has no steady state: its peaks are not said to include a switch-on transient.
    assert "Peaks over the whole run.\n" in summary and "Peaks over the run:\n" in summary
    assert "switch-on" not in summary


def test_unwritable_output_is_an_error_before_any_computing(scenario, tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setattr(run_module, "damping_ratios", lambda *a: pytest.fail("computed anyway"))
    with pytest.raises(InputError, match=r"--out: expected a folder where results can be written"):
        run_scenario(scenario, blocker / "out", progress=False)


@pytest.mark.slow  # 4 s each on the 2-core machine
@pytest.mark.parametrize("error", [KeyboardInterrupt, OSError])
def test_interrupted_run_keeps_the_previous_results_and_leaves_no_partial_output(outcome, scenario, monkeypatch, error):
    folder = outcome[1]
    before = {p.name: p.read_bytes() for p in folder.iterdir()}

    def interrupted(*args, **kwargs):
        raise error("disk full" if error is OSError else None)

    monkeypatch.setattr("sixdof.plots.drawer.InProcessDrawer.save", interrupted)
    with pytest.raises(error):
        run_scenario(scenario, folder.parent, progress=False)
    after = {p.name: p.read_bytes() for p in folder.iterdir()}
    assert after == before
    assert not [p for p in folder.parent.iterdir() if p.name.startswith(".")]


def test_sample_rate_too_low_is_warned_with_the_numbers(scenario):
    slow = parse_scenario(SCENARIO.replace("sample_rate_hz = 1000.0", "sample_rate_hz = 100.0"), "slow.toml")
    modes = modal_analysis(slow.system.M, slow.system.K)
    messages = sampling_warnings(slow, modes)
    top = modes.frequency_hz.max()
    assert any(f"100 Hz gives {100 / top:.1f} samples per period of the highest natural frequency ({top:.4g} Hz)" in m for m in messages)
    # The 20 ms half-sine carries energy up to about 50 Hz: 2 samples per period.
    assert any("half_sine pulse" in m and "2.0 samples per period" in m for m in messages)
    assert sampling_warnings(scenario, modal_analysis(scenario.system.M, scenario.system.K)) == []


@pytest.mark.long  # over 10 s on the 2-core machine
def test_cli_run_and_plot(tmp_path, capsys):
    path = tmp_path / "small.toml"
    path.write_text(SCENARIO.replace("duration = 0.6", "duration = 0.2"))
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "Direct solve vs modal superposition" in out and "ok" in out
    results = tmp_path / "out" / "small" / "results.h5"
    assert results.exists()
    assert main(["plot", str(results), "--out", str(tmp_path / "figures")]) == 0
    assert (tmp_path / "figures" / "mode_shapes.png").exists()
    capsys.readouterr()
    blocker = tmp_path / "file"  # --out an existing file: bad input, as for run, not a failed write
    blocker.write_text("mine")
    for out in (blocker, blocker / "figures"):
        assert main(["plot", str(results), "--out", str(out)]) == 2
        assert capsys.readouterr().err == (f"sixdof: error: --out: expected a folder where results can be written, got "
                                           f"'{out} (Not a directory)'\n")
    assert blocker.read_text() == "mine"


def test_cli_bad_input_writes_nothing(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(SCENARIO.replace("duration = 0.6", "duration = -1.0"))
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "simulation.duration" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow  # 2 s on the 2-core machine
def test_truncated_superposition_reports_its_error_and_warns(tmp_path):
    from sixdof.workflows.time_response import AgreementWarning

    text = SCENARIO + "\n[superposition]\nn_modes = 3\n"
    scenario = parse_scenario(text.replace("duration = 0.6", "duration = 0.2"), "trunc.toml")
    with pytest.warns(AgreementWarning, match=r"direct and modal superposition disagree: worst DOF"):
        results, folder = run_scenario(scenario, tmp_path, progress=False)
    assert results.superposition.superposition.modes_kept == (0, 1, 2)
    assert results.superposition.superposition.truncation.worst > 1e-6
    # Against the direct solve, the truncated superposition's displacements are off by what its truncation says
    # (its accelerations by more: the worst over q, q' and q'' is in q'').
    assert results.agreement.worst_quantity == "qdd" and results.agreement.worst > max(results.agreement.per_dof)
    assert max(results.agreement.per_dof) == pytest.approx(results.superposition.superposition.truncation.worst, rel=RTOL_REPORTED_TRUNCATION)
    assert "Truncated to modes 1, 2, 3" in (folder / "summary.md").read_text()


@pytest.mark.long  # over 10 s on the 2-core machine
def test_output_table_leaves_derived_quantities_out_and_reading_derives_them_again(outcome, tmp_path):
    import dataclasses

    from sixdof import load_results

    folder = outcome[1]

    lean = parse_scenario(SCENARIO.replace("[simulation]", '[output]\nderived = ["mount_check"]\n\n[simulation]'))
    assert lean.output.omitted == ("mount_forces",) and parse_scenario(SCENARIO).output.derived == (
        "mount_forces", "mount_check")
    written, written_folder = run_scenario(lean, tmp_path, progress=False)
    tree = load_tree(written_folder / "results.h5")
    assert "time/mount_force" not in tree.datasets and "time/mount_force_elastic" not in tree.datasets
    assert "time/mount_check/compression" in tree.datasets and tree.attrs[""]["derived_omitted"] == ("mount_forces",)
    assert (written_folder / "results.h5").stat().st_size < 0.75 * (folder / "results.h5").stat().st_size
    # Read back, the file gives the same mount forces as the run that stored them: derived again, bit for bit.
    full, back = load_results(folder / "results.h5"), load_results(written_folder / "results.h5")
    for field in dataclasses.fields(full.mount_forces):
        np.testing.assert_array_equal(getattr(back.mount_forces, field.name), getattr(full.mount_forces, field.name))
    # Nothing derived left out: the mount check too is derived on reading, equal to the stored one.
    none, none_folder = run_scenario(parse_scenario(SCENARIO.replace("[simulation]", "[output]\nderived = []\n\n[simulation]")),
                        tmp_path / "none", progress=False)
    back = load_results(none_folder / "results.h5")
    assert "time/mount_check" not in load_tree(none_folder / "results.h5").attrs
    for field in dataclasses.fields(full.mount_check):
        a, b = getattr(back.mount_check, field.name), getattr(full.mount_check, field.name)
        if isinstance(b, np.ndarray):
            np.testing.assert_array_equal(a, b)
        else:
            assert a == b, field.name


@pytest.mark.parametrize(("table", "message"), [
    ('derived = ["mount_force"]', r"output\.derived\[0\]: expected 'mount_forces' or 'mount_check', got 'mount_force'"),
    ('derived = "all"', r"output\.derived: expected a list of names from mount_forces, mount_check"),
    ("keep = []", r"output"),
    ('animate_modes = "yes"', r"output\.animate_modes: expected true or false, got 'yes'"),
    ('formats = "png"', r"output\.formats: expected a non-empty list of formats from 'png', 'svg', 'pdf', .*got 'png'"),
    ("formats = []", r"output\.formats: expected a non-empty list of formats .*got \[\]"),
    ('formats = ["png", "jpg"]', r"output\.formats\[1\]: expected 'png', 'svg' or 'pdf', got 'jpg'"),
    ("dpi = 72.5", r"output\.dpi: expected a whole number of dots per inch from 50 to 600 \(default 150\), got 72\.5"),
    ("dpi = 10", r"output\.dpi: expected a whole number of dots per inch from 50 to 600 \(default 150\), got 10"),
    ('dpi = "300"', r"output\.dpi: expected a whole number of dots per inch .*got '300'"),
])
def test_output_table_errors_name_the_field(table, message):
    with pytest.raises(InputError, match=message):
        parse_scenario(SCENARIO.replace("[simulation]", f"[output]\n{table}\n\n[simulation]"))


def test_bad_formats_or_dpi_are_refused_naming_the_file_before_computing(tmp_path, capsys):
    file = tmp_path / "bad.toml"
    file.write_text(SCENARIO.replace("[simulation]", '[output]\nformats = ["png", "tiff"]\n\n[simulation]'))
    with pytest.raises(ScenarioError, match=rf"^{re.escape(str(file))}: output\.formats\[1\]: expected 'png', "):
        load_scenario(file)
    file.write_text(SCENARIO.replace("[simulation]", "[output]\ndpi = 0\n\n[simulation]"))
    assert main(["run", str(file), "--out", str(tmp_path / "out"), "--quiet"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert f"{file}: output.dpi: expected a whole number of dots per inch from 50 to 600" in err, err
    assert not (tmp_path / "out").exists()  # refused before anything was computed or written


@pytest.mark.slow  # 2 s on the 2-core machine
def test_formats_write_each_figure_in_each_format_at_the_dpi(tmp_path):
    from PIL import Image

    modal = SCENARIO.split("[[loads]]")[0] + '\n[output]\nformats = ["png", "svg", "pdf"]\ndpi = 60\n'
    scenario = parse_scenario(modal, "modal.toml")
    assert scenario.output.formats == ("png", "svg", "pdf") and scenario.output.dpi == 60
    assert parse_scenario(SCENARIO).output.formats == ("png",) and parse_scenario(SCENARIO).output.dpi == 150
    results, folder = run_scenario(scenario, tmp_path, progress=False)
    figures = ("mode_shapes", "ke_distribution")
    for stem in figures:
        assert (folder / f"{stem}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert b"<svg" in (folder / f"{stem}.svg").read_bytes()[:1000]
        assert (folder / f"{stem}.pdf").read_bytes()[:5] == b"%PDF-"
    # The PNG is the figure's size in inches times the dpi asked for.
    from sixdof.plots import plot_ke_distribution

    inches = plot_ke_distribution(results.modes, name=results.name).get_size_inches()
    with Image.open(folder / "ke_distribution.png") as image:
        assert image.size == tuple(round(v * 60) for v in inches)
        assert image.info["dpi"] == pytest.approx((60, 60), abs=0.01)
    # The summary shows each figure once (its PNG); every file is sixdof's (replaced by the next run).
    summary = (folder / "summary.md").read_text()
    assert "(mode_shapes.png)" in summary and "mode_shapes.svg" not in summary and "mode_shapes.pdf" not in summary
    assert {f"{stem}.{kind}" for stem in figures for kind in ("png", "svg", "pdf")} <= set(
        (folder / ".sixdof-files").read_text().splitlines())
    # `sixdof plot` draws the file's figures again as the run did: the stored scenario's formats and dpi.
    assert main(["plot", str(folder / "results.h5"), "--out", str(tmp_path / "again")]) == 0
    assert {p.name for p in (tmp_path / "again").iterdir()} >= {f"{s}.{k}" for s in figures for k in ("png", "svg", "pdf")}
    with Image.open(tmp_path / "again" / "ke_distribution.png") as image:
        assert image.size == tuple(round(v * 60) for v in inches)


def test_stored_figure_settings_read_the_scenario_text_else_the_defaults():
    from sixdof.io.settings import stored_figure_settings

    text = SCENARIO.replace("[simulation]", '[output]\nformats = ["pdf"]\ndpi = 300\n\n[simulation]')
    assert stored_figure_settings({"scenario_text": text}) == (("pdf",), 300)
    assert stored_figure_settings({"scenario_text": SCENARIO}) == (("png",), 150)
    assert stored_figure_settings({}) == (("png",), 150)
    with pytest.raises(InputError, match=r"output\.dpi: expected a whole number of dots per inch"):
        stored_figure_settings({"scenario_text": text.replace("dpi = 300", "dpi = 3")})


def test_default_dpi_is_150(tmp_path):
    from PIL import Image

    from sixdof import plots

    assert plots.DPI == 150
    results, folder = run_scenario(parse_scenario(SCENARIO.split("[[loads]]")[0], "modal.toml"), tmp_path,
                                   progress=False)
    inches = plots.plot_ke_distribution(results.modes, name=results.name).get_size_inches()
    assert sorted(p.suffix for p in folder.glob("ke_distribution.*")) == [".png"]
    with Image.open(folder / "ke_distribution.png") as image:
        assert image.size == tuple(round(v * 150) for v in inches)


@pytest.mark.slow  # 4 s on the 2-core machine
def test_animate_modes_writes_one_looping_gif_per_mode(tmp_path, monkeypatch):
    from PIL import Image, ImageSequence

    from sixdof.plots import modes as mode_plots

    monkeypatch.setattr(mode_plots, "ANIMATION_FRAMES", 4)  # a quarter period a frame: rest, +shape, rest, -shape
    modal = SCENARIO.split("[[loads]]")[0] + "\n[output]\nanimate_modes = true\n"
    scenario = parse_scenario(modal, "modal.toml")
    assert scenario.output.animate_modes and not parse_scenario(SCENARIO).output.animate_modes
    _, folder = run_scenario(scenario, tmp_path, progress=False)
    assert sorted(p.name for p in folder.glob("*.gif")) == [f"mode_{j}.gif" for j in range(1, 7)]
    for j in range(1, 7):
        with Image.open(folder / f"mode_{j}.gif") as gif:
            assert gif.n_frames == 4 and gif.info["loop"] == 0  # for ever
            assert gif.info["duration"] == pytest.approx(1000 / mode_plots.ANIMATION_FPS, abs=10)
            rest, up, _, down = (np.asarray(frame.convert("RGB"), dtype=int) for frame in ImageSequence.Iterator(gif))
        # The body moves one way, then the other.
        assert np.abs(up - rest).sum() > 0 and np.abs(down - rest).sum() > 0 and np.abs(up - down).sum() > 0
    # Written by sixdof as the rest (replaced by the next run, kept by none of the user's): off by default, see
    # test_run_writes_results_figures_and_summary.
    assert {f"mode_{j}.gif" for j in range(1, 7)} <= set((folder / ".sixdof-files").read_text().splitlines())
    # Shown in the report (embedded, with a sentence) and linked from the summary.
    page = (folder / "report.html").read_text()
    for j in range(1, 7):
        assert f'<figure id="mode_{j}"><img src="data:image/gif;base64,' in page
        assert f"Mode {j} oscillating through one period" in page
        assert f"![mode_{j}](mode_{j}.gif)" in (folder / "summary.md").read_text()
