"""What every command shares: the app, the consoles, one error form, argument parsing and
the workspace request options."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.text import Text

from ..config import load_mechanism
from ..errors import ParameterError
from ..mechanisms import SPATIAL, Mechanism
from ..mechanisms.mobility import POSE
from ..units import parse_angle, parse_length
from ..yamlio import locate_error

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="pkmlab: design-optimisation workbench for parallel manipulators.")
out = Console()
err = Console(stderr=True, soft_wrap=True)  # one line per error, whatever the width

POSE_KEYS = POSE
JSON_HELP = ("Print JSON. Pose keys: x, y, z (mm), theta_x, theta_y, theta_z (deg, Z-Y-X Euler); "
             "actuators: {name: value} with the family's actuator names, in mm (prismatic) or "
             "deg (rotary families such as rss6; the key actuator_unit says which).")


#: library argument names → the command-line options a user typed for them
OPTION_NAMES = {"resolution": "--resolution", "segment_time": "--segment-time",
                "payload_mass_kg": "--payload", "max_speed": "--max-speed",
                "max_force": "--max-force", "well_conditioned": "--well-conditioned",
                "force_required": "--force-required", "metric": "--metric",
                "samples": "--samples", "kind": "--kind",
                "--constraints.link_diameter": "--link-diameter",
                "--constraints.kappa_max": "--kappa-max",
                "--constraints.joint_limits": "--joint-limit",
                "--constraints.joint_limits.base": "--joint-limit[0]",
                "--constraints.joint_limits.platform": "--joint-limit[1]",
                "--constraints.stroke": "--stroke", "--constraints.stroke[0]": "--stroke[0]",
                "--constraints.stroke[1]": "--stroke[1]"}


def _fail(exc: Exception, options: dict[str, str] | None = None) -> None:
    """Print one error line and exit 2. ``options`` (default :data:`OPTION_NAMES`) renames a
    library argument in the message to the command-line option the user typed."""
    if isinstance(exc, ParameterError):
        field = (OPTION_NAMES if options is None else options).get(exc.field)
        if field is not None:
            exc = ParameterError(field, exc.allowed, exc.got, exc.where)
        locate_error(exc)  # the line and column of its field, when it came from a file
    err.print(Text("error", style="bold red") + Text(": " + " ".join(str(exc).split())))
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


def _parse_pose(text: str, field: str = "--pose", mech: Mechanism | None = None,
                relative: bool = False) -> np.ndarray:
    """A pose in the mechanism's free coordinates (``x,y,z`` for a translational one, ``x,y,θz``
    for a planar one; mm and deg unless units are given) or all six; returns six coordinates
    (the others at the nominal pose). ``relative``: the values are offsets from the nominal
    pose, added coordinate by coordinate (the Euler angles too)."""
    mob = SPATIAL if mech is None else mech.mobility
    parts = [p.strip() for p in text.split(",")]
    coords = POSE if len(parts) == len(POSE) else mob.coordinates
    if len(parts) != len(coords) or any(p == "" for p in parts):
        also = "" if mob.is_spatial else " or all six (x,y,z,θx,θy,θz)"
        _fail(ParameterError(field, f"{mob.width} comma-separated values "
                             f"({','.join(mob.coordinates)}){also}", text))
    try:
        values = np.array([(parse_angle if c.startswith("theta") else parse_length)(
            p, f"{field}[{i}]") for i, (c, p) in enumerate(zip(coords, parts))])
    except ParameterError as exc:
        _fail(exc)
    if relative:
        values = values + np.asarray(mech.nominal_pose)[[POSE.index(c) for c in coords]]
    return values if len(coords) == len(POSE) else mob.full(values, mech.nominal_pose)[0]


def _pose_json(pose: np.ndarray) -> dict:
    vals = list(pose[:3]) + [math.degrees(a) for a in pose[3:]]
    return {k: (None if not np.isfinite(v) else float(v)) for k, v in zip(POSE_KEYS, vals)}


def _act_unit(mech: Mechanism) -> str:
    """Display unit of the actuator values: ``"mm"``, or ``"deg"`` for rotary (rad) families."""
    return "deg" if mech.actuator_unit == "rad" else mech.actuator_unit


def _act_display(mech: Mechanism, q) -> np.ndarray:
    """Actuator values (internal units) in the display unit of :func:`_act_unit`."""
    q = np.asarray(q, dtype=float)
    return np.degrees(q) if mech.actuator_unit == "rad" else q


def _act_json(mech: Mechanism, q: np.ndarray) -> dict:
    q = _act_display(mech, q)
    return {n: (None if not np.isfinite(v) else float(v)) for n, v in zip(mech.actuator_names, q)}


def _act_str(mech: Mechanism, q, digits: int = 4) -> str:
    return ", ".join(f"{n}=" + ("none" if not np.isfinite(v) else f"{v:.{digits}f}")
                     for n, v in zip(mech.actuator_names, _act_display(mech, q)))


def _parse_actuators(mech: Mechanism, text: str) -> np.ndarray:
    """``"q1,…,qL"``, one value per declared actuator: mm (or with units) for prismatic
    families, deg (or with units) for rotary ones."""
    parts = _parse_csv(text, "--actuators", mech.n_actuators)
    parse = parse_angle if mech.actuator_unit == "rad" else parse_length
    try:
        return np.array([parse(p, f"--actuators[{i}]") for i, p in enumerate(parts)])
    except ParameterError as exc:
        _fail(exc)


def _pose_str(pose: np.ndarray, mech: Mechanism | None = None) -> str:
    """The pose's coordinates (the free ones of ``mech``'s mobility when given) in mm and deg."""
    p = _pose_json(np.asarray(pose, dtype=float).reshape(-1)[:len(POSE)])
    coords = POSE if mech is None else mech.mobility.coordinates
    if any(p[c] is None for c in coords):
        return "undefined"
    lin = " ".join(f"{c}={p[c]:.4f}" for c in coords if not c.startswith("theta"))
    ang = " ".join(f"θ{c[-1]}={p[c]:.4f}" for c in coords if c.startswith("theta"))
    return ", ".join(s for s in (lin and lin + " mm", ang and ang + " deg") if s)


def _emit(data: dict) -> None:
    sys.stdout.write(json.dumps(data, indent=2) + "\n")


MechArg = Annotated[Path, typer.Argument(help="Mechanism YAML file.")]
JsonOpt = Annotated[bool, typer.Option("--json", help=JSON_HELP)]


def _kappa_text(rep: dict) -> str:
    """One line: κ with its characteristic length and status (from a pose report)."""
    cl = rep["characteristic_length"]
    k = "inf (singular)" if rep["kappa"] is None else f"{rep['kappa']:.4g}"
    if cl["length_mm"] is None:             # no rotational column: κ of J itself
        return f"κ = {k} (no characteristic length: {cl['source']})"
    return (f"κ = {k} (Jacobian homogenised with L = {cl['length_mm']:.2f} mm, "
            f"{cl['status']})")


def _csv_list(text: str | None, field: str, n: int) -> list[str] | None:
    return None if text is None else _parse_csv(text, field, n)


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
    help='evaluate with another actuator window "min,max": lengths (mm or with units), or '
    'servo angles (deg or with units) for rotary actuators')]


def _request(kind, orientation, box, semantics, tilt, torsion, samples, resolution,
             link_diameter, joint_limit, kappa_max, all_components, stroke=None,
             slice_layout="auto"):
    """CLI workspace options → validated request (the config module does the validation)."""
    from ..config import workspace_spec
    from ..workspaces.output.slicing import LAYOUTS

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


