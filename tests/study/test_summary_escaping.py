"""Hostile strings in summary.md (issue 27, item 11): a study name, description, variable name,
choice value, note, reason or catalogue name holding a link, HTML or Markdown markup is written
escaped, so a Markdown renderer (markdown-it, the one rich uses to show summary.md on the
console; CommonMark with tables, as GitHub) shows it as text: no link, no HTML element, no
emphasis, no extra table cell."""

from __future__ import annotations

import types

import pytest

from pkmlab.escaping import markdown_text
from pkmlab.study.definition import Objective
from pkmlab.study.report import _summary

markdown_it = pytest.importorskip("markdown_it")

EVIL = ('<a href="https://evil.example/x">click</a><img src=x onerror=alert(1)>'
        '[md](https://evil.example/m) **bold** | cell ![i](https://evil.example/i.png)')


class _Var:
    unit = "mm"
    role = "geometry"
    kind = "choice"           # never on a bound of the design box

    def __init__(self, name):
        self.name = name

    def display(self, v):
        return v


class _Space:
    def baseline_values(self):
        return {EVIL: EVIL}


class _Study:
    name = EVIL
    description = "- " + EVIL
    variables = [_Var(EVIL)]
    objectives = [Objective("constant_volume", "maximize")]
    constraints = []
    top = 2
    space = _Space()
    evaluation = types.SimpleNamespace(task=None)     # no task: no placement or κ flags


def _render(text: str) -> str:
    return markdown_it.MarkdownIt("commonmark").enable("table").render(text)


def _records():
    ok = {"role": "candidate", "seq": 1, "status": "ok", "reason": "", "params": {EVIL: EVIL},
          "metrics": {"constant_volume": None}, "notes": {"constant_volume": EVIL}}
    bad = {"role": "candidate", "seq": 2, "status": "invalid", "reason": EVIL + "\nmore",
           "params": {EVIL: 1.5}, "metrics": {}, "notes": {}}
    base = {"role": "baseline", "seq": 0, "status": "invalid", "reason": EVIL,
            "params": {EVIL: 2.5}, "metrics": {}, "notes": {}}
    return [base, ok, bad], [ok]


def test_hostile_strings_in_summary_md_render_as_text():
    records, front = _records()
    text = _summary(_Study(), records, front, records[0])
    page = _render(text)
    # no element made from the user's strings: no link, image, emphasis, raw HTML; list items
    # only from pkmlab's own note lines (the description starting with "- " is not a list)
    for tag in ("<a ", "<img", "<strong>", "<em>"):
        assert tag not in page, (tag, page)
    own = [ln for ln in text.splitlines() if ln.startswith(("- baseline", "- #"))]
    assert own and page.count("<li>") == len(own), page
    assert not text.splitlines()[2].startswith("- ")       # the escaped description
    # the strings are there, as text (the renderer's entities for < and >)
    assert page.count("&lt;a href=&quot;https://evil.example/x&quot;&gt;click&lt;/a&gt;") >= 5
    assert page.count("[md](https://evil.example/m) **bold** | cell") >= 5
    # every table row keeps its cell count (a | in a name would add a cell)
    rows = [ln for ln in text.splitlines() if ln.startswith("| ")]
    head = rows[0].count(" | ")
    assert all(r.replace("\\|", "").count(" | ") == head for r in rows[:3]), rows[:3]


def test_markdown_text_keeps_ordinary_names_readable():
    assert markdown_text("EC-S-1k (left)") == "EC-S-1k (left)"
    assert markdown_text("- x") == "\\- x" and markdown_text("3. x") == "3\\. x"
    assert markdown_text("# x") == "\\# x" and markdown_text("a_b*c") == "a\\_b\\*c"
    assert _render(markdown_text("1) x")).strip() == "<p>1) x</p>"
