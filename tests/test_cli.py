"""The ``sixdof`` command, called as ``main([...])``."""

import ast
import json
import math
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sixdof import DOFS, InputError
from sixdof.cli import EXIT_CANNOT_WRITE, EXIT_CLOSED_PIPE, _parser, main
from sixdof.cli._process import BLAS_THREAD_VARIABLES
from sixdof.io.store import write_results
from store_cases import run_parts
from systems import BRIDGE_INERTIA, BRIDGE_MASS, bridge, heavily_damped_box, heavily_damped_box_toml
from tolerances import ATOL_QUOTED_HZ, RTOL_LINALG


def test_modes_prints_readable_tables(capsys):
    assert main(["modes", "scenarios/bridge_beam.toml"]) == 0
    out = capsys.readouterr().out
    for text in ["f [Hz]", "38.0344", "dominant DOF", "Kinetic energy distribution", "(x, ry, rz)", "(y, z, rx)", "203.488", "compression"]:
        assert text in out
    # The ground scenario's bearings are symmetric about x: its static ry and rz are round-off (~1e-21 rad), shown
    # as 0 like a KE share of -1e-17, not as "-3.3881e-12 nrad" or "-0.0".
    assert main(["modes", "scenarios/bridge_beam_ground.toml"]) == 0
    out = capsys.readouterr().out
    section = out.split("static deflection")[1].split("Load on each mount")[0]
    static = dict(line.strip("| ").split(" | ")[:2] for line in section.splitlines() if line.startswith("| r"))
    assert static["rx "].strip() == "6.1879 µrad" and static["ry "].strip() == static["rz "].strip() == "0 nrad"
    assert "e-" not in section and "-0.0 " not in out


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


@pytest.mark.slow  # 4 s on the 2-core machine
def test_modes_json_keys_are_the_results_file_s_names(tmp_path, capsys):
    """Every dataset and attribute of the file's modal and statics groups under its own name, same values."""
    from sixdof.io.store import load_tree

    assert main(["run", "scenarios/bridge_beam_traffic.toml", "--out", str(tmp_path), "--quiet"]) == 0
    tree = load_tree(tmp_path / "bridge_beam_traffic" / "results.h5")
    capsys.readouterr()
    assert main(["modes", "scenarios/bridge_beam_traffic.toml", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for group, found in (("modal", data), ("statics", data["statics"])):
        names = [p.split("/", 1)[1] for p in tree.datasets if p.startswith(f"{group}/") and p.count("/") == 1]
        assert len(names) >= 8
        for name in names:
            stored = tree.array(f"{group}/{name}")
            if stored.dtype.kind == "f":
                np.testing.assert_allclose(np.array(found[name], dtype=float), stored, rtol=1e-12, atol=0)
            else:
                assert found[name] == stored.tolist(), name
    assert data["rigid_body_modes"] == [] and data["statics"]["uplift"] == []
    assert data["frequencies_hz"] == data["frequency_hz"]  # the name of earlier versions, kept


def test_modes_json_legacy_mount_forces_keep_their_sign(capsys):
    """``mount_forces_n`` of earlier versions was the force of each mount on the body (git f879cd7:
    ``-k delta``): under -z gravity every bearing pushes up and the bearings together hold the weight,
    ``sum Fz = m g``. Today's ``mount_force`` is the body's load on the mount, its opposite."""
    from sixdof.analysis.statics import STANDARD_GRAVITY

    assert main(["modes", "scenarios/bridge_beam.toml", "--json"]) == 0
    statics = json.loads(capsys.readouterr().out)["statics"]
    legacy, today = np.array(statics["mount_forces_n"]), np.array(statics["mount_force"])
    assert legacy.shape == (4, 3) and np.all(legacy[:, 2] > 0)
    np.testing.assert_allclose(legacy.sum(axis=0), [0.0, 0.0, BRIDGE_MASS * STANDARD_GRAVITY],
                               rtol=RTOL_LINALG, atol=RTOL_LINALG * BRIDGE_MASS * STANDARD_GRAVITY)
    np.testing.assert_array_equal(legacy, -today)
    assert statics["support_n"] == statics["support"]  # the same sign then and now: > 0 in compression


def test_modes_json_numbers_a_free_body_s_rigid_body_modes_as_integers(tmp_path, capsys):
    """One mount under the CG leaves three rigid-body modes (the body turns about it): numbered 1, 2, 3, as the
    file's attribute, not 1.0, 2.0, 3.0."""
    scenario = tmp_path / "free.toml"
    scenario.write_text('name = "free"\n[body]\nmass = 10.0\ninertia = [1.0, 1.0, 1.0]\n[[mounts]]\nname = "a"\n'
                        'position = [0.0, 0.0, -0.1]\nstiffness = [1e4, 1e4, 1e4]\n')
    assert main(["modes", str(scenario), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["rigid_body_modes"] == [1, 2, 3] and all(type(j) is int for j in data["rigid_body_modes"])
    assert data["zero_modes"] == [0, 1, 2]


def test_version_module_entry_and_options_after_the_command(capsys):
    from sixdof import __version__

    result = subprocess.run([sys.executable, "-m", "sixdof", "--version"], capture_output=True, text=True)
    assert result.returncode == 0 and result.stdout.strip() == f"sixdof {__version__}"
    args = _parser().parse_args(["run", "scenario.toml", "--debug", "--quiet"])
    assert args.debug and args.quiet
    args = _parser().parse_args(["--debug", "modes", "scenario.toml"])
    assert args.debug and not args.quiet  # given before the command, not reset by the command's default


def test_plot_of_a_sweep_file_is_an_error_not_an_empty_success(tmp_path, capsys):
    from sixdof.io.store import write_results
    from sixdof.results import RunResults

    path = tmp_path / "sweep.h5"
    write_results(path, RunResults(name="s", system=bridge("equal")))
    assert main(["plot", str(path)]) == 2
    err = capsys.readouterr().err
    assert "results: expected a results file with something to draw" in err and str(path) in err
    assert list(tmp_path.glob("*.png")) == []


@pytest.mark.slow  # 4 s on the 2-core machine
def test_warnings_go_to_stderr_and_prose_lines_stay_short(tmp_path, capsys):
    """``modes`` and ``run`` warn of uplift on stderr, as every command warns; the run's report has no line over 120
    characters (the agreement's per-DOF values on a line of their own)."""
    overhang = tmp_path / "overhang.toml"
    overhang.write_text('name = "overhang"\n[body]\nmass = 100.0\ninertia = [5.0, 5.0, 5.0]\n'
                        '[[mounts]]\nname = "near"\nposition = [0, 0.5, 0]\nstiffness = [1e5, 1e5, 1e6]\n'
                        '[[mounts]]\nname = "far"\nposition = [0, 1.5, 0]\nstiffness = [1e5, 1e5, 1e6]\n')
    for command in ("modes", "run"):
        assert main([command, str(overhang), *(["--out", str(tmp_path)] if command == "run" else [])]) == 0
        out, err = capsys.readouterr()
        assert "WARNING: mounts in tension (uplift): far" in err and "WARNING" not in out, command
    assert main(["run", "scenarios/bridge_beam_traffic.toml", "--out", str(tmp_path), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "  per DOF: x " in out
    assert max(len(line.replace(str(tmp_path), "")) for line in out.splitlines() if not line.startswith("|")) <= 120


def test_a_sag_no_mount_could_give_is_warned_by_modes_and_run(tmp_path, capsys):
    """Stiffness meant in N/mm, given in N/m: both commands say so, and the run's summary keeps it."""
    soft = tmp_path / "soft.toml"
    soft.write_text('name = "soft"\n[body]\nmass = 100.0\ninertia = [5.0, 5.0, 5.0]\ndimensions = [1.0, 1.0, 1.0]\n'
                    + "".join(f'[[mounts]]\nname = "{name}"\nposition = [{x}, {y}, -0.5]\nstiffness = [100, 100, 250]\n'
                              for name, x, y in (("a", -0.4, -0.4), ("b", 0.4, -0.4), ("c", -0.4, 0.4), ("d", 0.4, 0.4))))
    warning = "WARNING: the static deflection under gravity, 980.7 mm at the CG, exceeds the body's half-size (866 mm)"
    assert main(["modes", str(soft)]) == 0
    assert warning in capsys.readouterr().err
    # With the dashpots in N s/m too (a few hundred), the vertical mode is far beyond critical: marked so.
    soft.write_text(soft.read_text().replace("stiffness = [100, 100, 250]\n",
                                             "stiffness = [100, 100, 250]\ndamping = [1, 1, 300]\n"))
    assert main(["modes", str(soft)]) == 0
    zeta = 4 * 300 / (2 * math.sqrt(4 * 250 * 100.0))  # c / c_critical of the vertical bounce
    rows = [line.split("|") for line in capsys.readouterr().out.splitlines() if line.startswith("| 3 ")]
    bounce = rows[0]  # mode 3, in the modes table (the first)
    assert bounce[4].strip() == "z" and bounce[-2].strip() == f"{100 * zeta:.2f} overdamped"
    assert main(["run", str(soft), "--out", str(tmp_path), "--quiet"]) == 0
    assert warning in capsys.readouterr().err
    assert warning.removeprefix("WARNING: ") in (tmp_path / "soft" / "summary.md").read_text()


def test_bad_input_exits_2_without_traceback(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "b"\n[body]\nmass = -5\ninertia = [1, 1, 1]\n[[mounts]]\nname = "1"\nposition = [0, 0, 0]\nstiffness = [1, 1, 1]\n')
    assert main(["modes", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "bad.toml: body.mass: expected a positive number in kg, got -5" in err
    assert "Traceback" not in err


def sweep_files(tmp_path) -> tuple[Path, Path]:
    """A scenario of 0.2 s under a half-sine and a spec of 8 variants of its stiffness, written into ``tmp_path``."""
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
    return scenario, spec


@pytest.mark.slow  # 4 s on the 2-core machine
def test_sweep_writes_distributions(tmp_path, capsys):
    scenario, spec = sweep_files(tmp_path)
    assert main(["sweep", str(scenario), "--spec", str(spec), "--out", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "s_sweep" / "sweep.h5").exists()
    out = capsys.readouterr().out
    assert "Wrote" in out and out.startswith("s\n\n")  # a scenario without a description: its name alone, no "s: "
    spec.write_text('count = 8\n[[vary]]\nparameter = "mass"\n')
    assert main(["sweep", str(scenario), "--spec", str(spec), "--out", str(tmp_path / "out2")]) == 2
    assert "vary[0].parameter" in capsys.readouterr().err
    assert not (tmp_path / "out2").exists()
    spec.write_text('count = 1000000000\n[[vary]]\nparameter = "stiffness"\ndistribution = "uniform"\nlow = 0.8\n'
                    'high = 1.2\n')  # refused up front, with the time it would take
    assert main(["sweep", str(scenario), "--spec", str(spec), "--out", str(tmp_path / "out2")]) == 2
    assert capsys.readouterr().err == (f"sixdof: error: {spec}: count: expected at most 10,000,000 variants, got "
                                       "1,000,000,000 (at least 8.33 h of computing at 30 µs each)\n")
    assert not (tmp_path / "out2").exists()


@pytest.mark.parametrize("size", ["0", "-5"])
def test_a_chunk_size_below_one_is_refused_before_computing(size, tmp_path, monkeypatch, capsys):
    """``--chunk-size`` is checked as the spec's ``chunk_size`` is (0 was read as "not given", -5 failed once
    computed)."""
    from sixdof.analysis.sweep import ChunkedSweep
    from sixdof.io.scenario import load_scenario
    from sixdof.io.sweep import load_sweep_spec
    from sixdof.workflows import sweep as sweeps

    scenario, spec = sweep_files(tmp_path)
    monkeypatch.setattr(ChunkedSweep, "run", lambda *args, **kwargs: pytest.fail("computed anyway"))
    out = tmp_path / "out"
    assert main(["sweep", str(scenario), "--spec", str(spec), "--out", str(out), "--chunk-size", size]) == 2
    assert capsys.readouterr().err == f"sixdof: error: --chunk-size: expected a positive integer, got {size}\n"
    with pytest.raises(InputError, match=r"^--chunk-size: expected a positive integer, got 2\.0$"):
        sweeps.sweep(load_scenario(scenario), load_sweep_spec(spec), chunk_size=2.0)
    assert not out.exists()


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


@pytest.mark.long  # over 10 s on the 2-core machine
def test_plot_never_imports_jax(tmp_path):
    path = tmp_path / "results.h5"
    write_results(path, **run_parts())
    assert "jax" not in loaded_modules(f"from sixdof.cli import main\nassert main(['plot', {str(path)!r}]) == 0")
    assert sorted(png.stem for png in tmp_path.glob("*.png")) == [  # every figure the stored results hold
        "bode", "free_decays", "ke_distribution", "mode_shapes", "mount_forces", "point_frfs", "superposition",
        "time_dofs", "time_points", "validation_frf"]


@pytest.mark.slow  # 2 s on the 2-core machine
def test_plot_of_modal_results_imports_no_jax(tmp_path):
    path = tmp_path / "results.h5"
    system = bridge("equal")
    write_results(path, system=system, modes=system.modes)
    assert "jax" not in loaded_modules(f"from sixdof.cli import main\nassert main(['plot', {str(path)!r}]) == 0")
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["ke_distribution.png", "mode_shapes.png"]


@pytest.mark.slow  # 2 s each on the 2-core machine
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


@pytest.mark.slow  # 1-2 s each on the 2-core machine
@pytest.mark.parametrize("command", ["modes", "examples"])
def test_a_reader_that_went_away_ends_the_command_quietly(command, tmp_path):
    """``sixdof modes ... | head -1``: output to a closed pipe ends the command with 128 + SIGPIPE, as a shell
    reports ``yes | head``, and no message (nothing failed: the examples are copied in full)."""
    arguments = {"modes": ["modes", "scenarios/bridge_beam_traffic.toml"], "examples": ["examples", str(tmp_path)]}
    code = f"import sys\nfrom sixdof.cli import main\nsys.argv = ['sixdof', *{arguments[command]!r}]\nsys.exit(main())\n"
    process = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    process.stdout.close()  # before the command has written anything
    with process.stderr:
        err = process.stderr.read()
    assert process.wait() == EXIT_CLOSED_PIPE and err == ""
    if command == "examples":
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in Path("scenarios").iterdir())


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_a_broken_pipe_that_is_not_the_output_s_is_a_failed_write():
    """A BrokenPipeError with stdout and stderr still read (a socket's, say) is reported as any failed write."""
    code = ("import sys\nfrom sixdof import cli\nfrom sixdof.cli.commands import modes\n"
            "def broken(args, workers=None):\n    raise BrokenPipeError(32, 'Broken pipe')\n"
            "modes.main = broken\nsys.argv = ['sixdof', 'modes', 'scenarios/bridge_beam.toml']\n"
            "sys.exit(cli.main())\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == EXIT_CANNOT_WRITE
    assert result.stderr == "sixdof: could not write: Broken pipe; results already in place are unchanged\n"


@pytest.mark.slow  # 2 s on the 2-core machine
def test_only_the_command_s_own_process_collects_garbage_less_often():
    """The ``sixdof`` command collects every COLLECT_EVERY allocations; a program calling main() keeps its settings."""
    from sixdof.cli._process import COLLECT_EVERY

    code = ("import gc, sys\nfrom sixdof.cli import main\nbefore = gc.get_threshold()\n"
            "main(['modes', 'scenarios/bridge_beam.toml', '--json'])\nlibrary = gc.get_threshold()\n"
            "sys.argv = ['sixdof', 'modes', 'scenarios/bridge_beam.toml', '--json']\nmain()\n"
            "print(repr((before, library, gc.get_threshold())), file=sys.stderr)\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    before, library, command = ast.literal_eval(result.stderr)
    assert library == before and before[0] != COLLECT_EVERY
    assert command == (COLLECT_EVERY, *before[1:])


@pytest.mark.slow  # 1-2 s each on the 2-core machine
@pytest.mark.parametrize("user_flags", [None, "--xla_cpu_use_fusion_emitters=true --xla_dump_to=/dev/null"])
def test_only_the_command_s_own_process_compiles_without_xla_s_fusion_emitters(user_flags):
    """The ``sixdof`` command turns XLA's CPU fusion emitters off (they slow its compilation) and keeps any
    flag the user set, their own value of that one included; a program calling main() keeps XLA_FLAGS as it was."""
    env = {k: v for k, v in os.environ.items() if k != "XLA_FLAGS"}
    if user_flags is not None:
        env["XLA_FLAGS"] = user_flags
    code = ("import os, sys\nfrom sixdof.cli import main\nbefore = os.environ.get('XLA_FLAGS')\n"
            "main(['modes', 'scenarios/bridge_beam.toml', '--json'])\nlibrary = os.environ.get('XLA_FLAGS')\n"
            "sys.argv = ['sixdof', 'modes', 'scenarios/bridge_beam.toml', '--json']\nmain()\n"
            "print(repr((before, library, os.environ.get('XLA_FLAGS'))), file=sys.stderr)\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert result.returncode == 0, result.stderr
    before, library, command = ast.literal_eval(result.stderr)
    assert before == library == user_flags
    assert command == (user_flags or "--xla_cpu_use_fusion_emitters=false")


@pytest.mark.slow  # 3 s each on the 2-core machine
@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="glibc's allocator")
@pytest.mark.parametrize("user_setting", [None, "MALLOC_TRIM_THRESHOLD_", "GLIBC_TUNABLES"])
def test_the_command_s_own_process_keeps_the_memory_it_frees(user_setting):
    """As the ``sixdof`` command, arrays of a few MB allocated and freed again come back without page faults
    (glibc's defaults hand them back to the system and fault them in anew every time); a program calling main()
    and a user who set glibc's own variables keep their allocator as it was."""
    from sixdof.cli._process import MALLOC_VARIABLES

    env = {k: v for k, v in os.environ.items() if k not in (*MALLOC_VARIABLES, "GLIBC_TUNABLES")}
    if user_setting is not None:
        env[user_setting] = "glibc.malloc.trim_threshold=131072" if user_setting == "GLIBC_TUNABLES" else "131072"
    churn = ("import resource, numpy as np\n"
             "def faults():\n"
             "    for _ in range(13):  # six arrays of 3.2 MB at a time, then none; counted after three rounds\n"
             "        if _ == 3:\n"
             "            before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt\n"
             "        arrays = [np.ones(400_000) for _ in range(6)]\n"
             "        del arrays\n"
             "    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before\n")

    def faults(call: str) -> int:
        result = subprocess.run([sys.executable, "-c", f"import sys\nfrom sixdof.cli import main\n{churn}{call}\n"
                                 "print(faults(), file=sys.stderr)"], capture_output=True, text=True, env=env)
        assert result.returncode == 0, result.stderr
        return int(result.stderr.strip().splitlines()[-1])

    pages = 10 * 6 * 400_000 * 8 // 4096  # every array's pages, every round
    library = faults("main(['modes', 'scenarios/bridge_beam.toml', '--json'])")
    command = faults("sys.argv = ['sixdof', 'modes', 'scenarios/bridge_beam.toml', '--json']\nmain()")
    assert library > pages // 2
    if user_setting is None:
        assert command < pages // 100
    else:
        assert command > pages // 2


@pytest.mark.slow  # 3 s each on the 2-core machine
@pytest.mark.parametrize("user_setting", [None, "OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"])
def test_commands_drawing_in_workers_run_blas_on_one_thread_unless_the_user_chose(tmp_path, user_setting):
    """``run``, ``validate`` and ``plot`` as the ``sixdof`` command set OpenBLAS to one thread before NumPy loads
    (the figure workers take the other cores); a program calling main(), another command, or a user who set a
    thread count keeps its own."""
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    if user_setting is not None:
        env[user_setting] = "2"
    missing = str(tmp_path / "missing.h5")

    def seen(code: str):
        result = subprocess.run([sys.executable, "-c", "import os, sys\nfrom sixdof.cli import main\n" + code],
                                capture_output=True, text=True, env=env)
        return ast.literal_eval(result.stderr.strip().splitlines()[-1])

    # The command first: main() as the command ends the process without the exit handlers registered before
    # it, and the library call's figure workers leave a folder for multiprocessing's own handler to remove.
    other, library = seen("sys.argv = ['sixdof', 'modes', 'scenarios/bridge_beam.toml', '--json']\nmain()\n"
                          f"other = os.environ.get('OPENBLAS_NUM_THREADS')\nmain(['plot', {missing!r}])\n"
                          "print(repr((other, os.environ.get('OPENBLAS_NUM_THREADS'))), file=sys.stderr)")
    assert library == other == env.get("OPENBLAS_NUM_THREADS")
    numpy_before, command, threads = seen(
        f"sys.argv = ['sixdof', 'plot', {missing!r}]\nnumpy_before = 'numpy' in sys.modules\nmain()\n"
        "import numpy\nnumpy.ones((500, 500)) @ numpy.ones((500, 500))\n"
        "print(repr((numpy_before, os.environ.get('OPENBLAS_NUM_THREADS'), len(os.listdir('/proc/self/task')))), "
        "file=sys.stderr)")
    assert not numpy_before
    if user_setting is None:
        assert command == "1" and threads == 1  # OpenBLAS read it when NumPy loaded: no thread besides this one
    else:
        assert command == env.get("OPENBLAS_NUM_THREADS")


def test_examples_are_copied_runnable_and_never_overwritten(tmp_path, capsys):
    from sixdof.io.scenario import load_scenario

    folder = tmp_path / "mine"
    assert main(["examples", str(folder)]) == 0
    repository = Path("scenarios")
    bundled = sorted(p.relative_to(repository).as_posix() for p in repository.rglob("*") if p.suffix in (".toml", ".csv", ".uff", ".json"))
    copied = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())
    assert copied == bundled and "bridge_beam_traffic.toml" in copied
    assert all((folder / name).read_bytes() == (repository / name).read_bytes() for name in copied)
    assert load_scenario(folder / "cabinet_earthquake.toml").excitation is not None  # reads its CSV beside it
    capsys.readouterr()
    (folder / "bridge_beam.toml").write_text("# my edits\n")
    (folder / "machine_unbalance.toml").unlink()
    assert main(["examples", str(folder)]) == 2
    err = capsys.readouterr().err
    assert "none is overwritten" in err and "bridge_beam.toml" in err
    assert (folder / "bridge_beam.toml").read_text() == "# my edits\n"
    assert not (folder / "machine_unbalance.toml").exists()  # nothing copied at all


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_a_sweep_shows_its_progress(capsys):
    from sixdof.analysis.batch import make_variants, run_batch
    from sixdof.analysis.direct import SimulationSettings
    from sixdof.excitation import Excitation, Harmonic, Load

    system = bridge("equal")
    variants = make_variants(system, stiffness_factor=np.random.default_rng(1).uniform(0.9, 1.1, (5, 4, 3)))
    excitation = Excitation(loads=(Load("traffic", point=[0.0, 5.0, 0.0], force=[0.0, 0.0, 1e4],
                                        signal=Harmonic(f_hz=3.0)),))
    run_batch(system, variants, excitation, SimulationSettings(duration=0.5, sample_rate_hz=200.0), chunk_size=2,
              cross_check=2, progress="text")
    err = capsys.readouterr().err
    assert "sweep (exact engine): 5 / 5 variants (100%)\n" in err
    assert err.endswith("cross-check (diffrax): 2 / 2 variants (100%)\n")
    assert "sweep (exact engine): 1 / 5 variants (33%)" in err  # after the first of 3 chunks


def test_the_damping_ratios_say_what_they_include():
    from sixdof import Rayleigh
    from sixdof.io.report import damping_note

    assert "no viscous damping is given" in damping_note(bridge())
    note = damping_note(bridge(((1e4, 1e4, 2e4),) * 4, rayleigh=Rayleigh(alpha=0.1, beta=0.0))).replace("\n", " ")
    assert "from mount dashpots + Rayleigh damping, added together" in note and "loss factors" not in note
    note = damping_note(bridge(((1e4, 1e4, 2e4),) * 4, loss_factor=(0.1, 0.1, 0.1)))
    assert "from mount dashpots;" in note and "not the mounts' loss factors" in note.replace("\n", " ")


@pytest.mark.slow  # 1-2 s on the 2-core machine
def test_plot_and_export_of_a_damaged_results_file_fail_in_one_line(tmp_path, capsys):
    """200 KB of random bytes over the middle of a results file: exit 2, one line naming the file, nothing drawn
    or exported (before checksums: plotted and exported with 2.7e306 and NaN, exit 0)."""
    path = tmp_path / "run" / "results.h5"
    write_results(path, **run_parts())
    size = path.stat().st_size
    with open(path, "r+b") as f:
        f.seek(size // 2 - 100_000)
        f.write(np.random.default_rng(45).bytes(200_000))
    for command in (["plot", str(path)], ["export", str(path), "--format", "csv"]):
        assert main(command) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("sixdof: error: results: expected an undamaged results file")
        assert str(path) in err[0]
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == ["results.h5"]


@pytest.mark.slow  # 2 s on the 2-core machine
def test_modes_and_run_mark_modes_without_an_oscillating_pole_overdamped(tmp_path, capsys):
    """Two modes of the heavily damped box have no complex pole (tests/test_model.py checks this against the
    state matrix's eigenvalues): the modes table, the run's and summary.md say "overdamped" there, never the
    diagonal approximation's 83 % or 90 %, and the JSON gives null."""
    from sixdof.analysis.statespace import damping_ratios, modal_damping_ratios

    system = heavily_damped_box()
    zeta, approx = damping_ratios(system.C, system.modes), modal_damping_ratios(system.C, system.modes)
    overdamped = np.flatnonzero(np.isinf(zeta))
    assert overdamped.size == 2
    scenario = tmp_path / "heavy.toml"
    scenario.write_text('name = "heavy"\n' + heavily_damped_box_toml()
                        + '[[loads]]\nname = "tap"\npoint = [0.0, 0.0, 0.0]\nforce = [10.0, 10.0, 10.0]\n'
                        'signal = { kind = "half_sine", start = 0.0, duration = 0.005 }\n'
                        "[simulation]\nduration = 0.05\nsample_rate_hz = 2000.0\n")

    def zeta_cells(text):
        rows = [line.split("|") for line in text.splitlines() if line.startswith("| ")]
        first = next(i for i, r in enumerate(rows) if r[1].strip() == "mode")
        return [r[-2].strip() for r in rows[first + 1:first + 7]]

    assert main(["modes", str(scenario)]) == 0
    out = capsys.readouterr().out
    assert main(["run", str(scenario), "--out", str(tmp_path), "--quiet"]) == 0
    printed = capsys.readouterr().out
    for text in (out, printed, (tmp_path / "heavy" / "summary.md").read_text()):
        cells = zeta_cells(text)
        assert [cells[j] for j in overdamped] == ["overdamped", "overdamped"]
        for j in overdamped:
            assert f"{100 * approx[j]:.2f}" not in text
        for j in set(range(6)) - set(overdamped):
            assert cells[j] == f"{100 * zeta[j]:.2f}"
    assert main(["modes", str(scenario), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [data["damping_ratio"][j] for j in overdamped] == [None, None] and data["rigid_body_modes"] == []
