"""Export the chosen Pareto designs in full: mechanism file, workspace meshes, slices, κ map.

The only part of reporting that computes: each exported design's workspace is evaluated again
(with the study's request) to write its hull, slices and per-voxel κ. Everything the HTML
report and :func:`pkmlab.open_results` need later is written here, so they only read files.

``designs/NN-key/`` (``NN``: 1 = the knee, then the extremes, then the spread designs; see
:mod:`.selection`) holds ``mechanism.yaml``, the mechanism in every mechanism format of the
exporter registry (``mechanism.mjcf.xml``, ``mechanism.urdf``, ``mechanism.joints.csv`` and
``.json``, ``mechanism.step`` when build123d is installed), ``design.json`` (why it was
chosen, its Pareto rank, values, slice layout, files), ``workspace.stl`` (mm),
``workspace.ply`` (mm, κ per vertex as a property), ``workspace.glb`` (m, coloured by κ),
``slices.png`` and
``kappa_slices.png``; ``designs/index.json`` lists them and the exports that failed.

With requirements (:mod:`pkmlab.requirements`): the task region is drawn in red into the
slices and written as ``task.stl`` (mm, base frame) and, with the workspace, as one scene
``workspace_task.glb``; without a workspace block the dexterous workspace over the task's
orientation set is computed for the drawing. Each required motion gets
``actuators-<motion>.png`` (actuator force or torque and speed against time with the chosen
actuator's limits dashed, and its torque–speed curve with the required points) and
``actuators.json`` the numbers drawn.
"""

from __future__ import annotations

import dataclasses
import io
import json
import logging
import shutil
import time
from pathlib import Path

import numpy as np
import yaml

from ..config import to_display
from ..errors import NumericalError, ParameterError
from ..export import exporters
from ..runtime import atomic
from .definition import Study
from .folder import DESIGN_FOLDER
from .run import BASELINE, objective_matrix
from .selection import select_designs
from .violations import least_violating, violated_text

log = logging.getLogger(__name__)

__all__ = ["export_designs", "chosen_designs", "read_index", "DESIGN_FOLDER"]

#: Exported design folders: ``NN-<first 8 characters of the candidate key>``.


def _plain(obj):
    return json.loads(json.dumps(obj, default=float))


def chosen_designs(study: Study, front: list[dict]) -> list[tuple[dict, int, str]]:
    """The ``study.top`` designs of ``front`` to export: ``(record, pareto rank, why)``."""
    if not front:
        return []
    F, _ = objective_matrix(study, front)
    names = [o.metric for o in study.objectives]
    return [(front[s.index], s.index + 1, s.why)
            for s in select_designs(F, study.top, names)]


def export_designs(out: Path, study: Study, front: list[dict], *, maps=("kappa",),
                   progress=None, records: list[dict] | None = None
                   ) -> tuple[list[Path], list[str]]:
    """Write the chosen designs of ``front`` (the Pareto records, in pareto.csv order).

    Args:
        out: the study's results folder.
        study: the study.
        front: :func:`.report.pareto_records`.
        maps: per-voxel metrics of :mod:`pkmlab.dexterity.maps` written as PLY vertex
            properties (the first also colours the GLB and the slices).
        progress: optional ``progress(done, total, message)``, called as each step starts.
        records: every evaluation: when ``front`` is empty (nothing feasible), the
            ``study.top`` least-violating candidates (:func:`.violations.least_violating`)
            are exported instead, with Pareto rank 0 and ``why`` naming what they violate.

    Returns ``(folders, problems)``: a design whose export fails is skipped with its reason
    in ``problems`` (logged), so an export error never stops the report.
    """
    out = Path(out)
    chosen = chosen_designs(study, front)
    if not front and records:
        least = least_violating(study, records, max(study.top, 1))
        chosen = [(r, 0, f"least violating {i + 1} of {len(least)} (no feasible design): "
                   f"{violated_text(study, r)}") for i, r in enumerate(least)]
    root = out / "designs"
    root.mkdir(parents=True, exist_ok=True)
    folders, problems, entries = [], [], []
    t0 = time.perf_counter()
    for i, (r, rank, why) in enumerate(chosen):
        d = root / f"{i + 1:02d}-{r['key'][:8]}"

        def step(message: str, i=i) -> None:
            log.info("design %d/%d: %s", i + 1, len(chosen), message)
            if progress:
                progress(i, len(chosen), message)

        step(f"design #{r['seq']}: {why}")
        try:
            info = _export_one(d, study, r, i + 1, rank, why, maps, step)
            folders.append(d)
            entries.append({"folder": d.name, "number": i + 1, "pareto_rank": rank,
                            "why": why, "seq": r["seq"], "key": r["key"],
                            "files": info["files"]})
        except (ParameterError, NumericalError, ValueError, OSError) as exc:
            log.warning("export of design #%s failed: %s", r["seq"], exc)
            problems.append(f"design #{r['seq']}: {type(exc).__name__}: {exc}")
    keep = {d.name for d in folders}
    for stale in root.iterdir():
        if stale.is_dir() and DESIGN_FOLDER.match(stale.name) and stale.name not in keep:
            shutil.rmtree(stale)
    atomic.write_text(root / "index.json", json.dumps(
        {"designs": entries, "problems": problems}, indent=2) + "\n")
    if progress:
        progress(len(chosen), len(chosen), "done")
    log.info("exported %d design(s) in %.1f s", len(folders), time.perf_counter() - t0)
    return folders, problems


def _every(seconds: float, report):
    """``report(x)`` at most once per ``seconds`` (for progress callbacks)."""
    last = [time.perf_counter()]

    def tick(x) -> None:
        now = time.perf_counter()
        if now - last[0] >= seconds:
            last[0] = now
            report(x)
    return tick


def read_index(out: Path) -> dict:
    """``designs/index.json`` of a results folder (empty when nothing was exported)."""
    p = Path(out) / "designs" / "index.json"
    if not p.is_file():
        return {"designs": [], "problems": []}
    return json.loads(p.read_text())


def _export_one(d: Path, study: Study, r: dict, number: int, rank: int, why: str, maps,
                step) -> dict:
    from .. import dexterity as dx
    from ..dexterity.maps import METRICS as MAPS
    from ..dexterity.maps import drawn_voxels, mesh_colours, metric_map, vertex_values
    from ..workspaces import workspace
    from ..workspaces.output.plots import SlicePicture, sections_layout, write_slice_pictures

    d.mkdir(parents=True, exist_ok=True)
    params = study.space.baseline_values() if r["params"] == BASELINE else r["params"]
    spec = study.space.spec_of(r["params"] if r["params"] != BASELINE else None)
    spec = spec.model_copy(update={"name": f"{study.name}-design-{r['seq']}"})
    atomic.write_text(d / "mechanism.yaml",
                      f"# Design #{r['seq']} of study {study.name} (its evaluation number, "
                      f"the seq column of evaluations.csv): {why} "
                      f"(candidate {r['key']}). Lengths in mm, angles in degrees.\n"
                      + yaml.safe_dump(_plain(to_display(spec)), sort_keys=False,
                                       allow_unicode=True))
    files = ["mechanism.yaml"]
    info: dict = {"number": number, "pareto_rank": rank, "why": why, "seq": r["seq"],
                  "key": r["key"], "params": params, "metrics": r["metrics"],
                  "notes": r.get("notes", {}), "files": files}
    step("simulator and CAD formats")
    _mechanism_formats(d, study, spec.build(), files, info)
    ev = study.evaluation
    if ev.tripod_workspace is not None:
        step("tripod workspace slices")
        _tripod_slices(d, spec.build(), ev.tripod_workspace, files, info)
    mech = spec.build() if (ev.workspace is not None or ev.task is not None
                            or ev.motions is not None) else None
    task = _placed_task(ev.task, r["metrics"])
    overlay = _task_overlay(mech, task, info, ev)
    if ev.motions is not None:
        step("actuator plots over the required motions")
        centre = None if task is None else np.asarray(task.region.centre) + \
            task.region.offset(mech)
        _actuator_plots(d, study, mech, r, info, files, centre)
    if ev.workspace is not None or ev.task is not None:
        force_limit = ev.dexterity.force_limit if ev.dexterity is not None else 150.0
        step("workspace")
        if ev.workspace is not None:
            res = workspace(mech, **ev.request)
            opts = ev.workspace.slice_options()
        else:       # only a task: draw it in the workspace it must be contained in
            h = _task_drawing_resolution(mech, ev.task)
            res = workspace(mech, "dexterous", ev.task.orientations, h)
            opts = {}
            info["task_workspace"] = (f"dexterous workspace over the task's orientation set "
                                      f"({len(ev.task.orientations.rotations())} "
                                      f"orientations), h = {h:g} mm, drawn for the task")
        lay = sections_layout(res, overlay.get("overlay"), **opts)
        info["workspace"] = {k: v for k, v in res.metrics().items()
                             if k in ("kind", "volume_cm3", "volume_error_cm3", "bbox_mm",
                                      "z_range_mm", "centroid_mm", "resolution_mm", "empty",
                                      "method")}
        info["slice_layout"] = lay.as_dict()
        pictures, first = [SlicePicture(d / "slices.png")], None
        if overlay:
            cut = [z for z in lay.levels if overlay["overlay"](z)]
            info["task_slices_mm"] = cut or ("the task lies between the slices: none "
                                             "cuts it (see task.stl)")
        if ev.task is not None:
            step("task mesh")
            _task_meshes(d, mech, task, res, files, info)
        if res.mesh_problem is not None:
            info["mesh"] = res.mesh_problem
        else:
            length = dx.resolve_length(mech, r["metrics"].get("characteristic_length"))
            L = length.length if length.status != "fallback" else None
            mesh = res.mesh()
            values, first = {}, None
            # κ maps for the workspace the study asked for (not for one drawn for a task),
            # evaluated only on the voxels the pictures show (slice layers and surface)
            mapped = maps if L and ev.workspace is not None else ()
            drawn = drawn_voxels(res, lay.levels) if mapped else None
            for name in mapped:
                step(f"{name} map over the {int(drawn.sum())} drawn voxels (of "
                     f"{int(res.occupancy.sum())}) × {len(res.orientations.rotations())} "
                     "orientations")
                mm = metric_map(mech, res, name, L, f_max=force_limit, where=drawn,
                                progress=_every(2.0, lambda f, name=name: step(
                                    f"{name} map {100 * f:.0f} %")))
                values[name] = vertex_values(mesh, mm)
                if first is None:
                    first = mm
            colours = mesh_colours(mesh, first) if first is not None else None
            formats = exporters("mesh", study=True)
            step(f"meshes ({', '.join(f.upper() for f in formats)})")
            for fmt in formats:         # each takes the colours and values it understands
                res.save_mesh(d / f"workspace.{fmt}", colors=colours, values=values)
                files.append(f"workspace.{fmt}")
            info["characteristic_length"] = L
            info["vertex_values"] = {n: {"label": MAPS[n][0], "unit": MAPS[n][1]}
                                     for n in values}
            if first is not None:
                pictures.append(SlicePicture(d / f"{first.metric}_slices.png",
                                             np.where(np.isfinite(first.grid), first.grid,
                                                      np.nan),
                                             f"{first.label}, L = {L:.4g} mm", 110))
        step("slices" + (f" and {first.metric} slices" if first is not None else ""))
        write_slice_pictures(res, pictures, **opts, **overlay)
        files += [pic.path.name for pic in pictures]
    atomic.write_text(d / "design.json", json.dumps(_plain(info), indent=2) + "\n")
    return info


def _tripod_slices(d: Path, mech, plan, files: list, info: dict) -> None:
    """``parasitic_slices.png``: the (θx, θy) sections of a tripod study's workspace grid at
    several heights, coloured by the parasitic |(x, y)| (:func:`~pkmlab.workspaces.tripod.
    plot_tripod`); its grid numbers in ``info["tripod_workspace"]``."""
    from ..workspaces.tripod import plot_tripod, tripod_workspace

    res = tripod_workspace(mech, plan.tilt, z_range=plan.z_range,
                           resolution_z=plan.resolution_z,
                           resolution_angle=plan.resolution_angle, bracket_target=None)
    info["tripod_workspace"] = {k: v for k, v in res.metrics().items()
                                if k not in ("bracket", "volume_bracket_mm_deg2",
                                             "volume_bracket_mm_rad2")}
    if res.empty:
        info["tripod_workspace"]["picture"] = "no feasible grid point: nothing to draw"
        return
    plot_tripod(res, d / "parasitic_slices.png",
                title=f"{mech.family}: feasible (θx, θy) sections, "
                      f"|θx|, |θy| <= {np.degrees(plan.tilt):g}°")
    files.append("parasitic_slices.png")


def _mechanism_formats(d: Path, study: Study, mech, files: list, info: dict) -> None:
    """``mechanism.<suffix>`` in every mechanism format of the exporter registry written by
    studies (MJCF, URDF, joint frames, STEP), with the study's masses; a format whose
    optional package is missing is listed in ``info["formats_skipped"]`` with the reason."""
    from ..export import export_mechanism, mechanism_formats
    from .candidates import mass_model

    mass = mass_model(study)
    for fmt, ex in mechanism_formats(study=True).items():
        ok, why = ex.available()
        if not ok:
            info.setdefault("formats_skipped", {})[fmt] = why
            continue
        for p in export_mechanism(mech, fmt, d, stem="mechanism", mass=mass):
            files.append(p.name)


# ---- requirement outputs (task region, actuators over the motions) ---------------------------


def _placed_task(task, metrics: dict):
    """The task plan with its centre where the evaluation placed it (``task.centre: auto``:
    the ``task_centre_*`` metrics), so that drawings and motions use that centre."""
    if task is None or not any(task.auto):
        return task
    c = [metrics.get(f"task_centre_{a}") for a in "xyz"]
    if any(v is None for v in c):
        return task
    return dataclasses.replace(task, region=dataclasses.replace(
        task.region, centre=tuple(float(v) for v in c)))


def _wider(task, ev) -> str:
    """Why the task's outline on the workspace slices is not a containment picture: its
    orientation set reaches further than the workspace's ('' when it does not)."""
    req = getattr(ev, "request", None) or {}
    oset = req.get("orientations")
    if ev.workspace is None or oset is None:
        return ""
    t, w = task.orientations, oset

    def text(o):
        if o.kind == "box":
            return "±" + ", ±".join(f"{np.degrees(a):.4g}" for a in o.angles) + "° Euler box"
        if o.kind == "tilt-torsion":
            return f"tilt ≤ {np.degrees(o.tilt):.4g}°, torsion ±{np.degrees(o.torsion):.4g}°"
        return "one orientation"

    def reach(o):
        return (np.asarray(o.angles) if o.kind == "box" else
                np.array([o.tilt, o.tilt, o.torsion]) if o.kind == "tilt-torsion" else
                np.zeros(3))

    if t.kind == "fixed" and w.kind != "fixed":
        return ""
    if t.kind != w.kind or np.any(reach(t) > reach(w) + 1e-9):
        return (f"the task's orientations ({text(t)}) reach beyond the workspace drawn "
                f"({text(w)}): the outline is not a containment check on these slices "
                "(task_contained is)")
    return ""


def _task_overlay(mech, task, info: dict, ev=None) -> dict:
    """``slice_figure`` keywords that draw the task's sections in red (none without a task)."""
    if task is None:
        return {}
    from ..requirements.task import task_outline

    info["task"] = {**task.region.describe(), "orientations": task.orientations.describe()}
    wider = _wider(task, ev) if ev is not None else ""
    if wider:
        info["task_drawing_note"] = wider
    return {"overlay": lambda z: task_outline(mech, task.region, z),
            "overlay_label": "the task region (required positions)" + (
                f"\nnote: {wider}" if wider else "")}


def _task_drawing_resolution(mech, task) -> float:
    """Grid spacing of the workspace drawn around a task when the study asks for none:
    about 1/100 of the mechanism's size, never finer than the task's own resolution."""
    return float(max(task.resolution, round(mech.scale / 100, 1)))


def _task_meshes(d: Path, mech, task, res, files: list, info: dict) -> None:
    """``task.stl`` (the task region, mm, base frame) and, with a workspace boundary,
    ``workspace_task.glb`` (both in one scene: workspace grey and translucent, task red)."""
    import trimesh

    from ..requirements.task import task_mesh
    from ..workspaces.output.mesh import write_mesh, write_scene

    V, F = task_mesh(mech, task.region)
    tm = trimesh.Trimesh(V, F, process=False)
    write_mesh(tm, d / "task.stl")
    files.append("task.stl")
    info["task_mesh_bounds_mm"] = tm.bounds.tolist()
    if res.mesh_problem is None:
        write_scene({"workspace": (res.mesh(), (160, 160, 160, 90)),
                     "task": (tm, (220, 30, 30, 255))}, d / "workspace_task.glb")
        files.append("workspace_task.glb")


def _actuator_plots(d: Path, study: Study, mech, r: dict, info: dict, files: list,
                    task_centre=None) -> None:
    """``actuators-<motion>.png`` per required motion (forces or torques, speeds, the
    torque–speed curve, the chosen actuator's limits) and ``actuators.json`` (the numbers
    drawn)."""
    from ..motion.dynamics import inverse_dynamics
    from ..requirements.plots import actuator_figure, actuator_plot_data

    ev = study.evaluation
    body = ev.payload.for_mechanism(mech)
    spec = None
    if ev.actuators is not None:
        choice = study.space.evaluation_choices(None if r["params"] == BASELINE
                                                else r["params"])
        spec = ev.actuators.catalogue[choice.get("actuator", ev.actuators.default)]
    data = {"actuator": None if spec is None else spec.describe(), "motions": []}
    for m in ev.motions.motions(mech, task_centre):
        res = inverse_dynamics(mech, m, body)
        fig = actuator_figure(res, spec)
        name = f"actuators-{m.name}.png"
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=100)
        atomic.write_bytes(d / name, buf.getvalue())
        files.append(name)
        data["motions"].append({**actuator_plot_data(res, spec), "file": name})
    atomic.write_text(d / "actuators.json", json.dumps(_plain(data), indent=2) + "\n")
    files.append("actuators.json")
    info["actuators"] = data
