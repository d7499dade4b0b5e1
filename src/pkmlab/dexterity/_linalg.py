"""Batched singular values of small matrices (numba, one-sided Jacobi).

``np.linalg.svd`` on a stack of 6 × 6 matrices pays LAPACK's per-matrix set-up cost, which
dominates at this size (≈ 6.5 µs per matrix measured on the 2-core development VM); one-sided
Jacobi (Hestenes) written out for small matrices takes ≈ 3 µs and is as accurate: singular
values to a few ulps of σmax, and to high relative accuracy for the small ones, which is what a
condition number needs. Stacks of 50,000 or more run on numba's thread pool.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import njit, prange
from numba import types as nt

from .._jit import cached_kernel

__all__ = ["singular_values"]

_MAX_SWEEPS = 60
_PARALLEL_FROM = 50_000      # below this, thread start-up costs more than it saves


@njit(cache=True, inline="always", error_model="numpy")
def _one(J, m, out, A, d, r, c):
    """Singular values of ``J[m] (r, c)`` into ``out[m] (c,)``, descending.

    ``A (c, r)`` and ``d (c,)`` are scratch. Rotate pairs of columns until all are mutually
    orthogonal (cosine below 1e-15); the singular values are then the column norms. ``d``
    holds the squared column norms, recomputed every sweep and updated through rotations.
    ``r, c`` are passed in so that the 6 × 6 driver inlines them as constants.
    """
    for i in range(c):
        for k in range(r):
            v = J[m, k, i]
            if not math.isfinite(v):
                for j in range(c):
                    out[m, j] = np.nan
                return
            A[i, k] = v
    for _ in range(_MAX_SWEEPS):
        for i in range(c):             # exact squared norms at the start of each sweep
            s = 0.0
            for k in range(r):
                s += A[i, k] * A[i, k]
            d[i] = s
        rotated = False
        for i in range(c - 1):
            for j in range(i + 1, c):
                g = 0.0
                for k in range(r):
                    g += A[i, k] * A[j, k]
                if g * g <= 1e-30 * (d[i] * d[j]):       # cosine <= 1e-15, no sqrt
                    continue
                rotated = True
                zeta = (d[j] - d[i]) / (2.0 * g)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                cs = 1.0 / math.sqrt(1.0 + t * t)
                sn = cs * t
                for k in range(r):
                    x = A[i, k]
                    y = A[j, k]
                    A[i, k] = cs * x - sn * y
                    A[j, k] = sn * x + cs * y
                d[i] -= t * g
                d[j] += t * g
        if not rotated:
            break
    for i in range(c):                 # exact norms, then insertion sort (descending)
        s = 0.0
        for k in range(r):
            s += A[i, k] * A[i, k]
        v = math.sqrt(s)
        j = i
        while j > 0 and out[m, j - 1] < v:
            out[m, j] = out[m, j - 1]
            j -= 1
        out[m, j] = v


@njit(cache=True, error_model="numpy")
def _serial(J, out):
    r, c = J.shape[1], J.shape[2]
    A = np.empty((c, r))
    d = np.empty(c)
    for m in range(J.shape[0]):
        _one(J, m, out, A, d, r, c)


@njit(cache=True, error_model="numpy")
def _serial6(J, out):
    A = np.empty((6, 6))
    d = np.empty(6)
    for m in range(J.shape[0]):
        _one(J, m, out, A, d, 6, 6)


def _parallel_loop(J, out):
    r, c = J.shape[1], J.shape[2]
    for m in prange(J.shape[0]):
        A = np.empty((c, r))
        d = np.empty(c)
        _one(J, m, out, A, d, r, c)


@cache
def _parallel():
    """:func:`_parallel_loop` compiled on numba's thread pool; a parallel kernel is cached only
    through :func:`pkmlab._jit.cached_kernel` (see there why)."""
    return cached_kernel(_parallel_loop, nt.void(nt.float64[:, :, ::1], nt.float64[:, ::1]),
                         parallel=True, error_model="numpy")


def singular_values(J: np.ndarray) -> np.ndarray:
    """Singular values of a stack of matrices, largest first.

    Args:
        J: ``(..., r, c)`` real matrices with ``r >= c``.

    Returns:
        ``(..., c)`` singular values, descending; all NaN for a matrix with any non-finite
        entry (mask: ``np.isfinite(J).all(axis=(-2, -1))``).
    """
    J = np.asarray(J, dtype=float)
    if J.ndim < 2 or J.shape[-2] < J.shape[-1]:
        raise ValueError(f"singular_values needs (..., r, c) with r >= c, got {J.shape}")
    lead = J.shape[:-2]
    flat = np.require(J.reshape((-1,) + J.shape[-2:]), np.float64, ("C", "A", "W"))
    out = np.empty((flat.shape[0], J.shape[-1]))
    if flat.shape[0] >= _PARALLEL_FROM:
        _parallel()(flat, out)
    elif flat.shape[0] and J.shape[-2:] == (6, 6):
        _serial6(flat, out)
    elif flat.shape[0]:
        _serial(flat, out)
    return out.reshape(lead + (J.shape[-1],))
