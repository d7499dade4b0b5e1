"""The shortcuts that made the tolerance ladder's run faster change no stored value (issue 28,
item 3, session 5).

Each shortcut is compared with the computation it replaces, with no tolerance (``==``):

* ``resolve_length`` computes Angeles' length once per mechanism instance: the memoised value
  equals a fresh search on an equal, new instance, and differs between designs (a memo shared
  across mechanisms would fail);
* the force's singular rule reuses κ: ``worst_bound`` equals the same bound with the force's
  own singular values, and the dexterity evaluator's ``sampled_min_force`` equals the force
  recomputed over the same poses with the full rule;
* the ladder's coarse rung skips the capability point's random-rotation check (notes only):
  the coarse capability's metrics equal the checked search's, the check does not run on the
  coarse rung and does run on the fine one;
* evaluators no objective or constraint reads wait for the re-certification: a Sobol study
  with the paper motion deferred exports the plain run's Pareto records and designs.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR, sampled_designs

from pkmlab import dexterity as dx
from pkmlab.study import load_study
from pkmlab.study.evaluators import EVALUATORS
from pkmlab.study.evaluators import worst_bound as wb
from pkmlab.study.evaluators.registry import Context
from pkmlab.study.ladder import ladder_from_spec
from pkmlab.workspaces.optima import search as optima

DEMO = Path(__file__).resolve().parents[2] / "studies" / "hopkins-6psu-redesign.yaml"


@pytest.fixture(scope="module")
def demo():
    """The demo study and 5 of its valid sampled designs whose workspace is not empty."""
    study = load_study(DEMO)
    mechs = []
    for mech, res in sampled_designs(study, 5):
        mechs.append((mech, res))
        if len(mechs) == 5:
            break
    assert len(mechs) == 5
    return study, mechs


def test_angeles_length_is_memoised_per_mechanism_instance(demo, monkeypatch):
    _, mechs = demo
    calls = []
    search = dx.metrics.characteristic_length

    def counted(mech, pose=None):
        calls.append(mech)
        return search(mech, pose)
    monkeypatch.setattr(dx.metrics, "characteristic_length", counted)
    lengths = []
    for mech, _ in mechs:
        fresh = dataclasses.replace(mech)            # equal design, new instance: no memo
        a, b = dx.resolve_length(mech), dx.resolve_length(mech)
        assert a is b                                # the second call is the memo
        assert dx.resolve_length(fresh) == a         # a fresh search gives the same record
        lengths.append(a.length)
    assert len(calls) <= 2 * len(mechs)              # at most one search per instance
    assert len(set(lengths)) == len(lengths)         # per mechanism, not one shared value


def _worst_bound_full_rule(mech, result, length, effort):
    """``worst_bound`` as it was: the force's singular rule computes its singular values."""
    idx, centres = wb._voxels(result)
    pos = wb._units(mech, idx, centres)[0]
    Rs = result.orientations.rotations()
    u, m = wb._extreme_units(pos), wb._corner_orientations(result.orientations)
    uu, mm = np.repeat(u, len(m)), np.tile(m, len(u))
    p, R = np.ascontiguousarray(pos[uu]), np.ascontiguousarray(Rs[mm])
    valid = mech.inverse((p, R)).valid
    J = mech.jacobian((p[valid], R[valid]))
    kap = dx.condition_number(J, length)
    singular = bool(np.any(~np.isfinite(kap)))
    F = dx.max_force_all_directions(J, effort, L=length.length, mobility=mech.mobility)
    F = np.where(np.isfinite(F), F, 0.0)
    f_up = 0.0 if singular else float(np.min(F)) * (1.0 + wb.ALLOWANCE)
    k_low = math.inf if singular else float(np.max(kap)) * (1.0 - wb.ALLOWANCE)
    return wb.WorstBound(k_low, f_up, singular, int(valid.sum()))


def test_the_worst_bound_and_the_sampled_force_equal_the_full_singular_rule(demo):
    study, mechs = demo
    for mech, res in mechs:
        length = dx.resolve_length(mech)
        got = wb.worst_bound(res.mechanism, res, length, 150.0)
        assert got == _worst_bound_full_rule(res.mechanism, res, length, 150.0)
        # the evaluator's sampled force: the same poses as its GCI, the full rule here
        ctx = Context(study.evaluation, 1, choices={})
        EVALUATORS["workspace"](mech, ctx)
        out = EVALUATORS["dexterity"](mech, ctx)
        p, R = dx.aggregate.sample_poses(ctx.result, study.evaluation.dexterity.gci_samples,
                                         np.random.default_rng(1))
        valid = mech.inverse((p, R)).valid
        F = dx.max_force_all_directions(mech.jacobian((p[valid], R[valid])), 150.0,
                                        L=length.length, mobility=mech.mobility)
        assert out["sampled_min_force"] == float(np.min(F))


def test_a_wrong_singular_mask_changes_the_force():
    """The comparison above can fail: a singular pose passed as regular gets a force from its
    (meaningless) inverse instead of the rule's 0."""
    J = np.eye(6)[None].repeat(2, axis=0)
    J[1, 5, 5] = 1e-14                                   # singular by the rule
    full = dx.max_force_all_directions(J, 150.0, L=100.0)
    assert full[1] == 0.0
    lied = dx.max_force_all_directions(J, 150.0, L=100.0, singular=np.zeros(2, bool))
    assert lied[1] != full[1] and lied[0] == full[0]


def test_the_coarse_rung_skips_only_the_point_check(demo, monkeypatch):
    study, mechs = demo
    coarse = study.evaluation.with_tolerances(
        ladder_from_spec({"coarse": {"angle": "0.1 deg"}}, study.evaluation).coarse)
    assert coarse.coarse and not study.evaluation.coarse
    checks = []
    real = optima.point_failures

    def counted(*a, **k):
        checks.append(a)
        return real(*a, **k)
    monkeypatch.setattr(optima, "point_failures", counted)
    for mech, _ in mechs[:3]:
        ctx = Context(coarse, 1, choices={})
        got = EVALUATORS["orientation_capability"](mech, ctx)
        assert not checks                                # no check on the coarse rung
        b = optima.orientation_capability(mech, 5, tol_deg=0.1)      # checked
        assert len(checks) == 1
        assert (got["orientation_capability"], got["orientation_capability_upper"]) == \
            (b.lower, b.upper)
        assert "orientation_capability" not in ctx.notes or "fails" not in \
            ctx.notes["orientation_capability"]
        checks.clear()
        EVALUATORS["orientation_capability"](mech, Context(study.evaluation, 1, choices={}))
        assert len(checks) == 1                          # the fine rung checks the point
        checks.clear()


# ---- evaluators no objective or constraint reads wait for the re-certification -------------

def _sobol_study(tmp, name, ladder=None):
    data = {
        "study": "deferred", "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
        "design": {"platform_outer_radius": {"low": "55 mm", "high": "90 mm"},
                   "link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "dexterous", "box": ["5 deg"] * 3, "samples": 3,
                                   "semantics": "simultaneous", "resolution": "10 mm"},
                     "orientation_capability": True, "dexterity": {"gci_samples": 200},
                     "trajectory": {"paper_motion": True}},
        "objectives": [{"maximize": "orientation_capability"}, {"maximize": "gci"}],
        "constraints": [{"worst_kappa": {"max": 4.5}}],
        "optimizer": {"method": "sobol", "samples": 12}, "seed": 3,
        "output": str(tmp / name), "top": 3}
    if ladder:
        data["tolerance_ladder"] = ladder
    p = tmp / f"{name}.yaml"
    p.write_text(yaml.safe_dump(data))
    return load_study(p)


def test_a_deferred_evaluator_runs_only_for_re_certified_candidates(tmp_path, monkeypatch):
    """The paper motion (no objective or constraint reads it) is not computed on the coarse
    rung: re-certified candidates get it exactly as a run without the ladder computes it (the
    Pareto records and the exported designs are the plain run's, every metric ==), pruned
    ones keep it null with a note, and it runs once per re-certified candidate only."""
    from pkmlab.study import SerialRunner, run_study
    from pkmlab.study.export import chosen_designs
    from pkmlab.study.ladder import NOT_COMPUTED, coarse_evaluation, deferred
    from pkmlab.study.report import pareto_records

    s0 = _sobol_study(tmp_path, "plain")
    store = run_study(s0, SerialRunner())
    r0 = store.all()
    store.close()
    s1 = _sobol_study(tmp_path, "ladder", {"coarse": {"angle": "1 deg"}})
    # the paper motion, and the dexterity's sampled force (session 6) that nothing reads
    assert deferred(s1) == ("trajectory", "sampled_min_force")
    assert "trajectory" not in coarse_evaluation(s1).evaluators
    runs = []
    traj = EVALUATORS["trajectory"]
    real = traj.compute
    monkeypatch.setattr(traj, "compute", lambda mech, ctx: runs.append(1) or real(mech, ctx))
    store = run_study(s1, SerialRunner())
    r1, meta = store.all(), store.get_meta("ladder")
    store.close()
    f0, f1 = pareto_records(s0, r0), pareto_records(s1, r1)
    assert len(f0) >= 2 and [r["params"] for r in f0] == [r["params"] for r in f1]
    for a, b in zip(f0, f1, strict=True):
        assert {m: b["metrics"][m] for m in a["metrics"]} == a["metrics"]
        assert b["metrics"]["paper_motion_fits"] is not None
    e0, e1 = chosen_designs(s0, f0), chosen_designs(s1, f1)
    assert [(r["params"], k) for r, k, _ in e0] == [(r["params"], k) for r, k, _ in e1]
    fine = {str(r["params"]): r for r in r0}
    pruned = [r for r in r1 if r["status"] == "pruned"]
    assert pruned and meta["pruned"] == len(pruned)
    for r in pruned:
        for m in ("paper_motion_fits", "sampled_min_force"):
            assert r["metrics"][m] is None
            assert r["notes"][m] == NOT_COMPUTED
    for r in r1:
        if r["status"] == "ok":          # re-certified: the plain run's values and notes
            ref = fine[str(r["params"])]
            assert r["metrics"]["sampled_min_force"] is not None
            for m in ("paper_motion_fits", "paper_motion_margin", "sampled_min_force"):
                assert r["metrics"][m] == ref["metrics"][m]
                assert r["notes"].get(m) == ref["notes"].get(m)
    assert len(runs) == meta["refined"]   # baseline and re-certified candidates only


def test_the_re_certification_s_sampled_force_is_the_plain_evaluator_s(demo):
    """Session 6: the coarse rung leaves ``sampled_min_force`` (nothing reads it) to the
    re-certification, which computes it apart (``dexterity.sampled_force``: the same
    Monte-Carlo poses, the full singular rule): equal value and note to the plain evaluator's,
    and the coarse rung's other dexterity metrics are unchanged by the deferral."""
    from pkmlab.study.evaluators.dexterity import sampled_force

    study, mechs = demo
    ladder = ladder_from_spec({"coarse": {"angle": "0.1 deg"}}, study.evaluation)
    coarse = study.evaluation.with_tolerances(ladder.coarse)
    later = study.evaluation.with_tolerances(ladder.coarse, ("sampled_min_force",))
    for mech, _ in mechs:
        plain = Context(study.evaluation, 1, choices={})
        EVALUATORS["workspace"](mech, plain)
        want = EVALUATORS["dexterity"](mech, plain)
        again = Context(study.evaluation, 1, choices={})
        EVALUATORS["workspace"](mech, again)
        got = sampled_force(mech, again)
        assert got == {"sampled_min_force": want["sampled_min_force"]}
        assert again.notes.get("sampled_min_force") == plain.notes.get("sampled_min_force")
        a, b = (Context(ev, 1, choices={}) for ev in (coarse, later))
        for ctx in (a, b):
            EVALUATORS["workspace"](mech, ctx)
        full, left = EVALUATORS["dexterity"](mech, a), EVALUATORS["dexterity"](mech, b)
        assert left.pop("sampled_min_force") is None and "sampled_min_force" not in b.notes
        assert full.pop("sampled_min_force") == want["sampled_min_force"]
        assert full == left


def test_the_sampled_force_waits_only_when_nothing_reads_it_and_the_dexterity_is_re_certified(
        tmp_path):
    from pkmlab.study.ladder import deferred, deferred_metrics

    exact = _sobol_study(tmp_path, "exact", {"coarse": {"angle": "1 deg", "worst_case": "exact"}})
    assert "sampled_min_force" not in deferred(exact)       # the dexterity is not re-certified
    data = yaml.safe_load((tmp_path / "exact.yaml").read_text())
    data["tolerance_ladder"] = {"coarse": {"angle": "1 deg"}}
    data["constraints"].append({"sampled_min_force": {"min": 10}})
    (tmp_path / "read.yaml").write_text(yaml.safe_dump(data))
    read = load_study(tmp_path / "read.yaml")
    assert "sampled_min_force" not in deferred(read)        # a constraint reads it
    assert "sampled_min_force" not in deferred_metrics(read)
