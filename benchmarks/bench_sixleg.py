"""The generic six-leg family against the hand-tuned kernels, in the same run.

IK throughput (10⁶ poses near nominal) and the Jacobian (10⁵ poses) of the generic declaration
(``SixLeg.from_mechanism``) of each shipped 6-PSU / 6-UPS / 6-RSS against the family's own
kernels (ratio = generic time / fast time), each also as a multiple of the **memory floor**: a
parallel numba pass that reads the ``(N, 6)`` poses and writes fresh ``(N, 6)`` float64, ``(N,
6)`` int8 and ``(N,)`` int8 outputs, the least ``inverse`` must do (issue 28: generic ≤ 3×).
And the Hexaglide-like 6-PUS (sliders on horizontal
rails): IK throughput and its constant workspace at 5 mm, exact columns against sampled voxels
(ratio = sampled time / column time).

``--cpu``: the IK only, one numba thread, CPU time (best of 7, the three timed in turn) of the
memory floor, the dedicated family and the generic declaration, and their ratios (on a loaded
machine), for the shipped files and a mixed prismatic/slider instance (legs 2, 4, 6 of the
6-UPS on inclined rails, ``tests/mechanisms/test_sixleg.py::_mixed_linear``). Also the
generic declaration on the same 10⁶ poses in batches of 4,096, whose inputs and outputs stay
in the caches: its compute alone, which no overlap of memory traffic can go below. A kernel compiled
in the measuring process runs 2-4x slower than the same kernel loaded from numba's cache (seen
for every kernel here: issue 28, session 4), so when this process had to compile, ``--cpu``
measures again in a fresh process, which loads them.

Run: .venv/bin/python benchmarks/bench_sixleg.py [--cpu]   (state the load: ``uptime``)
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import numba
import numpy as np
from _timing import cpu_best, timed
from numba import njit, prange

import pkmlab
from pkmlab.mechanisms import SixLeg
from pkmlab.workspaces import workspace

ROOT = Path(__file__).resolve().parents[1] / "studies" / "mechanisms"
FILES = ("hopkins-williams-6psu", "gough-stewart-6ups", "instructables-servo-6rss")
N_IK, N_J = 1_000_000, 100_000
#: poses per batch of the in-cache timing (``--cpu``): inputs and outputs, 0.4 MB, stay in L2
N_CACHE = 4096


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


def _mixed_linear():
    """Legs 1, 3, 5 of the Kotlarski 6-UPS; legs 2, 4, 6 sliders on rails inclined 60° inward
    (as ``tests/mechanisms/test_sixleg.py::_mixed_linear``)."""
    from pkmlab.mechanisms.families.sixleg_layout import rail_axes

    ups = pkmlab.load_mechanism(ROOT / "gough-stewart-6ups.yaml")
    e = rail_axes(ups.base_points, math.radians(60), "inward")
    even = (np.arange(len(e)) % 2 == 1)[:, None]
    return SixLeg(np.where(even, ups.base_points - 600 * e, ups.base_points),
                  ups.platform_points, ["prismatic", "slider"] * 3, np.where(even, e, 0.0),
                  np.zeros_like(e), 0.0, [0.0, 450.0] * 3, ups.stroke, -1.0,
                  name="mixed-linear")


def _in_cache(mech, X):
    """The IK driver ``mech.inverse`` runs, on ``X`` in batches of :data:`N_CACHE` poses into
    outputs allocated once: the batches' inputs and outputs stay in the caches, so this times
    the compute alone, without memory traffic, page faults or per-call overhead."""
    from pkmlab.mechanisms.kernels import ik

    g, (lo, hi) = mech._ik_geometry, map(float, mech.stroke)
    drive = ik.make_driver(mech._ik_kernel(), len(g), "euler", mech.n_actuators)
    batches = [ik.carray(X[k:k + N_CACHE]) for k in range(0, len(X), N_CACHE)]
    q, st = np.empty((N_CACHE, mech.n_actuators)), np.empty((N_CACHE, mech.n_actuators), np.int8)
    reason = np.empty(N_CACHE, np.int8)

    def run():
        for b in batches:
            m = len(b)
            drive(b, g, lo, hi, q[:m], st[:m], reason[:m])
    return run


def cpu_mode() -> None:
    from pkmlab.runtime.jit import compile_log

    numba.set_num_threads(1)
    print(f"one numba thread, CPU time, load average: {os.getloadavg()}")
    rng = np.random.default_rng(0)
    with compile_log() as rec:
        cases = []
        for name in (*FILES, "hexaglide-6pus", "mixed"):
            fast = (_mixed_linear() if name == "mixed"
                    else pkmlab.load_mechanism(ROOT / f"{name}.yaml"))
            gen = fast if fast.family == "sixleg" else SixLeg.from_mechanism(fast)
            fast.inverse(fast.nominal_pose[None])
            gen.inverse(gen.nominal_pose[None])
            cases.append((name, fast, gen))
    if rec.compiled and os.environ.get("PKMLAB_BENCH_RERUN") != "1":
        print(f"{rec.summary()}; measuring in a fresh process that loads them", flush=True)
        env = dict(os.environ, PKMLAB_BENCH_RERUN="1")
        os.execve(sys.executable, [sys.executable, *sys.argv], env)
    for name, fast, gen in cases:
        X = _poses(fast, N_IK, rng)
        fns = {"floor": lambda: memory_floor(X), "generic": lambda: gen.inverse(X),  # noqa: B023
               "in cache": _in_cache(gen, X)}
        if gen is not fast:
            fns["dedicated"] = lambda: fast.inverse(X)         # noqa: B023
        t = cpu_best(fns)
        tk = t.get("dedicated", math.nan)
        print(f"{name}: memory floor {t['floor'] * 1e3:5.1f} ms; dedicated "
              f"{tk / t['floor']:4.2f}x, generic {t['generic'] / t['floor']:4.2f}x the floor; "
              f"generic in cache {t['in cache'] / t['floor']:4.2f}x")
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
