"""6-UPS Gough–Stewart platform: six extensible legs between base U joints and platform S joints.

Leg i joins the base joint ``B_i`` to the platform joint ``W_i = p + R·(P_i - O)``; the actuator
value is the leg length ``q_i = |W_i - B_i|``. With ``n_i = (W_i - B_i)/q_i`` and
``r_i = R·(P_i - O)`` the velocity Jacobian row is ``J_i = [n_iᵀ, (r_i × n_i)ᵀ]``.

Working mode: each platform joint stays on the side of its base joint's height that it has at
the nominal pose (above it, for the usual upright platform); a leg on the other side is
reported as ``leg outside the working mode`` by :meth:`~UPS6.inverse`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar, Literal

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ...poses import euler_to_matrix
from ...specbase import PairedCircles, _Common
from ..base import NO_STROKE, Mechanism, as_points, as_stroke, as_vector3
from ..joints import DEFAULT_FIELDS, ParamField, kind_arrays, kind_template, platform_joints
from ..kernels import boxes as _box
from ..kernels import ik as _kernels
from ..legs.layout import PAIRED_ALIASES, build_paired
from .psu6 import _radii

__all__ = ["UPS6", "working_sides"]


def working_sides(mech) -> np.ndarray:
    """``(6,)`` ±1: the side of its base joint (above/below) each platform joint of ``mech``
    keeps.

    The working mode: a leg that passes its base joint's height swaps to the mirror assembly
    mode (with a level platform, through a parallel singularity where all legs are
    horizontal). Taken from ``mech.nominal`` when given, else +1 (platform above the base,
    which is also where the mid-stroke nominal pose is searched).
    """
    if mech.nominal is None:
        return np.ones(6)
    pose = np.asarray(mech.nominal, dtype=float)
    R = euler_to_matrix(pose[3:])
    sz = pose[2] + mech.tool_points @ R[2] - mech.base_points[:, 2]
    return np.where(sz < 0, -1.0, 1.0)


@njit(cache=True, forceinline=True)
def _ups_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, bx, by, bz, ux, uy, uz,
             side, qmin, qmax):
    """One leg: ``(length, status)``; ``side`` (±1) is its working-mode side, a leg on the
    other side of its base joint is ``OTHER_MODE`` (also the prismatic legs of ``sixleg``)."""
    sx = px + r00 * ux + r01 * uy + r02 * uz - bx
    sy = py + r10 * ux + r11 * uy + r12 * uz - by
    sz = pz + r20 * ux + r21 * uy + r22 * uz - bz
    v = math.sqrt(sx * sx + sy * sy + sz * sz)
    s = _kernels.OTHER_MODE if sz * side <= 0.0 else _kernels.stroke_status(v, qmin, qmax)
    return v, (_kernels.DEGENERATE if v < 1e-12 else s)


@register_jitable(inline="always")
def _ups_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    """Per-pose inverse kinematics (see :mod:`._kernels`): leg lengths; ``g[36 + i]`` is leg
    i's working-mode side (±1), a leg on the other side of its base joint is ``OTHER_MODE``."""
    for i in range(6):
        v, s = _ups_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                        g[3 * i], g[3 * i + 1], g[3 * i + 2], g[18 + 3 * i], g[19 + 3 * i],
                        g[20 + 3 * i], g[36 + i], qmin, qmax)
        k = i * _kernels.ROW + j
        q[k] = v
        st[k] = s


@register_jitable(inline="always")
def _ups_jac_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, q, J, k):
    """Per-pose Jacobian (:func:`._kernels.make_jacobian_driver`): row i is
    ``[n_iᵀ, (r_i × n_i)ᵀ]``."""
    for i in range(6):
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        rx = r00 * ux + r01 * uy + r02 * uz
        ry = r10 * ux + r11 * uy + r12 * uz
        rz = r20 * ux + r21 * uy + r22 * uz
        sx = px + rx - g[3 * i]
        sy = py + ry - g[3 * i + 1]
        sz = pz + rz - g[3 * i + 2]
        v = math.sqrt(sx * sx + sy * sy + sz * sz)
        nx, ny, nz = sx / v, sy / v, sz / v
        J[k, i, 0] = nx
        J[k, i, 1] = ny
        J[k, i, 2] = nz
        J[k, i, 3] = ry * nz - rz * ny
        J[k, i, 4] = rz * nx - rx * nz
        J[k, i, 5] = rx * ny - ry * nx


@register_jitable(inline="always")
def _ups_jac_box(plo, phi, Rlo, Rhi, g, Jlo, Jhi):
    """:func:`_ups_jac_one` enclosed over a box of poses (:mod:`..kernels.boxes`): ``n = s /
    |s|`` by intervals (within [-1, 1]), then ``r × n``. False where ``|s|`` may fall below
    1e-2 of its largest value in the box."""
    for i in range(6):
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        rx0, rx1 = _box.irot(Rlo, Rhi, 0, ux, uy, uz)
        ry0, ry1 = _box.irot(Rlo, Rhi, 1, ux, uy, uz)
        rz0, rz1 = _box.irot(Rlo, Rhi, 2, ux, uy, uz)
        sx0, sx1 = plo[0] + rx0 - g[3 * i], phi[0] + rx1 - g[3 * i]
        sy0, sy1 = plo[1] + ry0 - g[3 * i + 1], phi[1] + ry1 - g[3 * i + 1]
        sz0, sz1 = plo[2] + rz0 - g[3 * i + 2], phi[2] + rz1 - g[3 * i + 2]
        qx0, qx1 = _box.isq(sx0, sx1)
        qy0, qy1 = _box.isq(sy0, sy1)
        qz0, qz1 = _box.isq(sz0, sz1)
        v0, v1 = qx0 + qy0 + qz0, qx1 + qy1 + qz1
        if not v0 >= 1e-4 * v1:
            return False
        iv0, iv1 = 1.0 / math.sqrt(v1), 1.0 / math.sqrt(v0)
        nx0, nx1 = _box.imul(sx0, sx1, iv0, iv1)
        ny0, ny1 = _box.imul(sy0, sy1, iv0, iv1)
        nz0, nz1 = _box.imul(sz0, sz1, iv0, iv1)
        nx0, nx1 = max(nx0, -1.0), min(nx1, 1.0)
        ny0, ny1 = max(ny0, -1.0), min(ny1, 1.0)
        nz0, nz1 = max(nz0, -1.0), min(nz1, 1.0)
        a0, a1 = _box.imul(ry0, ry1, nz0, nz1)
        b0, b1 = _box.imul(rz0, rz1, ny0, ny1)
        c0, c1 = _box.imul(rz0, rz1, nx0, nx1)
        d0, d1 = _box.imul(rx0, rx1, nz0, nz1)
        e0, e1 = _box.imul(rx0, rx1, ny0, ny1)
        f0, f1 = _box.imul(ry0, ry1, nx0, nx1)
        Jlo[i, 0], Jhi[i, 0] = _box.widen(nx0, nx1)
        Jlo[i, 1], Jhi[i, 1] = _box.widen(ny0, ny1)
        Jlo[i, 2], Jhi[i, 2] = _box.widen(nz0, nz1)
        Jlo[i, 3], Jhi[i, 3] = _box.widen(a0 - b1, a1 - b0)
        Jlo[i, 4], Jhi[i, 4] = _box.widen(c0 - d1, c1 - d0)
        Jlo[i, 5], Jhi[i, 5] = _box.widen(e0 - f1, e1 - f0)
    return True


@njit(inline="always")
def _ups_column_leg(x, y, wx, wy, wz, side, qmin2, qmax2):
    """Along a column q² = d² + (z + w_z)² (d the horizontal leg length): the stroke window
    is |z + w_z| in [sqrt(qmin² - d²), sqrt(qmax² - d²)], two intervals mirrored about the
    base joint's height; the working mode keeps the one on the nominal pose's side."""
    sx = x + wx
    sy = y + wy
    d2 = sx * sx + sy * sy
    A = qmax2 - d2
    B = qmin2 - d2
    ro = math.sqrt(A if A > 0.0 else 0.0)
    ri = math.sqrt(B if B > 0.0 else 0.0)
    if side > 0.0:
        return -wz + ri, -wz + ro, A >= 0.0
    return -wz - ro, -wz - ri, A >= 0.0


class UPS6Spec(_Common):
    family: Literal["ups6"]
    generator: PairedCircles | None = None

    def build(self) -> UPS6:
        if self._explicit("generator"):
            return UPS6(self.base_points, self.platform_points, self.stroke, self.tool_offset,
                        **self._kw())
        return UPS6.from_circles(**self.generator.model_dump(), stroke=self.stroke,
                                 tool_offset=self.tool_offset, **self._kw())


@dataclass(frozen=True, eq=False)
class UPS6(Mechanism):
    """6-UPS geometry.

    Attributes:
        base_points: ``(6, 3)`` base U-joint centres (mm, base frame).
        platform_points: ``(6, 3)`` platform S-joint centres (mm, platform frame).
        stroke_window: leg-length window (min, max) in mm, 0 < min < max.
        tool_offset: ``(3,)`` tool-frame origin in the platform frame (mm).
    """

    family = "ups6"
    #: the YAML model (``family: ups6``) and the named study variables (paths in it)
    spec_model: ClassVar[type] = UPS6Spec
    design_aliases: ClassVar[dict] = dict(PAIRED_ALIASES)

    base_points: np.ndarray
    platform_points: np.ndarray
    stroke_window: tuple[float, float]
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]

    _ik_one = _ups_one
    _jac_one = _ups_jac_one
    _jac_box = _ups_jac_box

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 6))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 6))
        set_(self, "stroke_window", as_stroke(self.stroke_window, "stroke", positive=True))
        set_(self, "tool_offset", as_vector3(self.tool_offset, "tool_offset"))

    @classmethod
    def from_circles(cls, *, base_radii=(300.0, 300.0), platform_radii=(150.0, 150.0),
                     base_pair_angle: float | None = None,
                     platform_rotation: float = math.radians(30.0),
                     base_pair_separation: float = math.radians(20.0),
                     platform_pair_separation: float = math.radians(20.0),
                     pairing: str = "same", stroke=(400.0, 700.0), tool_offset=(0.0, 0.0, 0.0),
                     name: str = "", nominal=None) -> UPS6:
        """Paired layout on circles (see :mod:`pkmlab.mechanisms.legs.layout`).

        Equal inner and outer radii with pair separations give the usual "two circles with pair
        separation angles" Gough–Stewart (``base_pair_angle=None`` solves it for equal
        legs); distinct inner/outer radii with zero separations give
        the Stoughton–Arai (1993) concentric-circle variant. Angles in rad, lengths in mm.
        """
        base_radii = _radii(base_radii, "base_radii")
        platform_radii = _radii(platform_radii, "platform_radii")
        B, P, desc = build_paired(base_radii, platform_radii, base_pair_angle,
                                  platform_rotation, base_pair_separation,
                                  platform_pair_separation, pairing)
        return cls(B, P, stroke, tool_offset, name=name, nominal=nominal, description=desc)

    @property
    def scale(self) -> float:
        return float(np.max(np.linalg.norm(self.base_points, axis=1))
                     + np.max(np.linalg.norm(self.platform_points, axis=1)) + self.stroke[1])

    def _gparams(self) -> np.ndarray:
        return np.concatenate([self.base_points.ravel(), self.tool_points.ravel(),
                               self._sides])

    @cached_property
    def _sides(self) -> np.ndarray:
        """``(6,)`` ±1 working-mode sides (:func:`working_sides`)."""
        return working_sides(self)

    def _legs(self, p, R):
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        s = p[:, None, :] + r - self.base_points
        length = np.linalg.norm(s, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            n = s / length[..., None]
        return r, n, length

    def _closure(self, p, R, q):
        r, n, length = self._legs(p, R)
        return length - q, np.concatenate([n, np.cross(r, n)], axis=-1)

    # ---- workspace hooks -------------------------------------------------------------------
    column_method = "quadratic"

    column_radial = True
    column_leg = _ups_column_leg

    def column_params(self) -> np.ndarray:
        lo, hi = self.stroke
        return np.stack([self._sides, np.full(6, lo * lo), np.full(6, hi * hi)], axis=1)

    def column_profile(self) -> np.ndarray:
        """``(6, 2, 3)``: each leg's lower and upper column end as ``(c, σ, K)``, the end
        being ``c + σ·sqrt(max(K - d², 0)) - w_z`` (see :class:`.base.Mechanism`)."""
        lo2, hi2 = self.stroke[0] ** 2, self.stroke[1] ** 2
        up = self._sides > 0
        z, one = np.zeros(6), np.ones(6)
        sig = np.where(up, one, -one)
        return np.stack([np.stack([z, sig, np.where(up, lo2, hi2)], axis=1),
                         np.stack([z, sig, np.where(up, hi2, lo2)], axis=1)], axis=1)

    def position_bounds(self, R):
        """Per orientation: each leg within qmax, on its working-mode side: ``(M, 2, 3)``."""
        W = self.leg_offsets(R)
        qmax = self.stroke[1]
        lo, hi = -W - qmax, -W + qmax
        up = self._sides > 0
        lo[:, up, 2] = -W[:, up, 2]              # z + w_z >= 0 above the base joint
        hi[:, ~up, 2] = -W[:, ~up, 2]
        return np.stack([lo.max(axis=1), hi.min(axis=1)], axis=1)

    # ---- joints (:mod:`.joints`): U on the base, P (the leg), S on the platform -------------
    parameter_fields = (ParamField("base_points", "base", "mm",
                                   "leg {i}'s base U joint centre (base frame)"),
                        *DEFAULT_FIELDS[1:])

    def _joint_arrays(self, p, R, axes=True):
        W = platform_joints(self, p, R)
        q = self.inverse((p, R), stroke=NO_STROKE).q if axes else None
        return kind_arrays(self, "prismatic", self.base_points, W, q, R, axes)

    def _leg_templates(self):
        return tuple(kind_template("prismatic", i, n, self.base_points[i],
                                   self.platform_points[i], (0.0, 0.0), zero=self.base_points[i])
                     for i, n in enumerate(self.actuator_names))
