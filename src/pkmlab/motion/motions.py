"""Required motions: poses with their velocities and accelerations.

A :class:`Motion` holds times ``t (T,)`` in s, tool poses ``(T, 6)`` (mm, rad, Z-Y-X Euler
angles: R = Rz(θz)·Ry(θy)·Rx(θx)), the base-frame twist ``[v (mm/s); ω (rad/s)]`` of the tool
frame and its time derivative ``[a (mm/s²); α (rad/s²)]``. Angular velocity and acceleration
come from the Euler-angle rates exactly (:func:`euler_rates_to_twist`):
``ω = E(θ)·θ̇`` with the columns of ``E`` the axes ``Rz·Ry·e_x``, ``Rz·e_y``, ``e_z``, and
``α = E·θ̈ + Ė·θ̇``.

Sources and how derivatives are obtained (``Motion.derivatives`` says which):

* :func:`sinusoid_motion` — per-axis sinusoids about the nominal pose; analytic derivatives;
* :func:`paper_motion` — Hopkins & Williams' ±2 in / ±30° motion
  (:func:`pkmlab.motion.paper_motion`); analytic derivatives of its cubic lobes
  (the acceleration jumps at the knots: each side's value is exact on its own segment);
* :func:`load_motion_csv` — a recording ``t, x, y, z, theta_x, theta_y, theta_z`` (s, mm, deg).
  Velocities and accelerations are read from the optional columns ``<coordinate>_dot`` and
  ``<coordinate>_ddot`` (mm/s, deg/s, mm/s², deg/s²) when present, otherwise taken by a
  Savitzky–Golay filter (:func:`scipy.signal.savgol_filter`, polynomial order ``polyorder``
  fitted over a window of ``window`` seconds, derivatives of the local fit; the recorded
  positions themselves are used unsmoothed). Differentiation needs uniformly sampled time
  (steps equal to within 1e-6 relative).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from . import paper as _paper

__all__ = ["Motion", "euler_rates_to_twist", "sinusoid_motion", "paper_motion",
           "load_motion_csv", "differentiate", "POSE_COLUMNS"]

POSE_COLUMNS = ("x", "y", "z", "theta_x", "theta_y", "theta_z")
_DOT = tuple(f"{c}_dot" for c in POSE_COLUMNS)
_DDOT = tuple(f"{c}_ddot" for c in POSE_COLUMNS)


@dataclass(frozen=True)
class Motion:
    """One required motion (see the module docstring for units and frames)."""

    name: str
    t: np.ndarray
    poses: np.ndarray
    twist: np.ndarray
    accel: np.ndarray
    derivatives: str

    def __len__(self) -> int:
        return len(self.t)


def euler_rates_to_twist(poses, rates, rates2) -> tuple[np.ndarray, np.ndarray]:
    """Pose derivatives ``(T, 6)`` (ẋ in mm/s, Euler rates in rad/s) and second derivatives
    → base-frame twist ``[v; ω]`` and its derivative ``[a; α]``, each ``(T, 6)``."""
    poses, rates, rates2 = (np.asarray(a, dtype=float).reshape(-1, 6)
                            for a in (poses, rates, rates2))
    ty, tz = poses[:, 4], poses[:, 5]
    cz, sz, cy, sy = np.cos(tz), np.sin(tz), np.cos(ty), np.sin(ty)
    ez = np.broadcast_to([0.0, 0.0, 1.0], (len(poses), 3))
    ey = np.stack([-sz, cz, np.zeros_like(tz)], axis=1)                 # Rz·e_y
    ex = np.stack([cz * cy, sz * cy, -sy], axis=1)                      # Rz·Ry·e_x
    dx, dy, dz = rates[:, 3:4], rates[:, 4:5], rates[:, 5:6]
    w = ex * dx + ey * dy + ez * dz
    d_ey = np.cross(ez * dz, ey)
    d_ex = np.cross(ez * dz + ey * dy, ex)
    alpha = ex * rates2[:, 3:4] + ey * rates2[:, 4:5] + ez * rates2[:, 5:6] \
        + d_ex * dx + d_ey * dy
    return (np.concatenate([rates[:, :3], w], axis=1),
            np.concatenate([rates2[:, :3], alpha], axis=1))


def _motion(name, t, poses, d1, d2, how) -> Motion:
    tw, ac = euler_rates_to_twist(poses, d1, d2)
    return Motion(name, np.asarray(t, float), np.asarray(poses, float), tw, ac, how)


def sinusoid_motion(mech, amplitude, frequency, phase=(0.0,) * 6, duration: float = 2.0,
                    rate: float = 200.0, name: str = "sinusoid") -> Motion:
    """``pose_k(t) = nominal_k + A_k·sin(2π f_k t + φ_k)`` for the six coordinates (A in mm and
    rad, f in Hz, φ in rad), sampled at ``rate`` Hz over ``duration`` s; exact derivatives."""
    A, f, ph = (np.broadcast_to(np.asarray(v, dtype=float), (6,)) for v in
                (amplitude, frequency, phase))
    n = max(2, int(round(duration * rate)) + 1)
    t = np.linspace(0.0, duration, n)
    w = 2 * np.pi * f
    arg = np.outer(t, w) + ph
    poses = mech.nominal_pose + A * np.sin(arg)
    return _motion(name, t, poses, A * w * np.cos(arg), -A * w * w * np.sin(arg), "analytic")


def paper_motion(mech, segment_time: float = 1.0, rate: float = 100.0,
                 name: str = "paper") -> Motion:
    """Hopkins & Williams' motion (:func:`pkmlab.motion.paper_motion`) with the exact
    derivatives of its cubic lobes."""
    t, poses = _paper.paper_motion(mech, segment_time=segment_time, rate_hz=rate)
    d1, d2 = np.zeros_like(poses), np.zeros_like(poses)
    for (axis, t0, _t1), (_, idx) in zip(_paper.paper_motion_phases(segment_time),
                                         _paper.PAPER_AXES):
        amp = math.radians(30.0) if axis.startswith("theta") else 2.0 * _paper.MM_PER_IN
        knots = np.array([0.0, amp, 0.0, -amp, 0.0])
        inside = (t >= t0) & (t <= t0 + 4 * segment_time)
        u = np.clip((t[inside] - t0) / segment_time, 0.0, 4.0)
        k = np.minimum(np.floor(u).astype(int), 3)
        tau = u - k
        dk = knots[k + 1] - knots[k]
        d1[inside, idx] = dk * (6 * tau - 6 * tau * tau) / segment_time
        d2[inside, idx] = dk * (6 - 12 * tau) / segment_time ** 2
    return _motion(name, t, poses, d1, d2, "analytic")


def differentiate(t, x, window: float, polyorder: int, field: str = "smoothing"
                  ) -> tuple[np.ndarray, np.ndarray, int]:
    """First and second time derivatives of ``x (T, k)`` by Savitzky–Golay: the local
    polynomial of order ``polyorder`` over ``window`` s (rounded to an odd sample count, at
    least ``polyorder + 2``). Returns ``(ẋ, ẍ, window samples)``."""
    t = np.asarray(t, dtype=float)
    dt = np.diff(t)
    step = float(np.mean(dt))
    if np.max(np.abs(dt - step)) > 1e-6 * step:
        raise ParameterError(f"{field}", "uniformly sampled time for differentiation "
                             "(or derivative columns <coord>_dot, <coord>_ddot)",
                             f"steps from {dt.min():g} s to {dt.max():g} s")
    n = int(round(window / step))
    n = max(n + (1 - n % 2), polyorder + 2 + (polyorder + 2 + 1) % 2)
    if n > len(t):
        raise ParameterError(f"{field}.window", f"at most the recording's {len(t)} samples "
                             f"({(len(t) - 1) * step:g} s)", f"{window:g} s = {n} samples")
    from scipy.signal import savgol_filter  # lazy: scipy.signal costs 0.5 s at import

    d1 = savgol_filter(x, n, polyorder, deriv=1, delta=step, axis=0, mode="interp")
    d2 = savgol_filter(x, n, polyorder, deriv=2, delta=step, axis=0, mode="interp")
    return d1, d2, n


def load_motion_csv(path, name: str | None = None, window: float = 0.05, polyorder: int = 3,
                    field: str = "file") -> Motion:
    """Read a recorded motion (see the module docstring). Errors name ``field`` with the file,
    line and column: missing or unknown columns, non-numeric or non-finite values, time not
    strictly increasing, fewer than ``polyorder + 2`` samples."""
    path = Path(path)
    if not path.is_file():
        raise ParameterError(field, "an existing CSV file (relative to the study file)",
                             str(path))
    with path.open(newline="", encoding="utf-8") as fh:
        lines = [(n, line) for n, line in enumerate(fh, start=1)
                 if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ParameterError(field, "a CSV file with the header t," + ",".join(POSE_COLUMNS),
                             "an empty file", where=str(path))
    rows = list(csv.reader([line for _, line in lines]))
    header = [h.strip() for h in rows[0]]
    here = f"{path}, line {lines[0][0]}"
    known = ("t", *POSE_COLUMNS, *_DOT, *_DDOT)
    unknown = [h for h in header if h not in known]
    dupes = sorted({h for h in header if header.count(h) > 1})
    if unknown or dupes:
        raise ParameterError(f"{field} header", f"columns from {list(known)}, each once",
                             f"unknown {unknown}" if unknown else f"duplicate {dupes}",
                             where=here)
    missing = [c for c in ("t", *POSE_COLUMNS) if c not in header]
    if missing:
        raise ParameterError(f"{field} header", "the columns t," + ",".join(POSE_COLUMNS)
                             + " (s, mm, deg)", f"missing {missing}", where=here)
    for group in (_DOT, _DDOT):
        have = [c for c in group if c in header]
        if have and len(have) != 6:
            raise ParameterError(f"{field} header", f"all or none of {list(group)}",
                                 f"only {have}", where=here)
    data = np.empty((len(rows) - 1, len(header)))
    for r, (row, (lineno, _)) in enumerate(zip(rows[1:], lines[1:])):
        if len(row) != len(header):
            raise ParameterError(field, f"{len(header)} comma-separated fields per row",
                                 f"{len(row)} fields", where=f"{path}, line {lineno}")
        for j, text in enumerate(row):
            try:
                v = float(text)
            except ValueError:
                v = None
            if v is None or not math.isfinite(v):
                raise ParameterError(f"{field} column {header[j]!r}", "a finite number",
                                     text.strip(), where=f"{path}, line {lineno}")
            data[r, j] = v
    col = {h: data[:, j] for j, h in enumerate(header)}
    t = col["t"]
    if len(t) < max(2, polyorder + 2):
        raise ParameterError(field, f"at least {max(2, polyorder + 2)} data rows", len(t),
                             where=str(path))
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        k = int(bad[0]) + 1
        raise ParameterError(f"{field} column 't'", f"strictly increasing time (> {t[k - 1]:g}"
                             " s on the previous row)", float(t[k]),
                             where=f"{path}, line {lines[k + 1][0]}")
    deg = np.array([1, 1, 1, math.pi / 180, math.pi / 180, math.pi / 180])
    poses = np.stack([col[c] for c in POSE_COLUMNS], axis=1) * deg
    name = name or path.stem
    if all(c in col for c in _DOT) and all(c in col for c in _DDOT):
        d1 = np.stack([col[c] for c in _DOT], axis=1) * deg
        d2 = np.stack([col[c] for c in _DDOT], axis=1) * deg
        return _motion(name, t, poses, d1, d2, "columns")
    s1, s2, n = differentiate(t, poses, window, polyorder, field=f"{field} (smoothing)")
    how = f"savgol(window={n} samples = {n * float(np.mean(np.diff(t))):.4g} s, " \
          f"polyorder={polyorder})"
    if all(c in col for c in _DOT):
        s1 = np.stack([col[c] for c in _DOT], axis=1) * deg
        how = "velocity columns; acceleration " + how
    return _motion(name, t, poses, s1, s2, how)
