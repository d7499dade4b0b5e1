"""Slice layouts: which horizontal sections a slice plot shows, through which window.

* ``auto`` (the default): the window is a square around the workspace's x-y bounding box
  (its larger edge, padded by 5 % and rounded up to a round length), centred on the box; the
  spacing is a round step (1, 2, 2.5 or 5 × 10ⁿ mm, never finer than the grid) giving at most
  ``max_panels`` sections, each at least half a spacing inside the workspace's z range. No
  section is clipped, whatever the size of the machine.
* ``paper``: Hopkins & Williams (2002), Figs. 7-8: a 152.4 mm (6 in) square every 12.7 mm
  (½ in), centred on the nominal pose (a large workspace is clipped, as in the paper).

An explicit ``window`` or ``spacing`` overrides the layout's. :func:`slice_layout` takes one
result or several (one common layout, e.g. for overlaid designs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError

__all__ = ["SliceLayout", "slice_layout", "nice_ceil", "LAYOUTS", "PAPER_WINDOW",
           "PAPER_SPACING", "MAX_PANELS"]

PAPER_WINDOW = 152.4        # mm, 6 in
PAPER_SPACING = 12.7        # mm, 1/2 in
MAX_PANELS = 16
LAYOUTS = ("auto", "paper")


@dataclass(frozen=True)
class SliceLayout:
    """A square ``window`` (mm) centred at ``centre`` (x, y), sections at ``levels`` (mm)."""

    layout: str
    window: float
    spacing: float
    centre: tuple[float, float]
    levels: np.ndarray

    def as_dict(self) -> dict:
        return {"layout": self.layout, "window_mm": self.window, "spacing_mm": self.spacing,
                "centre_mm": list(self.centre), "levels_mm": [float(z) for z in self.levels]}

    def describe(self) -> str:
        return (f"{self.window:g} × {self.window:g} mm top views every {self.spacing:g} mm, "
                "lowest top-left")


def nice_ceil(x: float) -> float:
    """The smallest of 1, 2, 2.5, 5 × 10ⁿ that is ≥ ``x`` (> 0)."""
    if not (x > 0 and math.isfinite(x)):
        raise ValueError(f"nice_ceil needs a finite x > 0; got {x}")
    e = math.floor(math.log10(x))
    for m in (1.0, 2.0, 2.5, 5.0, 10.0):
        v = m * 10.0**e
        if v >= x * (1 - 1e-12):
            return float(f"{v:.12g}")
    return 10.0 ** (e + 1)  # pragma: no cover - unreachable


def _window_ceil(x: float) -> float:
    """Round a window edge up to a multiple of a round step of about a tenth of it
    (107 → 120, 210 → 225, 1312 → 1400)."""
    step = nice_ceil(x / 10.0)
    return float(f"{math.ceil(x / step - 1e-9) * step:.12g}")


def _bounds(results):
    boxes = [r.metrics()["bbox_mm"] for r in results if not r.empty]
    if not boxes:
        return None
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    return lo, hi


def _inset_levels(zlo: float, zhi: float, spacing: float) -> np.ndarray:
    """As many sections ``spacing`` apart as fit with half a spacing of margin, centred."""
    span = zhi - zlo
    n = max(1, int(math.floor(span / spacing + 1e-9)))
    start = zlo + 0.5 * (span - (n - 1) * spacing)
    return start + spacing * np.arange(n)


def slice_layout(results, layout: str = "auto", window: float | None = None,
                 spacing: float | None = None, centre=None,
                 max_panels: int = MAX_PANELS, cover=None) -> SliceLayout:
    """The layout of a slice plot of one :class:`~pkmlab.WorkspaceResult` or several.

    Args:
        results: a result, or a list of results sharing one layout.
        layout: ``"auto"`` or ``"paper"`` (module docstring).
        window, spacing: override the layout's window edge / section spacing (mm).
        centre: override the window's centre ``(x, y)`` (mm).
        max_panels: the most sections the ``auto`` layout shows.
        cover: ``((x0, y0), (x1, y1))`` mm that the ``auto`` window must show as well as the
            workspaces (e.g. a task region drawn on the sections); the sections' heights
            stay the workspaces'.
    """
    if layout not in LAYOUTS:
        raise ParameterError("slice layout", f"one of {list(LAYOUTS)}", layout)
    if not isinstance(results, list | tuple):
        results = [results]
    for name, v in (("slice window", window), ("slice spacing", spacing)):
        if v is not None and not (math.isfinite(v) and v > 0):
            raise ParameterError(name, "a length > 0 mm", v)
    first = results[0]
    bounds = _bounds(results)
    if layout == "paper":
        win = PAPER_WINDOW if window is None else window
        step = PAPER_SPACING if spacing is None else spacing
        c = first.mechanism.nominal_pose[:2] if centre is None else centre
        levels = (np.empty(0) if bounds is None
                  else _paper_levels(bounds[0][2], bounds[1][2], step))
        return SliceLayout("paper", float(win), float(step), (float(c[0]), float(c[1])),
                           levels)
    h = max(r.resolution for r in results)
    if bounds is None:
        win = window or _window_ceil(max(4 * h, 10.0))
        c = first.mechanism.nominal_pose[:2] if centre is None else centre
        return SliceLayout("auto", float(win), float(spacing or h),
                           (float(c[0]), float(c[1])), np.empty(0))
    lo, hi = bounds
    if cover is not None:
        lo, hi = lo.copy(), hi.copy()
        lo[:2] = np.minimum(lo[:2], cover[0])
        hi[:2] = np.maximum(hi[:2], cover[1])
    edge = float(max(hi[0] - lo[0], hi[1] - lo[1]))
    win = window if window is not None else _window_ceil(max(1.05 * edge, 2 * h))
    c = (0.5 * (lo[:2] + hi[:2])) if centre is None else centre
    span = float(hi[2] - lo[2])
    if spacing is not None:
        step = spacing
    else:
        step = max(nice_ceil(span / max(max_panels, 1)) if span > 0 else h, h)
    return SliceLayout("auto", float(win), float(step), (float(c[0]), float(c[1])),
                       _inset_levels(float(lo[2]), float(hi[2]), step))


def _paper_levels(zlo: float, zhi: float, spacing: float) -> np.ndarray:
    """The paper's stack: from the bottom to the top ``spacing`` apart, centred."""
    n = int(math.floor((zhi - zlo) / spacing)) + 1
    start = zlo + 0.5 * ((zhi - zlo) - (n - 1) * spacing)
    return start + spacing * np.arange(n)
