"""Inverse dynamics of the platform: Newton–Euler of one rigid body → actuator forces.

The moving body (platform + payload + lumped leg masses, :mod:`.payload`) has mass ``m``,
centre of mass ``c`` and inertia ``I_c`` (platform frame). Along a :class:`~.motions.Motion`
with tool pose ``(p, R)``, twist ``[v; ω]`` and its derivative ``[a; α]`` (base frame):

    r   = R·(c − o)                              (o: the tool offset; r from the tool point)
    a_c = a + α × r + ω × (ω × r)                (acceleration of the centre of mass)
    F   = m·a_c − m_w·g,        g = (0, 0, −g₀)
    M   = I·α + ω × (I·ω) + r × m·a_c − r_w × m_w·g,   I = R·I_c·Rᵀ

(``m_w`` at ``r_w = R·(c_w − o)``: the body's weight, :mod:`.payload`; ``m_w = m``,
``c_w = c`` unless slender-rod legs are included.)

``w = [F; M]`` (N; N·mm) is the wrench the actuators exert on the platform, about the tool
point, in the base frame (mass × mm/s² is 10⁻³ N: the code applies the factor). The actuator
forces follow from virtual work, ``w = Jᵀ·f`` with ``q̇ = J·[v; ω]``
(:mod:`pkmlab.dexterity.force`): ``f = J⁻ᵀ·w``, solved per sample by LU with partial
pivoting. The actuator speeds are ``q̇ = J·[v; ω]`` and the powers ``f·q̇`` (W). For
prismatic families ``f`` is a force in N along +q (positive pushes towards larger q; a rotary
drive behind it, a screw of lead ``ℓ``, is handled by :mod:`.actuators`); for rotary families
(``actuator_unit`` rad, ``rss6``) ``f`` is the crank torque in N·mm about the servo axis and
``q̇`` in rad/s (``DynamicsResult.unit``). The Jacobians come from
``mech.inverse_and_jacobian`` (numba per pose for psu6, ups6 and rss6).

Failures are data: a sample whose pose has no inverse kinematics within the stroke, or whose
Jacobian is singular (pkmlab's one rule, :func:`pkmlab.dexterity.is_singular`, with ``J`` as
given), has NaN forces and a status naming why (``DynamicsResult.status``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange
from numba import types as nt

from ..dexterity.metrics import is_singular
from ..runtime.jit import cached_kernel
from .motions import Motion
from .payload import GRAVITY, MassProperties

__all__ = ["DynamicsResult", "inverse_dynamics", "platform_wrench", "platform_energy"]

_SUSPECT = 1e-8      # LU pivot ratio below which the singular rule is applied exactly


@dataclass(frozen=True)
class DynamicsResult:
    """Per-sample actuator series of one motion.

    Attributes:
        motion: the motion's name; t ``(T,)`` s.
        q ``(T, L)`` mm, qdot ``(T, L)`` mm/s, force ``(T, L)`` N, power ``(T, L)`` W (L
        actuators).
        wrench ``(T, 6)`` [N; N·mm] the actuators exert on the platform.
        code ``(T,)`` int8: 0 ok, 1 no inverse kinematics within the stroke (``reasons``:
        sample → the IK reason), 2 singular, 3 a force, speed or power that is not finite
        (overflow); :attr:`status` spells it out.
        actuator_names, stroke (min, max) mm.
    """

    motion: str
    t: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    force: np.ndarray
    power: np.ndarray
    wrench: np.ndarray
    code: np.ndarray
    reasons: dict
    actuator_names: tuple[str, ...]
    stroke: tuple[float, float]
    unit: str = "mm"            # the mechanism's actuator_unit: "rad" → torques N·mm, rad/s

    @property
    def ok(self) -> np.ndarray:
        return self.code == 0

    @property
    def status(self) -> np.ndarray:
        """``(T,)`` text: ``ok``, ``ik: <reason>`` or ``singular``."""
        out = np.where(self.code == 2, "singular", "ok").astype(object)
        out[self.code == 3] = "non-finite force, speed or power (overflow)"
        for k, why in self.reasons.items():
            out[k] = f"ik: {why}"
        return out

    def first_problem(self) -> str:
        """The first failing sample, spelt out ('' if none)."""
        bad = np.flatnonzero(self.code)
        if not len(bad):
            return ""
        k = int(bad[0])
        return f"{self.motion}: t = {self.t[k]:.4g} s: {self.status[k]}"

    def summary(self) -> dict:
        """Per actuator (arrays ``(L,)``): ``peak_force`` |f| N, ``rms_force`` N,
        ``peak_speed`` |q̇| mm/s, ``peak_power`` |f·q̇| W, ``travel`` (min q, max q) mm (for
        rotary actuators: torques in N·mm, speeds in rad/s, travel in rad); over the samples
        that are ``ok`` (NaN if none)."""
        ok = self.ok
        if not np.any(ok):
            nan = np.full(self.q.shape[1], np.nan)
            return {"peak_force": nan, "rms_force": nan, "peak_speed": nan,
                    "peak_power": nan, "travel": np.full((len(nan), 2), np.nan)}
        f, v, P, q = self.force[ok], self.qdot[ok], self.power[ok], self.q[ok]
        t = self.t[ok]
        if len(t) > 1:
            rms = np.sqrt(np.trapezoid(f * f, t, axis=0) / (t[-1] - t[0]))
        else:
            rms = np.abs(f[0])
        return {"peak_force": np.max(np.abs(f), axis=0), "rms_force": rms,
                "peak_speed": np.max(np.abs(v), axis=0),
                "peak_power": np.max(np.abs(P), axis=0),
                "travel": np.stack([q.min(axis=0), q.max(axis=0)], axis=1)}


def platform_wrench(p, R, twist, accel, body: MassProperties, tool_offset,
                    gravity: float = GRAVITY) -> np.ndarray:
    """Newton–Euler wrench ``(T, 6)`` [N; N·mm] the actuators exert (module docstring)."""
    o = np.asarray(tool_offset, dtype=float)
    r = np.einsum("nij,j->ni", R, body.com - o)
    rw = np.einsum("nij,j->ni", R, body.weight_com - o)
    w, al = twist[:, 3:], accel[:, 3:]
    ac = accel[:, :3] + np.cross(al, r) + np.cross(w, np.cross(w, r))
    Fi = body.mass * ac * 1e-3
    Fw = np.broadcast_to([0.0, 0.0, body.weight_mass * gravity * 1e-3], Fi.shape)
    Ib = np.einsum("nij,jk,nlk->nil", R, body.inertia, R)
    M = (np.einsum("nij,nj->ni", Ib, al)
         + np.cross(w, np.einsum("nij,nj->ni", Ib, w))) * 1e-3 + np.cross(r, Fi) \
        + np.cross(rw, Fw)
    return np.concatenate([Fi + Fw, M], axis=1)


def platform_energy(p, R, twist, body: MassProperties, tool_offset,
                    gravity: float = GRAVITY) -> np.ndarray:
    """Kinetic + gravitational potential energy ``(T,)`` in J (for the power balance)."""
    o = np.asarray(tool_offset, dtype=float)
    r = np.einsum("nij,j->ni", R, body.com - o)
    rw = np.einsum("nij,j->ni", R, body.weight_com - o)
    w = twist[:, 3:]
    vc = twist[:, :3] + np.cross(w, r)
    Ib = np.einsum("nij,jk,nlk->nil", R, body.inertia, R)
    kin = 0.5 * body.mass * np.sum(vc * vc, axis=1) + 0.5 * np.einsum("ni,nij,nj->n", w, Ib, w)
    pot = body.weight_mass * gravity * (p[:, 2] + rw[:, 2])
    return (kin + pot) * 1e-6


def _solve_kernel(J, R, tw, ac, mass, rc, Ic, g0, wmass, rw, w, f, qd, pw, piv):
    """Per sample: the Newton–Euler wrench ``w``, ``Jᵀ f = w`` by LU with partial pivoting,
    ``q̇ = J t`` and ``f·q̇`` (the same formulas as :func:`platform_wrench`)."""
    n = J.shape[0]
    nb = (n + 255) // 256
    for blk in prange(nb):
        r = np.empty(3)
        IA = np.empty(3)
        IW = np.empty(3)
        b = np.empty(6)
        A = np.empty((6, 6))
        for k in range(blk * 256, min(n, blk * 256 + 256)):
            _one(k, J, R, tw, ac, mass, rc, Ic, g0, wmass, rw, w, f, qd, pw, piv, r, IA,
                 IW, b, A)


@functools.cache
def _solver():
    """:func:`_solve_kernel` compiled once, cached on disk safely (:mod:`pkmlab.runtime.jit`)."""
    F1, F2, F3 = nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]
    return cached_kernel(_solve_kernel, nt.void(F3, F3, F2, F2, nt.float64, F1, F2, nt.float64,
                                                nt.float64, F1, F2, F2, F2, F2, F1),
                         parallel=True)


@njit(inline="always")
def _one(k, J, R, tw, ac, mass, rc, Ic, g0, wmass, rw, w, f, qd, pw, piv, r, IA, IW, b, A):
    """One sample of :func:`_solve` (scratch arrays r, IA, IW, b, A)."""
    for i in range(3):
        r[i] = R[k, i, 0] * rc[0] + R[k, i, 1] * rc[1] + R[k, i, 2] * rc[2]
    wx, wy, wz = tw[k, 3], tw[k, 4], tw[k, 5]
    ax, ay, az = ac[k, 3], ac[k, 4], ac[k, 5]
    # ω × r, then ω × (ω × r)
    ux, uy, uz = wy * r[2] - wz * r[1], wz * r[0] - wx * r[2], wx * r[1] - wy * r[0]
    Fx = mass * (ac[k, 0] + ay * r[2] - az * r[1] + wy * uz - wz * uy) * 1e-3
    Fy = mass * (ac[k, 1] + az * r[0] - ax * r[2] + wz * ux - wx * uz) * 1e-3
    Fz = mass * (ac[k, 2] + ax * r[1] - ay * r[0] + wx * uy - wy * ux) * 1e-3
    Gz = wmass * g0 * 1e-3                       # the weight, at R·rw
    gx = R[k, 0, 0] * rw[0] + R[k, 0, 1] * rw[1] + R[k, 0, 2] * rw[2]
    gy = R[k, 1, 0] * rw[0] + R[k, 1, 1] * rw[1] + R[k, 1, 2] * rw[2]
    # I = R Ic Rᵀ applied to α and ω: R (Ic (Rᵀ v))
    for vsel in range(2):
        vx, vy, vz = (ax, ay, az) if vsel == 0 else (wx, wy, wz)
        lx = R[k, 0, 0] * vx + R[k, 1, 0] * vy + R[k, 2, 0] * vz
        ly = R[k, 0, 1] * vx + R[k, 1, 1] * vy + R[k, 2, 1] * vz
        lz = R[k, 0, 2] * vx + R[k, 1, 2] * vy + R[k, 2, 2] * vz
        mx = Ic[0, 0] * lx + Ic[0, 1] * ly + Ic[0, 2] * lz
        my = Ic[1, 0] * lx + Ic[1, 1] * ly + Ic[1, 2] * lz
        mz = Ic[2, 0] * lx + Ic[2, 1] * ly + Ic[2, 2] * lz
        for i in range(3):
            val = R[k, i, 0] * mx + R[k, i, 1] * my + R[k, i, 2] * mz
            if vsel == 0:
                IA[i] = val
            else:
                IW[i] = val
    b[0], b[1], b[2] = Fx, Fy, Fz + Gz
    b[3] = (IA[0] + wy * IW[2] - wz * IW[1]) * 1e-3 + r[1] * Fz - r[2] * Fy + gy * Gz
    b[4] = (IA[1] + wz * IW[0] - wx * IW[2]) * 1e-3 + r[2] * Fx - r[0] * Fz - gx * Gz
    b[5] = (IA[2] + wx * IW[1] - wy * IW[0]) * 1e-3 + r[0] * Fy - r[1] * Fx
    for i in range(6):
        w[k, i] = b[i]
        s = 0.0
        for j in range(6):
            A[i, j] = J[k, j, i]
            s += J[k, i, j] * tw[k, j]
        qd[k, i] = s
    pmax, pmin = 0.0, np.inf
    for c in range(6):
        m = c
        for i in range(c + 1, 6):
            if abs(A[i, c]) > abs(A[m, c]):
                m = i
        if m != c:
            for j in range(6):
                A[c, j], A[m, j] = A[m, j], A[c, j]
            b[c], b[m] = b[m], b[c]
        d = abs(A[c, c])
        pmax = max(pmax, d)
        pmin = min(pmin, d)
        if d == 0.0 or not np.isfinite(d):
            pmin = 0.0
            break
        for i in range(c + 1, 6):
            gg = A[i, c] / A[c, c]
            for j in range(c, 6):
                A[i, j] -= gg * A[c, j]
            b[i] -= gg * b[c]
    piv[k] = pmin / pmax if pmax > 0.0 else 0.0
    if piv[k] > 0.0:
        for i in range(5, -1, -1):
            s = b[i]
            for j in range(i + 1, 6):
                s -= A[i, j] * f[k, j]
            f[k, i] = s / A[i, i]
    for i in range(6):
        if piv[k] <= 0.0:
            f[k, i] = np.nan
        pw[k, i] = f[k, i] * qd[k, i] * 1e-3


#: samples per chunk: few parallel regions (each waits for every thread to be scheduled, which
#: on a loaded machine costs more than the work), the chunk's arrays ~100 MB
_CHUNK = 262144


@njit(cache=True)
def _euler_frames(X, p, R):
    """Euler poses ``(n, 6)`` → positions and ``R = Rz·Ry·Rx`` (as :func:`pkmlab.poses.
    euler_to_matrix`), without NumPy's temporaries."""
    for k in range(X.shape[0]):
        p[k, 0], p[k, 1], p[k, 2] = X[k, 0], X[k, 1], X[k, 2]
        cx, cy, cz = math.cos(X[k, 3]), math.cos(X[k, 4]), math.cos(X[k, 5])
        sx, sy, sz = math.sin(X[k, 3]), math.sin(X[k, 4]), math.sin(X[k, 5])
        R[k, 0, 0] = cz * cy
        R[k, 0, 1] = cz * sy * sx - sz * cx
        R[k, 0, 2] = cz * sy * cx + sz * sx
        R[k, 1, 0] = sz * cy
        R[k, 1, 1] = sz * sy * sx + cz * cx
        R[k, 1, 2] = sz * sy * cx - cz * sx
        R[k, 2, 0] = -sy
        R[k, 2, 1] = cy * sx
        R[k, 2, 2] = cy * cx


def inverse_dynamics(mech, motion: Motion, body: MassProperties,
                     gravity: float = GRAVITY) -> DynamicsResult:
    """Actuator forces, speeds and powers of ``mech`` along ``motion`` carrying ``body``
    (in chunks of ``_CHUNK`` samples: the (T, 6, 6) Jacobians are never all in memory).

    A lower-mobility mechanism (``mech.mobility`` not spatial) takes :func:`_free_dynamics`:
    the same wrench, balanced on its free components only."""
    if not mech.mobility.is_spatial:
        return _free_dynamics(mech, motion, body, gravity)
    n = len(motion.t)
    q, f, qd, pw, w = (np.empty((n, 6)) for _ in range(5))
    piv = np.empty(n)
    valid = np.empty(n, dtype=bool)
    rc = np.ascontiguousarray(body.com - np.asarray(mech.tool_offset, dtype=float))
    rw = np.ascontiguousarray(body.weight_com - np.asarray(mech.tool_offset, dtype=float))
    Ic = np.ascontiguousarray(body.inertia)
    tw, ac = np.ascontiguousarray(motion.twist), np.ascontiguousarray(motion.accel)
    poses = np.ascontiguousarray(motion.poses, dtype=float)
    reasons: dict = {}
    sing = []
    for s in range(0, n, _CHUNK):
        e = min(n, s + _CHUNK)
        p, R = np.empty((e - s, 3)), np.empty((e - s, 3, 3))
        _euler_frames(poses[s:e], p, R)
        ik, J = mech.inverse_and_jacobian((p, R))
        q[s:e], valid[s:e] = ik.q, ik.valid
        if not np.all(ik.valid):
            idx = np.flatnonzero(~ik.valid)
            reasons.update(zip((s + idx).tolist(), np.asarray(ik.reason_text)[idx].tolist()))
        J = np.ascontiguousarray(J)
        _solver()(J, np.ascontiguousarray(R), tw[s:e], ac[s:e], float(body.mass), rc, Ic,
                  float(gravity), float(body.weight_mass), rw, w[s:e], f[s:e], qd[s:e],
                  pw[s:e], piv[s:e])
        sus = np.flatnonzero(ik.valid & ~(piv[s:e] > _SUSPECT))
        if len(sus):
            sing.append(s + sus[is_singular(J[sus])])
    bad = ~valid
    code = np.zeros(n, dtype=np.int8)
    code[bad] = 1
    f[bad] = np.nan
    pw[bad] = np.nan
    for idx in sing:
        code[idx] = 2
        f[idx] = np.nan
        pw[idx] = np.nan
    # a force, speed or power that overflowed (extreme accelerations or masses) is flagged,
    # never carried into the summaries as a silent NaN
    over = (code == 0) & ~(np.all(np.isfinite(f), axis=1) & np.all(np.isfinite(qd), axis=1)
                           & np.all(np.isfinite(pw), axis=1))
    code[over] = 3
    f[over] = np.nan
    pw[over] = np.nan
    return DynamicsResult(motion.name, motion.t, q, qd, f, pw, w, code, reasons,
                          tuple(mech.actuator_names), tuple(mech.stroke),
                          mech.actuator_unit)


def _free_dynamics(mech, motion: Motion, body: MassProperties, gravity: float) -> DynamicsResult:
    """Inverse dynamics of a lower-mobility mechanism (NumPy): the Newton–Euler wrench of
    :func:`platform_wrench`, balanced on the free twist components ``c`` of the mobility,
    ``J_cᵀ f = w_c`` (least-norm when there are more actuators than free coordinates); the
    constraint wrench of the joints carries the other components. ``q̇ = J_c t_c``."""
    cols = mech.mobility.twist_columns
    poses = np.asarray(motion.poses, dtype=float)
    n, L = len(poses), mech.n_actuators
    p, R = np.empty((n, 3)), np.empty((n, 3, 3))
    _euler_frames(np.ascontiguousarray(poses), p, R)
    ik, J = mech.inverse_and_jacobian((p, R))                       # J (n, L, free)
    w = platform_wrench(p, R, motion.twist, motion.accel, body, mech.tool_offset, gravity)
    valid = np.asarray(ik.valid, dtype=bool)
    singular = valid & is_singular(J)
    ok = valid & ~singular
    f = np.full((n, L), np.nan)
    if ok.any():
        Jt = np.swapaxes(J[ok], 1, 2)
        rhs = w[ok][:, cols, None]
        f[ok] = (np.linalg.solve(Jt, rhs) if L == len(cols) else np.linalg.pinv(Jt) @ rhs)[..., 0]
    with np.errstate(invalid="ignore"):
        qd = np.einsum("nij,nj->ni", J, motion.twist[:, cols])
    code = np.where(~valid, 1, np.where(singular, 2, 0)).astype(np.int8)
    bad = np.flatnonzero(~valid)
    reasons = dict(zip(bad.tolist(), np.asarray(ik.reason_text)[bad].tolist()))
    return DynamicsResult(motion.name, motion.t, np.asarray(ik.q, dtype=float), qd, f,
                          f * qd * 1e-3, w, code, reasons, tuple(mech.actuator_names),
                          tuple(mech.stroke), mech.actuator_unit)
