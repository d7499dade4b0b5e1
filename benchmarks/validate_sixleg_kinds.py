"""The generic six-leg family's per-leg-kind IK kernels against its all-kinds kernel
``SixLeg._ik_one`` (the kernel every instance ran before issue 28): statuses and reasons
identical, q to 1e-12 mm or rad, on the suite's five instances (ups6, psu6 and rss6 layouts,
a Hexaglide, a mixed prismatic/slider machine) and 4,000 poses each. Moved out of the suite:
the all-kinds kernel is compiled by nothing else, and compiling it costs about a minute of
CPU on an empty cache. The suite keeps the per-kind kernels' checks against an independent
NumPy evaluation and against the dedicated families (tests/mechanisms/test_sixleg_ik.py).

Run: .venv/bin/python benchmarks/validate_sixleg_kinds.py      (exit status 1 on a mismatch)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path[:0] = [str(Path(__file__).resolve().parents[1] / "tests"),
                str(Path(__file__).resolve().parents[1] / "tests" / "mechanisms")]
from test_sixleg_ik import _cases, _poses  # noqa: E402

from pkmlab.mechanisms import SixLeg  # noqa: E402
from pkmlab.mechanisms.kernels import ik as K  # noqa: E402


def main() -> int:
    bad = 0
    for name, m in sorted(_cases().items()):
        X = _poses(m)
        res = m.inverse(X)
        n, g = len(X), m._ik_geometry
        q0, st0 = np.empty((n, 6)), np.empty((n, 6), dtype=np.int8)
        r0 = np.empty(n, dtype=np.int8)
        K.make_driver(SixLeg._ik_one, len(g), "euler")(X, g, *m.stroke, q0, st0, r0)
        same = (np.array_equal(res.leg_status, st0) and np.array_equal(res.reason, r0)
                and np.array_equal(np.isnan(res.q), np.isnan(q0)))
        dq = float(np.nanmax(np.abs(res.q - q0))) if np.isfinite(q0).any() else 0.0
        ok = same and dq <= 1e-12
        bad += not ok
        print(f"{name:10s} {n} poses: statuses and reasons identical: {same}; "
              f"largest |Δq| {dq:.3g} (≤ 1e-12: {dq <= 1e-12})")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
