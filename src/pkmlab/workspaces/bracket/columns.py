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

**Reachable, second order in x-y** (:meth:`.bracket_level.Level._reach_upper`, families with
:attr:`.legbounds.Legs.planar`). Over a square, the top of the union over a cell is below an
affine function of x-y: any convex combination of the legs' upper ends is above the top, each
end is concave in x-y (below its tangent plane; beyond its sphere the leg is unreachable), and
the rotation moves the plane by at most the linearised cell plus the remainder. The weights
are chosen on one leg or a pair so that opposite slopes over the cell cancel (first order in
the cell otherwise, at every ridge of the minimum over legs). The maximum of these affine
functions over the cells is convex, so at most its corner interpolation; symmetrically the
bottom is above a concave function (a convex combination of lower ends whose spheres cover
the moved square, minimised over the cell), at least its corner interpolation. The column's
volume is at most the integral of the interpolated difference's positive part. The samples'
own planes and pieces are kept in those extremes, and a cell whose corner values do not pass
them is dropped (its outer set joins a per-column hull, for connectivity). The cells' most
promising vertices (by the linear model) are evaluated as samples in the next step, and a new
x-y level starts from each parent column's best sample rotations.

**Time budget.** ``budget_s`` counts from the end of the set-up (kernels loaded or
compiled, legs' reach), reported as ``setup_seconds``. The first step always completes; then
items are evaluated in batches sized to take about 0.5 s, the clock is checked before each, and
a step whose next batch, or whose remaining items at twice the recent speed (plus the last
step's bookkeeping), would end past the budget is abandoned: the result is the bracket of the
last completed step, returned early when the next step clearly cannot fit. Overrun: about
one misjudged batch (``tests/workspaces/test_bracket.py`` allows ``0.25·budget + 1 s``).

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
Families that bound their legs over cells (``cell_bounds``: luzi3, and rss6, whose crank
column sets are not radial) are bracketed on position × orientation cells instead
(:mod:`.bracket_cells`).
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time

import numpy as np

from ...errors import ParameterError
from ...mechanisms.mobility import require_spatial
from ...poses import as_frames, matrix_to_euler
from .. import cells as oc
from ..constraints import Constraints
from ..orientations import OrientationSet
from .cells import cell_volume_bracket
from .legbounds import Legs
from .level import BATCH, Level
from .octree import octree_volume_bracket
from .result import VolumeBracket
from .sets import connected, length, warm_up

log = logging.getLogger(__name__)

__all__ = ["VolumeBracket", "volume_bracket"]

# ---- driver -------------------------------------------------------------------------------------


def _request(mech, kind, orientations, resolution, constraints):
    from ..engine import check_request

    check_request(kind, resolution)
    if not mech.cell_bounds and (not mech.column_radial or mech.column_method is None):
        raise ParameterError("bracket", "a family with radial column kernels (psu6, ups6) or "
                             f"cell leg bounds (luzi3, rss6); family {mech.family!r} has neither",
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


class _Clock:
    """The time budget, counted from ``start`` (after the set-up). The rest of a step is
    allowed while the time it is expected to take (its cell and sample items at their recent
    rates, plus the bookkeeping of a step as last measured) still ends within the budget; the
    first step of a run is always allowed (it gives the first bracket). An optimistic estimate
    costs wasted work, never an overrun: the check repeats before every batch."""

    #: target duration of one batch (s): the tolerance of the budget
    BATCH_S = 0.5
    #: share of the predicted time of the rest of a step that must fit
    OPTIMISM = 0.5

    def __init__(self, start: float, budget: float):
        self.deadline = start + budget
        self.rate = {True: 0.0, False: 0.0}     # s per item: cells, samples
        self.post = 0.0          # s of bookkeeping after a step's batches
        self.enforce = False
        self.t = self.t_end = start

    def batch(self, cells: bool) -> int:
        """Items per batch: about ``BATCH_S`` seconds at the current rate."""
        r = self.rate[cells] or self.rate[not cells]
        return int(min(max(self.BATCH_S / r, 1_000), BATCH)) if r > 0 else 5_000

    def allows(self, cells: int, samples: int) -> bool:
        self.t = time.perf_counter()
        need = cells * (self.rate[True] or self.rate[False]) \
            + samples * (self.rate[False] or self.rate[True])
        # the rates are noisy on a shared machine: give up on the step only when it would not
        # fit even at twice the measured speed (or its next batch would not fit at all)
        nxt = min(cells + samples, BATCH) * max(self.rate.values())
        return not self.enforce or (self.t + self.OPTIMISM * need + self.post <= self.deadline
                                    and self.t + nxt <= self.deadline)

    def done(self, items: int, cells: bool) -> None:
        self.t_end = time.perf_counter()
        r = (self.t_end - self.t) / max(items, 1)
        old = self.rate[cells]
        self.rate[cells] = r if old == 0 else 0.5 * (old + r)

    def passed(self) -> bool:
        return time.perf_counter() >= self.deadline


def volume_bracket(mech, kind: str = "constant", orientations: OrientationSet | None = None,
                   resolution: float = 2.5, constraints: Constraints | None = None,
                   target: float = 0.01, budget_s: float = 30.0,
                   max_evaluations: float = 5e9, max_cells: int = 3_000_000) -> VolumeBracket:
    """Bracket the volume of a workspace over the continuous orientation set (module notes).

    Args:
        mech, kind, orientations, resolution, constraints: as for :func:`pkmlab.workspace`;
            ``resolution`` is the first x-y cell size (halved as needed).
        target: stop when ``upper - lower <= target·upper``.
        budget_s: wall-time budget (s), counted after the set-up (kernel compilation or
            cache load, reported as ``setup_seconds``). The first refinement step always
            completes; after it, the clock is checked between batches of items sized to
            take about 0.5 s, and a step is abandoned as soon as its next batch, or its
            remaining items at twice the recent speed, would end past the budget:
            the bracket of the last completed step is returned, possibly well before the
            budget. The overrun is the misjudged part of one batch and one step's
            bookkeeping, about 0.5 s (``tests`` allow ``0.25·budget + 1 s``), unless the first
            step alone is longer.
        max_evaluations: budget of leg-bound evaluations.
        max_cells: largest number of (column × orientation cell) items of one step (an
            orientation split that would pass it halves the x-y cells instead).
    """
    if getattr(mech, "cube_margin", None) is not None:      # delta3, ldelta3 (translational)
        return octree_volume_bracket(mech, kind, orientations, resolution, constraints,
                                     target=target, budget_s=budget_s)
    require_spatial(mech, "volume brackets")
    t_call = time.perf_counter()
    mech, oset, cons = _request(mech, kind, orientations, resolution, constraints)
    if mech.cell_bounds:
        return cell_volume_bracket(mech, kind, oset, resolution, cons, target, budget_s,
                                   max_cells, max_evaluations)
    legs = Legs(mech, oset)
    p_nom = mech.nominal_pose[:3]
    # every feasible p has |p_xy + w_xy| <= reach_i, |w_xy + b_xy| <= |u_i|
    reach = legs.reach()
    warm_up()
    legs.warm_up()
    t0 = time.perf_counter()
    setup = t0 - t_call
    clock = _Clock(t0, budget_s)
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
                             time.perf_counter() - t_call, ["no position is within every leg's "
                                                            "reach"], setup_seconds=setup)
    gx = np.arange(math.floor(box_lo[0] / h), math.ceil(box_hi[0] / h) + 1) * h
    gy = np.arange(math.floor(box_lo[1] / h), math.ceil(box_hi[1] / h) + 1) * h
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    cx, cy = X.ravel(), Y.ravel()
    level = 0
    stop = None
    final = None                                # (h, cells, kept sets) of the last step
    lower, upper, outside, seen_outside = 0.0, math.inf, False, False
    seed = None
    while stop is None:
        lv = Level(legs, kind, cx, cy, h, C0, H0, seed)
        while True:
            sets = lv.step(clock)
            if sets is None:
                stop = "budget: seconds"
                break
            t_post = clock.t_end                         # the end of the step's last batch
            inner, outer, inner_x, outer_x = sets
            lo_s, up_s, note, kept = _volumes(inner, outer, cons, lv, p_nom)
            final = (lv.h, np.stack([lv.cx, lv.cy], axis=1), kept)
            history.append({"level": level, "h_mm": h, "items": int(len(lv.col)),
                            "lower_mm3": lo_s, "upper_mm3": up_s,
                            "seconds": time.perf_counter() - t_call,
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
            clock.post = max(0.0, time.perf_counter() - t_post)
            clock.enforce = True
            if upper <= 0 or gap <= target * upper:
                stop = "converged" if upper > 0 else "empty"
            elif clock.passed():
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
            elif lv.reach_up is not None:
                more = lv.pl_upper - lv.pl_upper_x
                g_orient = float(np.sum(more[np.isfinite(more)]))
                g_all = gap
            # (reachable: part of the cells' excess over the samples does not shrink with
            # the cells, so halve h as soon as the x-y part is as large)
            share = 1.0 if lv.reach_up is not None else 0.5
            if not np.any(lv.H > 0) or g_orient <= share * (g_all - g_orient):
                break                                    # the x-y cells dominate: halve h
            if len(lv.col) * 8 > max_cells:
                break                                    # too many cells: halve h instead
            lv.split()
        if stop is None:
            alive = np.unique(kept[1][0])
            # the children start from their parent's best sample rotations
            seed = np.tile(lv.best_rotations()[alive], (4, 1, 1)) if kind == "reachable" \
                else None
            cx = np.concatenate([lv.cx[alive] + dx * h / 4 for dx in (-1, 1) for _ in (0, 1)])
            cy = np.concatenate([lv.cy[alive] + dy * h / 4 for _ in (0, 1) for dy in (-1, 1)])
            h *= 0.5
            level += 1
            if len(cx) * len(C0) > max_cells:
                stop = "budget: cells"
    if outside:
        notes.append("the nominal position is outside the workspace: the bracket covers every "
                     "component (lower 0)")
    h_f, cells_f, kept_f = final
    return VolumeBracket(lower, upper, target, stop, history, h_f, legs.count,
                         time.perf_counter() - t_call, notes, cells_f, kept_f[0], kept_f[1],
                         setup_seconds=setup)


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
