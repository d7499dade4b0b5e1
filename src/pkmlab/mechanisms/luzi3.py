"""Over-constrained modified Gough–Stewart platform with three planar chains.

Luzi, Sancisi & Parenti Castelli, "A new direct position analysis solution for an
over-constrained Gough–Stewart platform". Chain i has base points ``A_i1, A_i2``, two actuated
legs ``A_ij B_ij`` and an upper link ``B_i1 B_i2`` of length ``l`` whose midpoint is the platform
U-joint ``C_i``. The chain stays in the plane γ_i through ``A_i1, A_i2, C_i`` and the upper
link lies both in γ_i and in the platform plane σ, so

    u_i = r_i × (C_i - A_i1)        (normal of γ_i, r_i = A_i2 - A_i1)
    t_i = ± (k × u_i) / |k × u_i|   (k = platform normal; sign: t_i · r_i ≥ 0)
    B_i1 = C_i - (l/2)·t_i,  B_i2 = C_i + (l/2)·t_i,  q_ij = |B_ij - A_ij|

which is the closed-form inverse kinematics. The platform frame is the paper's S_P: origin at
C_1, y axis along C_1 → C_3, z axis normal to σ. Actuators are ordered
``[l11, l12, l21, l22, l31, l32]`` as in the paper's Table 1.

Working mode: chain i's branch is the sign of ``n_i · r_i = |r_i|² k · d_i`` (``n_i = k ×
u_i``, ``d_i`` the part of ``C_i - A_i1`` normal to the chord ``A_i1 A_i2``). Where it changes,
``t_i`` (kept along ``r_i``) turns over and the leg lengths jump, so each chain keeps its sign
at the nominal pose (:func:`working_branches`); a chain on the other branch (e.g. the mirror
image below the base) is ``leg outside the working mode`` in :meth:`~Luzi3.inverse`.

The module also implements the paper's reduced direct position analysis in ψ1..ψ4
(eqs. 1-13) and the ψ ↔ pose conversion; see ``docs/validation.md`` for the conventions and
the errata found.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ..errors import ParameterError
from ..poses import as_frames, frames_to_poses, skew
from . import _kernels
from .base import NO_STROKE, Mechanism, as_points, as_positive, as_stroke, as_vector3

__all__ = ["Luzi3", "pose_to_psi", "psi_to_pose", "reduced_dpa", "ReducedDPAResult",
           "working_branches"]


def working_branches(mech) -> np.ndarray:
    """``(3,)`` ±1: the branch (sign of ``n_i · r_i``, module notes) each chain of ``mech``
    keeps: its sign at ``mech.nominal`` when given, else +1 (the platform normal pointing away
    from every base chord, as at a level platform above the base, where the mid-stroke nominal
    pose is searched)."""
    if mech.nominal is None:
        return np.ones(3)
    p, R = as_frames(np.asarray(mech.nominal, dtype=float))
    A1, r = mech.base_points[0::2], mech.base_points[1::2] - mech.base_points[0::2]
    n = np.cross(R[0, :, 2], np.cross(r, p[0] + mech.tool_points @ R[0].T - A1))
    return np.where(np.einsum("ki,ki->k", n, r) >= 0, 1.0, -1.0)


@njit(inline="always")
def _luzi_chain(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, i):
    """Chain ``i``: lengths ``(q_i1, q_i2)`` of its legs, False where the chain is degenerate
    (its plane parallel to the platform normal, |k × u_i| ≈ 0; the lengths are then garbage),
    and False where its branch (sign of n·r) is not its working one, ``g[28 + i]``."""
    a1x, a1y, a1z = g[6 * i], g[6 * i + 1], g[6 * i + 2]
    a2x, a2y, a2z = g[6 * i + 3], g[6 * i + 4], g[6 * i + 5]
    ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
    half = 0.5 * g[27]
    kx, ky, kz = r02, r12, r22
    cx = px + r00 * ux + r01 * uy + r02 * uz
    cy = py + r10 * ux + r11 * uy + r12 * uz
    cz = pz + r20 * ux + r21 * uy + r22 * uz
    rx, ry, rz = a2x - a1x, a2y - a1y, a2z - a1z
    dx, dy, dz = cx - a1x, cy - a1y, cz - a1z
    wx, wy, wz = ry * dz - rz * dy, rz * dx - rx * dz, rx * dy - ry * dx
    nx, ny, nz = ky * wz - kz * wy, kz * wx - kx * wz, kx * wy - ky * wx
    nn = math.sqrt(nx * nx + ny * ny + nz * nz)
    scale = math.sqrt(rx * rx + ry * ry + rz * rz) * math.sqrt(dx * dx + dy * dy + dz * dz)
    # ±1 such that t_i · r_i >= 0 (arithmetic, not a conditional expression: this function is
    # inlined twice over, where numba's IR inliner mishandles conditional expressions)
    sign = (nx * rx + ny * ry + nz * rz >= 0.0) * 2.0 - 1.0
    s = sign * (half / nn)
    ex, ey, ez = cx - s * nx - a1x, cy - s * ny - a1y, cz - s * nz - a1z
    v1 = math.sqrt(ex * ex + ey * ey + ez * ez)
    ex, ey, ez = cx + s * nx - a2x, cy + s * ny - a2y, cz + s * nz - a2z
    v2 = math.sqrt(ex * ex + ey * ey + ez * ez)
    return v1, v2, nn > 1e-12 * scale, sign * g[28 + i] > 0.0


@register_jitable(inline="always")
def _luzi_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    """Per-pose inverse kinematics (see :mod:`._kernels`); both legs of a degenerate chain are
    ``DEGENERATE`` with NaN lengths, both legs of a chain off its working branch
    ``OTHER_MODE`` with their lengths.

    Branch-free (the degenerate case is computed too, a division by zero that is discarded),
    and the chains are unrolled by hand so that ``g`` is indexed by constants.
    """
    chains = (_luzi_chain(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 0),
              _luzi_chain(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 1),
              _luzi_chain(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 2))
    for i, (v1, v2, ok, mode) in enumerate(chains):
        k = 2 * i * _kernels.ROW + j
        q[k] = v1 if ok else np.nan
        s1 = _kernels.stroke_status(v1, qmin, qmax) if mode else _kernels.OTHER_MODE
        st[k] = s1 if ok else _kernels.DEGENERATE
        k += _kernels.ROW
        q[k] = v2 if ok else np.nan
        s2 = _kernels.stroke_status(v2, qmin, qmax) if mode else _kernels.OTHER_MODE
        st[k] = s2 if ok else _kernels.DEGENERATE


@dataclass(frozen=True, eq=False)
class Luzi3(Mechanism):
    """Three-chain over-constrained Gough–Stewart geometry.

    Attributes:
        base_points: ``(6, 3)`` ``[A11, A12, A21, A22, A31, A32]`` (mm, base frame).
        platform_points: ``(3, 3)`` ``C_i`` in the platform frame S_P (mm).
        upper_link: length ``l`` of each upper link ``B_i1 B_i2`` (mm).
        stroke_window: actuator-length window (min, max) in mm.
        tool_offset: ``(3,)`` tool-frame origin in S_P (mm).
    """

    family = "luzi3"
    actuator_names = ("l11", "l12", "l21", "l22", "l31", "l32")

    base_points: np.ndarray
    platform_points: np.ndarray
    upper_link: float
    stroke_window: tuple[float, float]
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]

    _ik_one = _luzi_one

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 6))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 3))
        set_(self, "upper_link", as_positive(self.upper_link, "upper_link"))
        set_(self, "stroke_window", as_stroke(self.stroke_window, "stroke", positive=True))
        set_(self, "tool_offset", as_vector3(self.tool_offset, "tool_offset"))
        chord = np.linalg.norm(self.base_points[1::2] - self.base_points[0::2], axis=1)
        if np.any(chord <= self.upper_link):
            i = int(np.argmin(chord))
            raise ParameterError("upper_link", f"shorter than chain {i + 1}'s base chord "
                                 f"|A{i + 1}1 A{i + 1}2| = {chord[i]:.3f} mm", self.upper_link)

    @classmethod
    def from_paper(cls, *, base_diameter=840.0, phi=math.pi / 9, platform_diameter=280.0,
                   upper_link=100.0, stroke=(750.0, 1150.0), tool_offset=None, name: str = "",
                   nominal=None) -> Luzi3:
        """The paper's parametrisation (Sect. 4).

        Base points on a circle of ``base_diameter``; consecutive points of different chains
        subtend ``phi``, so each chain's two points subtend ``120° - phi``; chain 1 is centred
        at -90° so that x ∥ A11→A12 (the paper's S_B). ``C_i`` form an equilateral triangle
        inscribed in ``platform_diameter``, C_i facing chain i. ``tool_offset=None`` puts the
        tool frame at the platform centre. Angles in rad, lengths in mm.
        """
        if not (0 < phi < 2 * math.pi / 3):
            raise ParameterError("phi", "an angle in (0°, 120°)", math.degrees(phi))
        for fname, v in (("base_diameter", base_diameter),
                         ("platform_diameter", platform_diameter)):
            if not (np.isfinite(v) and v > 0):
                raise ParameterError(fname, "a length > 0 mm", v)
        centre = -math.pi / 2 + 2 * math.pi / 3 * np.arange(3)
        half = (2 * math.pi / 3 - phi) / 2
        ang = np.stack([centre - half, centre + half], axis=1).ravel()
        rb = base_diameter / 2
        A = np.stack([rb * np.cos(ang), rb * np.sin(ang), np.zeros(6)], axis=1)
        rp = platform_diameter / 2
        C = np.stack([rp * np.cos(centre), rp * np.sin(centre), np.zeros(3)], axis=1)
        y = (C[2] - C[0]) / np.linalg.norm(C[2] - C[0])
        z = np.array([0.0, 0.0, 1.0])
        F = np.stack([np.cross(y, z), y, z], axis=1)          # S_P axes at the level pose
        c = (C - C[0]) @ F
        offset = c.mean(axis=0) if tool_offset is None else tool_offset
        desc = {"generator": "Luzi et al. Sect. 4", "base_diameter_mm": base_diameter,
                "phi_deg": math.degrees(phi), "platform_diameter_mm": platform_diameter}
        return cls(A, c, upper_link, stroke, offset, name=name, nominal=nominal,
                   description=desc)

    # ---- family hooks ----------------------------------------------------------------------
    @property
    def scale(self) -> float:
        return float(np.max(np.linalg.norm(self.base_points, axis=1))
                     + np.max(np.linalg.norm(self.platform_points - self.tool_offset, axis=1))
                     + self.stroke[1])

    def _gparams(self) -> np.ndarray:
        return np.concatenate([self.base_points.ravel(), self.tool_points.ravel(),
                               [self.upper_link], self._branches])

    @cached_property
    def _branches(self) -> np.ndarray:
        """``(3,)`` ±1: each chain's working branch (:func:`working_branches`)."""
        return working_branches(self)

    def _level_yaw(self) -> float:
        """Yaw that points C_1 (seen from the platform centre) at chain 1's base midpoint."""
        c = self.platform_points[0] - self.platform_points.mean(axis=0)
        m = 0.5 * (self.base_points[0] + self.base_points[1]) - self.base_points.mean(axis=0)
        return float(np.arctan2(m[1], m[0]) - np.arctan2(c[1], c[0]))

    def _chains(self, p, R):
        """Leg lengths ``(N, 6)`` and their twist derivative ``(N, 6, 6)``."""
        n_pose = p.shape[0]
        A1, A2 = self.base_points[0::2], self.base_points[1::2]            # (3, 3)
        r = A2 - A1
        rho = np.einsum("nij,kj->nki", R, self.tool_points)            # (N, 3, 3)
        C = p[:, None, :] + rho
        k = R[:, :, 2]                                                      # (N, 3)
        eye = np.broadcast_to(np.eye(3), (n_pose, 3, 3, 3))
        MC = np.concatenate([eye, -skew(rho)], axis=-1)                    # (N, 3, 3, 6)
        Mk = np.concatenate([np.zeros((n_pose, 3, 3)), -skew(k)], axis=-1)  # (N, 3, 6)
        w = np.cross(r, C - A1)                                             # (N, 3, 3)
        Mw = np.einsum("kij,nkjm->nkim", skew(r), MC)
        n = np.cross(k[:, None, :], w)
        Mn = (-np.einsum("nkij,njm->nkim", skew(w), Mk)
              + np.einsum("nij,nkjm->nkim", skew(k), Mw))
        nn = np.linalg.norm(n, axis=-1)
        sgn = np.where(np.einsum("nki,ki->nk", n, r) >= 0, 1.0, -1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = n * (sgn / nn)[..., None]
            P = np.eye(3) - t[..., :, None] * t[..., None, :]
            Mt = np.einsum("nkij,nkjm->nkim", P, Mn) * (sgn / nn)[..., None, None]
            half = 0.5 * self.upper_link
            e1 = C - half * t - A1
            e2 = C + half * t - A2
            q1, q2 = np.linalg.norm(e1, axis=-1), np.linalg.norm(e2, axis=-1)
            J1 = np.einsum("nki,nkim->nkm", e1 / q1[..., None], MC - half * Mt)
            J2 = np.einsum("nki,nkim->nkm", e2 / q2[..., None], MC + half * Mt)
        q = np.stack([q1, q2], axis=-1).reshape(n_pose, 6)
        J = np.stack([J1, J2], axis=2).reshape(n_pose, 6, 6)
        return q, J

    def _jacobian(self, p, R):
        return self._chains(p, R)[1]

    def _closure(self, p, R, q):
        qq, J = self._chains(p, R)
        return qq - q, J

    def describe(self) -> dict:
        d = super().describe()
        d.update(upper_link_mm=self.upper_link)
        return d

    # ---- workspace hooks -------------------------------------------------------------------
    def position_bounds(self, R):
        """Each C_i lies within qmax + l/2 of both its base points: ``(M, 2, 3)``."""
        rho = np.einsum("mij,kj->mki", R, self.tool_points)             # (M, 3, 3)
        A = self.base_points.reshape(3, 2, 3)
        reach = self.stroke[1] + 0.5 * self.upper_link
        centre = A[None, :, :, :] - rho[:, :, None, :]                      # (M, 3, 2, 3)
        lo = (centre - reach).reshape(len(R), 6, 3).max(axis=1)
        hi = (centre + reach).reshape(len(R), 6, 3).min(axis=1)
        return np.stack([lo, hi], axis=1)

    cell_bounds = True
    position_curvature = True

    def leg_cell_bounds(self, p, R, delta, alpha, mode: bool = False):
        """Leg lengths at ``(p, R)`` and a bound on their change over a cell (triangle
        inequalities, no linearisation): for ``|p' - p| <= δ`` and ``angle(R'R^T) <= α``,
        with ``c = 2 sin(α/2)``,

        * ``|C' - C| <= εC = δ + c·|ρ_i|`` and ``|k' - k| <= c``;
        * ``w = r × (C - A1)``: ``|w' - w| <= εw = |r|·εC``;
        * ``n = k × w``: ``|n' - n| <= εn = c·(|w| + εw) + εw``;
        * when ``|n·r| > εn·|r|`` the sign that makes ``t·r >= 0`` is the same over the cell
          and ``n`` never vanishes, so the angle between ``n'`` and ``n`` is at most
          ``asin(εn/|n|)`` and ``|t' - t| <= εt = 2 sin(asin(εn/|n|)/2)``, and
          ``|q'_ij - q_ij| <= |B'_ij - B_ij| <= εC + (l/2)·εt``;
        * otherwise (the upper link may flip or be undefined in the cell) ``B = C ∓ (l/2)t``
          with ``|t| = 1`` still gives ``|q' - |C - A_ij|| <= εC + l/2``: the centre returned
          is then ``|C - A_ij|``, not the leg length (``q`` below is the centre of each bound,
          equal to the leg length wherever the sign is fixed; a pose where the link is
          undefined is not in the workspace, so the bound only needs to hold elsewhere).

        A slack of ``1e-9 mm + 1e-12·scale`` covers floating-point rounding. ``delta`` and
        ``alpha`` are ``(N,)`` (mm, rad); returns ``(q, eps)`` ``(N, 6)``, and with
        ``mode`` also ``(N, 3)`` int8 per chain: +1 where its branch (sign of ``n·r``) is the
        working one over the whole cell, -1 where it is the other one over the whole cell (no
        pose of the cell is in the working mode), 0 where it may flip or vanish.
        """
        p = np.asarray(p, float).reshape(-1, 3)
        R = np.asarray(R, float).reshape(-1, 3, 3)
        delta = np.broadcast_to(np.asarray(delta, float), (len(p),))
        c = 2 * np.sin(0.5 * np.minimum(np.broadcast_to(np.asarray(alpha, float),
                                                        (len(p),)), math.pi))
        A1, A2 = self.base_points[0::2], self.base_points[1::2]
        r = A2 - A1
        rn = np.linalg.norm(r, axis=1)                                     # (3,)
        rho = np.einsum("nij,kj->nki", R, self.tool_points)
        C = p[:, None, :] + rho
        k = R[:, None, :, 2]
        w = np.cross(r, C - A1)
        n = np.cross(k, w)
        nn = np.linalg.norm(n, axis=-1)
        eC = delta[:, None] + c[:, None] * np.linalg.norm(self.tool_points, axis=1)
        ew = rn * eC
        en = c[:, None] * (np.linalg.norm(w, axis=-1) + ew) + ew
        nr = np.einsum("nki,ki->nk", n, r)
        fixed = np.abs(nr) > en * rn
        sgn = np.where(nr >= 0, 1.0, -1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = n * (sgn / nn)[..., None]
            et = 2 * np.sin(0.5 * np.arcsin(np.minimum(en / nn, 1.0)))
        half = 0.5 * self.upper_link
        q = np.stack([np.linalg.norm(C - half * t - A1, axis=-1),
                      np.linalg.norm(C + half * t - A2, axis=-1)], axis=-1).reshape(-1, 6)
        slack = 1e-9 + 1e-12 * self.scale
        e = np.repeat(np.where(fixed, eC + half * et, eC + half) + slack, 2, axis=1)
        far = np.stack([np.linalg.norm(C - A1, axis=-1), np.linalg.norm(C - A2, axis=-1)],
                       axis=-1).reshape(-1, 6)
        out = np.where(np.repeat(fixed, 2, axis=1), q, far), e
        return (*out, np.where(fixed, sgn * self._branches, 0.0).astype(np.int8)) if mode \
            else out

    def leg_position_curvature(self, p, R, delta):
        """Gradient ``g (N, 6, 3)`` of each leg length in the position at ``(p, R)`` and a
        bound ``M (N, 6)`` on its second derivative over the ball ``|p' - p| <= δ`` (rotation
        fixed), so ``|q(p') - q(p) - g·(p' - p)| <= M·|p' - p|²/2``; ``inf`` where none holds.

        At fixed R, ``n = N·(C - A1)`` is linear with ``N = [k]×[r]×``, ``|N| <= |r|``; the
        unit vector ``t`` has ``|Dt| <= |r|/|n|`` and ``|D²t| <= (2/√3)·|r|²/|n|²`` (the
        second derivative of ``x/|x|`` along a unit ``h`` is ``-(2a·h + (1 - 3a²)·x̂)/|x|²``,
        ``a = x̂·h``, of norm ``sqrt(1 + 2a² - 3a⁴) <= 2/√3``). With ``e = C ∓ (l/2)t - A``:
        ``|De| <= G = 1 + (l/2)|r|/|n|min``, ``|D²e| <= (l/2)(2/√3)|r|²/|n|min²``, and
        ``|D²|e|| <= G²/|e|min + |D²e|``, where ``|n|min = |n| - |r|δ`` and ``|e|min = q -
        G·δ`` must be positive, and the sign of ``t`` fixed (as in :meth:`leg_cell_bounds`).
        """
        p = np.asarray(p, float).reshape(-1, 3)
        R = np.asarray(R, float).reshape(-1, 3, 3)
        delta = np.broadcast_to(np.asarray(delta, float), (len(p),))[:, None]
        A1, A2 = self.base_points[0::2], self.base_points[1::2]
        r = A2 - A1
        rn = np.linalg.norm(r, axis=1)
        C = p[:, None, :] + np.einsum("nij,kj->nki", R, self.tool_points)
        k = R[:, None, :, 2]
        n = np.cross(k, np.cross(r, C - A1))
        nn = np.linalg.norm(n, axis=-1)
        nr = np.einsum("nki,ki->nk", n, r)
        nmin = nn - rn * delta
        sgn = np.where(nr >= 0, 1.0, -1.0)
        half = 0.5 * self.upper_link
        with np.errstate(divide="ignore", invalid="ignore"):
            t = n * (sgn / nn)[..., None]
            N = np.einsum("nkij,kjl->nkil", skew(R[:, None, :, 2]), skew(r))   # (N, 3, 3, 3)
            Dt = (np.eye(3) - t[..., :, None] * t[..., None, :]) @ N * (sgn / nn)[..., None,
                                                                                  None]
            G = 1 + half * rn / nmin
            D2e = half * (2 / math.sqrt(3)) * rn**2 / nmin**2
            g, M = [], []
            for s, A in ((-1.0, A1), (1.0, A2)):
                e = C + s * half * t - A
                q = np.linalg.norm(e, axis=-1)
                De = np.eye(3) + s * half * Dt
                g.append(np.einsum("nki,nkij->nkj", e / q[..., None], De))
                emin = q - G * delta
                ok = (np.abs(nr) > rn**2 * delta * (1 + 1e-9)) & (nmin > 0) & (emin > 0)
                M.append(np.where(ok, (G**2 / emin + D2e) * (1 + 1e-9) + 1e-12, np.inf))
        g = np.stack(g, axis=2).reshape(-1, 6, 3)
        M = np.stack(M, axis=2).reshape(-1, 6)
        return g, M

    def leg_segments(self, p, R):
        """Actuated legs ``A_ij → B_ij`` as end points ``(N, 6, 3)`` each."""
        rho = np.einsum("nij,kj->nki", R, self.tool_points)
        C = p[:, None, :] + rho
        A1, A2 = self.base_points[0::2], self.base_points[1::2]
        n = np.cross(R[:, None, :, 2], np.cross(A2 - A1, C - A1))
        sgn = np.where(np.einsum("nki,ki->nk", n, A2 - A1) >= 0, 1.0, -1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = n * (sgn / np.linalg.norm(n, axis=-1))[..., None]
        half = 0.5 * self.upper_link
        end = np.stack([C - half * t, C + half * t], axis=2).reshape(-1, 6, 3)
        return np.broadcast_to(self.base_points, end.shape).copy(), end

    # ---- ψ parametrisation ---------------------------------------------------------------
    def chain1_frame(self) -> np.ndarray:
        """Columns: x ∥ A11→A12, y = ẑ × x (normalised), z = x × y. Identity for the paper."""
        ex = self.base_points[1] - self.base_points[0]
        ex = ex / np.linalg.norm(ex)
        ey = np.cross([0.0, 0.0, 1.0], ex)
        ey /= np.linalg.norm(ey)
        return np.stack([ex, ey, np.cross(ex, ey)], axis=1)


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


def four_bar_theta(mech: Luzi3, psi1, l11, l12, branch: int = -1):
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


def psi_to_pose(mech: Luzi3, psi, l11, l12, branch: int = -1) -> np.ndarray:
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


def pose_to_psi(mech: Luzi3, poses) -> np.ndarray:
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


def _reduced_residual(mech: Luzi3, psi, q, branch: int, literal: bool = False) -> np.ndarray:
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


def reduced_dpa(mech: Luzi3, q, *, grid: int = 9, tol: float = 1e-9, max_iter: int = 60,
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
            if np.any((dp < 1e-6 * mech.scale) & (dr < 1e-6)):
                continue
        keep.append(int(i))
    psi, res, branch, pose, p, R = (a[keep] for a in (psi, res, branch, pose, p, R))
    ik = mech.inverse((p, R), stroke=NO_STROKE)
    with np.errstate(invalid="ignore"):
        err = np.max(np.abs(ik.q - q), axis=1) if pose.size else np.zeros(0)
    physical = np.isfinite(err) & (err < 1e-6)
    rank = np.lexsort((mech._pose_distance(p, R) if pose.size else np.zeros(0), ~physical))
    return ReducedDPAResult(psi=psi[rank], branch=branch[rank], residual=res[rank],
                            pose=pose[rank], physical=physical[rank], ik_error=err[rank])
