"""Exact crank and inclined-rail slider columns of the generic ``sixleg`` family.

A ``sixleg`` declared from an ``rss6`` (same joints, axes, lengths, branches, window) must give
the same column sets and workspace volumes as ``rss6``'s own exact crank method (validated
against dense IK in ``test_rss6_columns.py``), and its interval ends must be where the
*sixleg's own* IK kernel flips validity. Paths that need single-interval radial legs (refine,
exact task check, continuous optima) must decline it as they decline ``rss6``. Inclined and
horizontal rails (``mechanisms/legs/slider.py``) are checked against the IK on a dense z grid and
at 1e-9 mm either side of every interval end.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from scipy.spatial.transform import Rotation

import pkmlab
from pkmlab.mechanisms import RSS6, SixLeg
from pkmlab.requirements.task import TaskRegion, task_contained
from pkmlab.testing import check_columns
from pkmlab.workspaces import Constraints, OrientationSet, workspace
from pkmlab.workspaces.optima.search import supports_continuous

EPS = 1e-9                                         # boundary probe (mm)
FILE = ROOT / "studies/mechanisms/instructables-servo-6rss.yaml"


def _tilted():
    """The servo hexapod with servo axes 1, 3, 5 tilted 20° about their zero directions and
    mixed branches (``u_z``, ``v_z`` terms of the crank equation non-zero)."""
    g = pkmlab.load_mechanism(FILE)
    n = g.servo_axes.copy()
    for i in range(0, 6, 2):
        n[i] = Rotation.from_rotvec(np.radians(20.0) * g.zero_directions[i]).apply(n[i])
    return RSS6(g.base_points, g.platform_points, n, g.zero_directions, g.crank_length,
                g.rod_length, g.stroke, branch=[-1, 1, -1, -1, 1, -1])


GEOMETRIES = {
    "file": lambda: pkmlab.load_mechanism(FILE),
    "tilted": _tilted,
    # tests/mechanisms/test_rss6_columns.py's sized geometry: non-empty ±10° dexterous workspace
    "sized": lambda: RSS6.from_circles(base_radii=(102.0, 102.0), platform_radii=(80.0, 80.0),
                                       crank_length=46.0, rod_length=183.0,
                                       crank_plane="tangential"),
}


def _close(a, b, scale):
    """Equal to 1e-9 relative (of the mechanism's scale for the interval ends); empty slots
    (±inf) in the same places."""
    assert np.array_equal(np.isfinite(a), np.isfinite(b))
    f = np.isfinite(a)
    np.testing.assert_allclose(a[f], b[f], rtol=1e-9, atol=1e-9 * scale)


@pytest.mark.parametrize("name", sorted(GEOMETRIES))
def test_crank_sixleg_columns_equal_rss6(name):
    rss = GEOMETRIES[name]()
    six = SixLeg.from_mechanism(rss)
    assert six.column_method == "crank" and six.column_leg is None and not six.column_radial
    oset = OrientationSet.box(np.radians([4.0] * 3), "simultaneous", samples=2)
    R = oset.centred((0.0, 0.0, 0.0)).rotations()
    xs, ys = np.linspace(-40.0, 40.0, 9), np.linspace(-35.0, 35.0, 8)
    pieces = 0
    for mode in ("all", "any"):
        lo, hi, over = six.column_intervals(xs, ys, R, mode)
        lo_r, hi_r, over_r = rss.column_intervals(xs, ys, R, mode)
        assert over == over_r == 0
        _close(lo, lo_r, rss.scale)
        _close(hi, hi_r, rss.scale)
        pieces += int(np.sum(lo <= hi))
    assert pieces > 20
    # the sixleg's own IK flips validity at interval ends (independent of rss6)
    checked = 0
    for mode, agg in (("all", np.all), ("any", np.any)):
        lo, hi, _ = six.column_intervals(xs, ys, R, mode)
        for ix, iy, k in list(zip(*np.nonzero(lo <= hi), strict=True))[::7]:
            for z, inward in ((lo[ix, iy, k], EPS), (hi[ix, iy, k], -EPS)):
                p = np.tile([xs[ix], ys[iy], 0.0], (2 * len(R), 1))
                p[:len(R), 2] = z + inward
                p[len(R):, 2] = z - inward
                v = six.inverse((p, np.concatenate([R, R]))).valid
                assert agg(v[:len(R)]) and not agg(v[len(R):])
                checked += 1
    assert checked >= 4


@pytest.mark.parametrize("name", sorted(GEOMETRIES))
def test_crank_sixleg_workspace_volumes_equal_rss6(name):
    rss = GEOMETRIES[name]()
    six = SixLeg.from_mechanism(rss)
    cons = Constraints(connected=False)
    box = OrientationSet.box(np.radians([10.0] * 3), "simultaneous", samples=2)
    for kind, oset in (("constant", None), ("reachable", box), ("dexterous", box)):
        a = workspace(six, kind, oset, 6.0, cons)
        b = workspace(rss, kind, oset, 6.0, cons)
        assert a.method == b.method == "columns (crank), exact in z"
        assert abs(a.volume - b.volume) <= 1e-9 * b.volume
        if name == "sized":
            assert b.volume > 1e4
        assert abs(a.volume_error - b.volume_error) <= 1e-9 * b.volume_error


def test_crank_sixleg_declines_radial_only_paths():
    six = SixLeg.from_mechanism(GEOMETRIES["sized"]())
    oset = OrientationSet.box(np.radians([5.0] * 3), "simultaneous", samples=2)
    r = workspace(six, "dexterous", oset, 8.0, refine=True)
    assert r.method == "columns (crank), exact in z"
    assert any("refine: not available" in n for n in r.notes)
    assert not supports_continuous(six)
    task = TaskRegion("box", size=(4.0, 4.0, 4.0))
    assert task_contained(six, task, resolution=2.0).method == "sampled"
    # linear-leg sixlegs keep the class-level radial legs and the exact task check
    ups = SixLeg.from_mechanism(pkmlab.load_mechanism(
        ROOT / "studies/mechanisms/gough-stewart-6ups.yaml"))
    assert ups.column_radial and ups.column_leg is not None and supports_continuous(ups)
    assert task_contained(ups, task).method == "exact"


# ---- inclined and horizontal rails ------------------------------------------------------------

def _hexaglide(incl_deg):
    from test_sixleg import _hexaglide as make

    return make(incl_deg)


def _mixed():
    from test_sixleg import _mixed_linear

    return _mixed_linear()


SLIDERS = {"hexaglide": lambda: pkmlab.load_mechanism(ROOT / "studies/mechanisms/"
                                                       "hexaglide-6pus.yaml"),
           "inclined20": lambda: _hexaglide(20.0), "mixed": _mixed}
DZ = 0.1                                           # dense z step (mm)


@pytest.mark.parametrize("name", sorted(SLIDERS))
@pytest.mark.parametrize("mode", ["all", "any"])
def test_slider_columns_match_dense_ik(name, mode):
    m = SLIDERS[name]()
    assert m.column_method == "slider" and m.column_leg is None and not m.column_radial
    oset = OrientationSet.box(np.radians([4.0] * 3), "simultaneous", samples=2)
    _, Rn = pkmlab.poses.as_frames(m.nominal_pose)
    R = oset.centred(tuple(pkmlab.poses.matrix_to_euler(Rn[0]))).rotations()
    c = m.nominal_pose[:2]
    xs, ys = c[0] + np.linspace(-60.0, 60.0, 3), c[1] + np.linspace(-50.0, 50.0, 3)
    pieces = check_columns(m, R, xs, ys, mode, dz=DZ, eps=EPS)
    assert pieces >= 5


@pytest.mark.parametrize("name", ["hexaglide", "inclined20"])
def test_slider_workspace_against_sampled(name):
    m = SLIDERS[name]()
    r = workspace(m, "constant", resolution=8.0)
    s = workspace(m, "constant", resolution=8.0, method="sampled")
    assert r.method == "columns (slider), exact in z" and s.method == "sampled voxels"
    assert abs(r.volume - s.volume) <= r.volume_error + s.volume_error
    box = OrientationSet.box(np.radians([5.0] * 3), "simultaneous", samples=2)
    d = workspace(m, "dexterous", box, 8.0, refine=True)
    assert d.volume > 0 and any("refine: not available" in n for n in d.notes)


def test_slider_interval_against_a_numpy_scan():
    """:func:`._slider.slider_interval` on 300 random legs (inclination ±80°, any heading,
    branch, side, window) against the leg conditions evaluated in NumPy (h² ≥ 0, side, stroke)
    on a 0.05 mm z grid: the sets differ only at grid points next to the interval ends."""
    from pkmlab.mechanisms.legs.slider import slider_interval

    rng = np.random.default_rng(7)
    zs = np.arange(-1200.0, 1200.0, 0.05)
    nonempty = 0
    for _ in range(300):
        incl, head = np.radians(rng.uniform(-80, 80)), rng.uniform(0, 2 * np.pi)
        e = np.array([np.cos(incl) * np.cos(head), np.cos(incl) * np.sin(head), np.sin(incl)])
        ln, b, s = rng.uniform(100, 500), rng.choice([-1.0, 1.0]), rng.choice([-1.0, 1.0])
        X, Y, wz = rng.uniform(-400, 400), rng.uniform(-400, 400), rng.uniform(-100, 100)
        qmin, qmax = np.sort(rng.uniform(-400, 400, 2))
        lo, hi, ok = slider_interval(X, Y, wz, *e, ln, b, s, qmin, qmax)
        d = np.stack([np.full_like(zs, X), np.full_like(zs, Y), zs + wz], axis=1)
        t = d @ e
        perp = d - t[:, None] * e
        h2 = ln * ln - np.sum(perp**2, axis=1)
        h = np.sqrt(np.clip(h2, 0.0, None))
        q = t + b * h
        v = (h2 >= 0) & (s * (perp[:, 2] - b * h * e[2]) >= 0) & (q >= qmin) & (q <= qmax)
        exact = (zs >= lo) & (zs <= hi) if ok else np.zeros(len(zs), dtype=bool)
        near = (np.abs(zs - lo) < 0.05) | (np.abs(zs - hi) < 0.05) if ok else exact
        assert np.array_equal(exact[~near], v[~near])
        nonempty += bool(ok and lo <= hi)
    assert nonempty > 60
