"""What the study page shows, as plain data: every candidate in display units, the baseline
comparison, constraint margins, rounded build dimensions, failure counts, provenance.

Nothing here computes kinematics or workspaces: the page is built from the store and the
files :func:`pkmlab.study.export.export_designs` wrote.
"""

from __future__ import annotations

import math
import re
from collections import Counter

from ..errors import ParameterError
from ..escaping import plotly_text
from ..study.definition import Study
from ..study.metrics import METRICS
from ..study.run import BASELINE, feasible

__all__ = ["fmt", "difference", "candidate_rows", "objective_axes", "compare_rows",
           "constraint_rows", "build_values", "failure_counts", "derived_rows",
           "LENGTH_STEP_MM", "ANGLE_STEP_DEG", "ROUND_OFF"]

#: Smaller magnitudes are shown as 0 (round-off: lengths in mm, volumes in cm³, forces in N).
ROUND_OFF = 1e-9
#: Rounding of the dimensions shown for building a design.
LENGTH_STEP_MM = 0.5
ANGLE_STEP_DEG = 0.1


def fmt(v, digits: int = 4) -> str:
    """A number for a table: ``digits`` significant digits, ``—`` when undefined."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int | float):
        x = float(v)
        if abs(x) < ROUND_OFF:
            return "0"
        if x != 0 and (abs(x) >= 1e6 or abs(x) < 1e-3):
            return f"{x:.{digits - 1}e}"
        text = f"{x:.{digits}g}"
        return text if "e" not in text else f"{x:.0f}"
    return str(v)


def difference(value, base) -> tuple[str, str]:
    """``(Δ, Δ %)`` of ``value`` against ``base`` as text (``—`` when undefined)."""
    if not isinstance(value, int | float) or not isinstance(base, int | float) or \
            isinstance(value, bool) or isinstance(base, bool):
        return "—", "—"
    if not (math.isfinite(value) and math.isfinite(base)):
        return "—", "—"
    d = float(value) - float(base)
    if abs(d) < ROUND_OFF:
        return "0", ("0 %" if abs(base) >= ROUND_OFF else "—")
    pct = "—" if abs(base) < ROUND_OFF else f"{100 * d / abs(base):+.1f} %"
    return ("0" if d == 0 else f"{d:+.4g}"), pct


def params_of(study: Study, record: dict) -> dict:
    """A record's design values (internal units; the baseline's from the mechanism spec)."""
    return study.space.baseline_values() if record["params"] == BASELINE else record["params"]


def _display_params(study: Study, record: dict) -> dict:
    p = params_of(study, record)
    return {v.name: None if p.get(v.name) is None else v.display(p[v.name])
            for v in study.variables}


def objective_axes(study: Study) -> list[dict]:
    """One axis per objective: key, label with unit and sense."""
    out = []
    for o in study.objectives:
        m = METRICS[o.metric]
        out.append({"key": o.metric, "metric": o.metric, "sense": o.sense, "unit": m.unit,
                    "label": f"{m.label}, {'max.' if o.sense == 'maximize' else 'min.'}"})
    return out


def _hover(study: Study, row: dict, status: str) -> str:
    lines = [f"<b>{'baseline' if row['role'] == 'baseline' else '#' + str(row['seq'])}"
             f"</b> · {status}"]
    if row.get("pareto_rank"):
        lines[0] += " · on the Pareto front"
    if row.get("design"):
        lines[0] += " · exported (card)"
    for v in study.variables:          # user strings are escaped for plotly's markup
        x = row["params"].get(v.name)
        x = x if isinstance(x, int | float) or x is None else plotly_text(x)
        lines.append(f"{plotly_text(v.name)} = {fmt(x)} {v.unit}".rstrip())
    for o in study.objectives:
        m = METRICS[o.metric]
        lines.append(f"{o.metric} = {fmt(row['metrics'].get(o.metric))} {m.unit}".rstrip())
    if row["reason"]:
        lines.append(plotly_text(row["reason"][:120]))
    return "<br>".join(lines)


def candidate_rows(study: Study, records: list[dict], front: list[dict],
                   designs: dict[int, int]) -> list[dict]:
    """Every evaluation for the page: ``seq, role, status, reason, feasible, pareto_rank,
    design`` (card number or None), ``params`` in display units, ``metrics``, ``notes``,
    ``group`` (for the charts) and ``hover`` text. ``designs``: seq → card number."""
    ok = feasible(study, records) if records else []
    rank = {r["seq"]: i + 1 for i, r in enumerate(front)}
    rows = []
    for r, f in zip(records, ok):
        row = {"seq": r["seq"], "role": r["role"], "status": r["status"],
               "reason": (r["reason"] or "").splitlines()[0] if r["reason"] else "",
               "feasible": bool(f), "pareto_rank": rank.get(r["seq"]),
               "design": designs.get(r["seq"]), "params": _display_params(study, r),
               "metrics": {k: v for k, v in r["metrics"].items()}, "notes": r.get("notes", {})}
        if r["role"] == "baseline":
            row["group"] = "baseline"
        elif row["pareto_rank"]:
            row["group"] = "pareto"
        elif r["status"] == "pruned":
            row["group"] = "pruned"
        else:
            row["group"] = "feasible" if f else "infeasible"
        status = ("feasible" if f else ("infeasible" if r["status"] == "ok" else r["status"]))
        row["hover"] = _hover(study, row, status)
        rows.append(row)
    return rows


def compare_rows(items: list[tuple[str, str, object, object]]) -> list[dict]:
    """Table rows ``name, unit, value, baseline, Δ, Δ %`` from ``(name, unit, value, base)``."""
    out = []
    for name, unit, value, base in items:
        d, pct = difference(value, base)
        out.append({"name": name, "unit": unit, "value": fmt(value), "baseline": fmt(base),
                    "delta": d, "pct": pct})
    return out


def constraint_rows(study: Study, metrics: dict) -> list[dict]:
    """Each constraint bound: the value, the margin (≥ 0: met) and whether it is met."""
    rows = []
    for c in study.constraints:
        v = metrics.get(c.metric)
        unit = METRICS[c.metric].unit
        for bound in ("min", "max"):
            b = getattr(c, bound)
            if b is None:
                continue
            if v is None:
                margin, ok = None, False
            else:
                margin = (v - b) if bound == "min" else (b - v)
                ok = margin >= 0
            flag = METRICS[c.metric].statistic == "flag"
            rule = ("must be 1 (true)" if flag and bound == "min" and b == 1
                    else f"{'≥' if bound == 'min' else '≤'} {b:g} {unit}".rstrip())
            rows.append({"metric": c.metric, "rule": rule, "value": fmt(v),
                         "margin": "—" if margin is None or flag else f"{margin:+.4g} {unit}"
                         .rstrip(), "ok": ok})
    return rows


def _round(v, x):
    if x is None or isinstance(x, str):
        return x
    if v.kind == "integer":
        return int(x)
    if v.quantity == "length":
        return round(x / LENGTH_STEP_MM) * LENGTH_STEP_MM
    if v.quantity == "angle":
        return math.radians(round(math.degrees(x) / ANGLE_STEP_DEG) * ANGLE_STEP_DEG)
    return float(f"{x:.3g}")


def build_values(study: Study, params: dict) -> tuple[dict, str | None]:
    """The design rounded for building (lengths to 0.5 mm, angles to 0.1°, other numbers to 3
    significant digits), in internal units, and why it cannot be built (None: it can)."""
    rounded = {v.name: _round(v, params.get(v.name)) for v in study.variables}
    try:
        _ = study.space.decode(rounded).nominal_pose
    except ParameterError as exc:
        return rounded, str(exc)
    return rounded, None


def derived_rows(study: Study, params: dict, rounded: dict) -> list[dict]:
    """The derived mechanism fields of a design and of its rounded version."""
    from ..study.space import get_path
    from ..study.spec import family_aliases

    if not study.space.derived:
        return []
    family = study.space.base_spec.family
    aliases = family_aliases(family)
    spec, spec_r = study.space.spec_of(params), study.space.spec_of(rounded)
    rows = []
    for d in study.space.derived:
        quantity = aliases.get(d.name, (None, "number"))[1]
        conv = math.degrees if quantity == "angle" else (lambda x: x)
        unit = {"length": "mm", "angle": "deg"}.get(quantity, "")
        x, xr = get_path(spec, d.target), get_path(spec_r, d.target)
        rows.append({"name": d.name, "unit": unit, "expression": d.expression.text,
                     "value": fmt(conv(x)), "build": fmt(conv(xr), 6)})
    return rows


#: the tolerance ladder's pruning reasons (:mod:`pkmlab.study.ladder`): certainly dominated
#: by a named candidate, or a constraint violated by a certified bound
_DOMINATED = re.compile(r"^(.*certainly dominated by) (evaluation \d+: .*)$")
_CERTIFIED = re.compile(r"^(.*?)(\w+) (>=|<=) (\S+) ([<>]) (\S+) \(certified\)$")


def _reason_kind(reason: str) -> tuple[str, str]:
    """``(kind, example)``: a reason without its values (``field: must be …``; a ladder's
    pruning without the dominating candidate or the bound), and the values it was given."""
    m = _DOMINATED.match(reason)
    if m:
        return f"{m[1]} a refined candidate", m[2]
    m = _CERTIFIED.match(reason)
    if m:
        return (f"{m[1]}{m[2]} {m[5]} {m[6]} (certified bound)",
                f"{'lower' if m[3] == '>=' else 'upper'} bound {m[4]}")
    head, sep, got = reason.partition("; got ")
    return head, (sep.lstrip("; ") + got if sep else "")


def failure_counts(records: list[dict]) -> tuple[dict, list[dict]]:
    """``({status: count}, [{status, reason, count, example}])`` — why the evaluations that
    are not ``ok`` failed, grouped by reason (values stripped), most common first."""
    counts = Counter(r["status"] for r in records)
    groups: Counter = Counter()
    example: dict = {}
    for r in records:
        if r["status"] == "ok":
            continue
        first = (r["reason"] or "").splitlines()[0] if r["reason"] else ""
        kind, ex = _reason_kind(first)
        groups[(r["status"], kind)] += 1
        example.setdefault((r["status"], kind), ex)
    return dict(sorted(counts.items())), [
        {"status": s, "reason": why or "(no reason recorded)", "count": n,
         "example": example[(s, why)]} for (s, why), n in groups.most_common()]
