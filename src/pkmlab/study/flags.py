"""Warnings about a study's answer that the tables alone do not show (summary, report, log).

* **On a bound of the design box.** A value of a range variable (continuous or integer) of a
  Pareto design (or, when nothing is feasible, of a least-violating one) within
  ``BOUND_SHARE`` (1 %) of the range from its low or high end: the best design may lie
  outside the box; widen it in that direction. (A grid search always samples the ends.)
* **Poor conditioning at the task.** ``sampled_task_kappa`` (κ at the task's corners and
  centre × its orientation samples, :mod:`pkmlab.requirements.placement`) above
  ``TASK_KAPPA_WARN`` (20), reported in every requirement study with a ``task`` block, with
  or without ``dexterity``.
* **Where the task was placed.** With ``task.centre: auto``, the centre the search chose
  (``task_centre_*``) for each design listed.
"""

from __future__ import annotations

import logging

from ..requirements.placement import TASK_KAPPA_WARN
from .definition import Study

log = logging.getLogger(__name__)

__all__ = ["BOUND_SHARE", "TASK_KAPPA_WARN", "on_bound", "design_flags"]

#: share of a variable's range within which a value counts as on the bound
BOUND_SHARE = 0.01


def label(record: dict) -> str:
    """The one name of a design everywhere (summary, report, compare, Python): its
    evaluation number ``#seq`` (the ``seq`` column of evaluations.csv and pareto.csv)."""
    return "baseline" if record.get("role") == "baseline" else f"#{record['seq']}"


def on_bound(study: Study, params: dict) -> list[str]:
    """The range variables of ``params`` (internal units) within ``BOUND_SHARE`` of their
    range from an end, as text: ``"crank_length 349.5 of ≤ 350 mm"``."""
    out = []
    for v in study.variables:
        if v.kind not in ("continuous", "integer") or params.get(v.name) is None:
            continue
        x, lo, hi = float(params[v.name]), float(v.low), float(v.high)
        tol = BOUND_SHARE * (hi - lo)
        unit = f" {v.unit}" if v.unit else ""
        shown = f"{v.display(x):.4g}"
        if x >= hi - tol:
            out.append(f"{v.name} {shown} of ≤ {v.display(hi):.4g}{unit}")
        elif x <= lo + tol:
            out.append(f"{v.name} {shown} of ≥ {v.display(lo):.4g}{unit}")
    return out


def design_flags(study: Study, designs: list[dict], params_of, quiet: bool = False,
                 text=str) -> list[str]:
    """Markdown bullet lines (and a log line each) for ``designs`` (the Pareto designs, or the
    least-violating ones): on-bound variables, poor conditioning at the task, the placed
    task centre. ``params_of(record)`` gives a record's design values; ``text`` escapes the
    user's strings (variable names) for the renderer (Markdown: ``markdown_text``)."""
    out, info, logged = [], [], []
    for r in designs:
        name = label(r)
        b = on_bound(study, params_of(r))
        for esc, lines in ((text, out), (str, logged)):      # escaped: the file; raw: the log
            if b:
                lines.append(f"- {name} lies on a bound of the design box (within "
                             f"{BOUND_SHARE:.0%} of the range): {', '.join(map(esc, b))}; the "
                             "best design may lie outside the box — widen it in that direction")
        k = r["metrics"].get("sampled_task_kappa")
        if "sampled_task_kappa" in r["metrics"] and (k is None or k > TASK_KAPPA_WARN):
            shown = "singular or unreachable" if k is None else f"κ {k:.3g}"
            line = (f"- {name}: poor conditioning at the task ({shown} > "
                    f"{TASK_KAPPA_WARN:g} at its corners and centre × orientation samples, "
                    "a sampled value): force and accuracy degrade there")
            out.append(line)
            logged.append(line)
        if getattr(study.evaluation.task, "auto", None) and any(study.evaluation.task.auto):
            c = [r["metrics"].get(f"task_centre_{a}") for a in "xyz"]
            if all(v is not None for v in c):
                info.append(f"- {name}: task centre placed at x {c[0]:.4g}, y {c[1]:.4g}, "
                           f"z {c[2]:.4g} mm (relative to the task frame; a search result, "
                           "not a proven optimum)")
    for line in [] if quiet else logged:
        log.warning("%s", line[2:])
    for line in [] if quiet else info:
        log.info("%s", line[2:])
    return out + info
