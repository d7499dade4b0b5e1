"""Exact κ fused with the family's Jacobian: the κ maps, the GCI and the trajectory check
(issue 28 item 1).

:mod:`._fused` serves the worst case: the family's per-pose Jacobian and
:func:`~pkmlab.dexterity._linalg.sweep_one` in one numba loop. The other callers of the same
per-pose pass formed every Jacobian in NumPy first (``(N, 6, 6)`` arrays of tiled positions and
repeated rotations), homogenised a copy of it and took its singular values in a second pass:

* the export's κ maps (:func:`pkmlab.dexterity.maps.metric_map`): the certified κ bound of every
  unit × orientation, then the exact κ where the bound reaches the unit's maximum;
* the GCI (:func:`pkmlab.dexterity.kappa_grid`, :func:`~pkmlab.dexterity.gci_monte_carlo`):
  the exact κ of every pose;
* the trajectory check (:func:`pkmlab.motion.check_trajectory`: κ of every sample, and its
  Jacobian for the static forces; :func:`pkmlab.motion.trajectory_fit`: "singular?" from the
  bound, exact κ only where the bound cannot decide, as :func:`pkmlab.dexterity.sweep.singular`).

Here one loop does it per pose: the family's per-pose Jacobian (``_jac_one``, as in
:mod:`._fused`) into a scratch matrix, its homogenised copy (columns 3:6 divided by ``L``, the
operation of :func:`~pkmlab.dexterity.homogenised_jacobian`), the singular values by the same
inline one-sided Jacobi (:func:`._linalg._one`, which
:func:`~pkmlab.dexterity.singular_values` runs on a stack) and pkmlab's one singular rule
(:func:`~pkmlab.dexterity.metrics._kappa_from_sv`). The arithmetic of every pose is the
unfused path's, operation for operation, so κ is the same bit for bit (checked in
``tests/dexterity/test_fused_exact.py`` and ``benchmarks/bench_fused_callers.py``).

Served: the families :func:`._fused.fused_available` accepts (``psu6``, ``ups6``), while
:data:`FUSED` is True; the others keep the unfused path.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import prange
from numba import types as nt

from ..runtime.jit import cached_kernel, identity, jitable
from ..runtime.threads import threads_for
from ._fused import _TASK, fused_available, fused_sweep
from ._linalg import KAPPA_ROUND, _one, kappa_upper, sweep_one
from .metrics import KAPPA_SINGULAR, SINGULAR_RTOL, _as_length

__all__ = ["FUSED", "serves", "fused_kappa", "fused_kappa_grid", "fused_kappa_max",
           "fused_singular", "warm"]

#: use these kernels where :func:`._fused.fused_available`; False: the unfused NumPy path
#: everywhere (benchmarks and tests compare the two)
FUSED = True

#: :func:`._linalg.kappa_upper` of one bound, as scalars: above ``_KUP_FINITE`` unbounded,
#: else ``kup · _KUP_SAFE``
_KUP_FINITE = 1e8
_KUP_SAFE = 1.0 + KAPPA_ROUND

# kinds of pass of the kernel
_EXACT = 0          # exact κ of every pose
_SINGULAR = 1       # -1.0 where the certified bound rules out "singular", else the exact κ


def serves(mech) -> bool:
    """True when the κ maps, the GCI and the trajectory check of ``mech`` take these kernels."""
    return FUSED and fused_available(mech)


def _kappa_h(Jm, L, H, sv, A, d):
    """Exact κ of ``Jm (6, 6)`` homogenised with ``L``: ``H (1, 6, 6)``, ``sv (1, 6)``,
    ``A (6, 6)``, ``d (6,)`` scratch. :func:`~pkmlab.dexterity.condition_number`'s arithmetic:
    ``J[..., 3:] / L``, :func:`._linalg._one`, then ``σmax / σmin``, or inf where not finite
    or ``σmin <= SINGULAR_RTOL · σmax``."""
    for i in range(6):
        for k in range(6):
            H[0, i, k] = Jm[i, k] if k < 3 else Jm[i, k] / L
    _one(H, 0, sv, A, d, 6, 6)
    smax, smin = sv[0, 0], sv[0, 5]
    if math.isfinite(smax) and smin > SINGULAR_RTOL * smax:
        return smax / smin
    return np.inf


def _singular_bound(Jm, L, A, B, G, T, piv, ones):
    """True when the certified κ bound of :func:`._linalg.sweep_one` on ``Jm``, made safe as
    :func:`._linalg.kappa_upper` does, is below :data:`~pkmlab.dexterity.KAPPA_SINGULAR`
    (``Jm`` is certainly not singular)."""
    kup = sweep_one(Jm, L, ones, A, B, G, T, piv)[0]
    ku = np.inf if kup > _KUP_FINITE else kup * _KUP_SAFE
    return ku < KAPPA_SINGULAR


# The two helpers are compiled into each family's loop as functions of their own, not inlined
# (inlined, ``sweep_one`` alone took the loop's compile from 3.7 to 18.9 s of CPU; its LU and
# Gram bounds are now a function of their own everywhere, :func:`._linalg.sweep_core`), and not as
# ``njit(cache=True)`` functions: their cache would be keyed by this file only, and would keep
# stale code after an edit of ``_linalg``, which they inline. ``jitable`` names them after
# ``_HELPERS``, which covers both (and, through them, ``_linalg``).
_HELPERS = identity(_kappa_h, _singular_bound, extra=("fused-exact helpers",))
_kappa_h = jitable(_kappa_h, _HELPERS, error_model="numpy")
_singular_bound = jitable(_singular_bound, _HELPERS, error_model="numpy")


@cache
def _kernel(jac, ng: int):
    """The loop for the per-pose Jacobian ``jac`` and geometry tuples of ``ng`` floats, built by
    :func:`pkmlab.runtime.jit.cached_kernel` (named after all it compiles in).

    Pose ``i`` is ``(P[iu[u]], R[im[m]])``: ``u, m = i % U, i // U`` on the grid ``iu × im``
    when ``grid`` (``U = len(iu)``, orientation-major), else ``u = m = i`` (pairs). Its value goes
    to ``out[i]`` and, when ``jac_out`` has rows, its Jacobian to ``jac_out[i]``."""

    def fused_exact_loop(P, R, iu, im, grid, g, L, kind, out, jac_out):
        U = iu.shape[0]
        n = U * im.shape[0] if grid else U
        keep = jac_out.shape[0] > 0
        for task in prange((n + _TASK - 1) // _TASK):
            J = np.empty((1, 6, 6))
            H = np.empty((1, 6, 6))
            sv = np.empty((1, 6))
            A = np.empty((6, 6))
            B = np.empty((6, 6))
            G = np.empty((6, 6))
            T = np.empty((6, 6))
            d = np.empty(6)
            piv = np.empty(6, np.int64)
            q = np.empty((1, 6))
            ones = np.ones(6)
            for i in range(task * _TASK, min(n, (task + 1) * _TASK)):
                if grid:
                    u, m = iu[i % U], im[i // U]
                else:
                    u, m = iu[i], im[i]
                jac(P[u, 0], P[u, 1], P[u, 2], R[m, 0, 0], R[m, 0, 1], R[m, 0, 2],
                    R[m, 1, 0], R[m, 1, 1], R[m, 1, 2], R[m, 2, 0], R[m, 2, 1], R[m, 2, 2],
                    g, q, J, 0)
                if keep:
                    for r in range(6):
                        for c in range(6):
                            jac_out[i, r, c] = J[0, r, c]
                if kind == _SINGULAR and _singular_bound(J[0], L, A, B, G, T, piv, ones):
                    out[i] = -1.0                    # certified: not singular
                    continue
                out[i] = _kappa_h(J[0], L, H, sv, A, d)

    f1, i1 = nt.float64[::1], nt.int64[::1]
    return cached_kernel(fused_exact_loop,
                         nt.void(nt.float64[:, ::1], nt.float64[:, :, ::1], i1, i1, nt.boolean,
                                 nt.UniTuple(nt.float64, ng), nt.float64, nt.int64, f1,
                                 nt.float64[:, :, ::1]),
                         parallel=True, error_model="numpy")


def _run(mech, P, R, iu, im, grid: bool, L, kind: int, jacobians=None) -> np.ndarray:
    L = _as_length(L)                  # as condition_number: raises for a bad L, poses or not
    P = np.require(np.reshape(P, (-1, 3)), np.float64, ("C", "A", "W"))
    R = np.require(np.reshape(R, (-1, 3, 3)), np.float64, ("C", "A", "W"))
    iu = np.require(iu, np.int64, ("C", "A", "W"))
    im = np.require(im, np.int64, ("C", "A", "W"))
    n = len(iu) * len(im) if grid else len(iu)
    out = np.empty(n)
    J = np.empty((0, 6, 6)) if jacobians is None else jacobians
    if J.shape[0] not in (0, n) or J.dtype != np.float64 or not J.flags.c_contiguous:
        raise ValueError(f"jacobians: a C-contiguous float64 ({n}, 6, 6) array, got "
                         f"{J.dtype} {J.shape}")
    if n:
        jac, g = mech.jacobian_kernel()
        with threads_for(n):
            _kernel(jac, len(g))(P, R, iu, im, grid, g, L, kind, out, J)
    return out


def fused_kappa(mech, p, R, L, *, jacobians: np.ndarray | None = None) -> np.ndarray:
    """``(n,)`` :func:`~pkmlab.dexterity.condition_number` of ``mech.jacobian((p, R))`` (the
    poses ``p (n, 3)``, ``R (n, 3, 3)`` in pairs) with ``L`` (mm), bit for bit; the Jacobians
    go to ``jacobians (n, 6, 6)`` (C-contiguous float64) when it is given."""
    n = len(p)
    at = np.arange(n)
    return _run(mech, p, R, at, at, False, L, _EXACT, jacobians)


def fused_kappa_at(mech, P, R, iu, im, L) -> np.ndarray:
    """``(n,)`` the exact κ at the poses ``(P[iu[j]], R[im[j]])``."""
    return _run(mech, P, R, iu, im, False, L, _EXACT)


def fused_kappa_grid(mech, P, R, L) -> np.ndarray:
    """``(U, M)`` the exact κ at every position ``P (U, 3)`` × rotation ``R (M, 3, 3)`` (as
    :func:`fused_kappa` of the pairs; a transposed view of an orientation-major array)."""
    U, M = len(P), len(R)
    return _run(mech, P, R, np.arange(U), np.arange(M), True, L, _EXACT).reshape(M, U).T


def fused_singular(mech, p, R, L) -> np.ndarray:
    """``(n,)`` bool: :func:`pkmlab.dexterity.sweep.singular` of ``mech.jacobian((p, R))``
    with ``L``: the certified κ bound of :func:`._linalg.sweep_one` (made safe as
    :func:`._linalg.kappa_upper` does) decides where it is below
    :data:`~pkmlab.dexterity.KAPPA_SINGULAR`, the exact κ elsewhere."""
    n = len(p)
    at = np.arange(n)
    return ~np.isfinite(_run(mech, p, R, at, at, False, L, _SINGULAR))


def fused_kappa_max(mech, P, R, L) -> np.ndarray:
    """``(U,)`` the largest exact κ of every position ``P (U, 3)`` over the rotations
    ``R (M, 3, 3)``: :func:`pkmlab.dexterity.maps._unit_kappa_max`'s algorithm and values, bit
    for bit. The certified bound of every pose (:func:`._fused.fused_sweep`); each unit's exact
    κ at its largest bound; then the exact κ of the poses whose bound reaches it."""
    U, M = len(P), len(R)
    if U == 0 or M == 0:
        return np.full(U, -np.inf)
    kup = fused_sweep(mech, P, R, np.ones((U, M), dtype=bool), L, np.ones(6))[0]
    up = kappa_upper(kup.T)                                      # (M, U) as unfused
    kmax = fused_kappa_at(mech, P, R, np.arange(U), np.argmax(up, axis=0), L)
    cand = np.argwhere(up >= kmax)                               # (orientation, unit)
    if len(cand):
        np.maximum.at(kmax, cand[:, 1], fused_kappa_at(mech, P, R, cand[:, 1], cand[:, 0], L))
    return kmax


def warm(mech) -> None:
    """Compile (or load) the kernel of ``mech``'s family, and :mod:`._fused`'s worst-case loop
    that :func:`fused_kappa_max` takes (the study warm-up, :func:`pkmlab.study.warm`)."""
    if not fused_available(mech):
        return
    p = np.asarray(mech.nominal_pose[:3], dtype=float)[None]
    R = np.eye(3)[None]
    fused_kappa_max(mech, p, R, 100.0)
    fused_singular(mech, p, R, 100.0)
