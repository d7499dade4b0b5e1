"""Compiled searches over continuous positions for radial column families.

Three numba kernels per family, built from its ``column_leg`` (radial: the leg interval along
the column ``(x, y)`` depends on ``(x, y)`` through the horizontal distance ``d`` from the leg's
axis only, monotone in ``d``; ``ok`` true on ``d <= d_max``) and cached like every kernel
(:func:`pkmlab.runtime.jit.cached_kernel`). Used by :mod:`pkmlab.workspaces.optima.search`,
which states the method; in short:

* **margin** of a column over an orientation sample ``W (M, 6, 3)``:
  ``f(x, y) = min b - max a`` over leg × orientation pairs (``-inf`` where a leg cannot reach
  the column). The dexterous set over the sample is non-empty iff ``f >= 0`` somewhere; the
  column then holds the exact z interval ``[max a, min b]``.
* **bounds over a rectangle of positions**: over a tile ``[x0, x1] × [y0, y1]`` each pair's
  ``a`` and ``b`` lie between their values at the tile's nearest and farthest distance from
  the axis (monotone in ``d``), so ``f <= min bmax - max amin`` on the *whole continuous
  tile*, and ``f = -inf`` there if a pair fails ``ok`` at the nearest distance.
* :func:`make_branch_bound`: branch and bound over continuous ``(x, y)`` — tiles start on the
  grid, are bounded as above, split in four while their bound exceeds the best centre value
  (decision mode: while it is ``>= 0``; a centre with ``f >= 0`` is a witness), down to
  ``min_size`` mm. An empty tile list proves ``f < 0`` at every continuous position.
  Hardest orientations first: a bound stops as soon as it falls below the pruning threshold
  (it is still a bound), and the orientation that stopped it is tried first on the next
  tile; the decisions and the best margin are those of the full evaluation. A split tile
  bounds its children and evaluates their centres over its *kept* pairs only, those that can
  still give the maximum ``a`` or minimum ``b`` somewhere in it (:mod:`.branch`, exact:
  the same tiles, decisions and outputs as over all pairs, bit for bit).
* :func:`make_certify`: whether one point ``p`` keeps every leg within its stroke for *every*
  orientation of the continuous Euler box ``centre ± θ`` (not a sample). The box is split into
  cells of half-width ``δ``; over a cell ``w_i = R·u_i - b_i`` moves from its value at the
  cell's centre by ``J·Δθ + e`` with ``J = ∂(R·u_i)/∂θ`` at the centre and ``|e| <=
  |u_i|·(3δ)²/2`` (every first and second derivative of ``R·u_i`` is ``u_i`` rotated and
  crossed with unit axes, so its norm is at most ``|u_i|``; also ``|Δw| <= |u_i|·3δ``).
  That bounds ``w_z`` within ``± (δ·Σ_k |J_zk| + |e|)`` and the distance ``d`` from the
  leg's axis within ``[d - ρ_r, d + ρ_r + ρ_xy²/(2d)]`` (``ρ_r`` the radial component,
  ``ρ_xy`` the horizontal length of the displacement). ``a`` and ``b`` are monotone in ``d``
  and in ``w_z`` (the leg depends on ``z + w_z``), so their extremes over that range are at
  its corners. That first-order bound loses the correlation of ``d`` and ``w_z``; with the
  family's closed form ``c + σ·sqrt(K - |v|²) - w_z`` (``column_profile()``, ``v`` the
  horizontal leg vector) a second bound applies: the end's linearisation ``ℓ = (-σv/g, -1)``
  is bounded exactly over the linearised cell (``δ·Σ_k |ℓ·J_k| + |ℓ|·|e|``), and the sphere's
  curvature ``K/(K - r_max²)^{3/2}·|Δv|²/2`` is added only on the side where the end is not
  concave (σ > 0) or convex (σ < 0), where the cell keeps ``|v| < sqrt(K)``. A leg holds on
  the cell when either bound shows it. The cell is certified when ``z`` lies inside
  every leg's guaranteed interval, refuted when the centre orientation itself fails, split in
  eight otherwise.
* :func:`make_capability`: the whole orientation-capability search in one call — bisection on
  ``θ`` with the branch and bound (upper end: the sample of the ±θ box found empty at every
  continuous position), then the certified lower end: levels from the sampled one down in
  doubling steps, then bisection; at each level the best point near the witness is certified,
  and an orientation that refutes it joins the sample for the next point (cutting planes).
  Finally the upper end is bisected again over the sample *and* those cut orientations (all
  inside the box, so a level where together they admit no position is above the capability):
  the cuts are the orientations between the samples that bind, so the upper end moves from the
  grid's capability down towards the certified one.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import types as nt

from ...runtime.jit import cached_kernel, identity, jitable
from . import columns as column_kernels
from . import ik as _kernels
from .branch import (
    BB_F,
    BB_STATUS,
    BB_X,
    BB_Y,
    BB_ZHI,
    BB_ZLO,
    EMPTY,
    FEASIBLE,
    STACK,
    UNDECIDED,
    branch_core,
)
from .tiles import DPAD  # DPAD: padding of distance ranges (mm)

__all__ = ["make_branch_bound", "make_certify", "make_capability", "DPAD"]

#: the best point of a sample is searched to this margin (mm) before it is certified
MAX_EPS = 1e-2
#: half-width (mm) of the region around the sample's witness searched for the point to certify
LOCAL_MM = 5.0
#: orientations that refuted a point, kept for choosing the next (at most), and the attempts
#: per level
CUTS = 64
CUTS_PER_LEVEL = 6
#: padding (mm) of the second-order certification bounds against rounding
TPAD = 1e-8


@cache
def _core(leg):
    """The jitable building blocks for ``leg`` (margin, tile bound, sample, branch and bound,
    certification), named after their identity like the IK stage functions."""
    leg = column_kernels.inlined(leg)

    def sample(U, Bp, e0, theta, n, W):
        """``W (n³, 6, 3)`` of the ±theta box sampled with n angles per axis about e0."""
        m = 0
        for i in range(n):
            for j in range(n):
                for k in range(n):
                    tx = e0[0] + (-theta + 2.0 * theta * i / (n - 1) if n > 1 else 0.0)
                    ty = e0[1] + (-theta + 2.0 * theta * j / (n - 1) if n > 1 else 0.0)
                    tz = e0[2] + (-theta + 2.0 * theta * k / (n - 1) if n > 1 else 0.0)
                    r = _kernels._euler_matrix(math.sin(tx), math.cos(tx), math.sin(ty),
                                               math.cos(ty), math.sin(tz), math.cos(tz))
                    for s in range(6):
                        ux, uy, uz = U[s, 0], U[s, 1], U[s, 2]
                        W[m, s, 0] = r[0] * ux + r[1] * uy + r[2] * uz - Bp[s, 0]
                        W[m, s, 1] = r[3] * ux + r[4] * uy + r[5] * uz - Bp[s, 1]
                        W[m, s, 2] = r[6] * ux + r[7] * uy + r[8] * uz - Bp[s, 2]
                    m += 1

    def sample_cuts(U, Bp, e0, theta, n, extra, ne, X):
        """The sample of :func:`sample` followed by the first ``ne`` cut orientations
        ``e0 + extra[k]·theta`` (``extra`` in unit-box coordinates, so inside the box)."""
        sample(U, Bp, e0, theta, n, X)
        M = n * n * n
        for k in range(ne):
            tx = e0[0] + extra[k, 0] * theta
            ty = e0[1] + extra[k, 1] * theta
            tz = e0[2] + extra[k, 2] * theta
            rr = _kernels._euler_matrix(math.sin(tx), math.cos(tx), math.sin(ty),
                                        math.cos(ty), math.sin(tz), math.cos(tz))
            for s in range(6):
                ux, uy, uz = U[s, 0], U[s, 1], U[s, 2]
                X[M + k, s, 0] = rr[0] * ux + rr[1] * uy + rr[2] * uz - Bp[s, 0]
                X[M + k, s, 1] = rr[3] * ux + rr[4] * uy + rr[5] * uz - Bp[s, 1]
                X[M + k, s, 2] = rr[6] * ux + rr[7] * uy + rr[8] * uz - Bp[s, 2]

    def certify(U, Bp, P, PR, e0, theta, x, y, z, min_half, budget, bad):
        """1: ``(x, y, z)`` holds for every orientation of the box e0 ± theta; 0: refuted (an
        orientation of the box fails it, written to ``bad``); -1: undecided (cells below
        ``min_half`` rad or more than ``budget`` cells). ``PR (6, 2, 3)``: the family's
        ``column_profile()`` (second-order bounds; ``K < 0`` rows: first order only).
        Returns ``(status, cells)``."""
        ulen = np.empty(6)
        for s in range(6):
            ulen[s] = math.sqrt(U[s, 0] ** 2 + U[s, 1] ** 2 + U[s, 2] ** 2)
        C = np.empty((STACK, 4))
        C[0, 0], C[0, 1], C[0, 2], C[0, 3] = e0[0], e0[1], e0[2], theta
        sp = 1
        cells = 0
        status = 1
        while sp > 0:
            sp -= 1
            tx, ty, tz, dl = C[sp, 0], C[sp, 1], C[sp, 2], C[sp, 3]
            cells += 1
            sa, ca, sb, cb, sc, cc = (math.sin(tx), math.cos(tx), math.sin(ty), math.cos(ty),
                                      math.sin(tz), math.cos(tz))
            r = _kernels._euler_matrix(sa, ca, sb, cb, sc, cc)
            good = True
            for s in range(6):
                ux, uy, uz = U[s, 0], U[s, 1], U[s, 2]
                vx = r[0] * ux + r[1] * uy + r[2] * uz
                vy = r[3] * ux + r[4] * uy + r[5] * uz
                vz = r[6] * ux + r[7] * uy + r[8] * uz
                wx, wy, wz = vx - Bp[s, 0], vy - Bp[s, 1], vz - Bp[s, 2]
                a, b, ok = leg(x, y, wx, wy, wz, P[s, 0], P[s, 1], P[s, 2])
                if not ok or z < a or z > b:
                    bad[0], bad[1], bad[2] = tx, ty, tz
                    return 0, cells          # the cell's centre orientation fails
                if not good:
                    continue
                # d(R·u)/dθ at the centre: θz: e_z × R·u; θx: R·(e_x × u);
                # θy: Rz·Ry·(e_y × Rx·u); second-order remainder <= |u|·(3δ)²/2
                jzx, jzy, jzz = -vy, vx, 0.0
                ex, ey, ez = 0.0, -uz, uy
                jxx = r[0] * ex + r[1] * ey + r[2] * ez
                jxy = r[3] * ex + r[4] * ey + r[5] * ez
                jxz = r[6] * ex + r[7] * ey + r[8] * ez
                qx, qz = ux, sa * uy + ca * uz                             # Rx·u (x, z)
                kx, ky, kz = qz, 0.0, -qx                                  # e_y × Rx·u
                mx, my, mz = cb * kx + sb * kz, ky, -sb * kx + cb * kz     # Ry·(...)
                jyx, jyy, jyz = cc * mx - sc * my, sc * mx + cc * my, mz  # Rz·(...)
                r2 = 0.5 * ulen[s] * (3.0 * dl) ** 2
                sx, sy = x + wx, y + wy
                d = math.sqrt(sx * sx + sy * sy)
                rho = ulen[s] * 3.0 * dl
                rho_xy = min(rho, dl * (math.hypot(jxx, jxy) + math.hypot(jyx, jyy)
                                        + math.hypot(jzx, jzy)) + r2)
                rho_z = min(rho, dl * (abs(jxz) + abs(jyz) + abs(jzz)) + r2)
                dlo, dhi = d - rho_xy, d + rho_xy
                if d > 0.0:
                    nx_, ny_ = sx / d, sy / d
                    rho_r = dl * (abs(nx_ * jxx + ny_ * jxy) + abs(nx_ * jyx + ny_ * jyy)
                                  + abs(nx_ * jzx + ny_ * jzy)) + r2
                    dlo = max(dlo, d - rho_r)
                    dhi = min(dhi, d + rho_r + rho_xy * rho_xy / (2.0 * d))
                dlo = max(dlo - DPAD, 0.0)
                dhi = dhi + DPAD
                amax, bmin = -np.inf, np.inf
                for e in range(4):
                    dd = dlo if e // 2 == 0 else dhi
                    zz = wz - rho_z - DPAD if e % 2 == 0 else wz + rho_z + DPAD
                    a, b, ok = leg(dd - wx, -wy, wx, wy, zz, P[s, 0], P[s, 1], P[s, 2])
                    if not ok:
                        amax = np.inf
                    amax = max(amax, a)
                    bmin = min(bmin, b)
                if amax <= z <= bmin:
                    continue
                # second order from the closed form c + σ·sqrt(K - |v|²) - w_z, v = s_xy:
                # linear part exact over the linearised cell, remainder of R·u (r2) through
                # |ℓ|, and the sphere's curvature on the side where the end is not concave
                # (σ > 0) / convex (σ < 0); only where |v| stays below sqrt(K) on the cell
                rmax = d + rho_xy + DPAD
                ok2 = True
                for e in range(2):
                    c0, sg, K = PR[s, e, 0], PR[s, e, 1], PR[s, e, 2]
                    if not rmax * rmax < K * (1.0 - 1e-12):
                        ok2 = False
                        break
                    g0 = math.sqrt(K - d * d)
                    lx, ly = -sg * sx / g0, -sg * sy / g0          # ℓ = (lx, ly, -1)
                    lin = dl * (abs(lx * jxx + ly * jxy - jxz) + abs(lx * jyx + ly * jyy - jyz)
                                + abs(lx * jzx + ly * jzy - jzz)) \
                        + math.sqrt(lx * lx + ly * ly + 1.0) * r2
                    curv = 0.5 * K / (K - rmax * rmax) ** 1.5 * rho_xy * rho_xy
                    E0 = c0 + sg * g0 - wz
                    if e == 0:          # lower end: its largest value over the cell
                        top = E0 + lin + (curv if sg < 0.0 else 0.0) + TPAD
                        if not top <= z:
                            ok2 = False
                    else:               # upper end: its smallest value
                        bot = E0 - lin - (curv if sg > 0.0 else 0.0) - TPAD
                        if not z <= bot:
                            ok2 = False
                if not ok2:
                    good = False
            if good or dl == 0.0:
                continue
            if dl < min_half or cells > budget:
                status = -1
                continue
            if sp + 8 > C.shape[0]:
                C2 = np.empty((2 * C.shape[0], 4))
                C2[:sp] = C[:sp]
                C = C2
            hd = 0.5 * dl
            for q in range(8):
                C[sp, 0] = tx + (hd if q & 1 else -hd)
                C[sp, 1] = ty + (hd if q & 2 else -hd)
                C[sp, 2] = tz + (hd if q & 4 else -hd)
                C[sp, 3] = hd
                sp += 1
        return status, cells

    raw = (sample, sample_cuts, certify)
    ident = identity(*raw, extra=("search-core",))
    # the functions call each other through closure cells: rebinding the names makes those
    # cells hold the jitable versions
    sample = jitable(sample, ident, error_model="numpy")
    sample_cuts = jitable(sample_cuts, ident, error_model="numpy")
    certify = jitable(certify, ident, error_model="numpy")
    return branch_core(leg) | {"sample": sample, "sample_cuts": sample_cuts,
                               "certify": certify}


_F1, _F2, _F3 = nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]


@cache
def make_branch_bound(leg):
    """``bb(W (M, 6, 3), P (6, 3), box (4,), h0, min_size, eps, decide, out (8,))``: branch
    and bound over continuous positions for the orientation sample whose leg offsets
    ``w = R·u - b`` are ``W`` (any orientations: a grid of the box, plus the binding ones the
    caller adds; see the module notes); ``out`` gets status (1 feasible, 0 empty at every
    position, -1 undecided), best margin, its x, y, z interval, the global upper bound of the
    margin and the tile count."""
    core = _core(leg)
    branch_bound = core["branch_bound"]

    def bb(W, P, box, h0, min_size, eps, decide, out):
        branch_bound(W, W.shape[0], P, box, h0, min_size, eps, decide, out)

    f8 = nt.float64
    return cached_kernel(bb, nt.void(_F3, _F2, _F1, f8, f8, f8, nt.boolean, _F1),
                         roots=tuple(_raw(core)))


@cache
def make_certify(leg):
    """``cert(U, Bp, P, PR, e0, theta, x, y, z, min_half, budget, out (2,) or (5,))``:
    certification of one point over the continuous box (module notes; ``PR`` the column
    profile or rows with ``K < 0``); out = (status, cells) and, given room, the Euler angles
    of the orientation that refuted the point (status 0)."""
    core = _core(leg)
    certify = core["certify"]

    def cert(U, Bp, P, PR, e0, theta, x, y, z, min_half, budget, out):
        bad = np.full(3, np.nan)
        s, c = certify(U, Bp, P, PR, e0, theta, x, y, z, min_half, budget, bad)
        out[0], out[1] = s, c
        if out.shape[0] >= 5:
            out[2], out[3], out[4] = bad[0], bad[1], bad[2]

    f8 = nt.float64
    return cached_kernel(cert, nt.void(_F2, _F2, _F2, _F3, _F1, f8, f8, f8, f8, f8, nt.int64,
                                       _F1), roots=tuple(_raw(core)))


@cache
def make_capability(leg):
    """``cap(U, Bp, P, PR, e0, n, box, h0, theta_max, tol, min_size, min_half, budget,
    out (13,), cuts (CUTS, 3))``: the orientation capability in one call (module notes;
    ``PR`` the column profile of the certification, or rows with ``K < 0``). ``out``: theta_lo
    (certified), theta_hi (the sample and the cut orientations admit no position), sampled
    theta (the ``n³`` grid alone, witness), its x, y, z, the certified point x, y, z, flags
    (1: not bounded below theta_max, 2: nominal empty, 4: an undecided branch and bound, 8:
    certification undecided or ``budget`` cells spent; one certification gets an eighth of
    it), branch-and-bound calls, certification cells, the number of cut orientations written
    to ``cuts`` (unit-box coordinates: the Euler offset at level θ is ``cuts[k]·θ``)."""
    core = _core(leg)
    sample, branch_bound, certify = core["sample"], core["branch_bound"], core["certify"]
    sample_cuts = core["sample_cuts"]

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

    f8, i8 = nt.float64, nt.int64
    return cached_kernel(cap, nt.void(_F2, _F2, _F2, _F3, _F1, i8, _F1, f8, f8, f8, f8, f8, i8,
                                      _F1, _F2), roots=tuple(_raw(core)))


def _raw(core):
    """The Python functions behind the jitable core (their source is part of the identity)."""
    return [getattr(v, "py_func", v) for v in core.values()]
