"""Side-by-side comparison of candidate designs under one evaluation protocol.

Every number comes from the library function that computes it elsewhere, with the same
request, so a compare row can be reproduced with the other commands:

* workspaces: :func:`pkmlab.workspace` — the level constant-orientation workspace and the
  ±``box_deg`` simultaneous dexterous one with ``samples`` per angle (default 7, as
  ``pkmlab workspace`` and ``pkmlab dexterity``);
* inscribed box and cylinder: :meth:`WorkspaceResult.inscribed_box` /
  :meth:`~WorkspaceResult.inscribed_cylinder` with their defaults — the call of
  ``pkmlab workspace --inscribed`` — with their status;
* L: :func:`pkmlab.dexterity.resolve_length` (Angeles'), with its status;
* GCI: :func:`pkmlab.dexterity.gci_grid` (every voxel × orientation sample, singular poses
  counting 0); κ range: the grid's smallest κ … :func:`pkmlab.dexterity.worst_case`'s worst κ
  (inf with a singular pose found inside or on the boundary); force: ``worst_case``'s
  smallest all-direction force;
* the paper's ±2 in / ±30° motion: :func:`pkmlab.motion.check_trajectory`.

The inscribed shapes, GCI, κ and force are over the dexterous workspace, or over the level one
when the dexterous one is empty (the row's ``reference`` says which).

The protocol follows the mechanism's mobility (issue 24), and a cell that does not apply says
why instead of holding a number:

* x, y, z free without a free rotation (the deltas): the level workspace is the workspace (the
  orientation is fixed), everything above is computed over it; the dexterous set and the
  paper's motion (it turns the platform ±30°) are not applicable;
* planar (3-RPR, five-bar): :func:`pkmlab.workspaces.planar.planar_workspace`, the area with its
  guaranteed bracket at the nominal φ and, with φ free, the dexterous area over ±``box_deg``;
  GCI and κ from the ``planar_workspace`` evaluator (same numbers as a study);
* dependent coordinates (3-PRS): :func:`pkmlab.workspaces.tripod.tripod_workspace` over
  |θx|, |θy| <= ``box_deg``, its sampled (z, θx, θy) volume and parasitic motions.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np

from .. import dexterity as dx
from ..escaping import markdown_text
from ..motion import check_trajectory, paper_motion
from ..units import effort_limit
from ..workspaces import OrientationSet, workspace

log = logging.getLogger(__name__)

__all__ = ["compare_designs", "comparison_markdown", "plot_overlaid_slices", "COLUMNS"]

#: (key, header, format)
COLUMNS = [
    ("footprint_mm", "footprint radius (mm)", "{:.1f}"),
    ("constant_volume_cm3", "level workspace (cm³)", "{:.1f}"),
    ("dexterous_volume_cm3", "dexterous ±a (cm³)", "{:.2f}"),
    ("box_mm", "inscribed box (mm)", "{}"),
    ("cylinder_mm", "inscribed cylinder r × h (mm)", "{}"),
    ("L_mm", "characteristic length L (mm)", "{}"),
    ("gci", "GCI (grid; singular poses count 0)", "{:.4f}"),
    ("kappa_range", "κ range (grid min … worst case)", "{}"),
    ("force_N", "force, every direction: worst case (N)", "{:.1f}"),
    ("singular", "singular pose (inside or on the boundary)", "{}"),
    ("paper_motion", "paper motion: stroke used / margin", "{}"),
]


def _shape_text(shape, text: str) -> str:
    return text if shape.status == "ok" else f"{shape.status}: {text}"


def _has_xyz(mech) -> bool:
    mob = mech.mobility
    return not mob.dependent and {"x", "y", "z"} <= set(mob.coordinates)


def _fixed_orientation(mech) -> bool:
    return not {"theta_x", "theta_y", "theta_z"} & set(mech.mobility.coordinates)


def _na(mech, what: str) -> str:
    mob = mech.mobility
    return f"n/a: {what} ({mob.name} mobility: {', '.join(mob.coordinates)})"


def _base_row(label, mech, request) -> dict:
    """A row whose cells all say 'not applicable' until filled."""
    row = {"label": label, "mechanism": mech, "request": request,
           "footprint_mm": mech.footprint()["base_radius"], "results": (None, None)}
    for key, _, _ in COLUMNS[1:]:
        row[key] = _na(mech, "not computed for this mobility")
    return row


def _planar_row(label, mech, request, box_deg, resolution, samples) -> dict:
    from types import SimpleNamespace

    from ..workspaces.planar import planar_workspace
    from .evaluators.planar_workspace import PlanarWorkspace, PlanarWorkspaceSpec
    from .evaluators.registry import Context

    row = _base_row(label, mech, request)
    const = planar_workspace(mech, "constant", None, resolution)
    row["constant_volume_cm3"] = _area_text(const)
    rotates = "theta_z" in mech.mobility.coordinates and box_deg > 0
    phi0 = float(mech.nominal_pose[5])
    a = math.radians(box_deg)
    if rotates:
        dex = planar_workspace(mech, "dexterous", (phi0 - a, phi0 + a), resolution,
                               samples=samples)
        row["dexterous_volume_cm3"] = _area_text(dex)
        plan = PlanarWorkspaceSpec(kind="dexterous", phi=[phi0 - a, phi0 + a],
                                   resolution=resolution, samples=samples)
    else:
        row["dexterous_volume_cm3"] = _na(mech, "the orientation is fixed")
        plan = PlanarWorkspaceSpec(kind="constant", resolution=resolution)
    ctx = Context(SimpleNamespace(planar_workspace=plan), seed=0)
    m = PlanarWorkspace().compute(mech, ctx)
    row["gci"] = m["gci_planar"] if m["gci_planar"] is not None else ctx.notes["gci_planar"]
    k = m["sampled_planar_worst_kappa"]
    row["kappa_range"] = (f"worst sampled {k:.2f}" if k is not None
                          else ctx.notes.get("sampled_planar_worst_kappa", "inf"))
    row["reference"] = ("planar: area (cm²) with its guaranteed bracket; GCI / κ over the "
                        + ("dexterous" if rotates else "constant") + " cells sampled")
    row["planar"] = {"constant": const.metrics(), "gci_planar": m["gci_planar"],
                     "sampled_planar_worst_kappa": k}
    return row


def _area_text(res) -> str:
    lo, hi = res.bracket
    exact = "" if res.exact is None else f", exact {res.exact / 100:.1f}"
    return (f"area {res.estimate / 100:.1f} cm² (grid), bracket {lo / 100:.1f} … "
            f"{hi / 100:.1f} cm²{exact}")


def _tripod_row(label, mech, request, box_deg, resolution) -> dict:
    from ..workspaces.tripod import tripod_workspace

    row = _base_row(label, mech, request)
    res = tripod_workspace(mech, math.radians(box_deg), resolution_z=resolution)
    m = res.metrics()
    lo, hi = m["volume_bracket_mm_deg2"]
    row["dexterous_volume_cm3"] = (f"bracket {lo:.4g} … {hi:.4g} mm·deg² (sampled "
                                   f"{m['sampled_volume_mm_deg2']:.4g}) over (z, θx, θy), "
                                   f"|θx|, |θy| <= {box_deg:g}°")
    row["constant_volume_cm3"] = _na(mech, "x, y, θz follow z, θx, θy (parasitic: "
                                     + (f"|x, y| up to {m['parasitic_xy_max_mm']:.2f} mm"
                                        if m["parasitic_xy_max_mm"] is not None
                                        else "empty") + ")")
    row["reference"] = ("dependent coordinates: (z, θx, θy) volume with its guaranteed "
                        "bracket; grid estimate sampled")
    row["tripod"] = m
    return row


def compare_designs(designs: list[tuple[str, object]], box_deg: float = 15.0,
                    resolution: float = 2.5, samples: int = 7, force_limit: float = 150.0,
                    seed: int = 0, torque_limit: float | None = None) -> list[dict]:
    """Evaluate each ``(label, mechanism)`` with the same protocol → one row per design.

    Args:
        designs: ``(label, mechanism)`` pairs.
        box_deg: half-range (deg) of the simultaneous Euler box of the dexterous workspace.
        resolution: grid spacing (mm).
        samples: orientation samples per angle of the box.
        force_limit: linear actuator force limit (N) of the force capability.
        seed: seed of the inscribed shapes' verification sample.
        torque_limit: servo torque limit (N·m) of a rotary family's force capability; no
            linear default is ever applied to a servo: without it the force cell of a rotary
            design says why it is empty.

    Returns:
        One dict per design: the :data:`COLUMNS` values (text or numbers), plus
        ``request`` (the workspace request), ``characteristic_length``, ``worst_case``,
        ``gci_result``, ``inscribed_box``, ``inscribed_cylinder`` (JSON-ready dicts with
        their statuses), ``reference``, and ``mechanism`` / ``results`` (the objects).
    """
    oset = OrientationSet.box(np.radians([box_deg] * 3), samples=samples)
    request = {"dexterous_set": f"±{box_deg:g}° simultaneous Euler box, {samples} samples per "
                                f"angle ({samples ** 3} orientations)",
               "resolution_mm": float(resolution), "force_limit_N": float(force_limit),
               "torque_limit_N_m": None if torque_limit is None else float(torque_limit),
               "inscribed": f"inscribed_box() / inscribed_cylinder() defaults (seed {seed})"}
    rows = []
    for i, (label, mech) in enumerate(designs):
        log.info("compare: design %d of %d (%s)", i + 1, len(designs), label)
        if mech.mobility.dependent:
            rows.append(_tripod_row(label, mech, request, box_deg, resolution))
            continue
        if not _has_xyz(mech):
            rows.append(_planar_row(label, mech, request, box_deg, resolution, samples))
            continue
        fixed = _fixed_orientation(mech)
        const = workspace(mech, "constant", None, resolution)
        dex = None if fixed else workspace(mech, "dexterous", oset, resolution)
        ref = const if fixed or dex.empty else dex
        box = ref.inscribed_box(seed=seed)
        cyl = ref.inscribed_cylinder(seed=seed)
        length = dx.resolve_length(mech)
        grid = dx.kappa_grid(mech, ref, length)
        gci = dx.gci_grid(mech, ref, grid=grid)
        kmin = dx.kappa_statistics(grid.kappa[grid.valid]).min
        effort = effort_limit(mech.actuator_unit, force_limit, torque_limit)
        wc = dx.worst_case(mech, ref, length, force_limit if effort is None else effort)
        motion_text = _na(mech, "the paper's motion turns the platform ±30°") if fixed \
            else _paper_motion_text(mech, length)
        L_text = (f"{length.length:.2f} ({length.status})" if length.length is not None
                  else f"n/a ({length.status}: {length.reason or 'no rotation is free'})")
        rows.append({
            "label": label,
            "mechanism": mech,
            "request": request,
            "footprint_mm": mech.footprint()["base_radius"],
            "constant_volume_cm3": const.volume / 1e3,
            "dexterous_volume_cm3": _na(mech, "the orientation is fixed") if fixed
            else dex.volume / 1e3,
            "box_mm": _shape_text(box, " × ".join(f"{s:.1f}" for s in box.size)
                                  if box.ok else box.reason),
            "cylinder_mm": _shape_text(cyl, f"{cyl.radius:.1f} × {cyl.height:.1f}"
                                       if cyl.ok else cyl.reason),
            "inscribed_box": box.as_dict(),
            "inscribed_cylinder": cyl.as_dict(),
            "L_mm": L_text,
            "characteristic_length": length.as_dict(),
            "gci": gci.gci if gci.ok else gci.reason,
            "gci_result": {"gci": gci.gci if gci.ok else None, "samples": gci.samples,
                           "singular": gci.singular, "rejected": gci.rejected,
                           "method": gci.method, "reason": gci.reason},
            "kappa_range": (f"{kmin:.2f} … {wc.worst_kappa:.2f}" if wc.ok and not wc.singular
                            else f"{kmin:.2f} … inf" if wc.ok else wc.reason),
            "force_N": (_na(mech, "servos need a torque limit (--max-torque, N·m)")
                        if effort is None and mech.actuator_unit == "rad"
                        else wc.min_force if wc.ok else wc.reason),
            "singular": ("not found (not excluded between samples)" if not wc.singular
                         else f"yes: {wc.reason}") if wc.ok
            else wc.status,
            "worst_case": wc.as_dict(),
            "paper_motion": motion_text,
            "results": (const, dex),
            "reference": ("level (the orientation is fixed)" if fixed else "dexterous"
                          if not dex.empty else "level (dexterous empty)"),
        })
    return rows


def _paper_motion_text(mech, length) -> str:
    motion = paper_motion(mech)
    rep = check_trajectory(mech, motion.t, motion.poses, characteristic_length=length)
    q = rep.q[np.all(np.isfinite(rep.q), axis=1)]
    used = (q.max() - q.min()) / (mech.stroke[1] - mech.stroke[0]) if len(q) else math.nan
    margin = min(rep.margin_low.min(), rep.margin_high.min())
    return f"{100 * used:.0f} % / {margin:.2f} mm" + ("" if rep.fits else " (does not fit)")


def comparison_markdown(rows: list[dict], box_deg: float | None = None) -> str:
    """The rows as a Markdown table, with the request they were evaluated under."""
    req = rows[0]["request"] if rows else {}
    lines = [f"# Design comparison (dexterous set: {req.get('dexterous_set', '')}, grid "
             f"{req.get('resolution_mm', float('nan')):g} mm)", "",
             "| | " + " | ".join(markdown_text(r["label"]) for r in rows) + " |",
             "|---" * (len(rows) + 1) + "|"]
    for key, header, fmt in COLUMNS:
        lines.append(f"| {header} | " + " | ".join(
            fmt.format(r[key]) if not isinstance(r[key], str) else markdown_text(r[key])
            for r in rows) + " |")
    lines.append("| inscribed shapes / GCI / κ / force over | "
                 + " | ".join(markdown_text(r["reference"]) for r in rows) + " |")
    lines += ["", f"Inscribed shapes: {req.get('inscribed', '')}, the call of "
              "`pkmlab workspace --inscribed`. L: Angeles' characteristic length (status in "
              "brackets). GCI: every voxel × orientation sample. κ range and force: the grid's "
              "smallest κ and `pkmlab.dexterity.worst_case` (every voxel and column end × "
              f"orientation sample; {_limits_text(req)}; inf / 0 N when a singular pose is "
              "found inside or on the boundary, at a sample or column end or by a sign "
              "change of det J between neighbours; otherwise a singular pose between samples "
              "is not excluded)."]
    return "\n".join(lines) + "\n"


def _limits_text(req: dict) -> str:
    """The actuator limits the force row was computed with."""
    torque = req.get("torque_limit_N_m")
    servos = ("servos ±" + f"{torque:g} N·m" if torque is not None
              else "servos: no torque limit given")
    return f"linear actuators ±{req.get('force_limit_N', float('nan')):g} N, {servos}"


def plot_overlaid_slices(rows: list[dict], path: Path, which: int = 1,
                         layout: str = "auto") -> Path | None:
    """Outlines of every design's workspace (``which``: 0 level, 1 dexterous; the level ones
    when every dexterous workspace is empty) per section, on one layout scaled to all of them
    (``layout="paper"``: Hopkins & Williams' 152.4 mm every 12.7 mm), as a PNG at ``path``;
    designs without an x-y × z workspace (planar, 3-PRS) are left out, and ``None`` is returned
    (nothing written) when no design has one."""
    from ..workspaces.output.plots import overlay_figure

    def pick(k):
        return [(r["label"], r["results"][k]) for r in rows if r["results"][k] is not None]

    res = pick(which)
    if all(x.empty for _, x in res):
        res, which = pick(0), 0
    if not res:
        return None
    kind = "dexterous" if which == 1 else "level"
    fig = overlay_figure([x for _, x in res], [lab for lab, _ in res], layout=layout,
                         title=f"{kind} workspaces, overlaid")
    fig.savefig(Path(path), dpi=110)
    return Path(path)
