"""The ``sixdof`` command tunes its own process (:mod:`sixdof.cli._process`); a program that imports sixdof and
calls the library keeps its process as it was."""

import ast
import os
import platform
import subprocess
import sys

import pytest

from sixdof.cli._process import MALLOC_VARIABLES

#: Allocates six arrays of 3.2 MB at a time and frees them, 13 times; the page faults of the last 10 rounds.
CHURN = """
import resource, numpy as np
def faults():
    for _ in range(13):
        if _ == 3:
            before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        arrays = [np.ones(400_000) for _ in range(6)]
        del arrays
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
"""
#: Every page of CHURN's arrays, every round counted: glibc's defaults fault in about all of them.
CHURN_PAGES = 10 * 6 * 400_000 * 8 // 4096


@pytest.mark.long  # over 10 s on the 2-core machine
def test_a_program_calling_the_library_keeps_its_process_settings():
    """``import sixdof``, parsing a bundled scenario, its modes and a simulation leave the garbage collector's
    thresholds, the environment (XLA_FLAGS, OpenBLAS's threads), the nice level and glibc's allocator (freed
    arrays of a few MB still go back to the system: their pages fault in again) as they were."""
    code = CHURN + (
        "import gc, os, sys\n"
        "before = (gc.get_threshold(), dict(os.environ), os.nice(0))\n"
        "from pathlib import Path\n"
        "import sixdof\n"
        "scenario = sixdof.load_scenario(Path(sixdof.__file__).parent / 'scenarios' / 'bridge_beam_traffic.toml')\n"
        "modes = sixdof.modal_analysis(scenario.system.M, scenario.system.K)\n"
        "response = sixdof.simulate(scenario.system, scenario.excitation,\n"
        "                           sixdof.SimulationSettings(duration=0.2, sample_rate_hz=1000.0))\n"
        "assert response.q.shape[0] == 201 and modes.frequency_hz.size == 6\n"
        "after = (gc.get_threshold(), dict(os.environ), os.nice(0))\n"
        "print(repr((before == after, 'sixdof.cli' in sys.modules, faults())), file=sys.stderr)\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in (*MALLOC_VARIABLES, "GLIBC_TUNABLES", "XLA_FLAGS")}
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert result.returncode == 0, result.stderr
    unchanged, cli_loaded, faults = ast.literal_eval(result.stderr.strip().splitlines()[-1])
    assert unchanged and not cli_loaded
    if platform.libc_ver()[0] == "glibc":
        assert faults > CHURN_PAGES // 2
