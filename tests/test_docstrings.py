"""Every public name (``sixdof.__all__``), and every result class a public function returns, carries a
numpydoc docstring the API reference can show, and the API reference shows it.

A small parser of numpydoc sections (a title underlined with dashes; entries ``name : type`` at the
section's indentation, their description indented below) is enough here: no docstring library needed.
"""

import dataclasses
import importlib
import importlib.util
import inspect
import re
from pathlib import Path

import pytest

import sixdof

ROOT = Path(__file__).resolve().parents[1]
API_PAGE = ROOT / "docs" / "reference" / "api.md"

_TITLE = re.compile(r"^([A-Z][A-Za-z ]+)\n-{3,}$", re.M)
_ENTRY = re.compile(r"^(\*{0,2}[A-Za-z_]\w*(?:\s*,\s*\*{0,2}[A-Za-z_]\w*)*)\s*(?::(.*))?$")
#: A unit in brackets (``[Hz]``, ``[N/m]``, ``[1]``) or words saying there is none.
_UNIT = re.compile(r"\[[^\]]+\]|dimensionless|\bunits?\b|\bratio\b|\bcount\b|\bindex\b", re.I)
#: Entry types that hold numbers, whose descriptions must state a unit.
_NUMERIC = re.compile(r"\b(floats?|complex|ndarray|array_like)\b(?! of (bool|int|str))")


def sections(doc: str) -> dict[str, list[tuple[str, str, str]]]:
    """The docstring's sections: title -> entries ``(name, type, description)``.

    Parameters
    ----------
    doc : str
        A docstring, cleaned (:func:`inspect.cleandoc`).

    Returns
    -------
    dict of str to list of (str, str, str)
        Each section's entries in order; the text before the first section under ``""``.
    """
    titles = list(_TITLE.finditer(doc))
    out = {"": [("", "", doc[: titles[0].start()] if titles else doc)]}
    for i, title in enumerate(titles):
        body = doc[title.end(): titles[i + 1].start() if i + 1 < len(titles) else len(doc)]
        entries = out.setdefault(title.group(1).strip(), [])
        for line in body.strip("\n").splitlines():
            if line and not line[0].isspace():
                match = _ENTRY.match(line)
                name, kind = (match.group(1), (match.group(2) or "").strip()) if match else (line, "")
                entries.append((name, kind, ""))
            elif line.strip() and entries:
                name, kind, text = entries[-1]
                entries[-1] = (name, kind, f"{text} {line.strip()}")
    return out


def documented(entries) -> set[str]:
    """Every name the entries document (``x, y : float`` documents both), stars dropped."""
    return {part.strip().lstrip("*") for name, _, _ in entries for part in name.split(",")}


def _resolve(name: str, namespace: dict):
    """The object a docstring's type names, looked up as the function's module sees it, else by its path."""
    if name in namespace:
        return namespace[name]
    module, _, attr = name.rpartition(".")
    try:
        return getattr(importlib.import_module(module), attr) if module else getattr(sixdof, name, None)
    except (ImportError, AttributeError):
        return None


def returned_classes() -> dict[str, type]:
    """The sixdof classes the public functions' Returns sections name, by name (those outside ``__all__``)."""
    found = {}
    for name in sixdof.__all__:
        obj = getattr(sixdof, name)
        if not inspect.isfunction(obj):
            continue
        for kind, _, _ in sections(inspect.getdoc(obj) or "").get("Returns", []):
            for word in re.findall(r"[A-Za-z_][\w.]*", kind):
                cls = _resolve(word, obj.__globals__)
                if (inspect.isclass(cls) and cls.__module__.startswith("sixdof.")
                        and cls.__name__ not in sixdof.__all__):
                    found[cls.__name__] = cls
    return found


def _public():
    for name in sixdof.__all__:
        obj = getattr(sixdof, name)
        if inspect.isclass(obj) or inspect.isfunction(obj):
            yield pytest.param(name, obj, id=name)
    for name, cls in returned_classes().items():
        yield pytest.param(name, cls, id=f"returned-{name}")


def _problems_function(obj) -> list[str]:
    doc = sections(inspect.getdoc(obj) or "")
    problems = []
    wanted = [p.name for p in inspect.signature(obj).parameters.values() if p.name not in ("self", "cls")]
    missing = [p for p in wanted if p not in documented(doc.get("Parameters", []))]
    if missing:
        problems.append(f"parameters not under Parameters: {missing}")
    if not (doc.get("Returns") or doc.get("Yields")):
        problems.append("no Returns section")
    return problems


def _problems_class(obj) -> list[str]:
    doc = sections(inspect.getdoc(obj) or "")
    if issubclass(obj, BaseException):   # errors and warnings: what they mean is enough
        return []
    entries = doc.get("Parameters", []) + doc.get("Attributes", [])
    if not entries:
        return ["no Parameters or Attributes section"]
    problems = []
    if dataclasses.is_dataclass(obj):
        fields = [f.name for f in dataclasses.fields(obj) if not f.name.startswith("_")]
        missing = [f for f in fields if f not in documented(entries)]
        if missing:
            problems.append(f"fields not under Parameters or Attributes: {missing}")
    return problems


def _problems_units(obj) -> list[str]:
    doc = sections(inspect.getdoc(obj) or "")
    return [f"{section} {name!r} ({kind}) states no unit" for section in ("Parameters", "Attributes", "Returns")
            for name, kind, text in doc.get(section, [])
            if _NUMERIC.search(re.sub(r"\{.*?\}", "", kind)) and not _UNIT.search(f"{kind} {text}")]


@pytest.mark.parametrize(("name", "obj"), list(_public()))
def test_public_name_has_numpydoc_docstring(name, obj):
    doc = inspect.getdoc(obj) or ""
    summary = sections(doc)[""][0][2].strip()
    where = f"{obj.__module__}.{obj.__qualname__}"
    assert summary, f"{where} has no docstring summary"
    problems = _problems_class(obj) if inspect.isclass(obj) else _problems_function(obj)
    problems += _problems_units(obj)
    assert not problems, f"{where}: " + "; ".join(problems)


def test_api_page_shows_every_public_name_and_returned_class():
    shown = set(re.findall(r"^::: sixdof\.[\w.]*\.(\w+)$", API_PAGE.read_text(), re.M))
    assert (set(sixdof.__all__) | set(returned_classes())) - shown == set()


def test_returned_classes_are_found():
    """The Returns sections' types resolve: the result classes receptance and mount_forces return among them."""
    found = returned_classes()
    assert {"FRF", "MountForces", "Agreement", "DesignMetrics"} <= set(found)
    assert found["FRF"].__module__.startswith("sixdof.analysis.frf")


def test_parser_reads_sections_entries_and_units():
    doc = inspect.cleandoc('''Summary.

        Parameters
        ----------
        f_hz, g : float
            Frequency [Hz].
        n : float
            How many.
        **parts
            Passed on.

        Returns
        -------
        ndarray
            Out [m].
        ''')
    got = sections(doc)
    assert got[""][0][2].strip() == "Summary."
    assert documented(got["Parameters"]) == {"f_hz", "g", "n", "parts"}
    assert [e[0] for e in got["Returns"]] == ["ndarray"]

    def f(f_hz, g, n, m, **parts):
        pass

    f.__doc__ = doc
    assert _problems_function(f) == ["parameters not under Parameters: ['m']"]
    assert _problems_units(f) == ["Parameters 'n' (float) states no unit"]


def test_roles_hook_turns_sphinx_roles_into_cross_references():
    spec = importlib.util.spec_from_file_location("docs_roles", ROOT / "scripts" / "docs_roles.py")
    roles = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(roles)
    html = ("see :func:<code>~sixdof.analysis.frf.receptance.receptance</code> and :class:<code>Modes</code>, "
            ":attr:<code>K</code>; <code>:func:</code> and :func: alone stay")
    assert roles.on_page_content(html) == (
        'see <autoref identifier="sixdof.analysis.frf.receptance.receptance" optional><code>receptance</code>'
        '</autoref> and <autoref identifier="Modes" optional><code>Modes</code></autoref>, '
        '<autoref identifier="K" optional><code>K</code></autoref>; <code>:func:</code> and :func: alone stay')

    page = ('<h3 id="sixdof.model.modes.Modes">Modes</h3><h3 id="sixdof.a.K"></h3><h3 id="sixdof.b.K"></h3>'
            ':class:<code>Modes</code> :attr:<code>K</code>')
    assert roles.on_page_content(page).endswith(   # the page's one Modes; two K: left unresolved
        '<autoref identifier="sixdof.model.modes.Modes" optional><code>Modes</code></autoref> '
        '<autoref identifier="K" optional><code>K</code></autoref>')
