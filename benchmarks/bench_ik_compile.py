"""Compile cost and bit-identity of the IK kernels (issue 28, session 6).

The IK (Euler and frame inputs) and the Jacobian of each shipped six-leg instance, the
family's own kernels and the generic ``SixLeg`` declaration, on 5,000 fixed random poses per
instance (NaN poses and angles beyond the fast sine range among them); then the IK and
Jacobian of every other shipped mechanism on 3,000 random poses of its own coordinates
(±20 % of the nominal pose, NaN poses among them). Prints the CPU seconds
this takes, most of it compiling when ``NUMBA_CACHE_DIR`` is empty, and saves every output to
an ``.npz``; ``--compare A.npz B.npz`` then checks that two such files are bit-identical (NaN
equal to NaN), e.g. before and after a change of how the kernels are compiled.

Run: NUMBA_CACHE_DIR=$(mktemp -d) .venv/bin/python benchmarks/bench_ik_compile.py OUT.npz
     .venv/bin/python benchmarks/bench_ik_compile.py --compare BEFORE.npz AFTER.npz
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import pkmlab
from pkmlab.mechanisms import SixLeg
from pkmlab.poses import euler_to_matrix

ROOT = Path(__file__).resolve().parents[1] / "studies" / "mechanisms"


def compare(a_path: str, b_path: str) -> None:
    a, b = np.load(a_path), np.load(b_path)
    if set(a.files) != set(b.files):
        raise SystemExit(f"different outputs: {sorted(set(a.files) ^ set(b.files))}")
    bad = [k for k in a.files if not np.array_equal(a[k], b[k], equal_nan=True)]
    print(f"{len(a.files)} arrays compared; differing: {bad or 'none'}")


FILES = ("hopkins-williams-6psu", "gough-stewart-6ups", "instructables-servo-6rss",
         "hexaglide-6pus")
OTHERS = ("clavel-delta3", "klipper-example-ldelta3", "luzi-3chain", "planar-3rpr",
          "tripod-3prs", "fivebar-scara", "paradex-6pus")


def _poses(mech, rng, n=5000):
    X = mech.nominal_pose + np.concatenate(
        [rng.uniform(-60, 60, (n, 3)), np.radians(rng.uniform(-25, 25, (n, 3)))], axis=1)
    X[::97] = np.nan                    # non-finite poses
    X[5::89, 3] = 2e5                   # angles beyond the vectorised sine's range
    return X


def main(path: str) -> None:
    out = {}
    rng = np.random.default_rng(7)
    c0 = time.process_time()
    for name in FILES:
        fast = pkmlab.load_mechanism(ROOT / f"{name}.yaml")
        generic = fast if fast.family == "sixleg" else SixLeg.from_mechanism(fast)
        for tag, m in (("fast", fast), ("gen", generic)):
            X = _poses(m, rng)
            r = m.inverse(X)
            r2 = m.inverse((X[:, :3].copy(), euler_to_matrix(X[:, 3:])))
            key = f"{name}-{tag}"
            out[f"{key}-q"], out[f"{key}-st"], out[f"{key}-r"] = r.q, r.leg_status, r.reason
            out[f"{key}-q2"], out[f"{key}-r2"] = r2.q, r2.reason
            out[f"{key}-J"] = np.asarray(m.jacobian(X[:300]))
    c1 = time.process_time()
    print(f"the six-leg IK and Jacobians of {len(FILES)} instances, dedicated and generic: "
          f"{c1 - c0:.1f} s CPU")
    for name in OTHERS:
        m = pkmlab.load_mechanism(ROOT / f"{name}.yaml")
        x0 = np.asarray(m.nominal_pose, dtype=float)
        X = x0 + rng.uniform(-0.2, 0.2, (3000, x0.size)) * np.maximum(np.abs(x0), 1.0)
        X[::97] = np.nan
        r = m.inverse(X)
        out[f"{name}-q"], out[f"{name}-st"], out[f"{name}-r"] = r.q, r.leg_status, r.reason
        out[f"{name}-J"] = np.asarray(m.jacobian(X[:200]))
    print(f"the IK and Jacobians of {len(OTHERS)} other mechanisms: "
          f"{time.process_time() - c1:.1f} s CPU")
    np.savez(path, **out)

if __name__ == "__main__":
    if sys.argv[1] == "--compare":
        compare(sys.argv[2], sys.argv[3])
    else:
        main(sys.argv[1])
