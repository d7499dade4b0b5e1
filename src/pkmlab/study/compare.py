"""Side-by-side comparison of candidate designs under one evaluation protocol."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["compare_designs", "comparison_markdown", "plot_overlaid_slices", "COLUMNS"]

#: (key, header, format)
COLUMNS = [
    ("footprint_mm", "footprint radius (mm)", "{:.1f}"),
    ("constant_volume_cm3", "level workspace (cm³)", "{:.1f}"),
    ("dexterous_volume_cm3", "dexterous ±a (cm³)", "{:.2f}"),
    ("box_mm", "inscribed box (mm)", "{}"),
    ("cylinder_mm", "inscribed cylinder r × h (mm)", "{}"),
    ("gci", "GCI", "{:.4f}"),
    ("kappa_range", "κ range", "{}"),
    ("force_N", "force, every direction (N)", "{:.1f}"),
    ("paper_motion", "paper motion: stroke used / margin", "{}"),
]


def compare_designs(designs: list[tuple[str, object]], box_deg: float = 15.0,
                    resolution: float = 2.5, samples: int = 5, force_limit: float = 150.0,
                    seed: int = 0) -> list[dict]:
    """Evaluate each ``(label, mechanism)`` with the same protocol → one row per design.

    Protocol: the level constant-orientation workspace; the ±``box_deg`` simultaneous
    dexterous workspace (falling back to the level one for the inscribed shapes and the
    conditioning when it is empty); Angeles' characteristic length; 1,000 Monte-Carlo poses
    for GCI, κ and force; the paper's ±2 in / ±30° motion for stroke use.
    """
    from .. import dexterity as dx
    from ..trajectory import check_trajectory, paper_motion
    from ..workspaces import OrientationSet, workspace

    rows = []
    for label, mech in designs:
        const = workspace(mech, "constant", None, resolution)
        dex = workspace(mech, "dexterous",
                        OrientationSet.box(np.radians([box_deg] * 3), samples=samples),
                        resolution)
        ref = dex if not dex.empty else const
        box = ref.inscribed_box(samples=4000, seed=seed)
        cyl = ref.inscribed_cylinder(samples=4000, seed=seed)
        L = dx.characteristic_length(mech).length
        rng = np.random.default_rng(seed)
        p, R = dx.aggregate.sample_poses(ref, 1000, rng)
        valid = mech.inverse((p, R)).valid
        J = mech.jacobian((p[valid], R[valid]))
        kap = dx.condition_number(J, L)
        kap = kap[np.isfinite(kap)]
        force = dx.max_force_all_directions(J, force_limit)
        t, X = paper_motion(mech)
        rep = check_trajectory(mech, t, X)
        q = rep.q[np.all(np.isfinite(rep.q), axis=1)]
        used = (q.max() - q.min()) / (mech.stroke[1] - mech.stroke[0]) if len(q) else math.nan
        margin = min(rep.margin_low.min(), rep.margin_high.min())
        rows.append({
            "label": label,
            "mechanism": mech,
            "footprint_mm": float(np.max(np.linalg.norm(mech.base_points[:, :2], axis=1))),
            "constant_volume_cm3": const.volume / 1e3,
            "dexterous_volume_cm3": dex.volume / 1e3,
            "box_mm": " × ".join(f"{s:.1f}" for s in box.size),
            "cylinder_mm": f"{cyl.radius:.1f} × {cyl.height:.1f}",
            "gci": float(np.mean(1.0 / kap)) if len(kap) else 0.0,
            "kappa_range": f"{kap.min():.2f} … {kap.max():.2f}" if len(kap) else "—",
            "force_N": float(np.nanmin(force)) if len(force) else 0.0,
            "paper_motion": (f"{100 * used:.0f} % / {margin:.2f} mm"
                             + ("" if rep.fits else " (does not fit)")),
            "results": (const, dex),
            "reference": "dexterous" if not dex.empty else "level (dexterous empty)",
        })
    return rows


def comparison_markdown(rows: list[dict], box_deg: float) -> str:
    lines = [f"# Design comparison (dexterous set: ±{box_deg:g}° simultaneous)", "",
             "| | " + " | ".join(r["label"] for r in rows) + " |",
             "|---" * (len(rows) + 1) + "|"]
    for key, header, fmt in COLUMNS:
        lines.append(f"| {header} | " + " | ".join(
            fmt.format(r[key]) if not isinstance(r[key], str) else r[key] for r in rows) + " |")
    lines.append("| inscribed shapes / GCI / κ / force over | "
                 + " | ".join(r["reference"] for r in rows) + " |")
    return "\n".join(lines) + "\n"


def plot_overlaid_slices(rows: list[dict], path: Path, which: int = 1, window: float = 152.4,
                         spacing: float = 12.7) -> Path:
    """Outlines of every design's workspace (``which``: 0 level, 1 dexterous) per slice."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    res = [r["results"][which] for r in rows]
    spans = [x.metrics()["z_range_mm"] for x in res if not x.empty]
    if not spans:
        res = [r["results"][0] for r in rows]
        spans = [x.metrics()["z_range_mm"] for x in res if not x.empty]
    lo = min(s[0] for s in spans)
    hi = max(s[1] for s in spans)
    n = int(math.floor((hi - lo) / spacing)) + 1
    levels = lo + 0.5 * ((hi - lo) - (n - 1) * spacing) + spacing * np.arange(n)
    cols = int(math.ceil(math.sqrt(n)))
    nrows = int(math.ceil(n / cols))
    fig, axes = plt.subplots(nrows, cols, figsize=(2.4 * cols, 2.4 * nrows + 0.8),
                             squeeze=False, constrained_layout=True)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for a, ax in enumerate(axes.ravel()):
        ax.set_xlim(-window / 2, window / 2)
        ax.set_ylim(-window / 2, window / 2)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=6)
        if a >= n:
            ax.axis("off")
            continue
        z = levels[a]
        for k, w in enumerate(res):
            if w.empty or len(w.xs) < 2 or len(w.ys) < 2:
                continue
            sec = w.slice(z).astype(float)
            if sec.any():
                ax.contour(w.xs, w.ys, sec.T, levels=[0.5], colors=[colours[k % len(colours)]],
                           linewidths=1.2)
        ax.set_title(f"z = {z:.1f} mm", fontsize=7)
    handles = [plt.Line2D([], [], color=colours[k % len(colours)], label=r["label"])
               for k, r in enumerate(rows)]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(rows), 4), fontsize=8)
    fig.suptitle(f"{'dexterous' if which else 'level'} workspaces, {window:g} mm windows every "
                 f"{spacing:g} mm (lowest top-left)", fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
