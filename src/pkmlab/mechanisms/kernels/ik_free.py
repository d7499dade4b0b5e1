"""Inverse-kinematics driver for poses given in a mechanism's free coordinates.

A mechanism whose mobility is not spatial (:mod:`..mobility`: deltas, planar, five-bar,
3-PRS) is usually given its poses as ``(N, width)`` free coordinates. Expanding them to six
coordinates and running the Euler driver of :mod:`.ik` costs, per pose, a 48-byte row written
and read back, three sines and cosines and the Z-Y-X product, even when no angle is free: for a
two-actuator family that is more than its own kernel (the five-bar's driver floor, issue 24).

:func:`make_free_driver` builds a driver for one mobility, its free coordinates given as
positions in the six-coordinate pose (``index``, compile-time constants):

* positions: each of the rows 0-2 of the block buffer ``T`` is the pose's free coordinate or
  the fixed (nominal) value;
* **no free angle** (translational, planar point): the rotation is the same for every pose.
  Its nine entries are computed once, by the Euler driver's own :func:`.ik._sincos` and
  :func:`.ik._euler_matrix` (``math.sin``/``math.cos`` beyond :data:`.ik.TRIG_MAX`, as there),
  and passed to the per-pose function as constants, so no rotation row is stored or read;
* **a free angle** (planar ``theta_z``; the 3-PRS tilts): the three angles, free ones from the
  input and fixed ones constant, go through the Euler driver's block stage
  (:func:`.ik._sincos_block`, :func:`.ik._euler_matrix`).

Either way every number the per-pose function sees is bit-identical to what the Euler driver
computes for the expanded pose, so the results are too (``tests/mechanisms/
test_ik_free.py``). Stage 2 (the family's ``one``) and stage 3 are the Euler driver's.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import njit, prange
from numba import types as nt

from ...poses import POSE_SIZE
from ...runtime.jit import cached_kernel, identity, jitable
from ...runtime.threads import threads_for
from ..results import IKResult
from .ik import (
    _F1,
    _F2,
    _I1,
    _I2,
    BLOCK,
    OK,
    ROW,
    TRIG_MAX,
    _euler_matrix,
    _legs,
    _prefill,
    _rows,
    _sincos,
    _sincos_block,
    _store,
    _store_invalid,
    _store_matrix,
    _width,
    carray,
)

__all__ = ["make_free_driver", "fixed_rotation", "free_rows", "inverse_free"]


@njit(cache=True)
def _sincos3(a, b, c):
    """The nine entries of R = Rz(c)·Ry(b)·Rx(a) exactly as the Euler driver computes them."""
    sx, cx = _sincos(a)
    sy, cy = _sincos(b)
    sz, cz = _sincos(c)
    return _euler_matrix(sx, cx, sy, cy, sz, cz)


def fixed_rotation(angles) -> tuple:
    """Rotation entries ``r00 ... r22`` of the fixed Euler angles ``(θx, θy, θz)`` (rad), as
    the Euler driver computes them for a pose with those angles."""
    a = [float(v) for v in angles]
    if abs(a[0]) + abs(a[1]) + abs(a[2]) <= TRIG_MAX:
        r = _sincos3(a[0], a[1], a[2])
    else:           # the Euler driver's slow path (libm)
        r = _euler_matrix(math.sin(a[0]), math.cos(a[0]), math.sin(a[1]), math.cos(a[1]),
                          math.sin(a[2]), math.cos(a[2]))
    return tuple(float(v) for v in r)


@njit(cache=True)
def _load_positions(x, width, m, w, where, fixed, T):
    """Rows 0-2 of ``T``: pose coordinate ``c`` is column ``where[c]`` of the ``(m, width)``
    block ``x`` (flat), or ``fixed[c]`` where ``where[c] < 0``. Returns the number of poses
    whose position is not finite (the Euler driver's test, ``px + py + pz``)."""
    for c in range(3):
        k = where[c]
        if k >= 0:
            for j in range(m):
                T[c * ROW + j] = x[width * j + k]
        else:
            v = fixed[c]
            for j in range(m):
                T[c * ROW + j] = v
        for j in range(m, w):
            T[c * ROW + j] = 0.0
    nbad = 0
    for j in range(m):
        nbad += 0 if math.isfinite(T[j] + T[ROW + j] + T[2 * ROW + j]) else 1
    return nbad


@njit(cache=True)
def _load_angles(x, width, m, w, where, fixed, T, A, C):
    """Rows 3-11 of ``T`` from the angles (free from ``x``, fixed from ``fixed``), as
    :func:`.ik._load_euler`; returns the number of poses beyond :data:`.ik.TRIG_MAX`."""
    for r in range(3):
        k = where[3 + r]
        if k >= 0:
            for j in range(m):
                A[r * ROW + j] = x[width * j + k]
        else:
            v = fixed[3 + r]
            for j in range(m):
                A[r * ROW + j] = v
        for j in range(m, w):
            A[r * ROW + j] = 0.0
    slow = 0
    for j in range(m):
        small = abs(A[j]) + abs(A[ROW + j]) + abs(A[2 * ROW + j]) <= TRIG_MAX
        slow += 0 if small else 1
    _sincos_block(A, C, w)
    for j in range(w):
        _store_matrix(T, j, _euler_matrix(A[j], C[j], A[ROW + j], C[ROW + j],
                                          A[2 * ROW + j], C[2 * ROW + j]))
    return slow


@njit(cache=True)
def _free_slow(x, width, m, where, fixed, T, bad):
    """Scalar pass over a block with slow poses, as :func:`.ik._euler_slow`: flags the
    non-finite ones in ``bad`` and takes the rotation of large angles from libm."""
    a = np.empty(3)
    for j in range(m):
        for r in range(3):
            k = where[3 + r]
            a[r] = x[width * j + k] if k >= 0 else fixed[3 + r]
        bad[j] = not (math.isfinite(T[j] + T[ROW + j] + T[2 * ROW + j])
                      and math.isfinite(a[0] + a[1] + a[2]))
        if not bad[j] and not abs(a[0]) + abs(a[1]) + abs(a[2]) <= TRIG_MAX:
            _store_matrix(T, j, _euler_matrix(math.sin(a[0]), math.cos(a[0]), math.sin(a[1]),
                                              math.cos(a[1]), math.sin(a[2]), math.cos(a[2])))


@cache
def _legs_fixed(one, ng: int):
    """Stage 2 with one rotation for every pose, passed as constants (:func:`.ik._legs`)."""

    def legs_fixed(T, w, r, g, qmin, qmax, q, st):
        for j in range(w):
            one(T[j], T[ROW + j], T[2 * ROW + j], r[0], r[1], r[2], r[3], r[4], r[5], r[6],
                r[7], r[8], g, qmin, qmax, q, st, j)

    return jitable(legs_fixed, identity(legs_fixed, extra=("legs_fixed", ng)),
                   error_model="numpy")


@cache
def make_free_driver(one, ng: int, legs: int, index: tuple[int, ...]):
    """Parallel driver ``free(X (N, width), where (6,) int64, fixed (6,), r (9-tuple), g, qmin,
    qmax, q_out (N, legs), st_out (N, legs) int8, reason_out (N,) int8)`` for the per-pose
    function ``one`` (:func:`.ik.make_driver`) and a mobility whose free coordinates are at
    ``index`` in the six-coordinate pose (module notes).

    ``where[c]`` is the column of pose coordinate ``c`` in ``X`` (-1: fixed at ``fixed[c]``);
    ``r`` the fixed rotation's entries (:func:`fixed_rotation`), read only when no angle is
    free. Cached by :func:`pkmlab.runtime.jit.cached_kernel` like the other drivers.
    """
    nlegs, rows = legs, _rows(legs)
    width = len(index)

    if any(c >= 3 for c in index):
        stage = _legs(one, ng)

        def drive_free(X, where, fixed, r, g, qmin, qmax, q_out, st_out, reason_out):
            """Inverse kinematics over free coordinates ``(N, width)`` with a free angle."""
            n = X.shape[0]
            x, q_flat, st_flat = X.reshape(-1), q_out.reshape(-1), st_out.reshape(-1)
            for b in prange((n + BLOCK - 1) // BLOCK):
                k0 = b * BLOCK
                m = min(BLOCK, n - k0)
                w = _width(m)
                xb = x[width * k0:width * (k0 + m)]
                T = np.empty(12 * ROW)
                A = np.empty(3 * ROW)
                C = np.empty(3 * ROW)
                q = np.empty(rows * ROW)
                st = np.empty(rows * ROW, dtype=np.int8)
                slow = _load_positions(xb, width, m, w, where, fixed, T)
                slow += _load_angles(xb, width, m, w, where, fixed, T, A, C)
                bad = np.zeros(BLOCK, dtype=np.bool_)
                if slow:
                    _free_slow(xb, width, m, where, fixed, T, bad)
                _prefill(st, nlegs, w)
                stage(T, w, g, qmin, qmax, q, st)
                out = slice(nlegs * k0, nlegs * (k0 + m))
                _store(q, st, m, nlegs, q_flat[out], st_flat[out], reason_out[k0:k0 + m])
                if slow:
                    _store_invalid(bad, m, nlegs, q_flat[out], st_flat[out],
                                   reason_out[k0:k0 + m])
    else:
        stage = _legs_fixed(one, ng)

        def drive_free(X, where, fixed, r, g, qmin, qmax, q_out, st_out, reason_out):
            """Inverse kinematics over free coordinates ``(N, width)``, one rotation ``r``."""
            n = X.shape[0]
            x, q_flat, st_flat = X.reshape(-1), q_out.reshape(-1), st_out.reshape(-1)
            for b in prange((n + BLOCK - 1) // BLOCK):
                k0 = b * BLOCK
                m = min(BLOCK, n - k0)
                w = _width(m)
                xb = x[width * k0:width * (k0 + m)]
                T = np.empty(12 * ROW)
                q = np.empty(rows * ROW)
                st = np.empty(rows * ROW, dtype=np.int8)
                nbad = _load_positions(xb, width, m, w, where, fixed, T)
                _prefill(st, nlegs, w)
                stage(T, w, r, g, qmin, qmax, q, st)
                out = slice(nlegs * k0, nlegs * (k0 + m))
                _store(q, st, m, nlegs, q_flat[out], st_flat[out], reason_out[k0:k0 + m])
                if nbad:
                    bad = np.zeros(BLOCK, dtype=np.bool_)
                    _free_slow(xb, width, m, where, fixed, T, bad)
                    _store_invalid(bad, m, nlegs, q_flat[out], st_flat[out],
                                   reason_out[k0:k0 + m])

    f8 = nt.float64
    sig = nt.void(_F2, nt.int64[::1], _F1, nt.UniTuple(f8, 9), nt.UniTuple(f8, ng), f8, f8,
                  _F2, _I2, _I1)
    return cached_kernel(drive_free, sig, parallel=True,
                         extra=("legs", nlegs, "index", tuple(index)))


def free_rows(mobility, X: np.ndarray) -> np.ndarray | None:
    """``X`` as ``(N, width)`` rows when it holds poses in a non-spatial ``mobility``'s free
    coordinates (``(width,)`` or ``(N, width)``), else None."""
    if mobility.is_spatial or X.ndim not in (1, 2) or X.shape[-1] != mobility.width:
        return None
    return X.reshape(-1, mobility.width)


def inverse_free(mech, X: np.ndarray, lo: float, hi: float):
    """``mech.inverse`` of free-coordinate rows ``X (N, width)`` (the other coordinates at
    the nominal pose's) through :func:`make_free_driver` → :class:`..results.IKResult`."""
    g = mech._ik_geometry
    n, L = X.shape[0], mech.n_actuators
    q = np.empty((n, L))
    st = np.empty((n, L), dtype=np.int8)
    reason = np.empty(n, dtype=np.int8)
    index = tuple(int(c) for c in mech.mobility.index)
    where = np.full(POSE_SIZE, -1, dtype=np.int64)
    where[list(index)] = np.arange(len(index))
    fixed = carray(mech.nominal_pose)
    drive = make_free_driver(mech._ik_kernel(), len(g), L, index)
    with threads_for(n):
        drive(carray(X), where, fixed, fixed_rotation(fixed[3:]), g, float(lo), float(hi), q,
              st, reason)
    mech._check_legs(reason)
    return IKResult(q=q, valid=reason == OK, reason=reason, leg_status=st)
