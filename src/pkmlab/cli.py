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

import click
import numpy as np
import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from .config import load_mechanism
from .errors import ParameterError
from .mechanisms import Mechanism
from .units import parse_angle, parse_length

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
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


def _write_workspace(res, out_dir: Path, mesh_formats: list[str], slices: dict) -> list[Path]:
    """Write every output into a scratch folder first, then move it into ``out_dir``;
    ``slices``: the slice layout (``WorkspaceSpec.slice_options()``)."""
    from .atomic import staged

    for stale in ("workspace.stl", "workspace.ply", "workspace.glb"):
        (out_dir / stale).unlink(missing_ok=True)
    with staged(out_dir) as tmp:
        files = [res.save_npz(tmp / "workspace.npz"), res.save_json(tmp / "workspace.json"),
                 res.plot_slices(tmp / "slices.png", **slices)]
        if not res.empty:
            files += [res.save_mesh(tmp / f"workspace.{fmt}") for fmt in mesh_formats]
    return [out_dir / f.name for f in files]


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


KindOpt = Annotated[str, typer.Option(help="constant | reachable | dexterous")]
OrientationOpt = Annotated[str | None, typer.Option(
    help='constant kind: "θx,θy,θz" relative to nominal (deg or with units)')]
BoxOpt = Annotated[str | None, typer.Option(help='Euler half-ranges "a,b,c" (deg)')]
SemanticsOpt = Annotated[str, typer.Option(help="simultaneous | single-axis")]
TiltOpt = Annotated[str | None, typer.Option(help="tilt-and-torsion set: largest tilt")]
TorsionOpt = Annotated[str, typer.Option(help="tilt-and-torsion set: torsion half-range")]
SamplesOpt = Annotated[int, typer.Option(help="orientation samples per angle")]
ResolutionOpt = Annotated[str, typer.Option(help="grid spacing (mm or with units)")]
LinkDiameterOpt = Annotated[str | None, typer.Option(help="leg interference diameter")]
JointLimitOpt = Annotated[str | None, typer.Option(
    help='passive joint cone half-angles "base,platform" (deg)')]
KappaMaxOpt = Annotated[float | None, typer.Option(help="largest condition number")]
AllComponentsOpt = Annotated[bool, typer.Option(
    "--all-components", help="keep regions not connected to the nominal pose")]
StrokeOpt = Annotated[str | None, typer.Option(
    help='evaluate with another actuator window "min,max" (mm or with units)')]


def _request(kind, orientation, box, semantics, tilt, torsion, samples, resolution,
             link_diameter, joint_limit, kappa_max, all_components, stroke=None,
             slice_layout="auto"):
    """CLI workspace options → validated request (the config module does the validation)."""
    from .config import workspace_spec
    from .workspaces.slicing import LAYOUTS

    if slice_layout not in LAYOUTS:
        _fail(ParameterError("--slice-layout", f"one of {list(LAYOUTS)}", slice_layout))
    data: dict = {"kind": kind, "semantics": semantics, "samples": samples,
                  "resolution": resolution, "torsion": torsion, "slice_layout": slice_layout,
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
    win = _csv_list(stroke, "--stroke", 2)
    if win is not None:
        data["constraints"]["stroke"] = win
    try:
        spec = workspace_spec(data, prefix="--")
    except ParameterError as exc:
        _fail(exc)
    return spec, spec.build()


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
    mesh: Annotated[str, typer.Option(
        help="mesh formats, comma-separated: stl (mm), ply (mm), glb (m, y up)")] = "stl",
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
    from .workspaces import workspace as compute

    mech = _load(mech_file)
    spec, req = _request(kind, orientation, box, semantics, tilt, torsion, samples, resolution,
                         link_diameter, joint_limit, kappa_max, all_components, stroke,
                         slice_layout)
    formats = [f.strip().lower() for f in mesh.split(",") if f.strip()]
    bad = [f for f in formats if f not in ("stl", "ply", "glb")]
    if bad or not formats:
        _fail(ParameterError("--mesh", "comma-separated formats from ['stl', 'ply', 'glb']",
                             mesh))
    try:
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
    written = _write_workspace(res, out_dir, formats, spec.slice_options())
    if extra:
        (out_dir / "workspace.json").write_text(
            json.dumps({**res.metrics(), **extra}, indent=2) + "\n")
    _workspace_summary(res, written, as_json, extra)


def _finite_or_none(v):
    v = float(v)
    return v if math.isfinite(v) else None


@app.command()
def dexterity(
    mech_file: MechArg,
    kind: KindOpt = "dexterous",
    orientation: OrientationOpt = None,
    box: BoxOpt = "15,15,15",
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
    metric: Annotated[str, typer.Option(help="map: kappa | lci | force | stiffness")]
    = "kappa",
    characteristic_length: Annotated[str, typer.Option(
        help="L for κ: a length, or 'auto' (Angeles: the L minimising κ at nominal)")]
    = "auto",
    well_conditioned: Annotated[float, typer.Option(
        help="κ bound of the well-conditioned sub-workspace")] = 10.0,
    force_limit: Annotated[float, typer.Option(help="actuator force limit (N)")] = 150.0,
    force_required: Annotated[float, typer.Option(
        help="force (N) the platform must hold in every direction: its sub-workspace")]
    = 100.0,
    actuator_stiffness: Annotated[float, typer.Option(help="actuator stiffness (N/mm)")]
    = 1.0e4,
    gci_samples: Annotated[int, typer.Option(help="Monte-Carlo GCI samples")] = 2000,
    seed: Annotated[int, typer.Option(help="Monte-Carlo seed")] = 0,
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")]
    = Path("results/dexterity"),
    as_json: JsonOpt = False,
) -> None:
    """Conditioning, force and stiffness at the nominal pose and over a workspace.

    Writes dexterity.json, <metric>_slices.png and workspace_<metric>.ply/.glb (the workspace
    mesh coloured by the metric's worst value over the orientation set) into --out.
    """
    import shutil
    import tempfile

    from . import dexterity as dx
    from .dexterity.maps import METRICS, mesh_colours, metric_map
    from .workspaces import workspace as compute
    from .workspaces.plots import slice_figure

    mech = _load(mech_file)
    spec, req = _request(kind, orientation, box, semantics, tilt, torsion, samples, resolution,
                         link_diameter, joint_limit, kappa_max, all_components, stroke)
    if metric not in METRICS:
        _fail(ParameterError("--metric", f"one of {list(METRICS)}", metric))
    if characteristic_length.strip().lower() == "auto":
        cl = dx.characteristic_length(mech)
        L, L_source = cl.length, "Angeles (minimises κ at the nominal pose)"
    else:
        try:
            L = parse_length(characteristic_length, "--characteristic-length")
        except ParameterError as exc:
            _fail(exc)
        if not L > 0:
            _fail(ParameterError("--characteristic-length", "a length > 0 mm or 'auto'",
                                 characteristic_length))
        L_source = "given"
    for name, v, lo in (("--force-limit", force_limit, 0), ("--actuator-stiffness",
                                                              actuator_stiffness, 0),
                        ("--well-conditioned", well_conditioned, 1),
                        ("--force-required", force_required, 0)):
        if not (math.isfinite(v) and v > lo):
            _fail(ParameterError(name, f"a number > {lo}", v))
    if not 10 <= gci_samples <= 10_000_000:
        _fail(ParameterError("--gci-samples", "an integer in [10, 10000000]", gci_samples))

    res = compute(mech, **req)
    mech = res.mechanism          # carries a --stroke window, if one was given
    # nominal pose
    X = mech.nominal_pose
    J = mech.jacobian(X)
    flags = dx.singularity_flags(mech, X)
    wt, wr = dx.manipulability(J)
    st = dx.stiffness(J, actuator_stiffness)
    nominal = {
        "pose": _pose_json(X),
        "characteristic_length_mm": L, "characteristic_length_source": L_source,
        "kappa": _finite_or_none(dx.condition_number(J, L)[0]),
        "lci": float(dx.lci(J, L)[0]),
        "sigma_min": _finite_or_none(dx.smallest_singular_value(J, L)[0]),
        "manipulability_translational": _finite_or_none(wt[0]),
        "manipulability_rotational": _finite_or_none(wr[0]),
        "singularity": str(flags.kind[0]),
        "force_all_directions_N": _finite_or_none(dx.max_force_all_directions(J, force_limit)[0]),
        "moment_all_directions_Nmm": _finite_or_none(
            dx.max_moment_all_directions(J, force_limit)[0]),
        "stiffness_translational_min_N_per_mm": _finite_or_none(st.translational_min[0]),
        "stiffness_rotational_min_Nmm_per_rad": _finite_or_none(st.rotational_min[0]),
    }
    agg: dict = {"workspace_volume_cm3": res.volume / 1e3, "empty": res.empty}
    mmap = None
    if not res.empty:
        g = dx.kappa_grid(mech, res, L)
        ks = dx.kappa_statistics(g.kappa[g.valid])
        grid_gci = dx.gci_grid(mech, res, L)
        mc = dx.gci_monte_carlo(mech, res, L, samples=gci_samples, seed=seed)
        wc = dx.well_conditioned_volume(mech, res, well_conditioned, L)
        mmap = metric_map(mech, res, metric, L, force_limit, actuator_stiffness)
        fmap = mmap if metric == "force" else metric_map(mech, res, "force", L, force_limit)
        agg.update({
            "gci_grid": grid_gci.gci, "gci_monte_carlo": mc.gci,
            "gci_monte_carlo_std_error": mc.std_error, "gci_samples": mc.samples,
            "gci_rejected": mc.rejected,
            "kappa": {"min": ks.min, "mean": ks.mean, "p5": ks.p5, "p50": ks.p50,
                      "p95": ks.p95, "max": _finite_or_none(ks.max)},
            "well_conditioned_kappa_max": well_conditioned,
            "well_conditioned_volume_cm3": wc.volume / 1e3,
            "well_conditioned_fraction": wc.fraction,
            "force_all_directions_N": {
                "min": float(fmap.values.min()), "mean": float(fmap.values.mean()),
                "p5": float(np.percentile(fmap.values, 5)),
                "p50": float(np.percentile(fmap.values, 50)),
                "max": float(fmap.values.max())},
            "force_required_N": force_required,
            "force_capable_volume_cm3": float(np.mean(fmap.values >= force_required))
            * res.volume / 1e3,
        })
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    with tempfile.TemporaryDirectory(dir=out_dir, prefix=".partial-") as tmp:
        tmp = Path(tmp)
        report = {"mechanism": mech.name, "workspace": res.metrics(), "nominal": nominal,
                  "aggregates": agg, "metric": metric}
        files = [tmp / "dexterity.json"]
        files[0].write_text(json.dumps(report, indent=2, default=float) + "\n")
        if mmap is not None:
            import matplotlib.pyplot as plt

            vals = np.where(np.isfinite(mmap.grid), mmap.grid, np.nan)
            fig = slice_figure(res, window=spec.slice_window, spacing=spec.slice_spacing,
                               values=vals, label=mmap.label)
            files.append(tmp / f"{metric}_slices.png")
            fig.savefig(files[-1], dpi=120)
            plt.close(fig)
            m = res.mesh()
            m.visual.vertex_colors = mesh_colours(m, mmap)
            for fmt in ("ply", "glb"):
                files.append(tmp / f"workspace_{metric}.{fmt}")
                m.export(files[-1])
        for f in files:
            shutil.move(str(f), out_dir / f.name)
            written.append(out_dir / f.name)
    if as_json:
        report["files"] = [str(p) for p in written]
        _emit(report)
        return
    n = nominal
    out.print(f"[bold]{escape(mech.name or mech.family)}[/] at the nominal pose "
              f"{_pose_str(X)}:")
    out.print(f"  κ = {n['kappa']:.4g} (L = {L:.2f} mm, {L_source}), LCI = {n['lci']:.4f}, "
              f"σ_min = {n['sigma_min']:.4g}; singularity: {n['singularity']}")
    out.print(f"  force in every direction {n['force_all_directions_N']:.1f} N, moment "
              f"{n['moment_all_directions_Nmm'] / 1e3:.2f} N·m (actuators ±{force_limit:g} N); "
              f"stiffness ≥ {n['stiffness_translational_min_N_per_mm']:.0f} N/mm")
    if res.empty:
        out.print("  workspace: [bold]empty[/] — no aggregates")
    else:
        k = agg["kappa"]
        out.print(f"  over the {res.kind} workspace ({agg['workspace_volume_cm3']:.2f} cm³): "
                  f"GCI {agg['gci_monte_carlo']:.4f} ± {agg['gci_monte_carlo_std_error']:.4f} "
                  f"(Monte-Carlo, {agg['gci_samples']} samples), {agg['gci_grid']:.4f} (grid)")
        out.print(f"  κ min {k['min']:.3g}, mean {k['mean']:.3g}, p95 {k['p95']:.3g}, max "
                  f"{k['max'] if k['max'] is None else format(k['max'], '.3g')}; κ ≤ "
                  f"{well_conditioned:g} in {agg['well_conditioned_volume_cm3']:.2f} cm³ "
                  f"({100 * agg['well_conditioned_fraction']:.1f} %)")
        f = agg["force_all_directions_N"]
        out.print(f"  force held in every direction: min {f['min']:.1f} N, median "
                  f"{f['p50']:.1f} N; ≥ {force_required:g} N in "
                  f"{agg['force_capable_volume_cm3']:.2f} cm³")
    for p in written:
        out.print(f"  wrote {escape(str(p))}")


@app.command()
def trajectory(
    mech_file: MechArg,
    csv: Annotated[Path | None, typer.Option(
        help="CSV with t,x,y,z,theta_x,theta_y,theta_z (s, mm, deg)")] = None,
    paper_motion: Annotated[bool, typer.Option(
        "--paper-motion", help="Hopkins & Williams' motion: ±2 in in x, y, z then ±30° in "
        "θz, θy, θx, one after the other")] = False,
    segment_time: Annotated[float, typer.Option(help="paper motion: s per cubic segment")]
    = 1.0,
    payload: Annotated[float, typer.Option(help="payload mass (kg) at the tool point")] = 0.0,
    max_speed: Annotated[float | None, typer.Option(help="actuator speed limit (mm/s)")]
    = None,
    max_force: Annotated[float | None, typer.Option(help="actuator force limit (N)")] = 150.0,
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")]
    = Path("results/trajectory"),
    as_json: JsonOpt = False,
) -> None:
    """Actuator values, rates and forces along a trajectory, checked against the limits.

    Writes trajectory.json, trajectory.csv and actuators.png into --out.
    """
    import shutil
    import tempfile

    from . import trajectory as tr

    mech = _load(mech_file)
    if (csv is None) == (not paper_motion):
        _fail(ParameterError("--csv / --paper-motion", "exactly one of them", "both"
                             if paper_motion else "neither"))
    try:
        if csv is not None:
            t, poses = tr.load_csv(csv)
        else:
            t, poses = tr.paper_motion(mech, segment_time=segment_time)
        rep = tr.check_trajectory(mech, t, poses, payload_mass_kg=payload,
                                  max_speed=max_speed, max_force=max_force)
    except ParameterError as exc:
        _fail(exc)
    summary = rep.summary()
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    with tempfile.TemporaryDirectory(dir=out_dir, prefix=".partial-") as tmp:
        tmp = Path(tmp)
        (tmp / "trajectory.json").write_text(json.dumps(summary, indent=2, default=float)
                                             + "\n")
        names = mech.actuator_names
        header = ",".join(["t", *[f"{n}_mm" for n in names], *[f"{n}_rate_mm_s" for n in names],
                           *[f"{n}_force_N" for n in names], "status"])
        rows = [",".join([f"{t[i]:.6g}", *[f"{v:.6g}" for v in rep.q[i]],
                          *[f"{v:.6g}" for v in rep.qdot[i]], *[f"{v:.6g}" for v in
                                                               rep.force[i]], str(rep.status[i])])
                for i in range(len(t))]
        (tmp / "trajectory.csv").write_text(header + "\n" + "\n".join(rows) + "\n")
        phases = tr.paper_motion_phases(segment_time) if paper_motion else None
        tr.plot_actuators(rep, tmp / "actuators.png", title=f"{mech.name}: actuator values",
                          phases=phases)
        for name in ("trajectory.json", "trajectory.csv", "actuators.png"):
            shutil.move(str(tmp / name), out_dir / name)
            written.append(out_dir / name)
    if as_json:
        summary["files"] = [str(p) for p in written]
        _emit(summary)
        return
    verdict = "[bold green]fits[/]" if rep.fits else "[bold red]does not fit[/]"
    out.print(f"{escape(mech.name or mech.family)}: {len(t)} samples over {t[-1] - t[0]:.2f} s "
              f"— {verdict} the limits")
    for kind, v in rep.violations.items():
        if v is not None:
            what = "" if v.value is None else (
                f", {escape(str(v.actuator))} = {v.value:.6g}"
                + ("" if v.limit is None else f" vs limit {v.limit:.6g}"))
            out.print(f"  first {kind} violation: sample {v.index} (t = {v.time:.3f} s){what}"
                      + (f" — {escape(v.reason)}" if v.reason else ""))
    lo_m, hi_m = rep.margin_low, rep.margin_high
    out.print("  stroke margins (mm) below / above: " + ", ".join(
        f"{n} {a:.2f}/{b:.2f}" for n, a, b in zip(mech.actuator_names, lo_m, hi_m)))
    out.print(f"  peak speed {np.nanmax(np.abs(rep.qdot)):.1f} mm/s, peak force "
              f"{np.nanmax(np.abs(rep.force)):.2f} N")
    for p in written:
        out.print(f"  wrote {escape(str(p))}")


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
        written = _write_workspace(res, out_dir / spec.study / name, ["stl"],
                                   ws.slice_options())
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


# ---- design studies ------------------------------------------------------------------------------

StudyArg = Annotated[Path, typer.Argument(help="Study YAML file.")]


def _load_study(path: Path):
    from .study import load_study

    try:
        return load_study(path)
    except ParameterError as exc:
        _fail(exc)
        raise  # unreachable


@app.command()
def validate(study_file: StudyArg, as_json: JsonOpt = False,
             check_space: Annotated[int, typer.Option(
                 help="designs sampled to estimate how much of the design box is "
                      "geometrically invalid (0: skip)", min=0, max=4096)] = 128) -> None:
    """Check a study file (exit 2 with the offending field on error; writes nothing)."""
    from .study.optimisers import expected_evaluations

    study = _load_study(study_file)
    info = {"study": study.name, "file": str(study_file), "valid": True,
            "variables": [v.name for v in study.variables],
            "derived": [d.name for d in study.space.derived],
            "objectives": [f"{o.sense} {o.metric}" for o in study.objectives],
            "constraints": [c.describe() for c in study.constraints],
            "metrics": list(study.evaluation.metrics),
            "optimizer": study.optimizer.method,
            "evaluations": expected_evaluations(study.space, study.optimizer),
            "output": str(study.output), "warnings": []}
    if check_space:
        bad, reasons = study.space.validity(check_space, study.seed)
        info["invalid_fraction"] = bad
        if bad >= 0.2:
            info["warnings"].append(
                f"{100 * bad:.0f} % of {check_space} sampled designs are geometrically "
                "invalid (" + "; ".join(f"{n}× {r}" for r, n in reasons) + "): the optimiser "
                "will spend that share of its budget on them; narrow the ranges or "
                "parametrise coupled variables with 'derived' (docs/studies.md)")
    if as_json:
        _emit(info)
        return
    out.print(escape(f"{study_file}: valid — {len(info['variables'])} design variables, "
                     f"{len(info['objectives'])} objectives, {len(info['constraints'])} "
                     f"constraints, {info['optimizer']} (~{info['evaluations']} evaluations), "
                     f"output {info['output']}"), highlight=False)
    for w in info["warnings"]:
        err.print(escape(f"warning: {w}"), highlight=False)


@app.command()
def schema() -> None:
    """Print the JSON Schema of study files (for editors)."""
    from .study import study_schema

    _emit(study_schema())


@app.command()
def metrics(as_json: JsonOpt = False) -> None:
    """List every study metric: unit, evaluate block, kind of number, meaning."""
    from .study.metrics import METRICS, metrics_markdown

    if as_json:
        _emit({m.name: {"unit": m.unit, "evaluator": m.evaluator, "statistic": m.statistic,
                        "description": m.description} for m in METRICS.values()})
        return
    sys.stdout.write(metrics_markdown())


def _progress_bar(total: int):
    """A rich progress bar with rate and ETA on a terminal; without one (a log, CI, a batch
    job), a line on stderr every 5 s or every tenth of the candidates."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        ProgressColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )
    from rich.text import Text

    class Rate(ProgressColumn):
        def render(self, task):
            return Text(f"{task.speed:.1f} candidates/s" if task.speed else "… candidates/s")

    if not err.is_terminal:
        from .progress import ProgressLines

        return None, ProgressLines(total, sys.stderr)
    prog = Progress(TextColumn("evaluating"), BarColumn(), MofNCompleteColumn(), Rate(),
                    TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                    console=err, transient=True)
    task = prog.add_task("eval", total=total)
    return prog, (lambda n: prog.advance(task, n))


@app.command()
def run(
    study_file: StudyArg,
    jobs: Annotated[int, typer.Option(help="parallel evaluations (joblib workers)")] = 1,
    resume: Annotated[bool, typer.Option(
        "--resume", help="continue the study in its output folder without repeating work")]
    = False,
    overwrite: Annotated[bool, typer.Option(
        "--overwrite", help="replace an earlier run in the output folder")] = False,
    backend: Annotated[str, typer.Option(help="loky | dask")] = "loky",
    scheduler: Annotated[str | None, typer.Option(help="Dask scheduler address")] = None,
    out_dir: Annotated[Path | None, typer.Option(
        "--out", help="output folder (default: the study's, results/<study>)")] = None,
    as_json: JsonOpt = False,
) -> None:
    """Run a design study: evaluate candidates, keep every result, report the Pareto set."""
    import time

    from .progress import log_lines
    from .study.optimisers import expected_evaluations
    from .study.report import export_designs, pareto_records, write_report
    from .study.run import run_study
    from .study.runners import make_runner
    from .webreport import write_study_page

    study = _load_study(study_file)
    if out_dir is not None:
        study = study.with_output(out_dir)
    if resume and overwrite:
        _fail(ParameterError("--resume / --overwrite", "one of them", "both"))
    try:
        runner = make_runner(backend, jobs, scheduler)
    except ParameterError as exc:
        _fail(exc)
    prog, advance = _progress_bar(expected_evaluations(study.space, study.optimizer))
    t0 = time.perf_counter()
    try:
        if prog is not None:
            prog.start()
        store = run_study(study, runner, resume=resume, overwrite=overwrite, progress=advance)
    except ParameterError as exc:
        _fail(exc)
    finally:
        if prog is not None:
            prog.stop()
        runner.close()
    elapsed = time.perf_counter() - t0
    records = store.all()
    store.close()
    outp = Path(study.output)
    with log_lines():
        info = write_report(outp, study, records)
        _, problems = export_designs(outp, study, pareto_records(study, records))
        page = write_study_page(outp, study, records)
    info.update(seconds=elapsed, output=str(outp), export_problems=problems, report=str(page))
    if as_json:
        _emit(info)
        return
    out.print(escape(f"{study.name}: {info['evaluations']} evaluations ({info['failed']} "
                     f"invalid or failed) in {elapsed:.1f} s, {info['pareto']} Pareto designs"),
              highlight=False)
    out.print(escape((outp / "summary.md").read_text()), highlight=False)
    for p in problems:
        err.print(escape(f"warning: export skipped: {p}"), highlight=False)
    out.print(escape(f"results in {outp}/ (report.html, summary.md, pareto.csv, pareto.png, "
                     "evaluations.csv, designs/)"), highlight=False)
    out.print(escape(f"open {page.resolve().as_uri()} in a browser"), highlight=False)


def _open_results(results_dir: Path):
    """A results folder → ``(study, records)``, read-only."""
    from .study import study_from_mapping
    from .study.store import Store

    path = results_dir / "evaluations.sqlite"
    if not path.is_file():
        _fail(ParameterError("RESULTS_DIR", "a study results folder with evaluations.sqlite",
                             str(results_dir)))
    try:
        store = Store(path, read_only=True)
        resolved, records = store.get_meta("resolved"), store.all()
        store.close()
        study = study_from_mapping(resolved)
    except ParameterError as exc:
        _fail(exc)
    return study.with_output(results_dir), records


@app.command()
def report(results_dir: Annotated[Path, typer.Argument(help="a study's results folder")],
           as_json: JsonOpt = False) -> None:
    """Rebuild the tables, Pareto plot, summary and report.html from the store and the
    exported designs (no re-evaluation)."""
    from .progress import log_lines
    from .study.report import write_report
    from .webreport import write_study_page

    study, records = _open_results(results_dir)
    with log_lines():
        info = write_report(results_dir, study, records)
        info["report"] = str(write_study_page(results_dir, study, records))
    info["output"] = str(results_dir)
    if as_json:
        _emit(info)
        return
    out.print(escape(f"rebuilt {results_dir}: {info['evaluations']} evaluations, "
                     f"{info['pareto']} Pareto designs"), highlight=False)


@app.command()
def compare(
    mech_files: Annotated[list[Path] | None, typer.Argument(help="Mechanism YAML files.")]
    = None,
    pareto: Annotated[Path | None, typer.Option(
        help="a study's pareto.csv: compare its rows (with --rows)")] = None,
    rows: Annotated[str | None, typer.Option(help='Pareto ranks, e.g. "1,3"')] = None,
    box: Annotated[float, typer.Option(help="dexterous set: ±box° simultaneous")] = 15.0,
    resolution: ResolutionOpt = "2.5",
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")]
    = Path("results/compare"),
    as_json: JsonOpt = False,
) -> None:
    """Compare designs side by side: volumes, inscribed shapes, GCI, κ, force, footprint,
    stroke use on the paper's motion; writes compare.md and overlaid slice plots."""
    import csv as csv_mod

    from .study.compare import compare_designs, comparison_markdown, plot_overlaid_slices

    loaded = [_load(f) for f in (mech_files or [])]
    designs = [(m.name or f.stem, m) for f, m in zip(mech_files or [], loaded)]
    if pareto is not None:
        if not pareto.is_file() or not (pareto.parent / "evaluations.sqlite").is_file():
            _fail(ParameterError("--pareto", "a study's pareto.csv next to its "
                                 "evaluations.sqlite", str(pareto)))
        with open(pareto) as fh:
            table = list(csv_mod.DictReader(fh))
        wanted = [r.strip() for r in (rows or "1").split(",")]
        study, all_records = _open_results(pareto.parent)
        records = {str(r["seq"]): r for r in all_records}
        by_rank = {row["rank"]: row for row in table}
        for w in wanted:
            if w not in by_rank:
                _fail(ParameterError("--rows", f"ranks present in {pareto.name} "
                                     f"(1..{len(table)})", w))
            rec = records[by_rank[w]["seq"]]
            try:
                designs.append((f"{study.name} #{w}", study.space.decode(rec["params"])))
            except ParameterError as exc:
                _fail(exc)
    if len(designs) < 1:
        _fail(ParameterError("MECH_FILES / --pareto", "at least one design", "none"))
    try:
        h = parse_length(resolution, "--resolution")
    except ParameterError as exc:
        _fail(exc)
    if not (0 <= box <= 90):
        _fail(ParameterError("--box", "an angle in [0, 90] deg", box))
    table_rows = compare_designs(designs, box_deg=box, resolution=h)
    out_dir.mkdir(parents=True, exist_ok=True)
    md = comparison_markdown(table_rows, box)
    (out_dir / "compare.md").write_text(md)
    plot_overlaid_slices(table_rows, out_dir / "compare_dexterous_slices.png", which=1)
    plot_overlaid_slices(table_rows, out_dir / "compare_level_slices.png", which=0)
    if as_json:
        _emit({"designs": [{k: v for k, v in r.items() if k not in ("mechanism", "results")}
                           for r in table_rows],
               "files": [str(out_dir / n) for n in ("compare.md",
                                                    "compare_dexterous_slices.png",
                                                    "compare_level_slices.png")]})
        return
    out.print(md)
    out.print(f"wrote {escape(str(out_dir))}/compare.md and overlaid slice plots")


_DEBUG = {"on": False}


def _version(value: bool) -> None:
    if value:
        from . import __version__

        sys.stdout.write(f"pkmlab {__version__}\n")
        raise typer.Exit()


@app.callback()
def _root(
    debug: Annotated[bool, typer.Option(
        "--debug", help="show the full traceback of an unexpected error")] = False,
    version: Annotated[bool | None, typer.Option(
        "--version", callback=_version, is_eager=True, help="print the version and exit")]
    = None,
) -> None:
    """pkmlab: design-optimisation workbench for parallel manipulators."""
    _DEBUG["on"] = debug


def main() -> None:
    """Console entry point: input errors exit 2 (one line); a file-system error exits 2 with
    its path; a candidate's programming error exits 1 with its traceback and parameters; any
    other unexpected error exits 1 with one line (``--debug``: the traceback)."""
    from .study.run import CandidateError

    try:
        app(standalone_mode=False)
    except click.exceptions.Exit as exc:
        raise SystemExit(exc.exit_code) from None
    except click.ClickException as exc:
        exc.show()
        raise SystemExit(2) from None
    except (click.exceptions.Abort, KeyboardInterrupt):
        sys.stderr.write("interrupted\n")
        raise SystemExit(130) from None
    except CandidateError as exc:
        sys.stderr.write(f"error: {exc}\n")
        raise SystemExit(1) from None
    except OSError as exc:
        if _DEBUG["on"]:
            raise
        where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
        sys.stderr.write(f"error: file system: {exc.strerror or exc}{where}\n")
        raise SystemExit(2) from None
    except Exception as exc:  # noqa: BLE001 - last resort: one line unless --debug
        if _DEBUG["on"]:
            raise
        sys.stderr.write(f"error: {type(exc).__name__}: {exc} (this is a bug in pkmlab; run "
                         "with --debug for the traceback)\n")
        raise SystemExit(1) from None


if __name__ == "__main__":
    main()
