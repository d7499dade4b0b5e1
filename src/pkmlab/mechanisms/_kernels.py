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

__all__ = ["make_drivers", "stroke_status"]

# Leg status codes, ordered by severity: a pose's reason is its legs' maximum.
OK, BELOW_STROKE, ABOVE_STROKE, DEGENERATE, NO_SOLUTION, INVALID_INPUT = 0, 1, 2, 3, 4, 5


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
