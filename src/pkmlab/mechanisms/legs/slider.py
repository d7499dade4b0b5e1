"""Exact feasible z interval of a slider leg on an inclined or horizontal rail, on a column.

Leg model (as :mod:`.sixleg`): a slider at ``S = B + q·e`` on a rail of unit axis ``e`` with
``k = e_x² + e_y² > 0`` (not vertical), a link of length ``l`` to the platform joint ``W``,
branch ``b = ±1`` (``q = d·e + b·h``, ``h = sqrt(l² − |d − (d·e)e|²)``, ``d = W − B``) and a
working-mode side ``s = ±1``: the link's vertical component ``a_z = t − q·e_z`` (``a = d − q e``)
has the sign ``s``. On the column (x, y) at a fixed orientation ``d = (X, Y, t)`` with
``X = x + w_x``, ``Y = y + w_y``, ``t = z + w_z`` (``w`` the engine's leg offset).

The pairs ``(t, q)`` with ``|d(t) − q e| = l`` form an ellipse (two lines, one a column, one a
rail, not parallel). Its branch-``b`` half is the graph ``q(t)`` the IK returns, and along it
``dq/dt = −b·a_z/h``: ``q`` is monotone on each working-mode side. The line ``a_z = 0`` meets
the ellipse at its two q-extremes (the link horizontal), the roots of

    k q² − 2 c0 q + ρ² − l² = 0,   c0 = X e_x + Y e_y,  ρ² = X² + Y²,

whose discriminant ``Δ = c0² − k(ρ² − l²)`` is that of the ellipse's t-extent (``h = 0``),
so ``Δ < 0`` means the column misses the leg entirely. The feasible arc, branch ``b`` on
side ``s``, is the quarter ellipse from the q-extreme of branch ``b``, ``q_c = (c0 + b√Δ)/k``,
to the t-extreme on side ``s``, where ``q_e = (c0 + s·e_z·√Δ)/k``; ``q`` is monotone on it.
So the leg's feasible set on the column is one interval: ``q`` clamped to
``[min(q_c, q_e), max(q_c, q_e)] ∩ [q_min, q_max]``, mapped to ``t`` on side ``s`` by

    t(q) = q·e_z + s·sqrt(l² − (X − q e_x)² − (Y − q e_y)²)

(monotone on the arc; at the arc's own ends, where the root vanishes, ``t = q_c e_z`` and
``t_e = (c0 e_z + s·√Δ)/k`` are used instead), and ``z = t − w_z``. Vertical rails
(``k = 0``) have the closed-form linear interval of :mod:`.sixleg`; rails with ``k < K_MIN``
are not handled here (the ``1/k`` terms lose precision) and the family samples them.
"""

from __future__ import annotations

import math

from numba.extending import register_jitable

__all__ = ["slider_interval", "K_MIN"]

#: smallest ``e_x² + e_y²`` of a rail handled exactly (about 0.0018° from vertical)
K_MIN = 1e-9


@register_jitable
def slider_interval(X, Y, wz, ex, ey, ez, l, b, s, qmin, qmax):
    """Feasible z interval ``(z_lo, z_hi, ok)`` of one inclined-rail slider leg on a column
    (module docstring): ``(X, Y)`` the platform joint's horizontal offset from the slider zero
    ``B``, ``wz`` its vertical offset at z = 0, ``e`` the unit rail axis (``k >= K_MIN``),
    ``l`` the link length, ``b`` the branch, ``s`` the working-mode side, ``[qmin, qmax]`` the
    stroke window (mm)."""
    k = ex * ex + ey * ey
    c0 = X * ex + Y * ey
    disc = c0 * c0 - k * (X * X + Y * Y - l * l)
    if disc < 0.0:
        return math.inf, -math.inf, False
    sq = math.sqrt(disc)
    qc = (c0 + b * sq) / k
    qe = (c0 + s * ez * sq) / k
    qa = max(qmin, min(qc, qe))
    qb = min(qmax, max(qc, qe))
    if qa > qb:
        return math.inf, -math.inf, False
    te = (c0 * ez + s * sq) / k
    ta = _t_of(qa, qc, qe, te, X, Y, ex, ey, ez, l, s)
    tb = _t_of(qb, qc, qe, te, X, Y, ex, ey, ez, l, s)
    return min(ta, tb) - wz, max(ta, tb) - wz, True


@register_jitable
def _t_of(q, qc, qe, te, X, Y, ex, ey, ez, l, s):
    """``t(q)`` on the arc; at the arc's own ends in closed form (the link horizontal at
    ``q_c``: ``t = q_c e_z``; ``h = 0`` at ``q_e``: ``t_e = (c0 e_z + s√Δ)/k``), where the
    general form's square root of a rounded zero would cost ~√ε·l."""
    if q == qc:
        return qc * ez
    if q == qe:
        return te
    r = l * l - (X - q * ex) ** 2 - (Y - q * ey) ** 2
    return q * ez + s * math.sqrt(r if r > 0.0 else 0.0)
