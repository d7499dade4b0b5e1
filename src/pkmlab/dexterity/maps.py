"""Per-voxel metric maps over a workspace, and their export as coloured meshes.

A map reduces a metric over the orientation set at every occupied voxel to its worst case
(the value a designer can count on at that position): the largest κ, the smallest LCI, the
smallest isotropic force capability, the smallest translational stiffness eigenvalue.
Unreachable (voxel, orientation) pairs count as the worst possible value. κ, "singular" and
the default characteristic length are those of :mod:`pkmlab.dexterity.metrics`; the extreme of
a map over the whole workspace, with singularities between samples, is
:func:`pkmlab.dexterity.worst_case`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from . import _fused_exact
from ._linalg import kappa_upper
from .aggregate import _CHUNK, _ik_valid, _units, _voxels, orientation_batches
from .force import max_force_all_directions
from .metrics import CharacteristicLength, condition_number, resolve_length
from .stiffness import stiffness
from .sweep import sweep_bounds

__all__ = ["METRICS", "MetricMap", "metric_map", "drawn_voxels", "mesh_colours",
           "vertex_values"]

#: metric → (label, unit, worse is larger)
METRICS = {
    "kappa": ("worst κ (homogenised condition number)", "", True),
    "lci": ("worst LCI = 1/κ", "", False),
    "force": ("smallest force held in every direction", "N", False),
    "stiffness": ("smallest translational stiffness eigenvalue", "N/mm", False),
}


@dataclass(frozen=True)
class MetricMap:
    """Worst value of a metric over the orientation set at every occupied voxel.

    Attributes:
        metric: key of :data:`METRICS`.
        values: ``(V,)`` per occupied voxel (``inf``/0 where an orientation is unreachable).
        index: ``(V, 3)`` voxel indices into the workspace grid.
        positions: ``(V, 3)`` voxel centres (mm).
        grid: ``(nx, ny, nz)`` values on the workspace grid, NaN outside.
        length: the characteristic length used (κ, LCI, and the singular rule of the force),
            with its status and reason.
    """

    metric: str
    values: np.ndarray
    index: np.ndarray
    positions: np.ndarray
    grid: np.ndarray
    length: CharacteristicLength | None = None

    @property
    def label(self) -> str:
        name, unit, _ = METRICS[self.metric]
        return f"{name} ({unit})" if unit else name


def drawn_voxels(result, levels) -> np.ndarray:
    """``(nx, ny, nz)`` bool: the occupied voxels a picture shows, those of the voxel layers
    nearest to the slice heights ``levels`` (mm; the layers :func:`.slice_figure` colours)
    and those on the workspace's surface (occupied voxels with an empty face neighbour, the
    ones nearest to a boundary mesh's vertices). A map needs no other voxel to be drawn."""
    from scipy import ndimage

    occ = np.asarray(result.occupancy, dtype=bool)
    mask = occ & ~ndimage.binary_erosion(occ, border_value=0)
    if len(result.zs):
        k = np.clip(np.rint((np.asarray(levels, dtype=float) - result.zs[0])
                            / result.resolution).astype(int), 0, len(result.zs) - 1)
        mask[:, :, k] |= occ[:, :, k]
    return mask


def metric_map(mech, result, metric: str = "kappa",
               L: float | CharacteristicLength | None = None, f_max=150.0,
               k=1.0e4, progress=None, where: np.ndarray | None = None) -> MetricMap:
    """Worst-case ``metric`` over ``result``'s orientation set at every occupied voxel.

    Args:
        mech, result: the mechanism and its :class:`~pkmlab.WorkspaceResult`.
        metric: ``"kappa"``, ``"lci"``, ``"force"`` or ``"stiffness"``.
        L: characteristic length (mm) for κ, LCI and the singular rule; default
            :func:`pkmlab.dexterity.resolve_length` (Angeles').
        f_max: actuator force limit(s) in N for ``"force"``.
        k: actuator stiffness(es) in N/mm for ``"stiffness"``.
        progress: optional ``progress(fraction_done)``, called after each batch of
            orientations (a map over a large workspace takes tens of seconds).
        where: optional ``(nx, ny, nz)`` bool: evaluate only these occupied voxels (e.g.
            :func:`drawn_voxels`); the others stay NaN in ``grid`` and out of ``values``.
    """
    if metric not in METRICS:
        raise ParameterError("metric", f"one of {list(METRICS)}", metric)
    length = resolve_length(mech, L)
    L = length.length
    idx, pos = _voxels(result)
    if where is not None:
        keep = np.asarray(where, dtype=bool)[idx[:, 0], idx[:, 1], idx[:, 2]]
        idx, pos = idx[keep], pos[keep]
    R = result.orientations.rotations()
    V = len(pos)
    # J (and so the metric) is evaluated once per (x, y) column for column-invariant families
    unit_pos, voxel_unit, _ = _units(mech, idx, pos)
    U = len(unit_pos)
    worse_is_larger = METRICS[metric][2]
    bad = np.inf if worse_is_larger else 0.0          # an unreachable pose
    worst = np.full(V, -np.inf if worse_is_larger else np.inf)
    # κ and LCI: the exact largest κ of every unit over the whole set; a voxel takes it where
    # every orientation is reachable there (else the worst possible value)
    kmax = _unit_kappa_max(mech, unit_pos, R, L) if metric in ("kappa", "lci") else None
    for m0, n, p, Rr in orientation_batches(pos, R):
        if kmax is not None:
            val = np.broadcast_to(kmax if metric == "kappa" else 1.0 / kmax, (n, U))
        else:
            J = mech.jacobian((np.tile(unit_pos, (n, 1)), np.repeat(R[m0:m0 + n], U, axis=0)))
            val = _unit_metric(metric, J, L, f_max, k, mech.mobility)
        val = np.where(_ik_valid(mech, p, Rr).reshape(n, V),
                       np.reshape(val, (n, U))[:, voxel_unit], bad)
        worst = np.maximum(worst, val.max(axis=0)) if worse_is_larger else \
            np.minimum(worst, val.min(axis=0))
        if progress is not None:
            progress((m0 + n) / len(R))
    grid = np.full(result.occupancy.shape, np.nan)
    grid[idx[:, 0], idx[:, 1], idx[:, 2]] = worst
    return MetricMap(metric, worst, idx, pos, grid, length)


def _unit_metric(metric: str, J, L, f_max, k, mobility=None) -> np.ndarray:
    """The force or stiffness metric of every Jacobian (0 where J is not finite)."""
    if metric == "force":
        return np.nan_to_num(max_force_all_directions(J, f_max, L, mobility))
    ok = np.all(np.isfinite(J), axis=(1, 2))
    val = np.zeros(len(J))
    if ok.any():
        val[ok] = stiffness(J[ok], k, mobility).translational_min
    return val


def _unit_kappa_max(mech, unit_pos, R, L) -> np.ndarray:
    """``(U,)`` the largest κ of every unit over the orientations ``R``, exact.

    Every pose gets the certified bound of :func:`._linalg.sweep_bounds` (one LU per pose,
    made safe against rounding by :func:`._linalg.kappa_upper`); each unit's exact κ at its
    largest bound is a lower bound on its maximum, so only the poses whose bound reaches it
    need the exact κ (singular values): on the demo designs about a fifth of them. A family
    with a numba per-pose Jacobian runs the same algorithm with the Jacobian fused into each
    pass (:func:`._fused_exact.fused_kappa_max`: the same values, bit for bit)."""
    if _fused_exact.serves(mech):
        return _fused_exact.fused_kappa_max(mech, unit_pos, R, L)
    U, M = len(unit_pos), len(R)
    if U == 0 or M == 0:
        return np.full(U, -np.inf)
    up = np.empty((M, U))
    ones = np.ones(mech.n_actuators)
    step = max(1, _CHUNK // max(U, 1))
    for m0 in range(0, M, step):
        Rm = R[m0:m0 + step]
        n = len(Rm)
        J = np.ascontiguousarray(mech.jacobian((np.tile(unit_pos, (n, 1)),
                                                np.repeat(Rm, U, axis=0))))
        kup, force, det = (np.empty(n * U) for _ in range(3))
        sweep_bounds(J, L, ones, kup, force, det, mech.mobility)
        up[m0:m0 + n] = kup.reshape(n, U)
    up = kappa_upper(up)
    kmax = condition_number(mech.jacobian((unit_pos, R[np.argmax(up, axis=0)])), L)
    cand = np.argwhere(up >= kmax)                   # (orientation, unit)
    for b0 in range(0, len(cand), _CHUNK):
        c = cand[b0:b0 + _CHUNK]
        np.maximum.at(kmax, c[:, 1], condition_number(mech.jacobian((unit_pos[c[:, 1]],
                                                                        R[c[:, 0]])), L))
    return kmax


def vertex_values(mesh, mmap: MetricMap) -> np.ndarray:
    """``(n_vertices,)`` the map's value at each vertex of ``mesh``: its nearest voxel's."""
    from scipy.spatial import cKDTree

    if len(mmap.positions) == 0:
        return np.full(len(mesh.vertices), np.nan)
    _, near = cKDTree(mmap.positions).query(mesh.vertices)
    return mmap.values.astype(float)[near]


def mesh_colours(mesh, mmap: MetricMap, vmin=None, vmax=None, cmap: str = "viridis"):
    """``(n_vertices, 4)`` uint8 RGBA colours: each vertex takes its nearest voxel's value;
    the colour range is the slices' (1st-99th percentiles when outliers stretch it)."""
    import matplotlib

    vals = mmap.values.astype(float)
    finite = np.isfinite(vals)
    if not finite.any():
        return np.tile([128, 128, 128, 255], (len(mesh.vertices), 1)).astype(np.uint8)
    # the slices' colour range: clipped to the 1st-99th percentiles when a few near-singular
    # voxels would stretch it (so κ of the bulk is not one colour)
    from ..workspaces.output.plots import _colour_range

    plo, phi, _ = _colour_range(vals)
    lo = plo if vmin is None else vmin
    hi = phi if vmax is None else vmax
    v = vertex_values(mesh, mmap)
    t = np.clip((np.where(np.isfinite(v), v, hi) - lo) / max(hi - lo, 1e-300), 0, 1)
    rgba = matplotlib.colormaps[cmap](t)
    return (rgba * 255).round().astype(np.uint8)
