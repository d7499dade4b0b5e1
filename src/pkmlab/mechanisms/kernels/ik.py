"""Numba drivers shared by every family's inverse kinematics.

Each family supplies a per-pose function ``one(px, py, pz, r00, ..., r22, g, qmin, qmax, q, st,
j)``, declared with ``numba.extending.register_jitable(inline="always")``, that writes the
actuator value and status code of each leg ``i`` of block pose ``j`` to ``q[i * ROW + j]`` and
``st[i * ROW + j]``. :func:`make_driver` wraps it in parallel drivers over poses; the family
function is captured as a compile-time constant and inlined, so a new family needs no driver
code of its own.

The drivers work on blocks of :data:`BLOCK` poses held as structure-of-arrays buffers, so that
LLVM vectorises each stage over the poses of a block:

1. load: copy the block's positions into rows 0-2 of ``T`` and its rotation entries
   ``r00 ... r22`` into rows 3-11 (Euler input: sines and cosines by the vectorisable
   :func:`_sincos`, the Z-Y-X product by :func:`_euler_matrix`);
2. legs: call ``one`` for every pose ``j`` of the block; it writes leg ``i`` to slot
   ``i * ROW + j`` of the leg-major buffers ``q`` (float64) and ``st`` (int8);
3. store: transpose the buffers into the ``(N, L)`` outputs (``L`` the family's actuator count,
   ``Mechanism.n_actuators``) and take each pose's reason, the most severe leg status.

Before stage 2 the status rows of the block are filled with :data:`UNWRITTEN`, one row more than
the family declares (:func:`_prefill`): a pose whose ``one`` left a declared leg unwritten, or
wrote a leg beyond them, gets the reason :data:`LEG_FAULT`, and the mechanism raises (a
programming error of the family, never returned as data). The buffers hold at least seven
rows, so a kernel written for six legs behind a smaller declaration stays inside them.

For stage 2 to vectorise, ``one`` must be branch-free (conditional expressions that LLVM turns
into selects, no early exit or ``continue``; helpers it calls must be inlined, see below),
its loop over legs must be small enough for LLVM to unroll it (``g`` is then indexed by
constants; see ``_luzi_one`` for a hand-unrolled one), and ``g``, the family's geometry, is
passed as a tuple of floats, so its entries are constants to the loop rather than memory that
the output buffers might alias. The stage loops run from 0 (numba's negative-index handling
otherwise hides from LLVM that the indices are >= 0) over the block's poses rounded up to
:data:`LANES`, so every pose goes through the same vector code, whatever its position in the
batch: a pose's result does not depend on the batch it is part of.

Helpers that a per-pose function calls (a leg, ``atan2``, :func:`stroke_status`) are declared
``njit(cache=True, forceinline=True)``: numba compiles each once per signature and LLVM inlines
it at every call site, so the legs loop still vectorises. numba's own ``inline="always"``
instead copies and re-types the helper's IR at every call site, which made the crank kernels
(six legs, each with an inlined ``atan2``) compile 3-4x longer for bit-identical code (issue
28, session 6).

Poses with a non-finite coordinate (and, in the Euler driver, poses with an angle beyond
:data:`TRIG_MAX`, whose rotation is then taken from ``math.sin``/``math.cos``) take a scalar
path after stage 1; non-finite poses get NaN actuator values and ``INVALID_INPUT`` for every
leg.

Caching and invalidation
------------------------
The drivers (:func:`make_driver`), the workspace column kernels
(:func:`.column_kernels.make_column_kernel`) and the vectorised leg interval of the refinement
(:func:`.column_kernels.make_leg_eval`) are made per family
by closures over the family's function, and all are cached in numba's disk cache
(``NUMBA_CACHE_DIR``): a process, a joblib or Dask worker included, loads them in well under a
second instead of compiling them for seconds. They are built by
:func:`pkmlab.runtime.jit.cached_kernel`, which is what makes that safe:

- A kernel's *identity* is a SHA-256 of the numba and Python versions, its name, signature and
  options, and the full text of every source file it compiles code from. That is this module,
  the family's module (``psu6.py`` ...) and any module whose functions the family function calls,
  found by following globals, closure cells and module attributes, and
  ``mechanisms/kernels/intervals.py`` for the column kernels.
- The kernel is compiled from a copy of its function named ``<name>_<16 hex digits of the
  identity>``. ``legs`` (stage 2, a function of its own) and the inlined per-leg interval are
  renamed the same way. numba's symbols and cache file names start with that name, so two
  kernels with different code never share a symbol or an index file.
- It is compiled eagerly for its one signature with numba's per-process uid counter moved into
  a range that belongs to its identity. So the symbols numba names only by address and counter,
  the parfor gufuncs, are unique to the identity too, and no later call can compile it again
  outside that range.

Without this, the closures of all families shared one qualname, ``make_drivers.<locals>.
drive_euler``, and the gufuncs shared ``__numba_parfor_gufunc_<address>``. Their symbols differed
only by the per-process counter, so two processes could give two families' kernels the same
symbol. A third process that loaded both then ran the first one's code for both: the ``legs``
of psu6 behind the 6-UPS driver gave NaN, the frames driver of ups6 behind psu6 gave plausible
wrong numbers (``tests/runtime/test_kernel_cache.py``).

Invalidation: editing this module, a family module, or anything a kernel compiles in changes
the kernel's identity and so its name. The next process finds no cache entry under the new
name and compiles. Entries under old names stay on disk and are never loaded again; delete
``NUMBA_CACHE_DIR`` to reclaim the space. The shared helpers below (``_load_euler`` ...) are
ordinary module-level ``njit(cache=True)`` functions: numba drops their entries when this file
changes. Every kernel has one signature, so arguments must be C-contiguous, aligned and
writeable arrays of the declared dtype (:func:`carray`) and plain floats.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
from numba import njit, prange
from numba import types as nt

from ...runtime.jit import cached_kernel, identity, jitable

__all__ = ["BLOCK", "ROW", "carray", "make_driver", "make_jacobian_driver",
           "make_kinematics_driver", "stroke_status"]

# Leg status codes, ordered by severity: a pose's reason is its legs' maximum.
OK, BELOW_STROKE, ABOVE_STROKE, DEGENERATE, NO_SOLUTION, INVALID_INPUT = 0, 1, 2, 3, 4, 5
# A leg on the other side of its base joint than at the nominal pose (another assembly mode).
OTHER_MODE = 6
#: A leg whose passive joint is beyond its declared limit (delta3's forearm ball-joint cone,
#: ldelta3's rod angle): the actuator value is still reported.
JOINT_LIMIT = 8
#: Reason of a pose whose per-pose function wrote another number of legs than the family
#: declares (``Mechanism.n_actuators``); the mechanism raises on it.
LEG_FAULT = 7
#: Status a block's rows hold until the per-pose function writes them.
UNWRITTEN = -1

#: Poses per block of the inverse-kinematics drivers (the buffers of a block, ~110 kB, stay in
#: the L2 cache).
BLOCK = 512
#: Row stride of the block buffers: a little more than BLOCK, so that the rows a loop streams
#: through do not all map to the same cache sets (4 KiB aliasing).
ROW = BLOCK + 8
#: The stages run over a block's poses rounded up to a multiple of LANES (a multiple of any
#: SIMD width × unroll LLVM picks), so every pose goes through the vector loop bodies and a
#: short batch does not pay for a whole block.
LANES = 64
#: Largest angle sum |θx| + |θy| + |θz| (rad) for which the Euler driver uses :func:`_sincos`.
TRIG_MAX = 1e5


@njit(cache=True, forceinline=True)
def stroke_status(q, qmin, qmax):
    if q < qmin:
        return BELOW_STROKE
    if q > qmax:
        return ABOVE_STROKE
    return OK


# ---- sine and cosine that LLVM can vectorise ---------------------------------------------------
# fdlibm's algorithm (Sun Microsystems, 1993; k_sin.c, k_cos.c, e_rem_pio2.c): x = n·π/2 + y
# with |y| <= π/4 (Cody-Waite, π/2 split into a 33-bit head and a tail, exact for |n| < 2^20),
# then degree-13/14 minimax polynomials in y = y0 + y1. Written without branches or integer
# conversions, so that a loop over angles becomes SIMD code (~4x cheaper than libm calls).
# For |x| <= TRIG_MAX the error is within 1 ulp of 1 (absolute, ~1.1e-16), which moves the
# actuator values by ~1e-13 mm at most compared with libm.
_INVPIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_1T = 6.07710050650619224932e-11
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11


@njit(cache=True, forceinline=True)
def _sincos(x):
    """``(sin x, cos x)`` for ``|x| <= TRIG_MAX``, branch-free."""
    fn = np.floor(x * _INVPIO2 + 0.5)          # nearest multiple of π/2, as a float
    r = x - fn * _PIO2_1
    w = fn * _PIO2_1T
    y0 = r - w                                 # reduced argument y0 + y1
    y1 = (r - y0) - w
    z = y0 * y0
    v = z * y0
    p = _S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))
    s = y0 - ((z * (0.5 * y1 - v * p) - y1) - v * _S1)
    zz = z * z
    p = z * (_C1 + z * (_C2 + z * _C3)) + zz * zz * (_C4 + z * (_C5 + z * _C6))
    hz = 0.5 * z
    w = 1.0 - hz
    c = w + (((1.0 - w) - hz) + (z * p - y0 * y1))
    quadrant = fn - 4.0 * np.floor(0.25 * fn)  # 0, 1, 2, 3
    sin_x = s if quadrant == 0.0 else (c if quadrant == 1.0 else (-s if quadrant == 2.0 else -c))
    cos_x = c if quadrant == 0.0 else (-s if quadrant == 1.0 else (-c if quadrant == 2.0 else s))
    return sin_x, cos_x


@njit(cache=True, forceinline=True)
def _euler_matrix(sx, cx, sy, cy, sz, cz):
    """Entries ``r00, r01, ..., r22`` of R = Rz·Ry·Rx from the angles' sines and cosines."""
    return (cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
            sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
            -sy, cy * sx, cy * cx)


@njit(cache=True, forceinline=True)
def _store_matrix(T, j, r):
    """Rotation entries ``r`` (9-tuple) into rows 3-11 of the block buffer ``T`` at pose ``j``."""
    T[3 * ROW + j] = r[0]
    T[4 * ROW + j] = r[1]
    T[5 * ROW + j] = r[2]
    T[6 * ROW + j] = r[3]
    T[7 * ROW + j] = r[4]
    T[8 * ROW + j] = r[5]
    T[9 * ROW + j] = r[6]
    T[10 * ROW + j] = r[7]
    T[11 * ROW + j] = r[8]


@njit(cache=True, forceinline=True)
def _width(m):
    """``m`` rounded up to a multiple of LANES (the low bits are then known zero to LLVM)."""
    return (m + LANES - 1) & ~(LANES - 1)


# ---- stage 1: load a block ---------------------------------------------------------------------
@njit(cache=True)
def _load_euler(x, m, w, T, A, C):
    """Block of ``m`` Euler poses (``x`` flat, 6 per pose) → ``T``; returns the number of poses
    that need :func:`_euler_slow` (non-finite, or angles beyond ``TRIG_MAX``).

    ``A`` and ``C`` (3 rows of ROW each) are scratch: the angles, then their sines and cosines.
    """
    slow = 0
    for j in range(m):
        px, py, pz = x[6 * j], x[6 * j + 1], x[6 * j + 2]
        tx, ty, tz = x[6 * j + 3], x[6 * j + 4], x[6 * j + 5]
        T[j] = px
        T[ROW + j] = py
        T[2 * ROW + j] = pz
        A[j] = tx
        A[ROW + j] = ty
        A[2 * ROW + j] = tz
        fast = math.isfinite(px + py + pz) & (abs(tx) + abs(ty) + abs(tz) <= TRIG_MAX)
        slow += 0 if fast else 1
    for j in range(m, w):                     # padding up to w: harmless values
        for r in range(3):
            T[r * ROW + j] = 0.0
            A[r * ROW + j] = 0.0
    _sincos_block(A, C, w)
    for j in range(w):
        _store_matrix(T, j, _euler_matrix(A[j], C[j], A[ROW + j], C[ROW + j],
                                          A[2 * ROW + j], C[2 * ROW + j]))
    return slow


@njit(cache=True, fastmath={"contract"})
def _sincos_block(A, C, w):
    """Angles ``A`` (3 rows, first ``w`` of each) → their sines in place, cosines in ``C``.

    Fused multiply-adds (``contract``) shorten the polynomials; they do not change the error
    bound. Kept apart from the matrix products, which stay unfused as in ``euler_to_matrix``.
    """
    for r in range(3):
        for j in range(w):      # not range(r * ROW, ...): LLVM must see the index is >= 0
            A[r * ROW + j], C[r * ROW + j] = _sincos(A[r * ROW + j])


@njit(cache=True)
def _euler_slow(x, m, T, bad):
    """Scalar pass over a block with slow poses: flags non-finite ones in ``bad`` and takes the
    rotation of large angles from libm."""
    for j in range(m):
        px, py, pz = x[6 * j], x[6 * j + 1], x[6 * j + 2]
        tx, ty, tz = x[6 * j + 3], x[6 * j + 4], x[6 * j + 5]
        bad[j] = not (math.isfinite(px + py + pz) and math.isfinite(tx + ty + tz))
        if not bad[j] and not abs(tx) + abs(ty) + abs(tz) <= TRIG_MAX:
            _store_matrix(T, j, _euler_matrix(math.sin(tx), math.cos(tx), math.sin(ty),
                                              math.cos(ty), math.sin(tz), math.cos(tz)))


@njit(cache=True)
def _load_frames(p, R, m, w, T):
    """Block of ``m`` frames (``p`` flat 3 per pose, ``R`` flat 9 per pose) → ``T``; returns the
    number of non-finite poses."""
    nbad = 0
    for j in range(m):
        total = p[3 * j] + p[3 * j + 1] + p[3 * j + 2]
        for r in range(3):
            T[r * ROW + j] = p[3 * j + r]
        for r in range(9):
            v = R[9 * j + r]
            T[(3 + r) * ROW + j] = v
            total += v
        nbad += 0 if math.isfinite(total) else 1
    for j in range(m, w):
        for r in range(12):
            T[r * ROW + j] = 0.0
    return nbad


@njit(cache=True)
def _frames_bad(p, R, m, bad):
    """Flags the non-finite poses of a block (same test as :func:`_load_frames`)."""
    for j in range(m):
        total = p[3 * j] + p[3 * j + 1] + p[3 * j + 2]
        for r in range(9):
            total += R[9 * j + r]
        bad[j] = not math.isfinite(total)


def _rows(legs: int) -> int:
    """Rows of a block's leg buffers: the declared legs, a sentinel row, and at least seven."""
    return max(legs, 6) + 1


@njit(cache=True)
def _prefill(st, legs, w):
    """:data:`UNWRITTEN` in the status rows of the ``legs`` declared legs and the one after."""
    for i in range(legs + 1):
        for j in range(w):
            st[i * ROW + j] = UNWRITTEN


# ---- stage 3: store a block --------------------------------------------------------------------
@njit(cache=True)
def _store(q, st, m, legs, q_out, st_out, reason_out):
    """Leg-major block buffers → rows of the ``(m, legs)`` outputs (flat) and each pose's
    reason (:data:`LEG_FAULT` where a declared leg was left unwritten or one more written)."""
    for j in range(m):
        worst = np.int8(OK)
        fault = st[legs * ROW + j] != UNWRITTEN
        for i in range(legs):
            s = st[i * ROW + j]
            q_out[legs * j + i] = q[i * ROW + j]
            st_out[legs * j + i] = s
            worst = max(worst, s)
            fault |= s == UNWRITTEN
        reason_out[j] = LEG_FAULT if fault else worst


@njit(cache=True)
def _store_invalid(bad, m, legs, q_out, st_out, reason_out):
    """NaN and ``INVALID_INPUT`` for the flagged poses of a block."""
    for j in range(m):
        if bad[j]:
            for i in range(legs):
                q_out[legs * j + i] = np.nan
                st_out[legs * j + i] = INVALID_INPUT
            reason_out[j] = INVALID_INPUT


# ---- signatures -------------------------------------------------------------------------------
# Every kernel has exactly one signature (see :func:`.._jit.cached_kernel`); :func:`carray`
# makes an argument match it.
_F1, _F2, _F3 = nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
_I1, _I2 = nt.int8[::1], nt.int8[:, ::1]


def carray(a, dtype=np.float64) -> np.ndarray:
    """``a`` as a C-contiguous, aligned, writeable array of ``dtype`` (copied only if needed):
    the array types of the kernels' signatures."""
    if isinstance(a, np.ndarray) and a.dtype == dtype and a.flags.carray:
        return a
    return np.require(a, dtype, ("C", "A", "W"))


@cache
def _legs(one, ng: int):
    """Stage 2 for the per-pose function ``one``: compiled as a function of its own, which keeps
    the drivers' parallel loop bodies small (numba's parfor passes are slow on large ones), and
    named after ``one``'s identity (:func:`.._jit.jitable`), since its code is the family's."""

    def legs(T, w, g, qmin, qmax, q, st):
        """Stage 2 over the first ``w`` poses of a block."""
        for j in range(w):
            one(T[j], T[ROW + j], T[2 * ROW + j],
                T[3 * ROW + j], T[4 * ROW + j], T[5 * ROW + j],
                T[6 * ROW + j], T[7 * ROW + j], T[8 * ROW + j],
                T[9 * ROW + j], T[10 * ROW + j], T[11 * ROW + j],
                g, qmin, qmax, q, st, j)

    return jitable(legs, identity(legs, extra=("legs", ng)), error_model="numpy")


@cache
def make_driver(one, ng: int, kind: str, legs: int = 6):
    """Parallel driver ``kind`` (``"euler"`` or ``"frames"``) for the per-pose function ``one``
    of ``legs`` legs and geometry tuples of ``ng`` floats, loaded from or compiled into numba's
    disk cache.

    ``one`` must be a module-level function declared with ``register_jitable``. The driver is
    built by :func:`.._jit.cached_kernel` (see the module notes): its name carries a hash of
    all the source it compiles in, so no two families' drivers can alias and an edit
    recompiles.

    ``euler(poses (N, 6), g, qmin, qmax, q_out (N, legs), st_out (N, legs) int8, reason_out
    (N,) int8)``; ``frames(p (N, 3), R (N, 3, 3), g, ...)`` likewise. All arrays C-contiguous,
    writeable, float64 unless stated (:func:`carray`).
    """
    nlegs, rows = legs, _rows(legs)
    legs = _legs(one, ng)

    def drive_euler(poses, g, qmin, qmax, q_out, st_out, reason_out):
        """Inverse kinematics over Euler poses ``(N, 6)`` (R = Rz·Ry·Rx), C-contiguous."""
        n = poses.shape[0]
        x, q_flat, st_flat = poses.reshape(-1), q_out.reshape(-1), st_out.reshape(-1)
        for b in prange((n + BLOCK - 1) // BLOCK):
            k0 = b * BLOCK
            m = min(BLOCK, n - k0)
            w = _width(m)
            xb = x[6 * k0:6 * (k0 + m)]
            T = np.empty(12 * ROW)
            A = np.empty(3 * ROW)
            C = np.empty(3 * ROW)
            q = np.empty(rows * ROW)
            st = np.empty(rows * ROW, dtype=np.int8)
            slow = _load_euler(xb, m, w, T, A, C)
            bad = np.zeros(BLOCK, dtype=np.bool_)
            if slow:
                _euler_slow(xb, m, T, bad)
            _prefill(st, nlegs, w)
            legs(T, w, g, qmin, qmax, q, st)
            out = slice(nlegs * k0, nlegs * (k0 + m))
            _store(q, st, m, nlegs, q_flat[out], st_flat[out], reason_out[k0:k0 + m])
            if slow:
                _store_invalid(bad, m, nlegs, q_flat[out], st_flat[out],
                               reason_out[k0:k0 + m])

    def drive_frames(p, R, g, qmin, qmax, q_out, st_out, reason_out):
        """Inverse kinematics over positions ``(N, 3)`` and rotations ``(N, 3, 3)``."""
        n = p.shape[0]
        pf, Rf = p.reshape(-1), R.reshape(-1)
        q_flat, st_flat = q_out.reshape(-1), st_out.reshape(-1)
        for b in prange((n + BLOCK - 1) // BLOCK):
            k0 = b * BLOCK
            m = min(BLOCK, n - k0)
            w = _width(m)
            pb, Rb = pf[3 * k0:3 * (k0 + m)], Rf[9 * k0:9 * (k0 + m)]
            T = np.empty(12 * ROW)
            q = np.empty(rows * ROW)
            st = np.empty(rows * ROW, dtype=np.int8)
            nbad = _load_frames(pb, Rb, m, w, T)
            _prefill(st, nlegs, w)
            legs(T, w, g, qmin, qmax, q, st)
            out = slice(nlegs * k0, nlegs * (k0 + m))
            _store(q, st, m, nlegs, q_flat[out], st_flat[out], reason_out[k0:k0 + m])
            if nbad:
                bad = np.zeros(BLOCK, dtype=np.bool_)
                _frames_bad(pb, Rb, m, bad)
                _store_invalid(bad, m, nlegs, q_flat[out], st_flat[out],
                               reason_out[k0:k0 + m])

    g, f8 = nt.UniTuple(nt.float64, ng), nt.float64
    if kind == "euler":
        return cached_kernel(drive_euler, nt.void(_F2, g, f8, f8, _F2, _I2, _I1), parallel=True,
                             extra=("legs", nlegs))
    if kind == "frames":
        return cached_kernel(drive_frames, nt.void(_F2, _F3, g, f8, f8, _F2, _I2, _I1),
                             parallel=True, extra=("legs", nlegs))
    raise ValueError(f"kind must be 'euler' or 'frames', got {kind!r}")


# ---- velocity Jacobians -------------------------------------------------------------------------
# A family may supply ``jac(px, py, pz, r00, ..., r22, g, q, J, k)`` (``register_jitable(inline=
# "always")``) that writes the ``(6, 6)`` Jacobian of pose ``k`` to ``J[k]`` from the pose, the
# IK geometry tuple ``g`` and, for families whose Jacobian depends on them, the actuator values
# ``q[k]``. Rows of legs with no real solution come out NaN (0/0 and sqrt of a negative number
# under numba's "numpy" error model), as the NumPy formulas give them.


@cache
def _jac_block(jac, ng: int):
    """The poses ``[k0, k1)`` through ``jac``, a function of its own named after its identity
    (as :func:`_legs`)."""

    def jac_block(p, R, g, q, J, k0, k1):
        for k in range(k0, k1):
            jac(p[k, 0], p[k, 1], p[k, 2], R[k, 0, 0], R[k, 0, 1], R[k, 0, 2],
                R[k, 1, 0], R[k, 1, 1], R[k, 1, 2], R[k, 2, 0], R[k, 2, 1], R[k, 2, 2],
                g, q, J, k)

    return jitable(jac_block, identity(jac_block, extra=("jac_block", ng)),
                   error_model="numpy")


@cache
def make_jacobian_driver(jac, ng: int):
    """Parallel driver ``jacobian(p (N, 3), R (N, 3, 3), g, q (N, L), J_out (N, L, 6))`` for the
    per-pose Jacobian ``jac`` (above) and geometry tuples of ``ng`` floats, built by
    :func:`.._jit.cached_kernel` like :func:`make_driver`."""
    block = _jac_block(jac, ng)

    def drive_jacobian(p, R, g, q, J):
        n = p.shape[0]
        for b in prange((n + BLOCK - 1) // BLOCK):
            block(p, R, g, q, J, b * BLOCK, min(n, b * BLOCK + BLOCK))

    return cached_kernel(drive_jacobian, nt.void(_F2, _F3, nt.UniTuple(nt.float64, ng), _F2,
                                                 _F3), parallel=True, error_model="numpy")


@cache
def make_kinematics_driver(one, jac, ng: int, legs: int = 6):
    """Inverse kinematics and Jacobian of frames in one parallel pass: ``kinematics(p, R, g,
    qmin, qmax, q_out, st_out, reason_out, J_out)``, the ``frames`` driver of
    :func:`make_driver` for ``one`` followed, block by block, by ``jac`` (which reads the
    block's stored actuator values). One parallel region instead of two: on a loaded machine
    each region waits for every thread to be scheduled."""
    nlegs, rows = legs, _rows(legs)
    legs = _legs(one, ng)
    block_jac = _jac_block(jac, ng)

    def drive_kinematics(p, R, g, qmin, qmax, q_out, st_out, reason_out, J):
        n = p.shape[0]
        pf, Rf = p.reshape(-1), R.reshape(-1)
        q_flat, st_flat = q_out.reshape(-1), st_out.reshape(-1)
        for b in prange((n + BLOCK - 1) // BLOCK):
            k0 = b * BLOCK
            m = min(BLOCK, n - k0)
            w = _width(m)
            pb, Rb = pf[3 * k0:3 * (k0 + m)], Rf[9 * k0:9 * (k0 + m)]
            T = np.empty(12 * ROW)
            q = np.empty(rows * ROW)
            st = np.empty(rows * ROW, dtype=np.int8)
            nbad = _load_frames(pb, Rb, m, w, T)
            _prefill(st, nlegs, w)
            legs(T, w, g, qmin, qmax, q, st)
            out = slice(nlegs * k0, nlegs * (k0 + m))
            _store(q, st, m, nlegs, q_flat[out], st_flat[out], reason_out[k0:k0 + m])
            if nbad:
                bad = np.zeros(BLOCK, dtype=np.bool_)
                _frames_bad(pb, Rb, m, bad)
                _store_invalid(bad, m, nlegs, q_flat[out], st_flat[out],
                               reason_out[k0:k0 + m])
            block_jac(p, R, g, q_out, J, k0, k0 + m)

    gt, f8 = nt.UniTuple(nt.float64, ng), nt.float64
    return cached_kernel(drive_kinematics, nt.void(_F2, _F3, gt, f8, f8, _F2, _I2, _I1, _F3),
                         parallel=True, error_model="numpy", extra=("legs", nlegs))
