"""Continuous optima with a bracket: orientation capability and the stroke a set needs.

Both are found over *continuous* positions, not over the grid columns of a workspace, for
families with radial column intervals (``Mechanism.column_radial``: ``psu6``, ``ups6``) and the
stroke constraint alone. The kernels are in :mod:`pkmlab.mechanisms.kernels.search`; this module
states what their numbers mean.

**Orientation capability** — the largest ``θ`` such that some position keeps every leg within
its stroke at *every* orientation of the simultaneous Euler box ``nominal ± θ`` (the
dexterous workspace of the continuous box is non-empty). One compiled call
(:func:`orientation_capability`) returns a bracket ``[lower, upper]`` that contains it:

* ``upper``: the box's sample (``samples`` angles per axis, corners included) admits *no*
  position. The search is a branch and bound over continuous ``(x, y)``: a tile of positions
  is discarded when an upper bound of the column margin ``min b - max a`` over the whole tile
  (from the monotone radial leg intervals at the tile's nearest and farthest distance from
  each leg's axis) is negative; tiles are split down to 1e-4 mm. z is exact per column.
  Every larger box contains this sample, so no larger box has a dexterous position either.
  The sample is the ``samples³`` grid plus the orientations that refuted points on the way to
  the lower end (below; all inside the box): ``upper`` is bisected once more with them, which
  moves it from the grid's value towards the certified one (``binding`` lists them).
* ``lower``: a point ``p`` (reported) certified for the continuous box: the box is split into
  cells, and on a cell each leg's offset ``w = R·u - b`` stays within ``|u|·3δ`` of its value
  at the cell's centre (δ the cell's half-width), so the leg's interval is bounded from the
  interval at the ball's extreme distances and heights (first order), or, for families
  with a ``column_profile()`` (closed-form leg ends ``c + σ·sqrt(K - d²) - w_z``), by the
  end's linearisation over the cell plus the rotation's and the sphere's second-order
  remainders (whichever certifies); cells are split until every cell is certified (or one's
  centre orientation fails ``p``). The point is the best one (largest
  margin, to 0.01 mm) within 5 mm of the sample's witness, against the sample at that ``θ``
  plus the orientations that refuted earlier points. ``θ`` steps down from the sampled level
  in doubling steps until a level is certified, then is bisected to ``tol``, within a budget
  of orientation cells (the note says when it ran out; the lower end is certified anyway).
* ``sampled``: the largest ``θ`` whose ``samples³`` grid has a position (a witness), to
  ``tol``; ``upper`` may lie below it.

**The whole rotation group.** A ±180° Euler box is all of SO(3), so the capability is at
most 180°. When the ±180° sample admits a position, :func:`whole_group_margin` tries to prove
180° by the *sphere argument*: as ``R`` ranges over SO(3), leg i's platform joint relative to
its base joint, ``v = p - b_i + R·u_i``, ranges over the sphere of radius ``|u_i|`` about
``p - b_i``, and the leg is feasible iff ``v`` lies in the leg's set ``{ρ = |v_xy|: ok(ρ),
A(ρ) <= v_z <= B(ρ)}`` (the radial column ends at ``w = 0``, monotone in ρ). The sphere is cut
into horizontal slabs ``v_z - (p - b_i)_z ∈ [t0, t1]``; on a slab ρ lies in ``[max(0, ρ_c -
h_max, h_min - ρ_c), ρ_c + h_max]`` (``h = sqrt(|u_i|² - t²)``, ρ_c the centre's), so the slab
is inside if the ends at those two distances satisfy ``max A <= z0``, ``min B >= z1``. A
positive smallest slack over legs and slabs proves that every rotation keeps every leg in its
window at ``p``: the answer is then ``[180, 180]`` with that point (searched from the sample's
witness, the certified point and the nominal position, by Nelder–Mead on the slack). Otherwise
the upper end is 180° and the lower end what the certification reached.

**The reported point** is checked once more by inverse kinematics at random rotations of its
box (a check that can fail; the proof is the certification or the sphere argument); a point
that fails it is not reported (``point`` NaN, with a note), nor is one when no level above 0
was certified and it fails the nominal orientation.

``upper`` and ``sampled`` are bisected to ``tol`` (0.01°). The bracket ``upper - lower`` is
wider than ``tol`` when the cuts miss orientations that bind or the cell bounds are loose
(links near horizontal): certification then fails or runs out of budget above ``lower``.

**Needed stroke** (:func:`stroke_needed`) — for an orientation set (a simultaneous box with
equal half-ranges), the smallest upper actuator limit ``q_max`` (the lower limit kept) for which
the dexterous workspace is non-empty, bracketed by exchange rounds (the cutting-plane method
of semi-infinite programming):

* ``lower``: the largest ``q_max`` (bisected to ``tol/4``) at which a finite set ``S`` of
  orientations of the box admits no continuous position (branch and bound). ``S`` starts as
  the ``n³`` grid; each round adds the *binding orientations* of the sample's best column
  (:func:`pkmlab.workspaces.optima.binding.binding_orientations`: for every leg, L-BFGS-B over the
  continuous box minimises the column's upper end ``b_i`` and maximises its lower end
  ``a_i``, from the sample's most binding orientations, and keeps the optima that bind harder
  than the sample). ``S`` stays a subset of the box, so every lower end is a proof; how the
  added orientations are found only decides how fast it rises.
* ``upper``: the smallest ``q_max`` (bisected to ``tol/4``) at which the sample's best column,
  at the middle of its z interval, is certified for the continuous box (``cell_budget`` cells
  per certification). It is run once the binding search no longer shrinks that column's
  interval by more than ``tol/4`` (the sample then binds the column as the box does).

Rounds stop when ``upper - lower <= tol``, when no binding orientation is found (the upper end
is then limited by the certification's cell bounds), or after ``rounds`` rounds; the note says
which.

The grid engine's answers lie below these: a grid column is one continuous position.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ...limits import CAPABILITY_MAX_DEG
from ...mechanisms.kernels import ik as _kernels
from ...mechanisms.kernels import search as _search
from ...mechanisms.mobility import require_spatial
from ...poses import as_frames, euler_to_matrix, matrix_to_euler
from ..bracket.legbounds import EPS, Legs
from ..orientations import OrientationSet
from .binding import binding_orientations, column_ends

log = logging.getLogger(__name__)

__all__ = ["OptimumBracket", "orientation_capability", "stroke_needed", "supports_continuous",
           "whole_group_margin", "point_failures", "CAPABILITY_TOL_DEG", "STROKE_TOL_MM"]

#: bisection tolerance of the capability (deg)
CAPABILITY_TOL_DEG = 0.01
#: bisection tolerance of the needed stroke (mm)
STROKE_TOL_MM = 0.01
#: smallest tile of the branch and bound (mm)
MIN_TILE_MM = 1e-4
#: first tiles of the branch and bound (mm)
FIRST_TILE_MM = 40.0
#: smallest orientation cell half-width of the certification (rad); cell budget of all the
#: capability's certifications together
MIN_HALF_RAD = 1e-7
#: orientation cells of one certification of the needed stroke (a point whose margin is a
#: few µm needs small cells near the binding orientations; 3e6 cells take ~1 s)
STROKE_CELL_BUDGET = 3_000_000
#: exchange rounds of the needed stroke (each adds at most 12 binding orientations)
STROKE_ROUNDS = 8
#: the witness column of a sample is its best one to this margin (mm)
WITNESS_EPS_MM = 1e-3
CAPABILITY_CELL_BUDGET = 600_000
#: slabs per sphere of the whole-group (sphere) argument
SPHERE_SLABS = 512
#: random rotations of the check of a reported point
CHECK_ROTATIONS = 20_000


@dataclass(frozen=True)
class OptimumBracket:
    """A continuous optimum and the bracket that contains it.

    ``lower`` and ``upper`` bound the true value (method in the module notes), ``sampled``
    is the value for the ``samples³`` grid alone, ``point`` the certified position (mm, base
    frame) at the certified end (``lower`` for the capability, ``upper`` for the needed
    stroke); ``note`` says why a bracket is wider or open. ``history`` lists the
    exchange rounds of :func:`stroke_needed` and ``binding`` the orientations (Euler offsets
    from the box's centre, rad) they added to the ``samples³`` grid (for the capability: the
    cut orientations at the upper end's level)."""

    name: str
    unit: str
    lower: float
    upper: float
    sampled: float
    point: tuple
    samples: int
    method: str
    note: str = ""
    seconds: float = 0.0
    history: tuple = ()
    binding: tuple = ()

    @property
    def width(self) -> float:
        return self.upper - self.lower

    def as_dict(self) -> dict:
        return dataclasses.asdict(self) | {"width": self.width}


def supports_continuous(mech, constraints=None) -> bool:
    """True when the continuous search applies: radial column intervals, stroke only."""
    extra = bool(constraints is not None and constraints.extra)
    return bool(mech.column_radial) and mech.column_method is not None and not extra


def _inputs(mech):
    _, Rn = as_frames(mech.nominal_pose)
    e0 = _kernels.carray(np.array(matrix_to_euler(Rn[0]), dtype=float))
    U = _kernels.carray(np.array(mech.tool_points, dtype=float))
    B = _kernels.carray(np.array(mech.base_points, dtype=float))
    # every orientation's position bounds lie within the nominal one's grown by 2·max|u|
    b = mech.position_bounds(Rn)[0]
    g = 2.0 * float(np.max(np.linalg.norm(U, axis=1))) + 1.0
    box = _kernels.carray(np.array([b[0, 0] - g, b[1, 0] + g, b[0, 1] - g, b[1, 1] + g]))
    return e0, U, B, box


def _profile(mech):
    """The family's ``column_profile()`` for the second-order certification (``K = -1``
    rows: first order only)."""
    pr = mech.column_profile()
    return _kernels.carray(np.full((6, 2, 3), -1.0) if pr is None else pr)


def _require(mech, constraints=None):
    if not supports_continuous(mech, constraints):
        raise ParameterError("family", "a family with radial column intervals (psu6, ups6) "
                             "and the stroke constraint only", mech.family)


def orientation_capability(mech, samples: int = 7, tol_deg: float = CAPABILITY_TOL_DEG,
                           max_deg: float = CAPABILITY_MAX_DEG, *,
                           check: bool = True) -> OptimumBracket:
    """The orientation capability over continuous positions, bracketed (module notes), in one
    compiled search. ``check``: the reported point's check at random rotations (a check that
    can fail, not part of the proof; False skips it and the method says so: a caller that
    reports no point, such as a tolerance ladder's coarse rung)."""
    require_spatial(mech, "orientation capability")
    _require(mech)
    if not (isinstance(samples, int) and samples >= 2):
        raise ParameterError("samples", "an integer >= 2 (angles per axis)", samples)
    t0 = time.perf_counter()
    e0, U, B, box = _inputs(mech)
    P = _kernels.carray(mech.column_params())
    cap = _search.make_capability(type(mech).column_leg)
    out = np.empty(13)
    cuts = np.empty((_search.CUTS, 3))
    cap(U, B, P, _profile(mech), e0, int(samples), box, FIRST_TILE_MM, math.radians(max_deg),
        math.radians(tol_deg), MIN_TILE_MM, MIN_HALF_RAD, CAPABILITY_CELL_BUDGET, out, cuts)
    flags = int(out[9])
    notes = []
    if flags & 2:
        notes.append("no workspace at the nominal orientation")
    if flags & 1:
        notes.append(f"not bounded by the search: the ±{max_deg:g}° box has a dexterous "
                     "position")
    if flags & 4:
        notes.append("a branch and bound was undecided (margin within 1e-9 mm of zero on a "
                     f"{MIN_TILE_MM:g} mm tile); the upper end stops there")
    if flags & 8:
        notes.append(f"certification stopped by its budget ({CAPABILITY_CELL_BUDGET:,} "
                     "orientation cells): the lower end is certified, the truth may lie higher")
    lower, upper, sampled = (math.degrees(v) for v in out[:3])
    point = tuple(map(float, out[6:9]))
    method = (f"branch and bound over continuous positions ({samples}^3 orientation samples "
              f"and {int(out[12])} cut orientations, upper end) and a point certified for the "
              f"continuous box (lower end), bisected to {tol_deg:g}°; {int(out[10])} searches, "
              f"{int(out[11])} orientation cells")
    if flags & 1:
        upper = math.inf
        if max_deg >= 180.0:
            # a ±180° Euler box is the whole rotation group
            upper = 180.0
            notes[notes.index(next(n for n in notes if n.startswith("not bounded")))] = (
                "the ±180° box (the whole rotation group) has a dexterous position in its "
                f"{samples}^3 sample")
            cands = [point, tuple(out[3:6]), tuple(np.asarray(mech.nominal_pose[:3]))]
            slack, p = best_whole_group_point(mech, cands)
            if slack > 0.0:
                lower, point = 180.0, p
                notes = [n for n in notes if not n.startswith("certification stopped")]
                method = ("the sphere argument: at the point, every leg's platform joint stays "
                          "in its window on the whole sphere it sweeps under all rotations "
                          f"(slack {slack:.4f} mm over {SPHERE_SLABS} slabs per sphere; "
                          "module notes)")
            else:
                notes.append(f"the sphere argument proves no point (best slack {slack:.4f} mm):"
                             " the upper end is 180°, the lower end what the cells certified")
    fails = point_failures(mech, point, math.radians(lower)) if check else 0
    if not check:
        method += "; the point's check at random rotations skipped"
    if fails:
        notes.append(f"the point {tuple(round(v, 4) for v in point)} fails {fails} of "
                     f"{CHECK_ROTATIONS:,} random rotations of the ±{lower:g}° box: not "
                     "reported")
        point = (math.nan,) * 3
    return OptimumBracket(
        "orientation_capability", "deg", lower, upper, sampled, point, samples, method,
        "; ".join(notes), time.perf_counter() - t0,
        binding=tuple(tuple(map(float, c)) for c in cuts[:int(out[12])] * out[1])
        if math.isfinite(upper) and not flags & 1 else ())


def whole_group_margin(mech, p) -> float:
    """Smallest slack (mm) over the legs and the slabs of the sphere argument at position
    ``p`` (module notes): positive proves that every rotation keeps every leg in its window
    at ``p``; -inf where a slab leaves a leg's reach."""

    c = np.asarray(p, float) - mech.base_points                      # (6, 3) sphere centres
    r = np.linalg.norm(mech.tool_points, axis=1)[:, None]            # (6, 1) radii
    t = np.linspace(-1.0, 1.0, SPHERE_SLABS + 1)[None] * r           # (6, S + 1) slab ends
    t0, t1 = t[:, :-1], t[:, 1:]
    h = np.sqrt(np.maximum(r**2 - t**2, 0.0))
    hmax = np.where((t0 <= 0) & (t1 >= 0), r, np.maximum(h[:, :-1], h[:, 1:]))
    hmin = np.minimum(h[:, :-1], h[:, 1:])
    rc = np.hypot(c[:, 0], c[:, 1])[:, None]
    d = np.stack([np.maximum.reduce([np.zeros_like(hmax), rc - hmax, hmin - rc]), rc + hmax])
    A, B, ok = Legs(mech, None).ends(np.moveaxis(d, 1, -1))          # (2, S, 6)
    A, B, ok = (np.moveaxis(x, -1, 1) for x in (A, B, ok))           # (2, 6, S)
    z0, z1 = c[:, 2, None] + t0, c[:, 2, None] + t1
    slack = np.minimum(z0 - A.max(axis=0), B.min(axis=0) - z1) - EPS
    return float(np.min(np.where(ok.all(axis=0), slack, -np.inf)))


def best_whole_group_point(mech, candidates) -> tuple[float, tuple]:
    """The candidate with the largest :func:`whole_group_margin`, improved by Nelder–Mead:
    ``(slack, point)``."""
    from scipy.optimize import minimize  # lazy: only for a machine whose whole group fits

    cands = [np.asarray(c, float) for c in candidates if np.all(np.isfinite(c))]
    vals = [whole_group_margin(mech, c) for c in cands]
    k = int(np.argmax(vals))
    res = minimize(lambda x: -max(whole_group_margin(mech, x), -1e9), cands[k],
                   method="Nelder-Mead", options={"xatol": 1e-3, "fatol": 1e-4,
                                                  "maxfev": 400, "initial_simplex":
                                                  cands[k] + np.vstack([np.zeros(3),
                                                                        5.0 * np.eye(3)])})
    best = whole_group_margin(mech, res.x)
    if best > vals[k]:
        return best, tuple(map(float, res.x))
    return vals[k], tuple(map(float, cands[k]))


def point_failures(mech, point, theta: float, n: int | None = None, seed: int = 0) -> int:
    """How many of ``n`` random rotations of the ±theta box about the nominal orientation
    (uniform in the Euler offsets, corners and the centre included) put a leg of ``point``
    outside its window: the check that can fail of a certified point."""
    if not np.all(np.isfinite(point)):
        return 0
    n = CHECK_ROTATIONS if n is None else n
    rng = np.random.default_rng(seed)
    corners = np.array([[i, j, k] for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)])
    E = np.vstack([corners, rng.uniform(-1.0, 1.0, (n - len(corners), 3))]) * theta
    _, Rn = as_frames(mech.nominal_pose)
    e0 = np.asarray(matrix_to_euler(Rn[0]))
    R = euler_to_matrix(e0 + E)
    P = np.broadcast_to(np.asarray(point, float), (n, 3)).copy()
    return int(np.sum(~mech.inverse((P, R)).valid))


def _box_sample(theta: float, n: int) -> np.ndarray:
    """``(n³, 3)`` Euler offsets of the ±theta box, n angles per axis, corners included."""
    ax = np.linspace(-theta, theta, n)
    return np.stack([g.ravel() for g in np.meshgrid(ax, ax, ax, indexing="ij")], axis=1)


def stroke_needed(mech, orientations: OrientationSet, tol_mm: float = STROKE_TOL_MM,
                  q_max_limit: float | None = None,
                  rounds: int = STROKE_ROUNDS,
                  cell_budget: int = STROKE_CELL_BUDGET) -> OptimumBracket:
    """The smallest upper actuator limit giving a non-empty dexterous workspace over the
    simultaneous box ``orientations`` (equal half-ranges), the lower limit kept, bracketed
    (module notes). ``q_max_limit`` caps the search (default: lower limit + 4 × scale);
    ``rounds`` caps the exchange rounds that add binding orientations to the sample,
    ``cell_budget`` the orientation cells of one certification."""
    require_spatial(mech, "the needed stroke")
    _require(mech)
    if orientations.kind != "box" or orientations.semantics != "simultaneous" or \
            len(set(orientations.angles)) != 1:
        raise ParameterError("orientations", "a simultaneous box with equal half-ranges",
                             orientations.describe())
    if not (isinstance(rounds, int) and 0 <= rounds <= 100):
        raise ParameterError("rounds", "an integer in [0, 100]", rounds)
    if not (isinstance(tol_mm, (int, float)) and 1e-4 <= tol_mm <= 10.0):
        raise ParameterError("tol_mm", "a tolerance in [1e-4, 10] mm", tol_mm)
    t0 = time.perf_counter()
    theta = float(orientations.angles[0])
    n = int(orientations.samples)
    qmin = float(mech.stroke[0])
    hi = float(q_max_limit) if q_max_limit is not None else qmin + 4.0 * mech.scale
    if not hi > qmin:
        raise ParameterError("q_max_limit", f"a limit above the lower one ({qmin:g} mm)", hi)
    e0, U, B, box = _inputs(dataclasses.replace(mech, stroke_window=(qmin, hi)))
    if orientations.centre is not None:
        e0 = _kernels.carray(np.array(orientations.centre, dtype=float))
    bb = _search.make_branch_bound(type(mech).column_leg)
    cert = _search.make_certify(type(mech).column_leg)
    r, c = np.empty(8), np.empty(2)
    E = _box_sample(theta, n)
    W = _kernels.carray(mech.leg_offsets(euler_to_matrix(e0 + E)))

    def params(qmax):
        return _kernels.carray(dataclasses.replace(mech, stroke_window=(qmin, qmax))
                               .column_params())

    def empty(qmax):           # True: proved empty at every position; False: a witness
        bb(W, params(qmax), box, FIRST_TILE_MM, MIN_TILE_MM, 0.0, True, r)
        return {1.0: False, 0.0: True}.get(float(r[0]))

    def profile(qmax):
        return _profile(dataclasses.replace(mech, stroke_window=(qmin, qmax)))

    def certified(qmax, xy):
        """The column ``xy`` at the middle of the sample's z interval, if certified for the
        continuous box at qmax; else None."""
        P = params(qmax)
        a, b, ok = column_ends(mech, P, xy[0], xy[1], e0, E)
        zl, zh = float(np.max(a)), float(np.min(b))
        if not (ok.all() and zh >= zl):
            return None
        p = (float(xy[0]), float(xy[1]), 0.5 * (zl + zh))
        cert(U, B, P, profile(qmax), e0, theta, *p, MIN_HALF_RAD, cell_budget, c)
        return p if c[0] == 1 else None

    lo = float(mech.stroke[1])
    if lo >= hi or not empty(lo):
        # already non-empty: the needed limit lies between qmin and the current one
        lo = qmin + 1e-9
        if empty(lo) is not True:
            raise ParameterError("stroke", "a window whose lower limit alone admits no "
                                 "position", mech.stroke)
    if empty(hi) is not False:
        raise ParameterError("q_max_limit", "a limit at which the set is non-empty", hi)
    s_lo, c_hi, point, sampled = lo, hi, None, math.nan
    notes, history, added, undecided = [], [], 0, 0
    guess = hi                 # a limit with a witness for the current sample
    for rnd in range(rounds + 1):
        # lower end: bisection of the (enlarged) sample's needed limit; s_lo stays proved
        # empty (a larger sample is harder)
        s_hi = min(guess, c_hi)
        while s_hi - s_lo > 0.25 * tol_mm:
            mid = 0.5 * (s_lo + s_hi)
            e = empty(mid)
            if e is None:        # not proved empty: the lower end stays below it
                undecided += 1
            s_lo, s_hi = (mid, s_hi) if e else (s_lo, mid)
        if rnd == 0:
            sampled = s_hi
        # the sample's best column at its own needed limit, and the orientations of the box
        # that bind it harder than the sample
        bb(W, params(s_hi), box, FIRST_TILE_MM, MIN_TILE_MM, WITNESS_EPS_MM, False, r)
        xy = (float(r[2]), float(r[3]))
        new, gain = binding_orientations(mech, params(s_hi), xy[0], xy[1], e0, theta, E) \
            if rnd < rounds else (np.empty((0, 3)), 0.0)
        if gain <= 0.25 * tol_mm or rnd == rounds:
            # the sample binds the column as the box does: certify it (upper end)
            if point is None:
                point = certified(hi, xy)
                if point is None:
                    raise ParameterError("q_max_limit", "a limit at which a point is "
                                         "certified", hi)
            c_lo = s_lo
            while c_hi - c_lo > 0.25 * tol_mm:
                mid = 0.5 * (c_lo + c_hi)
                p = certified(mid, xy)
                if p is None:
                    c_lo = mid
                else:
                    c_hi, point = mid, p
        history.append({"round": rnd, "orientations": len(E), "lower": s_lo,
                        "upper": c_hi if point is not None else None,
                        "binding_gain": gain, "seconds": time.perf_counter() - t0})
        if point is not None and c_hi - s_lo <= tol_mm:
            break
        if rnd == rounds:
            notes.append(f"stopped after {rounds} exchange rounds at width "
                         f"{c_hi - s_lo:.4f} mm")
            break
        if len(new) == 0:
            notes.append(f"no orientation of the box binds the witness column harder than "
                         f"the sample ({len(E)} orientations): the upper end is limited by "
                         f"the certification ({cell_budget:,} orientation cells)")
            break
        log.debug("stroke_needed round %d: [%.4f, %.4f] mm, +%d orientations (gain %.4f mm)",
                  rnd, s_lo, c_hi, len(new), gain)
        E = np.vstack([E, new])
        added += len(new)
        W = _kernels.carray(mech.leg_offsets(euler_to_matrix(e0 + E)))
        # the witness column loses about `gain`: a limit just above that usually has a witness
        guess = s_hi + gain + tol_mm
        if guess < c_hi and empty(guess) is not False:
            guess = c_hi
    if undecided:
        notes.append(f"{undecided} branch and bound(s) undecided (margin within 1e-9 mm of "
                     f"zero on a {MIN_TILE_MM:g} mm tile), counted as not empty: the lower "
                     "end stays proved")
    return OptimumBracket(
        "stroke_needed", "mm", s_lo, c_hi, sampled, point, n,
        f"upper actuator limit, lower limit {qmin:g} mm kept: branch and bound over "
        f"continuous positions ({n}^3 orientation samples + {added} binding orientations "
        f"found by local optimisation in {len(history) - 1} exchange round"
        f"{'' if len(history) == 2 else 's'}, lower end), a "
        f"point certified for the continuous ±{math.degrees(theta):g}° box (upper end), "
        f"bisected to {0.25 * tol_mm:g} mm", "; ".join(notes), time.perf_counter() - t0,
        tuple(history), tuple(map(tuple, E[n ** 3:].tolist())))
