"""``results/<study>/report.html``: the study's interactive report, from the store and the
exported design files (nothing is evaluated again)."""

from __future__ import annotations

import json
import logging
import math
import time
from pathlib import Path

import numpy as np
import yaml

from ..export import exporters
from ..study.definition import Study
from ..study.export import read_index
from ..study.flags import design_flags
from ..study.ladder import coarse_view
from ..study.metrics import METRICS
from ..study.violations import least_violating, tally, violated_text
from . import data as D
from .figures import design_scene, pareto_matrix, pareto_parcoords
from .page import colour_option, data_json, figure_json, hull_of_ply, png_uri, render_page
from .posepanel import panel_model, task_shapes, task_traces

log = logging.getLogger(__name__)

__all__ = ["write_study_page", "REPORT_NAME"]

REPORT_NAME = "report.html"

_FILES = {
    "mechanism.yaml": "mechanism file (pkmlab inspect / workspace / compare read it)",
    "design.json": "why it was chosen, values, slice layout",
    "slices.png": "horizontal sections",
    "actuators.json": "the actuator values, torques or forces and speeds drawn in "
                      "actuators-*.png, with the chosen actuator's limits",
    "task.stl": "the task region (mm, base frame, placed where the evaluation put it)",
    "workspace_task.glb": "the workspace hull and the task region in one scene (glTF, m)",
}


def _what(name: str) -> str:
    """The file table's description of an exported design's file: its own, a workspace hull
    in a registered mesh format (the exporter's description), or a coloured slice picture."""
    stem, _, fmt = name.rpartition(".")
    ex = exporters("mesh").get(fmt)
    if stem == "workspace" and ex is not None:
        return "workspace hull, " + ex.description
    for mex in exporters("mechanism").values():      # mechanism.mjcf.xml, .urdf, ...
        if any(name == "mechanism" + sfx for sfx in mex.files or (mex.suffix,)):
            return f"mechanism, {mex.format.upper()}: {mex.description}"
    if name.startswith("actuators-") and name.endswith(".png"):
        return "actuator torques or forces and speeds over the motion, limits dashed"
    return _FILES.get(name, "slices coloured by the metric" if name.endswith("_slices.png")
                      else "")


def _runs(out: Path) -> list[dict]:
    from ..study.store import Store

    path = out / "evaluations.sqlite"
    if not path.is_file():
        return []
    store = Store(path, read_only=True)
    try:
        return store.get_meta("runs") or []
    finally:
        store.close()


def _points(study: Study, rows: list[dict]) -> list[dict]:
    pts = []
    for r in rows:
        if r["status"] not in ("ok", "pruned"):
            continue
        # a candidate the tolerance ladder pruned: at the coarse values it was pruned with
        metrics = coarse_view(r)["metrics"] if r["status"] == "pruned" else r["metrics"]
        values = {o.metric: metrics.get(o.metric) for o in study.objectives}
        pts.append({"seq": r["seq"], "group": r["group"], "values": values,
                    "hover": r["hover"]})
        if r["design"]:
            pts.append({"seq": r["seq"], "group": "exported", "values": values,
                        "hover": r["hover"], "text": f"#{r['seq']}"})
    return pts


def _other_kind(metrics: dict, notes: dict, name: str) -> bool:
    """The other actuator kind's metric (a servo's ``actuator_force_rating``): null with a
    note pointing at the metric of its own kind; left off the card (kept in the CSV)."""
    why = str(notes.get(name, ""))
    return metrics.get(name) is None and (" actuator: see " in why
                                          or " actuators: see " in why)


def _card(out: Path, study: Study, entry: dict, baseline: dict | None,
          n: int) -> tuple[dict, object | None, list]:
    folder = out / "designs" / entry["folder"]
    info = json.loads((folder / "design.json").read_text())
    params = info["params"]
    base_p = baseline["params"] if baseline else {}
    base_m = baseline["metrics"] if baseline else {}
    rounded, problem = D.build_values(study, params)
    prow = []
    for v in study.variables:
        x = params.get(v.name)
        xd = None if x is None else v.display(x)
        xr = rounded.get(v.name)
        d, pct = D.difference(xd, base_p.get(v.name))
        prow.append({"name": v.name, "unit": v.unit, "value": D.fmt(xd),
                     "build": D.fmt(None if xr is None else v.display(xr), 6),
                     "baseline": D.fmt(base_p.get(v.name)), "delta": d, "pct": pct})
    objectives = {o.metric: o.sense[:3] + "." for o in study.objectives}
    metrics = info["metrics"]
    notes = info.get("notes", {})
    mrows = D.compare_rows([(m, METRICS[m].unit, metrics.get(m), base_m.get(m))
                            for m in METRICS if (m in metrics or m in base_m)
                            and not _other_kind(metrics, notes, m)])
    for r in mrows:
        r["objective"] = objectives.get(r["name"], "")
        r["title"] = METRICS[r["name"]].description
    mrows.sort(key=lambda r: (not r["objective"],))
    card = {"number": entry["number"], "seq": entry["seq"], "key": entry["key"][:12],
            "pareto_rank": entry["pareto_rank"], "why": info["why"],
            "short": info["why"].split(":")[0], "params": prow,
            "derived": D.derived_rows(study, params, rounded), "metrics": mrows,
            "constraints": D.constraint_rows(study, metrics), "notes": info.get("notes", {}),
            "violated": violated_text(study, {"status": "ok", "metrics": metrics,
                                              "notes": info.get("notes", {})}),
            "build_problem": problem, "slices": [], "files": [], "has_scene": False,
            "colour_options": [], "scene_note": ""}
    for name in info["files"]:
        card["files"].append({"name": name, "href": f"designs/{entry['folder']}/{name}",
                              "what": _what(name)})
    card["files"].append({"name": "design.json", "href": f"designs/{entry['folder']}/"
                          "design.json", "what": _FILES["design.json"]})
    lay = info.get("slice_layout")
    for name in sorted(info["files"], key=lambda s: (s == "slices.png", s)):
        if name.endswith(".png") and (folder / name).is_file():
            if name.startswith("actuators-"):       # not a section: its own caption
                card["slices"].append({"uri": png_uri(folder / name), "caption": (
                    f"actuators over the motion {name[len('actuators-'):-4]}: "
                    + _what(name))})
                continue
            caption = ("sections" if name == "slices.png" else
                       f"sections coloured by {name.replace('_slices.png', '')}")
            if lay:
                caption += (f", {lay['window_mm']:g} mm window every {lay['spacing_mm']:g} mm "
                            f"({lay['layout']} layout)")
            if info.get("task_drawing_note"):
                caption += "; note: " + info["task_drawing_note"]
            card["slices"].append({"uri": png_uri(folder / name), "caption": caption})
    fig, colours = None, []
    mech = None
    try:
        mech = study.space.decode(params)
    except Exception as exc:  # noqa: BLE001 - a drawing problem never stops the report
        log.warning("design %d: mechanism not drawn: %s", n, exc)
    ply = folder / "workspace.ply"
    if mech is not None:
        hull = None
        if ply.is_file():
            h = hull_of_ply(ply)
            labels = info.get("vertex_values", {})
            for name, vals in h["values"].items():
                meta = labels.get(name, {"label": name, "unit": ""})
                text = meta["label"] + (f" ({meta['unit']})" if meta.get("unit") else "")
                colours.append(colour_option(text, vals))
            colours.append(colour_option("height z (mm)", h["vertices"][:, 2]))
            first = colours[0]
            hull = {"vertices": h["vertices"], "faces": h["faces"],
                    "intensity": np.asarray(first["values"]), "label": first["label"]}
            card["scene_note"] = (f"{len(h['faces'])} triangles; the hull is the set of tool "
                                  "points of the study's workspace request. Colour range: 1st "
                                  "to 99th percentile. Drag to rotate, scroll to zoom; click "
                                  "legend entries to hide parts.")
        else:
            card["scene_note"] = ("No workspace hull: " + ("the workspace is empty."
                                  if info.get("workspace", {}).get("empty")
                                  else "the study evaluates no workspace."))
        fig = design_scene(mech, hull)
        _pose_panel(card, fig, study, mech, n)
        if hull is not None:
            fig.data[0].update(cmin=colours[0]["cmin"], cmax=colours[0]["cmax"])
        card["has_scene"] = True
        card["colour_options"] = [c["label"] for c in colours] or ["—"]
    else:
        card["scene_note"] = "The mechanism could not be drawn (see the log)."
    return card, fig, colours


def _pose_panel(card: dict, fig, study: Study, mech, n: int) -> None:
    """The card's pose panel (its model as ``card["pose_json"]``) and the task region in its
    3-D view; a problem here never stops the report."""
    try:
        shapes = task_shapes(study, mech)
        fig.add_traces(task_traces(shapes))
        card["pose_model"] = f"pose-model-{n}"
        card["pose_json"] = data_json(panel_model(mech, shapes))
    except Exception as exc:  # noqa: BLE001 - a panel problem never stops the report
        log.warning("design %d: no pose panel: %s", n, exc)
        card.pop("pose_model", None)


def _variables(study: Study) -> list[dict]:
    base = study.space.baseline_values()
    out = []
    for v in study.variables:
        if v.kind == "choice":
            rng = ", ".join(str(c) for c in v.choices)
        else:
            rng = f"{D.fmt(v.display(v.low))} … {D.fmt(v.display(v.high))}"
            if v.kind == "integer":
                rng += " (integer)"
        b = base.get(v.name)
        out.append({"name": v.name, "unit": v.unit, "range": rng,
                    "baseline": "— (free parameter)" if b is None else D.fmt(v.display(b))})
    return out


def _optimizer_text(study: Study) -> str:
    opt = study.optimizer.model_dump()
    method = opt.get("method", "")
    keys = {"sobol": ("samples",), "lhs": ("samples",), "grid": (),
            "nsga2": ("population", "generations"), "de": ("population", "generations")}
    return ", ".join([str(method)] + [f"{k} {opt[k]}" for k in keys.get(method, ())
                                      if opt.get(k) is not None])


def write_study_page(out: Path, study: Study, records: list[dict], *, progress=None) -> Path:
    """Write ``out/report.html`` for ``study`` from its ``records`` (``Store.all()``) and the
    designs exported into ``out/designs`` (:func:`pkmlab.study.export.export_designs`).

    ``progress``: optional ``progress(message)`` per step (also logged at INFO).
    """
    from ..study.report import pareto_records

    t0 = time.perf_counter()
    out = Path(out)

    def step(message: str) -> None:
        log.info("report.html: %s", message)
        if progress:
            progress(message)

    step("tables")
    front = pareto_records(study, records)
    index = read_index(out)
    by_seq = {e["seq"]: e["number"] for e in index["designs"]}
    rows = D.candidate_rows(study, records, front, by_seq)
    baseline = next((r for r in rows if r["role"] == "baseline"), None)
    axes = D.objective_axes(study)
    step("Pareto charts")
    figures = {"fig-pareto-matrix": figure_json(pareto_matrix(axes, _points(study, rows)))}
    has_parcoords = len(axes) > 2
    parcoords_title = "feasible candidates; Pareto set in red"
    if has_parcoords:
        # nothing feasible: the least-violating designs instead of an empty box
        least = set() if front else {r["seq"] for r in least_violating(
            study, records, max(study.top, 1) * 4)}
        if least:
            parcoords_title = (f"no feasible candidate: the {len(least)} least-violating "
                               "designs (fewest violations, then smallest), in red")
        pc = [{"values": {a["key"]: r["metrics"][a["key"]] for a in axes},
               "pareto": bool(r["pareto_rank"]) or r["seq"] in least} for r in rows
              if r["role"] == "candidate" and (r["feasible"] or r["seq"] in least)
              and all(isinstance(r["metrics"].get(a["key"]), int | float) and
                      math.isfinite(r["metrics"][a["key"]]) for a in axes)]
        figures["fig-pareto-parcoords"] = figure_json(pareto_parcoords(axes, pc))
    cards, colours = [], {}
    for entry in index["designs"]:
        if not (out / "designs" / entry["folder"] / "design.json").is_file():
            continue
        step(f"design card {entry['number']}")
        card, fig, opts = _card(out, study, entry, baseline, entry["number"])
        cards.append(card)
        if fig is not None:
            figures[f"fig-design-{card['number']}"] = figure_json(fig)
        if card.get("pose_model"):
            figures[card["pose_model"]] = card.pop("pose_json")
        if opts:
            colours[card["number"]] = opts
    metrics = [m for m in METRICS if any(m in r["metrics"] for r in rows)]
    counts, reasons = D.failure_counts(records)
    why_fail = [{"what": w, "count": n, "of": of} for w, n, of in tally(study, records) if n]
    shown = front[:max(study.top, 1) * 2] or least_violating(study, records, max(study.top, 1))
    flags = [{"text": f[2:], "warn": "task centre placed" not in f}
             for f in design_flags(study, shown, lambda r: D.params_of(study, r), quiet=True)]
    resolved = out / "study.resolved.yaml"
    resolved_text = (resolved.read_text() if resolved.is_file() else
                     yaml.safe_dump(json.loads(json.dumps(study.resolved(), default=float)),
                                    sort_keys=False, allow_unicode=True))
    data = {"study": study.name, "objectives": axes,
            "variables": [{"name": v.name, "unit": v.unit} for v in study.variables],
            "metrics": [{"name": m, "unit": METRICS[m].unit} for m in metrics],
            "candidates": [{k: v for k, v in r.items() if k != "hover"} for r in rows],
            "pareto": [r["seq"] for r in front],
            "designs": [{k: c[k] for k in ("number", "seq", "pareto_rank", "why")}
                        for c in cards],
            "colours": colours}
    step("writing")
    path = render_page(
        out / REPORT_NAME, "study.html.j2", title=study.name, kind="design study report",
        data=data, figures=figures, description=study.description, axes=axes, cards=cards,
        n_evaluations=len(records), counts=counts, reasons=reasons,
        n_feasible=sum(r["feasible"] for r in rows if r["role"] == "candidate"),
        n_pareto=len(front), has_parcoords=has_parcoords, parcoords_title=parcoords_title,
        constraints_text=", ".join(c.describe() for c in study.constraints) or "none",
        export_problems=index["problems"], why_fail=why_fail, variables=_variables(study),
        flags=flags,
        optimizer=_optimizer_text(study),
        seed=study.seed, resolved_yaml=resolved_text, runs=_runs(out),
        length_step=D.LENGTH_STEP_MM, angle_step=D.ANGLE_STEP_DEG,
        stale_designs=not index["designs"] and any(
            p.is_dir() for p in (out / "designs").glob("[0-9][0-9]-*")))
    log.info("report.html written in %.1f s (%d design cards)", time.perf_counter() - t0,
             len(cards))
    return path

