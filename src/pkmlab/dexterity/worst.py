"""Worst case of κ and of the all-direction force over a whole workspace grid.

:func:`worst_case` evaluates *every* occupied voxel centre of a
:class:`~pkmlab.workspaces.WorkspaceResult` × *every* sample orientation of its set (the poses of
:func:`pkmlab.dexterity.kappa_grid` and :mod:`pkmlab.dexterity.maps`), not a random subset:

* ``worst_kappa`` — the largest κ(J_h) (:func:`pkmlab.dexterity.condition_number`) over those
  poses and the column ends (below), ``inf`` when a singular pose is found (below);
* ``min_force`` — the smallest force held in every direction
  (:func:`pkmlab.dexterity.max_force_all_directions`), 0 N when a singular pose is found;
* ``singular`` — a singular pose lies in the workspace or on its boundary, with a certificate:
  a sample is singular by pkmlab's one rule (:func:`pkmlab.dexterity.is_singular`), **or** a
  column end is, **or** ``det J`` has opposite signs at two neighbouring samples (voxels sharing
  a face, at the same orientation; neighbouring orientation samples — the same voxel, one set
  coordinate one step apart; a column end and the nearest voxel centre of its slot). ``det J``
  is continuous wherever every leg has a real solution, so by the intermediate value theorem
  it vanishes — the pose is singular — somewhere on the path between two such samples (a
  serial singularity, where a row of J grows without bound, is singular by the same rule).
  This catches the parallel singularity surfaces that a grid crosses but never lands on
  exactly, where the sampled κ is large but finite;
* ``singularity`` — ``"singular"`` (the certificate above) or ``"not excluded"``: no
  certificate was found, and absence is not proved (no bound on ``det J`` between samples is
  computed), so a workspace is never called singularity-free.

The boundary: on the exact column method the workspace knows its z sets exactly, and the voxel
centres lie up to ``h`` inside their ends. A singular set *on* the boundary — the Hexaglide's
rail plane or the 6-UPS base plane, where every leg is horizontal at the edge of the working
mode, or a slider's reach limit (the link perpendicular to its rail, a serial singularity) — is
then never sampled and no pair of samples spans it: before the column ends were evaluated, the
Hexaglide with its rails raised 3.3 mm was "not singular" with a worst κ of 236 at 10 mm and
1,100 at 5 mm (doubling with every halving of the grid, unbounded in truth). Every slot's two
end points (:mod:`pkmlab.dexterity._boundary`) are therefore evaluated at every orientation
where they are feasible (inverse kinematics valid 1e-6 mm inside the slot): their κ joins the
maximum, a singular end is a certificate (a singular pose on the closure of the workspace: the
supremum of κ is infinite), and so is a sign change of ``det J`` between an end and the
nearest voxel centre of its slot. For families whose Jacobian does not depend on z the ends of
a column that holds a voxel carry that column's Jacobian and are skipped. Not covered: the
lateral (x, y) boundary between the outermost columns and the true edge, and the sampled
method (no exact ends) — a singular set there is only "not excluded".

What lies between samples: ``worst_kappa`` and ``min_force`` otherwise are extremes *of the
sampled grid and the column ends* — lower (upper) bounds on the supremum of κ (infimum of the
force) over the continuous workspace × orientation set. κ and the force capability are
continuous away from singularities, so the extremes converge to them as the resolution
``h → 0`` and the orientation samples per angle ``n → ∞`` (typically like ``h`` and ``1/n``;
compare two resolutions to see how far). A singular set between samples that ``det J`` touches
without changing sign (tangency) or crosses twice between two samples is not detected: hence
``"not excluded"``.

Speed: for each pose one LU factorisation gives ``det J``, ``J⁻¹`` (the force capability) and a
certified upper bound on κ (:func:`pkmlab.dexterity._linalg.sweep_bounds`, numba); the exact κ
(singular values) is computed only for the poses whose bound reaches the largest exact κ found,
in decreasing order of the bound. Families whose Jacobian does not depend on z at fixed (x, y)
and orientation (``column_invariant``, the 6-PSU) are evaluated once per (x, y) column.
Feasibility comes from the inverse kinematics, per unit (voxel or column) and orientation: a
column counts at an orientation when one of its voxels is feasible (its middle voxel is tried
first, the others only where that fails). Only the feasible pairs count: all of them in a
dexterous or constant workspace except voxel centres on its boundary to rounding (e.g. the
6-UPS base plane, the edge of its working mode), and in a reachable workspace only the
orientations reachable at each voxel.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..poses import POSE_SIZE, matrix_to_euler
from ._boundary import column_ends
from ._cells import CellPlan, cells_available
from ._fused import fused_available, fused_sweep
from ._linalg import KAPPA_BRACKET, KAPPA_ROUND, kappa_upper
from .aggregate import _CHUNK, _ik_valid, _units, _voxels, orientation_batches
from .force import _fmax, max_force_all_directions
from .metrics import KAPPA_SINGULAR, CharacteristicLength, condition_number, resolve_length
from .sweep import sweep_bounds

log = logging.getLogger(__name__)

__all__ = ["WorstCase", "worst_case", "MAX_POSES"]

#: Default cap on the number of (voxel or column) × orientation poses :func:`worst_case`
#: evaluates (about 1.5 µs each, one byte of memory each).
MAX_POSES = 50_000_000

_EXACT_BATCH = 256
#: use the fused Jacobian + bounds kernel (:mod:`._fused`) where the family has one; the
#: unfused path (NumPy Jacobians, then :func:`sweep_bounds`) gives the same values bit for bit
#: and is kept as the reference of the tests and benchmarks
FUSED = True
#: prune the per-pose pass by certified bounds over cells of neighbouring units
#: (:mod:`._cells`) where the family has a box Jacobian; False: every sample is evaluated
CELLS = True
_ROUND = KAPPA_ROUND   # relative allowance for rounding in the κ bound of sweep_bounds
_SINGULAR_BOUND = KAPPA_SINGULAR / KAPPA_BRACKET / (1 + _ROUND) ** 2   # may be singular


@dataclass(frozen=True)
class WorstCase:
    """Worst κ and smallest all-direction force over a workspace grid × orientation set.

    Attributes:
        worst_kappa: largest κ(J_h) over every feasible (voxel, orientation) sample and column
            end; ``inf`` when ``singular``; NaN only when ``status`` is not ``"ok"``
            (``reason`` says why). A lower bound on the supremum otherwise.
        min_force: smallest force (N) held in every direction over those poses; 0.0 when
            ``singular``; NaN only when ``status`` is not ``"ok"``.
        singular: a singular pose lies in the workspace or on its boundary, certified (module
            docstring). ``False`` does not mean singularity-free: see ``singularity``.
        singularity: ``"singular"`` or ``"not excluded"`` (no certificate found; absence is not
            proved).
        reason: why ``singular`` (which test fired, where), or why ``status`` is not ``"ok"``;
            "" otherwise.
        grid_max_kappa: largest κ at a voxel (or column) sample, column ends left out (``inf``
            only if a sample itself is singular).
        grid_min_force: smallest force (N) at a sample (0 only at a singular sample).
        worst_kappa_pose: ``(6,)`` the sample or column end with the largest κ (mm, rad, Z-Y-X
            Euler).
        min_force_pose: ``(6,)`` the sample or column end with the smallest force.
        singular_samples: samples singular by :func:`pkmlab.dexterity.is_singular`.
        sign_changes: neighbouring sample pairs with opposite signs of ``det J`` (column ends
            not counted: ``boundary_sign_changes``).
        sign_change_poses: ``(2, 6)`` the first such pair (mm, rad), or ``None``: a singular
            pose lies on the path between them.
        pairs_checked: neighbouring sample pairs compared.
        voxels, orientations: the grid: occupied voxels × sample orientations.
        poses: Jacobians evaluated ((voxels, or (x, y) columns) and column ends, ×
            orientations).
        feasible: feasible (unit, orientation) pairs: units are the voxels, or the (x, y)
            columns of a column-invariant family, and a pair is feasible when the inverse
            kinematics is valid at one of the unit's voxels.
        exact: poses whose κ was computed exactly (the others were bounded below the maximum).
        L: characteristic length used (mm); ``length``: with its status and reason.
        force_limit: ``(n_actuators,)`` actuator force limits (N).
        method: one line: what was maximised over, and the singularity tests.
        status: ``"ok"``, ``"empty"`` (nothing to evaluate) or ``"too large"`` (more poses
            than ``max_poses``; nothing evaluated).
        seconds: wall time.
        boundary_points: column end points (two per slot of the column method; 0 on the
            sampled method); ``boundary_feasible``: feasible (end, orientation) pairs.
        boundary_max_kappa, boundary_min_force: κ and force extremes over the feasible column
            ends (NaN when there are none).
        boundary_singular: (end, orientation) poses singular by the one rule.
        boundary_sign_changes: sign changes of ``det J`` between a column end and the nearest
            voxel centre of its slot (or its other end), or between neighbouring orientation
            samples at a column end.
    """

    worst_kappa: float
    min_force: float
    singular: bool
    reason: str
    grid_max_kappa: float
    grid_min_force: float
    worst_kappa_pose: np.ndarray
    min_force_pose: np.ndarray
    singular_samples: int
    sign_changes: int
    pairs_checked: int
    voxels: int
    orientations: int
    poses: int
    feasible: int
    exact: int
    L: float
    force_limit: np.ndarray
    method: str
    status: str = "ok"
    seconds: float = 0.0
    length: CharacteristicLength | None = field(default=None, repr=False)
    sign_change_poses: np.ndarray | None = None
    singularity: str = "not excluded"
    boundary_points: int = 0
    boundary_feasible: int = 0
    boundary_max_kappa: float = math.nan
    boundary_min_force: float = math.nan
    boundary_singular: int = 0
    boundary_sign_changes: int = 0

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def as_dict(self) -> dict:
        """JSON-ready summary (non-finite numbers as ``None``, poses in mm and deg)."""
        def fin(v):
            return float(v) if math.isfinite(v) else None

        def pose(X):
            X = np.asarray(X, dtype=float)
            if not np.all(np.isfinite(X)):
                return None
            return {"position_mm": X[:3].tolist(), "euler_zyx_deg": np.degrees(X[3:]).tolist()}

        return {
            "status": self.status, "worst_kappa": fin(self.worst_kappa),
            "min_force_N": fin(self.min_force), "singular": bool(self.singular),
            "reason": self.reason, "grid_max_kappa": fin(self.grid_max_kappa),
            "grid_min_force_N": fin(self.grid_min_force),
            "worst_kappa_pose": pose(self.worst_kappa_pose),
            "min_force_pose": pose(self.min_force_pose),
            "singular_samples": self.singular_samples, "sign_changes": self.sign_changes,
            "pairs_checked": self.pairs_checked, "voxels": self.voxels,
            "orientations": self.orientations, "poses": self.poses, "feasible": self.feasible,
            "exact_kappa_evaluations": self.exact, "force_limit_N": self.force_limit.tolist(),
            "characteristic_length": (self.length.as_dict() if self.length is not None
                                      else {"length_mm": self.L}),
            "sign_change_poses": (None if self.sign_change_poses is None else
                                  [pose(X) for X in self.sign_change_poses]),
            "singularity": self.singularity, "boundary_points": self.boundary_points,
            "boundary_feasible": self.boundary_feasible,
            "boundary_max_kappa": fin(self.boundary_max_kappa),
            "boundary_min_force_N": fin(self.boundary_min_force),
            "boundary_singular": self.boundary_singular,
            "boundary_sign_changes": self.boundary_sign_changes,
            "method": self.method, "seconds": self.seconds,
        }


def _nan_result(status, reason, V, M, L, length, fmax, t0, method) -> WorstCase:
    nan = float("nan")
    none = np.full(POSE_SIZE, nan)
    return WorstCase(nan, nan, False, reason, nan, nan, none, none.copy(), 0, 0, 0, V, M, 0, 0,
                     0, L, fmax, method, status, time.perf_counter() - t0, length)


def _unit_feasibility(mech, pos, Rs, voxel_unit, U) -> np.ndarray:
    """``(U, M)`` bool: some voxel of the unit is feasible at the orientation (inverse
    kinematics valid). Each unit's middle voxel is tried first at every orientation; only where
    it fails are the unit's other voxels tried, so a column that holds the whole set costs one
    pose per orientation instead of one per voxel (the result is the same)."""
    M = len(Rs)
    counts = np.bincount(voxel_unit, minlength=U)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    rep = starts + counts // 2
    feas = np.zeros((U, M), dtype=bool)
    step = max(1, _CHUNK // U)
    for m0 in range(0, M, step):
        Rm = Rs[m0:m0 + step]
        k = len(Rm)
        feas[:, m0:m0 + k] = _ik_valid(mech, np.tile(pos[rep], (k, 1)),
                                       np.repeat(Rm, U, axis=0)).reshape(k, U).T
    miss = np.argwhere(~feas & (counts > 1)[:, None])          # (unit, orientation)
    if not len(miss):
        return feas
    n = counts[miss[:, 0]] - 1                                  # the other voxels of each
    ends = np.cumsum(n)
    first = 0
    while first < len(miss):                                    # batches of about _CHUNK poses
        last = int(np.searchsorted(ends, ends[first] - n[first] + _CHUNK, side="right"))
        last = max(last, first + 1)
        u, m, nb = miss[first:last, 0], miss[first:last, 1], n[first:last]
        off = np.repeat(np.cumsum(nb) - nb, nb)
        j = np.arange(int(nb.sum())) - off                      # 0 .. n-1 within each pair
        vox = np.repeat(starts[u], nb) + j
        vox += vox >= np.repeat(rep[u], nb)                     # skip the middle voxel
        ok = _ik_valid(mech, pos[vox], Rs[np.repeat(m, nb)])
        feas[u, m] = np.logical_or.reduceat(ok, np.cumsum(nb) - nb)
        first = last
    return feas


def _spatial_pairs(result, idx, voxel_unit, shared) -> np.ndarray:
    """``(P, 2)`` unit pairs of face-neighbouring occupied voxels (distinct units only)."""
    shape = result.occupancy.shape
    lut = np.full(shape, -1, dtype=np.int64)
    lut[idx[:, 0], idx[:, 1], idx[:, 2]] = np.arange(len(idx))
    out = []
    for ax in range(2 if shared else 3):          # J does not depend on z: no z pairs
        inside = idx[:, ax] + 1 < shape[ax]
        a = np.flatnonzero(inside)
        nb = idx[a].copy()
        nb[:, ax] += 1
        b = lut[nb[:, 0], nb[:, 1], nb[:, 2]]
        keep = b >= 0
        out.append(np.stack([voxel_unit[a[keep]], voxel_unit[b[keep]]], axis=1))
    pairs = np.concatenate(out) if out else np.empty((0, 2), dtype=np.int64)
    if shared and len(pairs):
        n = int(pairs.max()) + 1                       # unique rows through one int64 key
        key = np.unique(pairs[:, 0].astype(np.int64) * n + pairs[:, 1])
        pairs = np.stack([key // n, key % n], axis=1)
    return pairs


def _orientation_pairs(oset) -> np.ndarray:
    """``(Q, 2)`` sample pairs one step apart in one set coordinate, the others equal."""
    P = np.round(oset.parameters(), 12)
    out = []
    for c in range(3):
        others = [k for k in range(3) if k != c]
        order = np.lexsort((P[:, c], P[:, others[1]], P[:, others[0]]))
        a, b = order[:-1], order[1:]
        same = np.all(P[a][:, others] == P[b][:, others], axis=1) & (P[a, c] != P[b, c])
        out.append(np.stack([a[same], b[same]], axis=1))
    return np.concatenate(out) if out else np.empty((0, 2), dtype=np.int64)


def _pose(p, R) -> np.ndarray:
    return np.concatenate([p, matrix_to_euler(R[None])[0]])


def worst_case(mech, result, L: float | CharacteristicLength | None = None,
               force_limit=150.0, *, max_poses: int = MAX_POSES) -> WorstCase:
    """Worst κ, smallest all-direction force and any singularity over a whole workspace.

    Every occupied voxel centre and column end × every sample orientation of ``result`` is
    evaluated (module docstring): the values are extremes of those poses, and ``singular`` also
    detects singular poses *between* neighbouring samples, and between the column ends and the
    samples, through sign changes of ``det J``; without such a certificate a singular pose is
    ``"not excluded"`` (``singularity``), never ruled out.

    Args:
        mech: the mechanism of ``result``: its inverse kinematics decides feasibility, so pass
            ``result.mechanism`` when the request overrode the stroke window.
        result: a :class:`pkmlab.workspaces.WorkspaceResult`.
        L: characteristic length (mm) for κ; default :func:`pkmlab.dexterity.resolve_length`
            (Angeles'), recorded with its status in ``length``.
        force_limit: actuator force limit(s) in N, scalar or one per actuator.
        max_poses: refuse (``status="too large"``, nothing evaluated) above this many
            Jacobian evaluations.

    Returns:
        :class:`WorstCase`. Never raises for a numerical reason.
    """
    t0 = time.perf_counter()
    length = resolve_length(mech, L)
    L = length.length
    fmax = _fmax(force_limit, mech.n_actuators)
    idx, pos = _voxels(result)
    Rs = result.orientations.rotations()
    V, M = len(pos), len(Rs)
    unit_pos, voxel_unit, shared = _units(mech, idx, pos)
    U = len(unit_pos)
    where = (f"{V:,} voxels × {M:,} orientations" + (f" ({U:,} (x, y) columns: J does not "
                                                     "depend on z)" if shared else ""))
    if V == 0 or M == 0:
        return _nan_result("empty", "the workspace is empty: nothing to evaluate", V, M, L,
                           length, fmax, t0, f"max over {where}")
    ends = column_ends(result, idx, shared)
    E = 0 if ends is None else len(ends)
    if (U + E) * M > max_poses:
        reason = (f"({U:,} + {E:,} column ends) × {M:,} = {(U + E) * M:,} poses exceed "
                  f"max_poses = {max_poses:,}: use a coarser resolution or fewer orientation "
                  "samples, or raise max_poses")
        log.warning("worst_case: %s", reason)
        return _nan_result("too large", reason, V, M, L, length, fmax, t0, f"max over {where}")

    feas = _unit_feasibility(mech, pos, Rs, voxel_unit, U)
    n_feasible = int(feas.sum())
    if n_feasible < U * M:
        log.debug("worst_case: %d of %d (unit, orientation) pairs infeasible",
                  U * M - n_feasible, U * M)
    end_pos = np.empty((0, 3)) if ends is None else ends.pos
    feas_end = np.zeros((E, M), dtype=bool)
    for m0, n, p, Rr in (orientation_batches(ends.probe, Rs) if E else ()):
        feas_end[:, m0:m0 + n] = _ik_valid(mech, p, Rr).reshape(n, E).T

    vox = _sweep(mech, unit_pos, Rs, feas, L, fmax, result.resolution)
    bnd = _sweep(mech, end_pos, Rs, feas_end, L, fmax, result.resolution)
    # exact κ where the bound reaches the maximum (decreasing bound, stop once below it)
    kmax, k_arg, exact, n_sing = _exact_max(mech, unit_pos, Rs, vox.cand, vox.up, L)
    bmax, b_arg, b_exact, b_sing = _exact_max(mech, end_pos, Rs, bnd.cand, bnd.up, L)

    # sign changes of det J between neighbours: voxels (or columns) and orientation samples,
    # and each column end with the nearest voxel centre of its slot (or the slot's other end)
    allpos = np.concatenate([unit_pos, end_pos])
    s = np.concatenate([vox.sign, bnd.sign])
    spatial = _spatial_pairs(result, idx, voxel_unit, shared)
    if E:
        e = np.arange(E)
        with_voxel = ends.voxel >= 0
        alone = ends.other >= 0
        spatial = np.concatenate([
            spatial, np.stack([U + e[with_voxel], voxel_unit[ends.voxel[with_voxel]]], axis=1),
            np.stack([U + e[alone], U + ends.other[alone]], axis=1)])
    changes = b_changes = n_pairs = 0
    example = ""
    example_poses = None
    if len(spatial):
        prod = s[spatial[:, 0]].astype(np.int16) * s[spatial[:, 1]]
        n_pairs += int(np.sum((s[spatial[:, 0]] != 0) & (s[spatial[:, 1]] != 0)))
        hit = prod < 0
        at_end = spatial[:, 0] >= U
        changes += int(hit[~at_end].sum())
        b_changes += int(hit[at_end].sum())
        if hit.any():
            q, m = np.argwhere(hit)[0]
            a, b = allpos[spatial[q, 0]], allpos[spatial[q, 1]]
            eu = np.degrees(matrix_to_euler(Rs[m][None])[0])
            example = (f"between positions {np.round(a, 3).tolist()}"
                       + (" (a column end)" if spatial[q, 0] >= U else "")
                       + f" and {np.round(b, 3).tolist()} mm at orientation "
                       f"{np.round(eu, 3).tolist()} deg (Z-Y-X Euler)")
            example_poses = np.stack([_pose(a, Rs[m]), _pose(b, Rs[m])])
    opairs = _orientation_pairs(result.orientations)
    if len(opairs):
        sa, sb = s[:, opairs[:, 0]], s[:, opairs[:, 1]]
        n_pairs += int(np.sum((sa != 0) & (sb != 0)))
        hit = sa.astype(np.int16) * sb < 0
        changes += int(hit[:U].sum())
        b_changes += int(hit[U:].sum())
        if hit.any() and not example:
            u, q = np.argwhere(hit)[0]
            eu = np.degrees(matrix_to_euler(Rs[list(opairs[q])]))
            example = (f"at position {np.round(allpos[u], 3).tolist()} mm"
                       + (" (a column end)" if u >= U else "") + " between orientations "
                       f"{np.round(eu[0], 3).tolist()} and {np.round(eu[1], 3).tolist()} deg "
                       "(Z-Y-X Euler)")
            example_poses = np.stack([_pose(allpos[u], Rs[opairs[q, 0]]),
                                      _pose(allpos[u], Rs[opairs[q, 1]])])

    singular = n_sing > 0 or changes > 0 or b_sing > 0 or b_changes > 0
    reasons = []
    if n_sing:
        reasons.append(f"{n_sing:,} sample(s) singular (κ >= {KAPPA_SINGULAR:.0e} or J not "
                       "finite)")
    if b_sing:
        reasons.append(f"{b_sing:,} column end pose(s) singular (κ >= {KAPPA_SINGULAR:.0e} "
                       "or J not finite): a singular pose on the workspace's boundary")
    if changes or b_changes:
        reasons.append(f"det J changes sign between {changes + b_changes:,} pair(s) of "
                       f"neighbouring samples or column ends, first {example}: a singular "
                       "pose lies between them")
    kpose = _pose(unit_pos[k_arg[0]], Rs[k_arg[1]]) if k_arg else np.full(POSE_SIZE, np.nan)
    if not k_arg:                                     # no feasible sample (cannot happen)
        kmax = math.nan
    f_exact, fpose = _force_at(mech, unit_pos, Rs, vox.f_arg, fmax, L)
    worst, wpose, fworst, fwpose = kmax, kpose, f_exact, fpose
    if b_arg is not None and bmax > kmax:
        worst, wpose = bmax, _pose(end_pos[b_arg[0]], Rs[b_arg[1]])
    bforce, bfpose = _force_at(mech, end_pos, Rs, bnd.f_arg, fmax, L)
    if bnd.f_arg is not None and bforce < f_exact:
        fworst, fwpose = bforce, bfpose
    unit = "column" if shared else "voxel"
    n_end = int(feas_end.sum())
    method = (f"max over {where} = {U * M:,} poses, {n_feasible:,} of {U * M:,} ({unit}, "
              f"orientation) pairs feasible, and {E:,} column end points × {M:,} orientations "
              f"({n_end:,} feasible); exact κ at {exact + b_exact:,} poses (the others bounded "
              f"below the maximum); singular: κ = inf at a sample or a column end, or det J "
              f"changes sign across {n_pairs:,} neighbouring pairs")
    res = WorstCase(
        worst_kappa=math.inf if singular else worst, min_force=0.0 if singular else fworst,
        singular=singular, reason="; ".join(reasons), grid_max_kappa=kmax,
        grid_min_force=f_exact, worst_kappa_pose=wpose, min_force_pose=fwpose,
        singular_samples=n_sing, sign_changes=changes, pairs_checked=n_pairs, voxels=V,
        orientations=M, poses=(U + E) * M, feasible=n_feasible, exact=exact + b_exact, L=L,
        force_limit=fmax, method=method, status="ok", seconds=time.perf_counter() - t0,
        length=length, sign_change_poses=example_poses,
        singularity="singular" if singular else "not excluded",
        boundary_points=E, boundary_feasible=n_end,
        boundary_max_kappa=bmax if b_arg is not None else math.nan,
        boundary_min_force=bforce if bnd.f_arg is not None else math.nan,
        boundary_singular=b_sing, boundary_sign_changes=b_changes)
    log.debug("worst_case: κ %.6g, force %.6g N, singular %s, %.3f s (%s)", res.worst_kappa,
              res.min_force, singular, res.seconds, method)
    return res


def _force_at(mech, unit_pos, Rs, arg, fmax, L):
    """The library's own all-direction force (same rule, same L) at the pose ``arg`` =
    ``(unit, orientation)`` with its pose; ``(0.0, NaN pose)`` when ``arg`` is None (every
    pose has a non-finite J); 0 where the force is not finite."""
    if arg is None:
        return 0.0, np.full(POSE_SIZE, np.nan)
    u, m = arg
    f = float(max_force_all_directions(mech.jacobian((unit_pos[u][None], Rs[m][None])), fmax,
                                       L, mech.mobility)[0])
    return (f if math.isfinite(f) else 0.0), _pose(unit_pos[u], Rs[m])


@dataclass(frozen=True)
class _Sweep:
    sign: np.ndarray      # (U, M) int8 sign of det J; 0: singular or infeasible
    cand: np.ndarray      # flat unit · M + orientation of the poses whose κ may be the maximum
    up: np.ndarray        # their certified upper bounds on κ
    f_min: float          # smallest force bound over the feasible poses
    f_arg: tuple | None   # its (unit, orientation)


def _sweep(mech, unit_pos, Rs, feas, L, fmax, h=None) -> _Sweep:
    """One LU per feasible (unit, orientation) pose (:func:`sweep_bounds`): det J's sign, the
    candidates for the largest κ (bound at or above the largest certified lower bound, or
    possibly singular) and the smallest force. With a grid step ``h`` and :data:`CELLS`, the
    samples that certified cell bounds exclude from both extremes are skipped (:mod:`._cells`:
    the same extremes, arguments, signs)."""
    U, M = len(unit_pos), len(Rs)
    sign = np.zeros((U, M), dtype=np.int8)
    cand_idx, cand_up = [np.empty(0, dtype=np.int64)], [np.empty(0)]
    lower = -math.inf                                 # largest certified lower bound on κ
    f_min, f_arg = math.inf, None
    step = max(1, _CHUNK // max(U, 1))
    fused = FUSED and fused_available(mech)
    plan = None
    if fused and CELLS and h and U and cells_available(mech):
        plan = CellPlan(mech, unit_pos, Rs, feas, L, fmax, h, lambda u, m: float(
            condition_number(mech.jacobian((unit_pos[[u]], Rs[[m]])), L)[0]))
    for m0 in range(0, M if U else 0, step):
        Rm = Rs[m0:m0 + step]
        k = len(Rm)
        fe = feas[:, m0:m0 + k]
        if plan is not None:
            kup, force, det = plan.chunk(m0, k)
        elif fused:       # Jacobian and bounds in one numba loop, infeasible poses skipped
            kup, force, det = fused_sweep(mech, unit_pos, Rm, fe, L, fmax)
        else:
            J = mech.jacobian((np.tile(unit_pos, (k, 1)), np.repeat(Rm, U, axis=0)))
            kup = np.empty(k * U)
            force = np.empty(k * U)
            det = np.empty(k * U)
            sweep_bounds(np.ascontiguousarray(J), L, fmax, kup, force, det, mech.mobility)
            kup, force, det = (a.reshape(k, U).T for a in (kup, force, det))
            kup = np.where(fe, kup, -np.inf)
            force = np.where(fe, force, np.inf)
            det = np.where(fe, det, 0.0)
        up = kappa_upper(kup)
        fin = np.isfinite(up)
        if fin.any():
            lower = max(lower, float(up[fin].max()) / KAPPA_BRACKET / (1 + _ROUND) ** 2)
        sel = np.argwhere(up >= min(lower, _SINGULAR_BOUND))
        cand_idx.append(sel[:, 0] * M + m0 + sel[:, 1])
        cand_up.append(up[sel[:, 0], sel[:, 1]])
        fc = np.where(np.isnan(force), np.inf, force)  # NaN: J not finite (singular sample)
        j = int(np.argmin(fc))
        if fc.flat[j] < f_min:
            f_min, f_arg = float(fc.flat[j]), (j // k, m0 + j % k)
        sign[:, m0:m0 + k] = np.sign(np.nan_to_num(det, nan=0.0)).astype(np.int8)
    cand, up = np.concatenate(cand_idx), np.concatenate(cand_up)
    keep = up >= min(lower, _SINGULAR_BOUND)
    return _Sweep(sign, cand[keep], up[keep], f_min, f_arg)


def _exact_max(mech, unit_pos, Rs, cand, up, L):
    """Largest exact κ over the candidate poses ``cand`` (flat ``unit · M + orientation``)
    with bounds ``up``.

    The candidates are the poses whose bound reaches the largest certified lower bound (any
    other pose is certainly below the maximum) or :data:`_SINGULAR_BOUND`. They are evaluated
    in decreasing order of the bound until the next bound is below the best exact κ — except
    that every candidate that may be singular is evaluated, so singular samples are all counted.

    Returns ``(kmax, (unit, orientation), exact evaluations, singular samples)``.
    """
    M = len(Rs)
    if len(cand):
        # the exact κ of the largest bound is a lower bound on the maximum: a pose whose bound
        # is below it (and that cannot be singular) is never the maximum, so it is dropped
        # before the sort (the sort of every candidate dominated the worst case's time)
        u0, m0 = divmod(int(cand[int(np.argmax(up))]), M)
        k0 = float(condition_number(mech.jacobian((unit_pos[[u0]], Rs[[m0]])), L)[0])
        if math.isfinite(k0):
            sel = (up >= k0) | (up >= _SINGULAR_BOUND)
            cand, up = cand[sel], up[sel]
    order = np.argsort(-up, kind="stable")
    cand, up = cand[order], up[order]
    best, arg, exact, n_sing = -math.inf, None, 0, 0
    for b0 in range(0, len(cand), _EXACT_BATCH):
        if up[b0] < best and up[b0] < _SINGULAR_BOUND:
            break
        c = cand[b0:b0 + _EXACT_BATCH]
        u, m = c // M, c % M
        kap = condition_number(mech.jacobian((unit_pos[u], Rs[m])), L)
        exact += len(c)
        n_sing += int(np.sum(~np.isfinite(kap)))
        j = int(np.argmax(kap))
        if kap[j] > best:
            best, arg = float(kap[j]), (int(u[j]), int(m[j]))
    return best, arg, exact, n_sing
