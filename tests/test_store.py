"""The results file: layout, units, labelled axes, provenance, round trip and atomic writes."""

import datetime as dt
import itertools
import os
import re
import subprocess
import sys
from operator import attrgetter

import h5py
import numpy as np
import pytest

import sixdof
from sixdof import DOFS, InputError, modal_analysis, write_results
from sixdof.dofs import LOADS, UNITS
from sixdof.io import store
from sixdof.io.store import Dataset, Results, build_results, load_tree, save_results, writer
from store_cases import SCENARIO_TEXT, run_parts
from systems import bridge


@pytest.fixture(scope="module")
def parts():
    return run_parts()


@pytest.fixture(scope="module")
def written(parts, tmp_path_factory):
    path = tmp_path_factory.mktemp("run") / "bridge_beam" / "results.h5"
    return write_results(path, **parts)


@pytest.fixture(scope="module")
def loaded(written):
    return load_tree(written.path)


def assert_same(a: Results, b: Results):
    assert list(a.datasets) == list(b.datasets)
    for path, x in a.datasets.items():
        y = b[path]
        assert x.data.dtype.kind == y.data.dtype.kind, path
        np.testing.assert_array_equal(x.data, y.data, err_msg=path)
        assert (x.units, x.dims) == (y.units, y.dims), path
        assert_attrs_equal(x.attrs, y.attrs, path)
    assert list(a.attrs) == list(b.attrs)
    for group in a.attrs:
        assert_attrs_equal(a.attrs[group], b.attrs[group], group or "/")


def assert_attrs_equal(x, y, where):
    assert sorted(x) == sorted(y), where
    for key in x:
        assert type(x[key]) is type(y[key]), (where, key, type(x[key]), type(y[key]))
        if isinstance(x[key], np.ndarray):
            np.testing.assert_array_equal(x[key], y[key], err_msg=f"{where}@{key}")
        elif isinstance(x[key], float) and np.isnan(x[key]):
            assert np.isnan(y[key])
        else:
            assert x[key] == y[key], (where, key)


# ----------------------------------------------------------------------------------------------------
# Round trip and layout.
# ----------------------------------------------------------------------------------------------------


def test_round_trip_returns_everything_written(written, loaded):
    assert loaded.path == written.path
    assert_same(written, loaded)


def test_round_trip_values_equal_the_library_objects(parts, loaded):
    system, modes, response, frf, extras = (parts[k] for k in ("system", "modes", "response", "frf", "frf_extras"))
    expected = {
        **{f"model/{name}": getattr(system, name) for name in ("M", "C", "K")},
        **{f"modal/{name}": getattr(modes, name) for name in ("frequency_hz", "shapes", "ke_distribution",
                                                             "effective_mass")},
        "modal/damping_ratio": parts["damping_ratios"],
        **{f"time/{key}": getattr(response, key) for key in ("t", "q", "qd", "qdd", "Q")},
        "time/superposition/q": parts["superposition"].q,
        "frf/f_hz": frf.direct.f_hz,
        "frf/receptance": frf.direct.H,
        "frf/point/deck_vertical/values": extras["deck_vertical"].values,
        "frf/force_transmissibility/vertical_load/mount_forces": extras["vertical_load"].mount_forces,
        "frf/ground_transmissibility/ground_y/transmissibility": extras["ground_y"].transmissibility,
    }
    for path, value in expected.items():
        np.testing.assert_array_equal(loaded.array(path), value, err_msg=path)
    assert tuple(loaded.array("modal/dominant_dof")) == modes.dominant_dof
    assert loaded.attrs["modal"]["subsystems"] == tuple(",".join(s) for s in modes.subsystems)
    assert loaded.attrs["time"]["solver_num_steps"] == response.stats.num_steps
    assert loaded.attrs["time"]["solver"] == response.stats.solver
    agreement = parts["agreement"]
    attrs = loaded.attrs["time/superposition"]
    np.testing.assert_array_equal(attrs["agreement_per_dof"], agreement.per_dof)
    for key in ("worst_dof", "worst", "tolerance"):
        assert attrs[f"agreement_{key}"] == getattr(agreement, key), key
    assert attrs["agreement_ok"] == int(agreement.ok)
    assert attrs["method"] == parts["superposition"].superposition.method
    assert loaded.array("frf/receptance").dtype == np.complex128
    assert loaded.attrs["frf"]["cross_check_max_relative_difference"] == frf.max_relative_difference
    assert loaded["frf/point/deck_vertical/values"].units == extras["deck_vertical"].unit == "(m/s^2)/N"


def test_round_trip_of_responses_and_validation(parts, loaded):
    forces, points, report = parts["mount_forces"], parts["points"], parts["validation"]
    run, decay = report.random_runs[4], report.decays[2]
    expected = {
        "time/mount_force": forces.total,
        "time/mount_force_local": forces.local,
        "time/foundation_force": forces.foundation_force,
        "time/foundation_moment": forces.foundation_moment,
        **{f"time/point_{name}": [getattr(motion, name) for motion in points.values()]
           for name in ("acceleration", "position")},
        **{f"validation/{name}": [getattr(r, name) for r in report.rows] for name in ("mode", "zeta_estimated")},
        "validation/random/mode_5/H1": run.estimated.H1[:, 0],
        "validation/random/mode_5/model": run.model[:, 0],
        "validation/decay/mode_3/eta": decay.eta,
        "validation/decay/mode_3/extrema_t": decay.estimate.extrema_t,
    }
    for path, value in expected.items():
        np.testing.assert_array_equal(loaded.array(path), value, err_msg=path)
    assert loaded["time/mount_force"].dims == ("mount", "t", "axis")
    assert tuple(loaded.array("time/mount")) == forces.names
    assert tuple(loaded.array("time/point")) == tuple(points)
    for name in ("f_damped_estimated_hz", "h1_error_at_peak", "dominant_dof"):
        assert tuple(loaded.array(f"validation/{name}")) == tuple(getattr(r, name) for r in report.rows)
    np.testing.assert_array_equal(loaded.attrs["validation/random/mode_5"]["band_hz"], run.band_hz)
    assert loaded.attrs["validation/decay/mode_3"]["zeta"] == decay.estimate.zeta
    assert loaded.attrs["validation"]["notes"] == report.notes


def test_load_results_gives_back_the_typed_objects(parts, written):
    run = sixdof.load_results(written.path)
    assert isinstance(run, sixdof.RunResults) and run.name == "bridge_beam"
    assert isinstance(run.system, sixdof.System) and isinstance(run.response, sixdof.TimeHistory)

    def read_and_written(name):  # "system.M": run.system.M and parts["system"].M
        part, _, rest = name.partition(".")
        return attrgetter(rest)(getattr(run, part)), attrgetter(rest)(parts[part])

    for name in ("system.M", "system.C", "system.K", "modes.shapes", "response.t", "response.q", "response.qd",
                 "response.qdd", "response.Q", "superposition.q", "superposition.superposition.eigenvalues",
                 "mount_forces.total", "mount_check.force", "mount_check.compression", "mount_check.peak_deflection_t",
                 "mount_check.tension_start_t", "frf.direct.H", "frf.modal.H"):
        np.testing.assert_array_equal(*read_and_written(name), err_msg=name)
    for name in ("system.mount_names", "system.rayleigh", "system.modal_damping", "modes.subsystems",
                 "modes.zero_modes", "response.stats.num_steps", "superposition.superposition.method",
                 "superposition.superposition.modes_kept", "agreement.worst", "agreement.ok", "mount_forces.names",
                 "mount_check.names", "mount_check.preload", "mount_check.violations", "frf.max_relative_difference",
                 "validation.rows"):
        read, written_value = read_and_written(name)
        assert read == written_value, name
    assert run.response.ground_displacement is None
    assert list(run.points) == list(parts["points"])
    assert {k: type(v) for k, v in run.frf_extras.items()} == {k: type(v) for k, v in parts["frf_extras"].items()}
    for name, extra in parts["frf_extras"].items():
        np.testing.assert_array_equal(run.frf_extras[name].f_hz, extra.f_hz)
    report = parts["validation"]
    assert [d.mode for d in run.validation.decays] == [d.mode for d in report.decays]
    np.testing.assert_array_equal(run.validation.decays[0].history.q, report.decays[0].history.q)
    np.testing.assert_array_equal(run.validation.random_runs[0].estimated.H1, report.random_runs[0].estimated.H1)
    assert run.provenance["scenario_text"] == SCENARIO_TEXT


def test_fixed_names_shapes_and_labels(loaded):
    shapes = {
        "model/M": (6, 6), "model/C": (6, 6), "model/K": (6, 6),
        "modal/frequency_hz": (6,), "modal/shapes": (6, 6),
        "time/t": (401,), "time/q": (401, 6), "time/qd": (401, 6), "time/qdd": (401, 6),
        "time/superposition/q": (401, 6),
        "frf/f_hz": (300,), "frf/receptance": (300, 6, 6),
    }
    for path, shape in shapes.items():
        assert loaded[path].data.shape == shape, path
    assert loaded.dofs == DOFS
    assert loaded.mount_names == ("1", "2", "3", "4")
    assert loaded.name == "bridge_beam"
    for path, dims in {"time/q": ("t", "dof"), "time/superposition/q": ("t", "dof"), "modal/shapes": ("dof", "mode"),
                       "frf/receptance": ("f_hz", "dof", "load"), "model/mount_stiffness": ("mount", "mount_axis")}.items():
        assert loaded[path].dims == dims, path
    assert np.all(np.diff(loaded.array("modal/frequency_hz")) > 0)
    assert loaded["time/q"].units.description == "m (x, y, z); rad (rx, ry, rz)"
    assert dict(loaded["time/q"].units.factors) == {"dof": ("m", "m", "m", "rad", "rad", "rad")}
    assert dict(loaded["time/qdd"].units.factors) == {"dof": ("m/s^2",) * 3 + ("rad/s^2",) * 3}
    assert loaded["modal/frequency_hz"].units == "Hz"
    assert loaded["time/t"].units == "s"
    # No ground motion: no relative motion either.
    assert "time/q_relative" not in loaded.datasets and "time/ground_acceleration" not in loaded.datasets


def _unit_of(units, index: dict[str, int]) -> str:
    """The unit of one element of an array: its ``units``, or the product of its mixed axes' factors."""
    if isinstance(units, str):
        return units
    return " * ".join(f"({dict(units.factors)[dim][i]})" for dim, i in index.items() if dim in dict(units.factors))


def test_units_parse_in_pint_with_the_right_dimensions(loaded):
    pint = pytest.importorskip("pint")
    ureg = pint.UnitRegistry()
    for path, dataset in loaded.datasets.items():
        if isinstance(dataset.units, str):
            if dataset.units:  # "" marks text labels
                ureg.parse_units(dataset.units)
            continue
        assert set(dict(dataset.units.factors)) <= set(dataset.dims), path
        for _, factors in dataset.units.factors:
            assert len(factors) == 6, path
            for factor in factors:
                ureg.parse_units(factor)
    # Elements of the mixed arrays, against units derived by hand (rad counts as dimensionless).
    expected = {
        ("time/q", "dof", "z"): "m", ("time/q", "dof", "ry"): "rad", ("time/qdd", "dof", "rx"): "rad/s^2",
        ("model/K", ("load", "dof"), ("Fz", "z")): "N/m", ("model/K", ("load", "dof"), ("Mx", "rx")): "N m/rad",
        ("model/K", ("load", "dof"), ("Fx", "ry")): "N/rad", ("model/K", ("load", "dof"), ("My", "x")): "N",
        ("model/M", ("load", "dof"), ("Fz", "z")): "kg", ("model/M", ("load", "dof"), ("Mz", "rz")): "kg m^2",
        ("model/M", ("load", "dof"), ("Fy", "rx")): "kg m", ("model/C", ("load", "dof"), ("Mx", "y")): "N s",
        ("frf/receptance", ("dof", "load"), ("x", "My")): "m/(N m)",
        ("frf/receptance", ("dof", "load"), ("rz", "Fx")): "rad/N",
        ("modal/shapes", "dof", "rx"): "kg^-0.5/m", ("modal/effective_mass", "dof", "rz"): "kg m^2",
    }
    for (path, dims, labels), unit in expected.items():
        dims, labels = ((dims,), (labels,)) if isinstance(dims, str) else (dims, labels)
        index = {dim: (DOFS if dim == "dof" else LOADS).index(label) for dim, label in zip(dims, labels)}
        got = ureg.Quantity(1, _unit_of(loaded[path].units, index))
        assert got.to(unit).magnitude == pytest.approx(1.0), (path, labels, got)


def test_every_dataset_in_the_file_has_units_and_named_axes(written):
    seen = []

    def visit(name, node):
        if isinstance(node, h5py.Dataset):
            seen.append(name)
            if "units_description" in node.attrs:  # mixed translations and rotations: a unit per label
                assert "units" not in node.attrs, name
                assert any(f"{dim[0].name.rsplit('/', 1)[-1]}_units" in node.attrs for dim in node.dims), name
            else:
                assert isinstance(node.attrs["units"], str), name
            if node.is_scale:
                return
            for axis in range(node.ndim):
                assert len(node.dims[axis]) == 1, (name, axis)  # exactly one dimension scale

    with h5py.File(written.path, "r") as f:
        f.visititems(visit)
    assert len(seen) == len(written.datasets) > 40


def test_provenance(loaded):
    root = loaded.attrs[""]
    assert root["scenario_text"] == SCENARIO_TEXT
    assert root["command_line"] == "sixdof run scenarios/bridge_beam.toml"
    assert root["format"] == "sixdof-results" and root["format_version"] == store.FORMAT_VERSION
    created = dt.datetime.fromisoformat(root["created_utc"])
    assert created.utcoffset() == dt.timedelta(0)
    assert abs(dt.datetime.now(dt.UTC) - created) < dt.timedelta(hours=1)
    for package in ("sixdof", "numpy", "scipy", "jax", "diffrax", "h5py"):
        assert root[f"version_{package}"] == __import__("importlib.metadata").metadata.version(package)
    assert root["version_numpy"] == np.__version__


def test_modal_only_run_has_no_time_group(tmp_path):
    system = bridge("equal")
    results = write_results(tmp_path / "r.h5", system=system, modes=modal_analysis(system.M, system.K))
    loaded = load_tree(tmp_path / "r.h5")
    assert "time" not in loaded and "frf" not in loaded and "modal" in loaded
    assert_same(results, loaded)
    assert "model/body_dimensions" in loaded.datasets


def test_body_without_dimensions_stores_none(tmp_path):
    system = bridge("equal", dimensions=None)
    write_results(tmp_path / "r.h5", system=system)
    assert "model/body_dimensions" not in load_tree(tmp_path / "r.h5").datasets
    assert sixdof.load_results(tmp_path / "r.h5").system.body.dimensions is None


def test_superposition_without_direct_response_is_refused(parts):
    with pytest.raises(InputError, match=r"superposition: expected a direct response to compare with, got none"):
        build_results(superposition=parts["superposition"])


# ----------------------------------------------------------------------------------------------------
# netCDF view (xarray through h5netcdf).
# ----------------------------------------------------------------------------------------------------


@pytest.mark.slow  # 2 s on the 2-core machine
def test_xarray_opens_every_group_with_labelled_axes_and_reads_complex(written, parts):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    with xr.open_dataset(written.path, group="time", engine="h5netcdf") as ds:
        assert ds["q"].dims == ("t", "dof")
        assert list(ds["dof"].values) == list(DOFS)
        np.testing.assert_array_equal(ds["t"].values, parts["response"].t)
        np.testing.assert_array_equal(ds["q"].sel(dof="rz").values, parts["response"].q[:, 5])
        assert ds["q"].attrs["units_description"] == "m (x, y, z); rad (rx, ry, rz)"
        assert list(ds["q"].attrs["dof_units"]) == ["m", "m", "m", "rad", "rad", "rad"]
        assert ds.attrs["solver"] == "Tsit5"
    with xr.open_dataset(written.path, group="time/superposition", engine="h5netcdf") as ds:
        assert ds["q"].dims == ("t", "dof")
    for group in written.groups[1:]:
        with xr.open_dataset(written.path, group=group, engine="h5netcdf") as ds:
            for name, variable in ds.variables.items():
                expected = written.get(f"{group}/{name}")
                assert expected is not None, (group, name)
                assert variable.dims == expected.dims, (group, name)
    with xr.open_dataset(written.path, group="frf", engine="h5netcdf") as ds:
        H = ds["receptance"]
        assert H.dtype == np.complex128 and H.dims == ("f_hz", "dof", "load")
        np.testing.assert_array_equal(H.sel(dof="z", load="Fz").values, parts["frf"].direct.H[:, 2, 2])
    with xr.open_dataset(written.path, group="modal", engine="h5netcdf") as ds:
        assert list(ds["mode"].values) == [1, 2, 3, 4, 5, 6]
        np.testing.assert_array_equal(ds["shapes"].values, parts["modes"].shapes)
    # A point FRF under a name attribute access reaches (ds.values is xarray's own method), beside "values".
    with xr.open_dataset(written.path, group="frf/point/deck_vertical", engine="h5netcdf") as ds:
        np.testing.assert_array_equal(ds.frf.values, parts["frf_extras"]["deck_vertical"].values)
        np.testing.assert_array_equal(ds["values"].values, ds.frf.values)
        assert ds.frf.attrs["units"] == "(m/s^2)/N"


def test_open_datatree_gives_every_group_with_its_inherited_coordinates(parts, tmp_path):
    """The documented way to open a run's whole file: sub-groups see their parents' coordinates (t, dof...)."""
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    path = write_results(tmp_path / "results.h5", **{**parts, "validation": None}).path
    with xr.open_datatree(path, engine="h5netcdf") as tree:
        modal_q = tree["time/superposition"].to_dataset()["q"]
        assert modal_q.dims == ("t", "dof") and list(modal_q["dof"].values) == list(DOFS)
        np.testing.assert_array_equal(modal_q["t"].values, parts["response"].t)
        point = tree["frf/point/deck_vertical"].to_dataset()
        np.testing.assert_array_equal(point["f_hz"].values, parts["frf"].direct.f_hz)


# ----------------------------------------------------------------------------------------------------
# Atomic writes.
# ----------------------------------------------------------------------------------------------------


def _failing_after(n, exception):
    real, calls = writer._write_dataset, itertools.count(1)

    def failing(f, path, dataset):
        if next(calls) > n:
            raise exception
        return real(f, path, dataset)

    return failing


@pytest.mark.parametrize("exception", [RuntimeError("disk on fire"), KeyboardInterrupt()])
def test_failed_write_leaves_no_file_and_no_temporary(written, tmp_path, monkeypatch, exception):
    monkeypatch.setattr(writer, "_write_dataset", _failing_after(5, exception))
    target = tmp_path / "results.h5"
    with pytest.raises(type(exception)):
        save_results(written, target)
    assert list(tmp_path.iterdir()) == []


def test_failed_write_does_not_clobber_an_existing_file(written, tmp_path, monkeypatch):
    target = tmp_path / "results.h5"
    save_results(written, target)
    before = target.read_bytes()
    monkeypatch.setattr(writer, "_write_dataset", _failing_after(10, KeyboardInterrupt()))
    with pytest.raises(KeyboardInterrupt):
        save_results(written, target)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.h5"]
    assert_same(written, load_tree(target))


def test_successful_write_replaces_the_old_file(written, tmp_path):
    target = tmp_path / "results.h5"
    target.write_bytes(b"an older, different file")
    save_results(written, target)
    assert_same(written, load_tree(target))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.h5"]


# ----------------------------------------------------------------------------------------------------
# Bad input and the generic tree.
# ----------------------------------------------------------------------------------------------------


def test_load_missing_file(tmp_path):
    with pytest.raises(InputError, match=r"results: expected an existing results file \(\.h5\), got '.*nope\.h5'"):
        load_tree(tmp_path / "nope.h5")


def test_load_foreign_files(tmp_path):
    text = tmp_path / "text.h5"
    text.write_text("not hdf5")
    with pytest.raises(InputError, match=r"results: expected an HDF5 results file written by sixdof, got .*text\.h5 \("):
        load_tree(text)
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = 1.0
    with pytest.raises(InputError, match=r"results: expected an HDF5 file with format = 'sixdof-results', got .*foreign\.h5 without it"):
        load_tree(foreign)


def test_dataset_checks():
    with pytest.raises(InputError, match=r"dims: expected 2 non-empty axis names for shape \(3, 2\), got \('t',\)"):
        Dataset(np.zeros((3, 2)), "m", ("t",))
    with pytest.raises(InputError, match=r"units: expected a string or MixedUnits, got 3"):
        Dataset(np.zeros(3), 3, ("t",))
    with pytest.raises(InputError, match=r"attrs: expected attribute names other than units and HDF5's own, got 'units'"):
        Dataset(np.zeros(3), "m", ("t",), {"units": "s"})
    for bad in ({"a": 1}, [1, "a"], [1j]):
        with pytest.raises(InputError, match=r"attrs\['bad'\]: expected a string, a number or an array of numbers"):
            Dataset(np.zeros(3), "m", ("t",), {"bad": bad})


def test_axis_without_a_dimension_scale_is_refused():
    q = {"time/q": Dataset(np.zeros((3, 6)), "m", ("t", "dof")), "time/dof": Dataset(np.array(DOFS), "", ("dof",))}
    with pytest.raises(InputError, match=r"time/q\.dims\[0\]: expected the name of a dimension-scale dataset 't'"):
        Results(q, {})
    with pytest.raises(InputError, match=r"time/q\.dims\[0\]: expected scale 'time/t' of length 3, got \(4,\)"):
        Results({**q, "time/t": Dataset(np.zeros(4), "s", ("t",))}, {})


def test_extra_datasets_and_attributes_round_trip(tmp_path):
    system = bridge("equal")
    extra = {"statics/q": Dataset(np.arange(6.0), UNITS["q"], ("dof",), {"gravity": 9.81}),
             "statics/dof": Dataset(np.array(DOFS), "", ("dof",)),
             "statics/flag": Dataset(np.array([True, False]), "1", ("dof2",)),
             "statics/dof2": Dataset(np.array([0, 1]), "1", ("dof2",)),
             # a scalar text, as a force-deflection table names its axis: h5py reads it back as bare bytes
             "statics/axis": Dataset(np.array("w"), "", ())}
    results = write_results(tmp_path / "r.h5", system=system, extra=extra,
                            extra_attrs={"statics": {"uplift": ("1", "2"), "ok": True, "none": None, "empty": ()}})
    loaded = load_tree(tmp_path / "r.h5")
    assert_same(results, loaded)
    assert loaded.attrs["statics"]["uplift"] == ("1", "2")
    assert loaded.attrs["statics"]["ok"] is True and loaded.attrs["statics"]["empty"] == ()
    assert "none" not in loaded.attrs["statics"]
    assert loaded["statics/flag"].data.dtype == bool
    assert loaded["statics/axis"].data.shape == () and str(loaded["statics/axis"].data) == "w"
    _set(tmp_path / "r.h5", "statics/axis", "u")  # and a change to it is caught
    with pytest.raises(InputError, match="dataset statics/axis: its checksum fails"):
        load_tree(tmp_path / "r.h5")
    assert loaded["statics/q"].units == UNITS["q"]
    # Booleans read back as booleans in xarray too.
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    with xr.open_dataset(tmp_path / "r.h5", group="statics", engine="h5netcdf") as ds:
        assert ds["flag"].dtype == bool and ds.attrs["ok"] is np.True_


def test_results_are_read_only(loaded):
    with pytest.raises(ValueError):
        loaded.array("time/q")[0, 0] = 1.0
    with pytest.raises(TypeError):
        loaded.datasets["time/q"] = None
    with pytest.raises(KeyError, match="no dataset 'time/nothing'"):
        loaded["time/nothing"]


def test_import_sixdof_does_not_load_h5py_or_pyplot():
    code = (
        "import sys, sixdof, sixdof.io.store\n"
        "heavy = [m for m in ('h5py', 'matplotlib.pyplot') if m in sys.modules]\n"
        "assert not heavy, heavy\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            env={**os.environ, "PYTHONWARNINGS": ""})
    assert result.returncode == 0, result.stderr


def test_results_convert_to_xarray_with_dims_coordinates_and_units(parts):
    pytest.importorskip("xarray")
    history = parts["response"].to_xarray()
    assert history["q"].dims == ("t", "dof") and list(history["dof"].values) == list(DOFS)
    np.testing.assert_array_equal(history["q"].sel(dof="rz").values, parts["response"].q[:, 5])
    assert history["q"].attrs["units_description"] == "m (x, y, z); rad (rx, ry, rz)"
    assert history["q"].attrs["dof_units"] == ("m", "m", "m", "rad", "rad", "rad") and history["t"].attrs["units"] == "s"
    H = parts["frf"].direct.to_xarray()["receptance"]
    assert H.dims == ("f_hz", "dof", "load")
    np.testing.assert_array_equal(H.sel(dof="z", load="Fz").values, parts["frf"].direct.H[:, 2, 2])
    modes = parts["modes"].to_xarray()
    assert modes["frequency_hz"].attrs["units"] == "Hz" and modes["shapes"].dims == ("dof", "mode")
    forces = parts["mount_forces"].to_xarray()
    assert list(forces["mount"].values) == list(parts["mount_forces"].names)
    assert forces["mount_force"].dims == ("mount", "t", "axis")


def test_label_scales_live_in_their_top_level_group(written):
    # As the file has always had them: one frf/axis and frf/mount for every transmissibility below /frf,
    # validation/dof for every decay, modal/mode for the damping ratios; no stray root scale.
    for path in ("frf/axis", "frf/mount", "validation/dof", "modal/mode"):
        assert path in written.datasets, path
    assert "mode" not in written.datasets
    assert not [p for p in written.datasets if p.count("/") >= 3 and p.rsplit("/", 1)[1] in ("axis", "mount", "dof")]


def test_a_part_is_not_found_through_its_parents_scales(parts, tmp_path):
    # An agreement stored without its superposition history: the history's t is only the parent's scale.
    path = tmp_path / "r.h5"
    write_results(path, system=parts["system"], response=parts["response"], agreement=parts["agreement"])
    run = sixdof.load_results(path)
    assert run.superposition is None and run.agreement.worst == parts["agreement"].worst


def test_a_plain_frf_is_refused_and_files_of_another_version_are_named(parts, written, tmp_path):
    with pytest.raises(InputError, match=r"frf: expected an FRFCrossCheck"):
        sixdof.RunResults(frf=parts["frf"].direct)
    old = tmp_path / "old.h5"
    tree = load_tree(written.path)
    save_results(Results(tree.datasets, {**tree.attrs, "": {**tree.attrs[""], "format_version": 1}}), old)
    with pytest.raises(InputError, match=r"results: expected a results file of format version 2 .*version 1"):
        sixdof.load_results(old)


def test_open_datatree_reads_a_file_with_a_validation(written, parts):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    with xr.open_datatree(written.path, engine="h5netcdf") as tree:
        # Each free decay has its own time and extrema axes, the parents' labels inherited.
        for decay in parts["validation"].decays:
            node = tree[f"validation/decay/mode_{decay.mode}"]
            np.testing.assert_array_equal(node["t"].values, decay.history.t)
            assert node["extrema_t"].dims == ("extremum",) and len(node["extremum"]) == len(decay.estimate.extrema_t)
            np.testing.assert_array_equal(node["q"].sel(dof="z").values, decay.history.q[:, 2])



# ----------------------------------------------------------------------------------------------------
# Damaged files: checksums on every object, checked on reading; nothing followed before it is checked.
# ----------------------------------------------------------------------------------------------------


def _copy(written, tmp_path, name="damaged.h5"):
    path = tmp_path / name
    path.write_bytes(written.path.read_bytes())
    return path


def test_every_object_carries_a_checksum(written):
    with h5py.File(written.path, "r") as f:
        assert f.attrs[store.CHECKSUMS]
        assert h5py.h5o.get_info(f["time/q"].id).hdr.version == 2  # object headers with checksums (HDF5 1.8+)
        found = []
        f.visititems(lambda name, node: found.append((name, node)))
        for name, node in [("", f), *found]:
            assert store.CRC in node.attrs, name
            if isinstance(node, h5py.Dataset) and node.dtype.kind in "fiucb" and node.ndim and node.size:
                assert node.fletcher32, name  # the data of every numeric array is checked by HDF5 itself
        assert not f["model/body_mass"].fletcher32 and f["model/body_mass"].ndim == 0  # covered by the CRC


def test_random_bytes_over_the_middle_of_a_file_are_refused(written, tmp_path):
    path = _copy(written, tmp_path)
    size = path.stat().st_size
    with open(path, "r+b") as f:
        f.seek(size // 2 - size // 8)
        f.write(np.random.default_rng(45).bytes(size // 4))
    with pytest.raises(InputError, match=r"results: expected an undamaged results file .*damaged\.h5: "):
        load_tree(path)


def _overwrite_chunk(path, dataset):
    with h5py.File(path, "r") as f:
        info = f[dataset].id.get_chunk_info(0)
    with open(path, "r+b") as f:
        f.seek(info.byte_offset + info.size // 2)
        f.write(np.random.default_rng(2).bytes(64))


def _set(path, dataset, value=None, **attrs):
    with h5py.File(path, "r+") as f:
        if value is not None:
            f[dataset][...] = value
        for key, new in attrs.items():
            f[dataset].attrs[key] = new


@pytest.mark.parametrize(("damage", "where", "what"), [
    (lambda p: _overwrite_chunk(p, "time/q"), "dataset time/q", r"its data fail their checksum \(fletcher32"),
    (lambda p: _set(p, "model/body_mass", 1.0), "dataset model/body_mass", "its checksum fails"),  # a scalar
    (lambda p: _set(p, "model/mount", ["a", "b", "c", "d"]), "dataset model/mount", "its checksum fails"),  # text
    (lambda p: _set(p, "time/q", units_description="furlongs"), "dataset time/q", "its checksum fails"),
])
def test_damage_to_data_text_or_attributes_names_the_dataset(written, tmp_path, damage, where, what):
    path = _copy(written, tmp_path)
    damage(path)
    with pytest.raises(InputError, match=rf"undamaged results file .*damaged\.h5: {where}: .*{what}"):
        load_tree(path)


def test_a_file_without_checksums_is_read_with_one_warning(written, tmp_path):
    path = _copy(written, tmp_path, "old.h5")
    with h5py.File(path, "r+") as f:  # as an earlier version wrote it: no marker, no CRCs
        del f.attrs[store.CHECKSUMS]
        f.visititems(lambda name, node: node.attrs.__delitem__(store.CRC))
        del f.attrs[store.CRC]
    with pytest.warns(store.UncheckedWarning, match=r"old\.h5 was written by an earlier version of sixdof, without "
                      r"checksums: damage to it would go unnoticed") as caught:
        tree = load_tree(path)
    assert len(caught) == 1
    assert_same(written, tree)


DANGLING = r"""
import shutil, sys
import h5py
from sixdof.io.store import load_tree

source, folder = sys.argv[1:]
for case in ("scale recreated", "scale recreated as a scale", "freed header reused", "dependent recreated"):
    path = f"{folder}/{case.replace(' ', '_')}.h5"
    shutil.copy(source, path)
    with h5py.File(path, "r+") as f:
        if case == "dependent recreated":  # a new dataset with the old one's attributes: DIMENSION_LIST copied
            node = f["modal/frequency_hz"]
            data, attrs = node[()], dict(node.attrs)
            del f["modal/frequency_hz"]
            new = f.create_dataset("modal/frequency_hz", data=data)
            for key, value in attrs.items():
                new.attrs[key] = value
        else:
            data = f["modal/mode"][()]
            del f["modal/mode"]  # the scale goes: its dependents' DIMENSION_LIST references dangle
            if case == "freed header reused":
                for i in range(20):
                    f[f"modal/other_{i}"] = data * 1.5
            f["modal/mode"] = data
            if case == "scale recreated as a scale":
                f["modal/mode"].make_scale("mode")
    try:
        load_tree(path)
        print(f"{case}: read")
    except ValueError as exc:
        print(f"{case}: {exc}")
"""


def test_dangling_dimension_scales_are_refused_and_never_abort_hdf5(written, tmp_path):
    """Read in a child process: an abort in libhdf5 (heap corruption, SIGABRT) shows as a negative status."""
    done = subprocess.run([sys.executable, "-c", DANGLING, str(written.path), str(tmp_path)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 4, done.stdout
    for line in lines[:3]:
        assert re.search(r"results: expected an undamaged results file .*: dataset modal/\w+: axis 0: its "
                         r"dimension scale (is not an array of the file \(a dangling reference\)|cannot be opened)",
                         line), line
    assert re.search(r"dependent recreated: .*dataset modal/frequency_hz: its checksum fails", lines[3]), lines[3]


def test_empty_and_truncated_files_are_refused_in_one_line(written, tmp_path):
    empty = tmp_path / "empty.h5"
    empty.write_bytes(b"")
    truncated = tmp_path / "truncated.h5"
    truncated.write_bytes(written.path.read_bytes()[: written.path.stat().st_size // 2])
    for path, reason in ((empty, "file signature not found"), (truncated, "truncated file")):
        with pytest.raises(InputError, match=rf"expected an HDF5 results file written by sixdof, got .*{path.name} "
                           rf"\(.*{reason}") as caught:
            load_tree(path)
        assert "\n" not in str(caught.value)


def test_result_classes_are_found_by_their_registered_names():
    from sixdof.model.modes import Modes
    from sixdof.results import result_class, result_type

    assert result_class("Modes") is Modes and result_class(Modes) is Modes
    with pytest.raises(LookupError, match="no result type 'Nothing' is registered"):
        result_class("Nothing")

    class Modes:  # another class of a registered name would make the files' kinds ambiguous
        pass

    with pytest.raises(TypeError, match="result type 'Modes': registered already by sixdof.model.modes"):
        result_type(Modes)
