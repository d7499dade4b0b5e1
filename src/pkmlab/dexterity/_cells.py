"""Branch and bound over cells of neighbouring units for the worst case (issue 28 item 2).

:func:`pkmlab.dexterity.worst_case` needs, over every feasible (unit, orientation) sample, the
largest κ, the smallest all-direction force, and the sign of ``det J`` (for the sign-change
certificate of a singularity). Most samples are far from both extremes. Here the units (the
voxels, or the (x, y) columns of a column-invariant family) are grouped into cells of
:data:`TILE` neighbouring grid units per axis, at one orientation sample each, and every cell
gets certified bounds over all its samples:

* the family's box Jacobian (``_jac_box``, :mod:`pkmlab.mechanisms.kernels.boxes`) encloses
  ``J`` over the cell's box of positions: ``|J(s) - J₀| <= Δ`` entrywise, with ``J₀`` the
  Jacobian at the box centre, so ``‖J(s) - J₀‖₂ <= δ = ‖Δ‖_F`` (``δ_h`` for ``J_h``, the
  angular columns divided by ``L``);
* from one LU of ``J₀`` (:func:`._linalg.sweep_one`): ``σ̄ >= σmax(J_h₀)`` and
  ``ι >= ‖J_h₀⁻¹‖₂`` (Gram-trace bounds, :func:`._linalg._gram_lambda_max`) and the column
  norms ``g_c = ‖(J_h₀⁻¹)_{0:3, c}‖`` (the first three rows of ``J_h⁻¹`` are those of
  ``J⁻¹``);
* with ``D_h`` the entrywise bound of ``|J_h(s) - J_h₀|``, ``‖J_h₀⁻¹ (J_h(s) - J_h₀)‖₂ <= μ =
  min(ι δ_h, ‖ |J_h₀⁻¹| D_h ‖_F)`` (``|M Δ x| <= |M| D |x|`` entrywise) and
  ``‖(J_h₀⁻¹)_{0:3, :} (J_h(s) - J_h₀)‖₂ <= ν``, the Frobenius norm of the first three rows
  of ``|J_h₀⁻¹| D_h``;
* where ``μ < 1`` (Weyl and the Neumann series): ``κ(J_h(s)) <= K = (σ̄ + δ_h) ι /
  (1 - μ)``; ``(J_h(s)⁻¹ - J_h₀⁻¹)_{0:3, c} = -(J_h₀⁻¹)_{0:3, :} (J_h(s) - J_h₀) J_h(s)⁻¹ e_c``
  and ``‖J_h(s)⁻¹ e_c‖ <= ‖b_c‖ / (1 - μ)`` (``b_c`` the column of ``J_h₀⁻¹``), so
  ``‖(J(s)⁻¹)_{0:3, c}‖ <= g_c + ν ‖b_c‖ / (1 - μ)``, which bounds the force
  ``min_c fmax_c / ‖(J(s)⁻¹)_{0:3, c}‖`` below by ``F``; and ``J_h₀ + t (J_h(s) - J_h₀)`` is
  non-singular for ``t ∈ [0, 1]``, so ``det J(s)`` has the sign of ``det J₀``.

**First-order cells** (families with ``_jac_lin``, the 6-PSU; cells of :data:`LINEAR_TILE`
units per axis, and for a column-invariant family the columns' z does not split a cell). The
interval bound's slack grows like the cell (``|J_h₀⁻¹| D_h`` takes absolute values, so the
legs' first-order changes never cancel). ``_jac_lin`` gives ``A_k`` and ``W`` with ``|J(s) -
J₀ - Σ_k Δ_k A_k| <= W`` entrywise (``Δ = s - centre``, ``|Δ_k| <= h_k``; ``W`` is second
order in the cell, plus the rounding allowance). With ``N_k = J_h₀⁻¹ A_k H`` (``H`` the
homogenising column scale), ``Q = |J_h₀⁻¹| W H`` and ``E(s) = J_h₀⁻¹ (J_h(s) - J_h₀) = Σ_k
Δ_k N_k + J_h₀⁻¹ (rem)``:

* ``‖E(s)‖₂ <= μ = max_corners ‖Σ_k Δ_k N_k‖_F + ‖Q‖_F`` (a convex function of ``Δ`` is
  largest at a corner of the box; ``‖Σ Δ_k N_k‖_F²`` from the Gram matrix of the ``N_k``),
  and ``‖J_h(s) - J_h₀‖₂ <= δ_h = max_corners ‖Σ_k Δ_k A_k H‖_F + ‖W H‖_F``; ``K`` as above;
* ``J_h(s)⁻¹ e_c = (I + E)⁻¹ b_c = b_c - E b_c + E² (I + E)⁻¹ b_c``, so the first three
  entries have norm at most ``max_corners ‖g_c - Σ_k Δ_k (N_k b_c)_{0:3}‖ + ‖(Q |b_c|)_{0:3}‖
  + μ² ‖b_c‖ / (1 - μ)`` (``g_c = (b_c)_{0:3}``): the first-order change of the force is
  exact, only the remainder and the second-order term are bounded by norms. ``F`` follows, and
  ``μ < 1`` gives the sign of ``det J`` as above.

Every bound is multiplied (or divided) by ``1 + KAPPA_ROUND`` per rounded quantity, and a cell
with ``K >= 1e8`` is never pruned (:func:`._linalg.kappa_upper`'s range). The box Jacobians'
own allowance covers the round-off of the enclosure and of the per-pose kernel's ``J``.

A cell's samples are evaluated one by one (:func:`._fused.fused_sweep_at`) unless it is
certified (``K``, ``F`` finite, the sign known) **and** ``K`` is below a certified lower bound
on the largest κ **and** ``F`` is above the smallest force already found. The lower bound and
the force incumbent come first from the cells with the largest ``K`` and the smallest ``F``
(evaluated first), then from every chunk evaluated. A pruned sample gets ``kup = -inf``
(never a candidate for the largest κ: its κ is below a sample's), ``force = inf`` (its force
is above a sample's, strictly) and ``det = ±1`` (the certified sign), so the worst case's
extremes, their poses, the singular samples and the sign-change counts are those of the pass
over every sample; only the count of exact κ evaluations can differ. A sample of a cell that
is certified with ``K`` below the lower bound but not ``F`` above the incumbent is evaluated
for its force and ``det J`` only (:func:`._linalg.lu_force`, the same arithmetic as the full
pass's, so both are the same bit for bit) and gets ``kup = -inf``: ``K`` certifies that its
κ is below the maximum and not singular. The choice per cell and the bookkeeping are one numba
loop per chunk of orientations (:func:`_eval_kernel`).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import prange
from numba import types as nt
from numba.extending import register_jitable

from ..runtime.jit import cached_kernel
from ..runtime.threads import threads_for
from ._fused import fused_available, fused_sweep_at
from ._linalg import KAPPA_BRACKET, KAPPA_ROUND, lu_force, sweep_core, sweep_one

__all__ = ["CellPlan", "cells_available", "TILE"]

#: grid units per axis in a cell (cells are TILE × TILE (× TILE) units at one orientation)
TILE = 3
#: cells evaluated first (largest K, smallest F) for the incumbents
_SEED = 8
_KMAX = 1e8
#: use the family's first-order form (``_jac_lin``) for the cell bounds where it has one
LINEAR = True
#: grid units per axis in a cell bounded by the first-order form
LINEAR_TILE = 5


def _lin_of(mech):
    """The family's first-order form ``_jac_lin``, declared by the class that declares its
    ``_jac_one``, or None."""
    owner = next(c for c in type(mech).__mro__ if "_jac_one" in vars(c))
    return vars(owner).get("_jac_lin")


def cells_available(mech) -> bool:
    """True when ``mech`` has a fused Jacobian kernel and a box Jacobian (``_jac_box``)
    declared by the same class as its ``_jac_one`` (a subclass with its own ``_jac_one`` does
    not inherit the box of another)."""
    if not fused_available(mech):
        return False
    owner = next(c for c in type(mech).__mro__ if "_jac_one" in vars(c))
    return vars(owner).get("_jac_box") is not None


@register_jitable(inline="always")
def _feasible_box(P, order, j0, j1, feas, m, plo, phi):
    """The box ``plo``–``phi`` of the positions of the units ``order[j0:j1]`` feasible at
    orientation ``m`` → their count (the box is empty, ``inf``/``-inf``, when none is)."""
    n = 0
    for c in range(3):
        plo[c], phi[c] = np.inf, -np.inf
    for j in range(j0, j1):
        u = order[j]
        if feas[u, m]:
            n += 1
            for c in range(3):
                plo[c] = min(plo[c], P[u, c])
                phi[c] = max(phi[c], P[u, c])
    return n


@cache
def _bounds_kernel(jac, box, ng: int):
    def cell_bounds_loop(P, R, order, start, feas, g, L, fmax, K, F, S):
        T, M = start.shape[0] - 1, R.shape[0]
        r = 1.0 + KAPPA_ROUND
        for t in prange(T):
            J = np.empty((1, 6, 6))
            Jlo = np.empty((6, 6))
            Jhi = np.empty((6, 6))
            A = np.empty((6, 6))
            B = np.empty((6, 6))
            G = np.empty((6, 6))
            Tm = np.empty((6, 6))
            piv = np.empty(6, np.int64)
            q = np.empty((1, 6))
            plo = np.empty(3)
            phi = np.empty(3)
            pc = np.empty(3)
            for m in range(M):
                K[t, m], F[t, m], S[t, m] = -np.inf, np.inf, 0
                n = _feasible_box(P, order, start[t], start[t + 1], feas, m, plo, phi)
                if n == 0:
                    continue                            # nothing to evaluate in the cell
                K[t, m], F[t, m] = np.inf, 0.0          # not certified, until shown
                if not box(plo, phi, R[m], R[m], g, Jlo, Jhi):
                    continue
                for c in range(3):
                    pc[c] = 0.5 * (plo[c] + phi[c])
                jac(pc[0], pc[1], pc[2], R[m, 0, 0], R[m, 0, 1], R[m, 0, 2], R[m, 1, 0],
                    R[m, 1, 1], R[m, 1, 2], R[m, 2, 0], R[m, 2, 1], R[m, 2, 2], g, q, J, 0)
                la, lb, f0, d0 = sweep_core(J[0], L, fmax, A, B, G, Tm, piv)
                if not (la > 0.0 and lb > 0.0 and d0 != 0.0):
                    continue
                sigma, iota = math.sqrt(la) * r, math.sqrt(lb) * r    # B = J_h0⁻¹
                dh2 = 0.0
                for i in range(6):
                    for c in range(6):
                        x = J[0, i, c]
                        e = max(Jhi[i, c] - x, x - Jlo[i, c], 0.0)
                        e = e if c < 3 else e / L
                        Jlo[i, c] = e                       # D_h: |J_h(s) - J_h0| <= D_h
                        dh2 += e * e
                dh = math.sqrt(dh2) * r
                mu2 = 0.0                                   # ‖ |J_h0⁻¹| D_h ‖_F², and rows 0:3
                nu2 = 0.0
                for i in range(6):
                    for c in range(6):
                        v = 0.0
                        for k in range(6):
                            v += abs(B[i, k]) * Jlo[k, c]
                        mu2 += v * v
                        if i < 3:
                            nu2 += v * v
                mu = min(iota * dh, math.sqrt(mu2) * r) * r   # >= ‖J_h0⁻¹ (J_h(s) - J_h0)‖₂
                nu = math.sqrt(nu2) * r * r
                if not mu < 1.0:
                    continue
                kb = (sigma + dh) * iota / (1.0 - mu) * r * r * r
                if not kb < _KMAX:
                    continue
                fb = np.inf
                for c in range(6):
                    gc = B[0, c] * B[0, c] + B[1, c] * B[1, c] + B[2, c] * B[2, c]
                    bc = gc
                    for i in range(3, 6):
                        bc += B[i, c] * B[i, c]
                    eps = nu * math.sqrt(bc) / (1.0 - mu) * r * r
                    fb = min(fb, fmax[c] / ((math.sqrt(gc) * r + eps) * r))
                K[t, m], F[t, m], S[t, m] = kb, fb / r, 1 if d0 > 0.0 else -1

    f8, f1, f2, f3 = nt.float64, nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
    i1 = nt.int64[::1]
    return cached_kernel(cell_bounds_loop,
                         nt.void(f2, f3, i1, i1, nt.boolean[:, ::1], nt.UniTuple(nt.float64, ng),
                                 f8, f1, f2, f2, nt.int8[:, ::1]),
                         parallel=True, error_model="numpy")


@cache
def _lin_bounds_kernel(jac, lin, ng: int):
    """:func:`_bounds_kernel` with the family's first-order form ``_jac_lin`` (module notes,
    "first-order cells"): ``K``, ``F``, ``S`` with the same meaning."""

    def cell_lin_bounds_loop(P, R, order, start, feas, g, L, fmax, K, F, S):
        T, M = start.shape[0] - 1, R.shape[0]
        r = 1.0 + KAPPA_ROUND
        for t in prange(T):
            J = np.empty((1, 6, 6))
            Ad = np.empty((3, 6, 6))
            W = np.empty((6, 6))
            N = np.empty((3, 6, 6))
            A = np.empty((6, 6))
            B = np.empty((6, 6))
            G = np.empty((6, 6))
            Tm = np.empty((6, 6))
            piv = np.empty(6, np.int64)
            q = np.empty((1, 6))
            plo = np.empty(3)
            phi = np.empty(3)
            pc = np.empty(3)
            hk = np.empty(3)
            gn = np.empty((3, 3))
            ga = np.empty((3, 3))
            v = np.empty((3, 3))
            for m in range(M):
                K[t, m], F[t, m], S[t, m] = -np.inf, np.inf, 0
                n = _feasible_box(P, order, start[t], start[t + 1], feas, m, plo, phi)
                if n == 0:
                    continue                            # nothing to evaluate in the cell
                K[t, m], F[t, m] = np.inf, 0.0          # not certified, until shown
                for c in range(3):
                    pc[c] = 0.5 * (plo[c] + phi[c])
                if not lin(plo, phi, pc, R[m], g, Ad, W):
                    continue
                jac(pc[0], pc[1], pc[2], R[m, 0, 0], R[m, 0, 1], R[m, 0, 2], R[m, 1, 0],
                    R[m, 1, 1], R[m, 1, 2], R[m, 2, 0], R[m, 2, 1], R[m, 2, 2], g, q, J, 0)
                la, lb, f0, d0 = sweep_core(J[0], L, fmax, A, B, G, Tm, piv)
                if not (la > 0.0 and lb > 0.0 and d0 != 0.0):
                    continue
                sigma, iota = math.sqrt(la) * r, math.sqrt(lb) * r    # B = J_h0⁻¹
                for k in range(3):                  # half-widths; directions J depends on
                    hk[k] = max(phi[k] - pc[k], pc[k] - plo[k]) * (1.0 + 1e-12)
                    nz = False
                    for i in range(6):
                        for c in range(6):
                            if c >= 3:
                                Ad[k, i, c] /= L                # A_k·H, H = diag(1, 1, 1, 1/L..)
                            if Ad[k, i, c] != 0.0:
                                nz = True
                    if not nz:
                        hk[k] = 0.0
                w2 = 0.0
                for i in range(6):
                    for c in range(3, 6):
                        W[i, c] /= L
                    for c in range(6):
                        w2 += W[i, c] * W[i, c]
                for k in range(3):                  # N_k = J_h0⁻¹ A_k H
                    if hk[k] == 0.0:
                        continue
                    for i in range(6):
                        for c in range(6):
                            x = 0.0
                            for l in range(6):
                                x += B[i, l] * Ad[k, l, c]
                            N[k, i, c] = x
                for k in range(3):                  # Gram matrices of the N_k and the A_k H
                    for l in range(k, 3):
                        sn, sa = 0.0, 0.0
                        if hk[k] > 0.0 and hk[l] > 0.0:
                            for i in range(6):
                                for c in range(6):
                                    sn += N[k, i, c] * N[l, i, c]
                                    sa += Ad[k, i, c] * Ad[l, i, c]
                        gn[k, l], gn[l, k], ga[k, l], ga[l, k] = sn, sn, sa, sa
                mn, ma = 0.0, 0.0                   # max over the corners ‖Σ Δ_k N_k‖_F²
                for s1 in (-1.0, 1.0):
                    for s2 in (-1.0, 1.0):
                        d0_ = (hk[0], s1 * hk[1], s2 * hk[2])
                        xn, xa = 0.0, 0.0
                        for k in range(3):
                            for l in range(3):
                                xn += d0_[k] * d0_[l] * gn[k, l]
                                xa += d0_[k] * d0_[l] * ga[k, l]
                        mn, ma = max(mn, xn), max(ma, xa)
                q2 = 0.0                            # Q = |J_h0⁻¹| W_h, stored in A
                for i in range(6):
                    for c in range(6):
                        x = 0.0
                        for l in range(6):
                            x += abs(B[i, l]) * W[l, c]
                        A[i, c] = x
                        q2 += x * x
                mu = (math.sqrt(max(mn, 0.0)) * r + math.sqrt(q2) * r) * r
                dh = (math.sqrt(max(ma, 0.0)) * r + math.sqrt(w2) * r) * r
                if not mu < 1.0:
                    continue
                kb = (sigma + dh) * iota / (1.0 - mu) * r * r * r
                if not kb < _KMAX:
                    continue
                fb = np.inf
                for c in range(6):
                    bc = 0.0
                    for i in range(6):
                        bc += B[i, c] * B[i, c]
                    qc = 0.0                        # ‖(Q |b_c|)_{0:3}‖
                    for i in range(3):
                        x = 0.0
                        for l in range(6):
                            x += A[i, l] * abs(B[l, c])
                        qc += x * x
                    for k in range(3):              # v_k = (N_k b_c)_{0:3}
                        for i in range(3):
                            x = 0.0
                            if hk[k] > 0.0:
                                for l in range(6):
                                    x += N[k, i, l] * B[l, c]
                            v[k, i] = x
                    worst = 0.0                     # max over the corners ‖g_c - Σ Δ_k v_k‖
                    for s0 in (-1.0, 1.0):
                        for s1 in (-1.0, 1.0):
                            for s2 in (-1.0, 1.0):
                                x = 0.0
                                for i in range(3):
                                    y = (B[i, c] - s0 * hk[0] * v[0, i] - s1 * hk[1] * v[1, i]
                                         - s2 * hk[2] * v[2, i])
                                    x += y * y
                                worst = max(worst, x)
                    e = (math.sqrt(worst) * r + math.sqrt(qc) * r
                         + mu * mu * math.sqrt(bc) / (1.0 - mu) * r * r) * r
                    fb = min(fb, fmax[c] / (e * r))
                K[t, m], F[t, m], S[t, m] = kb, fb / r, 1 if d0 > 0.0 else -1

    f8, f1, f2, f3 = nt.float64, nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
    i1 = nt.int64[::1]
    return cached_kernel(cell_lin_bounds_loop,
                         nt.void(f2, f3, i1, i1, nt.boolean[:, ::1], nt.UniTuple(nt.float64, ng),
                                 f8, f1, f2, f2, nt.int8[:, ::1]),
                         parallel=True, error_model="numpy")


@cache
def _eval_kernel(jac, ng: int):
    """The per-chunk pass over the cells: each cell × orientation either pruned (its samples
    get ``-inf``, ``inf`` and the certified sign), or its feasible samples evaluated — in
    full (:func:`._linalg.sweep_one`) where the cell may hold the largest κ, else only the
    force and ``det J`` (:func:`._linalg.lu_force`, the same arithmetic, ``kup = -inf``:
    ``K`` below the lower bound certifies that no sample of the cell is the maximum or
    singular). Per cell: the largest finite ``kup`` below ``_KMAX``, the smallest non-NaN
    force and the count of evaluated samples (for the incumbents)."""

    def cell_eval_loop(P, R, order, start, feas, K, F, S, k_low, f_inc, m0, g, L, fmax,
                       kup, force, det, tk, tf, tn):
        T, k = start.shape[0] - 1, kup.shape[0]
        for t in prange(T):
            J = np.empty((1, 6, 6))
            A = np.empty((6, 6))
            B = np.empty((6, 6))
            G = np.empty((6, 6))
            Tm = np.empty((6, 6))
            piv = np.empty(6, np.int64)
            q = np.empty((1, 6))
            kt, ft, nt_ = -np.inf, np.inf, 0
            for mm in range(k):
                m = m0 + mm
                cert = K[t, m] < np.inf and S[t, m] != 0
                kneed = not (cert and K[t, m] < k_low)
                fneed = not (cert and F[t, m] > f_inc)
                for j in range(start[t], start[t + 1]):
                    u = order[j]
                    if not feas[u, m]:
                        kup[mm, u], force[mm, u], det[mm, u] = -np.inf, np.inf, 0.0
                        continue
                    if not (kneed or fneed):
                        kup[mm, u], force[mm, u], det[mm, u] = -np.inf, np.inf, S[t, m]
                        continue
                    nt_ += 1
                    jac(P[u, 0], P[u, 1], P[u, 2], R[m, 0, 0], R[m, 0, 1], R[m, 0, 2],
                        R[m, 1, 0], R[m, 1, 1], R[m, 1, 2], R[m, 2, 0], R[m, 2, 1], R[m, 2, 2],
                        g, q, J, 0)
                    if kneed:
                        ku, fo, de = sweep_one(J[0], L, fmax, A, B, G, Tm, piv)
                    else:
                        ok, fo, de = lu_force(J[0], fmax, A, B, piv)
                        ku = -np.inf
                    kup[mm, u], force[mm, u], det[mm, u] = ku, fo, de
                    if ku < _KMAX and ku > kt:          # finite: -inf < ku < 1e8
                        kt = ku
                    if fo < ft:                         # NaN never compares less
                        ft = fo
            tk[t], tf[t], tn[t] = kt, ft, nt_

    f8, f1, f2, f3 = nt.float64, nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
    i1 = nt.int64[::1]
    return cached_kernel(cell_eval_loop,
                         nt.void(f2, f3, i1, i1, nt.boolean[:, ::1], f2, f2, nt.int8[:, ::1],
                                 f8, f8, nt.int64, nt.UniTuple(nt.float64, ng), f8, f1, f2, f2,
                                 f2, f1, f1, i1),
                         parallel=True, error_model="numpy")


def bounds_kernel(mech):
    """The cell-bound kernel for ``mech``: the first-order one where the family has
    ``_jac_lin`` (and :data:`LINEAR`), else the box one (also what the warm-up builds)."""
    jac, g = mech.jacobian_kernel()
    lin = _lin_of(mech) if LINEAR else None
    return (_lin_bounds_kernel(jac, lin, len(g)) if lin is not None
            else _bounds_kernel(jac, type(mech)._jac_box, len(g)))


def _tiles(unit_pos: np.ndarray, h: float, planar: bool = False, tile: int | None = None):
    """Units grouped into cells of ``tile`` (:data:`TILE`) grid steps per axis: ``(order,
    start)``, the units of cell ``t`` being ``order[start[t]:start[t + 1]]``, and the cell of
    each unit. ``planar``: the units are (x, y) columns of a family whose Jacobian does not
    depend on z, so their z (a column's lowest voxel) does not split the cells."""
    idx = (np.floor((unit_pos - unit_pos.min(axis=0)) / h + 0.5).astype(np.int64)
           // (tile or TILE))
    if planar:
        idx[:, 2] = 0
    n = idx.max(axis=0) + 1                      # one integer key per cell, in the row order
    _, cell = np.unique((idx[:, 0] * n[1] + idx[:, 1]) * n[2] + idx[:, 2], return_inverse=True)
    cell = cell.ravel()
    order = np.argsort(cell, kind="stable")
    start = np.searchsorted(cell[order], np.arange(cell.max() + 2))
    return order.astype(np.int64), start.astype(np.int64), cell


class CellPlan:
    """Certified cell bounds of one (units × orientations) sweep and the incumbents; its
    :meth:`chunk` gives the per-pose arrays of :func:`._fused.fused_sweep` with the pruned
    samples marked (module notes)."""

    def __init__(self, mech, unit_pos, Rs, feas, L, fmax, h, exact_kappa):
        self.mech, self.L = mech, float(L)
        self.P = np.require(unit_pos, np.float64, ("C", "A", "W"))
        self.R = np.require(Rs, np.float64, ("C", "A", "W"))
        self.fmax = np.require(np.broadcast_to(fmax, (6,)), np.float64, ("C", "A", "W"))
        self.feas = np.require(feas, np.bool_, ("C", "A", "W"))
        U, M = feas.shape
        lin = _lin_of(mech) if LINEAR else None
        self.order, start, self.cell = _tiles(
            self.P, h, bool(getattr(mech, "column_invariant", False)),
            LINEAR_TILE if lin is not None else TILE)
        self.start = start
        T = len(start) - 1
        self.K, self.F = np.empty((T, M)), np.empty((T, M))
        self.S = np.empty((T, M), dtype=np.int8)
        kernel = bounds_kernel(mech)
        g = mech.jacobian_kernel()[1]
        with threads_for(T * M * 4):
            kernel(self.P, self.R, self.order, start, self.feas, g, self.L, self.fmax, self.K,
                   self.F, self.S)
        self.certified = np.isfinite(self.K) & (self.S != 0)
        self.k_low, self.f_inc = -math.inf, math.inf
        self.evaluated = 0
        # incumbents: the cells of largest K and smallest F (certified or not), evaluated now
        cand = np.flatnonzero(self.certified.ravel())
        if len(cand):
            kk, ff = self.K.ravel()[cand], self.F.ravel()[cand]
            n = min(_SEED, len(cand)) - 1
            seed = np.unique(np.concatenate([cand[np.argpartition(-kk, n)[:n + 1]],
                                             cand[np.argpartition(ff, n)[:n + 1]]]))
            at = []                                      # their feasible samples, m · U + u
            for t, m in zip(seed // M, seed % M):
                units = self.order[start[t]:start[t + 1]]
                at.append(m * U + units[self.feas[units, m]])
            at = np.sort(np.concatenate(at))
            # only the entries at `at` are written and read (np.empty: no fill of M × U)
            kup, force, det = np.empty((M, U)), np.empty((M, U)), np.empty((M, U))
            fused_sweep_at(mech, self.P, self.R, at, self.L, self.fmax, kup, force, det)
            ku, fo = kup.ravel()[at], force.ravel()[at]
            self._update(ku, fo)
            j = int(np.argmax(ku)) if len(ku) else 0
            if len(ku) and ku[j] > -np.inf:              # an exact κ is a lower bound too
                k = exact_kappa(int(at[j] % U), int(at[j] // U))
                if math.isfinite(k):
                    self.k_low = max(self.k_low, k)

    def _update(self, kup, force):
        fin = np.isfinite(kup) & (kup < _KMAX)
        if fin.any():
            self.k_low = max(self.k_low, float(kup[fin].max()) * (1 + KAPPA_ROUND)
                             / KAPPA_BRACKET / (1 + KAPPA_ROUND) ** 3)
        fc = force[~np.isnan(force)]
        if len(fc):
            self.f_inc = min(self.f_inc, float(fc.min()))

    def chunk(self, m0: int, k: int):
        """``(kup, force, det)`` ``(U, k)`` (transposed views) for orientations
        ``m0 … m0 + k - 1``: evaluated where a sample may hold an extreme or its cell is not
        certified (``kup = -inf`` where only the force may: :func:`_eval_kernel`); ``-inf``,
        ``inf``, the certified sign elsewhere; infeasible: ``-inf``, ``inf``, ``0``."""
        U, T = len(self.P), len(self.start) - 1
        kup, force, det = np.empty((k, U)), np.empty((k, U)), np.empty((k, U))
        tk, tf, tn = np.empty(T), np.empty(T), np.empty(T, dtype=np.int64)
        jac, g = self.mech.jacobian_kernel()
        with threads_for(U * k):
            _eval_kernel(jac, len(g))(self.P, self.R, self.order, self.start, self.feas,
                                      self.K, self.F, self.S, self.k_low, self.f_inc, m0, g,
                                      self.L, self.fmax, kup, force, det, tk, tf, tn)
        self.evaluated += int(tn.sum())
        kt = float(tk.max()) if T else -math.inf
        if kt > -math.inf:
            self.k_low = max(self.k_low, kt * (1 + KAPPA_ROUND) / KAPPA_BRACKET
                             / (1 + KAPPA_ROUND) ** 3)
        if T:
            self.f_inc = min(self.f_inc, float(tf.min()))
        return kup.T, force.T, det.T
