"""Required motions: poses with their velocities and accelerations.

A :class:`Motion` holds times ``t (T,)`` in s, tool poses ``(T, 6)`` (mm, rad, Z-Y-X Euler
angles: R = Rz(θz)·Ry(θy)·Rx(θx)), the base-frame twist ``[v (mm/s); ω (rad/s)]`` of the tool
frame and its time derivative ``[a (mm/s²); α (rad/s²)]``. Angular velocity and acceleration
come from the Euler-angle rates exactly (:func:`euler_rates_to_twist`):
``ω = E(θ)·θ̇`` with the columns of ``E`` the axes ``Rz·Ry·e_x``, ``Rz·e_y``, ``e_z``, and
``α = E·θ̈ + Ė·θ̇``.

Sources and how derivatives are obtained (``Motion.derivatives`` says which):

* :func:`sinusoid_motion` — per-axis sinusoids about the nominal pose; analytic derivatives;
* :func:`pkmlab.motion.paper.paper_motion` — Hopkins & Williams' ±2 in / ±30° motion; analytic
  derivatives of its cubic lobes;
* :func:`pkmlab.motion.csvfile.load_motion_csv` — a recording (derivative columns, or
  :func:`differentiate`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..poses import POSE_SIZE
from ..tolerances import TOL

__all__ = ["Motion", "euler_rates_to_twist", "make_motion", "sinusoid_motion", "differentiate",
           "POSE_COLUMNS"]

POSE_COLUMNS = ("x", "y", "z", "theta_x", "theta_y", "theta_z")


@dataclass(frozen=True)
class Motion:
    """One required motion (see the module docstring for units and frames)."""

    name: str
    t: np.ndarray
    poses: np.ndarray
    twist: np.ndarray | None
    accel: np.ndarray | None
    #: how the derivatives were obtained ("analytic", "columns", "savgol(...)"; "none" when the
    #: motion was read without them)
    derivatives: str

    def __len__(self) -> int:
        return len(self.t)


def euler_rates_to_twist(poses, rates, rates2) -> tuple[np.ndarray, np.ndarray]:
    """Pose derivatives ``(T, 6)`` (ẋ in mm/s, Euler rates in rad/s) and second derivatives
    → base-frame twist ``[v; ω]`` and its derivative ``[a; α]``, each ``(T, 6)``."""
    poses, rates, rates2 = (np.asarray(a, dtype=float).reshape(-1, POSE_SIZE)
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


def make_motion(name, t, poses, d1, d2, how) -> Motion:
    """A :class:`Motion` from poses and their first and second time derivatives (Euler
    rates), converted to the twist exactly."""
    tw, ac = euler_rates_to_twist(poses, d1, d2)
    return Motion(name, np.asarray(t, float), np.asarray(poses, float), tw, ac, how)


def sinusoid_motion(mech, amplitude, frequency, phase=(0.0,) * POSE_SIZE, duration: float = 2.0,
                    rate: float = 200.0, name: str = "sinusoid") -> Motion:
    """``pose_k(t) = nominal_k + A_k·sin(2π f_k t + φ_k)`` for the six coordinates (A in mm and
    rad, f in Hz, φ in rad), sampled at ``rate`` Hz over ``duration`` s; exact derivatives."""
    A, f, ph = (np.broadcast_to(np.asarray(v, dtype=float), (POSE_SIZE,)) for v in
                (amplitude, frequency, phase))
    n = max(2, int(round(duration * rate)) + 1)
    t = np.linspace(0.0, duration, n)
    w = 2 * np.pi * f
    arg = np.outer(t, w) + ph
    poses = mech.nominal_pose + A * np.sin(arg)
    return make_motion(name, t, poses, A * w * np.cos(arg), -A * w * w * np.sin(arg), "analytic")


def differentiate(t, x, window: float, polyorder: int, field: str = "smoothing"
                  ) -> tuple[np.ndarray, np.ndarray, int]:
    """First and second time derivatives of ``x (T, k)`` by Savitzky–Golay: the local
    polynomial of order ``polyorder`` over ``window`` s (rounded to an odd sample count, at
    least ``polyorder + 2``). Returns ``(ẋ, ẍ, window samples)``."""
    t = np.asarray(t, dtype=float)
    dt = np.diff(t)
    step = float(np.mean(dt))
    if np.max(np.abs(dt - step)) > TOL.uniform_time_rel * step:
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
