"""The column end points of a workspace, for :func:`pkmlab.dexterity.worst_case`.

On the exact column method a :class:`~pkmlab.workspaces.WorkspaceResult` knows its z sets
exactly: ``lo[i, j, k] … hi[i, j, k]`` per (x, y) column and slot. Voxel centres lie up to
``h`` inside those ends, so a singular set *on* the boundary (e.g. the Hexaglide's rail plane,
where every link is horizontal) is never sampled and no pair of samples spans it. The end
points close that gap along z: :func:`column_ends` lists them with, for each, the nearest
occupied voxel centre of the same slot (the segment between the two lies in the slot, so a
sign change of ``det J`` between them puts a singular pose in the workspace), or the slot's
other end when the slot holds no voxel centre.

The end of a slot is where a leg reaches its window, its reach (a serial singularity) or the
edge of its working mode; at that point the inverse kinematics may fail by rounding. An end
counts as feasible at an orientation when the inverse kinematics is valid a hair inside
(:data:`NUDGE`), the Jacobian itself is evaluated at the exact end.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ColumnEnds", "column_ends", "NUDGE"]

#: how far inside the slot (mm) an end's feasibility is tested (the end itself may fail by
#: rounding); at most half the slot
NUDGE = 1e-6


@dataclass(frozen=True)
class ColumnEnds:
    """End points of the column slots.

    Attributes:
        pos: ``(E, 3)`` end points (mm).
        probe: ``(E, 3)`` the points, :data:`NUDGE` inside their slot, where feasibility is
            tested.
        voxel: ``(E,)`` index (into the occupied voxels in ``np.argwhere`` order) of the
            nearest occupied voxel centre in the same slot, or -1.
        other: ``(E,)`` index of the slot's other end when the slot holds no voxel centre
            and has positive length, else -1 (set on the lower end only: one pair per slot).
    """

    pos: np.ndarray
    probe: np.ndarray
    voxel: np.ndarray
    other: np.ndarray

    def __len__(self) -> int:
        return len(self.pos)


def column_ends(result, idx: np.ndarray, shared: bool) -> ColumnEnds | None:
    """End points of ``result``'s column slots (``None`` on the sampled method).

    ``idx`` are the occupied voxel indices (:func:`pkmlab.dexterity.aggregate._voxels`). With
    ``shared`` (the Jacobian does not depend on z) the ends of a column that holds a voxel have
    that column's Jacobian and are left out; the other columns' ends are kept.
    """
    if not result.exact_columns:
        return None
    lo, hi = result.lo, result.hi
    i, j, k = np.nonzero(lo <= hi)
    if shared and len(i):
        has = np.zeros(lo.shape[:2], dtype=bool)
        has[idx[:, 0], idx[:, 1]] = True
        keep = ~has[i, j]
        i, j, k = i[keep], j[keep], k[keep]
    n = len(i)
    z0, z1 = lo[i, j, k], hi[i, j, k]
    xs, ys, zs = result.xs, result.ys, result.zs
    nz, h = len(zs), result.resolution
    lut = np.full(result.occupancy.shape, -1, dtype=np.int64)
    lut[idx[:, 0], idx[:, 1], idx[:, 2]] = np.arange(len(idx))

    def nearest(t):
        """The occupied voxel of the column at grid index round-off ``t``, if in the slot."""
        if not nz:
            return np.full(n, -1, dtype=np.int64)
        kz = t.astype(np.int64)
        ok = (kz >= 0) & (kz < nz)
        kz = np.clip(kz, 0, nz - 1)
        ok &= (zs[kz] >= z0) & (zs[kz] <= z1)
        return np.where(ok, lut[i, j, kz], -1)

    first = nearest(np.ceil((z0 - zs[0]) / h)) if nz else nearest(None)
    last = nearest(np.floor((z1 - zs[0]) / h)) if nz else nearest(None)
    xy = np.stack([xs[i], ys[j]], axis=1)
    pos = np.concatenate([np.column_stack([xy, z0]), np.column_stack([xy, z1])])
    d = np.minimum(NUDGE, 0.5 * (z1 - z0))
    probe = pos.copy()
    probe[:n, 2] += d
    probe[n:, 2] -= d
    voxel = np.concatenate([first, last])
    lone = (first < 0) & (z1 > z0)                 # no voxel centre in the slot
    other = np.full(2 * n, -1, dtype=np.int64)
    other[:n] = np.where(lone, np.arange(n) + n, -1)
    return ColumnEnds(pos, probe, voxel, other)
