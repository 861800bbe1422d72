"""The documentation build's hooks (scripts/docs_tables.py, scripts/docs_gallery.py): what they put in the site."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def hook(name: str):
    """A hook module loaded from its file, as mkdocs loads it (scripts/ is no package)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_an_escaped_pipe_in_code_becomes_a_pipe_and_nowhere_else():
    html = (r"<td><code>--format uff58\|csv</code> or \| text</td>"
            "<pre><code>a \\| b\nc</code></pre>")
    assert hook("docs_tables").on_page_content(html) == (r"<td><code>--format uff58|csv</code> or \| text</td>"
                                                         "<pre><code>a | b\nc</code></pre>")


def test_the_gallery_page_shows_each_entry_and_its_figures_in_order(tmp_path):
    gallery = hook("docs_gallery")
    name = gallery.ENTRIES[0][0]
    (tmp_path / name).mkdir()
    for png in ("zzz_new.png", "bode.png", "mode_shapes.png"):
        (tmp_path / name / png).write_bytes(b"")
    page = gallery._page(tmp_path)
    assert page.startswith("# Gallery\n")
    assert f"    sixdof run scenarios/{name}.toml" in page
    images = [line for line in page.splitlines() if line.startswith("![")]
    # The library's order (modes first), then a figure the table of words does not know, under its own name.
    assert images == [f"![{gallery.WORDS['mode_shapes.png']}](gallery/{name}/mode_shapes.png)",
                      f"![{gallery.WORDS['bode.png']}](gallery/{name}/bode.png)",
                      f"![zzz new](gallery/{name}/zzz_new.png)"]
    assert {kind for _, kind, _ in gallery.ENTRIES} == {"run", "design", "correlate"}
    assert all((ROOT / "scenarios" / f"{n}.toml").is_file() for n, _, _ in gallery.ENTRIES)


def test_the_gallery_is_drawn_again_when_the_source_changes(tmp_path, monkeypatch):
    """The cache key is that of the package's source and the scenarios: the same for the same files, another for
    a changed module or scenario."""
    gallery = hook("docs_gallery")
    (tmp_path / "src" / "sixdof").mkdir(parents=True)
    (tmp_path / "scenarios").mkdir()
    module, scenario = tmp_path / "src" / "sixdof" / "a.py", tmp_path / "scenarios" / "b.toml"
    module.write_text("x = 1\n")
    scenario.write_text('name = "b"\n')
    monkeypatch.setattr(gallery, "ROOT", tmp_path)
    first = gallery._key()
    assert gallery._key() == first
    module.write_text("x = 2\n")
    second = gallery._key()
    scenario.write_text('name = "c"\n')
    assert len({first, second, gallery._key()}) == 3
