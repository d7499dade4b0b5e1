"""How the report shows the candidates the tolerance ladder pruned (issue 28, item 3).

A pruned candidate has its laddered metrics null and their coarse values kept
(``<metric>_coarse``). In "Why candidates fail" (and the ``violated`` column) it is counted
under each constraint its certified coarse bounds violate, with the certified least amount,
or else on one line of its own, certainly dominated, with the dominating candidate; it is
never a constraint called "pruned". The Pareto plot draws it at its coarse values with a
marker of its own. Hand-made records on a study with a constraint on a laddered metric."""

from __future__ import annotations

import yaml
from conftest import MECH_DIR
from matplotlib.axes import Axes

from pkmlab.study import load_study
from pkmlab.study import report as study_report
from pkmlab.study.violations import DOMINATED, tally, violated_text, violations

REASON = "not re-certified at the fine tolerance: "


def _study(tmp_path):
    data = {
        "study": "ladder-report",
        "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
        "design": {"link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "dexterous", "box": ["5 deg"] * 3, "samples": 3,
                                   "semantics": "simultaneous", "resolution": "10 mm"},
                     "orientation_capability": True, "needed_stroke": True},
        "objectives": [{"maximize": "orientation_capability"},
                       {"minimize": "needed_stroke"}],
        "constraints": [{"orientation_capability": {"min": 20}}],
        "optimizer": {"method": "sobol", "samples": 4},
        "tolerance_ladder": {"coarse": {"angle": "1 deg", "length": "1 mm"}},
        "seed": 3, "output": str(tmp_path / "out"),
    }
    p = tmp_path / "study.yaml"
    p.write_text(yaml.safe_dump(data))
    return load_study(p)


def _pruned(seq, capability, upper, stroke, why):
    """A record as ``ladder._prune`` stores it: laddered metrics null, coarse values kept."""
    m = {"orientation_capability": None, "orientation_capability_upper": None,
         "needed_stroke": None, "needed_stroke_lower": None,
         "orientation_capability_coarse": capability,
         "orientation_capability_upper_coarse": upper,
         "needed_stroke_coarse": stroke, "needed_stroke_lower_coarse": stroke - 0.5}
    return {"status": "pruned", "role": "candidate", "seq": seq, "metrics": m, "notes": {},
            "reason": REASON + why}


def test_pruned_candidates_are_tallied_by_their_certified_reason(tmp_path):
    s = _study(tmp_path)
    # certified: the fine capability is at most 18.5 < 20, so the constraint fails by ≥ 1.5
    bad = _pruned(4, 17.9, 18.5, 60.0, "orientation_capability <= 18.5 < 20 (certified)")
    assert violations(s, bad) == [("orientation_capability ≥ 20", 1.5, "certified coarse bound")]
    assert violated_text(s, bad) == ("orientation_capability ≥ 20 by at least 1.5 "
                                     "(certified coarse bound)")
    # its coarse value (17.9) is not what is certified: the upper end (18.5) is
    dom = _pruned(5, 24.0, 24.9, 70.0, "certainly dominated by evaluation 2: best case "
                  "(orientation_capability 24.9, needed_stroke 69.5) vs (30, 50)")
    assert violations(s, dom) == [(DOMINATED, None, "by evaluation 2: best case "
                                   "(orientation_capability 24.9, needed_stroke 69.5) vs "
                                   "(30, 50)")]
    # an upper end above the bound proves nothing, whatever the coarse value
    near = _pruned(6, 19.6, 20.4, 70.0, "certainly dominated by evaluation 2: best case")
    assert [w for w, _, _ in violations(s, near)] == [DOMINATED]
    ok = {"status": "ok", "role": "candidate", "seq": 2, "notes": {},
          "metrics": {"orientation_capability": 30.0, "needed_stroke": 50.0}}
    rows = {w: n for w, n, _ in tally(s, [ok, bad, dom, near])}
    assert rows == {"orientation_capability ≥ 20": 1, DOMINATED: 2}
    assert "pruned" not in rows


def test_the_pareto_plot_draws_pruned_candidates_at_their_coarse_values(tmp_path, monkeypatch):
    s = _study(tmp_path)
    drawn = {}
    real = Axes.scatter

    def scatter(self, x, y, *args, label=None, **kw):
        drawn[label] = (list(x), list(y))
        return real(self, x, y, *args, label=label, **kw)

    monkeypatch.setattr(Axes, "scatter", scatter)
    ok = {"status": "ok", "role": "candidate", "seq": 2, "notes": {},
          "metrics": {"orientation_capability": 30.0, "needed_stroke": 50.0}}
    dom = _pruned(5, 24.0, 24.9, 70.0, "certainly dominated by evaluation 2")
    study_report._plot(tmp_path / "pareto.png", s, [ok, dom], [ok])
    key = next(k for k in drawn if k and k.startswith("pruned"))
    assert drawn[key] == ([24.0], [70.0])
    # no candidate is infeasible: no such group, and none in the legend
    assert "infeasible" not in drawn
    assert (tmp_path / "pareto.png").stat().st_size > 0


def test_the_pareto_legend_lists_only_groups_with_points(tmp_path, monkeypatch):
    s = _study(tmp_path)
    labels = []
    real = Axes.legend

    def legend(self, *args, **kw):
        labels.append(self.get_legend_handles_labels()[1])
        return real(self, *args, **kw)

    monkeypatch.setattr(Axes, "legend", legend)
    ok = {"status": "ok", "role": "candidate", "seq": 2, "notes": {},
          "metrics": {"orientation_capability": 30.0, "needed_stroke": 50.0}}
    study_report._plot(tmp_path / "pareto.png", s, [ok], [ok])
    assert labels[0] == ["feasible", "Pareto (all objectives)"]
    low = {"status": "ok", "role": "candidate", "seq": 3, "notes": {},
           "metrics": {"orientation_capability": 10.0, "needed_stroke": 50.0}}
    study_report._plot(tmp_path / "pareto.png", s, [low], [])
    assert labels[1] == ["infeasible"]
    # an invalid candidate has null metrics: nothing to draw, no legend entry
    bad = {"status": "invalid", "role": "candidate", "seq": 4, "notes": {},
           "metrics": {"orientation_capability": None, "needed_stroke": None}}
    study_report._plot(tmp_path / "pareto.png", s, [ok, bad], [ok])
    assert labels[2] == ["feasible", "Pareto (all objectives)"]


def test_the_browser_report_groups_pruning_reasons_and_draws_pruned_candidates(tmp_path):
    from pkmlab.webreport.data import candidate_rows, failure_counts
    from pkmlab.webreport.study_page import _points

    s = _study(tmp_path)
    ok = {"status": "ok", "role": "candidate", "seq": 2, "notes": {}, "reason": "",
          "params": {"link_length": 230.0},
          "metrics": {"orientation_capability": 30.0, "needed_stroke": 50.0}}
    pruned = [_pruned(seq, 24.0 + seq, 25.0 + seq, 70.0 + seq,
                      f"certainly dominated by evaluation 2: best case (o {seq}) vs (30, 50)")
              for seq in (5, 6, 7)]
    pruned.append(_pruned(8, 17.0, 18.5, 60.0, "orientation_capability <= 18.5 < 20 "
                          "(certified)"))
    for r in pruned:
        r["params"] = {"link_length": 240.0}
    _, groups = failure_counts([ok, *pruned])
    assert [(g["reason"], g["count"], g["example"]) for g in groups] == [
        (REASON + "certainly dominated by a refined candidate", 3,
         "evaluation 2: best case (o 5) vs (30, 50)"),
        (REASON + "orientation_capability < 20 (certified bound)", 1, "upper bound 18.5")]
    rows = candidate_rows(s, [ok, *pruned], [ok], {})
    pts = {p["seq"]: p for p in _points(s, rows)}
    assert pts[5]["group"] == "pruned"
    assert pts[5]["values"] == {"orientation_capability": 29.0, "needed_stroke": 75.0}
    assert pts[2]["group"] == "pareto"
