"""Export for test and correlation tools (issue 19, point 5): UFF58 read back with pyuff, CSV read back with
the csv module, both against the results file; a file of the wrong kind refused."""

from __future__ import annotations

import csv
import os
import warnings

import numpy as np
import pytest

from sixdof import InputError, load_results, parse_scenario, run_scenario
from sixdof.cli import main
from sixdof.io.store import load_tree
from test_run import SCENARIO

#: Binary UFF58 holds doubles: the even time axis comes back as min + k * increment (1 ulp off), the rest exactly.
RTOL_TIME_AXIS = 1e-14


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    results, folder = run_scenario(parse_scenario(SCENARIO.replace("duration = 0.6", "duration = 0.2")),
                           tmp_path_factory.mktemp("run"), progress=False)
    return folder / "results.h5"


#: The small run shaken by its base instead of struck: a 1 g half-sine acceleration of the ground, inclined in y-z.
GROUND = """[ground]
quantity = "acceleration"
direction = [0.0, 0.6, 0.8]
scale = 9.81
signal = { kind = "half_sine", start = 0.05, duration = 0.02 }

"""
#: The ground's channels: the results file's dataset, its UFF58 ordinate type and its CSV column letter.
GROUND_CHANNELS = (("time/ground_displacement", 8, "d"), ("time/ground_velocity", 11, "v"),
                   ("time/ground_acceleration", 12, "a"))


@pytest.fixture(scope="module")
def shaken(tmp_path_factory):
    text = (SCENARIO.split("[[loads]]")[0] + GROUND + "[simulation]"
            + SCENARIO.split("[simulation]")[1].replace("duration = 0.6", "duration = 0.2"))
    results, folder = run_scenario(parse_scenario(text), tmp_path_factory.mktemp("shaken"), progress=False)
    return folder / "results.h5"


def function_sets(path) -> list[dict]:
    """The datasets 58 of a UFF file, read back with pyuff."""
    import pyuff

    uff = pyuff.UFF(str(path))
    with warnings.catch_warnings():  # pyuff leaves a handle per binary dataset to the garbage collector
        warnings.simplefilter("ignore", ResourceWarning)
        return [data for data in (uff.read_sets(k) for k in range(uff.get_n_sets())) if data["type"] == 58]


@pytest.mark.slow  # 3 s on the 2-core machine
def test_uff58_carries_every_history_and_receptance_with_its_dof_and_units(results, tmp_path, capsys):
    pytest.importorskip("pyuff")
    assert main(["export", str(results), "--out", str(tmp_path)]) == 0
    assert "small.uff" in capsys.readouterr().out
    run = load_results(results)
    sets = function_sets(tmp_path / "small_export" / "small.uff")
    first = 6 + 3 * len(run.points) + 3 * len(run.mount_forces.names)  # then the applied loads, the input
    assert len(sets) == first + 6 + 36 + 3 + 3 * 4 + 1  # and the force transmissibility and the point FRF
    for k in range(6):  # the CG's displacement: node 1, direction k+1
        data = sets[k]
        assert (data["func_type"], data["rsp_node"], data["rsp_dir"], data["ordinate_spec_data_type"]) == (1, 1, k + 1, 8)
        assert data["ordinate_axis_units_lab"].strip() == ("m" if k < 3 else "rad")
        np.testing.assert_allclose(data["x"], run.response.t, rtol=RTOL_TIME_AXIS, atol=1e-15)
        np.testing.assert_array_equal(data["data"], run.response.q[:, k])
    top = sets[6 + 2]  # the first point's z acceleration: node 2, direction 3, ordinate type 12
    assert (top["rsp_node"], top["rsp_dir"], top["ordinate_spec_data_type"]) == (2, 3, 12)
    np.testing.assert_array_equal(top["data"], run.points["top"].acceleration[:, 2])
    Q = load_tree(results)["time/Q"]
    assert np.abs(Q.data).max() > 100.0  # the hit is there to be exported
    for j in range(6):  # the applied loads: excitation force at node 1, direction j+1, its own DOF as reference
        data = sets[first + j]
        assert (data["func_type"], data["rsp_node"], data["rsp_dir"], data["ref_node"], data["ref_dir"],
                data["ordinate_spec_data_type"]) == (1, 1, j + 1, 1, j + 1, 13)
        assert data["ordinate_axis_units_lab"].strip() == ("N" if j < 3 else "N m") == dict(Q.units.factors)["load"][j]
        np.testing.assert_array_equal(data["data"], Q.data[:, j])
    frf = run.frf.direct
    for data in sets[first + 6:first + 6 + 36]:  # receptance: response over reference (node 1 both)
        i, j = data["rsp_dir"] - 1, data["ref_dir"] - 1
        assert (data["func_type"], data["ordinate_spec_data_type"], data["orddenom_spec_data_type"]) == (4, 8, 13)
        assert data["orddenom_axis_units_lab"].strip() == ("N" if j < 3 else "N m")
        np.testing.assert_array_equal(data["x"], frf.f_hz)  # an uneven (log) grid, every digit kept
        np.testing.assert_array_equal(data["data"], frf.H[:, i, j])


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_uff58_unit_exponents_follow_the_unit_labels(results):
    # Records 8-11: a test tool that reads the exponents (length, force) rather than the label gets the same unit.
    pytest.importorskip("pyuff")
    from sixdof.io.exchange import uff58_sets

    expected = {"m": (1, 0), "m/s": (1, 0), "m/s^2": (1, 0), "rad": (0, 0), "N": (0, 1), "N m": (1, 1), "s": (0, 0),
                "Hz": (0, 0), "NONE": (0, 0)}
    for data in uff58_sets(load_results(results))[2:]:  # after the header and the nodes
        for axis in ("abscissa", "ordinate", "orddenom"):
            label = data[f"{axis}_axis_units_lab"]
            assert (data[f"{axis}_len_unit_exp"], data[f"{axis}_force_unit_exp"]) == expected[label], (data["id1"], axis)


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_uff58_keeps_the_node_and_direction_of_a_point_with_a_long_name(results, tmp_path):
    # Record 6 has 10 characters for an entity name: a longer one shifted the node and direction out of their
    # columns (read back as node 0). The whole name stays in the ID line.
    import dataclasses

    pyuff = pytest.importorskip("pyuff")
    from sixdof.io.exchange import uff58_sets

    run = load_results(results)
    run = dataclasses.replace(run, points={"circuit_board_corner": run.points["top"]})
    path = tmp_path / "long.uff"
    with warnings.catch_warnings():  # pyuff leaves a handle per binary dataset to the garbage collector
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(uff58_sets(run), mode="add")
    sets = function_sets(path)
    for axis in range(3):
        data = sets[6 + axis]
        assert (data["rsp_node"], data["rsp_dir"], data["rsp_ent_name"].strip()) == (2, axis + 1, "circuit_bo")
        assert data["id1"].strip() == f"small: circuit_board_corner acceleration {'xyz'[axis]}"
        np.testing.assert_array_equal(data["data"], run.points["circuit_board_corner"].acceleration[:, axis])


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_csv_columns_name_their_quantity_and_unit_and_hold_the_results(results, tmp_path):
    from sixdof.io.exchange import export

    files = export(results, tmp_path, "csv")
    assert [f.name for f in files] == ["small_time.csv", "small_frf.csv"]
    run = load_results(results)
    with files[0].open() as stream:
        rows = list(csv.reader(stream))
    assert rows[0][:3] == ["t [s]", "x [m]", "y [m]"] and rows[0][4] == "rx [rad]" and rows[0][7] == "top ax [m/s^2]"
    table = np.array(rows[1:], dtype=float)
    np.testing.assert_array_equal(table[:, 0], run.response.t)  # CSV keeps every digit (repr)
    np.testing.assert_array_equal(table[:, 1:7], run.response.q)
    loads = rows[0].index("Fx [N]")  # the input: the applied loads, after the points and the mounts
    assert loads == 1 + 6 + 3 * len(run.points) + 3 * len(run.mount_forces.names) and rows[0][loads + 3:] == ["Mx [N m]", "My [N m]", "Mz [N m]"]
    np.testing.assert_array_equal(table[:, loads:], load_tree(results).array("time/Q"))
    with files[1].open() as stream:
        rows = list(csv.reader(stream))
    assert rows[0][1:3] == ["Re x/Fx [m/N]", "Im x/Fx [m/N]"] and "Re rx/Mx [rad/(N m)]" in rows[0]
    table = np.array(rows[1:], dtype=float)
    column = rows[0].index("Re z/My [m/(N m)]")
    np.testing.assert_array_equal(table[:, column] + 1j * table[:, column + 1], run.frf.direct.H[:, 2, 4])


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_a_format_or_file_of_the_wrong_kind_is_refused(results, tmp_path):
    from sixdof.io.exchange import export

    with pytest.raises(InputError, match=r"--format: expected uff58 or csv, got 'uff'"):
        export(results, tmp_path, "uff")
    bad = tmp_path / "not.h5"
    bad.write_text("no")
    with pytest.raises(InputError, match=r"results: expected an HDF5 results file written by sixdof"):
        export(bad, tmp_path, "csv")


@pytest.mark.slow  # 2 s on the 2-core machine
def test_each_format_replaces_its_own_files_and_keeps_the_other_s(results, tmp_path, capsys):
    """UFF58 then CSV into one folder: both kept; CSV again from a run with FRFs only replaces the CSVs (the
    time history's, no longer in the results, goes) and leaves the UFF58 file and the user's file alone."""
    pytest.importorskip("pyuff")
    folder = tmp_path / "small_export"
    assert main(["export", str(results), "--out", str(tmp_path)]) == 0
    uff = (folder / "small.uff").read_bytes()
    (folder / "notes.txt").write_text("mine")
    assert main(["export", str(results), "--format", "csv", "--out", str(tmp_path)]) == 0
    assert "kept them: notes.txt" in capsys.readouterr().err
    assert sorted(os.listdir(folder)) == [".sixdof-files", "notes.txt", "small.uff", "small_frf.csv", "small_modes.uff",
                                          "small_time.csv"]
    assert (folder / "small.uff").read_bytes() == uff
    assert (folder / ".sixdof-files").read_text().split() == ["small.uff", "small_frf.csv", "small_modes.uff",
                                                              "small_time.csv"]
    frf_only = SCENARIO.split("[simulation]")[0] + "[frf]" + SCENARIO.split("[frf]")[1].replace("points = 50",
                                                                                                 "points = 30")
    frf_only, frf_folder = run_scenario(parse_scenario(frf_only), tmp_path / "frf_only", progress=False)
    assert main(["export", str(frf_folder / "results.h5"), "--format", "csv", "--out", str(tmp_path)]) == 0
    assert sorted(os.listdir(folder)) == [".sixdof-files", "notes.txt", "small.uff", "small_frf.csv", "small_modes.uff"]
    assert (folder / "small.uff").read_bytes() == uff and (folder / "notes.txt").read_text() == "mine"
    with (folder / "small_frf.csv").open() as stream:
        assert len(list(csv.reader(stream))) == 1 + 30  # the header and the new run's frequencies


@pytest.mark.slow  # 4 s on the 2-core machine
def test_uff58_of_a_base_excited_run_carries_the_ground_motion_as_input_channels(shaken, tmp_path):
    """The ground's displacement, velocity and acceleration per axis after the body's histories: node 0, entity
    GROUND, its own DOF as reference, each equal to the results file's dataset and labelled with its units."""
    pytest.importorskip("pyuff")
    assert main(["export", str(shaken), "--out", str(tmp_path)]) == 0
    tree, run = load_tree(shaken), load_results(shaken)
    sets = function_sets(tmp_path / "small_export" / "small.uff")
    first = 6 + 3 * len(run.points) + 3 * len(run.mount_forces.names)
    assert len(sets) == first + 9 + 36 + 3 + 3 * 4 + 1
    assert np.abs(tree.array("time/ground_acceleration")).max() > 1.0  # the shake is there to be exported
    for n, (path, data_type, _) in enumerate(GROUND_CHANNELS):
        for axis in range(3):
            data = sets[first + 3 * n + axis]
            assert (data["func_type"], data["rsp_node"], data["rsp_dir"], data["ref_node"], data["ref_dir"],
                    data["ordinate_spec_data_type"]) == (1, 0, axis + 1, 0, axis + 1, data_type)
            assert data["rsp_ent_name"].strip() == data["ref_ent_name"].strip() == "GROUND"
            assert data["ordinate_axis_units_lab"].strip() == tree[path].units
            assert data["id1"].strip() == f"small: ground {path.split('_')[-1]} {'xyz'[axis]} (input)"
            np.testing.assert_allclose(data["x"], tree.array("time/t"), rtol=RTOL_TIME_AXIS, atol=1e-15)
            np.testing.assert_array_equal(data["data"], tree.array(path)[:, axis])
            # Records 8-11 read back: the ground's displacement, velocity and acceleration are all of length 1.
            assert (data["ordinate_len_unit_exp"], data["ordinate_force_unit_exp"]) == (1, 0)
    assert sets[first + 9]["func_type"] == 4  # the receptances follow
    assert [sets[k]["id1"].strip() for k in (0, 3, 6)] == ["small: CG x displacement (absolute)",
                                                           "small: CG rx displacement (absolute)",
                                                           "small: top acceleration x (absolute)"]


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_csv_of_a_base_excited_run_carries_the_ground_motion_after_the_body_s_columns(shaken, tmp_path):
    from sixdof.io.exchange import export

    files = export(shaken, tmp_path, "csv")
    tree = load_tree(shaken)
    with files[0].open() as stream:
        rows = list(csv.reader(stream))
    table = np.array(rows[1:], dtype=float)
    first = 1 + 6 + 3 + 3 * 4  # t, the CG, the point, the mounts
    for n, (path, _, letter) in enumerate(GROUND_CHANNELS):
        columns = slice(first + 3 * n, first + 3 * n + 3)
        assert rows[0][columns] == [f"ground {letter}{axis} [{tree[path].units}]" for axis in "xyz"]
        np.testing.assert_array_equal(table[:, columns], tree.array(path))
    assert len(rows[0]) == first + 9
    assert rows[0][first + 6:] == ["ground ax [m/s^2]", "ground ay [m/s^2]", "ground az [m/s^2]"]
    # With the ground moving, the body's channels say they are absolute (as stored: q, not q_relative).
    assert rows[0][1:first] == [*(f"{d} (absolute) [{u}]" for d, u in zip(("x", "y", "z", "rx", "ry", "rz"),
                                                                          ("m",) * 3 + ("rad",) * 3)),
                                *(f"top a{a} (absolute) [m/s^2]" for a in "xyz"),
                                *(f"mount {m} F{a} [N]" for m in "abcd" for a in "xyz")]
    np.testing.assert_array_equal(table[:, 1:7], tree.array("time/q"))


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_csv_export_read_back_as_test_data_gives_the_run_s_data_exactly(results, tmp_path):
    """The loads' generalized force at the CG are the references, the points' accelerations the responses."""
    from sixdof import load_test
    from sixdof.io.exchange import export

    files = export(results, tmp_path, "csv")
    run = load_results(results)
    test = load_test(files[0], parse_scenario(SCENARIO, "small.toml"))
    assert (test.kind, test.quantity) == ("time", "acceleration")
    np.testing.assert_array_equal(test.t, run.response.t)
    np.testing.assert_array_equal(test.responses, run.points["top"].acceleration)
    np.testing.assert_array_equal(test.inputs, run.response.Q)
    assert test.out_labels == ("top ax", "top ay", "top az") and test.ref_labels == ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
    np.testing.assert_array_equal(test.out_positions, [[0.4, 0.5, 0.3]] * 3)
    np.testing.assert_array_equal(test.ref_rotation, [False] * 3 + [True] * 3)
    np.testing.assert_array_equal(test.load_columns(), np.eye(6))  # the generalized force itself
    assert test.sample_rate_hz == pytest.approx(1000.0, rel=1e-12)


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_modes_are_exported_as_uff55_at_the_points_with_uff15_geometry(results, tmp_path):
    pyuff = pytest.importorskip("pyuff")
    from sixdof.model.kinematics import point_map
    from tolerances import RTOL_UFF_ASCII

    assert main(["export", str(results), "--out", str(tmp_path)]) == 0
    run = load_results(results)
    uff = pyuff.UFF(str(tmp_path / "small_export" / "small_modes.uff"))
    sets = [uff.read_sets(k) for k in range(uff.get_n_sets())]
    assert [s["type"] for s in sets] == [15] + [55] * 6
    assert list(sets[0]["node_nums"]) == [2]  # the point, numbered as in the UFF58 file
    np.testing.assert_allclose([sets[0][c][0] for c in "xyz"], [0.4, 0.5, 0.3], rtol=RTOL_UFF_ASCII)
    expected = point_map([0.4, 0.5, 0.3]) @ run.modes.shapes  # (3, 6): the point's translations per mode
    for j, data in enumerate(sets[1:]):
        assert (data["analysis_type"], data["data_ch"], data["spec_data_type"], data["mode_n"]) == (2, 2, 8, j + 1)
        assert data["freq"] == pytest.approx(run.modes.frequency_hz[j], rel=RTOL_UFF_ASCII)
        shape = np.array([data["r1"][0], data["r2"][0], data["r3"][0]])
        np.testing.assert_allclose(shape, expected[:, j], rtol=0, atol=RTOL_UFF_ASCII * np.abs(expected[:, j]).max())


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_modes_go_to_the_test_nodes_in_the_test_frame(results):
    """With [test.nodes], origin and axes: the shapes at origin + p @ axes, turned into the test frame."""
    import dataclasses

    pytest.importorskip("pyuff")
    from sixdof.io.exchange import modal_sets
    from sixdof.model.kinematics import point_map

    axes = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    text = SCENARIO + """
[test]
origin = [0.1, 0.0, -0.2]
axes = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]

[test.nodes]
7 = [0.25, -0.4, 0.3]
3 = [0.0, 0.5, -0.125]
"""
    run = load_results(results)
    sets = modal_sets(dataclasses.replace(run, provenance={"scenario_text": text}))
    assert list(sets[0]["node_nums"]) == [3, 7]
    np.testing.assert_array_equal(sets[0]["x"], [0.0, 0.25])  # the lab's coordinates, as given
    body = np.array([[-0.4, 0.0, -0.325], [0.5, 0.25, 0.1]])  # origin + p @ axes, by hand
    for j, data in enumerate(sets[1:]):
        for n in range(2):
            expected = axes @ (point_map(body[n]) @ run.modes.shapes[:, j])
            np.testing.assert_allclose([data["r1"][n], data["r2"][n], data["r3"][n]], expected, rtol=1e-12,
                                       atol=1e-15)
