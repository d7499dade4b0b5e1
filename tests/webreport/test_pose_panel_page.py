"""The pose panel in a real study report (Chromium): a design card has one slider per free
coordinate, its table shows pkmlab's actuator values at the nominal pose and follows a slider,
and a task region that is a single point is drawn in the card's 3-D view and the panel's."""

from __future__ import annotations

import json
import re
import tempfile

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR
from test_report_browser import ARGS, CHROMIUM, pytestmark  # noqa: F401 - the skip marker
from typer.testing import CliRunner

import pkmlab
from pkmlab.cli import app

try:
    from playwright.sync_api import sync_playwright
except ImportError:  # pragma: no cover - depends on the environment
    sync_playwright = None

STUDY = {
    "study": "jog", "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
    "design": {"link_length": {"low": "215 mm", "high": "235 mm"}},
    "evaluate": {"task": {"shape": "box", "size": ["0 mm"] * 3, "frame": "nominal",
                          "box": ["1 deg"] * 3, "samples": 2}},
    "objectives": [{"maximize": "task_margin"}],
    "optimizer": {"method": "sobol", "samples": 2}, "seed": 1, "top": 1,
}


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    d = tmp_path_factory.mktemp("jog")
    (d / "study.yaml").write_text(yaml.safe_dump({**STUDY, "output": str(d / "out")}))
    r = CliRunner().invoke(app, ["run", str(d / "study.yaml"), "--json"])
    assert r.exit_code == 0, r.output
    return d / "out"


def _values(text: str) -> list[float]:
    return [float(v) for v in re.findall(r"(-?\d+\.\d+) mm", text)]


def test_panel_jogs_and_draws_a_point_task(report):
    html = (report / "report.html").read_text()
    folder = next(p for p in (report / "designs").iterdir() if p.is_dir())
    mech = pkmlab.load_mechanism(folder / "mechanism.yaml")
    fig = json.loads(re.search(r'id="fig-design-1">(.*?)</script>', html, re.S).group(1))
    task = [t for t in fig["data"] if t.get("name", "").startswith("task region")]
    assert len(task) == 1 and task[0]["mode"] == "markers"          # a point: one marker
    assert np.allclose([task[0]["x"][0], task[0]["y"][0], task[0]["z"][0]],
                       mech.nominal_pose[:3], atol=1e-9)
    with tempfile.TemporaryDirectory() as profile, sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(profile, executable_path=CHROMIUM, args=ARGS,
                                                   headless=True,
                                                   viewport={"width": 1400, "height": 1000})
        pg = ctx.new_page()
        errors = []
        pg.on("pageerror", lambda e: errors.append(str(e)))
        pg.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        pg.goto((report / "report.html").resolve().as_uri())
        pg.wait_for_selector("body[data-ready=true]", timeout=60_000)
        pg.click("[data-show-design='1']")
        sel = "#design-1 .pose-panel"
        labels = pg.eval_on_selector_all(sel + " .pose-slider span",
                                         "e => e.map(x => x.textContent)")
        assert labels == ["Δx (mm)", "Δy (mm)", "Δz (mm)", "Δθx (deg)", "Δθy (deg)", "Δθz (deg)"]
        got = _values(pg.inner_text(sel + " .pose-legs tbody"))
        assert np.allclose(got, mech.inverse(mech.nominal_pose).q[0], atol=0.006)
        pg.eval_on_selector(sel + " input[data-coordinate=z]",
                            "e => { e.value = 20; e.dispatchEvent(new Event('input')); }")
        X = mech.nominal_pose + np.array([0, 0, 20.0, 0, 0, 0])
        got = _values(pg.inner_text(sel + " .pose-legs tbody"))
        assert np.allclose(got, mech.inverse(X).q[0], atol=0.006)
        pg.locator(sel + " .pose-view").scroll_into_view_if_needed()
        pg.wait_for_selector(sel + "[data-drawn=true]", timeout=30_000)
        names = pg.eval_on_selector(sel + " .pose-view", "d => d.data.map(t => t.name)")
        assert any(n.startswith("task region") for n in names), names
        assert "κ = " in pg.inner_text(sel + " .pose-info")
        ctx.close()
    assert not errors, errors
