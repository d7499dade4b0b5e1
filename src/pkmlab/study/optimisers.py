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

from .definition import PENALTY

__all__ = ["OPTIMISERS", "expected_evaluations", "check_memory"]

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
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=len(space.variables), seed=seed).random(opt.samples)
    for start in range(0, len(u), CHUNK):
        evaluate_batch([space.from_unit(r) for r in u[start:start + CHUNK]])


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
    evaluation: NSGA-II sorts with ``population²`` distance and dominance matrices, Latin
    hypercube sampling builds every sample at once (Sobol and grids are generated lazily)."""
    from ..memory import memory_limit, require

    if opt.method == "nsga2":
        need = 8.0 * opt.population ** 2 + 200.0 * opt.population * max(n_var, 1)
        fit = int((memory_limit() / 8.0) ** 0.5 * 0.9)
        require("optimizer.population", need, "a population whose sorting matrices",
                f"{opt.population}", f"try <= {fit}")
    elif opt.method == "lhs":
        need = 32.0 * opt.samples * max(n_var, 1)
        fit = int(memory_limit() / (32.0 * max(n_var, 1)) * 0.9)
        require("optimizer.samples", need, "a Latin hypercube whose samples",
                f"{opt.samples}", f"try <= {fit}, or method 'sobol', generated lazily")



OPTIMISERS = {"grid": _grid, "sobol": _sobol, "lhs": _lhs, "nsga2": _nsga2, "de": _de}
