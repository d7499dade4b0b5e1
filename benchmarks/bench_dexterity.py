"""Dexterity timings on the Hopkins-Williams 6-PSU (target: 2,000-sample Monte-Carlo GCI ≤ 20 ms).

Workspace: simultaneous dexterous, Z-Y-X Euler box ±15° with 7 × 7 × 7 orientations, 2.5 mm
grid. Reports Angeles' characteristic length and κ at the nominal pose, the Monte-Carlo GCI
(median time of several seeded runs after a warm-up that loads the numba kernels) with a
breakdown by stage, and, for reference, the equal-weight grid GCI.

Run: .venv/bin/python benchmarks/bench_dexterity.py
"""

from __future__ import annotations

import time
from pathlib import Path

import numba
import numpy as np

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.dexterity.aggregate import sample_orientations
from pkmlab.workspaces import OrientationSet, workspace

ROOT = Path(__file__).resolve().parents[1]
SAMPLES, RUNS = 2_000, 21


def median_ms(fn, runs: int = RUNS) -> tuple[float, float, float]:
    times = []
    for k in range(runs):
        t = time.perf_counter()
        fn(k)
        times.append(time.perf_counter() - t)
    ms = np.array(times) * 1e3
    return float(np.median(ms)), float(ms.min()), float(ms.max())


def main() -> None:
    mech = pkmlab.load_mechanism(ROOT / "studies" / "mechanisms" / "hopkins-williams-6psu.yaml")
    _ = mech.nominal_pose                               # compiles the IK driver (numba JIT)
    print(f"numba threads: {numba.get_num_threads()}")
    t = time.perf_counter()
    cl = dx.characteristic_length(mech)
    t_cl = time.perf_counter() - t
    r_mean = dx.joint_radius(mech)
    k_mean = dx.condition_number(mech.jacobian(mech.nominal_pose), r_mean)[0]
    print(f"Angeles characteristic length L = {cl.length:.4f} mm, κ(nominal) = {cl.kappa:.5f} "
          f"({t_cl * 1e3:.1f} ms)")
    print(f"  (mean platform joint radius {r_mean:.3f} mm would give κ = {k_mean:.5f})")

    oset = OrientationSet.box(np.radians([15.0, 15.0, 15.0]), samples=7)
    t = time.perf_counter()
    res = workspace(mech, "dexterous", oset, resolution=2.5)
    print(f"workspace: {res.volume / 1e3:.2f} cm³, {int(res.occupancy.sum())} voxels, "
          f"{len(oset.parameters())} orientations ({(time.perf_counter() - t) * 1e3:.0f} ms)")

    out = dx.gci_monte_carlo(mech, res, cl.length, SAMPLES, seed=0)    # warm-up
    med, lo, hi = median_ms(lambda k: dx.gci_monte_carlo(mech, res, cl.length, SAMPLES, seed=k))
    print(f"Monte-Carlo GCI ({SAMPLES} samples): {out.gci:.5f} ± {out.std_error:.5f} "
          f"({out.rejected} rejected)")
    print(f"  time median {med:.2f} ms (min {lo:.2f}, max {hi:.2f}, {RUNS} runs) "
          f"[{'within' if med <= 20 else 'ABOVE'} the 20 ms target]")

    # stage breakdown on one fixed sample
    rng = np.random.default_rng(1)
    occ = np.flatnonzero(res.occupancy)
    i, j, k = np.unravel_index(occ[rng.integers(0, len(occ), SAMPLES)], res.occupancy.shape)
    p = np.stack([res.xs[i], res.ys[j], res.zs[k]], axis=1)
    R = sample_orientations(res.orientations, SAMPLES, rng)
    J = mech.jacobian((p, R))
    stages = {
        "orientation sampling": lambda _: sample_orientations(res.orientations, SAMPLES, rng),
        "inverse kinematics": lambda _: mech.inverse((p, R)),
        "Jacobian": lambda _: mech.jacobian((p, R)),
        "LCI (batched SVD)": lambda _: dx.lci(J, cl.length),
    }
    print("  stages (median ms): " + ", ".join(f"{name} {median_ms(fn)[0]:.2f}"
                                              for name, fn in stages.items()))

    t = time.perf_counter()
    grid = dx.gci_grid(mech, res, cl.length)
    print(f"grid GCI (equal weights, {grid.samples} poses): {grid.gci:.5f} "
          f"({(time.perf_counter() - t) * 1e3:.0f} ms)")


if __name__ == "__main__":
    main()
