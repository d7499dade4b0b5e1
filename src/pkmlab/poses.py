"""Pose conventions and batched rotation helpers.

A pose is ``X = (x, y, z, θx, θy, θz)`` of the tool frame in the base frame (mm, rad) with
``R = Rz(θz) · Ry(θy) · Rx(θx)`` (Z-Y-X Euler angles, Craig 1989), as in Hopkins & Williams
(2002). Every function also accepts homogeneous transforms of shape ``(4, 4)`` or ``(N, 4, 4)``.
"""

from __future__ import annotations

import numpy as np

from .errors import ParameterError

#: the six pose coordinates of pkmlab (mm, mm, mm, rad, rad, rad; R = Rz·Ry·Rx); a mechanism's
#: mobility frees a subset of them (:mod:`pkmlab.mechanisms.mobility`)
POSE = ("x", "y", "z", "theta_x", "theta_y", "theta_z")
#: the number of pose coordinates, and of components of a rigid-body twist [v; ω] or wrench
POSE_SIZE = len(POSE)

__all__ = [
    "POSE",
    "POSE_SIZE",
    "euler_to_matrix",
    "matrix_to_euler",
    "as_frames",
    "frames_to_poses",
    "exp_so3",
    "log_so3",
    "skew",
]


def euler_to_matrix(angles: np.ndarray) -> np.ndarray:
    """Z-Y-X Euler angles ``(..., 3)`` as ``(θx, θy, θz)`` → rotation matrices ``(..., 3, 3)``."""
    a = np.asarray(angles, dtype=float)
    cx, cy, cz = np.cos(a[..., 0]), np.cos(a[..., 1]), np.cos(a[..., 2])
    sx, sy, sz = np.sin(a[..., 0]), np.sin(a[..., 1]), np.sin(a[..., 2])
    R = np.empty(a.shape[:-1] + (3, 3))
    R[..., 0, 0] = cz * cy
    R[..., 0, 1] = cz * sy * sx - sz * cx
    R[..., 0, 2] = cz * sy * cx + sz * sx
    R[..., 1, 0] = sz * cy
    R[..., 1, 1] = sz * sy * sx + cz * cx
    R[..., 1, 2] = sz * sy * cx - cz * sx
    R[..., 2, 0] = -sy
    R[..., 2, 1] = cy * sx
    R[..., 2, 2] = cy * cx
    return R


def matrix_to_euler(R: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` → Z-Y-X Euler angles ``(..., 3)`` as ``(θx, θy, θz)``.

    θy is returned in [-π/2, π/2]; θx and θz in (-π, π].
    """
    R = np.asarray(R, dtype=float)
    ty = np.arctan2(-R[..., 2, 0], np.hypot(R[..., 0, 0], R[..., 1, 0]))
    tz = np.arctan2(R[..., 1, 0], R[..., 0, 0])
    tx = np.arctan2(R[..., 2, 1], R[..., 2, 2])
    return np.stack([tx, ty, tz], axis=-1)


def as_frames(poses: np.ndarray, field: str = "poses") -> tuple[np.ndarray, np.ndarray]:
    """Normalise pose input to positions ``(N, 3)`` and rotation matrices ``(N, 3, 3)``.

    Accepts ``(6,)`` or ``(N, 6)`` Euler poses and ``(4, 4)`` or ``(N, 4, 4)`` transforms.
    """
    X = np.asarray(poses, dtype=float)
    if X.ndim == 1 and X.shape == (POSE_SIZE,):
        X = X[None, :]
    elif X.ndim == 2 and X.shape == (4, 4):
        X = X[None, :, :]
    if X.ndim == 2 and X.shape[1] == POSE_SIZE:
        return X[:, :3].copy(), euler_to_matrix(X[:, 3:])
    if X.ndim == 3 and X.shape[1:] == (4, 4):
        return X[:, :3, 3].copy(), X[:, :3, :3].copy()
    raise ParameterError(field, "an array of shape (6,), (N, 6), (4, 4) or (N, 4, 4)", X.shape)


def frames_to_poses(p: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Positions ``(N, 3)`` and rotations ``(N, 3, 3)`` → Euler poses ``(N, 6)``."""
    return np.concatenate([np.asarray(p, dtype=float), matrix_to_euler(R)], axis=-1)


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrices ``(..., 3, 3)`` of vectors ``(..., 3)``: ``skew(a) @ b == a × b``."""
    v = np.asarray(v, dtype=float)
    S = np.zeros(v.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


def exp_so3(w: np.ndarray) -> np.ndarray:
    """Rodrigues' formula: rotation vectors ``(..., 3)`` → rotation matrices ``(..., 3, 3)``."""
    w = np.asarray(w, dtype=float)
    theta = np.linalg.norm(w, axis=-1)[..., None, None]
    K = skew(w)
    small = theta < 1e-8       # algorithm constant: the series is exact to round-off below
    safe = np.where(small, 1.0, theta)
    a = np.where(small, 1.0 - theta**2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(safe)) / safe**2)
    return np.eye(3) + a * K + b * (K @ K)


def log_so3(R: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` → rotation vectors ``(..., 3)`` (angle in [0, π])."""
    R = np.asarray(R, dtype=float)
    cos = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    theta = np.arccos(cos)
    v = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                  R[..., 1, 0] - R[..., 0, 1]], axis=-1)
    s = np.sin(theta)
    small = s < 1e-6           # algorithm constant: the series is exact to round-off below
    ratio = theta / (2 * np.where(small, 1.0, s))
    out = np.where(small[..., None], 0.5 * v, v * ratio[..., None])
    # Near θ = π the antisymmetric part vanishes: use the symmetric part instead.
    near_pi = (theta > np.pi - 1e-3)
    if np.any(near_pi):
        B = (R[near_pi] + np.eye(3)) / 2.0
        axis_idx = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        axis = B[np.arange(B.shape[0]), axis_idx]
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        sign = np.sign(np.einsum("...i,...i->...", axis, v[near_pi]))
        sign = np.where(sign == 0, 1.0, sign)
        out[near_pi] = axis * (theta[near_pi] * sign)[..., None]
    return out
