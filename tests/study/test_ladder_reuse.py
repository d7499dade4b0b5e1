"""The re-certification reuses the coarse rung's mechanism and workspace (issue 28, session 6:
:mod:`pkmlab.study.evaluators.kept`), and the values it stores are those it computes without
them (``==``, metrics and notes)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.stats import qmc

import pkmlab.study.evaluators.workspace as ws_evaluator
from pkmlab.errors import ParameterError
from pkmlab.study import load_study
from pkmlab.study.evaluators import evaluate_design, kept
from pkmlab.study.ladder import coarse_evaluation, refine_design

DEMO = Path(__file__).resolve().parents[2] / "studies" / "hopkins-6psu-redesign.yaml"
#: what the demo ladder re-certifies (laddered and deferred evaluators)
NAMES = ("orientation_capability", "dexterity", "task")


@pytest.fixture(scope="module")
def ladder_study(tmp_path_factory):
    data = yaml.safe_load(DEMO.read_text())
    data["mechanism"]["file"] = str(DEMO.parent / data["mechanism"]["file"])
    data["tolerance_ladder"] = {"coarse": {"angle": "0.1 deg", "worst_case": "bound"}}
    p = tmp_path_factory.mktemp("reuse") / "ladder.yaml"
    p.write_text(yaml.safe_dump(data))
    return load_study(p)


def _designs(study, n):
    """The first ``n`` valid designs of scrambled Sobol points (seed 11)."""
    space = study.space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=11).random(8 * n)
    out = []
    for r in u:
        try:
            space.decode(space.from_unit(r))
        except ParameterError:
            continue
        out.append(space.from_unit(r))
    return out[:n]


def _same(a, b):
    return {k: a[k] for k in ("status", "reason", "metrics", "notes")} == {
        k: b[k] for k in ("status", "reason", "metrics", "notes")}


def test_a_re_certification_from_the_kept_workspace_equals_one_without(ladder_study,
                                                                       monkeypatch):
    study = ladder_study
    space, seed = study.space, study.seed
    coarse = coarse_evaluation(study)
    calls = []
    real = ws_evaluator.workspace

    def counted(mech, **kw):
        calls.append(mech)
        return real(mech, **kw)
    monkeypatch.setattr(ws_evaluator, "workspace", counted)
    checked = 0
    for params in _designs(study, 8):
        kept.clear()
        first = evaluate_design(space, params, coarse, seed)
        if first["status"] != "ok":
            continue
        assert len(kept._KEPT) == 1
        calls.clear()
        hit = refine_design(space, params, study.evaluation, seed, NAMES)
        assert calls == [] and not kept._KEPT          # taken: no workspace computed again
        fresh = refine_design(space, params, study.evaluation, seed, NAMES)
        assert len(calls) == 1                         # a miss computes it
        assert hit["status"] == "ok" and _same(hit, fresh)
        assert set(hit["metrics"]) >= {"orientation_capability", "worst_kappa", "min_force"}
        checked += 1
    assert checked >= 4


def test_only_an_equal_mechanism_under_an_equal_request_is_taken(ladder_study):
    study = ladder_study
    space = study.space
    a, b = (space.decode(p) for p in _designs(study, 2))
    req = study.evaluation.request
    kept.clear()
    kept.keep(a, req, "workspace of a")
    assert kept.take(b, req) is None                            # another geometry
    assert kept.take(a, {**req, "resolution": 5.0}) is None     # another request
    again = space.decode(_designs(study, 1)[0])                 # equal geometry, new instance
    assert again is not a and kept.take(again, dict(req)) == (a, "workspace of a")
    assert kept.take(a, req) is None                            # taken once


def test_the_kept_candidates_are_bounded(ladder_study, monkeypatch):
    space = ladder_study.space
    mechs = [space.decode(p) for p in _designs(ladder_study, 4)]
    monkeypatch.setattr(kept, "KEEP", 3)
    kept.clear()
    for k, m in enumerate(mechs):
        kept.keep(m, {}, k)
    assert len(kept._KEPT) == 3 and kept.take(mechs[0], {}) is None
    assert kept.take(mechs[3], {}) == (mechs[3], 3)
    kept.clear()


def test_a_plain_run_keeps_nothing(ladder_study):
    study = ladder_study
    kept.clear()
    evaluate_design(study.space, _designs(study, 1)[0], study.evaluation, study.seed)
    assert not kept._KEPT


def test_the_kept_workspaces_are_bounded_in_bytes(ladder_study, monkeypatch):
    space = ladder_study.space
    mechs = [space.decode(p) for p in _designs(ladder_study, 3)]

    class Big:
        def __init__(self, n):
            self.lo = np.zeros(n)       # n · 8 bytes
    monkeypatch.setattr(kept, "KEEP_BYTES", 1000)
    kept.clear()
    kept.keep(mechs[0], {}, Big(200))                     # 1,600 bytes: not kept
    assert not kept._KEPT
    kept.keep(mechs[0], {}, Big(60))
    kept.keep(mechs[1], {}, Big(60))                      # 960 bytes in all
    kept.keep(mechs[2], {}, Big(60))                      # the oldest leaves
    assert kept.take(mechs[0], {}) is None and kept.take(mechs[1], {}) is not None
    kept.clear()
