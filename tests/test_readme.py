"""The README's Python example runs as written, and every scenario it lists exists and loads."""

import re
from pathlib import Path

import pytest

from sixdof import load_scenario

README = Path(__file__).resolve().parents[1] / "README.md"


@pytest.mark.parametrize("code", re.findall(r"```python\n(.*?)```", README.read_text(), re.S))
def test_python_examples_run(code):
    exec(compile(code, "README.md", "exec"), {})


@pytest.mark.parametrize("name", re.findall(r"^\| `(\w+\.toml)` \|", README.read_text(), re.M))
def test_listed_scenarios_load(name):
    scenario = load_scenario(README.parent / "scenarios" / name)
    assert scenario.description
