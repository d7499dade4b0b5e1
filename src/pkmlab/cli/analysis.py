"""Analysis commands: dexterity, trajectory, compare."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.markup import escape

from ..errors import ParameterError
from ..export import exporters
from ..motion import costs
from ..runtime.progress import log_lines
from ..units import parse_length
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
    _kappa_text,
    _load,
    _pose_str,
    _request,
    app,
    out,
)
from .study import _open_results


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
    force_limit: Annotated[float | None, typer.Option(
        help="linear actuator force limit (N); default 150 N for linear actuators")] = None,
    max_torque: Annotated[float | None, typer.Option(
        help="rotary actuator (servo) torque limit (N·m); required for a rotary family")]
    = None,
    force_required: Annotated[float, typer.Option(
        help="force (N) the platform must hold in every direction: its sub-workspace")]
    = 100.0,
    actuator_stiffness: Annotated[float | None, typer.Option(
        help="linear actuator stiffness (N/mm); default 10000 N/mm for linear actuators")]
    = None,
    torsional_stiffness: Annotated[float | None, typer.Option(
        help="rotary actuator (servo) torsional stiffness (N·m/rad); required for a rotary "
             "family")] = None,
    gci_samples: Annotated[int, typer.Option(help="Monte-Carlo GCI samples")] = 2000,
    seed: Annotated[int, typer.Option(help="Monte-Carlo seed")] = 0,
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")]
    = Path("results/dexterity"),
    as_json: JsonOpt = False,
) -> None:
    """Conditioning, force and stiffness at the nominal pose and over a workspace.

    The analysis is pkmlab.dexterity.report.dexterity_report. Writes dexterity.json,
    <metric>_slices.png and workspace_<metric>.ply/.glb (the workspace mesh coloured by the
    metric's worst value over the orientation set) into --out.
    """
    import shutil
    import tempfile

    from ..dexterity.maps import METRICS, mesh_colours, vertex_values
    from ..dexterity.report import dexterity_report
    from ..workspaces.output.plots import plot_slices

    mech = _load(mech_file)
    spec, req = _request(kind, orientation, box, semantics, tilt, torsion, samples, resolution,
                         link_diameter, joint_limit, kappa_max, all_components, stroke)
    if metric not in METRICS:
        _fail(ParameterError("--metric", f"one of {list(METRICS)}", metric))
    L = None
    if characteristic_length.strip().lower() != "auto":
        try:
            L = parse_length(characteristic_length, "--characteristic-length")
        except ParameterError as exc:
            _fail(exc)
        if not L > 0:
            _fail(ParameterError("--characteristic-length", "a length > 0 mm or 'auto'",
                                 characteristic_length))
    force_limit, actuator_stiffness = _dexterity_actuators(
        mech, force_limit, actuator_stiffness, max_torque, torsional_stiffness)
    for name, v, lo in (("--force-limit", force_limit, 0), ("--actuator-stiffness",
                                                              actuator_stiffness, 0),
                        ("--well-conditioned", well_conditioned, 1),
                        ("--force-required", force_required, 0)):
        if not (math.isfinite(v) and v > lo):
            _fail(ParameterError(name, f"a number > {lo}", v))
    if not 10 <= gci_samples <= 10_000_000:
        _fail(ParameterError("--gci-samples", "an integer in [10, 10000000]", gci_samples))

    try:
        with log_lines():
            rep = dexterity_report(mech, req, L=L, metric=metric,
                                   well_conditioned=well_conditioned, force_limit=force_limit,
                                   force_required=force_required,
                                   actuator_stiffness=actuator_stiffness,
                                   gci_samples=gci_samples, seed=seed)
    except ParameterError as exc:
        _fail(exc)
    res, mmap, report = rep.result, rep.map, rep.data
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    with tempfile.TemporaryDirectory(dir=out_dir, prefix=".partial-") as tmp:
        tmp = Path(tmp)
        files = [tmp / "dexterity.json"]
        files[0].write_text(json.dumps(report, indent=2, default=float) + "\n")
        if mmap is not None:
            vals = np.where(np.isfinite(mmap.grid), mmap.grid, np.nan)
            files.append(plot_slices(res, tmp / f"{metric}_slices.png", values=vals,
                                     label=mmap.label, **spec.slice_options()))
            if res.mesh_problem is None:
                m = res.mesh()
                colours = mesh_colours(m, mmap)
                # every mesh format that takes colours (PLY in mm with the metric per
                # vertex, GLB in m): the ones that take values get the metric's
                for fmt in exporters("mesh", option="colors"):
                    files.append(tmp / f"workspace_{metric}.{fmt}")
                    res.save_mesh(files[-1], colors=colours,
                                  values={metric: vertex_values(m, mmap)})
        for f in files:
            shutil.move(str(f), out_dir / f.name)
            written.append(out_dir / f.name)
    if as_json:
        report["files"] = [str(p) for p in written]
        _emit(report)
        return
    _print_dexterity(rep, force_limit, well_conditioned, force_required, written)


def _dexterity_actuators(mech, force_limit, actuator_stiffness, max_torque,
                         torsional_stiffness):
    """Effort limit and actuator stiffness in internal units (N, N/mm; N·mm, N·mm/rad for a
    servo) from the options of the mechanism's actuator kind. A rotary family needs
    --max-torque and --torsional-stiffness: no linear default is applied to a servo."""
    if mech.actuator_unit != "rad":
        for opt, v in (("--max-torque", max_torque),
                       ("--torsional-stiffness", torsional_stiffness)):
            if v is not None:
                _fail(ParameterError(opt, f"--force-limit (N) / --actuator-stiffness (N/mm): "
                                     f"{mech.family} has linear actuators", v))
        return (LINEAR_FORCE_DEFAULT_N if force_limit is None else force_limit,
                1.0e4 if actuator_stiffness is None else actuator_stiffness)
    for opt, v in (("--force-limit", force_limit), ("--actuator-stiffness",
                                                    actuator_stiffness)):
        if v is not None:
            _fail(ParameterError(opt, f"--max-torque (N·m) / --torsional-stiffness (N·m/rad): "
                                 f"{mech.family} has rotary actuators", v))
    for opt, v, what in (("--max-torque", max_torque, "the servo torque limit (N·m)"),
                         ("--torsional-stiffness", torsional_stiffness,
                          "the servo torsional stiffness (N·m/rad)")):
        if v is None:
            _fail(ParameterError(opt, f"{what}: {mech.family} has rotary actuators and no "
                                 "linear default applies to them", "not given"))
        if not (math.isfinite(v) and v > 0):
            _fail(ParameterError(opt, "a number > 0", v))
    return max_torque * 1e3, torsional_stiffness * 1e3


def _print_dexterity(rep, force_limit, well_conditioned, force_required, written) -> None:
    """Text output of ``dexterity`` (everything printed is in ``rep.data``)."""
    def g(v, fmt):
        return "—" if v is None else format(v, fmt)

    d, mech = rep.data, rep.mechanism
    n, agg, cl = d["nominal"], d["aggregates"], d["characteristic_length"]
    out.print(f"[bold]{escape(mech.name or mech.family)}[/] at the nominal pose "
              f"{_pose_str(mech.nominal_pose, mech)}:")
    out.print(escape(f"  {_kappa_text(n)}, LCI = {n['lci']:.4f}, σ_min = "
                     f"{g(n['sigma_min'], '.4g')}; singularity: {n['singularity']}"),
              highlight=False)
    if cl["status"] not in ("angeles", "given"):
        out.print(escape(f"  note: {cl['reason']}"), highlight=False)
    moment = n["moment_all_directions_Nmm"]
    out.print(f"  force in every direction {g(n['force_all_directions_N'], '.1f')} N, moment "
              f"{g(None if moment is None else moment / 1e3, '.2f')} "
              f"N·m ({_limit_text(mech, force_limit)}); stiffness ≥ "
              f"{g(n['stiffness_translational_min_N_per_mm'], '.0f')} N/mm")
    if agg["empty"]:
        out.print("  workspace: [bold]empty[/] — no aggregates")
    elif agg.get("no_samples"):
        out.print(escape(f"  workspace {agg['workspace_volume_cm3']:.4f} cm³, no aggregates: "
                         f"{agg['no_samples']}"), highlight=False)
    else:
        k, w = agg["kappa"], agg["worst_case"]
        out.print(f"  over the {rep.result.kind} workspace ({agg['workspace_volume_cm3']:.2f} "
                  f"cm³): GCI {g(agg['gci_grid'], '.4f')} (every voxel × orientation), "
                  f"{g(agg['gci_monte_carlo'], '.4f')} ± "
                  f"{g(agg['gci_monte_carlo_std_error'], '.4f')} (Monte-Carlo, "
                  f"{agg['gci_samples']} samples)")
        worst = "inf" if w["worst_kappa"] is None else f"{w['worst_kappa']:.4g}"
        out.print(f"  worst case over every voxel and column end × orientation: κ {worst}, "
                  f"force {g(w['min_force_N'], '.1f')} N"
                  + (" — singularity not excluded between samples" if not w["singular"]
                     else escape(f" — singular: {w['reason']}")),
                  highlight=False)
        out.print(f"  κ min {g(k['min'], '.3g')}, mean {g(k['mean'], '.3g')}, p95 "
                  f"{g(k['p95'], '.3g')}; κ ≤ {well_conditioned:g} in "
                  f"{agg['well_conditioned_volume_cm3']:.2f} cm³ "
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
        help="CSV with t,x,y,z,theta_x,theta_y,theta_z (s, mm, deg): absolute poses in the "
        "base frame, or offsets from the nominal pose with --relative (a study's motions "
        "say the same with frame: base / frame: nominal)")] = None,
    relative: Annotated[bool, typer.Option(
        "--relative", help="the --csv poses are offsets from the mechanism's nominal pose "
        "(added coordinate by coordinate), as a study motion's frame: nominal")] = False,
    paper_motion: Annotated[bool, typer.Option(
        "--paper-motion", help="Hopkins & Williams' motion: ±2 in in x, y, z then ±30° in "
        "θz, θy, θx, one after the other")] = False,
    segment_time: Annotated[float, typer.Option(help="paper motion: s per cubic segment")]
    = 1.0,
    payload: Annotated[float, typer.Option(help="payload mass (kg) at the tool point")] = 0.0,
    max_speed: Annotated[float | None, typer.Option(
        help="linear actuator speed limit (mm/s)")] = None,
    max_force: Annotated[float | None, typer.Option(
        help="linear actuator force limit (N); default 150 N for linear actuators")] = None,
    max_torque: Annotated[float | None, typer.Option(
        help="rotary actuator (servo) torque limit (N·m); no default")] = None,
    max_angular_speed: Annotated[float | None, typer.Option(
        help="rotary actuator (servo) angular speed limit (deg/s)")] = None,
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")]
    = Path("results/trajectory"),
    as_json: JsonOpt = False,
) -> None:
    """Actuator values, rates and forces along a trajectory, checked against the limits.

    Writes trajectory.json, trajectory.csv and actuators.png into --out. Exits with status 1
    when a sample fails (no solution, out of stroke, over a limit, singular), after writing
    and printing why.
    """
    import shutil
    import tempfile

    from .. import motion as tr

    mech = _load(mech_file)
    max_speed, max_force = _actuator_limits(mech, max_speed, max_force, max_torque,
                                            max_angular_speed)
    if (csv is None) == (not paper_motion):
        _fail(ParameterError("--csv / --paper-motion", "exactly one of them", "both"
                             if paper_motion else "neither"))
    if relative and csv is None:
        _fail(ParameterError("--relative", "only with --csv (the paper motion is always about "
                             "the nominal pose)", "--paper-motion"))
    try:
        if csv is not None:
            motion = tr.load_motion_csv(csv, field="--csv", derivatives=False)
            _trajectory_budget("--csv", len(motion.t), 1.0, "rows")
            if relative:
                motion = tr.Motion(motion.name, motion.t, motion.poses + mech.nominal_pose,
                                   motion.twist, motion.accel, motion.derivatives)
        else:
            _trajectory_budget("--segment-time", costs.paper_samples(segment_time, 100.0),
                               segment_time, "s")
            motion = tr.paper_motion(mech, segment_time=segment_time, rate_hz=100.0)
        t = motion.t
        rep = tr.check_trajectory(mech, t, motion.poses, payload_mass_kg=payload,
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
        d = rep.display     # mm, mm/s, N; or deg, deg/s, N·m for rotary actuators
        a = d.ascii
        header = ",".join(["t", *[f"{n}_{a(d.value_unit)}" for n in names],
                           *[f"{n}_rate_{a(d.rate_unit)}" for n in names],
                           *[f"{n}_{d.effort}_{a(d.effort_unit)}" for n in names], "status"])
        rows = [",".join([f"{t[i]:.6g}", *[f"{v * d.value_scale:.6g}" for v in rep.q[i]],
                          *[f"{v * d.rate_scale:.6g}" for v in rep.qdot[i]],
                          *[f"{v * d.effort_scale:.6g}" for v in rep.force[i]],
                          str(rep.status[i])])
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
        if not rep.fits:
            raise typer.Exit(1)
        return
    verdict = "[bold green]fits[/]" if rep.fits else "[bold red]does not fit[/]"
    out.print(f"{escape(mech.name or mech.family)}: {len(t)} samples over {t[-1] - t[0]:.2f} s "
              f"— {verdict} the limits")
    d = rep.display
    shown = {"stroke": (d.value, d.value_scale, d.value_unit),
             "speed": (d.rate, d.rate_scale, d.rate_unit),
             "force": (d.effort, d.effort_scale, d.effort_unit)}
    for kind, v in rep.violations.items():
        if v is not None:
            name, scale, unit = shown.get(kind, (kind, 1.0, ""))
            what = "" if v.value is None else (
                f", {escape(str(v.actuator))} = {v.value * scale:.6g} {unit}"
                + ("" if v.limit is None else f" vs limit {v.limit * scale:.6g} {unit}"))
            out.print(f"  first {name} violation: sample {v.index} (t = {v.time:.3f} s){what}"
                      + (f" — {escape(v.reason)}" if v.reason else ""))
    lo_m, hi_m = rep.margin_low * d.value_scale, rep.margin_high * d.value_scale
    out.print(f"  {d.value} margins ({d.value_unit}) below / above: " + ", ".join(
        f"{n} {a:.2f}/{b:.2f}" for n, a, b in zip(mech.actuator_names, lo_m, hi_m)))
    out.print(f"  peak {d.rate} {_nanpeak(rep.qdot) * d.rate_scale:.4g} {d.rate_unit}, peak "
              f"{d.effort} {_nanpeak(rep.force) * d.effort_scale:.4g} {d.effort_unit}"
              + ("" if rep.max_force is not None else f" (no {d.effort} limit given)"))
    for p in written:
        out.print(f"  wrote {escape(str(p))}")
    if not rep.fits:
        raise typer.Exit(1)


def _trajectory_budget(field: str, n: float, value: float, unit: str) -> None:
    """The ``trajectory`` command's cost model against the budgets: memory and time per
    sample (:mod:`pkmlab.motion.costs`), driven by ``field`` = ``value`` ``unit``."""
    from ..study.evaluators.registry import Cost, check_costs

    check_costs([Cost(field, value, unit, 1.0, n * costs.TRAJECTORY_COMMAND_BYTES_PER_SAMPLE,
                      n * costs.DYNAMICS_SECONDS_PER_SAMPLE
                      + n * costs.TRAJECTORY_SECONDS_PER_SAMPLE, f"{n:.6g} samples",
                      integer=unit == "rows")])


def _limit_text(mech, force_limit) -> str:
    if mech.actuator_unit == "rad":
        return f"servos ±{force_limit / 1e3:g} N·m"
    return f"actuators ±{force_limit:g} N"


def _nanpeak(a) -> float:
    a = np.abs(np.asarray(a, dtype=float))
    return float(np.nanmax(a)) if np.isfinite(a).any() else math.nan


#: the linear force limit applied when none is given (never to a rotary actuator)
LINEAR_FORCE_DEFAULT_N = 150.0


def _actuator_limits(mech, max_speed, max_force, max_torque, max_angular_speed):
    """The speed and effort limits in internal units (mm/s, N; rad/s, N·mm for a servo)
    from the options of the mechanism's actuator kind; the other kind's options are refused
    and no linear default is applied to a rotary actuator."""
    rotary = mech.actuator_unit == "rad"
    given = {"--max-speed": max_speed, "--max-force": max_force, "--max-torque": max_torque,
             "--max-angular-speed": max_angular_speed}
    wrong = ("--max-speed", "--max-force") if rotary else ("--max-torque",
                                                           "--max-angular-speed")
    for opt in wrong:
        if given[opt] is not None:
            kind = "rotary" if rotary else "linear"
            use = ("--max-torque (N·m) / --max-angular-speed (deg/s)" if rotary else
                   "--max-force (N) / --max-speed (mm/s)")
            _fail(ParameterError(opt, f"{use}: {mech.family} has {kind} actuators",
                                 given[opt]))
    for opt, v in given.items():
        if v is not None and not (math.isfinite(v) and v > 0):
            _fail(ParameterError(opt, "a number > 0", v))
    if rotary:
        return (None if max_angular_speed is None else math.radians(max_angular_speed),
                None if max_torque is None else max_torque * 1e3)
    return max_speed, LINEAR_FORCE_DEFAULT_N if max_force is None else max_force


@app.command()
def compare(
    mech_files: Annotated[list[Path] | None, typer.Argument(help="Mechanism YAML files.")]
    = None,
    pareto: Annotated[Path | None, typer.Option(
        help="a study's pareto.csv: compare its rows (with --rows)")] = None,
    rows: Annotated[str | None, typer.Option(help='rows of pareto.csv, e.g. "1,3"')] = None,
    designs_opt: Annotated[str | None, typer.Option(
        "--designs", help='designs by their evaluation number #seq (the one numbering of '
        'the summary, report and pareto.csv\'s seq column), e.g. "12,40"')] = None,
    box: Annotated[float, typer.Option(help="dexterous set: ±box° simultaneous")] = 15.0,
    samples: SamplesOpt = 7,
    resolution: ResolutionOpt = "2.5",
    out_dir: Annotated[Path, typer.Option("--out", help="output folder")]
    = Path("results/compare"),
    as_json: JsonOpt = False,
    force_limit: Annotated[float, typer.Option(
        help="linear actuator force limit (N) of the force row")] = 150.0,
    max_torque: Annotated[float | None, typer.Option(
        help="servo torque limit (N·m) of a rotary family's force row; no default")] = None,
) -> None:
    """Compare designs side by side: volumes, inscribed shapes, GCI, κ, force, footprint,
    stroke use on the paper's motion; writes compare.md and overlaid slice plots.

    Each figure is the library's, with the request of the other commands (``workspace
    --inscribed``, ``dexterity``): see pkmlab.study.compare."""
    import csv as csv_mod

    from ..study.compare import compare_designs, comparison_markdown, plot_overlaid_slices
    from ..webreport import compare_html

    loaded = [_load(f) for f in (mech_files or [])]
    designs = [(m.name or f.stem, m) for f, m in zip(mech_files or [], loaded)]
    if pareto is not None:
        if not pareto.is_file() or not (pareto.parent / "evaluations.sqlite").is_file():
            _fail(ParameterError("--pareto", "a study's pareto.csv next to its "
                                 "evaluations.sqlite", str(pareto)))
        with open(pareto) as fh:
            table = list(csv_mod.DictReader(fh))
        study, all_records = _open_results(pareto.parent)
        records = {str(r["seq"]): r for r in all_records}
        if designs_opt is not None and rows is not None:
            _fail(ParameterError("--designs", "not given with --rows (one way to choose)",
                                 designs_opt))
        if designs_opt is not None:
            seqs = [s.strip() for s in designs_opt.split(",")]
            for s in seqs:
                if s not in records or records[s]["role"] != "candidate":
                    _fail(ParameterError("--designs", "evaluation numbers (seq) of "
                                         "candidates in evaluations.csv", s))
        else:
            wanted = [r.strip() for r in (rows or "1").split(",")]
            by_rank = {row["rank"]: row for row in table}
            for w in wanted:
                if w not in by_rank:
                    _fail(ParameterError("--rows", f"ranks present in {pareto.name} "
                                         f"(1..{len(table)})", w))
            seqs = [by_rank[w]["seq"] for w in wanted]
        for s in seqs:
            rec = records[s]
            try:
                designs.append((f"{study.name} #{s}", study.space.decode(rec["params"])))
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
    if not 1 <= samples <= 101:
        _fail(ParameterError("--samples", "an integer in [1, 101]", samples))
    for name, v in (("--force-limit", force_limit), ("--max-torque", max_torque)):
        if v is not None and not (math.isfinite(v) and v > 0):
            _fail(ParameterError(name, "a finite value > 0", v))
    try:
        with log_lines():
            table_rows = compare_designs(designs, box_deg=box, resolution=h, samples=samples,
                                         force_limit=force_limit, torque_limit=max_torque)
    except ParameterError as exc:
        _fail(exc)
    out_dir.mkdir(parents=True, exist_ok=True)
    md = comparison_markdown(table_rows, box)
    (out_dir / "compare.md").write_text(md)
    pngs = [plot_overlaid_slices(table_rows, out_dir / f"compare_{k}_slices.png", which=w)
            for k, w in (("dexterous", 1), ("level", 0))]
    with log_lines():
        page = compare_html(table_rows, out_dir / "compare.html", box_deg=box)
    names = ("compare.md", "compare.html", *(p.name for p in pngs if p is not None))
    if as_json:
        _emit({"designs": [{k: v for k, v in r.items() if k not in ("mechanism", "results")}
                           for r in table_rows],
               "files": [str(out_dir / n) for n in names]})
        return
    out.print(md, markup=False, highlight=False)
    out.print(f"wrote {escape(str(out_dir))}/compare.md, compare.html and overlaid slice plots; "
              f"open {escape(page.resolve().as_uri())} in a browser")


