"""``ldelta3``: the linear delta (the delta 3-D printer) — three carriages on vertical or
inclined towers, parallelogram rods, a translating effector.

Why a family apart from the rotary ``delta3``: see :mod:`.delta3`'s notes (one actuator unit
per family; different joints, parameters, column maths and outputs).

Leg i: a carriage runs on a rail of unit direction ``e_i`` (up the tower); its rod joint is
at ``C_i = B_i + q_i·e_i``, ``B_i`` where the actuator reads 0 (the generator puts it on the
tower line at the bed plane z = 0). A rod of length ``l_i`` (the parallelogram, modelled as
one S–S rod) joins it to the effector joint ``P_i = p + R·t_i``. With ``W = P_i - B_i``,
``c = W·e`` and ``W⊥ = W - c·e``:

    q_i = c + sqrt(l_i² - |W⊥|²)         (the carriage above the effector, along e)

Statuses per actuator: no real solution (``|W⊥| > l``: the rod cannot reach the rail), the
working mode (the rod must go *down* from the carriage, ``(P - C)_z <= 0``; only an inclined
tower can violate it: ``OTHER_MODE``), the carriage window ``stroke`` (mm: the endstop at
its top, the lowest carriage position at its bottom) and the **rod angle**: the angle
between the rod and the tower, ``asin(|W⊥|/l)``, must stay within ``rod_angle_limit``
(``JOINT_LIMIT``; printers limit it to keep the carriages' speed ratio bounded).

Jacobian ``J_i = d_iᵀ / (d_i·e_i)``, ``d_i = P_i - C_i`` (:mod:`._delta`); serial singular when
the rod is perpendicular to its tower.

**Exact columns** (:func:`ldelta_column_leg`). Vertical tower (``e = ẑ``): with ``d`` the
horizontal distance of the column from the tower line, the leg holds on
``z ∈ [q_min - sqrt(l² - d²), q_max - sqrt(l² - d²)] - w_z`` where ``d <= l·sin(limit)``.
Inclined tower: the carriage coordinate is monotone along the column on the working side, so
the set is one interval with closed-form ends (:func:`.._slider.slider_interval`, branch +1,
side -1), intersected with the rod-angle condition ``|W⊥|² <= l² sin² limit``, a quadratic in
``t = z + w_z``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from numba import njit
from numba.extending import register_jitable
from pydantic import Field

from ...errors import ParameterError
from ...quantities import Angle, Length, PositiveLength
from ...specbase import FamilySpec, _Model
from ..base import NO_STROKE, as_points, as_positive, as_stroke, as_vector3
from ..joints import DEFAULT_FIELDS, JointArrays, LegTemplate, ParamField, platform_joints
from ..kernels import ik as _kernels
from ..legs.slider import K_MIN, slider_interval
from ..validation import unit_rows
from ._delta import DeltaFamily

__all__ = ["LDelta3", "LDelta3Spec"]

_ANGLES = tuple(math.radians(a) for a in (210.0, 330.0, 90.0))     # Klipper's A, B, C

# g layout: B 0-8, tool points 9-17, rails e 18-26, l² 27-29, (l sin limit)² 30-32


@njit(cache=True, forceinline=True)
def _ldelta_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, i, qmin, qmax):
    tx, ty, tz = g[9 + 3 * i], g[10 + 3 * i], g[11 + 3 * i]
    ex, ey, ez = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
    wx = px + r00 * tx + r01 * ty + r02 * tz - g[3 * i]
    wy = py + r10 * tx + r11 * ty + r12 * tz - g[3 * i + 1]
    wz = pz + r20 * tx + r21 * ty + r22 * tz - g[3 * i + 2]
    c = wx * ex + wy * ey + wz * ez
    ax, ay, az = wx - c * ex, wy - c * ey, wz - c * ez
    perp2 = ax * ax + ay * ay + az * az
    h2 = g[27 + i] - perp2
    real = h2 >= 0.0
    v = c + math.sqrt(h2 if real else 0.0)
    down = wz - v * ez <= 0.0
    s = _kernels.stroke_status(v, qmin, qmax)
    s = s if s != _kernels.OK or perp2 <= g[30 + i] else _kernels.JOINT_LIMIT
    s = _kernels.NO_SOLUTION if not real else (s if down else _kernels.OTHER_MODE)
    return (v if real else np.nan), s


@register_jitable(inline="always")
def _ldelta3_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
                 j):
    """Per-pose inverse kinematics (:mod:`.._kernels`), legs unrolled by hand."""
    v, s = _ldelta_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 0, qmin,
                       qmax)
    q[j], st[j] = v, s
    v, s = _ldelta_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 1, qmin,
                       qmax)
    q[_kernels.ROW + j], st[_kernels.ROW + j] = v, s
    v, s = _ldelta_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 2, qmin,
                       qmax)
    q[2 * _kernels.ROW + j], st[2 * _kernels.ROW + j] = v, s


@register_jitable
def ldelta_column_leg(x, y, wx, wy, wz, p, zlo, zhi, out_lo, out_hi):
    """Set leg (:mod:`._delta`) of a tower: its one z interval on the column (module notes),
    clipped to ``[zlo, zhi]``. ``p``: rail ``e`` (3), ``l``, ``q_min``, ``q_max``,
    ``(l sin limit)²``, 1 for a vertical rail."""
    X = x + wx
    Y = y + wy
    ex, ey, ez, l, qmin, qmax, lim2 = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    if p[7] > 0.5:
        d2 = X * X + Y * Y
        if d2 > l * l or d2 > lim2:
            return 0
        s = math.sqrt(l * l - d2)
        a = qmin - wz - s
        b = qmax - wz - s
    else:
        a, b, ok = slider_interval(X, Y, wz, ex, ey, ez, l, 1.0, -1.0, qmin, qmax)
        if not ok:
            return 0
        if lim2 < l * l:
            k = ex * ex + ey * ey
            c0 = X * ex + Y * ey
            half = c0 * ez
            disc = half * half - k * (X * X + Y * Y - c0 * c0 - lim2)
            if disc < 0.0:
                return 0
            sq = math.sqrt(disc)
            a = max(a, (half - sq) / k - wz)
            b = min(b, (half + sq) / k - wz)
    a = max(a, zlo)
    b = min(b, zhi)
    if not a < b:
        return 0
    out_lo[0] = a
    out_hi[0] = b
    return 1


@register_jitable
def ldelta_margin(x, y, z, P):
    """The smallest signed leg margin at ``(x, y, z)`` (:meth:`LDelta3.leg_margins`, the
    numba form): ``P`` rows ``w = R·t - B`` (3), ``e`` (3), ``l``, ``q_min``, ``q_max``,
    ``l·sin(limit)``."""
    out = np.inf
    for i in range(P.shape[0]):
        wx, wy, wz = x + P[i, 0], y + P[i, 1], z + P[i, 2]
        ex, ey, ez, l, lo, hi = P[i, 3], P[i, 4], P[i, 5], P[i, 6], P[i, 7], P[i, 8]
        c = wx * ex + wy * ey + wz * ez
        ax, ay, az = wx - c * ex, wy - c * ey, wz - c * ez
        reach = P[i, 9] - math.sqrt(ax * ax + ay * ay + az * az)
        tx, ty, tz = wx - hi * ex, wy - hi * ey, wz - hi * ez
        top = min(hi - c, math.sqrt(tx * tx + ty * ty + tz * tz) - l)
        bx, by, bz = wx - lo * ex, wy - lo * ey, wz - lo * ez
        bottom = max(c - lo, l - math.sqrt(bx * bx + by * by + bz * bz))
        out = min(out, min(reach, min(top, bottom)))
    return out


class LDelta3Generator(_Model):
    tower_radius: PositiveLength = Field(description="distance of the towers' carriage-joint "
                                         "lines from the centre at the bed plane (mm)")
    effector_radius: Length = Field(0.0, description="effector joint circle radius "
                                   "(mm); Klipper's delta_radius is tower - effector radius")
    tilt: Angle = Field(0.0, description="tower inclination from vertical, leaning inwards "
                        "as they rise (deg)")
    angles: list[float] = Field(default_factory=lambda: [210.0, 330.0, 90.0],
                                description="towers A, B, C about z (deg; Klipper's defaults)")


class LDelta3Spec(FamilySpec):
    """Linear delta: ``stroke`` is the carriage window along the towers (mm from the bed
    plane; the top is the endstop)."""

    family: Literal["ldelta3"]
    generator: LDelta3Generator
    rod_length: PositiveLength
    rod_angle_limit: Angle = Field(math.pi / 2, description="largest angle between a rod and "
                                   "its tower (deg)")

    def build(self):
        if self.base_points is not None or self.platform_points is not None:
            raise ParameterError("base_points", "absent: ldelta3 takes its joints from the "
                                 "generator", "given")
        g = self.generator
        if g.effector_radius < 0:
            raise ParameterError("generator.effector_radius", "a radius >= 0 mm",
                                 g.effector_radius)
        return LDelta3.from_towers(tower_radius=g.tower_radius,
                                   effector_radius=g.effector_radius, tilt=g.tilt,
                                   angles=np.radians(g.angles), rod_length=self.rod_length,
                                   stroke=self.stroke, rod_angle_limit=self.rod_angle_limit,
                                   tool_offset=self.tool_offset, **self.explicit_kw())


@dataclass(frozen=True, eq=False)
class LDelta3(DeltaFamily):
    """Linear delta geometry (module notes).

    Attributes:
        base_points: ``(3, 3)`` carriage rod-joint positions at actuator value 0 (mm).
        platform_points: ``(3, 3)`` effector joints in the platform frame (mm).
        rail_directions: ``(3, 3)`` unit rail directions e_i (up the towers).
        rod_length: ``(3,)`` rods (mm).
        stroke_window: carriage window (mm).
        rod_angle_limit: largest rod-to-tower angle (rad, in (0, π/2]).
        tool_offset: ``(3,)`` the tool (nozzle) point in the platform frame (mm).
    """

    family = "ldelta3"
    spec_model = LDelta3Spec
    actuator_names = ("carriage_a", "carriage_b", "carriage_c")

    base_points: np.ndarray
    platform_points: np.ndarray
    rail_directions: np.ndarray
    rod_length: np.ndarray
    stroke_window: tuple
    rod_angle_limit: float = math.pi / 2
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)

    _ik_one = _ldelta3_one
    column_set_leg = ldelta_column_leg
    column_pieces = 1         # each tower's set is one interval, so is their intersection
    #: named study variables (paths in the YAML model)
    design_aliases: ClassVar[dict] = {
        "tower_radius": ("generator.tower_radius", "length"),
        "effector_radius": ("generator.effector_radius", "length"),
        "tilt": ("generator.tilt", "angle"), "rod_length": ("rod_length", "length"),
        "stroke_min": ("stroke[0]", "length"), "stroke_max": ("stroke[1]", "length"),
        "rod_angle_limit": ("rod_angle_limit", "angle")}

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 3))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 3))
        e = np.asarray(self.rail_directions, dtype=float)
        if e.shape != (3, 3) or not np.all(np.isfinite(e)) \
                or np.any(np.linalg.norm(e, axis=1) < 1e-9):
            raise ParameterError("rail_directions", "three non-zero directions", e.tolist())
        e = unit_rows(e)
        k = e[:, 0] ** 2 + e[:, 1] ** 2
        if np.any(e[:, 2] <= 0) or np.any((k > 0) & (k < K_MIN)):
            raise ParameterError("rail_directions", "rising directions (z > 0), exactly "
                                 "vertical or at least 0.002 deg from it", e.tolist())
        e.setflags(write=False)
        set_(self, "rail_directions", e)
        set_(self, "rod_length", as_positive(self.rod_length, "rod_length", (3,)))
        self.rod_length.setflags(write=False)
        set_(self, "stroke_window", as_stroke(self.stroke_window, "stroke"))
        lim = float(self.rod_angle_limit)
        if not 0.0 < lim <= math.pi / 2:
            raise ParameterError("rod_angle_limit", "an angle in (0, 90] deg", math.degrees(lim))
        set_(self, "rod_angle_limit", lim)
        set_(self, "tool_offset", as_vector3(self.tool_offset, "tool_offset"))

    @classmethod
    def from_towers(cls, *, tower_radius=215.0, effector_radius=40.0, rod_length=333.0,
                    stroke=(0.0, 600.0), tilt=0.0, angles=_ANGLES,
                    rod_angle_limit=math.pi / 2, tool_offset=(0.0, 0.0, 0.0), name: str = "",
                    nominal=None) -> LDelta3:
        """Towers at ``angles`` (rad) about z, their carriage-joint lines crossing the bed
        plane z = 0 at ``tower_radius``, tilted inwards by ``tilt`` (rad) as they rise;
        effector joints on the circle ``effector_radius``. Lengths mm."""
        a = np.asarray(angles, dtype=float)
        u = np.stack([np.cos(a), np.sin(a), np.zeros(3)], axis=1)
        e = math.cos(tilt) * np.array([0.0, 0.0, 1.0]) - math.sin(tilt) * u
        desc = {"generator": "delta towers", "tower_radius_mm": float(tower_radius),
                "effector_radius_mm": float(effector_radius), "tilt_deg": math.degrees(tilt),
                "angles_deg": np.degrees(a).tolist()}
        return cls(tower_radius * u, effector_radius * u, e, np.full(3, float(rod_length)),
                   stroke, rod_angle_limit, tool_offset, name=name, nominal=nominal,
                   description=desc)

    # ---- family hooks ----------------------------------------------------------------------
    @property
    def vertical(self) -> np.ndarray:
        """``(3,)`` True for the exactly vertical towers."""
        return (self.rail_directions[:, 0] == 0.0) & (self.rail_directions[:, 1] == 0.0)

    @property
    def scale(self) -> float:
        return float(np.max(np.linalg.norm(self.base_points, axis=1))
                     + np.max(np.linalg.norm(self.platform_points, axis=1))
                     + np.max(self.rod_length) + (self.stroke[1] - self.stroke[0]))

    def _gparams(self) -> np.ndarray:
        lim = self.rod_length * math.sin(self.rod_angle_limit)
        return np.concatenate([self.base_points.ravel(), self.tool_points.ravel(),
                               self.rail_directions.ravel(), self.rod_length ** 2, lim ** 2])

    def driven_points(self, q):
        return self.base_points + np.asarray(q, dtype=float)[..., None] * self.rail_directions

    carriages = driven_points

    def driven_velocity(self, q):
        return np.broadcast_to(self.rail_directions, np.shape(q) + (3,))

    def describe(self) -> dict:
        d = super().describe()
        d.update(rod_length_mm=self.rod_length.tolist(),
                 rail_directions=self.rail_directions.tolist(),
                 rod_angle_limit_deg=math.degrees(self.rod_angle_limit))
        return d

    # ---- workspace -------------------------------------------------------------------------
    def column_params(self) -> np.ndarray:
        """``(3, 8)`` rows of :func:`ldelta_column_leg`."""
        lo, hi = self.stroke
        lim = self.rod_length * math.sin(self.rod_angle_limit)
        return np.ascontiguousarray(np.column_stack([
            self.rail_directions, self.rod_length, np.full(3, lo), np.full(3, hi),
            np.where(self.rod_angle_limit >= math.pi / 2, np.inf, lim ** 2),
            self.vertical.astype(float)]))

    def position_bounds(self, R):
        """The carriage segment widened by the rod, per leg, intersected: ``(M, 2, 3)``."""
        W = self.leg_offsets(R)                                    # (M, 3, 3)
        lo, hi = self.stroke
        ends = np.stack([lo * self.rail_directions, hi * self.rail_directions])   # (2, 3, 3)
        l = self.rod_length[:, None]
        a = ends.min(axis=0) - l - W
        b = ends.max(axis=0) + l - W
        return np.stack([a.max(axis=1), b.min(axis=1)], axis=1)

    def leg_margins(self, p):
        """Signed margins of the towers (:mod:`pkmlab.workspaces.bracket_octree`), ``(N, 3)``."""
        W = np.asarray(p, dtype=float)[:, None, :] + self.tool_points @ self._rotation.T \
            - self.base_points
        e, l = self.rail_directions, self.rod_length
        lo, hi = self.stroke
        c = np.sum(W * e, axis=-1)
        perp = np.linalg.norm(W - c[..., None] * e, axis=-1)
        reach = l * math.sin(self.rod_angle_limit) - perp
        top = np.minimum(hi - c, np.linalg.norm(W - hi * e, axis=-1) - l)
        bottom = np.maximum(c - lo, l - np.linalg.norm(W - lo * e, axis=-1))
        return np.minimum(reach, np.minimum(top, bottom))

    cube_margin = ldelta_margin

    def margin_params(self) -> np.ndarray:
        """``(3, 10)`` rows of :func:`ldelta_margin`."""
        lo, hi = self.stroke
        w = self.tool_points @ self._rotation.T - self.base_points
        return np.ascontiguousarray(np.column_stack([
            w, self.rail_directions, self.rod_length, np.full(3, lo), np.full(3, hi),
            self.rod_length * math.sin(self.rod_angle_limit)]))

    def check_bracket(self) -> None:
        tilt = np.arccos(np.clip(self.rail_directions[:, 2], -1.0, 1.0))
        if np.any(~self.vertical & (tilt + self.rod_angle_limit >= math.pi / 2)):
            raise ParameterError("rod_angle_limit", "below 90 deg minus the tower tilt for a "
                                 "volume bracket of inclined towers (the rods then always go "
                                 "down from the carriages: the working mode needs no margin)",
                                 math.degrees(self.rod_angle_limit))

    # ---- joints: P (carriage, actuated), S at the carriage, the rod, S at the effector ------
    parameter_fields = (
        ParamField("base_points", "base", "mm",
                   "leg {i}'s carriage rod joint at actuator value 0 (base frame)"),
        DEFAULT_FIELDS[1],
        ParamField("rail_directions", "rail", "1", "leg {i}'s rail direction (up the tower)"),
        ParamField("rod_length", "rod", "mm", "leg {i}'s rods (parallelogram), ball to ball"),
        DEFAULT_FIELDS[2],
        ParamField("rod_angle_limit", "rod_angle_limit", "rad",
                   "largest angle between a rod and its tower"),
        DEFAULT_FIELDS[3])

    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        C = self.driven_points(q)
        W = platform_joints(self, p, R)
        ax = None
        if axes:
            ax = np.full((len(p), 3, 3, 2, 3), np.nan)
            ax[:, :, 0, 0] = self.rail_directions
        return JointArrays((C, C, W), ax, q)

    def _leg_templates(self):
        out = []
        for i, n in enumerate(self.actuator_names):
            leg = f"leg{i + 1}"
            out.append(LegTemplate(
                n, ("P", "S", "S"), (f"{leg}.P", f"{leg}.carriage_S", f"{leg}.platform_S"),
                ("base", f"{leg}.carriage", f"{leg}.rod", "platform"),
                (0.0, float(self.rod_length[i])), 0, (1, 2), self.base_points[i],
                self.platform_points[i], zero=self.base_points[i]))
        return tuple(out)
