"""The branch and bound over continuous positions of :mod:`.search`, with exact pair pruning.

:func:`branch_core` builds, for a radial ``column_leg``, the jitable column margin, the tile
bound and the branch and bound that :mod:`.search` states (its module notes: margin
``f = min b - max a`` over leg × orientation *pairs*, the tile bound from each pair's interval
at the tile's nearest and farthest distance from the leg's axis, decisions and pruning
thresholds).

**Pair pruning** (issue 28, session 4). A tile's bound ``Ub - La`` has ``La = max amin`` and
``Ub = min bmax`` over the pairs (``amin``, ``amax``: the pair's lower end at the tile's two
distances, ``a`` monotone in the distance; ``b`` likewise). A pair with ``amax < La - SLACK``,
``bmin > Ub + SLACK`` that holds ``ok`` at the tile's farthest distance is never the maximum
``a`` nor the minimum ``b`` anywhere in the tile, nor in any tile inside it (the pair's range
only shrinks there, and ``La`` only grows, ``Ub`` only falls), and it cannot fail ``ok`` there:
the tile's *kept list* leaves it out. A split tile bounds its four children and evaluates
their centres over its kept list only. The maxima and minima over a list that holds the
extreme element are that element, bit for bit, so every bound that decides something and
every centre margin that can change the best are the values the full evaluation gives, and the
branch and bound visits the same tiles and returns the same status, best margin, point and z
interval (``out[BB_UB]``, a bound of the discarded tiles, may differ below the thresholds).
``SLACK`` covers the centre's distance being computed along another path than the tile's
(padded by ``DPAD``): both are ~1e-13 mm from the exact value, far below ``SLACK``. The same
argument prunes the column kernel's pairs (:mod:`.tiles`).

The top-level grid is evaluated exactly as before (all pairs, hardest orientations first), so
its bounds (sorted to order the search) are unchanged; a tile bounded in full there gets its
kept list. Kept lists live in one buffer used as a stack alongside the tile stack: a split
tile's children write theirs above the buffer end recorded with the tile, so the buffer holds
the lists of the tiles on the stack only (at most ~4 per level of depth).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np

from ...runtime.jit import identity, jitable
from . import columns as column_kernels
from .tiles import SLACK, tile_distances

__all__ = ["branch_core", "UB_TOL", "STACK", "BB_STATUS", "BB_F", "BB_X", "BB_Y", "BB_ZLO",
           "BB_ZHI", "BB_UB", "BB_TILES", "FEASIBLE", "EMPTY", "UNDECIDED"]

#: a tile's upper bound must be below -UB_TOL (mm) to count as empty
UB_TOL = 1e-9
#: initial capacity of the tile and cell stacks (grown when needed)
STACK = 4096

# out[] of the branch and bound
BB_STATUS, BB_F, BB_X, BB_Y, BB_ZLO, BB_ZHI, BB_UB, BB_TILES = range(8)
FEASIBLE, EMPTY, UNDECIDED = 1.0, 0.0, -1.0
# columns of the tile stack: x0, x1, y0, y1, bound, kept list start, its length, buffer end
_COLS = 8


@cache
def branch_core(leg):
    """The jitable margin, tile bounds and branch and bound for ``leg`` (module notes)."""
    leg = column_kernels.inlined(leg)

    def margin(x, y, W, M, P, thr, order):
        """``(f, max a, min b)`` of the column (x, y) over the first M orientations of W,
        exact when ``f >= thr``; otherwise some value below ``thr`` (the pairs are visited in
        ``order`` and stop once the running margin is below it; the orientation that stopped
        them moves to the front of ``order``)."""
        lo, hi = -np.inf, np.inf
        for k in range(M):
            m = order[k]
            for i in range(6):
                a, b, ok = leg(x, y, W[m, i, 0], W[m, i, 1], W[m, i, 2],
                               P[i, 0], P[i, 1], P[i, 2])
                if not ok:
                    order[k], order[0] = order[0], m
                    return -np.inf, np.inf, -np.inf
                lo = max(lo, a)
                hi = min(hi, b)
            if hi - lo < thr:
                order[k], order[0] = order[0], m
                return hi - lo, lo, hi
        return hi - lo, lo, hi

    def margin_list(x, y, W, P, L, l0, nl, thr):
        """:func:`margin` over the pairs ``L[l0:l0 + nl]`` (pair ``6·m + i``: orientation m,
        leg i); the same value when the list holds the extreme pairs of (x, y)."""
        lo, hi = -np.inf, np.inf
        for t in range(nl):
            p = L[l0 + t]
            m = p // 6
            i = p - 6 * m
            a, b, ok = leg(x, y, W[m, i, 0], W[m, i, 1], W[m, i, 2], P[i, 0], P[i, 1], P[i, 2])
            if not ok:
                return -np.inf, np.inf, -np.inf
            lo = max(lo, a)
            hi = min(hi, b)
            if hi - lo < thr:
                return hi - lo, lo, hi
        return hi - lo, lo, hi

    def pair_bound(x0, x1, y0, y1, W, m, i, P):
        """The pair's ends at the tile's nearest and farthest distance from the leg's axis:
        ``(min a, max a, min b, max b, ok near, ok far)``."""
        wx, wy, wz = W[m, i, 0], W[m, i, 1], W[m, i, 2]
        dmin, dmax = tile_distances(x0, x1, y0, y1, -wx, -wy)
        a1, b1, ok1 = leg(dmin - wx, -wy, wx, wy, wz, P[i, 0], P[i, 1], P[i, 2])
        if not ok1:
            return 0.0, 0.0, 0.0, 0.0, False, False
        a2, b2, ok2 = leg(dmax - wx, -wy, wx, wy, wz, P[i, 0], P[i, 1], P[i, 2])
        return min(a1, a2), max(a1, a2), min(b1, b2), max(b1, b2), True, ok2

    def tile_ub(x0, x1, y0, y1, W, M, P, thr, order, AX, BN, OK, PID):
        """Upper bound of the margin over the continuous tile, all pairs, orientations in
        ``order``; once it is below ``thr`` it may stop early (the value returned is still an
        upper bound; ``order`` as in margin). Returns ``(bound, La, Ub, full)``; when ``full``
        (no early stop) pair ``PID[t]``'s max a, min b and ok at the far distance are in
        ``AX[t]``, ``BN[t]``, ``OK[t]`` for :func:`write_kept`."""
        La, Ub = -np.inf, np.inf
        t = 0
        for k in range(M):
            m = order[k]
            for i in range(6):
                amin, amax, bmin, bmax, ok1, ok2 = pair_bound(x0, x1, y0, y1, W, m, i, P)
                if not ok1:
                    order[k], order[0] = order[0], m
                    return -np.inf, La, Ub, False
                La = max(La, amin)
                Ub = min(Ub, bmax)
                AX[t], BN[t], OK[t], PID[t] = amax, bmin, ok2, 6 * m + i
                t += 1
            if Ub - La < thr:
                order[k], order[0] = order[0], m
                return Ub - La, La, Ub, False
        return Ub - La, La, Ub, True

    def tile_ub_list(x0, x1, y0, y1, W, P, L, l0, nl, thr, AX, BN, OK, PID):
        """:func:`tile_ub` over the pairs ``L[l0:l0 + nl]`` (a kept list of a tile holding
        this one); the pair that stops it early moves to the list's front."""
        La, Ub = -np.inf, np.inf
        for t in range(nl):
            p = L[l0 + t]
            m = p // 6
            i = p - 6 * m
            amin, amax, bmin, bmax, ok1, ok2 = pair_bound(x0, x1, y0, y1, W, m, i, P)
            if not ok1:
                L[l0 + t], L[l0] = L[l0], p
                return -np.inf, La, Ub, False
            La = max(La, amin)
            Ub = min(Ub, bmax)
            AX[t], BN[t], OK[t], PID[t] = amax, bmin, ok2, p
            if Ub - La < thr:
                L[l0 + t], L[l0] = L[l0], p
                return Ub - La, La, Ub, False
        return Ub - La, La, Ub, True

    def write_kept(n, La, Ub, AX, BN, OK, PID, L, l0):
        """The kept list of a tile bounded in full over ``n`` pairs, written to ``L[l0:]``
        (module notes); returns its length (>= 1: the pair that gives La is kept)."""
        k = 0
        lim_a, lim_b = La - SLACK, Ub + SLACK
        for t in range(n):
            if OK[t] and AX[t] < lim_a and BN[t] > lim_b:
                continue
            L[l0 + k] = PID[t]
            k += 1
        return k

    def exit_below(decide, best, eps):
        """Where a tile bound may stop early: below the pruning threshold, and in the
        non-deciding mode while no witness is known also below -UB_TOL, so that a status
        EMPTY (every bound below -UB_TOL) stays exact."""
        if decide:
            return -UB_TOL
        return best + eps if best >= 0.0 else min(best + eps, -UB_TOL)

    def grown(A, need):
        """``A`` with room for ``need`` rows (doubled, contents kept)."""
        if need <= A.shape[0]:
            return A
        B = np.empty((max(need, 2 * A.shape[0]),) + A.shape[1:], A.dtype)
        B[:A.shape[0]] = A
        return B

    def branch_bound(W, M, P, box, h0, min_size, eps, decide, out):
        """Branch and bound of the margin over continuous (x, y) in ``box`` (x0, x1, y0, y1);
        see :mod:`.search`'s notes and this module's (pair pruning). Writes ``out[BB_*]``."""
        nx = max(1, int(math.ceil((box[1] - box[0]) / h0)))
        ny = max(1, int(math.ceil((box[3] - box[2]) / h0)))
        npairs = 6 * M
        cap = nx * ny + STACK
        T = np.empty((cap, _COLS))
        AX, BN = np.empty(npairs), np.empty(npairs)
        OK, PID = np.empty(npairs, np.bool_), np.empty(npairs, np.int64)
        # kept lists; the first npairs entries: every pair (for a tile bounded only in part)
        L = np.empty(npairs + 16 * npairs, np.int64)
        for t in range(npairs):
            L[t] = t
        top = npairs
        best, bx, by, bzl, bzh = -np.inf, np.nan, np.nan, np.nan, np.nan
        gub = -np.inf                 # bound of the discarded tiles
        n = 0
        tiles = 0
        # hardest orientations first: the one that last ended a bound is tried first; early
        # exits below the pruning threshold never change a decision (exit_below)
        first = np.arange(M)
        for i in range(nx):
            for j in range(ny):
                x0 = box[0] + i * h0
                y0 = box[2] + j * h0
                x1 = min(x0 + h0, box[1])
                y1 = min(y0 + h0, box[3])
                ub, La, Ub, full = tile_ub(x0, x1, y0, y1, W, M, P,
                                           exit_below(decide, best, eps), first, AX, BN, OK, PID)
                tiles += 1
                if ub < -UB_TOL:
                    gub = max(gub, ub)
                    continue
                f, zl, zh = margin(0.5 * (x0 + x1), 0.5 * (y0 + y1), W, M, P, best, first)
                if f > best:
                    best, bx, by, bzl, bzh = f, 0.5 * (x0 + x1), 0.5 * (y0 + y1), zl, zh
                l0, nl = 0, npairs
                if full:
                    L = grown(L, top + npairs)
                    l0, nl = top, write_kept(npairs, La, Ub, AX, BN, OK, PID, L, top)
                    top += nl
                T[n, 0], T[n, 1], T[n, 2], T[n, 3], T[n, 4] = x0, x1, y0, y1, ub
                T[n, 5], T[n, 6] = l0, nl
                n += 1
        status = UNDECIDED
        if decide and best >= 0.0:
            status = FEASIBLE
            n = 0
        # the most promising tiles last on the stack (popped first)
        order = np.argsort(T[:n, 4])
        S = np.empty((cap, _COLS))
        for k in range(n):
            for c in range(_COLS - 1):
                S[k, c] = T[order[k], c]
            S[k, _COLS - 1] = top
        sp = n
        undecided = 0
        while sp > 0:
            sp -= 1
            x0, x1, y0, y1, ub = S[sp, 0], S[sp, 1], S[sp, 2], S[sp, 3], S[sp, 4]
            l0, nl, base = int(S[sp, 5]), int(S[sp, 6]), int(S[sp, 7])
            thr = -UB_TOL if decide else best + eps
            if ub < thr:
                gub = max(gub, ub)
                continue
            if max(x1 - x0, y1 - y0) <= min_size:
                gub = max(gub, ub)
                undecided += 1
                continue
            xm, ym = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
            S = grown(S, sp + 4)
            L = grown(L, base + 4 * nl)
            for q in range(4):
                cx0 = x0 if q // 2 == 0 else xm
                cx1 = xm if q // 2 == 0 else x1
                cy0 = y0 if q % 2 == 0 else ym
                cy1 = ym if q % 2 == 0 else y1
                v, La, Ub, full = tile_ub_list(cx0, cx1, cy0, cy1, W, P, L, l0, nl,
                                               exit_below(decide, best, eps), AX, BN, OK, PID)
                cub = min(ub, v)
                tiles += 1
                cl0, cnl = l0, nl
                if full:
                    cl0, cnl = base, write_kept(nl, La, Ub, AX, BN, OK, PID, L, base)
                    base += cnl
                f, zl, zh = margin_list(0.5 * (cx0 + cx1), 0.5 * (cy0 + cy1), W, P, L, cl0,
                                        cnl, best)
                if f > best:
                    best, bx, by, bzl, bzh = f, 0.5 * (cx0 + cx1), 0.5 * (cy0 + cy1), zl, zh
                S[sp, 0], S[sp, 1], S[sp, 2], S[sp, 3], S[sp, 4] = cx0, cx1, cy0, cy1, cub
                S[sp, 5], S[sp, 6], S[sp, 7] = cl0, cnl, base
                sp += 1
            if decide and best >= 0.0:
                status = FEASIBLE
                break
        if status != FEASIBLE and decide:
            status = EMPTY if undecided == 0 and best < 0.0 else UNDECIDED
        if not decide:
            status = FEASIBLE if best >= 0.0 else (EMPTY if gub < -UB_TOL else UNDECIDED)
        out[BB_STATUS], out[BB_F], out[BB_X], out[BB_Y] = status, best, bx, by
        out[BB_ZLO], out[BB_ZHI], out[BB_UB], out[BB_TILES] = bzl, bzh, max(gub, best), tiles

    raw = (margin, margin_list, pair_bound, tile_ub, tile_ub_list, write_kept, exit_below,
           grown, branch_bound)
    ident = identity(*raw, extra=("search-branch",))
    # the functions call each other through closure cells: rebinding the names makes those
    # cells hold the jitable versions
    margin = jitable(margin, ident, error_model="numpy")
    margin_list = jitable(margin_list, ident, error_model="numpy")
    pair_bound = jitable(pair_bound, ident, error_model="numpy", inline="always")
    tile_ub = jitable(tile_ub, ident, error_model="numpy")
    tile_ub_list = jitable(tile_ub_list, ident, error_model="numpy")
    write_kept = jitable(write_kept, ident, error_model="numpy")
    exit_below = jitable(exit_below, ident, error_model="numpy")
    grown = jitable(grown, ident, error_model="numpy")
    branch_bound = jitable(branch_bound, ident, error_model="numpy")
    return {"margin": margin, "margin_list": margin_list, "pair_bound": pair_bound,
            "tile_ub": tile_ub, "tile_ub_list": tile_ub_list, "write_kept": write_kept,
            "exit_below": exit_below, "grown": grown, "branch_bound": branch_bound}
