"""Validation of the rss6 cell bracket (``pkmlab.mechanisms.legs.crank_cells`` through
``pkmlab.workspaces.bracket.cells``): the bounds really bound, and the bracket contains the
engine's estimates.

1. ``RSS6.leg_cell_bounds`` / ``leg_cell_margins`` on random cells (positions within
   ±80 × ±80 × ±60 mm of the nominal, rotations ~0.25 rad from level, δ up to 10 mm, α up to
   0.1 rad) and one random point per cell, half of them on the cell's boundary: the largest
   circular |θ(point) - θ(centre)| / εθ from the IK where εθ is finite, and the largest
   |μ| / |ΔW| over the legs whose IK status (closing and window) differs between centre and
   point (|μ| must be at most the distance the platform joint moved), plus the count of
   wrong decisions (``μ > ε`` at an infeasible point or ``μ < -ε`` at a feasible one), and
   the second-order remainder of ``leg_position_curvature`` over its bound (rotation fixed).
2. Brackets on the shipped servo platform (studies/mechanisms/instructables-servo-6rss.yaml)
   and on a geometry of our own, for each kind (±2° simultaneous box for dexterous and
   reachable), with growing budgets, against the engine (exact in z, its ``volume_error``
   covers the x-y grid) at 1 mm and several orientation sample counts: dexterous samples
   over-estimate, reachable ones under-estimate.

Prints markdown tables (docs/validation.md). Run:
``.venv/bin/python benchmarks/validate_rss6_bracket.py [bounds|brackets]`` (a few minutes; state
the load).
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from pkmlab import load_mechanism
from pkmlab.mechanisms import NO_STROKE
from pkmlab.mechanisms.families.rss6 import RSS6
from pkmlab.testing import cell_points
from pkmlab.workspaces import OrientationSet, workspace
from pkmlab.workspaces.bracket.columns import volume_bracket

ROOT = Path(__file__).resolve().parents[1]


def servo():
    return load_mechanism(ROOT / "studies/mechanisms/instructables-servo-6rss.yaml")


def own():
    """Cranks in radial planes, 120 mm base, 60 mm platform, crank 35 mm, rod 140 mm, window
    [-0.9, 1.3] rad (the test geometry of tests/workspaces/test_bracket_rss6.py)."""
    return RSS6.from_circles(base_radii=(120.0, 120.0), platform_radii=(60.0, 60.0),
                             crank_plane="radial", zero_direction="outward",
                             crank_length=35.0, rod_length=140.0, stroke=(-0.9, 1.3),
                             name="own")


def bound_check(mech, n=200_000, seed=0):
    rng = np.random.default_rng(seed)
    p = mech.nominal_pose[:3] + rng.uniform(-1, 1, (n, 3)) * [80, 80, 60]
    R = Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.25).as_matrix()
    delta, alpha = rng.uniform(0, 10, n), rng.uniform(0, 0.1, n)
    p2, R2, _ = cell_points(rng, p, R, delta, alpha, ball=True)
    theta, et = mech.leg_cell_bounds(p, R, delta, alpha)
    _, mu, eps = mech.leg_cell_margins(p, R, delta, alpha)
    ik, ik2 = (mech.inverse(x, stroke=NO_STROKE) for x in ((p, R), (p2, R2)))
    fin = np.isfinite(et) & np.isfinite(ik2.q)
    d = np.abs(np.mod(ik2.q - theta + math.pi, 2 * math.pi) - math.pi)
    rt = d[fin] / et[fin]
    lo, hi = mech.stroke
    with np.errstate(invalid="ignore"):
        ok, ok2 = ((np.isfinite(x.q) & (x.q >= lo) & (x.q <= hi)) for x in (ik, ik2))
    moved = np.linalg.norm((p2 - p)[:, None, :]
                           + np.einsum("nij,kj->nki", R2 - R, mech.tool_points), axis=-1)
    flip = ok != ok2
    rm = np.abs(mu[flip]) / moved[flip]
    wrong = int(np.sum((mu > eps) & ~ok2) + np.sum((mu < -eps) & ok2))
    # second order in the position (rotation fixed): |θ(p + dp) - θ - g·dp| <= M |dp|² / 2
    g, M = mech.leg_position_curvature(p, R, delta)
    dp = p2 - p
    q3 = mech.inverse((p + dp, R), stroke=NO_STROKE).q
    rem = np.abs(np.mod(q3 - ik.q - np.einsum("nkj,nj->nk", g, dp) + math.pi, 2 * math.pi)
                 - math.pi)
    dd = np.sum(dp * dp, axis=1)
    sec = np.isfinite(M) & (dd > 1.0)[:, None]
    r2 = rem[sec] / (0.5 * M * dd[:, None])[sec]
    return (float(rt.max()), float(np.median(rt)), float(fin.mean()), float(rm.max()),
            int(flip.sum()), float(np.mean(np.abs(mu) > eps)), wrong, float(r2.max()),
            float(np.median(r2)), float(np.isfinite(M).mean()))


def brackets(mech, budgets=(1.0, 4.0, 16.0)):
    box = lambda s: OrientationSet.box((math.radians(2),) * 3, samples=s)  # noqa: E731
    rows = []
    for kind in ("constant", "dexterous", "reachable"):
        refs = []
        for s in ((None,) if kind == "constant" else (3, 5, 9)):
            t = time.perf_counter()
            w = workspace(mech, kind, None if s is None else box(s), resolution=1.0)
            refs.append((s, w.volume, w.volume_error, time.perf_counter() - t))
        for bud in budgets:
            b = volume_bracket(mech, kind, None if kind == "constant" else box(3), 2.0,
                               budget_s=bud)
            rows.append((mech.name or "own", kind, bud, b.lower, b.upper, b.stop_reason,
                         b.seconds, b.resolution, refs))
            print(f"| {rows[-1][0]} | {kind} | {bud:g} s | [{b.lower / 1e3:.1f}, "
                  f"{b.upper / 1e3:.1f}] cm³ | {100 * (b.upper - b.lower) / b.upper:.1f} % | "
                  f"{b.seconds:.1f} s, {b.stop_reason}, cubes {b.resolution:g} mm | "
                  + "; ".join(f"{'' if s is None else f'{s}³: '}{v / 1e3:.2f} ± {e / 1e3:.2f}"
                              for s, v, e, _ in refs) + " |", flush=True)
    return rows


def main(what):
    print("load:", os.getloadavg())
    if what in ("all", "bounds"):
        print("| geometry | θ ratio max | θ ratio median | share with finite εθ | "
              "|μ|/|ΔW| max (status changed) | status changes | decided | wrong decisions | "
              "2nd order ratio max | median | share with finite M |")
        for m in (servo(), own()):
            r = bound_check(m)
            print(f"| {m.name or 'own'} | {r[0]:.4f} | {r[1]:.3f} | {r[2]:.2f} | {r[3]:.4f} | "
                  f"{r[4]} | {r[5]:.2f} | {r[6]} | {r[7]:.4f} | {r[8]:.3f} | {r[9]:.2f} |",
                  flush=True)
    if what in ("all", "brackets"):
        print("| geometry | kind | budget | bracket | width | took | engine (cm³) |")
        for m in (servo(), own()):
            brackets(m)
    print("load:", os.getloadavg())


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "all")
