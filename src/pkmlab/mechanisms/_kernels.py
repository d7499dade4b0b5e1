"""Numba drivers shared by every family's inverse kinematics.

Each family supplies a per-pose function ``one(px, py, pz, r00, ..., r22, g, qmin, qmax, q, st,
k)`` (compiled with ``numba.njit``) that writes row ``k`` of the actuator values ``q (N, 6)`` and
leg status codes ``st (N, 6)`` and returns the pose's most severe status. :func:`make_drivers`
wraps it in parallel loops over poses; the family function is captured as a compile-time
constant, so numba inlines it, and a new family needs no driver code of its own.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import njit, prange

__all__ = ["make_drivers", "make_column_kernels", "make_leg_eval", "stroke_status"]

# Leg status codes, ordered by severity: a pose's reason is its legs' maximum.
OK, BELOW_STROKE, ABOVE_STROKE, DEGENERATE, NO_SOLUTION, INVALID_INPUT = 0, 1, 2, 3, 4, 5
# A leg on the other side of its base joint than at the nominal pose (another assembly mode).
OTHER_MODE = 6


@njit(cache=True, inline="always")
def stroke_status(q, qmin, qmax):
    if q < qmin:
        return BELOW_STROKE
    if q > qmax:
        return ABOVE_STROKE
    return OK


@njit(cache=True, inline="always")
def _invalid(q_out, st_out, k):
    for i in range(6):
        q_out[k, i] = np.nan
        st_out[k, i] = INVALID_INPUT
    return INVALID_INPUT


@cache
def make_drivers(one):
    """Parallel drivers ``(euler, frames)`` for the per-pose function ``one``."""

    @njit(parallel=True)
    def drive_euler(poses, g, qmin, qmax, q_out, st_out, reason_out):
        """Inverse kinematics over Euler poses ``(N, 6)`` (R = Rz·Ry·Rx)."""
        for k in prange(poses.shape[0]):
            px, py, pz = poses[k, 0], poses[k, 1], poses[k, 2]
            tx, ty, tz = poses[k, 3], poses[k, 4], poses[k, 5]
            if not (math.isfinite(px + py + pz) and math.isfinite(tx + ty + tz)):
                reason_out[k] = _invalid(q_out, st_out, k)
                continue
            cx, sx = math.cos(tx), math.sin(tx)
            cy, sy = math.cos(ty), math.sin(ty)
            cz, sz = math.cos(tz), math.sin(tz)
            reason_out[k] = one(px, py, pz,
                                cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
                                sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
                                -sy, cy * sx, cy * cx,
                                g, qmin, qmax, q_out, st_out, k)

    @njit(parallel=True)
    def drive_frames(p, R, g, qmin, qmax, q_out, st_out, reason_out):
        """Inverse kinematics over positions ``(N, 3)`` and rotations ``(N, 3, 3)``."""
        for k in prange(p.shape[0]):
            total = p[k, 0] + p[k, 1] + p[k, 2]
            for i in range(3):
                for j in range(3):
                    total += R[k, i, j]
            if not math.isfinite(total):
                reason_out[k] = _invalid(q_out, st_out, k)
                continue
            reason_out[k] = one(p[k, 0], p[k, 1], p[k, 2],
                                R[k, 0, 0], R[k, 0, 1], R[k, 0, 2],
                                R[k, 1, 0], R[k, 1, 1], R[k, 1, 2],
                                R[k, 2, 0], R[k, 2, 1], R[k, 2, 2],
                                g, qmin, qmax, q_out, st_out, k)

    return drive_euler, drive_frames


# ---- column kernels for the workspace engine --------------------------------------------------
# A family with exact column intervals supplies ``leg(x, y, wx, wy, wz, p0, p1, p2) -> (a, b,
# ok)``: the z interval [a, b] in which leg i (offset w = R·u_i - b_i, parameters p = P[i]) is
# within its stroke on the column (x, y), ``ok = False`` where the leg cannot reach the column at
# all. The drivers intersect these intervals over legs and orientations ("all") or unite the
# per-orientation intersections ("any").


@cache
def make_column_kernels(leg):
    """Parallel drivers ``(columns_all, columns_any)`` for the per-leg interval ``leg``."""
    from .._intervals import union_merge

    @njit(parallel=True)
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

    @njit(parallel=True)
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

    return columns_all, columns_any


@cache
def make_leg_eval(leg):
    """Vectorised ``leg`` over items: ``(x, y, W (n, 3), P (n, 3)) -> (a, b, ok)``, each (n,)."""

    @njit(parallel=True)
    def leg_eval(x, y, W, P, a, b, ok):
        for k in prange(x.shape[0]):
            a[k], b[k], ok[k] = leg(x[k], y[k], W[k, 0], W[k, 1], W[k, 2],
                                    P[k, 0], P[k, 1], P[k, 2])

    def run(x, y, W, P):
        n = len(x)
        a, b, ok = np.empty(n), np.empty(n), np.empty(n, dtype=np.bool_)
        leg_eval(np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(y, dtype=float),
                 np.ascontiguousarray(W, dtype=float), np.ascontiguousarray(P, dtype=float),
                 a, b, ok)
        return a, b, ok

    return run
