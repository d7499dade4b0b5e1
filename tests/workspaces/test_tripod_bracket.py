"""The guaranteed (z, θx, θy) volume bracket of the 3-PRS tripod (issue 24): the interval
arithmetic against sampled points, the bracket against a dense grid count and against the
inverse kinematics at random points (every feasible point in the bracket's outer set, every
point of its inner boxes feasible), on vertical rails (column form) and inclined rails (box
form), and a deliberately broken enclosure that the same checks catch."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab.mechanisms.families.prs3 import Prs3, tripod_layout
from pkmlab.mechanisms.families.prs3_boxes import classify_boxes
from pkmlab.mechanisms.kernels.interval_arith import Iv
from pkmlab.workspaces.tripod import _z_bounds, tripod_volume_bracket, tripod_workspace

TILT = math.radians(20.0)


@pytest.fixture(scope="module")
def mech():
    return pkmlab.load_mechanism(MECH_DIR / "tripod-3prs.yaml")


@pytest.fixture(scope="module")
def inclined():
    a, d, n, b = tripod_layout(200.0, 100.0, math.radians(15.0))
    return Prs3(a, b, d, n, [250.0] * 3, (0.0, 400.0))


def _feasible(mech, F):
    X = np.zeros((len(F), 6))
    X[:, 2:5] = F
    return mech.inverse(X).valid


def _violations(mech, br, n=40_000, seed=0):
    """(feasible random points outside the outer set, infeasible points drawn in inner
    boxes): both must be 0 for a correct bracket."""
    rng = np.random.default_rng(seed)
    zlo, zhi = _z_bounds(mech)
    F = np.column_stack([rng.uniform(zlo, zhi, n), rng.uniform(-TILT, TILT, (n, 2))])
    ok = _feasible(mech, F)
    missed = int((~br.contains(F[ok])).sum())
    B = br.inner
    vol = np.prod(B[:, 1] - B[:, 0], axis=1)
    pick = rng.choice(len(B), size=min(n // 4, 20 * len(B)), p=vol / vol.sum())
    G = B[pick, 0] + rng.uniform(size=(len(pick), 3)) * (B[pick, 1] - B[pick, 0])
    wrong = int((~_feasible(mech, G)).sum())
    assert ok.sum() > 1000 and len(G) > 1000
    return missed, wrong


def test_interval_arithmetic_encloses_sampled_values():
    rng = np.random.default_rng(3)
    lo = rng.uniform(-4, 4, 500)
    hi = lo + rng.uniform(0, 3, 500)
    x = Iv(lo, hi)
    t = rng.uniform(size=(200, 1))
    pts = lo + t * (hi - lo)                                  # (200, 500) points inside
    y = Iv(lo - 1.0, hi + 0.5)
    pts_y = (lo - 1.0) + rng.uniform(size=(200, 1)) * (hi - lo + 1.5)
    checks = [(x.cos(), np.cos(pts)), (x.sin(), np.sin(pts)), (x.atan(), np.arctan(pts)),
              (x.sq(), pts ** 2), (x * y, pts * pts_y), (x - y, pts - pts_y),
              (x + 2.5, pts + 2.5), ((x * 0.3).acos(), np.arccos(np.clip(pts * 0.3, -1, 1))),
              (Iv(np.abs(lo), np.abs(lo) + 1).sqrt(), np.sqrt(np.abs(lo) + t))]
    for enc, val in checks:
        assert np.all((enc.lo <= val) & (val <= enc.hi))
    pos = Iv(np.abs(lo) + 0.1, np.abs(lo) + 2)
    v = np.abs(lo) + 0.1 + t * 1.9
    r = pos.recip()
    assert np.all((r.lo <= 1 / v) & (1 / v <= r.hi))
    # cos over an interval holding a maximum / minimum reaches ±1
    c = Iv(np.array([-0.1, 3.0]), np.array([0.1, 3.3])).cos()
    assert c.hi[0] == 1.0 and c.lo[1] == -1.0


def test_column_bracket_against_a_dense_grid_and_random_points(mech):
    br = tripod_volume_bracket(mech, TILT, target=0.01)
    assert br.stop_reason == "converged" and 0 < br.relative_width <= 0.01
    assert br.lower > 0 and len(br.undecided) > 0
    dense = tripod_workspace(mech, TILT, resolution_z=5.0, resolution_angle=math.radians(1.0),
                             bracket_target=None).volume
    assert br.lower <= dense <= br.upper, (br.lower, dense, br.upper)
    tight = tripod_volume_bracket(mech, TILT, target=0.003)
    assert tight.lower <= dense <= tight.upper
    assert br.lower <= tight.lower <= tight.upper <= br.upper
    assert _violations(mech, br) == (0, 0)


def test_box_bracket_on_inclined_rails(inclined):
    br = tripod_volume_bracket(inclined, TILT, target=0.05)
    assert br.stop_reason == "converged"
    grid = tripod_workspace(inclined, TILT, resolution_z=5.0,
                            resolution_angle=math.radians(1.0), bracket_target=None)
    assert not grid.notes and br.lower <= grid.volume <= br.upper
    assert _violations(inclined, br) == (0, 0)


def test_box_and_column_forms_agree_on_vertical_rails(mech):
    col = tripod_volume_bracket(mech, TILT, target=0.01)
    box = tripod_volume_bracket(mech, TILT, target=0.06, classify=classify_boxes)
    assert box.lower <= col.upper and col.lower <= box.upper
    assert box.upper - box.lower > col.upper - col.lower


def test_a_broken_enclosure_is_caught(mech):
    """Classifying each box by its centre alone (a point evaluation passed off as an
    enclosure) counts infeasible points as proved feasible: the random-point check finds
    them, so the checks above can fail."""
    def centre_only(m, lo, hi, slack):
        c = 0.5 * (lo + hi)
        return classify_boxes(m, c, c, slack)

    br = tripod_volume_bracket(mech, TILT, target=0.06, classify=centre_only, max_level=3)
    missed, wrong = _violations(mech, br)
    assert wrong > 0 or missed > 0


def test_workspace_metrics_carry_the_bracket(mech):
    res = tripod_workspace(mech, TILT, resolution_z=5.0, resolution_angle=math.radians(1.0))
    m = res.metrics()
    lo, hi = m["volume_bracket_mm_rad2"]
    assert lo <= res.volume <= hi and hi - lo <= 0.01 * hi
    d2 = math.degrees(1) ** 2
    assert m["volume_bracket_mm_deg2"] == pytest.approx([lo * d2, hi * d2], rel=1e-15)
    assert m["sampled_volume_mm_deg2"] == pytest.approx(res.volume * d2, rel=1e-15)
    assert m["bracket"]["stop_reason"] == "converged"
    assert "volume_mm_deg2" not in m


def test_a_z_range_clips_the_bracket_like_the_grid(mech):
    """With a z range the bracket is of the set within it (column form clipped; the box
    form over the same range agrees), and the grid count over that range lies inside."""
    zr = (-240.0, -60.0)                       # crosses the set's lower boundary
    col = tripod_volume_bracket(mech, TILT, z_range=zr, target=0.01)
    full = tripod_volume_bracket(mech, TILT, target=0.01)
    assert col.stop_reason == "converged" and 0 < col.lower and col.upper < full.lower
    grid = tripod_workspace(mech, TILT, z_range=zr, resolution_z=2.0,
                            resolution_angle=math.radians(1.0), bracket_target=None)
    # the grid's end row z = -60 mm (inside the set) counts a whole 2 mm row where the range
    # holds half of one (the row at -240 mm is empty): 181 mm of rows for 180 mm
    est = grid.volume * 180.0 / 181.0
    assert col.lower <= est <= col.upper, (col.lower, est, col.upper)
    box = tripod_volume_bracket(mech, TILT, z_range=zr, target=0.08, classify=classify_boxes)
    assert box.lower <= col.upper and col.lower <= box.upper
