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
  coarse rung and does run on the fine one.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.stats import qmc

from pkmlab import dexterity as dx
from pkmlab.errors import ParameterError
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
    space = study.space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=5).random(16)
    mechs = []
    for r in u:
        try:
            mech = space.decode(space.from_unit(r))
            _ = mech.nominal_pose
        except ParameterError:
            continue
        ctx = Context(study.evaluation, 1, choices={})
        EVALUATORS["workspace"](mech, ctx)
        if not ctx.result.empty:
            mechs.append((mech, ctx.result))
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
