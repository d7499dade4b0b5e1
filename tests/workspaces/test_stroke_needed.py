"""The needed stroke over continuous positions (exchange rounds with binding orientations):
its bracket against independent computations with the inverse kinematics (not the column
kernels), the `pkmlab optimum` commands and the `needed_stroke` study metric."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from conftest import MECH_DIR, assert_point_holds
from scipy.optimize import minimize
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.errors import ParameterError
from pkmlab.mechanisms import NO_STROKE
from pkmlab.poses import euler_to_matrix
from pkmlab.study import SerialRunner, run_study, study_from_mapping
from pkmlab.study.evaluators import evaluate_mechanism
from pkmlab.workspaces import OrientationSet
from pkmlab.workspaces.optima.search import stroke_needed

HOPKINS = MECH_DIR / "hopkins-williams-6psu.yaml"
UPS = MECH_DIR / "gough-stewart-6ups.yaml"
runner = CliRunner()


@pytest.fixture(scope="module")
def hopkins():
    return load_mechanism(HOPKINS)


@pytest.fixture(scope="module")
def hopkins30(hopkins):
    """±30° simultaneous box, 3 angles per axis to start from (the grid alone is 0.12 mm
    low: binding orientations lie between its angles)."""
    return stroke_needed(hopkins, OrientationSet.box(np.radians([30.0] * 3), samples=3))


def _q_at_z0(mech, x, y, euler):
    """6-PSU slider values at the column (x, y), z = 0, from the inverse kinematics: along a
    column q = z + c, so the column needs an upper limit of q_min + max q - min q."""
    R = euler_to_matrix(np.atleast_2d(euler))
    ik = mech.inverse((np.tile([x, y, 0.0], (len(R), 1)), R), stroke=NO_STROKE)
    return np.where(np.isfinite(ik.q), ik.q, np.nan)


def test_hopkins_bracket_is_closed_and_holds_independently(hopkins, hopkins30):
    """Width ≤ 0.01 mm from a 3³ grid. Upper end: the certified point keeps every leg in
    stroke at 20,000 random orientations, the corners and local minima of its margin. Lower
    end: with the grid plus the binding orientations the search added, no continuous column
    fits (Nelder–Mead over (x, y)). Independent estimate: a dense 17³ brute force over the
    box, minimised over columns, lies below the upper end; the same column's continuous
    need (local maximisation of each leg's slider over the box) lies above the lower end."""
    b = hopkins30
    assert b.note == "" and 0.0 < b.width <= 0.01
    assert b.sampled < b.lower - 0.05            # the 3³ grid alone is far too low
    assert 131.0 < b.lower <= b.upper < 131.3     # measured [131.1415, 131.1456]
    th = math.radians(30.0)
    qmin = hopkins.stroke[0]
    # upper end
    mech = dataclasses.replace(hopkins, stroke_window=(qmin, b.upper))
    p = np.asarray(b.point)
    rng = np.random.default_rng(5)
    assert_point_holds(mech, p, th, rng)
    # lower end: the search's own sample (grid + binding orientations) admits no column
    S = np.vstack([OrientationSet.box(np.radians([30.0] * 3), samples=3).parameters(),
                   np.asarray(b.binding)])
    assert len(b.binding) > 0

    def need(xy, S=S):
        q = _q_at_z0(hopkins, xy[0], xy[1], S)
        return 1e3 if np.isnan(q).any() else qmin + np.max(q) - np.min(q)

    starts = [p[:2]] + list(p[:2] + rng.normal(0, 3, (2, 2)))
    best = min(minimize(need, s, method="Nelder-Mead",
                        options={"xatol": 1e-7, "fatol": 1e-9}).fun for s in starts)
    assert best > b.lower
    # independent estimate: dense grid, then the continuous need of its best column
    D = OrientationSet.box(np.radians([30.0] * 3), samples=17).parameters()
    res = minimize(lambda v: need(v, D), p[:2], method="Nelder-Mead",
                   options={"xatol": 1e-6, "fatol": 1e-8})
    dense = res.fun
    q = _q_at_z0(hopkins, *res.x, D)
    hi_q, lo_q = np.max(q), np.min(q)
    for i in range(6):
        for sign in (1.0, -1.0):
            e0 = D[np.argmax(sign * q[:, i])]
            r = minimize(lambda v, s=sign, i=i: -s * _q_at_z0(hopkins, *res.x, v)[0, i], e0,
                         method="L-BFGS-B", bounds=[(-th, th)] * 3)
            v = -sign * r.fun
            hi_q, lo_q = (max(hi_q, v), lo_q) if sign > 0 else (hi_q, min(lo_q, v))
    column = qmin + hi_q - lo_q
    assert dense <= b.upper + 1e-9 and b.lower <= column + 1e-9
    assert column - dense < 0.02                  # the dense grid is nearly converged


def _lengths(mech, p, euler):
    R = euler_to_matrix(np.atleast_2d(euler))
    return mech.inverse((np.tile(p, (len(R), 1)), R), stroke=NO_STROKE).q


def test_6ups_bracket_is_closed_and_holds_independently():
    """Shipped 6-UPS (legs 390–950 mm), ±30° box from a 3³ grid: width ≤ 0.01 mm (the
    second-order cell bounds certify where every leg reaches its lower limit); the certified
    point keeps every leg length in stroke at 20,000 random orientations and at local minima
    of its margin started from the worst of them. Independent
    estimate: Nelder–Mead over (x, y, z) of the longest leg over a dense 9³ sample (shortest
    ≥ 390 mm) stays below the upper end; at that point, raised until the continuous box's
    shortest leg (L-BFGS-B) is in stroke, the longest leg lies above the lower end."""
    ups = load_mechanism(UPS)
    th = math.radians(30.0)
    b = stroke_needed(ups, OrientationSet.box(np.full(3, th), samples=3))
    assert b.note == "" and 0.0 < b.width <= 0.01
    assert 493.9 < b.lower < 494.1                     # measured [494.0305, 494.0319]
    qmin = ups.stroke[0]
    mech = dataclasses.replace(ups, stroke_window=(qmin, b.upper))
    assert_point_holds(mech, np.asarray(b.point), th, np.random.default_rng(2))
    D = OrientationSet.box(np.full(3, th), samples=9).parameters()

    def longest(p):
        q = _lengths(ups, p, D)
        return np.max(q) + 1e5 * max(0.0, qmin - np.min(q))

    res = minimize(longest, np.asarray(b.point), method="Nelder-Mead",
                   options={"xatol": 1e-6, "fatol": 1e-8, "maxiter": 3000})
    assert res.fun <= b.upper + 1e-9
    p = res.x.copy()

    def extreme(i, s):
        q = _lengths(ups, p, D)[:, i]
        r = minimize(lambda v: -s * _lengths(ups, p, v)[0, i], D[np.argmax(s * q)],
                     method="L-BFGS-B", bounds=[(-th, th)] * 3)
        return -s * r.fun

    for _ in range(40):
        short = min(extreme(i, -1.0) for i in range(6))
        if short >= qmin - 1e-7:
            break
        p[2] += 1.5 * (qmin - short)
    long_ = max(extreme(i, 1.0) for i in range(6))
    assert b.lower <= long_ + 1e-9 and long_ - b.lower < 0.01


def test_stroke_needed_refuses_bad_requests(hopkins):
    single = OrientationSet.box(np.radians([30.0] * 3), "single-axis", 3)
    with pytest.raises(ParameterError, match="orientations"):
        stroke_needed(hopkins, single)
    with pytest.raises(ParameterError, match="rounds"):
        stroke_needed(hopkins, OrientationSet.box(np.radians([30.0] * 3), samples=3),
                      rounds=-1)


def test_cli_optimum_json_text_and_refusals():
    r = runner.invoke(app, ["optimum", "stroke", str(HOPKINS), "--box", "30deg",
                            "--samples", "3", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["unit"] == "mm" and d["box_deg"] == pytest.approx(30.0)
    assert d["lower"] <= d["upper"] and d["width"] <= 0.01
    assert d["travel_mm"] == pytest.approx([d["lower"], d["upper"]])     # lower limit 0 mm
    r = runner.invoke(app, ["optimum", "stroke", str(HOPKINS), "--box", "0.5 rad",
                            "--samples", "3"])
    assert r.exit_code == 0 and "upper actuator limit in [" in r.stdout.replace("\n", " ")
    r = runner.invoke(app, ["optimum", "stroke", str(MECH_DIR / "luzi-3chain.yaml")])
    assert r.exit_code == 2 and len(r.stderr.splitlines()) == 1
    assert "family: must be a family with radial column intervals" in r.stderr
    r = runner.invoke(app, ["optimum", "stroke", str(HOPKINS), "--box", "0"])
    assert r.exit_code == 2 and "--box: must be a half-range in (0, 180] deg" in r.stderr
    r = runner.invoke(app, ["optimum", "capability", str(HOPKINS), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["unit"] == "deg" and 23.1 < d["lower"] <= d["upper"] < 23.2 and d["width"] <= 0.01
    r = runner.invoke(app, ["optimum", "capability", str(HOPKINS), "--samples", "1"])
    assert r.exit_code == 2 and "--samples: must be an integer in [2, 41]" in r.stderr


def _study(**evaluate) -> dict:
    return {"study": "stroke", "mechanism": {"file": str(HOPKINS)},
            "design": {"link_length": {"low": "200 mm", "high": "260 mm"}},
            "evaluate": {"workspace": {"kind": "dexterous", "box": ["10 deg"] * 3,
                                       "samples": 3, "resolution": "10 mm"}} | evaluate,
            "objectives": [{"minimize": "needed_stroke"}],
            "optimizer": {"method": "sobol", "samples": 2}, "output": "out"}


def test_study_metric_needed_stroke(hopkins, tmp_path):
    """The metric is the certified travel, its lower end the proved one; a study refuses it
    without a simultaneous equal box."""
    study = study_from_mapping(_study(needed_stroke=True), tmp_path)
    metrics, notes = evaluate_mechanism(hopkins, study.evaluation, 1)
    ref = stroke_needed(hopkins, OrientationSet.box(np.radians([10.0] * 3), samples=3))
    assert metrics["needed_stroke"] == pytest.approx(ref.upper - hopkins.stroke[0])
    assert metrics["needed_stroke_lower"] == pytest.approx(ref.lower - hopkins.stroke[0])
    assert 0.0 < metrics["needed_stroke_bracket"] <= 0.01
    # the workspace's own actuator window: its lower limit is the one kept
    win = _study(needed_stroke=True)
    win["evaluate"]["workspace"]["constraints"] = {"stroke": ["20 mm", "4 in"]}
    m2, _ = evaluate_mechanism(hopkins, study_from_mapping(win, tmp_path).evaluation, 1)
    ref2 = stroke_needed(dataclasses.replace(hopkins, stroke_window=(20.0, 101.6)),
                         OrientationSet.box(np.radians([10.0] * 3), samples=3))
    assert m2["needed_stroke"] == pytest.approx(ref2.upper - 20.0)
    assert m2["needed_stroke"] != pytest.approx(metrics["needed_stroke"], abs=1e-3)
    # a tiny study run: the metric is stored for every candidate
    data = _study(needed_stroke=True) | {"output": str(tmp_path / "out")}
    store = run_study(study_from_mapping(data, tmp_path), SerialRunner())
    records = store.all()
    store.close()
    assert len(records) == 3 and all(r["status"] == "ok" for r in records)
    assert all(0 < r["metrics"]["needed_stroke_bracket"] <= 0.01 for r in records)
    assert len({round(r["metrics"]["needed_stroke"], 3) for r in records}) == 3
    bad = _study(needed_stroke=True)
    bad["evaluate"]["workspace"]["semantics"] = "single-axis"
    with pytest.raises(ParameterError, match="evaluate.needed_stroke"):
        study_from_mapping(bad, tmp_path)
    with pytest.raises(ParameterError, match="evaluate.needed_stroke"):
        study_from_mapping(_study(), tmp_path)       # objective without the block


def test_second_order_certification_holds_where_links_are_near_horizontal():
    """The study's first Pareto design (rounded printed parameters): at its capability the
    links are near horizontal, where the sphere's curvature term matters. The second-order
    bounds lift the certified lower end from 43.52° (first order) to ≥ 44.0°; the certified
    point keeps every leg in stroke at 20,000 random orientations, the corners and local
    minima of its margin (inverse kinematics)."""
    from pkmlab.workspaces.optima.search import orientation_capability

    mech = load_mechanism({
        "name": "pareto-1", "family": "psu6", "link_length": "295.6 mm",
        "generator": {"base_radii": ["100 mm", "132.9 mm"],
                      "platform_radii": ["29.2 mm", "48.6 mm"], "base_pair_angle": "auto",
                      "platform_rotation": "27.8 deg", "pairing": "same"},
        "stroke": ["0 mm", "4 in"], "tool_offset": ["0 mm", "0 mm", "47 mm"]})
    b = orientation_capability(mech, 5)
    assert 44.0 <= b.lower <= b.upper < 44.2              # measured [44.0757, 44.0850]
    th = math.radians(b.lower)
    p = np.asarray(b.point)
    assert_point_holds(mech, p, th, np.random.default_rng(11), minima=4)
