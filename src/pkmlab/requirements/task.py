"""Required workspaces: a task region (box, cylinder or point set) × an orientation set.

A :class:`TaskRegion` is a set of tool positions in mm, given relative to the base frame or to
the nominal pose's position (``frame``). :func:`task_contained` decides whether *every* position
of the region works at *every* orientation of an :class:`~pkmlab.workspaces.OrientationSet`
(relative to the nominal orientation), and :func:`task_margins` measures how much room is
left, in mm and in degrees.

Method (``TaskCheck.method``):

* ``exact`` — families with radial column intervals (``Mechanism.column_radial``: ``psu6``,
  ``ups6``): proved over the continuous region *and* the continuous orientation set. At one
  orientation, leg i admits along the column ``(x, y)`` the z interval ``[a_i(d), b_i(d)]``
  (the workspace engine's ``column_leg``), where ``d`` is the horizontal distance from the
  leg's column axis ``-w_i,xy`` (``w_i = R·u_i - b_i``) and ``a_i + w_i,z``, ``b_i + w_i,z``
  and the existence flag are monotone in ``d``. A box or cylinder task with z extent
  ``[z0, z1]`` and footprint ``F`` is inside leg i's set iff it is at the two extreme
  distances ``d_min = dist(-w_i,xy, F)`` and ``d_max = max dist(-w_i,xy, F)``: the worst ends
  of monotone functions over ``[d_min, d_max]`` are at the ends. So the footprint is never
  sampled. Orientations: the set is covered by the orientation cells of
  :mod:`pkmlab.workspaces.cells` (as for the volume brackets); on a cell of angle bound α,
  ``w_i`` stays within ``r_i = 2 sin(α/2)·|u_i|`` of its value at the cell's centre, so the
  axis moves by at most ``r_i`` (distances in ``[d_min - r_i, d_max + r_i]``) and the ends by
  at most ``r_i``: the leg is *proved* on the whole cell if ``max a + r_i <= z0`` and
  ``min b - r_i >= z1`` at those widened distances (and it exists at the larger). A cell
  whose centre rotation fails the task *refutes* it (the rotation is in the set; so does the
  set's sample, checked first); any other cell is split (:func:`.cells.split`) until every
  cell is proved (``contained``) or one is refuted (``not contained``). Past
  ``CELL_BUDGET`` cells or cells narrower than ``MIN_CELL_RAD`` the answer is ``undecided``
  (``contained`` False, with a note): never a containment that is not proved. A point set is a
  set of zero-size boxes.
* ``sampled`` — other families (``luzi3``) or workspace constraints beyond the stroke
  (joint limits, link diameter, κ): the task is sampled on a grid of spacing at most the
  resolution h, boundary included, and every sample is checked by inverse kinematics at every
  orientation. Stated error: a failure inside a gap of the sample grid can be missed; any
  missed region lies within h·√3/2 mm of a checked sample.

Margins (:func:`task_margins`, the largest verified level of a bisection, kind ``bound``; with
the ``exact`` method every level is decided over the continuous orientation set, so the lower
end is proved; a level left ``undecided`` counts as not contained, and the note says that the
upper end of that bracket is then not proved):

* ``margin_mm`` — the largest δ such that the task grown by δ (box half-sizes + δ, cylinder
  radius and half-height + δ, each point a cube of half-size δ) is contained: a lower bound of
  the distance from the task to the workspace boundary (the grown box contains the δ-ball
  neighbourhood). Negative when not contained: −(the smallest erosion that fits). Bracket
  ``MARGIN_TOL_MM`` (sampled method: a quarter of the resolution, bisecting on the task's
  boundary samples).
* ``orientation_margin_deg`` — the largest Δ such that the task is contained at the
  orientation set widened by Δ (every non-zero half-range, tilt and torsion + Δ; a fixed
  orientation becomes a ±Δ simultaneous box), negative when it must be narrowed. Bracket
  ``ORIENTATION_TOL_DEG``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..mechanisms.kernels.columns import make_leg_eval
from ..poses import as_frames, matrix_to_euler
from ..workspaces import cells as oc
from ..workspaces.bracket.legbounds import EPS
from ..workspaces.constraints import Constraints, check
from ..workspaces.orientations import OrientationSet

__all__ = ["TaskRegion", "TaskCheck", "task_contained", "task_margins", "task_mesh",
           "task_outline", "MARGIN_TOL_MM", "ORIENTATION_TOL_DEG"]

MARGIN_TOL_MM = 0.01
#: items (orientation cell × task part) of one exact check, all levels together, and the
#: smallest cell half-width (rad): past either the check says "undecided"
CELL_BUDGET = 1_000_000
MIN_CELL_RAD = 1e-7
#: items per evaluation (about 70 MB of temporaries)
_CHUNK = 100_000
ORIENTATION_TOL_DEG = 0.01
_SHAPES = ("box", "cylinder", "points")
_FRAMES = ("nominal", "base")


@dataclass(frozen=True)
class TaskRegion:
    """A required set of tool positions (mm).

    Attributes:
        shape: ``"box"`` (axis-aligned, ``size`` = full edges), ``"cylinder"`` (vertical axis,
            ``radius`` and ``height``) or ``"points"`` (``points (N, 3)``).
        frame: ``"nominal"`` — coordinates relative to the nominal pose's position — or
            ``"base"`` — the base frame.
        centre: box / cylinder centre (mm) in ``frame``.
    """

    shape: str
    frame: str = "nominal"
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)
    radius: float = 0.0
    height: float = 0.0
    points: np.ndarray | None = None

    def __post_init__(self):
        if self.shape not in _SHAPES:
            raise ParameterError("task.shape", f"one of {list(_SHAPES)}", self.shape)
        if self.frame not in _FRAMES:
            raise ParameterError("task.frame", f"one of {list(_FRAMES)}", self.frame)
        if self.shape == "box" and (len(self.size) != 3 or min(self.size) < 0):
            raise ParameterError("task.size", "three edge lengths >= 0 mm", self.size)
        if self.shape == "cylinder" and not (self.radius >= 0 and self.height >= 0):
            raise ParameterError("task.radius", "a radius and a height >= 0 mm",
                                 [self.radius, self.height])
        if self.shape == "points":
            P = np.asarray(self.points, dtype=float)
            if P.ndim != 2 or P.shape[1] != 3 or len(P) == 0 or not np.all(np.isfinite(P)):
                raise ParameterError("task.points", "a non-empty (N, 3) array of finite mm",
                                     None if self.points is None else P.shape)
            P = P.copy()
            P.setflags(write=False)
            object.__setattr__(self, "points", P)

    def offset(self, mech) -> np.ndarray:
        """Base-frame position of the task frame's origin (mm)."""
        return np.asarray(mech.nominal_pose[:3]) if self.frame == "nominal" else np.zeros(3)

    def boxes(self, mech, grow: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Box / point task as base-frame boxes ``(lo (B, 3), hi (B, 3))`` grown by ``grow``
        (negative: eroded, never below a point)."""
        o = self.offset(mech)
        if self.shape == "box":
            c = np.asarray(self.centre) + o
            half = np.maximum(np.asarray(self.size) / 2 + grow, 0.0)
            return (c - half)[None], (c + half)[None]
        P = self.points + o
        g = max(grow, 0.0)
        return P - g, P + g

    def cylinder(self, mech, grow: float = 0.0) -> tuple[np.ndarray, float, float]:
        """Cylinder task in the base frame grown by ``grow``: ``(centre, radius, half height)``."""
        c = np.asarray(self.centre) + self.offset(mech)
        return c, max(self.radius + grow, 0.0), max(self.height / 2 + grow, 0.0)

    @property
    def extent(self) -> float:
        """Largest half-extent (mm): how far an erosion can go."""
        if self.shape == "box":
            return float(max(self.size) / 2)
        if self.shape == "cylinder":
            return float(max(self.radius, self.height / 2))
        return 0.0

    def describe(self) -> dict:
        d: dict = {"shape": self.shape, "frame": self.frame}
        if self.shape == "box":
            d.update(centre_mm=list(self.centre), size_mm=list(self.size))
        elif self.shape == "cylinder":
            d.update(centre_mm=list(self.centre), radius_mm=self.radius,
                     height_mm=self.height)
        else:
            d.update(points=int(len(self.points)))
        return d


@dataclass(frozen=True)
class TaskCheck:
    """Result of :func:`task_contained`.

    ``contained``; ``method`` (``exact`` or ``sampled``); ``resolution`` (mm, the sample
    spacing of the ``sampled`` method, 0 for ``exact``); ``orientations`` (samples used);
    ``failures`` (count of failing leg × orientation extremes or samples); ``note``;
    ``status`` — ``contained`` (``exact``: proved over the continuous orientation set),
    ``not contained`` (a rotation of the set fails it) or ``undecided`` (``exact``: orientation
    cells left undecided at the budget; ``contained`` is then False); ``cells`` (orientation
    cells of the ``exact`` proof) and ``undecided`` (cells left open).
    """

    contained: bool
    method: str
    resolution: float
    orientations: int
    failures: int
    note: str = ""
    status: str = ""
    cells: int = 0
    undecided: int = 0

    def __post_init__(self):
        if not self.status:
            object.__setattr__(self, "status",
                               "contained" if self.contained else "not contained")


# ---- exact check on radial column families ---------------------------------------------------


def _legs_at(mech, W, dmin, dmax):
    """Intervals of every leg at ``dmin`` and ``dmax``: ``W (K, 6, 3)``, ``d* (K, 6)`` →
    ``(a, b, ok)`` each ``(2, K, 6)``."""
    D = np.stack([dmin, dmax]).ravel()
    Wf = np.ascontiguousarray(np.broadcast_to(W, (2,) + W.shape).reshape(-1, 3))
    P = np.asarray(mech.column_params(), dtype=float)
    Pf = np.ascontiguousarray(np.broadcast_to(P, (2,) + W.shape).reshape(-1, 3))
    # the leg's interval on the column at horizontal distance D along its own x axis
    a, b, ok = make_leg_eval(type(mech).column_leg)(D - Wf[:, 0], -Wf[:, 1], Wf, Pf)
    shape = (2,) + W.shape[:2]
    return a.reshape(shape), b.reshape(shape), ok.reshape(shape)


def _parts(mech, task: TaskRegion, grow: float):
    """The task as base-frame boxes ``(lo (B, 3), hi (B, 3))`` or, for a cylinder, one
    ``(centre, radius, half height)``."""
    return task.cylinder(mech, grow) if task.shape == "cylinder" else task.boxes(mech, grow)


def _fail_items(mech, W, parts, bid, r=None) -> np.ndarray:
    """``(K, 6)`` True where leg i at offsets ``W (K, 6, 3)`` fails the task part ``bid
    (K,)``. With ``r (K, 6)``: where the leg is not *proved* to hold it at every rotation
    whose offset ``w_i`` lies within ``r`` of ``W`` (the column axis ``-w_i,xy`` and the
    shift ``-w_i,z`` each move by at most ``r``: the distances widen by ``r``, the ends by
    ``r``)."""
    axis = -W[..., :2]                                          # column axes (K, 6, 2)
    if len(parts) == 3:                                         # cylinder
        c, rad, hz = parts
        dc = np.linalg.norm(axis - c[:2], axis=-1)
        dmin, dmax = np.maximum(dc - rad, 0.0), dc + rad
        z0, z1 = np.full(len(W), c[2] - hz), np.full(len(W), c[2] + hz)
    else:
        lo, hi = parts[0][bid], parts[1][bid]                   # (K, 3)
        l, h = lo[:, None, :2], hi[:, None, :2]
        gap = np.maximum(np.maximum(l - axis, axis - h), 0.0)
        far = np.maximum(np.abs(axis - l), np.abs(h - axis))
        dmin, dmax = np.linalg.norm(gap, axis=-1), np.linalg.norm(far, axis=-1)
        z0, z1 = lo[:, 2], hi[:, 2]
    rr = 0.0 if r is None else r
    if r is not None:
        dmin, dmax = np.maximum(dmin - rr, 0.0), dmax + rr
    a, b, ok = _legs_at(mech, W, dmin, dmax)
    pad = 0.0 if r is None else rr + EPS
    good = ok & (a + pad <= z0[None, :, None]) & (b - pad >= z1[None, :, None])
    return ~np.all(good, axis=0)


def _exact_fail(mech, R, task: TaskRegion, grow: float = 0.0) -> np.ndarray:
    """``(B, M, 6)`` True where leg × orientation ``R (M, 3, 3)`` fails task part B."""
    parts = _parts(mech, task, grow)
    nb = 1 if task.shape == "cylinder" else len(parts[0])
    W = mech.leg_offsets(R)
    bid = np.repeat(np.arange(nb), len(R))
    return _fail_items(mech, np.tile(W, (nb, 1, 1)), parts, bid).reshape(nb, len(R), 6)


def _exact_cells(mech, oset: OrientationSet, task: TaskRegion, grow: float = 0.0
                 ) -> TaskCheck:
    """Containment over the continuous orientation set (module notes): the sample first
    (a failure there is a proof), then items (orientation cell × task part; a cylinder is
    one part, a box one, a point set one per point), each proved, refuted at its cell's
    centre, or split with the cell (:func:`pkmlab.workspaces.cells.split`)."""
    R = oset.rotations()
    n = int(_exact_fail(mech, R, task, grow).sum())
    if n:
        return TaskCheck(False, "exact", 0.0, len(R), n, status="not contained")
    parts = _parts(mech, task, grow)
    nb = 1 if task.shape == "cylinder" else len(parts[0])
    C, H = oc.initial_cells(oset, 1)
    cid, bid = np.repeat(np.arange(len(C)), nb), np.tile(np.arange(nb), len(C))
    unorm = np.linalg.norm(mech.tool_points, axis=1)            # (6,)
    cells = items = 0
    while len(cid):
        cells += len(C)
        items += len(cid)
        W = mech.leg_offsets(oset.rotations_at(C))              # (L, 6, 3)
        r = oc.chord(oc.angle_bound(oset, C, H))[:, None] * unorm
        keep = np.zeros(len(cid), bool)
        for s in range(0, len(cid), _CHUNK):
            c, bb = cid[s:s + _CHUNK], bid[s:s + _CHUNK]
            fail0 = _fail_items(mech, W[c], parts, bb)
            if fail0.any():
                return TaskCheck(False, "exact", 0.0, len(R) + cells, int(fail0.sum()),
                                 status="not contained", cells=cells)
            keep[s:s + _CHUNK] = _fail_items(mech, W[c], parts, bb, r[c]).any(axis=1)
        cid, bid = cid[keep], bid[keep]
        if not len(cid):
            break
        if items + 8 * len(cid) > CELL_BUDGET or np.max(H) < MIN_CELL_RAD:
            return TaskCheck(False, "exact", 0.0, len(R) + cells, 0, status="undecided",
                             cells=cells, undecided=len(cid),
                             note=f"not proved: {len(cid)} orientation cell × task part "
                                  f"item(s) undecided after {items:,} items (budget "
                                  f"{CELL_BUDGET:,}); no sampled orientation fails")
        # the open cells' children inherit their parent's open parts
        live, cid = np.unique(cid, return_inverse=True)
        C, H = C[live], H[live]
        order = np.argsort(cid, kind="stable")
        cid, bid = cid[order], bid[order]
        counts = np.bincount(cid, minlength=len(C))
        first = np.cumsum(counts) - counts
        C, H, par = oc.split(C, H)
        cnt = counts[par]
        off = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        bid = bid[np.repeat(first[par], cnt) + off]
        cid = np.repeat(np.arange(len(C)), cnt)
    return TaskCheck(True, "exact", 0.0, len(R) + cells, 0, status="contained", cells=cells)


# ---- sampled fallback ------------------------------------------------------------------------


def _samples(mech, task: TaskRegion, h: float, grow: float = 0.0,
             surface: bool = False) -> np.ndarray:
    """Task positions (base frame) on a grid of spacing <= h, boundary included (only the
    boundary with ``surface``)."""
    def axis(a, b):
        n = max(1, math.ceil((b - a) / h - 1e-9))
        return np.linspace(a, b, n + 1) if b > a else np.array([a])

    if task.shape == "cylinder":
        c, r, hz = task.cylinder(mech, grow)
        zs = axis(c[2] - hz, c[2] + hz)
        pts = [np.zeros((1, 2))]
        for rho in axis(0.0, r)[1:]:
            m = max(6, math.ceil(2 * math.pi * rho / h))
            ang = 2 * math.pi * np.arange(m) / m
            pts.append(np.stack([rho * np.cos(ang), rho * np.sin(ang)], axis=1))
        xy = np.concatenate(pts) + c[:2]
        p = np.concatenate([np.column_stack([xy, np.full(len(xy), z)]) for z in zs])
        if surface:
            rim = np.linalg.norm(p[:, :2] - c[:2], axis=1) >= r - 1e-9
            p = p[rim | (p[:, 2] <= zs[0]) | (p[:, 2] >= zs[-1])]
        return p
    lo, hi = task.boxes(mech, grow)
    out = []
    for a, b in zip(lo, hi):
        g = np.meshgrid(*[axis(a[k], b[k]) for k in range(3)], indexing="ij")
        p = np.stack([x.ravel() for x in g], axis=1)
        if surface:
            p = p[np.any((p <= a) | (p >= b), axis=1)]
        out.append(p)
    return np.concatenate(out)


def _sampled_fail(mech, R, task, h, cons, grow=0.0, surface=False) -> int:
    p = _samples(mech, task, h, grow, surface)
    lo_q, hi_q = mech.stroke
    bad = 0
    for m in range(len(R)):
        Rm = np.ascontiguousarray(np.broadcast_to(R[m], (len(p), 3, 3)))
        ok = mech.inverse((p, Rm), stroke=(lo_q, hi_q)).valid
        if cons.extra:
            idx = np.nonzero(ok)[0]
            ok[idx] = check(mech, p[idx], Rm[idx], cons)
        bad += int(np.sum(~ok))
    return bad


# ---- public ------------------------------------------------------------------------------------


def _prepare(mech, orientations: OrientationSet | None, constraints: Constraints | None):
    cons = (constraints or Constraints()).resolved(mech)
    if cons.stroke is not True:
        mech = dataclasses.replace(mech, stroke_window=cons.stroke)
    oset = orientations or OrientationSet.fixed()
    _, Rn = as_frames(mech.nominal_pose)
    return mech, oset.centred(tuple(matrix_to_euler(Rn[0]))), cons


def _check(mech, oset, task, resolution, cons, grow=0.0, surface=False) -> TaskCheck:
    R = oset.rotations()
    exact = bool(getattr(mech, "column_radial", False)) and mech.column_method \
        is not None and not cons.extra
    if exact:
        return _exact_cells(mech, oset, task, grow)
    why = ("no radial column intervals for family " + repr(mech.family)) if not cons.extra \
        else "constraints beyond the stroke"
    n = _sampled_fail(mech, R, task, resolution, cons, grow, surface)
    return TaskCheck(n == 0, "sampled", float(resolution), len(R), n,
                     f"sampled at spacing <= {resolution:g} mm ({why}): a failure between "
                     f"samples (within {resolution * math.sqrt(3) / 2:.3g} mm of one) can "
                     "be missed")


def task_contained(mech, task: TaskRegion, orientations: OrientationSet | None = None,
                   resolution: float = 2.5, constraints: Constraints | None = None
                   ) -> TaskCheck:
    """Is every position of ``task`` feasible at every orientation of ``orientations``?

    ``orientations`` are relative to the nominal orientation (default: the nominal one);
    ``resolution`` (mm) is the sample spacing of the sampled fallback; ``constraints`` as
    for :func:`pkmlab.workspaces.workspace` (the stroke window override is honoured; other
    constraints force the sampled method). See the module docstring for the method.
    """
    mech, oset, cons = _prepare(mech, orientations, constraints)
    return _check(mech, oset, task, resolution, cons)


def _widened(oset: OrientationSet, delta: float) -> OrientationSet:
    if oset.kind == "fixed":
        if delta <= 0:
            return oset
        return OrientationSet.box((delta,) * 3, "simultaneous", oset.samples,
                                  centre=tuple(np.asarray(oset.centre) + oset.angles))
    # widened within the set's own limits (box and torsion 180°, tilt 90°)
    if oset.kind == "box":
        return dataclasses.replace(oset, angles=tuple(min(max(a + delta, 0.0), math.pi)
                                                      if a > 0 else a for a in oset.angles))
    return dataclasses.replace(oset, tilt=min(max(oset.tilt + delta, 0.0), math.pi / 2)
                               if oset.tilt > 0 else oset.tilt,
                               torsion=min(max(oset.torsion + delta, 0.0), math.pi)
                               if oset.torsion > 0 else oset.torsion)


def _bisect(ok, lo: float, hi: float, tol: float) -> tuple[float, float]:
    """Largest verified level in [lo, hi] (ok(lo) True, ok(hi) False) and the bracket."""
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo, hi - lo


def task_margins(mech, task: TaskRegion, orientations: OrientationSet | None = None,
                 resolution: float = 2.5, constraints: Constraints | None = None,
                 max_growth: float | None = None) -> dict:
    """Position and orientation margins of ``task`` (see the module docstring).

    Returns ``{"check": TaskCheck, "margin_mm", "margin_bracket_mm", "orientation_margin_deg",
    "orientation_bracket_deg", "notes": {...}}``; a margin that does not exist (no part of the
    task fits, or not even its nominal orientation) is ``None`` with a note.
    """
    mech, oset, cons = _prepare(mech, orientations, constraints)
    base = _check(mech, oset, task, resolution, cons)
    notes: dict = {}
    out = {"check": base, "notes": notes}

    # the sampled method bisects on the boundary samples only, to a quarter of its spacing
    surface = base.method == "sampled"
    tol = max(MARGIN_TOL_MM, resolution / 4) if surface else MARGIN_TOL_MM
    otol = 10 * ORIENTATION_TOL_DEG if surface else ORIENTATION_TOL_DEG

    open_levels: dict = {"task_margin": 0, "task_orientation_margin": 0}

    def decided(c: TaskCheck, key: str) -> bool:
        open_levels[key] += c.status == "undecided"
        return c.contained

    def fits(g):
        return decided(_check(mech, oset, task, resolution, cons, grow=g, surface=surface),
                       "task_margin")

    if base.contained:
        cap = max_growth if max_growth is not None else 2.0 * mech.scale
        g = 1.0
        while g < cap and fits(g):
            g *= 2.0
        if g >= cap and fits(cap):
            out["margin_mm"], out["margin_bracket_mm"] = cap, 0.0
            notes["task_margin"] = f"not bounded by the search (grown by {cap:g} mm)"
        else:
            g = min(g, cap)
            out["margin_mm"], out["margin_bracket_mm"] = _bisect(fits, g / 2 if g > 1 else 0.0,
                                                                 g, tol)
    else:
        e = task.extent
        if e > 0 and fits(-e):
            lo, br = _bisect(lambda g: not fits(-g), 0.0, e, tol)
            out["margin_mm"], out["margin_bracket_mm"] = -(lo + br), br
        else:
            out["margin_mm"] = out["margin_bracket_mm"] = None
            notes["task_margin"] = ("a point of the task is outside the workspace at some "
                                    "orientation" if task.shape == "points" else
                                    "the task's centre is outside the workspace")

    def ofits(d_deg):
        return decided(_check(mech, _widened(oset, math.radians(d_deg)), task, resolution,
                              cons, surface=surface), "task_orientation_margin")

    if base.contained:
        if ofits(90.0):
            out["orientation_margin_deg"], out["orientation_bracket_deg"] = 90.0, 0.0
            notes["task_orientation_margin"] = "not bounded by the search (+90°)"
        else:
            out["orientation_margin_deg"], out["orientation_bracket_deg"] = _bisect(
                ofits, 0.0, 90.0, otol)
    else:
        widest = max([*oset.angles] if oset.kind == "box" else
                     [oset.tilt, oset.torsion] if oset.kind == "tilt-torsion" else [0.0])
        if widest > 0 and ofits(-math.degrees(widest)):
            lo, br = _bisect(lambda d: not ofits(-d), 0.0, math.degrees(widest), otol)
            out["orientation_margin_deg"], out["orientation_bracket_deg"] = -(lo + br), br
        else:
            out["orientation_margin_deg"] = out["orientation_bracket_deg"] = None
            notes["task_orientation_margin"] = "the task does not fit even at the centre " \
                "orientation"
    for key, n in open_levels.items():
        if n:
            notes[key] = (notes[key] + "; " if key in notes else "") + (
                f"{n} level(s) undecided (orientation cell budget {CELL_BUDGET:,}) counted as "
                "not contained: the margin is proved, the upper end of its bracket is not")
    return out


# ---- geometry for drawing ----------------------------------------------------------------------


def task_mesh(mech, task: TaskRegion, segments: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of the task region in the base frame: ``(vertices (V, 3) mm,
    faces (F, 3))``; a point set gives one small cube (0.5 mm) per point."""
    if task.shape == "cylinder":
        c, r, hz = task.cylinder(mech)
        ang = 2 * np.pi * np.arange(segments) / segments
        ring = np.stack([c[0] + r * np.cos(ang), c[1] + r * np.sin(ang)], axis=1)
        V = np.concatenate([np.column_stack([ring, np.full(segments, c[2] - hz)]),
                            np.column_stack([ring, np.full(segments, c[2] + hz)]),
                            [[c[0], c[1], c[2] - hz], [c[0], c[1], c[2] + hz]]])
        F = []
        for k in range(segments):
            n = (k + 1) % segments
            F += [[k, n, segments + n], [k, segments + n, segments + k],
                  [2 * segments, n, k], [2 * segments + 1, segments + k, segments + n]]
        return V, np.array(F)
    lo, hi = task.boxes(mech, 0.0) if task.shape == "box" else task.boxes(mech, 0.25)
    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                     [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
    faces = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                      [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])
    V = (lo[:, None, :] + cube[None] * (hi - lo)[:, None, :]).reshape(-1, 3)
    F = (faces[None] + 8 * np.arange(len(lo))[:, None, None]).reshape(-1, 3)
    return V, F


def task_outline(mech, task: TaskRegion, z: float, segments: int = 96) -> list[np.ndarray]:
    """Cross-section of the task at height ``z`` (base frame): closed polygons ``(n, 2)``
    in mm (empty list where the plane misses the task; a point set gives its points there,
    each as a one-vertex polygon)."""
    if task.shape == "cylinder":
        c, r, hz = task.cylinder(mech)
        if abs(z - c[2]) > hz:
            return []
        ang = 2 * np.pi * np.arange(segments + 1) / segments
        return [np.stack([c[0] + r * np.cos(ang), c[1] + r * np.sin(ang)], axis=1)]
    lo, hi = task.boxes(mech)
    out = []
    for a, b in zip(lo, hi):
        if a[2] <= z <= b[2]:
            if task.shape == "points":
                out.append(a[None, :2].copy())
            else:
                out.append(np.array([[a[0], a[1]], [b[0], a[1]], [b[0], b[1]], [a[0], b[1]],
                                     [a[0], a[1]]]))
    return out
