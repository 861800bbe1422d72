"""A results folder's ``report.html`` parsed with the standard library's HTML parser (:class:`Page`), and
the checks every report must pass (:func:`check_report`): each figure of the folder embedded byte for byte,
nothing referenced outside the file."""

from __future__ import annotations

import base64
from html.parser import HTMLParser
from pathlib import Path

from sixdof.io.html_report import REPORT


class Page(HTMLParser):
    """What a page holds: its tags with their attributes, the text of each heading, table cell and ``<pre>``."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict]] = []
        self.texts: dict[str, list[str]] = {}
        self._open: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag in ("h1", "h2", "h3", "h4", "pre", "td", "th", "figcaption", "p"):
            self._open.append(tag)
            self.texts.setdefault(tag, []).append("")

    def handle_endtag(self, tag):
        if self._open and self._open[-1] == tag:
            self._open.pop()

    def handle_data(self, data):
        if self._open:
            self.texts[self._open[-1]][-1] += data


def parsed(text: str) -> Page:
    page = Page()
    page.feed(text)
    page.close()
    return page


def check_report(folder: Path, figures: str = "*.png") -> Page:
    """``folder/report.html`` parsed, once checked: every file ``figures`` matches in ``folder`` is in it as a
    ``data:`` URI holding that file's bytes; no script, style sheet, frame or object; no ``src`` but a figure's
    ``data:`` URI and no ``href`` but a link to an ``id`` of the page; no ``url(``, ``@import`` or address."""
    text = (folder / REPORT).read_text(encoding="utf-8")
    page = parsed(text)
    images = {attrs["alt"]: attrs["src"] for tag, attrs in page.tags if tag == "img"}
    assert sorted(images) == sorted(p.name for p in folder.glob(figures))
    for name, src in images.items():
        kind = "svg+xml" if name.endswith(".svg") else "png"
        prefix = f"data:image/{kind};base64,"
        assert src.startswith(prefix) and base64.b64decode(src[len(prefix):]) == (folder / name).read_bytes()
    assert not [tag for tag, _ in page.tags if tag in ("script", "link", "iframe", "object", "embed", "base")]
    for tag, attrs in page.tags:
        for key in ("src", "href", "srcset", "data", "action", "poster"):
            value = attrs.get(key)
            if value is not None:  # a figure's data: URI, or a link to a section of the page itself
                assert value.startswith("data:image/") if key == "src" else value.startswith("#"), (tag, attrs)
    assert "url(" not in text and "@import" not in text and "http://" not in text and "https://" not in text
    anchors = {attrs["href"][1:] for tag, attrs in page.tags if tag == "a"}
    assert anchors <= {attrs.get("id") for _, attrs in page.tags}
    return page


def section(folder: Path, key: str) -> Page:
    """The section ``key`` (``summary``, ``model``, ``figures``, ``checks``, ``scenario``) of ``folder/report.html``,
    parsed."""
    text = (folder / REPORT).read_text(encoding="utf-8")
    return parsed(text.split(f'<section id="{key}">')[1].split("</section>")[0])
