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

The paper's reduced direct position analysis in ψ1..ψ4 (eqs. 1-13) and the ψ ↔ pose
conversion are in :mod:`.luzi3_psi` (re-exported here); see ``docs/validation.md`` for the
conventions and the errata found.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar, Literal

import numpy as np
from numba import njit
from numba.extending import register_jitable
from pydantic import Field

from ...errors import ParameterError
from ...poses import as_frames, skew
from ...quantities import Angle, PositiveLength, Vector3
from ...specbase import _Common, _Model
from ..base import Mechanism, as_points, as_positive, as_stroke, as_vector3
from ..joints import DEFAULT_FIELDS, JointArrays, LegTemplate, ParamField, unit
from ..kernels import ik as _kernels
from ..results import NO_STROKE

__all__ = ["Luzi3", "pose_to_psi", "psi_to_pose", "reduced_dpa", "ReducedDPAResult",
           "four_bar_theta", "working_branches"]


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


@njit(cache=True, forceinline=True)
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


class Luzi3Generator(_Model):
    base_diameter: PositiveLength
    phi: Angle = Field(description="angle between consecutive base points of different chains")
    platform_diameter: PositiveLength


class Luzi3Spec(_Common):
    family: Literal["luzi3"]
    generator: Luzi3Generator | None = None
    upper_link: PositiveLength
    tool_offset: Vector3 | Literal["centroid"] = "centroid"  # type: ignore[assignment]

    def build(self) -> Luzi3:
        explicit = self._explicit("generator")
        offset = self.tool_offset
        if explicit:
            if offset == "centroid":
                offset = np.mean(np.asarray(self.platform_points), axis=0)
            return Luzi3(self.base_points, self.platform_points, self.upper_link, self.stroke,
                         offset, **self._kw())
        return Luzi3.from_paper(**self.generator.model_dump(), upper_link=self.upper_link,
                                stroke=self.stroke,
                                tool_offset=None if offset == "centroid" else offset,
                                **self._kw())


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
    #: the YAML model (``family: luzi3``) and the named study variables (paths in it)
    spec_model: ClassVar[type] = Luzi3Spec
    design_aliases: ClassVar[dict] = {
        "base_diameter": ("generator.base_diameter", "length"),
        "platform_diameter": ("generator.platform_diameter", "length"),
        "phi": ("generator.phi", "angle"),
        "upper_link": ("upper_link", "length"),
        "stroke_min": ("stroke[0]", "length"),
        "stroke_max": ("stroke[1]", "length")}
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

    # ---- joints (:mod:`.joints`; the paper's Fig. 2) -----------------------------------------
    # Leg l_ij: U at A_ij (axes: the chord r_i, fixed in the base and collinear for the chain's
    # two U joints, and the normal u_i of the chain plane γ_i), the actuated P along A_ij → B_ij,
    # R at B_ij (axis u_i, parallel to the U joints' moving axes), the upper link B_ij → C_i
    # (l/2), shared by the chain's two legs, and U at C_i (axes t_i along the upper link and
    # the platform normal k, both in the platform plane σ or normal to it).
    parameter_fields = (
        ParamField("base_points", "base", "mm",
                   "base U joint {i} of A11, A12, A21, A22, A31, A32 (base frame)"),
        ParamField("platform_points", "platform", "mm",
                   "chain {i}'s platform U joint C_i (platform frame S_P)"),
        ParamField("upper_link", "upper_link", "mm", "upper link length |B_i1 B_i2|"),
        *DEFAULT_FIELDS[2:])

    def _joint_arrays(self, p, R, axes=True):
        C = p[:, None, :] + np.einsum("nij,kj->nki", R, self.tool_points)
        A1, A2 = self.base_points[0::2], self.base_points[1::2]
        u = np.cross(A2 - A1, C - A1)                            # γ_i normals (N, 3, 3)
        n = np.cross(R[:, None, :, 2], u)
        sgn = np.where(np.einsum("nki,ki->nk", n, A2 - A1) >= 0, 1.0, -1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = n * (sgn / np.linalg.norm(n, axis=-1))[..., None]
        half = 0.5 * self.upper_link
        B = np.stack([C - half * t, C + half * t], axis=2).reshape(-1, 6, 3)
        A = np.broadcast_to(self.base_points, B.shape)
        C2 = np.repeat(C, 2, axis=1)
        ax = np.full((len(p), 6, 4, 2, 3), np.nan) if axes else None
        if axes:
            u2 = np.repeat(unit(u), 2, axis=1)
            ax[:, :, 0, 0] = np.repeat(unit(A2 - A1), 2, axis=0)
            ax[:, :, 0, 1] = u2
            ax[:, :, 1, 0] = unit(B - A)
            ax[:, :, 2, 0] = u2
            ax[:, :, 3, 0] = np.repeat(t, 2, axis=1)
            ax[:, :, 3, 1] = np.repeat(R[:, None, :, 2], 6, axis=1)
        return JointArrays((A, B, B, C2), ax,
                           self.inverse((p, R), stroke=NO_STROKE).q if axes else None)

    def _leg_templates(self):
        out = []
        for k, name in enumerate(self.actuator_names):
            chain = f"chain{k // 2 + 1}"
            out.append(LegTemplate(
                name, ("U", "P", "R", "U"),
                (f"{name}.base_U", f"{name}.P", f"{name}.R", f"{chain}.platform_U"),
                ("base", f"{name}.cylinder", f"{name}.rod", f"{chain}.upper_link", "platform"),
                (0.0, 0.0, 0.5 * self.upper_link), 1, (0, 2), self.base_points[k],
                self.platform_points[k // 2], zero=self.base_points[k]))
        return tuple(out)

    # ---- ψ parametrisation ---------------------------------------------------------------
    def chain1_frame(self) -> np.ndarray:
        """Columns: x ∥ A11→A12, y = ẑ × x (normalised), z = x × y. Identity for the paper."""
        ex = self.base_points[1] - self.base_points[0]
        ex = ex / np.linalg.norm(ex)
        ey = np.cross([0.0, 0.0, 1.0], ex)
        ey /= np.linalg.norm(ey)
        return np.stack([ex, ey, np.cross(ex, ey)], axis=1)


from .luzi3_psi import (  # noqa: E402  (re-exported; the module needs Luzi3 only for types)
    ReducedDPAResult,
    four_bar_theta,
    pose_to_psi,
    psi_to_pose,
    reduced_dpa,
)
