"""Bounds of each leg's column interval over an (x-y square × orientation cell) pair.

The derivation is in :mod:`pkmlab.workspaces.bracket.columns` (first order, from the monotone
ends and the rotation's angle bound) and in :meth:`Legs.second` (second order, from the ends' closed
form ``c + σ·sqrt(max(K - d², 0)) - w_z`` given by the family's ``column_profile()``). Every
bound is widened by ``EPS`` mm against floating-point rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ...mechanisms.kernels.columns import make_leg_eval
from .. import cells as oc

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

    @staticmethod
    def warm_up() -> None:
        """Load (or compile) the kernels of the bounds, so that a time budget does not pay
        for them."""
        _pair(np.zeros((1, 6)), np.zeros((1, 6, 3)), np.zeros((1, 3)))

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

    def bounds(self, cx, cy, s, C, H, with_cells=True, reachable=False):
        """Per item: the column intervals ``(lo, hi, ok)`` intersected over the legs:
        ``in0, out0`` (x-y cell at the centre rotation) and, ``with_cells``, ``inr, outr``
        (x-y cell × orientation cell). With the x-y second order (:attr:`planar`), also the
        samples' corner values ``pl_sample`` and the cells' ``pl_cell`` (dexterous: bounds
        from inside) or, ``reachable``, ``pl_out`` (bounds from outside)."""
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
        legs = {}
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
            legs[name] = (lo, hi)
        if self.planar:
            corner = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float) * s   # (4, 2)
            out["pl_sample"] = self._sample_corners(cx, cy, W, corner)
            if with_cells and reachable:
                out["pl_out"] = _outer_corners(second, out["outr"], corner)
                out["toward"] = _toward(second)
            elif with_cells:
                out["pl_cell"] = _cell_corners(second, legs["inr"], corner)
        return out

    @property
    def planar(self) -> bool:
        """Whether the x-y second-order (piecewise-linear) volume bounds apply: every end
        is ``c + sqrt(...)`` (concave in x-y), as for psu6 and ups6 above the base."""
        return self.profile is not None and bool(np.all(self.profile[:, :, 1] > 0))

    def _sample_corners(self, cx, cy, W, corner):
        """At exact rotations: each end at the square's corners, exact, and the volume-upper
        pieces (see :mod:`.bracket`): the tangent plane at the centre of the leg with the
        lowest upper end, the lower end at the corners of the leg with the highest one."""
        v0 = np.stack([cx[:, None] + W[..., 0], cy[:, None] + W[..., 1]], axis=-1)   # (n,6,2)
        vc = v0[:, :, None, :] + corner                                              # (n,6,4,2)
        d2 = np.sum(vc**2, axis=-1)
        c, K = self.profile[:, :, 0], self.profile[:, :, 2]                           # (6, 2)
        wz = W[..., 2][..., None]
        lo_end = c[:, 0, None] + np.sqrt(np.maximum(K[:, 0, None] - d2, 0)) - wz
        hi_end = c[:, 1, None] + np.sqrt(np.maximum(K[:, 1, None] - d2, 0)) - wz
        reach = d2 <= K[:, 1, None]                  # the upper end's sphere bounds the reach
        top = np.where(reach, hi_end, -np.inf).min(axis=1)                           # (n, 4)
        bot = np.where(reach, lo_end, np.inf).max(axis=1)
        d0 = np.sum(v0**2, axis=-1)                                                  # (n, 6)
        e_hi = c[:, 1] + np.sqrt(np.maximum(K[:, 1] - d0, 0)) - W[..., 2]
        e_lo = c[:, 0] + np.sqrt(np.maximum(K[:, 0] - d0, 0)) - W[..., 2]
        n = np.arange(len(cx))
        j = np.argmin(np.where(d0 < K[:, 1], e_hi, np.inf), axis=1)
        g = np.sqrt(np.maximum(K[j, 1] - d0[n, j], 0))
        with np.errstate(divide="ignore", invalid="ignore"):
            grad = -v0[n, j] / g[:, None]
        plane = e_hi[n, j, None] + grad @ corner.T
        ok_plane = (d0[n, j] < K[j, 1]) & np.all(plane >= (c[j, 1] - W[n, j, 2])[:, None], axis=1)
        k = np.argmax(np.where(d0 < K[:, 0], e_lo, -np.inf), axis=1)
        ok_piece = np.all(d2[n, k] < K[k, 0][:, None], axis=1)
        # a convex bound of the bottom over the square: per leg the tangent plane of its lower
        # end at the centre (or the flat part beyond the sphere), the larger over the legs
        g_lo = np.sqrt(np.maximum(K[:, 0] - d0, 0))
        inside = d0 < K[:, 0] * (1 - 1e-12)
        with np.errstate(divide="ignore", invalid="ignore"):
            gr = np.where(inside[..., None], -v0 / g_lo[..., None], 0.0)
        tang = np.maximum(e_lo[..., None] + gr @ corner.T, (c[:, 0] - W[..., 2])[..., None])
        gbot = np.where(inside.all(axis=1)[:, None], tang.max(axis=1), np.inf)
        return {"top": top, "bot": bot, "gbot": gbot,
                "plane_c": np.where(ok_plane, e_hi[n, j], np.inf),
                "plane": np.where(ok_plane[:, None], plane, np.inf),
                "piece_c": np.where(ok_piece, e_lo[n, k], -np.inf),
                "piece": np.where(ok_piece[:, None], lo_end[n, k], -np.inf)}


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
            lin_th = lin - (np.abs(ell[..., 0]) + np.abs(ell[..., 1])) * s
            out.append((np.where(inside, lo, -np.inf), np.where(inside, hi, np.inf),
                        {"E0": E0, "g": grad, "lin_th": lin_th, "flat": flat, "lz": lz,
                         "curv": curv, "inside": inside, "v": v,
                         "slope": np.einsum("nlkj,nlj->nlk", J, ell), "J": J, "rho": rho,
                         "r": r, "H": H, "K": K}))
        return out




def _cell_corners(second, box, corner):
    """Per item, at the x-y square's corners: an upper bound of the lower end that is convex
    over the square (per leg the tangent plane at the centre or the square's constant bound,
    whichever is lower on average), and a pointwise lower bound of the upper end."""
    (_, _, lo_end), (_, _, hi_end) = second
    box_lo, box_hi = box                                          # (n, 6), valid on the square
    tang = np.maximum(lo_end["E0"][..., None] + lo_end["lin_th"][..., None]
                      + lo_end["g"] @ corner.T, (lo_end["flat"] + lo_end["lz"])[..., None])
    tang = np.where(lo_end["inside"][..., None], tang, np.inf)
    use = tang.mean(axis=-1) < box_lo
    bot = np.where(use[..., None], tang, box_lo[..., None]).max(axis=1) + EPS
    pt = hi_end["E0"][..., None] + hi_end["g"] @ corner.T - hi_end["lin_th"][..., None] \
        - hi_end["curv"][..., None]                               # curv = ½·M·(s√2 + r)²
    pt = np.where(hi_end["inside"][..., None], pt, -np.inf)
    top = np.maximum(pt, box_hi[..., None]).min(axis=1) - EPS
    return {"bot": bot, "top": top}


def _outer_corners(second, box, corner):
    """Per item, at the x-y square's corners (reachable upper bound, see :mod:`.bracket`):

    * ``top``: an affine function of x-y above the top over the square × orientation cell:
      one leg's upper end is concave in x-y, so below its tangent plane at the square's centre
      (its points beyond the sphere are not reachable); over the cell the plane moves by at
      most the linearised rotation plus the remainder (``lin_th``). The leg with the lowest
      plane, or the cell's constant outer bound where that is lower on average;
    * ``bot``: lower bounds at the corners of a function that is concave in x-y and below the
      bottom over the cell: one leg's lower end minimised over the cell (a minimum of concave
      functions) where its sphere covers the moved square, bounded at each corner by the
      second-order expansion with curvature; or the cell's constant outer bound.

    Items whose outer set is empty get ``top = -inf``, ``bot = +inf`` (they reach nothing)."""
    (_, _, lo_end), (_, _, hi_end) = second
    box_lo, box_hi, ok = box                                     # (n,)
    Aj = _top_plane(hi_end, corner)
    top = np.where((Aj.mean(axis=-1) < box_hi)[:, None], Aj, box_hi[:, None]) + EPS
    bk = _bottom_corners(lo_end, corner)
    bot = np.where((bk.mean(axis=-1) > box_lo)[:, None], bk, box_lo[:, None]) - EPS
    return {"top": np.where(ok[:, None], top, -np.inf),
            "bot": np.where(ok[:, None], bot, np.inf)}


@njit(cache=True)
def _pair_kernel(a, sl, H, oi, oj, ow, ov):
    n = a.shape[0]
    for q in range(n):
        best, bi, bj, bw = np.inf, 0, 1, 1.0
        for i in range(6):
            for j in range(i + 1, 6):
                for c in range(5):
                    if c == 0:
                        t = 0.0
                    elif c == 1:
                        t = 1.0
                    else:
                        den = sl[q, j, c - 2] - sl[q, i, c - 2]
                        if den == 0.0:
                            continue
                        t = sl[q, j, c - 2] / den
                        if not (0.0 < t < 1.0):
                            continue
                    v = 0.0
                    if t > 0.0:
                        v += t * a[q, i]
                    if t < 1.0:
                        v += (1.0 - t) * a[q, j]
                    for k in range(3):
                        v += abs(t * sl[q, i, k] + (1.0 - t) * sl[q, j, k]) * H[q, k]
                    if v < best:
                        best, bi, bj, bw = v, i, j, t
        oi[q], oj[q], ow[q], ov[q] = bi, bj, bw, best


def _pair(a, sl, H):
    """The weights ``λ`` on one leg or two minimising ``Σ λ_i·a_i + Σ_k |Σ λ_i·sl_ik|·H_k``
    (``a (n, 6)``, ``inf`` for a leg that cannot be used; ``sl (n, 6, 3)``; ``H (n, 3)``):
    ``(i, j, w, value)`` with weight ``w`` on leg ``i`` and ``1 - w`` on leg ``j``. The
    objective is convex and piecewise linear in ``w``: its minimum is at 0, 1 or where a
    coordinate's combined slope cancels."""
    n = len(a)
    oi, oj = np.empty(n, np.int64), np.empty(n, np.int64)
    ow, ov = np.empty(n), np.empty(n)
    _pair_kernel(np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(sl, dtype=float),
                 np.ascontiguousarray(H, dtype=float), oi, oj, ow, ov)
    return oi, oj, ow, ov


def _mix(w, x, y):
    """``w·x + (1 - w)·y`` with a zero weight silencing an infinite term."""
    w = w.reshape(w.shape + (1,) * (x.ndim - w.ndim))
    with np.errstate(invalid="ignore"):
        return np.where(w > 0, w * x, 0.0) + np.where(w < 1, (1 - w) * y, 0.0)


def _top_plane(hi_end, corner):
    """``(n, 4)``: at the square's corners, an affine upper bound of the top over the square
    × cell: ``Σ λ_i·(tangent plane of leg i's upper end, moved over the cell)`` for the best
    weights on one leg or two (:func:`_pair`): the top is below every convex combination of
    the legs' upper ends, and two legs whose ends slope oppositely over the cell cancel
    their first-order terms."""
    sl, H = hi_end["slope"], hi_end["H"]
    rest = hi_end["lin_th"] - (np.abs(sl) * H[:, None, :]).sum(axis=-1)      # |ell|·rho
    a = np.where(hi_end["inside"], hi_end["E0"] + rest, np.inf)
    i, j, w, val = _pair(a, sl, H)
    n = np.arange(len(a))
    return val[:, None] + _mix(w, hi_end["g"][n, i], hi_end["g"][n, j]) @ corner.T


def _bottom_corners(lo_end, corner):
    """``(n, 4)``: at the square's corners, lower bounds of ``min over the cell of Σ λ_i·(leg
    i's lower end)`` (below the bottom, concave in x-y when every leg used has its sphere
    covering the moved square), for the best weights on one leg or two; each end is expanded
    about each corner point (curvature over the rotation's reach only)."""
    cover = lo_end["inside"] & np.isfinite(lo_end["curv"])               # (n, 6)
    K = lo_end["K"][None, :, None]
    vk = lo_end["v"][:, :, None, :] + corner                            # (n, 6, 4, 2)
    r = np.broadcast_to(lo_end["r"], cover.shape)[..., None]
    d2 = np.sum(vk**2, axis=-1)
    g0 = np.sqrt(np.maximum(K - d2, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        ell = np.concatenate([-vk / g0[..., None], -np.ones(d2.shape + (1,))], axis=-1)
        slope = np.einsum("nlmj,nlcj->nlcm", lo_end["J"], ell)          # (n, 6, 4, 3)
        rm = np.sqrt(d2) + r
        curv = np.where(rm**2 < K, 0.5 * K / (K - rm**2) ** 1.5 * r**2, np.inf)
    base = lo_end["flat"][..., None] + g0 - np.linalg.norm(ell, axis=-1) \
        * lo_end["rho"][..., None] - curv
    base = np.where(cover[..., None] & (d2 < K), base, -np.inf)
    H = lo_end["H"]
    # the weights from the centre's expansion, then exact corner values for them
    sl0 = lo_end["slope"]
    rest = lo_end["lin_th"] - (np.abs(sl0) * H[:, None, :]).sum(axis=-1) + lo_end["curv"]
    a = np.where(cover, -(lo_end["E0"] - rest), np.inf)
    i, j, w, _ = _pair(a, -sl0, H)
    n = np.arange(len(a))
    b = _mix(w, base[n, i], base[n, j]) - (np.abs(_mix(w, slope[n, i], slope[n, j]))
                                           * H[:, None, :]).sum(axis=-1)
    return np.where(np.isnan(b), -np.inf, b)


def _toward(second):
    """``((n, 2, 3),)`` signs per item: the cell vertex (centre + sign·half) where the linear
    model of the leg with the lowest upper end is highest (``[:, 0]``) and that of the leg
    with the highest lower end lowest (``[:, 1]``): candidate rotations for the top and the
    bottom of the union, used as extra samples by the reachable bracket."""
    (lo_lo, _, lo_end), (_, hi_hi, hi_end) = second
    n = np.arange(len(lo_lo))
    j = np.argmin(hi_hi, axis=1)
    k = np.argmax(np.where(np.isfinite(lo_lo), lo_end["E0"] - lo_end["lin_th"], -np.inf),
                  axis=1)
    return (np.stack([np.sign(hi_end["slope"][n, j]), -np.sign(lo_end["slope"][n, k])],
                     axis=1),)
