"""Issue 26 item 2: why designs fail. Each candidate's violated constraints with their margins
(column ``violated`` of evaluations.csv / pareto.csv and every design card), a tally per
constraint in summary.md and report.html, and the least-violating designs exported and drawn
when nothing is feasible. The margins are checked against the metric values read back from
evaluations.csv (min − value, to 4 significant digits as written)."""

from __future__ import annotations

import csv
import json

import pytest
from clihelp import cli, small_study

from pkmlab.study import load_study
from pkmlab.study.violations import least_violating, tally, violated_text, violations


def test_zero_feasible_study_says_why_and_exports_the_least_violating(tmp_path, capsys):
    path = small_study(tmp_path, constraints=[{"constant_volume": {"min": 1.0e12}}], top=2)
    code, o, e = cli(capsys, "run", path)
    assert code == 0, e
    out = tmp_path / "out"
    with (out / "evaluations.csv").open() as f:
        rows = list(csv.DictReader(f))
    cand = [r for r in rows if r["role"] == "candidate"]
    assert cand and all(r["violated"].startswith("constant_volume ≥ 1e+12 by ") for r in cand)
    label = next(k for k in rows[0] if k.startswith("constant_volume"))
    for r in cand:
        amount = float(r["violated"].rsplit("by ", 1)[1])
        assert amount == pytest.approx(1.0e12 - float(r[label]), rel=1e-3)
    summary = (out / "summary.md").read_text()
    # the constraint's metric name is escaped for Markdown (renders as constant_volume)
    assert f"| constant\\_volume ≥ 1e+12 | {len(cand)} | {len(cand)} |" in summary
    assert "No feasible design. The 2 least violating" in summary
    index = json.loads((out / "designs" / "index.json").read_text())
    assert len(index["designs"]) == 2
    assert all(d["pareto_rank"] == 0 and d["why"].startswith("least violating")
               for d in index["designs"])
    # the least violating are those with the largest volume (the one constraint, min bound)
    vols = sorted(float(r[label]) for r in cand)
    chosen = {d["seq"] for d in index["designs"]}
    got = sorted(float(r[label]) for r in cand if int(r["seq"]) in chosen)
    assert got == vols[-2:]
    html = (out / "report.html").read_text()
    assert "Why candidates fail" in html and "No candidate is feasible" in html
    assert html.count("violated: constant_volume ≥ 1e+12 by") >= 2     # on each card
    assert "not feasible, not on the Pareto front" in html


def test_violations_name_each_bound_and_undefined_metric(tmp_path):
    path = small_study(tmp_path, constraints=[{"constant_volume": {"min": 10, "max": 20}}])
    s = load_study(path)
    rec = {"status": "ok", "role": "candidate", "seq": 3,
           "metrics": {"constant_volume": 25.0}, "notes": {}}
    assert violations(s, rec) == [("constant_volume ≤ 20", 5.0, "")]
    assert violated_text(s, rec) == "constant_volume ≤ 20 by 5"
    low = {**rec, "seq": 4, "metrics": {"constant_volume": 4.0}}
    assert violated_text(s, low) == "constant_volume ≥ 10 by 6"
    none = {**rec, "seq": 5, "metrics": {"constant_volume": None},
            "notes": {"constant_volume": "empty workspace"}}
    assert "constant_volume ≥ 10: empty workspace" in violated_text(s, none)
    ok = {**rec, "seq": 6, "metrics": {"constant_volume": 15.0}}
    assert violated_text(s, ok) == ""
    failed = {**rec, "seq": 7, "status": "failed", "reason": "no IK\nmore"}
    assert violated_text(s, failed) == "failed: no IK"
    t = dict((w, n) for w, n, _ in tally(s, [rec, low, none, ok, failed]))
    # an undefined metric violates both of its bounds and leaves the objective undefined
    assert t["constant_volume ≤ 20"] == 2 and t["constant_volume ≥ 10"] == 2
    assert t["failed"] == 1 and t["maximize constant_volume"] == 1
    # fewest violations first (6: none; 3 and 4: one; 5: three), then the amount divided by
    # the largest of its bound (1.0 for both 3 and 4), then seq
    assert [r["seq"] for r in least_violating(s, [low, rec, none, ok], 4)] == [6, 3, 4, 5]
