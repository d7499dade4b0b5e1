"""Why designs fail: each candidate's violated constraints with their margins, a tally per
constraint, and the least-violating designs when nothing is feasible (issue 26, item 2).

A candidate is feasible when it evaluated, every objective is defined and every constraint
holds (:func:`pkmlab.study.run.feasible`). :func:`violations` lists what stops it, each item
``(what, amount, reason)``:

* a constraint bound crossed: ``what`` = ``"<metric> ≥ <min>"`` or ``"<metric> ≤ <max>"``,
  ``amount`` = how far it is crossed, in the metric's unit (``min − value`` or
  ``value − max``, > 0);
* a constraint or objective metric undefined: ``amount`` ``None``, ``reason`` the
  evaluator's note (or "not computed");
* a failed evaluation: ``what`` = its status, ``reason`` the first line of its reason;
* a candidate the tolerance ladder pruned (status ``pruned``, :mod:`.ladder`): each
  constraint its certified coarse bounds violate whatever the fine value, with the certified
  least amount (``reason`` says it is certified by the coarse rung), else ``what`` =
  :data:`DOMINATED` and the reason naming the candidate that certainly dominates it (its
  feasibility at the fine tolerance is not known, and not needed: it is not on the front).

The least-violating ranking (:func:`least_violating`) orders evaluated candidates by the number
of violations, then by the sum of the crossed amounts each divided by the largest amount of
that constraint over the candidates (so metrics of different units weigh alike), then by
``seq``.
"""

from __future__ import annotations

import math

from . import ladder
from .definition import Study

__all__ = ["violations", "violated_text", "tally", "least_violating", "DOMINATED"]

#: the tally's line for candidates the tolerance ladder pruned as certainly dominated
DOMINATED = "certainly dominated (tolerance ladder, not re-certified)"


def _value(record: dict, metric: str):
    v = record["metrics"].get(metric)
    return None if v is None or not math.isfinite(float(v)) else float(v)


def _why(record: dict, metric: str) -> str:
    return str(record.get("notes", {}).get(metric) or "not computed")


def violations(study: Study, record: dict) -> list[tuple[str, float | None, str]]:
    """What keeps ``record`` from being feasible (module docstring); empty when feasible."""
    if record["status"] == "pruned":
        return _pruned(study, record)
    if record["status"] != "ok":
        why = (record.get("reason") or "").splitlines()
        return [(record["status"], None, why[0] if why else "")]

    def exact(metric):
        v = _value(record, metric)
        return (math.nan, math.nan) if v is None else (v, v)
    out = _crossed(study, exact, lambda metric: _why(record, metric), "")
    for o in study.objectives:
        if _value(record, o.metric) is None:
            out.append((f"{o.sense} {o.metric}", None, _why(record, o.metric)))
    return out


def _crossed(study: Study, bounds, undefined, note: str) -> list[tuple[str, float | None, str]]:
    """Each constraint bound that ``bounds(metric)`` (its ``(low, high)``; NaN: undefined)
    crosses whatever the value in it, with the least amount and ``note``; an undefined
    metric with ``undefined(metric)``."""
    out: list[tuple[str, float | None, str]] = []
    for c in study.constraints:
        lo, hi = bounds(c.metric)
        for bound, sign in (("min", "≥"), ("max", "≤")):
            b = getattr(c, bound)
            if b is None:
                continue
            what = f"{c.metric} {sign} {b:g}"
            if math.isnan(lo):
                out.append((what, None, undefined(c.metric)))
                continue
            amount = (b - hi) if bound == "min" else (lo - b)
            if amount > 0:
                out.append((what, amount, note))
    return out


def _pruned(study: Study, record: dict) -> list[tuple[str, float | None, str]]:
    """A pruned candidate's certain violations from its coarse bounds (:func:`.ladder.bounds`
    on the values the coarse pass stored), else the dominance that pruned it."""
    coarse = ladder.coarse_view(record)
    out = _crossed(study, lambda metric: ladder.bounds(coarse, metric),
                   lambda metric: "undefined at the coarse tolerance", "certified coarse bound")
    if out:
        return out
    why = (record.get("reason") or "").splitlines()
    text = why[0] if why else ""
    return [(DOMINATED, None, text.split("certainly dominated ", 1)[-1])]


def violated_text(study: Study, record: dict) -> str:
    """One cell: ``"task_contained ≥ 1 by 1; actuators_fit ≥ 1 by 1"``, ``""`` if feasible."""
    parts = []
    for what, amount, why in violations(study, record):
        if amount is not None and why:          # a certified least amount (pruned)
            parts.append(f"{what} by at least {amount:.4g} ({why})")
        elif amount is not None:
            parts.append(f"{what} by {amount:.4g}")
        else:
            parts.append(f"{what}: {why}" if why else what)
    return "; ".join(parts)


def tally(study: Study, records: list[dict]) -> list[tuple[str, int, int]]:
    """Per constraint bound (and failed evaluations, undefined objectives): ``(what,
    violated, of)`` over the candidates, most violated first."""
    cand = [r for r in records if r["role"] == "candidate"]
    counts: dict[str, int] = {}
    for c in study.constraints:
        for bound, sign in (("min", "≥"), ("max", "≤")):
            if getattr(c, bound) is not None:
                counts[f"{c.metric} {sign} {getattr(c, bound):g}"] = 0
    for r in cand:
        for what in dict.fromkeys(w for w, _, _ in violations(study, r)):
            counts[what] = counts.get(what, 0) + 1
    return sorted(((w, n, len(cand)) for w, n in counts.items()), key=lambda x: -x[1])


def least_violating(study: Study, records: list[dict], k: int) -> list[dict]:
    """The ``k`` evaluated candidates closest to feasible (module docstring)."""
    cand = [r for r in records if r["role"] == "candidate" and r["status"] == "ok"]
    viol = [violations(study, r) for r in cand]
    scale: dict[str, float] = {}
    for vs in viol:
        for what, amount, _ in vs:
            if amount is not None:
                scale[what] = max(scale.get(what, 0.0), amount)

    def key(i):
        vs = viol[i]
        size = sum(1.0 if a is None else a / scale[w] if scale.get(w) else 0.0
                   for w, a, _ in vs)
        return (len(vs), size, cand[i]["seq"])

    order = sorted(range(len(cand)), key=key)
    return [cand[i] for i in order[:k]]
