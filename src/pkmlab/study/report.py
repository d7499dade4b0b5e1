"""Study results from the store: tables, Pareto set, plots, exported designs, summary.

Everything here reads the store; only :func:`export_designs` computes (the full workspace,
mesh and κ map of the few Pareto designs it exports).
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import yaml

from .run import feasible, objective_matrix

__all__ = ["pareto_mask", "write_report", "export_designs", "display_value"]


def pareto_mask(F: np.ndarray) -> np.ndarray:
    """``(n,)`` True for the rows of ``F (n, m)`` (minimised) that no other row dominates.

    Row a dominates b when a <= b everywhere and a < b somewhere. Duplicated rows are all kept.
    """
    F = np.asarray(F, dtype=float)
    n = len(F)
    keep = np.ones(n, dtype=bool)
    for i in range(n):
        if not keep[i]:
            continue
        dominated = np.all(F <= F[i], axis=1) & np.any(F < F[i], axis=1)
        if dominated.any():
            keep[i] = False
    return keep


def display_value(var: dict, x):
    """A parameter in display units (mm, deg) for tables."""
    if var["quantity"] == "angle":
        return math.degrees(x)
    return x


def _rows(resolved: dict, records: list[dict]):
    metrics = sorted({k for r in records for k in r["metrics"]})
    names = [v["name"] for v in resolved["variables"]]
    units = {v["name"]: v["unit"] for v in resolved["variables"]}
    header = (["seq", "role", "status", "reason", "seconds"]
              + [f"{n} ({units[n]})" if units[n] else n for n in names] + metrics)
    rows = []
    for r in records:
        p = r["params"]
        vals = [display_value(v, p[v["name"]]) if v["name"] in p else "" for v in
                resolved["variables"]]
        rows.append([r["seq"], r["role"], r["status"], r["reason"], f"{r['seconds']:.4f}",
                     *vals, *[r["metrics"].get(m, "") for m in metrics]])
    return header, rows


def _write_csv(path: Path, header, rows) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


def pareto_records(resolved: dict, records: list[dict]) -> list[dict]:
    """The non-dominated feasible candidates, best first by the first objective."""
    cand = [r for r in records if r["role"] == "candidate"]
    if not cand:
        return []
    ok = feasible(resolved, cand)
    F, _ = objective_matrix(resolved, cand)
    idx = np.flatnonzero(ok)
    front = idx[pareto_mask(F[idx])] if len(idx) else idx
    front = sorted(front, key=lambda i: tuple(F[i]))
    return [cand[i] for i in front]


def write_report(out: Path, resolved: dict, records: list[dict]) -> dict:
    """evaluations.csv, pareto.csv, pareto.png, study.resolved.yaml, summary.md."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    from .. import __version__

    (out / "study.resolved.yaml").write_text(yaml.safe_dump(
        {"pkmlab_version": __version__, **_plain(resolved)}, sort_keys=False))
    header, rows = _rows(resolved, records)
    _write_csv(out / "evaluations.csv", header, rows)
    front = pareto_records(resolved, records)
    h2, r2 = _rows(resolved, front)
    _write_csv(out / "pareto.csv", ["rank", *h2], [[i + 1, *row] for i, row in enumerate(r2)])
    _plot(out / "pareto.png", resolved, records, front)
    baseline = next((r for r in records if r["role"] == "baseline"), None)
    (out / "summary.md").write_text(_summary(resolved, records, front, baseline))
    return {"evaluations": len(records), "pareto": len(front),
            "failed": sum(r["status"] != "ok" for r in records)}


def _plain(obj):
    return json.loads(json.dumps(obj, default=float))


def _plot(path: Path, resolved, records, front) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    objs = resolved["objectives"]
    cand = [r for r in records if r["role"] == "candidate"]
    ok = feasible(resolved, cand) if cand else np.zeros(0, dtype=bool)

    def vals(rs, m):
        return np.array([np.nan if r["metrics"].get(m) is None else r["metrics"][m]
                         for r in rs], dtype=float)

    ncols = 2 if len(objs) > 2 else 1
    fig, axes = plt.subplots(1, ncols, figsize=(6.5 * ncols, 5), squeeze=False)
    ax = axes[0, 0]
    mx = objs[0]["metric"]
    my = objs[1]["metric"] if len(objs) > 1 else None
    x = vals(cand, mx)
    y = vals(cand, my) if my else np.arange(len(cand))
    ax.scatter(x[~ok], y[~ok], s=8, c="0.75", label="infeasible")
    ax.scatter(x[ok], y[ok], s=10, c="tab:blue", label="feasible")
    if front:
        fx, fy = vals(front, mx), vals(front, my) if my else np.arange(len(front))
        ax.scatter(fx, fy, s=30, c="tab:red", label="Pareto")
    base = [r for r in records if r["role"] == "baseline" and r["status"] == "ok"]
    if base and my:
        ax.scatter(vals(base, mx), vals(base, my), marker="*", s=160, c="k", label="baseline")
    ax.set_xlabel(f"{mx} ({objs[0]['sense']})")
    ax.set_ylabel(f"{my} ({objs[1]['sense']})" if my else "candidate")
    ax.legend(fontsize=8)
    if len(objs) > 2:
        ax = axes[0, 1]
        names = [o["metric"] for o in objs]
        data = np.array([[np.nan if r["metrics"].get(m) is None else r["metrics"][m]
                          for m in names] for r in front], dtype=float)
        if len(data):
            lo, hi = np.nanmin(data, axis=0), np.nanmax(data, axis=0)
            norm = (data - lo) / np.where(hi > lo, hi - lo, 1.0)
            for row in norm:
                ax.plot(range(len(names)), row, c="tab:red", alpha=0.5)
        ax.set_xticks(range(len(names)), [f"{n}\n({o['sense'][:3]})" for n, o in
                                          zip(names, objs)], fontsize=8)
        ax.set_ylabel("normalised over the Pareto set")
        ax.set_title("Pareto set, parallel coordinates", fontsize=9)
    fig.suptitle(f"{resolved['study']}: {len(cand)} candidates, {len(front)} Pareto")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _fmt(v) -> str:
    if v is None:
        return "—"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _summary(resolved, records, front, baseline) -> str:
    objs = [o["metric"] for o in resolved["objectives"]]
    cons = [c["metric"] for c in resolved["constraints"]]
    metrics = list(dict.fromkeys(objs + cons))
    var_names = [v["name"] for v in resolved["variables"]]
    n_fail = sum(r["status"] != "ok" for r in records)
    lines = [f"# {resolved['study']}", "", resolved.get("description", ""), "",
             f"{len(records)} evaluations ({n_fail} invalid or failed, recorded with their "
             f"reason in evaluations.csv); {len(front)} designs on the Pareto front.",
             "", "Objectives: " + ", ".join(f"{o['sense']} {o['metric']}" for o in
                                            resolved["objectives"]),
             "Constraints: " + (", ".join(
                 f"{c['metric']} " + " and ".join(f"{'≥' if k == 'min' else '≤'} {c[k]:g}"
                                                  for k in ("min", "max") if k in c)
                 for c in resolved["constraints"]) or "none"), "",
             "| design | " + " | ".join(var_names + metrics) + " |",
             "|---" * (1 + len(var_names) + len(metrics)) + "|"]

    def row(label, r):
        p = r["params"]
        vals = [_fmt(display_value(v, p[v["name"]])) if v["name"] in p else "(paper)"
                for v in resolved["variables"]]
        ms = [_fmt(r["metrics"].get(m)) for m in metrics]
        return f"| {label} | " + " | ".join(vals + ms) + " |"

    if baseline is not None:
        lines.append(row("baseline" + ("" if baseline["status"] == "ok" else
                                       f" ({baseline['status']})"), baseline))
    for i, r in enumerate(front[:max(resolved.get("top", 5), 1) * 2]):
        lines.append(row(f"Pareto {i + 1}", r))
    lines += ["", "Parameters in mm and degrees. Full tables: evaluations.csv, pareto.csv; "
              "exported designs (mechanism YAML, workspace STL, slices, κ map) under designs/."]
    return "\n".join(lines) + "\n"


def export_designs(out: Path, resolved: dict, front: list[dict]) -> list[Path]:
    """For the top designs: mechanism.yaml, workspace.stl, slices.png, kappa_slices.png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .. import dexterity as dx
    from ..config import load_mechanism, workspace_spec
    from ..dexterity.maps import metric_map
    from ..workspaces import workspace
    from ..workspaces.plots import slice_figure
    from .evaluate import candidate_mapping

    folders = []
    ev = resolved["evaluate"]
    for i, r in enumerate(front[:resolved.get("top", 5)]):
        d = Path(out) / "designs" / f"{i + 1:02d}-{r['key'][:8]}"
        d.mkdir(parents=True, exist_ok=True)
        data = candidate_mapping(resolved["mechanism"], resolved["variables"], r["params"])
        data = {**data, "name": f"{resolved['study']}-pareto-{i + 1}"}
        (d / "mechanism.yaml").write_text(
            f"# Pareto design {i + 1} of study {resolved['study']} (candidate {r['key']})\n"
            + yaml.safe_dump(_plain(data), sort_keys=False))
        if ev.get("workspace"):
            mech = load_mechanism(data)
            spec = workspace_spec(ev["workspace"])
            res = workspace(mech, **spec.build())
            res.plot_slices(d / "slices.png", window=spec.slice_window,
                            spacing=spec.slice_spacing)
            if not res.empty:
                res.save_mesh(d / "workspace.stl")
                L = (ev.get("dexterity") or {}).get("characteristic_length") or \
                    dx.characteristic_length(mech).length
                mm = metric_map(mech, res, "kappa", L)
                fig = slice_figure(res, window=spec.slice_window, spacing=spec.slice_spacing,
                                   values=np.where(np.isfinite(mm.grid), mm.grid, np.nan),
                                   label=mm.label)
                fig.savefig(d / "kappa_slices.png", dpi=110)
                plt.close(fig)
        folders.append(d)
    return folders
