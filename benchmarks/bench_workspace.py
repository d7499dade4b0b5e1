"""Workspace engine benchmark: exact column method vs a plain NumPy brute force.

Prints, in one run:

* the time of the 6-PSU (Hopkins & Williams) ±15° simultaneous dexterous workspace at 2.5 mm
  with 7×7×7 orientations, through the public ``pkmlab.workspaces`` call (median of repeats);
* the time of a plain NumPy brute force on the same candidate grid (every voxel × every
  orientation × every leg), the ratio, and whether the two voxel grids agree;
* the time of the same request on two 6-UPS: one sized like the 6-PSU (radii 165/100 mm
  base, 80/50 mm platform, legs 250-350 mm) and the Kotlarski et al. Gough–Stewart of the
  shipped studies (their exactness is tested in ``tests/workspaces/test_workspace.py``);
* peak memory (max RSS of a fresh process) of the 6-PSU case at 1 mm including its mesh;
* the 6-RSS servo hexapod (``python benchmarks/bench_workspace.py rss6`` runs only this): the
  ±10° simultaneous dexterous workspace at 2 mm with 7×7×7 orientations by the exact crank
  column method, against a plain NumPy brute force (the closed-form crank angle of every voxel
  × orientation × leg) timed on every ``RSS_STRIDE``-th x slab of the same grid and
  extrapolated by the slab count; the two agree voxel for voxel on those slabs.
* the time to a guaranteed 1 % volume bracket per family and kind (:func:`bracket_report`;
  ``bench_workspace.py bracket`` runs only that).

Targets on 2 cores: ≤ 10 ms (6-PSU), ≤ 50 ms (6-UPS), ratio ≥ 1000×, < 1 GB at 1 mm;
6-RSS ratio ≥ 500×.
Run: ``.venv/bin/python benchmarks/bench_workspace.py [rss6]``.
"""

from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from _timing import timed  # noqa: E402 - the benchmarks folder is on sys.path

from pkmlab import RSS6, UPS6, load_mechanism
from pkmlab.workspaces import Constraints, OrientationSet, workspace
from pkmlab.workspaces.engine import _grid_xy

ROOT = Path(__file__).resolve().parents[1]
BOX = OrientationSet.box(np.radians([15.0, 15.0, 15.0]), "simultaneous", samples=7)
H = 2.5
RSS_BOX = OrientationSet.box(np.radians([10.0, 10.0, 10.0]), "simultaneous", samples=7)
RSS_H = 2.0
RSS_STRIDE = 16



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


def brute_force_rss(mech, R, xs, ys, zs):
    """Plain NumPy for the 6-RSS: the branch's crank angle (atan2(F, E) + b·acos(G/ρ), wrapped)
    of every voxel at every orientation; all real and within the servo range."""
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    p = np.stack([X, Y, Z], axis=-1).reshape(-1, 3)
    a, s, b = mech.crank_length, mech.rod_length, mech.branch
    lo, hi = mech.stroke
    ok = np.ones(len(p), dtype=bool)
    for Rm in R:
        W = p[:, None, :] + (mech.tool_points @ Rm.T)[None] - mech.base_points[None]
        E = 2 * a * np.einsum("nki,ki->nk", W, mech.zero_directions)
        F = 2 * a * np.einsum("nki,ki->nk", W, mech.v_directions)
        G = np.einsum("nki,nki->nk", W, W) + a * a - s * s
        rho = np.hypot(E, F)
        with np.errstate(invalid="ignore", divide="ignore"):
            alpha = np.arctan2(F, E) + b * np.arccos(G / rho)
        alpha = np.where(alpha > np.pi, alpha - 2 * np.pi,
                         np.where(alpha <= -np.pi, alpha + 2 * np.pi, alpha))
        ok &= np.all((np.abs(G) <= rho) & (alpha >= lo) & (alpha <= hi), axis=1)
    return ok.reshape(X.shape)


def compare_rss(name, mech, repeats=3):
    """The 6-RSS case: exact columns vs the brute force on every RSS_STRIDE-th x slab."""
    t_fast, res = timed(lambda: workspace(mech, "dexterous", RSS_BOX, RSS_H), repeats)
    R = res.orientations.rotations()
    xs, ys, zb = _grid_xy(mech, R, "all", RSS_H)
    zs = np.arange(math.ceil(zb[0] / RSS_H), math.floor(zb[1] / RSS_H) + 1) * RSS_H
    fast_all = workspace(mech, "dexterous", RSS_BOX, RSS_H, Constraints(connected=False))
    sub = np.arange(0, len(xs), RSS_STRIDE)
    t0 = time.perf_counter()
    brute = brute_force_rss(mech, R, xs[sub], ys, zs)
    t_brute = (time.perf_counter() - t0) * len(xs) / len(sub)
    # the engine crops to the occupied footprint: put its columns back on the full grid
    K = fast_all.lo.shape[-1]
    lo = np.full((len(xs), len(ys), K), np.inf)
    hi = np.full((len(xs), len(ys), K), -np.inf)
    cx, cy = np.searchsorted(xs, fast_all.xs), np.searchsorted(ys, fast_all.ys)
    assert np.array_equal(xs[cx], fast_all.xs) and np.array_equal(ys[cy], fast_all.ys)
    lo[np.ix_(cx, cy)], hi[np.ix_(cx, cy)] = fast_all.lo, fast_all.hi
    lo, hi = lo[sub][:, :, None, :], hi[sub][:, :, None, :]
    fast = np.any((lo <= zs[:, None]) & (zs[:, None] <= hi), axis=-1)
    diff = int(np.sum(fast != brute))
    print(f"{name}:")
    print(f"  exact columns (public call): {t_fast * 1e3:8.1f} ms, volume "
          f"{res.volume / 1e3:.1f} cm3 on {len(res.xs)} x {len(res.ys)} columns")
    print(f"  plain NumPy brute force    : {t_brute:8.1f} s (measured on {len(sub)} of "
          f"{len(xs)} x slabs, extrapolated) on {len(xs) * len(ys) * len(zs):,} voxels x "
          f"{len(R)} orientations")
    print(f"  ratio                      : {t_brute / t_fast:8.0f}x   (target >= 500x)")
    print(f"  grids agree on those slabs : {'yes' if diff == 0 else 'NO'} ({diff} of "
          f"{int(brute.sum()):,} inside voxels differ)")
    return t_fast, t_brute, diff


def rss_main() -> None:
    sized = RSS6.from_circles(base_radii=(102.0, 102.0), platform_radii=(80.0, 80.0),
                              crank_length=46.0, rod_length=183.0, crank_plane="tangential",
                              name="6-RSS a = 46 mm, s = 183 mm, radii 102 / 80 mm")
    compare_rss("6-RSS (a = 46, s = 183 mm, radii 102/80 mm), ±10° simultaneous dexterous, "
                "2 mm, 7x7x7", sized)
    hobby = load_mechanism(ROOT / "studies/mechanisms/instructables-servo-6rss.yaml")
    t, res = timed(lambda: workspace(hobby, "dexterous", RSS_BOX, RSS_H), 3)
    print(f"6-RSS instructables file, same request: {t * 1e3:.0f} ms; volume "
          f"{res.volume / 1e3:.1f} cm3 (it has no ±10° dexterous workspace)")


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


def load() -> str:
    """The machine's load averages (``uptime``), quoted with every timing."""
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def ups_pruning(columns: int = 300, seed: int = 0) -> None:
    """The shipped 6-UPS (legs 390-950 mm), ±10° simultaneous dexterous, 7³ orientations,
    2.5 mm: the public call (tile pruning, :mod:`pkmlab.mechanisms.kernels.tiles`), the plain column
    kernel without pruning, and a plain NumPy brute force (every voxel × orientation × leg)
    run on ``columns`` random columns of the same grid and extrapolated to all of them."""
    from pkmlab.mechanisms.kernels import columns as column_kernels
    from pkmlab.mechanisms.kernels import ik as _kernels

    big = load_mechanism(ROOT / "studies/mechanisms/gough-stewart-6ups.yaml")
    box = OrientationSet.box(np.radians([10.0] * 3), "simultaneous", samples=7)
    print(f"6-UPS pruning, load: {load()}")
    t_fast, res = timed(lambda: workspace(big, "dexterous", box, H), 5)
    R = res.orientations.rotations()
    xs, ys, zb = _grid_xy(big, R, "all", H)
    zs = np.arange(math.ceil(zb[0] / H), math.floor(zb[1] / H) + 1) * H
    W = big.leg_offsets(R)
    W = _kernels.carray(W[np.argsort(-np.linalg.norm(R - np.eye(3), axis=(1, 2)),
                                     kind="stable")])
    lo, hi = np.empty((len(xs), len(ys), 1)), np.empty((len(xs), len(ys), 1))
    plain = column_kernels.make_column_kernel(type(big).column_leg, "all")
    t_plain, _ = timed(lambda: plain(_kernels.carray(xs), _kernels.carray(ys), W,
                                     _kernels.carray(big.column_params()), lo, hi), 3)
    tlo, thi, _ = big.column_intervals(xs, ys, R, "all")
    same = np.array_equal(lo, tlo) and np.array_equal(hi, thi)
    rng = np.random.default_rng(seed)
    ix, iy = rng.integers(0, len(xs), columns), rng.integers(0, len(ys), columns)
    t0 = time.perf_counter()
    brute = brute_force_columns(big, R, xs[ix], ys[iy], zs)
    t_sub = time.perf_counter() - t0
    t_brute = t_sub * len(xs) * len(ys) / columns
    # the brute force agrees with the exact intervals on the sampled columns (voxel centres)
    inside = (zs[None] >= lo[ix, iy, 0][:, None]) & (zs[None] <= hi[ix, iy, 0][:, None])
    print(f"  grid {len(xs)} x {len(ys)} columns x {len(zs)} z, {len(R)} orientations")
    print(f"  public call (tile pruning)  : {t_fast * 1e3:8.1f} ms (median of 5)")
    print(f"  plain column kernel         : {t_plain * 1e3:8.1f} ms  -> pruning "
          f"{t_plain / t_fast:.1f}x")
    print(f"  NumPy brute force           : {t_sub:.2f} s on {columns} random columns, "
          f"extrapolated {t_brute:.0f} s")
    print(f"  ratio vs brute force        : {t_brute / t_fast:8.0f}x   (target >= 1000x)")
    print(f"  pruned == plain intervals   : {'yes' if same else 'NO'}; brute force agrees on "
          f"the sampled columns: {'yes' if np.array_equal(inside, brute) else 'NO'}")
    print(f"  load after: {load()}")


def brute_force_columns(mech, R, x, y, zs):
    """Plain NumPy on the columns ``(x[k], y[k])``: ``(k, nz)`` inside flags (6-UPS legs within
    stroke on their working-mode side)."""
    p = np.stack(np.broadcast_arrays(x[:, None], y[:, None], zs[None]), -1).reshape(-1, 3)
    u, B = mech.tool_points, mech.base_points
    lo, hi = mech.stroke
    ok = np.ones(len(p), dtype=bool)
    for Rm in R:
        W = p[:, None, :] + (u @ Rm.T)[None] - B[None]
        q = np.linalg.norm(W, axis=-1)
        ok &= ((q >= lo) & (q <= hi) & (W[..., 2] > 0)).all(axis=1)
    return ok.reshape(len(x), len(zs))


def capability_cost(repeats: int = 3) -> None:
    """Orientation capability per candidate, Hopkins & Williams 6-PSU, 5 samples per angle:
    before (bisection over full 2.5 mm workspaces, ``study.evaluators.capability``) and after
    (one compiled search over continuous positions, ``workspaces.optima``)."""
    from pkmlab.study.evaluators import capability
    from pkmlab.workspaces.optima.search import orientation_capability

    psu = load_mechanism(ROOT / "studies/mechanisms/hopkins-williams-6psu.yaml")
    req = {"orientations": OrientationSet.box(np.radians([5.0] * 3), samples=5),
           "resolution": H, "constraints": Constraints()}
    print(f"capability per candidate, load: {load()}")
    t_old, old = timed(lambda: capability(psu, req), repeats)
    t_new, new = timed(lambda: orientation_capability(psu, 5), repeats)
    print(f"  before (grid bisection)     : {t_old * 1e3:8.1f} ms  -> {old[0]:.3f}° "
          f"(+{old[1]:.3f}° bracket, grid columns)")
    print(f"  after (continuous, 1 call)  : {t_new * 1e3:8.1f} ms  -> [{new.lower:.4f}°, "
          f"{new.upper:.4f}°] certified bracket")
    print(f"  load after: {load()}")


def main() -> None:
    if sys.argv[1:] == ["rss6"]:
        rss_main()
        return
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
              f"(exactness: tests/workspaces/test_workspace.py)")
    print(f"peak memory, 6-PSU case at 1 mm with mesh: {peak_memory_1mm():.0f} MB "
          "(target < 1024 MB)")
    ups_pruning()
    capability_cost()
    rss_main()


def bracket_report(budget_s: float = 120.0) -> None:
    """Time to a guaranteed 1 % volume bracket (pkmlab.workspaces.bracket.columns), per family and
    kind (``bracket [budget_s]``), against the plain sampled engine call of the same request
    (no guarantee) timed in the same run. The machine's load is printed with it."""
    import os

    from pkmlab.workspaces.bracket.columns import volume_bracket

    print(f"volume bracket, time to 1 % (load {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores):")
    psu = load_mechanism(ROOT / "studies/mechanisms/hopkins-williams-6psu.yaml")
    ups = load_mechanism(ROOT / "studies/mechanisms/gough-stewart-6ups.yaml")
    box10 = OrientationSet.box(np.radians([10.0] * 3))
    box5 = OrientationSet.box(np.radians([5.0] * 3))
    luzi = load_mechanism(ROOT / "studies/mechanisms/luzi-3chain.yaml")
    cases = [("psu6", psu, 2.5, ("constant", None), ("dexterous", box10), ("reachable", box5)),
             ("ups6", ups, 5.0, ("constant", None), ("dexterous", box10), ("reachable", box5)),
             # luzi3 reachable is left out: its sampled engine call alone takes minutes at
             # 10 mm, and its bracket is 85 % wide at 20 s (docs/validation.md)
             ("luzi3", luzi, 10.0, ("constant", None), ("dexterous", box5))]
    for fam, mech, h, *kinds in cases:
        for kind, oset in kinds:
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
    if sys.argv[1:2] == ["bracket"]:
        bracket_report(float(sys.argv[2]) if len(sys.argv) > 2 else 120.0)
    else:
        main()
        bracket_report()
