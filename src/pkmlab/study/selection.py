"""Which Pareto designs to export: a few that differ, spread across the front.

Three neighbours on the front teach a designer nothing the first did not. :func:`select_designs`
picks, in objective space normalised over the front (each objective to [0, 1], 0 best):

1. the *knee*: the design closest to the ideal point (every objective at its best), the best
   compromise;
2. the *extremes*: the best design for each objective;
3. then, one at a time, the design farthest from every design already chosen (ties broken by
   pymoo's crowding distance), until ``k`` are chosen.

The non-dominated sorting itself is pymoo's (:func:`non_dominated`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["non_dominated", "select_designs", "Selection"]


def non_dominated(F: np.ndarray) -> np.ndarray:
    """``(n,)`` True for the rows of ``F (n, m)`` (minimised) no other row dominates (pymoo's
    non-dominated sorting; duplicated rows are all kept)."""
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    F = np.asarray(F, dtype=float)
    keep = np.zeros(len(F), dtype=bool)
    if len(F):
        keep[NonDominatedSorting().do(F, only_non_dominated_front=True)] = True
    return keep


@dataclass(frozen=True)
class Selection:
    """``index`` into the front, and ``why`` it was chosen (shown in the report)."""

    index: int
    why: str


def _crowding(F: np.ndarray) -> np.ndarray:
    from pymoo.operators.survival.rank_and_crowding.metrics import calc_crowding_distance

    if len(F) <= 2:
        return np.full(len(F), np.inf)
    return calc_crowding_distance(F)


def select_designs(F: np.ndarray, k: int, names: list[str] | None = None) -> list[Selection]:
    """Choose ``k`` rows of the front ``F (n, m)`` (minimised) that differ (module docstring).

    Args:
        F: the front's objective values, every objective to be minimised.
        k: how many to choose (all of them when the front is no larger).
        names: objective names, for the reasons (default ``objective 1`` …).
    """
    F = np.asarray(F, dtype=float)
    n = len(F)
    if n == 0 or k <= 0:
        return []
    m = F.shape[1]
    names = names or [f"objective {j + 1}" for j in range(m)]
    lo, hi = F.min(axis=0), F.max(axis=0)
    span = np.where(hi > lo, hi - lo, 1.0)
    Z = (F - lo) / span
    chosen: list[Selection] = []
    taken: set[int] = set()

    def take(i: int, why: str) -> None:
        if i not in taken and len(chosen) < k:
            taken.add(i)
            chosen.append(Selection(int(i), why))

    dist_ideal = np.linalg.norm(Z, axis=1)
    if m > 1:
        take(int(np.argmin(dist_ideal)), "knee: closest to the ideal point")
    for j in range(m):
        # the best for objective j; among ties, the one best overall
        best = np.flatnonzero(F[:, j] == lo[j])
        take(int(best[np.argmin(dist_ideal[best])]), f"best {names[j]}")
    crowd = _crowding(Z)
    while len(chosen) < min(k, n):
        rest = np.array([i for i in range(n) if i not in taken])
        sel = np.array([c.index for c in chosen])
        d = np.min(np.linalg.norm(Z[rest, None, :] - Z[None, sel, :], axis=-1), axis=1)
        far = rest[np.isclose(d, d.max())]
        i = int(far[np.argmax(crowd[far])])
        take(i, "spread: farthest from the designs above")
    return chosen
