"""An mkdocs hook (``hooks:`` in mkdocs.yml): the docstrings' Sphinx roles read as names, linked where they can be.

sixdof's docstrings cross-reference in Sphinx's way (``:func:`~sixdof.analysis.frf.receptance.receptance```),
which mkdocstrings leaves as it is: the API page would show ``:func:receptance``. Each role becomes its
name in code (``~`` keeping the last component, as Sphinx does), wrapped in an optional cross-reference
that mkdocs-autorefs turns into a link when the name is an object the site documents (fully qualified
names, or short ones the page documents one object for) and leaves as plain code otherwise, without a warning.
"""

import re

_ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|attr|data|exc|obj|const):<code>(~?)([\w.]+)(\(\))?</code>")


_ANCHOR = re.compile(r'id="(sixdof\.[\w.]+)"')


def on_page_content(html, **_):
    """mkdocs' page-content event: each ``:role:<code>name</code>`` becomes the name, cross-referenced.

    A name that is not fully qualified (``:func:`compare```, relative to its docstring's module) is looked
    up among the objects the page itself documents: the one whose qualified name ends with it, if only one does.
    """
    by_tail = {}
    for anchor in _ANCHOR.findall(html):
        for i in range(1, anchor.count(".") + 1):
            by_tail.setdefault(anchor.split(".", i)[-1], set()).add(anchor)

    def name(match: re.Match) -> str:
        short, target = match.group(1) == "~", match.group(2).lstrip(".")
        title = (target.rsplit(".", 1)[-1] if short else target) + (match.group(3) or "")
        found = by_tail.get(target, set())
        identifier = next(iter(found)) if not target.startswith("sixdof.") and len(found) == 1 else target
        return f'<autoref identifier="{identifier}" optional><code>{title}</code></autoref>'

    return _ROLE.sub(name, html)
