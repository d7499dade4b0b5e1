"""Batched singular values of small matrices (numba, one-sided Jacobi).

``np.linalg.svd`` on a stack of 6 × 6 matrices pays LAPACK's per-matrix set-up cost, which
dominates at this size (≈ 6.5 µs per matrix measured on the 2-core development VM); one-sided
Jacobi (Hestenes) written out for small matrices takes ≈ 3 µs and is as accurate: singular
values to a few ulps of σmax, and to high relative accuracy for the small ones, which is what a
condition number needs. Stacks of 50,000 or more run on numba's thread pool.

:func:`sweep_bounds` is the per-pose pass of :func:`pkmlab.dexterity.worst_case`: one LU
factorisation per Jacobian gives ``det J``, ``J⁻¹`` (hence the all-direction force) and a
certified upper bound on κ, so that exact singular values are needed only near the maximum.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import njit, prange
from numba import types as nt

from ..runtime.jit import cached_kernel
from ..runtime.threads import threads_for

__all__ = ["singular_values", "sweep_bounds", "KAPPA_BRACKET"]

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
    through :func:`pkmlab.runtime.jit.cached_kernel` (see there why)."""
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


# ---------------------------------------------------------------------------------------------
# one pass over a stack of 6 × 6 Jacobians for the workspace worst case

_POWER = 2                     # λmax from tr(G^4): κ bracket ratio 6^(1/4) ≈ 1.57


@njit(cache=True, inline="always", error_model="numpy")
def _gram_lambda_max(A, G, T):
    """Upper bound on λmax(AᵀA) for ``A (6, 6)`` (scratch ``G``, ``T``); 0.0 for A = 0.

    With ``G = AᵀA / tr(AᵀA)`` (eigenvalues λ_i / Σλ), ``λmax^p <= tr(G^p) <= 6·λmax^p`` for
    ``p = 2^k``; ``tr(G^(2^j)) = ‖G^(2^(j-1))‖_F²`` so k - 1 products give ``p = 2^k``.
    Renormalising after every product keeps the entries in range: the bound is
    ``tr(AᵀA) · Π_j c_j^(2^-j)`` with ``c_j`` the squared Frobenius norm at step j.
    """
    s = 0.0
    for i in range(6):
        for j in range(i, 6):
            v = 0.0
            for k in range(6):
                v += A[k, i] * A[k, j]
            G[i, j] = v
            G[j, i] = v
        s += G[i, i]
    if not s > 0.0:
        return 0.0
    inv = 1.0 / s
    for i in range(6):
        for j in range(6):
            G[i, j] *= inv
    b = s
    for step in range(_POWER):
        c = 0.0
        for i in range(6):
            for j in range(6):
                c += G[i, j] * G[i, j]
        r = c                       # c^(2^-(step+1)) by square roots (c in [1/6, 1])
        for _ in range(step + 1):
            r = math.sqrt(r)
        b *= r
        if step == _POWER - 1:
            break
        inv = 1.0 / c
        for i in range(6):
            for j in range(i, 6):
                v = 0.0
                for k in range(6):
                    v += G[i, k] * G[k, j]
                T[i, j] = v * inv
                T[j, i] = v * inv
        for i in range(6):
            for j in range(6):
                G[i, j] = T[i, j]
    return b


#: poses per parallel task of :func:`sweep_bounds` (each task has its own scratch matrices)
_SWEEP_TASK = 512


def sweep_bounds(J, L, fmax, kup, force, det) -> None:
    """For each ``J[m] (6, 6)``: det J, the all-direction force capability and an upper bound
    on κ(J_h), from one LU factorisation (partial pivoting) and the inverse, written into
    ``kup``, ``force`` and ``det`` (C-contiguous float64 ``(M,)``); on numba's threads in
    tasks of :data:`_SWEEP_TASK` poses (one thread for a small stack,
    :func:`pkmlab.runtime.threads.threads_for`).

    * ``force[m] = min_i fmax_i / ‖(J⁻ᵀ)_{i,0:3}‖`` (N; :func:`max_force_all_directions`);
    * ``kup[m] >= κ(J_h) = σmax(J_h)·σmax(J_h⁻¹)``, from ``λmax(G) <= tr(G^(2^k))^(2^-k)`` for
      the Gram matrices of ``J_h`` and ``J_h⁻¹`` (k = 2): ``κ <= kup <= KAPPA_BRACKET·κ`` in
      exact arithmetic (measured on the 6-PSU over its ±15° workspace: kup / κ <= 1.18; one
      more squaring per matrix tightens it to 1.02 but costs more than the exact κ it saves);
    * a matrix with a non-finite entry: ``kup = inf``, ``force = NaN``, ``det = NaN``;
      an exactly zero pivot: ``kup = inf``, ``force = 0``, ``det = 0``.

    Other (square) shapes, a lower mobility's ``(M, w, w)``, go through
    :func:`pkmlab.dexterity.sweep.sweep_bounds`, which calls this for a 6 × 6 stack.
    """
    if np.shape(J)[1:] != (6, 6):
        raise ValueError(f"sweep_bounds: a stack of 6 × 6 matrices, got {np.shape(J)}")
    J = np.require(J, np.float64, ("C", "A", "W"))     # the kernel's one signature: writeable
    fmax = np.require(np.broadcast_to(fmax, (6,)), np.float64, ("C", "A", "W"))
    for name, a in (("kup", kup), ("force", force), ("det", det)):
        if not (a.dtype == np.float64 and a.flags.c_contiguous and a.flags.writeable
                and a.shape == (len(J),)):
            raise ValueError(f"sweep_bounds: {name} must be a writeable C-contiguous float64 "
                             f"array of shape ({len(J)},), got {a.dtype} {a.shape}")
    with threads_for(len(J)):
        _sweep()(J, float(L), fmax, kup, force, det)


def _sweep_loop(J, L, fmax, kup, force, det):
    n = J.shape[0]
    for task in prange((n + _SWEEP_TASK - 1) // _SWEEP_TASK):
        A = np.empty((6, 6))
        B = np.empty((6, 6))
        G = np.empty((6, 6))
        T = np.empty((6, 6))
        piv = np.empty(6, np.int64)
        for m in range(task * _SWEEP_TASK, min(n, (task + 1) * _SWEEP_TASK)):
            _sweep_pose(J, m, L, fmax, kup, force, det, A, B, G, T, piv)


@cache
def _sweep():
    """:func:`_sweep_loop` compiled on numba's thread pool (cached through
    :func:`pkmlab.runtime.jit.cached_kernel`, like every parallel kernel)."""
    f1 = nt.float64[::1]
    return cached_kernel(_sweep_loop, nt.void(nt.float64[:, :, ::1], nt.float64, f1, f1, f1, f1),
                         parallel=True, error_model="numpy")


@njit(cache=True, error_model="numpy", inline="always")
def _sweep_pose(J, m, L, fmax, kup, force, det, A, B, G, T, piv):
    """One pose of :func:`sweep_bounds`, with the caller's scratch ``A, B, G, T, piv``."""
    kup[m], force[m], det[m] = sweep_one(J[m], L, fmax, A, B, G, T, piv)


# sweep_core and lu_force are compiled as functions of their own that the kernels call, not
# inlined (issue 28, session 6): inlined, every kernel that uses them compiled the LU and the
# two Gram bounds again (a parallel kernel at about twice a serial one's cost); called, they
# compile once per process and load from the cache after. Each is one function (the LU,
# _lu_force, is inlined into both), so a pose costs one call; sweep_one, inlined, is only the
# call and the square root. The demo's kernels went from 109 to about 55 s of compile CPU, the
# arithmetic is the same operation for operation, and the worst case's run time changed by
# about 2-3 % (docs/validation.md, "Issue 28 — compile time of the demo's kernels").
@njit(cache=True, error_model="numpy", inline="always")
def sweep_one(Jm, L, fmax, A, B, G, T, piv):
    """``(kup, force, det)`` of one ``Jm (6, 6)`` (:func:`sweep_bounds`), with scratch
    ``A, B, G, T (6, 6)`` and ``piv (6,)`` int64."""
    la, lb, fm, d = sweep_core(Jm, L, fmax, A, B, G, T, piv)
    return (math.sqrt(la * lb) if la > 0.0 and lb > 0.0 else np.inf), fm, d


@njit(cache=True, error_model="numpy")
def lu_force(Jm, fmax, A, B, piv):
    """:func:`_lu_force`, called."""
    return _lu_force(Jm, fmax, A, B, piv)


@njit(cache=True, error_model="numpy", inline="always")
def _lu_force(Jm, fmax, A, B, piv):
    """The first half of :func:`sweep_core`: ``(ok, force, det)`` from one LU of ``Jm``
    (partial pivoting) and ``B = J⁻¹``; ``ok`` False for a non-finite ``Jm`` (force and det
    NaN) or an exactly zero pivot (both 0). :func:`sweep_core` calls it, so a caller that
    needs only the force and the sign of ``det J`` (:mod:`._cells`) gets the same values bit
    for bit without the two Gram bounds."""
    finite = True
    for i in range(6):
        for k in range(6):
            v = Jm[i, k]
            if not math.isfinite(v):
                finite = False
            A[i, k] = v
    if not finite:
        return False, np.nan, np.nan
    d = 1.0
    zero = False
    for k in range(6):
        p = k
        best = abs(A[k, k])
        for i in range(k + 1, 6):
            if abs(A[i, k]) > best:
                best = abs(A[i, k])
                p = i
        piv[k] = p
        if best == 0.0:
            zero = True
            break
        if p != k:
            d = -d
            for c in range(6):
                t = A[k, c]
                A[k, c] = A[p, c]
                A[p, c] = t
        d *= A[k, k]
        for i in range(k + 1, 6):
            f = A[i, k] / A[k, k]
            A[i, k] = f
            for c in range(k + 1, 6):
                A[i, c] -= f * A[k, c]
    if zero:
        return False, 0.0, 0.0
    for i in range(6):                    # B = P·I, then forward and back substitution
        for c in range(6):
            B[i, c] = 1.0 if i == c else 0.0
    for k in range(6):
        p = piv[k]
        if p != k:
            for c in range(6):
                t = B[k, c]
                B[k, c] = B[p, c]
                B[p, c] = t
    for c in range(6):
        for i in range(6):
            v = B[i, c]
            for k in range(i):
                v -= A[i, k] * B[k, c]
            B[i, c] = v
        for i in range(5, -1, -1):
            v = B[i, c]
            for k in range(i + 1, 6):
                v -= A[i, k] * B[k, c]
            B[i, c] = v / A[i, i]
    fm = np.inf                           # B = J⁻¹, so (J⁻ᵀ)_{i,0:3} = B[0:3, i]
    for c in range(6):
        g = B[0, c] * B[0, c] + B[1, c] * B[1, c] + B[2, c] * B[2, c]
        if g > 0.0:
            v = fmax[c] / math.sqrt(g)
            if v < fm:
                fm = v
    return True, fm, d


@njit(cache=True, error_model="numpy")
def sweep_core(Jm, L, fmax, A, B, G, T, piv):
    """:func:`sweep_one`'s parts: ``(la, lb, force, det)`` with ``la >= λmax(J_hᵀJ_h)`` and
    ``lb >= λmax(J_h⁻ᵀJ_h⁻¹)`` (``-1`` for a non-finite or exactly singular ``Jm``); on
    return ``B`` holds ``J_h⁻¹`` and ``A`` its transpose."""
    ok, fm, d = _lu_force(Jm, fmax, A, B, piv)
    if not ok:
        return -1.0, -1.0, fm, d
    for i in range(6):                    # J_h = J·diag(1, 1, 1, 1/L, 1/L, 1/L)
        for k in range(6):
            A[i, k] = Jm[i, k] if k < 3 else Jm[i, k] / L
    for i in range(3, 6):                 # J_h⁻¹ = diag(1, 1, 1, L, L, L)·J⁻¹
        for c in range(6):
            B[i, c] *= L
    la = _gram_lambda_max(A, G, T)
    for i in range(6):                    # λmax(B Bᵀ) = λmax(Bᵀ B): use Bᵀ as "A"
        for c in range(6):
            A[i, c] = B[c, i]
    lb = _gram_lambda_max(A, G, T)
    return la, lb, fm, d


#: ``kup / KAPPA_BRACKET`` of :func:`sweep_bounds` is a lower bound on κ (exact arithmetic).
KAPPA_BRACKET = 6.0 ** (1.0 / 2 ** _POWER)
#: relative allowance for rounding in ``kup``: ``kup·(1 + KAPPA_ROUND) >= κ`` below 1e8 (above
#: it, treat the bound as unbounded)
KAPPA_ROUND = 1e-6


def kappa_upper(kup: np.ndarray) -> np.ndarray:
    """``kup`` of :func:`sweep_bounds` made safe against rounding: ``kup·(1 + KAPPA_ROUND)``,
    and ``inf`` above 1e8, where the rounding may exceed the allowance."""
    return np.where(kup > 1e8, np.inf, kup * (1 + KAPPA_ROUND))
