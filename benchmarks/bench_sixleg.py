"""The generic six-leg family against the hand-tuned kernels, in the same run.

IK throughput (10⁶ poses near nominal) and the Jacobian (10⁵ poses) of the generic declaration
(``SixLeg.from_mechanism``) of each shipped 6-PSU / 6-UPS / 6-RSS against the family's own
kernels (ratio = generic time / fast time), each also as a multiple of the **memory floor**: a
parallel numba pass that reads the ``(N, 6)`` poses and writes fresh ``(N, 6)`` float64, ``(N,
6)`` int8 and ``(N,)`` int8 outputs, the least ``inverse`` must do (issue 28: generic ≤ 3×).
And the Hexaglide-like 6-PUS (sliders on horizontal
rails): IK throughput and its constant workspace at 5 mm, exact columns against sampled voxels
(ratio = sampled time / column time).

``--cpu``: the IK only, one numba thread, CPU time (best of 7) of the memory floor, the
dedicated family and the generic declaration, and their ratios (on a loaded machine).

Run: .venv/bin/python benchmarks/bench_sixleg.py [--cpu]   (state the load: ``uptime``)
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numba
import numpy as np
from _timing import timed
from numba import njit, prange

import pkmlab
from pkmlab.mechanisms import SixLeg
from pkmlab.workspaces import workspace

ROOT = Path(__file__).resolve().parents[1] / "studies" / "mechanisms"
FILES = ("hopkins-williams-6psu", "gough-stewart-6ups", "instructables-servo-6rss")
N_IK, N_J = 1_000_000, 100_000


@njit(parallel=True, cache=True)
def _floor_kernel(x, q, st, reason):
    for k in prange(x.shape[0]):
        s = x[k, 0] + x[k, 1] + x[k, 2] + x[k, 3] + x[k, 4] + x[k, 5]
        for i in range(q.shape[1]):
            q[k, i] = s
            st[k, i] = 0
        reason[k] = 0


def memory_floor(X):
    """The memory traffic of ``inverse(X)`` alone (see the module docstring)."""
    n = len(X)
    q = np.empty((n, 6))
    _floor_kernel(X, q, np.empty((n, 6), dtype=np.int8), np.empty(n, dtype=np.int8))
    return q


def _poses(mech, n, rng):
    return mech.nominal_pose + np.concatenate(
        [rng.uniform(-40, 40, (n, 3)), np.radians(rng.uniform(-15, 15, (n, 3)))], axis=1)


def _cpu(fn, repeats: int = 7) -> float:
    fn()
    ts = []
    for _ in range(repeats):
        c = time.process_time()
        fn()
        ts.append(time.process_time() - c)
    return min(ts)


def cpu_mode() -> None:
    numba.set_num_threads(1)
    print(f"one numba thread, CPU time, load average: {os.getloadavg()}")
    rng = np.random.default_rng(0)
    for name in (*FILES, "hexaglide-6pus"):
        fast = pkmlab.load_mechanism(ROOT / f"{name}.yaml")
        gen = fast if fast.family == "sixleg" else SixLeg.from_mechanism(fast)
        X = _poses(fast, N_IK, rng)
        tf = _cpu(lambda: memory_floor(X))                     # noqa: B023
        tg = _cpu(lambda: gen.inverse(X))                      # noqa: B023
        tk = _cpu(lambda: fast.inverse(X)) if gen is not fast else math.nan  # noqa: B023
        print(f"{name}: memory floor {tf * 1e3:5.1f} ms; dedicated {tk / tf:4.2f}x, "
              f"generic {tg / tf:4.2f}x the floor")
    print(f"load average after: {os.getloadavg()}")


def main() -> None:
    if "--cpu" in sys.argv:
        cpu_mode()
        return
    print(f"numba threads: {numba.get_num_threads()}, load average: {os.getloadavg()}")
    rng = np.random.default_rng(0)
    for name in FILES:
        fast = pkmlab.load_mechanism(ROOT / f"{name}.yaml")
        gen = SixLeg.from_mechanism(fast)
        X = _poses(fast, N_IK, rng)
        t_floor, _ = timed(lambda: memory_floor(X), 5)         # noqa: B023
        t_fast, _ = timed(lambda: fast.inverse(X), 5)          # noqa: B023
        t_gen, _ = timed(lambda: gen.inverse(X), 5)            # noqa: B023
        XJ = X[:N_J]
        j_fast, _ = timed(lambda: fast.jacobian(XJ), 3)        # noqa: B023
        j_gen, _ = timed(lambda: gen.jacobian(XJ), 3)          # noqa: B023
        print(f"{fast.family}: IK {N_IK / t_fast / 1e6:6.1f} M/s fast, "
              f"{N_IK / t_gen / 1e6:6.1f} M/s generic (ratio {t_gen / t_fast:4.2f}); memory "
              f"floor {t_floor * 1e3:5.1f} ms: fast {t_fast / t_floor:4.1f}x, generic "
              f"{t_gen / t_floor:4.1f}x; "
              f"Jacobian {j_gen / j_fast:4.2f}x the fast family's time")
    hx = pkmlab.load_mechanism(ROOT / "hexaglide-6pus.yaml")
    X = _poses(hx, N_IK, rng)
    t_floor, _ = timed(lambda: memory_floor(X), 5)
    t, _ = timed(lambda: hx.inverse(X), 5)
    tw, r = timed(lambda: workspace(hx, "constant", resolution=5.0), 3)
    ts, s = timed(lambda: workspace(hx, "constant", resolution=5.0, method="sampled"), 3)
    print(f"hexaglide-6pus: IK {N_IK / t / 1e6:6.1f} M poses/s ({t / t_floor:4.1f}x the memory "
          f"floor); constant workspace at 5 mm "
          f"{tw:.3f} s ({r.method}, {r.volume / 1e3:.1f} ± {r.volume_error / 1e3:.1f} cm3), "
          f"sampled {ts:.3f} s ({s.volume / 1e3:.1f} ± {s.volume_error / 1e3:.1f} cm3; "
          f"ratio {ts / tw:.1f})")


if __name__ == "__main__":
    main()
