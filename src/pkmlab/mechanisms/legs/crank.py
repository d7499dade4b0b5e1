"""Exact feasible z set of a crank leg (rotary servo + fixed-length rod) on a vertical column.

Leg model (as :mod:`.rss6`): a crank of length ``a`` turns about the axis ``n`` through the
pivot ``B``; its end is ``C(α) = B + a(cos α·u + sin α·v)`` with ``u`` the zero direction
(⟂ n), ``v = n × u``, α positive by the right-hand rule about ``n``. A rod of length ``s``
joins ``C`` to the platform joint. On the column (x, y) at a fixed orientation the platform
joint relative to the pivot is ``W = (x + w_x, y + w_y, t)`` with ``t = z + w_z`` and
``w = R·t_i − B_i`` (the engine's leg offset). The rod equation ``|W − (C − B)|² = s²`` is

    E(t)·cos α + F(t)·sin α = G(t),   E = e0 + e1·t,  F = f0 + f1·t,  G = t² + g0

with ``e0 = 2a(d_x u_x + d_y u_y)``, ``e1 = 2a·u_z`` (``f`` likewise with ``v``) and
``g0 = d_x² + d_y² + a² − s²``. The branch-``b`` solution is
``α = atan2(F, E) + b·acos(G/ρ)``, ``ρ² = E² + F²`` (wrapped to (−π, π], exactly the IK
kernel's formula). Along the column the leg's feasibility can change only where

* the real solution appears or disappears: ``D(t) = E² + F² − G² = 0``. ``D`` is a quartic
  with no cubic term, ``−D = t⁴ + p t² + q t + r`` with ``p = 2g0 − A``, ``q = −B``,
  ``r = g0² − C`` (``ρ² = A t² + B t + C``); its real roots come from Ferrari's resolvent
  cubic (largest root ``m ≥ 0``), ``−D = (t² + p/2 + m)² − (√(2m)·t − k)²``,
  ``k = q / (2√(2m))``, i.e. two quadratics, each root then polished by Newton on ``D``;
* the angle reaches a window edge ``α = α_min`` or ``α_max``: ``E cos α_m + F sin α_m = G``,
  a quadratic ``t² − k1 t − k0 = 0`` in t. (Every solution angle crossing ``α_m`` is a root of
  it, so the wrap of α at ±π is covered when a window edge is at ±π and irrelevant otherwise.)

Between consecutive such points feasibility is constant, so each sub-interval is classified by
the IK test at its midpoint (same formula, same window, same degenerate threshold) and
adjacent feasible ones are merged. ``D < 0`` beyond its outermost real roots (leading
coefficient −1), so the set is bounded, and it is empty when ``D`` has no real root. Isolated
points (tangencies) are dropped: they hold no volume.
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

__all__ = ["crank_leg_set", "crank_column_leg", "crank_params", "crank_ik_geometry", "PIECES",
           "NPARAM"]

#: capacity the output arrays of :func:`crank_leg_set` need (it sorts its ≤ 8 breakpoints and
#: the two range ends in ``out_hi``); it returns at most 4 pieces
PIECES = 10
#: per-leg parameters of :func:`crank_column_leg`
NPARAM = 15


@register_jitable
def _cubic_largest(a, b, c):
    """Largest real root of ``x³ + a x² + b x + c`` (Cardano / trigonometric), polished."""
    P = b - a * a / 3.0
    Q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c
    disc = 0.25 * Q * Q + P * P * P / 27.0
    if disc > 0.0:
        sd = math.sqrt(disc)
        u = -0.5 * Q + sd
        w = -0.5 * Q - sd
        y = math.copysign(abs(u) ** (1.0 / 3.0), u) + math.copysign(abs(w) ** (1.0 / 3.0), w)
    elif P < 0.0:
        r = math.sqrt(-P / 3.0)
        arg = -0.5 * Q / (r * r * r)
        arg = min(1.0, max(-1.0, arg))
        y = 2.0 * r * math.cos(math.acos(arg) / 3.0)
    else:
        y = 0.0
    x = y - a / 3.0
    for _ in range(2):
        f = ((x + a) * x + b) * x + c
        df = (3.0 * x + 2.0 * a) * x + b
        if df == 0.0:
            break
        x1 = x - f / df
        f1 = ((x1 + a) * x1 + b) * x1 + c
        if abs(f1) < abs(f):
            x = x1
    return x


@register_jitable
def _quad_roots(B, C, out, n):
    """Real roots of ``t² + B t + C`` appended to ``out`` from slot ``n``; a discriminant a hair
    below zero (``> -1e-12``, normalised units) counts as a double root. Returns the new n."""
    disc = 0.25 * B * B - C
    if disc < -1e-12:
        return n
    sq = math.sqrt(disc if disc > 0.0 else 0.0)
    t1 = -0.5 * B - math.copysign(sq, B)          # the root without cancellation
    out[n] = t1
    out[n + 1] = C / t1 if t1 != 0.0 else -0.5 * B + sq
    return n + 2


@register_jitable
def _ok(t, e0, e1, f0, f1, g0, b, eps, cmin, smin, cmax, smax, wide):
    """The IK test at ``t``: real, not degenerate, angle within the window. The angle
    ``α = atan2(Y, X)`` (the IK's) is compared with the window's edge directions by cross
    products instead of being computed (no atan2): within a window of width <= π, ``α`` is
    counter-clockwise of ``α_min`` and clockwise of ``α_max``; in a wider one (``wide``), either
    (the complement of the open cone from ``α_max`` to ``α_min``). The two tests differ only
    for ``α`` on an edge; the caller tests midpoints of pieces whose ends are the edges'
    crossings."""
    E = e0 + e1 * t
    F = f0 + f1 * t
    G = t * t + g0
    rho2 = E * E + F * F
    h2 = rho2 - G * G
    if h2 < 0.0 or rho2 <= eps:
        return False
    h = math.sqrt(h2)
    Y = F * G + b * E * h
    X = E * G - b * F * h
    after_min = cmin * Y - smin * X >= 0.0
    before_max = X * smax - Y * cmax >= 0.0
    return (after_min or before_max) if wide else (after_min and before_max)


@register_jitable
def _positive_on(ta, tb, e0, e1, f0, f1, g0, A):
    """True when ``D > 0`` on the finite range ``[ta, tb]`` by a certificate: D positive at
    both ends and concave on the range (``D'' = −12t² + 2(A − 2g0) <= 0`` there), so no root of
    the quartic need be computed. False means "not certified", not "not positive"."""
    if not (math.isfinite(ta) and math.isfinite(tb)):
        return False
    c2 = (A - 2.0 * g0) / 6.0                      # D'' <= 0 where t² >= c2
    concave = c2 <= 0.0 or (ta > 0.0 and ta * ta >= c2) or (tb < 0.0 and tb * tb >= c2)
    if not concave:
        return False
    for t in (ta, tb):
        E = e0 + e1 * t
        F = f0 + f1 * t
        G = t * t + g0
        if not E * E + F * F - G * G > 0.0:
            return False
    return True


@register_jitable
def _d_roots(e0, e1, f0, f1, g0, A, L, tlo, thi, T):
    """Real roots of ``D`` into ``T`` (count returned), by Ferrari's method in units of ``L``;
    the ones within 1 mm of ``[tlo, thi]`` polished by Newton on D."""
    Bq = 2.0 * (e0 * e1 + f0 * f1)
    Cq = e0 * e0 + f0 * f0
    L2 = L * L
    p = (2.0 * g0 - A) / L2
    q = -Bq / (L2 * L)
    r = (g0 * g0 - Cq) / (L2 * L2)
    if q == 0.0:
        # biquadratic (no linear term: the crank's zero direction horizontal and its 90°
        # direction vertical, as the delta3 and rss6 generators build them): u = T² solves
        # u² + p u + r = 0, T = ±√u, no resolvent cubic; then polished as Ferrari's roots
        n = 0
        if _quad_roots(p, r, T, 0) == 2:
            u1 = T[0]
            u2 = T[1]
            for u in (u1, u2):
                if u >= 0.0:
                    T[n] = math.sqrt(u)
                    T[n + 1] = -T[n]
                    n += 2
    else:
        # resolvent: m³ + p m² + (p²/4 − r) m − q²/8 = 0, largest root (≥ 0 in exact
        # arithmetic)
        m = _cubic_largest(p, 0.25 * p * p - r, -0.125 * q * q)
        m = m if m > 0.0 else 0.0
        s2 = math.sqrt(2.0 * m)
        c = 0.5 * p + m
        if m > 1e-6:
            k = q / (2.0 * s2)
        else:
            kk = c * c - r
            k = math.copysign(math.sqrt(kk if kk > 0.0 else 0.0), q)
        n = _quad_roots(-s2, c + k, T, 0)
        n = _quad_roots(s2, c - k, T, n)
    for j in range(n):
        t = T[j] * L
        if tlo - 1.0 <= t <= thi + 1.0:
            for _ in range(3):
                E = e0 + e1 * t
                F = f0 + f1 * t
                G = t * t + g0
                D = E * E + F * F - G * G
                dD = 2.0 * (E * e1 + F * f1) - 4.0 * t * G
                if dD == 0.0:
                    break
                t1 = t - D / dD
                E = e0 + e1 * t1
                F = f0 + f1 * t1
                G = t1 * t1 + g0
                if abs(E * E + F * F - G * G) < abs(D):
                    t = t1
                else:
                    break
        T[j] = t
    return n


@register_jitable
def crank_leg_set(dx, dy, wz, ux, uy, uz, vx, vy, vz, a, s, b, amin, amax, cmin, smin, cmax,
                  smax, zlo, zhi, out_lo, out_hi):
    """Feasible z set of one crank leg on a column, clipped to ``[zlo, zhi]`` (infinite ends
    allowed): writes sorted disjoint ``[lo, hi]`` pieces (at most 4) to ``out_lo, out_hi``
    (capacity :data:`PIECES`; ``out_hi`` is also scratch) and returns their count.

    ``(dx, dy)`` is the platform joint's horizontal offset from the crank pivot on this column
    (``x + w_x``, ``y + w_y``), ``wz`` the vertical one at z = 0 (the joint is at height
    ``z + wz`` above the pivot); ``u``, ``v`` the crank's unit zero direction and 90° direction,
    ``a``, ``s`` crank and rod lengths (mm), ``b = ±1`` the branch, ``[amin, amax]`` the servo
    window (rad, within [−π, π]) and ``cmin, smin, cmax, smax`` the cosines and sines of its
    ends. Clipping lets a caller that intersects skip the breakpoints it would cut away.
    """
    a2 = 2.0 * a
    e0 = a2 * (dx * ux + dy * uy)
    e1 = a2 * uz
    f0 = a2 * (dx * vx + dy * vy)
    f1 = a2 * vz
    g0 = dx * dx + dy * dy + a * a - s * s
    eps = 1e-24 * a * a * a * a
    T = out_hi                                     # scratch for the breakpoints
    wide = amax - amin > math.pi
    tlo = zlo + wz
    thi = zhi + wz
    A = e1 * e1 + f1 * f1
    n = 0
    if _positive_on(tlo, thi, e0, e1, f0, f1, g0, A):
        t_a = tlo                                  # no root of D in the clip range
        t_b = thi
    else:
        n = _d_roots(e0, e1, f0, f1, g0, A, a + s, tlo, thi, T)
        if n == 0:
            return 0                               # D < 0 on the whole column
        rmin = np.inf
        rmax = -np.inf
        for j in range(n):
            rmin = min(rmin, T[j])
            rmax = max(rmax, T[j])
        t_a = max(tlo, rmin)                       # D < 0 outside [rmin, rmax]
        t_b = min(thi, rmax)
    if not t_a < t_b:
        return 0
    nb = 0                                         # breakpoints strictly inside (t_a, t_b)
    for j in range(n):
        if t_a < T[j] < t_b:
            T[nb] = T[j]                           # nb <= j: in place
            nb += 1
    # window edges: t² − k1 t − k0 = 0 with k1 = e1 cos + f1 sin, k0 = e0 cos + f0 sin − g0
    for edge in range(2):
        ca = cmin if edge == 0 else cmax
        sa = smin if edge == 0 else smax
        k1 = e1 * ca + f1 * sa
        k0 = e0 * ca + f0 * sa - g0
        disc = 0.25 * k1 * k1 + k0
        if disc >= 0.0:
            sq = math.sqrt(disc)
            t1 = 0.5 * k1 + math.copysign(sq, k1)
            t2 = -k0 / t1 if t1 != 0.0 else 0.5 * k1 - sq
            if t_a < t1 < t_b:
                T[nb] = t1
                nb += 1
            if t_a < t2 < t_b:
                T[nb] = t2
                nb += 1
    for j in range(1, nb):                         # insertion sort
        v = T[j]
        i = j - 1
        while i >= 0 and T[i] > v:
            T[i + 1] = T[i]
            i -= 1
        T[i + 1] = v
    for j in range(nb, 0, -1):                     # then the range ends around them
        T[j] = T[j - 1]
    T[0] = t_a
    T[nb + 1] = t_b
    nb += 2
    cnt = 0
    open_ = False
    for j in range(nb - 1):
        t0 = T[j]
        t1 = T[j + 1]
        if not t1 > t0:
            continue
        if _ok(0.5 * (t0 + t1), e0, e1, f0, f1, g0, b, eps, cmin, smin, cmax, smax, wide):
            # piece cnt <= j: writing out_hi[cnt] never overwrites an unread T[j + 1]
            if open_:
                out_hi[cnt - 1] = t1 - wz
            else:
                out_lo[cnt] = t0 - wz
                out_hi[cnt] = t1 - wz
                cnt += 1
                open_ = True
        else:
            open_ = False
    return cnt


@register_jitable
def crank_column_leg(x, y, wx, wy, wz, p, zlo, zhi, out_lo, out_hi):
    """Set-valued column leg (:mod:`._set_columns`) for a crank leg with parameters ``p``
    (:func:`crank_params`): ``u (3), v (3), a, s, b, α_min, α_max`` and the cosines and sines
    of ``α_min``, ``α_max``."""
    return crank_leg_set(x + wx, y + wy, wz, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7],
                         p[8], p[9], p[10], p[11], p[12], p[13], p[14], zlo, zhi, out_lo,
                         out_hi)


def crank_params(u, v, crank_length, rod_length, branch, window) -> np.ndarray:
    """``(n, 15)`` per-leg rows of :func:`crank_column_leg`: unit ``u``, ``v`` ``(n, 3)``,
    lengths ``(n,)`` in mm, branches ``(n,)`` ±1 and the window ``(α_min, α_max)`` in rad
    (one pair for all legs or ``(n, 2)``)."""
    u = np.asarray(u, dtype=float)
    n = len(u)
    win = np.broadcast_to(np.asarray(window, dtype=float), (n, 2))
    return np.ascontiguousarray(np.column_stack([
        u, np.asarray(v, dtype=float), np.broadcast_to(crank_length, (n,)),
        np.broadcast_to(rod_length, (n,)), np.broadcast_to(branch, (n,)), win,
        np.cos(win[:, 0]), np.sin(win[:, 0]), np.cos(win[:, 1]), np.sin(win[:, 1])]))


def crank_ik_geometry(mech) -> np.ndarray:
    """The geometry vector every crank-and-rod IK kernel reads (rss6, delta3): base points,
    tool points, ``2a·u`` and ``2a·v`` (zero and 90° crank directions), ``a² − l²``, the
    degenerate-root floor ``1e-24·a⁴`` and the branches; families append their own fields."""
    a2 = 2.0 * mech.crank_length[:, None]
    return np.concatenate([mech.base_points.ravel(), mech.tool_points.ravel(),
                           (a2 * mech.zero_directions).ravel(),
                           (a2 * mech.v_directions).ravel(),
                           mech.crank_length**2 - mech.rod_length**2,
                           1e-24 * mech.crank_length**4, mech.branch])
