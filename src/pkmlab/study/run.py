"""Drive a design study: optimiser → runner → store, resumable and reproducible.

A run owns its output folder (:mod:`.folder`): it holds a lock there while it runs (a second run
into the same folder refuses, naming the holder), and it never mixes with or deletes an earlier
run unless asked (``resume`` continues it, ``overwrite`` replaces it, deleting only what pkmlab
wrote).
"""

from __future__ import annotations

import logging
import platform
import time
from pathlib import Path

from .. import __version__
from ..errors import CandidateError, ParameterError, Shown
from ..runtime.jit import compile_lines, compile_log
from ..runtime.memory import BudgetError
from .definition import Study
from .evaluators import check_budget, evaluate_design
from .folder import OutputLock, check_output, claim, clear_for_overwrite
from .ladder import PENDING, coarse_evaluation, coarse_view, deferred_metrics, refine
from .objectives import feasible, objective_matrix
from .optimisers import OPTIMISERS, check_time
from .store import Store, candidate_key

log = logging.getLogger(__name__)

__all__ = ["run_study", "objective_matrix", "feasible", "CandidateError", "BASELINE",
           "OutputLock", "provenance"]

BASELINE = {"__baseline__": True}


def provenance() -> dict:
    """Where and when results were made."""
    return {"pkmlab_version": __version__, "time": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "machine": platform.node(), "python": platform.python_version(),
            "platform": platform.platform()}


def _prepare(out: Path, fp: str, resume: bool, overwrite: bool, study_name: str) -> Store:
    path = out / "evaluations.sqlite"
    if path.exists() and resume:
        store = Store(path)
        old = store.get_meta("fingerprint")
        if old is not None and old != fp:
            store.close()
            raise ParameterError("--resume", "a results folder of the same study definition "
                                 "(mechanism, design, evaluate and seed unchanged)",
                                 f"{path} holds study fingerprint {old}, this file is {fp}")
        return store
    if resume:
        raise ParameterError("--resume", "a results folder holding a started run",
                             f"no evaluations.sqlite in {out}")
    leftovers = [p for p in out.iterdir() if p.name != ".lock"] if out.exists() else []
    if leftovers and not overwrite:
        raise ParameterError("output", "a new or empty folder (--resume continues the run in "
                             "it, --overwrite replaces it)",
                             f"{out} holds {len(leftovers)} entries of an earlier run")
    if leftovers:
        clear_for_overwrite(out)
    claim(out, study_name)
    return Store(path)


def run_study(study: Study, runner, *, resume: bool = False, overwrite: bool = False,
              progress=None, lock: OutputLock | None = None) -> Store:
    """Run (or resume) a study; every evaluation is committed to the store as it finishes.

    Args:
        study: from :func:`pkmlab.study.load_study`.
        runner: a runner from :mod:`.runners` (serial, joblib, Dask).
        resume: continue the run in the output folder: candidates already stored are read
            back, never evaluated again.
        overwrite: replace an earlier run in the output folder (without it, a non-empty
            folder is refused).
        progress: optional callable ``progress(n_done_now)`` called per finished evaluation.
        lock: the folder's :class:`~.folder.OutputLock`, held by the caller, which then writes
            the report and designs before releasing it (as ``pkmlab run`` does); without it,
            the run takes the lock for the evaluations only.

    Raises:
        ParameterError: the folder is in use, not empty, or holds another study.
        CandidateError: a candidate raised an undeclared exception (recorded first).
    """
    out = Path(study.output)
    # the budgets (and their environment variables) are checked on the baseline before
    # anything is written: a run that cannot fit is refused before it starts
    check_budget(study.evaluation, study.space.decode(None))
    check_output(out, study.source, overwrite=overwrite)
    fp = study.fingerprint()
    if lock is None:
        with OutputLock(out) as held:
            return run_study(study, runner, resume=resume, overwrite=overwrite,
                             progress=progress, lock=held)
    if lock.path.parent.resolve() != out.resolve():
        raise ValueError(f"the lock held is on {lock.path.parent}, the study writes {out}")
    store = _prepare(out, fp, resume, overwrite, study.name)
    try:
        _run(study, runner, store, fp, progress)
    except BaseException:
        store.close()
        raise
    return store


#: a first evaluation longer than this (s) is timed once more, warm, for the time estimate
WARM_RETIME_S = 1.0


def compile_baseline(space, evaluation, seed: int, *, every: bool = False,
                     where: str = "before the workers start") -> dict:
    """Evaluate the baseline design in this process and log (INFO) what numba compiled, one
    line per group of kernels.

    A study's workers are separate processes, and each would otherwise compile the same
    kernels at the same time (about 35 s of CPU each on the demo study): evaluated here first,
    the baseline leaves every kernel its evaluation uses in numba's disk cache, so the workers
    load them. The kernels that other designs use and the baseline does not
    (:func:`.warm.extra_kernels`) are built too when the baseline compiled anything (a cold
    cache) or ``every``. With a warm cache (``make`` fills it after installing) nothing
    compiles here.
    """
    from .warm import extra_kernels

    with compile_log() as compiled:
        result = evaluate_design(space, None, evaluation, seed)
        if every or compiled.entries:
            extra_kernels(space.decode(None))
    for line in compile_lines(compiled.entries, where):
        log.info("%s", line)
    return result


def _check_time(study: Study, runner, store: Store, seconds: float) -> None:
    """The remaining evaluations at the baseline's measured time must fit the time budget;
    over it, the baseline is timed once more (its first evaluation may have compiled the
    kernels) before the study is refused."""
    done = store.conn.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0]
    workers = getattr(runner, "jobs", 1)
    try:
        check_time(study.space, study.optimizer, done, seconds, workers)
    except ParameterError:
        again = evaluate_design(study.space, None, study.evaluation, study.seed)["seconds"]
        check_time(study.space, study.optimizer, done, min(seconds, again), workers)


def _run(study: Study, runner, store: Store, fp: str, progress) -> None:
    store.set_meta("fingerprint", fp)
    store.set_meta("resolved", study.resolved())
    store.set_meta("version", __version__)
    runs = store.get_meta("runs") or []
    store.set_meta("runs", [*runs, {**provenance(), "seed": study.seed,
                                    "resumed": bool(runs)}])
    space, seed = study.space, study.seed
    ladder = study.tolerance_ladder
    # with a tolerance ladder the optimiser sees the coarse tolerances (.ladder), and the
    # evaluators no objective or constraint reads wait for the re-certification (null, noted)
    ev = study.evaluation if ladder is None else coarse_evaluation(study)
    pending = [] if ladder is None else deferred_metrics(study)

    def commit(key, role, params, result):
        if result["status"] == "budget":       # the environment's limit: stop, store nothing
            m = result["metrics"]
            raise BudgetError(m["field"], m["allowed"], Shown(m["got"]))
        if pending and result["status"] == "ok":
            result = {**result, "metrics": {**result["metrics"], **dict.fromkeys(pending)},
                      "notes": {**result["notes"], **dict.fromkeys(pending, PENDING)}}
        store.put(key, role, params, result)
        if progress:
            progress(1)
        if result["status"] == "error":
            raise CandidateError(params, result["reason"])

    def evaluate_batch(params_list: list[dict]):
        keys = [candidate_key(fp, p) for p in params_list]
        todo, seen = [], set()
        for k, p in zip(keys, params_list):
            if k in seen or store.get(k) is not None:
                continue
            seen.add(k)
            todo.append((k, (space, p, ev, seed)))
        by_key = dict(zip(keys, params_list))
        for k, result in runner.map(evaluate_design, todo):
            commit(k, "candidate", by_key[k], result)
        records = [store.get(k) for k in keys]
        return objective_matrix(study, records if ladder is None else
                                [coarse_view(r) for r in records])

    base_key = candidate_key(fp, BASELINE)
    compiling = 0.0
    if store.get(base_key) is None:
        # in this process, before any worker starts: it compiles every kernel the evaluation
        # uses into numba's disk cache once, and the workers then load them (compile_baseline)
        result = compile_baseline(space, ev, seed)
        commit(base_key, "baseline", BASELINE, result)
        compiling = float(result.get("compile_seconds", 0.0))
    # the estimate leaves out the one-off kernel compilation of the first evaluation, and the
    # other first-call costs (kernels loaded from numba's cache, plain njit compiles, lazy
    # imports): a first evaluation over WARM_RETIME_S is timed once more, warm
    seconds = store.get(base_key)["seconds"]
    seconds = max(seconds - compiling, 0.05 * seconds)
    if seconds > WARM_RETIME_S:
        again = evaluate_design(space, None, ev, seed)["seconds"]
        log.info("baseline timed again for the estimate: %.3g s (first evaluation %.3g s "
                 "without compiling)", again, seconds)
        seconds = min(seconds, again)
    _check_time(study, runner, store, seconds)
    OPTIMISERS[study.optimizer.method](space, evaluate_batch, study.optimizer, seed)
    if ladder is not None:
        store.set_meta("ladder", refine(study, runner, store))
    store.set_meta("complete", True)
