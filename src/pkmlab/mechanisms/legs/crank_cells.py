"""Bounds of a crank leg (rotary servo + fixed-length rod, :mod:`.rss6`) over a cell: a
position ball ``|p' - p| <= δ`` times a rotation cell ``angle(R' Rᵀ) <= α``, for the cell
volume bracket (:mod:`pkmlab.workspaces.bracket.cells`).

Leg model as :mod:`.rss6`: pivot ``B``, unit axis ``n``, zero direction ``u``, ``v = n × u``,
crank ``a``, rod ``s``, branch ``b``. With ``W = p + R·t - B`` (``t`` the platform joint about
the tool point) write ``x = W·u``, ``y = W·v``, ``z = W·n`` and ``r = hypot(x, y)``. The crank
end runs on a circle of radius ``a``; the nearest and farthest distances from ``W`` to it are

    d_min = hypot(z, r - a),   d_max = hypot(z, r + a).

**Closing.** The rod closes (the IK has a real solution, ``h² = ρ² - G² >= 0`` with ``ρ = 2ar``
and ``G = |W|² + a² - s²``) exactly when ``d_min <= s <= d_max``, since ``ρ - G = s² - d_min²``
and ``ρ + G = d_max² - s²``. The margins ``m1 = s - d_min`` and ``m2 = d_max - s`` are
1-Lipschitz in ``W`` (the nearest and the farthest distance to a fixed set are), and over the
cell ``|W' - W| <= εP = δ + 2 sin(α/2)·|t|``, so ``|m' - m| <= εP``.

**Angle.** ``θ = atan2(y, x) + b·acos(G/ρ)``. Differentiating ``f(θ, W) = |W - C(θ)|² - s² = 0``:
``∂f/∂W = 2(W - C)`` (norm ``2s``) and ``∂f/∂θ = ρ sin(θ - atan2(y, x)) = b·h``, so
``|∇_W θ| = 2s/h``. Over the ball, when ``m1 > εP`` and ``m2 > εP``,

    h² = (s - d_min)(s + d_min)(d_max - s)(d_max + s)
       >= h_min² = (m1 - εP)(s + max(d_min - εP, 0))(m2 - εP)(d_max - εP + s) > 0,

so the solution exists on the whole ball, the (lifted) angle is smooth along every segment in
it (``h > 0`` gives ``r > 0`` and ``|G/ρ| < 1``) and ``|θ' - θ| <= εθ = 2s·εP/h_min``.
Otherwise ``εθ = inf`` (the solution may vanish, or both branches meet, inside the cell).

**Feasibility margin** (what the bracket tests, ``leg_cell_margins``). Leg i is feasible at
``W`` when the rod closes and the branch-``b`` angle lies in the window ``[lo, hi]`` (tested
after wrapping to ``(-π, π]``). A lower bound ``D`` of the distance from ``W`` to the set of
the other status:

* the rod does not close at ``W`` (``m1 < 0`` or ``m2 < 0``): every feasible point closes, so
  it is at least ``D = -min(m1, m2)`` away (1-Lipschitz margins);
* it closes: a segment from ``W`` to a point of the other status either leaves the closing
  region (crossing ``m1 = 0`` or ``m2 = 0``, at least ``min(m1, m2)`` away) or stays in it,
  where the angle is continuous (``h > 0``), and then passes a point whose angle is a window
  edge ``e``: a point at distance ``s`` from the crank end ``C(e)`` and, being on branch
  ``b`` (``θ = ψ + b·φ``, ``φ = acos(G/ρ) ∈ [0, π]``, ``ψ = atan2(y, x)``, so
  ``b·sin(e - ψ) = sin φ >= 0``), in the half-space ``b·(x sin e - y cos e) >= 0`` bounded by
  the plane through the servo axis and the crank at ``e``. The distance to the intersection is
  at least the larger of the distances to the sphere and to the half-space:
  ``D_e = max(||W - C(e)| - s|, -b·(x sin e - y cos e))``, and
  ``D = min(m1, m2, D_lo, D_hi)`` (no edge terms for a full window ``[-π, π]``, whose wrap is
  no edge). Without the half-space, the sphere's points where the *other* branch reaches the
  edge (on the servo platform, close to the nominal pose) would keep cells undecided.

The margin is ``μ = ±D`` (+ where feasible at ``W``) with ``ε = εP``: ``μ > ε`` proves the leg
feasible on the whole cell, ``μ < -ε`` infeasible. ``μ`` itself is not Lipschitz (``D`` is a
lower bound), but those two implications are all the bracket uses. It needs no derivative,
so it holds up to the singular rod positions (``h = 0``), where the angle bound above is
infinite.

Every bound gets ``1e-9 mm + 1e-12·scale`` of slack for rounding. The degenerate status
(``ρ² <= 1e-24 a⁴``, the platform joint on the servo axis) needs ``r ≈ 0``, i.e. ``d_max ≈
d_min`` (``d_max² - d_min² = 4ar``), which ``μ > ε`` excludes.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["crank_cell_terms", "crank_position_curvature"]


def crank_cell_terms(p, R, delta, alpha, B, T, u, v, n, a, s, b, window, slack):
    """Per cell centre ``(p (N, 3), R (N, 3, 3))`` with radii ``delta (N,)`` mm and
    ``alpha (N,)`` rad, for legs with pivots ``B``, platform joints ``T`` (about the tool
    point), unit ``u``, ``v``, ``n`` (all ``(6, 3)``), lengths ``a``, ``s`` and branches ``b``
    ``(6,)``: ``(θ, εθ, μ, εP)``, all ``(N, 6)`` (module notes); θ NaN where the rod does not
    close at the centre, εθ inf where the rod may fail to close in the cell."""
    p = np.asarray(p, float).reshape(-1, 3)
    R = np.asarray(R, float).reshape(-1, 3, 3)
    N = len(p)
    delta = np.broadcast_to(np.asarray(delta, float), (N,))[:, None]
    c = 2 * np.sin(0.5 * np.minimum(np.broadcast_to(np.asarray(alpha, float), (N,)),
                                    math.pi))[:, None]
    W = p[:, None, :] + np.einsum("nij,kj->nki", R, T) - B                 # (N, 6, 3)
    x = np.einsum("nki,ki->nk", W, u)
    y = np.einsum("nki,ki->nk", W, v)
    z = np.einsum("nki,ki->nk", W, n)
    r = np.hypot(x, y)
    dmin, dmax = np.hypot(z, r - a), np.hypot(z, r + a)
    eP = delta + c * np.linalg.norm(T, axis=1) + slack
    m1, m2 = s - dmin, dmax - s
    # the angle, by the IK kernel's formula (rss6 module docstring)
    E, F = 2 * a * x, 2 * a * y
    G = np.sum(W * W, axis=-1) + a * a - s * s
    h2 = E * E + F * F - G * G
    real = (m1 >= 0) & (m2 >= 0) & (h2 >= 0)
    h = np.sqrt(np.where(real, h2, 0.0))
    theta = np.where(real, np.arctan2(F * G + b * E * h, E * G - b * F * h), np.nan)
    ok = (m1 > eP) & (m2 > eP)
    with np.errstate(invalid="ignore", divide="ignore"):
        hmin = np.sqrt(np.where(ok, (m1 - eP) * (s + np.maximum(dmin - eP, 0.0))
                                * (m2 - eP) * (dmax - eP + s), np.nan))
        et = np.where(ok, 2 * s * eP / hmin * (1 + 1e-12) + 1e-12, np.inf)
    # the feasibility margin: distance bounds to the closing limits and the edge spheres
    lo, hi = window
    D = np.minimum(m1, m2)
    feasible = real.copy()
    if hi - lo < 2 * math.pi * (1 - 1e-15):
        for edge in (lo, hi):
            Ce = a[:, None] * (math.cos(edge) * u + math.sin(edge) * v)            # (6, 3)
            side = -b * (x * math.sin(edge) - y * math.cos(edge))   # distance to the half-space
            D = np.minimum(D, np.maximum(np.abs(np.linalg.norm(W - Ce, axis=-1) - s), side))
        with np.errstate(invalid="ignore"):
            feasible &= (theta >= lo) & (theta <= hi)
    D = np.where(real, D, -np.minimum(m1, m2))
    return theta, et, np.where(feasible, D, -D), np.broadcast_to(eP, m1.shape)


def crank_position_curvature(p, R, delta, B, T, u, v, n, a, s, b, slack):
    """Gradient ``g (N, 6, 3)`` of each crank angle in the position at ``(p, R)`` and a bound
    ``M (N, 6)`` on its second derivative over the ball ``|p' - p| <= δ`` (rotation fixed), so
    ``|θ(p') - θ(p) - g·(p' - p)| <= M·|p' - p|²/2``; ``inf`` where none is given.

    From ``f(θ, W) = |W - C(θ)|² - s² = 0`` (``d = W - C``): ``f_W = 2d``, ``f_θ = b·h``,
    ``f_WW = 2I``, ``f_Wθ = -2C'`` (``|C'| = a``), ``f_θθ = G`` (``|G| <= ρ = 2ar``), so
    ``g = -2d/(b·h)`` and ``D²θ = -(f_WW + f_Wθ gᵀ + g f_Wθᵀ + f_θθ g gᵀ)/f_θ``, of norm at most
    ``M = (2 + 4a·L + 2a·(r + δ)·L²)/h_min`` with ``L = 2s/h_min`` (module notes: ``h >=
    h_min`` on the ball where ``m1, m2 > δ``). Finite only there and where the angle cannot
    wrap across ±π on the ball (``|θ| + δ·L < π``), so that the wrapped angle is the smooth
    one."""
    theta, et, _, _ = crank_cell_terms(p, R, delta, 0.0, B, T, u, v, n, a, s, b,
                                       (-math.pi, math.pi), slack)
    p = np.asarray(p, float).reshape(-1, 3)
    R = np.asarray(R, float).reshape(-1, 3, 3)
    N = len(p)
    dl = np.broadcast_to(np.asarray(delta, float), (N,))[:, None] + slack
    W = p[:, None, :] + np.einsum("nij,kj->nki", R, T) - B
    x = np.einsum("nki,ki->nk", W, u)
    y = np.einsum("nki,ki->nk", W, v)
    z = np.einsum("nki,ki->nk", W, n)
    r = np.hypot(x, y)
    dmin, dmax = np.hypot(z, r - a), np.hypot(z, r + a)
    m1, m2 = s - dmin, dmax - s
    ok = (m1 > dl) & (m2 > dl) & np.isfinite(theta)
    with np.errstate(invalid="ignore", divide="ignore"):
        C = a[:, None] * (np.cos(theta)[..., None] * u + np.sin(theta)[..., None] * v)
        d = W - C
        h = np.sqrt(np.maximum((s - dmin) * (s + dmin) * (dmax - s) * (dmax + s), 0.0))
        g = -2 * d * (b / h)[..., None]
        hmin = np.sqrt(np.where(ok, (m1 - dl) * (s + np.maximum(dmin - dl, 0.0))
                                * (m2 - dl) * (dmax - dl + s), np.nan))
        L = 2 * s / hmin
        M = (2 + 4 * a * L + 2 * a * (r + dl) * L * L) / hmin
        ok &= np.abs(theta) + dl * L * (1 + 1e-9) < math.pi
        M = np.where(ok, M * (1 + 1e-9) + 1e-12, np.inf)
    return np.where(ok[..., None], g, 0.0), M
