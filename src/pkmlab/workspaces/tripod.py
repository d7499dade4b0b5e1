"""Workspaces of mechanisms with dependent coordinates (issue 24: the 3-PRS tripod): the set of
free coordinates ``(z, θx, θy)`` whose inverse kinematics is valid, on a grid, with the
parasitic motions (the dependent ``x, y, θz``) over it as metrics.

The grid: ``z`` at multiples of ``resolution_z`` over ``z_range`` (default: the nominal z
± the stroke span plus the largest link, checked to leave an empty border), ``θx, θy`` at
multiples of ``resolution_angle`` within ``±tilt_max``. Every number is **sampled**: the
volume is the count of feasible grid points × the cell volume (mm·rad²; points on the faces
of the tilt box count half, corners a quarter), an estimate whose
convergence the caller can see by halving the resolutions; the parasitic excursions are the
largest magnitudes over the feasible grid points. No guaranteed bracket is computed for this
family (its cell bounds are not written yet).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError

__all__ = ["TripodWorkspace", "tripod_workspace", "plot_tripod"]


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

    @property
    def empty(self) -> bool:
        return not self.occupancy.any()

    def metrics(self) -> dict:
        P = self.parasitic[self.occupancy]
        big = (np.max(np.abs(P), axis=0) if len(P) else np.full(3, np.nan)).tolist()
        zs = self.zs[np.any(self.occupancy, axis=(1, 2))]
        return {"volume_mm_deg2": self.volume * math.degrees(1) ** 2,
                "method": "sampled: grid count × cell volume (an estimate)",
                "z_range_mm": [float(zs.min()), float(zs.max())] if len(zs) else None,
                "parasitic_x_max_mm": big[0], "parasitic_y_max_mm": big[1],
                "parasitic_theta_z_max_deg": math.degrees(big[2]),
                "parasitic_xy_max_mm": float(np.max(np.hypot(P[:, 0], P[:, 1])))
                if len(P) else None,
                "points": int(self.occupancy.sum()), "seconds": self.seconds,
                "notes": list(self.notes)}


def tripod_workspace(mech, tilt_max: float, *, z_range=None, resolution_z: float = 5.0,
                     resolution_angle: float = math.radians(1.0)) -> TripodWorkspace:
    """The free-coordinate workspace of ``mech`` (module docstring); ``tilt_max`` (rad)."""
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
    return TripodWorkspace(zs, angles, occ, par, vol, resolution_z, resolution_angle,
                           time.perf_counter() - t0, tuple(notes))


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
