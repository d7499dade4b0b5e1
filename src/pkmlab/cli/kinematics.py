"""Kinematics commands: inspect, ik, fk, demo."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.markup import escape
from rich.table import Table

from ..errors import ParameterError
from .common import (
    POSE_KEYS,
    JsonOpt,
    MechArg,
    _act_display,
    _act_json,
    _act_str,
    _act_unit,
    _emit,
    _fail,
    _kappa_text,
    _load,
    _parse_actuators,
    _parse_pose,
    _pose_json,
    _pose_str,
    app,
    out,
)


@app.command()
def inspect(mech_file: MechArg, as_json: JsonOpt = False) -> None:
    """Geometry, nominal pose, its actuator values and κ (homogenised, Angeles' L)."""
    from ..dexterity.report import pose_report

    mech = _load(mech_file)
    nominal = mech.nominal_pose
    rep = pose_report(mech, nominal)
    data = {
        "geometry": mech.describe(),
        "nominal_pose": _pose_json(nominal),
        "actuator_unit": _act_unit(mech),
        "nominal_actuators": _act_json(mech, mech.inverse(nominal).q[0]),
        "nominal_valid": rep["valid"],
        "nominal_reason": (rep["reason"] if not (rep["valid"] and rep["singular"]) else
                           "singular: the Jacobian is rank-deficient at the nominal pose"),
        "actuator_limits": {n: list(map(float, _act_display(mech, lim)))
                            for n, lim in zip(mech.actuator_names, mech.actuator_limits)},
        "kappa": rep["kappa"],
        "singular": rep["singular"],
        "characteristic_length": rep["characteristic_length"],
    }
    if as_json:
        _emit(data)
        return
    out.print(f"[bold]{escape(mech.name or mech_file.stem)}[/] — family [cyan]{mech.family}[/]")
    g = mech.describe()
    for key, val in g.items():
        if key.endswith("points_mm") or key in ("family", "name"):
            continue
        out.print(f"  {key}: {escape(str(val))}")
    pts = [k for k in g if k.endswith("points_mm")]
    table = Table("joint", *[k.removesuffix("_mm") + " (mm)" for k in pts])
    for i in range(max(len(g[k]) for k in pts)):
        table.add_row(str(i + 1), *[(" ".join(f"{c:9.3f}" for c in g[k][i])
                                     if i < len(g[k]) else "") for k in pts])
    out.print(table)
    out.print(f"nominal pose: {_pose_str(nominal, mech)}")
    out.print(f"nominal actuators ({_act_unit(mech)}): "
              + _act_str(mech, mech.inverse(nominal).q[0]) + escape(f"  [{rep['reason']}]"))
    out.print(escape(f"at nominal: {_kappa_text(rep)}"), highlight=False)
    if rep["characteristic_length"]["status"] not in ("angeles", "given"):
        out.print(escape(f"  note: {rep['characteristic_length']['reason']}"), highlight=False)


@app.command()
def ik(mech_file: MechArg,
       pose: Annotated[str, typer.Option(help='Tool pose in the mechanism\'s free coordinates, '
                                              'mm and deg: "x,y,z,θx,θy,θz" (six-DOF), "x,y,z" '
                                              '(translational), "x,y,θz" (planar); all six are '
                                              'accepted too; units may be given, e.g. "2 in". '
                                              'Base frame unless --relative.')],
       relative: Annotated[bool, typer.Option(
           "--relative", help="--pose is an offset from the mechanism's nominal pose (added "
           "coordinate by coordinate, mm and deg), not a base-frame pose")] = False,
       as_json: JsonOpt = False) -> None:
    """Inverse kinematics: actuator values of one pose, with validity, reason and κ.

    Exits with status 1 when the pose is not valid (a leg without a solution, out of its
    stroke or beyond a joint limit), after printing why."""
    from ..dexterity.report import pose_report

    mech = _load(mech_file)
    X = _parse_pose(pose, mech=mech, relative=relative)
    rep = pose_report(mech, X)
    legs = [rep["reason"]] if rep["valid"] else [
        f"{n}: {st}" for n, st in rep["leg_status"].items() if st != "ok"]
    data = {"pose": _pose_json(X), "actuator_unit": _act_unit(mech),
            "actuators": _act_json(mech, mech.inverse(X).q[0]), "valid": rep["valid"],
            "reason": rep["reason"], "leg_status": rep["leg_status"], "kappa": rep["kappa"],
            "singular": rep["singular"], "characteristic_length": rep["characteristic_length"]}
    dep = mech.mobility.dependent
    if dep:                 # a 3-PRS: the dependent coordinates follow from the free ones
        par = mech.parasitic(X[None])[0]
        data["dependent"] = {c: float(np.degrees(v) if c.startswith("theta") else v)
                             for c, v in zip(dep, par)}
    if as_json:
        _emit(data)
        if not rep["valid"]:
            raise typer.Exit(1)
        return
    out.print(f"pose: {_pose_str(X, mech)}")
    if dep:
        out.print("dependent (parasitic, replacing the pose's): " + ", ".join(
            f"{c}={v:.4f}{' deg' if c.startswith('theta') else ' mm'}"
            for c, v in data["dependent"].items()))
    out.print(f"actuators ({_act_unit(mech)}): " + _act_str(mech, mech.inverse(X).q[0], 6))
    out.print(("[green]valid[/]" if rep["valid"] else "[red]invalid[/]") + ": "
              + escape("; ".join(legs)))
    out.print(escape(_kappa_text(rep)), highlight=False)
    if not rep["valid"]:
        raise typer.Exit(1)


def mech_status(code: int) -> str:
    from ..mechanisms import LEG_STATUS

    return LEG_STATUS[int(code)]


@app.command()
def fk(mech_file: MechArg,
       actuators: Annotated[str, typer.Option(help='Actuator values "q1,…,q6" (one per '
                                              'actuator of the family) in mm, or in deg for '
                                              'rotary families (rss6).')],
       all_modes: Annotated[bool, typer.Option("--all", help="List every assembly mode found "
                                               "by the multi-start search.")] = False,
       guess: Annotated[str | None, typer.Option(help='Start pose "x,y,z,θx,θy,θz" (mm, deg); '
                                                 'default the nominal pose.')] = None,
       starts: Annotated[int, typer.Option(help="Random starts for --all.", min=1)] = 1500,
       seed: Annotated[int, typer.Option(help="Seed of the --all starts.")] = 0,
       as_json: JsonOpt = False) -> None:
    """Forward kinematics (Newton from the nominal pose or --guess); --all for every mode."""
    mech = _load(mech_file)
    q = _parse_actuators(mech, actuators)
    g = None if guess is None else _parse_pose(guess, "--guess", mech)
    res = mech.forward(q, g, modes=True)
    amb = bool(res.ambiguous[0])
    data = {"actuator_unit": _act_unit(mech), "actuators": _act_json(mech, q),
            "pose": _pose_json(res.pose[0]),
            "converged": bool(res.converged[0]), "residual_mm": float(res.residual[0]),
            "iterations": int(res.iterations[0]), "status": str(res.status[0]),
            "ambiguous": amb, "mode_starts": int(res.mode_starts),
            "next_mode": {"pose": _pose_json(res.next_mode[0]),
                          "distance_mm": float(res.next_mode_mm[0]),
                          "angle_deg": float(res.next_mode_deg[0])} if amb else None}
    if all_modes:
        modes = mech.assembly_modes(q, starts=starts, seed=seed)
        data["assembly_modes"] = [
            {"pose": _pose_json(p), "residual_mm": float(r), "working_mode": bool(w),
             "distance_to_nominal": float(d)}
            for p, r, w, d in zip(modes.pose, modes.residual, modes.working_mode, modes.distance)]
        data["starts"] = modes.starts
        data["modes_complete"] = bool(getattr(mech, "closed_form_modes", False))
    if as_json:
        _emit(data)
        return
    out.print(f"forward kinematics: [{'green' if res.converged[0] else 'red'}]"
              f"{res.status[0]}[/] after {res.iterations[0]} iterations, "
              f"residual {res.residual[0]:.3g} mm")
    out.print(f"pose: {_pose_str(res.pose[0], mech)}")
    if amb:
        out.print(f"[yellow]ambiguous[/]: another working-mode assembly mode has the same "
                  f"actuator values, {res.next_mode_mm[0]:.4g} mm and "
                  f"{res.next_mode_deg[0]:.4g}° away: {_pose_str(res.next_mode[0], mech)} "
                  "(--all lists every mode found)")
    elif res.converged[0] and getattr(mech, "closed_form_modes", False):
        out.print("every assembly mode found in closed form: no other one is in the working "
                  "mode (--all lists them)")
    elif res.converged[0]:
        out.print(f"no other working-mode assembly mode reached from {res.mode_starts} starts "
                  "in the working region (a search, not a proof; --all searches wider)")
    if all_modes:
        found = (f"{len(modes.residual)} assembly modes: every real one (closed form)"
                 if getattr(mech, "closed_form_modes", False) else
                 f"{len(modes.residual)} assembly modes from {modes.starts} starts (a "
                 "multi-start search: not known to be complete)")
    if all_modes and not out.is_terminal:
        # piped: one line per mode, tab-separated, never wrapped at a console width
        lines = [f"# {found}",
                 "\t".join(["#", "x (mm)", "y (mm)", "z (mm)", "θx (deg)", "θy (deg)",
                            "θz (deg)", "residual (mm)", "working mode"])]
        for i, (p, r, w) in enumerate(zip(modes.pose, modes.residual, modes.working_mode)):
            pj = _pose_json(p)
            lines.append("\t".join([str(i + 1), *[f"{pj[k]:.4f}" for k in POSE_KEYS],
                                    f"{r:.2e}", "yes" if w else "no"]))
        out.file.write("\n".join(lines) + "\n")
    elif all_modes:
        table = Table("#", "x (mm)", "y (mm)", "z (mm)", "θx (deg)", "θy (deg)", "θz (deg)",
                      "residual (mm)", "working mode",
                      title=found)
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
        out.rule(f"[bold]{escape(f.name)}")
        inspect(f)
        mech = _load(f)
        X = mech.nominal_pose + np.array([10.0, -5.0, 8.0, *np.radians([5.0, -4.0, 10.0])])
        res = mech.inverse(X)
        out.print(f"IK of a displaced pose {_pose_str(X, mech)}:")
        out.print("  " + _act_str(mech, res.q[0])
                  + escape(f" {_act_unit(mech)} [{res.reason_text[0]}]"))
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


