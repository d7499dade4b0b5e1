"""Workspace commands: workspace, workspaces."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.table import Table

from ..errors import ParameterError
from ..export import exporters
from ..runtime.progress import log_lines
from .common import (
    AllComponentsOpt,
    BoxOpt,
    JointLimitOpt,
    JsonOpt,
    KappaMaxOpt,
    KindOpt,
    LinkDiameterOpt,
    MechArg,
    OrientationOpt,
    ResolutionOpt,
    SamplesOpt,
    SemanticsOpt,
    StrokeOpt,
    TiltOpt,
    TorsionOpt,
    _emit,
    _fail,
    _load,
    _request,
    app,
    out,
)


def _write_workspace(res, out_dir: Path, mesh_formats: list[str], slices: dict) -> list[Path]:
    """Write every output into a scratch folder first, then move it into ``out_dir``;
    ``slices``: the slice layout (``WorkspaceSpec.slice_options()``)."""
    from ..runtime.atomic import staged

    for fmt in exporters("mesh"):
        (out_dir / f"workspace.{fmt}").unlink(missing_ok=True)
    with staged(out_dir) as tmp:
        files = [res.save_npz(tmp / "workspace.npz"), res.save_json(tmp / "workspace.json"),
                 res.plot_slices(tmp / "slices.png", **slices)]
        if res.mesh_problem is None:
            files += [res.save_mesh(tmp / f"workspace.{fmt}") for fmt in mesh_formats]
        elif not res.empty:
            res.notes.append(f"no mesh written: {res.mesh_problem}")
    return [out_dir / f.name for f in files]


def _print_bracket(res, vb) -> None:
    if vb:
        out.print(f"  guaranteed volume bracket [{vb['lower_cm3']:.3f}, {vb['upper_cm3']:.3f}] cm³ "
                  f"over the continuous set (width {100 * vb['relative_width']:.2f} %, "
                  f"{escape(vb['stop_reason'])}, {vb['seconds']:.1f} s of which set-up "
                  f"{vb['setup_seconds']:.1f} s, final cell "
                  f"{vb['final_resolution_mm']:g} mm)")


def _workspace_summary(res, written, as_json: bool, extra: dict | None = None) -> None:
    m = res.metrics()
    m["files"] = [str(p) for p in written]
    if extra:
        m.update(extra)
    if as_json:
        _emit(m)
        return
    title = f"{m['mechanism'] or m['family']}: {m['kind']} workspace"
    if res.empty:
        out.print(f"{escape(title)}: [bold]empty[/] — no position satisfies the constraints "
                  "for this orientation set (no mesh written).")
    else:
        out.print(f"{escape(title)}: volume {m['volume_cm3']:.3f} ± "
                  f"{m['volume_error_cm3']:.3f} cm³ ({escape(m['method'])})")
        z0, z1 = m["z_range_mm"]
        c = m["centroid_mm"]
        out.print(f"  z range {z0:.2f} … {z1:.2f} mm, centroid ({c[0]:.2f}, {c[1]:.2f}, "
                  f"{c[2]:.2f}) mm, {m['components']} component(s)")
        box, cyl = (extra or {}).get("inscribed_box"), (extra or {}).get("inscribed_cylinder")
        if box:
            sx, sy, sz = box["size_mm"]
            cx, cy, cz = box["centre_mm"]
            out.print(f"  inscribed box {sx:.2f} × {sy:.2f} × {sz:.2f} mm centred at ({cx:.2f}, "
                      f"{cy:.2f}, {cz:.2f}) mm: {box['volume_cm3']:.3f} cm³, "
                      f"{box['verified_samples']} points verified")
        if cyl:
            cx, cy = cyl["centre_xy_mm"]
            z0, z1 = cyl["z_range_mm"]
            out.print(f"  inscribed vertical cylinder r = {cyl['radius_mm']:.2f} mm at ({cx:.2f}, "
                      f"{cy:.2f}) mm, z {z0:.2f} … {z1:.2f} mm: {cyl['volume_cm3']:.3f} cm³, "
                      f"{cyl['verified_samples']} points verified")
    _print_bracket(res, (extra or {}).get("volume_bracket"))
    if extra and extra.get("orientation_convergence"):
        out.print("  orientation sampling convergence (volume in cm³):")
        for row in extra["orientation_convergence"]:
            ref = row.get("refined_volume_mm3")
            out.print(f"    n = {row['samples']:2d} ({row['orientations']:5d} orientations): "
                      f"{row['volume_mm3'] / 1e3:.4f}"
                      + (f"   refined {ref / 1e3:.4f}" if ref is not None else ""))
    for note in m["notes"]:
        out.print(f"  note: {escape(note)}")
    out.print(f"  orientations: {m['orientations']['count']}, grid {m['grid']}, "
              f"{m['timings_s']['total_s'] * 1e3:.1f} ms")
    for p in written:
        out.print(f"  wrote {escape(str(p))}")


@app.command()
def workspace(
    mech_file: MechArg,
    kind: KindOpt = "constant",
    orientation: OrientationOpt = None,
    box: BoxOpt = None,
    semantics: SemanticsOpt = "simultaneous",
    tilt: TiltOpt = None,
    torsion: TorsionOpt = "0",
    samples: SamplesOpt = 7,
    resolution: ResolutionOpt = "2.5",
    link_diameter: LinkDiameterOpt = None,
    joint_limit: JointLimitOpt = None,
    kappa_max: KappaMaxOpt = None,
    all_components: AllComponentsOpt = False,
    stroke: StrokeOpt = None,
    inscribed: Annotated[bool, typer.Option(
        "--inscribed", help="also find the largest inscribed box and vertical cylinder")]
    = False,
    refine: Annotated[bool, typer.Option(
        "--refine", help="dexterous: search each leg's extremes over the continuous set")]
    = False,
    convergence: Annotated[bool, typer.Option(
        "--convergence", help="also report the volume for 3, 5, 7, 9, 13, 17 samples")]
    = False,
    bracket: Annotated[bool, typer.Option(
        "--bracket", help="also bracket the volume over the continuous orientation set and "
                          "positions: guaranteed [lower, upper] (psu6, ups6; luzi3, rss6 on "
                          "position x orientation cells; stroke only)")]
    = False,
    bracket_budget: Annotated[float, typer.Option(
        help="--bracket: wall-time budget in s, counted after loading the kernels (the "
             "first refinement step always completes; later steps that would pass the "
             "budget are abandoned, about 0.5 s tolerance; the bracket of the last completed "
             "step is reported)")] = 20.0,
    bracket_target: Annotated[float, typer.Option(
        help="--bracket: relative width to reach, (upper - lower) / upper")] = 0.01,
    mesh: Annotated[str, typer.Option(
        help="mesh formats, comma-separated, of: " + "; ".join(
            f"{k} ({e.description})" for k, e in exporters("mesh").items()))] = "stl",
    slice_layout: Annotated[str, typer.Option(
        help="slices.png: auto (window and spacing scaled to the workspace) | paper "
             "(Hopkins & Williams: 152.4 mm every 12.7 mm)")] = "auto",
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")]
    = Path("results/workspace"),
    as_json: JsonOpt = False,
) -> None:
    """Workspace volume, slices (PNG), boundary mesh (STL) and arrays (npz) of a mechanism.

    Writes workspace.npz, workspace.json, slices.png and workspace.stl into --out.
    """
    from ..workspaces import workspace as compute

    mech = _load(mech_file)
    spec, req = _request(kind, orientation, box, semantics, tilt, torsion, samples, resolution,
                         link_diameter, joint_limit, kappa_max, all_components, stroke,
                         slice_layout)
    formats = [f.strip().lower() for f in mesh.split(",") if f.strip()]
    known = list(exporters("mesh"))
    if not formats or any(f not in known for f in formats):
        _fail(ParameterError("--mesh", f"comma-separated formats from {known}", mesh))
    try:
        with log_lines():                 # the time estimate of a long grid, before it runs
            res = compute(mech, **req, refine=refine)
        extra = {}
        if inscribed and not res.empty:
            extra = {"inscribed_box": res.inscribed_box().as_dict(),
                     "inscribed_cylinder": res.inscribed_cylinder().as_dict()}
        if convergence and req["kind"] != "constant":
            from ..workspaces.engine import orientation_convergence

            extra["orientation_convergence"] = orientation_convergence(mech, **req)
        if bracket:
            from ..workspaces.bracket.columns import volume_bracket

            if not (bracket_budget > 0):
                raise ParameterError("--bracket-budget", "a time > 0 s", bracket_budget)
            if not (0 < bracket_target < 1):
                raise ParameterError("--bracket-target", "a fraction in (0, 1)", bracket_target)
            extra["volume_bracket"] = volume_bracket(
                mech, **req, target=bracket_target, budget_s=bracket_budget).describe()
    except ParameterError as exc:
        _fail(exc)
    written = _write_workspace(res, out_dir, formats, spec.slice_options())
    if extra:
        (out_dir / "workspace.json").write_text(
            json.dumps({**res.metrics(), **extra}, indent=2) + "\n")
    _workspace_summary(res, written, as_json, extra)


@app.command()
def workspaces(
    study_file: Annotated[Path, typer.Argument(help="Workspace study YAML file.")],
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")] = Path("results"),
    refine: Annotated[bool, typer.Option(help="refine dexterous leg extremes")] = True,
    as_json: JsonOpt = False,
) -> None:
    """Run every workspace request of a study file (e.g. studies/papers/*.yaml).

    Each request writes its npz, json, slices.png and mesh into OUT/<study>/<name>/.
    """
    from ..config import load_workspace_study
    from ..workspaces import workspace as compute

    try:
        spec, mech, requests = load_workspace_study(study_file)
    except ParameterError as exc:
        _fail(exc)
    rows = {}
    for name, req in requests.items():
        res = compute(mech, **req, refine=refine and req["kind"] == "dexterous")
        ws = spec.workspaces[name]
        written = _write_workspace(res, out_dir / spec.study / name, ["stl"],
                                   ws.slice_options())
        m = res.metrics()
        m["files"] = [str(p) for p in written]
        rows[name] = m
    if as_json:
        _emit({"study": spec.study, "mechanism": mech.name, "workspaces": rows})
        return
    table = Table(title=escape(f"{spec.study}: {mech.name}"))
    for col in ("workspace", "kind", "orientations", "volume cm³", "z range mm", "components"):
        table.add_column(col)
    for name, m in rows.items():
        o = m["orientations"]
        oset = o["kind"] if o["kind"] == "fixed" else (
            f"±{o['half_ranges_deg'][0]:g}° {o['semantics']}" if o["kind"] == "box"
            else f"tilt {o['tilt_deg']:g}°, torsion ±{o['torsion_deg']:g}°")
        z = "—" if m["empty"] else f"{m['z_range_mm'][0]:.1f} … {m['z_range_mm'][1]:.1f}"
        vol = "empty" if m["empty"] else f"{m['volume_cm3']:.2f} ± {m['volume_error_cm3']:.2f}"
        table.add_row(escape(name), m["kind"], oset, vol, z, str(m["components"]))
    out.print(table)
    out.print(f"outputs under {escape(str(out_dir / spec.study))}/<workspace>/")


# ---- design studies ------------------------------------------------------------------------------

