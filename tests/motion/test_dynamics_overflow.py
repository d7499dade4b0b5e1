"""Non-finite forces are flagged (issue 27, item 9): a sample whose force, speed or power
overflows is not ``ok``, its problem is spelt out, and the study's ``motions`` evaluator
reports ``motions_feasible`` 0 with a note instead of a silent null beside a 1."""

from __future__ import annotations

import numpy as np
from conftest import MECH_DIR

import pkmlab
from pkmlab.motion.dynamics import inverse_dynamics
from pkmlab.motion.motions import make_motion
from pkmlab.motion.payload import MassProperties
from pkmlab.requirements.spec import build_motions, build_payload
from pkmlab.study.definition import Evaluation
from pkmlab.study.evaluators import EVALUATORS, Context


def _overflowing(mech, n=21):
    t = np.linspace(0.0, 1.0, n)
    poses = np.tile(mech.nominal_pose, (n, 1))
    d1 = np.zeros((n, 6))
    d2 = np.zeros((n, 6))
    d2[n // 2, 2] = 1e308          # one sample: z acceleration 1e308 mm/s² → force inf
    return make_motion("spike", t, poses, d1, d2, "analytic")


def test_an_overflowing_sample_is_flagged_not_ok():
    mech = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
    body = MassProperties(100.0, np.zeros(3), np.eye(3) * 1e6)
    r = inverse_dynamics(mech, _overflowing(mech), body)
    assert r.code[10] == 3 and not r.ok[10] and r.ok.sum() == 20
    assert "non-finite" in r.first_problem() and "t = 0.5 s" in r.first_problem()
    s = r.summary()
    assert np.all(np.isfinite(s["peak_force"])) and np.all(np.isfinite(s["peak_power"]))


def test_the_motions_evaluator_reports_it(tmp_path, monkeypatch):
    mech = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
    plan = build_motions([{"name": "p", "paper": True}], tmp_path)
    monkeypatch.setattr(type(plan), "motions", lambda self, m, centre=None: [_overflowing(m)])
    ev = Evaluation({"motions": plan, "payload": build_payload({"mass": "100 kg"})})
    ctx = Context(ev, 0)
    out = EVALUATORS["motions"](mech, ctx)
    assert out["motions_feasible"] == 0.0
    assert "non-finite" in ctx.notes["motions_feasible"]
    assert out["peak_actuator_force"] is not None and np.isfinite(out["peak_actuator_force"])
