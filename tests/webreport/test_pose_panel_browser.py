"""The pose panel's inverse kinematics, leg status and κ, computed in Chromium by
``assets/posepanel.js`` from the declared legs (:mod:`pkmlab.webreport.posepanel`), against
pkmlab's own on 100 poses per family (70 near the nominal pose, 30 far from it, so that legs
leave their stroke, hit joint limits or lose their solution).

Tolerances: actuator values 1e-9 (mm, or rad compared modulo 2π); the dependent coordinates of a
mobility that has them 1e-9 (mm, rad); the status category (ok / out of stroke / joint limit /
unreachable) equal; κ to 1e-9 relative where finite (both ∞ otherwise). A perturbed model (one
declared link 1e-6 longer) must fail.
"""

from __future__ import annotations

import json
import tempfile

import numpy as np
import pytest
from export_samples import FAMILIES, sample
from test_report_browser import ARGS, CHROMIUM, pytestmark  # noqa: F401 - the skip marker

from pkmlab.dexterity.metrics import condition_number, resolve_length
from pkmlab.mechanisms.kernels import ik as K
from pkmlab.webreport.page import _asset
from pkmlab.webreport.posepanel import pose_model

try:
    from playwright.sync_api import sync_playwright
except ImportError:  # pragma: no cover - depends on the environment
    sync_playwright = None

#: pkmlab leg status → the panel's category (0 ok, 1 out of stroke, 2 joint limit, 3 unreachable)
CATEGORY = {K.OK: 0, K.BELOW_STROKE: 1, K.ABOVE_STROKE: 1, K.JOINT_LIMIT: 2,
            K.DEGENERATE: 3, K.NO_SOLUTION: 3, K.OTHER_MODE: 3}
N_NEAR, N_FAR = 70, 30


@pytest.fixture(scope="module")
def page():
    with tempfile.TemporaryDirectory() as profile, sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(profile, executable_path=CHROMIUM,
                                                   args=ARGS, headless=True)
        pg = ctx.new_page()
        pg.set_content("<!DOCTYPE html><html><body><script>" + _asset("posepanel.js")
                       + "</script></body></html>")
        yield pg
        ctx.close()


def poses(mech, seed=0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    free = mech.mobility.index
    s = float(mech.scale)
    X = np.repeat(mech.nominal_pose[None], N_NEAR + N_FAR, axis=0)
    for n0, n1, lin, ang in ((0, N_NEAR, 0.1 * s, 10.0), (N_NEAR, N_NEAR + N_FAR, 0.6 * s, 45.0)):
        for j in free:
            span = np.radians(ang) if j >= 3 else lin
            X[n0:n1, j] += rng.uniform(-span, span, n1 - n0)
    return X


def js_solve(page, model, X):
    return page.evaluate("([m, X]) => X.map(x => { const r = pkmlabPose.solve(m, x); "
                         "return {q: r.q.map(v => Number.isFinite(v) ? v : null), "
                         "status: r.status, pose: r.pose, "
                         "kappa: Number.isFinite(r.kappa) ? r.kappa : null}; })",
                         [json.loads(json.dumps(model)), X.tolist()])


def compare(mech, model, got, X) -> dict:
    """Worst differences between the page and pkmlab: ``q``, ``pose``, ``kappa_rel``,
    ``status`` (count of legs whose category differs), ``statuses`` (categories seen)."""
    Xc = mech.complete(X) if mech.mobility.dependent else X
    ik = mech.inverse(Xc, stroke=mech.stroke)
    kap = condition_number(mech.jacobian(Xc), resolve_length(mech))
    q_js = np.array([[np.nan if v is None else v for v in g["q"]] for g in got])
    st_js = np.array([g["status"] for g in got])
    st_pk = np.vectorize(CATEGORY.get)(ik.leg_status)
    both = np.isfinite(q_js) & np.isfinite(ik.q) & (st_pk != 3)
    d = q_js - ik.q
    if mech.actuator_unit == "rad":
        d = np.remainder(d + np.pi, 2 * np.pi) - np.pi
    k_js = np.array([np.inf if g["kappa"] is None else g["kappa"] for g in got])
    fin = np.isfinite(kap) & np.isfinite(k_js)
    return {"q": float(np.max(np.abs(d[both]), initial=0.0)),
            "pose": float(np.max(np.abs(np.array([g["pose"] for g in got]) - Xc))),
            "kappa_rel": float(np.max(np.abs(k_js[fin] / kap[fin] - 1.0), initial=0.0)),
            "kappa_inf": int(np.sum(np.isfinite(kap) != np.isfinite(k_js))),
            "status": int(np.sum(st_js != st_pk)), "statuses": sorted(set(st_pk.ravel())),
            "compared": int(both.sum())}


SOLVED = [f for f in FAMILIES if pose_model(sample(f))["supported"]]


def test_every_family_is_solved():
    """Every sample family's legs are kinds the page solves (luzi3's chains as ``pair`` legs,
    two struts sharing their upper link); a mechanism whose legs are not says which and why."""
    unsolved = {f: pose_model(sample(f))["reason"] for f in FAMILIES}
    assert set(SOLVED) == set(FAMILIES), {f: r for f, r in unsolved.items() if r}
    assert {"delta3", "ldelta3", "fivebar", "rpr3", "prs3", "psu6", "ups6", "rss6",
            "sixleg", "tri3", "luzi3"} <= set(SOLVED)
    assert {leg["kind"] for leg in pose_model(sample("luzi3"))["legs"]} == {"pair"}


@pytest.mark.parametrize("family", SOLVED)
def test_page_ik_matches_pkmlab(page, family):
    mech = sample(family)
    model = pose_model(mech)
    X = poses(mech)
    r = compare(mech, model, js_solve(page, model, X), X)
    assert r["compared"] >= 0.5 * N_NEAR * len(model["legs"]), r
    assert r["q"] <= 1e-9, r
    assert r["pose"] <= 1e-9, r
    assert r["status"] == 0, r
    assert r["kappa_inf"] == 0 and r["kappa_rel"] <= 1e-9, r
    assert len(r["statuses"]) >= 2, r                # the far poses leave the ok set


@pytest.mark.parametrize("family", ["rss6", "prs3", "fivebar", "luzi3"])
def test_perturbed_model_fails(page, family):
    """The comparison can fail: one declared link 1e-6 mm longer than the mechanism's (a
    pair's shared-link offset; a strut's base point moved by 1e-6 mm)."""
    mech = sample(family)
    model = pose_model(mech)
    leg = model["legs"][0]
    if "link" in leg:
        leg["link"] += 1e-6
    elif "offset" in leg:
        leg["offset"] += 1e-6 if leg["offset"] > 0 else -1e-6
    else:
        leg["base"] = [leg["base"][0] + 1e-6, *leg["base"][1:]]
    X = poses(mech)
    r = compare(mech, model, js_solve(page, model, X), X)
    assert r["q"] > 1e-9, r
