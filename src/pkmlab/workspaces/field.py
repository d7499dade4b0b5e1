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
    used = int(np.max(np.sum(lo <= hi, axis=-1), initial=0))
    z = zs[None, None, :]
    for k in range(used):
        a = lo[..., k, None]
        b = hi[..., k, None]
        with np.errstate(invalid="ignore"):
            piece = np.minimum(z - a, b - z)
        piece = np.where(a <= b, piece, -np.inf)
        np.maximum(f, np.clip(piece, -h, h), out=f)
    return f
