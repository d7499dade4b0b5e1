"""Each leg's extremes over a continuous orientation set, not just over its samples.

On a column, a dexterous workspace is ``[max_i max_θ a_i(θ), min_i min_θ b_i(θ)]`` where
``[a_i(θ), b_i(θ)]`` is leg i's stroke interval at orientation θ. Sampling θ on a grid
under-estimates every max and over-estimates every min, so the sampled workspace is slightly
too large. Here each (column, leg, bound) starts from its best sample and a pattern search
(compass search, step halved on failure) climbs to the continuous extreme inside the set's
parameter box; the result is the refined interval. Corners of the Euler box are not special:
a leg's extreme usually lies on an edge or face of the box, or inside it.
"""

from __future__ import annotations

import numpy as np

from ..mechanisms.kernels.columns import make_leg_eval
from .orientations import rotations_from_parameters

__all__ = ["refine_columns"]

_CHUNK = 4000


def _allowed_axes(oset, seeds: np.ndarray) -> np.ndarray:
    """``(n, 3)`` bool: which set coordinates a search from each seed may move."""
    if oset.kind == "fixed":
        return np.zeros(seeds.shape, dtype=bool)
    if oset.kind == "box" and oset.semantics == "single-axis":
        return seeds != 0.0          # stay on the seed's axis; the centre does not move
    allowed = np.ones(seeds.shape, dtype=bool)
    if oset.kind == "box":
        allowed &= np.array(oset.angles) > 0
    else:
        allowed &= np.array([oset.tilt > 0, oset.tilt > 0, oset.torsion > 0])
    return allowed


def _initial_steps(oset) -> np.ndarray:
    n = max(oset.samples - 1, 1)
    if oset.kind == "box":
        return np.array(oset.angles) / n
    return np.array([np.pi / (4 * n), oset.tilt / n, oset.torsion / n])


def refine_columns(mech, xs, ys, oset, lo, hi, iterations: int = 14):
    """Refine dexterous column intervals ``(nx, ny, 1)`` in place of copies.

    Returns ``(lo, hi, changed)`` where ``changed`` counts columns whose interval shrank by
    more than 1e-9 mm.
    """
    if mech.column_leg is None:
        raise ValueError(f"refine needs single-interval column legs; {mech.family!r} "
                         f"({mech.column_method}) has none")
    lo, hi = lo.copy(), hi.copy()
    alive = np.nonzero(lo[..., 0] <= hi[..., 0])
    if len(alive[0]) == 0 or oset.kind == "fixed":
        return lo, hi, 0
    params = oset.parameters()
    R = oset.rotations()
    W = mech.leg_offsets(R)                                 # (M, legs, 3)
    P = np.asarray(mech.column_params(), dtype=float)       # (legs, 3)
    n = W.shape[1]
    U, B = mech.tool_points, mech.base_points
    ev = make_leg_eval(type(mech).column_leg)
    bounds = oset.bounds()
    step0 = _initial_steps(oset)
    changed = 0
    for start in range(0, len(alive[0]), _CHUNK):
        ix, iy = alive[0][start:start + _CHUNK], alive[1][start:start + _CHUNK]
        C, M = len(ix), len(R)
        # values at every sample: (C, M, legs)
        x = np.broadcast_to(xs[ix, None, None], (C, M, n)).ravel()
        y = np.broadcast_to(ys[iy, None, None], (C, M, n)).ravel()
        a, b, ok = ev(x, y, np.broadcast_to(W, (C, M, n, 3)).reshape(-1, 3),
                      np.broadcast_to(P, (C, M, n, 3)).reshape(-1, 3))
        a = np.where(ok, a, np.inf).reshape(C, M, n)
        b = np.where(ok, b, -np.inf).reshape(C, M, n)
        best = []
        for vals, sign in ((a, 1.0), (b, -1.0)):              # maximise a, minimise b
            m0 = np.argmax(sign * vals, axis=1)                # (C, legs)
            theta = params[m0]                                 # (C, legs, 3)
            f = sign * np.take_along_axis(vals, m0[:, None, :], axis=1)[:, 0, :]
            theta, f = _pattern_search(mech, oset, ev, xs[ix], ys[iy], U, B, P, theta, f, sign,
                                       bounds, step0, iterations)
            best.append(sign * f)
        new_lo = np.max(best[0], axis=1)
        new_hi = np.min(best[1], axis=1)
        old_lo, old_hi = lo[ix, iy, 0], hi[ix, iy, 0]
        new_lo, new_hi = np.maximum(new_lo, old_lo), np.minimum(new_hi, old_hi)
        changed += int(np.sum((new_lo > old_lo + 1e-9) | (new_hi < old_hi - 1e-9)))
        dead = new_lo > new_hi
        lo[ix, iy, 0] = np.where(dead, np.inf, new_lo)
        hi[ix, iy, 0] = np.where(dead, -np.inf, new_hi)
    return lo, hi, changed


def _pattern_search(mech, oset, ev, x, y, U, B, P, theta, f, sign, bounds, step0, iterations):
    """Compass search maximising ``sign·bound`` per (column, leg) from ``theta (C, legs, 3)``."""
    C, n = theta.shape[:2]
    allowed = _allowed_axes(oset, theta.reshape(-1, 3)).reshape(C, n, 3)
    step = np.broadcast_to(step0 * 0.5, (C, n, 3)).copy()
    leg = np.broadcast_to(np.arange(n), (C, n))
    xx = np.broadcast_to(x[:, None], (C, n))
    yy = np.broadcast_to(y[:, None], (C, n))
    finite = np.isfinite(f)
    for _ in range(iterations):
        improved = np.zeros((C, n), dtype=bool)
        for k in range(3):
            for direction in (1.0, -1.0):
                cand = theta.copy()
                cand[..., k] += direction * step[..., k]
                cand[..., k] = np.clip(cand[..., k], bounds[k, 0], bounds[k, 1])
                move = allowed[..., k] & finite & (step[..., k] > 0)
                if not move.any():
                    continue
                sel = np.nonzero(move)
                Rc = rotations_from_parameters(oset, cand[sel])
                w = np.einsum("nij,nj->ni", Rc, U[leg[sel]]) - B[leg[sel]]
                a, b, ok = ev(xx[sel], yy[sel], w, P[leg[sel]])
                val = sign * np.where(ok, a if sign > 0 else b, sign * np.inf)
                better = val > f[sel]
                s0, s1 = sel[0][better], sel[1][better]
                f[s0, s1] = val[better]
                theta[s0, s1] = cand[s0, s1]
                improved[s0, s1] = True
        step[~improved] *= 0.5
    return theta, f
