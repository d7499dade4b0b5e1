"""Validation of the guaranteed volume bracket (``pkmlab.workspaces.bracket.columns``) against dense
brute-force estimates, for each kind, on the Hopkins & Williams 6-PSU and the shipped 6-UPS.

For every case, the bracket is computed once with a budget of leg-bound evaluations; every
step of its refinement is itself a guaranteed bracket, and the table shows how it narrows.
Each step is compared with independent estimates by the engine:

* constant: the engine on a fine grid (exact in z, x-y error second order);
* dexterous: the engine with a dense orientation grid *and* its local optimisation of every
  leg's extremes over the continuous set (``refine=True``, compass search from the best
  samples) on a fine grid: it can only miss extremes, so it approaches the true volume from
  above;
* reachable: the engine with dense orientation grids (the union over samples approaches the
  true volume from below).

Prints a markdown table (docs/validation.md). Run:
``.venv/bin/python benchmarks/validate_bracket.py`` (several minutes; state the load).
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

from pkmlab import load_mechanism
from pkmlab.workspaces import OrientationSet, workspace
from pkmlab.workspaces.bracket.columns import volume_bracket

ROOT = Path(__file__).resolve().parents[1]


def deg(*a):
    return [math.radians(x) for x in a]


def cases():
    psu = load_mechanism(ROOT / "studies/mechanisms/hopkins-williams-6psu.yaml")
    ups = load_mechanism(ROOT / "studies/mechanisms/gough-stewart-6ups.yaml")
    box10 = OrientationSet.box(deg(10, 10, 10))
    yield ("6-PSU Hopkins", psu, "constant", None, 2.5, (2e5, 1e6, 5e6),
           [("engine, 0.5 mm grid", lambda: workspace(psu, "constant", None, 0.5).volume)])
    yield ("6-PSU Hopkins", psu, "dexterous", box10, 2.5, (3e6, 1e7, 4e7),
           [("engine 7³ samples, 2.5 mm", lambda: workspace(psu, "dexterous", box10, 2.5).volume),
            ("engine 9³ + local optimisation, 1.25 mm",
             lambda: workspace(psu, "dexterous", box10.with_samples(9), 1.25,
                               refine=True).volume)])
    single = OrientationSet.box(deg(20, 20, 20), "single-axis")
    yield ("6-PSU Hopkins", psu, "dexterous single-axis ±20°", single, 2.5, (1e6, 5e6, 2e7),
           [("engine 19 per axis + local optimisation, 1.25 mm",
             lambda: workspace(psu, "dexterous", single.with_samples(19), 1.25,
                               refine=True).volume)])
    box5 = OrientationSet.box(deg(5, 5, 5))
    yield ("6-PSU Hopkins", psu, "reachable", box5, 2.5, (1e6, 1e7, 4e7),
           [(f"engine {n}³ samples, 1.25 mm",
             lambda n=n: workspace(psu, "reachable", box5.with_samples(n), 1.25).volume)
            for n in (5, 9, 13)])
    yield ("6-UPS Kotlarski", ups, "constant", None, 5.0, (1e6, 3e6, 1e7),
           [("engine, 1 mm grid", lambda: workspace(ups, "constant", None, 1.0).volume)])
    yield ("6-UPS Kotlarski", ups, "dexterous", box10, 5.0, (1e7, 4e7, 1e8),
           [("engine 7³ samples, 5 mm", lambda: workspace(ups, "dexterous", box10, 5.0).volume),
            ("engine 9³ + local optimisation, 2.5 mm",
             lambda: workspace(ups, "dexterous", box10.with_samples(9), 2.5,
                               refine=True).volume)])
    tt = OrientationSet.tilt_torsion(*deg(10, 5))
    yield ("6-UPS Kotlarski", ups, "reachable tilt 10°, torsion ±5°", tt, 10.0,
           (3e6, 2e7, 6e7),
           [(f"engine tilt-torsion n = {n}, 5 mm",
             lambda n=n: workspace(ups, "reachable", tt.with_samples(n), 5.0).volume)
            for n in (5, 9)])


def main() -> None:
    only = sys.argv[1:]
    print(f"load: {os.getloadavg()[0]:.1f} (1-min average) on {os.cpu_count()} cores")
    print("| machine | kind (set) | budget (evaluations) | lower cm³ | upper cm³ | width | "
          "stop | final h mm | s |")
    print("|---|---|---|---|---|---|---|---|---|")
    refs = []
    for name, mech, kind, oset, h, budgets, ref in cases():
        if only and not any(o in f"{name} {kind}" for o in only):
            continue
        k = kind.split()[0]
        label = kind if oset is None or " " in kind else f"{kind} ({_describe(oset)})"
        # one run; every step of its history is a guaranteed bracket at that budget
        b = volume_bracket(mech, k, oset, h, target=0.002, budget_s=3600,
                           max_evaluations=max(budgets))
        hist = b.history
        rows = [hist[0]] + [max((r for r in hist if r["evaluations"] <= bud),
                                key=lambda r: r["evaluations"], default=hist[0])
                            for bud in budgets[:-1]] + [hist[-1]]
        seen = set()
        for r in rows:
            if id(r) in seen:
                continue
            seen.add(id(r))
            w = (r["upper_mm3"] - r["lower_mm3"]) / r["upper_mm3"] if r["upper_mm3"] else 0
            stop = b.stop_reason if r is hist[-1] else "(step)"
            print(f"| {name} | {label} | {r['evaluations']:.2e} | {r['lower_mm3'] / 1e3:.2f} | "
                  f"{r['upper_mm3'] / 1e3:.2f} | {100 * w:.2f} % | {stop} | {r['h_mm']:g} | "
                  f"{r['seconds']:.1f} |", flush=True)
        for rname, fn in ref:
            t = time.perf_counter()
            v = fn()
            inside = all(r["lower_mm3"] <= v <= r["upper_mm3"] for r in hist)
            refs.append(f"| {name} | {label} | {rname} | {v / 1e3:.2f} | "
                        f"{'yes' if inside else 'NO'} | {time.perf_counter() - t:.1f} |")
    print()
    print("| machine | kind (set) | independent estimate | cm³ | inside every bracket | s |")
    print("|---|---|---|---|---|---|")
    print("\n".join(refs))


def _describe(o) -> str:
    if o.kind == "box":
        return f"±{math.degrees(o.angles[0]):g}° {o.semantics}"
    return f"tilt {math.degrees(o.tilt):g}°, torsion ±{math.degrees(o.torsion):g}°"


if __name__ == "__main__":
    main()
