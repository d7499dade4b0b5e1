"""Where the generic six-leg crank IK's time goes (issue 28, session 5).

Replicas of the Euler driver of ``pkmlab.mechanisms.kernels.ik`` (one block at a time, no
``prange``, the block buffers allocated per block as there) running the generic crank
per-pose function ``sixleg_ik._crank_one`` on 10⁶ poses of the shipped servo hexapod (±40 mm,
±15°), outputs preallocated, CPU time, least of 9 rounds with all variants timed in turn:

* ``floor``: the memory floor of ``bench_sixleg.py`` (read the poses, write q, status, reason);
* ``copy`` / ``+sincos`` / ``+matrix``: stage 1 (the block load) in its three parts;
* ``legs``: stage 2 alone (on the loaded block buffers); ``pipeline``: all stages, = the
  library's driver on one thread;
* ``pipeline, matrix in legs``: the rotation entries formed inside the legs loop from the
  sines and cosines instead of stored to and reloaded from nine block rows (bit-identical:
  printed);
* ``pipeline, legs contracted``: the legs loop compiled with ``fastmath={"contract"}`` (FMA;
  changes the bits: the largest difference is printed);
* the vector divider alone: ``x/y``, ``sqrt`` and both, ns per element, and a 16-operation
  polynomial for comparison.

A kernel compiled in the measuring process runs 2-4x slower than the same kernel loaded from
numba's cache (issue 28, session 4); like ``bench_sixleg.py --cpu``, this script measures in a
fresh process when it had to compile.

Run: .venv/bin/python benchmarks/bench_crank_parts.py   (state the load: ``uptime``)
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import numba
import numpy as np
from _timing import cpu_best
from numba import njit
from numba.extending import register_jitable

import pkmlab
from pkmlab.mechanisms import SixLeg
from pkmlab.mechanisms.families.sixleg_ik import _crank_one
from pkmlab.mechanisms.kernels.ik import (
    BLOCK,
    ROW,
    TRIG_MAX,
    _euler_matrix,
    _load_euler,
    _prefill,
    _sincos_block,
    _store,
    _store_matrix,
    _width,
)

ROOT = Path(__file__).resolve().parents[1] / "studies" / "mechanisms"
N = 1_000_000


@njit(cache=True)
def _floor(x, q, st, reason):
    for k in range(x.shape[0]):
        s = x[k, 0] + x[k, 1] + x[k, 2] + x[k, 3] + x[k, 4] + x[k, 5]
        for i in range(q.shape[1]):
            q[k, i] = s
            st[k, i] = 0
        reason[k] = 0


@njit(cache=True)
def _copy(x, m, w, T, A):
    """Stage 1 without the sines and cosines: the poses into the block rows."""
    slow = 0
    for j in range(m):
        px, py, pz = x[6 * j], x[6 * j + 1], x[6 * j + 2]
        tx, ty, tz = x[6 * j + 3], x[6 * j + 4], x[6 * j + 5]
        T[j] = px
        T[ROW + j] = py
        T[2 * ROW + j] = pz
        A[j] = tx
        A[ROW + j] = ty
        A[2 * ROW + j] = tz
        slow += 0 if math.isfinite(px + py + pz) & (abs(tx) + abs(ty) + abs(tz) <= TRIG_MAX) else 1
    for j in range(m, w):
        for r in range(3):
            T[r * ROW + j] = 0.0
            A[r * ROW + j] = 0.0
    return slow


@njit(cache=True)
def _matrix(T, A, C, w):
    for j in range(w):
        _store_matrix(T, j, _euler_matrix(A[j], C[j], A[ROW + j], C[ROW + j], A[2 * ROW + j],
                                          C[2 * ROW + j]))


@register_jitable(error_model="numpy")
def _legs(T, w, g, qmin, qmax, q, st):
    for j in range(w):
        _crank_one(T[j], T[ROW + j], T[2 * ROW + j], T[3 * ROW + j], T[4 * ROW + j],
                   T[5 * ROW + j], T[6 * ROW + j], T[7 * ROW + j], T[8 * ROW + j],
                   T[9 * ROW + j], T[10 * ROW + j], T[11 * ROW + j], g, qmin, qmax, q, st, j)


@register_jitable(error_model="numpy", fastmath={"contract"})
def _legs_contracted(T, w, g, qmin, qmax, q, st):
    for j in range(w):
        _crank_one(T[j], T[ROW + j], T[2 * ROW + j], T[3 * ROW + j], T[4 * ROW + j],
                   T[5 * ROW + j], T[6 * ROW + j], T[7 * ROW + j], T[8 * ROW + j],
                   T[9 * ROW + j], T[10 * ROW + j], T[11 * ROW + j], g, qmin, qmax, q, st, j)


@register_jitable(error_model="numpy")
def _legs_matrix(T, A, C, w, g, qmin, qmax, q, st):
    for j in range(w):
        r = _euler_matrix(A[j], C[j], A[ROW + j], C[ROW + j], A[2 * ROW + j], C[2 * ROW + j])
        _crank_one(T[j], T[ROW + j], T[2 * ROW + j], r[0], r[1], r[2], r[3], r[4], r[5], r[6],
                   r[7], r[8], g, qmin, qmax, q, st, j)


@njit(cache=True, error_model="numpy")
def _drive(poses, g, qmin, qmax, q_out, st_out, reason_out, mode):
    """mode 0 copy, 1 +sincos, 2 +matrix (stage 1), 3 stage 2 alone, 4 the whole pipeline,
    5 the pipeline with the matrix in the legs loop, 6 with the legs loop contracted. Slow
    poses (non-finite, angles > TRIG_MAX) are not handled: the poses here have none."""
    n = poses.shape[0]
    x, q_flat, st_flat = poses.reshape(-1), q_out.reshape(-1), st_out.reshape(-1)
    for b in range((n + BLOCK - 1) // BLOCK):
        k0 = b * BLOCK
        m = min(BLOCK, n - k0)
        w = _width(m)
        xb = x[6 * k0:6 * (k0 + m)]
        T = np.empty(12 * ROW)
        A = np.empty(3 * ROW)
        C = np.empty(3 * ROW)
        q = np.empty(7 * ROW)
        st = np.empty(7 * ROW, dtype=np.int8)
        if mode <= 2 or mode == 5:
            _copy(xb, m, w, T, A)
            if mode >= 1:
                _sincos_block(A, C, w)
            if mode == 2:
                _matrix(T, A, C, w)
        elif mode != 3:
            _load_euler(xb, m, w, T, A, C)
        if mode >= 3:
            _prefill(st, 6, w)
            if mode == 5:
                _legs_matrix(T, A, C, w, g, qmin, qmax, q, st)
            elif mode == 6:
                _legs_contracted(T, w, g, qmin, qmax, q, st)
            else:
                if mode == 3:
                    for i in range(12 * ROW):
                        T[i] = 0.5
                _legs(T, w, g, qmin, qmax, q, st)
        if mode >= 4:
            out = slice(6 * k0, 6 * (k0 + m))
            _store(q, st, m, 6, q_flat[out], st_flat[out], reason_out[k0:k0 + m])


@njit(cache=True, error_model="numpy")
def _divider(a, out, mode):
    for i in range(a.shape[0]):
        x = a[i]
        if mode == 0:
            out[i] = 1.0 / x
        elif mode == 1:
            out[i] = math.sqrt(x)
        elif mode == 2:
            out[i] = x / math.sqrt(x)
        else:
            out[i] = ((((((((x * 1.1 + 0.3) * x + 0.2) * x + 0.1) * x + 0.3) * x + 0.2) * x
                        + 0.1) * x + 0.3) * x + 0.2)


def main() -> None:
    numba.set_num_threads(1)
    fast = pkmlab.load_mechanism(ROOT / "instructables-servo-6rss.yaml")
    gen = SixLeg.from_mechanism(fast)
    rng = np.random.default_rng(0)
    X = gen.nominal_pose + np.concatenate([rng.uniform(-40, 40, (N, 3)),
                                           np.radians(rng.uniform(-15, 15, (N, 3)))], axis=1)
    g, (lo, hi) = gen._ik_geometry, gen.stroke
    outs = [(np.empty((N, 6)), np.empty((N, 6), np.int8), np.empty(N, np.int8))
            for _ in range(3)]
    names = {0: "copy", 1: "+sincos", 2: "+matrix", 3: "legs", 4: "pipeline",
             5: "pipeline, matrix in legs", 6: "pipeline, legs contracted"}
    fns = {"floor": lambda: _floor(X, *outs[0])}
    for mode, name in names.items():
        o = outs[1] if mode == 5 else outs[2] if mode == 6 else outs[0]
        fns[name] = lambda mode=mode, o=o: _drive(X, g, lo, hi, *o, mode)   # noqa: B008
    a = np.random.default_rng(1).uniform(1, 2, 4096)
    b = np.empty_like(a)
    for mode, name in enumerate(("x/y", "sqrt", "x/sqrt(x)", "16-op polynomial")):
        fns[name] = lambda mode=mode: [_divider(a, b, mode) for _ in range(200)]  # noqa: B008
    for fn in fns.values():                      # compiles or loads every kernel
        fn()
    misses = sum(sum(f.stats.cache_misses.values()) for f in (_floor, _drive, _divider))
    if misses and os.environ.get("PKMLAB_BENCH_RERUN") != "1":
        print(f"compiled {misses} kernel(s); measuring in a fresh process that loads them",
              flush=True)
        os.execve(sys.executable, [sys.executable, *sys.argv],
                  dict(os.environ, PKMLAB_BENCH_RERUN="1"))
    print(f"one thread, CPU time, least of 9; load average {os.getloadavg()}")
    t = cpu_best(fns, 9)
    for key, v in t.items():
        if key in ("x/y", "sqrt", "x/sqrt(x)", "16-op polynomial"):
            print(f"{key:28s} {v / (200 * len(a)) * 1e9:6.3f} ns per element")
        else:
            print(f"{key:28s} {v * 1e3:6.2f} ms  {v / t['floor']:5.2f}x the floor")
    q0, s0, r0 = outs[0]
    for name, (q1, s1, r1) in (("matrix in legs", outs[1]), ("legs contracted", outs[2])):
        fin = np.isfinite(q0)
        print(f"{name}: statuses identical {np.array_equal(s0, s1) and np.array_equal(r0, r1)},"
              f" q bit-identical on {np.mean(q1[fin] == q0[fin]):.4%} of finite legs, largest "
              f"difference {np.max(np.abs(q1[fin] - q0[fin])):.3g} rad")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
