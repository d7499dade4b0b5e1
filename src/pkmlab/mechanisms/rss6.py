"""6-RSS rotary-servo Stewart platform: six cranks (servo horns) and six fixed-length rods.

Leg i: a crank of length ``a_i`` turns about the servo axis ``n_i`` through the base joint
``B_i``; its end is ``C_i = B_i + a_i (cos α_i u_i + sin α_i v_i)``, where ``u_i`` is the crank's
zero direction (perpendicular to ``n_i``), ``v_i = n_i × u_i`` and the actuator value ``α_i``
(**rad**) is measured from ``u_i``, positive by the right-hand rule about ``n_i``. A rod of
length ``s_i`` joins ``C_i`` (ball joint) to the platform joint ``P_i`` (ball joint).

Inverse kinematics (closed form, per leg). With ``W = p + R·(P_i - O) - B_i`` (``O`` the tool
offset), ``|W - C|² = s²`` reads ``E cos α + F sin α = G`` with ``E = 2a W·u``,
``F = 2a W·v``, ``G = |W|² + a² - s²``. Writing ``ρ² = E² + F²`` and ``h = sqrt(ρ² - G²)``:

    cos α ∝ E·G - b·F·h,   sin α ∝ F·G + b·E·h,   α = atan2(F·G + b·E·h, E·G - b·F·h)

i.e. ``α = atan2(F, E) + b·acos(G/ρ)`` wrapped to (-π, π], with one atan2 and no division.
``b_i = ±1`` is leg i's **branch** (declared per leg): ``b = -1`` puts the crank end on the
clockwise side, in the (u, v) plane, of the direction from the axis to the platform joint. For
the generator (v = +z, platform above) that is the crank end *away from the platform*, the
branch of the usual servo hexapod with horns near horizontal. ``ρ² < G²`` has no real
solution (``NO_SOLUTION``, NaN), ``ρ ≈ 0`` (platform joint on the servo axis) is
``DEGENERATE``; an angle outside the servo range ``stroke`` is ``BELOW/ABOVE_STROKE``.

Velocity Jacobian: differentiating ``|d|² = s²`` with ``d = W - C(α)`` and
``Ẇ = v + ω × r`` (``r = R·(P_i - O)``) gives ``d·(v + ω × r) = (d·∂C/∂α) α̇``, so

    J_i = [dᵀ, (r × d)ᵀ] / (d · ∂C/∂α),   ∂C/∂α = a(-sin α u + cos α v)

singular (serial singularity) when the rod is perpendicular to the crank's velocity.

With actuator values in rad, ``Jᵀ τ = w`` relates servo torques ``τ`` (N·mm) and the tool
wrench ``w = [f (N); m (N·mm)]``: ``τ = J⁻ᵀ w`` (see :meth:`RSS6.servo_torques`).

Workspace: the feasible z set of a column is a union of intervals (the crank equation is not
monotone in z), so this family has no exact column hooks and the workspace engine samples
voxels; :meth:`RSS6.position_bounds` bounds the sampled box.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba.extending import register_jitable

from ..errors import ParameterError
from . import _kernels
from .base import NO_STROKE, Mechanism, as_points, as_positive, as_vector3
from .layout import build_paired

__all__ = ["RSS6"]

# g layout: B 0-17, tool points 18-35, u 36-53, v 54-71, crank 72-77, rod 78-83, branch 84-89.


@register_jitable(inline="always")
def _rss_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    """Per-pose inverse kinematics (see :mod:`._kernels`): the crank angle of each leg."""
    for i in range(6):
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        wx = px + r00 * ux + r01 * uy + r02 * uz - g[3 * i]
        wy = py + r10 * ux + r11 * uy + r12 * uz - g[3 * i + 1]
        wz = pz + r20 * ux + r21 * uy + r22 * uz - g[3 * i + 2]
        a, s, b = g[72 + i], g[78 + i], g[84 + i]
        e = 2.0 * a * (wx * g[36 + 3 * i] + wy * g[37 + 3 * i] + wz * g[38 + 3 * i])
        f = 2.0 * a * (wx * g[54 + 3 * i] + wy * g[55 + 3 * i] + wz * g[56 + 3 * i])
        gg = wx * wx + wy * wy + wz * wz + a * a - s * s
        rho2 = e * e + f * f
        h2 = rho2 - gg * gg
        real = h2 >= 0.0
        h = math.sqrt(h2 if real else 0.0)
        v = math.atan2(f * gg + b * e * h, e * gg - b * f * h)
        degenerate = rho2 <= 1e-24 * (a * a) * (a * a)
        k = i * _kernels.ROW + j
        q[k] = v if real and not degenerate else np.nan
        st[k] = (_kernels.DEGENERATE if degenerate else
                 (_kernels.stroke_status(v, qmin, qmax) if real else _kernels.NO_SOLUTION))


def _unit_rows(value, field: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (6, 3) or not np.all(np.isfinite(arr)):
        raise ParameterError(field, "an array of shape (6, 3) of directions", arr.shape)
    n = np.linalg.norm(arr, axis=1)
    if np.any(n < 1e-9):
        raise ParameterError(field, "non-zero directions", arr.tolist())
    out = arr / n[:, None]
    out.setflags(write=False)
    return out


def _angle_window(value) -> tuple[float, float]:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (2,) or not np.all(np.isfinite(arr)):
        raise ParameterError("stroke", "[min, max], two finite servo angles in rad", value)
    if not (-math.pi <= arr[0] < arr[1] <= math.pi):
        raise ParameterError("stroke", "[min, max] servo angles with -180 deg <= min < max "
                             "<= 180 deg", np.degrees(arr).tolist())
    return float(arr[0]), float(arr[1])


@dataclass(frozen=True, eq=False)
class RSS6(Mechanism):
    """6-RSS geometry (rotary servo Stewart platform).

    Attributes:
        base_points: ``(6, 3)`` crank pivots B_i, on the servo axes (mm, base frame).
        platform_points: ``(6, 3)`` rod ball joints in the platform frame (mm).
        servo_axes: ``(6, 3)`` servo axis directions n_i (normalised).
        zero_directions: ``(6, 3)`` crank zero directions u_i (made perpendicular to n_i).
        crank_length: ``(6,)`` crank (horn) lengths a_i (mm).
        rod_length: ``(6,)`` rod lengths s_i (mm).
        stroke_window: servo-angle range (min, max) in **rad**, within [-π, π].
        branch: ``(6,)`` ±1 per leg (see the module docstring); default -1.
        tool_offset: ``(3,)`` tool-frame origin in the platform frame (mm).
    """

    family = "rss6"
    actuator_names = ("theta1", "theta2", "theta3", "theta4", "theta5", "theta6")
    actuator_unit = "rad"

    base_points: np.ndarray
    platform_points: np.ndarray
    servo_axes: np.ndarray
    zero_directions: np.ndarray
    crank_length: np.ndarray
    rod_length: np.ndarray
    stroke_window: tuple[float, float]
    branch: np.ndarray = (-1.0,) * 6  # type: ignore[assignment]
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]

    _ik_one = _rss_one

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 6))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 6))
        n = _unit_rows(self.servo_axes, "servo_axes")
        u = _unit_rows(self.zero_directions, "zero_directions")
        u = u - np.sum(u * n, axis=1, keepdims=True) * n          # Gram-Schmidt
        if np.any(np.linalg.norm(u, axis=1) < 1e-6):
            raise ParameterError("zero_directions", "directions not parallel to the servo axes",
                                 self.zero_directions)
        u = u / np.linalg.norm(u, axis=1, keepdims=True)
        for arr in (n, u):
            arr.setflags(write=False)
        set_(self, "servo_axes", n)
        set_(self, "zero_directions", u)
        set_(self, "crank_length", as_positive(self.crank_length, "crank_length", (6,)))
        set_(self, "rod_length", as_positive(self.rod_length, "rod_length", (6,)))
        set_(self, "stroke_window", _angle_window(self.stroke_window))
        br = np.asarray(self.branch, dtype=float)
        if br.shape == ():
            br = np.full(6, float(br))
        if br.shape != (6,) or not np.all(np.isin(br, (-1.0, 1.0))):
            raise ParameterError("branch", "-1 or +1, or six of them", self.branch)
        set_(self, "branch", br)
        set_(self, "tool_offset", as_vector3(self.tool_offset, "tool_offset"))
        for arr in (self.crank_length, self.rod_length, self.branch):
            arr.setflags(write=False)

    # ---- generator ---------------------------------------------------------------------------
    @classmethod
    def from_circles(cls, *, base_radii=(100.0, 100.0), platform_radii=(75.0, 75.0),
                     base_pair_angle: float | None = None,
                     platform_rotation: float = math.radians(30.0),
                     base_pair_separation: float = math.radians(30.0),
                     platform_pair_separation: float = math.radians(20.0),
                     pairing: str = "same", crank_length=25.0, rod_length=150.0,
                     stroke=(-1.3962634015954636, 1.3962634015954636),
                     crank_plane: str = "radial", zero_direction: str = "outward",
                     branch=-1.0, tool_offset=(0.0, 0.0, 0.0), name: str = "",
                     nominal=None) -> RSS6:
        """Three servo pairs on circles (joint centres from :func:`.layout.build_paired`).

        ``crank_plane="radial"``: servo axes tangent to the base circle, the crank turns in the
        vertical plane through the base centre, zero direction horizontal and radial
        (``zero_direction`` "outward" or "inward"). ``"tangential"``: servo axes radial (the
        common hobby layout), zero direction horizontal and tangent, pointing away from
        ("outward") or towards ("inward") the pair partner. In both, the axis is
        ``n = u × ẑ``, so that ``v = n × u = +ẑ``: a positive angle raises the crank end.
        Lengths in mm, angles in rad (default servo range ±80°); defaults are hobby-scale, not
        a specific machine.
        """
        from .psu6 import _radii

        if crank_plane not in ("radial", "tangential"):
            raise ParameterError("crank_plane", "one of ['radial', 'tangential']", crank_plane)
        if zero_direction not in ("outward", "inward"):
            raise ParameterError("zero_direction", "one of ['outward', 'inward']",
                                 zero_direction)
        B, P, desc = build_paired(_radii(base_radii, "base_radii"),
                                  _radii(platform_radii, "platform_radii"), base_pair_angle,
                                  platform_rotation, base_pair_separation,
                                  platform_pair_separation, pairing)
        ang = np.arctan2(B[:, 1], B[:, 0])
        radial = np.stack([np.cos(ang), np.sin(ang), np.zeros(6)], axis=1)
        tangent = np.stack([-np.sin(ang), np.cos(ang), np.zeros(6)], axis=1)
        sign = 1.0 if zero_direction == "outward" else -1.0
        if crank_plane == "radial":
            u = sign * radial
        else:       # leg 2k sits clockwise of its partner 2k+1: away is -tangent for it
            u = sign * tangent * np.tile([-1.0, 1.0], 3)[:, None]
        n = np.cross(u, [0.0, 0.0, 1.0])
        desc.update(generator="paired servo circles", crank_plane=crank_plane,
                    zero_direction=zero_direction)
        return cls(B, P, n, u, crank_length, rod_length, stroke, branch, tool_offset,
                   name=name, nominal=nominal, description=desc)

    # ---- family hooks ----------------------------------------------------------------------
    @property
    def v_directions(self) -> np.ndarray:
        """``(6, 3)`` ``v_i = n_i × u_i``: the crank direction at α = 90°."""
        return np.cross(self.servo_axes, self.zero_directions)

    @property
    def scale(self) -> float:
        return float(np.max(np.linalg.norm(self.base_points, axis=1))
                     + np.max(np.linalg.norm(self.platform_points, axis=1))
                     + np.max(self.crank_length) + np.max(self.rod_length))

    def _gparams(self) -> np.ndarray:
        return np.concatenate([self.base_points.ravel(), self.tool_points.ravel(),
                               self.zero_directions.ravel(), self.v_directions.ravel(),
                               self.crank_length, self.rod_length, self.branch])

    def crank_ends(self, q: np.ndarray) -> np.ndarray:
        """Crank end points C_i ``(N, 6, 3)`` (mm, base frame) for servo angles ``q (N, 6)``."""
        q = np.asarray(q, dtype=float)[..., None]
        return self.base_points + self.crank_length[:, None] * (
            np.cos(q) * self.zero_directions + np.sin(q) * self.v_directions)

    def _legs(self, p, R, q):
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        d = p[:, None, :] + r - self.crank_ends(q)                     # rod vectors C → P
        return r, d

    def _jacobian(self, p, R):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        r, d = self._legs(p, R, q)
        qq = q[..., None]
        dC = self.crank_length[:, None] * (-np.sin(qq) * self.zero_directions
                                           + np.cos(qq) * self.v_directions)
        den = np.sum(d * dC, axis=-1, keepdims=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.concatenate([d, np.cross(r, d)], axis=-1) / den

    def _closure(self, p, R, q):
        r, d = self._legs(p, R, np.broadcast_to(q, (len(p), 6)))
        norm = np.linalg.norm(d, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            n = d / norm[..., None]
        return norm - self.rod_length, np.concatenate([n, np.cross(r, n)], axis=-1)

    def servo_torques(self, poses, wrench) -> np.ndarray:
        """Servo torques ``(N, 6)`` in N·mm statically equivalent to the tool wrench
        ``w = [f (N), m (N·mm)]`` (base frame, about the tool origin): ``τ = J⁻ᵀ w``, so that
        ``τ·q̇ = w·[v; ω]`` (virtual work). To hold an external load L, the servos exert
        ``τ(-L)``. NaN at a singular pose."""
        J = self.jacobian(poses)
        w = np.broadcast_to(np.asarray(wrench, dtype=float), (len(J), 6))
        out = np.full((len(J), 6), np.nan)
        ok = np.all(np.isfinite(J), axis=(1, 2))
        ok[ok] = np.abs(np.linalg.det(J[ok])) > 0
        if np.any(ok):
            out[ok] = np.linalg.solve(np.transpose(J[ok], (0, 2, 1)), w[ok][..., None])[..., 0]
        return out

    def describe(self) -> dict:
        d = super().describe()
        d.pop("stroke_mm", None)
        d.update(servo_range_deg=np.degrees(self.stroke).tolist(),
                 crank_length_mm=self.crank_length.tolist(),
                 rod_length_mm=self.rod_length.tolist(),
                 servo_axes=self.servo_axes.tolist(),
                 zero_directions=self.zero_directions.tolist(), branch=self.branch.tolist())
        return d

    # ---- workspace hooks -------------------------------------------------------------------
    def position_bounds(self, R):
        """Each platform joint within ``a_i + s_i`` of its pivot: ``(M, 2, 3)``."""
        W = self.leg_offsets(R)
        reach = (self.crank_length + self.rod_length)[:, None]
        return np.stack([(-W - reach).max(axis=1), (-W + reach).min(axis=1)], axis=1)

    def leg_segments(self, p, R):
        """Rod end points ``(N, 6, 3)`` each: crank-end ball joint → platform ball joint."""
        W = p[:, None, :] + np.einsum("nij,kj->nki", R, self.tool_points)
        q = self.inverse((p, R), stroke=NO_STROKE).q
        return self.crank_ends(q), W
