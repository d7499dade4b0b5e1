"""Numba drivers shared by every family's inverse kinematics.

Each family supplies a per-pose function ``one(px, py, pz, r00, ..., r22, g, qmin, qmax, q, st)``
(compiled with ``numba.njit``) that writes one pose's six actuator values and leg status codes.
The drivers below loop over poses in parallel; numba specialises them for each family's function,
so a new family needs no driver of its own.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__ = ["drive_euler", "drive_frames", "stroke_status"]

# Leg status codes, ordered by severity: a pose's reason is its legs' maximum.
OK, BELOW_STROKE, ABOVE_STROKE, DEGENERATE, NO_SOLUTION, INVALID_INPUT = 0, 1, 2, 3, 4, 5


@njit(cache=True, inline="always")
def stroke_status(q, qmin, qmax):
    if q < qmin:
        return BELOW_STROKE
    if q > qmax:
        return ABOVE_STROKE
    return OK


@njit(cache=True, parallel=True, fastmath=False)
def drive_euler(one, poses, g, qmin, qmax, q_out, st_out):
    """Inverse kinematics over Euler poses ``(N, 6)`` (R = Rz·Ry·Rx)."""
    n = poses.shape[0]
    for k in prange(n):
        px, py, pz = poses[k, 0], poses[k, 1], poses[k, 2]
        tx, ty, tz = poses[k, 3], poses[k, 4], poses[k, 5]
        if not (math.isfinite(px) and math.isfinite(py) and math.isfinite(pz)
                and math.isfinite(tx) and math.isfinite(ty) and math.isfinite(tz)):
            for i in range(6):
                q_out[k, i] = np.nan
                st_out[k, i] = INVALID_INPUT
            continue
        cx, sx = math.cos(tx), math.sin(tx)
        cy, sy = math.cos(ty), math.sin(ty)
        cz, sz = math.cos(tz), math.sin(tz)
        one(px, py, pz,
            cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
            sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
            -sy, cy * sx, cy * cx,
            g, qmin, qmax, q_out[k], st_out[k])


@njit(cache=True, parallel=True, fastmath=False)
def drive_frames(one, p, R, g, qmin, qmax, q_out, st_out):
    """Inverse kinematics over positions ``(N, 3)`` and rotation matrices ``(N, 3, 3)``."""
    n = p.shape[0]
    for k in prange(n):
        finite = True
        for i in range(3):
            if not math.isfinite(p[k, i]):
                finite = False
            for j in range(3):
                if not math.isfinite(R[k, i, j]):
                    finite = False
        if not finite:
            for i in range(6):
                q_out[k, i] = np.nan
                st_out[k, i] = INVALID_INPUT
            continue
        one(p[k, 0], p[k, 1], p[k, 2],
            R[k, 0, 0], R[k, 0, 1], R[k, 0, 2],
            R[k, 1, 0], R[k, 1, 1], R[k, 1, 2],
            R[k, 2, 0], R[k, 2, 1], R[k, 2, 2],
            g, qmin, qmax, q_out[k], st_out[k])
