"""The README's and the documentation pages' Python examples run as written, every scenario they list exists and
loads, and the README stays a front page: short, its commands CI's, its links into the site alive."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from sixdof import load_scenario

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
#: Every page whose examples a reader copies: the README and the site's Markdown sources (docs/, mkdocs.yml).
PAGES = [README, *sorted((ROOT / "docs").rglob("*.md"))]


def blocks(pattern: str) -> list:
    """``pytest.param`` of each match of ``pattern`` in every page, named by page and number."""
    found = []
    for page in PAGES:
        for i, match in enumerate(re.findall(pattern, page.read_text(encoding="utf-8"), re.S | re.M), 1):
            found.append(pytest.param(match, id=f"{page.relative_to(ROOT)}:{i}"))
    return found


@pytest.mark.long  # over 10 s on the 2-core machine
@pytest.mark.parametrize("code", blocks(r"```python\n(.*?)```"))
def test_python_examples_run(code, tmp_path):
    """Each block runs saved as a script and run from the repository, warnings as errors: as a reader who
    copies it runs it (a sweep's worker processes import the script again, which exec() never shows)."""
    script = tmp_path / "example.py"
    script.write_text(code)
    result = subprocess.run([sys.executable, "-W", "error", str(script)], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_the_pages_hold_examples_and_scenario_lists():
    """The patterns above find what they are for (a page moved or reformatted would leave the tests nothing to
    run): the Python API guide's, the sweep guide's and the correlation guide's examples, and the bundled table."""
    ids = [p.id.split(":")[0] for p in blocks(r"```python\n(.*?)```")]
    assert {"docs/guides/python.md", "docs/guides/sweeps.md", "docs/guides/correlation.md"} <= set(ids)
    assert len(blocks(r"^\| `(\w+\.toml)` \|")) >= len(list((ROOT / "scenarios").glob("*.toml")))


@pytest.mark.parametrize("name", blocks(r"^\| `(\w+\.toml)` \|"))
def test_listed_scenarios_load(name):
    scenario = load_scenario(ROOT / "scenarios" / name)
    assert scenario.description


def test_quick_start_installs_the_package_alone_and_tests_with_their_extra():
    """The run command installs sixdof without the test extra (pytest, Dask, the peer libraries: hundreds of MB
    a user running one example does not need); the test command installs the test extra and runs pytest as CI
    does (.ci/run's pytest line)."""
    first_block = re.search(r"```bash\n(.*?)```", README.read_text(), re.S).group(1).splitlines()
    run, test = first_block
    assert re.search(r'pip install -e \.(\s|$)', run) and "[test]" not in run and "sixdof run scenarios/" in run
    ci = [line for line in (ROOT / ".ci" / "run").read_text().splitlines() if line.startswith("python -m pytest")]
    assert len(ci) == 1
    assert test.startswith('pip install -e ".[test]" && ') and test.endswith(f"&& {ci[0]}")


def test_the_readme_is_a_front_page_linking_into_the_site():
    """At most 10 KB (issue 50), and every relative link or image of it names a file of the repository, so that
    its links into docs/ work on GitHub as in a checkout; it says how to build and open the site."""
    text = README.read_text(encoding="utf-8")
    assert len(text.encode()) <= 10 * 1024
    targets = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text)
    local = [t for t in targets if "://" not in t]
    assert sum(t.startswith("docs/") for t in local) >= 10
    assert [t for t in local if not (ROOT / t).is_file()] == []
    assert 'pip install -e ".[docs]" && mkdocs build' in text and "site/index.html" in text


def test_every_page_is_in_the_site_navigation():
    """Each docs page is reachable from the site's menu (mkdocs only warns of a page left out of it); the
    gallery page is the build's own (scripts/docs_gallery.py)."""
    nav = set(re.findall(r":\s*(\S+\.md)\s*$", (ROOT / "mkdocs.yml").read_text(), re.M))
    pages = {str(p.relative_to(ROOT / "docs")) for p in PAGES[1:]}
    assert pages <= nav and nav - pages == {"gallery.md"}
