"""The luzi3 cell bracket (pkmlab.workspaces.bracket.cells): the leg bound over a cell holds on
random samples, the inner and outer cube sets agree with the kinematics evaluated
independently (IK at random points and rotations), the bracket contains the engine's volume,
and the CLI brackets luzi3."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import MECH_DIR
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.mechanisms import NO_STROKE
from pkmlab.testing import cell_points
from pkmlab.workspaces import OrientationSet, workspace
from pkmlab.workspaces.bracket.cells import touching_components
from pkmlab.workspaces.bracket.columns import volume_bracket

LUZI = MECH_DIR / "luzi-3chain.yaml"


@pytest.fixture(scope="module")
def luzi():
    return load_mechanism(LUZI)


def _in_stroke(mech, p, R):
    ik = mech.inverse((p, R), stroke=NO_STROKE)
    lo, hi = mech.stroke
    with np.errstate(invalid="ignore"):
        return ik.valid & np.all((ik.q >= lo) & (ik.q <= hi), axis=1)


def test_leg_bound_holds_on_random_cells(luzi):
    rng = np.random.default_rng(3)
    n = 40_000
    p = rng.uniform([-500, -500, 150], [500, 500, 1250], (n, 3))
    R = Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.3).as_matrix()
    delta, alpha = rng.uniform(0, 60, n), rng.uniform(0, 0.3, n)
    q, eps = luzi.leg_cell_bounds(p, R, delta, alpha)
    ik = luzi.inverse((p, R), stroke=NO_STROKE).q
    centred = np.isclose(q, ik, rtol=0, atol=1e-9)   # elsewhere the link may flip in the cell
    p2, R2, _ = cell_points(rng, p, R, delta, alpha)    # half on the cell's boundary
    q2 = luzi.inverse((p2, R2), stroke=NO_STROKE).q
    fin = np.isfinite(q2)                       # the link is defined at the point
    assert centred.mean() > 0.9 and not centred.all() and np.all(np.isfinite(eps))
    ratio = np.abs(q2 - q)[fin] / eps[fin]
    assert np.all(ratio <= 1.0)
    assert ratio[centred[fin]].max() > 0.5      # the bound is not vacuous
    assert ratio[~centred[fin]].max() > 0.5     # nor is the fallback where the link may flip


def test_touching_cubes_are_connected():
    C = np.array([[0, 0, 0], [2, 0, 0], [3.5, 1.5, 1.5], [10, 0, 0]], float)
    h = np.array([1.0, 1.0, 0.5, 1.0])
    n, lab = touching_components(C, h)
    assert n == 2 and lab[0] == lab[1] == lab[2] != lab[3]


def test_constant_bracket_agrees_with_the_kinematics(luzi):
    b = volume_bracket(luzi, "constant", None, 10.0, budget_s=60, max_evaluations=4e5)
    assert b.stop_reason == "budget: evaluations" and b.resolution == 20.0
    ref = workspace(luzi, "constant", resolution=10.0)      # an estimate, with its grid error
    assert b.lower - ref.volume_error <= ref.volume <= b.upper + ref.volume_error
    # every step is a bracket, and they narrow; at 20 mm cubes the second-order bounds are
    # within 10 % and 5 % (first order alone: 27 % low; the upper bound reaches the mirror
    # image below the base unless the links' branch is followed)
    lows = [r["lower_mm3"] for r in b.history]
    assert lows == sorted(lows) and b.lower > 0.9 * ref.volume and b.upper < 1.05 * ref.volume
    rng = np.random.default_rng(5)
    p = rng.uniform([-700, -700, 0], [700, 700, 1300], (60_000, 3))
    R = np.broadcast_to(np.eye(3) @ Rotation.from_euler("z", math.pi / 6).as_matrix(),
                        (len(p), 3, 3))
    ok = _in_stroke(luzi, p, R)
    assert np.all(ok[b.contains(p, "inner")]) and b.contains(p, "inner").sum() > 1000
    assert np.all(b.contains(p[ok], "outer"))


def test_dexterous_and_reachable_brackets_hold(luzi):
    box = OrientationSet.box((math.radians(3),) * 3, samples=2)
    rng = np.random.default_rng(6)
    p = rng.uniform([-600, -600, 200], [600, 600, 1200], (20_000, 3))
    Rn = Rotation.from_euler("z", math.pi / 6)
    vols = {}
    for kind in ("dexterous", "reachable"):
        b = volume_bracket(luzi, kind, box, 20.0, budget_s=60, max_evaluations=6e5)
        ref = workspace(luzi, kind, box, resolution=20.0)
        vols[kind] = (b.lower, b.upper)
        if kind == "dexterous":       # samples over-estimate the dexterous volume
            assert b.lower <= ref.volume + ref.volume_error
        else:                         # and under-estimate the reachable one
            assert ref.volume - ref.volume_error <= b.upper
        # inner points at random rotations of the box are feasible (dexterous); outer points
        # include every point feasible at some random rotation (reachable)
        ang = rng.uniform(-1, 1, (len(p), 3)) * math.radians(3)
        R = (Rn * Rotation.from_euler("ZYX", ang[:, ::-1])).as_matrix()
        ok = _in_stroke(luzi, p, R)
        if kind == "dexterous":
            inner = b.contains(p, "inner")
            assert inner.sum() > 100 and np.all(ok[inner])
        else:
            assert np.all(b.contains(p[ok], "outer"))
    assert vols["dexterous"][0] <= vols["reachable"][1]


@pytest.mark.parametrize(("path", "resolution"), [
    (LUZI, "20"),
    # rss6 was refused before (exit 2: 'a family with radial column kernels ... or cell leg
    # bounds')
    (MECH_DIR / "instructables-servo-6rss.yaml", "4")])
def test_cli_brackets_cell_families(tmp_path, path, resolution):
    r = CliRunner().invoke(app, ["workspace", str(path), "--resolution", resolution, "--bracket",
                                 "--bracket-budget", "1", "--bracket-target", "0.2",
                                 "--out", str(tmp_path), "--json"])
    assert r.exit_code == 0, r.output
    vb = json.loads(r.stdout)["volume_bracket"]
    assert 0 < vb["lower_mm3"] <= vb["upper_mm3"]
    assert vb["stop_reason"] in ("converged", "budget: seconds")


def test_position_curvature_bounds_the_linearisation(luzi):
    rng = np.random.default_rng(8)
    n = 40_000
    p = rng.uniform([-500, -500, 150], [500, 500, 1250], (n, 3))
    R = Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.3).as_matrix()
    delta = rng.uniform(0, 60, n)
    g, M = luzi.leg_position_curvature(p, R, delta)
    h = 1e-4                       # the gradient, against central differences
    for j in range(3):
        d = np.zeros(3)
        d[j] = h
        fd = (luzi.inverse((p + d, R), stroke=NO_STROKE).q
              - luzi.inverse((p - d, R), stroke=NO_STROKE).q) / (2 * h)
        np.testing.assert_allclose(g[:, :, j], fd, atol=1e-6)
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    dp = u * (np.where(rng.uniform(size=n) < 0.5, 1.0, rng.uniform(size=n)) * delta)[:, None]
    q = luzi.inverse((p, R), stroke=NO_STROKE).q
    q2 = luzi.inverse((p + dp, R), stroke=NO_STROKE).q
    rem = np.abs(q2 - q - np.einsum("nkj,nj->nk", g, dp))
    bound = 0.5 * M * np.sum(dp * dp, axis=1)[:, None]
    fin = np.isfinite(M) & (np.sum(dp * dp, axis=1) > 1.0)[:, None]
    assert fin.mean() > 0.9
    ratio = rem[fin] / bound[fin]
    assert ratio.max() <= 1.0 and ratio.max() > 0.5


def test_cube_fraction_matches_monte_carlo():
    from pkmlab.workspaces.bracket.partial import cube_fraction

    rng = np.random.default_rng(9)
    g = rng.normal(size=(60, 3))
    g[:10, 0] = 0.0                # degenerate directions
    g[10:15, :2] = 0.0
    s = rng.uniform(0.5, 3, 60)
    c = rng.normal(size=60) * np.abs(g).sum(axis=1) * s
    lo, hi = cube_fraction(g, c, s)
    x = rng.uniform(-1, 1, (100_000, 3))
    mc = np.array([np.mean((x * s[i]) @ g[i] <= c[i]) for i in range(60)])
    tol = 5 * np.sqrt(0.25 / len(x))
    assert np.all(lo <= mc + tol) and np.all(mc <= hi + tol) and np.all(hi - lo < 3e-3)


def test_euler_angle_bound_holds_off_level():
    """The L2 form of cells.angle_bound (sqrt(1 + sin β)·|half|₂), with the set's centre
    included in β, against the true rotation angle."""
    from pkmlab.workspaces import cells as oc

    rng = np.random.default_rng(10)
    for cy in (0.0, 0.7, 1.5):
        oset = OrientationSet.box((0.6, 0.6, 0.6)).centred((0.2, cy, -0.4))
        n = 20_000
        C = rng.uniform(-0.5, 0.5, (n, 3))
        H = rng.uniform(0, 0.3, (n, 3))
        P = C + H * rng.choice([-1.0, 1.0], (n, 3))            # cell corners: the worst case
        R0, R1 = oset.rotations_at(C), oset.rotations_at(P)
        angle = Rotation.from_matrix(np.swapaxes(R0, 1, 2) @ R1).magnitude()
        bound = oc.angle_bound(oset, C, H)
        assert np.all(angle <= bound * (1 + 1e-12))
        assert np.median(bound / H.sum(axis=1)) < 0.95     # tighter than the L1 sum
