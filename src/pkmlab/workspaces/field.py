"""The exact column sets as a clipped signed-distance field on the voxel grid (for meshing,
slices and voxel queries)."""

from __future__ import annotations

import numpy as np

__all__ = ["interval_field"]


def interval_field(xs, ys, zs, lo, hi, h):
    """Signed z distance to the column sets, clipped to [-h, h] (positive inside)."""
    f = np.full((len(xs), len(ys), len(zs)), -h, dtype=np.float32)
    if f.size == 0:
        return f
    valid = lo <= hi
    used = int(np.max(np.nonzero(valid.any(axis=(0, 1)))[0], initial=-1)) + 1
    z = zs[None, None, :].astype(np.float32)
    # x slabs of about a million voxels: the temporaries stay small whatever the grid
    per = max(1, 1_000_000 // max(1, len(ys) * len(zs)))
    for i0 in range(0, len(xs), per):
        s = slice(i0, i0 + per)
        for k in range(used):
            a = np.where(valid[s, :, k], lo[s, :, k], np.inf).astype(np.float32)[..., None]
            b = np.where(valid[s, :, k], hi[s, :, k], -np.inf).astype(np.float32)[..., None]
            with np.errstate(invalid="ignore"):
                piece = np.minimum(z - a, b - z)
            np.maximum(f[s], np.clip(piece, -h, h), out=f[s])
    return f
