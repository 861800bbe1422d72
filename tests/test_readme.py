"""The README's Python examples run as written, and every scenario it lists exists and loads."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from sixdof import load_scenario

README = Path(__file__).resolve().parents[1] / "README.md"


@pytest.mark.slow  # over 10 s on the 2-core machine
@pytest.mark.parametrize("code", re.findall(r"```python\n(.*?)```", README.read_text(), re.S))
def test_python_examples_run(code, tmp_path):
    """Each block runs saved as a script and run from the repository, warnings as errors: as a reader who
    copies it runs it (a sweep's worker processes import the script again, which exec() never shows)."""
    script = tmp_path / "example.py"
    script.write_text(code)
    result = subprocess.run([sys.executable, "-W", "error", str(script)], cwd=README.parent, capture_output=True,
                            text=True)
    assert result.returncode == 0, result.stderr


@pytest.mark.parametrize("name", re.findall(r"^\| `(\w+\.toml)` \|", README.read_text(), re.M))
def test_listed_scenarios_load(name):
    scenario = load_scenario(README.parent / "scenarios" / name)
    assert scenario.description


def test_quick_start_installs_the_package_alone_and_tests_with_their_extra():
    """The run command installs sixdof without the test extra (pytest, Dask, the peer libraries: hundreds of MB
    a user running one example does not need); the test command installs the test extra and runs pytest as CI
    does (the last line of .ci/run)."""
    first_block = re.search(r"```bash\n(.*?)```", README.read_text(), re.S).group(1).splitlines()
    run, test = first_block
    assert re.search(r'pip install -e \.(\s|$)', run) and "[test]" not in run and "sixdof run scenarios/" in run
    ci = (README.parent / ".ci" / "run").read_text().strip().splitlines()[-1]
    assert ci.startswith("python -m pytest")
    assert test.startswith('pip install -e ".[test]" && ') and test.endswith(f"&& {ci}")
