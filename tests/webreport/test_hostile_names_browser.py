"""Hostile names in the report pages, in a real browser (issue 27, item 11): a link or markup
in a variable name, a reason or a design label is shown as text — never a live link — in the
hover labels of report.html, the legend of compare.html and the rows of compare.md."""

from __future__ import annotations

import pytest
from conftest import MECH_DIR
from test_report_browser import CHROMIUM, Page, browser, sync_playwright  # noqa: F401

from pkmlab.escaping import markdown_text, plotly_text

EVIL = '<a href="https://evil.example/x">click</a><b>bold</b>[md](https://evil.example/m)'


def test_escapes_are_literal_text():
    assert "<" not in plotly_text(EVIL) and "&lt;a href=" in plotly_text(EVIL)
    md = markdown_text(EVIL + " | cell")
    assert "](" not in md.replace("\\](", "") and "\\[" in md and "\\|" in md
    assert "<a" not in md


@pytest.mark.skipif(CHROMIUM is None or sync_playwright is None, reason="needs Chromium")
def test_hostile_labels_in_the_compare_legend_are_text(browser, tmp_path):  # noqa: F811
    import pkmlab
    from pkmlab.webreport import compare_html

    m = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
    level = pkmlab.workspace(m, "constant", None, 20.0)
    rows = [{"label": EVIL, "mechanism": m, "results": (level, level),
             "constant_volume_cm3": level.volume / 1e3},
            {"label": "plain", "mechanism": m, "results": (level, level),
             "constant_volume_cm3": level.volume / 1e3}]
    cols = [("constant_volume_cm3", "level workspace (cm³)", "{:.1f}")]
    page = Page(browser, compare_html(rows, tmp_path / "compare.html", box_deg=5,
                                      columns=cols, slices=False))
    try:
        pg = page.page
        assert page.problems == [] and page.network == []
        assert pg.locator('a[href*="evil"]').count() == 0
        assert pg.locator('svg a, .legend a').count() == 0
        legend = pg.locator("#scene-overlay-1 .legend").first.text_content()
        assert '<a href="https://evil.example/x">' in legend, legend
    finally:
        page.page.close()


@pytest.mark.skipif(CHROMIUM is None or sync_playwright is None, reason="needs Chromium")
def test_hostile_names_in_report_hover_labels_are_text(browser, tmp_path):  # noqa: F811
    """The Pareto chart's hover label of a candidate whose variable name and reason carry
    markup (the study page's own hover text, shown by plotly on hover)."""
    import plotly.graph_objects as go

    from pkmlab.study.definition import Objective
    from pkmlab.webreport import data as D
    from pkmlab.webreport.page import figure_json, render_page

    class V:
        name, unit = EVIL, "mm"

    class S:
        variables = [V()]
        objectives = [Objective("constant_volume", "maximize")]

    row = {"role": "candidate", "seq": 7, "params": {EVIL: 1.5}, "metrics":
           {"constant_volume": 2.0}, "reason": EVIL}
    hover = D._hover(S(), row, "invalid")
    fig = go.Figure(go.Scatter(x=[1], y=[1], mode="markers", hovertext=[hover],
                               hovertemplate="%{hovertext}<extra></extra>", name=plotly_text(EVIL)))
    path = render_page(tmp_path / "hover.html", "compare.html.j2", title="hover",
                       kind="test", data={"designs": [], "scenes": [{"div": "scene-overlay-1",
                                                                    "figure": "f"}]},
                       figures={"f": figure_json(fig)}, labels=["x"], table=[],
                       scenes=[{"div": "scene-overlay-1", "figure": "f", "title": "t",
                                "empty": []}], images=[], box_deg=5)
    page = Page(browser, path)
    try:
        pg = page.page
        pg.locator("#scene-overlay-1").scroll_into_view_if_needed()
        box = pg.locator("#scene-overlay-1 .nsewdrag").first.bounding_box()
        pts = pg.evaluate("""() => { const gd = document.getElementById('scene-overlay-1');
            const L = gd._fullLayout, r = gd.getBoundingClientRect();
            return [r.left + L.xaxis._offset + L.xaxis.l2p(1),
                    r.top + L.yaxis._offset + L.yaxis.l2p(1)]; }""")
        assert box is not None
        pg.mouse.move(*pts)
        pg.wait_for_selector(".hoverlayer .hovertext", timeout=10_000)
        text = pg.locator(".hoverlayer").first.text_content()
        assert '<a href="https://evil.example/x">' in text, text
        assert pg.locator('a[href*="evil"]').count() == 0
        assert pg.locator(".hoverlayer a").count() == 0
    finally:
        page.page.close()
