"""Inverse kinematics kernels of the generic six-leg family (:mod:`.sixleg`), one per leg kind.

Every leg is one of three kinds, and each kind has its own per-leg kernel:

* prismatic: :func:`.ups6._ups_leg`, the kernel of ``ups6``;
* slider: :func:`_slider_leg` (any rail direction; ``psu6`` has vertical rails only);
* crank: :func:`.rss6._rss_leg`, the kernel of ``rss6``.

The per-pose functions (:mod:`..kernels.ik`) are chosen per instance by the kinds its legs have
(:func:`ik_function`), so a leg only computes its own kind's formula:

* every leg of one kind: :func:`_prismatic_one`, :func:`_slider_one`, :func:`_crank_one`;
* prismatic legs mixed with sliders: :func:`_linear_one` (both linear kernels, the declared one
  selected per leg; cranks cannot mix with linear legs, see :mod:`.sixleg`).

:func:`_sixleg_one` evaluates all three kinds and selects the declared one: the family's class
kernel (``SixLeg._ik_one``), correct for any instance. All of them give bit-identical results
for a leg of a given kind, since they call the same per-leg kernel.

Geometry tuple ``g``: :data:`L` floats per leg, at offset ``o = L·i``: B 0-2, tool point 3-5,
kind 6, slider ``e`` / crank ``2a·u`` 7-9, crank ``2a·v`` 10-12, slider ``l²`` / crank ``a² -
s²`` 13, slider side / crank degenerate threshold on ρ² 14, branch (prismatic: side) 15. (The
drivers take at most 100 floats: numba's parfor tuple limit.)
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ..kernels import ik as _kernels
from .rss6 import _rss_leg
from .ups6 import _ups_leg

__all__ = ["L", "ik_function"]

#: floats per leg in the IK geometry tuple
L = 16


@njit(cache=True, forceinline=True)
def _slider_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, bx, by, bz, tx, ty, tz,
                ex, ey, ez, l2, side, b, qmin, qmax):
    """One slider leg: ``(q, status)``, ``q = d·e + b·h`` with ``h = sqrt(l² - |d⊥|²)`` (NaN
    and ``NO_SOLUTION`` where ``h² < 0``); ``OTHER_MODE`` when the link's vertical component
    has the sign opposite to ``side``."""
    dx = px + r00 * tx + r01 * ty + r02 * tz - bx
    dy = py + r10 * tx + r11 * ty + r12 * tz - by
    dz = pz + r20 * tx + r21 * ty + r22 * tz - bz
    t = dx * ex + dy * ey + dz * ez
    nx, ny, nz = dx - t * ex, dy - t * ey, dz - t * ez
    h2 = l2 - (nx * nx + ny * ny + nz * nz)
    real = h2 >= 0.0
    qs = t + b * math.sqrt(h2 if real else 0.0)
    az = nz - b * math.sqrt(h2 if real else 0.0) * ez        # vertical part of the link
    ss = (_kernels.OTHER_MODE if az * side < 0.0 else
          _kernels.stroke_status(qs, qmin, qmax)) if real else _kernels.NO_SOLUTION
    return (qs if real else np.nan), ss


@njit(cache=True, forceinline=True)
def _prismatic(x, g, o, qmin, qmax):
    """Leg at offset ``o`` of ``g``, prismatic, at the pose ``x = (px, py, pz, r00, ..., r22)``."""
    px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22 = x
    return _ups_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[o], g[o + 1], g[o + 2], g[o + 3], g[o + 4], g[o + 5], g[o + 15], qmin, qmax)


@njit(cache=True, forceinline=True)
def _slider(x, g, o, qmin, qmax):
    px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22 = x
    return _slider_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                       g[o], g[o + 1], g[o + 2], g[o + 3], g[o + 4], g[o + 5], g[o + 7],
                       g[o + 8], g[o + 9], g[o + 13], g[o + 14], g[o + 15], qmin, qmax)


@njit(cache=True, forceinline=True)
def _crank(x, g, o, qmin, qmax):
    px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22 = x
    return _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[o], g[o + 1], g[o + 2], g[o + 3], g[o + 4], g[o + 5], g[o + 7], g[o + 8],
                    g[o + 9], g[o + 10], g[o + 11], g[o + 12], g[o + 13], g[o + 14], g[o + 15],
                    qmin, qmax)


@njit(cache=True, forceinline=True)
def _linear(x, g, o, qmin, qmax):
    """Prismatic or slider, as declared (both evaluated, the declared one selected)."""
    vp, cp = _prismatic(x, g, o, qmin, qmax)
    vs, cs = _slider(x, g, o, qmin, qmax)
    prism = g[o + 6] == 0.0
    return (vp if prism else vs), (cp if prism else cs)


@njit(cache=True, forceinline=True)
def _any(x, g, o, qmin, qmax):
    """Any kind, as declared (the three evaluated, the declared one selected)."""
    vp, cp = _prismatic(x, g, o, qmin, qmax)
    vs, cs = _slider(x, g, o, qmin, qmax)
    vc, cc = _crank(x, g, o, qmin, qmax)
    kind = g[o + 6]
    return ((vp if kind == 0.0 else (vs if kind == 1.0 else vc)),
            (cp if kind == 0.0 else (cs if kind == 1.0 else cc)))


@njit(cache=True, forceinline=True)
def _put(q, st, i, j, vc):
    k = i * _kernels.ROW + j
    q[k] = vc[0]
    st[k] = vc[1]


# The per-pose functions call their leg kernel six times with constant offsets (unrolled by
# hand, as rss6's: a loop over legs with a large body is not unrolled by LLVM, and ``g`` would
# then be indexed by a variable).
@register_jitable(inline="always")
def _prismatic_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q,
                   st, j):
    """Per-pose inverse kinematics (see :mod:`..kernels.ik`), every leg prismatic."""
    x = (px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22)
    _put(q, st, 0, j, _prismatic(x, g, 0, qmin, qmax))
    _put(q, st, 1, j, _prismatic(x, g, L, qmin, qmax))
    _put(q, st, 2, j, _prismatic(x, g, 2 * L, qmin, qmax))
    _put(q, st, 3, j, _prismatic(x, g, 3 * L, qmin, qmax))
    _put(q, st, 4, j, _prismatic(x, g, 4 * L, qmin, qmax))
    _put(q, st, 5, j, _prismatic(x, g, 5 * L, qmin, qmax))


@register_jitable(inline="always")
def _slider_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
                j):
    """Per-pose inverse kinematics, every leg a slider."""
    x = (px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22)
    _put(q, st, 0, j, _slider(x, g, 0, qmin, qmax))
    _put(q, st, 1, j, _slider(x, g, L, qmin, qmax))
    _put(q, st, 2, j, _slider(x, g, 2 * L, qmin, qmax))
    _put(q, st, 3, j, _slider(x, g, 3 * L, qmin, qmax))
    _put(q, st, 4, j, _slider(x, g, 4 * L, qmin, qmax))
    _put(q, st, 5, j, _slider(x, g, 5 * L, qmin, qmax))


@register_jitable(inline="always")
def _crank_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
               j):
    """Per-pose inverse kinematics, every leg a crank."""
    x = (px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22)
    _put(q, st, 0, j, _crank(x, g, 0, qmin, qmax))
    _put(q, st, 1, j, _crank(x, g, L, qmin, qmax))
    _put(q, st, 2, j, _crank(x, g, 2 * L, qmin, qmax))
    _put(q, st, 3, j, _crank(x, g, 3 * L, qmin, qmax))
    _put(q, st, 4, j, _crank(x, g, 4 * L, qmin, qmax))
    _put(q, st, 5, j, _crank(x, g, 5 * L, qmin, qmax))


@register_jitable(inline="always")
def _linear_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
                j):
    """Per-pose inverse kinematics, prismatic legs mixed with sliders."""
    x = (px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22)
    _put(q, st, 0, j, _linear(x, g, 0, qmin, qmax))
    _put(q, st, 1, j, _linear(x, g, L, qmin, qmax))
    _put(q, st, 2, j, _linear(x, g, 2 * L, qmin, qmax))
    _put(q, st, 3, j, _linear(x, g, 3 * L, qmin, qmax))
    _put(q, st, 4, j, _linear(x, g, 4 * L, qmin, qmax))
    _put(q, st, 5, j, _linear(x, g, 5 * L, qmin, qmax))


@register_jitable(inline="always")
def _sixleg_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
                j):
    """Per-pose inverse kinematics of any instance: the three kinds evaluated per leg and the
    declared one selected (no branches on the kind)."""
    x = (px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22)
    _put(q, st, 0, j, _any(x, g, 0, qmin, qmax))
    _put(q, st, 1, j, _any(x, g, L, qmin, qmax))
    _put(q, st, 2, j, _any(x, g, 2 * L, qmin, qmax))
    _put(q, st, 3, j, _any(x, g, 3 * L, qmin, qmax))
    _put(q, st, 4, j, _any(x, g, 4 * L, qmin, qmax))
    _put(q, st, 5, j, _any(x, g, 5 * L, qmin, qmax))


def ik_function(kinds: np.ndarray):
    """The per-pose function for legs of kind codes ``kinds`` (0 prismatic, 1 slider, 2 crank):
    the one-kind kernel when all legs share a kind, :func:`_linear_one` for prismatic legs mixed
    with sliders, else :func:`_sixleg_one`."""
    present = set(np.asarray(kinds, dtype=float).tolist())
    if present == {0.0}:
        return _prismatic_one
    if present == {1.0}:
        return _slider_one
    if present == {2.0}:
        return _crank_one
    if present == {0.0, 1.0}:
        return _linear_one
    return _sixleg_one
