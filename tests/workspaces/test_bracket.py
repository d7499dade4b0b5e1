"""The guaranteed volume bracket (pkmlab.workspaces.bracket.columns): its cell bounds, its soundness
against independent evaluations of the kinematics, its narrowing with the budget, and the study
metrics and CLI fields that carry it."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.errors import ParameterError
from pkmlab.mechanisms.families.sixleg import SixLeg
from pkmlab.mechanisms.families.ups6 import working_sides
from pkmlab.mechanisms.kernels.columns import make_leg_eval
from pkmlab.study import evaluators as ev_mod
from pkmlab.study import load_study
from pkmlab.workspaces import OrientationSet, workspace
from pkmlab.workspaces import cells as oc
from pkmlab.workspaces.bracket.columns import volume_bracket
from pkmlab.workspaces.bracket.legbounds import Legs
from pkmlab.workspaces.bracket.level import Level
from pkmlab.workspaces.constraints import Constraints

HOPKINS = MECH_DIR / "hopkins-williams-6psu.yaml"
UPS = MECH_DIR / "gough-stewart-6ups.yaml"
D5 = math.radians(5.0)


@pytest.fixture(scope="module")
def psu():
    return load_mechanism(HOPKINS)


@pytest.fixture(scope="module")
def ups():
    return load_mechanism(UPS)


# ---- the cell bounds ----------------------------------------------------------------------------

SETS = [OrientationSet.box([0.3, 0.2, 0.4], centre=(0.1, -0.2, 0.3)),
        OrientationSet.box([0.3, 0.0, 0.4], "single-axis", centre=(0.0, 0.0, 0.5)),
        OrientationSet.tilt_torsion(0.6, 0.3, centre=(0.1, 0.2, -0.1))]


@pytest.mark.parametrize("oset", SETS, ids=["box", "single-axis", "tilt-torsion"])
def test_cells_cover_the_set_and_bound_the_rotation(oset):
    rng = np.random.default_rng(3)
    C, H = oc.initial_cells(oset, 2)
    for _ in range(2):
        C, H, _ = oc.split(C, H)
    lo, hi = C - H, C + H
    # every sample of the set lies in some cell
    P = oset.with_samples(5).parameters()
    if oset.kind == "tilt-torsion":
        P[:, 0] = np.mod(P[:, 0], 2 * math.pi)
    inside = np.all((P[:, None] >= lo[None] - 1e-12) & (P[:, None] <= hi[None] + 1e-12), axis=2)
    assert inside.any(axis=1).all()
    # the angle, chord and linearisation bounds hold at random points of random cells
    u = np.array([80.0, 30.0, -47.0])
    A, R0 = oc.axes(oset, C), oset.rotations_at(C)
    for _ in range(30):
        D = rng.uniform(-1, 1, C.shape) * H
        R = oset.rotations_at(C + D)
        move = np.linalg.norm(R @ u - R0 @ u, axis=1)
        assert np.all(move <= oc.chord(oc.angle_bound(oset, C, H)) * np.linalg.norm(u) + 1e-9)
        lin = R0 @ u + sum(np.cross(A[:, k], R0 @ u) * D[:, k:k + 1] for k in range(3))
        err = np.linalg.norm(R @ u - lin, axis=1)
        assert np.all(err <= oc.remainder(oset, C, H) * np.linalg.norm(u) + 1e-9)


@pytest.mark.parametrize("name", ["psu", "ups", "ups-below"])
def test_column_profile_is_the_column_kernel(name, request):
    """The closed form the second-order bounds use is what the family's kernel computes
    (for the 6-UPS also in the mirrored working mode, platform below the base joints)."""
    mech = request.getfixturevalue(name.split("-")[0])
    if name == "ups-below":
        mech = dataclasses.replace(mech, nominal=np.array([0.0, 0.0, -600.0, 0.0, 0.0, 0.0]))
        assert np.all(mech.column_profile()[:, :, 1] == -1)
    rng = np.random.default_rng(0)
    ev = make_leg_eval(type(mech).column_leg)
    n = 3000
    leg = rng.integers(0, 6, n)
    x, y = rng.uniform(-800, 800, (2, n))
    W = rng.uniform(-300, 300, (n, 3))
    a, b, ok = ev(x, y, W, mech.column_params()[leg])
    d = np.hypot(x + W[:, 0], y + W[:, 1])
    prof = mech.column_profile()[leg]                      # (n, 2, 3)
    ends = prof[:, :, 0] + prof[:, :, 1] * np.sqrt(np.maximum(prof[:, :, 2] - d[:, None] ** 2,
                                                              0.0)) - W[:, 2:3]
    assert ok.any() and (~ok).any()
    np.testing.assert_allclose(a[ok], ends[ok, 0], atol=1e-9)
    np.testing.assert_allclose(b[ok], ends[ok, 1], atol=1e-9)


# ---- soundness against the kinematics -----------------------------------------------------------


def _feasible(mech, p, R):
    """(N,) True where every leg of pose (p, R) is within the stroke (the IK, not the
    column kernels)."""
    return mech.inverse((p, R)).valid


def _points(b, which, n, rng):
    col, lo, hi = b.inner if which == "inner" else b.outer
    k = rng.integers(0, len(col), n)
    c = b.cells[col[k]]
    h = b.resolution
    xy = c + rng.uniform(-h / 2, h / 2, (n, 2))
    z = lo[k] + rng.uniform(0, 1, n) * (hi[k] - lo[k])
    return np.column_stack([xy, z])


def test_dexterous_bracket_is_sound_pointwise(psu):
    """Inner points work at random orientations of the continuous set; points the outer set
    excludes fail at some orientation (or at all, for the nominal one)."""
    oset = OrientationSet.box([D5] * 3)
    b = volume_bracket(psu, "dexterous", oset, 5.0, budget_s=60, max_evaluations=1.5e6)
    assert 0 < b.lower < b.upper
    rng = np.random.default_rng(1)
    P = _points(b, "inner", 400, rng)
    for _ in range(20):
        R = oset.rotations_at(rng.uniform(-D5, D5, (len(P), 3)))
        assert _feasible(psu, P, R).all()
    # a dense cloud around the workspace: whatever works at every grid orientation is in outer
    lo = np.array([-90, -90, 220.0])
    Q = lo + rng.uniform(0, 1, (20000, 3)) * np.array([180, 180, 160.0])
    ok = np.ones(len(Q), bool)
    for R in oset.with_samples(3).rotations():
        ok &= _feasible(psu, Q, np.broadcast_to(R, (len(Q), 3, 3)))
    assert ok.sum() > 100
    assert b.contains(Q[ok], "outer").all()


def test_reachable_bracket_is_sound_pointwise(ups):
    oset = OrientationSet.tilt_torsion(math.radians(8), math.radians(5))
    b = volume_bracket(ups, "reachable", oset, 25.0, budget_s=60, max_evaluations=4e5)
    assert 0 < b.lower <= b.upper
    rng = np.random.default_rng(2)
    # a point feasible at any orientation of the set lies in the outer set
    nom = ups.nominal_pose[:3]
    Q = nom + rng.uniform(-1, 1, (20000, 3)) * np.array([500, 500, 350.0])
    R = oset.rotations_at(np.column_stack([rng.uniform(0, 2 * math.pi, len(Q)),
                                           rng.uniform(0, oset.tilt, len(Q)),
                                           rng.uniform(-oset.torsion, oset.torsion, len(Q))]))
    ok = _feasible(ups, Q, R)
    assert ok.sum() > 100
    assert b.contains(Q[ok], "outer").all()


def test_bracket_contains_a_dense_estimate_and_narrows_with_the_budget(psu):
    """Constant kind: the engine at a 2x finer grid (exact in z, second order in x-y) lies
    inside every bracket, and a larger budget gives a narrower one."""
    dense = workspace(psu, "constant", resolution=2.5).volume
    widths = []
    for budget in (1e5, 8e6):
        b = volume_bracket(psu, "constant", None, 5.0, target=0.002, budget_s=120,
                           max_evaluations=budget)
        assert b.lower <= dense <= b.upper
        assert b.stop_reason in ("budget: evaluations", "converged")
        widths.append(b.width)
        assert [r["h_mm"] for r in b.history] == sorted((r["h_mm"] for r in b.history),
                                                        reverse=True)
    assert widths[1] < 0.2 * widths[0]


def test_reachable_bracket_contains_independent_estimates(psu, ups):
    """Reachable kind (x-y second-order upper bound over pairs of legs, cells' vertices as
    samples): the bracket contains estimates that lie on known sides of the truth.

    * from below: the engine's union over a dense orientation grid (every sample is in the
      set; its x-y error is second order and far below the margins here);
    * from above (6-UPS, whose leg lengths and working-mode sides move by at most the
      platform points' displacement): the points of a lattice that some cell centre reaches
      with every leg's stroke and side widened by the cell's chord bound, ``2 sin(α/2)·|u|``:
      every truly reachable point is among them (up to the lattice's counting error)."""
    box5 = OrientationSet.box([D5] * 3)
    b = volume_bracket(psu, "reachable", box5, 5.0, budget_s=2.0)
    below = workspace(psu, "reachable", box5.with_samples(7), 2.5).volume
    assert b.lower < below <= b.upper

    tt = OrientationSet.tilt_torsion(math.radians(8), math.radians(5))
    b = volume_bracket(ups, "reachable", tt, 25.0, budget_s=2.0)
    below = workspace(ups, "reachable", tt.with_samples(5), 25.0).volume
    assert below <= b.upper
    C, H = oc.initial_cells(tt, 1)
    C, H, _ = oc.split(C, H)
    R = tt.rotations_at(C)
    eps = oc.chord(oc.angle_bound(tt, C, H))[:, None] * np.linalg.norm(ups.tool_points, axis=1)
    side = working_sides(ups)
    col, zlo, zhi = b.outer
    g = 40.0
    axes = [np.arange(b.cells[:, k].min() - g, b.cells[:, k].max() + g, g) for k in (0, 1)]
    axes.append(np.arange(zlo.min() - g, zhi.max() + g, g))
    P = np.stack([a.ravel() for a in np.meshgrid(*axes, indexing="ij")], axis=1)
    lo, hi = ups.stroke
    reached = np.zeros(len(P), bool)
    Ru = np.einsum("mij,kj->mki", R, ups.tool_points) - ups.base_points
    for m in range(len(R)):
        v = P[:, None, :] + Ru[m]
        q = np.linalg.norm(v, axis=-1)
        reached |= np.all((q >= lo - eps[m]) & (q <= hi + eps[m])
                          & (v[..., 2] * side >= -eps[m]), axis=1)
    above = reached.sum() * g**3
    assert b.lower <= above
    assert below <= above


@pytest.mark.parametrize("name", ["psu", "ups"])
def test_reachable_cell_bounds_hold_pointwise(name, request):
    """The cells' x-y bounds of the reachable upper bound, at random points of the square and
    random rotations of the cell (the column kernel at one exact rotation): the top is below
    the affine function through the corner values, and the bottom above their interpolation on
    either triangulation of the square."""
    mech = request.getfixturevalue(name)
    oset = (OrientationSet.box([D5] * 3) if name == "psu"
            else OrientationSet.tilt_torsion(math.radians(10), math.radians(5)))
    legs = Legs(mech, oset)
    rng = np.random.default_rng(7)
    C, H = oc.initial_cells(oset, 1)
    for _ in range(3):                                    # small cells: tight bounds
        C, H, _ = oc.split(C, H)
    n, s = 4000, (0.5 if name == "psu" else 2.0)
    ext = 120.0 if name == "psu" else 600.0
    k = rng.integers(0, len(C), n)
    cx, cy = rng.uniform(-ext, ext, (2, n))
    b = legs.bounds(cx, cy, s, C[k], H[k], reachable=True)["pl_out"]
    top, bot = b["top"], b["bot"]
    P = C[k] + rng.uniform(-1, 1, (n, 3)) * H[k]
    R = oset.rotations_at(P)
    u, v = rng.uniform(-1, 1, (2, n))                      # the point in square coordinates
    checked = 0
    for q in range(n):
        lo, hi, _ = mech.column_intervals(np.array([cx[q] + u[q] * s]),
                                          np.array([cy[q] + v[q] * s]), R[q:q + 1], "all")
        lo, hi = lo[0, 0, 0], hi[0, 0, 0]
        if not hi >= lo:
            continue
        checked += 1
        t = top[q]                                        # corners (-1,-1), (1,-1), (1,1), (-1,1)
        a = 0.25 * ((1 - u[q]) * (1 - v[q]) * t[0] + (1 + u[q]) * (1 - v[q]) * t[1]
                    + (1 + u[q]) * (1 + v[q]) * t[2] + (1 - u[q]) * (1 + v[q]) * t[3])
        assert hi <= a + 1e-6, q
        g = bot[q]
        x, y = 0.5 * (u[q] + 1), 0.5 * (v[q] + 1)         # in [0, 1]²
        # diagonal 0-2: triangles (0,1,2) below y = x, (0,2,3) above
        d1 = (g[0] + x * (g[1] - g[0]) + y * (g[2] - g[1]) if y <= x
              else g[0] + y * (g[3] - g[0]) + x * (g[2] - g[3]))
        # diagonal 1-3: triangles (0,1,3) below x + y = 1, (1,2,3) above
        d2 = (g[0] + x * (g[1] - g[0]) + y * (g[3] - g[0]) if x + y <= 1
              else g[2] + (1 - x) * (g[3] - g[2]) + (1 - y) * (g[1] - g[2]))
        assert lo >= max(d1, d2) - 1e-6, q
    assert checked > 200


def test_reachable_upper_bound_holds_column_by_column(psu):
    """The x-y second-order upper bound of each column (affine tops and concave bottoms over
    pairs of legs, 3 refinement steps) is above the column's volume estimated from below by
    a dense union: 7³ rotations of the set at 6 × 6 points of the column's square (measured
    margin at 9³ and 8 × 8: at least 1.3 % of the column, over 300 columns)."""
    oset = OrientationSet.box([D5] * 3)              # the nominal orientation is the identity
    legs = Legs(psu, oset)
    h = 5.0
    g = np.arange(-150.0, 150.01, h)
    cx, cy = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    C0, H0 = oc.initial_cells(oset, 1)
    lv = Level(legs, "reachable", cx, cy, h, C0, H0)
    for k in range(3):
        _, outer, _, _ = lv.step()
        if k < 2:
            lv.split()
    box = np.bincount(outer[0], outer[2] - outer[1], minlength=len(cx)) * h * h
    up = np.minimum(box, lv.pl_upper)
    assert np.all(np.isfinite(lv.pl_upper))
    R = oset.rotations_at(oset.with_samples(7).parameters())
    off = (np.arange(6) + 0.5) / 6 * h - h / 2
    rng = np.random.default_rng(5)
    cols = rng.choice(np.nonzero(up > 0)[0], 80, replace=False)
    for c in cols:
        lo, hi, _ = psu.column_intervals(cx[c] + off, cy[c] + off, R, "any")
        est = np.where(hi >= lo, hi - lo, 0.0).sum(axis=-1).mean() * h * h
        assert est <= up[c] * (1 + 1e-9) + 1e-9, c


def test_time_budget_is_honoured_within_its_tolerance(psu):
    """The budget is checked between batches and a step that would pass it is abandoned
    (the bracket of the last completed step is returned). Before, the step running at the
    budget completed. The budget is set relative to the first step's time on this machine
    (so that the load does not move it across step boundaries): 5 first steps, which the
    old code overran to about 10 (its fourth step)."""
    box5 = OrientationSet.box([D5] * 3)
    for _ in range(2):                               # the second call runs warm
        first = volume_bracket(psu, "reachable", box5, 2.5, budget_s=1e-3)
        assert len(first.history) == 1               # the first step always completes
    budget = 5.0 * (first.history[0]["seconds"] - first.setup_seconds)
    b = volume_bracket(psu, "reachable", box5, 2.5, target=1e-4, budget_s=budget)
    assert b.stop_reason == "budget: seconds"
    assert b.seconds - b.setup_seconds <= 1.25 * budget + 1.0
    assert b.history[-1]["seconds"] <= b.seconds
    assert b.lower <= b.upper


def test_bracket_refuses_what_it_cannot_guarantee(psu):
    # rss6 is bracketed on cells (tests/workspaces/test_bracket_rss6.py); its generic sixleg
    # declaration (crank columns, not radial, no cell bounds) is still refused
    six = SixLeg.from_mechanism(load_mechanism(MECH_DIR / "instructables-servo-6rss.yaml"))
    with pytest.raises(ParameterError, match="bracket"):
        volume_bracket(six, "constant")
    with pytest.raises(ParameterError, match="constraints"):
        volume_bracket(psu, "constant", constraints=Constraints(kappa_max=50.0))


# ---- study metrics and CLI ----------------------------------------------------------------------


def test_study_writes_the_bracket_metrics(tmp_path):
    data = {
        "study": "bracket", "mechanism": {"file": str(HOPKINS)},
        "design": {"link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "dexterous", "box": ["5 deg"] * 3, "samples": 2,
                                   "resolution": "10 mm"},
                     "volume_bracket": {"budget": 1.0, "target": 0.2}},
        "objectives": [{"maximize": "dexterous_volume_lower"}],
        "constraints": [{"workspace_volume_upper": {"max": 1e6}}],
        "optimizer": {"method": "sobol", "samples": 2}, "seed": 1,
        "output": str(tmp_path / "out"), "top": 1,
    }
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(data))
    s = load_study(p)
    metrics, _ = ev_mod.evaluate_mechanism(s.baseline(), s.evaluation, 0)
    for n in ("workspace_volume_lower", "workspace_volume_upper", "dexterous_volume_lower",
              "dexterous_volume_upper", "workspace_volume_bracket_width"):
        assert n in metrics
    assert "constant_volume_lower" not in metrics
    assert metrics["dexterous_volume_lower"] <= metrics["dexterous_volume"] * 1.001 + 1e-9
    assert metrics["dexterous_volume_lower"] <= metrics["dexterous_volume_upper"]
    bad = dict(data, objectives=[{"maximize": "reachable_volume_lower"}])
    p.write_text(yaml.safe_dump(bad))
    with pytest.raises(ParameterError, match="dexterous_volume"):
        load_study(p)


def test_cli_prints_and_writes_the_bracket(tmp_path):
    r = CliRunner().invoke(app, ["workspace", str(HOPKINS), "--resolution", "10",
                                 "--bracket", "--bracket-budget", "1", "--bracket-target",
                                 "0.2", "--out", str(tmp_path), "--json"])
    assert r.exit_code == 0, r.output
    vb = json.loads(r.output)["volume_bracket"]
    assert vb["lower_mm3"] <= vb["estimate_mm3"] <= vb["upper_mm3"]
    assert vb["stop_reason"] in ("converged", "budget: seconds")
    assert vb["history"] and "lower_mm3" in vb["history"][0]
    r = CliRunner().invoke(app, ["workspace", str(HOPKINS), "--bracket", "--bracket-target",
                                 "2", "--out", str(tmp_path)])
    assert r.exit_code == 2 and "--bracket-target" in r.output


def test_positive_part_of_an_affine_function_integrates_exactly():
    """The closed form behind the x-y second-order volumes, against a fine midpoint rule."""
    from pkmlab.workspaces.bracket.sets import tri_positive

    rng = np.random.default_rng(4)
    f = rng.normal(size=(200, 3))
    n = 300                      # centroid rule on the n² sub-triangles (up and down ones)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    up, down = i + j <= n - 1, i + j <= n - 2
    b1 = np.concatenate([(i[up] + 1 / 3) / n, (i[down] + 2 / 3) / n])
    b2 = np.concatenate([(j[up] + 1 / 3) / n, (j[down] + 2 / 3) / n])
    vals = f[:, 0, None] * (1 - b1 - b2) + f[:, 1, None] * b1 + f[:, 2, None] * b2
    approx = np.maximum(vals, 0).mean(axis=1)
    exact = tri_positive(f[:, 0], f[:, 1], f[:, 2], 1.0)
    np.testing.assert_allclose(exact, approx, atol=2e-4)
