"""Vectorised interval arithmetic with outward rounding (NumPy), for guaranteed enclosures of
closed-form kinematic chains over boxes of coordinates (the 3-PRS volume bracket,
:mod:`pkmlab.workspaces.tripod`).

An :class:`Iv` holds arrays ``lo <= hi`` (any common shape): every real value the enclosed
quantity takes is in ``[lo, hi]``. Each operation returns an enclosure of the exact result:

* ``+``, ``-``, ``*`` and ``sqrt`` are correctly rounded in IEEE double, so moving each
  computed end one ulp outwards (``numpy.nextafter``) encloses the exact result;
* ``sin``, ``cos``, ``atan``, ``acos`` come from the platform's libm, accurate to about one ulp
  but not correctly rounded: their ends are moved :data:`LIBM_ULPS` ulps outwards.

Constants (floats) are taken as exact. Intervals are the natural extension: a variable that
appears twice is enclosed twice independently (the dependency effect), so enclosures are
wider than the range; they shrink linearly with the box width, which is what subdivision
relies on.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["Iv", "LIBM_ULPS", "hull", "widen"]

#: outward ulps added to the ends of libm functions (sin, cos, atan, acos; ≤ 1 ulp error on
#: glibc's double functions, margin ×4)
LIBM_ULPS = 4
_INF = math.inf


def _dn(x, k=1):
    for _ in range(k):
        x = np.nextafter(x, -_INF)
    return x


def _up(x, k=1):
    for _ in range(k):
        x = np.nextafter(x, _INF)
    return x


class Iv:
    """An interval array (module docstring)."""

    __slots__ = ("lo", "hi")

    def __init__(self, lo, hi=None):
        lo = np.asarray(lo, dtype=float)
        self.lo = lo
        self.hi = lo if hi is None else np.asarray(hi, dtype=float)

    # ---- arithmetic --------------------------------------------------------------------------
    def __add__(self, o):
        o = _as(o)
        return Iv(_dn(self.lo + o.lo), _up(self.hi + o.hi))

    __radd__ = __add__

    def __sub__(self, o):
        o = _as(o)
        return Iv(_dn(self.lo - o.hi), _up(self.hi - o.lo))

    def __rsub__(self, o):
        return _as(o) - self

    def __neg__(self):
        return Iv(-self.hi, -self.lo)

    def __mul__(self, o):
        if np.isscalar(o):
            c = float(o)
            a, b = self.lo * c, self.hi * c
            return Iv(_dn(np.minimum(a, b)), _up(np.maximum(a, b)))
        o = _as(o)
        p = (self.lo * o.lo, self.lo * o.hi, self.hi * o.lo, self.hi * o.hi)
        lo = np.minimum(np.minimum(p[0], p[1]), np.minimum(p[2], p[3]))
        hi = np.maximum(np.maximum(p[0], p[1]), np.maximum(p[2], p[3]))
        return Iv(_dn(lo), _up(hi))

    __rmul__ = __mul__

    def sq(self) -> Iv:
        """``x²`` (tighter than ``x*x``: one variable)."""
        a, b = self.lo * self.lo, self.hi * self.hi
        lo = np.where((self.lo <= 0) & (self.hi >= 0), 0.0, np.minimum(a, b))
        return Iv(np.maximum(_dn(lo), 0.0), _up(np.maximum(a, b)))

    def sqrt(self) -> Iv:
        """``√x`` over the non-negative part (negative ends clipped to 0)."""
        return Iv(np.maximum(_dn(np.sqrt(np.maximum(self.lo, 0.0))), 0.0),
                  _up(np.sqrt(np.maximum(self.hi, 0.0))))

    def recip(self) -> Iv:
        """``1/x`` for intervals not containing 0 (others give ``[-inf, inf]``)."""
        ok = (self.lo > 0) | (self.hi < 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            lo = np.where(ok, _dn(1.0 / self.hi), -_INF)
            hi = np.where(ok, _up(1.0 / self.lo), _INF)
        return Iv(lo, hi)

    def __truediv__(self, o):
        return self * _as(o).recip()

    # ---- elementary functions ----------------------------------------------------------------
    def cos(self) -> Iv:
        """``cos x`` for any interval: the ends, widened by the maxima/minima inside."""
        lo, hi = self.lo, self.hi
        ca, cb = np.cos(lo), np.cos(hi)
        low, high = np.minimum(ca, cb), np.maximum(ca, cb)
        # a maximum (2kπ) or minimum ((2k+1)π) strictly inside the interval
        k_max = np.ceil(lo / (2 * math.pi))
        has_max = k_max * 2 * math.pi <= hi
        k_min = np.ceil((lo - math.pi) / (2 * math.pi))
        has_min = k_min * 2 * math.pi + math.pi <= hi
        wide = (hi - lo) >= 2 * math.pi
        high = np.where(has_max | wide, 1.0, _up(high, LIBM_ULPS))
        low = np.where(has_min | wide, -1.0, _dn(low, LIBM_ULPS))
        return Iv(np.maximum(low, -1.0), np.minimum(high, 1.0))

    def sin(self) -> Iv:
        """``sin x = cos(x - π/2)`` (the shift enclosed)."""
        return (self - _HALF_PI).cos()

    def atan(self) -> Iv:
        return Iv(_dn(np.arctan(self.lo), LIBM_ULPS), _up(np.arctan(self.hi), LIBM_ULPS))

    def acos(self) -> Iv:
        """``acos x`` over the part in ``[-1, 1]`` (ends clipped)."""
        lo = np.clip(self.lo, -1.0, 1.0)
        hi = np.clip(self.hi, -1.0, 1.0)
        return Iv(np.maximum(_dn(np.arccos(hi), LIBM_ULPS), 0.0),
                  np.minimum(_up(np.arccos(lo), LIBM_ULPS), _up(math.pi, 2)))

    def __getitem__(self, k):
        return Iv(self.lo[k], self.hi[k])

    def __repr__(self):
        return f"Iv({self.lo!r}, {self.hi!r})"


#: π/2 as an interval (the double nearest π/2 is within one ulp of it)
_HALF_PI = Iv(_dn(math.pi / 2), _up(math.pi / 2))


def _as(o) -> Iv:
    return o if isinstance(o, Iv) else Iv(o, o)


def hull(a: Iv, b: Iv, where) -> Iv:
    """``a`` where ``where`` is False, the hull of ``a`` and ``b`` where it is True."""
    return Iv(np.where(where, np.minimum(a.lo, b.lo), a.lo),
              np.where(where, np.maximum(a.hi, b.hi), a.hi))


def widen(a: Iv, by) -> Iv:
    """``a`` widened by ``by`` (>= 0) on both sides."""
    return Iv(_dn(a.lo - by), _up(a.hi + by))
