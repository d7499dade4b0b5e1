"""Cost model of the analyses over a whole workspace (issue 27): :func:`kappa_grid` keeps
``(V, M)`` arrays (κ, validity and their working copies, about 34 B per voxel × orientation
sample) and :func:`worst_case` ``(U, M)`` flags (2 B per unit × orientation); both are
checked against the memory budget once the workspace is known, before they allocate, and
refused with a coarser resolution or fewer orientation samples that would fit."""

from __future__ import annotations

from ..runtime.memory import coarser_resolution, require

__all__ = ["GRID_BYTES_PER_SAMPLE", "WORST_BYTES_PER_SAMPLE", "grid_bytes", "require_grid"]

#: bytes per (voxel, orientation) of kappa_grid and the statistics built on it
GRID_BYTES_PER_SAMPLE = 34.0
#: bytes per (unit, orientation) of worst_case's feasibility and det-sign flags
WORST_BYTES_PER_SAMPLE = 2.0


def grid_bytes(result, per_sample: float = GRID_BYTES_PER_SAMPLE) -> tuple[float, int, int]:
    """``(bytes, voxels, orientations)`` of an analysis over ``result``'s voxels × its
    orientation samples at ``per_sample`` bytes each."""
    V = int(result.occupancy.sum()) if not result.empty else 0
    M = len(result.orientations.rotations())
    return float(V) * M * per_sample, V, M


def require_grid(result, field: str = "resolution",
                 per_sample: float = GRID_BYTES_PER_SAMPLE) -> None:
    """Refuse (:class:`~pkmlab.runtime.memory.BudgetError` on ``field``) an analysis over
    ``result`` whose arrays would not fit the memory budget; the hint is a grid spacing at
    which they would (memory scales as ``h**-3``)."""
    need, V, M = grid_bytes(result, per_sample)
    h = float(result.resolution)
    fit = coarser_resolution(h, need, 3.0)
    require(field, need, "a grid whose voxel × orientation arrays", f"{h:g} mm ({V} voxels × "
            f"{M} orientations)", f"try >= {fit:g} mm or fewer orientation samples")
