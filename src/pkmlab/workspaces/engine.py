"""The workspace engine: exact column intervals where the kinematics allow, sampling elsewhere.

Positions lie on a grid anchored at the origin with spacing ``h`` (``x = i·h``), so results
of different runs and geometries share voxels. For families with column kernels
(``Mechanism.column_method``) every (x, y) column gets its exact stroke-feasible z set as a
few intervals; the volume is then integrated exactly in z and only the x-y footprint is
discretised. Other families (and constraints that depend on z along a column) are sampled on
the voxel grid, one slab of x columns at a time, and kept as the same column intervals (runs
of inside voxels), so memory grows with the footprint (nx·ny), not with the volume (nx·ny·nz).
The signed field (positive inside, zero on the boundary) is built on first use for display
(slices, meshes) over the kept workspace's bounding box only. The memory a request needs is
estimated before anything is allocated (:func:`estimate_bytes`) and a request over the budget
(:mod:`pkmlab.runtime.memory`) is refused.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time

import numpy as np
from scipy import ndimage

from ..dexterity.metrics import resolve_length
from ..errors import ParameterError
from ..limits import RESOLUTION_MM
from ..mechanisms import NO_STROKE
from ..mechanisms.kernels.intervals import label_pieces
from ..poses import as_frames, matrix_to_euler
from ..runtime.memory import coarser_resolution, require
from ..runtime.time_budget import coarser_for_time, require_time, workspace_seconds
from .constraints import Constraints, check
from .field import interval_field
from .orientations import OrientationSet
from .refine import refine_columns
from .result import WorkspaceResult

log = logging.getLogger(__name__)

__all__ = ["workspace", "orientation_convergence", "estimate_bytes", "check_request", "KINDS",
           "request_cost"]

KINDS = ("constant", "reachable", "dexterous")
_CHUNK = 200_000
#: voxels evaluated per x slab on the sampled method
_SLAB = 1_000_000
#: start of the note on a mechanism singular at its nominal pose
SINGULAR_NOTE = "singular at the nominal pose"
#: interval pieces kept per column (union of orientations, sampled runs)
_K = 8


def check_request(kind: str, resolution) -> None:
    """Refuse an unknown workspace ``kind`` or a grid spacing outside
    :data:`~pkmlab.limits.RESOLUTION_MM` (one line naming the field)."""
    if kind not in KINDS:
        raise ParameterError("kind", f"one of {list(KINDS)}", kind)
    if not (isinstance(resolution, int | float) and math.isfinite(resolution)
            and RESOLUTION_MM[0] <= resolution <= RESOLUTION_MM[1]):
        raise ParameterError("resolution", f"a grid spacing in [{RESOLUTION_MM[0]:g}, "
                             f"{RESOLUTION_MM[1]:g}] mm", resolution)


def estimate_bytes(nx: int, ny: int, nz: int, M: int, columns: bool, dense: bool) -> float:
    """Peak bytes of a workspace request on an ``nx × ny`` footprint, ``nz`` z samples and
    ``M`` orientations: the ``(nx, ny, K)`` intervals with their working copies (lo, hi,
    component labels, masks), an orientation mask ``(nx, ny, M)``, the sampled slab buffers
    and, for z-dependent constraints on the column method (``dense``), the voxel field."""
    cols = nx * ny
    b = cols * _K * (2 * 8 * 3 + 8 + 8 + 1) + cols * M + cols * 64
    if not columns:
        b += 80 * _SLAB
    if dense:
        b += 4 * 4 * nx * ny * max(nz, 1)
    return float(b)


def workspace(mech, kind: str = "constant", orientations: OrientationSet | None = None,
              resolution: float = 2.5, constraints: Constraints | None = None,
              method: str = "auto", refine: bool = False) -> WorkspaceResult:
    """Compute a workspace of ``mech``.

    Args:
        mech: a registered mechanism.
        kind: ``"constant"`` (one orientation), ``"reachable"`` (at least one orientation of
            the set) or ``"dexterous"`` (every orientation of the set).
        orientations: the orientation set, relative to the nominal orientation; default the
            nominal orientation itself.
        resolution: grid spacing h in mm (x, y and the display voxels in z).
        constraints: which constraints apply (default: stroke, connected to nominal).
        method: ``"auto"`` (exact columns where available), ``"columns"`` or ``"sampled"``.
        refine: dexterous workspaces on the column method: search each leg's extremes over
            the continuous orientation set from the best samples
            (:mod:`pkmlab.workspaces.refine`) instead of trusting the samples alone.

    Returns:
        :class:`WorkspaceResult`; an empty workspace is a valid result (``result.empty``).
    """
    t0 = time.perf_counter()
    check_request(kind, resolution)
    _check_mobility(mech, kind, orientations)
    if method not in ("auto", "columns", "sampled"):
        raise ParameterError("method", "one of ['auto', 'columns', 'sampled']", method)
    cons = (constraints or Constraints()).resolved(mech)
    if cons.stroke is not True:
        # the same geometry with another actuator window (the family re-validates it)
        mech = dataclasses.replace(mech, stroke_window=cons.stroke)
    notes: list[str] = []
    if cons.kappa_max is not None:
        length = resolve_length(mech, cons.characteristic_length)
        cons = dataclasses.replace(cons, characteristic_length=length.length)
        shown = "none" if length.length is None else f"{length.length:.6g} mm"
        notes.append(f"kappa_max: L = {shown} ({length.status}): {length.reason}")
    sing = _nominal_singularity(mech)
    if sing:
        notes.append(sing)
    oset = orientations or OrientationSet.fixed()
    if kind == "constant" and oset.kind != "fixed":
        raise ParameterError("orientations", "a single fixed orientation for kind 'constant'",
                             oset.kind)
    _, Rn = as_frames(mech.nominal_pose)
    oset = oset.centred(tuple(matrix_to_euler(Rn[0])))
    R = oset.rotations()
    mode = "any" if kind == "reachable" else "all"
    h = float(resolution)
    use_columns = mech.column_method is not None and method != "sampled"
    if method == "columns" and mech.column_method is None:
        raise ParameterError("method", f"'auto' or 'sampled' for family {mech.family!r} "
                             "(it has no column kernel)", method)

    xs, ys, zb, nz, need, secs, got = _grid_cost(mech, R, mode, h, use_columns, cons)
    fit = max(coarser_resolution(h, need), coarser_for_time(h, secs, 2 if use_columns else 3))
    require("resolution", need, "a grid whose arrays", got, f"try >= {fit:g} mm")
    require_time("resolution", secs, "a grid whose evaluation is", got, f"try >= {fit:g} mm")
    timings = {}
    sampled = False
    lo = hi = field = None
    p_nom = mech.nominal_pose[:3]
    if use_columns and len(xs) and len(ys):
        t = time.perf_counter()
        lo, hi, overflow = mech.column_intervals(xs, ys, R, mode)
        timings["columns_s"] = time.perf_counter() - t
        if refine and mode == "all" and oset.kind != "fixed" and mech.column_leg is None:
            notes.append(f"refine: not available for family {mech.family!r} (set-valued "
                         "column legs); sampled orientations only")
        elif refine and mode == "all" and oset.kind != "fixed":
            t = time.perf_counter()
            before = _column_volume(lo, hi, h)
            lo, hi, changed = refine_columns(mech, xs, ys, oset, lo, hi)
            after = _column_volume(lo, hi, h)
            timings["refine_s"] = time.perf_counter() - t
            rel = 100 * (after - before) / max(before, 1e-300)
            notes.append(f"leg extremes refined over the continuous orientation set: "
                         f"{changed} columns shrank, volume {before / 1e3:.4f} -> "
                         f"{after / 1e3:.4f} cm3 ({rel:+.3f} %)")
        if cons.extra and mech.column_invariant:
            t = time.perf_counter()
            lo, hi, overflow = _column_extras(mech, xs, ys, R, mode, cons, lo, hi, overflow)
            timings["column_constraints_s"] = time.perf_counter() - t
        if overflow:
            notes.append(f"{overflow} columns needed more interval pieces than stored; "
                         "their sets are truncated")
        zs = _z_axis(lo, hi, h)
        if cons.extra and not mech.column_invariant:
            t = time.perf_counter()
            field = _voxel_extras(mech, xs, ys, zs, R, mode, cons,
                                  interval_field(xs, ys, zs, lo, hi, h), h)
            timings["voxel_constraints_s"] = time.perf_counter() - t
            lo = hi = None
    else:
        t = time.perf_counter()
        if use_columns:
            zs = np.empty(0)
        else:
            zs = np.arange(math.ceil(zb[0] / h), math.floor(zb[1] / h) + 1) * h
        lo, hi, overflow = _sampled_columns(mech, xs, ys, zs, R, mode, cons, h)
        if overflow:
            notes.append(f"{overflow} columns had more than {_K} separate runs of voxels; "
                         "their sets are truncated")
        sampled = not use_columns
        zs = _z_axis(lo, hi, h)
        timings["sampled_s"] = time.perf_counter() - t

    if lo is not None:
        # sampled runs touch when 26-connected voxels do; exact pieces within h of each other
        n_comp, keep, nominal_inside = _piece_components(lo, hi, xs, ys, p_nom,
                                                         0.0 if sampled else None)
        if cons.connected and n_comp > 1:
            lo = np.where(keep, lo, np.inf)
            hi = np.where(keep, hi, -np.inf)
        xs, ys, lo, hi = _crop(xs, ys, lo, hi)
        zs = _z_axis(lo, hi, h)
    else:
        n_comp, keep, nominal_inside = _components(field >= 0, xs, ys, zs, p_nom, h)
        if cons.connected and n_comp > 1:
            field = np.where(keep, field, np.minimum(field, -h)).astype(np.float32)
    if cons.connected and n_comp > 1:
        notes.append(f"{n_comp} connected components; kept the one "
                     f"{'containing' if nominal_inside else 'nearest to'} the nominal position")
    if sampled:
        method_used = "sampled voxels"
    elif lo is not None:
        method_used = f"columns ({mech.column_method}), exact in z"
    elif use_columns:
        method_used = "columns for the stroke, voxels for z-dependent constraints"
    else:
        method_used = "sampled voxels"
    timings["total_s"] = time.perf_counter() - t0
    return WorkspaceResult(
        mechanism=mech, kind=kind, orientations=oset, constraints=cons, resolution=h,
        xs=xs, ys=ys, zs=zs, lo=lo, hi=hi, voxel_field=field,
        method=method_used, components=n_comp, nominal_inside=nominal_inside,
        timings=timings, notes=notes)


# ---------------------------------------------------------------------------------------------


def _column_volume(lo, hi, h) -> float:
    with np.errstate(invalid="ignore"):
        return float(np.sum(np.where(lo <= hi, hi - lo, 0.0)) * h * h)


def orientation_convergence(mech, kind: str, orientations: OrientationSet,
                            resolution: float = 2.5, constraints: Constraints | None = None,
                            samples=(3, 5, 7, 9, 13, 17)) -> list[dict]:
    """Volume against orientation sampling: one row per sample count, sampled and refined.

    Each row: ``samples``, ``orientations`` (count), ``volume_mm3`` and, for dexterous
    workspaces on the column method, ``refined_volume_mm3``. Dexterous volumes fall as the
    sampling is refined (more orientations can only remove positions); the refined value is
    the limit they approach.
    """
    rows = []
    for n in samples:
        o = orientations.with_samples(int(n))
        r = workspace(mech, kind, o, resolution, constraints)
        row = {"samples": int(n), "orientations": int(len(o.parameters())),
               "volume_mm3": r.volume, "seconds": r.timings["total_s"]}
        if kind == "dexterous" and mech.column_leg is not None:
            rr = workspace(mech, kind, o, resolution, constraints, refine=True)
            row["refined_volume_mm3"] = rr.volume
        rows.append(row)
    return rows


def _grid_cost(mech, R, mode, h, use_columns, cons):
    """The grid of a request and its cost model: ``(xs, ys, z bounds, nz, bytes, seconds,
    description)``."""
    xs, ys, zb = _grid_xy(mech, R, mode, h)
    nz = int(max(0.0, zb[1] - zb[0]) / h) + 1
    need = estimate_bytes(len(xs), len(ys), nz, len(R), use_columns,
                          use_columns and bool(cons.extra) and not mech.column_invariant)
    secs = workspace_seconds(len(xs) * len(ys), len(R), len(mech.actuator_names), nz,
                             not use_columns)
    return xs, ys, zb, nz, need, secs, \
        f"{h:g} mm ({len(xs)} × {len(ys)} columns, {len(R)} orientations)"


def request_cost(mech, kind: str = "constant", orientations: OrientationSet | None = None,
                 resolution: float = 2.5, constraints: Constraints | None = None,
                 method: str = "auto", refine: bool = False) -> tuple[float, float, str, float]:
    """The cost model of :func:`workspace` with these arguments, without computing it:
    ``(bytes, seconds, description, exponent)`` — memory and time scale as
    ``resolution ** -exponent``."""
    cons = (constraints or Constraints()).resolved(mech)
    if cons.stroke is not True:
        mech = dataclasses.replace(mech, stroke_window=cons.stroke)
    oset = orientations or OrientationSet.fixed()
    _, Rn = as_frames(mech.nominal_pose)
    R = oset.centred(tuple(matrix_to_euler(Rn[0]))).rotations()
    use_columns = mech.column_method is not None and method != "sampled"
    mode = "any" if kind == "reachable" else "all"
    *_, need, secs, got = _grid_cost(mech, R, mode, float(resolution), use_columns, cons)
    return need, secs, got, 2.0 if use_columns else 3.0


def _grid_xy(mech, R, mode, h):
    b = mech.position_bounds(R)                           # (M, 2, 3)
    if mode == "all":
        lo, hi = b[:, 0].max(axis=0), b[:, 1].min(axis=0)
    else:
        lo, hi = b[:, 0].min(axis=0), b[:, 1].max(axis=0)
    if np.any(lo > hi):
        return np.empty(0), np.empty(0), (0.0, -1.0)
    xs = np.arange(math.ceil(lo[0] / h), math.floor(hi[0] / h) + 1) * h
    ys = np.arange(math.ceil(lo[1] / h), math.floor(hi[1] / h) + 1) * h
    return xs, ys, (float(lo[2]), float(hi[2]))


def _z_axis(lo, hi, h):
    finite = np.isfinite(lo) & (lo <= hi)
    if not np.any(finite):
        return np.empty(0)
    zmin, zmax = float(lo[finite].min()), float(hi[finite].max())
    return np.arange(math.floor(zmin / h), math.ceil(zmax / h) + 1) * h


def _column_extras(mech, xs, ys, R, mode, cons, lo, hi, overflow):
    """Apply z-independent constraints to whole columns (per orientation)."""
    alive = np.any(lo <= hi, axis=-1)
    ix, iy = np.nonzero(alive)
    if len(ix) == 0:
        return lo, hi, overflow
    z = np.where(lo[ix, iy, 0] <= hi[ix, iy, 0], lo[ix, iy, 0], 0.0)   # any z will do
    p = np.stack([xs[ix], ys[iy], z], axis=1)
    M = len(R)
    if mode == "all":
        ok = np.ones(len(ix), dtype=bool)
        for m in range(M):
            idx = np.nonzero(ok)[0]
            if len(idx) == 0:
                break
            ok[idx] = check(mech, p[idx], np.broadcast_to(R[m], (len(idx), 3, 3)), cons)
        lo, hi = lo.copy(), hi.copy()
        lo[ix[~ok], iy[~ok]] = np.inf
        hi[ix[~ok], iy[~ok]] = -np.inf
        return lo, hi, overflow
    allowed = np.zeros((len(xs), len(ys), M), dtype=np.bool_)
    for m in range(M):
        allowed[ix, iy, m] = check(mech, p, np.broadcast_to(R[m], (len(ix), 3, 3)), cons)
    return mech.column_intervals(xs, ys, R, "any", allowed)


def _voxel_extras(mech, xs, ys, zs, R, mode, cons, field, h):
    """Re-check occupied voxels with z-dependent constraints (families not column-invariant)."""
    occ = field >= 0
    idx = np.argwhere(occ)
    if len(idx) == 0:
        return field
    p = np.stack([xs[idx[:, 0]], ys[idx[:, 1]], zs[idx[:, 2]]], axis=1)
    lo_q, hi_q = mech.stroke
    if mode == "all":      # stroke already holds for every orientation inside the sets
        ok = np.ones(len(p), dtype=bool)
        for m in range(len(R)):
            live = np.nonzero(ok)[0]
            ok[live] = check(mech, p[live], np.broadcast_to(R[m], (len(live), 3, 3)), cons)
    else:
        ok = np.zeros(len(p), dtype=bool)
        for m in range(len(R)):
            todo = np.nonzero(~ok)[0]
            if len(todo) == 0:
                break
            Rm = np.broadcast_to(R[m], (len(todo), 3, 3))
            ik = mech.inverse((p[todo], Rm), stroke=(lo_q, hi_q))
            sel = todo[ik.valid]
            ok[sel] = check(mech, p[sel], np.broadcast_to(R[m], (len(sel), 3, 3)), cons)
    out = field.copy()
    bad = idx[~ok]
    out[bad[:, 0], bad[:, 1], bad[:, 2]] = -h
    return out


def _check_mobility(mech, kind, orientations) -> None:
    """A mechanism without a free rotation has constant-orientation workspaces only: refuse
    the other kinds and any orientation set, naming the field."""
    mob = mech.mobility
    what = f"family {mech.family!r} with {mob.name} mobility ({', '.join(mob.coordinates)})"
    if not {"x", "y", "z"} <= set(mob.coordinates):
        raise ParameterError("mechanism", "a mechanism with x, y and z free (the x-y × z "
                             "column grid); planar mechanisms: pkmlab.workspaces.planar, "
                             "dependent coordinates (3-PRS): pkmlab.workspaces.tripod", what)
    if mob.rotations:
        return
    if kind != "constant":
        raise ParameterError("kind", "'constant' for a mechanism without a free rotation "
                             "(its orientation is fixed)", f"{kind!r} ({what})")
    if orientations is not None and orientations.kind != "fixed":
        raise ParameterError("orientations", "the nominal orientation for a mechanism without "
                             "a free rotation", f"{orientations.kind!r} ({what})")


def _nominal_singularity(mech) -> str | None:
    """A note when the Jacobian is rank-deficient at the nominal pose (architecturally
    singular designs: platform equal to the base, collinear joints), where the stroke-feasible
    volume says nothing about what the mechanism can hold or control. The rotational columns
    (the mobility's) are scaled by ``mech.scale``; a translational J is taken as it is."""
    from ..dexterity.metrics import CharacteristicLength, is_singular, rotational_columns

    X = mech.nominal_pose
    J = mech.jacobian(X)
    L = mech.scale
    if not mech.mobility.is_spatial:
        L = CharacteristicLength(L, math.nan, False, False, "given",
                                 rotational=rotational_columns(mech.mobility))
    if not bool(is_singular(J, L)[0]):
        return None
    return (f"{SINGULAR_NOTE} (the Jacobian is rank-deficient there): the mechanism cannot "
            "resist or control every load and motion; the volume counts stroke only")


def _crop(xs, ys, lo, hi):
    """The columns that hold a piece, and their bounding footprint (the display field and the
    stored arrays then cover the workspace, not the search box)."""
    alive = np.any(lo <= hi, axis=-1)
    if not alive.any():
        return xs, ys, lo, hi
    ix, iy = np.nonzero(alive.any(axis=1))[0], np.nonzero(alive.any(axis=0))[0]
    sx, sy = slice(ix[0], ix[-1] + 1), slice(iy[0], iy[-1] + 1)
    lo, hi = lo[sx, sy], hi[sx, sy]
    # pieces first in each column (a dropped component may leave a hole in the slots)
    order = np.argsort(~(lo <= hi), axis=-1, kind="stable")
    used = max(1, int(np.max(np.sum(lo <= hi, axis=-1))))
    order = order[..., :used]
    return (xs[sx], ys[sy], np.ascontiguousarray(np.take_along_axis(lo, order, -1)),
            np.ascontiguousarray(np.take_along_axis(hi, order, -1)))


def _sampled_columns(mech, xs, ys, zs, R, mode, cons, h):
    """The sampled voxel grid as column intervals, one x slab at a time: each run of inside
    voxels ``k0..k1`` becomes ``[z_k0 - h/2, z_k1 + h/2]`` (its length is the voxel count)."""
    nx, ny, nz = len(xs), len(ys), len(zs)
    lo = np.full((nx, ny, _K), np.inf)
    hi = np.full((nx, ny, _K), -np.inf)
    overflow = 0
    if nx * ny * nz == 0:
        return lo, hi, overflow
    per = max(1, _SLAB // (ny * nz))
    for i0 in range(0, nx, per):
        f = _sampled_field(mech, xs[i0:i0 + per], ys, zs, R, mode, cons, h)
        overflow += _runs(f >= 0, zs, h, lo[i0:i0 + per], hi[i0:i0 + per])
    return lo, hi, overflow


def _runs(occ, zs, h, lo, hi) -> int:
    """Write the runs of ``occ (n, ny, nz)`` along z into ``lo, hi (n, ny, K)``; returns the
    number of columns with more than K runs."""
    n, ny, nz = occ.shape
    d = np.diff(np.pad(occ.reshape(n * ny, nz), ((0, 0), (1, 1))).astype(np.int8), axis=1)
    c0, k0 = np.nonzero(d == 1)
    _, k1 = np.nonzero(d == -1)               # end (exclusive), same order as the starts
    if len(c0) == 0:
        return 0
    first = np.searchsorted(c0, c0, side="left")
    rank = np.arange(len(c0)) - first
    ok = rank < lo.shape[-1]
    lo2, hi2 = lo.reshape(n * ny, -1), hi.reshape(n * ny, -1)
    lo2[c0[ok], rank[ok]] = zs[k0[ok]] - 0.5 * h
    hi2[c0[ok], rank[ok]] = zs[k1[ok] - 1] + 0.5 * h
    return int(len(np.unique(c0[~ok])))


def _sampled_field(mech, xs, ys, zs, R, mode, cons, h):
    """Actuator-stroke margin (mm) over the voxel grid, min (all) or max (any) over R."""
    shape = (len(xs), len(ys), len(zs))
    if 0 in shape:
        return np.full(shape, -h, dtype=np.float32)
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    p = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    lo_q, hi_q = mech.stroke
    f = np.full(len(p), np.inf if mode == "all" else -np.inf)
    live = np.arange(len(p))
    for m in range(len(R)):
        if mode == "all":
            live = live[f[live] >= 0]
            if len(live) == 0:
                break
        margin = np.empty(len(live))
        for s in range(0, len(live), _CHUNK):
            sl = live[s:s + _CHUNK]
            Rm = np.ascontiguousarray(np.broadcast_to(R[m], (len(sl), 3, 3)))
            ik = mech.inverse((p[sl], Rm), stroke=NO_STROKE)
            with np.errstate(invalid="ignore"):
                mg = np.min(np.minimum(ik.q - lo_q, hi_q - ik.q), axis=1)
            # raw IK (no stroke): any other status is a geometric failure or another mode
            mg = np.where(ik.valid & ~np.isnan(mg), mg, -np.inf)
            if cons.extra:
                good = np.nonzero(mg >= 0)[0]
                okx = check(mech, p[sl[good]], Rm[good], cons)
                mg[good[~okx]] = -h
            margin[s:s + len(sl)] = mg
        f[live] = np.minimum(f[live], margin) if mode == "all" else np.maximum(f[live], margin)
    return np.clip(f, -h, h).reshape(shape).astype(np.float32)


def _piece_components(lo, hi, xs, ys, p_nom, tol=None):
    """Components of column pieces; keep mask ``(nx, ny, K)`` of the nominal one."""
    h = xs[1] - xs[0] if len(xs) > 1 else 1.0
    labels, n = label_pieces(lo, hi, h if tol is None else tol)
    if n == 0:
        return 0, labels >= 0, False
    ix, iy, k = np.nonzero(labels >= 0)
    a, b = lo[ix, iy, k], hi[ix, iy, k]
    dz = np.maximum(np.maximum(a - p_nom[2], p_nom[2] - b), 0.0)
    d = np.hypot(np.hypot(xs[ix] - p_nom[0], ys[iy] - p_nom[1]), dz)
    j = int(np.argmin(d))
    inside = bool(d[j] <= 0.5 * h * math.sqrt(2))
    return n, labels == labels[ix[j], iy[j], k[j]], inside


def _components(occ, xs, ys, zs, p_nom, h):
    """Label 26-connected components; pick the nominal one (or the one nearest to it)."""
    if not occ.any():
        return 0, occ, False
    labels, n = ndimage.label(occ, structure=np.ones((3, 3, 3), dtype=bool))
    ijk = np.round((np.asarray(p_nom) - [xs[0], ys[0], zs[0]]) / h).astype(int)
    inside = bool(np.all(ijk >= 0) and np.all(ijk < occ.shape) and occ[tuple(ijk)])
    if inside:
        lab = labels[tuple(ijk)]
    else:
        pts = np.argwhere(occ)
        d = np.linalg.norm(pts - ijk, axis=1)
        lab = labels[tuple(pts[np.argmin(d)])]
    return n, labels == lab, inside
