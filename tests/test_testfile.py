"""Measured test data in (issue 47, item 1): synthetic UFF58 files written with pyuff from a known 6-DOF model and
read back by ``load_test``, against the model's FRF on the channels worked out by hand; unit conversion, node
geometry (UFF15, 2420, ``[test.nodes]``, the test frame), the ``[test]`` table, the HDF5 round trip, and each
refused file with its message."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from sixdof import InputError, load_test, parse_scenario
from sixdof.validation.testdata import TestData
from test_run import SCENARIO
from tolerances import RTOL_LINALG, RTOL_UFF_ASCII

pyuff = pytest.importorskip("pyuff")

#: A known 6-DOF model (SI): mass and inertia with a coupling term, a coupled stiffness, Rayleigh damping.
M = np.diag([300.0, 300.0, 300.0, 20.0, 30.0, 25.0])
M[0, 4] = M[4, 0] = 15.0
K = np.diag([4e5, 4e5, 1.6e6, 5e4, 6e4, 4e4])
K[1, 3] = K[3, 1] = -2e4
K[0, 4] = K[4, 0] = 3e4
C = 1e-3 * K + 0.5 * M
F_HZ = np.linspace(1.0, 50.0, 50)
#: Test nodes in the test frame [m] (exact in UFF15's 6 digits).
NODES = {101: (0.25, -0.4, 0.3), 102: (-0.25, -0.4, 0.3), 103: (0.0, 0.5, -0.125)}
#: Standard gravity and the pound-force, in SI.
G, LBF = 9.80665, 4.4482216152605


def receptance(f_hz):
    """(nf, 6, 6) = (K - w^2 M + i w C)^-1 [m/N, rad/(N m)...]."""
    w = 2 * np.pi * np.asarray(f_hz)[:, None, None]
    return np.linalg.inv(K - w**2 * M + 1j * w * C)


def unit_vector(code):
    return np.sign(code) * np.eye(3)[(abs(code) - 1) % 3]


def row(position, code):
    """The motion along a channel of ``q``: u_p . d = u . d + theta . (p x d); a rotation: theta . d."""
    d = unit_vector(code)
    return np.concatenate([np.zeros(3), d]) if abs(code) > 3 else np.concatenate([d, np.cross(position, d)])


def column(position, code):
    """Generalized force of a unit force at p along d: [d, p x d]; of a unit moment: [0, d]."""
    return row(position, code)  # the same vector: the point map's transpose


def write(path, sets):
    assert not path.exists()
    with warnings.catch_warnings():  # pyuff leaves the handle of each binary dataset to the collector
        warnings.simplefilter("ignore", ResourceWarning)
        # "add" to a new file: pyuff's "overwrite" puts a stray delimiter before a binary dataset 58 that comes first
        pyuff.UFF(str(path)).write_sets(sets, mode="add")
    return path


def geometry(nodes=NODES, def_cs=0, disp_cs=0):
    numbers = list(nodes)
    return pyuff.prepare_15(node_nums=numbers, def_cs=[def_cs] * len(numbers), disp_cs=[disp_cs] * len(numbers),
                            color=[1] * len(numbers), x=[nodes[n][0] for n in numbers],
                            y=[nodes[n][1] for n in numbers], z=[nodes[n][2] for n in numbers])


def axis(name, data_type, units, length=0, force=0):
    return {f"{name}_spec_data_type": data_type, f"{name}_axis_units_lab": units, f"{name}_len_unit_exp": length,
            f"{name}_force_unit_exp": force, f"{name}_temp_unit_exp": 0}


def frf_set(rsp, ref, data, f=F_HZ, ordinate=(12, "m/s^2"), denominator="N", func_type=4):
    """One FRF (function type 4): its exponents those of a translation (length 1) or rotation (0) per force (force 1)
    or moment (length 1, force 1)."""
    rotation, moment = abs(rsp[1]) > 3, abs(ref[1]) > 3
    return pyuff.prepare_58(
        binary=1, func_type=func_type, rsp_node=rsp[0], rsp_dir=rsp[1], ref_node=ref[0], ref_dir=ref[1],
        ord_data_type=6, id1="synthetic", rsp_ent_name="T", ref_ent_name="T", **axis("abscissa", 18, "Hz"),
        **axis("ordinate", ordinate[0], ordinate[1], 0 if rotation else 1),
        **axis("orddenom", 13, denominator, 1 if moment else 0, 1),
        data=np.asarray(data, complex), x=f, num_pts=f.size, abscissa_spacing=1, abscissa_min=float(f[0]),
        abscissa_inc=float(f[1] - f[0]))


def time_set(node, code, data_type, units, data, step=1e-3):
    t = step * np.arange(len(data))
    return pyuff.prepare_58(
        binary=1, func_type=1, rsp_node=node, rsp_dir=code, ref_node=node if data_type == 13 else 0,
        ref_dir=code if data_type == 13 else 0, ord_data_type=4, id1="synthetic", rsp_ent_name="T", ref_ent_name="T",
        **axis("abscissa", 17, "s"), **axis("ordinate", data_type, units), **axis("orddenom", 0, "NONE"),
        data=np.asarray(data, float), x=t, num_pts=t.size, abscissa_spacing=1, abscissa_min=0.0, abscissa_inc=step)


#: Responses (node, direction code) and references: a force along +Z, one along -X, a moment about +X.
OUTPUTS = ((101, 1), (101, 3), (102, -2), (103, 3), (103, 4))
REFERENCES = ((101, 3), (102, -1), (103, 4))
#: The translations among OUTPUTS (a rotation is never in g or mm).
TRANSLATIONS = OUTPUTS[:4]


def model_channels(quantity_factor, outputs=OUTPUTS, positions=NODES):
    """The model's FRF on ``outputs`` x REFERENCES, (nf, n_out, n_ref), by hand."""
    rows = np.array([row(positions[n], c) for n, c in outputs])
    cols = np.array([column(positions[n], c) for n, c in REFERENCES]).T
    return quantity_factor * (rows @ receptance(F_HZ) @ cols)


def frf_file(path, H, outputs=OUTPUTS, data_type=12, units=("m/s^2", "rad/s^2"), force="N", moment="N m",
             extra=()):
    """A file of the FRFs ``H`` on ``outputs`` x REFERENCES with UFF15 geometry: ``units`` of a translation and a
    rotation response, ``force`` and ``moment`` the denominators' labels."""
    sets = [frf_set(o, r, H[:, i, j], ordinate=(data_type, units[abs(o[1]) > 3]),
                    denominator=moment if abs(r[1]) > 3 else force)
            for i, o in enumerate(outputs) for j, r in enumerate(REFERENCES)]
    return write(path, [*extra, geometry(), *sets])


def accelerance_factor():
    return -(2 * np.pi * F_HZ[:, None, None]) ** 2


def test_an_accelerance_file_is_read_on_its_channels_exactly(tmp_path):
    expected = model_channels(accelerance_factor())
    test = load_test(frf_file(tmp_path / "rig.uff", expected))
    assert (test.kind, test.quantity, test.name, test.source) == ("frf", "accelerance", "rig", str(tmp_path / "rig.uff"))
    np.testing.assert_array_equal(test.f_hz, F_HZ)
    np.testing.assert_array_equal(test.H, expected)  # binary UFF58: every digit
    assert test.out_labels == ("101+X", "101+Z", "102-Y", "103+Z", "103+RX")
    assert test.ref_labels == ("101+Z", "102-X", "103+RX")
    np.testing.assert_array_equal(test.out_nodes, [101, 101, 102, 103, 103])
    np.testing.assert_array_equal(test.out_directions[2], [0.0, -1.0, 0.0])
    np.testing.assert_array_equal(test.out_rotation, [False, False, False, False, True])
    np.testing.assert_array_equal(test.ref_rotation, [False, False, True])
    np.testing.assert_array_equal(test.ref_positions[1], NODES[102])
    # The channels' maps reproduce the hand-made rows and columns: the model FRF on the channels is rows H6 cols.
    H6 = receptance(F_HZ)
    np.testing.assert_allclose(accelerance_factor() * (test.response_rows() @ H6 @ test.load_columns()), expected,
                               rtol=RTOL_LINALG, atol=RTOL_LINALG * np.abs(expected).max())
    assert test.H is not None and test.t is None and test.inputs is None and test.sample_rate_hz is None


def test_units_g_mm_lbf_and_moments_are_converted_to_si(tmp_path):
    per = np.array([LBF, LBF, LBF * 0.0254])  # the references: lbf, lbf, lbf in
    accelerance = model_channels(accelerance_factor(), TRANSLATIONS)
    test = load_test(frf_file(tmp_path / "g.uff", accelerance / G * per, TRANSLATIONS, 12, ("g", ""), "lbf", "lbf in"))
    np.testing.assert_allclose(test.H, accelerance, rtol=1e-15)  # g per lbf -> (m/s^2)/N
    receptance_ = model_channels(1.0, TRANSLATIONS)
    test = load_test(frf_file(tmp_path / "mm.uff", receptance_ * 1e3, TRANSLATIONS, 8, ("mm", ""), "N", "N*m"))
    assert test.quantity == "receptance"
    np.testing.assert_allclose(test.H, receptance_, rtol=1e-15)
    mobility = model_channels(2j * np.pi * F_HZ[:, None, None])
    test = load_test(frf_file(tmp_path / "in.uff", mobility / np.array([0.0254] * 4 + [np.pi / 180])[:, None],
                              OUTPUTS, 11, ("in/s", "deg/s"), "N", "Nm"))
    assert test.quantity == "mobility"
    np.testing.assert_allclose(test.H, mobility, rtol=1e-15)
    from sixdof.io.testfile import unit_factor

    assert unit_factor("lbf in", 13, True) == pytest.approx(LBF * 0.0254, rel=1e-15)
    assert unit_factor("N*m", 13, True) == unit_factor("Nm", 13, True) == 1.0
    assert unit_factor("deg/s^2", 12, True) == pytest.approx(np.pi / 180, rel=1e-15)
    assert unit_factor("g", 12, True) is None  # a rotation is never in g


def test_blank_unit_labels_take_the_units_dataset_164(tmp_path):
    # Inches and pound-force: UFF164's factors divide a file value into SI, by each axis's length and force
    # exponents (frf_set: length 1 for a translation response and for a moment reference, force 1 per reference).
    length, force = 39.37007874015748, 0.2248089430997105
    units = pyuff.prepare_164(units_code=7, units_description="inch lbf", temp_mode=1, length=length, force=force,
                              temp=1.8, temp_offset=459.67)
    H = model_channels(1.0)
    out_length = np.array([abs(c) <= 3 for _, c in OUTPUTS], float)[:, None]
    ref_length = np.array([abs(c) > 3 for _, c in REFERENCES], float)[None, :]
    inches = {n: tuple(length * v for v in p) for n, p in NODES.items()}
    sets = [frf_set(o, r, (H * length**out_length / (length**ref_length * force))[:, i, j], ordinate=(8, "NONE"),
                    denominator="") for i, o in enumerate(OUTPUTS) for j, r in enumerate(REFERENCES)]
    test = load_test(write(tmp_path / "inch.uff", [units, geometry(inches), *sets]))
    np.testing.assert_allclose(test.H, H, rtol=1e-12)
    np.testing.assert_allclose(test.out_positions[0], NODES[101], rtol=RTOL_UFF_ASCII)  # 6 digits of UFF15


def test_geometry_from_test_nodes_in_a_test_frame_with_time_histories(tmp_path):
    # The test frame's x is the body's y, its y the body's -x; its origin 0.1 m along x, 0.2 m below the CG.
    scenario = parse_scenario(SCENARIO + """
[test]
origin = [0.1, 0.0, -0.2]
axes = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
max_frequency_error_percent = 3.0

[test.nodes]
101 = [0.25, -0.4, 0.3]
103 = [0.0, 0.5, -0.125]
""", "small.toml")
    rng = np.random.default_rng(47)
    a1, a2, force = rng.standard_normal((3, 400))
    test = load_test(write(tmp_path / "tap.uff", [time_set(101, 1, 12, "g", a1), time_set(103, -3, 12, "g", a2),
                                                    time_set(103, 2, 13, "lbf", force)]), scenario)
    assert (test.kind, test.quantity, test.sample_rate_hz) == ("time", "acceleration", pytest.approx(1000.0))
    np.testing.assert_allclose(test.responses, np.column_stack([a1, a2]) * G, rtol=1e-15)
    np.testing.assert_allclose(test.inputs[:, 0], force * LBF, rtol=1e-15)
    np.testing.assert_allclose(test.t, 1e-3 * np.arange(400), rtol=1e-14, atol=1e-15)
    # By hand: body = origin + p @ axes; node 101 (0.25, -0.4, 0.3) -> (0.1 + 0.4, 0.25, -0.2 + 0.3).
    np.testing.assert_allclose(test.out_positions, [[0.5, 0.25, 0.1], [-0.4, 0.0, -0.325]], atol=1e-15)
    np.testing.assert_allclose(test.out_directions, [[0.0, 1.0, 0.0], [0.0, 0.0, -1.0]], atol=1e-15)
    np.testing.assert_allclose(test.ref_directions, [[-1.0, 0.0, 0.0]], atol=1e-15)  # test +Y is body -X
    assert test.ref_labels == ("103+Y",) and test.out_labels == ("101+X", "103-Z")
    assert scenario.test.max_frequency_error_percent == 3.0 and scenario.test.min_mac == 0.9


def test_a_node_in_a_local_coordinate_system_is_placed_by_its_dataset_2420(tmp_path):
    # System 5: its x along global y, its y along global -x, origin at (0.1, 0, 0); node 104 at (0.2, 0, 0.1) in it.
    matrix = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.1, 0.0, 0.0]])
    systems = pyuff.prepare_2420(Part_UID=1, Part_Name="rig", CS_sys_labels=[5], CS_types=[0], CS_colors=[8],
                                 CS_names=["local"], CS_matrices=[matrix])
    sets = [geometry({104: (0.2, 0.0, 0.1)}, def_cs=5, disp_cs=5), geometry({105: (0.0, 0.0, 0.0)}),
            time_set(104, 1, 12, "m/s^2", np.ones(10)), time_set(105, 3, 13, "N", np.ones(10))]
    test = load_test(write(tmp_path / "local.uff", [systems, *sets]))
    np.testing.assert_allclose(test.out_positions[0], [0.1, 0.2, 0.1], atol=1e-15)
    np.testing.assert_allclose(test.out_directions[0], [0.0, 1.0, 0.0], atol=1e-15)
    with pytest.raises(InputError, match=r"nolocal\.uff dataset 1 \(UFF15 node 104\): expected displacement coordinate "
                       r"system 0 \(global\) or one a dataset 2420 in the file defines, got coordinate system 5"):
        load_test(write(tmp_path / "nolocal.uff", [geometry({104: (0.2, 0.0, 0.1)}, disp_cs=5), *sets[1:]]))


@pytest.mark.parametrize(("case", "message"), [
    ("unit", r"dataset 2 \(UFF58 ordinate_axis_units_lab\): expected a unit of an acceleration that sixdof can "
             r"convert .*, got 'furlong/s\^2'"),
    ("blank", r"dataset 2 \(UFF58 ordinate_axis_units_lab\): expected a unit label, or a units dataset 164 in the "
              r"file, got a blank label and no dataset 164"),
    ("node", r"dataset 2 \(UFF58 rsp_node\): expected coordinates of node 107 \(a dataset 15 or 2411 in the file, or "
             r"\[test.nodes\] in the scenario\), got none"),
    ("abscissa", r"dataset 3 \(UFF58 abscissa\): expected the abscissa of dataset 2 \(50 points from 1 Hz, step 1\): "
                 r"one sample rate and abscissa for every set, got 50 points from 1 Hz, step 2"),
    ("reference", r": expected an FRF for every response and reference \(2 x 2 datasets 58\): a reference "
                  r"channel is missing, got none of 101\+Z per 102-X"),
    ("function", r"dataset 2 \(UFF58 func_type\): expected function type 1 \(time response\) or 4 \(FRF\), got 2"),
    ("rate", r"dataset 3 \(UFF58 abscissa\): expected the abscissa of dataset 2 \(10 points from 0 s, step 0.001\): "
             r"one sample rate and abscissa for every set, got 10 points from 0 s, step 0.002"),
    ("force", r": expected a reference channel: a time history of force \(ordinate type 13\), got 1 "
              r"responses and no force"),
])
def test_a_file_that_cannot_be_read_unambiguously_is_refused(tmp_path, case, message):
    data = np.ones(F_HZ.size, complex)
    sets = {
        "unit": [frf_set((101, 1), (101, 3), data, ordinate=(12, "furlong/s^2"))],
        "blank": [frf_set((101, 1), (101, 3), data, ordinate=(12, ""))],
        "node": [frf_set((107, 1), (101, 3), data)],
        "abscissa": [frf_set((101, 1), (101, 3), data), frf_set((101, 3), (101, 3), data, f=2 * F_HZ - 1)],
        "reference": [frf_set((101, 1), (101, 3), data), frf_set((101, 3), (101, 3), data),
                      frf_set((101, 1), (102, -1), data)],
        "function": [frf_set((101, 1), (101, 3), data, func_type=2)],
        "rate": [time_set(101, 1, 12, "g", np.ones(10)), time_set(101, 3, 13, "N", np.ones(10), step=2e-3)],
        "force": [time_set(101, 1, 12, "g", np.ones(10))],
    }[case]
    path = write(tmp_path / "bad.uff", [geometry(), *sets])
    with pytest.raises(InputError, match=re.escape(str(path)) + (" " if message.startswith("dataset") else "") + message):
        load_test(path)


def test_a_csv_needs_the_scenario_and_each_of_its_columns(tmp_path):
    path = tmp_path / "run_time.csv"
    path.write_text("t [s],top ax [m/s^2],top ay [m/s^2]\n0,1,2\n0.001,1,2\n0.002,1,2\n")
    with pytest.raises(InputError, match=r"run_time\.csv: expected a scenario whose \[\[points\]\] place the CSV's"):
        load_test(path)
    with pytest.raises(InputError, match=r"run_time\.csv column 'top az': expected the acceleration of point 'top' "
                       r"\('top az \[m/s\^2\]'\), got no such column"):
        load_test(path, parse_scenario(SCENARIO, "small.toml"))
    with pytest.raises(InputError, match=r"missing\.uff: expected a test file \(UFF58 or CSV\), got no such file"):
        load_test(tmp_path / "missing.uff")


def test_the_test_table_is_checked(tmp_path):
    assert parse_scenario(SCENARIO, "small.toml").test is None
    for table, message in (("axes = [[1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 1.0]]",
                            r"small\.toml: test\.axes: expected 3 orthonormal rows"),
                           ("min_mac = 1.5", r"test\.min_mac: expected a MAC from 0 to 1, got 1\.5"),
                           ("mac = 0.9", r"test\.mac: expected one of the keys .*min_mac"),
                           ("nodes = { a1 = [0.0, 0.0, 0.0] }", r"test\.nodes\.a1: expected a positive integer node"),
                           ("nodes = { 7 = [0.0, 0.0] }", r"test\.nodes\.7: expected 3 coordinates")):
        with pytest.raises(InputError, match=message):
            parse_scenario(SCENARIO + "\n[test]\n" + table + "\n", "small.toml")


def _frf_data():
    H = model_channels(accelerance_factor())
    return TestData(name="rig", source="rig.uff", kind="frf", quantity="accelerance", f_hz=F_HZ, H=H,
                    out_nodes=[n for n, _ in OUTPUTS], out_positions=[NODES[n] for n, _ in OUTPUTS],
                    out_directions=[unit_vector(c) for _, c in OUTPUTS], out_rotation=[abs(c) > 3 for _, c in OUTPUTS],
                    out_labels=[f"{n}:{c}" for n, c in OUTPUTS], ref_nodes=[n for n, _ in REFERENCES],
                    ref_positions=[NODES[n] for n, _ in REFERENCES],
                    ref_directions=[unit_vector(c) for _, c in REFERENCES],
                    ref_rotation=[abs(c) > 3 for _, c in REFERENCES], ref_labels=[f"{n}:{c}" for n, c in REFERENCES])


def test_test_data_round_trips_through_the_results_store(tmp_path):
    from sixdof.io.store import FORMAT, FORMAT_VERSION, Results, load_tree, save_results
    from sixdof.io.store.codec import _Decoder, _Encoder

    frf = _frf_data()
    time = TestData(name="tap", source="tap.csv", kind="time", quantity="acceleration", t=np.arange(5) * 0.01,
                    inputs=np.arange(5.0)[:, None], responses=np.arange(10.0).reshape(5, 2), sample_rate_hz=100.0,
                    **{f"{side}_{name}": getattr(frf, f"{side}_{name}")[:k] for side, k in (("out", 2), ("ref", 1))
                       for name in ("nodes", "positions", "directions", "rotation", "labels")})
    encoder = _Encoder()
    encoder.set_attrs("", format=FORMAT, format_version=FORMAT_VERSION)
    encoder.encode(frf, "test")
    encoder.encode(time, "time_test")
    save_results(Results(encoder.datasets, encoder.attrs), tmp_path / "test.h5")
    tree = load_tree(tmp_path / "test.h5")
    assert dict(tree["test/H"].units.factors)["reference"] == ("1/N", "1/N", "1/(N m)")
    for original, group in ((frf, "test"), (time, "time_test")):
        back = _Decoder(tree).decode(TestData, group)
        for name in ("name", "source", "kind", "quantity", "sample_rate_hz", "out_labels", "ref_labels"):
            assert getattr(back, name) == getattr(original, name)
        for name in ("f_hz", "H", "t", "inputs", "responses", "out_nodes", "out_positions", "out_directions",
                     "out_rotation", "ref_nodes", "ref_positions", "ref_directions", "ref_rotation"):
            value = getattr(original, name)
            if value is None:
                assert getattr(back, name) is None, name
            else:
                np.testing.assert_array_equal(getattr(back, name), value)
                assert getattr(back, name).dtype == value.dtype, name


def test_test_data_as_xarray_names_its_channels_and_units():
    pytest.importorskip("xarray")
    data = _frf_data().to_xarray()
    assert data["H"].dims == ("f_hz", "output", "reference")
    assert list(data["output"].values) == ["101:1", "101:3", "102:-2", "103:3", "103:4"]
    assert list(data["out_node"].values) == [101, 101, 102, 103, 103]
    assert data["out_direction"].dims == ("output", "axis")
    assert list(data["H"].attrs["output_units"]) == ["m/s^2"] * 4 + ["rad/s^2"]
    assert data["f_hz"].attrs["units"] == "Hz" and data.attrs["quantity"] == "accelerance"


def test_test_data_refuses_arrays_that_do_not_fit_its_channels():
    frf = _frf_data()
    import dataclasses

    with pytest.raises(InputError, match=r"H: expected shape \(50, 5, 3\), got shape \(50, 5, 2\)"):
        dataclasses.replace(frf, H=frf.H[:, :, :2])
    with pytest.raises(InputError, match=r"quantity: expected one of receptance, mobility, accelerance for frf data"):
        dataclasses.replace(frf, quantity="acceleration")
    with pytest.raises(InputError, match=r"out_directions: expected unit vectors"):
        dataclasses.replace(frf, out_directions=2 * frf.out_directions)


def test_geometry_from_a_dataset_2411_in_double_precision(tmp_path):
    nodes = {201: (0.123456789012, -0.4, 0.3), 202: (0.0, 0.5, -0.125)}
    numbers = list(nodes)
    points = pyuff.prepare_2411(node_nums=numbers, def_cs=[0, 0], disp_cs=[0, 0], color=[1, 1],
                                x=[nodes[n][0] for n in numbers], y=[nodes[n][1] for n in numbers],
                                z=[nodes[n][2] for n in numbers])
    test = load_test(write(tmp_path / "fine.uff", [points, time_set(201, 2, 12, "m/s^2", np.ones(10)),
                                                   time_set(202, -4, 13, "N m", np.ones(10))]))
    np.testing.assert_allclose(test.out_positions, [nodes[201]], rtol=1e-15)  # 2411 keeps 16 digits
    np.testing.assert_array_equal(test.ref_rotation, [True])  # a force channel about -X: a moment
    np.testing.assert_array_equal(test.ref_directions, [[-1.0, 0.0, 0.0]])
    np.testing.assert_array_equal(test.load_columns()[:, 0], [0, 0, 0, -1, 0, 0])
