"""Figures of docs/validation.md, "Continuous optima": the Hopkins & Williams 6-PSU's
orientation capability and the stroke its ±30° simultaneous set needs, over continuous
positions with their brackets, against the grid searches they replace, at several orientation
samplings and exchange rounds (with independent checks by dense brute force and local
optimisation on the inverse kinematics); the shipped 6-UPS's needed stroke for several boxes.
Prints the load (``uptime``) with the times.

Run: ``.venv/bin/python benchmarks/optima_validation.py``.
"""

from __future__ import annotations

import math
import subprocess
import time
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

from pkmlab import load_mechanism
from pkmlab.mechanisms import NO_STROKE
from pkmlab.poses import euler_to_matrix
from pkmlab.study.evaluators import capability
from pkmlab.workspaces import Constraints, OrientationSet, workspace
from pkmlab.workspaces.optima.search import orientation_capability, stroke_needed

ROOT = Path(__file__).resolve().parents[1]


def _q(mech, p, E):
    R = euler_to_matrix(np.atleast_2d(E))
    q = mech.inverse((np.tile(p, (len(R), 1)), R), stroke=NO_STROKE).q
    return np.where(np.isfinite(q), q, np.nan)


def _extremes(mech, p, th, D):
    """Each leg's largest and smallest actuator value at the point p over the continuous box:
    L-BFGS-B from the dense sample D's extremes."""
    q = _q(mech, p, D)
    hi, lo = np.nanmax(q), np.nanmin(q)
    for i in range(6):
        for s in (1.0, -1.0):
            r = minimize(lambda v, s=s, i=i: -s * _q(mech, p, v)[0, i],
                         D[np.nanargmax(s * q[:, i])], method="L-BFGS-B",
                         bounds=[(-th, th)] * 3)
            hi, lo = (max(hi, -r.fun), lo) if s > 0 else (hi, min(lo, r.fun))
    return hi, lo


def _psu_independent(psu, b, th):
    """Dense 21³ brute force with the inverse kinematics (q = z + c along a column: the
    column needs q_min + max q - min q), minimised over columns by Nelder–Mead; then that
    column's continuous need (each leg's slider extremes by L-BFGS-B)."""
    D = OrientationSet.box(np.full(3, th), samples=21).parameters()
    qmin = psu.stroke[0]

    def need(xy):
        q = _q(psu, [xy[0], xy[1], 0.0], D)
        return 1e3 if np.isnan(q).any() else qmin + np.max(q) - np.min(q)

    t = time.perf_counter()
    res = minimize(need, np.asarray(b.point[:2]), method="Nelder-Mead",
                   options={"xatol": 1e-6, "fatol": 1e-8})
    hi, lo = _extremes(psu, [res.x[0], res.x[1], 0.0], th, D)
    return (f"dense 21^3 {res.fun:.4f} mm at ({res.x[0]:.3f}, {res.x[1]:.3f}); that column "
            f"over the continuous box {qmin + hi - lo:.4f} mm; bracket "
            f"[{b.lower:.4f}, {b.upper:.4f}]; {time.perf_counter() - t:.1f} s")


def _ups_independent(ups, b, th):
    """Dense 13³ brute force with the inverse kinematics: Nelder–Mead over (x, y, z) of the
    largest leg length, with the smallest kept >= q_min (penalty); then that point's
    continuous extremes (L-BFGS-B)."""
    D = OrientationSet.box(np.full(3, th), samples=13).parameters()
    qmin = ups.stroke[0]

    def need(p):
        q = _q(ups, p, D)
        return 1e6 if np.isnan(q).any() else np.max(q) + 1e5 * max(0.0, qmin - np.min(q))

    t = time.perf_counter()
    res = minimize(need, np.asarray(b.point), method="Nelder-Mead",
                   options={"xatol": 1e-6, "fatol": 1e-8, "maxiter": 4000})
    hi, lo = _extremes(ups, res.x, th, D)
    text = (f"dense 13^3 {res.fun:.4f} mm at {np.round(res.x, 3)}; that point over the "
            f"continuous box: longest {hi:.4f}, shortest {lo:.4f} mm")
    p = res.x.copy()
    for _ in range(40):               # raise the point until the shortest leg is in stroke
        if lo >= qmin - 1e-7:
            break
        p[2] += 1.5 * (qmin - lo)
        hi, lo = _extremes(ups, p, th, D)
    if p[2] != res.x[2]:
        text += f"; raised to z {p[2]:.4f}: longest {hi:.4f}, shortest {lo:.4f} mm"
    return text + (f"; bracket [{b.lower:.4f}, {b.upper:.4f}]; "
                   f"{time.perf_counter() - t:.1f} s")


def main() -> None:
    print(subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())
    psu = load_mechanism(ROOT / "studies/mechanisms/hopkins-williams-6psu.yaml")
    print("orientation capability (deg): samples | grid bisection 2.5 mm | continuous "
          "[lower, upper] (sampled) | seconds")
    for n in (5, 7, 13):
        req = {"orientations": OrientationSet.box(np.radians([5.0] * 3), samples=n),
               "resolution": 2.5, "constraints": Constraints()}
        a, br, _ = capability(psu, req)
        b = orientation_capability(psu, n)
        print(f"  {n:2d} | {a:.3f} (+{br:.3f}) | [{b.lower:.4f}, {b.upper:.4f}] "
              f"({b.sampled:.4f}) | {b.seconds:.2f}  point {np.round(b.point, 4)}")
    # the study's first Pareto design (rounded printed parameters, docs/validation.md): links
    # near horizontal at its capability, where the first-order cell bounds are loose
    pareto = load_mechanism({
        "name": "pareto-1", "family": "psu6", "link_length": "295.6 mm",
        "generator": {"base_radii": ["100 mm", "132.9 mm"],
                      "platform_radii": ["29.2 mm", "48.6 mm"], "base_pair_angle": "auto",
                      "platform_rotation": "27.8 deg", "pairing": "same"},
        "stroke": ["0 mm", "4 in"], "tool_offset": ["0 mm", "0 mm", "47 mm"]})
    for n in (5, 9):
        b = orientation_capability(pareto, n)
        print(f"  Pareto design, {n:2d} | [{b.lower:.4f}, {b.upper:.4f}] ({b.sampled:.4f}) | "
              f"{b.seconds:.2f} | {b.method.split('; ')[-1]} | {b.note}")
    print("stroke needed for the ±30° simultaneous set (mm, stroke [0, q_max]): samples | "
          "rounds | [lower, upper] width (grid alone) | seconds | per round: orientations "
          "[lower, upper] s")
    o30 = OrientationSet.box(np.radians([30.0] * 3), samples=3)
    for n in (3, 5, 7, 13):
        for rounds in (0, 8):
            b = stroke_needed(psu, o30.with_samples(n), rounds=rounds)
            print(f"  {n:2d} | {rounds} | [{b.lower:.4f}, {b.upper:.4f}] {b.width:.4f} "
                  f"({b.sampled:.4f}) | {b.seconds:.1f} | " + "; ".join(
                      f"{h['orientations']} [{h['lower']:.4f}, {h['upper'] or math.inf:.4f}]"
                      f" {h['seconds']:.1f}" for h in b.history) + f"  {b.note}")
    b = stroke_needed(psu, o30)
    print("  independent (Hopkins, ±30°):", _psu_independent(psu, b, math.radians(30.0)))
    ups = load_mechanism(ROOT / "studies/mechanisms/gough-stewart-6ups.yaml")
    print("6-UPS stroke needed (legs from 390 mm): box | [lower, upper] width (3^3 grid "
          "alone) | seconds | rounds | note")
    for a in (5.0, 10.0, 20.0, 30.0, 60.0):
        b = stroke_needed(ups, OrientationSet.box(np.radians([a] * 3), samples=3))
        print(f"  ±{a:g}° | [{b.lower:.4f}, {b.upper:.4f}] {b.width:.4f} ({b.sampled:.4f}) | "
              f"{b.seconds:.1f} | {len(b.history) - 1} | {b.note}")
        print("     independent:", _ups_independent(ups, b, math.radians(a)))
    # the grid at the bracket's ends: the sample is empty below, the set non-empty above
    o7 = OrientationSet.box(np.radians([30.0] * 3), samples=7)
    for q in (131.0, 131.5, 132.0):
        r = workspace(psu, "dexterous", o7, 2.5, Constraints(stroke=(0.0, q)))
        print(f"  grid 2.5 mm, 7 samples, stroke [0, {q}]: volume {r.volume / 1e3:.4f} cm3")
    print(subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())


if __name__ == "__main__":
    main()
