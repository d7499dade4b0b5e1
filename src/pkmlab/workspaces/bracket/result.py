"""The result type of a guaranteed volume bracket (:mod:`.bracket` for column families,
:mod:`.bracket_cells` for families bounded on position × orientation cells)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["VolumeBracket"]


@dataclass(frozen=True, eq=False)
class VolumeBracket:
    """A guaranteed volume bracket (mm³) and how it was reached.

    Attributes:
        lower, upper: the bracket (mm³): the intersection of every step's bracket (each
            holds; a new x-y level restarts the orientation refinement, so the last step is not
            always the tightest).
        target: relative width asked for (``upper - lower <= target·upper``).
        stop_reason: ``"converged"``, ``"budget: seconds"``, ``"budget: evaluations"``,
            ``"budget: cells"`` (the next x-y level would pass ``max_cells``; a split that
            would pass it halves the x-y cells instead) or ``"empty"``.
        history: one dict per refinement step (level, cell size h, orientation cells, lower,
            upper, seconds, evaluations).
        resolution: the x-y cell size of the last level (mm).
        evaluations: leg-bound evaluations spent.
        seconds: wall time of the call, set-up included.
        setup_seconds: the set-up before the budget's clock starts (loading or compiling
            the kernels, the legs' reach; 0 for the cell bracket, which has none).
        notes: remarks (connectivity, nominal position).
        cells: the last level's column centres ``(n, 2)``; ``inner``/``outer``: its sets as
            ``(column index, lo, hi)`` piece arrays, connectivity applied. These are the
            per-cell (first order in x-y) sets: ``inner`` lies inside the workspace and the
            workspace inside ``outer``; the x-y second-order volume bounds (constant,
            dexterous) are tighter than their volumes and are not stored as sets.
        boxes: for the cell bracket (:mod:`.bracket_cells`), the last step's cubes ``(centres
            (n, 3), half-edges (n,), inner (n,) bool)``, connectivity not applied: the inner
            cubes lie inside the stroke-feasible set, and it lies inside all of them
            (``cells``/``inner``/``outer`` are then None).
    """

    lower: float
    upper: float
    target: float
    stop_reason: str
    history: list
    resolution: float
    evaluations: int
    seconds: float
    notes: list = field(default_factory=list)
    cells: np.ndarray | None = None
    inner: tuple | None = None
    outer: tuple | None = None
    boxes: tuple | None = None
    setup_seconds: float = 0.0

    @property
    def estimate(self) -> float:
        """Midpoint of the bracket (mm³); it is within ``width / 2`` of the true volume."""
        return 0.5 * (self.lower + self.upper)

    @property
    def width(self) -> float:
        return self.upper - self.lower

    @property
    def relative_width(self) -> float:
        return self.width / self.upper if self.upper > 0 else 0.0

    def contains(self, points, which: str = "outer") -> np.ndarray:
        """``(N,)`` bool: points in the final inner or outer set (closed cells)."""
        P = np.asarray(points, float).reshape(-1, 3)
        if self.boxes is not None:
            from scipy.spatial import cKDTree  # lazy: 0.25 s at import

            C, hb, inner = self.boxes
            sel = inner if which == "inner" else np.ones(len(hb), bool)
            out = np.zeros(len(P), dtype=bool)
            for hh in np.unique(hb[sel]):
                d, _ = cKDTree(C[sel & (hb == hh)]).query(P, p=np.inf,
                                                          distance_upper_bound=hh * (1 + 1e-12))
                out |= np.isfinite(d)
            return out
        col, lo, hi = self.inner if which == "inner" else self.outer
        out = np.zeros(len(P), dtype=bool)
        h = self.resolution
        for c in np.unique(col):
            cx, cy = self.cells[c]
            sel = (np.abs(P[:, 0] - cx) <= h / 2) & (np.abs(P[:, 1] - cy) <= h / 2)
            for a, b in zip(lo[col == c], hi[col == c], strict=True):
                out |= sel & (P[:, 2] >= a) & (P[:, 2] <= b)
        return out

    def describe(self) -> dict:
        """Plain-dict summary (mm³ and cm³) for JSON."""
        return {"lower_mm3": self.lower, "upper_mm3": self.upper,
                "estimate_mm3": self.estimate, "lower_cm3": self.lower / 1e3,
                "upper_cm3": self.upper / 1e3, "estimate_cm3": self.estimate / 1e3,
                "relative_width": self.relative_width, "target": self.target,
                "stop_reason": self.stop_reason, "final_resolution_mm": self.resolution,
                "evaluations": self.evaluations, "seconds": self.seconds,
                "setup_seconds": self.setup_seconds,
                "history": list(self.history), "notes": list(self.notes)}
