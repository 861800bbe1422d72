"""The ``sixdof`` command, called as ``main([...])``."""

import json

import numpy as np
import pytest

from sixdof.cli import main
from sixdof.dofs import DOFS


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
    assert np.all(np.diff(f) > 0) and f[-1] == pytest.approx(38.0344, abs=1e-4)
    shapes = np.array(data["shapes"])
    # shapes[i][j] = DOF i of mode j, mass-normalized: Phi' M Phi = I.
    M = np.diag([83e3, 83e3, 83e3, 11.105e6, 0.0491e6, 11.064e6])
    assert shapes.T @ M @ shapes == pytest.approx(np.eye(6), abs=1e-10)
    assert data["subsystems"] == [["x", "ry", "rz"], ["y", "z", "rx"]]


def test_bad_input_exits_2_without_traceback(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "b"\n[body]\nmass = -5\ninertia = [1, 1, 1]\n[[mounts]]\nname = "1"\nposition = [0, 0, 0]\nstiffness = [1, 1, 1]\n')
    assert main(["modes", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml: body.mass: expected a positive number in kg, got -5" in err
    assert "Traceback" not in err
