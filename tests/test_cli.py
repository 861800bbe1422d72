"""The ``sixdof`` command, called as ``main([...])``."""

import json
import subprocess
import sys

import numpy as np
import pytest

from sixdof import DOFS
from sixdof.cli import main
from sixdof.io.store import write_results
from store_cases import run_parts
from systems import BRIDGE_INERTIA, BRIDGE_MASS, bridge
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


def loaded_modules(code: str, modules=("numpy", "scipy", "jax", "matplotlib", "h5py")) -> list[str]:
    """Which of ``modules`` a fresh interpreter has imported after running ``code``."""
    script = f"import sys\n{code}\nprint('loaded:', *(m for m in {modules!r} if m in sys.modules))\n"
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return result.stdout.splitlines()[-1].split()[1:]


def test_help_and_import_load_no_numerics():
    """``sixdof --help`` and ``import sixdof`` answer at once: nothing numeric is imported."""
    assert loaded_modules("import sixdof\nfrom sixdof.cli import main\ntry:\n    main(['--help'])\n"
                          "except SystemExit:\n    pass") == []


def test_plot_never_imports_jax(tmp_path):
    path = tmp_path / "results.h5"
    write_results(path, **run_parts())
    assert "jax" not in loaded_modules(f"from sixdof.cli import main\nassert main(['plot', {str(path)!r}]) == 0")
    assert len(list(tmp_path.glob("*.png"))) == 9


def test_plot_of_modal_results_imports_no_jax(tmp_path):
    path = tmp_path / "results.h5"
    system = bridge("equal")
    write_results(path, system=system, modes=system.modes)
    assert "jax" not in loaded_modules(f"from sixdof.cli import main\nassert main(['plot', {str(path)!r}]) == 0")
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["ke_distribution.png", "mode_shapes.png"]


@pytest.mark.parametrize(("arguments", "status"), [(["modes", "scenarios/bridge_beam.toml", "--json"], 0),
                                                    (["modes", "missing.toml"], 2)])
def test_the_command_ends_with_its_status_and_all_its_output(arguments, status):
    """As the ``sixdof`` command (main() reading sys.argv), the process skips the interpreter's teardown:
    its exit status and every line it printed still come through a pipe."""
    code = f"import sys\nfrom sixdof.cli import main\nsys.argv = ['sixdof', *{arguments!r}]\nsys.exit(main())\n"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == status, result.stderr
    if status == 0:
        assert json.loads(result.stdout)["name"] == "bridge_beam"
    else:
        assert result.stderr.startswith("sixdof: error: ") and "missing.toml" in result.stderr
