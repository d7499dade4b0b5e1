"""Drive a design study: optimiser → runner → store, resumable and reproducible."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np

from .. import __version__
from ..errors import ParameterError
from .evaluate import candidate_mapping, evaluate_candidate
from .optimisers import OPTIMISERS, PENALTY, DesignSpace
from .store import Store, candidate_key, fingerprint

log = logging.getLogger(__name__)

__all__ = ["run_study", "objective_matrix", "feasible", "expected_evaluations"]

BASELINE = {"__baseline__": True}


def _value(record: dict, metric: str):
    v = record["metrics"].get(metric) if record["status"] == "ok" else None
    return None if v is None or not math.isfinite(v) else float(v)


def objective_matrix(resolved: dict, records: list[dict]) -> tuple[np.ndarray, np.ndarray]:
    """``F (n, n_obj)`` to minimise and ``G (n, n_con)`` that must be ``<= 0``."""
    F = np.full((len(records), len(resolved["objectives"])), PENALTY)
    G = np.full((len(records), sum(len(c) - 1 for c in resolved["constraints"])), PENALTY)
    for i, r in enumerate(records):
        for j, o in enumerate(resolved["objectives"]):
            v = _value(r, o["metric"])
            if v is not None:
                F[i, j] = v if o["sense"] == "minimize" else -v
        j = 0
        for c in resolved["constraints"]:
            v = _value(r, c["metric"])
            for bound in ("min", "max"):
                if bound in c:
                    if v is not None:
                        G[i, j] = (c["min"] - v) if bound == "min" else (v - c["max"])
                    j += 1
    return F, G


def feasible(resolved: dict, records: list[dict]) -> np.ndarray:
    """``(n,)`` evaluated, every objective defined, every constraint met."""
    F, G = objective_matrix(resolved, records)
    ok = np.array([r["status"] == "ok" for r in records], dtype=bool)
    return ok & np.all(F < PENALTY, axis=1) & np.all(G <= 0, axis=1)


def expected_evaluations(resolved: dict) -> int:
    opt = resolved["optimizer"]
    if opt["method"] == "grid":
        return len(DesignSpace(resolved["variables"]).grid()) + 1
    if opt["method"] in ("sobol", "lhs"):
        return opt["samples"] + 1
    if opt["method"] == "nsga2":
        return opt["population"] * opt["generations"] + 2
    return opt["population"] * (opt["generations"] + 1) + 1


def run_study(resolved: dict, runner, *, resume: bool = False, progress=None) -> Store:
    """Run (or resume) a study; every evaluation is committed to the store as it finishes.

    Args:
        resolved: the resolved study from :func:`pkmlab.config.load_study`.
        runner: a runner from :mod:`.runners` (serial, joblib, Dask).
        resume: continue from the store in the output folder: candidates already stored are
            read back, never evaluated again. Without it an existing store is replaced.
        progress: optional callable ``progress(n_done_now)`` called per finished evaluation.
    """
    out = Path(resolved["output"])
    path = out / "evaluations.sqlite"
    fp = fingerprint(resolved)
    if path.exists() and resume:
        store = Store(path)
        old = store.get_meta("fingerprint")
        if old is not None and old != fp:
            store.close()
            raise ParameterError("--resume", "a results folder of the same study definition "
                                 "(mechanism, design, evaluate and seed unchanged)",
                                 f"{path} holds study fingerprint {old}, this file is {fp}")
    else:
        for suffix in ("", "-wal", "-shm"):
            Path(str(path) + suffix).unlink(missing_ok=True)
        store = Store(path)
    store.set_meta("fingerprint", fp)
    store.set_meta("resolved", resolved)
    store.set_meta("version", __version__)
    space = DesignSpace(resolved["variables"])
    mech, ev, seed = resolved["mechanism"], resolved["evaluate"], resolved["seed"]

    def evaluate_batch(params_list: list[dict]):
        keys = [candidate_key(fp, p) for p in params_list]
        todo, seen = [], set()
        for k, p in zip(keys, params_list):
            if k in seen or store.get(k) is not None:
                continue
            seen.add(k)
            todo.append((k, (candidate_mapping(mech, space.variables, p), ev, seed)))
        by_key = dict(zip(keys, params_list))
        for k, result in runner.map(evaluate_candidate, todo):
            store.put(k, "candidate", by_key[k], result)
            if progress:
                progress(1)
        return objective_matrix(resolved, [store.get(k) for k in keys])

    base_key = candidate_key(fp, BASELINE)
    if store.get(base_key) is None:
        for k, result in runner.map(evaluate_candidate, [(base_key, (mech, ev, seed))]):
            store.put(k, "baseline", BASELINE, result)
            if progress:
                progress(1)
    OPTIMISERS[resolved["optimizer"]["method"]](space, evaluate_batch, resolved["optimizer"],
                                                seed)
    store.set_meta("complete", True)
    return store
