"""Bounds of each leg's column interval over an (x-y square × orientation cell) pair.

The derivation is in :mod:`pkmlab.workspaces.bracket` (first order, from the monotone ends and
the rotation's angle bound) and in :meth:`Legs.second` (second order, from the ends' closed
form ``c + σ·sqrt(max(K - d², 0)) - w_z`` given by the family's ``column_profile()``). Every
bound is widened by ``EPS`` mm against floating-point rounding.
"""

from __future__ import annotations

import math

import numpy as np

from ..mechanisms._kernels import make_leg_eval
from . import cells as oc

__all__ = ["Legs", "EPS"]

#: floating-point slack (mm) added to every outer set and removed from every inner one
EPS = 1e-9





class Legs:
    """What the leg bounds need from the mechanism."""

    def __init__(self, mech, oset):
        self.mech, self.oset = mech, oset
        self.eval = make_leg_eval(type(mech).column_leg)
        self.P = np.asarray(mech.column_params(), float)            # (6, 3)
        self.unorm = np.linalg.norm(mech.tool_points, axis=1)        # (6,)
        self.profile = mech.column_profile()                         # (6, 2, 3) or None
        self.count = 0

    def ends(self, d):
        """``A(d), B(d), ok(d)`` per leg for ``d (..., 6)``."""
        shape = d.shape
        n = d.size
        P = np.broadcast_to(self.P, shape + (3,)).reshape(-1, 3)
        a, b, ok = self.eval(d.ravel(), np.zeros(n), np.zeros((n, 3)), P)
        self.count += n
        return a.reshape(shape), b.reshape(shape), ok.reshape(shape)

    def reach(self) -> np.ndarray:
        """``(6,)`` largest ``d`` at which each leg has a z set (bisection on ``ok``)."""
        lo, hi = np.zeros(6), np.full(6, 10.0 * self.mech.scale + 1.0)
        _, _, ok = self.ends(hi[None, :])
        hi = np.where(ok[0], np.inf, hi)                 # unbounded legs: no limit
        fin = np.isfinite(hi)
        for _ in range(60):
            mid = np.where(fin, 0.5 * (lo + hi), 0.0)
            _, _, ok = self.ends(mid[None, :])
            lo = np.where(ok[0] & fin, mid, lo)
            hi = np.where(~ok[0] & fin, mid, hi)
        return hi

    def bounds(self, cx, cy, s, C, H, with_cells=True):
        """Per item: the column intervals ``(lo, hi, ok)`` intersected over the legs:
        ``in0, out0`` (x-y cell at the centre rotation) and, ``with_cells``, ``inr, outr``
        (x-y cell × orientation cell)."""
        R = self.oset.rotations_at(C)
        W = self.mech.leg_offsets(R)                                 # (n, 6, 3)
        ax = np.abs(cx[:, None] + W[..., 0])
        ay = np.abs(cy[:, None] + W[..., 1])
        dmin = np.hypot(np.maximum(ax - s, 0.0), np.maximum(ay - s, 0.0))
        dmax = np.hypot(ax + s, ay + s)
        if with_cells:
            r = oc.chord(oc.angle_bound(self.oset, C, H))[:, None] * self.unorm
            d = np.stack([dmin, dmax, np.maximum(dmin - r, 0.0), dmax + r])
            todo = (("in0", 0, 1, 0.0), ("out0", 0, 1, 0.0), ("inr", 2, 3, r),
                    ("outr", 2, 3, r))
        else:
            d = np.stack([dmin, dmax])
            todo = (("in0", 0, 1, 0.0), ("out0", 0, 1, 0.0))
        a, b, ok = self.ends(d)
        wz = W[..., 2]
        second = (self.second(cx, cy, s, C, H, W, r) if with_cells and self.profile is not None
                  else None)
        out = {}
        for name, i, j, rr in todo:
            if name.startswith("in"):
                lo = np.maximum(a[i], a[j]) - wz + rr
                hi = np.minimum(b[i], b[j]) - wz - rr
                good = ok[j]
            else:
                lo = np.minimum(a[i], a[j]) - wz - rr
                hi = np.maximum(b[i], b[j]) - wz + rr
                good = ok[i]
            if second is not None and name == "inr":
                lo, hi = np.minimum(lo, second[0][1]), np.maximum(hi, second[1][0])
            elif second is not None and name == "outr":
                lo, hi = np.maximum(lo, second[0][0]), np.minimum(hi, second[1][1])
            sgn = 1.0 if name.startswith("in") else -1.0
            L, Hh = (lo + sgn * EPS).max(axis=1), (hi - sgn * EPS).min(axis=1)
            out[name] = (L, Hh, good.all(axis=1) & (L <= Hh))
        return out


    def second(self, cx, cy, s, C, H, W, r):
        """Second-order bounds ``((min, max) of the lower end, (min, max) of the upper end)``
        per item and leg, from the ends' closed form ``c + σ·sqrt(max(K - d², 0)) - w_z``:
        the linear part is bounded exactly over the x-y square and the linearised orientation
        cell, the rest by the remainder of ``R·u`` and the sphere's curvature (on the side
        where the end is not concave / convex; none is needed on the other)."""
        Ru = W + self.mech.base_points                                # (n, 6, 3)
        A = oc.axes(self.oset, C)                                     # (n, 3, 3)
        J = np.cross(A[:, None, :, :], Ru[:, :, None, :])             # (n, 6, k, 3)
        rho = oc.remainder(self.oset, C, H)[:, None] * self.unorm      # (n, 6)
        v = np.stack([cx[:, None] + W[..., 0], cy[:, None] + W[..., 1]], axis=-1)
        vn = np.linalg.norm(v, axis=-1)
        Dv = s * math.sqrt(2) + r
        lz = (np.abs(J[..., 2]) * H[:, None, :]).sum(axis=-1) + rho    # range of Δw_z
        out = []
        for e in range(2):
            c, sig, K = (self.profile[:, e, k] for k in range(3))
            g0 = np.sqrt(np.maximum(K - vn**2, 0.0))
            inside = vn**2 < K * (1 - 1e-12)
            with np.errstate(divide="ignore", invalid="ignore"):
                grad = np.where(inside[..., None], -sig[:, None] * v / g0[..., None], 0.0)
            ell = np.concatenate([grad, -np.ones(vn.shape + (1,))], axis=-1)   # (n, 6, 3)
            lin = (np.abs(ell[..., 0]) + np.abs(ell[..., 1])) * s \
                + (np.abs(np.einsum("nlkj,nlj->nlk", J, ell)) * H[:, None, :]).sum(axis=-1) \
                + np.linalg.norm(ell, axis=-1) * rho
            E0 = c + sig * g0 - W[..., 2]
            flat = c - W[..., 2]
            rmax = vn + Dv
            with np.errstate(divide="ignore", invalid="ignore"):
                curv = np.where(rmax**2 < K, 0.5 * K / (K - rmax**2) ** 1.5 * Dv**2, np.inf)
            up = sig > 0
            hi = np.where(up, np.maximum(E0 + lin, flat + lz), E0 + lin + curv)
            lo = np.where(up, E0 - lin - curv, np.minimum(E0 - lin, flat - lz))
            out.append((np.where(inside, lo, -np.inf), np.where(inside, hi, np.inf)))
        return out


