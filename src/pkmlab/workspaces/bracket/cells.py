"""A guaranteed volume bracket on position cells × orientation cells, for families without
column kernels whose legs are bounded over a cell (``cell_bounds``: luzi3; rss6, whose rods
may also fail to close, through the margins of its ``leg_cell_margins``).

**Cells.** Positions are covered by axis-aligned cubes on a grid anchored at the origin (edge
``resolution·2^k``; the first edge is the smallest such that the search box is at most 32
cubes wide), orientations by the boxes of :mod:`.cells` (angle bound α per cell). An *item* is
a (cube, orientation cell) pair. The family's ``leg_cell_bounds(p, R, δ, α)`` gives each leg's
value ``q`` at the item's centre and ``ε`` with ``|q' - q| <= ε`` for every position within
``δ`` (the cube's half-diagonal) and rotation within α; with α = 0 it bounds the cube at the
centre rotation alone (a *sample*, a rotation that belongs to the set). With ``m = min(q -
qmin, qmax - q)`` per leg (or the family's ``leg_cell_margins``: ``m > ε`` proves the leg
feasible on the item, ``m < -ε`` infeasible):

* item *in*: every leg has ``m > ε`` and the family says the whole item is in its working
  mode (``leg_cell_bounds(..., mode=True)``: luzi3, every upper link on its working branch),
  so it is feasible at every point and rotation of the item; item *out*: some leg has ``m <
  -ε``, or no point of the item is in the working mode; the same at α = 0 for the sample.
* constant and dexterous (every orientation): a cube is *out* when any sample of it is out,
  *in* when all its items are in (the items cover the set); the items found in are dropped.
* reachable (some orientation): a cube is *in* when any sample of it is in, *out* when all its
  items are out; the items found out are dropped.
* the samples of a cube are its items' centres and the corners of the set's first cells
  (where leg extremes often lie), re-checked at every step.

``lower`` is the volume of the cubes in, ``upper`` that of the cubes in or undecided (closed
cubes: the workspace lies in their union). Every undecided cube is refined each step: the
orientation cells of its items whose rotation part of ε (``ε(α) - ε(0)``) exceeds the
position part are split (:func:`.cells.split`); a cube with no such item is split into its 8
children, which inherit its live items. It stops when ``upper - lower <= target·upper``, or
the budget (seconds, items of a step, leg evaluations) runs out, and says which; a step
whose predicted time (the last one's, scaled by the items) would overrun the seconds is not
started.

**Connected to nominal.** As in :mod:`.bracket`: components of the in cubes and of the in or
undecided cubes (closed cubes that touch, ``|c_a - c_b|_∞ <= h_a + h_b``, are connected);
``lower`` counts the in component holding the nominal position, ``upper`` the outer one. If no
outer cube holds it, it is certainly outside the workspace and the bracket covers every
component (lower 0), with a note.

The initial search box is the union over the first orientation cells of the family's
``position_bounds`` at the cell centre widened by ``2 sin(α/2)·max|tool point|`` (those
bounds come from the base points and ``R·u_i``, which move by at most that).
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np

from .. import cells as oc
from .partial import sample_fractions, vertices
from .result import VolumeBracket

log = logging.getLogger(__name__)

__all__ = ["cell_volume_bracket", "touching_pairs", "touching_components"]

#: cubes across the search box's widest side at the first step (at most)
_FIRST = 32
#: items evaluated per call of the family's bound
_BATCH = 200_000
#: split an item's orientation cell when its rotation part of the bound exceeds this many
#: times the position part (otherwise the cube)
_TURN = 1.0


def touching_pairs(C: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(i, j)`` of closed cubes (centres ``C (n, 3)``, half-edges ``h (n,)``) that
    touch, ``|c_i - c_j|_∞ <= h_i + h_j``: a k-d tree in the maximum norm per cube size."""
    from scipy.spatial import cKDTree  # lazy (0.25 s at import): a study imports this module

    sizes, inv = np.unique(h, return_inverse=True)
    idx = [np.flatnonzero(inv == k) for k in range(len(sizes))]
    trees = [cKDTree(C[i]) for i in idx]
    rows, cols = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    for a in range(len(sizes)):
        for b in range(a, len(sizes)):
            r = (sizes[a] + sizes[b]) * (1 + 1e-9)
            if a == b:
                pr = trees[a].query_pairs(r, p=np.inf, output_type="ndarray")
                i, j = pr[:, 0], pr[:, 1]
            else:
                m = trees[a].sparse_distance_matrix(trees[b], r, p=np.inf,
                                                    output_type="ndarray")
                i, j = m["i"], m["j"]
            rows.append(idx[a][i])
            cols.append(idx[b][j])
    return np.concatenate(rows), np.concatenate(cols)


def touching_components(C: np.ndarray, h: np.ndarray, pairs=None) -> tuple[int, np.ndarray]:
    """Components of closed cubes that touch (:func:`touching_pairs`, or the ``pairs``
    given): ``(count, labels (n,))``."""
    n = len(C)
    if n == 0:
        return 0, np.zeros(0, np.int64)
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    i, j = touching_pairs(C, h) if pairs is None else pairs
    g = coo_matrix((np.ones(len(i), np.int8), (i, j)), shape=(n, n))
    return connected_components(g, directed=False)


def _home(C, h, p_nom, pairs):
    """Mask of the cubes in the component holding ``p_nom`` (None if no cube holds it)."""
    if len(C) == 0:
        return None
    home = np.flatnonzero(np.all(np.abs(C - p_nom) <= h[:, None] * (1 + 1e-9), axis=1))
    if len(home) == 0:
        return None
    _, lab = touching_components(C, h, pairs)
    return lab == lab[home[0]]


def _search_box(mech, oset, C0, H0):
    R = oset.rotations_at(C0)
    pb = mech.position_bounds(R)                                   # (L, 2, 3)
    grow = (oc.chord(oc.angle_bound(oset, C0, H0))
            * np.max(np.linalg.norm(mech.tool_points, axis=1)))[:, None]
    ok = np.all(pb[:, 0] <= pb[:, 1], axis=1)
    if not ok.any():
        return None
    return (pb[ok, 0] - grow[ok]).min(axis=0), (pb[ok, 1] + grow[ok]).max(axis=0)


def _first_cubes(lo, hi, resolution):
    e = float(resolution)
    while np.max(hi - lo) / e > _FIRST:
        e *= 2
    axes = [(np.arange(math.floor(a / e), math.ceil(b / e)) + 0.5) * e for a, b in zip(lo, hi,
                                                                                       strict=True)]
    G = np.meshgrid(*axes, indexing="ij")
    C = np.stack([g.ravel() for g in G], axis=1)
    return C, np.full(len(C), 0.5 * e)


def _corners(C0, H0):
    """The distinct corners of the first orientation cells that are not a centre (none for
    a fixed orientation)."""
    if not np.any(H0 > 0):
        return np.zeros((0, 3))
    signs = np.array(np.meshgrid(*[(-1.0, 1.0)] * 3, indexing="ij")).reshape(3, -1).T
    V = np.unique(np.round((C0[:, None, :] + signs[None] * H0[:, None, :]).reshape(-1, 3),
                           12), axis=0)
    # algorithm constant: the vertices were rounded to 12 decimals just above
    return V[~np.any(np.all(np.abs(V[:, None, :] - C0[None]) < 1e-12, axis=2), axis=1)]


def _evaluate(mech, oset, P, hP, pid, Oc, Oh):
    """Per item: ``(q (K, 6), margins (K, M), eps over the item, eps of the sample, working
    mode over the item (K,), working mode of the sample (K,))``: the margins of the family's
    ``leg_cell_margins`` (M = 6, ``min(q - qmin, qmax - q)``, unless the family says
    otherwise); the modes +1 (certainly in it), -1 (certainly not) or 0 (undecided), the least
    of the chains'."""
    K = len(pid)
    rotating = bool(np.any(Oh > 0))
    out: list[list] = [[] for _ in range(6)]
    for s in range(0, K, _BATCH):
        sl = slice(s, s + _BATCH)
        p, R = P[pid[sl]], oset.rotations_at(Oc[sl])
        delta = math.sqrt(3.0) * hP[pid[sl]]
        q, ms, es, b = mech.leg_cell_margins(p, R, delta, 0.0, mode=True)
        ws = b.min(axis=1)
        if rotating:
            _, _, ec, bc = mech.leg_cell_margins(p, R, delta,
                                                 oc.angle_bound(oset, Oc[sl], Oh[sl]), mode=True)
            wc = bc.min(axis=1)
        else:
            ec, wc = es, ws
        for acc, x in zip(out, (q, ms, ec, es, wc, ws)):
            acc.append(x)
    if K == 0:
        return (*(np.zeros((0, 6)) for _ in range(4)), np.zeros(0, np.int8),
                np.zeros(0, np.int8))
    return tuple(np.concatenate(x) for x in out)


def cell_volume_bracket(mech, kind, oset, resolution, cons, target, budget_s,
                        max_cells=3_000_000, max_evaluations=5e9) -> VolumeBracket:
    """The bracket of :func:`.bracket.volume_bracket` for a ``cell_bounds`` family (module
    notes). ``oset`` is already centred on the nominal orientation, ``cons`` checked
    (stroke and connectivity only) and the stroke applied to ``mech``."""
    t0 = time.perf_counter()
    p_nom = np.asarray(mech.nominal_pose[:3], float)
    C0, H0 = oc.initial_cells(oset, 1)
    box = _search_box(mech, oset, C0, H0)
    if box is None:
        return VolumeBracket(0.0, 0.0, target, "empty", [], float(resolution), 0,
                             time.perf_counter() - t0, ["no position is within every leg's "
                                                        "reach"])
    P, hP = _first_cubes(*box, resolution)
    L = len(C0)
    pid = np.repeat(np.arange(len(P)), L)
    Oc, Oh = np.tile(C0, (len(P), 1)), np.tile(H0, (len(P), 1))
    in_C, in_h = np.zeros((0, 3)), np.zeros(0)
    V = _corners(C0, H0)
    history: list[dict] = []
    notes: list[str] = []
    evaluations = 0
    lower, upper = 0.0, math.inf
    stop = None
    step = 0
    while True:
        q, m, e_cell, e_s, w_cell, w_s = _evaluate(mech, oset, P, hP, pid, Oc, Oh)
        evaluations += 6 * len(pid) * (2 if np.any(Oh > 0) else 1)
        with np.errstate(invalid="ignore"):
            # feasible = within the stroke and in the working mode (every chain on its branch)
            item_in = np.all(m > e_cell, axis=1) & (w_cell > 0)
            item_out = np.any(m < -e_cell, axis=1) | (w_cell < 0)
            s_in, s_out = np.all(m > e_s, axis=1) & (w_s > 0), np.any(m < -e_s, axis=1) | (w_s < 0)
        n = len(P)
        spid, sO, sq, sw = pid, Oc, q, w_s
        if len(V):
            # the corners of the set as extra samples of every cube (leg extremes lie there)
            vp = np.repeat(np.arange(n), len(V))
            vO = np.tile(V, (n, 1))
            vq, vm, _, ve, _, vw = _evaluate(mech, oset, P, hP, vp, vO, np.zeros((len(vp), 3)))
            evaluations += 6 * len(vp)
            with np.errstate(invalid="ignore"):
                s_in = np.concatenate([s_in, np.all(vm > ve, axis=1) & (vw > 0)])
                s_out = np.concatenate([s_out, np.any(vm < -ve, axis=1) | (vw < 0)])
            spid, sO, sq, sw = np.concatenate([pid, vp]), np.concatenate([Oc, vO]), \
                np.concatenate([q, vq]), np.concatenate([w_s, vw])
        if kind == "reachable":
            c_in = np.zeros(n, bool)
            np.logical_or.at(c_in, spid, s_in)
            keep = ~item_out & ~c_in[pid]
            c_out = ~c_in & (np.bincount(pid[keep], minlength=n) == 0)
        else:
            c_out = np.zeros(n, bool)
            np.logical_or.at(c_out, spid, s_out)
            keep = ~item_in & ~c_out[pid]
            c_in = ~c_out & (np.bincount(pid[keep], minlength=n) == 0)
        und = ~c_in & ~c_out
        in_C, in_h = np.concatenate([in_C, P[c_in]]), np.concatenate([in_h, hP[c_in]])
        u_C, u_h = P[und], hP[und]
        sets = _components(in_C, in_h, u_C, u_h, p_nom, cons.connected)
        sel = und[spid]
        part = (_partial(mech, oset, kind, P, hP, und, spid[sel], sO[sel], sq[sel], sw[sel],
                         in_C[sets[0]], in_h[sets[0]], cons.connected)
                if mech.position_curvature else None)
        lo_s, up_s, note = _volumes(in_h, u_h, sets, part)
        lower = max(lower, lo_s)
        upper = up_s if note else min(upper, up_s)
        if note and note not in notes:
            notes.append(note)
        elapsed = time.perf_counter() - t0
        history.append({"step": step, "cube_mm": float(2 * hP.min()) if n else None,
                        "undecided_cubes": int(und.sum()), "items": int(keep.sum()),
                        "lower_mm3": lo_s, "upper_mm3": up_s, "seconds": elapsed,
                        "evaluations": evaluations})
        log.debug("cell bracket %s", history[-1])
        if upper <= 0 or upper - lower <= target * upper:
            stop = "converged" if upper > 0 else "empty"
        elif elapsed >= budget_s:
            stop = "budget: seconds"
        elif evaluations >= max_evaluations:
            stop = "budget: evaluations"
        if stop is not None:
            break
        n_items = len(pid)
        P, hP, pid, Oc, Oh = _refine(P, hP, pid[keep], Oc[keep], Oh[keep], e_cell[keep],
                                     e_s[keep], und)
        if len(pid) > max_cells:
            stop = "budget: cells"
            break
        # a step costs about in proportion to its items: do not start one that cannot end
        # within the budget
        took = elapsed - (history[-2]["seconds"] if len(history) > 1 else 0.0)
        if elapsed + took * len(pid) / max(n_items, 1) > budget_s:
            stop = "budget: seconds"
            break
        step += 1
    if notes:
        lower = 0.0
    res = float(2 * u_h.min()) if len(u_h) else float(resolution)
    boxes = (np.concatenate([in_C, u_C]), np.concatenate([in_h, u_h]),
             np.concatenate([np.ones(len(in_h), bool), np.zeros(len(u_h), bool)]))
    return VolumeBracket(lower, upper, target, stop, history, res, evaluations,
                         time.perf_counter() - t0, notes, boxes=boxes)


def _components(in_C, in_h, u_C, u_h, p_nom, connected):
    """``(in cubes kept (n_in,), all cubes kept (n_in + n_u,) or None)``: the components
    holding the nominal position (every cube without connectivity; None when no cube holds
    it). The touching pairs are found once and restricted to the in cubes."""
    n = len(in_h)
    if not connected:
        return np.ones(n, bool), np.ones(n + len(u_h), bool)
    C, h = np.concatenate([in_C, u_C]), np.concatenate([in_h, u_h])
    i, j = touching_pairs(C, h)
    outer = _home(C, h, p_nom, (i, j))
    if outer is None:
        return np.zeros(n, bool), None
    both = (i < n) & (j < n)
    inner = _home(in_C, in_h, p_nom, (i[both], j[both]))
    return (np.zeros(n, bool) if inner is None else inner), outer


def _volumes(in_h, u_h, sets, part):
    """``(lower, upper, note)`` (mm³) of one step; ``part`` the undecided cubes' fractions
    ``(inner lower bound, outer upper bound)`` or None (0 and 1)."""
    v_in, v_u = (2 * in_h) ** 3, (2 * u_h) ** 3
    f_lo, f_up = part if part is not None else (np.zeros(len(u_h)), np.ones(len(u_h)))
    inner, outer = sets
    if outer is None:
        return 0.0, float(v_in.sum() + (f_up * v_u).sum()), (
            "the nominal position is outside the workspace: the bracket covers every "
            "component (lower 0)")
    n = len(in_h)
    return (float(v_in[inner].sum() + (f_lo * v_u).sum()),
            float(v_in[outer[:n]].sum() + (f_up * v_u)[outer[n:]].sum()), None)


def _partial(mech, oset, kind, P, hP, und, pid, O, q, w, keep_C, keep_h, connected):
    """Second-order fractions of the undecided cubes (:mod:`.bracket_partial`) from their
    samples: the upper one (constant, dexterous) is the smallest over the samples; the lower
    one (constant, reachable) the largest over the samples in the working mode over the cube
    (``w > 0``) whose inner region has a vertex in a kept in cube (so it joins the kept
    component; any sample without connectivity).
    ``q`` is the family's bound centre at α = 0, the leg length wherever the curvature bound
    ``M`` is finite (luzi3: both need the link's sign fixed over the cube)."""
    ui = np.cumsum(und) - 1
    nu = int(und.sum())
    f_lo, f_up = np.zeros(nu), np.ones(nu)
    if len(pid) == 0:
        return f_lo, f_up
    s = hP[pid]
    g, M = mech.leg_position_curvature(P[pid], oset.rotations_at(O), math.sqrt(3.0) * s)
    inner, up, vert = sample_fractions(q, g, M, s, mech.stroke)
    cube = ui[pid]
    if kind != "reachable":
        np.minimum.at(f_up, cube, up)
    if kind != "dexterous":
        if connected:
            Vx = vertices(P[pid], s).reshape(-1, 3)
            vert = vert & _in_cubes(Vx, keep_C, keep_h).reshape(vert.shape)
        ok = vert.any(axis=1) & (w > 0)
        np.maximum.at(f_lo, cube[ok], inner[ok])
    return f_lo, f_up


def _in_cubes(points, C, h):
    """``(N,)`` bool: points in any of the closed cubes."""
    from scipy.spatial import cKDTree

    out = np.zeros(len(points), bool)
    for hh in np.unique(h):
        d, _ = cKDTree(C[h == hh]).query(points, p=np.inf, distance_upper_bound=hh * (1 + 1e-9))
        out |= np.isfinite(d)
    return out


def _refine(P, hP, pid, Oc, Oh, e_cell, e_s, und):
    """Split the live items' orientation cells where rotation dominates their bound, and the
    cubes where it dominates none (children inherit the items)."""
    with np.errstate(invalid="ignore"):
        orient = (np.max(e_cell - e_s, axis=1) > _TURN * np.max(e_s, axis=1)) & np.any(Oh > 0,
                                                                              axis=1)
    n = len(P)
    turn = np.zeros(n, bool)
    np.logical_or.at(turn, pid, orient)
    # renumber the undecided cubes: those turning keep their cube, the others get 8 children
    stay = und & turn
    halve = und & ~turn
    new_id = np.full(n, -1)
    new_id[stay] = np.arange(int(stay.sum()))
    ns = int(stay.sum())
    h_idx = np.flatnonzero(halve)
    signs = np.array(np.meshgrid(*[(-1.0, 1.0)] * 3, indexing="ij")).reshape(3, -1).T  # (8, 3)
    kids = (P[h_idx, None, :] + 0.5 * hP[h_idx, None, None] * signs).reshape(-1, 3)
    P2 = np.concatenate([P[stay], kids])
    h2 = np.concatenate([hP[stay], np.repeat(0.5 * hP[h_idx], 8)])
    # items of the cubes that turn
    a = turn[pid]
    sp = a & orient
    Cs, Hs, par = oc.split(Oc[sp], Oh[sp])
    ids = [new_id[pid[a & ~orient]], new_id[pid[sp]][par]]
    Ocs, Ohs = [Oc[a & ~orient], Cs], [Oh[a & ~orient], Hs]
    # items of the cubes that halve: copied to each child
    b = halve[pid]
    rank = np.full(n, -1)
    rank[h_idx] = np.arange(len(h_idx))
    child = ns + 8 * rank[pid[b]][:, None] + np.arange(8)[None, :]
    ids.append(child.ravel())
    Ocs.append(np.repeat(Oc[b], 8, axis=0))
    Ohs.append(np.repeat(Oh[b], 8, axis=0))
    return (P2, h2, np.concatenate(ids), np.concatenate(Ocs), np.concatenate(Ohs))
