"""Escaping of user strings (study, variable and mechanism names, reasons, labels) for each
renderer they reach (issue 27): plotly's text (hover labels, legends, titles) is a subset of
HTML — ``<a href>``, ``<b>``, ``<br>`` are live markup — so a user string is entity-escaped
before it joins it (plotly shows ``&lt;`` as ``<``); Markdown tables escape the characters
that make links, emphasis, cells or HTML. The page itself is rendered by Jinja with
autoescaping (:mod:`.page`), which must get the raw string (not escaped twice)."""

from __future__ import annotations

import html
import re

__all__ = ["plotly_text", "markdown_text"]

_MD = re.compile(r"([\\`*_{}\[\]()#+!|~>-])")


def plotly_text(value) -> str:
    """``value`` as literal text inside plotly's pseudo-HTML (hover labels, legend names)."""
    return html.escape(str(value), quote=False)    # plotly decodes &lt; &gt; &amp; only


def markdown_text(value) -> str:
    """``value`` as literal text in a Markdown table cell: no link, emphasis, code, cell
    boundary or raw HTML; line breaks become spaces."""
    text = " ".join(str(value).split())
    return _MD.sub(r"\\\1", html.escape(text, quote=False))
