"""Slice plots in the format of Hopkins & Williams (2002), Figs. 7-8.

A grid of horizontal top-view sections through a square window, lowest slice top-left,
advancing left-to-right then top-to-bottom, each labelled with its height.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["plot_slices", "slice_figure"]


def slice_figure(result, window: float = 152.4, spacing: float = 12.7, centre=None,
                 columns: int | None = None, values: np.ndarray | None = None,
                 cmap: str = "viridis", label: str = ""):
    """Build the figure (a :class:`matplotlib.figure.Figure`, no pyplot state, no global
    backend); ``values (nx, ny, nz)`` colours the sections (nearest voxel layer)."""
    from matplotlib.figure import Figure

    levels = result.slice_levels(spacing)
    n = max(len(levels), 1)
    cols = columns or int(math.ceil(math.sqrt(n)))
    rows = int(math.ceil(n / cols))
    cx, cy = centre if centre is not None else result.mechanism.nominal_pose[:2]
    half = window / 2
    h = result.resolution
    fig = Figure(figsize=(2.2 * cols, 2.2 * rows + 0.6), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    extent = (result.xs[0] - h / 2, result.xs[-1] + h / 2, result.ys[0] - h / 2,
              result.ys[-1] + h / 2) if len(result.xs) else (0, 1, 0, 1)
    im = None
    if values is not None and not np.any(np.isfinite(values)):
        values = None                     # nothing to colour: plain sections
    if values is not None:
        vmin, vmax = np.nanmin(values), np.nanmax(values)
    for a, ax in enumerate(axes.ravel()):
        ax.set_xlim(cx - half, cx + half)
        ax.set_ylim(cy - half, cy + half)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=6)
        if a >= len(levels):
            ax.axis("off")
            continue
        z = levels[a]
        sec = result.slice(z)
        if values is None:
            img = np.where(sec, 1.0, np.nan).T
            ax.imshow(img, origin="lower", extent=extent, cmap="Greys", vmin=0, vmax=1.3,
                      interpolation="nearest")
        else:
            k = int(np.clip(round((z - result.zs[0]) / h), 0, len(result.zs) - 1))
            img = np.where(sec, values[:, :, k], np.nan).T
            im = ax.imshow(img, origin="lower", extent=extent, cmap=cmap, vmin=vmin, vmax=vmax,
                           interpolation="nearest")
        ax.set_title(f"z = {z:.1f} mm", fontsize=7)
    if im is not None:
        fig.colorbar(im, ax=axes, shrink=0.6, label=label)
    name = getattr(result.mechanism, "name", "") or result.mechanism.family
    if result.empty:
        axes.ravel()[0].text(0.5, 0.5, "empty: no position satisfies\nthe constraints",
                             ha="center", va="center", transform=axes.ravel()[0].transAxes,
                             fontsize=8)
    empty = " (empty)" if result.empty else ""
    fig.suptitle(f"{name}: {result.kind} workspace{empty}\n{window:g} × {window:g} mm top views "
                 f"every {spacing:g} mm, lowest top-left", fontsize=9)
    return fig


def plot_slices(result, path, **kw) -> Path:
    """Write the slice grid to ``path`` (PNG). An empty workspace gets a labelled blank."""
    path = Path(path)
    slice_figure(result, **kw).savefig(path, dpi=120)
    return path
