"""The numbers of docs/validation.md, "Planar and tripod families (issue 24)": areas with their
brackets and exact values, brute-force counts, the published 3-RPR assembly-mode count, the
tripod's parasitic excursions and volumes; writes the pictures to ``--out`` (default
results/planar-validation).

Run: .venv/bin/python benchmarks/validate_planar.py [--out DIR]
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

import pkmlab
from pkmlab.mechanisms.families import planar_fk
from pkmlab.mechanisms.families.rpr3 import Rpr3
from pkmlab.workspaces.planar import (
    area_per_phi,
    areas_per_working_mode,
    planar_workspace,
    plot_planar,
    resolution_map,
)
from pkmlab.workspaces.tripod import plot_tripod, tripod_workspace

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "studies" / "mechanisms"


def published():
    d1, d2, d3 = 17.04, 16.54, 20.84
    x = (d1 ** 2 + d3 ** 2 - d2 ** 2) / (2 * d1)
    U = np.array([[0.0, 0.0, 0.0], [d1, 0.0, 0.0], [x, math.sqrt(d3 ** 2 - x ** 2), 0.0]])
    A = np.array([[0.0, 0.0, 0.0], [15.91, 0.0, 0.0], [0.0, 10.0, 0.0]])
    return Rpr3(A, U, (1.0, 40.0), nominal=np.zeros(6)), np.array([14.98, 15.38, 12.0])


def brute(mech, phis, h, kind):
    x = np.arange(-600.0, 600.0, h)
    X, Y = (g.ravel() for g in np.meshgrid(x, x, indexing="ij"))
    acc = None
    for a in phis:
        P = np.zeros((len(X), 6))
        P[:, 0], P[:, 1], P[:, 5] = X, Y, a
        ok = mech.inverse(P).valid
        acc = ok if acc is None else (acc | ok if kind == "reachable" else acc & ok)
    return acc.sum() * h * h


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    m0, rho = published()
    modes = m0.assembly_modes(rho)
    C = planar_fk.rpr3_polynomial(m0.base_points[:, :2], m0.tool_points[:, :2], rho[None])
    print(f"published 3-RPR: {len(modes.pose)} real modes, residual max "
          f"{modes.residual.max():.2e} mm, |c4|/max|c| = "
          f"{max(abs(C[0, 0]), abs(C[0, 8])) / np.abs(C).max():.1e}")
    for x, y, p in modes.pose[:, [0, 1, 5]]:
        print(f"   x = {x:9.4f}  y = {y:9.4f}  phi = {math.degrees(p):9.4f} deg")
    r = pkmlab.load_mechanism(MECH / "planar-3rpr.yaml")
    print("\n3-RPR constant-orientation areas (5 mm grid, target 1 %): cm²")
    phis = np.radians([-60, -30, 0, 30, 60, 90])
    res = area_per_phi(r, phis, 5.0)
    for a, w in zip(phis, res):
        print(f"  phi {math.degrees(a):6.1f}: exact {w.exact / 100:9.3f}  bracket "
              f"[{w.lower / 100:9.3f}, {w.upper / 100:9.3f}]  estimate {w.estimate / 100:9.3f}"
              f"  ({w.seconds:.2f} s, {w.depth} levels)")
    plot_planar(r, res, out / "rpr3-area-per-phi.png", title="planar-3rpr: area per φ")
    for kind in ("reachable", "dexterous"):
        t = time.perf_counter()
        w = planar_workspace(r, kind, np.radians([-30.0, 30.0]), 5.0)
        b = brute(r, np.linspace(*np.radians([-30.0, 30.0]), 241), 2.0, kind)
        print(f"  {kind} ±30°: bracket [{w.lower / 100:.3f}, {w.upper / 100:.3f}] estimate "
              f"{w.estimate / 100:.3f} ({time.perf_counter() - t:.2f} s); brute force 2 mm × "
              f"241 φ: {b / 100:.3f}")
        plot_planar(r, [w], out / f"rpr3-{kind}.png")
    fb = pkmlab.load_mechanism(MECH / "fivebar-scara.yaml")
    print("\nfive-bar area per working mode (5 mm grid): cm²")
    for mode, w in areas_per_working_mode(fb, 5.0).items():
        mm = fb.with_working_mode(mode)
        b = brute(mm, [0.0], 1.0, "constant")
        print(f"  {mode}: bracket [{w.lower / 100:.3f}, {w.upper / 100:.3f}] estimate "
              f"{w.estimate / 100:.3f}; brute force 1 mm: {b / 100:.3f}")
        plot_planar(mm, [w], out / f"fivebar-{mode}.png", title=f"five-bar, mode {mode}")
    free = type(fb)(fb.base_points, fb.proximal, fb.distal, (-math.pi, math.pi), fb.branch)
    w = planar_workspace(free, "constant", None, 5.0)
    print(f"  no motor window: exact {w.exact / 100:.3f} in [{w.lower / 100:.3f}, "
          f"{w.upper / 100:.3f}]")
    w = planar_workspace(fb, "constant", None, 5.0)
    rm = resolution_map(fb, w, math.radians(0.01))
    fin = rm["worst"][np.isfinite(rm["worst"])]
    print(f"  resolution, 0.01° motor steps: worst displacement min {fin.min():.4f} mm, median "
          f"{np.median(fin):.4f}, 90 % {np.percentile(fin, 90):.4f}, max {fin.max():.3f}")
    plot_planar(fb, [w], out / "fivebar-resolution.png", values=[rm["worst"]],
                value_label="mm per 0.01° motor step")
    tp = pkmlab.load_mechanism(MECH / "tripod-3prs.yaml")
    print("\n3-PRS free-coordinate workspace, tilt box ±30°:")
    for hz, ha in ((10.0, 2.0), (5.0, 1.0), (2.5, 0.5)):
        w = tripod_workspace(tp, math.radians(30.0), resolution_z=hz,
                             resolution_angle=math.radians(ha))
        m = w.metrics()
        print(f"  {hz} mm / {ha}°: volume {m['sampled_volume_mm_deg2']:,.0f} mm·deg², z "
              f"{m['z_range_mm']}, parasitic |x| {m['parasitic_x_max_mm']:.4f} mm, |y| "
              f"{m['parasitic_y_max_mm']:.4f} mm, |(x, y)| {m['parasitic_xy_max_mm']:.4f} mm, "
              f"|θz| {m['parasitic_theta_z_max_deg']:.4f}° ({m['seconds']:.1f} s)")
    w = tripod_workspace(tp, math.radians(60.0), resolution_z=5.0,
                         resolution_angle=math.radians(1.0))
    plot_tripod(w, out / "tripod-tilts.png", title="tripod-3prs: tilt region per height")
    print(f"  tilt box ±60° (5 mm / 1°): {w.metrics()['sampled_volume_mm_deg2']:,.0f} mm·deg²")


if __name__ == "__main__":
    args = sys.argv[1:]
    main(Path(args[args.index("--out") + 1]) if "--out" in args
         else ROOT / "results" / "planar-validation")
