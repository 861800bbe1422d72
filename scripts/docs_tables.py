"""An mkdocs hook (``hooks:`` in mkdocs.yml): a pipe escaped inside a table cell's code reads as a pipe.

The pages' tables follow GitHub's syntax, where ``\\|`` is a literal pipe in a cell, code spans included
(`` `--format uff58\\|csv` ``), so that they read right on GitHub too. Python-Markdown's tables take ``\\|`` as a
pipe for splitting the cells but leave the backslash inside code; this puts the pipe back, there alone.
"""

import re

_CODE = re.compile(r"<code>(.*?)</code>", re.S)


def on_page_content(html, **_):
    """mkdocs' page-content event: ``\\|`` inside each ``<code>`` element becomes ``|``."""
    return _CODE.sub(lambda m: "<code>" + m.group(1).replace("\\|", "|") + "</code>", html)
