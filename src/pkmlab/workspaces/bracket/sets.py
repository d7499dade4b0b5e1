"""Column piece sets of the volume bracket (:mod:`.bracket`): unions per column, containment,
the component through the nominal position, and the exact integral of the positive part of an
affine function over a triangle (the x-y second-order volumes)."""

from __future__ import annotations

import numpy as np
from numba import njit

from ...mechanisms.kernels.intervals import label_pieces

__all__ = ["union", "inside", "pieces_of", "length", "tri_positive", "tri_volume", "connected",
           "warm_up"]


# ---- interval helpers ---------------------------------------------------------------------------


@njit(cache=True)
def _merge(col, lo, hi, ncol, out_lo, out_hi, starts):
    """Union per column of intervals sorted by (column, lo); returns the piece count.

    ``starts (ncol + 1)`` receives each column's first piece."""
    m = 0
    n = col.shape[0]
    t = 0
    for c in range(ncol):
        starts[c] = m
        have = False
        cl, ch = 0.0, 0.0
        while t < n and col[t] == c:
            if have and lo[t] <= ch:
                if hi[t] > ch:
                    ch = hi[t]
            else:
                if have:
                    out_lo[m], out_hi[m] = cl, ch
                    m += 1
                cl, ch, have = lo[t], hi[t], True
            t += 1
        if have:
            out_lo[m], out_hi[m] = cl, ch
            m += 1
    starts[ncol] = m
    return m


@njit(cache=True)
def inside(col, lo, hi, starts, plo, phi):
    """``[lo, hi] ⊂`` one piece of column ``col``, for each query."""
    out = np.zeros(col.shape[0], dtype=np.bool_)
    for q in range(col.shape[0]):
        c = col[q]
        for k in range(starts[c], starts[c + 1]):
            if plo[k] <= lo[q] and hi[q] <= phi[k]:
                out[q] = True
                break
    return out


def union(ncol, *parts):
    """Union per column of ``(col, lo, hi)`` interval arrays → pieces ``(col, lo, hi,
    starts)``."""
    col = np.concatenate([p[0] for p in parts]).astype(np.int64)
    lo = np.concatenate([p[1] for p in parts]).astype(float)
    hi = np.concatenate([p[2] for p in parts]).astype(float)
    good = lo <= hi
    col, lo, hi = col[good], lo[good], hi[good]
    order = np.lexsort((lo, col))
    col, lo, hi = col[order], lo[order], hi[order]
    out_lo, out_hi = np.empty(len(lo)), np.empty(len(lo))
    starts = np.empty(ncol + 1, dtype=np.int64)
    m = _merge(col, lo, hi, ncol, out_lo, out_hi, starts)
    pcol = np.repeat(np.arange(ncol), np.diff(starts))
    return pcol, out_lo[:m], out_hi[:m], starts


def pieces_of(lo, hi, ok):
    """Single intervals per column → pieces ``(col, lo, hi)``."""
    good = ok & (lo <= hi)
    idx = np.nonzero(good)[0]
    return idx, lo[idx], hi[idx]


def length(pieces) -> float:
    return float(np.sum(pieces[2] - pieces[1])) if len(pieces[0]) else 0.0


def tri_positive(f1, f2, f3, area):
    """``∫ max(f, 0)`` over a triangle of ``area`` for ``f`` affine with vertex values."""
    v = np.sort(np.stack([f1, f2, f3]), axis=0)[::-1]
    a, b, c = (np.maximum(np.minimum(x, 1e12), -1e12) for x in v)
    with np.errstate(divide="ignore", invalid="ignore"):
        one = area * a**3 / (3 * (a - b) * (a - c))
        two = area * (a + b + c) / 3 + area * (-c) ** 3 / (3 * (a - c) * (b - c))
    out = np.where(c >= 0, area * (a + b + c) / 3,
                   np.where(a <= 0, 0.0, np.where(b <= 0, one, two)))
    return np.nan_to_num(out, nan=0.0, posinf=0.0)


def tri_volume(f, area, pick):
    """``∫ f₊`` over the square from corner values ``f (n, 4)`` (corners counter-clockwise),
    under its two triangulations, combined by ``pick`` (max for a lower bound of a concave
    ``f``, min for an upper bound by an affine one)."""
    d1 = tri_positive(f[:, 0], f[:, 1], f[:, 2], area) + tri_positive(f[:, 0], f[:, 2],
                                                                         f[:, 3], area)
    d2 = tri_positive(f[:, 0], f[:, 1], f[:, 3], area) + tri_positive(f[:, 1], f[:, 2],
                                                                         f[:, 3], area)
    return pick(d1, d2)


# ---- connectivity -------------------------------------------------------------------------------


def connected(pieces, cx, cy, h, p_nom):
    """Keep the pieces of the component through ``p_nom``: ``(pieces, found)``."""
    pcol, plo, phi = pieces
    if len(pcol) == 0:
        return pieces, False
    ix = np.round((cx - cx.min()) / h).astype(np.int64)
    iy = np.round((cy - cy.min()) / h).astype(np.int64)
    nx, ny = int(ix.max()) + 1, int(iy.max()) + 1
    starts = np.searchsorted(pcol, np.arange(len(cx) + 1))
    rank = np.arange(len(pcol)) - starts[pcol]
    K = int(rank.max()) + 1
    lo = np.full((nx, ny, K), np.inf)
    hi = np.full((nx, ny, K), -np.inf)
    lo[ix[pcol], iy[pcol], rank] = plo
    hi[ix[pcol], iy[pcol], rank] = phi
    labels, _ = label_pieces(lo, hi, 0.0)
    lab = labels[ix[pcol], iy[pcol], rank]
    near = ((np.abs(cx[pcol] - p_nom[0]) <= h / 2) & (np.abs(cy[pcol] - p_nom[1]) <= h / 2)
            & (plo <= p_nom[2]) & (p_nom[2] <= phi))
    if not near.any():
        return pieces, False
    keep = lab == lab[np.argmax(near)]
    return (pcol[keep], plo[keep], phi[keep]), True


def warm_up() -> None:
    """Load (or compile) the numba kernels used here, so that a time budget does not pay
    for them."""
    one, z = np.ones(1), np.zeros(1)
    pcs = union(1, (np.zeros(1, np.int64), z, one))
    inside(pcs[0], z, one, pcs[3], pcs[1], pcs[2])
    connected(pcs[:3], z, z, 1.0, np.array([0.0, 0.0, 0.5]))
