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

__all__ = ["DesignSpace", "OPTIMISERS"]

log = logging.getLogger(__name__)

PENALTY = 1.0e12


class DesignSpace:
    """The design variables: maps unit-cube points and optimiser vectors to parameter dicts."""

    def __init__(self, variables: list[dict]):
        self.variables = variables

    @property
    def names(self) -> list[str]:
        return [v["name"] for v in self.variables]

    def bounds(self) -> np.ndarray:
        """``(n, 2)`` box for continuous optimisers (integers span [low, high + 1))."""
        return np.array([[v["low"], v["high"] + (1.0 if v["type"] == "integer" else 0.0)]
                         for v in self.variables])

    def from_vector(self, x: np.ndarray) -> dict:
        out = {}
        for v, xi in zip(self.variables, x):
            if v["type"] == "integer":
                out[v["name"]] = int(min(np.floor(xi), v["high"]))
            else:
                out[v["name"]] = float(xi)
        return out

    def from_unit(self, u: np.ndarray) -> dict:
        out = {}
        for v, ui in zip(self.variables, u):
            if v["type"] == "choice":
                c = v["choices"]
                out[v["name"]] = c[min(int(ui * len(c)), len(c) - 1)]
            elif v["type"] == "integer":
                n = int(v["high"] - v["low"]) + 1
                out[v["name"]] = int(v["low"] + min(int(ui * n), n - 1))
            else:
                out[v["name"]] = float(v["low"] + ui * (v["high"] - v["low"]))
        return out

    def grid(self) -> list[dict]:
        axes = []
        for v in self.variables:
            if v["type"] == "choice":
                axes.append(list(v["choices"]))
            elif v["type"] == "integer":
                vals = np.unique(np.round(np.linspace(v["low"], v["high"], v["levels"])))
                axes.append([int(x) for x in vals])
            else:
                axes.append([float(x) for x in np.linspace(v["low"], v["high"], v["levels"])])
        return [dict(zip(self.names, combo)) for combo in itertools.product(*axes)]


def _grid(space, evaluate_batch, opt, seed):
    evaluate_batch(space.grid())


def _sobol(space, evaluate_batch, opt, seed):
    from scipy.stats import qmc

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)   # any n; powers of 2 balance best
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=seed).random(opt["samples"])
    evaluate_batch([space.from_unit(r) for r in u])


def _lhs(space, evaluate_batch, opt, seed):
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=len(space.variables), seed=seed).random(opt["samples"])
    evaluate_batch([space.from_unit(r) for r in u])


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

    minimize(StudyProblem(), NSGA2(pop_size=opt["population"]),
             ("n_gen", opt["generations"]), seed=seed, verbose=False)


def _de(space, evaluate_batch, opt, seed):
    from scipy.optimize import differential_evolution

    b = space.bounds()

    def f(X):
        X = np.atleast_2d(X.T) if X.ndim == 2 else X[None]
        F, G = evaluate_batch([space.from_vector(x) for x in X])
        # constraints as a penalty: DE here is for one scalar objective
        viol = np.sum(np.clip(G, 0, None), axis=1) if G.shape[1] else 0.0
        return F[:, 0] + PENALTY * (viol > 0) + viol

    differential_evolution(f, b, seed=seed, maxiter=opt["generations"],
                           popsize=max(1, opt["population"] // len(b)), polish=False,
                           vectorized=True, updating="deferred", tol=0.0)


OPTIMISERS = {"grid": _grid, "sobol": _sobol, "lhs": _lhs, "nsga2": _nsga2, "de": _de}
