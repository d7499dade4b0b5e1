"""Figures of docs/validation.md, "Continuous optima": the Hopkins & Williams 6-PSU's
orientation capability and the stroke its ±30° simultaneous set needs, over continuous
positions with their brackets, against the grid searches they replace, at several orientation
samplings. Prints the load (``uptime``) with the times.

Run: ``.venv/bin/python benchmarks/optima_validation.py``.
"""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

import numpy as np

from pkmlab import load_mechanism
from pkmlab.study.evaluators import capability
from pkmlab.workspaces import Constraints, OrientationSet, workspace
from pkmlab.workspaces.optima import orientation_capability, stroke_needed

ROOT = Path(__file__).resolve().parents[1]


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
    print("stroke needed for the ±30° simultaneous set (mm, stroke [0, q_max]): samples | "
          "[lower, upper] (sampled) | seconds")
    for n in (7, 13, 25):
        o = OrientationSet.box(np.radians([30.0] * 3), samples=n)
        t = time.perf_counter()
        b = stroke_needed(psu, o)
        print(f"  {n:2d} | [{b.lower:.2f}, {b.upper:.2f}] ({b.sampled:.2f}) | "
              f"{time.perf_counter() - t:.1f}  point {np.round(b.point, 3)}")
    # the grid at the bracket's ends: the sample is empty below, the set non-empty above
    o7 = OrientationSet.box(np.radians([30.0] * 3), samples=7)
    for q in (131.0, 131.5, 132.0):
        r = workspace(psu, "dexterous", o7, 2.5, Constraints(stroke=(0.0, q)))
        print(f"  grid 2.5 mm, 7 samples, stroke [0, {q}]: volume {r.volume / 1e3:.4f} cm3")
    print(subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())


if __name__ == "__main__":
    main()
