"""The rss6 cell bracket (pkmlab.mechanisms.legs.crank_cells through bracket_cells): the crank
angle's and the rod's closing margins' bounds over a cell hold on random cells (the angle
against the IK, the closing margins against the distances to the crank ends of the crank
circle, the decisions against the IK's status), the bracket contains the engine's exact-column
volume for each kind on the shipped servo platform and on a geometry of our own, and the CLI
brackets rss6 (it refused before)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import MECH_DIR
from scipy.spatial.transform import Rotation

from pkmlab import load_mechanism
from pkmlab.mechanisms import NO_STROKE
from pkmlab.mechanisms.families.rss6 import RSS6
from pkmlab.testing import cell_points
from pkmlab.workspaces import OrientationSet, workspace
from pkmlab.workspaces.bracket.columns import volume_bracket

SERVO = MECH_DIR / "instructables-servo-6rss.yaml"


@pytest.fixture(scope="module")
def servo():
    return load_mechanism(SERVO)


@pytest.fixture(scope="module")
def own():
    """Cranks turning in radial planes (not the shipped tangential ones), a wider base, an
    off-centre servo window."""
    return RSS6.from_circles(base_radii=(120.0, 120.0), platform_radii=(60.0, 60.0),
                             crank_plane="radial", zero_direction="outward",
                             crank_length=35.0, rod_length=140.0, stroke=(-0.9, 1.3))


@pytest.fixture(scope="module")
def mixed():
    """Both branches (+1 on legs 0, 2, 4), cranks pointing inwards (leg bounds only: its
    automatic nominal pose is outside the window)."""
    return RSS6.from_circles(base_radii=(120.0, 120.0), platform_radii=(60.0, 60.0),
                             crank_plane="radial", zero_direction="inward", crank_length=35.0,
                             rod_length=140.0, stroke=(-0.9, 1.3), branch=[1, -1] * 3)


@pytest.fixture(scope="module")
def full(servo):
    """A full servo window [-π, π]: the closing limits alone decide (no window edge)."""
    return dataclasses.replace(servo, stroke_window=(-math.pi, math.pi))


def _cells(mech, rng, n, dmax=10.0, amax=0.1):
    pn = mech.nominal_pose[:3]
    p = pn + rng.uniform(-1, 1, (n, 3)) * [80, 80, 60]
    R = Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.25).as_matrix()
    delta, alpha = rng.uniform(0, dmax, n), rng.uniform(0, amax, n)
    p2, R2, _ = cell_points(rng, p, R, delta, alpha)    # half on the cell's boundary
    return p, R, delta, alpha, p2, R2


def _closing(mech, p, R):
    """Nearest and farthest distance from each platform joint to its crank circle, through
    the crank ends at the angle of the joint's projection and opposite (``crank_ends``)."""
    W = p[:, None, :] + np.einsum("nij,kj->nki", R, mech.tool_points)
    rel = W - mech.base_points
    psi = np.arctan2(np.einsum("nki,ki->nk", rel, mech.v_directions),
                     np.einsum("nki,ki->nk", rel, mech.zero_directions))
    near = np.linalg.norm(W - mech.crank_ends(psi), axis=-1)
    far = np.linalg.norm(W - mech.crank_ends(psi + math.pi), axis=-1)
    return mech.rod_length - near, far - mech.rod_length


@pytest.mark.parametrize("which", ["servo", "own", "mixed", "full"])
def test_leg_bounds_hold_on_random_cells(which, request):
    mech = request.getfixturevalue(which)
    rng = np.random.default_rng(21)
    p, R, delta, alpha, p2, R2 = _cells(mech, rng, 30_000)
    theta, et = mech.leg_cell_bounds(p, R, delta, alpha)
    _, mu, eps = mech.leg_cell_margins(p, R, delta, alpha)
    ik, ik2 = (mech.inverse(x, stroke=NO_STROKE) for x in ((p, R), (p2, R2)))
    # the angle at the centre is the IK's
    np.testing.assert_allclose(theta, ik.q, atol=1e-9)
    assert np.array_equal(np.isnan(theta), np.isnan(ik.q))
    # the angle's bound, against the IK at the other point (circular difference)
    fin = np.isfinite(et) & np.isfinite(ik2.q)
    d = np.abs(np.mod(ik2.q - theta + math.pi, 2 * math.pi) - math.pi)
    ratio = d[fin] / et[fin]
    assert fin.mean() > 0.25 and ratio.max() <= 1.0 and ratio.max() > 0.5
    # the margin where the rod does not close is the distance to the crank circle's
    # nearest or farthest point (crank_ends)
    c1, c2 = _closing(mech, p, R)
    off = np.isnan(ik.q)
    np.testing.assert_allclose(mu[off], np.minimum(c1, c2)[off], atol=1e-9)
    # |μ| bounds the distance to a point of the other status (IK status with the window):
    # D / |W' - W| <= 1 wherever the status differs
    lo, hi = mech.stroke
    with np.errstate(invalid="ignore"):
        ok, ok2 = ((np.isfinite(x.q) & (x.q >= lo) & (x.q <= hi)) for x in (ik, ik2))
    assert np.array_equal(ok, mu > 0)
    moved = np.linalg.norm((p2 - p)[:, None, :]
                           + np.einsum("nij,kj->nki", R2 - R, mech.tool_points), axis=-1)
    assert np.all(moved <= eps)
    flip = ok != ok2
    r = np.abs(mu[flip]) / moved[flip]
    assert flip.sum() > 1000 and r.max() <= 1.0 and r.max() > 0.9
    # the decisions: certainly feasible legs are feasible at the other point, certainly
    # infeasible ones are not
    surely, never = mu > eps, mu < -eps
    assert surely.sum() > 1000 and never.sum() > 1000
    assert np.all(ok2[surely]) and not np.any(ok2[never])


@pytest.mark.parametrize("which", ["servo", "mixed"])
def test_position_curvature_bounds_the_linearisation(which, request):
    """Gradient against central differences of the IK; the second-order remainder against
    its bound M·|dp|²/2 (rotation fixed), where M is finite."""
    mech = request.getfixturevalue(which)
    rng = np.random.default_rng(8)
    p, R, delta, _, p2, _ = _cells(mech, rng, 20_000)
    g, M = mech.leg_position_curvature(p, R, delta)
    fin = np.isfinite(M)
    h = 1e-5
    for j in range(3):
        d = np.zeros(3)
        d[j] = h
        fd = (mech.inverse((p + d, R), stroke=NO_STROKE).q
              - mech.inverse((p - d, R), stroke=NO_STROKE).q) / (2 * h)
        np.testing.assert_allclose(g[:, :, j][fin], fd[fin], atol=1e-7)
    dp = p2 - p
    q = mech.inverse((p, R), stroke=NO_STROKE).q
    q2 = mech.inverse((p2, R), stroke=NO_STROKE).q
    rem = np.abs(np.mod(q2 - q - np.einsum("nkj,nj->nk", g, dp) + math.pi, 2 * math.pi)
                 - math.pi)
    dd = np.sum(dp * dp, axis=1)
    sec = fin & (dd > 1.0)[:, None]
    ratio = rem[sec] / (0.5 * M * dd[:, None])[sec]
    assert fin.mean() > 0.3 and ratio.max() <= 1.0 and ratio.max() > 0.3


def _engine_inside(b, ref, kind):
    """The engine is exact in z, its volume_error covers the x-y grid; its orientation set is
    a sample: an upper estimate of the dexterous volume, a lower one of the reachable."""
    err = ref.volume_error
    if kind != "reachable":
        assert b.lower - err <= ref.volume
    if kind != "dexterous":
        assert ref.volume <= b.upper + err


@pytest.mark.parametrize("which", ["servo", "own"])
def test_constant_bracket_contains_the_engine_volume(which, request):
    mech = request.getfixturevalue(which)
    b = volume_bracket(mech, "constant", None, 2.0, budget_s=60, max_evaluations=1.5e6)
    ref = workspace(mech, "constant", resolution=1.0)
    assert b.stop_reason == "budget: evaluations" and 0 < b.lower < b.upper
    _engine_inside(b, ref, "constant")
    assert b.upper - b.lower < 0.25 * b.upper
    lows = [r["lower_mm3"] for r in b.history]
    assert lows == sorted(lows)
    # pointwise: inner points are feasible, feasible points are outer (IK, independent)
    rng = np.random.default_rng(4)
    pn = mech.nominal_pose[:3]
    p = pn + rng.uniform(-1, 1, (40_000, 3)) * [80, 80, 50]
    R = np.broadcast_to(np.eye(3), (len(p), 3, 3))
    ik = mech.inverse((p, R), stroke=NO_STROKE)
    lo, hi = mech.stroke
    with np.errstate(invalid="ignore"):
        ok = ik.valid & np.all((ik.q >= lo) & (ik.q <= hi), axis=1)
    inner = b.contains(p, "inner")
    assert inner.sum() > 1000 and np.all(ok[inner])
    assert np.all(b.contains(p[ok], "outer"))


@pytest.mark.parametrize("kind", ["dexterous", "reachable"])
def test_orientation_brackets_hold(kind, servo):
    box = OrientationSet.box((math.radians(2),) * 3, samples=3)
    b = volume_bracket(servo, kind, box, 4.0, budget_s=60, max_evaluations=2e6)
    ref = workspace(servo, kind, box, resolution=2.0)
    assert 0 <= b.lower < b.upper
    _engine_inside(b, ref, kind)
    rng = np.random.default_rng(7)
    p = servo.nominal_pose[:3] + rng.uniform(-1, 1, (20_000, 3)) * [120, 120, 70]
    ang = rng.uniform(-1, 1, (len(p), 3)) * math.radians(2)
    R = Rotation.from_euler("ZYX", ang[:, ::-1]).as_matrix()
    ik = servo.inverse((p, R), stroke=NO_STROKE)
    lo, hi = servo.stroke
    with np.errstate(invalid="ignore"):
        ok = ik.valid & np.all((ik.q >= lo) & (ik.q <= hi), axis=1)
    if kind == "dexterous":
        inner = b.contains(p, "inner")
        assert b.lower > 0 and inner.sum() > 100 and np.all(ok[inner])
    else:
        assert np.all(b.contains(p[ok], "outer"))
