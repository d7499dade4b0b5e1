"""The study's trajectory evaluator computes only what its metrics use (issue 28, item 5):
``paper_motion_fits`` and the stroke margin need the inverse kinematics and a certified
singularity test, not the full check's singular values (κ per sample) nor its static force
solve. With those made to fail, the evaluator's metrics are those the full check gives."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import qmc

import pkmlab.dexterity.sweep
import pkmlab.motion.check
from pkmlab import ParameterError
from pkmlab.motion import check_trajectory, paper_motion
from pkmlab.study import load_study
from pkmlab.study.evaluators import EVALUATORS
from pkmlab.study.evaluators.registry import Context
from pkmlab.tolerances import TOL

STUDY = Path(__file__).resolve().parents[2] / "studies" / "hopkins-6psu-redesign.yaml"


def _unused(name):
    def fail(*a, **k):
        raise AssertionError(f"{name} called: the trajectory metrics do not use it")
    return fail


@pytest.fixture(scope="module")
def designs():
    study = load_study(STUDY)
    space = study.space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=3).random(16)
    out = []
    for r in u:
        try:
            m = space.decode(space.from_unit(r))
            _ = m.nominal_pose
            out.append(m)
        except ParameterError:
            pass
    return study, out


def test_trajectory_metrics_equal_the_full_check_without_its_svd_and_force_solve(
        designs, monkeypatch):
    study, mechs = designs
    ref = []
    for mech in mechs:                      # the full check, before anything is disabled
        mo = paper_motion(mech)
        rep = check_trajectory(mech, mo.t, mo.poses)
        m = np.concatenate([rep.margin_low, rep.margin_high])
        margin = float(np.min(m)) if np.all(np.isfinite(m)) else None
        if margin is not None and abs(margin) <= TOL.stroke_roundoff_mm:
            margin = 0.0
        ref.append((float(rep.fits), margin))
    assert {f for f, _ in ref} == {0.0, 1.0}, ref          # both verdicts are exercised
    for mod in (pkmlab.motion.check, pkmlab.dexterity.sweep):
        monkeypatch.setattr(mod, "condition_number", _unused("condition_number (SVD)"))
    monkeypatch.setattr(pkmlab.motion.check, "check_trajectory", _unused("check_trajectory"))
    for f in ("solve", "pinv", "svd"):
        monkeypatch.setattr(np.linalg, f, _unused(f"numpy.linalg.{f}"))
    for mech, (fits, margin) in zip(mechs, ref, strict=True):
        ctx = Context(study.evaluation, study.seed, choices={})
        out = EVALUATORS["trajectory"](mech, ctx)
        assert out["paper_motion_fits"] == fits
        assert out["paper_motion_margin"] == margin         # identical, not close
        assert out["paper_motion_angle_margin"] is None


def test_the_evaluator_s_motion_poses_are_the_paper_motion_s(designs):
    """Session 6: the evaluator builds the paper motion's times and poses only
    (``paper_motion_poses``, no rates or twists): the same arrays as ``paper_motion``, bit for
    bit, on the demo's designs, with other timings, and on a translational mobility (a stand-in
    with a turned nominal pose: only x, y, z move; ``paper_motion`` reads nothing else)."""
    from types import SimpleNamespace

    from pkmlab.mechanisms.mobility import TRANSLATIONAL
    from pkmlab.motion.paper import paper_motion_poses

    _, mechs = designs
    moving = SimpleNamespace(nominal_pose=np.array([1.0, -2.0, 300.0, 0.1, -0.2, 0.3]),
                             mobility=TRANSLATIONAL)
    cases = [(m, {}) for m in mechs[:4]] + [
        (mechs[0], {"segment_time": 0.7, "dwell": 0.0, "rate_hz": 60.0}), (moving, {})]
    for mech, kw in cases:
        mo = paper_motion(mech, **kw)
        t, X = paper_motion_poses(mech, **kw)
        assert np.array_equal(t, mo.t) and np.array_equal(X, mo.poses)
    moved = paper_motion_poses(moving)[1] != moving.nominal_pose
    assert moved[:, :3].any() and not moved[:, 3:].any()      # x, y, z only
