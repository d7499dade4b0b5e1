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
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np

from .. import dexterity as dx
from ..escaping import markdown_text
from ..motion import check_trajectory, paper_motion
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


def compare_designs(designs: list[tuple[str, object]], box_deg: float = 15.0,
                    resolution: float = 2.5, samples: int = 7, force_limit: float = 150.0,
                    seed: int = 0) -> list[dict]:
    """Evaluate each ``(label, mechanism)`` with the same protocol → one row per design.

    Args:
        designs: ``(label, mechanism)`` pairs.
        box_deg: half-range (deg) of the simultaneous Euler box of the dexterous workspace.
        resolution: grid spacing (mm).
        samples: orientation samples per angle of the box.
        force_limit: actuator force limit (N) of the force capability.
        seed: seed of the inscribed shapes' verification sample.

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
               "inscribed": f"inscribed_box() / inscribed_cylinder() defaults (seed {seed})"}
    rows = []
    for i, (label, mech) in enumerate(designs):
        log.info("compare: design %d of %d (%s)", i + 1, len(designs), label)
        const = workspace(mech, "constant", None, resolution)
        dex = workspace(mech, "dexterous", oset, resolution)
        ref = dex if not dex.empty else const
        box = ref.inscribed_box(seed=seed)
        cyl = ref.inscribed_cylinder(seed=seed)
        length = dx.resolve_length(mech)
        grid = dx.kappa_grid(mech, ref, length)
        gci = dx.gci_grid(mech, ref, grid=grid)
        kmin = dx.kappa_statistics(grid.kappa[grid.valid]).min
        wc = dx.worst_case(mech, ref, length, force_limit)
        motion = paper_motion(mech)
        t, X = motion.t, motion.poses
        rep = check_trajectory(mech, t, X, characteristic_length=length)
        q = rep.q[np.all(np.isfinite(rep.q), axis=1)]
        used = (q.max() - q.min()) / (mech.stroke[1] - mech.stroke[0]) if len(q) else math.nan
        margin = min(rep.margin_low.min(), rep.margin_high.min())
        L_text = f"{length.length:.2f} ({length.status})"
        rows.append({
            "label": label,
            "mechanism": mech,
            "request": request,
            "footprint_mm": mech.footprint()["base_radius"],
            "constant_volume_cm3": const.volume / 1e3,
            "dexterous_volume_cm3": dex.volume / 1e3,
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
            "force_N": wc.min_force if wc.ok else wc.reason,
            "singular": ("not found (not excluded between samples)" if not wc.singular
                         else f"yes: {wc.reason}") if wc.ok
            else wc.status,
            "worst_case": wc.as_dict(),
            "paper_motion": (f"{100 * used:.0f} % / {margin:.2f} mm"
                             + ("" if rep.fits else " (does not fit)")),
            "results": (const, dex),
            "reference": "dexterous" if not dex.empty else "level (dexterous empty)",
        })
    return rows


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
              "orientation sample; inf / 0 N when a singular pose is found inside or on the "
              "boundary, at a sample or column end or by a sign change of det J between "
              "neighbours; otherwise a singular pose between samples is not excluded)."]
    return "\n".join(lines) + "\n"


def plot_overlaid_slices(rows: list[dict], path: Path, which: int = 1,
                         layout: str = "auto") -> Path:
    """Outlines of every design's workspace (``which``: 0 level, 1 dexterous; the level ones
    when every dexterous workspace is empty) per section, on one layout scaled to all of them
    (``layout="paper"``: Hopkins & Williams' 152.4 mm every 12.7 mm), as a PNG at ``path``."""
    from ..workspaces.output.plots import overlay_figure

    res = [r["results"][which] for r in rows]
    if all(x.empty for x in res):
        res, which = [r["results"][0] for r in rows], 0
    kind = "dexterous" if which == 1 else "level"
    fig = overlay_figure(res, [r["label"] for r in rows], layout=layout,
                         title=f"{kind} workspaces, overlaid")
    fig.savefig(Path(path), dpi=110)
    return Path(path)
