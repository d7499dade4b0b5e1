"""6-UPS Gough–Stewart platform: six extensible legs between base U joints and platform S joints.

Leg i joins the base joint ``B_i`` to the platform joint ``W_i = p + R·(P_i - O)``; the actuator
value is the leg length ``q_i = |W_i - B_i|``. With ``n_i = (W_i - B_i)/q_i`` and
``r_i = R·(P_i - O)`` the velocity Jacobian row is ``J_i = [n_iᵀ, (r_i × n_i)ᵀ]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from .._intervals import intersect_pair, union_merge
from . import _kernels
from .base import Mechanism, as_points, as_stroke, as_vector3
from .layout import build_paired
from .psu6 import _radii

__all__ = ["UPS6"]


@njit(cache=True, inline="always")
def _ups_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, k):
    worst = _kernels.OK
    for i in range(6):
        bx, by, bz = g[3 * i], g[3 * i + 1], g[3 * i + 2]
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        sx = px + r00 * ux + r01 * uy + r02 * uz - bx
        sy = py + r10 * ux + r11 * uy + r12 * uz - by
        sz = pz + r20 * ux + r21 * uy + r22 * uz - bz
        v = math.sqrt(sx * sx + sy * sy + sz * sz)
        q[k, i] = v
        s = _kernels.DEGENERATE if v < 1e-12 else _kernels.stroke_status(v, qmin, qmax)
        st[k, i] = s
        worst = max(worst, s)
    return worst


# ---- column kernels for the workspace engine ------------------------------------------------
# Along a vertical column q_i² = d_i² + (z + w_iz)² with w_i = R·u_i - b_i and d_i the
# horizontal leg length, so qmin <= q_i <= qmax is |z + w_iz| in [sqrt(qmin² - d²), sqrt(qmax² -
# d²)]: two z intervals mirrored about the base joint's height (one when d >= qmin).


@njit(inline="always")
def _leg_pieces(x, y, wx, wy, wz, qmin2, qmax2):
    sx = x + wx
    sy = y + wy
    d2 = sx * sx + sy * sy
    A = qmax2 - d2
    if A < 0.0:
        return np.inf, -np.inf, np.inf, -np.inf
    ro = math.sqrt(A)
    B = qmin2 - d2
    if B <= 0.0:
        return -wz - ro, -wz + ro, np.inf, -np.inf
    ri = math.sqrt(B)
    return -wz - ro, -wz - ri, -wz + ri, -wz + ro


@njit(parallel=True, cache=True)
def _points_all(px, py, W, qmin, qmax, out_lo, out_hi, count):
    """Exact intersection (all sign patterns) for the columns at ``(px[k], py[k])``."""
    M, K = W.shape[0], out_lo.shape[1]
    qmin2, qmax2 = qmin * qmin, qmax * qmax
    for c in prange(px.shape[0]):
        s_lo, s_hi = np.empty(K), np.empty(K)
        t_lo, t_hi = np.empty(K), np.empty(K)
        n = 1
        s_lo[0], s_hi[0] = -np.inf, np.inf
        count[c] = 0
        for m in range(M):
            for i in range(6):
                a1, b1, a2, b2 = _leg_pieces(px[c], py[c], W[m, i, 0], W[m, i, 1],
                                             W[m, i, 2], qmin2, qmax2)
                n = intersect_pair(s_lo, s_hi, n, a1, b1, a2, b2, t_lo, t_hi, K)
                if n > K:
                    n = K
                    count[c] = K + 1
                for k in range(n):
                    s_lo[k], s_hi[k] = t_lo[k], t_hi[k]
                if n == 0:
                    break
            if n == 0:
                break
        if count[c] <= K:
            count[c] = n
        for k in range(K):
            out_lo[c, k] = s_lo[k] if k < n else np.inf
            out_hi[c, k] = s_hi[k] if k < n else -np.inf


@njit(parallel=True, cache=True)
def _columns_any(xs, ys, W, qmin, qmax, allowed, out_lo, out_hi, count):
    nx, ny, M, K = xs.shape[0], ys.shape[0], W.shape[0], out_lo.shape[2]
    qmin2, qmax2 = qmin * qmin, qmax * qmax
    for ix in prange(nx):
        s_lo, s_hi = np.empty(K), np.empty(K)
        t_lo, t_hi = np.empty(K), np.empty(K)
        b_lo, b_hi = np.empty(M * K), np.empty(M * K)
        for iy in range(ny):
            nb = 0
            over = False
            for m in range(M):
                if not allowed[ix, iy, m]:
                    continue
                n = 1
                s_lo[0], s_hi[0] = -np.inf, np.inf
                for i in range(6):
                    a1, b1, a2, b2 = _leg_pieces(xs[ix], ys[iy], W[m, i, 0], W[m, i, 1],
                                                 W[m, i, 2], qmin2, qmax2)
                    n = intersect_pair(s_lo, s_hi, n, a1, b1, a2, b2, t_lo, t_hi, K)
                    if n > K:
                        n = K
                        over = True
                    for k in range(n):
                        s_lo[k], s_hi[k] = t_lo[k], t_hi[k]
                    if n == 0:
                        break
                for k in range(n):
                    b_lo[nb], b_hi[nb] = s_lo[k], s_hi[k]
                    nb += 1
            for k in range(K):
                out_lo[ix, iy, k] = np.inf
                out_hi[ix, iy, k] = -np.inf
            c = union_merge(b_lo, b_hi, nb, out_lo[ix, iy], out_hi[ix, iy], K)
            count[ix, iy] = K + 1 if over else c


@dataclass(frozen=True)
class UPS6(Mechanism):
    """6-UPS geometry.

    Attributes:
        base_points: ``(6, 3)`` base U-joint centres (mm, base frame).
        platform_points: ``(6, 3)`` platform S-joint centres (mm, platform frame).
        stroke_window: leg-length window (min, max) in mm, 0 < min < max.
        tool_offset: ``(3,)`` tool-frame origin in the platform frame (mm).
    """

    family = "ups6"

    base_points: np.ndarray
    platform_points: np.ndarray
    stroke_window: tuple[float, float]
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]

    _ik_one = _ups_one

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 6))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 6))
        set_(self, "stroke_window", as_stroke(self.stroke_window, "stroke", positive=True))
        set_(self, "tool_offset", as_vector3(self.tool_offset, "tool_offset"))

    @classmethod
    def from_circles(cls, *, base_radii=(300.0, 300.0), platform_radii=(150.0, 150.0),
                     base_pair_angle: float | None = None,
                     platform_rotation: float = math.radians(30.0),
                     base_pair_separation: float = math.radians(20.0),
                     platform_pair_separation: float = math.radians(20.0),
                     pairing: str = "same", stroke=(400.0, 700.0), tool_offset=(0.0, 0.0, 0.0),
                     name: str = "", nominal=None) -> UPS6:
        """Paired layout on circles (see :mod:`pkmlab.mechanisms.layout`).

        Equal inner and outer radii with pair separations give the usual "two circles with pair
        separation angles" Gough–Stewart (``base_pair_angle=None`` solves it for equal
        legs); distinct inner/outer radii with zero separations give
        the Stoughton–Arai (1993) concentric-circle variant. Angles in rad, lengths in mm.
        """
        base_radii = _radii(base_radii, "base_radii")
        platform_radii = _radii(platform_radii, "platform_radii")
        B, P, desc = build_paired(base_radii, platform_radii, base_pair_angle,
                                  platform_rotation, base_pair_separation,
                                  platform_pair_separation, pairing)
        return cls(B, P, stroke, tool_offset, name=name, nominal=nominal, description=desc)

    @property
    def scale(self) -> float:
        return float(np.max(np.linalg.norm(self.base_points, axis=1))
                     + np.max(np.linalg.norm(self.platform_points, axis=1)) + self.stroke[1])

    def _gparams(self) -> np.ndarray:
        return np.concatenate([self.base_points.ravel(), self._tool_points().ravel()])

    def _legs(self, p, R):
        r = np.einsum("nij,kj->nki", R, self._tool_points())
        s = p[:, None, :] + r - self.base_points
        length = np.linalg.norm(s, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            n = s / length[..., None]
        return r, n, length

    def _jacobian(self, p, R):
        r, n, _ = self._legs(p, R)
        return np.concatenate([n, np.cross(r, n)], axis=-1)

    def _closure(self, p, R, q):
        r, n, length = self._legs(p, R)
        return length - q, np.concatenate([n, np.cross(r, n)], axis=-1)

    # ---- workspace hooks -------------------------------------------------------------------
    column_method = "quadratic"

    def _leg_offsets(self, R: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(np.einsum("mij,kj->mki", R, self._tool_points())
                                    - self.base_points)

    def _columns(self, xs, ys, R, mode, allowed=None, K=8):
        W = self._leg_offsets(R)
        nx, ny = len(xs), len(ys)
        lo = np.empty((nx, ny, K))
        hi = np.empty((nx, ny, K))
        count = np.zeros((nx, ny), dtype=np.int64)
        if mode == "all":
            if allowed is not None:
                raise ValueError("mode 'all' takes no orientation mask; mask the columns")
            X, Y = np.meshgrid(xs, ys, indexing="ij")
            flat_lo, flat_hi = lo.reshape(-1, K), hi.reshape(-1, K)
            _points_all(X.ravel(), Y.ravel(), W, *self.stroke, flat_lo, flat_hi,
                        count.reshape(-1))
        else:
            if allowed is None:
                allowed = np.ones((nx, ny, len(R)), dtype=np.bool_)
            _columns_any(xs, ys, W, *self.stroke, allowed, lo, hi, count)
        return lo, hi, int(np.sum(count > K))

    def _position_bounds(self, R):
        W = self._leg_offsets(R)
        qmax = self.stroke[1]
        return np.stack([(-W - qmax).max(axis=1), (-W + qmax).min(axis=1)], axis=1)

    def leg_segments(self, p, R):
        """Leg end points ``(N, 6, 3)`` each: base U joint → platform S joint."""
        W = p[:, None, :] + np.einsum("nij,kj->nki", R, self._tool_points())
        return np.broadcast_to(self.base_points, W.shape).copy(), W
