"""The tolerance ladder of a study: optimise at a coarse certified tolerance, re-certify the
designs that can matter at the fine one (issue 28).

Study file::

    tolerance_ladder:
      coarse: {angle: 0.1 deg, length: 0.1 mm,   # the capability's and the needed stroke's
               worst_case: bound}                # the dexterity's worst case (default bound)
      prune: true                                  # certified pruning (default)

**Coarse pass.** The optimiser sees every candidate evaluated with the coarse tolerances
(:class:`Tolerances`): the orientation capability bisected to ``angle`` instead of 0.01°, the
needed stroke to ``length`` instead of 0.01 mm, and (``worst_case: bound``) the dexterity's
worst case replaced by certified bounds from a subset of its samples
(:mod:`.evaluators.worst_bound`: ``worst_kappa`` a lower bound, ``min_force`` an upper one,
``singularity_free`` 0 only on a singular sample). Every other metric does not depend on them.

**Deferred evaluators** (:func:`deferred`). A standalone evaluator whose metrics no
objective or constraint reads (the paper motion, the task) is not run on the coarse rung: the
optimiser and the pruning never read it. Its metrics are null with a note until the candidate
is re-certified, where it runs exactly as in a run without the ladder; a pruned candidate
keeps them null, noted as not computed. The same holds for a metric computed apart within a
laddered evaluator (:data:`_PARTS`: the dexterity's ``sampled_min_force``) when nothing reads
it: the re-certification, which runs that evaluator anyway, computes it.

**Refinement** (:func:`refine`, after the optimiser). The stored candidates are re-certified at
the fine tolerances (the study's own: exactly what a run without the ladder computes), front by
front of their coarse values, best first, one batch of workers at a time (within a front, the
candidates whose certified worst case dominates the most others' best cases first). Only the
laddered metrics (:data:`LADDERED`; the dexterity's worst-case metrics alone) and the deferred
evaluators' are computed; the fine values replace the coarse ones, and the coarse ones stay in
the record as ``<metric>_coarse``. A failure at the fine tolerance (an invalid design, a
declared numerical failure) is stored as that status, with the reason and the coarse values.

**Certified pruning.** Each laddered metric's fine value is bracketed by the coarse run's proofs
(:func:`bounds`): the fine ``orientation_capability`` lies at most at the coarse
``orientation_capability_upper`` (a proven upper bound of the true capability); the fine
``needed_stroke`` at least at the coarse ``needed_stroke_lower``; the fine ``worst_kappa`` at
least at the coarse one, the fine ``min_force`` at most at the coarse one. A candidate not yet
refined is *pruned* when its bounds violate a constraint whatever the fine value (checked
first: constraint-first, e.g. a certified worst κ above the constraint's maximum), or when its
best case over those bounds (every other metric exact) is dominated by the fine values of a
refined feasible candidate. Its record keeps the coarse values (``<metric>_coarse``, the fine
ones null), status ``pruned`` and the reason (the bounds and the dominating candidate or the
constraint). A pruned candidate is certainly infeasible or dominated at the fine tolerance, so
the fine Pareto front of the refined candidates is the one of all candidates, and the exported
designs and their metrics are those of a run without the ladder.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..errors import NumericalError, ParameterError
from ..units import parse_angle, parse_length
from .definition import FINE, Tolerances
from .evaluators import EVALUATORS
from .evaluators.dexterity import SAMPLED_FORCE, sampled_force, worst_metrics
from .evaluators.registry import Context
from .metrics import METRICS, metrics_of
from .objectives import feasible, objective_matrix
from .selection import non_dominated

__all__ = ["Tolerances", "ToleranceLadder", "LADDERED", "FINE", "bounds", "refine",
           "ladder_from_spec", "coarse_name", "coarse_view", "deferred", "deferred_metrics",
           "coarse_evaluation"]


@dataclass(frozen=True)
class ToleranceLadder:
    """``coarse`` tolerances for the optimisation; ``prune``: certified pruning."""

    coarse: Tolerances
    prune: bool = True

    def written(self) -> dict:
        return {"coarse": self.coarse.written(), "prune": self.prune}


def ladder_from_spec(data, evaluation) -> ToleranceLadder | None:
    """The study file's ``tolerance_ladder`` mapping → :class:`ToleranceLadder` (None: none),
    for a study whose ``evaluation`` computes a laddered metric."""
    if data is None:
        return None
    where = "tolerance_ladder"
    if not isinstance(data, dict) or set(data) - {"coarse", "prune"} or "coarse" not in data:
        raise ParameterError(where, "{coarse: {angle: <angle>, length: <length>, worst_case: "
                             "bound|exact}, prune: true|false}", data)
    c = data["coarse"]
    if not isinstance(c, dict) or set(c) - {"angle", "length", "worst_case"}:
        raise ParameterError(f"{where}.coarse", "{angle: 0.1 deg, length: 0.1 mm, worst_case: "
                             "bound}", c)
    angle = parse_angle(c.get("angle", "0.01 deg"), f"{where}.coarse.angle")
    length = parse_length(c.get("length", "0.01 mm"), f"{where}.coarse.length")
    if not FINE.angle <= angle <= math.radians(5.0):
        raise ParameterError(f"{where}.coarse.angle", "an angle in [0.01, 5] deg (the fine "
                             "tolerance is 0.01 deg)", c.get("angle"))
    if not FINE.length <= length <= 10.0:
        raise ParameterError(f"{where}.coarse.length", "a length in [0.01, 10] mm (the fine "
                             "tolerance is 0.01 mm)", c.get("length"))
    worst = c.get("worst_case", "bound")
    if worst not in ("bound", "exact"):
        raise ParameterError(f"{where}.coarse.worst_case", "'bound' (certified bounds from a "
                             "subset of the samples) or 'exact'", worst)
    prune = data.get("prune", True)
    if not isinstance(prune, bool):
        raise ParameterError(f"{where}.prune", "true or false", prune)
    ladder = ToleranceLadder(Tolerances(angle, length, worst), prune)
    if not laddered(evaluation, ladder):
        raise ParameterError(where, f"used with one of evaluate.{' or evaluate.'.join(LADDERED)}"
                             " (the optima with a certified tolerance; dexterity with "
                             "coarse.worst_case: bound)", data)
    return ladder


#: laddered evaluator → its metrics that the coarse rung changes, each with the coarse metric
#: bounding its fine value from below and from above (None: no certified bound on that side)
LADDERED = {
    "orientation_capability": {
        "orientation_capability": (None, "orientation_capability_upper"),
        "orientation_capability_upper": ("orientation_capability", None),
        "orientation_capability_bracket": (None, None)},
    "needed_stroke": {
        "needed_stroke": ("needed_stroke_lower", None),
        "needed_stroke_lower": (None, "needed_stroke"),
        "needed_stroke_bracket": (None, None)},
    # coarse.worst_case: bound (.evaluators.worst_bound); its other metrics are exact
    "dexterity": {
        "worst_kappa": ("worst_kappa", None),
        "min_force": (None, "min_force"),
        "singularity_free": (None, "singularity_free")},
}
#: what a laddered evaluator's re-certification runs before it (it reads the workspace)
_NEEDS = {"dexterity": ("workspace",)}
#: a laddered evaluator's re-certification, when it is not the whole evaluator: the
#: dexterity's other metrics (GCI, sampled statistics) do not depend on the rung
_REFINE = {"dexterity": worst_metrics}
_BOUNDS = {m: b for ms in LADDERED.values() for m, b in ms.items()}
#: evaluators that read nothing another evaluator leaves in the context and leave nothing
#: another reads, but for the evaluators listed (the task's placed centre: ``motions``): the
#: coarse rung can leave them to the re-certification when no objective or constraint reads
#: their metrics (:func:`deferred`)
_STANDALONE = {"trajectory": (), "task": ("motions",)}
#: metrics computed apart within a laddered evaluator, each with that evaluator: the coarse
#: rung leaves them to the re-certification (which runs the evaluator anyway) when no objective
#: or constraint reads them, and the re-certification computes them (:data:`_APART`)
_PARTS = {SAMPLED_FORCE: "dexterity"}
_APART = {SAMPLED_FORCE: sampled_force}
#: the note of a deferred metric: before the re-certification, and on a pruned candidate
PENDING = "computed when the candidate is re-certified at the fine tolerance (tolerance ladder)"
NOT_COMPUTED = ("not computed: the candidate was pruned before its re-certification (tolerance "
                "ladder); no objective or constraint reads this metric")


def coarse_name(metric: str) -> str:
    return f"{metric}_coarse"


def bounds(record: dict, metric: str, names=None) -> tuple[float, float]:
    """Certified ``(low, high)`` of ``metric``'s fine value from a coarse ``record`` (exact
    metrics, and those not in ``names``, the metrics the run's ladder changes (default: every
    laddered one): the value twice; a missing bound: ∓inf)."""
    m = record["metrics"]
    if metric not in _BOUNDS or (names is not None and metric not in names):
        v = m.get(metric)
        return (math.nan, math.nan) if v is None else (float(v), float(v))
    lo, hi = _BOUNDS[metric]

    def value(name, default):
        v = m.get(name) if name else None
        return default if v is None else float(v)
    # an open end (upper None: the search's largest box had a position) bounds nothing
    return value(lo, -math.inf), value(hi, math.inf)


def deferred(study) -> tuple[str, ...]:
    """The evaluators of ``study`` that its ladder's coarse rung leaves to the
    re-certification, in evaluation order: standalone ones (:data:`_STANDALONE`) whose
    metrics no objective or constraint reads and that no other evaluator of the study waits
    for; then the metrics computed apart within a re-certified evaluator (:data:`_PARTS`)
    that no objective or constraint reads. A pruned candidate needs only what proves it
    pruned; a re-certified one gets them computed exactly as a run without the ladder does."""
    ev = study.evaluation
    used = {o.metric for o in study.objectives} | {c.metric for c in study.constraints}
    runs = ev.evaluators
    whole = tuple(n for n in runs if n in _STANDALONE and not used & set(metrics_of(n))
                  and not any(r in runs for r in _STANDALONE[n])
                  and not any(n in EVALUATORS[m].after or n in EVALUATORS[m].requires
                              for m in runs))
    again = laddered(ev, study.tolerance_ladder) if study.tolerance_ladder else []
    return whole + tuple(m for m, n in _PARTS.items()
                         if n in again and m in ev.metrics and m not in used)


def deferred_metrics(study) -> list[str]:
    """The metrics of :func:`deferred` evaluators that the study's evaluation writes."""
    d = deferred(study)
    return [m for m in study.evaluation.metrics if METRICS[m].evaluator in d or m in d]


def coarse_evaluation(study):
    """The evaluation the optimiser's candidates get on the ladder's coarse rung."""
    return study.evaluation.with_tolerances(study.tolerance_ladder.coarse, deferred(study))


def laddered(evaluation, ladder: ToleranceLadder) -> list[str]:
    """The evaluators of ``evaluation`` whose metrics the coarse rung of ``ladder`` changes
    (dexterity only with ``worst_case: bound``), in evaluation order."""
    return [n for n in evaluation.evaluators if n in LADDERED
            and (n != "dexterity" or ladder.coarse.worst_case == "bound")]


def refine_design(space, params, evaluation, seed: int, names: tuple[str, ...]) -> dict:
    """The evaluators ``names`` of ``evaluation`` (fine tolerances) on one design → a result
    ``{"status", "reason", "metrics", "notes", "seconds"}`` with their metrics and notes (runs
    in a worker like :func:`.evaluators.evaluate_design`; an invalid design or a declared
    numerical failure is a status with its reason)."""
    t0 = time.perf_counter()
    run = [n for n in evaluation.evaluators
           if n in names or any(n in _NEEDS.get(m, ()) for m in names)]
    metrics: dict = {}
    status, reason = "ok", ""
    try:
        mech = space.decode(params)
        ctx = Context(evaluation, seed, choices=dict(space.evaluation_choices(params)))
        for name in run:
            if name in names:
                metrics.update(_REFINE.get(name, EVALUATORS[name])(mech, ctx))
                for part in names:
                    if _PARTS.get(part) == name:
                        metrics.update(_APART[part](mech, ctx))
            else:
                EVALUATORS[name](mech, ctx)
        notes = ctx.notes
    except ParameterError as exc:
        status, reason, notes = "invalid", str(exc), {}
    except NumericalError as exc:
        status, reason, notes = "failed", str(exc), {}
    return {"status": status, "reason": reason, "metrics": metrics, "notes": notes,
            "seconds": time.perf_counter() - t0}


def _minimised(study, record, case: str = "value", names=None) -> np.ndarray:
    """Objective row (minimised): the record's values, or (``case`` "best" / "worst") each
    objective at the end of its certified bounds that is best / worst for it."""
    row = []
    for o in study.objectives:
        lo, hi = bounds(record, o.metric, names)
        v = record["metrics"].get(o.metric)
        if case != "value":
            v = hi if (o.sense == "maximize") == (case == "best") else lo
        v = math.nan if v is None else float(v)
        row.append(math.inf if math.isnan(v) else (-v if o.sense == "maximize" else v))
    return np.array(row)


def _violation(study, record, names=None) -> str:
    """A constraint the record's certified bounds violate whatever the fine value, or ''."""
    for c in study.constraints:
        lo, hi = bounds(record, c.metric, names)
        if math.isnan(lo):
            return f"{c.metric} undefined"
        if c.min is not None and hi < c.min:
            return f"{c.metric} <= {hi:.6g} < {c.min:g} (certified)"
        if c.max is not None and lo > c.max:
            return f"{c.metric} >= {lo:.6g} > {c.max:g} (certified)"
    return ""


def refine(study, runner, store) -> dict:
    """Re-certify the stored candidates at the fine tolerances, pruning those certainly
    dominated (module notes) → ``{"refined": n, "pruned": n}``."""
    ladder = study.tolerance_ladder
    later = deferred(study)
    evaluators = tuple(n for n in study.evaluation.evaluators
                       if n in laddered(study.evaluation, ladder) or n in later) + tuple(
        m for m in later if m in _PARTS)
    names = [m for n in evaluators if n in LADDERED for m in LADDERED[n]]
    pending = deferred_metrics(study)
    ok = [r for r in store.all() if r["status"] == "ok"]
    fresh = [not any(coarse_name(m) in r["metrics"] for m in names) for r in ok]
    todo = [r for r, f in zip(ok, fresh, strict=True) if f]
    done = [r for r, f in zip(ok, fresh, strict=True) if not f]    # refined before a resume
    counts = {"refined": 0, "pruned": 0}
    if not names:
        return counts
    space, ev, seed = study.space, study.evaluation, study.seed
    jobs = _slots(runner)
    # the Pareto front is over candidates: the baseline never dominates (nor is pruned)
    dominators = [r for r in done if r["role"] == "candidate" and feasible(study, [r])[0]]
    rows: dict = {}                 # key → (coarse row, best case, worst case, violation)

    def row(r):
        if r["key"] not in rows:
            rows[r["key"]] = (_minimised(study, r), _minimised(study, r, "best", names),
                              _minimised(study, r, "worst", names),
                              _violation(study, r, names))
        return rows[r["key"]]
    while todo:
        # the next front of the coarse values among the candidates left
        front = set(np.flatnonzero(non_dominated(np.array([row(r)[0] for r in todo]))).tolist())
        Fd = objective_matrix(study, dominators)[0] if dominators else np.empty((0, 0))
        batch, keep = [], []
        for i, r in enumerate(todo):
            why = ""
            if ladder.prune and r["role"] == "candidate":
                _, best, _, why = row(r)
                if not why and len(Fd):
                    dom = np.all(Fd <= best, axis=1) & np.any(Fd < best, axis=1)
                    if dom.any():
                        j = int(np.argmax(dom))
                        why = (f"certainly dominated by evaluation {dominators[j]['seq']}: best "
                               f"case {_text(study, best)} vs {_text(study, Fd[j])}")
            if why:
                _prune(store, r, names, why, pending)
                counts["pruned"] += 1
            elif i in front or r["role"] == "baseline":
                batch.append(r)
            else:
                keep.append(r)
        if ladder.prune and len(batch) > jobs:
            # one batch of workers at a time, those likeliest to prune the most first
            power = _power([row(r)[2] for r in batch], [row(r)[1] for r in keep + batch])
            power[[r["role"] != "candidate" for r in batch]] = len(todo) + 1   # refined anyway
            order = np.argsort(-power, kind="stable")
            batch, keep = ([batch[k] for k in order[:jobs]],
                           keep + [batch[k] for k in order[jobs:]])
        tasks = [(r["key"], (space, None if r["role"] == "baseline" else r["params"], ev,
                             seed, evaluators)) for r in batch]
        by_key = {r["key"]: r for r in batch}
        for key, res in runner.map(refine_design, tasks):
            rec = _refined(store, by_key[key], names, res, pending)
            if rec["role"] == "candidate" and feasible(study, [rec])[0]:
                dominators.append(rec)
            counts["refined"] += 1
        todo = keep
    return counts


def _slots(runner) -> int:
    """Evaluations the runner runs at once: its ``jobs``, 1 in this process, and for a
    cluster (Dask) its workers' threads (large when unknown: whole fronts at once)."""
    if getattr(runner, "name", "") == "serial":
        return 1
    jobs = getattr(runner, "jobs", None)
    if jobs is None:
        try:
            jobs = sum(runner.client.nthreads().values())
        except Exception:  # noqa: BLE001 - unknown: no batching
            jobs = 1 << 30
    return max(1, int(jobs))


def _power(worst: list, best: list) -> np.ndarray:
    """For each certified worst case in ``worst``, how many of the best cases ``best`` it
    dominates: the order of the re-certifications within a front."""
    W, B = np.array(worst)[:, None, :], np.array(best)[None, :, :]
    return np.sum(np.all(W <= B, axis=2) & np.any(W < B, axis=2), axis=1)


def coarse_view(record: dict) -> dict:
    """``record`` as the coarse pass stored it (what the optimiser saw: a resumed run's
    optimiser sees the same values)."""
    m = record["metrics"]
    back = {k[:-len("_coarse")]: v for k, v in m.items() if k.endswith("_coarse")}
    if not back:
        return record
    # pruned, or failed at the fine tolerance only: the coarse pass stored it as evaluated
    coarse_ok = record["status"] == "pruned" or record["reason"].startswith(
        "at the fine tolerance")
    status = "ok" if coarse_ok else record["status"]
    return {**record, "status": status, "metrics": {**m, **back}}


def _text(study, row) -> str:
    return "(" + ", ".join(f"{o.metric} {(-v if o.sense == 'maximize' else v):.6g}"
                           for o, v in zip(study.objectives, row, strict=True)) + ")"


def _refined(store, record, names, res, pending=()) -> dict:
    metrics = dict(record["metrics"])
    for m in names:
        metrics[coarse_name(m)] = metrics.get(m)
        if res["status"] != "ok":
            metrics[m] = None
    metrics.update(res["metrics"])
    fresh = set(names) | set(pending)     # the re-certification's metrics and their notes
    notes = {k: v for k, v in record["notes"].items() if k not in fresh}
    notes.update({k: v for k, v in res["notes"].items() if k in fresh})
    extra = {} if res["status"] == "ok" else {
        "status": res["status"], "reason": f"at the fine tolerance: {res['reason']}"}
    return store.update(record["key"], metrics=metrics, notes=notes,
                        seconds=record["seconds"] + res["seconds"], **extra)


def _prune(store, record, names, why: str, pending=()) -> dict:
    metrics = dict(record["metrics"])
    for m in names:
        metrics[coarse_name(m)] = metrics.pop(m, None)
        metrics[m] = None
    notes = dict(record["notes"])
    for m in pending:                     # deferred to a re-certification that never runs
        metrics[m] = None
        notes[m] = NOT_COMPUTED
    return store.update(record["key"], metrics=metrics, notes=notes, status="pruned",
                        reason=f"not re-certified at the fine tolerance: {why}")
