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

#: characters that make markup anywhere in a line (links and images need ``[``, autolinks and
#: HTML ``<``, which html.escape turns into an entity first)
_MD = re.compile(r"([\\`*_\[\]!|~])")
#: what makes a block only at the start of a line (a heading, a list item; a quote's ``>`` is
#: an entity already): the text is one line, so only at its start
_MD_START = re.compile(r"^(\s*)([-+#=]|\d+(?=[.)]))")


def plotly_text(value) -> str:
    """``value`` as literal text inside plotly's pseudo-HTML (hover labels, legend names)."""
    return html.escape(str(value), quote=False)    # plotly decodes &lt; &gt; &amp; only


def markdown_text(value) -> str:
    """``value`` as literal text in Markdown (a table cell, a heading, a paragraph): no link,
    image, emphasis, code, cell boundary, raw HTML, or (at its start) heading, list or quote;
    line breaks become spaces. Characters that are markup only in pairs or at a line's start
    (``-``, ``#``, ``(``) are left alone elsewhere, so ``EC-S-1k`` stays readable."""
    text = _MD.sub(r"\\\1", " ".join(str(value).split()))
    text = _MD_START.sub(lambda m: m.group(1) + (m.group(2) + "\\" if m.group(2)[0].isdigit()
                                                 else "\\" + m.group(2)), text)
    return html.escape(text, quote=False)
