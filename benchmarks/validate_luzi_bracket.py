"""Validation of the luzi3 cell bracket (``pkmlab.workspaces.bracket.cells``): the leg bound
really bounds, and the bracket contains dense estimates.

1. ``Luzi3.leg_cell_bounds``: random cells (positions within ±500 mm of the nominal in x, y
   and z 150-1250 mm, rotations up to ~30° from level, δ up to 60 mm, α up to 0.3 rad) and one
   random point per cell, half of them on the cell's boundary (|Δp| = δ and rotation angle =
   α); reports the largest |q(point) - q(centre)| / ε over the cells with a finite bound.
2. Brackets on the paper's geometry (studies/mechanisms/luzi-3chain.yaml) and on one of our
   own, for each kind, with growing budgets, against the engine (sampled voxels) at a fine
   grid (5 mm constant, 10 mm dexterous, 20 mm reachable) and several orientation sample
   counts: dexterous samples over-estimate, reachable
   ones under-estimate; the engine's own grid error is its ``volume_error``.

Prints markdown tables (docs/validation.md). Run:
``.venv/bin/python benchmarks/validate_luzi_bracket.py [bounds|brackets]`` (minutes; state the
load).
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
from pkmlab.mechanisms.families.luzi3 import Luzi3
from pkmlab.testing import cell_points
from pkmlab.workspaces import OrientationSet, workspace
from pkmlab.workspaces.bracket.columns import volume_bracket

ROOT = Path(__file__).resolve().parents[1]


def paper():
    return load_mechanism(ROOT / "studies/mechanisms/luzi-3chain.yaml")


def own():
    """A smaller, wider-angle variant: 700 mm base, chains 30° apart, 220 mm platform,
    l = 80 mm, stroke 600-950 mm."""
    return Luzi3.from_paper(base_diameter=700.0, phi=math.radians(30), platform_diameter=220.0,
                            upper_link=80.0, stroke=(600.0, 950.0), name="own")


def bound_check(mech, n=200_000, seed=0):
    """Largest ratio |Δq| / ε over random (cell, point) pairs with a finite bound."""
    rng = np.random.default_rng(seed)
    p = mech.nominal_pose[:3] + rng.uniform(-500, 500, (n, 3))
    p[:, 2] = rng.uniform(150, 1250, n)
    R = Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.3).as_matrix()
    delta, alpha = rng.uniform(0, 60, n), rng.uniform(0, 0.3, n)
    q, eps = mech.leg_cell_bounds(p, R, delta, alpha)
    p2, R2, dp = cell_points(rng, p, R, delta, alpha, ball=True)
    rad = np.linalg.norm(dp, axis=1)
    q2 = mech.inverse((p2, R2), stroke=NO_STROKE).q
    fin = np.isfinite(eps) & np.isfinite(q2)     # (every bound is finite; the fallback
    ratio = np.abs(q2 - q)[fin] / eps[fin]      # |C - A| ± (εC + l/2) where the link may flip)
    # second order in the position (rotation fixed): |q(p + dp) - q - g·dp| <= M |dp|² / 2
    g, M = mech.leg_position_curvature(p, R, delta)
    q3 = mech.inverse((p + dp, R), stroke=NO_STROKE).q
    q0 = mech.inverse((p, R), stroke=NO_STROKE).q
    rem = np.abs(q3 - q0 - np.einsum("nkj,nj->nk", g, dp))
    ok = np.isfinite(M) & (rad > 1.0)[:, None] & np.isfinite(q3)
    r2 = rem[ok] / (0.5 * M * (rad**2)[:, None])[ok]
    return (float(ratio.max()), float(np.median(ratio)), float(fin.mean()), int(fin.sum()),
            float(r2.max()), float(np.median(r2)), int(ok.sum()))


def engine_rows(mech, kind, oset, h, samples):
    rows = []
    for s in samples:
        o = None if oset is None else oset.with_samples(s)
        t = time.perf_counter()
        r = workspace(mech, kind, o, resolution=h)
        rows.append((s, r.volume / 1e6, r.volume_error / 1e6, time.perf_counter() - t))
    return rows


def main(what):
    print(f"load: {os.getloadavg()}")
    if what in ("all", "bounds"):
        print("| geometry | (cell, leg) pairs bounded | share | max ratio | median | "
              "2nd order pairs | max ratio | median |")
        print("|---|---|---|---|---|---|---|---|")
        for name, m in (("paper", paper()), ("own", own())):
            mx, med, share, k, mx2, med2, k2 = bound_check(m)
            print(f"| {name} | {k} | {share:.3f} | {mx:.4f} | {med:.4f} | {k2} | {mx2:.4f} | "
                  f"{med2:.4f} |")
    if what in ("all", "brackets"):
        box = OrientationSet.box((math.radians(5),) * 3)
        for name, m in (("paper", paper()), ("own", own())):
            for kind, oset, samples, h in (("constant", None, (1,), 5.0),
                                           ("dexterous", box, (3, 5, 7), 10.0),
                                           ("reachable", box, (3, 5, 7), 20.0)):
                print(f"\n{name} {kind} (litres)")
                for budget in (5, 20, 60):
                    sys.stdout.flush()
                    b = volume_bracket(m, kind, oset, resolution=10.0, budget_s=budget,
                                       target=0.01)
                    print(f"| bracket | budget {budget} s | [{b.lower / 1e6:.2f}, "
                          f"{b.upper / 1e6:.2f}] | {100 * b.relative_width:.1f} % | "
                          f"{b.stop_reason} | cube {b.resolution:g} mm | {b.seconds:.1f} s |")
                for s, v, e, t in engine_rows(m, kind, oset, h, samples):
                    print(f"| engine {h:g} mm | {s} samples/angle | {v:.2f} ± {e:.2f} | | | | "
                          f"{t:.1f} s |")
    print(f"load: {os.getloadavg()}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "all")
