"""Second-order volume bounds inside an undecided cube of the cell bracket
(:mod:`.bracket_cells`), at one rotation (a *sample*).

For a family with ``leg_position_curvature`` (luzi3), leg ``j`` at the sample satisfies
``|q_j(c + x) - q_j(c) - g_j·x| <= ρ = M_j·δ²/2`` on the cube ``c + [-s, s]³`` (δ = √3·s its
half-diagonal). So, with ``m⁺ = qmax - q_j(c)`` and ``m⁻ = q_j(c) - qmin``, the cube's
stroke-feasible part at that rotation

* contains ``{x : g_j·x <= m⁺ - ρ and -g_j·x <= m⁻ - ρ for every j}`` (convex), whose volume is
  at least ``1 - Σ`` (the fractions outside each of the 12 half-spaces) of the cube's;
* lies in ``{g_j·x <= m⁺ + ρ, -g_j·x <= m⁻ + ρ}``: at most the smallest of those 12 fractions.

The fraction of a cube in a half-space ``g·x <= c`` is the distribution function of a sum of
three uniform variables (:func:`cube_fraction`), in closed form: ``Σ_σ (-1)^|σ| (c + Σa -
2σ·a)₊³ / (48·a1·a2·a3)`` over the vertices σ ∈ {0, 1}³, ``a_i = |g_i|·s``. Widths below
``τ = 1e-3·max a_i`` are raised to τ (the sum then moves by at most ``Σ(τ - a_i)₊``, by which
``c`` is shifted outwards), and the fraction is widened by 1e-6 against rounding.
"""

from __future__ import annotations

import numpy as np

__all__ = ["cube_fraction", "sample_fractions", "vertices"]

_SIGMA = np.array(np.meshgrid(*[(0.0, 1.0)] * 3, indexing="ij")).reshape(3, -1).T   # (8, 3)
_VERT = 2 * _SIGMA - 1                                                              # (8, 3)
_ROUND = 1e-6


def _cdf(a, c):
    """Fraction of the box ``Π[-a_i, a_i]`` with ``Σ x_i <= c``; ``a (..., 3) > 0``."""
    sign = (-1.0) ** _SIGMA.sum(axis=1)                                            # (8,)
    z = c[..., None] + a.sum(axis=-1)[..., None] - 2 * (a @ _SIGMA.T)             # (..., 8)
    v = (np.maximum(z, 0.0) ** 3 * sign).sum(axis=-1) / (48 * a.prod(axis=-1))
    return np.clip(v, 0.0, 1.0)


def cube_fraction(g, c, s):
    """``(lower, upper)`` bounds on the fraction of the cube ``[-s, s]³`` where ``g·x <= c``
    (``g (..., 3)``, ``c (...)``, ``s`` broadcastable to ``c``)."""
    a = np.abs(g) * np.asarray(s, float)[..., None]
    tau = np.maximum(1e-3 * a.max(axis=-1), 1e-12 * np.asarray(s, float))
    shift = np.maximum(tau[..., None] - a, 0.0).sum(axis=-1)
    af = np.maximum(a, tau[..., None])
    return (np.maximum(_cdf(af, c - shift) - _ROUND, 0.0),
            np.minimum(_cdf(af, c + shift) + _ROUND, 1.0))


def sample_fractions(q, g, M, s, stroke):
    """Per sample (``q (K, 6)``, ``g (K, 6, 3)``, ``M (K, 6)``, cube half-edge ``s (K,)``):
    ``(inner fraction lower bound (K,), outer fraction upper bound (K,), vertices (K, 8)``
    of the cube that lie in the inner region)."""
    lo_q, hi_q = stroke
    rho = 0.5 * M * 3.0 * (s * s)[:, None]                                        # (K, 6)
    fin = np.all(np.isfinite(rho), axis=1)
    rho = np.where(np.isfinite(rho), rho, 0.0)
    sq = np.broadcast_to(s[:, None], q.shape)
    m_hi, m_lo = hi_q - q, q - lo_q
    miss = np.zeros(len(q))
    up = np.ones(len(q))
    for sgn, m in ((1.0, m_hi), (-1.0, m_lo)):
        lo_in, _ = cube_fraction(sgn * g, m - rho, sq)
        _, hi_out = cube_fraction(sgn * g, m + rho, sq)
        miss += (1.0 - lo_in).sum(axis=1)
        up = np.minimum(up, hi_out.min(axis=1))
    gx = np.einsum("kjd,vd->kjv", g, _VERT) * s[:, None, None]                     # (K, 6, 8)
    vert = np.all((gx <= (m_hi - rho)[..., None]) & (-gx <= (m_lo - rho)[..., None]), axis=1)
    inner = np.where(fin, np.maximum(1.0 - miss, 0.0), 0.0)
    return inner, np.where(fin, up, 1.0), vert & fin[:, None]


def vertices(centres, s):
    """``(K, 8, 3)`` vertices of the cubes, in the order of :func:`sample_fractions`."""
    return centres[:, None, :] + _VERT[None] * np.asarray(s, float)[:, None, None]
