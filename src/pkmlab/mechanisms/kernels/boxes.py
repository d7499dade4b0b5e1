"""Interval arithmetic for the families' box Jacobians (``_jac_box``, issue 28 item 2).

A family may set the class attribute ``_jac_box`` (psu6 and ups6 do; read by
:func:`pkmlab.dexterity._cells.cells_available`, absent means no cell bounds) to a numba
function ``_jac_box(plo, phi, Rlo, Rhi, g, Jlo, Jhi)``, with ``g`` the IK geometry of its
``_jac_one``, that encloses its Jacobian ``J(p, R)``
over every position ``plo <= p <= phi`` and rotation whose entries lie in ``Rlo <= R <= Rhi``
(entrywise): ``Jlo <= J <= Jhi``. It returns False when it cannot (a link may become
horizontal in the box, a leg may have no real solution): the caller then evaluates pose by
pose. The intervals here are evaluated in round-to-nearest; :func:`widen` then adds a stated
allowance that covers the rounding of the enclosure *and* of the per-pose kernel's own
evaluation of ``J`` (see there), so that the float Jacobian the per-pose pass computes at a
pose in the box lies in ``[Jlo, Jhi]``.
"""

from __future__ import annotations

from numba.extending import register_jitable

__all__ = ["imul", "isq", "iscale", "irot", "widen", "ROUND_REL"]

#: relative allowance added to each enclosure bound by :func:`widen` (times ``1 + |bound|``):
#: covers the round-off of a few tens of float operations on quantities of size up to
#: ``1e4`` (mm) divided by a leg quantity that the box Jacobians require to be at least
#: ``1e-2`` of the leg's size: ``≲ 40 · 2⁻⁵³ · 1e4 ≈ 1e-10``, ten times below it
ROUND_REL = 1e-9


@register_jitable(inline="always")
def imul(a0, a1, b0, b1):
    """``[a0, a1] · [b0, b1]``."""
    p, q, r, s = a0 * b0, a0 * b1, a1 * b0, a1 * b1
    return min(min(p, q), min(r, s)), max(max(p, q), max(r, s))


@register_jitable(inline="always")
def isq(a0, a1):
    """``{x² : a0 <= x <= a1}``."""
    if a0 >= 0.0:
        return a0 * a0, a1 * a1
    if a1 <= 0.0:
        return a1 * a1, a0 * a0
    return 0.0, max(a0 * a0, a1 * a1)


@register_jitable(inline="always")
def iscale(c, a0, a1):
    """``c · [a0, a1]`` for a float ``c``."""
    return (c * a0, c * a1) if c >= 0.0 else (c * a1, c * a0)


@register_jitable(inline="always")
def irot(Rlo, Rhi, c, ux, uy, uz):
    """Row ``c`` of ``R · u`` for ``Rlo <= R <= Rhi`` (entrywise) and a float vector ``u``."""
    lo0, hi0 = iscale(ux, Rlo[c, 0], Rhi[c, 0])
    lo1, hi1 = iscale(uy, Rlo[c, 1], Rhi[c, 1])
    lo2, hi2 = iscale(uz, Rlo[c, 2], Rhi[c, 2])
    return lo0 + lo1 + lo2, hi0 + hi1 + hi2


@register_jitable(inline="always")
def widen(lo, hi):
    """``[lo, hi]`` widened by :data:`ROUND_REL` · ``(1 + |bound|)`` on each side."""
    return lo - ROUND_REL * (1.0 + abs(lo)), hi + ROUND_REL * (1.0 + abs(hi))
