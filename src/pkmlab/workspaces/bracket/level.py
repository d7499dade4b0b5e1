"""One x-y level of the volume bracket (:mod:`.bracket`): its columns, their orientation
cells (items), the running samples, and one refinement step (evaluate, update the bounds, keep
the cells that can still move a bound). The derivations are in :mod:`.bracket`."""

from __future__ import annotations

import numpy as np

from .. import cells as oc
from .sets import inside, pieces_of, tri_volume, union

__all__ = ["Level", "BATCH"]

#: items (column × orientation cell) evaluated per batch at most; under a time budget the
#: batches are sized to take about ``bracket._Clock.BATCH_S`` each, and the budget is checked
#: between them
BATCH = 25_000


def _collect(parts):
    """Concatenate per-batch outputs of :meth:`Legs.bounds` (tuples and dicts of arrays)."""
    out = {}
    for k in parts[0] if parts else ():
        v = parts[0][k]
        if isinstance(v, dict):
            out[k] = {f: np.concatenate([p[k][f] for p in parts]) for f in v}
        else:
            out[k] = tuple(np.concatenate([p[k][i] for p in parts]) for i in range(len(v)))
    return out


def _vertices(C, H):
    """The distinct vertices of the cells ``C ± H``."""
    signs = np.array(np.meshgrid(*[(-1.0, 1.0)] * 3, indexing="ij")).reshape(3, -1).T
    V = (C[:, None, :] + signs[None] * H[:, None, :]).reshape(-1, 3)
    return np.unique(np.round(V, 12), axis=0)


class Level:
    """Columns of one x-y level with their orientation cells (items) and running samples."""

    def __init__(self, legs, kind, cx, cy, h, C0, H0, seed=None):
        """``seed (n, m, 3)``: rotations (set coordinates, NaN for none) evaluated as samples
        in the first step (the parent columns' best, :meth:`best_rotations`)."""
        self.legs, self.kind, self.h = legs, kind, h
        self.cx, self.cy = cx, cy
        n, L = len(cx), len(C0)
        self.col = np.repeat(np.arange(n), L)
        self.C = np.tile(C0, (n, 1))
        self.H = np.tile(H0, (n, 1))
        self.corners = _vertices(C0, H0)
        if kind == "reachable":
            e = np.empty(0)
            self.samples = (np.empty(0, np.int64), e, e, np.zeros(n + 1, np.int64))
            self.samples_out = self.samples
            self.hull = (np.full(n, np.inf), np.full(n, -np.inf))
        else:
            self.s_in = [np.full(n, -np.inf), np.full(n, np.inf), np.ones(n, bool)]
            self.s_out = [np.full(n, -np.inf), np.full(n, np.inf), np.ones(n, bool)]
            # x-y second order: samples' ends at the corners, best upper-volume pieces
            self.pl = {"top": np.full((n, 4), np.inf), "bot": np.full((n, 4), -np.inf),
                       "plane_c": np.full(n, np.inf), "plane": np.full((n, 4), np.inf),
                       "piece_c": np.full(n, -np.inf), "piece": np.full((n, 4), -np.inf)}
        self.pl_lower = self.pl_upper = self.reach_pl = self.reach_up = None
        self.pending = None
        self.best = {}
        if seed is not None:
            good = ~np.isnan(seed).any(axis=-1)
            self.pending = (np.nonzero(good)[0], seed[good])

    def best_rotations(self) -> np.ndarray:
        """``(n, m, 3)``: per column, the sample rotations that gave its best top and bottom
        (inner set, plane and piece), NaN where none."""
        n = len(self.cx)
        out = [self.best[k][1] for k in sorted(self.best)]
        return np.stack(out, axis=1) if out else np.full((n, 0, 3), np.nan)

    def _track(self, key, value, scol, sP, larger):
        """Keep per column the sample rotation with the largest (or smallest) ``value``."""
        n = len(self.cx)
        if key not in self.best:
            self.best[key] = (np.full(n, -np.inf if larger else np.inf), np.full((n, 3), np.nan))
        v0, P = self.best[key]
        v = np.where(np.isnan(value), -np.inf if larger else np.inf, value)
        best = v0.copy()
        (np.maximum if larger else np.minimum).at(best, scol, v)
        win = ((v > v0[scol]) if larger else (v < v0[scol])) & (v == best[scol])
        P[scol[win]] = sP[win]
        self.best[key] = (best, P)

    def step(self, clock=None):
        """Evaluate the items; update the samples; keep the live items. Returns the column
        sets ``(inner, outer, inner_if_exact, outer_if_exact)`` as piece arrays (the last two
        estimate the gap with the orientation part removed), or ``None`` when ``clock`` (the
        driver's time budget: ``batch``, ``allows``, ``done``) says the rest of
        the step would end past the budget: the level is then left as it was before it."""
        n = len(self.cx)
        reach = self.kind == "reachable"
        # (column of each item, rotation cells or points, halves or None for samples)
        groups = [(self.col, self.C, self.H)]
        if self.corners is not None:
            # the vertices of the first cells (where leg extremes often lie) as samples
            V = self.corners
            vc = np.repeat(np.arange(n), len(V))
            VV = np.tile(V, (n, 1))
            groups.append((vc, VV, None))
        if self.pending is not None:
            # the previous step's live cells' most promising vertices as samples
            pc, PV = self.pending
            vc = np.concatenate([vc, pc]) if self.corners is not None else pc
            groups.append((pc, PV, None))
        parts, vparts = [], []
        left = {True: len(self.col), False: sum(len(g[0]) for g in groups[1:])}
        for gcol, C, H in groups:
            s = 0
            cells = H is not None
            while s < max(len(gcol), 1 if cells else 0):
                size = clock.batch(cells) if clock is not None else BATCH
                if clock is not None and not clock.allows(left[True], left[False]):
                    return None                          # the rest of the step would not fit
                left[cells] -= len(gcol[s:s + size])
                sl = slice(s, s + size)
                b = self.legs.bounds(self.cx[gcol[sl]], self.cy[gcol[sl]], 0.5 * self.h, C[sl],
                                     None if H is None else H[sl], with_cells=H is not None,
                                     reachable=reach)
                if clock is not None:
                    clock.done(len(gcol[sl]), cells)
                (parts if H is not None else vparts).append(b)
                s += size
        ev = _collect(parts)
        col = scol = self.col
        sP = self.C
        T = ev.pop("toward")[0] if "toward" in ev else None
        if vparts:
            b = _collect(vparts)
            for k in ("in0", "out0", "pl_sample"):
                if k in b:
                    ev[k] = _collect([{k: ev[k]}, {k: b[k]}])[k] if k in ev else b[k]
            scol = np.concatenate([col, vc])
            sP = np.concatenate([self.C] + ([VV] if self.corners is not None else [])
                                + ([PV] if self.pending is not None else []))
            self.corners = self.pending = None
        if self.kind == "reachable":
            # lower: union of the samples' x-y inner sets; upper: union of the samples' x-y
            # outer sets and of the outer sets of the cells that still reach beyond them
            lo, hi, ok = ev["in0"]
            self.samples = union(n, self.samples[:3], (scol[ok], lo[ok], hi[ok]))
            self._track("in_hi", np.where(ok, hi, np.nan), scol, sP, True)
            self._track("in_lo", np.where(ok, lo, np.nan), scol, sP, False)
            if "pl_sample" in ev:
                self._reach_planar(ev["pl_sample"], lo, hi, ok, scol)
                pl = ev["pl_sample"]
                good = ev["out0"][2]
                with np.errstate(invalid="ignore"):
                    self._track("plane", np.where(good, pl["plane"].mean(axis=1), np.nan), scol,
                                sP, True)
                    self._track("piece", np.where(good, pl["piece"].mean(axis=1), np.nan),
                                scol, sP, False)
            lo, hi, ok = ev["out0"]
            self.samples_out = union(n, self.samples_out[:3], (scol[ok], lo[ok], hi[ok]))
            pcol, plo, phi, starts = self.samples_out
            lo, hi, ok = ev["outr"]
            outer_x = (pcol, plo, phi)
            if "pl_out" in ev:
                # x-y second order: keep the cells that can raise that bound; the outer
                # sets of the others are covered by their hull per column
                live = ok & self._reach_upper(ev["pl_sample"], ev["pl_out"], ev["out0"][2],
                                              scol, col)
                gone = ok & ~live
                np.minimum.at(self.hull[0], col[gone], lo[gone])
                np.maximum.at(self.hull[1], col[gone], hi[gone])
                hull = pieces_of(self.hull[0], self.hull[1], self.hull[0] <= self.hull[1])
                outer = union(n, outer_x, (col[live], lo[live], hi[live]), hull)[:3]
            else:
                live = ok.copy()
                live[ok] = ~inside(col[ok], lo[ok], hi[ok], starts, plo, phi)
                outer = union(n, outer_x, (col[live], lo[live], hi[live]))[:3]
            inner = self.samples[:3]
            self._keep(live)
            if T is not None:
                T = T[live]
                self.pending = (np.concatenate([self.col, self.col]),
                                np.concatenate([self.C + T[:, 0] * self.H,
                                                self.C + T[:, 1] * self.H]))
            return inner, outer, inner, outer_x
        for st, key in ((self.s_in, "in0"), (self.s_out, "out0")):
            lo, hi, ok = ev[key]
            np.maximum.at(st[0], scol, lo)
            np.minimum.at(st[1], scol, hi)
            np.logical_and.at(st[2], scol, ok)
        sin_ok = self.s_in[2] & (self.s_in[0] <= self.s_in[1])
        sout_ok = self.s_out[2] & (self.s_out[0] <= self.s_out[1])
        ref_lo = np.where(sin_ok, self.s_in[0], self.s_out[0])
        ref_hi = np.where(sin_ok, self.s_in[1], self.s_out[1])
        lo, hi, ok = ev["inr"]
        live = sout_ok[col] & (~ok | (lo > ref_lo[col]) | (hi < ref_hi[col]))
        if "pl_cell" in ev:
            live |= self._planar(ev["pl_sample"], ev["pl_cell"], ok, scol, col, live, sout_ok)
        ilo, ihi, iok = self.s_in[0].copy(), self.s_in[1].copy(), sin_ok.copy()
        lc = col[live]
        np.maximum.at(ilo, lc, lo[live])
        np.minimum.at(ihi, lc, hi[live])
        np.logical_and.at(iok, lc, ok[live])
        inner = pieces_of(ilo, ihi, iok & sout_ok)
        outer = pieces_of(self.s_out[0], self.s_out[1], sout_ok)
        inner_x = pieces_of(self.s_in[0], self.s_in[1], sin_ok & sout_ok)
        self._keep(live)
        return inner, outer, inner_x, outer

    def _planar(self, sample, cell, ok, scol, col, live, sout_ok):
        """x-y second order (dexterous): update the samples' corner values and upper-volume
        pieces, mark the cells that could still move a corner bound live, and set the
        per-column volume bounds ``pl_lower`` / ``pl_upper`` (mm³)."""
        pl, n = self.pl, len(self.cx)
        np.minimum.at(pl["top"], scol, sample["top"])
        np.maximum.at(pl["bot"], scol, sample["bot"])
        for key, better in (("plane", np.less), ("piece", np.greater)):
            best = pl[key + "_c"].copy()
            (np.minimum if key == "plane" else np.maximum).at(best, scol, sample[key + "_c"])
            win = better(sample[key + "_c"], pl[key + "_c"][scol]) \
                & (sample[key + "_c"] == best[scol])
            pl[key][scol[win]] = sample[key][win]
            pl[key + "_c"] = best
        grow = ~ok | np.any(cell["bot"] > pl["bot"][col], axis=1) \
            | np.any(cell["top"] < pl["top"][col], axis=1)
        grow &= sout_ok[col]
        keep = live | grow
        bot, top = pl["bot"].copy(), pl["top"].copy()
        np.maximum.at(bot, col[keep], cell["bot"][keep])
        np.minimum.at(top, col[keep], cell["top"][keep])
        fine = np.ones(n, bool)
        np.logical_and.at(fine, col[keep], ok[keep])
        a = 0.5 * self.h * self.h
        low = tri_volume(top - bot, a, np.maximum)
        self.pl_lower_x = tri_volume(pl["top"] - pl["bot"], a, np.maximum)
        self.pl_lower = np.where(fine & sout_ok, low, 0.0)
        self.pl_centre = (0.5 * (bot[:, 0] + bot[:, 2]), 0.5 * (top[:, 0] + top[:, 2]),
                          0.5 * (bot[:, 1] + bot[:, 3]), 0.5 * (top[:, 1] + top[:, 3]))
        A = pl["plane"] - pl["piece"]
        self.pl_upper = np.where(np.isfinite(A).all(axis=1),
                                 tri_volume(np.where(np.isfinite(A), A, 0.0), a, np.minimum),
                                 np.inf)
        return grow

    def _reach_planar(self, sample, lo, hi, ok, scol):
        """x-y second order (reachable), for columns whose union of samples is one interval
        ``[L, U]``: the sample ``a`` with the lowest inner end and ``b`` with the highest meet
        it at every point of the square, so the column holds ``[min(bottom_a, L),
        max(top_b, U)]`` everywhere; ``top_b`` is concave (at least its corner interpolation)
        and ``bottom_a`` below a convex bound (at most its corner interpolation)."""
        n = len(self.cx)
        if self.reach_pl is None:
            self.reach_pl = {"L": np.full(n, np.inf), "gbot": np.full((n, 4), np.inf),
                             "U": np.full(n, -np.inf), "top": np.full((n, 4), -np.inf)}
        st = self.reach_pl
        for end, val, key, better in (("L", lo, "gbot", np.less), ("U", hi, "top", np.greater)):
            v = np.where(ok, val, np.inf if end == "L" else -np.inf)
            best = st[end].copy()
            (np.minimum if end == "L" else np.maximum).at(best, scol, v)
            win = ok & better(v, st[end][scol]) & (v == best[scol])
            st[key][scol[win]] = sample[key][win]
            st[end] = best
        pcol, plo, phi, starts = self.samples
        one = np.diff(starts) == 1
        A = self.h * self.h
        t, g = st["top"], np.where(np.isfinite(st["gbot"]), st["gbot"], 1e12)
        int_t = A * np.maximum(2 * t[:, 0] + t[:, 1] + 2 * t[:, 2] + t[:, 3],
                               t[:, 0] + 2 * t[:, 1] + t[:, 2] + 2 * t[:, 3]) / 6
        int_g = A * np.minimum(2 * g[:, 0] + g[:, 1] + 2 * g[:, 2] + g[:, 3],
                               g[:, 0] + 2 * g[:, 1] + g[:, 2] + 2 * g[:, 3]) / 6
        with np.errstate(invalid="ignore"):
            vol = np.maximum(int_t, st["U"] * A) - np.minimum(int_g, st["L"] * A)
        self.pl_lower = np.where(one & np.isfinite(vol), np.maximum(vol, 0.0), 0.0)
        self.pl_upper = np.full(n, np.inf)
        self.pl_centre = (st["L"], st["U"])

    def _reach_upper(self, sample, cell, s_ok, scol, col):
        """x-y second order of the reachable upper bound. Over the square, the top of the
        union is at most the maximum over the cells of their affine top bounds (convex, so
        at most the linear interpolation of its corner values) and the bottom at least the
        minimum of their concave bottom bounds (at least the interpolation of corner lower
        bounds); so the column holds at most the integral of the interpolated difference's
        positive part. The samples' own affine top (``plane``) and concave bottom
        (``piece``) are kept in that maximum and minimum; a cell whose corner values do not
        pass them is dropped (it cannot raise the bound). Sets ``pl_upper`` (mm³ per column)
        and ``pl_upper_x`` (the samples alone). Returns the cells to keep for this bound."""
        n = len(self.cx)
        if self.reach_up is None:
            self.reach_up = {"top": np.full((n, 4), -np.inf), "bot": np.full((n, 4), np.inf)}
        st = self.reach_up
        good = s_ok[:, None]
        np.maximum.at(st["top"], scol, np.where(good & np.isfinite(sample["plane"]),
                                                sample["plane"], -np.inf))
        np.minimum.at(st["bot"], scol, np.where(good & np.isfinite(sample["piece"]),
                                                sample["piece"], np.inf))
        grow = np.any(cell["top"] > st["top"][col], axis=1) \
            | np.any(cell["bot"] < st["bot"][col], axis=1)
        top, bot = st["top"].copy(), st["bot"].copy()
        np.maximum.at(top, col[grow], cell["top"][grow])
        np.minimum.at(bot, col[grow], cell["bot"][grow])
        a = 0.5 * self.h * self.h
        self.pl_upper = _upper_volume(top, bot, a)
        self.pl_upper_x = _upper_volume(st["top"], st["bot"], a)
        return grow

    def _keep(self, live):
        self.col, self.C, self.H = self.col[live], self.C[live], self.H[live]

    def split(self):
        C, H, parent = oc.split(self.C, self.H)
        col = self.col[parent]
        order = np.argsort(col, kind="stable")
        self.col, self.C, self.H = col[order], C[order], H[order]


def _upper_volume(top, bot, a):
    """``∫ (top - bot)₊`` of the corner interpolation (both triangulations bound a convex
    difference from above: the smaller); ``inf`` where a corner is unbounded."""
    f = top - bot
    bad = np.isnan(f).any(axis=1) | np.isposinf(f).any(axis=1)
    v = tri_volume(np.where(np.isfinite(f), f, -1e12), a, np.minimum)
    return np.where(bad, np.inf, v)
