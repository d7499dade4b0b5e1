"""A guaranteed bracket ``[lower, upper]`` on a workspace volume over the continuous
orientation set and the continuous x-y plane.

The engine (:mod:`.engine`) is exact in z, but samples the orientation set and takes one column
per ``h × h`` cell of the x-y plane. Here both are covered instead of sampled.

**Leg bound over a cell.** For a family with radial column kernels (``column_radial``: psu6,
ups6), leg ``i``'s stroke-feasible z set on the column through ``(x, y)`` at rotation ``R`` is
``[A_i(d) - w_z, B_i(d) - w_z]`` where ``w = R·u_i - b_i`` (:meth:`leg_offsets`), ``d = |(x, y)
+ w_xy|``, ``A_i`` and ``B_i`` are monotone in ``d``, and the set exists for ``d <= d_i``.
(The ends are the family's own ``column_leg`` evaluated at ``(d, 0)`` with ``w = 0``; a test
checks this form for every such family.) Take an x-y cell (the square of half-width ``s``
about a column) and an orientation cell (:mod:`.cells`) with centre rotation ``R0`` and angle
bound α. Over the pair, ``w`` stays within ``r_i = 2 sin(α/2)·|u_i|`` of ``w0 = R0·u_i -
b_i``, so ``d`` lies in ``[d⁻ - r_i, d⁺ + r_i]`` (``d⁻, d⁺`` the exact nearest and farthest
distance of the square shifted by ``w0_xy``) and ``w_z`` in ``w0_z ± r_i``. Monotone ends take
their extremes at the ends of the ``d`` range, so

* *inner* (feasible at every point and rotation of the pair):
  ``[max A(d±) - w0_z + r, min B(d±) - w0_z - r]``, if the set exists at ``d⁺ + r``;
* *outer* (no point or rotation of the pair is feasible outside):
  ``[min A(d±) - w0_z - r, max B(d±) - w0_z + r]``, none if it fails at ``d⁻ - r``;

and the same with ``r = 0`` bound the x-y cell at the centre rotation alone (a *sample*).

**Volumes.** With ``I`` and ``O`` the inner and outer column sets, ``Σ h²·|I| <= V <=
Σ h²·|O|`` over the cells:

* constant and dexterous (every orientation): ``I`` = intersection over the cells and legs of
  the inner sets; ``O`` = intersection over the sampled centre rotations of the outer sets at
  ``r = 0`` (a point feasible for every rotation is feasible for the samples);
* reachable (some orientation): ``I`` = union over the sampled centre rotations of their inner
  sets; ``O`` = union over the cells of the outer sets.

**Refinement.** Per column, a cell whose inner set does not cut the running intersection of
samples (dexterous), or whose outer set is empty or inside the running union of samples
(reachable), can never move a bound: it is dropped. The others are split (branch and bound)
while the orientation part of the gap is the larger; otherwise the x-y cells are halved and
the search restarts on the children of the columns still in the outer set. It stops when
``upper - lower <= target·upper`` or the budget (seconds or leg evaluations) runs out, and
says which.

**Connected to nominal.** Components are taken on the inner and outer sets separately (cells
8-adjacent, z sets touching). The component of the inner set that contains the nominal
position is a connected subset of the workspace through it, so it lies in the kept component;
the kept component lies in the outer set's component through the nominal position. Both
bounds are therefore guaranteed for "the component containing the nominal position". When the
nominal position is not inside the inner set, the lower bound is 0; when it is outside the outer
set the nominal position is certainly not in the workspace, the engine keeps the component
*nearest* to it (not a set-theoretic rule), and the bracket covers every component instead
(lower 0, upper the whole outer set), with a note.

Only the actuator stroke (and connectivity) are bracketed; other constraints are refused.
Families without column kernels that bound their legs over cells (``cell_bounds``: luzi3)
are bracketed on position × orientation cells instead (:mod:`.bracket_cells`).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time

import numpy as np

from ..errors import ParameterError
from ..poses import as_frames, matrix_to_euler
from . import cells as oc
from .bracket_cells import cell_volume_bracket
from .bracket_result import VolumeBracket
from .bracket_sets import connected, inside, length, pieces_of, tri_volume, union
from .constraints import Constraints
from .legbounds import Legs
from .orientations import OrientationSet

log = logging.getLogger(__name__)

__all__ = ["VolumeBracket", "volume_bracket"]

#: items (column × orientation cell) evaluated per batch
_BATCH = 100_000


# ---- one x-y level ------------------------------------------------------------------------------


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


class _Level:
    """Columns of one x-y level with their orientation cells (items) and running samples."""

    def __init__(self, legs, kind, cx, cy, h, C0, H0):
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
        else:
            self.s_in = [np.full(n, -np.inf), np.full(n, np.inf), np.ones(n, bool)]
            self.s_out = [np.full(n, -np.inf), np.full(n, np.inf), np.ones(n, bool)]
            # x-y second order: samples' ends at the corners, best upper-volume pieces
            self.pl = {"top": np.full((n, 4), np.inf), "bot": np.full((n, 4), -np.inf),
                       "plane_c": np.full(n, np.inf), "plane": np.full((n, 4), np.inf),
                       "piece_c": np.full(n, -np.inf), "piece": np.full((n, 4), -np.inf)}
        self.pl_lower = self.pl_upper = self.reach_pl = None

    def step(self):
        """Evaluate the items; update the samples; keep the live items. Returns the column
        sets ``(inner, outer, inner_if_exact, outer_if_exact)`` as piece arrays (the last two
        estimate the gap with the orientation part removed)."""
        n = len(self.cx)
        parts = [self.legs.bounds(self.cx[self.col[s:s + _BATCH]],
                                  self.cy[self.col[s:s + _BATCH]], 0.5 * self.h,
                                  self.C[s:s + _BATCH], self.H[s:s + _BATCH])
                 for s in range(0, max(len(self.col), 1), _BATCH)]
        ev = _collect(parts)
        col = scol = self.col
        if self.corners is not None:
            # the vertices of the first cells (where leg extremes often lie) as samples
            V = self.corners
            vc = np.repeat(np.arange(n), len(V))
            b = self.legs.bounds(self.cx[vc], self.cy[vc], 0.5 * self.h, np.tile(V, (n, 1)),
                                 None, with_cells=False)
            for k in ("in0", "out0", "pl_sample"):
                if k in b:
                    ev[k] = _collect([{k: ev[k]}, {k: b[k]}])[k] if k in ev else b[k]
            scol = np.concatenate([col, vc])
            self.corners = None
        if self.kind == "reachable":
            # lower: union of the samples' x-y inner sets; upper: union of the samples' x-y
            # outer sets and of the outer sets of the cells that still reach beyond them
            lo, hi, ok = ev["in0"]
            self.samples = union(n, self.samples[:3], (scol[ok], lo[ok], hi[ok]))
            if "pl_sample" in ev:
                self._reach_planar(ev["pl_sample"], lo, hi, ok, scol)
            lo, hi, ok = ev["out0"]
            self.samples_out = union(n, self.samples_out[:3], (scol[ok], lo[ok], hi[ok]))
            pcol, plo, phi, starts = self.samples_out
            lo, hi, ok = ev["outr"]
            live = ok.copy()
            live[ok] = ~inside(col[ok], lo[ok], hi[ok], starts, plo, phi)
            outer_x = (pcol, plo, phi)
            outer = union(n, outer_x, (col[live], lo[live], hi[live]))[:3]
            inner = self.samples[:3]
            self._keep(live)
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

    def _keep(self, live):
        self.col, self.C, self.H = self.col[live], self.C[live], self.H[live]

    def split(self):
        C, H, parent = oc.split(self.C, self.H)
        col = self.col[parent]
        order = np.argsort(col, kind="stable")
        self.col, self.C, self.H = col[order], C[order], H[order]


# ---- driver -------------------------------------------------------------------------------------


def _request(mech, kind, orientations, resolution, constraints):
    from .engine import check_request

    check_request(kind, resolution)
    if not mech.cell_bounds and (not mech.column_radial or mech.column_method is None):
        raise ParameterError("bracket", "a family with radial column kernels (psu6, ups6) or "
                             f"cell leg bounds (luzi3); family {mech.family!r} has neither",
                             mech.family)
    cons = constraints or Constraints()
    if cons.extra:
        raise ParameterError("constraints", "the stroke (and connectivity) only: a volume "
                             "bracket does not cover joint limits, link diameter or kappa_max",
                             cons.describe())
    if cons.stroke is not True:
        mech = dataclasses.replace(mech, stroke_window=cons.stroke)
    oset = orientations or OrientationSet.fixed()
    if kind == "constant" and oset.kind != "fixed":
        raise ParameterError("orientations", "a single fixed orientation for kind 'constant'",
                             oset.kind)
    _, Rn = as_frames(mech.nominal_pose)
    return mech, oset.centred(tuple(matrix_to_euler(Rn[0]))), cons


def volume_bracket(mech, kind: str = "constant", orientations: OrientationSet | None = None,
                   resolution: float = 2.5, constraints: Constraints | None = None,
                   target: float = 0.01, budget_s: float = 30.0,
                   max_evaluations: float = 5e9, max_cells: int = 3_000_000) -> VolumeBracket:
    """Bracket the volume of a workspace over the continuous orientation set (module notes).

    Args:
        mech, kind, orientations, resolution, constraints: as for :func:`pkmlab.workspace`;
            ``resolution`` is the first x-y cell size (halved as needed).
        target: stop when ``upper - lower <= target·upper``.
        budget_s: wall-time budget (s); the step running when it runs out completes.
        max_evaluations: budget of leg-bound evaluations.
        max_cells: largest number of (column × orientation cell) items of one step.
    """
    t0 = time.perf_counter()
    mech, oset, cons = _request(mech, kind, orientations, resolution, constraints)
    if mech.cell_bounds:
        return cell_volume_bracket(mech, kind, oset, resolution, cons, target, budget_s,
                                   max_cells, max_evaluations)
    legs = Legs(mech, oset)
    p_nom = mech.nominal_pose[:3]
    # every feasible p has |p_xy + w_xy| <= reach_i, |w_xy + b_xy| <= |u_i|
    reach = legs.reach()
    rad = reach + legs.unorm
    B = mech.base_points[:, :2]
    box_lo = np.max(B - rad[:, None], axis=0)
    box_hi = np.min(B + rad[:, None], axis=0)
    h = float(resolution)
    history: list[dict] = []
    notes: list[str] = []
    C0, H0 = oc.initial_cells(oset, 1)
    if np.any(box_lo > box_hi):
        return VolumeBracket(0.0, 0.0, target, "empty", history, h, legs.count,
                             time.perf_counter() - t0, ["no position is within every leg's "
                                                        "reach"])
    gx = np.arange(math.floor(box_lo[0] / h), math.ceil(box_hi[0] / h) + 1) * h
    gy = np.arange(math.floor(box_lo[1] / h), math.ceil(box_hi[1] / h) + 1) * h
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    cx, cy = X.ravel(), Y.ravel()
    level = 0
    stop = None
    lower, upper, outside, seen_outside = 0.0, math.inf, False, False
    while stop is None:
        lv = _Level(legs, kind, cx, cy, h, C0, H0)
        while True:
            inner, outer, inner_x, outer_x = lv.step()
            lo_s, up_s, note, kept = _volumes(inner, outer, cons, lv, p_nom)
            elapsed = time.perf_counter() - t0
            history.append({"level": level, "h_mm": h, "items": int(len(lv.col)),
                            "lower_mm3": lo_s, "upper_mm3": up_s, "seconds": elapsed,
                            "evaluations": legs.count})
            log.debug("bracket %s", history[-1])
            # every step's bracket holds, so their intersection does (after the nominal
            # position is found outside, only the steps covering every component bound above)
            outside = outside or note is not None
            lower = max(lower, lo_s)
            if note is not None and not seen_outside:
                upper = up_s
            elif note is not None or not outside:
                upper = min(upper, up_s)
            seen_outside = outside
            gap = upper - lower
            if upper <= 0 or gap <= target * upper:
                stop = "converged" if upper > 0 else "empty"
            elif elapsed >= budget_s:
                stop = "budget: seconds"
            elif legs.count >= max_evaluations:
                stop = "budget: evaluations"
            if stop is not None:
                break
            g_orient = (length(inner_x) - length(inner)
                        + length(outer) - length(outer_x)) * h * h
            g_all = (length(outer) - length(inner)) * h * h
            if lv.pl_lower is not None and kind != "reachable":
                g_orient = max(0.0, float(lv.pl_lower_x.sum() - lv.pl_lower.sum()))
                g_all = gap
            if not np.any(lv.H > 0) or g_orient <= 0.5 * (g_all - g_orient):
                break                                    # the x-y cells dominate: halve h
            nxt = len(lv.col) * 8
            if nxt > max_cells:
                stop = "budget: cells"
                break
            lv.split()
        if stop is None:
            alive = np.unique(kept[1][0])
            cx = np.concatenate([lv.cx[alive] + dx * h / 4 for dx in (-1, 1) for _ in (0, 1)])
            cy = np.concatenate([lv.cy[alive] + dy * h / 4 for _ in (0, 1) for dy in (-1, 1)])
            h *= 0.5
            level += 1
            if len(cx) * len(C0) > max_cells:
                stop = "budget: cells"
    if outside:
        notes.append("the nominal position is outside the workspace: the bracket covers every "
                     "component (lower 0)")
    return VolumeBracket(lower, upper, target, stop, history, lv.h, legs.count,
                         time.perf_counter() - t0, notes,
                         np.stack([lv.cx, lv.cy], axis=1), kept[0], kept[1])


def _volumes(inner, outer, cons, lv, p_nom):
    """Bracket (mm³) with connectivity: ``(lower, upper, note, (inner, outer) kept)``.

    Per column, the box sets' volume is combined with the x-y second-order bounds when
    there are any (dexterous and constant): the larger lower bound, the smaller upper one. A
    column's second-order lower region (convex: above a convex bound, below a concave one)
    counts only when it meets the column's kept box piece (so it joins the kept component)."""
    a = lv.h * lv.h
    e = np.empty(0)
    note = None
    if cons.connected:
        out_k, found_out = connected(outer, lv.cx, lv.cy, lv.h, p_nom)
        in_k, found_in = connected(inner, lv.cx, lv.cy, lv.h, p_nom)
        if not found_out:
            note = ("the nominal position is outside the workspace: the bracket covers every "
                    "component (lower 0)")
            out_k = outer
        if not (found_in and found_out):
            in_k = (np.empty(0, np.int64), e, e)
    else:
        in_k, out_k = inner, outer
    n = len(lv.cx)
    low = np.bincount(in_k[0], in_k[2] - in_k[1], minlength=n) * a
    up = np.bincount(out_k[0], out_k[2] - out_k[1], minlength=n) * a
    if lv.pl_lower is not None:
        up = np.minimum(up, lv.pl_upper)
        b0, t0 = lv.pl_centre[0][in_k[0]], lv.pl_centre[1][in_k[0]]
        meet = np.zeros(n, bool)
        meet[in_k[0][(np.maximum(b0, in_k[1]) <= np.minimum(t0, in_k[2]))]] = True
        if not cons.connected:
            meet[:] = True
        low = np.where(meet, np.maximum(low, lv.pl_lower), low)
    return float(low.sum()), float(up.sum()), note, (in_k, out_k)
