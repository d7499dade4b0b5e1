"""Numba column kernels of the workspace engine, shared by every family with exact columns.

A family with exact column intervals supplies ``leg(x, y, wx, wy, wz, p0, p1, p2) -> (a, b,
ok)``: the z interval [a, b] in which leg i (offset w = R·u_i - b_i, parameters p = P[i]) is
within its stroke on the column (x, y), ``ok = False`` where the leg cannot reach the column at
all. :func:`make_column_kernel` intersects these intervals over legs and orientations
(``"all"``) or unites the per-orientation intersections (``"any"``); :func:`make_leg_eval`
evaluates ``leg`` over a batch of items. All are built and cached by
:func:`pkmlab.runtime.jit.cached_kernel`, as the inverse-kinematics drivers of :mod:`._kernels` are
(its notes on caching and invalidation hold here: a kernel's identity covers this module,
the family's ``leg`` and ``mechanisms/kernels/intervals.py``).
"""

from __future__ import annotations

from functools import cache

import numpy as np
from numba import prange
from numba import types as nt

from ...runtime.jit import cached_kernel, identity, jitable
from .ik import _F1, _F2, _F3, carray
from .intervals import union_merge

__all__ = ["make_column_kernel", "make_leg_eval", "inlined"]


@cache
def inlined(leg):
    """``leg`` (an ``njit`` dispatcher or a plain function) as a plain function that numba
    inlines, named after its identity. A closure must not hold a dispatcher itself: a dispatcher
    pickles differently in every process, and the pickled closure is part of numba's cache key,
    so the cache would never hit."""
    fn = getattr(leg, "py_func", leg)
    return jitable(fn, identity(fn, extra=("leg",)), inline="always")


@cache
def make_column_kernel(leg, mode: str):
    """Parallel driver ``columns_all`` (``mode="all"``) or ``columns_any`` (``"any"``) for the
    per-leg interval ``leg``, cached like the IK drivers (:func:`make_driver`).

    ``columns_all(xs (nx,), ys (ny,), W (M, 6, 3), P (6, 3), out_lo, out_hi (nx, ny, 1))``;
    ``columns_any(xs, ys, W, P, allowed (nx, ny, M) bool, out_lo, out_hi (nx, ny, K), count
    (nx, ny) int64)``. All arrays C-contiguous and writeable (:func:`carray`).
    """
    leg = inlined(leg)

    def columns_all(xs, ys, W, P, out_lo, out_hi):
        """Intersection over orientations ``W (M, 6, 3)`` and legs; rows vectorised along y.

        Rows shrink from both ends as columns die, and stop when none is left.
        """
        nx, ny, M = xs.shape[0], ys.shape[0], W.shape[0]
        for ix in prange(nx):
            x = xs[ix]
            lo = np.full(ny, -np.inf)
            hi = np.full(ny, np.inf)
            j0, j1 = 0, ny
            for m in range(M):
                for i in range(6):
                    wx, wy, wz = W[m, i, 0], W[m, i, 1], W[m, i, 2]
                    p0, p1, p2 = P[i, 0], P[i, 1], P[i, 2]
                    for j in range(j0, j1):
                        a, b, ok = leg(x, ys[j], wx, wy, wz, p0, p1, p2)
                        lj = lo[j]
                        hj = hi[j]
                        lo[j] = (a if a > lj else lj) if ok else np.inf
                        hi[j] = b if b < hj else hj
                while j0 < j1 and lo[j0] > hi[j0]:
                    j0 += 1
                while j1 > j0 and lo[j1 - 1] > hi[j1 - 1]:
                    j1 -= 1
                if j0 == j1:
                    break
            for j in range(ny):
                if j0 <= j < j1 and lo[j] <= hi[j]:
                    out_lo[ix, j, 0] = lo[j]
                    out_hi[ix, j, 0] = hi[j]
                else:
                    out_lo[ix, j, 0] = np.inf
                    out_hi[ix, j, 0] = -np.inf

    def columns_any(xs, ys, W, P, allowed, out_lo, out_hi, count):
        """Union over the orientations that ``allowed (nx, ny, M)`` permits."""
        nx, ny, M, K = xs.shape[0], ys.shape[0], W.shape[0], out_lo.shape[2]
        for ix in prange(nx):
            blo = np.empty(M)
            bhi = np.empty(M)
            for iy in range(ny):
                n = 0
                for m in range(M):
                    if not allowed[ix, iy, m]:
                        continue
                    lo, hi = -np.inf, np.inf
                    for i in range(6):
                        a, b, ok = leg(xs[ix], ys[iy], W[m, i, 0], W[m, i, 1], W[m, i, 2],
                                       P[i, 0], P[i, 1], P[i, 2])
                        if not ok:
                            lo, hi = np.inf, -np.inf
                            break
                        lo = max(lo, a)
                        hi = min(hi, b)
                    if lo <= hi:
                        blo[n] = lo
                        bhi[n] = hi
                        n += 1
                for k in range(K):
                    out_lo[ix, iy, k] = np.inf
                    out_hi[ix, iy, k] = -np.inf
                count[ix, iy] = union_merge(blo, bhi, n, out_lo[ix, iy], out_hi[ix, iy], K)

    if mode == "all":
        return cached_kernel(columns_all, nt.void(_F1, _F1, _F3, _F2, _F3, _F3), parallel=True)
    if mode == "any":
        return cached_kernel(columns_any, nt.void(_F1, _F1, _F3, _F2, nt.boolean[:, :, ::1],
                                                  _F3, _F3, nt.int64[:, ::1]), parallel=True)
    raise ValueError(f"mode must be 'all' or 'any', got {mode!r}")


@cache
def make_leg_eval(leg):
    """Vectorised ``leg`` over items: ``(x, y, W (n, 3), P (n, 3)) -> (a, b, ok)``, each (n,);
    cached like the IK drivers (:func:`make_driver`)."""
    leg = inlined(leg)

    def leg_eval(x, y, W, P, a, b, ok):
        for k in prange(x.shape[0]):
            a[k], b[k], ok[k] = leg(x[k], y[k], W[k, 0], W[k, 1], W[k, 2],
                                    P[k, 0], P[k, 1], P[k, 2])

    kernel = cached_kernel(leg_eval, nt.void(_F1, _F1, _F2, _F2, _F1, _F1, nt.boolean[::1]),
                           parallel=True)

    def run(x, y, W, P):
        n = len(x)
        a, b, ok = np.empty(n), np.empty(n), np.empty(n, dtype=np.bool_)
        kernel(carray(x), carray(y), carray(W), carray(P), a, b, ok)
        return a, b, ok

    run.kernel = kernel
    return run
