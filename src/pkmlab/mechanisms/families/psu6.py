"""6-PSU: six vertical prismatic actuators, fixed-length links, S and U joints.

Hopkins & Williams (2002), "Modified 6-PSU platform" (ParaDex / HexaSlide family).

Leg i: the slider sits at ``B_i + q_i·ẑ`` (``B_i`` is its position at actuator value 0) and a
link of length ``l_i`` joins it to the platform joint ``W_i = p + R·(P_i - O)``, where ``O`` is
the tool offset in the platform frame. With ``a_i = W_i - B_i - q_i·ẑ`` and ``|a_i| = l_i``:

    q_i = W_iz - B_iz - sqrt(l_i² - (W_ix - B_ix)² - (W_iy - B_iy)²)      (positive root, eq. 6)

Differentiating ``|a_i|² = l_i²`` gives the velocity Jacobian row
``J_i = [a_iᵀ, (r_i × a_i)ᵀ] / a_iz`` with ``r_i = R·(P_i - O)``; it is singular (serial
singularity) when the link is horizontal (a_iz → 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ...errors import ParameterError, Shown
from ...quantities import LinkLengths
from ...specbase import PairedCircles, _Common
from ..base import NO_STROKE, Mechanism, as_points, as_positive, as_stroke, as_vector3
from ..joints import DEFAULT_FIELDS, ParamField, kind_arrays, kind_template, platform_joints
from ..kernels import boxes as _box
from ..kernels import ik as _kernels
from ..legs.layout import PAIRED_ALIASES, build_paired

__all__ = ["PSU6"]


@register_jitable(inline="always")
def _psu_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    """Per-pose inverse kinematics (see :mod:`._kernels`): eq. (6), NaN where h² < 0."""
    for i in range(6):
        bx, by, bz = g[3 * i], g[3 * i + 1], g[3 * i + 2]
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        ll = g[36 + i]
        ax = px + r00 * ux + r01 * uy + r02 * uz - bx
        ay = py + r10 * ux + r11 * uy + r12 * uz - by
        wz = pz + r20 * ux + r21 * uy + r22 * uz
        h2 = ll * ll - ax * ax - ay * ay
        real = h2 >= 0.0
        v = wz - bz - math.sqrt(h2 if real else 0.0)
        k = i * _kernels.ROW + j
        q[k] = v if real else np.nan
        st[k] = _kernels.stroke_status(v, qmin, qmax) if real else _kernels.NO_SOLUTION


@register_jitable(inline="always")
def _psu_jac_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, q, J, k):
    """Per-pose Jacobian (:func:`._kernels.make_jacobian_driver`): row i is
    ``[a_iᵀ, (r_i × a_i)ᵀ] / a_iz`` with ``a_iz = sqrt(l_i² - a_ix² - a_iy²)`` (NaN if < 0)."""
    for i in range(6):
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        rx = r00 * ux + r01 * uy + r02 * uz
        ry = r10 * ux + r11 * uy + r12 * uz
        rz = r20 * ux + r21 * uy + r22 * uz
        ax = px + rx - g[3 * i]
        ay = py + ry - g[3 * i + 1]
        ll = g[36 + i]
        az = math.sqrt(ll * ll - ax * ax - ay * ay)
        J[k, i, 0] = ax / az
        J[k, i, 1] = ay / az
        J[k, i, 2] = az / az
        J[k, i, 3] = (ry * az - rz * ay) / az
        J[k, i, 4] = (rz * ax - rx * az) / az
        J[k, i, 5] = (rx * ay - ry * ax) / az


@register_jitable(inline="always")
def _psu_jac_box(plo, phi, Rlo, Rhi, g, Jlo, Jhi):
    """:func:`_psu_jac_one` enclosed over a box of poses (:mod:`..kernels.boxes`): row i is
    ``[t_x, t_y, 1, r_y - r_z·t_y, r_z·t_x - r_x, r_x·t_y - r_y·t_x]`` with ``t = a_xy / a_z``
    (the kernel's row divided out). False where ``a_z`` may fall below 1e-2 of the link."""
    for i in range(6):
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        rx0, rx1 = _box.irot(Rlo, Rhi, 0, ux, uy, uz)
        ry0, ry1 = _box.irot(Rlo, Rhi, 1, ux, uy, uz)
        rz0, rz1 = _box.irot(Rlo, Rhi, 2, ux, uy, uz)
        ax0, ax1 = plo[0] + rx0 - g[3 * i], phi[0] + rx1 - g[3 * i]
        ay0, ay1 = plo[1] + ry0 - g[3 * i + 1], phi[1] + ry1 - g[3 * i + 1]
        ll = g[36 + i]
        sx0, sx1 = _box.isq(ax0, ax1)
        sy0, sy1 = _box.isq(ay0, ay1)
        h0, h1 = ll * ll - sx1 - sy1, ll * ll - sx0 - sy0
        if not h0 >= 1e-4 * ll * ll:
            return False
        iz0, iz1 = 1.0 / math.sqrt(h1), 1.0 / math.sqrt(h0)      # 1 / a_z
        tx0, tx1 = _box.imul(ax0, ax1, iz0, iz1)
        ty0, ty1 = _box.imul(ay0, ay1, iz0, iz1)
        a0, a1 = _box.imul(rz0, rz1, ty0, ty1)
        b0, b1 = _box.imul(rz0, rz1, tx0, tx1)
        c0, c1 = _box.imul(rx0, rx1, ty0, ty1)
        d0, d1 = _box.imul(ry0, ry1, tx0, tx1)
        Jlo[i, 0], Jhi[i, 0] = _box.widen(tx0, tx1)
        Jlo[i, 1], Jhi[i, 1] = _box.widen(ty0, ty1)
        Jlo[i, 2], Jhi[i, 2] = 1.0, 1.0                        # a_z / a_z, exact in float
        Jlo[i, 3], Jhi[i, 3] = _box.widen(ry0 - a1, ry1 - a0)
        Jlo[i, 4], Jhi[i, 4] = _box.widen(b0 - rx1, b1 - rx0)
        Jlo[i, 5], Jhi[i, 5] = _box.widen(c0 - d1, c1 - d0)
    return True


@register_jitable(inline="always")
def _psu_jac_lin(plo, phi, pc, R, g, A, W):
    """First-order form of :func:`_psu_jac_one` over the positions ``plo <= p <= phi`` at the
    rotation ``R`` (:mod:`..kernels.boxes`): for every such ``p`` the per-pose kernel's ``J(p)``
    satisfies ``|J(p) - J(pc) - Σ_k (p_k - pc_k) A[k]| <= W`` entrywise (``A (3, 6, 6)``,
    ``W (6, 6)``; ``A[2] = 0``: J does not depend on z).

    Row i is ``c + t_x e1 + t_y e2`` with ``t = a_xy / a_z``, ``e1 = [1, 0, 0, 0, r_z,
    -r_y]``, ``e2 = [0, 1, 0, -r_z, 0, r_x]``, and ``a_xy`` moves with ``p_xy``; the gradient
    of ``t`` is ``T = (I + t tᵀ) / a_z``. ``A`` holds ``T`` at the centre's ``a`` (``T₀``);
    by the mean value theorem per component, ``t(p) - t(pc) = T(ξ) Δ``, so the remainder is
    at most ``max |[T] - T₀| · |Δ|`` with ``[T]`` the interval enclosure of ``T`` over the
    box, plus an allowance ``3 · ROUND_REL · (1 + |J|)`` for the round-off of both kernel
    Jacobians and of ``A`` (the box Jacobians' premise). False where ``a_z`` may fall below
    1e-2 of the link."""
    hx = max(phi[0] - pc[0], pc[0] - plo[0]) * (1.0 + 1e-12)
    hy = max(phi[1] - pc[1], pc[1] - plo[1]) * (1.0 + 1e-12)
    for i in range(6):
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        rx = R[0, 0] * ux + R[0, 1] * uy + R[0, 2] * uz
        ry = R[1, 0] * ux + R[1, 1] * uy + R[1, 2] * uz
        rz = R[2, 0] * ux + R[2, 1] * uy + R[2, 2] * uz
        ax0, ax1 = plo[0] + rx - g[3 * i], phi[0] + rx - g[3 * i]
        ay0, ay1 = plo[1] + ry - g[3 * i + 1], phi[1] + ry - g[3 * i + 1]
        ll = g[36 + i]
        sx0, sx1 = _box.isq(ax0, ax1)
        sy0, sy1 = _box.isq(ay0, ay1)
        h0, h1 = ll * ll - sx1 - sy1, ll * ll - sx0 - sy0
        if not h0 >= 1e-4 * ll * ll:
            return False
        iz0, iz1 = 1.0 / math.sqrt(h1), 1.0 / math.sqrt(h0)      # 1 / a_z
        tx0, tx1 = _box.imul(ax0, ax1, iz0, iz1)
        tx0, tx1 = _box.widen(tx0, tx1)
        ty0, ty1 = _box.imul(ay0, ay1, iz0, iz1)
        ty0, ty1 = _box.widen(ty0, ty1)
        qx0, qx1 = _box.isq(tx0, tx1)
        qy0, qy1 = _box.isq(ty0, ty1)
        txx0, txx1 = _box.imul(1.0 + qx0, 1.0 + qx1, iz0, iz1)
        txx0, txx1 = _box.widen(txx0, txx1)
        tyy0, tyy1 = _box.imul(1.0 + qy0, 1.0 + qy1, iz0, iz1)
        tyy0, tyy1 = _box.widen(tyy0, tyy1)
        p0, p1 = _box.imul(tx0, tx1, ty0, ty1)
        txy0, txy1 = _box.imul(p0, p1, iz0, iz1)
        txy0, txy1 = _box.widen(txy0, txy1)
        cx, cy = pc[0] + rx - g[3 * i], pc[1] + ry - g[3 * i + 1]
        z = math.sqrt(ll * ll - cx * cx - cy * cy)
        vx, vy = cx / z, cy / z
        Txx, Tyy, Txy = (1.0 + vx * vx) / z, (1.0 + vy * vy) / z, vx * vy / z
        wxx = max(txx1 - Txx, Txx - txx0, 0.0)                  # |T(ξ) - T₀|, entrywise
        wyy = max(tyy1 - Tyy, Tyy - tyy0, 0.0)
        wxy = max(txy1 - Txy, Txy - txy0, 0.0)
        ex = wxx * hx + wxy * hy                                # |Δt_x - (T₀ Δ)_x|
        ey = wxy * hx + wyy * hy
        tmx = max(abs(tx0), abs(tx1))
        tmy = max(abs(ty0), abs(ty1))
        e1 = (1.0, 0.0, 0.0, 0.0, rz, -ry)
        e2 = (0.0, 1.0, 0.0, -rz, 0.0, rx)
        c0 = (0.0, 0.0, 1.0, ry, -rx, 0.0)
        for j in range(6):
            A[0, i, j] = Txx * e1[j] + Txy * e2[j]
            A[1, i, j] = Txy * e1[j] + Tyy * e2[j]
            A[2, i, j] = 0.0
            big = abs(c0[j]) + tmx * abs(e1[j]) + tmy * abs(e2[j])   # >= |J| in the box
            W[i, j] = ((ex * abs(e1[j]) + ey * abs(e2[j])) * (1.0 + 1e-12)
                       + 3.0 * _box.ROUND_REL * (1.0 + big + abs(A[0, i, j]) * hx
                                                 + abs(A[1, i, j]) * hy))
    return True


@njit(inline="always")
def _psu_column_leg(x, y, wx, wy, wz, l2, qmin, qmax):
    """Along a column q = z + w_z - sqrt(l² - |a_xy|²) with a_xy = (x, y) + w_xy: the stroke
    window is the z interval [qmin - w_z + h, qmax - w_z + h], none where h² < 0."""
    ax = x + wx
    ay = y + wy
    h2 = l2 - ax * ax - ay * ay
    s = math.sqrt(h2 if h2 > 0.0 else 0.0)
    return qmin - wz + s, qmax - wz + s, h2 >= 0.0


class PSU6Spec(_Common):
    family: Literal["psu6"]
    generator: PairedCircles | None = None
    link_length: LinkLengths

    def build(self) -> PSU6:
        if self._explicit("generator"):
            return PSU6(self.base_points, self.platform_points, self.link_length, self.stroke,
                        self.tool_offset, **self._kw())
        return PSU6.from_circles(**self.generator.model_dump(), link_length=self.link_length,
                                 stroke=self.stroke, tool_offset=self.tool_offset, **self._kw())


@dataclass(frozen=True, eq=False)
class PSU6(Mechanism):
    """6-PSU geometry.

    Attributes:
        base_points: ``(6, 3)`` slider positions at actuator value 0 (mm, base frame); sliders
            move along +z.
        platform_points: ``(6, 3)`` U-joint centres in the platform frame (mm).
        link_length: ``(6,)`` link lengths (mm).
        stroke_window: actuator window (min, max) in mm.
        tool_offset: ``(3,)`` tool-frame origin in the platform frame (mm); the tool frame has
            the platform frame's orientation (the paper's {H}, 47 mm above {P}).
    """

    family = "psu6"
    #: the YAML model (``family: psu6``) and the named study variables (paths in it)
    spec_model: ClassVar[type] = PSU6Spec
    design_aliases: ClassVar[dict] = {**PAIRED_ALIASES, "link_length": ("link_length", "length")}

    base_points: np.ndarray
    platform_points: np.ndarray
    link_length: np.ndarray
    stroke_window: tuple[float, float]
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]

    _ik_one = _psu_one
    _jac_one = _psu_jac_one
    _jac_box = _psu_jac_box
    _jac_lin = _psu_jac_lin

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 6))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 6))
        set_(self, "link_length", as_positive(self.link_length, "link_length", (6,)))
        set_(self, "stroke_window", as_stroke(self.stroke_window, "stroke"))
        set_(self, "tool_offset", as_vector3(self.tool_offset, "tool_offset"))
        self.link_length.setflags(write=False)
        span = np.linalg.norm((self.base_points - self._level_joints())[:, :2], axis=1)
        if np.any(span >= self.link_length):
            i = int(np.argmax(span - self.link_length))
            raise ParameterError("link_length",
                                 f"longer than leg {i + 1}'s horizontal span at the level "
                                 f"centred pose ({span[i]:.3f} mm)", float(self.link_length[i]))

    # ---- generator ---------------------------------------------------------------------------
    @classmethod
    def from_circles(cls, *, base_radii=(100.0, 165.0), platform_radii=(50.0, 80.0),
                     base_pair_angle: float | None = None,
                     platform_rotation: float = math.radians(33.7),
                     base_pair_separation: float = 0.0, platform_pair_separation: float = 0.0,
                     pairing: str = "same", link_length=225.0, stroke=(0.0, 101.6),
                     tool_offset=(0.0, 0.0, 47.0), name: str = "", nominal=None) -> PSU6:
        """Paired concentric-circle layout (see :mod:`pkmlab.mechanisms.legs.layout`).

        Defaults are the Hopkins & Williams prototype: radii 100/165 mm (base) and 50/80 mm
        (platform), ρ = 33.7°, 225 mm links, 101.6 mm stroke, {H} 47 mm above {P}.
        ``base_pair_angle=None`` solves β so that all legs are equal at the level pose, as the
        paper states; inner = outer radius with pair separations gives the single-circle
        ParaDex layout. Angles in rad, lengths in mm.
        """
        base_radii, platform_radii = _radii(base_radii, "base_radii"), \
            _radii(platform_radii, "platform_radii")
        B, P, desc = build_paired(base_radii, platform_radii, base_pair_angle,
                                  platform_rotation, base_pair_separation,
                                  platform_pair_separation, pairing)
        return cls(B, P, link_length, stroke, tool_offset, name=name, nominal=nominal,
                   description=desc)

    # ---- family hooks ----------------------------------------------------------------------
    @property
    def scale(self) -> float:
        return float(np.max(np.linalg.norm(self.base_points, axis=1))
                     + np.max(np.linalg.norm(self.platform_points, axis=1))
                     + np.max(self.link_length) + (self.stroke[1] - self.stroke[0]))

    def _level_joints(self) -> np.ndarray:
        return self.tool_points  # level, centred: horizontal positions are the points' own

    def _gparams(self) -> np.ndarray:
        return np.concatenate([self.base_points.ravel(), self.tool_points.ravel(),
                               self.link_length])

    def _closure(self, p, R, q):
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        a = p[:, None, :] + r - self.base_points
        a[..., 2] -= q
        norm = np.linalg.norm(a, axis=-1)
        u = a / norm[..., None]
        return norm - self.link_length, np.concatenate([u, np.cross(r, u)], axis=-1)

    def describe(self) -> dict:
        d = super().describe()
        d.update(link_length_mm=self.link_length.tolist())
        return d

    # ---- workspace hooks -------------------------------------------------------------------
    column_method = "linear"
    column_invariant = True   # link vectors, joint angles and J do not depend on z

    column_radial = True
    column_leg = _psu_column_leg

    def column_params(self) -> np.ndarray:
        lo, hi = self.stroke
        return np.stack([self.link_length**2, np.full(6, lo), np.full(6, hi)], axis=1)

    def column_profile(self) -> np.ndarray:
        """``(6, 2, 3)``: each leg's lower and upper column end as ``(c, σ, K)``, the end
        being ``c + σ·sqrt(max(K - d², 0)) - w_z`` (see :class:`.base.Mechanism`)."""
        lo, hi = self.stroke
        K = self.link_length**2
        one = np.ones(6)
        return np.stack([np.stack([lo * one, one, K], axis=1),
                         np.stack([hi * one, one, K], axis=1)], axis=1)

    def position_bounds(self, R):
        """Per orientation, the box each leg's reach and stroke allow: ``(M, 2, 3)``."""
        W = self.leg_offsets(R)
        l = self.link_length
        lo = np.stack([-W[..., 0] - l, -W[..., 1] - l, self.stroke[0] - W[..., 2]], axis=-1)
        hi = np.stack([-W[..., 0] + l, -W[..., 1] + l, self.stroke[1] - W[..., 2] + l],
                      axis=-1)
        return np.stack([lo.max(axis=1), hi.min(axis=1)], axis=1)

    # ---- joints (:mod:`.joints`): P (vertical rail), S on the slider, link, U on the platform
    parameter_fields = (
        ParamField("base_points", "base", "mm",
                   "leg {i}'s slider position at actuator value 0 (base frame; its z is the "
                   "actuator zero)"),
        *DEFAULT_FIELDS[1:2],
        ParamField("link_length", "link_length", "mm", "leg {i}'s link length, S to U"),
        *DEFAULT_FIELDS[2:])

    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        start = self.base_points + q[..., None] * np.array([0.0, 0.0, 1.0])
        return kind_arrays(self, "slider", start, platform_joints(self, p, R), q, R, axes,
                           rail=np.array([0.0, 0.0, 1.0]))

    def _leg_templates(self):
        return tuple(kind_template("slider", i, n, self.base_points[i], self.platform_points[i],
                                   (0.0, self.link_length[i]), zero=self.base_points[i])
                     for i, n in enumerate(self.actuator_names))


def _radii(value, field: str) -> tuple[float, float]:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (2,) or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ParameterError(field, "[inner, outer], two radii > 0 mm", value)
    if arr[0] > arr[1]:
        raise ParameterError(field, "[inner, outer] with inner <= outer",
                             Shown(f"[{arr[0]:.6g} mm, {arr[1]:.6g} mm]"))
    return float(arr[0]), float(arr[1])
