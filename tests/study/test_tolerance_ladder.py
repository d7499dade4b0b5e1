"""The tolerance ladder of a study (issue 28, item 3): the optimiser sees coarse certified
tolerances, the candidates that can be on the front are re-certified at the fine ones, and the
others are pruned with their certified bounds and the reason. The exported designs and every
metric of the Pareto records must be those of the same study run without the ladder."""

from __future__ import annotations

import math

import pytest
import yaml
from conftest import MECH_DIR

from pkmlab.errors import ParameterError
from pkmlab.study import SerialRunner, load_study, run_study
from pkmlab.study.export import chosen_designs
from pkmlab.study.ladder import FINE, bounds
from pkmlab.study.report import pareto_records, write_report


def _data(tmp_path, out, ladder=None) -> dict:
    data = {
        "study": "ladder",
        "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
        "design": {"platform_outer_radius": {"low": "55 mm", "high": "90 mm"},
                   "link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "dexterous", "box": ["5 deg"] * 3, "samples": 3,
                                   "semantics": "simultaneous", "resolution": "10 mm"},
                     "orientation_capability": True, "needed_stroke": True},
        "objectives": [{"maximize": "orientation_capability"},
                       {"minimize": "needed_stroke"}],
        "optimizer": {"method": "sobol", "samples": 12},
        "seed": 3, "output": str(tmp_path / out), "top": 3,
    }
    if ladder is not None:
        data["tolerance_ladder"] = ladder
    return data


def _run(tmp_path, name, ladder=None):
    p = tmp_path / f"{name}.yaml"
    p.write_text(yaml.safe_dump(_data(tmp_path, name, ladder)))
    study = load_study(p)
    store = run_study(study, SerialRunner())
    records = store.all()
    meta = store.get_meta("ladder")
    store.close()
    return study, records, meta


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ladder")
    plain = _run(tmp, "plain")
    coarse = {"angle": "1 deg", "length": "1 mm"}
    ladder = _run(tmp, "ladder", {"coarse": coarse})
    return plain, ladder


def test_exported_designs_and_their_metrics_equal_a_run_without_the_ladder(runs, tmp_path):
    (s0, r0, _), (s1, r1, meta) = runs
    f0, f1 = pareto_records(s0, r0), pareto_records(s1, r1)
    assert [r["params"] for r in f0] == [r["params"] for r in f1]
    for a, b in zip(f0, f1, strict=True):
        for m, v in a["metrics"].items():
            assert b["metrics"][m] == v, m                  # identical, not close
        assert b["metrics"]["orientation_capability_coarse"] is not None
    e0, e1 = chosen_designs(s0, f0), chosen_designs(s1, f1)
    assert [(r["params"], k) for r, k, _ in e0] == [(r["params"], k) for r, k, _ in e1]
    assert meta["refined"] >= len(f1) and meta["refined"] + meta["pruned"] == sum(
        r["status"] in ("ok", "pruned") for r in r1)
    # the evaluations table carries both values
    write_report(tmp_path, s1, r1)
    head = (tmp_path / "evaluations.csv").read_text().splitlines()[0]
    assert "orientation_capability (deg)" in head and "orientation_capability_coarse (deg)" in head


def test_pruned_candidates_keep_their_bounds_and_reason_and_are_truly_dominated(runs):
    (s0, r0, _), (_, r1, meta) = runs
    pruned = [r for r in r1 if r["status"] == "pruned"]
    assert meta["pruned"] == len(pruned) > 0               # the test must exercise pruning
    fine = {str(r["params"]): r for r in r0}
    front = pareto_records(s0, r0)
    for r in pruned:
        assert "not re-certified at the fine tolerance" in r["reason"]
        assert r["metrics"]["orientation_capability"] is None
        assert r["metrics"]["orientation_capability_coarse"] is not None
        # the certified bounds hold for the fine value of the run without the ladder
        lo, hi = bounds({"metrics": {k[:-7]: v for k, v in r["metrics"].items()
                                     if k.endswith("_coarse")}}, "orientation_capability")
        ref = fine[str(r["params"])]["metrics"]
        assert ref["orientation_capability"] <= hi
        lo, hi = bounds({"metrics": {k[:-7]: v for k, v in r["metrics"].items()
                                     if k.endswith("_coarse")}}, "needed_stroke")
        assert ref["needed_stroke"] is None or ref["needed_stroke"] >= lo
        assert str(r["params"]) not in {str(f["params"]) for f in front}


def test_refined_values_differ_from_coarse_ones_somewhere(runs):
    """The ladder is real: the coarse pass used the coarse tolerance."""
    (_, _, _), (_, r1, _) = runs
    ok = [r for r in r1 if r["status"] == "ok" and r["role"] == "candidate"]
    widths = [r["metrics"]["orientation_capability_bracket_coarse"] for r in ok]
    assert any(w > 0.05 for w in widths)
    assert all(r["metrics"]["orientation_capability_bracket"] <= 0.0101 + 1e-9 or
               r["notes"].get("orientation_capability") for r in ok)


def test_ladder_is_typed_with_units_and_refused_when_meaningless(tmp_path):
    p = tmp_path / "s.yaml"
    d = _data(tmp_path, "x", {"coarse": {"angle": "0.1 deg", "length": "0.2 mm"},
                              "prune": False})
    p.write_text(yaml.safe_dump(d))
    lad = load_study(p).tolerance_ladder
    assert lad.coarse.angle == pytest.approx(math.radians(0.1)) and lad.coarse.length == 0.2
    assert not lad.prune and lad.coarse.angle > FINE.angle
    for bad, field in [({"coarse": {"angle": "0.001 deg"}}, "tolerance_ladder.coarse.angle"),
                       ({"coarse": {"length": "50 mm"}}, "tolerance_ladder.coarse.length"),
                       ({"fine": {}}, "tolerance_ladder")]:
        p.write_text(yaml.safe_dump(_data(tmp_path, "x", bad)))
        with pytest.raises(ParameterError) as e:
            load_study(p)
        assert e.value.field == field
    d = _data(tmp_path, "x", {"coarse": {"angle": "0.1 deg"}})
    d["evaluate"] = {"workspace": d["evaluate"]["workspace"]}
    d["objectives"] = [{"maximize": "dexterous_volume"}]
    p.write_text(yaml.safe_dump(d))
    with pytest.raises(ParameterError, match="orientation_capability"):
        load_study(p)


def test_the_run_summary_counts_pruned_candidates_apart_from_failures(runs, tmp_path):
    """``write_report``'s counts (the CLI's "N evaluations (F invalid or failed, P pruned by
    the tolerance ladder)" line): a pruned candidate is not a failed evaluation."""
    _, (s1, r1, meta) = runs
    info = write_report(tmp_path / "rep", s1, r1)
    assert info["pruned"] == meta["pruned"] > 0
    assert info["failed"] == sum(r["status"] not in ("ok", "pruned") for r in r1)
