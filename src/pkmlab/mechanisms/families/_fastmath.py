"""``atan2`` that LLVM can vectorise, for the families' inverse-kinematics kernels.

fdlibm's algorithm (Sun Microsystems, 1993; s_atan.c, e_atan2.c): with ``t = min(|x|, |y|) /
max(|x|, |y|)`` in [0, 1], ``atan(t) = π/4 + atan((t - 1)/(t + 1))`` for ``t > tan(π/8)``, so
the polynomial argument stays within ±tan(π/8) < 7/16, where fdlibm's degree-22 odd minimax
polynomial holds; then the octant is restored. Written with conditional expressions only (no
branches, no integer conversions), so a loop over poses becomes SIMD code instead of one libm
call per value. Accuracy against ``math.atan2`` is checked in ``tests/test_fivebar.py``.
"""

from __future__ import annotations

from numba import njit

_AT0, _AT1, _AT2 = 3.33333333333329318027e-01, -1.99999999998764832476e-01, \
    1.42857142725034663711e-01
_AT3, _AT4, _AT5 = -1.11111104054623557880e-01, 9.09088713343650656196e-02, \
    -7.69187620504482999495e-02
_AT6, _AT7, _AT8 = 6.66107313738753120669e-02, -5.83357013379057348645e-02, \
    4.97687799461593236017e-02
_AT9, _AT10 = -3.65315727442169155270e-02, 1.62858201153657823623e-02
_PIO4_HI, _PIO4_LO = 7.85398163397448278999e-01, 3.06161699786838301793e-17
_PIO2_HI, _PIO2_LO = 1.57079632679489655800e+00, 6.12323399573676603587e-17
_PI_HI, _PI_LO = 3.14159265358979311600e+00, 1.22464679914735317720e-16
_TAN_PI8 = 0.41421356237309503


@njit(cache=True, forceinline=True)
def atan2(y, x):
    """``math.atan2(y, x)`` for finite inputs, in (-π, π]; 0 at (0, 0)."""
    ax, ay = abs(x), abs(y)
    big = max(ax, ay)
    t = min(ax, ay) / big if big > 0.0 else 0.0
    shift = t > _TAN_PI8
    u = (t - 1.0) / (t + 1.0) if shift else t
    z = u * u
    w = z * z
    s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
    s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
    r = u - (u * (s1 + s2) - _PIO4_LO) + _PIO4_HI if shift else u - u * (s1 + s2)
    r = (_PIO2_HI - (r - _PIO2_LO)) if ay > ax else r
    r = (_PI_HI - (r - _PI_LO)) if x < 0.0 else r
    return -r if y < 0.0 else r
