"""The per-leg helpers are ``njit(forceinline=True)`` (issue 28, session 6): numba compiles
each once and LLVM inlines it, instead of numba's ``inline="always"`` copying and re-typing it
at every call site. The legs loop must still vectorise: stage 2 of the IK drivers on the
generic six-crank function (``sixleg_ik._crank_one``: six ``_crank`` legs, each calling
``rss6._rss_leg`` and ``rss6._atan2``) compiles to packed division and square root. With the
helpers of ``rss6`` and ``sixleg_ik`` plain ``njit`` (no ``forceinline``), LLVM leaves them
calls, the loop is scalar (``divsd``, ``sqrtsd``) and this test fails (checked)."""

from __future__ import annotations

import numpy as np
from numba import njit

from pkmlab.mechanisms.families import sixleg_ik
from pkmlab.mechanisms.kernels import ik

NG = 6 * sixleg_ik.L
_legs = ik._legs(sixleg_ik._crank_one, NG)


@njit(error_model="numpy")
def _stage2(T, w, g, qmin, qmax, q, st):
    _legs(T, w, g, qmin, qmax, q, st)


def test_the_six_crank_legs_loop_vectorises_with_its_helpers_inlined():
    w = ik.LANES
    rng = np.random.default_rng(0)
    T = rng.uniform(-1, 1, 12 * ik.ROW)
    g = tuple(rng.uniform(-1, 1, NG).tolist())
    q, st = np.full(7 * ik.ROW, np.nan), np.zeros(7 * ik.ROW, np.int8)
    _stage2(T, w, g, -1.0, 1.0, q, st)
    asm = "\n".join(_stage2.inspect_asm().values())
    assert "divpd" in asm and "sqrtpd" in asm, "the crank legs loop is not vectorised"
    # the loop computes what one leg computes alone, pose by pose
    for j in range(0, w, 7):
        x = tuple(T[r * ik.ROW + j] for r in range(12))
        for i in range(6):
            v, s = sixleg_ik._crank(x, g, i * sixleg_ik.L, -1.0, 1.0)
            assert s == st[i * ik.ROW + j]
            assert (np.isnan(v) and np.isnan(q[i * ik.ROW + j])) or v == q[i * ik.ROW + j]
