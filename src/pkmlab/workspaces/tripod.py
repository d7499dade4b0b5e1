"""Workspaces of mechanisms with dependent coordinates (issue 24: the 3-PRS tripod): the set of
free coordinates ``(z, θx, θy)`` whose inverse kinematics is valid, with the parasitic motions
(the dependent ``x, y, θz``) over it as metrics, and a guaranteed bracket of its volume.

The grid: ``z`` at multiples of ``resolution_z`` over ``z_range`` (default: the nominal z
± the stroke span plus the largest link, checked to leave an empty border), ``θx, θy`` at
multiples of ``resolution_angle`` within ``±tilt_max``. The grid's numbers are **sampled**:
the sampled volume is the count of feasible grid points × the cell volume (mm·rad²; points on
the faces of the tilt box count half, corners a quarter), an estimate; the parasitic
excursions are the largest magnitudes over the feasible grid points.

The **bracket** (:func:`tripod_volume_bracket`) is guaranteed: interval enclosures of each
leg's inverse kinematics over boxes of ``(z, θx, θy)`` through the closed-form parasitic
motions (:mod:`pkmlab.mechanisms.families.prs3_boxes`), boxes proved feasible counted in the
lower bound, undecided ones split until the requested relative width. Volumes are in mm·rad²
(z in mm, the two tilts in rad); the metrics also give mm·deg².
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError

__all__ = ["TripodWorkspace", "TripodBracket", "tripod_workspace", "tripod_volume_bracket",
           "plot_tripod"]

#: the column bracket splits, each step, the cells holding the largest gaps, together at
#: least this share of the total gap (algorithm constant)
_SPLIT_SHARE = 0.6
#: the box form splits a box in z only while its z side exceeds this × its widest angle side ×
#: the largest platform joint radius (mm per rad; algorithm constant)
_Z_SPLIT = 1.0
#: boxes classified per call of the enclosure (bounds the temporaries: ~40 arrays of this size)
_CHUNK = 100_000


@dataclass(frozen=True)
class TripodWorkspace:
    """A workspace over the free coordinates (module docstring); lengths mm, angles rad."""

    zs: np.ndarray
    angles: np.ndarray
    occupancy: np.ndarray            # (nz, na, na): z, θx, θy
    parasitic: np.ndarray            # (nz, na, na, 3): x, y, θz (NaN outside)
    volume: float                    # mm·rad², sampled estimate
    resolution_z: float
    resolution_angle: float
    seconds: float
    notes: tuple[str, ...] = field(default=())
    bracket: TripodBracket | None = None

    @property
    def empty(self) -> bool:
        return not self.occupancy.any()

    def metrics(self) -> dict:
        P = self.parasitic[self.occupancy]
        big = (np.max(np.abs(P), axis=0) if len(P) else np.full(3, np.nan)).tolist()
        zs = self.zs[np.any(self.occupancy, axis=(1, 2))]
        b = self.bracket.describe() if self.bracket is not None else None
        return {"sampled_volume_mm_deg2": self.volume * math.degrees(1) ** 2,
                "volume_bracket_mm_deg2": None if b is None else b["volume_bracket_mm_deg2"],
                "volume_bracket_mm_rad2": None if b is None else b["volume_bracket_mm_rad2"],
                "bracket": b,
                "method": "sampled volume: grid count × cell volume (an estimate); "
                          + ("no bracket requested" if b is None else b["method"]),
                "z_range_mm": [float(zs.min()), float(zs.max())] if len(zs) else None,
                "parasitic_x_max_mm": big[0], "parasitic_y_max_mm": big[1],
                "parasitic_theta_z_max_deg": math.degrees(big[2]),
                "parasitic_xy_max_mm": float(np.max(np.hypot(P[:, 0], P[:, 1])))
                if len(P) else None,
                "points": int(self.occupancy.sum()), "seconds": self.seconds,
                "notes": list(self.notes)}


def tripod_workspace(mech, tilt_max: float, *, z_range=None, resolution_z: float = 5.0,
                     resolution_angle: float = math.radians(1.0),
                     bracket_target: float | None = 0.01) -> TripodWorkspace:
    """The free-coordinate workspace of ``mech`` (module docstring); ``tilt_max`` (rad).
    ``bracket_target``: the relative width of the guaranteed volume bracket
    (:func:`tripod_volume_bracket`, over ``z_range`` when one is given, else every z), None
    for none."""
    t0 = time.perf_counter()
    if not getattr(mech.mobility, "dependent", ()) or not hasattr(mech, "parasitic"):
        raise ParameterError("mechanism", "a mechanism with dependent coordinates (a 3-PRS)",
                             f"{mech.family!r} ({mech.mobility.name} mobility)")
    if not (0 < tilt_max < math.pi / 2):
        raise ParameterError("tilt_max", "an angle in (0, 90) deg", math.degrees(tilt_max))
    z0 = float(mech.nominal_pose[2])
    reach = float(mech.stroke[1] - mech.stroke[0]) + float(np.max(mech.link_length))
    zr = (z0 - reach, z0 + reach) if z_range is None else tuple(map(float, z_range))
    zs = np.arange(math.ceil(zr[0] / resolution_z), math.floor(zr[1] / resolution_z) + 1) \
        * resolution_z
    k = int(math.floor(tilt_max / resolution_angle + 1e-9))
    angles = np.arange(-k, k + 1) * resolution_angle
    Z, A, B = np.meshgrid(zs, angles, angles, indexing="ij")
    X = np.zeros((Z.size, 6))
    X[:, 2], X[:, 3], X[:, 4] = Z.ravel(), A.ravel(), B.ravel()
    occ = mech.inverse(X).valid.reshape(Z.shape)
    par = np.full(Z.shape + (3,), np.nan)
    if occ.any():
        par[occ] = mech.parasitic(X[occ.ravel()][:, [2, 3, 4]])
    notes = []
    if occ[[0, -1]].any():
        notes.append("feasible points on the z ends of the grid: widen z_range")
    # grid points on the faces of the tilt box stand for half cells (the box ends there)
    wa = np.ones(len(angles))
    if abs(k * resolution_angle - tilt_max) < 1e-9 * resolution_angle:
        wa[[0, -1]] = 0.5
    vol = float(np.einsum("zab,a,b->", occ, wa, wa)) * resolution_z * resolution_angle ** 2
    br = None
    if bracket_target is not None:
        br = tripod_volume_bracket(mech, tilt_max, z_range=z_range, target=bracket_target)
        if br.stop_reason != "converged":
            notes.append(f"volume bracket stopped before {bracket_target:.2%} "
                         f"({br.stop_reason}): width {br.relative_width:.2%}")
    return TripodWorkspace(zs, angles, occ, par, vol, resolution_z, resolution_angle,
                           time.perf_counter() - t0, tuple(notes), br)


def plot_tripod(res: TripodWorkspace, path, *, slices: int = 6, title: str | None = None):
    """Slices of the tilt region at ``slices`` heights, coloured by the parasitic
    displacement ``hypot(x, y)`` (mm). Writes ``path`` (PNG); returns it."""
    from matplotlib.figure import Figure

    live = np.flatnonzero(res.occupancy.any(axis=(1, 2)))
    if not len(live):
        raise ParameterError("result", "a non-empty workspace to draw", "empty")
    pick = live[np.linspace(0, len(live) - 1, min(slices, len(live))).round().astype(int)]
    nc = min(3, len(pick))
    nr = (len(pick) + nc - 1) // nc
    fig = Figure(figsize=(4.3 * nc, 3.9 * nr))
    axes = np.asarray(fig.subplots(nr, nc, squeeze=False))
    mag = np.hypot(res.parasitic[..., 0], res.parasitic[..., 1])
    vmax = float(np.nanmax(mag))
    deg = np.degrees(res.angles)
    h = math.degrees(res.resolution_angle) / 2
    for ax, i in zip(axes.ravel(), pick):
        im = ax.imshow(mag[i].T, origin="lower", cmap="viridis", vmin=0, vmax=vmax,
                       extent=(deg[0] - h, deg[-1] + h, deg[0] - h, deg[-1] + h))
        ax.set_title(f"z = {res.zs[i]:.1f} mm", fontsize=9)
        ax.set_xlabel("θx (deg)")
        ax.set_ylabel("θy (deg)")
        fig.colorbar(im, ax=ax, shrink=0.8, label="parasitic |(x, y)| (mm)")
    for ax in axes.ravel()[len(pick):]:
        ax.axis("off")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


# ---- guaranteed volume bracket -------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class TripodBracket:
    """A guaranteed bracket of the (z, θx, θy) volume (mm·rad²) of the feasible set within the
    tilt box ``|θx|, |θy| <= tilt_max`` (:func:`tripod_volume_bracket`).

    Attributes:
        lower, upper: the bracket (mm·rad²): the volume of the boxes proved feasible, and that
            plus the volume of the boxes still undecided.
        target: relative width asked for (``upper - lower <= target·upper``).
        stop_reason: ``"converged"``, ``"budget: seconds"``, ``"budget: boxes"``,
            ``"budget: levels"`` or ``"empty"``.
        history: one dict per level (level, boxes classified, lower, upper, seconds).
        inner: ``(n, 2, 3)`` boxes ``[lo, hi]`` proved feasible (every level's).
        undecided: ``(m, 2, 3)`` the last level's undecided boxes; every feasible point of the
            tilt box is in an inner or an undecided box.
        slack: the margin (mm) on the slider window (:mod:`..mechanisms.families.prs3_boxes`).
        seconds: wall time.
    """

    lower: float
    upper: float
    target: float
    stop_reason: str
    history: list
    inner: np.ndarray
    undecided: np.ndarray
    slack: float
    seconds: float

    @property
    def relative_width(self) -> float:
        return (self.upper - self.lower) / self.upper if self.upper > 0 else 0.0

    def contains(self, free, which: str = "outer") -> np.ndarray:
        """``(N,)`` bool: points ``(N, 3)`` (z, θx, θy) in an inner box (``"inner"``) or in an
        inner or undecided box (``"outer"``), closed boxes."""
        P = np.asarray(free, dtype=float).reshape(-1, 3)
        boxes = self.inner if which == "inner" else np.concatenate([self.inner, self.undecided])
        out = np.zeros(len(P), dtype=bool)
        if not len(boxes):
            return out
        # window on the axis whose boxes are narrowest against their spread
        w = boxes[:, 1] - boxes[:, 0]
        spread = np.ptp(boxes[:, 0], axis=0) + w.max(axis=0)
        ax = int(np.argmin(w.max(axis=0) / np.where(spread > 0, spread, 1.0)))
        boxes = boxes[np.argsort(boxes[:, 0, ax])]
        key, width = boxes[:, 0, ax], float(w[:, ax].max())
        first = np.searchsorted(key, P[:, ax] - width, side="left")
        last = np.searchsorted(key, P[:, ax], side="right")
        for k, p in enumerate(P):
            cand = boxes[first[k]:last[k]]
            out[k] = bool(np.any(np.all((cand[:, 0] <= p) & (p <= cand[:, 1]), axis=1)))
        return out

    def describe(self) -> dict:
        """Plain-dict summary: the bracket in mm·rad² and mm·deg²."""
        d2 = math.degrees(1) ** 2
        return {"volume_bracket_mm_rad2": [self.lower, self.upper],
                "volume_bracket_mm_deg2": [self.lower * d2, self.upper * d2],
                "relative_width": self.relative_width, "target": self.target,
                "stop_reason": self.stop_reason, "inner_boxes": int(len(self.inner)),
                "undecided_boxes": int(len(self.undecided)), "slack_mm": self.slack,
                "seconds": self.seconds, "history": list(self.history),
                "method": "guaranteed: interval enclosure of each leg's IK over boxes of "
                          "(z, θx, θy) (outward rounding), undecided boxes split in eight"}


def _z_bounds(mech) -> tuple[float, float]:
    """Every feasible z (mm): the platform joint is within a link of its slider, which is on
    its rail's window, and within ``|b_i|`` (the tool point's radius) of the tool point's
    height; intersected over the legs, grown by 1 mm."""
    lo, hi = -math.inf, math.inf
    for i in range(3):
        ends = mech.base_points[i, 2] + np.array(mech.stroke) * mech.rail_axes[i, 2]
        r = float(np.linalg.norm(mech.tool_points[i])) + float(mech.link_length[i])
        lo, hi = max(lo, float(ends.min()) - r), min(hi, float(ends.max()) + r)
    return lo - 1.0, hi + 1.0


def tripod_volume_bracket(mech, tilt_max: float, *, z_range=None, target: float = 0.01,
                          initial: tuple[int, int] = (8, 8), max_level: int = 14,
                          max_boxes: int = 4_000_000, budget_s: float = 120.0,
                          classify=None) -> TripodBracket:
    """A guaranteed bracket of the volume (mm·rad²) of ``mech``'s feasible set over
    ``(z, θx, θy)`` within ``|θx|, |θy| <= tilt_max`` (rad).

    Boxes start as ``initial`` = (z pieces, pieces per angle) over ``z_range`` (default
    :func:`_z_bounds`, which holds every feasible z) × the tilt box; each level classifies
    them with ``classify(mech, lo, hi, slack)`` (default
    :func:`pkmlab.mechanisms.families.prs3_boxes.classify_boxes`) into proved feasible
    (counted in ``lower``), proved infeasible (dropped) and undecided (split in eight, or in
    two along z while their z side is long against their angle sides, :func:`_split`), until
    ``upper - lower <= target·upper``, ``max_level`` levels, ``max_boxes`` boxes in the next
    level or ``budget_s`` seconds (a level predicted, at 8× the last, to end past it is not
    started).

    Where every rail is vertical (and no ``classify`` is given), z enters
    each leg linearly and the set is bracketed on **columns** instead: cells of (θx, θy),
    starting ``2·initial[1]`` per angle, each given a z interval proved feasible and one
    holding every feasible z (:func:`~pkmlab.mechanisms.families.prs3_boxes.column_bounds`);
    each step splits in four the cells holding the largest gaps (together at least
    :data:`_SPLIT_SHARE` of the total), until the target (``max_level`` counts steps).
    ``inner`` and ``undecided`` are then the columns' z intervals (clipped to ``z_range``
    when one is given) as boxes."""
    from ..mechanisms.families.prs3_boxes import classify_boxes, vertical_rails

    t0 = time.perf_counter()
    if not getattr(mech.mobility, "dependent", ()) or not hasattr(mech, "parasitic"):
        raise ParameterError("mechanism", "a mechanism with dependent coordinates (a 3-PRS)",
                             f"{mech.family!r} ({mech.mobility.name} mobility)")
    if not (0 < tilt_max < math.pi / 2):
        raise ParameterError("tilt_max", "an angle in (0, 90) deg", math.degrees(tilt_max))
    if not 0 < target < 1:
        raise ParameterError("target", "a relative width in (0, 1)", target)
    slack = 1e-9 + 1e-12 * mech.scale
    if classify is None and vertical_rails(mech):
        return _column_bracket(mech, tilt_max, target, 2 * initial[1], max_level, max_boxes,
                               budget_s, slack, t0, z_range)
    classify = classify or classify_boxes
    zr = _z_bounds(mech) if z_range is None else tuple(map(float, z_range))
    nz, na = initial
    ze = np.linspace(zr[0], zr[1], nz + 1)
    ae = np.linspace(-tilt_max, tilt_max, na + 1)
    I, J, K = np.meshgrid(np.arange(nz), np.arange(na), np.arange(na), indexing="ij")
    lo = np.stack([ze[I.ravel()], ae[J.ravel()], ae[K.ravel()]], axis=1)
    hi = np.stack([ze[I.ravel() + 1], ae[J.ravel() + 1], ae[K.ravel() + 1]], axis=1)
    inner, history = [], []
    lower, upper, stop, last = 0.0, math.inf, "budget: levels", 0.0
    z_per_rad = _Z_SPLIT * float(np.max(np.linalg.norm(mech.tool_points, axis=1)))
    for level in range(max_level + 1):
        t = time.perf_counter()
        ins = np.zeros(len(lo), dtype=bool)
        out = np.zeros(len(lo), dtype=bool)
        for s in range(0, len(lo), _CHUNK):
            ins[s:s + _CHUNK], out[s:s + _CHUNK] = classify(mech, lo[s:s + _CHUNK],
                                                            hi[s:s + _CHUNK], slack)
        vol = np.prod(hi - lo, axis=1)
        lower += float(vol[ins].sum())
        inner.append(np.stack([lo[ins], hi[ins]], axis=1))
        und = ~ins & ~out
        upper = lower + float(vol[und].sum())
        lo, hi = lo[und], hi[und]
        last = time.perf_counter() - t
        history.append({"level": level, "boxes": int(len(ins)), "lower_mm_rad2": lower,
                        "upper_mm_rad2": upper, "seconds": time.perf_counter() - t0})
        if upper == 0.0:
            stop = "empty"
            break
        if upper - lower <= target * upper:
            stop = "converged"
            break
        if level == max_level:
            break
        if 8 * len(lo) > max_boxes:
            stop = "budget: boxes"
            break
        if time.perf_counter() - t0 + 8 * last * max(1.0, len(lo) / max(len(ins), 1)) \
                > budget_s:
            stop = "budget: seconds"
            break
        lo, hi = _split(lo, hi, z_per_rad)
    return TripodBracket(lower, upper, target, stop, history,
                         np.concatenate(inner) if inner else np.empty((0, 2, 3)),
                         np.stack([lo, hi], axis=1), slack, time.perf_counter() - t0)


def _split(lo, hi, z_per_rad):
    """Undecided boxes split: in z only (two) where their z side exceeds ``z_per_rad`` × their
    widest angle side, else in eight (the z blur of a box's enclosure grows as its angle
    sides times about the platform radius: finer z slabs then resolve the top and bottom
    surfaces, as the column form does)."""
    w = hi - lo
    zonly = w[:, 0] > z_per_rad * np.maximum(w[:, 1], w[:, 2])
    mid = 0.5 * (lo + hi)
    nlo, nhi = [], []
    cut = np.where(zonly[:, None], np.array([True, False, False]), True)    # (N, 3) split sides
    for c in range(8):
        bit = np.array([(c >> k) & 1 for k in range(3)], dtype=bool)
        sel = ~zonly if c > 1 else np.ones(len(lo), dtype=bool)
        up, k = bit & cut[sel], cut[sel]
        nlo.append(np.where(k & up, mid[sel], lo[sel]))
        nhi.append(np.where(k & ~up, mid[sel], hi[sel]))
    return np.concatenate(nlo), np.concatenate(nhi)


def _column_bracket(mech, tilt_max, target, n0, max_steps, max_cells, budget_s, slack, t0,
                    z_range=None):
    """The column form of :func:`tripod_volume_bracket` (its docstring); both z intervals of
    a column are clipped to ``z_range`` when one is given."""
    from ..mechanisms.families.prs3_boxes import column_bounds

    e = np.linspace(-tilt_max, tilt_max, n0 + 1)
    I, J = np.meshgrid(np.arange(n0), np.arange(n0), indexing="ij")
    lo = np.stack([e[I.ravel()], e[J.ravel()]], axis=1)
    hi = np.stack([e[I.ravel() + 1], e[J.ravel() + 1]], axis=1)

    def evaluate(lo, hi):
        zin, zout = np.empty((len(lo), 2)), np.empty((len(lo), 2))
        for s in range(0, len(lo), _CHUNK):
            zin[s:s + _CHUNK], zout[s:s + _CHUNK] = column_bounds(
                mech, lo[s:s + _CHUNK], hi[s:s + _CHUNK], slack)
        if z_range is not None:
            for z in (zin, zout):
                z[:, 0] = np.maximum(z[:, 0], float(z_range[0]))
                z[:, 1] = np.minimum(z[:, 1], float(z_range[1]))
        area = np.prod(hi - lo, axis=1)
        return (zin, zout, area * np.maximum(zin[:, 1] - zin[:, 0], 0.0),
                area * np.maximum(zout[:, 1] - zout[:, 0], 0.0))

    zin, zout, vin, vout = evaluate(lo, hi)
    history, stop = [], "budget: levels"
    for step in range(max_steps + 1):
        lower, upper = float(vin.sum()), float(vout.sum())
        history.append({"level": step, "cells": int(len(lo)), "lower_mm_rad2": lower,
                        "upper_mm_rad2": upper, "seconds": time.perf_counter() - t0})
        if upper == 0.0:
            stop = "empty"
            break
        if upper - lower <= target * upper:
            stop = "converged"
            break
        if step == max_steps:
            break
        gap = vout - vin
        order = np.argsort(gap)[::-1]
        n_split = int(np.searchsorted(np.cumsum(gap[order]), _SPLIT_SHARE * gap.sum())) + 1
        if len(lo) + 3 * n_split > max_cells:
            stop = "budget: boxes"
            break
        if time.perf_counter() - t0 > budget_s:
            stop = "budget: seconds"
            break
        pick = order[:n_split]
        keep = np.ones(len(lo), dtype=bool)
        keep[pick] = False
        plo, phi = lo[pick], hi[pick]
        mid = 0.5 * (plo + phi)
        clo = np.concatenate([plo, np.column_stack([mid[:, 0], plo[:, 1]]),
                              np.column_stack([plo[:, 0], mid[:, 1]]), mid])
        chi = np.concatenate([mid, np.column_stack([phi[:, 0], mid[:, 1]]),
                              np.column_stack([mid[:, 0], phi[:, 1]]), phi])
        czin, czout, cvin, cvout = evaluate(clo, chi)
        lo, hi = np.concatenate([lo[keep], clo]), np.concatenate([hi[keep], chi])
        zin, zout = np.concatenate([zin[keep], czin]), np.concatenate([zout[keep], czout])
        vin, vout = np.concatenate([vin[keep], cvin]), np.concatenate([vout[keep], cvout])

    def boxes(sel, z0, z1):
        return np.stack([np.column_stack([z0[sel], lo[sel]]),
                         np.column_stack([z1[sel], hi[sel]])], axis=1)

    has_in = zin[:, 0] <= zin[:, 1]
    has_out = zout[:, 0] <= zout[:, 1]
    inner = boxes(has_in, zin[:, 0], zin[:, 1])
    und = np.concatenate([boxes(has_in & has_out, zout[:, 0], zin[:, 0]),
                          boxes(has_in & has_out, zin[:, 1], zout[:, 1]),
                          boxes(~has_in & has_out, zout[:, 0], zout[:, 1])])
    return TripodBracket(float(vin.sum()), float(vout.sum()), target, stop, history, inner,
                         und, slack, time.perf_counter() - t0)
