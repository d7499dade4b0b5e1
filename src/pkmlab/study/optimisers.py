"""Design-space samplers and optimisers behind one interface.

Each optimiser is a function ``(space, evaluate_batch, options, seed)``; ``evaluate_batch``
takes a list of parameter dicts and returns, in the same order, ``(F, G)`` rows: objective
values to *minimise* and constraint values that must be ``<= 0`` (failed candidates come back
with a large penalty). The optimisers are deterministic for a given seed and given
evaluation results, which is what makes a resumed study reproduce an uninterrupted one.
"""

from __future__ import annotations

import itertools
import logging
import warnings

import numpy as np

from ..runtime.memory import memory_limit, require
from ..runtime.time_budget import require_time, study_seconds, time_limit
from .definition import PENALTY

__all__ = ["OPTIMISERS", "expected_evaluations", "check_memory", "check_time", "lhs_chunks"]

log = logging.getLogger(__name__)

#: designs per batch handed to the runner by the sampling optimisers (generated lazily)
CHUNK = 256


def _chunks(designs, size: int = CHUNK):
    it = iter(designs)
    while batch := list(itertools.islice(it, size)):
        yield batch


def _grid(space, evaluate_batch, opt, seed):
    for batch in _chunks(space.grid()):
        evaluate_batch(batch)


def _qmc(engine, space, evaluate_batch, n):
    for start in range(0, n, CHUNK):
        u = engine.random(min(CHUNK, n - start))
        evaluate_batch([space.from_unit(r) for r in u])


def _sobol(space, evaluate_batch, opt, seed):
    from scipy.stats import qmc

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)   # any n; powers of 2 balance best
        _qmc(qmc.Sobol(d=len(space.variables), scramble=True, seed=seed), space,
             evaluate_batch, opt.samples)


def _lhs(space, evaluate_batch, opt, seed):
    for u in lhs_chunks(opt.samples, len(space.variables), seed):
        evaluate_batch([space.from_unit(r) for r in u])


def lhs_chunks(n: int, d: int, seed, size: int = CHUNK):
    """A Latin hypercube of ``n`` points in ``[0, 1)^d``, generated lazily in ``(size, d)``
    chunks: memory is O(d) per point of a block of :data:`_BLOCK` points, whatever ``n``.

    Point ``i`` lies in stratum ``π_j(i)`` of dimension ``j``, at a uniform random offset
    inside it; each ``π_j`` is a keyed pseudo-random permutation of ``range(n)`` computed
    point by point (:func:`_permute`), not stored. (scipy's ``qmc.LatinHypercube`` draws
    the ``n × d`` permutations at once, 1.1 GiB before the first evaluation for 10⁷ points
    in 4 dimensions.) Deterministic for a given seed, whatever ``size``.
    """
    jitter_ss, key_ss = np.random.SeedSequence(seed).spawn(2)
    rng = np.random.default_rng(jitter_ss)
    keys = key_ss.generate_state(d * _ROUNDS, dtype=np.uint64).reshape(d, _ROUNDS)
    for start in range(0, n, _BLOCK):          # whole blocks: numpy's per-call cost amortised
        idx = np.arange(start, min(start + _BLOCK, n), dtype=np.uint64)
        strata = np.stack([_permute(idx, n, keys[j]) for j in range(d)], axis=1)
        u = (strata + rng.random((len(idx), d))) / n
        for k in range(0, len(u), size):
            yield u[k:k + size]


_BLOCK = 16_384

_ROUNDS = 6
_M64 = np.uint64(0xFFFFFFFFFFFFFFFF)


def _mix(x: np.ndarray) -> np.ndarray:
    """splitmix64's finaliser (a bijective 64-bit hash), on a uint64 array."""
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


def _permute(i: np.ndarray, n: int, keys: np.ndarray) -> np.ndarray:
    """``π(i)`` for a keyed pseudo-random permutation π of ``range(n)``: a balanced Feistel
    network over the ``2^(2b) >= n`` integers of ``2b`` bits, cycle-walked back into
    ``range(n)`` (a bijection of the larger set restricted to ``range(n)`` by re-applying it
    until the value falls inside; the set is under 4n, so a few steps at most on average)."""
    b = max(1, (max(n - 1, 1).bit_length() + 1) // 2)
    mask, shift = np.uint64((1 << b) - 1), np.uint64(b)

    def encrypt(x):
        left, right = x >> shift, x & mask
        for k in keys:
            left, right = right, left ^ (_mix(right ^ k) & mask)
        return (left << shift) | right

    with np.errstate(over="ignore"):
        y = encrypt(i.astype(np.uint64))
        out = y >= np.uint64(n)
        while np.any(out):
            y[out] = encrypt(y[out])
            out = y >= np.uint64(n)
    return y.astype(np.int64)


def _nsga2(space, evaluate_batch, opt, seed):
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    b = space.bounds()
    probe_F, probe_G = evaluate_batch([space.from_vector(b[:, 0])])
    n_obj, n_con = probe_F.shape[1], probe_G.shape[1]

    class StudyProblem(Problem):
        def __init__(self):
            super().__init__(n_var=len(b), n_obj=n_obj, n_ieq_constr=n_con, xl=b[:, 0],
                             xu=b[:, 1] - 1e-9 * (b[:, 1] - b[:, 0]))

        def _evaluate(self, X, out, *args, **kwargs):
            F, G = evaluate_batch([space.from_vector(x) for x in X])
            out["F"] = F
            if n_con:
                out["G"] = G

    minimize(StudyProblem(), NSGA2(pop_size=opt.population),
             ("n_gen", opt.generations), seed=seed, verbose=False)


def _de(space, evaluate_batch, opt, seed):
    from scipy.optimize import differential_evolution

    b = space.bounds()

    def f(X):
        X = np.atleast_2d(X.T) if X.ndim == 2 else X[None]
        F, G = evaluate_batch([space.from_vector(x) for x in X])
        # constraints as a penalty: DE here is for one scalar objective
        viol = np.sum(np.clip(G, 0, None), axis=1) if G.shape[1] else 0.0
        return F[:, 0] + PENALTY * (viol > 0) + viol

    differential_evolution(f, b, seed=seed, maxiter=opt.generations,
                           popsize=max(1, opt.population // len(b)), polish=False,
                           vectorized=True, updating="deferred", tol=0.0)


def expected_evaluations(space, opt) -> int:
    """How many candidates ``opt`` evaluates (at most, for de), the baseline included."""
    if opt.method == "grid":
        return space.grid_size() + 1
    if opt.method in ("sobol", "lhs"):
        return opt.samples + 1
    if opt.method == "nsga2":
        return opt.population * opt.generations + 2
    return opt.population * (opt.generations + 1) + 1


def check_memory(n_var: int, opt) -> None:
    """Refuse optimiser settings whose own arrays exceed the memory budget, before any
    evaluation: NSGA-II sorts with ``population²`` distance and dominance matrices (grids,
    Sobol and Latin hypercube samples are generated lazily, a chunk at a time)."""
    if opt.method == "nsga2":
        need = 8.0 * opt.population ** 2 + 200.0 * opt.population * max(n_var, 1)
        fit = int((memory_limit() / 8.0) ** 0.5 * 0.9)
        require("optimizer.population", need, "a population whose sorting matrices",
                f"{opt.population}", f"try <= {fit}")


def check_time(space, opt, done: int, seconds_per_evaluation: float, workers: int,
               logger=None) -> None:
    """Refuse a study whose remaining evaluations (``expected_evaluations`` less the ``done``
    already stored) are estimated, at ``seconds_per_evaluation`` on ``workers`` parallel
    workers, to exceed the time budget (:mod:`pkmlab.runtime.time_budget`); log a long estimate."""
    remaining = max(expected_evaluations(space, opt) - done, 0)
    need = study_seconds(remaining, seconds_per_evaluation, workers)
    fit = int(time_limit() * max(workers, 1) / max(seconds_per_evaluation, 1e-9))
    if opt.method in ("sobol", "lhs"):
        field, hint = "optimizer.samples", f"try <= {max(fit - 1, 1)} or more --jobs"
    elif opt.method == "grid":
        field, hint = "design", f"try fewer levels (<= {fit} designs) or more --jobs"
    else:
        field, hint = "optimizer.generations", \
            f"try <= {max(fit // max(opt.population, 1) - 1, 1)} or more --jobs"
    require_time(field, need, "a study whose evaluations are",
                 f"{remaining} evaluations at {seconds_per_evaluation:.3g} s each on "
                 f"{workers} worker{'s' if workers != 1 else ''}", hint, logger or log)


OPTIMISERS = {"grid": _grid, "sobol": _sobol, "lhs": _lhs, "nsga2": _nsga2, "de": _de}
