"""Continuous optima (capability, needed stroke) and the exact tile pruning of the engine.

Independent checks: the plain column kernel (no pruning) for the tiles; the inverse
kinematics (not the column kernels) with dense orientation sampling and local optimisation for
the certified points; local optimisation over continuous positions for the empty samples.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import MECH_DIR as STUDIES
from conftest import assert_point_holds
from scipy.optimize import minimize

from pkmlab import UPS6, load_mechanism
from pkmlab.mechanisms import NO_STROKE
from pkmlab.mechanisms.kernels import columns as column_kernels
from pkmlab.mechanisms.kernels import ik as _kernels
from pkmlab.mechanisms.kernels import tiles as _tiles
from pkmlab.poses import euler_to_matrix
from pkmlab.workspaces import OrientationSet
from pkmlab.workspaces.engine import _grid_xy
from pkmlab.workspaces.optima.search import orientation_capability, stroke_needed


@pytest.fixture(scope="module")
def hopkins():
    return load_mechanism(STUDIES / "hopkins-williams-6psu.yaml")


def _plain_and_tiled(mech, R, h):
    xs, ys, _ = _grid_xy(mech, R, "all", h)
    W = mech.leg_offsets(R)
    W = _kernels.carray(W[np.argsort(-np.linalg.norm(R - np.eye(3), axis=(1, 2)),
                                     kind="stable")])
    P = _kernels.carray(mech.column_params())
    out = [np.empty((len(xs), len(ys), 1)) for _ in range(4)]
    column_kernels.make_column_kernel(type(mech).column_leg, "all")(
        _kernels.carray(xs), _kernels.carray(ys), W, P, out[0], out[1])
    _tiles.make_tiled_all(type(mech).column_leg)(
        _kernels.carray(xs), _kernels.carray(ys), W, P, out[2], out[3])
    return out


@pytest.mark.parametrize("case", ["psu15", "ups10", "ups20"])
def test_tile_pruning_gives_identical_intervals(hopkins, case):
    """The pruned kernel keeps every column's max a / min b bit for bit (6-PSU and 6-UPS)."""
    if case == "psu15":
        mech, a, h = hopkins, 15.0, 1.0
    else:
        mech = load_mechanism(STUDIES / "gough-stewart-6ups.yaml")
        a, h = (10.0, 10.0) if case == "ups10" else (20.0, 7.5)
    R = euler_to_matrix(OrientationSet.box(np.radians([a] * 3), samples=5).parameters())
    lo, hi, tlo, thi = _plain_and_tiled(mech, R, h)
    inside = lo <= hi
    assert inside.sum() > 100 and (~inside).sum() > 100     # both kinds of column exist
    assert np.array_equal(lo, tlo) and np.array_equal(hi, thi)


def _psu_margin_at(mech, x, y, R):
    """Along the column (x, y) a 6-PSU's slider is q = z + c (slope 1): the z interval of every
    leg × orientation from the inverse kinematics at z = 0 → (max a, min b)."""
    n = len(R)
    ik = mech.inverse((np.tile([x, y, 0.0], (n, 1)), R), stroke=NO_STROKE)
    q0 = np.where(np.isfinite(ik.q), ik.q, np.nan)
    if np.isnan(q0).any():
        return np.inf, -np.inf
    lo, hi = mech.stroke
    return float(np.max(lo - q0)), float(np.min(hi - q0))


def _assert_capability_holds(mech, b, rng):
    """Lower end: the certified point keeps every leg in stroke at 20,000 random orientations
    of the continuous box and at local minima of its margin found from the worst of them.
    Upper end: local maximisation of the column margin over continuous positions finds no
    position for the search's sample (the grid plus the cut orientations) at that level."""
    p = np.asarray(b.point)
    assert_point_holds(mech, p, math.radians(b.lower), rng)
    E = np.vstack([OrientationSet.box(np.radians([b.upper] * 3), samples=b.samples)
                   .parameters(), np.asarray(b.binding).reshape(-1, 3)])
    assert np.all(np.abs(E) <= math.radians(b.upper) * (1 + 1e-12))       # inside the box
    Rs = euler_to_matrix(E)

    def neg(v):
        lo, hi = _psu_margin_at(mech, v[0], v[1], Rs)
        return -(hi - lo) if np.isfinite(hi - lo) else 1e3

    starts = [p[:2]] + list(p[:2] + rng.normal(0, 5, (2, 2)))
    best = min(minimize(neg, s, method="Nelder-Mead",
                        options={"xatol": 1e-7, "fatol": 1e-9}).fun for s in starts)
    assert -best < 0.0


def test_capability_bracket_holds_independently(hopkins):
    """Hopkins & Williams: the bracket is within 0.01° and both ends hold independently."""
    b = orientation_capability(hopkins, 5)
    assert b.note == "" and 0.0 <= b.width <= 0.01 + 1e-9
    assert 23.1 < b.lower <= b.upper <= b.sampled + 0.01 < 23.26   # measured: 23.170 / 23.176
    _assert_capability_holds(hopkins, b, np.random.default_rng(3))


def test_capability_upper_end_uses_the_cut_orientations():
    """A demo-study design whose binding orientations lie between the 5³ samples: the grid's
    capability is 38.17° and the bracket was [38.02°, 38.17°]; with the orientations that
    refuted points (cuts) the upper end comes down to within 0.01° of the certified one."""
    from pkmlab import PSU6

    mech = PSU6.from_circles(base_radii=(100.0, 132.593374), platform_radii=(47.788508, 48.541357),
                             platform_rotation=0.169805412, link_length=297.961762)
    b = orientation_capability(mech, 5)
    assert b.note == "" and b.sampled - b.lower > 0.1                 # measured: 0.150°
    assert 0.0 <= b.width <= 0.015 and len(b.binding) > 0            # measured: 0.0097°
    _assert_capability_holds(mech, b, np.random.default_rng(4))


def test_stroke_needed_bracket(hopkins):
    """The ±30° set of Hopkins & Williams: the stroke (0 to q_max) it needs is bracketed, the
    certified point holds at dense orientations, and the search's sample (grid plus binding
    orientations) at the lower end admits no position (local search)."""
    o = OrientationSet.box(np.radians([30.0] * 3), samples=5)
    b = stroke_needed(hopkins, o)
    assert b.sampled <= b.lower <= b.upper and 128.0 < b.lower and b.upper < 134.0
    mech = dataclasses.replace(hopkins, stroke_window=(0.0, b.upper))
    th = math.radians(30.0)
    assert_point_holds(mech, np.asarray(b.point), th, np.random.default_rng(5), minima=0)
    low = dataclasses.replace(hopkins, stroke_window=(0.0, b.lower))
    Rs = euler_to_matrix(np.vstack([o.parameters(), np.asarray(b.binding).reshape(-1, 3)]))
    res = minimize(lambda v: -np.subtract(*_psu_margin_at(low, v[0], v[1], Rs)[::-1]),
                   np.asarray(b.point[:2]), method="Nelder-Mead", options={"xatol": 1e-7})
    assert -res.fun < 0.0


def test_continuous_search_refuses_other_families():
    from pkmlab.errors import ParameterError

    mech = load_mechanism(STUDIES / "luzi-3chain.yaml")
    with pytest.raises(ParameterError, match="family"):
        orientation_capability(mech, 5)


def test_capability_on_a_6ups_is_bracketed():
    """A small 6-UPS: the certified lower end is below the upper end and the grid value."""
    mech = UPS6.from_circles(base_radii=(100.0, 165.0), platform_radii=(50.0, 80.0),
                             platform_rotation=math.radians(33.7), base_pair_separation=0.0,
                             platform_pair_separation=0.0, stroke=(250.0, 350.0))
    b = orientation_capability(mech, 5)
    assert b.lower <= b.upper <= b.sampled + 0.01 and b.width <= 0.05 and b.lower > 1.0
    p = np.asarray(b.point)
    th = math.radians(b.lower)
    assert_point_holds(mech, p, th, np.random.default_rng(1), minima=0)
