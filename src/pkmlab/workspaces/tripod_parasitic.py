"""Guaranteed upper bounds of the parasitic excursions of a mechanism with dependent
coordinates (the 3-PRS tripod): the largest ``|x|``, ``|y|`` (mm) and ``|θz|`` (rad) over its
feasible set within the tilt box (issue 24).

Every feasible point lies in a box of the volume bracket (:class:`.tripod.TripodBracket`,
inner or undecided), and the dependent coordinates depend on ``(θx, θy)`` only, so the largest
excursion is at most the largest interval enclosure
(:func:`~pkmlab.mechanisms.families.prs3_boxes.parasitic_enclosure`) over the boxes' ``(θx,
θy)`` rectangles. Rectangles whose enclosure exceeds a known lower bound of the excursion
(``floor``: the largest excursion sampled at feasible points) by more than the tolerance are
split in four and enclosed again, level by level, so the bound tightens where it matters.
Rectangles proved to hold no solution of the constraint are dropped. The bound is guaranteed
for the boxes it is given: it can exceed the true maximum where undecided boxes reach beyond
the feasible set (the bracket's resolution).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

__all__ = ["ParasiticBounds", "parasitic_bounds"]

#: the coordinates bounded, in order
NAMES = ("x", "y", "theta_z")


@dataclass(frozen=True)
class ParasiticBounds:
    """Upper bounds ``(3,)`` of ``|x|``, ``|y|`` (mm) and ``|θz|`` (rad) over the feasible set
    (module docstring); ``converged`` when every rectangle left is within the tolerance of
    ``floor``; ``rectangles`` enclosed in all; ``seconds`` wall time."""

    upper: np.ndarray
    floor: np.ndarray
    converged: bool
    levels: int
    rectangles: int
    seconds: float

    @property
    def empty(self) -> bool:
        return not np.any(np.isfinite(self.upper))


def _magnitudes(mech, lo, hi):
    from ..mechanisms.families.prs3_boxes import parasitic_enclosure

    never, x, y, g = parasitic_enclosure(mech, lo, hi)
    mag = np.stack([np.maximum(np.abs(v.lo), np.abs(v.hi)) for v in (x, y, g)], axis=1)
    mag[:, 2] = np.minimum(mag[:, 2], math.pi)        # wrapping never increases |θz|
    mag[never] = -np.inf
    return mag


def parasitic_bounds(mech, boxes: np.ndarray, floor, *, rtol: float = 0.01,
                     atol=(1e-3, 1e-3, 1e-5), max_levels: int = 12,
                     max_rectangles: int = 200_000) -> ParasiticBounds:
    """Upper bounds of the parasitic excursions over the union of ``boxes`` ``(n, 2, 3)``
    (``[lo, hi]`` of ``(z, θx, θy)``, every feasible point in one of them), refined until each
    is within ``rtol·floor + atol`` of ``floor`` ``(3,)`` (a lower bound of each excursion:
    the largest sampled at feasible points), ``max_levels`` splits or ``max_rectangles``
    rectangles in a level (module docstring)."""
    t0 = time.perf_counter()
    floor = np.asarray(floor, dtype=float)
    tol = np.asarray(atol, dtype=float) + rtol * np.abs(floor)
    B = np.asarray(boxes, dtype=float).reshape(-1, 2, 3)
    if not len(B):
        return ParasiticBounds(np.full(3, -np.inf), floor, True, 0, 0,
                               time.perf_counter() - t0)
    rect = np.unique(np.concatenate([B[:, 0, 1:], B[:, 1, 1:]], axis=1), axis=0)
    lo, hi = rect[:, :2], rect[:, 2:]
    settled = np.full(3, -np.inf)
    count, level, converged = 0, 0, False
    while True:
        mag = _magnitudes(mech, lo, hi)
        count += len(lo)
        open_ = np.any(mag > floor + tol, axis=1)
        settled = np.maximum(settled, mag[~open_].max(axis=0, initial=-np.inf))
        lo, hi, mag = lo[open_], hi[open_], mag[open_]
        if not len(lo):
            converged = True
            break
        if level == max_levels or 4 * len(lo) > max_rectangles:
            settled = np.maximum(settled, mag.max(axis=0))
            break
        level += 1
        mid = 0.5 * (lo + hi)
        lo = np.concatenate([lo, np.column_stack([mid[:, 0], lo[:, 1]]),
                             np.column_stack([lo[:, 0], mid[:, 1]]), mid])
        hi = np.concatenate([mid, np.column_stack([hi[:, 0], mid[:, 1]]),
                             np.column_stack([mid[:, 0], hi[:, 1]]), hi])
    return ParasiticBounds(settled, floor, converged, level, count, time.perf_counter() - t0)
