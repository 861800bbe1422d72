"""``report.html`` (issue 49, items 4 and 6): one self-contained page per run, parsed back with the standard
library's HTML parser (every figure of the folder embedded byte for byte, nothing referenced outside the file,
the scenario's text and the sections present) and rendered by a real browser (headless Chromium) where one is
installed."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from html_pages import check_report, parsed, section
from sixdof.io.html_report import FIGURE_CAPTIONS, REPORT, embeddable, markdown_html, report_html, run_checks
from sixdof.plots import FIGURES
from sixdof.workflows.run import run_scenario

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "bridge_beam_traffic.toml"
SECTIONS = ["Summary", "Model", "Figures", "Checks", "Scenario"]


@pytest.fixture(scope="module")
def outcome(tmp_path_factory):
    results, folder = run_scenario(SCENARIO, tmp_path_factory.mktemp("out"), progress=False, log=lambda *_: None)
    return results, folder, (folder / REPORT).read_text(encoding="utf-8")


@pytest.mark.slow  # 4 s on the 2-core machine
def test_every_figure_is_in_the_report_and_nothing_outside_it(outcome):
    _, folder, _ = outcome
    page = check_report(folder)
    assert len([tag for tag, _ in page.tags if tag == "img"]) == len(list(folder.glob("*.png"))) >= 6


@pytest.mark.slow  # the run it reads: 4 s on the 2-core machine
def test_the_report_holds_the_sections_the_checks_and_the_scenario_itself(outcome):
    results, folder, text = outcome
    page = parsed(text)
    assert page.texts["h1"] == [results.name]
    assert page.texts["h2"] == SECTIONS
    summary = (folder / "summary.md").read_text(encoding="utf-8")
    headings = [line.lstrip("#").strip() for line in summary.splitlines()[1:] if line.startswith("## ")]
    assert "Natural frequencies" in headings and "Figures" in headings
    assert [h for h in headings if h != "Figures"] == [h for h in page.texts["h3"] if h not in ("Body", "Mounts")]
    assert SCENARIO.read_text(encoding="utf-8") in page.texts["pre"]  # unescaped by the parser: the file itself
    cells = page.texts["td"]
    verdict = cells[cells.index("direct solve against modal superposition") + 2]
    assert verdict == ("PASS" if results.agreement.ok else "FAIL") == "PASS"
    model = section(folder, "model")
    header = next(h for h in model.texts["th"] if h.startswith("stiffness"))
    per = {"[N/m]": 1.0, "[kN/m]": 1e3, "[MN/m]": 1e6}[header.split()[-1]]
    for mount in results.system.mounts:  # the model's table: each mount's stiffness as the scenario gives it
        row = model.texts["td"].index(mount.name)
        assert model.texts["td"][row + 2] == ", ".join(f"{v / per:.4g}" for v in mount.stiffness)
    assert f"{results.system.body.mass:.6g} kg" in model.texts["td"]
    captions = page.texts["figcaption"]
    assert len(captions) == len(list(folder.glob("*.png")))
    assert all(FIGURE_CAPTIONS[Path(c.split(":")[0]).stem] in c for c in captions)


def test_every_figure_of_a_run_has_its_sentence():
    assert {Path(name).stem for name, *_ in FIGURES} <= set(FIGURE_CAPTIONS)


def test_markdown_tables_paragraphs_and_escaping():
    text = ("# Title\n\nSome prose wrapped\nover two lines & <more>:\n| DOF | peak |q'| | at t [s] |\n"
            "|-----|----------:|---------:|\n| x   |    1 mm   |     0.5  |\n\n- one\n- two `a<b`\n")
    page = parsed(markdown_html(text, heading_shift=1))
    assert page.texts["h2"] == ["Title"]
    assert page.texts["p"] == ["Some prose wrapped over two lines & <more>:"]
    assert page.texts["th"] == ["DOF", "peak |q'|", "at t [s]"]  # the cell's pipes kept: cut at the rule's
    assert page.texts["td"] == ["x", "1 mm", "0.5"]
    right = [attrs.get("class") for tag, attrs in page.tags if tag == "td"]
    assert right == [None, "r", "r"]
    assert "&lt;more&gt;" in markdown_html(text) and "<code>a&lt;b</code>" in markdown_html(text)
    assert markdown_html("- a\n- b\nAfter.") == "<ul>\n<li>a</li>\n<li>b</li>\n</ul>\n<p>After.</p>"


def test_a_table_whose_rows_are_set_apart_stays_one_table_and_two_tables_stay_two():
    spaced = "| a | b |\n\n|---|--:|\n\n| 1 | 2 |\n\n| 3 | 4 |\n\nAfter."
    page = parsed(markdown_html(spaced))
    assert [tag for tag, _ in page.tags].count("table") == 1 and page.texts["td"] == ["1", "2", "3", "4"]
    assert page.texts["p"] == ["After."]
    two = "| a | b |\n|---|--:|\n| 1 | 2 |\n\n| c | d |\n|---|--:|\n| 3 | 4 |\n"
    page = parsed(markdown_html(two))
    assert [tag for tag, _ in page.tags].count("table") == 2 and page.texts["th"] == ["a", "b", "c", "d"]


def test_a_failed_check_and_a_warning_read_as_such():
    agreement = SimpleNamespace(worst=3e-5, worst_dof="rz", tolerance=1e-6, ok=False)
    check = SimpleNamespace(violations=("mount 2: deflection 12 mm beyond its max_deflection 10 mm",))
    results = SimpleNamespace(agreement=agreement, energy=None, refined=None, frf=None, mount_check=check,
                              random=None, records_check=None, validation=None, contacts=None,
                              notes=("something to know",))
    checks = run_checks(results)
    assert [c.verdict for c in checks] == ["FAIL", "FAIL", "warning"]
    assert "3.00e-05 (rz)" in checks[0].result and checks[1].result == check.violations[0]
    page = parsed(report_html("t", "# t\n", checks=checks))
    assert page.texts["td"][2::3] == ["FAIL", "FAIL", "warning"]


def test_a_figure_is_shown_once_from_its_png_else_its_svg(tmp_path):
    (tmp_path / "bode.png").write_bytes(b"\x89PNG fake")
    (tmp_path / "bode.svg").write_text("<svg/>")
    (tmp_path / "srs.svg").write_text("<svg/>")
    (tmp_path / "srs.pdf").write_bytes(b"%PDF")
    (tmp_path / "mac.pdf").write_bytes(b"%PDF")
    shown = embeddable(sorted(tmp_path.iterdir()))
    assert [p.name for p in shown] == ["bode.png", "srs.svg"]
    page = parsed(report_html("t", "", figures=sorted(tmp_path.iterdir())))
    sources = [attrs["src"] for tag, attrs in page.tags if tag == "img"]
    assert [s.split(";")[0] for s in sources] == ["data:image/png", "data:image/svg+xml"]


def _browser() -> str | None:
    return shutil.which("chromium") or next((p for p in ("/usr/bin/chromium",) if Path(p).exists()), None)


@pytest.mark.slow  # 2 s on the 2-core machine
@pytest.mark.skipif(_browser() is None, reason="no Chromium installed (.ci/run installs Debian's chromium where "
                                               "apt-get may run; elsewhere: apt-get install chromium)")
def test_chromium_renders_the_report(outcome, tmp_path):
    from PIL import Image  # noqa: PLC0415 (matplotlib's own dependency, for the screenshot's pixels)

    _, folder, _ = outcome
    shot = tmp_path / "report.png"
    subprocess.run([_browser(), "--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars",
                    f"--screenshot={shot}", "--window-size=1280,2000", (folder / REPORT).as_uri()],
                   check=True, capture_output=True, timeout=120, cwd=tmp_path)
    with Image.open(shot) as image:
        assert image.size == (1280, 2000)
        pixels = np.asarray(image.convert("RGB"), dtype=int)
    ink = np.any(pixels < 200, axis=2)  # text, rules and table borders
    assert 0.01 < ink.mean() < 0.5  # rendered: neither a blank page nor a black one
    assert ink[:, :640].mean() > 0.01 and ink[:1000].mean() > 0.01 and ink[1000:].mean() > 0.01
    tinted = (pixels[..., 2] - pixels[..., 0]) > 10  # the table headers' and links' blue: the style applied
    assert tinted.mean() > 0.001
