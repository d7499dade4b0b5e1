"""Command-line interface (typer). Speaks mm and degrees; the library speaks mm and radians.

JSON output (``--json``) uses these keys throughout:

* a pose is ``{"x": mm, "y": mm, "z": mm, "theta_x": deg, "theta_y": deg, "theta_z": deg}``
  (Z-Y-X Euler angles, R = Rz·Ry·Rx, of the tool frame in the base frame);
* actuator values are ``{"<name>": mm, ...}`` keyed by the family's actuator names
  (``q1``..``q6``, or ``l11``..``l32`` for ``luzi3``).

Errors in the input print one line naming the field, the allowed values and the value given,
and exit with status 2.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from .config import load_mechanism
from .errors import ParameterError
from .mechanisms import Mechanism
from .units import parse_angle, parse_length

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="pkmlab: design-optimisation workbench for parallel manipulators.")
out = Console()
err = Console(stderr=True)

POSE_KEYS = ("x", "y", "z", "theta_x", "theta_y", "theta_z")
JSON_HELP = ("Print JSON. Pose keys: x, y, z (mm), theta_x, theta_y, theta_z (deg, Z-Y-X Euler); "
             "actuators: {name: mm} with the family's actuator names.")


def _fail(exc: Exception) -> None:
    err.print(f"[bold red]error[/]: {exc}", highlight=False)
    raise typer.Exit(code=2)


def _load(path: Path) -> Mechanism:
    try:
        return load_mechanism(path)
    except ParameterError as exc:
        _fail(exc)
        raise  # unreachable


def _parse_csv(text: str, field: str, n: int) -> list[str]:
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != n or any(p == "" for p in parts):
        _fail(ParameterError(field, f"{n} comma-separated values", text))
    return parts


def _parse_pose(text: str, field: str = "--pose") -> np.ndarray:
    parts = _parse_csv(text, field, 6)
    try:
        lin = [parse_length(p, f"{field}[{i}]") for i, p in enumerate(parts[:3])]
        ang = [parse_angle(p, f"{field}[{i + 3}]") for i, p in enumerate(parts[3:])]
    except ParameterError as exc:
        _fail(exc)
    return np.array(lin + ang)


def _pose_json(pose: np.ndarray) -> dict:
    vals = list(pose[:3]) + [math.degrees(a) for a in pose[3:]]
    return {k: (None if not np.isfinite(v) else float(v)) for k, v in zip(POSE_KEYS, vals)}


def _act_json(mech: Mechanism, q: np.ndarray) -> dict:
    return {n: (None if not np.isfinite(v) else float(v)) for n, v in zip(mech.actuator_names, q)}


def _pose_str(pose: np.ndarray) -> str:
    p = _pose_json(pose)
    return (f"x={p['x']:.4f} y={p['y']:.4f} z={p['z']:.4f} mm, θx={p['theta_x']:.4f} "
            f"θy={p['theta_y']:.4f} θz={p['theta_z']:.4f} deg") if None not in p.values() \
        else "undefined"


def _emit(data: dict) -> None:
    sys.stdout.write(json.dumps(data, indent=2) + "\n")


MechArg = Annotated[Path, typer.Argument(help="Mechanism YAML file.")]
JsonOpt = Annotated[bool, typer.Option("--json", help=JSON_HELP)]


@app.command()
def inspect(mech_file: MechArg, as_json: JsonOpt = False) -> None:
    """Geometry, nominal pose, its actuator values and the Jacobian condition number."""
    mech = _load(mech_file)
    nominal = mech.nominal_pose
    ik = mech.inverse(nominal)
    J = mech.jacobian(nominal)[0]
    cond = float(np.linalg.cond(J)) if np.all(np.isfinite(J)) else None
    data = {
        "geometry": mech.describe(),
        "nominal_pose": _pose_json(nominal),
        "nominal_actuators": _act_json(mech, ik.q[0]),
        "nominal_valid": bool(ik.valid[0]),
        "nominal_reason": str(ik.reason_text[0]),
        "actuator_limits": {n: list(map(float, lim))
                            for n, lim in zip(mech.actuator_names, mech.actuator_limits)},
        "jacobian_condition_number": cond,
    }
    if as_json:
        _emit(data)
        return
    out.print(f"[bold]{mech.name or mech_file.stem}[/] — family [cyan]{mech.family}[/]")
    g = mech.describe()
    for key, val in g.items():
        if key.endswith("points_mm") or key in ("family", "name"):
            continue
        out.print(f"  {key}: {val}")
    pts = [k for k in g if k.endswith("points_mm")]
    table = Table("joint", *[k.removesuffix("_mm") + " (mm)" for k in pts])
    for i in range(max(len(g[k]) for k in pts)):
        table.add_row(str(i + 1), *[(" ".join(f"{c:9.3f}" for c in g[k][i])
                                     if i < len(g[k]) else "") for k in pts])
    out.print(table)
    out.print(f"nominal pose: {_pose_str(nominal)}")
    out.print("nominal actuators (mm): " + ", ".join(
        f"{n}={v:.4f}" for n, v in zip(mech.actuator_names, ik.q[0]))
        + escape(f"  [{ik.reason_text[0]}]"))
    out.print(f"Jacobian condition number at nominal (unscaled, mm and rad): {cond:.4g}"
              if cond is not None else "Jacobian undefined at nominal")


@app.command()
def ik(mech_file: MechArg,
       pose: Annotated[str, typer.Option(help='Tool pose "x,y,z,θx,θy,θz" in mm and deg '
                                              '(units may be given, e.g. "2 in").')],
       as_json: JsonOpt = False) -> None:
    """Inverse kinematics: actuator values of one pose, with validity and reason."""
    mech = _load(mech_file)
    X = _parse_pose(pose)
    res = mech.inverse(X)
    J = mech.jacobian(X)[0]
    cond = float(np.linalg.cond(J)) if np.all(np.isfinite(J)) else None
    legs = [str(res.reason_text[0])] if res.valid[0] else [
        f"{n}: {s}" for n, s in zip(mech.actuator_names,
                                    [mech_status(c) for c in res.leg_status[0]]) if s != "ok"]
    data = {"pose": _pose_json(X), "actuators": _act_json(mech, res.q[0]),
            "valid": bool(res.valid[0]), "reason": str(res.reason_text[0]),
            "leg_status": {n: mech_status(c) for n, c in zip(mech.actuator_names,
                                                              res.leg_status[0])},
            "jacobian_condition_number": cond}
    if as_json:
        _emit(data)
        return
    out.print(f"pose: {_pose_str(X)}")
    out.print("actuators (mm): " + ", ".join(f"{n}={v:.6f}" for n, v in
                                            zip(mech.actuator_names, res.q[0])))
    out.print(("[green]valid[/]" if res.valid[0] else "[red]invalid[/]") + ": "
              + escape("; ".join(legs)))


def mech_status(code: int) -> str:
    from .mechanisms import LEG_STATUS

    return LEG_STATUS[int(code)]


@app.command()
def fk(mech_file: MechArg,
       actuators: Annotated[str, typer.Option(help='Actuator values "q1,…,q6" in mm.')],
       all_modes: Annotated[bool, typer.Option("--all", help="List every assembly mode found "
                                               "by the multi-start search.")] = False,
       guess: Annotated[str | None, typer.Option(help='Start pose "x,y,z,θx,θy,θz" (mm, deg); '
                                                 'default the nominal pose.')] = None,
       starts: Annotated[int, typer.Option(help="Random starts for --all.", min=1)] = 1500,
       seed: Annotated[int, typer.Option(help="Seed of the --all starts.")] = 0,
       as_json: JsonOpt = False) -> None:
    """Forward kinematics (Newton from the nominal pose or --guess); --all for every mode."""
    mech = _load(mech_file)
    parts = _parse_csv(actuators, "--actuators", 6)
    try:
        q = np.array([parse_length(p, f"--actuators[{i}]") for i, p in enumerate(parts)])
    except ParameterError as exc:
        _fail(exc)
    g = None if guess is None else _parse_pose(guess, "--guess")
    res = mech.forward(q, g)
    data = {"actuators": _act_json(mech, q), "pose": _pose_json(res.pose[0]),
            "converged": bool(res.converged[0]), "residual_mm": float(res.residual[0]),
            "iterations": int(res.iterations[0]), "status": str(res.status[0])}
    if all_modes:
        modes = mech.assembly_modes(q, starts=starts, seed=seed)
        data["assembly_modes"] = [
            {"pose": _pose_json(p), "residual_mm": float(r), "working_mode": bool(w),
             "distance_to_nominal": float(d)}
            for p, r, w, d in zip(modes.pose, modes.residual, modes.working_mode, modes.distance)]
        data["starts"] = modes.starts
    if as_json:
        _emit(data)
        return
    out.print(f"forward kinematics: [{'green' if res.converged[0] else 'red'}]"
              f"{res.status[0]}[/] after {res.iterations[0]} iterations, "
              f"residual {res.residual[0]:.3g} mm")
    out.print(f"pose: {_pose_str(res.pose[0])}")
    if all_modes:
        table = Table("#", "x (mm)", "y (mm)", "z (mm)", "θx (deg)", "θy (deg)", "θz (deg)",
                      "residual (mm)", "working mode",
                      title=f"{len(modes.residual)} assembly modes from {modes.starts} starts")
        for i, (p, r, w) in enumerate(zip(modes.pose, modes.residual, modes.working_mode)):
            pj = _pose_json(p)
            table.add_row(str(i + 1), *[f"{pj[k]:.4f}" for k in POSE_KEYS], f"{r:.2e}",
                          "yes" if w else "no")
        out.print(table)


@app.command()
def demo(folder: Annotated[Path, typer.Argument(help="Folder of mechanism YAML files.")]
         = Path("studies/mechanisms")) -> None:
    """Kinematics demo on the shipped paper geometries: inspect, IK, FK round trip, modes."""
    files = sorted(folder.glob("*.yaml"))
    if not files:
        _fail(ParameterError("folder", "a folder containing mechanism YAML files", str(folder)))
    for f in files:
        out.rule(f"[bold]{f.name}")
        inspect(f)
        mech = _load(f)
        X = mech.nominal_pose + np.array([10.0, -5.0, 8.0, *np.radians([5.0, -4.0, 10.0])])
        res = mech.inverse(X)
        out.print(f"IK of a displaced pose {_pose_str(X)}:")
        out.print("  " + ", ".join(f"{n}={v:.4f}" for n, v in zip(mech.actuator_names,
                                                                   res.q[0]))
                  + escape(f" mm [{res.reason_text[0]}]"))
        back = mech.forward(res.q[0])
        errp = np.abs(back.pose[0] - X)
        out.print(f"FK back from the nominal pose: {back.status[0]} in {back.iterations[0]} "
                  f"iterations; error {errp[:3].max():.2e} mm, {errp[3:].max():.2e} rad")
        modes = mech.assembly_modes(res.q[0], starts=800)
        out.print(f"assembly modes for these actuator values: {len(modes.residual)} found from "
                  f"{modes.starts} starts ({int(modes.working_mode.sum())} in the working mode)")
    out.rule()
    out.print("Demo done. Try: pkmlab ik studies/mechanisms/hopkins-williams-6psu.yaml "
              '--pose "0,0,300,10,0,0"')


# ---- workspace ----------------------------------------------------------------------------------


def _csv_list(text: str | None, field: str, n: int) -> list[str] | None:
    return None if text is None else _parse_csv(text, field, n)


def _write_workspace(res, out_dir: Path, mesh_formats: list[str], window: float,
                     spacing: float) -> list[Path]:
    """Write every output into a scratch folder first, then move it into ``out_dir``."""
    import shutil
    import tempfile

    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    with tempfile.TemporaryDirectory(dir=out_dir, prefix=".partial-") as tmp:
        tmp = Path(tmp)
        files = [res.save_npz(tmp / "workspace.npz"), res.save_json(tmp / "workspace.json"),
                 res.plot_slices(tmp / "slices.png", window=window, spacing=spacing)]
        if not res.empty:
            files += [res.save_mesh(tmp / f"workspace.{fmt}") for fmt in mesh_formats]
        for stale in ("workspace.stl", "workspace.ply", "workspace.glb"):
            (out_dir / stale).unlink(missing_ok=True)
        for f in files:
            shutil.move(str(f), out_dir / f.name)
            written.append(out_dir / f.name)
    return written


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
    kind: Annotated[str, typer.Option(help="constant | reachable | dexterous")] = "constant",
    orientation: Annotated[str | None, typer.Option(
        help='constant kind: "θx,θy,θz" relative to nominal (deg or with units)')] = None,
    box: Annotated[str | None, typer.Option(help='Euler half-ranges "a,b,c" (deg)')] = None,
    semantics: Annotated[str, typer.Option(help="simultaneous | single-axis")]
    = "simultaneous",
    tilt: Annotated[str | None, typer.Option(help="tilt-and-torsion set: largest tilt")] = None,
    torsion: Annotated[str, typer.Option(help="tilt-and-torsion set: torsion half-range")]
    = "0",
    samples: Annotated[int, typer.Option(help="orientation samples per angle")] = 7,
    resolution: Annotated[str, typer.Option(help="grid spacing (mm or with units)")] = "2.5",
    link_diameter: Annotated[str | None, typer.Option(help="leg interference diameter")]
    = None,
    joint_limit: Annotated[str | None, typer.Option(
        help='passive joint cone half-angles "base,platform" (deg)')] = None,
    kappa_max: Annotated[float | None, typer.Option(help="largest condition number")] = None,
    all_components: Annotated[bool, typer.Option(
        "--all-components", help="keep regions not connected to the nominal pose")] = False,
    inscribed: Annotated[bool, typer.Option(
        "--inscribed", help="also find the largest inscribed box and vertical cylinder")]
    = False,
    refine: Annotated[bool, typer.Option(
        "--refine", help="dexterous: search each leg's extremes over the continuous set")]
    = False,
    convergence: Annotated[bool, typer.Option(
        "--convergence", help="also report the volume for 3, 5, 7, 9, 13, 17 samples")]
    = False,
    mesh: Annotated[str, typer.Option(help="mesh formats, comma-separated: stl,ply,glb")]
    = "stl",
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")]
    = Path("results/workspace"),
    as_json: JsonOpt = False,
) -> None:
    """Workspace volume, slices (PNG), boundary mesh (STL) and arrays (npz) of a mechanism.

    Writes workspace.npz, workspace.json, slices.png and workspace.stl into --out.
    """
    from .config import workspace_spec
    from .workspaces import workspace as compute

    mech = _load(mech_file)
    data: dict = {"kind": kind, "semantics": semantics, "samples": samples,
                  "resolution": resolution, "torsion": torsion,
                  "constraints": {"connected": not all_components}}
    for key, text in (("orientation", orientation), ("box", box)):
        vals = _csv_list(text, f"--{key}", 3)
        if vals is not None:
            data[key] = vals
    if tilt is not None:
        data["tilt"] = tilt
    if link_diameter is not None:
        data["constraints"]["link_diameter"] = link_diameter
    if kappa_max is not None:
        data["constraints"]["kappa_max"] = kappa_max
    jl = _csv_list(joint_limit, "--joint-limit", 2)
    if jl is not None:
        data["constraints"]["joint_limits"] = {"base": jl[0], "platform": jl[1]}
    formats = [f.strip().lower() for f in mesh.split(",") if f.strip()]
    bad = [f for f in formats if f not in ("stl", "ply", "glb")]
    if bad or not formats:
        _fail(ParameterError("--mesh", "comma-separated formats from ['stl', 'ply', 'glb']",
                             mesh))
    try:
        spec = workspace_spec(data, prefix="--")
        req = spec.build()
        res = compute(mech, **req, refine=refine)
        extra = {}
        if inscribed and not res.empty:
            extra = {"inscribed_box": res.inscribed_box().as_dict(),
                     "inscribed_cylinder": res.inscribed_cylinder().as_dict()}
        if convergence and req["kind"] != "constant":
            from .workspaces.engine import orientation_convergence

            extra["orientation_convergence"] = orientation_convergence(mech, **req)
    except ParameterError as exc:
        _fail(exc)
    written = _write_workspace(res, out_dir, formats, spec.slice_window, spec.slice_spacing)
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
    from .config import load_workspace_study
    from .workspaces import workspace as compute

    try:
        spec, mech, requests = load_workspace_study(study_file)
    except ParameterError as exc:
        _fail(exc)
    rows = {}
    for name, req in requests.items():
        res = compute(mech, **req, refine=refine and req["kind"] == "dexterous")
        ws = spec.workspaces[name]
        written = _write_workspace(res, out_dir / spec.study / name, ["stl"], ws.slice_window,
                                   ws.slice_spacing)
        m = res.metrics()
        m["files"] = [str(p) for p in written]
        rows[name] = m
    if as_json:
        _emit({"study": spec.study, "mechanism": mech.name, "workspaces": rows})
        return
    table = Table(title=f"{spec.study}: {mech.name}")
    for col in ("workspace", "kind", "orientations", "volume cm³", "z range mm", "components"):
        table.add_column(col)
    for name, m in rows.items():
        o = m["orientations"]
        oset = o["kind"] if o["kind"] == "fixed" else (
            f"±{o['half_ranges_deg'][0]:g}° {o['semantics']}" if o["kind"] == "box"
            else f"tilt {o['tilt_deg']:g}°, torsion ±{o['torsion_deg']:g}°")
        z = "—" if m["empty"] else f"{m['z_range_mm'][0]:.1f} … {m['z_range_mm'][1]:.1f}"
        vol = "empty" if m["empty"] else f"{m['volume_cm3']:.2f} ± {m['volume_error_cm3']:.2f}"
        table.add_row(name, m["kind"], oset, vol, z, str(m["components"]))
    out.print(table)
    out.print(f"outputs under {escape(str(out_dir / spec.study))}/<workspace>/")


def main() -> None:
    app()


if __name__ == "__main__":
    main()
