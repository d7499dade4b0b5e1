"""The capability search's pair pruning (issue 28, session 4) changes no output.

The reference is the previous algorithm, kept verbatim in ``_search_reference.py``: the
branch and bound must return the same status, best margin, point, z interval and tile count
bit for bit (the discarded tiles' bound ``out[BB_UB]`` may differ but stays a bound of the
best margin), in both modes, at levels near each design's capability where it does the most
work; the whole capability search (13 outputs and the cut orientations) must be bit-identical
on non-paper 6-PSU and 6-UPS designs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _search_reference import reference_bb, reference_capability

from pkmlab import PSU6, UPS6
from pkmlab.mechanisms.kernels import ik as _kernels
from pkmlab.mechanisms.kernels import search as _search
from pkmlab.mechanisms.kernels.branch import BB_F, BB_UB
from pkmlab.poses import euler_to_matrix
from pkmlab.workspaces.optima import search as optima

# demo-study designs (Sobol points of studies/hopkins-6psu-redesign.yaml) and two 6-UPS
DESIGNS = {
    "psu-a": lambda: PSU6.from_circles(base_radii=(100.0, 115.8777),
                                       platform_radii=(33.0538, 85.6739),
                                       platform_rotation=0.4523, link_length=292.8849),
    "psu-b": lambda: PSU6.from_circles(base_radii=(100.0, 146.9105),
                                       platform_radii=(40.6077, 71.0013),
                                       platform_rotation=0.2449, link_length=199.0569),
    "psu-c": lambda: PSU6.from_circles(base_radii=(100.0, 131.5809),
                                       platform_radii=(57.0177, 84.8563),
                                       platform_rotation=1.0426, link_length=282.5437),
    "ups-a": lambda: UPS6.from_circles(base_radii=(100.0, 165.0), platform_radii=(50.0, 80.0),
                                       platform_rotation=math.radians(33.7),
                                       stroke=(250.0, 350.0)),
    "ups-b": lambda: UPS6.from_circles(base_radii=(120.0, 150.0), platform_radii=(60.0, 90.0),
                                       platform_rotation=math.radians(20.0),
                                       base_pair_separation=0.3, platform_pair_separation=0.2,
                                       stroke=(240.0, 330.0)),
}


def _args(mech):
    e0, U, B, box = optima._inputs(mech)
    P = _kernels.carray(mech.column_params())
    return (U, B, P, optima._profile(mech), e0, 5, box, optima.FIRST_TILE_MM, math.pi,
            math.radians(0.01), optima.MIN_TILE_MM, optima.MIN_HALF_RAD,
            optima.CAPABILITY_CELL_BUDGET)


def _capability(kernel, mech):
    out, cuts = np.full(13, np.nan), np.full((_search.CUTS, 3), np.nan)
    kernel(*_args(mech), out, cuts)
    return out, cuts


@pytest.mark.parametrize("name", sorted(DESIGNS))
def test_capability_search_is_bit_identical_to_the_previous_algorithm(name):
    mech = DESIGNS[name]()
    leg = type(mech).column_leg
    new, new_cuts = _capability(_search.make_capability(leg), mech)
    old, old_cuts = _capability(reference_capability(leg), mech)
    assert 0.0 < new[0] <= new[1] < math.pi and int(new[9]) & 5 == 0    # a bounded bracket
    assert np.array_equal(new, old, equal_nan=True)
    assert np.array_equal(new_cuts, old_cuts, equal_nan=True)


@pytest.mark.parametrize("name", ["psu-a", "psu-b", "ups-b"])
def test_branch_and_bound_is_bit_identical_near_the_capability(name):
    """Both modes, at the sampled capability ± a few tolerances, with and without cut
    orientations (random ones inside the box), over the whole box and around the witness."""
    mech = DESIGNS[name]()
    leg = type(mech).column_leg
    out, _ = _capability(_search.make_capability(leg), mech)
    bb_new, bb_old = _search.make_branch_bound(leg), reference_bb(leg)
    e0, U, B, box = optima._inputs(mech)
    P = _kernels.carray(mech.column_params())
    near = _kernels.carray(np.array([out[3] - 5.0, out[3] + 5.0, out[4] - 5.0, out[4] + 5.0]))
    rng = np.random.default_rng(7)
    ax = np.linspace(-1.0, 1.0, 5)
    grid = np.stack([g.ravel() for g in np.meshgrid(ax, ax, ax, indexing="ij")], axis=1)
    checked = 0
    for dtheta in (-3e-3, -1e-3, -1e-4, 0.0, 1e-4, 1e-3):
        th = out[2] + math.radians(dtheta)
        for extra in (0, 12):
            E = np.vstack([grid, rng.uniform(-1.0, 1.0, (extra, 3))]) * th
            W = _kernels.carray(mech.leg_offsets(euler_to_matrix(e0 + E)))
            for region, h0, eps, decide in ((box, optima.FIRST_TILE_MM, 0.0, True),
                                            (near, 2.5, _search.MAX_EPS, False),
                                            (box, optima.FIRST_TILE_MM, 1e-3, False)):
                a, b = np.empty(8), np.empty(8)
                bb_new(W, P, region, h0, optima.MIN_TILE_MM, eps, decide, a)
                bb_old(W, len(W), P, region, h0, optima.MIN_TILE_MM, eps, decide, b)
                keep = np.arange(8) != BB_UB
                assert np.array_equal(a[keep], b[keep], equal_nan=True), (dtheta, extra, eps)
                assert a[BB_UB] >= a[BB_F]
                checked += a[7] > 100              # a search that split tiles
    assert checked >= 12
