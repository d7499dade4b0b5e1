"""Exported designs differ: the knee, the extremes, then the designs farthest from those
(issue "A report a designer opens in the browser", item 2)."""

from __future__ import annotations

import numpy as np
import pytest

from pkmlab.study.selection import non_dominated, select_designs


def _front(seed: int = 0) -> np.ndarray:
    """A convex 2-objective front (minimised) whose first-objective end is crowded."""
    rng = np.random.default_rng(seed)
    t = np.sort(np.concatenate([rng.uniform(0.0, 0.08, 30), rng.uniform(0.08, 1.0, 10)]))
    return np.stack([t, (1 - np.sqrt(t)) ** 2], axis=1)


def _spread(F, idx) -> float:
    Z = (F - F.min(0)) / (F.max(0) - F.min(0))
    P = Z[idx]
    d = np.linalg.norm(P[:, None] - P[None], axis=-1)
    return float(d[np.triu_indices(len(idx), 1)].min())


def test_chosen_designs_spread_across_the_front_not_three_neighbours():
    F = _front()
    assert non_dominated(F).all()
    chosen = select_designs(F, 3, ["a", "b"])
    idx = [c.index for c in chosen]
    assert len(set(idx)) == 3
    assert chosen[0].why.startswith("knee")
    assert {int(np.argmin(F[:, 0])), int(np.argmin(F[:, 1]))} <= set(idx)
    neighbours = list(np.argsort(F[:, 0])[:3])          # the old export: best by objective 1
    assert _spread(F, idx) > 0.3 > 10 * _spread(F, neighbours)
    assert [c.why for c in chosen[1:]] == ["best a", "best b"]
    # more designs: each new one is the farthest from those already chosen
    five = select_designs(F, 5, ["a", "b"])
    assert [c.index for c in five[:3]] == idx and five[3].why.startswith("spread")
    assert _spread(F, [c.index for c in five]) > 0.1


def test_knee_is_the_closest_to_the_ideal_point():
    F = np.array([[0.0, 1.0], [0.2, 0.2], [0.5, 0.1], [1.0, 0.0]])
    assert select_designs(F, 1)[0].index == 1


@pytest.mark.parametrize("k", [0, 1, 4, 10])
def test_small_fronts_and_budgets(k):
    F = np.array([[3.0, 1.0], [2.0, 2.0], [1.0, 3.0]])
    chosen = select_designs(F, k)
    assert len(chosen) == min(k, 3)
    assert len({c.index for c in chosen}) == len(chosen)
    assert select_designs(np.empty((0, 2)), k) == []


def test_one_objective_and_duplicates():
    F = np.array([[2.0], [1.0], [1.0], [3.0]])
    chosen = select_designs(F, 2, ["volume"])
    assert chosen[0].index in (1, 2) and chosen[0].why == "best volume"
    D = np.array([[1.0, 1.0], [1.0, 1.0], [0.0, 2.0]])
    assert non_dominated(D).all()                       # duplicates are all kept
    assert len({c.index for c in select_designs(D, 3)}) == 3


def test_non_dominated_matches_brute_force():
    rng = np.random.default_rng(4)
    F = rng.integers(0, 6, (80, 3)).astype(float)
    brute = np.array([not np.any(np.all(F <= f, axis=1) & np.any(F < f, axis=1)) for f in F])
    np.testing.assert_array_equal(non_dominated(F), brute)
