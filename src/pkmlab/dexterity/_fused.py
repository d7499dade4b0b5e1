"""The worst case's per-pose pass fused with the family's Jacobian (issue 28 item 1).

:func:`pkmlab.dexterity.worst_case` needs, for every feasible (unit, orientation) pose, the
certified κ bound, the all-direction force and ``det J``
(:func:`pkmlab.dexterity._linalg.sweep_bounds`). Done in NumPy, every pose's Jacobian is
written to a ``(N, 6, 6)`` array (positions tiled and rotations repeated first), read back by
the LU pass, and its outputs masked by the feasibility and transposed. Here one numba loop
does it per pose: the family's per-pose Jacobian (``_jac_one``, the same inline function the
Jacobian driver calls, with the same arguments) into a ``6 × 6`` scratch matrix,
:func:`~pkmlab.dexterity._linalg.sweep_one` on it (the same function ``sweep_bounds`` calls),
and the values written straight into the ``(U, k)`` unit × orientation layout, with
infeasible poses skipped and given the values the NumPy path masks them with (``-inf``,
``inf``, ``0``). The arithmetic of every pose is that of the unfused path, operation for
operation, so the outputs are the same bit for bit (checked in
``tests/dexterity/test_fused_sweep.py`` and ``benchmarks/bench_worst_case.py``).

Served: spatial families with a numba Jacobian that does not read the actuator values
(``psu6``, ``ups6``); the others keep the unfused path.
"""

from __future__ import annotations

from functools import cache

import numpy as np
from numba import prange
from numba import types as nt

from ..runtime.jit import cached_kernel
from ..runtime.threads import threads_for
from ._linalg import sweep_one

__all__ = ["fused_available", "fused_sweep", "fused_sweep_at"]

#: poses per parallel task (each task has its own scratch matrices)
_TASK = 512


def fused_available(mech) -> bool:
    """True when :func:`fused_sweep` serves ``mech``: a spatial mechanism of six actuators
    whose Jacobian is the family's numba per-pose function without actuator values
    (:meth:`~pkmlab.mechanisms.base.Mechanism.jacobian_kernel`)."""
    kernel = getattr(mech, "jacobian_kernel", None)      # a plugin need not derive from it
    return mech.n_actuators == 6 and kernel is not None and kernel() is not None


@cache
def _kernel(jac, ng: int):
    """The fused loop for the per-pose Jacobian ``jac`` and geometry tuples of ``ng`` floats,
    built by :func:`pkmlab.runtime.jit.cached_kernel` (named after all it compiles in)."""

    def fused_sweep_loop(P, R, feas, g, L, fmax, kup, force, det):
        U, K = P.shape[0], R.shape[0]
        n = U * K
        for task in prange((n + _TASK - 1) // _TASK):
            J = np.empty((1, 6, 6))
            A = np.empty((6, 6))
            B = np.empty((6, 6))
            G = np.empty((6, 6))
            T = np.empty((6, 6))
            piv = np.empty(6, np.int64)
            q = np.empty((1, 6))
            for i in range(task * _TASK, min(n, (task + 1) * _TASK)):
                m, u = i // U, i % U               # the unfused order: orientation-major
                if not feas[u, m]:
                    kup[m, u] = -np.inf
                    force[m, u] = np.inf
                    det[m, u] = 0.0
                    continue
                jac(P[u, 0], P[u, 1], P[u, 2], R[m, 0, 0], R[m, 0, 1], R[m, 0, 2],
                    R[m, 1, 0], R[m, 1, 1], R[m, 1, 2], R[m, 2, 0], R[m, 2, 1], R[m, 2, 2],
                    g, q, J, 0)
                kup[m, u], force[m, u], det[m, u] = sweep_one(J[0], L, fmax, A, B, G, T, piv)

    f8, f1, f2, f3 = nt.float64, nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
    return cached_kernel(fused_sweep_loop,
                         nt.void(f2, f3, nt.boolean[:, ::1], nt.UniTuple(nt.float64, ng),
                                 f8, f1, f2, f2, f2),
                         parallel=True, error_model="numpy")


@cache
def _kernel_at(jac, ng: int):
    """:func:`_kernel`'s per-pose loop on a list of poses (flat ``m · U + u``)."""

    def fused_at_loop(P, R, at, g, L, fmax, kup, force, det):
        U = P.shape[0]
        n = at.shape[0]
        for task in prange((n + _TASK - 1) // _TASK):
            J = np.empty((1, 6, 6))
            A = np.empty((6, 6))
            B = np.empty((6, 6))
            G = np.empty((6, 6))
            T = np.empty((6, 6))
            piv = np.empty(6, np.int64)
            q = np.empty((1, 6))
            for j in range(task * _TASK, min(n, (task + 1) * _TASK)):
                i = at[j]
                m, u = i // U, i % U
                jac(P[u, 0], P[u, 1], P[u, 2], R[m, 0, 0], R[m, 0, 1], R[m, 0, 2],
                    R[m, 1, 0], R[m, 1, 1], R[m, 1, 2], R[m, 2, 0], R[m, 2, 1], R[m, 2, 2],
                    g, q, J, 0)
                kup[m, u], force[m, u], det[m, u] = sweep_one(J[0], L, fmax, A, B, G, T, piv)

    f8, f1, f2, f3 = nt.float64, nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
    return cached_kernel(fused_at_loop,
                         nt.void(f2, f3, nt.int64[::1], nt.UniTuple(nt.float64, ng),
                                 f8, f1, f2, f2, f2),
                         parallel=True, error_model="numpy")


def fused_sweep_at(mech, P, R, at, L, fmax, kup, force, det) -> None:
    """:func:`fused_sweep`'s values at the poses ``at`` (flat ``m · U + u`` indices,
    orientation-major) written into ``kup, force, det (k, U)`` (C-contiguous float64); the
    other entries are left as they are (the poses :mod:`._cells` does not prune)."""
    P = np.require(P, np.float64, ("C", "A", "W"))
    R = np.require(R, np.float64, ("C", "A", "W"))
    at = np.require(at, np.int64, ("C", "A", "W"))
    fmax = np.require(np.broadcast_to(fmax, (6,)), np.float64, ("C", "A", "W"))
    jac, g = mech.jacobian_kernel()
    with threads_for(len(at)):
        _kernel_at(jac, len(g))(P, R, at, g, float(L), fmax, kup, force, det)


def fused_sweep(mech, P, R, feas, L, fmax):
    """``(kup, force, det)``, each ``(U, k)`` (transposed views), for positions ``P (U, 3)``
    × rotations ``R (k, 3, 3)``: where ``feas (U, k)`` holds, :func:`._linalg.sweep_bounds` of
    ``mech.jacobian`` at the pose; elsewhere ``-inf``, ``inf``, ``0``."""
    U, k = len(P), len(R)
    P = np.require(P, np.float64, ("C", "A", "W"))
    R = np.require(R, np.float64, ("C", "A", "W"))
    feas = np.require(feas, np.bool_, ("C", "A", "W"))
    fmax = np.require(np.broadcast_to(fmax, (6,)), np.float64, ("C", "A", "W"))
    kup, force, det = np.empty((k, U)), np.empty((k, U)), np.empty((k, U))
    jac, g = mech.jacobian_kernel()
    with threads_for(U * k):
        _kernel(jac, len(g))(P, R, feas, g, float(L), fmax, kup, force, det)
    return kup.T, force.T, det.T
