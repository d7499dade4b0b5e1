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

Workspace: exact column method (``column_method = "crank"``): on a column the feasible z set
of a leg is a union of intervals whose ends are roots of a quartic (the real solution appears)
and of two quadratics (the servo-window edges), see :mod:`._crank`; the set-valued column
drivers of :mod:`._set_columns` intersect / unite them. :meth:`RSS6.position_bounds` bounds the
search box. Interference covers the cranks too (``link_segments``, read from the joints), and
the crank-end ball joints' cones turn with the cranks (``base_joint_axes``, from the joints).
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
from ...quantities import AngleWindow, Branches, Directions, LinkLengths
from ...specbase import PairedCircles, _Common
from ...tolerances import TOL
from ..base import NO_STROKE, Mechanism, as_points, as_positive, as_vector3
from ..joints import DEFAULT_FIELDS, ParamField, kind_arrays, kind_template, platform_joints
from ..kernels import ik as _kernels
from ..kernels.set_columns import set_column_intervals
from ..legs.crank import crank_column_leg, crank_ik_geometry, crank_params
from ..legs.crank_cells import crank_cell_terms, crank_position_curvature
from ..legs.layout import PAIRED_ALIASES, build_paired
from ..validation import unit_rows, without_component
from .psu6 import _radii

__all__ = ["RSS6"]

# atan2 that LLVM can vectorise: fdlibm's atan (s_atan.c, Sun Microsystems 1993; argument
# reduction at 7/16 and 11/16 and an 11-term polynomial, < 1 ulp) on min/max of |x|, |y|, then
# the octant fix-up, all by selects. The reduced argument is formed from |x| and |y| with ONE
# division (fdlibm divides twice: t = min/max, then (2t - 1)/(2 + t) or (t - 1)/(t + 1)). Within
# 4.5e-16 rad of math.atan2 (tests/mechanisms/test_crank_atan2.py), and one division (the
# crank legs' costliest operation after the polynomial) fewer per leg (issue 28).
_ATANHI0, _ATANHI1 = 4.63647609000806093515e-01, 7.85398163397448278999e-01
_ATANLO0, _ATANLO1 = 2.26987774529616870924e-17, 3.06161699786838301793e-17
_AT = (3.33333333333329318027e-01, -1.99999999998764832476e-01, 1.42857142725034663711e-01,
       -1.11111104054623557880e-01, 9.09088713343650656196e-02, -7.69187620504482999495e-02,
       6.66107313738753120669e-02, -5.83357013379057348645e-02, 4.97687799461593236017e-02,
       -3.65315727442169155270e-02, 1.62858201153657823623e-02)
_AT0, _AT1, _AT2, _AT3, _AT4, _AT5, _AT6, _AT7, _AT8, _AT9, _AT10 = _AT
_PIO2_HI, _PIO2_LO = 1.57079632679489655800e+00, 6.12323399573676603587e-17
_PI_HI, _PI_LO = 3.1415926535897931160e+00, 1.2246467991473531772e-16


@njit(cache=True, forceinline=True)
def _atan2(y, x):
    """``atan2(y, x)`` in (-π, π], branch-free (0 for x = y = 0)."""
    ax, ay = abs(x), abs(y)
    mx = ax if ax > ay else ay
    mn = ay if ax > ay else ax
    # t = mn/mx < 7/16, < 11/16 compared without the quotient: 16·mn against 7·mx and 11·mx,
    # exact in the subnormal range, scaled by 1/32 (exact) above 1 so that nothing overflows;
    # mx = 0 and NaN take the first range (t = 0), as fdlibm's t = mn/mx if mx > 0 else 0
    sc = 0.03125 if mx > 1.0 else 1.0
    sn, sx = sc * mn, sc * mx
    c0 = not ((16.0 * sn >= 7.0 * sx) & (mx > 0.0))
    c1 = 16.0 * sn < 11.0 * sx
    # the reduced argument t, (2t - 1)/(2 + t) or (t - 1)/(t + 1) as ONE quotient of mn and mx
    num = mn if c0 else (2.0 * sn - sx if c1 else sn - sx)
    den = mx if c0 else (2.0 * sx + sn if c1 else sn + sx)
    hi = 0.0 if c0 else (_ATANHI0 if c1 else _ATANHI1)
    lo = 0.0 if c0 else (_ATANLO0 if c1 else _ATANLO1)
    xr = num / den if mx > 0.0 else 0.0
    z = xr * xr
    w = z * z
    s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
    s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
    r = hi - ((xr * (s1 + s2) - lo) - xr)            # atan(t) in [0, π/4]
    r = (_PIO2_HI - (r - _PIO2_LO)) if ay > ax else r
    r = (_PI_HI - (r - _PI_LO)) if x < 0.0 else r
    return -r if y < 0.0 else r


# g layout: B 0-17, tool points 18-35, 2a·u 36-53, 2a·v 54-71, a² - s² 72-77, degenerate
# threshold 1e-24·a⁴ on ρ² 78-83, branch 84-89.


@njit(cache=True, forceinline=True)
def _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, bx, by, bz, tx, ty, tz,
             ux, uy, uz, vx, vy, vz, c, eps, b, qmin, qmax):
    """One leg: ``(α, status)``, α NaN where there is no real solution. ``u``, ``v`` come
    scaled by 2a, ``c = a² - s²`` and ``eps`` is the degenerate threshold on ρ²."""
    wx = px + r00 * tx + r01 * ty + r02 * tz - bx
    wy = py + r10 * tx + r11 * ty + r12 * tz - by
    wz = pz + r20 * tx + r21 * ty + r22 * tz - bz
    e = wx * ux + wy * uy + wz * uz
    f = wx * vx + wy * vy + wz * vz
    gg = wx * wx + wy * wy + wz * wz + c
    rho2 = e * e + f * f
    h2 = rho2 - gg * gg
    real = h2 >= 0.0
    h = math.sqrt(h2 if real else 0.0)
    v = _atan2(f * gg + b * e * h, e * gg - b * f * h)
    degenerate = rho2 <= eps
    st = (_kernels.DEGENERATE if degenerate else
          (_kernels.stroke_status(v, qmin, qmax) if real else _kernels.NO_SOLUTION))
    return (v if real and not degenerate else np.nan), st


@register_jitable(inline="always")
def _rss_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    """Per-pose inverse kinematics (see :mod:`._kernels`): the crank angle of each leg, the
    loop over legs unrolled by hand so that ``g`` is indexed by constants."""
    v, c = _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[0], g[1], g[2], g[18], g[19], g[20], g[36], g[37], g[38],
                    g[54], g[55], g[56], g[72], g[78], g[84], qmin, qmax)
    q[j], st[j] = v, c
    v, c = _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[3], g[4], g[5], g[21], g[22], g[23], g[39], g[40], g[41],
                    g[57], g[58], g[59], g[73], g[79], g[85], qmin, qmax)
    q[_kernels.ROW + j], st[_kernels.ROW + j] = v, c
    v, c = _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[6], g[7], g[8], g[24], g[25], g[26], g[42], g[43], g[44],
                    g[60], g[61], g[62], g[74], g[80], g[86], qmin, qmax)
    q[2 * _kernels.ROW + j], st[2 * _kernels.ROW + j] = v, c
    v, c = _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[9], g[10], g[11], g[27], g[28], g[29], g[45], g[46],
                    g[47], g[63], g[64], g[65], g[75], g[81], g[87], qmin, qmax)
    q[3 * _kernels.ROW + j], st[3 * _kernels.ROW + j] = v, c
    v, c = _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[12], g[13], g[14], g[30], g[31], g[32], g[48], g[49],
                    g[50], g[66], g[67], g[68], g[76], g[82], g[88], qmin, qmax)
    q[4 * _kernels.ROW + j], st[4 * _kernels.ROW + j] = v, c
    v, c = _rss_leg(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22,
                    g[15], g[16], g[17], g[33], g[34], g[35], g[51], g[52],
                    g[53], g[69], g[70], g[71], g[77], g[83], g[89], qmin, qmax)
    q[5 * _kernels.ROW + j], st[5 * _kernels.ROW + j] = v, c


@register_jitable(inline="always")
def _rss_jac_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, q, J, k):
    """Per-pose Jacobian (:func:`._kernels.make_jacobian_driver`): row i is
    ``[dᵀ, (r × d)ᵀ] / (d · ∂C/∂α)`` (module docstring), from the angles ``q[k]``; ``g``
    holds 2a·u and 2a·v, so ``C - B = (cos α·2au + sin α·2av)/2``."""
    for i in range(6):
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        rx = r00 * ux + r01 * uy + r02 * uz
        ry = r10 * ux + r11 * uy + r12 * uz
        rz = r20 * ux + r21 * uy + r22 * uz
        c, s = 0.5 * math.cos(q[k, i]), 0.5 * math.sin(q[k, i])
        e0, e1, e2 = g[36 + 3 * i], g[37 + 3 * i], g[38 + 3 * i]
        f0, f1, f2 = g[54 + 3 * i], g[55 + 3 * i], g[56 + 3 * i]
        dx = px + rx - g[3 * i] - (c * e0 + s * f0)
        dy = py + ry - g[3 * i + 1] - (c * e1 + s * f1)
        dz = pz + rz - g[3 * i + 2] - (c * e2 + s * f2)
        den = dx * (c * f0 - s * e0) + dy * (c * f1 - s * e1) + dz * (c * f2 - s * e2)
        J[k, i, 0] = dx / den
        J[k, i, 1] = dy / den
        J[k, i, 2] = dz / den
        J[k, i, 3] = (ry * dz - rz * dy) / den
        J[k, i, 4] = (rz * dx - rx * dz) / den
        J[k, i, 5] = (rx * dy - ry * dx) / den


def _unit_rows(value, field: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (6, 3) or not np.all(np.isfinite(arr)):
        raise ParameterError(field, "an array of shape (6, 3) of directions", arr.shape)
    n = np.linalg.norm(arr, axis=1)
    if np.any(n < TOL.direction_norm):
        raise ParameterError(field, "non-zero directions", arr.tolist())
    out = unit_rows(arr)
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


class ServoCircles(PairedCircles):
    """Generator of the 6-RSS: servo pairs on the paired circles (see ``RSS6.from_circles``)."""

    crank_plane: Literal["radial", "tangential"] = Field(
        "radial", description="'radial': servo axes tangent to the base circle; 'tangential': "
        "servo axes radial")
    zero_direction: Literal["outward", "inward"] = Field(
        "outward", description="crank zero direction (horizontal): radially out/in, or away "
        "from / towards the pair partner")


class RSS6Spec(_Common):
    """6-RSS rotary-servo Stewart platform. ``stroke`` is the servo-angle range (deg)."""

    family: Literal["rss6"]
    generator: ServoCircles | None = None
    stroke: AngleWindow = Field(description="servo-angle range [min, max] (deg or with units)")
    crank_length: LinkLengths
    rod_length: LinkLengths
    servo_axes: Directions | None = None
    zero_directions: Directions | None = None
    branch: Branches = Field(default_factory=lambda: [-1.0] * 6)

    def build(self) -> RSS6:
        if self._explicit("generator"):
            if self.servo_axes is None or self.zero_directions is None:
                raise ParameterError("servo_axes" if self.servo_axes is None
                                     else "zero_directions",
                                     "given with explicit base_points (or use a generator)",
                                     None)
            return RSS6(self.base_points, self.platform_points, self.servo_axes,
                        self.zero_directions, self.crank_length, self.rod_length, self.stroke,
                        self.branch, self.tool_offset, **self._kw())
        if self.servo_axes is not None or self.zero_directions is not None:
            raise ParameterError("servo_axes", "absent with a generator (it sets the axes)",
                                 "given")
        m = RSS6.from_circles(**self.generator.model_dump(), crank_length=self.crank_length,
                              rod_length=self.rod_length, stroke=self.stroke,
                              branch=self.branch, tool_offset=self.tool_offset, **self._kw())
        return m


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
    #: the YAML model (``family: rss6``) and the named study variables (paths in it)
    spec_model: ClassVar[type] = RSS6Spec
    design_aliases: ClassVar[dict] = {
        **{k: v for k, v in PAIRED_ALIASES.items() if not k.startswith("stroke")},
        "crank_length": ("crank_length", "length"),
        "rod_length": ("rod_length", "length"),
        "servo_min": ("stroke[0]", "angle"),
        "servo_max": ("stroke[1]", "angle"),
        "crank_plane": ("generator.crank_plane", "text"),
        "zero_direction": ("generator.zero_direction", "text")}
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
    _jac_one = _rss_jac_one
    _jac_uses_q = True

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 6))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 6))
        n = _unit_rows(self.servo_axes, "servo_axes")
        u = _unit_rows(self.zero_directions, "zero_directions")
        u = without_component(u, n)                               # Gram-Schmidt
        if np.any(np.linalg.norm(u, axis=1) < TOL.perpendicular_rel):
            raise ParameterError("zero_directions", "directions not parallel to the servo axes",
                                 self.zero_directions)
        u = unit_rows(u)
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
        return crank_ik_geometry(self)

    def crank_ends(self, q: np.ndarray) -> np.ndarray:
        """Crank end points C_i ``(N, 6, 3)`` (mm, base frame) for servo angles ``q (N, 6)``."""
        q = np.asarray(q, dtype=float)[..., None]
        return self.base_points + self.crank_length[:, None] * (
            np.cos(q) * self.zero_directions + np.sin(q) * self.v_directions)

    def _legs(self, p, R, q):
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        d = p[:, None, :] + r - self.crank_ends(q)                     # rod vectors C → P
        return r, d

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
    column_method = "crank"
    #: set-valued column leg (:mod:`._set_columns`): the exact crank z set (:mod:`._crank`)
    column_set_leg = crank_column_leg

    def column_params(self) -> np.ndarray:
        """``(6, 11)`` rows of :func:`._crank.crank_column_leg`."""
        return crank_params(self.zero_directions, self.v_directions, self.crank_length,
                            self.rod_length, self.branch, self.stroke)

    def column_intervals(self, xs, ys, R, mode, allowed=None, K=8):
        """Exact feasible z sets of the columns (see :mod:`._crank`), same contract as
        :meth:`.base.Mechanism.column_intervals`; each leg's set may have several pieces, so
        the dexterous (``"all"``) sets have up to ``K`` pieces too."""
        return set_column_intervals(crank_column_leg, self.leg_offsets(R),
                                    self.column_params(), xs, ys, R, mode, allowed, K)

    def position_bounds(self, R):
        """Each platform joint within ``a_i + s_i`` of its pivot: ``(M, 2, 3)``."""
        W = self.leg_offsets(R)
        reach = (self.crank_length + self.rod_length)[:, None]
        return np.stack([(-W - reach).max(axis=1), (-W + reach).min(axis=1)], axis=1)

    # ---- cell volume bracket (pkmlab.workspaces.bracket.cells) -----------------------------
    cell_bounds = True

    def _cell_terms(self, p, R, delta, alpha):
        return crank_cell_terms(p, R, delta, alpha, self.base_points, self.tool_points,
                                self.zero_directions, self.v_directions, self.servo_axes,
                                self.crank_length, self.rod_length, self.branch, self.stroke,
                                1e-9 + 1e-12 * self.scale)

    @staticmethod
    def _in_mode(n):
        """The working-mode flags of the cell protocol: +1 for every leg (the inverse
        kinematics takes each leg's declared branch, so no pose is outside the mode)."""
        return np.ones((n, 6), np.int8)

    def leg_cell_bounds(self, p, R, delta, alpha, mode: bool = False):
        """Crank angles at ``(p, R)`` (NaN where the rod does not close) and a bound on their
        change over the cell ``|p' - p| <= δ``, ``angle(R'Rᵀ) <= α``: ``2s·εP/h_min`` where
        the rod closes on the whole cell, ``inf`` elsewhere (:mod:`._crank_cells`). With
        ``mode``, also the working-mode flags (+1: each leg keeps its declared branch)."""
        theta, et, _, _ = self._cell_terms(p, R, delta, alpha)
        return (theta, et, self._in_mode(len(theta))) if mode else (theta, et)

    def leg_cell_margins(self, p, R, delta, alpha, mode: bool = False):
        """``(θ, μ, ε[, mode])``, ``(N, 6)``: per leg a margin that proves it feasible
        on the whole cell where ``μ > ε`` and infeasible where ``μ < -ε`` (a signed lower
        bound of the distance to the other status, from the rod's closing limits and the
        spheres about the crank ends at the window edges; :mod:`._crank_cells`)."""
        theta, _, m, e = self._cell_terms(p, R, delta, alpha)
        return (theta, m, e, self._in_mode(len(theta))) if mode else (theta, m, e)

    #: off: the second-order fractions of :mod:`pkmlab.workspaces.bracket.partial` with the
    #: bound below narrow the bracket per cube size but cost more time than they save (the
    #: servo platform's boundary is mostly the rod's closing limit, where ``M`` is infinite;
    #: docs/validation.md, "Guaranteed volume bracket for rss6")
    position_curvature = False

    def leg_position_curvature(self, p, R, delta):
        """Gradient ``g (N, 6, 3)`` of each crank angle in the position and a bound ``M (N, 6)``
        on its second derivative over the ball ``|p' - p| <= δ`` (rotation fixed), ``inf``
        where the rod may fail to close on the ball or the angle may wrap
        (:func:`._crank_cells.crank_position_curvature`), in the form
        :mod:`pkmlab.workspaces.bracket.partial` takes (not enabled: see
        ``position_curvature``)."""
        return crank_position_curvature(p, R, delta, self.base_points, self.tool_points,
                                        self.zero_directions, self.v_directions,
                                        self.servo_axes, self.crank_length, self.rod_length,
                                        self.branch, 1e-9 + 1e-12 * self.scale)

    # ---- joints (:mod:`.joints`): R (servo, actuated), S at the crank end, rod, S --------
    parameter_fields = (
        ParamField("base_points", "base", "mm", "leg {i}'s crank pivot on its servo axis "
                   "(base frame)"),
        DEFAULT_FIELDS[1],
        ParamField("servo_axes", "servo_axis", "1", "leg {i}'s servo axis direction"),
        ParamField("zero_directions", "zero_direction", "1",
                   "leg {i}'s crank direction at angle 0 (the actuator zero)"),
        ParamField("crank_length", "crank_length", "mm", "leg {i}'s crank length"),
        ParamField("rod_length", "rod_length", "mm", "leg {i}'s rod length"),
        *DEFAULT_FIELDS[2:])

    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        return kind_arrays(self, "crank", self.crank_ends(q), platform_joints(self, p, R), q,
                           R, axes, rail=self.servo_axes)

    def _leg_templates(self):
        return tuple(kind_template("crank", i, n, self.base_points[i], self.platform_points[i],
                                   (self.crank_length[i], self.rod_length[i]),
                                   reference=self.zero_directions[i])
                     for i, n in enumerate(self.actuator_names))
