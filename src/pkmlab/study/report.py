"""Study results from the store: tables, Pareto set, plots, exported designs, summary.

Everything here reads the store; only :func:`.export.export_designs` computes (the full
workspace, mesh and κ map of the few Pareto designs it exports). Plots are built on
:class:`matplotlib.figure.Figure` objects (no pyplot state, no global backend).
"""

from __future__ import annotations

import csv
import io
import json
import logging
from pathlib import Path

import numpy as np
import yaml

from ..escaping import markdown_text
from ..runtime import atomic
from .definition import Study
from .export import export_designs
from .flags import design_flags
from .flags import label as design_label
from .ladder import coarse_view
from .metrics import METRICS
from .run import BASELINE, feasible, objective_matrix, provenance
from .selection import non_dominated
from .violations import least_violating, tally, violated_text

log = logging.getLogger(__name__)

__all__ = ["pareto_mask", "write_report", "export_designs", "pareto_records"]


def pareto_mask(F: np.ndarray) -> np.ndarray:
    """``(n,)`` True for the rows of ``F (n, m)`` (minimised) that no other row dominates.

    Row a dominates b when a <= b everywhere and a < b somewhere. Duplicated rows are all kept.
    (pymoo's non-dominated sorting: :func:`.selection.non_dominated`.)
    """
    return non_dominated(F)


def _params(study: Study, record: dict) -> dict:
    """A record's design values (the baseline's from the mechanism spec)."""
    if record["params"] == BASELINE:
        return study.space.baseline_values()
    return record["params"]


def _rows(study: Study, records: list[dict]):
    metrics = [m for m in METRICS if any(m in r["metrics"] for r in records)]
    # the tolerance ladder's coarse values (study.ladder), after the fine ones
    coarse = [f"{m}_coarse" for m in metrics if any(f"{m}_coarse" in r["metrics"]
                                                    for r in records)]
    header = (["seq", "role", "status", "reason", "seconds"]
              + [f"design.{v.name} ({v.unit})" if v.unit else f"design.{v.name}"
                 for v in study.variables]
              + [METRICS[m].label for m in metrics]
              + [f"{c} ({METRICS[c[:-7]].unit})" for c in coarse] + ["violated", "notes"])
    metrics = metrics + coarse
    rows = []
    for r in records:
        p = _params(study, r)
        vals = ["" if p.get(v.name) is None else v.display(p[v.name]) for v in study.variables]
        notes = "; ".join(f"{k}: {v}" for k, v in r.get("notes", {}).items())
        rows.append([r["seq"], r["role"], r["status"], r["reason"].splitlines()[0]
                     if r["reason"] else "", f"{r['seconds']:.4f}", *vals,
                     *["" if r["metrics"].get(m) is None else r["metrics"][m]
                       for m in metrics], violated_text(study, r), notes])
    return header, rows


def _write_csv(path: Path, header, rows) -> None:
    buf = io.StringIO(newline="")
    w = csv.writer(buf)
    w.writerow(header)
    w.writerows(rows)
    atomic.write_text(path, buf.getvalue())


def pareto_records(study: Study, records: list[dict]) -> list[dict]:
    """The non-dominated feasible candidates, best first by the first objective."""
    cand = [r for r in records if r["role"] == "candidate"]
    if not cand:
        return []
    ok = feasible(study, cand)
    F, _ = objective_matrix(study, cand)
    idx = np.flatnonzero(ok)
    front = idx[pareto_mask(F[idx])] if len(idx) else idx
    front = sorted(front, key=lambda i: tuple(F[i]))
    return [cand[i] for i in front]


def write_report(out: Path, study: Study, records: list[dict]) -> dict:
    """evaluations.csv, pareto.csv, pareto.png, study.resolved.yaml, summary.md."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    log.info("writing evaluations.csv, pareto.csv, pareto.png, summary.md (%d evaluations)",
             len(records))
    resolved = {**study.resolved(), "provenance": provenance()}
    atomic.write_text(out / "study.resolved.yaml",
                      "# The study as run: every default filled in, every quantity with its "
                      "unit.\n# `pkmlab run` accepts this file as it is.\n"
                      + yaml.safe_dump(_plain(resolved), sort_keys=False, allow_unicode=True))
    header, rows = _rows(study, records)
    _write_csv(out / "evaluations.csv", header, rows)
    front = pareto_records(study, records)
    h2, r2 = _rows(study, front)
    _write_csv(out / "pareto.csv", ["rank", *h2], [[i + 1, *row] for i, row in enumerate(r2)])
    _plot(out / "pareto.png", study, records, front)
    baseline = next((r for r in records if r["role"] == "baseline"), None)
    atomic.write_text(out / "summary.md", _summary(study, records, front, baseline))
    counts: dict = {}
    for r in records:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    return {"evaluations": len(records), "pareto": len(front), "statuses": counts,
            "failed": sum(r["status"] not in ("ok", "pruned") for r in records),
            "pruned": counts.get("pruned", 0)}


def _plain(obj):
    return json.loads(json.dumps(obj, default=float))


def _plot(path: Path, study: Study, records, front) -> None:
    from matplotlib.figure import Figure

    objs = study.objectives
    cand = [r for r in records if r["role"] == "candidate"]
    ok = feasible(study, cand) if cand else np.zeros(0, dtype=bool)

    def vals(rs, m):
        return np.array([np.nan if r["metrics"].get(m) is None else r["metrics"][m]
                         for r in rs], dtype=float)

    def label(o):
        return f"{METRICS[o.metric].label}, {o.sense[:3]}."

    ncols = 2 if len(objs) > 2 else 1
    fig = Figure(figsize=(6.5 * ncols, 5), layout="tight")
    axes = fig.subplots(1, ncols, squeeze=False)
    ax = axes[0, 0]
    mx = objs[0].metric
    my = objs[1].metric if len(objs) > 1 else None
    x = vals(cand, mx)
    y = vals(cand, my) if my else np.arange(len(cand))
    pruned = np.array([r["status"] == "pruned" for r in cand], dtype=bool)
    # a group is drawn (and so in the legend) only when it has points to draw: an invalid
    # candidate's metrics are null
    shown = np.isfinite(x) & np.isfinite(y)
    rest = ~ok & ~pruned & shown
    if rest.any():
        ax.scatter(x[rest], y[rest], s=8, c="0.75", label="infeasible")
    if pruned.any():            # the tolerance ladder's: drawn at the coarse values it pruned
        coarse = [coarse_view(r) for r, p in zip(cand, pruned, strict=True) if p]
        ax.scatter(vals(coarse, mx), vals(coarse, my) if my else np.flatnonzero(pruned),
                   s=14, marker="x", c="0.45", linewidths=0.8,
                   label="pruned by the tolerance ladder (coarse values)")
    if (ok & shown).any():
        ax.scatter(x[ok], y[ok], s=10, c="tab:blue", label="feasible")
    if front:
        fx, fy = vals(front, mx), vals(front, my) if my else np.arange(len(front))
        ax.scatter(fx, fy, s=30, c="tab:red", label="Pareto (all objectives)")
    base = [r for r in records if r["role"] == "baseline" and r["status"] == "ok"]
    if base and my:
        ax.scatter(vals(base, mx), vals(base, my), marker="*", s=160, c="k", label="baseline")
    ax.set_xlabel(label(objs[0]))
    ax.set_ylabel(label(objs[1]) if my else "candidate")
    if ax.get_legend_handles_labels()[1]:       # no empty legend box
        ax.legend(fontsize=8)
    if len(objs) > 2:
        ax = axes[0, 1]
        names = [o.metric for o in objs]
        # nothing feasible: the least-violating designs instead of an empty box
        shown = front or least_violating(study, records, max(study.top, 1) * 4)
        data = np.array([[np.nan if r["metrics"].get(m) is None else r["metrics"][m]
                          for m in names] for r in shown], dtype=float)
        if len(data):
            lo, hi = np.nanmin(data, axis=0), np.nanmax(data, axis=0)
            norm = (data - lo) / np.where(hi > lo, hi - lo, 1.0)
            for row in norm:
                ax.plot(range(len(names)), row, c="tab:red", alpha=0.5)
        ax.set_xticks(range(len(names)), [label(o).replace(", ", "\n") for o in objs],
                      fontsize=8)
        what = "Pareto set" if front else f"{len(shown)} least-violating designs"
        ax.set_ylabel(f"normalised over the {what}")
        ax.set_title(f"{what}, parallel coordinates" + ("" if front else
                     " (no feasible design)"), fontsize=9)
    fig.suptitle(f"{study.name}: {len(cand)} candidates, {len(front)} Pareto")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    atomic.write_bytes(path, buf.getvalue())


def _fmt(v) -> str:
    """A summary.md cell: numbers formatted, text (a choice, a catalogue name) escaped."""
    if v is None:
        return "—"
    if isinstance(v, float):
        return f"{v:.4g}"
    return v if isinstance(v, int) else markdown_text(v)


def _summary(study: Study, records, front, baseline) -> str:
    metrics = list(dict.fromkeys([o.metric for o in study.objectives]
                                 + [c.metric for c in study.constraints]))
    counts: dict = {}
    for r in records:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    status = ", ".join(f"{n} {s}" for s, n in sorted(counts.items()))
    md = markdown_text
    lines = [f"# {md(study.name)}", "", md(study.description), "",
             f"{len(records)} evaluations ({status}; reasons in evaluations.csv); "
             f"{len(front)} designs on the Pareto front.", "",
             "Objectives: " + ", ".join(f"{o.sense} {o.metric}" for o in study.objectives),
             "Constraints: " + (", ".join(c.describe() for c in study.constraints) or "none"),
             "", "| design | " + " | ".join(
                 [f"{md(v.name)} ({v.unit})" if v.unit else md(v.name) for v in study.variables]
                 + [md(METRICS[m].label) for m in metrics]) + " |",
             "|---" * (1 + len(study.variables) + len(metrics)) + "|"]
    notes = []

    def row(label, r):
        p = _params(study, r)
        vals = [_fmt(None if p.get(v.name) is None else v.display(p[v.name]))
                for v in study.variables]
        ms = [_fmt(r["metrics"].get(m)) for m in metrics]
        for v in study.variables:
            if p.get(v.name) is None:
                notes.append(f"- {label}, {md(v.name)}: a free parameter, which the baseline "
                             "mechanism file has no value for")
        for k, why in r.get("notes", {}).items():
            if k in metrics:
                notes.append(f"- {label}, {md(k)}: {md(why)}")
        for k in metrics:
            if r["metrics"].get(k) is None and k not in r.get("notes", {}):
                notes.append(f"- {label}, {md(k)}: {md(_no_value(r, k))}")
        return f"| {label} | " + " | ".join(vals + ms) + " |"

    if baseline is not None:
        label = "baseline" + ("" if baseline["status"] == "ok" else
                              f" ({baseline['status']}: {md(baseline['reason'].splitlines()[0])})")
        lines.append(row(label, baseline))
    for r in front[:max(study.top, 1) * 2]:
        lines.append(row(design_label(r), r))
    shown = front[:max(study.top, 1) * 2] or least_violating(study, records, max(study.top, 1))
    lines += _requirement_margins(study, baseline, shown, metrics, notes)
    lines += _catalogue_fits(study, records)
    lines += _why_they_fail(study, records, front)
    flags = design_flags(study, shown, lambda r: _params(study, r), text=markdown_text)
    if flags:
        lines += ["", "Flags (" + ("Pareto" if front else "least-violating") + " designs; "
                  "designs are named by their evaluation number, the `seq` column):", *flags]
    if notes:
        lines += ["", "Notes (a value shown as — is undefined for the reason given):", *notes]
    units = ", ".join(dict.fromkeys(METRICS[m].unit for m in metrics if METRICS[m].unit))
    lines += ["", "Each metric's unit is in its column header" + (f" ({units})" if units else "")
              + "; design variables and notes: lengths in mm, angles in degrees. Metric "
              "definitions: `pkmlab metrics`. Full tables: evaluations.csv, pareto.csv; "
              "exported designs (mechanism YAML, workspace STL, slices, κ map) under designs/."]
    return "\n".join(lines) + "\n"


#: requirement metrics that summary.md lists in its margins table (when evaluated)
REQUIREMENT_MARGINS = ("task_contained", "task_margin", "task_orientation_margin",
                       "motions_feasible", "peak_actuator_force", "peak_actuator_speed",
                       "peak_actuator_torque", "peak_actuator_angular_speed",
                       "peak_actuator_power", "actuators_fit", "actuator_force_margin",
                       "actuator_speed_margin", "actuator_torque_speed_margin",
                       "actuator_stroke_margin", "actuator_angle_margin")


def _requirement_margins(study: Study, baseline, front, shown, notes: list) -> list[str]:
    """The task and actuator margins of the baseline and the Pareto designs listed above, or
    the least-violating ones when nothing is feasible (markdown lines; none when the study
    has no requirement blocks). Every "—" gets its reason in ``notes``."""
    rows = ([("baseline", baseline)] if baseline is not None else []) + \
        [(design_label(r), r) for r in front]
    names = [m for m in REQUIREMENT_MARGINS if any(m in r["metrics"] for _, r in rows)
             and not all(_other_kind(r, m) for _, r in rows)]
    if not names:
        return []
    head = [markdown_text(METRICS[m].label) for m in names]
    out = ["", "Requirement margins (task: mm and deg of room left; actuators: % of the "
           "limit left, negative = exceeded; see `pkmlab metrics`):", "",
           "| design | " + " | ".join(head) + " |", "|---" * (1 + len(names)) + "|"]
    for label, r in rows:
        out.append(f"| {label} | " + " | ".join(_fmt(r["metrics"].get(m)) for m in names)
                   + " |")
        for m in names:
            if r["metrics"].get(m) is None and m not in shown:
                why = r.get("notes", {}).get(m) or _no_value(r, m)
                notes.append(f"- {label}, {markdown_text(m)}: {markdown_text(why)}")
    return out


def _no_value(record: dict, name: str) -> str:
    """The reason for a "—" when the evaluation left no note for it."""
    if record["status"] != "ok":
        return f"the evaluation {record['status']}: {(record['reason'] or '').splitlines()[0]}"
    if name not in record["metrics"]:
        return "not computed for this design (an earlier run without this block)"
    return "undefined for this design (no note was recorded)"


def _why_they_fail(study: Study, records, front) -> list[str]:
    """The tally of violated constraints over the candidates and, when nothing is feasible,
    the least-violating designs (what each misses, by how much)."""
    counts = [t for t in tally(study, records) if t[1]]
    if not counts:
        return []
    out = ["", "Why candidates fail (violations per constraint; a candidate can violate "
           "several; column `violated` of evaluations.csv):", "",
           "| constraint | violated | of |", "|---|---|---|"]
    out += [f"| {markdown_text(w)} | {n} | {of} |" for w, n, of in counts]
    if not front:
        least = least_violating(study, records, max(study.top, 1))
        if least:
            out += ["", f"No feasible design. The {len(least)} least violating (fewest "
                    "violations, then smallest; exported under designs/):", "",
                    "| design | violated |", "|---|---|"]
            out += [f"| {design_label(r)} | {markdown_text(violated_text(study, r))} |"
                    for r in least]
    return out


def _other_kind(record, name: str) -> bool:
    """Whether ``name`` is the other actuator kind's metric on this design (a servo's
    ``actuator_stroke_margin``, a linear actuator's ``actuator_torque_rating``): null, with a
    note pointing at the metric of its own kind."""
    why = str(record.get("notes", {}).get(name, ""))
    return record["metrics"].get(name) is None and (" actuator: see " in why
                                                    or " actuators: see " in why)


def _catalogue_fits(study: Study, records) -> list[str]:
    """Which catalogue actuators work: for a design variable choosing the actuator, per entry
    the evaluated designs on which it fits (``actuators_fit``) out of those evaluated with it."""
    var = next((v for v in study.variables if v.role == "actuator"), None)
    if var is None:
        return []
    parts = []
    for name in var.choices:
        with_it = [r for r in records if r["status"] == "ok"
                   and _params(study, r).get(var.name) == name]
        fits = sum(r["metrics"].get("actuators_fit") == 1.0 for r in with_it)
        parts.append(f"{markdown_text(name)} fits {fits} of {len(with_it)}")
    return ["", "Catalogue actuators (designs evaluated with each, on which it meets force, "
            "speed, torque–speed and stroke along every motion): " + "; ".join(parts) + "."]
