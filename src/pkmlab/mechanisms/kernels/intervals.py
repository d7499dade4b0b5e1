"""Numba helpers for small sorted sets of disjoint closed intervals.

A set is stored in two float arrays ``lo[:n], hi[:n]`` (sorted, disjoint, ``lo <= hi``) of
capacity ``K``; the workspace engine keeps one per (x, y) column. A union that would need more
than ``K`` pieces returns ``K + 1`` (overflow) and keeps the first ``K``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["union_merge", "label_pieces"]

@njit(cache=True)
def union_merge(lo, hi, n, out_lo, out_hi, K):
    """Union of ``n`` intervals (any order, may overlap) into sorted disjoint ``out``.

    Returns the piece count (``K + 1`` on overflow).
    """
    if n == 0:
        return 0
    order = np.argsort(lo[:n])
    m = 0
    cur_lo, cur_hi = lo[order[0]], hi[order[0]]
    for t in range(1, n):
        j = order[t]
        if lo[j] <= cur_hi:
            if hi[j] > cur_hi:
                cur_hi = hi[j]
        else:
            if m == K:
                return K + 1
            out_lo[m], out_hi[m] = cur_lo, cur_hi
            m += 1
            cur_lo, cur_hi = lo[j], hi[j]
    if m == K:
        return K + 1
    out_lo[m], out_hi[m] = cur_lo, cur_hi
    return m + 1


@njit(cache=True)
def _find(parent, a):
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@njit(cache=True)
def label_pieces(lo, hi, tol):
    """Connected components of column interval pieces ``(nx, ny, K)``.

    Two pieces are connected when their columns are 8-neighbours in x-y and their z
    intervals overlap or lie within ``tol`` of each other (a thin, steep region moves by more
    than its own height from one column to the next). Returns ``(labels, n)``: ``labels
    (nx, ny, K)`` in ``0..n-1`` and -1 for empty slots.
    """
    nx, ny, K = lo.shape
    parent = np.arange(nx * ny * K)
    for ix in range(nx):
        for iy in range(ny):
            for k in range(K):
                if not lo[ix, iy, k] <= hi[ix, iy, k]:
                    continue
                a = (ix * ny + iy) * K + k
                for d in range(4):
                    jx = ix + (1, 0, 1, 1)[d]
                    jy = iy + (0, 1, 1, -1)[d]
                    if jx >= nx or jy < 0 or jy >= ny:
                        continue
                    for kk in range(K):
                        l2, h2 = lo[jx, jy, kk], hi[jx, jy, kk]
                        if not l2 <= h2:
                            continue
                        if max(lo[ix, iy, k], l2) <= min(hi[ix, iy, k], h2) + tol:
                            ra = _find(parent, a)
                            rb = _find(parent, (jx * ny + jy) * K + kk)
                            if ra != rb:
                                parent[max(ra, rb)] = min(ra, rb)
    labels = np.full((nx, ny, K), -1, dtype=np.int64)
    remap = np.full(nx * ny * K, -1, dtype=np.int64)
    n = 0
    for ix in range(nx):
        for iy in range(ny):
            for k in range(K):
                if lo[ix, iy, k] <= hi[ix, iy, k]:
                    r = _find(parent, (ix * ny + iy) * K + k)
                    if remap[r] < 0:
                        remap[r] = n
                        n += 1
                    labels[ix, iy, k] = remap[r]
    return labels, n
