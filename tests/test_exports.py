"""Exports carry what users asked for (issue 49, item 5): the mounts' forces, the points' motions, the [frf]
point FRFs and transmissibilities in UFF58 and CSV, read back with pyuff, the csv module and ``load_test`` and
compared with the results in memory, value for value, with their nodes, directions and units; the channels
checked against each other too (a point FRF against the receptance it is made of, a force transmissibility's
resultant against its mounts'); the parts chosen with ``--what``, a bad choice refused in one line."""

from __future__ import annotations

import csv
import warnings

import numpy as np
import pytest

from sixdof import InputError, load_results, load_test, parse_scenario, run_scenario
from sixdof.cli import main
from sixdof.model.kinematics import point_map
from test_run import SCENARIO
from tolerances import RTOL_UFF_ASCII

#: Requests beside the small run's "drive" mobility and "to_floor" force transmissibility: an accelerance along no
#: axis at a place that is no point or mount (a node of its own), a rotation per moment (rx at the CG per Mx at
#: the top: the receptance's own entry), and a ground transmissibility along an inclined direction.
EXTRAS = """[[frf.point]]
name = "cross"
load_point = [0.4, 0.5, 0.3]
load_direction = "z"
response_point = [-0.2, 0.1, 0.3]
response_direction = [1.0, 1.0, 0.0]
quantity = "accelerance"

[[frf.point]]
name = "turn"
load_point = [0.4, 0.5, 0.3]
load_direction = "rx"
response_point = [0.0, 0.0, 0.0]
response_direction = "rx"

[[frf.ground_transmissibility]]
name = "base"
ground_direction = [0.0, 0.6, 0.8]
response_point = [0.4, 0.5, 0.3]

[[points]]"""
TEXT = SCENARIO.replace("duration = 0.6", "duration = 0.2").replace("[[points]]", EXTRAS)
MOUNTS = ("a", "b", "c", "d")
#: Node numbers: 1 the CG, 2 the point "top", 3-6 the mounts, 7 the place of "cross"'s response.
TOP, MOUNT_NODES, CROSS = 2, {"a": 3, "b": 4, "c": 5, "d": 6}, 7
POSITIONS = {1: (0.0, 0.0, 0.0), 2: (0.4, 0.5, 0.3), 3: (-0.3, -0.4, -0.3), 4: (0.3, -0.4, -0.3),
             5: (0.3, 0.4, -0.3), 6: (-0.3, 0.4, -0.3), 7: (-0.2, 0.1, 0.3)}
#: The unit exponents (length, force) of records 8-11, by unit label.
EXPONENTS = {"m": (1, 0), "m/s": (1, 0), "m/s^2": (1, 0), "rad": (0, 0), "N": (0, 1), "N m": (1, 1), "NONE": (0, 0),
             "s": (0, 0), "Hz": (0, 0)}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    _, folder = run_scenario(parse_scenario(TEXT, "small.toml"), tmp_path_factory.mktemp("run"), progress=False)
    return folder / "results.h5"


@pytest.fixture(scope="module")
def run(results):
    return load_results(results)


@pytest.fixture(scope="module")
def uff(results, tmp_path_factory):
    """Every dataset of the default UFF58 export, read back with pyuff."""
    pyuff = pytest.importorskip("pyuff")
    out = tmp_path_factory.mktemp("uff")
    assert main(["export", str(results), "--out", str(out)]) == 0
    return read_uff(pyuff, out / "small_export" / "small.uff")


def read_uff(pyuff, path) -> list[dict]:
    uff = pyuff.UFF(str(path))
    with warnings.catch_warnings():  # pyuff leaves a handle per binary dataset to the garbage collector
        warnings.simplefilter("ignore", ResourceWarning)
        return [uff.read_sets(k) for k in range(uff.get_n_sets())]


def by_id(sets: list[dict]) -> dict[str, dict]:
    """The datasets 58 by their ID line 1 (after the run's name)."""
    return {data["id1"].strip().removeprefix("small: "): data for data in sets if data["type"] == 58}


def dof(data: dict, side: str) -> tuple[int, int, str]:
    return data[f"{side}_node"], data[f"{side}_dir"], data[f"{side}_ent_name"].strip()


def units(data: dict, axis: str) -> tuple[int, str, int, int]:
    """An axis's specific data type, unit label, and that the label's exponents are UFF's for it."""
    label = data[f"{axis}_axis_units_lab"].strip()
    assert (data[f"{axis}_len_unit_exp"], data[f"{axis}_force_unit_exp"]) == EXPONENTS[label], (data["id1"], axis)
    return data[f"{axis}_spec_data_type"], label


def read_csv(path) -> tuple[list[str], np.ndarray]:
    with path.open(newline="") as stream:
        rows = list(csv.reader(stream))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.slow  # 3 s on the 2-core machine
def test_the_header_numbers_the_nodes_and_dataset_15_places_them(uff):
    assert [data["type"] for data in uff[:2]] == [151, 15]
    assert uff[0]["description"].strip() == "nodes: 0 ground, 1 CG, 2 point, 3-6 mounts, 7 frf place"
    nodes = uff[1]
    assert list(nodes["node_nums"]) == list(POSITIONS)
    positions = np.column_stack([nodes["x"], nodes["y"], nodes["z"]])
    np.testing.assert_allclose(positions, list(POSITIONS.values()), rtol=RTOL_UFF_ASCII, atol=1e-12)
    assert not np.any(nodes["def_cs"]) and not np.any(nodes["disp_cs"])  # body axes, no system of their own


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
def test_every_id_line_fits_uff58_s_80_characters(run):
    # A longer one is cut (pyuff writes 80): the ID lines say which request and channel a dataset is.
    from sixdof.io.exchange import uff58_sets

    sets = [data for data in uff58_sets(run) if data["type"] == 58]
    assert len(sets) == 6 + 3 + 12 + 6 + 36 + 15 + 3 + 3
    assert max(len(data.get(line, "")) for data in sets for line in ("id1", "id2")) <= 80
    assert len({data["id1"] for data in sets}) == len(sets)  # and no two alike


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
def test_mount_forces_are_reaction_force_responses_at_the_mounts_nodes(uff, run):
    sets, forces = by_id(uff), run.mount_forces
    assert forces.names == MOUNTS and np.abs(forces.total).max() > 10.0  # the hit loads the mounts
    total = np.zeros_like(forces.foundation_force)
    for m, name in enumerate(MOUNTS):
        for k, axis in enumerate("xyz"):
            data = sets[f"mount {name} force {axis}"]
            assert (data["func_type"], dof(data, "rsp"), dof(data, "ref")) == (1, (MOUNT_NODES[name], k + 1, name),
                                                                              (0, 0, "NONE"))
            assert units(data, "ordinate") == (9, "N") and data["ord_data_type"] == 4  # float64
            np.testing.assert_array_equal(data["data"], forces.total[m, :, k])
            total[:, k] += data["data"]
    # The file's mount channels add up to the foundation force (no Rayleigh or modal damping in this model).
    np.testing.assert_allclose(total, forces.foundation_force, rtol=1e-12, atol=1e-9 * np.abs(total).max())


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
def test_point_frfs_carry_their_response_and_reference_dofs_and_agree_with_the_receptance(uff, run):
    sets = by_id(uff)
    receptance = np.empty((run.frf.direct.f_hz.size, 6, 6), complex)
    for data in sets.values():
        if data["id1"].strip().startswith("small: receptance"):
            receptance[:, data["rsp_dir"] - 1, data["ref_dir"] - 1] = data["data"]
    np.testing.assert_array_equal(receptance, run.frf.direct.H)
    f = sets["point FRF drive (mobility)"]["x"]
    np.testing.assert_array_equal(f, run.frf.direct.f_hz)
    expected = {  # (response DOF, reference DOF, ordinate, denominator)
        "drive": ((TOP, 3, "top"), (TOP, 3, "top"), (11, "m/s"), (13, "N"), "mobility"),
        "cross": ((CROSS, 0, "cross"), (TOP, 3, "top"), (12, "m/s^2"), (13, "N"), "accelerance"),
        "turn": ((1, 4, "CG"), (TOP, 4, "top"), (8, "rad"), (13, "N m"), "receptance"),
    }
    for name, (response, reference, ordinate, denominator, quantity) in expected.items():
        data, frf = sets[f"point FRF {name} ({quantity})"], run.frf_extras[name]
        assert (data["func_type"], dof(data, "rsp"), dof(data, "ref")) == (4, response, reference)
        assert (units(data, "ordinate"), units(data, "orddenom"), data["ord_data_type"]) == (ordinate, denominator, 6)
        np.testing.assert_array_equal(data["data"], frf.values)
    assert sets["point FRF cross (accelerance)"]["id2"].strip() == "response along (0.707107, 0.707107, 0) body axes"
    # From the file's own receptance: rx per Mx is the receptance's entry; the drive mobility i w (T H T')_zz.
    np.testing.assert_allclose(sets["point FRF turn (receptance)"]["data"], receptance[:, 3, 3], rtol=1e-12)
    T = point_map(POSITIONS[TOP])
    drive = 2j * np.pi * f * (T @ receptance @ T.T)[:, 2, 2]
    np.testing.assert_allclose(sets["point FRF drive (mobility)"]["data"], drive, rtol=1e-10)


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
def test_transmissibilities_are_responses_per_their_reference(uff, run):
    sets = by_id(uff)
    floor, base = run.frf_extras["to_floor"], run.frf_extras["base"]
    resultant = np.zeros((floor.f_hz.size, 3), complex)
    for k, axis in enumerate("xyz"):
        data = sets[f"to_floor foundation F{axis}"]
        assert (dof(data, "rsp"), dof(data, "ref")) == ((0, k + 1, "GROUND"), (TOP, 3, "top"))
        assert (units(data, "ordinate"), units(data, "orddenom")) == ((9, "N"), (13, "N"))
        assert data["id2"].strip() == "force transmissibility"  # its load along +Z: no vector to give
        np.testing.assert_array_equal(data["data"], floor.total[:, k])
        for m, name in enumerate(MOUNTS):
            data = sets[f"to_floor mount {name} F{axis}"]
            assert (dof(data, "rsp"), dof(data, "ref")) == ((MOUNT_NODES[name], k + 1, name), (TOP, 3, "top"))
            np.testing.assert_array_equal(data["data"], floor.mount_forces[:, m, k])
            resultant[:, k] += data["data"]
        data = sets[f"base {axis} (absolute)"]
        assert (dof(data, "rsp"), dof(data, "ref")) == ((TOP, k + 1, "top"), (0, 0, "GROUND"))  # along no axis
        assert (units(data, "ordinate"), units(data, "orddenom")) == ((8, "m"), (8, "m"))
        assert data["id2"].strip() == "ground transmissibility, ground along (0, 0.6, 0.8) body axes"
        np.testing.assert_array_equal(data["data"], base.absolute[:, k])
    np.testing.assert_allclose(resultant, floor.total_force, rtol=1e-12, atol=1e-12 * np.abs(resultant).max())


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
def test_csv_carries_the_mounts_points_and_frf_requests_with_their_units(results, run, tmp_path):
    from sixdof.io.exchange import export

    time_file, frf_file = export(results, tmp_path, "csv", point_quantity="velocity")
    headers, table = read_csv(time_file)
    assert headers[:10] == ["t [s]", "x [m]", "y [m]", "z [m]", "rx [rad]", "ry [rad]", "rz [rad]", "top vx [m/s]",
                            "top vy [m/s]", "top vz [m/s]"]
    np.testing.assert_array_equal(table[:, 7:10], run.points["top"].velocity)
    for m, name in enumerate(MOUNTS):
        first = headers.index(f"mount {name} Fx [N]")
        assert headers[first:first + 3] == [f"mount {name} F{a} [N]" for a in "xyz"]
        np.testing.assert_array_equal(table[:, first:first + 3], run.mount_forces.total[m])
    assert headers[-6:] == ["Fx [N]", "Fy [N]", "Fz [N]", "Mx [N m]", "My [N m]", "Mz [N m]"]
    headers, table = read_csv(frf_file)
    np.testing.assert_array_equal(table[:, 0], run.frf.direct.f_hz)

    def column(name):
        k = next(k for k, h in enumerate(headers) if h.startswith(f"Re {name} ["))
        assert headers[k + 1] == "Im" + headers[k][2:]
        return headers[k][len(f"Re {name} ["):-1], table[:, k] + 1j * table[:, k + 1]

    for name in ("drive", "cross", "turn"):
        unit, values = column(name)
        assert unit == run.frf_extras[name].unit  # "(m/s)/N", "(m/s^2)/N", "rad/(N m)"
        np.testing.assert_array_equal(values, run.frf_extras[name].values)
    assert column("to_floor total Fz") == ("N/N", pytest.approx(run.frf_extras["to_floor"].total[:, 2], rel=0))
    unit, values = column("to_floor mount c Fy")
    assert unit == "N/N"
    np.testing.assert_array_equal(values, run.frf_extras["to_floor"].mount_forces[:, 2, 1])
    unit, values = column("base z (absolute)")
    assert unit == "m/m"
    np.testing.assert_array_equal(values, run.frf_extras["base"].absolute[:, 2])


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
@pytest.mark.parametrize("quantity", ["acceleration", "velocity", "displacement"])
def test_the_points_export_reads_back_exactly_as_test_data(results, run, tmp_path, quantity):
    """UFF58 of the points and the loads: what ``sixdof correlate`` reads (load_test), the nodes placed from the
    file's own dataset 15; the CSV of every part with the scenario's points."""
    pytest.importorskip("pyuff")
    from sixdof.io.exchange import export

    uff_file = export(results, tmp_path / "uff", "uff58", what="points", point_quantity=quantity)[0]
    csv_file = export(results, tmp_path / "csv", "csv", point_quantity=quantity)[0]
    labels = (("2+X", "2+Y", "2+Z"), tuple(f"top {quantity[0]}{axis}" for axis in "xyz"))  # ax, vx, dx
    for test, names in zip((load_test(uff_file), load_test(csv_file, parse_scenario(TEXT, "small.toml"))), labels):
        assert (test.kind, test.quantity, test.out_labels) == ("time", quantity, names)
        np.testing.assert_array_equal(test.responses, getattr(run.points["top"], quantity))
        np.testing.assert_array_equal(test.inputs, run.response.Q)
        np.testing.assert_array_equal(test.out_nodes, [TOP] * 3)
        np.testing.assert_allclose(test.out_positions, [POSITIONS[TOP]] * 3, rtol=RTOL_UFF_ASCII)
        np.testing.assert_array_equal(test.out_directions, np.eye(3))
        np.testing.assert_array_equal(test.ref_nodes, [1] * 6)
        np.testing.assert_array_equal(test.ref_rotation, [False] * 3 + [True] * 3)
        np.testing.assert_allclose(test.t, run.response.t, rtol=1e-14, atol=1e-15)


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
def test_the_whole_uff58_export_is_refused_by_load_test_in_one_line(results, tmp_path):
    # Time histories and FRFs in one file: load_test reads one kind of data per file, and says so.
    pytest.importorskip("pyuff")
    from sixdof.io.exchange import export

    path = export(results, tmp_path, "uff58")[0]
    with pytest.raises(InputError, match=r"func_type\): expected function type 1 as dataset 3: one kind of data per "
                                         r"file, got 4"):
        load_test(path)
    # Mount forces are no test response (a reaction force, not a motion): refused by name, not taken for inputs.
    path = export(results, tmp_path / "mounts", "uff58", what="points,mounts")[0]
    with pytest.raises(InputError, match=r"dataset 6 \(UFF58 ordinate_spec_data_type\): expected a response: 8 "
                                         r"\(displacement\), 11 \(velocity\) or 12 \(acceleration\), got 9"):
        load_test(path)


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
def test_an_export_is_the_same_bytes_each_time_dated_by_its_run(results, run, tmp_path):
    pytest.importorskip("pyuff")
    from sixdof.io.exchange import export

    first, second = (export(results, tmp_path / name, "uff58")[0].read_bytes() for name in ("one", "two"))
    assert first == second
    from datetime import datetime

    created = datetime.fromisoformat(run.provenance["created_utc"])  # dataset 151's dates: the run's
    lines = first.decode("latin-1").splitlines()
    assert lines[5].startswith(f"{created:%d-%b-%y} {created:%H:%M:%S}") and lines[6].startswith(lines[5][:18])


@pytest.mark.slow  # the run it reads: 3 s on the 2-core machine
def test_what_picks_the_parts_and_a_bad_choice_is_one_clear_error(results, run, tmp_path, capsys):
    from sixdof.io.exchange import export

    files = export(results, tmp_path / "mounts", "csv", what="mounts")
    assert [f.name for f in files] == ["small_time.csv"]  # no FRF part chosen: no FRF file
    headers, _ = read_csv(files[0])
    assert headers == ["t [s]", *(f"mount {m} F{a} [N]" for m in MOUNTS for a in "xyz"), "Fx [N]", "Fy [N]",
                       "Fz [N]", "Mx [N m]", "My [N m]", "Mz [N m]"]
    files = export(results, tmp_path / "frfs", "csv", what=["frfs"])
    assert [f.name for f in files] == ["small_frf.csv"]
    headers, _ = read_csv(files[0])
    assert len(headers) == 1 + 2 * (15 + 3 + 3) and headers[1] == "Re to_floor total Fx [N/N]"
    with pytest.raises(InputError, match=r"^--what: expected a comma-separated list of cg, points, mounts, frfs, got "
                                         r"'mounts,modes'$"):
        export(results, tmp_path, "csv", what="mounts,modes")
    with pytest.raises(InputError, match=r"^--point-quantity: expected displacement or velocity or acceleration"):
        export(results, tmp_path, "csv", point_quantity="jerk")
    assert main(["export", str(results), "--what", "cg,,points", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["sixdof: error: --what: expected a comma-separated list of cg, points, mounts, frfs, got "
                   "'cg,,points'"]


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_an_frf_only_run_exports_its_requests_numbered_by_the_scenario_s_points(tmp_path):
    """No time response: the points' numbers come from the scenario's text; mounts asked for are refused."""
    pytest.importorskip("pyuff")
    from sixdof.io.exchange import export

    text = TEXT.split("[simulation]")[0] + "[frf]" + TEXT.split("[frf]")[1]
    _, folder = run_scenario(parse_scenario(text, "small.toml"), tmp_path / "frf", progress=False)
    results = folder / "results.h5"
    with pytest.raises(InputError, match=r"^--what: expected parts the results hold \(cg, frfs\), got mounts, which "
                                         r".*results.h5 does not hold$"):
        export(results, tmp_path, "uff58", what="frfs,mounts")
    import pyuff

    sets = read_uff(pyuff, export(results, tmp_path, "uff58", what="frfs")[0])
    assert sets[0]["description"].strip() == "nodes: 0 ground, 1 CG, 2 point, 3-6 mounts, 7 frf place"
    drive = by_id(sets)["point FRF drive (mobility)"]
    assert (dof(drive, "rsp"), dof(drive, "ref")) == ((TOP, 3, "top"), (TOP, 3, "top"))
    assert len(by_id(sets)) == 3 + 3 * 4 + 3 + 3  # the requests only: no receptance
