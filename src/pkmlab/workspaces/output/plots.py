"""Slice plots in the format of Hopkins & Williams (2002), Figs. 7-8.

A grid of horizontal top-view sections through a square window, lowest slice top-left,
advancing left-to-right then top-to-bottom, each labelled with its height. The window and the
spacing come from :func:`.slicing.slice_layout`: scaled to the workspace by default, or the
paper's 152.4 mm every 12.7 mm (``layout="paper"``).
"""

from __future__ import annotations

import io
import math
import textwrap
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ...runtime.atomic import write_bytes
from .slicing import MAX_PANELS, SliceLayout, slice_layout

__all__ = ["SlicePicture", "overlay_figure", "plot_slices", "png_bytes", "sections_layout",
           "slice_figure", "write_slice_pictures"]


class SlicePicture(NamedTuple):
    """One picture of :func:`write_slice_pictures`: ``values (nx, ny, nz)`` colours the
    sections (``None``: plain grey sections), named ``label`` on the colour bar; written as
    PNG at ``dpi``."""

    path: Path
    values: np.ndarray | None = None
    label: str = ""
    dpi: int = 120


def slice_figure(result, window: float | None = None, spacing: float | None = None,
                 centre=None, columns: int | None = None, values: np.ndarray | None = None,
                 cmap: str = "viridis", label: str = "", layout: str = "auto",
                 max_panels: int = MAX_PANELS, overlay=None, overlay_label: str = ""):
    """Build the figure (a :class:`matplotlib.figure.Figure`, no pyplot state, no global
    backend); ``values (nx, ny, nz)`` colours the sections (nearest voxel layer).
    ``overlay(z)`` → closed polygons ``[(n, 2) mm, ...]`` drawn in red on the section at
    height z (e.g. a required task region, :func:`pkmlab.requirements.task.task_outline`),
    named ``overlay_label`` in the title.

    ``layout`` (``"auto"`` or ``"paper"``), ``window``, ``spacing``, ``centre`` and
    ``max_panels`` choose the sections (:func:`.slicing.slice_layout`; ``None``: the
    layout's)."""
    sections = _Sections(result, window, spacing, centre, columns, layout, max_panels,
                         overlay, overlay_label)
    sections.paint(values, cmap, label)
    return sections.fig


def write_slice_pictures(result, pictures: list[SlicePicture], cmap: str = "viridis",
                         **grid) -> list[Path]:
    """Write several slice grids of one workspace that differ only in their colouring (for
    example the plain sections and a κ map), building the panel grid, its titles, overlay and
    ticks once: about 70 ms of each picture. ``grid``: the layout and overlay keywords of
    :func:`slice_figure`. Each picture is what :func:`slice_figure` draws with its values."""
    sections = _Sections(result, **grid)
    written = []
    for pic in pictures:
        sections.paint(pic.values, cmap, pic.label)
        written.append(write_bytes(Path(pic.path), png_bytes(sections.fig, pic.dpi)))
    return written


def png_bytes(fig, dpi: int) -> bytes:
    """``fig`` as PNG at ``dpi``, with zlib's fastest compression: slice grids are flat
    colours, about 9 % larger than at the default level and 10 ms faster each."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, pil_kwargs={"compress_level": 1})
    return buf.getvalue()


def sections_layout(result, overlay=None, layout: str = "auto", window: float | None = None,
                    spacing: float | None = None, centre=None,
                    max_panels: int = MAX_PANELS) -> SliceLayout:
    """The slice layout of ``result`` (:func:`.slicing.slice_layout`) that also shows the
    ``overlay``'s sections at its heights: the ``auto`` window grows to cover them unless a
    window or centre is given (the ``paper`` layout stays the paper's, clipped)."""
    lay = slice_layout(result, layout, window, spacing, centre, max_panels)
    if overlay is None or layout != "auto" or window is not None or centre is not None:
        return lay
    polys = [np.asarray(p, dtype=float) for z in lay.levels for p in overlay(z)]
    if not polys:
        return lay
    pts = np.concatenate(polys)
    return slice_layout(result, layout, window, spacing, centre, max_panels,
                        cover=(pts.min(axis=0), pts.max(axis=0)))


class _Sections:
    """A slice grid's figure without its colouring: panels, titles, overlay, ticks, title.
    :meth:`paint` draws (or redraws) the sections' images and colour bar."""

    def __init__(self, result, window=None, spacing=None, centre=None, columns=None,
                 layout="auto", max_panels=MAX_PANELS, overlay=None, overlay_label=""):
        lay = sections_layout(result, overlay, layout, window, spacing, centre, max_panels)
        self.result, self.levels = result, lay.levels
        h = result.resolution
        name = getattr(result.mechanism, "name", "") or result.mechanism.family
        empty = " (empty)" if result.empty else ""
        drawn = f"; red: {overlay_label}" if overlay is not None and overlay_label else ""
        self.fig, self.axes = _panel_grid(
            lay, columns, 2.2, 0.8,
            title=f"{name}: {result.kind} workspace{empty}\n{lay.describe()}{drawn}")
        self.extent = (result.xs[0] - h / 2, result.xs[-1] + h / 2, result.ys[0] - h / 2,
                       result.ys[-1] + h / 2) if len(result.xs) else (0, 1, 0, 1)
        for z, ax in zip(self.levels, self.axes.ravel()):
            for poly in (overlay(z) if overlay is not None else ()):
                if len(poly) == 1:
                    ax.plot(poly[:, 0], poly[:, 1], "r.", ms=3, zorder=3)
                else:
                    ax.plot(poly[:, 0], poly[:, 1], "r-", lw=1, zorder=3)
        if result.empty:
            first = self.axes.ravel()[0]
            first.text(0.5, 0.5, "empty: no position satisfies\nthe constraints",
                       ha="center", va="center", transform=first.transAxes, fontsize=8)
        self._painted: list = []                 # the images of the current colouring
        self._bar = None
        # where the panels are before a colour bar shrinks and re-anchors them
        self._places = [(ax.get_position(original=True), ax.get_anchor())
                        for ax in self.axes.ravel()]
        self._width = self.fig.get_figwidth()    # inches, without a colour bar

    def paint(self, values, cmap: str, label: str) -> None:
        """Draw the sections coloured by ``values`` (``None``: grey), replacing the previous
        colouring and its colour bar (the panels get their places back)."""
        if self._bar is not None:             # before its image, which it refers to
            self._bar.remove()
            self._bar = None
            self.fig.set_figwidth(self._width)
            for ax, (pos, anchor) in zip(self.axes.ravel(), self._places):
                ax.set_position(pos)
                ax.set_anchor(anchor)
        for artist in self._painted:
            artist.remove()
        self._painted = []
        result, h = self.result, self.result.resolution
        if values is not None and not np.any(np.isfinite(values)):
            values = None                     # nothing to colour: plain sections
        if values is not None:
            vmin, vmax, extend = _colour_range(values)
        im = None
        for a, ax in enumerate(self.axes.ravel()[:len(self.levels)]):
            z = self.levels[a]
            sec = result.slice(z)
            if values is None:
                img = np.where(sec, 1.0, np.nan).T
                self._painted.append(ax.imshow(img, origin="lower", extent=self.extent,
                                               cmap="Greys", vmin=0, vmax=1.3,
                                               interpolation="nearest"))
            else:
                k = int(np.clip(round((z - result.zs[0]) / h), 0, len(result.zs) - 1))
                img = np.where(sec, values[:, :, k], np.nan).T
                im = ax.imshow(img, origin="lower", extent=self.extent, cmap=cmap, vmin=vmin,
                               vmax=vmax, interpolation="nearest")
                self._painted.append(im)
        if im is not None:
            note = {"neither": "", "max": "\n(colours capped at the 99th percentile)",
                    "min": "\n(colours floored at the 1st percentile)",
                    "both": "\n(colours: 1st to 99th percentile)"}[extend]
            self._bar = self._colour_bar(im, extend, label + note)

    def _colour_bar(self, im, extend: str, label: str):
        """A colour bar in :data:`BAR_IN` inches added to the figure's right, its label
        wrapped to the bar's length (0.6 of the panels' height; about 0.55 em per character):
        a bar taken from the panels' width had no room for its ticks and label on a grid of
        one or two columns, and the label ran beyond the figure's edges."""
        W, w = self._width, self._width + BAR_IN
        self.fig.set_figwidth(w)
        for ax, (pos, anchor) in zip(self.axes.ravel(), self._places):
            ax.set_position([pos.x0 * W / w, pos.y0, pos.width * W / w, pos.height])
            ax.set_anchor(anchor)
        sp, fs = self.fig.subplotpars, 8
        height = sp.top - sp.bottom
        cax = self.fig.add_axes([(W - 0.05) / w, sp.bottom + 0.2 * height, 0.12 / w,
                                 0.6 * height])
        chars = max(int(0.6 * height * self.fig.get_figheight() * 72 / (0.55 * fs)), 12)
        bar = self.fig.colorbar(im, cax=cax, extend=extend)
        bar.set_label("\n".join(textwrap.fill(line, chars) for line in label.split("\n")),
                      fontsize=fs)
        bar.ax.tick_params(labelsize=7)
        return bar


#: inches added to a slice grid's right for its colour bar, the bar's ticks and its label
BAR_IN = 1.1


def _panel_grid(lay: SliceLayout, columns: int | None, size: float, top: float,
                bottom: float = 0.0, title: str = "", fontsize: float = 9):
    """A figure of square panels of ``size`` inches, one per section of ``lay`` (``columns``
    per row, default about the square root of their number), with fixed margins: ``top``
    inches of height for the title (more when ``title``, wrapped to the figure's width, needs
    it) and ``bottom`` for a legend. Every used panel has its title
    (the height) and the layout's window, ticks on the outer panels only
    (:func:`_outer_ticks`); the panels left over are hidden. Fixed margins and outer ticks
    only draw several times faster than a constrained layout with every panel's own ticks:
    matplotlib builds every tick as artists, which dominated the time of a ``pkmlab
    workspace`` run and of a study's design export. What is drawn afterwards keeps the
    window (the limits are set, so autoscaling is off)."""
    from matplotlib.figure import Figure

    n = max(len(lay.levels), 1)
    cols = columns or int(math.ceil(math.sqrt(n)))
    rows = int(math.ceil(n / cols))
    W = size * cols
    # a line of the title wraps at the figure's width (about 0.55 em per character)
    chars = max(int(W * 72 / (0.55 * fontsize)), 20)
    title = "\n".join(textwrap.fill(line, chars) for line in title.split("\n"))
    # the lines, their gap to the figure's edge and the panels' own titles below them
    top = max(top, 0.45 + (title.count("\n") + 1) * 1.3 * fontsize / 72) if title else top
    H = size * rows + top + bottom
    fig = Figure(figsize=(W, H))
    if title:
        fig.suptitle(title, fontsize=fontsize)
    axes = fig.subplots(rows, cols, squeeze=False)
    fig.subplots_adjust(left=0.45 / W, right=1 - 0.15 / W, bottom=(0.3 + bottom) / H,
                        top=1 - top / H, wspace=0.12, hspace=0.25)
    for a, ax in enumerate(axes.ravel()):
        ax.set_aspect("equal")
        ax.tick_params(labelsize=6)
        if a < len(lay.levels):
            ax.set_title(f"z = {lay.levels[a]:.1f} mm", fontsize=7)
        else:
            ax.axis("off")
    (cx, cy), half = lay.centre, lay.window / 2
    _outer_ticks(axes, len(lay.levels), (cx - half, cx + half), (cy - half, cy + half))
    return fig, axes


def _outer_ticks(axes, used: int, xlim: tuple[float, float], ylim: tuple[float, float]) -> None:
    """The same window (mm) on every used panel (set before drawing: autoscaling is then
    off), and ticks on the outside of the used panels only: y ticks in the first column, x
    ticks under every used panel that has no used panel below it; the inner panels have
    none."""
    from matplotlib.ticker import MaxNLocator

    def ticks(lo, hi):
        t = MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
        return t[(t >= lo - 1e-9 * abs(hi - lo)) & (t <= hi + 1e-9 * abs(hi - lo))]

    xt, yt = ticks(*xlim), ticks(*ylim)
    rows, cols = axes.shape
    for a in range(min(used, rows * cols)):
        ax = axes[a // cols, a % cols]
        ax.set_xticks(xt if a + cols >= used else [])
        ax.set_yticks(yt if a % cols == 0 else [])
        # an axis without ticks draws nothing, yet matplotlib lays its ticks out at every
        # save: hidden, it is skipped (the figure is the same; its saves are about 40 % faster)
        ax.xaxis.set_visible(a + cols >= used)
        ax.yaxis.set_visible(a % cols == 0)
        ax.set_xlim(*xlim)
        ax.set_ylim(*ylim)


def _colour_range(values: np.ndarray) -> tuple[float, float, str]:
    """Colour limits: the full range, unless a few extreme voxels (near-singular κ in the
    hundreds) stretch it to more than 1.5 times the 1st-99th percentile range; then those
    percentiles, with ``extend`` marking the ends that were cut."""
    v = values[np.isfinite(values)]
    lo, hi = float(v.min()), float(v.max())
    plo, phi = (float(x) for x in np.percentile(v, [1, 99]))
    if not (phi > plo and hi - lo > 1.5 * (phi - plo)):
        return lo, hi if hi > lo else lo + 1e-12, "neither"
    span = phi - plo
    cut_lo, cut_hi = plo - lo > 0.25 * span, hi - phi > 0.25 * span
    if not cut_lo:
        plo = lo
    if not cut_hi:
        phi = hi
    extend = {(False, False): "neither", (True, False): "min", (False, True): "max",
              (True, True): "both"}[(cut_lo, cut_hi)]
    return plo, phi, extend


def plot_slices(result, path, values: np.ndarray | None = None, label: str = "",
                **kw) -> Path:
    """Write the slice grid to ``path`` (PNG, 120 dpi). An empty workspace gets a labelled
    blank."""
    return write_slice_pictures(result, [SlicePicture(Path(path), values, label)], **kw)[0]


def overlay_figure(results: list, labels: list[str], layout: str = "auto",
                   window: float | None = None, spacing: float | None = None,
                   max_panels: int = MAX_PANELS, title: str = ""):
    """Outlines of several workspaces' sections, one colour each, on one common layout
    (:func:`.slicing.slice_layout` over all of them: nothing is clipped by default)."""
    from matplotlib.lines import Line2D

    lay = slice_layout(list(results), layout, window, spacing, None, max_panels)
    colours = ["#0072B2", "#E69F00", "#009E73", "#CC79A7", "#D55E00", "#56B4E9", "#F0E442",
               "#000000"]
    fig, axes = _panel_grid(lay, None, 2.4, 0.95, 0.4,
                            title=(title + "\n" if title else "") + lay.describe())
    for z, ax in zip(lay.levels, axes.ravel()):
        for k, w in enumerate(results):
            if w.empty or len(w.xs) < 2 or len(w.ys) < 2:
                continue
            sec = w.slice(z)
            if sec.any():
                ax.contour(w.xs, w.ys, sec.T.astype(float), levels=[0.5],
                           colors=[colours[k % len(colours)]], linewidths=1.2)
    handles = [Line2D([], [], color=colours[k % len(colours)], label=lab)
               for k, lab in enumerate(labels)]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(labels), 4), fontsize=8,
               frameon=False)
    return fig
