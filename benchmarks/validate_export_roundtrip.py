"""Issue 25: the MJCF round trip's figures for docs/validation.md.

For one mechanism of every registered family (the first shipped file of each, and the
three-leg test plugin tri3) and the baseline design of every shipped study: 10 random valid
poses near the nominal pose (±25 mm, ±10° in the free coordinates, pkmlab.testing), each from
the nominal pose: ramp the servos along pkmlab's IK of the straight pose path (0.3 s), settle
4 s, gravity and contacts off, the exported file's own solver settings; then the worst tool
position and rotation errors, loop gap and joint-centre error against ``mech.legs(pose)``.
Sag: the nominal pose held with gravity on, 4 s. Run:

    PYTHONPATH=src python benchmarks/validate_export_roundtrip.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "data" / "plugin3"))

import pkmlab_tri3_family as tri3  # noqa: E402

import pkmlab  # noqa: E402
from pkmlab.export import roundtrip as rt  # noqa: E402
from pkmlab.study import load_study  # noqa: E402
from pkmlab.study.candidates import mass_model  # noqa: E402
from pkmlab.testing import random_valid_poses  # noqa: E402

N = 10


def cases():
    seen = set()
    for f in sorted((ROOT / "studies" / "mechanisms").glob("*.yaml")):
        m = pkmlab.load_mechanism(f)
        if m.family not in seen:
            seen.add(m.family)
            yield f"{m.family} ({f.stem})", m, None
    yield "tri3 (test plugin)", tri3.reporters_tripod(name="tri3"), None
    for f in sorted((ROOT / "studies").glob("*.yaml")):
        s = load_study(f)
        yield f"study {f.stem} baseline", s.space.spec_of(None).build(), mass_model(s)


def main() -> None:
    print("| mechanism | position mm | rotation rad | loop gap mm | joint mm | sag tool mm "
          "| sag tool rad | sag loop gap mm | s |")
    print("|---|---|---|---|---|---|---|---|---|")
    worst = np.zeros(7)
    for label, mech, mass in cases():
        t = time.perf_counter()
        w = np.zeros(4)
        for X in random_valid_poses(mech, N, seed=2025):
            model, data = rt.load(mech, mass=mass)
            rt.drive(mech, model, data, X)
            c = rt.compare(mech, model, data, X)
            w = np.maximum(w, [c["position_mm"], c["rotation_rad"], c["loop_gap_mm"],
                               c["joint_mm"]])
        model, data = rt.load(mech, mass=mass)
        s = rt.sag(mech, model, data)
        row = np.r_[w, s["tool_mm"], s["tool_rad"], s["loop_gap_mm"]]
        worst = np.maximum(worst, row)
        print(f"| {label} | " + " | ".join(f"{v:.1e}" for v in row)
              + f" | {time.perf_counter() - t:.1f} |")
    print("| **worst** | " + " | ".join(f"{v:.1e}" for v in worst) + " | |")
    import mujoco

    print(f"\nMuJoCo {mujoco.__version__}, {N} poses per mechanism")


if __name__ == "__main__":
    main()
