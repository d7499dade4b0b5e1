"""The tolerance ladder's coarse worst case and its pruning rules (issue 28, item 3).

* ``worst_bound`` (the coarse rung's worst case from a subset of the samples) bounds the exact
  worst case: its κ is at most ``worst_kappa`` and its force at least ``min_force``, with no
  tolerance, on sampled designs of the demo study;
* ``refine`` prunes exactly the candidates its certified bounds rule out (a candidate whose
  best case is not dominated, or whose bound does not violate a constraint, is re-certified),
  on hand-made coarse records with a stand-in runner (no evaluation);
* ``study.resolved.yaml`` states the ladder a run used.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR, sampled_designs

from pkmlab import dexterity as dx
from pkmlab.study import SerialRunner, load_study, run_study
from pkmlab.study.evaluators.worst_bound import worst_bound
from pkmlab.study.export import chosen_designs
from pkmlab.study.ladder import refine
from pkmlab.study.report import pareto_records, write_report
from pkmlab.study.store import Store

DEMO = Path(__file__).resolve().parents[2] / "studies" / "hopkins-6psu-redesign.yaml"


def test_the_coarse_worst_case_bounds_the_exact_one_on_demo_designs():
    """8 sampled valid designs of the demo study (±15° dexterous workspace, 2.5 mm grid):
    bound κ ≤ worst_kappa and bound force ≥ min_force exactly; the bound is tight (within
    5 % of the worst κ on the median design: the subset holds the extreme samples)."""
    ratios = []
    for mech, res in sampled_designs(load_study(DEMO), 11):
        length = dx.resolve_length(mech, None)
        b = worst_bound(res.mechanism, res, length, 150.0)
        wc = dx.worst_case(res.mechanism, res, length, 150.0)
        assert b.poses > 0
        assert b.kappa_lower <= wc.worst_kappa, (b, wc.worst_kappa)
        assert b.force_upper >= wc.min_force, (b, wc.min_force)
        ratios.append(b.kappa_lower / wc.worst_kappa)
        if len(ratios) == 8:
            break
    assert len(ratios) == 8
    assert np.median(ratios) > 0.95, ratios


# ---- the pruning rules on hand-made records ------------------------------------------------

def _study(tmp_path, prune=True):
    data = {
        "study": "rules",
        "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
        "design": {"link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "dexterous", "box": ["5 deg"] * 3, "samples": 3,
                                   "semantics": "simultaneous", "resolution": "10 mm"},
                     "orientation_capability": True, "dexterity": {}},
        "objectives": [{"maximize": "orientation_capability"},
                       {"maximize": "dexterous_volume"}],
        "constraints": [{"worst_kappa": {"max": 12}}],
        "optimizer": {"method": "sobol", "samples": 4},
        "seed": 1, "output": str(tmp_path / "out"),
        "tolerance_ladder": {"coarse": {"angle": "1 deg"}, "prune": prune},
    }
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(data))
    return load_study(p)


def _coarse(cap_lo, cap_hi, volume, kappa_lower):
    return {"orientation_capability": cap_lo, "orientation_capability_upper": cap_hi,
            "orientation_capability_bracket": cap_hi - cap_lo, "dexterous_volume": volume,
            "worst_kappa": kappa_lower, "min_force": 100.0, "singularity_free": 1.0}


#: name → (coarse metrics, fine metrics the stand-in runner returns)
CASES = {
    # the best: refined first, feasible; it dominates what follows
    "A": (_coarse(10.0, 11.0, 50.0, 5.0), {"orientation_capability": 10.5,
                                          "orientation_capability_upper": 10.51,
                                          "worst_kappa": 5.5}),
    # best case (10.4, 40) is dominated by A's fine (10.5, 50): pruned
    "B": (_coarse(9.5, 10.4, 40.0, 5.0), {}),
    # best case (10.6, 40): A's fine value does not dominate it → must be re-certified
    "C": (_coarse(9.5, 10.6, 40.0, 5.0), {"orientation_capability": 9.6,
                                         "orientation_capability_upper": 9.61,
                                         "worst_kappa": 6.0}),
    # worst κ is at least 12.5 > 12 whatever the rest: pruned by the constraint, first
    "D": (_coarse(20.0, 21.0, 90.0, 12.5), {}),
    # worst κ at least 11.9: may be feasible, on the coarse front → re-certified (fine: 12.3,
    # infeasible, so it dominates nothing)
    "E": (_coarse(30.0, 31.0, 95.0, 11.9), {"orientation_capability": 30.5,
                                           "orientation_capability_upper": 30.51,
                                           "worst_kappa": 12.3}),
}


class _Runner:
    def __init__(self, name="stand-in"):
        self.asked = []
        self.name = name            # "serial": one re-certification at a time

    def map(self, fn, tasks):
        for key, args in tasks:
            # the re-certification runs the laddered evaluators only, and the dexterity's
            # sampled force that the coarse rung left (nothing reads it: session 6)
            assert args[-1] == ("orientation_capability", "dexterity", "sampled_min_force"), args
            self.asked.append(key)
            fine = dict(CASES[key][1])
            fine.setdefault("orientation_capability_bracket", 0.01)
            fine.update(min_force=90.0, singularity_free=1.0)
            yield key, {"status": "ok", "reason": "", "metrics": fine, "notes": {},
                        "seconds": 0.0}


@pytest.mark.parametrize("prune,runner", [(True, "serial"), (True, "stand-in"),
                                           (False, "serial")])
def test_refine_prunes_exactly_the_certainly_dominated_or_infeasible(tmp_path, prune, runner):
    study = _study(tmp_path, prune)
    store = Store(tmp_path / "e.sqlite")
    for k, (m, _) in CASES.items():
        store.put(k, "candidate", {"link_length": 1.0}, {"status": "ok", "reason": "",
                                                        "metrics": m, "notes": {},
                                                        "seconds": 0.0})
    runner = _Runner(runner)
    counts = refine(study, runner, store)
    rec = {r["key"]: r for r in store.all()}
    if not prune:
        assert sorted(runner.asked) == sorted(CASES) and counts["pruned"] == 0
        return
    assert {k for k, r in rec.items() if r["status"] == "pruned"} == {"B", "D"}
    assert sorted(runner.asked) == ["A", "C", "E"]
    assert counts == {"refined": 3, "pruned": 2}
    assert "worst_kappa >= 12.5 > 12 (certified)" in rec["D"]["reason"]
    assert "certainly dominated by evaluation" in rec["B"]["reason"]
    for k in ("B", "D"):
        m = rec[k]["metrics"]
        assert m["worst_kappa"] is None and m["worst_kappa_coarse"] == CASES[k][0]["worst_kappa"]
        assert m["dexterous_volume"] == CASES[k][0]["dexterous_volume"]    # exact: kept
    for k in ("A", "C", "E"):
        m = rec[k]["metrics"]
        assert m["worst_kappa"] == CASES[k][1]["worst_kappa"]
        assert m["worst_kappa_coarse"] == CASES[k][0]["worst_kappa"]
    store.close()


def test_a_failure_at_the_fine_tolerance_is_stored_with_its_reason(tmp_path):
    study = _study(tmp_path)
    store = Store(tmp_path / "e.sqlite")
    store.put("A", "candidate", {"link_length": 1.0}, {"status": "ok", "reason": "",
                                                       "metrics": CASES["A"][0], "notes": {},
                                                       "seconds": 0.0})

    class Failing:
        def map(self, fn, tasks):
            for key, _ in tasks:
                yield key, {"status": "failed", "reason": "worst case over the workspace: "
                            "too large", "metrics": {}, "notes": {}, "seconds": 0.0}
    assert refine(study, Failing(), store) == {"refined": 1, "pruned": 0}
    r = store.get("A")
    assert r["status"] == "failed" and r["reason"].startswith("at the fine tolerance")
    assert r["metrics"]["worst_kappa"] is None and r["metrics"]["worst_kappa_coarse"] == 5.0
    store.close()


def test_the_resolved_study_states_the_ladder_it_ran_with(tmp_path):
    study = _study(tmp_path)
    write_report(tmp_path / "rep", study, [])
    text = (tmp_path / "rep" / "study.resolved.yaml").read_text()
    got = yaml.safe_load(text)["tolerance_ladder"]
    assert got == {"coarse": {"angle": "1 deg", "length": "0.01 mm", "worst_case": "bound"},
                   "prune": True}
    again = tmp_path / "again.yaml"
    again.write_text(text)
    assert load_study(again).tolerance_ladder == study.tolerance_ladder
    assert math.isclose(study.tolerance_ladder.coarse.angle, math.radians(1.0))


# ---- a whole study, with and without the ladder ---------------------------------------------

def _e2e(tmp, name, ladder=None):
    data = {
        "study": "e2e", "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
        "design": {"platform_outer_radius": {"low": "55 mm", "high": "90 mm"},
                   "link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "dexterous", "box": ["5 deg"] * 3, "samples": 3,
                                   "semantics": "simultaneous", "resolution": "10 mm"},
                     "orientation_capability": True, "dexterity": {"gci_samples": 200}},
        "objectives": [{"maximize": "orientation_capability"}, {"maximize": "gci"}],
        "constraints": [{"worst_kappa": {"max": 4.5}}],
        "optimizer": {"method": "sobol", "samples": 12}, "seed": 3,
        "output": str(tmp / name), "top": 3}
    if ladder:
        data["tolerance_ladder"] = ladder
    p = tmp / f"{name}.yaml"
    p.write_text(yaml.safe_dump(data))
    study = load_study(p)
    store = run_study(study, SerialRunner())
    records, meta = store.all(), store.get_meta("ladder")
    store.close()
    return study, records, meta


def test_a_study_with_the_coarse_worst_case_exports_what_a_plain_run_exports(tmp_path):
    """12 Sobol candidates of the 6-PSU, capability and GCI maximised, worst κ ≤ 4.5 (about
    half the candidates violate it), coarse 1° and worst-case bounds: the Pareto records (same
    designs, every metric ==) and the exported designs are the plain run's; candidates are
    pruned both by the constraint's certified bound and by dominance, and each pruned one is
    off the plain run's front, its bounds holding the plain run's values."""
    s0, r0, _ = _e2e(tmp_path, "plain")
    s1, r1, meta = _e2e(tmp_path, "ladder", {"coarse": {"angle": "1 deg"}})
    f0, f1 = pareto_records(s0, r0), pareto_records(s1, r1)
    assert len(f0) >= 2 and [r["params"] for r in f0] == [r["params"] for r in f1]
    for a, b in zip(f0, f1, strict=True):
        assert {m: b["metrics"][m] for m in a["metrics"]} == a["metrics"]
        assert b["metrics"]["worst_kappa_coarse"] <= b["metrics"]["worst_kappa"]
    e0, e1 = chosen_designs(s0, f0), chosen_designs(s1, f1)
    assert [(r["params"], k) for r, k, _ in e0] == [(r["params"], k) for r, k, _ in e1]
    fine = {str(r["params"]): r["metrics"] for r in r0}
    front = {str(r["params"]) for r in f0}
    pruned = [r for r in r1 if r["status"] == "pruned"]
    why = [r["reason"] for r in pruned]
    assert any("worst_kappa >=" in w for w in why) and any("dominated" in w for w in why), why
    assert meta["pruned"] == len(pruned) and meta["refined"] + len(pruned) == len(r1)
    for r in pruned:
        ref, m = fine[str(r["params"])], r["metrics"]
        assert str(r["params"]) not in front
        assert m["worst_kappa"] is None and m["worst_kappa_coarse"] <= ref["worst_kappa"]
        assert m["min_force_coarse"] >= ref["min_force"]
        assert ref["orientation_capability"] <= m["orientation_capability_upper_coarse"]
        assert m["gci"] == ref["gci"]                   # exact on both rungs
        if "worst_kappa >=" in r["reason"]:
            assert ref["worst_kappa"] > 4.5
