"""Exact pruning of the dexterous ("all") column kernel for radial families.

For families whose per-leg column interval is radial (``Mechanism.column_radial``: along the
column ``(x, y)`` leg ``i`` at orientation ``m`` admits ``[a(d), b(d)]`` with ``d`` the
horizontal distance from the leg's column axis ``-w_xy``, ``a``, ``b`` and ``ok`` monotone in
``d``), the interval of every column of a rectangular *tile* of columns is bounded from the
nearest and farthest distance of the tile to the axis: ``a`` lies in ``[amin, amax]`` (the
values at the two ends), and so does ``b``; ``ok`` holds on the whole tile if it holds at the
farthest distance and nowhere if it fails at the nearest.

A tile's columns keep ``[max a, min b]`` over every leg × orientation. With
``La = max amin`` and ``Ub = min bmax`` over the leg × orientation pairs:

* the tile is **rejected** before any column is looked at when a pair fails ``ok`` at the
  nearest distance, or when ``La > Ub`` (every column then has ``max a >= La > Ub >= min b``);
* a pair with ``amax < La`` can never be a column's ``max a`` (another pair is at least
  ``La`` on every column), nor one with ``bmin > Ub`` its ``min b``; unless it may fail ``ok``
  inside the tile, it is **pruned**: only the remaining pairs are evaluated column by column.

The kept pairs give each column the same maximum and minimum as all pairs (a max or min over a
subset that contains the extreme element is that element, bit for bit), so the intervals are
identical to :func:`.column_kernels.make_column_kernel`'s ``columns_all`` (tested on the 6-PSU
and the 6-UPS). The distances are padded by :data:`DPAD` and the comparisons by :data:`SLACK`,
so that rounding in the distance of a column cannot make a pruned pair the extreme one (the leg
functions are monotone in the computed distance under rounding, too: squares, differences and
``sqrt`` are). Top-level tiles of :data:`TILE` × :data:`TILE` columns are visited in parallel;
each is split in four, depth first, down to :data:`LEAF` × :data:`LEAF`, every level bounding
only the pairs its parent kept; at a leaf the kept pairs run over its columns, the hardest
(most tilted) orientations first as in ``columns_all``. """

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import prange
from numba import types as nt
from numba.extending import register_jitable

from ...runtime.jit import cached_kernel
from . import columns as column_kernels

__all__ = ["MIN_COLUMNS", "TILE", "make_tiled_all", "tile_distances"]

#: columns per side of a top-level tile; each tile is split in four down to LEAF
TILE = 32
#: columns per side of the tiles evaluated column by column
LEAF = 4
#: tile sizes from TILE down to LEAF
LEVELS = 4
#: footprints of at least this many columns use the tiles (a small footprint has too few
#: tiles to share among threads; the plain kernel's early exits serve it as well)
MIN_COLUMNS = 20_000
#: padding of the tile's distance range (mm)
DPAD = 1e-6
#: slack of the pruning comparisons (mm)
SLACK = 1e-6


@register_jitable(inline="always")
def tile_distances(x0, x1, y0, y1, cx, cy):
    """Nearest and farthest distance of the rectangle ``[x0, x1] × [y0, y1]`` from the point
    ``(cx, cy)`` (a leg's column axis), padded outward by :data:`DPAD` against rounding.

    A plain function registered for numba, not an ``njit`` dispatcher: the continuous search's
    kernels pickle their closures (by value, globals included) into numba's cache key, and a
    dispatcher pickles differently in every process, so its cache would never hit."""
    gx = max(max(x0 - cx, cx - x1), 0.0)
    gy = max(max(y0 - cy, cy - y1), 0.0)
    fx = max(abs(x0 - cx), abs(x1 - cx))
    fy = max(abs(y0 - cy), abs(y1 - cy))
    return (max(math.sqrt(gx * gx + gy * gy) - DPAD, 0.0),
            math.sqrt(fx * fx + fy * fy) + DPAD)


@cache
def make_tiled_all(leg):
    """Parallel ``columns_all(xs, ys, W (M, 6, 3), P (6, 3), out_lo, out_hi (nx, ny, 1))`` for
    a radial per-leg interval ``leg``, with the tile pruning of the module notes; the same
    signature and results as :func:`.column_kernels.make_column_kernel` ``(leg, "all")``."""
    leg = column_kernels.inlined(leg)

    def tiled_all(xs, ys, W, P, out_lo, out_hi):
        nx, ny, M = xs.shape[0], ys.shape[0], W.shape[0]
        tx, ty = (nx + TILE - 1) // TILE, (ny + TILE - 1) // TILE
        MI = 6 * M
        for t in prange(tx * ty):
            cand = np.empty((LEVELS, MI), dtype=np.int64)
            ncand = np.zeros(LEVELS, dtype=np.int64)
            amax = np.empty(MI)
            bmin = np.empty(MI)
            okall = np.empty(MI, dtype=np.bool_)
            lo = np.empty(LEAF * LEAF)
            hi = np.empty(LEAF * LEAF)
            st_l = np.empty(4 * LEVELS, dtype=np.int64)
            st_x = np.empty(4 * LEVELS, dtype=np.int64)
            st_y = np.empty(4 * LEVELS, dtype=np.int64)
            st_l[0], st_x[0], st_y[0] = 0, (t // ty) * TILE, (t % ty) * TILE
            sp = 1
            while sp > 0:
                sp -= 1
                lev, ix0, iy0 = st_l[sp], st_x[sp], st_y[sp]
                side = TILE >> lev
                mx, my = min(side, nx - ix0), min(side, ny - iy0)
                if mx <= 0 or my <= 0:
                    continue
                x0, x1, y0, y1 = xs[ix0], xs[ix0 + mx - 1], ys[iy0], ys[iy0 + my - 1]
                nsrc = MI if lev == 0 else ncand[lev - 1]
                La, Ub = -np.inf, np.inf
                dead = False
                for c in range(nsrc):
                    k = c if lev == 0 else cand[lev - 1, c]
                    m, i = k // 6, k % 6
                    wx, wy, wz = W[m, i, 0], W[m, i, 1], W[m, i, 2]
                    dmin, dmax = tile_distances(x0, x1, y0, y1, -wx, -wy)
                    a1, b1, ok1 = leg(dmin - wx, -wy, wx, wy, wz, P[i, 0], P[i, 1], P[i, 2])
                    a2, b2, ok2 = leg(dmax - wx, -wy, wx, wy, wz, P[i, 0], P[i, 1], P[i, 2])
                    if not ok1:
                        dead = True
                        break
                    La = max(La, min(a1, a2))
                    Ub = min(Ub, max(b1, b2))
                    amax[c] = max(a1, a2)
                    bmin[c] = min(b1, b2)
                    okall[c] = ok2
                if dead or La > Ub + SLACK:
                    for jx in range(mx):
                        for jy in range(my):
                            out_lo[ix0 + jx, iy0 + jy, 0] = np.inf
                            out_hi[ix0 + jx, iy0 + jy, 0] = -np.inf
                    continue
                n = 0
                for c in range(nsrc):
                    if okall[c] and amax[c] < La - SLACK and bmin[c] > Ub + SLACK:
                        continue
                    cand[lev, n] = c if lev == 0 else cand[lev - 1, c]
                    n += 1
                ncand[lev] = n
                if lev + 1 < LEVELS:
                    half = side >> 1
                    for q in range(4):
                        st_l[sp] = lev + 1
                        st_x[sp] = ix0 + (q // 2) * half
                        st_y[sp] = iy0 + (q % 2) * half
                        sp += 1
                    continue
                # a leaf: the kept pairs, column by column
                for j in range(LEAF * LEAF):
                    lo[j] = -np.inf
                    hi[j] = np.inf
                for c in range(n):
                    k = cand[lev, c]
                    m, i = k // 6, k % 6
                    wx, wy, wz = W[m, i, 0], W[m, i, 1], W[m, i, 2]
                    p0, p1, p2 = P[i, 0], P[i, 1], P[i, 2]
                    for jx in range(mx):
                        x = xs[ix0 + jx]
                        for jy in range(my):
                            a, b, ok = leg(x, ys[iy0 + jy], wx, wy, wz, p0, p1, p2)
                            j = jx * LEAF + jy
                            lj = lo[j]
                            hj = hi[j]
                            lo[j] = (a if a > lj else lj) if ok else np.inf
                            hi[j] = b if b < hj else hj
                for jx in range(mx):
                    for jy in range(my):
                        j = jx * LEAF + jy
                        if lo[j] <= hi[j]:
                            out_lo[ix0 + jx, iy0 + jy, 0] = lo[j]
                            out_hi[ix0 + jx, iy0 + jy, 0] = hi[j]
                        else:
                            out_lo[ix0 + jx, iy0 + jy, 0] = np.inf
                            out_hi[ix0 + jx, iy0 + jy, 0] = -np.inf

    f1, f2, f3 = nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
    return cached_kernel(tiled_all, nt.void(f1, f1, f3, f2, f3, f3), parallel=True)
