"""``task.centre: auto``: where a task region fits best, found by a search.

A task is normally placed at a fixed centre relative to the nominal pose (for a servo
platform: the servo-zero pose), which may lie far from the region that reaches the task's
orientations. ``centre: auto`` (or ``auto`` for some of the three coordinates, e.g.
``[0 mm, 0 mm, auto]``) lets the study place it for every candidate.

**What "best" means.** The score of a centre ``c`` is the task's position margin there
(:func:`pkmlab.requirements.task.task_margins`' ``margin_mm``: the largest growth δ of the
region that stays contained at every orientation of the set, negative: the erosion needed).
Where not even the region's centre fits (the margin is undefined) the score is worse than any
defined margin and ranks centres by their count of failing checks (leg × orientation
extremes, or samples of the sampled method): fewer is better. The chosen centre is the one
with the highest score that the search found.

**The search** (a search result, not a proven optimum: the margin need not be unimodal), one
coordinate at a time in the order z, x, y (only the ``auto`` ones; the others keep their given
value): the line through the current centre along the coordinate is sampled at ``LINE``
points over ``±span`` (``span`` = the mechanism's characteristic size ``mech.scale``) and the
segment where the set's centre orientation is reachable (inverse kinematics, the stroke) is
scanned at ``LEVELS`` equally spaced offsets, then a golden-section search between the best
level's neighbours runs down to ``TOL_MM``. During the search the margin's
bisection stops at ``TOL_MM`` (coarser than the 0.01 mm of the reported ``task_margin``,
which the evaluator then computes at the chosen centre in full), and the sampled method
(families without radial column intervals) checks only the task's boundary samples, as the
margin's bisection does; the reported containment is then checked on every sample.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..workspaces.orientations import OrientationSet
from .task import TaskRegion, _check, _prepare

__all__ = ["LEVELS", "TOL_MM", "Placement", "place_task"]

#: offsets scanned per coordinate, and the golden-section / bisection tolerance (mm)
LEVELS = 13
TOL_MM = 0.5
LINE = 401
_AXES = (2, 0, 1)
_NAMES = "xyz"


@dataclass(frozen=True)
class Placement:
    """The chosen centre (mm, in the task's frame), its search score and how it was found."""

    centre: tuple[float, float, float]
    margin_mm: float | None
    checks: int
    note: str


def _score(mech, oset, task, resolution, cons, cap, surface) -> tuple[tuple, int]:
    """``((defined, value), checks)``: the position margin to ``TOL_MM`` (``defined`` 1),
    or ``(0, -failures)`` where not even the centre fits."""
    n = 0

    def fits(g):
        nonlocal n
        n += 1
        return _check(mech, oset, task, resolution, cons, grow=g, surface=surface).contained

    base = _check(mech, oset, task, resolution, cons, surface=surface)
    n += 1
    if base.contained:
        lo, hi = 0.0, 1.0
        while hi < cap and fits(hi):
            lo, hi = hi, 2.0 * hi
        if hi >= cap:
            return (1, cap), n
        while hi - lo > TOL_MM:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if fits(mid) else (lo, mid)
        return (1, lo), n
    e = task.extent
    if e > 0 and fits(-e):
        lo, hi = 0.0, e                          # smallest erosion that fits, in (lo, hi]
        while hi - lo > TOL_MM:
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if fits(-mid) else (mid, hi)
        return (1, -hi), n
    return (0, -float(max(base.failures, 1))), n


def _reachable(mech, task, oset, c, k, span) -> tuple[float, float]:
    """The extent of coordinate ``k`` (task frame) along the line through ``c`` where the
    orientation set's centre is reachable; ``c[k] ± span`` if it is nowhere on the line."""
    from ..poses import euler_to_matrix

    v = c[k] + np.linspace(-span, span, LINE)
    p = np.tile(c + task.offset(mech), (LINE, 1))
    p[:, k] += v - c[k]
    centre = np.zeros(3) if oset.centre is None else np.asarray(oset.centre)
    R = np.ascontiguousarray(np.broadcast_to(euler_to_matrix(centre[None])[0], (LINE, 3, 3)))
    ok = mech.inverse((p, R)).valid
    if not ok.any():
        return c[k] - span, c[k] + span
    return float(v[ok].min()), float(v[ok].max())


def place_task(mech, task: TaskRegion, auto: tuple[bool, bool, bool], orientations=None,
               resolution: float = 2.5, constraints=None,
               span: float | None = None) -> Placement:
    """The centre of ``task`` (its ``auto`` coordinates searched, the module notes) that
    scores best; ``task.centre`` holds the given values of the other coordinates and the
    middle of the scan of the searched ones."""
    mech, oset, cons = _prepare(mech, orientations, constraints)
    # the sampled method checks the task's boundary samples only during the search (as the
    # margin's bisection does); the reported containment is checked in full afterwards
    surface = _check(mech, OrientationSet.fixed(), TaskRegion("points", points=np.zeros((1, 3))),
                     resolution, cons).method == "sampled"
    span = float(mech.scale if span is None else span)
    cap = 2.0 * mech.scale
    c = np.array(task.centre, dtype=float)
    checks = 0
    memo: dict = {}

    def score(cc):
        nonlocal checks
        key = tuple(np.round(cc, 9))
        if key not in memo:
            t = dataclasses.replace(task, centre=tuple(float(v) for v in cc))
            memo[key], n = _score(mech, oset, t, resolution, cons, cap, surface)
            checks += n
        return memo[key]

    for k in _AXES:
        if not auto[k]:
            continue
        lo, hi = _reachable(mech, task, oset, c, k, span)
        levels = np.linspace(lo, hi, LEVELS)
        scores = []
        for v in levels:
            cc = c.copy()
            cc[k] = v
            scores.append(score(cc))
        i = max(range(LEVELS), key=lambda j: (scores[j], -abs(levels[j] - c[k])))
        best, best_s = levels[i], scores[i]
        if best_s[0] == 1:                         # golden section between the neighbours
            a, b = levels[max(i - 1, 0)], levels[min(i + 1, LEVELS - 1)]
            g = (math.sqrt(5) - 1) / 2

            def f(v, k=k):
                cc = c.copy()
                cc[k] = v
                return score(cc)

            x1, x2 = b - g * (b - a), a + g * (b - a)
            f1, f2 = f(x1), f(x2)
            while b - a > TOL_MM:
                if f1 >= f2:
                    b, x2, f2 = x2, x1, f1
                    x1 = b - g * (b - a)
                    f1 = f(x1)
                else:
                    a, x1, f1 = x1, x2, f2
                    x2 = a + g * (b - a)
                    f2 = f(x2)
            for v, s in ((x1, f1), (x2, f2)):
                if s > best_s:
                    best, best_s = v, s
        c[k] = best
    final = score(c)
    searched = ", ".join(_NAMES[k] for k in _AXES if auto[k])
    margin = final[1] if final[0] == 1 else None
    note = (f"task centre: search result ({searched} scanned at {LEVELS} levels over the "
            f"reachable line within ±{span:.4g} mm, then golden section to {TOL_MM:g} mm; the "
            "position margin "
            "maximised, not a proven optimum): "
            + ", ".join(f"{_NAMES[k]} {c[k]:.4g} mm" for k in range(3)))
    if margin is None:
        note += "; no centre on the scan fits even the task's centre at every orientation " \
                f"(fewest failing checks: {int(-final[1])})"
    return Placement(tuple(float(v) for v in c), margin, checks, note)


# ---- conditioning at the task ---------------------------------------------------------------

#: κ above this at a task pose is flagged (summary, report, log), dexterity requested or not
TASK_KAPPA_WARN = 20.0


def task_probe_points(mech, task: TaskRegion) -> np.ndarray:
    """Positions (base frame, mm) where the conditioning at the task is sampled: a box's 8
    corners and centre, a cylinder's centre and 4 points on each rim, a point set's points
    (at most 64, evenly chosen)."""
    if task.shape == "cylinder":
        c, r, hz = task.cylinder(mech)
        ang = np.arange(4) * np.pi / 2
        rim = [[c[0] + r * np.cos(a), c[1] + r * np.sin(a), c[2] + s * hz]
               for a in ang for s in (-1, 1)]
        return np.array([list(c)] + rim)
    lo, hi = task.boxes(mech)
    if task.shape == "box":
        corners = np.array([[(lo[0], hi[0])[i][0], (lo[0], hi[0])[j][1], (lo[0], hi[0])[k][2]]
                            for i in (0, 1) for j in (0, 1) for k in (0, 1)])
        return np.concatenate([0.5 * (lo + hi), corners])
    idx = np.unique(np.linspace(0, len(lo) - 1, min(len(lo), 64)).astype(int))
    return lo[idx]


def task_kappa(mech, task: TaskRegion, orientations=None, L=None) -> tuple[float, int, str]:
    """Worst κ (:func:`pkmlab.dexterity.metrics.condition_number`, Jacobian homogenised with
    ``L``, default Angeles' length) over :func:`task_probe_points` × the orientation set's
    samples, at the poses the legs reach: ``(κ, poses used, note)``. A sampled value (the
    task's interior and the orientations between samples are not checked); ``inf`` at a
    singular pose; ``nan`` when no probe pose is reachable."""
    from ..dexterity.metrics import condition_number, resolve_length

    mech, oset, _ = _prepare(mech, orientations, None)
    P = task_probe_points(mech, task)
    R = oset.rotations()
    p = np.repeat(P, len(R), axis=0)
    Rm = np.ascontiguousarray(np.tile(R, (len(P), 1, 1)))
    ok = mech.inverse((p, Rm)).valid
    length = resolve_length(mech, L)
    if not ok.any():
        return float("nan"), 0, "no probe pose of the task is reachable"
    J = mech.jacobian((p[ok], np.ascontiguousarray(Rm[ok])))
    k = condition_number(J, length.length)
    worst = float(np.max(k))
    note = (f"sampled: worst κ over {int(ok.sum())} reachable pose(s) of {len(p)} (the task's "
            f"{len(P)} probe points × {len(R)} orientation samples), L = {length.length:.4g} mm "
            f"({length.status})")
    return worst, int(ok.sum()), note
