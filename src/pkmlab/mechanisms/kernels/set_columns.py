"""Column drivers for legs whose feasible z set on a column is a union of intervals.

The single-interval drivers of :mod:`._kernels` (``column_leg -> (a, b, ok)``) suit legs
whose stroke window maps to one z interval (6-PSU, 6-UPS). A crank leg's set is a union of up
to :data:`._crank.PIECES` intervals, so its family supplies a *set leg*
``leg(x, y, wx, wy, wz, p, zlo, zhi, out_lo, out_hi) -> n`` (``p`` the leg's parameter row,
the pieces within ``[zlo, zhi]`` written sorted to ``out_lo[:n], out_hi[:n]``, see
:func:`._crank.crank_column_leg`; the drivers pass the hull of the set they intersect with),
and these drivers intersect the sets over legs and orientations (``"all"``) or unite the
per-orientation intersections (``"any"``). Sets are kept sorted and disjoint with capacity
``K`` (the engine's slot count); a set that needs more pieces counts as an overflow and keeps
its first ``K``. Kernels are built by :func:`.._jit.cached_kernel` like every family kernel.
"""

from __future__ import annotations

from functools import cache

import numpy as np
from numba import prange
from numba import types as nt
from numba.extending import register_jitable

from ...runtime.jit import cached_kernel
from ..legs.crank import PIECES
from .columns import inlined
from .ik import carray
from .intervals import union_merge

__all__ = ["make_set_column_kernel", "set_column_intervals", "intersect_sets"]

_F1, _F2, _F3 = nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]


@register_jitable(inline="always")
def intersect_sets(alo, ahi, na, blo, bhi, nb, out_lo, out_hi, K):
    """Intersection of two sorted disjoint sets into ``out`` (capacity K):
    ``(count, overflowed)``."""
    i = 0
    j = 0
    n = 0
    over = False
    while i < na and j < nb:
        lo = alo[i] if alo[i] > blo[j] else blo[j]
        hi = ahi[i] if ahi[i] < bhi[j] else bhi[j]
        if lo <= hi:
            if n < K:
                out_lo[n] = lo
                out_hi[n] = hi
                n += 1
            else:
                over = True
        if ahi[i] < bhi[j]:
            i += 1
        else:
            j += 1
    return n, over


@cache
def make_set_column_kernel(leg, mode: str):
    """Parallel ``columns_all`` (``mode="all"``) or ``columns_any`` (``"any"``) for the set leg
    ``leg``; cached like :func:`.column_kernels.make_column_kernel`.

    ``columns_all(xs (nx,), ys (ny,), W (M, L, 3), P (L, np), out_lo, out_hi (nx, ny, K),
    count (nx, ny) int64)``; ``columns_any(xs, ys, W, P, allowed (nx, ny, M) bool, out_lo,
    out_hi, count)``. ``count`` is the number of pieces, ``K + 1`` on overflow.
    """
    leg = inlined(leg)

    def columns_all(xs, ys, W, P, out_lo, out_hi, count):
        """Intersection over orientations ``W (M, L, 3)`` and the L legs, column by column; a column
        stops at its first empty intersection (most tilted orientations come first)."""
        nx, ny, M, K = xs.shape[0], ys.shape[0], W.shape[0], out_lo.shape[2]
        for ix in prange(nx):
            slo = np.empty(K)
            shi = np.empty(K)
            tlo = np.empty(K)
            thi = np.empty(K)
            llo = np.empty(PIECES)
            lhi = np.empty(PIECES)
            for iy in range(ny):
                slo[0] = -np.inf
                shi[0] = np.inf
                n = 1
                over = False
                for m in range(M):
                    for i in range(W.shape[1]):
                        nl = leg(xs[ix], ys[iy], W[m, i, 0], W[m, i, 1], W[m, i, 2], P[i],
                                 slo[0], shi[n - 1], llo, lhi)
                        n, o = intersect_sets(slo, shi, n, llo, lhi, nl, tlo, thi, K)
                        over = over or o
                        slo, tlo = tlo, slo
                        shi, thi = thi, shi
                        if n == 0:
                            break
                    if n == 0:
                        break
                for k in range(K):
                    out_lo[ix, iy, k] = slo[k] if k < n else np.inf
                    out_hi[ix, iy, k] = shi[k] if k < n else -np.inf
                count[ix, iy] = K + 1 if over else n

    def columns_any(xs, ys, W, P, allowed, out_lo, out_hi, count):
        """Union over the orientations that ``allowed (nx, ny, M)`` permits."""
        nx, ny, M, K = xs.shape[0], ys.shape[0], W.shape[0], out_lo.shape[2]
        for ix in prange(nx):
            blo = np.empty(M * K)
            bhi = np.empty(M * K)
            slo = np.empty(K)
            shi = np.empty(K)
            tlo = np.empty(K)
            thi = np.empty(K)
            llo = np.empty(PIECES)
            lhi = np.empty(PIECES)
            for iy in range(ny):
                nb = 0
                over = False
                for m in range(M):
                    if not allowed[ix, iy, m]:
                        continue
                    slo[0] = -np.inf
                    shi[0] = np.inf
                    n = 1
                    for i in range(W.shape[1]):
                        nl = leg(xs[ix], ys[iy], W[m, i, 0], W[m, i, 1], W[m, i, 2], P[i],
                                 slo[0], shi[n - 1], llo, lhi)
                        n, o = intersect_sets(slo, shi, n, llo, lhi, nl, tlo, thi, K)
                        over = over or o
                        slo, tlo = tlo, slo
                        shi, thi = thi, shi
                        if n == 0:
                            break
                    for k in range(n):
                        blo[nb] = slo[k]
                        bhi[nb] = shi[k]
                        nb += 1
                for k in range(K):
                    out_lo[ix, iy, k] = np.inf
                    out_hi[ix, iy, k] = -np.inf
                c = union_merge(blo, bhi, nb, out_lo[ix, iy], out_hi[ix, iy], K)
                count[ix, iy] = K + 1 if over else c

    if mode == "all":
        return cached_kernel(columns_all, nt.void(_F1, _F1, _F3, _F2, _F3, _F3,
                                                  nt.int64[:, ::1]), parallel=True)
    if mode == "any":
        return cached_kernel(columns_any, nt.void(_F1, _F1, _F3, _F2, nt.boolean[:, :, ::1],
                                                  _F3, _F3, nt.int64[:, ::1]), parallel=True)
    raise ValueError(f"mode must be 'all' or 'any', got {mode!r}")


def set_column_intervals(leg, W, P, xs, ys, R, mode, allowed=None, K=8):
    """``Mechanism.column_intervals`` for a family with a set leg: ``(lo, hi, overflow)``,
    ``lo, hi (nx, ny, K)`` sorted disjoint pieces (empty slots ``inf, -inf``).

    ``W (M, L, 3)`` are the L legs' offsets of the rotations ``R (M, 3, 3)``, ``P`` the legs'
    parameter rows; ``mode`` and ``allowed`` as in :meth:`.base.Mechanism.column_intervals`.
    """
    xs, ys, P = carray(xs), carray(ys), carray(P)
    nx, ny = len(xs), len(ys)
    lo, hi = np.empty((nx, ny, K)), np.empty((nx, ny, K))
    count = np.empty((nx, ny), dtype=np.int64)
    if mode == "all":
        if allowed is not None:
            raise ValueError("mode 'all' takes no orientation mask; mask the columns")
        # Most tilted orientations first: dead columns then die after a few of them.
        W = W[np.argsort(-np.linalg.norm(R - np.eye(3), axis=(1, 2)), kind="stable")]
        make_set_column_kernel(leg, "all")(xs, ys, carray(W), P, lo, hi, count)
    else:
        if allowed is None:
            allowed = np.ones((nx, ny, len(R)), dtype=np.bool_)
        make_set_column_kernel(leg, "any")(xs, ys, carray(W), P, carray(allowed, np.bool_),
                                           lo, hi, count)
    return lo, hi, int(np.sum(count > K))
