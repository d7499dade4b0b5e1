"""``delta3``: the rotary (Clavel) delta robot — three motors, upper arms, parallelogram
forearms, a translating platform.

**Why a family of its own, and not ``ldelta3`` with an actuator kind.** The protocol has one
actuator unit per family (``actuator_unit``, a class attribute that the CLI, the YAML units,
the evaluators' ``requires`` — "rotary actuator" — and the stroke windows read), and the two
legs differ in everything a family declares: joints (R–S–S here, P–S–S there), parameters
(arm and forearm, motor axes, a cone limit; against rails, rods, a rod-angle limit), column
maths (a crank's z set is a union of up to four intervals, :mod:`.._crank`; a carriage's is
one closed-form interval) and outputs (the printer's cylinder and firmware values make sense
for towers only). Two families, sharing :mod:`._delta` (forward kinematics, singularities,
the column driver), keep each one's declaration true. (``sixleg`` refuses to mix cranks with
linear legs for the same reason.)

Leg i (i = 1, 2, 3): a motor of axis ``n_i`` through the pivot ``B_i`` turns an upper arm of
length ``a_i``; its end (the elbow) is ``E_i = B_i + a_i(cos θ_i u_i + sin θ_i v_i)``, ``u_i``
the arm's zero direction, ``v_i = n_i × u_i``. The forearm, a parallelogram of two rods with
ball joints at both ends, is modelled as one S–S rod of length ``b_i`` from ``E_i`` to the
platform joint ``P_i`` (its cross bars stay parallel to ``n_i``, so the platform translates).
The generator (:meth:`Delta3.from_radii`) puts the pivots on a circle of radius ``R`` in the
plane z = 0, the axes tangent (``n = ẑ × u``, ``u`` radial outward, so ``v = -ẑ``: **a
positive motor angle lowers the arm**, 0 = horizontal), and the platform below.

**Inverse kinematics** per leg is the crank formula of :mod:`..rss6`
(``E cos θ + F sin θ = G``, ``θ = atan2(F, E) + b·acos(G/ρ)``), the branch ``b = -1`` putting
the elbow outward (the usual Clavel assembly). Statuses per actuator: no real solution (the
forearm cannot reach the arm's circle), degenerate, the motor window (``stroke``, rad), and
the **forearm ball-joint cone**: the forearm's angle out of the arm's plane,
``asin(|d·n|/b)`` with ``d`` the rod, must stay within ``cone_limit`` (``JOINT_LIMIT``).
With the parallelogram's bars parallel to the motor axis, this is the angle every one of its
four ball joints turns off its plane of symmetry (the platform keeps its orientation). Since
``E·n = B·n``, ``d·n = (P - B)·n``: the limit is a slab between two planes parallel to the
motor axis, independent of the arm angle.

**Jacobian** ``J_i = d_iᵀ / (d_i·∂E_i/∂θ_i)`` (:mod:`._delta`), translational columns.

**Exact columns**: the crank leg's z set (:func:`.._crank.crank_leg_set`) clipped to the cone
slab (:func:`delta_column_leg`).
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
from ...quantities import Angle, AngleWindow, PositiveLength
from ...specbase import FamilySpec, _Model
from ..base import NO_STROKE, as_points, as_positive, as_vector3
from ..joints import DEFAULT_FIELDS, ParamField, kind_arrays, kind_template, platform_joints
from ..kernels import ik as _kernels
from ..legs.crank import crank_ik_geometry, crank_leg_set, crank_params
from ..legs.crank_cells import crank_cell_terms
from ..validation import unit_rows, without_component
from ._delta import DeltaFamily
from .rss6 import _angle_window, _rss_leg

__all__ = ["Delta3", "Delta3Spec"]

_WINDOW = (-math.radians(60), math.radians(90))
_ANGLES = tuple(math.radians(a) for a in (90.0, 210.0, 330.0))

# g layout: B 0-8, tool points 9-17, 2a·u 18-26, 2a·v 27-35, a² - b² 36-38, degenerate
# threshold 39-41, branch 42-44, motor axes n 45-53, b·sin(cone) 54-56


@njit(cache=True, forceinline=True)
def _delta_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, i, qmin, qmax):
    v, s = _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[3 * i], g[3 * i + 1], g[3 * i + 2], g[9 + 3 * i], g[10 + 3 * i],
                    g[11 + 3 * i], g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i], g[27 + 3 * i],
                    g[28 + 3 * i], g[29 + 3 * i], g[36 + i], g[39 + i], g[42 + i], qmin, qmax)
    tx, ty, tz = g[9 + 3 * i], g[10 + 3 * i], g[11 + 3 * i]
    wx = px + r00 * tx + r01 * ty + r02 * tz - g[3 * i]
    wy = py + r10 * tx + r11 * ty + r12 * tz - g[3 * i + 1]
    wz = pz + r20 * tx + r21 * ty + r22 * tz - g[3 * i + 2]
    wn = wx * g[45 + 3 * i] + wy * g[46 + 3 * i] + wz * g[47 + 3 * i]
    cone = abs(wn) > g[54 + i]
    return v, (_kernels.JOINT_LIMIT if s == _kernels.OK and cone else s)


@register_jitable(inline="always")
def _delta3_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
                j):
    """Per-pose inverse kinematics (:mod:`.._kernels`), legs unrolled by hand."""
    v, s = _delta_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 0, qmin, qmax)
    q[j], st[j] = v, s
    v, s = _delta_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 1, qmin, qmax)
    q[_kernels.ROW + j], st[_kernels.ROW + j] = v, s
    v, s = _delta_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, 2, qmin, qmax)
    q[2 * _kernels.ROW + j], st[2 * _kernels.ROW + j] = v, s


@register_jitable
def delta_column_leg(x, y, wx, wy, wz, p, zlo, zhi, out_lo, out_hi):
    """Set leg (:mod:`._delta`) of a rotary delta leg: the crank leg's exact z set on the
    column, clipped to the forearm cone slab ``|X n_x + Y n_y + t n_z| <= c`` (``t = z + w_z``,
    ``p[15:18] = n``, ``p[18] = c``); ``p[:15]`` the crank row of :func:`.._crank.crank_params`."""
    X = x + wx
    Y = y + wy
    s = X * p[15] + Y * p[16]
    c = p[18]
    nz = p[17]
    if abs(nz) < 1e-12:
        if abs(s) > c:
            return 0
    else:
        a = (-c - s) / nz - wz
        b = (c - s) / nz - wz
        zlo = max(zlo, min(a, b))
        zhi = min(zhi, max(a, b))
        if not zlo < zhi:
            return 0
    return crank_leg_set(X, Y, wz, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9],
                         p[10], p[11], p[12], p[13], p[14], zlo, zhi, out_lo, out_hi)


@register_jitable
def delta_margin(x, y, z, P):
    """The smallest signed leg margin at ``(x, y, z)`` (:meth:`Delta3.leg_margins`, the numba
    form of :func:`.._crank_cells.crank_cell_terms`' margin and the cone slab): ``P`` rows
    ``w = R·t - B`` (3), ``u``, ``v``, ``n`` (3 each), ``a``, ``s``, ``b``, ``α_min``,
    ``α_max``, 1 for a full window, the slab half-width, and the cosines and sines of
    ``α_min`` and ``α_max``."""
    out = np.inf
    for i in range(P.shape[0]):
        wx, wy, wz = x + P[i, 0], y + P[i, 1], z + P[i, 2]
        X = wx * P[i, 3] + wy * P[i, 4] + wz * P[i, 5]
        Y = wx * P[i, 6] + wy * P[i, 7] + wz * P[i, 8]
        Z = wx * P[i, 9] + wy * P[i, 10] + wz * P[i, 11]
        a, s, b, lo, hi = P[i, 12], P[i, 13], P[i, 14], P[i, 15], P[i, 16]
        r = math.hypot(X, Y)
        m1 = s - math.hypot(Z, r - a)
        m2 = math.hypot(Z, r + a) - s
        E = 2.0 * a * X
        F = 2.0 * a * Y
        G = wx * wx + wy * wy + wz * wz + a * a - s * s
        h2 = E * E + F * F - G * G
        real = m1 >= 0.0 and m2 >= 0.0 and h2 >= 0.0
        D = min(m1, m2)
        feasible = real
        if P[i, 17] < 0.5:
            for k in range(2):
                ce = P[i, 19 + 2 * k]
                se = P[i, 20 + 2 * k]
                cx = a * (ce * P[i, 3] + se * P[i, 6])
                cy = a * (ce * P[i, 4] + se * P[i, 7])
                cz = a * (ce * P[i, 5] + se * P[i, 8])
                sph = abs(math.sqrt((wx - cx) ** 2 + (wy - cy) ** 2 + (wz - cz) ** 2) - s)
                side = -b * (X * se - Y * ce)
                D = min(D, max(sph, side))
            if real:
                h = math.sqrt(h2)
                th = math.atan2(F * G + b * E * h, E * G - b * F * h)
                feasible = lo <= th <= hi
        D = D if real else -min(m1, m2)
        mu = D if feasible else -D
        out = min(out, min(mu, P[i, 18] - abs(Z)))
    return out


class Delta3Generator(_Model):
    base_radius: PositiveLength = Field(description="motor pivot circle radius R (mm)")
    platform_radius: PositiveLength = Field(description="platform joint circle radius r (mm)")
    angles: list[float] = Field(default_factory=lambda: [90.0, 210.0, 330.0],
                                description="the three legs' directions about z (deg)")


class Delta3Spec(FamilySpec):
    """Rotary (Clavel) delta: ``stroke`` is the motor-angle window (deg; 0 = arm horizontal,
    positive down)."""

    family: Literal["delta3"]
    generator: Delta3Generator
    stroke: AngleWindow = Field(description="motor-angle window [min, max] (deg or with units)")
    upper_arm: PositiveLength
    forearm: PositiveLength
    cone_limit: Angle = Field(math.pi / 2, description="forearm ball-joint cone half-angle "
                              "(deg): the forearm's angle out of the arm's plane")

    def build(self):
        if self.base_points is not None or self.platform_points is not None:
            raise ParameterError("base_points", "absent: delta3 takes its joints from the "
                                 "generator", "given")
        g = self.generator
        return Delta3.from_radii(base_radius=g.base_radius, platform_radius=g.platform_radius,
                                 upper_arm=self.upper_arm, forearm=self.forearm,
                                 stroke=self.stroke, cone_limit=self.cone_limit,
                                 angles=np.radians(g.angles), tool_offset=self.tool_offset,
                                 **self.explicit_kw())


def _unit3(value, field):
    arr = np.asarray(value, dtype=float)
    if arr.shape != (3, 3) or not np.all(np.isfinite(arr)) \
            or np.any(np.linalg.norm(arr, axis=1) < 1e-9):
        raise ParameterError(field, "three non-zero directions, shape (3, 3)", arr.tolist())
    return unit_rows(arr)


@dataclass(frozen=True, eq=False)
class Delta3(DeltaFamily):
    """Rotary delta geometry (module notes).

    Attributes:
        base_points: ``(3, 3)`` motor pivots B_i (mm, base frame).
        platform_points: ``(3, 3)`` forearm joints in the platform frame (mm; one point per
            parallelogram, its centre).
        servo_axes: ``(3, 3)`` motor axes n_i. zero_directions: ``(3, 3)`` arm directions at
            angle 0 (made ⟂ n_i).
        crank_length, rod_length: ``(3,)`` upper arms a_i and forearms b_i (mm).
        stroke_window: motor-angle window (rad, within [-π, π]).
        cone_limit: forearm ball-joint cone half-angle (rad, in (0, π/2]).
        branch: ``(3,)`` ±1 (-1: elbow outward).
        tool_offset: ``(3,)`` tool point in the platform frame (mm).
    """

    family = "delta3"
    spec_model = Delta3Spec
    actuator_names = ("theta1", "theta2", "theta3")
    actuator_unit = "rad"

    base_points: np.ndarray
    platform_points: np.ndarray
    servo_axes: np.ndarray
    zero_directions: np.ndarray
    crank_length: np.ndarray
    rod_length: np.ndarray
    stroke_window: tuple
    cone_limit: float = math.pi / 2
    branch: np.ndarray = (-1.0, -1.0, -1.0)
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)

    _ik_one = _delta3_one
    column_set_leg = delta_column_leg
    #: named study variables (paths in the YAML model)
    design_aliases: ClassVar[dict] = {
        "base_radius": ("generator.base_radius", "length"),
        "platform_radius": ("generator.platform_radius", "length"),
        "upper_arm": ("upper_arm", "length"), "forearm": ("forearm", "length"),
        "motor_min": ("stroke[0]", "angle"), "motor_max": ("stroke[1]", "angle"),
        "cone_limit": ("cone_limit", "angle")}

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 3))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 3))
        n = _unit3(self.servo_axes, "servo_axes")
        u = without_component(_unit3(self.zero_directions, "zero_directions"), n)
        if np.any(np.linalg.norm(u, axis=1) < 1e-6):
            raise ParameterError("zero_directions", "directions not parallel to the motor "
                                 "axes", self.zero_directions)
        set_(self, "servo_axes", n)
        set_(self, "zero_directions", unit_rows(u))
        set_(self, "crank_length", as_positive(self.crank_length, "crank_length", (3,)))
        set_(self, "rod_length", as_positive(self.rod_length, "rod_length", (3,)))
        set_(self, "stroke_window", _angle_window(self.stroke_window))
        cone = float(self.cone_limit)
        if not 0.0 < cone <= math.pi / 2:
            raise ParameterError("cone_limit", "a half-angle in (0, 90] deg", math.degrees(cone))
        set_(self, "cone_limit", cone)
        br = np.broadcast_to(np.asarray(self.branch, dtype=float), (3,)).copy()
        if not np.all(np.isin(br, (-1.0, 1.0))):
            raise ParameterError("branch", "-1 or +1, or three of them", self.branch)
        set_(self, "branch", br)
        set_(self, "tool_offset", as_vector3(self.tool_offset, "tool_offset"))
        for arr in (self.servo_axes, self.zero_directions, self.crank_length, self.rod_length,
                    self.branch):
            arr.setflags(write=False)

    @classmethod
    def from_radii(cls, *, base_radius=200.0, platform_radius=50.0, upper_arm=350.0,
                   forearm=800.0, stroke=_WINDOW, cone_limit=math.pi / 2, angles=_ANGLES,
                   tool_offset=(0.0, 0.0, 0.0), name: str = "", nominal=None) -> Delta3:
        """Pivots on the circle of radius ``base_radius`` at z = 0, platform joints on the
        circle of radius ``platform_radius``, both at ``angles`` (rad); motor axes tangent,
        arms radial at angle 0 (module notes). Lengths mm, angles rad; defaults are a
        generic mid-size pick-and-place delta, not a specific machine."""
        a = np.asarray(angles, dtype=float)
        u = np.stack([np.cos(a), np.sin(a), np.zeros(3)], axis=1)
        n = np.cross([0.0, 0.0, 1.0], u)
        desc = {"generator": "delta circles", "base_radius_mm": float(base_radius),
                "platform_radius_mm": float(platform_radius),
                "angles_deg": np.degrees(a).tolist()}
        return cls(base_radius * u, platform_radius * u, n, u, np.full(3, float(upper_arm)),
                   np.full(3, float(forearm)), stroke, cone_limit, (-1.0, -1.0, -1.0),
                   tool_offset, name=name, nominal=nominal, description=desc)

    # ---- family hooks ----------------------------------------------------------------------
    @property
    def v_directions(self) -> np.ndarray:
        return np.cross(self.servo_axes, self.zero_directions)

    @property
    def scale(self) -> float:
        return float(np.max(np.linalg.norm(self.base_points, axis=1))
                     + np.max(np.linalg.norm(self.platform_points, axis=1))
                     + np.max(self.crank_length) + np.max(self.rod_length))

    def _gparams(self) -> np.ndarray:
        return np.concatenate([crank_ik_geometry(self), self.servo_axes.ravel(),
                               self.rod_length * math.sin(self.cone_limit)])

    def driven_points(self, q):
        q = np.asarray(q, dtype=float)[..., None]
        return self.base_points + self.crank_length[:, None] * (
            np.cos(q) * self.zero_directions + np.sin(q) * self.v_directions)

    crank_ends = driven_points

    def driven_velocity(self, q):
        q = np.asarray(q, dtype=float)[..., None]
        return self.crank_length[:, None] * (-np.sin(q) * self.zero_directions
                                             + np.cos(q) * self.v_directions)

    def _q_domain(self, q):
        return np.all(np.isfinite(q) & (q > -math.pi) & (q <= math.pi), axis=1)

    def describe(self) -> dict:
        d = super().describe()
        d.pop("stroke_mm", None)
        d.update(motor_window_deg=np.degrees(self.stroke).tolist(),
                 upper_arm_mm=self.crank_length.tolist(), forearm_mm=self.rod_length.tolist(),
                 cone_limit_deg=math.degrees(self.cone_limit))
        return d

    # ---- workspace -------------------------------------------------------------------------
    def column_params(self) -> np.ndarray:
        """``(3, 19)``: the crank rows (:func:`.._crank.crank_params`), the motor axis and the
        cone slab's half-width ``b·sin(cone_limit)``."""
        crank = crank_params(self.zero_directions, self.v_directions, self.crank_length,
                             self.rod_length, self.branch, self.stroke)
        return np.ascontiguousarray(np.column_stack([
            crank, self.servo_axes, self.rod_length * math.sin(self.cone_limit)]))

    def position_bounds(self, R):
        """Each platform joint within ``a_i + b_i`` of its pivot: ``(M, 2, 3)``."""
        W = self.leg_offsets(R)
        reach = (self.crank_length + self.rod_length)[:, None]
        return np.stack([(-W - reach).max(axis=1), (-W + reach).min(axis=1)], axis=1)

    def leg_margins(self, p):
        """Signed margins of the arms (:mod:`pkmlab.workspaces.bracket_octree`), ``(N, 3)``:
        the crank leg's (:func:`.._crank_cells.crank_cell_terms`) and the cone slab's."""
        p = np.asarray(p, dtype=float).reshape(-1, 3)
        R = np.broadcast_to(self._rotation, (len(p), 3, 3))
        _, _, mu, _ = crank_cell_terms(p, R, 0.0, 0.0, self.base_points, self.tool_points,
                                       self.zero_directions, self.v_directions,
                                       self.servo_axes, self.crank_length, self.rod_length,
                                       self.branch, self.stroke, 0.0)
        W = p[:, None, :] + self.tool_points @ self._rotation.T - self.base_points
        slab = self.rod_length * math.sin(self.cone_limit) \
            - np.abs(np.sum(W * self.servo_axes, axis=-1))
        return np.minimum(mu, slab)

    cube_margin = delta_margin

    def margin_params(self) -> np.ndarray:
        """``(3, 23)`` rows of :func:`delta_margin`."""
        lo, hi = self.stroke
        w = self.tool_points @ self._rotation.T - self.base_points
        full = float(hi - lo >= 2 * math.pi * (1 - 1e-15))
        return np.ascontiguousarray(np.column_stack([
            w, self.zero_directions, self.v_directions, self.servo_axes, self.crank_length,
            self.rod_length, self.branch, np.full(3, lo), np.full(3, hi), np.full(3, full),
            self.rod_length * math.sin(self.cone_limit),
            np.full(3, math.cos(lo)), np.full(3, math.sin(lo)), np.full(3, math.cos(hi)),
            np.full(3, math.sin(hi))]))

    # ---- joints: R (motor, actuated), S at the elbow, the forearm, S at the platform ---------
    parameter_fields = (
        ParamField("base_points", "base", "mm", "leg {i}'s motor pivot (base frame)"),
        DEFAULT_FIELDS[1],
        ParamField("servo_axes", "motor_axis", "1", "leg {i}'s motor axis direction"),
        ParamField("zero_directions", "zero_direction", "1",
                   "leg {i}'s upper-arm direction at angle 0 (the actuator zero)"),
        ParamField("crank_length", "upper_arm", "mm", "leg {i}'s upper arm, pivot to elbow"),
        ParamField("rod_length", "forearm", "mm", "leg {i}'s forearm (parallelogram rods), "
                   "ball to ball"),
        DEFAULT_FIELDS[2],
        ParamField("cone_limit", "cone_limit", "rad", "forearm ball-joint cone half-angle"),
        DEFAULT_FIELDS[3])

    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        return kind_arrays(self, "crank", self.driven_points(q), platform_joints(self, p, R),
                           q, R, axes, rail=self.servo_axes)

    def _leg_templates(self):
        return tuple(kind_template("crank", i, n, self.base_points[i], self.platform_points[i],
                                   (self.crank_length[i], self.rod_length[i]),
                                   reference=self.zero_directions[i])
                     for i, n in enumerate(self.actuator_names))
