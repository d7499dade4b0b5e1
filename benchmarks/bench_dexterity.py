"""Dexterity timings on the Hopkins-Williams 6-PSU (target: 2,000-sample Monte-Carlo GCI ≤ 20 ms).

Workspace: simultaneous dexterous, Z-Y-X Euler box ±15° with 7 × 7 × 7 orientations, 2.5 mm
grid. Reports Angeles' characteristic length and κ at the nominal pose, the Monte-Carlo GCI
(median time of several seeded runs after a warm-up that loads the numba kernels) with a
breakdown by stage, and, for reference, the equal-weight grid GCI. Then the workspace worst case
(:func:`pkmlab.dexterity.worst_case`, every voxel × orientation) on that workspace and on the
6-UPS (Kotlarski) ±10° dexterous workspace at the 6-UPS study's grid (20 mm, 3 samples per
angle) and with 7 samples per angle, wall and CPU time.

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

    bench_worst_case(mech, res, cl)
    ups = pkmlab.load_mechanism(ROOT / "studies" / "mechanisms" / "gough-stewart-6ups.yaml")
    for n in (3, 7):
        r = workspace(ups, "dexterous", OrientationSet.box(np.radians([10.0] * 3), samples=n),
                      resolution=20.0)
        bench_worst_case(ups, r, dx.resolve_length(ups), runs=3)


def bench_worst_case(mech, res, length, runs: int = 7) -> None:
    """Median wall and CPU time of dx.worst_case after a warm-up, and its result."""
    w = dx.worst_case(mech, res, length)                                  # warm-up
    wall, cpu = [], []
    for _ in range(runs):
        t, c = time.perf_counter(), time.process_time()
        w = dx.worst_case(mech, res, length)
        wall.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    worst = ("inf (singular)" if not np.isfinite(w.worst_kappa) else
             f"{w.worst_kappa:.4f} (singularity {w.singularity})")
    print(f"worst case, {mech.name}: κ {worst}, force {w.min_force:.2f} N; wall median "
          f"{np.median(wall) * 1e3:.0f} ms, CPU median {np.median(cpu) * 1e3:.0f} ms "
          f"({runs} runs)\n  {w.method}" + (f"\n  {w.reason}" if w.reason else ""))


if __name__ == "__main__":
    main()
