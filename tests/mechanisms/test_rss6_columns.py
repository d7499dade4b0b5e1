"""6-RSS exact column method (``mechanisms/legs/crank.py``) against dense brute force.

The crank leg's feasible z set on a column comes from quartic and quadratic roots; here it is
checked against the IK kernel itself evaluated on a fine z grid (lengths within the grid
error), and each interval end against the IK just inside and just outside it (1e-9 mm).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import pkmlab
from pkmlab.mechanisms import RSS6
from pkmlab.workspaces import Constraints, OrientationSet, workspace

FILE = Path(__file__).resolve().parents[2] / "studies" / "mechanisms" / \
    "instructables-servo-6rss.yaml"
DZ = 0.05          # brute-force z step (mm)
EPS = 1e-9         # boundary probe (mm)


def _tilted():
    """Servo axes tilted out of the horizontal (u_z, v_z both non-zero), mixed branches and
    a window reaching -180 deg: every term of the crank equation is exercised."""
    base = RSS6.from_circles(crank_length=35.0, rod_length=150.0, crank_plane="radial")
    rng = np.random.default_rng(5)
    n = base.servo_axes + rng.normal(scale=0.3, size=(6, 3))
    u = base.zero_directions + rng.normal(scale=0.3, size=(6, 3))
    return RSS6(base.base_points, base.platform_points, n, u, base.crank_length,
                base.rod_length, (-math.pi, 2.0), branch=[-1, 1, -1, -1, 1, -1])


GEOMETRIES = {
    "file": lambda: pkmlab.load_mechanism(FILE),
    "sized": lambda: RSS6.from_circles(base_radii=(102.0, 102.0), platform_radii=(80.0, 80.0),
                                       crank_length=46.0, rod_length=183.0,
                                       crank_plane="tangential"),
    "tilted": _tilted,
}


def _rotations(mech, tilt_deg):
    oset = OrientationSet.box(np.radians([tilt_deg] * 3), "simultaneous", samples=2)
    return oset.centred((0.0, 0.0, 0.0)).rotations()


def _valid(mech, x, y, z, R):
    """IK validity ``(len(z), M)`` of the poses (x, y, z) at each rotation of ``R``."""
    z = np.atleast_1d(np.asarray(z, dtype=float))
    out = np.empty((len(z), len(R)), dtype=bool)
    p = np.stack([np.full_like(z, x), np.full_like(z, y), z], axis=1)
    for m, Rm in enumerate(R):
        out[:, m] = mech.inverse((p, np.broadcast_to(Rm, (len(z), 3, 3)).copy())).valid
    return out


@pytest.mark.parametrize("name", sorted(GEOMETRIES))
@pytest.mark.parametrize("mode", ["all", "any"])
def test_column_sets_match_dense_ik(name, mode):
    mech = GEOMETRIES[name]()
    R = _rotations(mech, 4.0)                    # 8 corners of a ±4° box
    xs = np.linspace(-30.0, 30.0, 3)
    ys = np.linspace(-25.0, 25.0, 3)
    lo, hi, overflow = mech.column_intervals(xs, ys, R, mode)
    assert overflow == 0
    box = mech.position_bounds(R)                # holds every feasible position
    zs = np.arange(box[:, 0, 2].min() - 1.0, box[:, 1, 2].max() + 1.0, DZ)
    pieces = 0
    for ix, x in enumerate(xs):
        for iy, y in enumerate(ys):
            v = _valid(mech, x, y, zs, R)
            inside = v.all(axis=1) if mode == "all" else v.any(axis=1)
            sel = lo[ix, iy] <= hi[ix, iy]
            a, b = lo[ix, iy][sel], hi[ix, iy][sel]
            assert np.all(a > zs[0]) and np.all(b < zs[-1])
            # lengths within the grid error: each end costs at most one step
            assert abs(inside.sum() * DZ - np.sum(b - a)) <= 2 * len(a) * DZ + 1e-9
            # every grid point is classified as the exact set says, away from its ends
            exact = np.zeros(len(zs), dtype=bool)
            for a_k, b_k in zip(a, b, strict=True):
                exact |= (zs >= a_k) & (zs <= b_k)
            near = np.zeros(len(zs), dtype=bool)
            for e in np.concatenate([a, b]):
                near |= np.abs(zs - e) < 1e-6
            assert np.array_equal(exact[~near], inside[~near])
            # ends to 1e-9 mm: the IK flips between e - EPS and e + EPS
            for a_k, b_k in zip(a, b, strict=True):
                vin = _valid(mech, x, y, [a_k + EPS, b_k - EPS], R)
                vout = _valid(mech, x, y, [a_k - EPS, b_k + EPS], R)
                agg = (lambda t: t.all(axis=1)) if mode == "all" else (lambda t: t.any(axis=1))
                assert agg(vin).all() and not agg(vout).any()
            pieces += len(a)
    assert pieces >= 3                           # the columns are not all empty


def test_dexterous_volume_matches_brute_force_voxels():
    """Engine volume (exact in z) against dense IK at 0.1 mm in z on every 9th column (of the
    same x-y grid), 27 orientations: equal within the z-grid error."""
    mech = GEOMETRIES["sized"]()
    oset = OrientationSet.box(np.radians([10.0] * 3), "simultaneous", samples=3)
    res = workspace(mech, "dexterous", oset, 6.0, Constraints(connected=False))
    assert res.method == "columns (crank), exact in z"
    R = res.orientations.rotations()
    dz = 0.1
    zs = np.arange(res.zs[0] - 6.0, res.zs[-1] + 6.0, dz)
    count, ends, exact = 0, 0, 0.0
    for k, (ix, iy) in enumerate(np.ndindex(len(res.xs), len(res.ys))):
        if k % 9:
            continue
        count += int(_valid(mech, res.xs[ix], res.ys[iy], zs, R).all(axis=1).sum())
        sel = res.lo[ix, iy] <= res.hi[ix, iy]
        ends += 2 * int(np.sum(sel))
        exact += float(np.sum(res.hi[ix, iy][sel] - res.lo[ix, iy][sel]))
    assert res.volume > 1e5 and exact > 200.0
    assert abs(count * dz - exact) <= ends * dz


def test_sampled_and_column_methods_agree_at_voxel_centres():
    mech = GEOMETRIES["file"]()
    cons = Constraints(connected=False)
    a = workspace(mech, "constant", resolution=4.0, constraints=cons)
    b = workspace(mech, "constant", resolution=4.0, constraints=cons, method="sampled")
    assert a.method.startswith("columns") and b.method == "sampled voxels"
    # exact volume vs the voxel count: within one voxel per column end
    ends = int(np.sum(a.lo <= a.hi)) * 2
    assert abs(a.volume - b.volume) <= ends * 0.5 * 4.0 ** 3


def test_refine_is_declined_with_a_note():
    mech = GEOMETRIES["sized"]()
    oset = OrientationSet.box(np.radians([5.0] * 3), "simultaneous", samples=2)
    r = workspace(mech, "dexterous", oset, 8.0, refine=True)
    assert any("refine: not available" in n for n in r.notes)
