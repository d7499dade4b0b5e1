"""The capability search's branch and bound and driver *before* pair pruning (session 4 of
issue 28), kept verbatim from commit 55b26a5 as the reference that
``test_search_pruning.py`` compares the production kernels with, bit for bit.

The branch and bound is compiled as the production kernels are (cached, named after its
identity); the driver runs in Python (the same float operations) with the production
``sample_cuts`` and certification."""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import types as nt

from pkmlab.mechanisms.kernels import columns as column_kernels
from pkmlab.mechanisms.kernels import search as _search
from pkmlab.mechanisms.kernels.branch import (
    BB_F,
    BB_STATUS,
    BB_TILES,
    BB_UB,
    BB_X,
    BB_Y,
    BB_ZHI,
    BB_ZLO,
    EMPTY,
    FEASIBLE,
    STACK,
    UB_TOL,
    UNDECIDED,
)
from pkmlab.mechanisms.kernels.ik import _F1, _F2, _F3
from pkmlab.mechanisms.kernels.search import CUTS, CUTS_PER_LEVEL, LOCAL_MM, MAX_EPS
from pkmlab.mechanisms.kernels.tiles import tile_distances
from pkmlab.runtime.jit import cached_kernel, identity, jitable


@cache
def reference_bb(leg):
    """The previous branch and bound for ``leg``, njit: ``bb(W, M, P, box, h0, min_size,
    eps, decide, out)`` (:func:`pkmlab.mechanisms.kernels.search.make_branch_bound`'s
    arguments with the orientation count ``M``)."""
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

    def tile_ub(x0, x1, y0, y1, W, M, P, thr, order):
        """Upper bound of the margin over the continuous tile; once it is below ``thr`` it may
        stop early (the value returned is still an upper bound; ``order`` as in margin)."""
        La, Ub = -np.inf, np.inf
        for k in range(M):
            m = order[k]
            for i in range(6):
                wx, wy, wz = W[m, i, 0], W[m, i, 1], W[m, i, 2]
                dmin, dmax = tile_distances(x0, x1, y0, y1, -wx, -wy)
                a1, b1, ok1 = leg(dmin - wx, -wy, wx, wy, wz, P[i, 0], P[i, 1], P[i, 2])
                if not ok1:
                    order[k], order[0] = order[0], m
                    return -np.inf
                a2, b2, ok2 = leg(dmax - wx, -wy, wx, wy, wz, P[i, 0], P[i, 1], P[i, 2])
                La = max(La, min(a1, a2))
                Ub = min(Ub, max(b1, b2))
            if Ub - La < thr:
                order[k], order[0] = order[0], m
                return Ub - La
        return Ub - La

    def exit_below(decide, best, eps):
        """Where a tile bound may stop early: below the pruning threshold, and in the
        non-deciding mode while no witness is known also below -UB_TOL, so that a status
        EMPTY (every bound below -UB_TOL) stays exact."""
        if decide:
            return -UB_TOL
        return best + eps if best >= 0.0 else min(best + eps, -UB_TOL)

    def branch_bound(W, M, P, box, h0, min_size, eps, decide, out):
        """Branch and bound of the margin over continuous (x, y) in ``box`` (x0, x1, y0, y1);
        see the module notes. Writes ``out[BB_*]``."""
        nx = max(1, int(math.ceil((box[1] - box[0]) / h0)))
        ny = max(1, int(math.ceil((box[3] - box[2]) / h0)))
        cap = nx * ny + STACK
        T = np.empty((cap, 5))
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
                ub = tile_ub(x0, x1, y0, y1, W, M, P,
                             exit_below(decide, best, eps), first)
                tiles += 1
                if ub < -UB_TOL:
                    gub = max(gub, ub)
                    continue
                f, zl, zh = margin(0.5 * (x0 + x1), 0.5 * (y0 + y1), W, M, P, best, first)
                if f > best:
                    best, bx, by, bzl, bzh = f, 0.5 * (x0 + x1), 0.5 * (y0 + y1), zl, zh
                T[n, 0], T[n, 1], T[n, 2], T[n, 3], T[n, 4] = x0, x1, y0, y1, ub
                n += 1
        status = UNDECIDED
        if decide and best >= 0.0:
            status = FEASIBLE
            n = 0
        # the most promising tiles last on the stack (popped first)
        order = np.argsort(T[:n, 4])
        S = np.empty((cap, 5))
        for k in range(n):
            for c in range(5):
                S[k, c] = T[order[k], c]
        sp = n
        undecided = 0
        while sp > 0:
            sp -= 1
            x0, x1, y0, y1, ub = S[sp, 0], S[sp, 1], S[sp, 2], S[sp, 3], S[sp, 4]
            thr = -UB_TOL if decide else best + eps
            if ub < thr:
                gub = max(gub, ub)
                continue
            if max(x1 - x0, y1 - y0) <= min_size:
                gub = max(gub, ub)
                undecided += 1
                continue
            xm, ym = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
            if sp + 4 > S.shape[0]:
                S2 = np.empty((2 * S.shape[0], 5))
                S2[:sp] = S[:sp]
                S = S2
            for q in range(4):
                cx0 = x0 if q // 2 == 0 else xm
                cx1 = xm if q // 2 == 0 else x1
                cy0 = y0 if q % 2 == 0 else ym
                cy1 = ym if q % 2 == 0 else y1
                cub = min(ub, tile_ub(cx0, cx1, cy0, cy1, W, M, P,
                                      exit_below(decide, best, eps), first))
                tiles += 1
                f, zl, zh = margin(0.5 * (cx0 + cx1), 0.5 * (cy0 + cy1), W, M, P, best,
                                   first)
                if f > best:
                    best, bx, by, bzl, bzh = f, 0.5 * (cx0 + cx1), 0.5 * (cy0 + cy1), zl, zh
                S[sp, 0], S[sp, 1], S[sp, 2], S[sp, 3], S[sp, 4] = cx0, cx1, cy0, cy1, cub
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


    raw = (margin, tile_ub, exit_below, branch_bound)
    ident = identity(*raw, extra=("search-reference",))
    margin = jitable(margin, ident, error_model="numpy")
    tile_ub = jitable(tile_ub, ident, error_model="numpy")
    exit_below = jitable(exit_below, ident, error_model="numpy")
    branch_bound = jitable(branch_bound, ident, error_model="numpy")

    def bb(W, M, P, box, h0, min_size, eps, decide, out):
        branch_bound(W, M, P, box, h0, min_size, eps, decide, out)

    f8 = nt.float64
    return cached_kernel(bb, nt.void(_F3, nt.int64, _F2, _F1, f8, f8, f8, nt.boolean, _F1),
                         roots=raw)


@cache
def reference_capability(leg):
    """The previous capability search for ``leg``: ``cap`` with
    :func:`pkmlab.mechanisms.kernels.search.make_capability`'s arguments, the driver in
    Python (the same float operations), :func:`reference_bb`, the production ``sample_cuts``
    (which samples the box, then the cuts) and the production certification kernel."""
    core = _search._core(leg)
    smc = core["sample_cuts"]
    branch_bound = reference_bb(leg)
    cert = _search.make_certify(leg)

    def sample_cuts_k(U, Bp, e0, theta, n, extra, ne, X):
        smc(U, Bp, e0, theta, n, extra, ne, X)

    f8, i8 = nt.float64, nt.int64
    sample_cuts = cached_kernel(sample_cuts_k, nt.void(_F2, _F2, _F1, f8, i8, _F2, i8, _F3),
                                roots=(smc,), extra=("search-reference",))

    def sample(U, Bp, e0, theta, n, W):
        sample_cuts(U, Bp, e0, float(theta), int(n), np.empty((0, 3)), 0, W)

    def certify(U, Bp, P, PR, e0, theta, x, y, z, min_half, budget, bad):
        o = np.empty(5)
        cert(U, Bp, P, PR, e0, theta, x, y, z, min_half, budget, o)
        bad[:] = o[2:]
        return int(o[0]), int(o[1])

    def cap(U, Bp, P, PR, e0, n, box, h0, theta_max, tol, min_size, min_half, budget, out,
            cuts):
        M = n * n * n
        W = np.empty((M, 6, 3))
        r = np.empty(8)
        for k in range(out.shape[0]):
            out[k] = np.nan
        flags = 0
        calls = 0
        sample(U, Bp, e0, 0.0, 1, W)
        branch_bound(W, 1, P, box, h0, min_size, 0.0, True, r)
        calls += 1
        if r[BB_STATUS] != FEASIBLE:
            out[0], out[1], out[2], out[9], out[10], out[11] = 0.0, 0.0, 0.0, 2.0, calls, 0.0
            out[12] = 0.0
            return
        lo, hi = 0.0, theta_max
        wx, wy, wz = r[BB_X], r[BB_Y], 0.5 * (r[BB_ZLO] + r[BB_ZHI])
        sample(U, Bp, e0, hi, n, W)
        branch_bound(W, M, P, box, h0, min_size, 0.0, True, r)
        calls += 1
        if r[BB_STATUS] == FEASIBLE:
            flags |= 1
            lo = hi
            wx, wy, wz = r[BB_X], r[BB_Y], 0.5 * (r[BB_ZLO] + r[BB_ZHI])
        elif r[BB_STATUS] == UNDECIDED:
            flags |= 4
        while hi - lo > 0.5 * tol and not flags & 1:
            mid = 0.5 * (lo + hi)
            sample(U, Bp, e0, mid, n, W)
            branch_bound(W, M, P, box, h0, min_size, 0.0, True, r)
            calls += 1
            if r[BB_STATUS] == FEASIBLE:
                lo = mid
                wx, wy, wz = r[BB_X], r[BB_Y], 0.5 * (r[BB_ZLO] + r[BB_ZHI])
            elif r[BB_STATUS] == EMPTY:
                hi = mid
            else:
                flags |= 4
                break
        out[1], out[2], out[3], out[4], out[5] = hi, lo, wx, wy, wz
        # certified lower end: the best point of the sample at theta, over the whole box
        clo, chi = 0.0, lo
        cx, cy, cz = wx, wy, wz
        cells = 0
        first = True
        # near the capability the sample's positions lie close to its witness: the best
        # point is searched around it (any certified point will do)
        near = np.empty(4)
        near[0], near[1] = max(box[0], wx - LOCAL_MM), min(box[1], wx + LOCAL_MM)
        near[2], near[3] = max(box[2], wy - LOCAL_MM), min(box[3], wy + LOCAL_MM)
        # orientations that refuted a point join the sample (as unit-box coordinates, scaled
        # to each level): the next point is chosen against them too
        X = np.empty((M + CUTS, 6, 3))
        extra = np.empty((CUTS, 3))
        ne = 0
        bad = np.empty(3)
        # levels from the sampled one downwards in doubling steps until one is certified,
        # then bisection (an uncertifiable level near the capability costs many cells; one
        # well below it few)
        step = 10.0 * tol
        found = False
        while (chi - clo > 0.5 * tol and hi - clo > tol) or first:
            if first:
                mid = chi
            elif found:
                mid = 0.5 * (clo + chi)
            else:
                mid = max(chi - step, 0.5 * (clo + chi) if clo > 0.0 else 0.0, 0.0)
                step *= 2.0
            ok = False
            for _ in range(CUTS_PER_LEVEL):
                sample_cuts(U, Bp, e0, mid, n, extra, ne, X)
                branch_bound(X, M + ne, P, near, 0.5 * LOCAL_MM, min_size, MAX_EPS, False, r)
                calls += 1
                if not r[BB_F] >= 0.0:
                    break
                px, py, pz = r[BB_X], r[BB_Y], 0.5 * (r[BB_ZLO] + r[BB_ZHI])
                st, c = certify(U, Bp, P, PR, e0, mid, px, py, pz, min_half, budget // 8,
                                bad)
                cells += c
                if st == 1:
                    ok = True
                    found = True
                    clo, cx, cy, cz = mid, px, py, pz
                    break
                if st == -1:
                    flags |= 8
                    break
                if ne == CUTS or mid == 0.0:
                    break
                for k in range(3):
                    extra[ne, k] = (bad[k] - e0[k]) / mid
                ne += 1
                if cells > budget:
                    break
            if not ok:
                chi = mid
            first = False
            if cells > budget:            # the whole certification's budget is spent
                flags |= 8
                break
        # the upper end again, with the cuts: the sample and the orientations that refuted
        # points all lie in the box, so a level where they leave no position is above the
        # capability too (their own capability lies in [clo, hi])
        if ne > 0 and not flags & 5:
            slo = max(clo, 0.0)
            while hi - slo > 0.5 * tol and hi - clo > tol:
                mid = 0.5 * (slo + hi)
                sample_cuts(U, Bp, e0, mid, n, extra, ne, X)
                branch_bound(X, M + ne, P, box, h0, min_size, 0.0, True, r)
                calls += 1
                if r[BB_STATUS] == FEASIBLE:
                    slo = mid
                elif r[BB_STATUS] == EMPTY:
                    hi = mid
                else:
                    flags |= 4
                    break
            out[1] = hi
        out[0], out[6], out[7], out[8] = clo, cx, cy, cz
        out[9], out[10], out[11], out[12] = flags, calls, cells, ne
        for k in range(ne):
            for c in range(3):
                cuts[k, c] = extra[k, c]

    return cap
