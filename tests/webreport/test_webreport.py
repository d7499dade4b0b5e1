"""report.html of a study and the compare page: self-contained, the same numbers as the
tables, a card per exported design, progress lines, the Python entry point for results
(issue "A report a designer opens in the browser"). The browser checks are in
test_report_browser.py."""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest
from conftest import MECH_DIR
from typer.testing import CliRunner

import pkmlab
from pkmlab.cli import app
from pkmlab.webreport import compare_html


def page_json(html: str, element_id: str):
    m = re.search(rf'<script type="application/json" id="{element_id}">(.*?)</script>', html,
                  re.S)
    assert m, element_id
    return json.loads(m.group(1))


def test_run_writes_a_self_contained_report(tiny_report):
    out, _ = tiny_report
    html = (out / "report.html").read_text()
    # nothing is fetched: no external script, style, image or frame
    tags = re.findall(r"<(script|link|img|iframe|source)\b[^>]*>", html)
    assert tags and not re.search(r"<(script|img|iframe|source)\b[^>]*\bsrc=[\"'](?!data:)",
                                  html)
    assert "<link" not in html and "@import" not in html
    assert re.search(r"plotly\.js v\d", html)                 # the library is embedded
    assert 'id="pareto-matrix"' in html and 'id="pareto-parcoords"' in html
    assert "(cm³)" in html and "(mm)" in html                  # axes carry units


def test_report_data_holds_the_same_numbers_as_pareto_csv(tiny_report):
    """Golden check: every pareto.csv row is in the page's data with the same values."""
    out, _ = tiny_report
    data = page_json((out / "report.html").read_text(), "pkmlab-data")
    with open(out / "pareto.csv") as fh:
        table = list(csv.DictReader(fh))
    assert table and data["pareto"] == [int(r["seq"]) for r in table]
    by_seq = {c["seq"]: c for c in data["candidates"]}
    metric_cols = {k: k.split(" (")[0] for k in table[0]
                   if k.split(" (")[0] in by_seq[int(table[0]["seq"])]["metrics"]}
    assert "dexterous_volume (cm³)" in metric_cols
    for row in table:
        c = by_seq[int(row["seq"])]
        assert c["pareto_rank"] == int(row["rank"]) and c["status"] == row["status"]
        for col, value in row.items():
            if col.startswith("design."):
                name = col[len("design."):].split(" (")[0]
                assert c["params"][name] == pytest.approx(float(value), rel=1e-12), col
        for col, name in metric_cols.items():
            want = row[col]
            got = c["metrics"][name]
            assert (got is None) if want == "" else got == pytest.approx(float(want),
                                                                          rel=1e-12), col
    # the chart plots exactly those values
    fig = page_json((out / "report.html").read_text(), "fig-pareto-matrix")
    pareto = [t for t in fig["data"] if t["name"] == "Pareto front"]
    assert sorted(pareto[0]["customdata"]) == sorted(data["pareto"])


def test_design_cards_differ_and_compare_against_the_baseline(tiny_report):
    out, _ = tiny_report
    html = (out / "report.html").read_text()
    index = json.loads((out / "designs" / "index.json").read_text())
    data = page_json(html, "pkmlab-data")
    n = len(index["designs"])
    assert n == min(3, len(data["pareto"])) >= 2
    assert len({e["seq"] for e in index["designs"]}) == n
    assert index["designs"][0]["why"].startswith("knee")
    for e in index["designs"]:
        card = html[html.index(f'id="design-{e["number"]}"'):]
        card = card[:card.index("</article>")]
        assert "Parameters against the baseline" in card and "Δ %" in card
        assert f'href="designs/{e["folder"]}/workspace.stl"' in card
        assert "data:image/png;base64," in card
        assert ("met" in card or "violated" in card) and "margin" in card
        fig = page_json(html, f"fig-design-{e['number']}")
        kinds = [t["type"] for t in fig["data"]]
        assert kinds[0] == "mesh3d" and kinds.count("scatter3d") >= 4
        names = " ".join(t.get("name", "") for t in fig["data"])
        assert all(w in names for w in ("base", "platform", "legs", "actuators"))
        folder = out / "designs" / e["folder"]
        assert {"workspace.stl", "workspace.ply", "workspace.glb", "mechanism.yaml",
                "design.json", "slices.png"} <= {p.name for p in folder.iterdir()}
    colours = data["colours"][str(index["designs"][0]["number"])]
    assert colours[0]["label"].startswith("worst κ") and len(colours) >= 2


def test_run_without_a_terminal_reports_progress(tiny_report):
    _, r = tiny_report
    lines = r.stderr.splitlines()
    assert any(re.match(r"pkmlab: evaluated \d+/~\d+ candidates", x) for x in lines)
    assert any(x.startswith("pkmlab: design 1/") for x in lines)
    assert any("report.html written" in x for x in lines)
    info = json.loads(r.stdout)
    assert info["report"].endswith("report.html")


def test_report_command_rebuilds_the_page_read_only(tiny_report, tmp_path):
    import shutil

    out, _ = tiny_report
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    (copy / "report.html").unlink()
    before = (copy / "evaluations.sqlite").read_bytes()
    r = CliRunner().invoke(app, ["report", str(copy), "--json"])
    assert r.exit_code == 0, r.output
    assert (copy / "report.html").is_file() and json.loads(r.stdout)["report"]
    assert (copy / "evaluations.sqlite").read_bytes() == before
    old = page_json((out / "report.html").read_text(), "pkmlab-data")
    new = page_json((copy / "report.html").read_text(), "pkmlab-data")
    assert new["candidates"] == old["candidates"] and new["designs"] == old["designs"]


def test_open_results_for_notebooks(tiny_report):
    out, _ = tiny_report
    res = pkmlab.open_results(out)
    assert len(res.evaluations) == len(res.records) == 9
    assert res.evaluations.units["dexterous_volume"] == "cm³"
    with open(out / "pareto.csv") as fh:
        table = list(csv.DictReader(fh))
    assert list(res.pareto["seq"]) == [int(r["seq"]) for r in table]
    np.testing.assert_allclose(res.pareto["dexterous_volume"],
                               [float(r["dexterous_volume (cm³)"]) for r in table])
    np.testing.assert_allclose(res.pareto["design.link_length"],
                               [float(r["design.link_length (mm)"]) for r in table])
    assert res.pareto[0]["rank"] == 1 and "Table" in repr(res.pareto)
    d = res.designs[0]
    assert d.number == 1 and d.why.startswith("knee")
    assert isinstance(d.mechanism, pkmlab.Mechanism)
    assert d.workspace().volume / 1e3 == pytest.approx(d.metrics["dexterous_volume"])
    assert d.mesh() is not None and "workspace.stl" in d.files
    assert res.mechanism(d.seq) == d.mechanism
    assert pkmlab.open_results(out / "pareto.csv").path == out
    with pytest.raises(pkmlab.ParameterError):
        pkmlab.open_results(out / "designs")
    assert "<table>" in res.evaluations._repr_html_()


def test_compare_html_overlays_the_designs(tmp_path):
    from pkmlab.study.compare import compare_designs

    a = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
    b = pkmlab.load_mechanism(MECH_DIR / "paradex-6pus.yaml")
    rows = compare_designs([("hopkins", a), ("paradex", b)], box_deg=5, resolution=10,
                           samples=2)
    path = compare_html(rows, tmp_path / "compare.html", box_deg=5)
    html = path.read_text()
    data = page_json(html, "pkmlab-data")
    assert [d["label"] for d in data["designs"]] == ["hopkins", "paradex"]
    assert data["designs"][1]["dexterous_volume_cm3"] == pytest.approx(
        rows[1]["dexterous_volume_cm3"])
    assert re.search(r"<small>\([+-]\d+\.\d %\)</small>", html)     # Δ % to the first
    for which in (0, 1):
        fig = page_json(html, f"fig-overlay-{which}")
        hulls = [t for t in fig["data"] if t["type"] == "mesh3d"]
        assert [t["name"] for t in hulls] == ["hopkins", "paradex"]
        assert len({t["color"] for t in hulls}) == 2
    assert len(re.findall(r'<img [^>]*src="data:image/png;base64,', html)) == 2
    assert not re.search(r"<script\b[^>]*\bsrc=", html)
    with pytest.raises(ValueError):
        compare_html([], tmp_path / "none.html")
    # a design without metrics (only a label) gets dashes, not a TypeError from the format
    bare = compare_html([rows[0], {"label": "bare"}], tmp_path / "bare.html", slices=False)
    cells = re.findall(r"<td[^>]*>(.*?)</td>", bare.read_text(), re.S)
    assert any(c.strip() == "—" for c in cells)


def test_data_is_strict_json_without_nan(tiny_report):
    out, _ = tiny_report
    text = (out / "report.html").read_text()
    m = re.search(r'id="pkmlab-data">(.*?)</script>', text, re.S)
    json.loads(m.group(1), parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}"))


def test_report_without_feasible_designs(tmp_path):
    """A study with no feasible candidate gets a page with the least-violating designs drawn
    (issue 26: before, no cards and nothing said which constraint failed)."""
    import yaml
    from conftest import TINY_STUDY

    data = {**TINY_STUDY, "constraints": [{"z_span": {"min": 1e6}}],
            "optimizer": {"method": "sobol", "samples": 2}, "output": str(tmp_path / "out")}
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    r = CliRunner().invoke(app, ["run", str(path), "--json"])
    assert r.exit_code == 0, r.output
    html = (tmp_path / "out" / "report.html").read_text()
    assert "No design was exported" not in html and 'id="design-1"' in html
    assert "Why candidates fail" in html and "violated: z_span ≥ 1e+06 by" in html
