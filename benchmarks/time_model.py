"""Calibrate and check the time model of :mod:`pkmlab.runtime.time_budget`.

    python benchmarks/time_model.py

For workspace requests on the exact column method and on the sampled method, prints the
measured time (median of 3 after a warm-up, :func:`_timing.timed`), the model's estimate,
their ratio, and the cost per leg evaluation the measurement implies (compare with
``NS_PER_COLUMN_LEG`` and ``NS_PER_VOXEL_LEG``). Also prints the plain baseline of the same
run — a NumPy loop doing one multiply-add per leg evaluation — so that figures from loaded
machines can be compared. State the load (``uptime``) with the figures.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
from _timing import timed  # noqa: E402 - the benchmarks folder is on sys.path

import pkmlab
from pkmlab.poses import as_frames, matrix_to_euler
from pkmlab.runtime.time_budget import (
    NS_PER_COLUMN_LEG,
    NS_PER_VOXEL_LEG,
    OVERHEAD_S,
    workspace_seconds,
)
from pkmlab.workspaces import OrientationSet, workspace
from pkmlab.workspaces.engine import _grid_xy

MECH = Path(__file__).parents[1] / "studies" / "mechanisms"
CASES = [  # file, kind, orientation set, resolution (mm), method
    ("hopkins-williams-6psu.yaml", "constant", None, 1.0, "auto"),
    ("hopkins-williams-6psu.yaml", "dexterous", OrientationSet.box(np.radians([15] * 3), samples=7),
     1.0, "auto"),
    ("gough-stewart-6ups.yaml", "dexterous", OrientationSet.box(np.radians([10] * 3), samples=5),
     2.5, "auto"),
    ("hopkins-williams-6psu.yaml", "constant", None, 2.5, "sampled"),
    ("luzi-3chain.yaml", "constant", None, 10.0, "auto"),
    ("luzi-3chain.yaml", "constant", None, 6.0, "auto"),
]


def _sizes(mech, kind, oset, h):
    o = oset or OrientationSet.fixed()
    _, Rn = as_frames(mech.nominal_pose)
    R = o.centred(tuple(matrix_to_euler(Rn[0]))).rotations()
    xs, ys, zb = _grid_xy(mech, R, "any" if kind == "reachable" else "all", h)
    return len(xs) * len(ys), len(R), int(max(0.0, zb[1] - zb[0]) / h) + 1


def main() -> None:
    sys.stdout.write(f"load: {os.getloadavg()}\n")
    work = np.random.default_rng(0).random(10_000_000)
    base, _ = timed(lambda: float(np.sum(work * 1.0001 + 0.5)), repeats=3)
    sys.stdout.write(f"plain baseline: {1e9 * base / len(work):.2f} ns per multiply-add\n")
    sys.stdout.write(f"model: {NS_PER_COLUMN_LEG:g} ns per column-leg, {NS_PER_VOXEL_LEG:g} ns "
                     f"per voxel-leg, {OVERHEAD_S:g} s per request\n")
    for f, kind, oset, h, method in CASES:
        mech = pkmlab.load_mechanism(MECH / f)
        cols, M, nz = _sizes(mech, kind, oset, h)
        t, res = timed(lambda m=mech, k=kind, o=oset, hh=h, mm=method:
                       workspace(m, k, o, hh, method=mm), repeats=3)
        sampled = res.method == "sampled voxels"
        legs = len(mech.actuator_names)
        est = workspace_seconds(cols, M, legs, nz, sampled)
        n = cols * M * legs * (nz if sampled else 1)
        sys.stdout.write(
            f"{f} {kind} h={h:g} {res.method}: {cols} columns × {M} orientations"
            + (f" × {nz} z" if sampled else "") + f": measured {t:.3f} s, model {est:.3f} s "
            f"(model/measured {est / t:.2f}); {1e9 * max(t - OVERHEAD_S, 0) / n:.2f} ns per "
            f"{'voxel' if sampled else 'column'}-leg "
            f"({max(t - OVERHEAD_S, 0) / n / (base / len(work)):.1f}× the baseline's "
            "multiply-add)\n")


if __name__ == "__main__":
    main()
