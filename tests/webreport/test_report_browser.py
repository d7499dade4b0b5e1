"""report.html and the compare page in a real browser: a headless Chromium from the OS packages
driven by Playwright (``make test`` installs Chromium when it is root; without a browser these
tests skip and say why).

Checked: no console error, no network request (every request is logged; name resolution is
disabled as well), the Pareto charts, the design cards and the 3-D canvas are there, clicking
a Pareto point opens its card, and the screenshots are not blank.
"""

from __future__ import annotations

import io
import os
import shutil
import tempfile

import numpy as np
import pytest
from conftest import MECH_DIR

try:
    from playwright.sync_api import sync_playwright
except ImportError:  # pragma: no cover - depends on the environment
    sync_playwright = None


def _chromium() -> str | None:
    for name in (os.environ.get("PKMLAB_CHROMIUM"), "chromium", "chromium-browser",
                 "google-chrome", "google-chrome-stable"):
        path = shutil.which(name) if name else None
        if path:
            return path
    return None


CHROMIUM = _chromium()
pytestmark = pytest.mark.skipif(
    CHROMIUM is None or sync_playwright is None,
    reason="browser tests need Chromium (apt-get install chromium; `make test` installs it "
           "when run as root) and Playwright (pip install -e '.[dev]'); found "
           f"chromium={CHROMIUM}, playwright={sync_playwright is not None}")

ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run",
        "--disable-default-apps", "--enable-unsafe-swiftshader", "--use-angle=swiftshader",
        "--host-resolver-rules=MAP * ~NOTFOUND"]


@pytest.fixture(scope="module")
def browser():
    with tempfile.TemporaryDirectory() as profile, sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(
            profile, executable_path=CHROMIUM, args=ARGS, headless=True,
            viewport={"width": 1400, "height": 1000})
        yield ctx
        ctx.close()


class Page:
    """A page with every console message, page error and request it made."""

    def __init__(self, ctx, path):
        self.page = ctx.new_page()
        self.console, self.errors, self.requests = [], [], []
        self.page.on("console", lambda m: self.console.append((m.type, m.text)))
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.on("request", lambda r: self.requests.append(r.url))
        self.url = path.resolve().as_uri()
        self.page.goto(self.url)
        self.page.wait_for_selector("body[data-ready=true]", timeout=60_000)

    @property
    def problems(self) -> list[str]:
        return self.errors + [text for kind, text in self.console if kind == "error"]

    @property
    def network(self) -> list[str]:
        return [u for u in self.requests if u != self.url and not u.startswith(("data:",
                                                                                "blob:"))]


@pytest.fixture(scope="module")
def report(browser, tiny_report):
    out, _ = tiny_report
    page = Page(browser, out / "report.html")
    yield page
    page.page.close()


def _not_blank(png: bytes, min_colours: int = 20) -> bool:
    from PIL import Image

    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=float)
    return img.std() > 10 and len(np.unique(img.reshape(-1, 3), axis=0)) >= min_colours


def test_the_report_loads_without_errors_or_network_requests(report):
    assert report.problems == []
    assert report.network == []


def test_pareto_charts_design_cards_and_3d_canvas_are_present(report):
    pg = report.page
    assert pg.locator("#pareto-matrix .main-svg").count() >= 1
    assert pg.locator("#pareto-matrix .scatterlayer .point").count() >= 9
    assert pg.locator("#pareto-parcoords .parcoords").count() >= 1 or \
        pg.locator("#pareto-parcoords canvas").count() >= 1
    assert pg.locator("article.design").count() == 3
    assert pg.locator("#design-1").is_visible() and not pg.locator("#design-2").is_visible()
    assert pg.locator("#scene-1 canvas").count() >= 1
    assert "(cm³)" in pg.locator("#pareto-matrix").inner_text()


def _point(pg, trace_name: str, which) -> tuple[float, float]:
    """Viewport position of a point of the first trace called ``trace_name`` (first panel)."""
    pg.locator("#pareto-matrix").scroll_into_view_if_needed()
    return pg.evaluate("""([name, which]) => {
        const gd = document.getElementById('pareto-matrix');
        const t = gd.data.find(d => d.name === name);
        const k = which.text !== undefined ? t.text.indexOf(which.text)
                                            : t.customdata.indexOf(which.seq);
        const L = gd._fullLayout;
        const xa = L['xaxis' + t.xaxis.slice(1)], ya = L['yaxis' + t.yaxis.slice(1)];
        const r = gd.getBoundingClientRect();
        return [r.left + xa._offset + xa.l2p(t.x[k]), r.top + ya._offset + ya.l2p(t.y[k])];
    }""", [trace_name, which])


def test_clicking_a_pareto_point_opens_its_card(report, tmp_path):
    pg = report.page
    # points are labelled by their evaluation number, "#seq" (one numbering everywhere)
    seq2 = pg.evaluate("window.pkmlab.data")["designs"][1]["seq"]
    x, y = _point(pg, "exported design (card)", {"text": f"#{seq2}"})
    pg.mouse.click(x, y)
    pg.wait_for_selector("#design-2", state="visible", timeout=10_000)
    assert not pg.locator("#design-1").is_visible()
    assert pg.locator("#tab-2").get_attribute("aria-selected") == "true"
    pg.wait_for_function("document.querySelector('#scene-2 canvas') !== null",
                         timeout=30_000)
    # a Pareto design that was not exported: a card built from the page's data
    data = pg.evaluate("window.pkmlab.data")
    exported = {d["seq"] for d in data["designs"]}
    other = next(s for s in data["pareto"] if s not in exported)
    x, y = _point(pg, "Pareto front", {"seq": other})
    pg.mouse.click(x, y)
    pg.wait_for_selector("#candidate-card", state="visible", timeout=10_000)
    assert pg.locator("#candidate-title").inner_text() == f"Design #{other}"
    assert pg.locator("#candidate-params tr").count() == 1 + 3
    assert report.problems == []


def test_screenshots_are_not_blank(report, tmp_path):
    pg = report.page
    pg.locator("#tab-1").click()
    pg.wait_for_function("document.querySelector('#scene-1 canvas') !== null")
    pg.evaluate("window.scrollTo(0, 0)")
    top = pg.screenshot(path=str(tmp_path / "report.png"))
    assert _not_blank(top, 200)
    scene = pg.locator("#scene-1").screenshot(path=str(tmp_path / "scene.png"))
    assert _not_blank(scene)


def test_the_compare_page_in_the_browser(browser, tmp_path):
    """The page of two designs' rows (real workspaces; the compare protocol's own numbers are
    checked in test_webreport.py)."""
    import pkmlab
    from pkmlab.webreport import compare_html

    rows = []
    for label, f in (("hopkins", "hopkins-williams-6psu"), ("paradex", "paradex-6pus")):
        m = pkmlab.load_mechanism(MECH_DIR / f"{f}.yaml")
        level = pkmlab.workspace(m, "constant", None, 10.0)
        dex = pkmlab.workspace(m, "dexterous",
                               pkmlab.OrientationSet.box(np.radians([5.0] * 3), samples=2), 10.0)
        rows.append({"label": label, "mechanism": m, "results": (level, dex),
                     "constant_volume_cm3": level.volume / 1e3,
                     "dexterous_volume_cm3": dex.volume / 1e3})
    columns = [("constant_volume_cm3", "level workspace (cm³)", "{:.1f}"),
               ("dexterous_volume_cm3", "dexterous ±5° (cm³)", "{:.2f}")]
    page = Page(browser, compare_html(rows, tmp_path / "compare.html", box_deg=5,
                                      columns=columns))
    try:
        assert page.problems == [] and page.network == []
        assert page.page.locator(".overlay canvas").count() >= 2
        assert _not_blank(page.page.locator("#scene-overlay-1").screenshot())
    finally:
        page.page.close()
