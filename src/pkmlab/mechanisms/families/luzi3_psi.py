"""The paper's reduced direct position analysis of the 3-chain platform (:mod:`.luzi3`) in
ψ1..ψ4 (Luzi, Sancisi & Parenti Castelli, eqs. 1-13) and the ψ ↔ pose conversion; see
``docs/validation.md`` for the conventions and the errata found. Moved out of :mod:`.luzi3`,
which re-exports every name. Every function takes ``mech``, a :class:`~.luzi3.Luzi3`."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...poses import as_frames, frames_to_poses
from ...tolerances import TOL
from ..results import NO_STROKE

__all__ = ["four_bar_theta", "pose_to_psi", "psi_to_pose", "reduced_dpa", "ReducedDPAResult"]

# ---------------------------------------------------------------------------------------------
# The paper's ψ parametrisation.
#
# Conventions adopted (see docs/validation.md): r_1 points from A11 to A12 (eq. 5 measures ψ1
# from +x, which contradicts the text's "r_i = A_i2 A_i1"); eq. (7) is the intrinsic product
# R = F1·Rx(ψ2)·Rz(θ)·Rx(ψ3)·Rz(ψ4) with F1 the chain-1 frame (identity for the paper's S_B):
# about x (not t_1) by ψ2, about the chain-plane normal u_1 by θ, about t_1 by ψ3 and about k
# by ψ4.


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(np.shape(a) + (3, 3))
    R[..., 0, 0] = 1.0
    R[..., 1, 1], R[..., 1, 2], R[..., 2, 1], R[..., 2, 2] = c, -s, s, c
    return R


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(np.shape(a) + (3, 3))
    R[..., 2, 2] = 1.0
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1] = c, -s, s, c
    return R


def four_bar_theta(mech, psi1, l11, l12, branch: int = -1):
    """Eqs. (1)-(3): the upper-link angle θ of chain 1 from ψ1 and the chain-1 leg lengths.

    ``branch=-1`` is the paper's root ``(-b - sqrt(b² - 4ac)) / 2a``; ``+1`` the other one.
    Returns NaN where the four-bar cannot close (negative discriminant).
    """
    r1 = np.linalg.norm(mech.base_points[1] - mech.base_points[0])
    ll = mech.upper_link
    h1, h2 = r1 / l11, r1 / ll
    h4 = (-r1**2 - l11**2 - ll**2 + l12**2) / (2 * ll * l11)
    a = -h1 + (1 + h2) * np.cos(psi1) + h4
    b = -2 * np.sin(psi1)
    c = h1 - (1 - h2) * np.cos(psi1) + h4
    disc = b * b - 4 * a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(disc)
        # Same root in two algebraically equal forms; use the better-conditioned one.
        num = -b + branch * root
        alt_den = -b - branch * root
        t = np.where(np.abs(2 * a) > np.abs(alt_den), num / (2 * a), 2 * c / alt_den)
    return np.where(disc >= 0, 2 * np.arctan(t), np.nan)


def psi_to_pose(mech, psi, l11, l12, branch: int = -1) -> np.ndarray:
    """ψ ``(N, 4)`` plus chain-1 lengths → tool poses ``(N, 6)`` (NaN where θ is not real)."""
    psi = np.atleast_2d(np.asarray(psi, dtype=float))
    p1, p2, p3, p4 = psi.T
    theta = four_bar_theta(mech, p1, l11, l12, branch)
    F = mech.chain1_frame()
    leg = np.stack([np.cos(p1), np.sin(p1) * np.cos(p2), np.sin(p1) * np.sin(p2)], axis=-1)
    up = np.stack([np.cos(theta), np.sin(theta) * np.cos(p2), np.sin(theta) * np.sin(p2)], -1)
    C1 = mech.base_points[0] + (np.asarray(l11)[..., None] * leg
                                + 0.5 * mech.upper_link * up) @ F.T
    R = F @ _rx(p2) @ _rz(theta) @ _rx(p3) @ _rz(p4)
    origin = C1 - np.einsum("nij,j->ni", R, mech.platform_points[0])
    tool = origin + np.einsum("nij,j->ni", R, mech.tool_offset)
    return frames_to_poses(tool, R)


def pose_to_psi(mech, poses) -> np.ndarray:
    """Tool poses ``(N, 6)`` / ``(N, 4, 4)`` → the paper's ψ1..ψ4 ``(N, 4)``."""
    p, R = as_frames(poses)
    F = mech.chain1_frame()
    origin = p - np.einsum("nij,j->ni", R, mech.tool_offset)
    C1 = origin + np.einsum("nij,j->ni", R, mech.platform_points[0])
    d = (C1 - mech.base_points[0]) @ F
    psi2 = np.arctan2(d[:, 2], d[:, 1])
    e = np.stack([np.zeros_like(psi2), np.cos(psi2), np.sin(psi2)], axis=1)
    k = R[:, :, 2] @ F
    r = np.array([1.0, 0.0, 0.0])
    n = np.cross(k, np.cross(r, d))
    n *= np.where(n[:, 0] >= 0, 1.0, -1.0)[:, None]
    t = n / np.linalg.norm(n, axis=1, keepdims=True)
    theta = np.arctan2(np.einsum("ni,ni->n", t, e), t[:, 0])
    b = d - 0.5 * mech.upper_link * t
    psi1 = np.arctan2(np.einsum("ni,ni->n", b, e), b[:, 0])
    N = np.swapaxes(_rz(theta), -1, -2) @ np.swapaxes(_rx(psi2), -1, -2) @ (F.T @ R)
    psi4 = np.arctan2(-N[:, 0, 1], N[:, 0, 0])
    psi3 = np.arctan2(-N[:, 1, 2], N[:, 2, 2])
    return np.stack([psi1, psi2, psi3, psi4], axis=1)


def _reduced_residual(mech, psi, q, branch: int, literal: bool = False) -> np.ndarray:
    """Eq. (13): the four closure residuals (mm) of chains 2 and 3, t_i from eq. (10).

    Eq. (10) fixes t_i's sign by the order of the cross products alone; unless ``literal``,
    t_i is oriented with t_i · r_i ≥ 0 (the inverse kinematics' convention), without which the
    reduced system cannot reach the modes where the printed sign points against r_i.
    """
    pose = psi_to_pose(mech, psi, q[0], q[1], branch)
    p, R = as_frames(pose)
    rho = np.einsum("nij,kj->nki", R, mech.platform_points - mech.tool_offset)
    C = p[:, None, :] + rho
    k = R[:, None, :, 2]
    A1, A2 = mech.base_points[0::2], mech.base_points[1::2]
    m = np.cross(k, np.cross(A2 - A1, C - A1))
    if not literal:
        m *= np.where(np.einsum("nki,ki->nk", m, A2 - A1) >= 0, 1.0, -1.0)[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        t = m / np.linalg.norm(m, axis=-1, keepdims=True)
    half = 0.5 * mech.upper_link
    l1 = np.linalg.norm(C - half * t - A1, axis=-1)
    l2 = np.linalg.norm(C + half * t - A2, axis=-1)
    res = np.stack([l1 - q[0::2], l2 - q[1::2]], axis=-1)     # (N, 3 chains, 2)
    return res[:, 1:, :].reshape(-1, 4)


@dataclass(frozen=True)
class ReducedDPAResult:
    """Solutions of the reduced system (13), physically consistent ones first.

    Attributes:
        psi: ``(M, 4)`` roots of eq. (13) (rad, wrapped to (-π, π]).
        branch: ``(M,)`` four-bar root used for θ (-1: the paper's).
        residual: ``(M,)`` largest residual of eq. (13) in mm.
        pose: ``(M, 6)`` tool poses.
        physical: ``(M,)`` True where the full inverse kinematics of the pose reproduces all
            six actuator lengths (false roots come from t_i's sign in eq. 10).
        ik_error: ``(M,)`` largest |q_IK(pose) - q| in mm.
    """

    psi: np.ndarray
    branch: np.ndarray
    residual: np.ndarray
    pose: np.ndarray
    physical: np.ndarray
    ik_error: np.ndarray


def reduced_dpa(mech, q, *, grid: int = 9, tol: float = 1e-9, max_iter: int = 60,
                literal_eq10: bool = False) -> ReducedDPAResult:
    """Solve the paper's 4-equation system (13) in ψ1..ψ4 by multi-start Newton.

    Starts: a ``grid⁴`` lattice over (-π, π]⁴, for both four-bar branches (configurations
    below the base plane have ψ1 or ψ2 outside (0, π), so the whole circle is searched).
    The Jacobian of (13) is taken by central
    differences (step 1e-7 rad); this solver is a cross-check of :meth:`Luzi3.forward`, which
    uses the analytic Jacobian of the full closure. Roots are de-duplicated by pose (distinct ψ
    can describe one pose, e.g. (ψ1, ψ2) and (-ψ1, ψ2 + π)). ``literal_eq10`` keeps eq. (10)'s
    printed sign of t_i (see :func:`_reduced_residual`).
    """
    q = np.asarray(q, dtype=float).reshape(6)
    a = np.linspace(-math.pi, math.pi, grid, endpoint=False) + math.pi / (2 * grid)
    starts = np.stack(np.meshgrid(a, a, a, a, indexing="ij"), -1).reshape(-1, 4)
    out_psi, out_branch, out_res = [], [], []
    h = 1e-7
    for branch in (-1, 1):
        x = starts.copy()
        for _ in range(max_iter):
            f = _reduced_residual(mech, x, q, branch, literal_eq10)
            ok = np.all(np.isfinite(f), axis=1)
            x, f = x[ok], f[ok]
            if x.shape[0] == 0:
                break
            Jm = np.empty((x.shape[0], 4, 4))
            for j in range(4):
                dx = np.zeros(4)
                dx[j] = h
                Jm[:, :, j] = (_reduced_residual(mech, x + dx, q, branch, literal_eq10)
                               - _reduced_residual(mech, x - dx, q, branch, literal_eq10)) / (2 * h)
            # algorithm constant: a non-zero determinant
            good = np.all(np.isfinite(Jm), axis=(1, 2)) & (np.abs(np.linalg.det(Jm)) > 1e-300)
            x, f, Jm = x[good], f[good], Jm[good]
            step = -np.linalg.solve(Jm, f[..., None])[..., 0]
            big = np.max(np.abs(step), axis=1)
            step *= np.minimum(1.0, 0.3 / np.maximum(big, 1e-300))[:, None]
            x = x + step
        f = _reduced_residual(mech, x, q, branch, literal_eq10)
        res = np.max(np.abs(f), axis=1)
        conv = res < tol
        out_psi.append(x[conv])
        out_res.append(res[conv])
        out_branch.append(np.full(int(conv.sum()), branch))
    psi = (np.concatenate(out_psi) + np.pi) % (2 * np.pi) - np.pi
    res = np.concatenate(out_res)
    branch = np.concatenate(out_branch)
    pose = np.concatenate([psi_to_pose(mech, psi[branch == b], q[0], q[1], b)
                           for b in (-1, 1)]) if psi.size else np.zeros((0, 6))
    order = np.concatenate([np.flatnonzero(branch == b) for b in (-1, 1)])
    psi, res, branch = psi[order], res[order], branch[order]
    p, R = as_frames(pose) if pose.size else (np.zeros((0, 3)), np.zeros((0, 3, 3)))
    keep: list[int] = []
    for i in np.argsort(res):
        if keep:
            k = np.array(keep)
            dp = np.max(np.abs(p[k] - p[i]), axis=1)
            dr = np.max(np.abs(R[k] - R[i]), axis=(1, 2))
            if np.any((dp < TOL.mode_duplicate_rel * mech.scale) & (dr < TOL.mode_duplicate_rel)):
                continue
        keep.append(int(i))
    psi, res, branch, pose, p, R = (a[keep] for a in (psi, res, branch, pose, p, R))
    ik = mech.inverse((p, R), stroke=NO_STROKE)
    with np.errstate(invalid="ignore"):
        err = np.max(np.abs(ik.q - q), axis=1) if pose.size else np.zeros(0)
    physical = np.isfinite(err) & (err < TOL.working_mode_mm)
    rank = np.lexsort((mech._pose_distance(p, R) if pose.size else np.zeros(0), ~physical))
    return ReducedDPAResult(psi=psi[rank], branch=branch[rank], residual=res[rank],
                            pose=pose[rank], physical=physical[rank], ik_error=err[rank])
