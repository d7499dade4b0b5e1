"""IK throughput (poses/s) on 10⁶ random poses per family, and FK solves/s.

Run: .venv/bin/python benchmarks/bench_kinematics.py   (targets: 6-PSU, 6-UPS IK ≥ 20 M/s;
6-RSS ≥ 15 M/s). ``python benchmarks/bench_kinematics.py rss6`` runs one family.
"""

from __future__ import annotations

import time
from pathlib import Path

import numba
import numpy as np

import pkmlab

ROOT = Path(__file__).resolve().parents[1]
FILES = {"psu6": "hopkins-williams-6psu.yaml", "ups6": "gough-stewart-6ups.yaml",
         "luzi3": "luzi-3chain.yaml", "rss6": "instructables-servo-6rss.yaml"}
N_IK, N_FK = 1_000_000, 2_000


def best_of(fn, repeat: int = 7) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main(only: list[str] | None = None) -> None:
    print(f"numba threads: {numba.get_num_threads()}, poses per IK batch: {N_IK:,}")
    rng = np.random.default_rng(0)
    for family, fname in FILES.items():
        if only and family not in only:
            continue
        mech = pkmlab.load_mechanism(ROOT / "studies" / "mechanisms" / fname)
        X = mech.nominal_pose + np.concatenate(
            [rng.uniform(-40, 40, (N_IK, 3)), np.radians(rng.uniform(-15, 15, (N_IK, 3)))],
            axis=1)
        mech.inverse(X[:10])                                   # compile / load cache
        t_ik = best_of(lambda: mech.inverse(X))                # noqa: B023
        ok = mech.inverse(X).valid
        Xv = X[ok][:N_FK]
        q = mech.inverse(Xv).q
        mech.forward(q[:5])
        t_fk = best_of(lambda: mech.forward(q), repeat=3)      # noqa: B023
        print(f"{family:6s} IK {N_IK / t_ik / 1e6:7.1f} M poses/s  ({t_ik * 1e3:6.1f} ms, "
              f"{ok.mean():.0%} valid)   FK {len(q) / t_fk:9.0f} solves/s "
              f"(batch of {len(q)}, from the nominal pose)")


if __name__ == "__main__":
    import sys

    main(sys.argv[1:] or None)
