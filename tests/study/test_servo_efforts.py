"""A servo's effort limit is a torque (issue 26 item 1): the study's ``dexterity`` evaluator
and ``compare`` never read the 150 N linear force default as a servo torque. The force held
at the tool scales linearly with the actuator effort limit, which checks the N·m → N·mm
conversion independently of the code that applies it."""

from __future__ import annotations

from pathlib import Path

import pytest
from clihelp import small_study

from pkmlab.config import load_mechanism
from pkmlab.errors import ParameterError
from pkmlab.study import load_study
from pkmlab.study.compare import compare_designs, comparison_markdown
from pkmlab.study.evaluators import evaluate_design

ROOT = Path(__file__).resolve().parents[2]
RSS6 = ROOT / "studies" / "mechanisms" / "instructables-servo-6rss.yaml"
WORKSPACE = {"kind": "constant", "samples": 1, "resolution": "12 mm"}


def _rss6_dexterity(tmp_path, **dexterity):
    path = small_study(tmp_path, mechanism={"file": str(RSS6)},
                       design={"crank_length": {"low": "45 mm", "high": "55 mm"}},
                       evaluate={"workspace": WORKSPACE,
                                 "dexterity": {"gci_samples": 50, **dexterity}})
    return load_study(path)


def test_servo_min_force_needs_a_torque_limit_and_scales_with_it(tmp_path):
    metrics = {}
    for torque in (None, 2.0, 4.0):
        s = _rss6_dexterity(tmp_path, **({} if torque is None else {"torque_limit": torque}))
        rec = evaluate_design(s.space, None, s.evaluation, 0)
        assert rec["status"] == "ok", rec.get("reason")
        metrics[torque] = rec
    none = metrics[None]
    assert none["metrics"]["min_force"] is None
    assert none["metrics"]["sampled_min_force"] is None
    assert "torque_limit" in none["notes"]["min_force"]
    f2, f4 = (metrics[t]["metrics"]["min_force"] for t in (2.0, 4.0))
    # this workspace's boundary holds a singular pose (certified): its worst force is 0 N
    assert metrics[2.0]["metrics"]["singularity_free"] == 0.0 and f2 == f4 == 0.0
    s2, s4 = (metrics[t]["metrics"]["sampled_min_force"] for t in (2.0, 4.0))
    # 2 N·m servos on 2 in cranks hold tens of N at the tool (150 N·mm would give a few N)
    assert 20.0 < s2 < 200.0 and s4 == pytest.approx(2 * s2, rel=1e-12)


def test_force_limit_on_a_servo_and_torque_limit_on_a_slider_are_refused(tmp_path):
    with pytest.raises(ParameterError, match=r"evaluate\.dexterity\.force_limit.*torque_limit"):
        _rss6_dexterity(tmp_path, force_limit=150)
    path = small_study(tmp_path, evaluate={"workspace": WORKSPACE,
                                           "dexterity": {"torque_limit": 2}})
    with pytest.raises(ParameterError, match=r"evaluate\.dexterity\.torque_limit"):
        load_study(path)


def test_compare_gives_a_servo_force_only_with_a_torque_limit(monkeypatch):
    import pkmlab.study.compare as cmp

    efforts = []
    original = cmp.dx.worst_case

    def spy(mech, res, length, limit, *a, **k):
        efforts.append(limit)
        return original(mech, res, length, limit, *a, **k)

    monkeypatch.setattr(cmp.dx, "worst_case", spy)
    mech = load_mechanism(RSS6)
    kwargs = dict(box_deg=5.0, resolution=12.0, samples=2)
    without = compare_designs([("rss6", mech)], **kwargs)[0]
    assert isinstance(without["force_N"], str) and "torque limit" in without["force_N"]
    with2 = compare_designs([("rss6", mech)], torque_limit=2.0, **kwargs)
    assert efforts[-1] == pytest.approx(2000.0)           # 2 N·m = 2000 N·mm, internal
    assert isinstance(with2[0]["force_N"], float)
    assert "servos ±2 N·m" in comparison_markdown(with2)
    ups6 = load_mechanism(ROOT / "studies" / "mechanisms" / "gough-stewart-6ups.yaml")
    compare_designs([("ups6", ups6)], force_limit=300.0, torque_limit=2.0, **kwargs)
    assert efforts[-1] == 300.0                           # a slider keeps its force in N
