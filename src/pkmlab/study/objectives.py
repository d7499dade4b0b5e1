"""A study's objectives and constraints as matrices (what the optimisers, the Pareto front and
the tolerance ladder compare)."""

from __future__ import annotations

import math

import numpy as np

from .definition import PENALTY, Study

__all__ = ["objective_matrix", "feasible"]


def _value(record: dict, metric: str):
    v = record["metrics"].get(metric) if record["status"] == "ok" else None
    return None if v is None or not math.isfinite(v) else float(v)


def objective_matrix(study: Study, records: list[dict]) -> tuple[np.ndarray, np.ndarray]:
    """``F (n, n_obj)`` to minimise and ``G (n, n_con)`` that must be ``<= 0``."""
    n_con = sum((c.min is not None) + (c.max is not None) for c in study.constraints)
    F = np.full((len(records), len(study.objectives)), PENALTY)
    G = np.full((len(records), n_con), PENALTY)
    for i, r in enumerate(records):
        for j, o in enumerate(study.objectives):
            v = _value(r, o.metric)
            if v is not None:
                F[i, j] = v if o.sense == "minimize" else -v
        j = 0
        for c in study.constraints:
            v = _value(r, c.metric)
            for bound in ("min", "max"):
                b = getattr(c, bound)
                if b is not None:
                    if v is not None:
                        G[i, j] = (b - v) if bound == "min" else (v - b)
                    j += 1
    return F, G


def feasible(study: Study, records: list[dict]) -> np.ndarray:
    """``(n,)`` evaluated, every objective defined, every constraint met."""
    F, G = objective_matrix(study, records)
    ok = np.array([r["status"] == "ok" for r in records], dtype=bool)
    return ok & np.all(F < PENALTY, axis=1) & np.all(G <= 0, axis=1)
