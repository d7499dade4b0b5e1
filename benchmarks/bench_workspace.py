"""Workspace engine benchmark: exact column method vs a plain NumPy brute force.

Prints, in one run:

* the time of the 6-PSU (Hopkins & Williams) ±15° simultaneous dexterous workspace at 2.5 mm
  with 7×7×7 orientations, through the public ``pkmlab.workspaces`` call (median of repeats);
* the time of a plain NumPy brute force on the same candidate grid (every voxel × every
  orientation × every leg), the ratio, and whether the two voxel grids agree;
* the time of the same request on two 6-UPS: one sized like the 6-PSU (radii 165/100 mm
  base, 80/50 mm platform, legs 250-350 mm) and the Kotlarski et al. Gough–Stewart of the
  shipped studies (their exactness is tested in ``tests/test_workspace.py``);
* peak memory (max RSS of a fresh process) of the 6-PSU case at 1 mm including its mesh;
* the time to a guaranteed 1 % volume bracket per family and kind (:func:`bracket_report`;
  ``bench_workspace.py bracket`` runs only that).

Targets on 2 cores: ≤ 10 ms (6-PSU), ≤ 50 ms (6-UPS), ratio ≥ 1000×, < 1 GB at 1 mm.
Run: ``.venv/bin/python benchmarks/bench_workspace.py``.
"""

from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from _timing import timed  # noqa: E402 - the benchmarks folder is on sys.path

from pkmlab import UPS6, load_mechanism
from pkmlab.workspaces import Constraints, OrientationSet, workspace
from pkmlab.workspaces.engine import _grid_xy

ROOT = Path(__file__).resolve().parents[1]
BOX = OrientationSet.box(np.radians([15.0, 15.0, 15.0]), "simultaneous", samples=7)
H = 2.5



def brute_force(mech, R, xs, ys, zs):
    """Plain NumPy: actuator values of every voxel at every orientation; all within stroke."""
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    p = np.stack([X, Y, Z], axis=-1).reshape(-1, 3)
    u = mech.tool_points
    B = mech.base_points
    lo, hi = mech.stroke
    ok = np.ones(len(p), dtype=bool)
    for Rm in R:
        W = p[:, None, :] + (u @ Rm.T)[None] - B[None]          # (N, 6, 3)
        if mech.family == "psu6":
            h2 = mech.link_length**2 - W[..., 0] ** 2 - W[..., 1] ** 2
            with np.errstate(invalid="ignore"):
                q = W[..., 2] - np.sqrt(h2)
            good = (h2 >= 0) & (q >= lo) & (q <= hi)
        else:
            q = np.linalg.norm(W, axis=-1)
            good = (q >= lo) & (q <= hi)
        ok &= good.all(axis=1)
    return ok.reshape(X.shape)


def compare(name, mech, repeats=7, target_ms=None):
    t_fast, res = timed(lambda: workspace(mech, "dexterous", BOX, H), repeats)
    R = res.orientations.rotations()
    xs, ys, zb = _grid_xy(mech, R, "all", H)
    zs = np.arange(math.ceil(zb[0] / H), math.floor(zb[1] / H) + 1) * H
    t0 = time.perf_counter()
    brute = brute_force(mech, R, xs, ys, zs)
    t_brute = time.perf_counter() - t0
    # The engine keeps only the component connected to the nominal pose; compare like with like.
    fast_all = workspace(mech, "dexterous", BOX, H, Constraints(connected=False))
    assert np.array_equal(fast_all.xs, xs) and np.array_equal(fast_all.ys, ys)
    fast = np.stack([fast_all.slice(z) for z in zs], axis=-1)
    diff = int(np.sum(fast != brute))
    voxels = int(brute.sum())
    print(f"{name}:")
    print(f"  exact columns (public call): {t_fast * 1e3:8.2f} ms"
          + (f"   (target <= {target_ms} ms)" if target_ms else ""))
    print(f"  plain NumPy brute force    : {t_brute * 1e3:8.0f} ms on {brute.size:,} voxels x "
          f"{len(R)} orientations")
    print(f"  ratio                      : {t_brute / t_fast:8.0f}x   (target >= 1000x)")
    print(f"  grids agree                : {'yes' if diff == 0 else 'NO'} ({diff} of "
          f"{voxels:,} inside voxels differ)")
    print(f"  volume {res.volume / 1e3:.3f} ± {res.volume_error / 1e3:.3f} cm3, "
          f"{res.components} component(s)")
    return t_fast, t_brute, diff


def peak_memory_1mm() -> float:
    code = (
        "import resource, numpy as np\n"
        "from pkmlab import load_mechanism\n"
        "from pkmlab.workspaces import workspace, OrientationSet\n"
        f"m = load_mechanism(r'{ROOT / 'studies/mechanisms/hopkins-williams-6psu.yaml'}')\n"
        "r = workspace(m, 'dexterous', OrientationSet.box(np.radians([15]*3)), 1.0)\n"
        "r.mesh()\n"
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    return float(out.stdout.strip().splitlines()[-1])


def main() -> None:
    psu = load_mechanism(ROOT / "studies/mechanisms/hopkins-williams-6psu.yaml")
    compare("6-PSU Hopkins & Williams, ±15° simultaneous dexterous, 2.5 mm, 7x7x7", psu,
            repeats=21, target_ms=10)
    small = UPS6.from_circles(base_radii=(100.0, 165.0), platform_radii=(50.0, 80.0),
                              platform_rotation=math.radians(33.7), base_pair_separation=0.0,
                              platform_pair_separation=0.0, stroke=(250.0, 350.0),
                              name="6-UPS sized like the 6-PSU")
    big = load_mechanism(ROOT / "studies/mechanisms/gough-stewart-6ups.yaml")
    for name, mech, reps in (("6-UPS sized like the 6-PSU (legs 250-350 mm)", small, 7),
                             ("6-UPS Kotlarski et al. (legs 390-950 mm)", big, 1)):
        t, res = timed(lambda m=mech: workspace(m, "dexterous", BOX, H), reps)
        print(f"{name}, same request: {t * 1e3:.0f} ms (target <= 50 ms); volume "
              f"{res.volume / 1e3:.1f} cm3 on {len(res.xs)} x {len(res.ys)} columns "
              f"(exactness: tests/test_workspace.py)")
    print(f"peak memory, 6-PSU case at 1 mm with mesh: {peak_memory_1mm():.0f} MB "
          "(target < 1024 MB)")


def bracket_report(budget_s: float = 120.0) -> None:
    """Time to a guaranteed 1 % volume bracket (pkmlab.workspaces.bracket), per family and
    kind, against the plain sampled engine call of the same request (no guarantee) timed in
    the same run. The machine's load is printed with it."""
    import os

    from pkmlab.workspaces.bracket import volume_bracket

    print(f"volume bracket, time to 1 % (load {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores):")
    psu = load_mechanism(ROOT / "studies/mechanisms/hopkins-williams-6psu.yaml")
    ups = load_mechanism(ROOT / "studies/mechanisms/gough-stewart-6ups.yaml")
    box10 = OrientationSet.box(np.radians([10.0] * 3))
    box5 = OrientationSet.box(np.radians([5.0] * 3))
    for fam, mech, h in (("psu6", psu, 2.5), ("ups6", ups, 5.0)):
        for kind, oset in (("constant", None), ("dexterous", box10), ("reachable", box5)):
            t_engine, _ = timed(lambda m=mech, k=kind, o=oset, g=h: workspace(m, k, o, g), 3)
            b = volume_bracket(mech, kind, oset, h, target=0.01, budget_s=budget_s)
            hit = next((r["seconds"] for r in b.history
                        if r["upper_mm3"] - r["lower_mm3"] <= 0.01 * r["upper_mm3"]), None)
            what = (f"{hit:.1f} s ({hit / t_engine:.0f}x the sampled engine call, "
                    f"{t_engine * 1e3:.0f} ms)" if hit is not None else
                    f"not within {budget_s:g} s: width {100 * b.relative_width:.1f} %")
            print(f"  {fam} {kind:9s} h {h:g} mm: [{b.lower / 1e3:.1f}, {b.upper / 1e3:.1f}] "
                  f"cm3, {what}, final x-y cell {b.resolution:g} mm")


if __name__ == "__main__":
    if sys.argv[1:] == ["bracket"]:
        bracket_report()
    else:
        main()
        bracket_report()
