"""An mkdocs hook (``hooks:`` in mkdocs.yml): the docstrings' Sphinx roles read as names, linked where they can be.

sixdof's docstrings cross-reference in Sphinx's way (``:func:`~sixdof.analysis.frf.receptance.receptance```),
which mkdocstrings leaves as it is: the API page would show ``:func:receptance``. Each role becomes its
name in code (``~`` keeping the last component, as Sphinx does), wrapped in an optional cross-reference
that mkdocs-autorefs turns into a link when the name is an object the site documents (fully qualified
names) and leaves as plain code otherwise, without a warning.
"""

import re

_ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|attr|data|exc|obj|const):<code>(~?)([\w.]+)(\(\))?</code>")


def _name(match: re.Match) -> str:
    short, target = match.group(1) == "~", match.group(2).lstrip(".")
    title = (target.rsplit(".", 1)[-1] if short else target) + (match.group(3) or "")
    return f'<autoref identifier="{target}" optional><code>{title}</code></autoref>'


def on_page_content(html, **_):
    """mkdocs' page-content event: each ``:role:<code>name</code>`` becomes the name, cross-referenced."""
    return _ROLE.sub(_name, html)
