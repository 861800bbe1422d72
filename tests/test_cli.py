"""The ``sixdof`` command, called as ``main([...])``."""

import json

import numpy as np
import pytest

from sixdof import DOFS
from sixdof.cli import main
from systems import BRIDGE_INERTIA, BRIDGE_MASS
from tolerances import ATOL_QUOTED_HZ, RTOL_LINALG


def test_modes_prints_readable_tables(capsys):
    assert main(["modes", "scenarios/bridge_beam.toml"]) == 0
    out = capsys.readouterr().out
    for text in ["f [Hz]", "38.0344", "dominant DOF", "Kinetic energy distribution", "(x, ry, rz)", "(y, z, rx)", "203.488", "compression"]:
        assert text in out


def test_modes_json_has_the_documented_keys(capsys):
    assert main(["modes", "scenarios/bridge_beam.toml", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["dofs"] == list(DOFS)
    f = np.array(data["frequencies_hz"])
    assert np.all(np.diff(f) > 0) and f[-1] == pytest.approx(38.0344, abs=ATOL_QUOTED_HZ)
    shapes = np.array(data["shapes"])
    # shapes[i][j] = DOF i of mode j, mass-normalized: Phi' M Phi = I.
    M = np.diag([BRIDGE_MASS] * 3 + BRIDGE_INERTIA)
    assert shapes.T @ M @ shapes == pytest.approx(np.eye(6), abs=RTOL_LINALG)
    assert data["subsystems"] == [["x", "ry", "rz"], ["y", "z", "rx"]]


def test_bad_input_exits_2_without_traceback(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "b"\n[body]\nmass = -5\ninertia = [1, 1, 1]\n[[mounts]]\nname = "1"\nposition = [0, 0, 0]\nstiffness = [1, 1, 1]\n')
    assert main(["modes", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml: body.mass: expected a positive number in kg, got -5" in err
    assert "Traceback" not in err


def test_sweep_writes_distributions(tmp_path, capsys):
    scenario = tmp_path / "s.toml"
    scenario.write_text(
        'name = "s"\n[body]\nmass = 100.0\ninertia = [5.0, 6.0, 7.0]\n'
        + "".join(
            f'[[mounts]]\nname = "{i}"\nposition = [{x}, {y}, -0.2]\nstiffness = [1e5, 1e5, 3e5]\ndamping = [50.0, 50.0, 90.0]\n'
            for i, (x, y) in enumerate([(-0.4, -0.4), (0.4, -0.4), (0.4, 0.4), (-0.4, 0.4)])
        )
        + '[[loads]]\nname = "hit"\npoint = [0.1, 0.2, 0.1]\nforce = [10.0, 20.0, 100.0]\n'
        'signal = { kind = "half_sine", start = 0.01, duration = 0.01 }\n'
        "[simulation]\nduration = 0.2\nsample_rate_hz = 1000.0\n"
    )
    spec = tmp_path / "spec.toml"
    spec.write_text('count = 8\nseed = 1\n[[vary]]\nparameter = "stiffness"\ndistribution = "uniform"\nlow = 0.8\nhigh = 1.2\n')
    assert main(["sweep", str(scenario), "--spec", str(spec), "--out", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "s_sweep" / "sweep.h5").exists()
    assert "Wrote" in capsys.readouterr().out
    spec.write_text('count = 8\n[[vary]]\nparameter = "mass"\n')
    assert main(["sweep", str(scenario), "--spec", str(spec), "--out", str(tmp_path / "out2")]) == 2
    assert "vary[0].parameter" in capsys.readouterr().err
    assert not (tmp_path / "out2").exists()
