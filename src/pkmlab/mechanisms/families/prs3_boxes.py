"""Guaranteed classification of boxes of the 3-PRS free coordinates ``(z, θx, θy)``: proved
feasible everywhere, proved infeasible everywhere, or undecided (:func:`classify_boxes`; used by
the volume bracket of :mod:`pkmlab.workspaces.tripod`).

The chain is the closed form of :mod:`.prs3`, carried in interval arithmetic with outward
rounding (:mod:`..kernels.interval_arith`) over the box:

1. ``sa, ca, sb, cb`` (sine and cosine of θx, θy), ``w_i = Ry·Rx·b_i``, ``A_i = n_i·w_i``,
   ``B_i = (n_i × w_i)·ẑ``, ``a = k·A``, ``b = k·B``, ``ρ = √(a² + b²)`` and ``e/ρ``
   (``e = k·h`` a constant). Where ``e/ρ`` is proved outside ``[-1, 1]`` the constraint has
   no solution (every leg's IK fails): the box is out.
2. The dependent rotation: ``θz = φ ± ω``, ``φ = atan2(b, a)`` (from ``atan(a/b)`` when b
   keeps one sign, ``atan(b/a)`` when a does; otherwise the whole circle), ``ω = acos(e/ρ)``.
   The IK takes the root with the larger cosine, which is ``φ - ω`` where ``b > 0`` and
   ``φ + ω`` where ``b <= 0``: where b changes sign in the box both roots are hulled.
3. ``x, y = P·(h - cos θz·A - sin θz·B)`` (``P`` the pseudo-inverse of the hinge axes' x-y
   rows), the platform joint ``S_i = (x, y, z) + Rz(θz)·w_i`` and ``D_i = S_i - a_i``.
4. Each leg in its rail frame ``(d_i, n_i, m_i = d_i × n_i)``: the constraint is ``n_i·D_i =
   0``, so the IK's discriminant is ``l_i² - (m_i·D_i)²`` and ``q_i = d_i·D_i + σ_i·√disc``.
   z enters ``d·D`` and ``m·D`` once each (and not ``m·D`` at all on vertical rails).

A box is **in** when, for every leg, ``e/ρ`` is proved within ``[-1, 1]``, the discriminant's
lower end is ``>= 0`` and ``q_i`` is proved within the slider window; **out** when ``e/ρ`` is
proved outside, or some leg's discriminant is proved negative or its ``q_i`` (over the part of
the box where the constraint and the discriminant hold) is proved outside the window. The
window is shrunk (in) or grown (out) by ``slack`` (mm), which covers the rounding of the design
constants (``k``, ``P``, ``h``), themselves exact floats of the mechanism's own numbers.

The mechanism has no joint limits on its revolute or spherical joints (``prs3`` declares
none): the feasible set is the one :meth:`.Prs3.inverse` calls valid (link reach, slider
window, the constraint's solvability).
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels.interval_arith import Iv, hull

__all__ = ["classify_boxes", "column_bounds", "vertical_rails", "box_constants",
           "parasitic_enclosure"]


def box_constants(mech) -> dict:
    """The design constants of the chain (module docstring), computed as the kernel does."""
    N = mech.hinge_axes[:, :2]
    k = np.cross(N[:, 0], N[:, 1])
    h = np.sum(mech.hinge_axes * mech.base_points, axis=1)
    m = np.cross(mech.rail_axes, mech.hinge_axes)
    return {"k": k, "h": h, "e": float(k @ h), "P": np.linalg.pinv(N), "m": m}


def _leg_w(c, i, mech, sa, ca, sb, cb):
    bx, by, bz = (float(v) for v in mech.tool_points[i])
    wx = cb * bx + (sb * sa) * by + (sb * ca) * bz
    wy = ca * by - sa * bz
    wz = -(sb * bx) + (cb * sa) * by + (cb * ca) * bz
    nx, ny = (float(v) for v in mech.hinge_axes[i, :2])
    A = wx * nx + wy * ny
    B = wx * ny - wy * nx
    return wx, wy, wz, A, B


def _phi(a: Iv, b: Iv):
    """An enclosure of ``atan2(b, a)`` (module docstring, step 2) and where it is bounded."""
    pos_b, neg_b, pos_a = b.lo > 0, b.hi < 0, a.lo > 0
    half = math.pi / 2
    with np.errstate(all="ignore"):
        t_b = (a / b).atan()                  # b keeps its sign: φ = ±π/2 - atan(a/b)
        t_a = (b / a).atan()                  # a > 0: φ = atan(b/a)
    up_ = half - t_b
    down = (-half) - t_b
    lo = np.where(pos_b, up_.lo, np.where(neg_b, down.lo, np.where(pos_a, t_a.lo, -math.pi)))
    hi = np.where(pos_b, up_.hi, np.where(neg_b, down.hi, np.where(pos_a, t_a.hi, math.pi)))
    bounded = pos_b | neg_b | pos_a
    return Iv(lo, hi), bounded


def _dependent(mech, c, ax: Iv, ay: Iv):
    """Steps 1-3 of the module docstring over boxes of ``(θx, θy)`` (z does not enter):
    ``(sure, never, legs, x, y, g)``, ``g`` the enclosure of θz (not wrapped)."""
    sa, ca, sb, cb = ax.sin(), ax.cos(), ay.sin(), ay.cos()
    legs = [_leg_w(c, i, mech, sa, ca, sb, cb) for i in range(3)]
    k = [float(v) for v in c["k"]]
    a = legs[0][3] * k[0] + legs[1][3] * k[1] + legs[2][3] * k[2]
    b = legs[0][4] * k[0] + legs[1][4] * k[1] + legs[2][4] * k[2]
    rho = (a.sq() + b.sq()).sqrt()
    if c["e"] == 0.0:                              # the symmetric layouts: e/ρ = 0 exactly
        ratio = Iv(np.zeros_like(rho.lo))
    else:
        ratio = rho.recip() * c["e"]
    tol = 1e-12
    never = (ratio.lo > 1.0) | (ratio.hi < -1.0)
    phi, bounded = _phi(a, b)
    sure = (ratio.lo >= -1.0 + tol) & (ratio.hi <= 1.0 - tol) & bounded & (rho.lo > 0)
    om = ratio.acos()
    g_minus, g_plus = phi - om, phi + om
    g = Iv(np.where(b.lo > 0, g_minus.lo, g_plus.lo), np.where(b.lo > 0, g_minus.hi, g_plus.hi))
    g = hull(g, g_minus, (b.lo <= 0) & (b.hi > 0))
    cg, sg = g.cos(), g.sin()
    r = [float(c["h"][i]) - cg * legs[i][3] - sg * legs[i][4] for i in range(3)]
    P = c["P"]
    x = r[0] * float(P[0, 0]) + r[1] * float(P[0, 1]) + r[2] * float(P[0, 2])
    y = r[0] * float(P[1, 0]) + r[1] * float(P[1, 1]) + r[2] * float(P[1, 2])
    return sure, never, legs, x, y, g


def parasitic_enclosure(mech, lo: np.ndarray, hi: np.ndarray):
    """Enclosures of the dependent coordinates over cells ``[lo, hi]`` ``(N, 2)`` of ``(θx,
    θy)`` (rad): ``(never, x, y, θz)``, ``never`` (N,) bool where the constraint is proved
    unsolvable (no feasible point), ``x, y`` (mm) and ``θz`` (rad, not wrapped to ±π: its
    magnitude bounds that of the wrapped value) as :class:`Iv` (outward rounding). The
    parasitic motions do not depend on z."""
    lo = np.asarray(lo, dtype=float).reshape(-1, 2)
    hi = np.asarray(hi, dtype=float).reshape(-1, 2)
    _, never, _, x, y, g = _dependent(mech, box_constants(mech), Iv(lo[:, 0], hi[:, 0]),
                                      Iv(lo[:, 1], hi[:, 1]))
    return never, x, y, g


def _enclose(mech, z: Iv, ax: Iv, ay: Iv):
    """The chain of the module docstring over boxes: ``(sure, never, q, disc)`` with ``sure``
    (the constraint proved solvable, its root choice bounded), ``never`` (proved unsolvable)
    and per leg the enclosures of ``q_i`` and of its discriminant."""
    c = box_constants(mech)
    sure, never, legs, x, y, g = _dependent(mech, c, ax, ay)
    cg, sg = g.cos(), g.sin()
    qs, discs = [], []
    for i in range(3):
        wx, wy, wz = legs[i][:3]
        ai = mech.base_points[i]
        Dx = x + cg * wx - sg * wy - float(ai[0])
        Dy = y + sg * wx + cg * wy - float(ai[1])
        Dz0 = wz - float(ai[2])
        d, m = mech.rail_axes[i], c["m"][i]
        t = Dx * float(d[0]) + Dy * float(d[1]) + Dz0 * float(d[2]) + z * float(d[2])
        mD = Dx * float(m[0]) + Dy * float(m[1]) + Dz0 * float(m[2])
        if m[2] != 0.0:
            mD = mD + z * float(m[2])
        li = float(mech.link_length[i])
        disc = li * li - mD.sq()
        root = disc.sqrt()
        qs.append(t + root if mech.branch[i] > 0 else t - root)
        discs.append(disc)
    return sure, never, qs, discs


def classify_boxes(mech, lo: np.ndarray, hi: np.ndarray, slack: float = 0.0):
    """``(inside, outside)`` ``(N,)`` bool for boxes ``[lo, hi]`` ``(N, 3)`` of ``(z, θx, θy)``
    (mm, rad; ``|θ| < 90°``): proved feasible everywhere / infeasible everywhere (module
    docstring)."""
    lo = np.asarray(lo, dtype=float).reshape(-1, 3)
    hi = np.asarray(hi, dtype=float).reshape(-1, 3)
    sure, never, qs, discs = _enclose(mech, Iv(lo[:, 0], hi[:, 0]), Iv(lo[:, 1], hi[:, 1]),
                                      Iv(lo[:, 2], hi[:, 2]))
    qmin, qmax = (float(v) for v in mech.stroke)
    inside, outside = sure.copy(), never.copy()
    for q, disc in zip(qs, discs):
        inside &= (disc.lo >= 0) & (q.lo >= qmin + slack) & (q.hi <= qmax - slack)
        outside |= (disc.hi < 0) | (q.lo > qmax + slack) | (q.hi < qmin - slack)
    return inside & ~outside, outside


def vertical_rails(mech) -> bool:
    """True when every rail is vertical (``d_i = ẑ`` exactly): z then enters each ``q_i`` as
    ``q_i = z + E_i(θx, θy)`` and the feasible z of a column is one interval per leg."""
    return bool(np.all(mech.rail_axes[:, :2] == 0.0) and np.all(mech.rail_axes[:, 2] == 1.0))


def column_bounds(mech, lo: np.ndarray, hi: np.ndarray, slack: float = 0.0):
    """For cells ``[lo, hi]`` ``(N, 2)`` of ``(θx, θy)`` on a mechanism with
    :func:`vertical_rails`: ``(inner, outer)``, each ``(N, 2)`` z intervals (mm; empty when
    ``lo > hi``) such that every point of the cell × ``inner`` is feasible and every feasible
    point of the cell's column has its z in ``outer``. With ``E_i = q_i - z``: leg i holds
    for ``z`` in ``[q_min - E_i, q_max - E_i]``, so ``inner`` is ``[max(q_min - E_i.lo),
    min(q_max - E_i.hi)]`` and ``outer`` ``[max(q_min - E_i.hi), min(q_max - E_i.lo)]``."""
    if not vertical_rails(mech):
        raise ValueError("column_bounds needs vertical rails")
    lo = np.asarray(lo, dtype=float).reshape(-1, 2)
    hi = np.asarray(hi, dtype=float).reshape(-1, 2)
    zero = Iv(np.zeros(len(lo)))
    sure, never, qs, discs = _enclose(mech, zero, Iv(lo[:, 0], hi[:, 0]), Iv(lo[:, 1], hi[:, 1]))
    qmin, qmax = (float(v) for v in mech.stroke)
    n = len(lo)
    inner = np.stack([np.full(n, -np.inf), np.full(n, np.inf)], axis=1)
    outer = inner.copy()
    ok, dead = sure.copy(), never.copy()
    for q, disc in zip(qs, discs):          # q = E_i (z = 0); z feasible iff z + E_i in window
        inner[:, 0] = np.maximum(inner[:, 0], np.nextafter(qmin + slack - q.lo, np.inf))
        inner[:, 1] = np.minimum(inner[:, 1], np.nextafter(qmax - slack - q.hi, -np.inf))
        outer[:, 0] = np.maximum(outer[:, 0], np.nextafter(qmin - slack - q.hi, -np.inf))
        outer[:, 1] = np.minimum(outer[:, 1], np.nextafter(qmax + slack - q.lo, np.inf))
        ok &= disc.lo >= 0
        dead |= disc.hi < 0
    inner[~ok] = (np.inf, -np.inf)
    outer[dead] = (np.inf, -np.inf)
    return inner, outer
