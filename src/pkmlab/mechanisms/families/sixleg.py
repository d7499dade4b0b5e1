"""Generic six-leg family (``sixleg``): each leg declared by its base joint, its actuator and
its platform joint.

Leg i joins the base-side point ``B_i`` to the platform joint ``W_i = p + R·(P_i - O)`` (``O``
the tool offset); ``d_i = W_i - B_i``. The actuator is one of three kinds:

* **prismatic** (UPS): ``q = |d|``, the leg length. Working mode as in ``ups6``: the platform
  joint stays on the side of ``B_i``'s height it has at the nominal pose (``OTHER_MODE``).
* **slider** (PSU/PUS): a slider at ``S = B + q·e`` on a rail of unit axis ``e`` (any
  direction) and a link of length ``l``. ``|d - q e| = l`` is a quadratic in ``q``:

      q = d·e + b·h,   h = sqrt(l² - |d - (d·e) e|²)

  ``b = ±1`` is the leg's **branch**: ``b = -1`` puts the platform joint ahead of the slider
  along ``e`` (``(W - S)·e = h ≥ 0``; vertical rails with the platform above, as ``psu6``).
  ``h² < 0`` has no real solution. Working mode: the link's vertical component keeps the
  sign it has at the nominal pose (``OTHER_MODE`` otherwise; fixed on vertical rails).
  Jacobian row, from ``a = W - S = d⊥ - b h e``: ``J = [aᵀ, (r × a)ᵀ] / (a·e)`` (serial
  singularity when the link is perpendicular to the rail).
* **crank** (RSS/RUS): crank of length ``a`` about the axis ``n`` through ``B``, zero direction
  ``u`` (made perpendicular to ``n``), ``v = n × u``; angle ``α`` (rad) from ``u``, positive by
  the right-hand rule about ``n``; a rod of length ``s`` to the platform joint. As ``rss6``:
  ``E cos α + F sin α = G`` with ``E = 2a d·u``, ``F = 2a d·v``, ``G = |d|² + a² - s²``,
  ``α = atan2(F G + b E h, E G - b F h)``, ``h = sqrt(E² + F² - G²)``, branch ``b = ±1``.

All legs share one actuator window (``stroke``), in mm when every leg is prismatic or a slider
(the two may be mixed: a slider's ``B`` is where its actuator reads 0) and in rad when every leg
is a crank. Mixing cranks with linear legs is refused (the protocol has one actuator unit).
The window's lower limit must be > 0 when every leg is prismatic (a window of lengths, as
``ups6``). Mixed with sliders it may be <= 0 (a rail coordinate may be negative); a prismatic
leg's value is its length, >= 0, so such a limit bounds nothing on it: its feasible lengths
are ``[max(min, 0), max]`` (none when ``max <= 0``), in the IK and in the columns alike.

Workspace: every leg's feasible z set along an (x, y) column has closed form, and the engine
gets the exact column method (``column_method``):

* ``"linear"`` / ``"quadratic"``: every leg prismatic (the ``ups6`` interval on the
  working-mode side) or a slider on a vertical rail (``e = ±ẑ``, the ``psu6`` linear
  interval); single-interval radial legs (``column_leg``, ``column_radial``), so refine, the
  exact task check and the continuous optima apply as for ``psu6`` / ``ups6``;
* ``"slider"``: some slider on an inclined or horizontal rail (:mod:`._slider`: on the
  working-mode side the slider coordinate is monotone along the column, so each leg's set is
  one interval whose ends are closed-form), mixed with any of the above;
* ``"crank"``: every leg a crank (the set-valued legs of :mod:`._crank`, as ``rss6``).

The last two are set-valued column legs (:mod:`._set_columns`): such an instance has
``column_leg = None`` and ``column_radial = False`` (instance values shadowing the class
ones), so refine, the exact task check and the continuous optima decline it as they decline
``rss6``. Only a rail within ~0.002° of vertical but not exactly vertical
(``e_x² + e_y² < _slider.K_MIN``) leaves ``column_method = None`` (sampled).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ...errors import ParameterError
from ...poses import euler_to_matrix
from ...tolerances import TOL
from .. import joints
from ..base import NO_STROKE, Mechanism, as_points, as_stroke, as_vector3
from ..kernels.set_columns import set_column_intervals
from ..legs.crank import crank_column_leg, crank_params
from ..legs.layout import PAIRED_ALIASES
from ..legs.slider import K_MIN, slider_interval
from ..validation import unit_rows, without_component
from .sixleg_ik import _sixleg_one, ik_function
from .ups6 import _ups_column_leg, working_sides

__all__ = ["SixLeg", "KINDS"]

#: actuator kind name → code stored in ``SixLeg.kinds``
KINDS = {"prismatic": 0.0, "slider": 1.0, "crank": 2.0}
_NAMES = {v: k for k, v in KINDS.items()}
@register_jitable
def _linear_interval(x, y, wx, wy, wz, k, p1, p2):
    """One leg's z interval on the column (x, y) (see :func:`.column_kernels.make_column_kernel`).

    Prismatic (``k = ±inf``: the tag of a leg without a link, its sign the working-mode side):
    ``p1 = max(qmin, 0)²``, ``p2 = qmax²`` (``-1`` when ``qmax <= 0``: never feasible); the
    interval of ``ups6`` (:func:`.ups6._ups_column_leg`). The limits are stored apart from the
    side because a leg length is >= 0: a window lower limit <= 0 bounds nothing
    (:meth:`SixLeg._linear_params`). Slider on a vertical rail (finite ``k``): ``|k| = l² >
    0``, ``sign(k) = c`` and the interval is ``[p1 - w_z + c·h, p2 - w_z + c·h]`` with ``h =
    sqrt(l² - |a_xy|²)`` (``psu6``'s for ``c = 1``)."""
    if math.isinf(k):
        return _ups_column_leg(x, y, wx, wy, wz, k, p1, p2)
    ax = x + wx
    ay = y + wy
    h2 = abs(k) - (ax * ax + ay * ay)
    s = math.sqrt(h2 if h2 > 0.0 else 0.0)
    c = 1.0 if k > 0.0 else -1.0
    return p1 - wz + c * s, p2 - wz + c * s, h2 >= 0.0


#: the single-interval column leg (``column_leg``) of prismatic and vertical-rail legs
_sixleg_column_leg = njit(inline="always")(_linear_interval)


@register_jitable
def _sixleg_set_leg(x, y, wx, wy, wz, p, zlo, zhi, out_lo, out_hi):
    """Set-valued column leg (:mod:`._set_columns`) of prismatic and slider legs, one interval
    each: row ``p = [0, k, p1, p2, ...]`` for :func:`_sixleg_column_leg`, or ``[1, e (3), l, b,
    side, qmin, qmax]`` for an inclined or horizontal rail (:func:`._slider.slider_interval`)."""
    if p[0] == 0.0:
        a, b, ok = _linear_interval(x, y, wx, wy, wz, p[1], p[2], p[3])
    else:
        a, b, ok = slider_interval(x + wx, y + wy, wz, p[1], p[2], p[3], p[4], p[5], p[6],
                                   p[7], p[8])
    a = max(a, zlo)
    b = min(b, zhi)
    if not (ok and a <= b):
        return 0
    out_lo[0] = a
    out_hi[0] = b
    return 1


def _directions(value, field: str, need: np.ndarray) -> np.ndarray:
    arr = np.asarray(value, dtype=float)        # legs numbered from 0, as in schema errors
    if arr.shape != (6, 3):
        raise ParameterError(field, "an array of shape (6, 3) of directions", arr.shape)
    if np.any(bad := need & ~(np.isfinite(scale := np.max(np.abs(arr), axis=1)) & (scale > 0))):
        i = int(np.argmax(bad))
        raise ParameterError(f"legs[{i}].{field}", "a finite non-zero direction", arr[i].tolist())
    big = need & ((scale > 1e150) | (scale < 1e-150))  # algorithm constant: squares overflow
    return np.where(need[:, None], unit_rows(arr / np.where(big, scale, 1.0)[:, None]), 0.0)


def _per_leg(value, field: str, need: np.ndarray, positive: bool = True) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape == ():
        arr = np.full(6, float(arr))
    if arr.shape != (6,) or not np.all(np.isfinite(arr)):
        raise ParameterError(field, "six finite numbers", value)
    bad = need & (arr <= 0) if positive else need & ~np.isin(arr, (-1.0, 1.0))
    if np.any(bad):
        i = int(np.argmax(bad))
        raise ParameterError(f"legs[{i}].{field}", "a length > 0 mm" if positive else
                             "-1 or +1", float(arr[i]))
    return np.where(need, arr, 0.0 if positive else -1.0)


@dataclass(frozen=True, eq=False)
class SixLeg(Mechanism):
    """Six legs, each prismatic, slider + link, or crank + rod (see the module docstring).

    Attributes:
        base_points: ``(6, 3)`` base U joints (prismatic), slider positions at actuator value
            0 (slider) or crank pivots on the servo axes (crank), mm, base frame.
        platform_points: ``(6, 3)`` platform joint centres in the platform frame (mm).
        kinds: ``(6,)`` actuator kind codes (:data:`KINDS`); :attr:`leg_kinds` gives names.
        axes: ``(6, 3)`` rail axes ``e`` (slider) or servo axes ``n`` (crank), normalised;
            zero for prismatic legs.
        zero_directions: ``(6, 3)`` crank zero directions ``u`` (made perpendicular to the
            axis); zero for the other kinds.
        crank_length: ``(6,)`` crank lengths ``a`` (mm), 0 for the other kinds.
        link_length: ``(6,)`` slider link or crank rod lengths (mm), 0 for prismatic legs.
        branch: ``(6,)`` ±1: slider and crank branches (default -1); unused for prismatic legs,
            whose working-mode side is taken from the nominal pose as in ``ups6``.
        stroke_window: shared actuator window (min, max): mm, or rad for cranks (YAML
            ``stroke`` or ``servo_range``).
        tool_offset: ``(3,)`` tool-frame origin in the platform frame (mm).
    """

    family = "sixleg"

    base_points: np.ndarray
    platform_points: np.ndarray
    kinds: np.ndarray
    axes: np.ndarray
    zero_directions: np.ndarray
    crank_length: np.ndarray
    link_length: np.ndarray
    stroke_window: tuple[float, float]
    branch: np.ndarray = (-1.0,) * 6  # type: ignore[assignment]
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)  # type: ignore[assignment]

    #: the kernel of any instance; :attr:`_ik_kernel` picks the one for the instance's kinds
    _ik_one = _sixleg_one
    #: named study variables (paths in the generator form of the YAML model)
    design_aliases: ClassVar[dict] = {
        **PAIRED_ALIASES,
        "link_length": ("generator.actuator.link_length", "length"),
        "rail_inclination": ("generator.actuator.rail_inclination", "angle"),
        "rail_heading": ("generator.actuator.rail_heading", "text"),
        "crank_length": ("generator.actuator.crank_length", "length"),
        "rod_length": ("generator.actuator.rod_length", "length"),
        "servo_min": ("servo_range[0]", "angle"),
        "servo_max": ("servo_range[1]", "angle"),
    }
    column_radial: ClassVar[bool] = True
    column_leg = _sixleg_column_leg

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 6))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 6))
        kinds = np.asarray(self.kinds, dtype=object)
        if kinds.shape != (6,):
            raise ParameterError("legs", "six legs", f"{kinds.size} legs")
        codes = np.array([KINDS.get(k, k) if isinstance(k, str) else float(k) for k in kinds])
        if not np.all(np.isin(codes, list(KINDS.values()))):
            raise ParameterError("kind", f"one of {list(KINDS)}", self.kinds)
        crank = codes == KINDS["crank"]
        if crank.any() and not crank.all():
            raise ParameterError("legs", "all cranks or no crank (one actuator unit, mm or "
                                 "rad, per mechanism)", [_NAMES[c] for c in codes])
        slider = codes == KINDS["slider"]
        set_(self, "kinds", codes)
        set_(self, "axes", _directions(self.axes, "axis", slider | crank))
        u = _directions(self.zero_directions, "zero_direction", crank)
        u = without_component(u, self.axes)                                  # Gram-Schmidt
        flat = crank & (np.linalg.norm(u, axis=1) < TOL.perpendicular_rel)
        if np.any(flat):
            i = int(np.argmax(flat))
            raise ParameterError(f"legs[{i}].zero_direction", "a direction not parallel "
                                 "to the servo axis", self.zero_directions[i])
        set_(self, "zero_directions", np.where(crank[:, None], unit_rows(u), 0.0))
        set_(self, "crank_length", _per_leg(self.crank_length, "crank_length", crank))
        set_(self, "link_length", _per_leg(self.link_length, "link_length", slider | crank))
        set_(self, "branch", _per_leg(self.branch, "branch", slider | crank, positive=False))
        if crank.all():
            w = as_stroke(self.stroke_window, "servo_range")
            if not (-math.pi <= w[0] and w[1] <= math.pi):
                raise ParameterError("servo_range", "[min, max] servo angles with -180 deg <= min "
                                     "< max <= 180 deg", np.degrees(w).tolist())
        else:
            w = as_stroke(self.stroke_window, "stroke", positive=bool(np.all(codes == 0.0)))
        set_(self, "stroke_window", w)
        set_(self, "tool_offset", as_vector3(self.tool_offset, "tool_offset"))
        for a in (self.kinds, self.axes, self.zero_directions, self.crank_length,
                  self.link_length, self.branch):
            a.setflags(write=False)
        if self.column_method in ("crank", "slider"):
            # Set-valued column legs (cranks, inclined rails): no single-interval
            # ``column_leg`` and no radial intervals for this instance, so refine, the exact
            # task check and the continuous optima (which need them) decline it as they
            # decline rss6. The instance values shadow the class ones that the other
            # instances keep.
            set_(self, "column_leg", None)
            set_(self, "column_radial", False)

    # ---- conversions -------------------------------------------------------------------------
    @classmethod
    def from_mechanism(cls, mech: Mechanism, name: str | None = None) -> SixLeg:
        """The generic declaration of a ``psu6``, ``ups6`` or ``rss6`` mechanism (same joints,
        window, tool offset, nominal pose and description)."""
        z = np.zeros((6, 3))
        kw = {"name": mech.name if name is None else name, "nominal": mech.nominal,
              "description": {**mech.description, "declared_from": mech.family}}
        common = (mech.base_points, mech.platform_points)
        if mech.family == "psu6":
            return cls(*common, ["slider"] * 6, np.tile([0.0, 0.0, 1.0], (6, 1)), z, 0.0,
                       mech.link_length, mech.stroke, -1.0, mech.tool_offset, **kw)
        if mech.family == "ups6":
            return cls(*common, ["prismatic"] * 6, z, z, 0.0, 0.0, mech.stroke, -1.0,
                       mech.tool_offset, **kw)
        if mech.family == "rss6":
            return cls(*common, ["crank"] * 6, mech.servo_axes, mech.zero_directions,
                       mech.crank_length, mech.rod_length, mech.stroke, mech.branch,
                       mech.tool_offset, **kw)
        raise ParameterError("family", "one of ['psu6', 'ups6', 'rss6'] to declare as sixleg",
                             mech.family)

    # ---- properties --------------------------------------------------------------------------
    @property
    def leg_kinds(self) -> tuple[str, ...]:
        return tuple(_NAMES[c] for c in self.kinds)

    @property
    def actuator_unit(self) -> str:           # type: ignore[override]
        return "rad" if self.kinds[0] == KINDS["crank"] else "mm"

    @property
    def actuator_names(self) -> tuple[str, ...]:    # type: ignore[override]
        return tuple(("theta" if k == "crank" else "q") + str(i + 1)
                     for i, k in enumerate(self.leg_kinds))

    def _mask(self, kind: str) -> np.ndarray:
        return self.kinds == KINDS[kind]

    @cached_property
    def _vertical(self) -> np.ndarray:
        """Sliders on rails along ±z exactly (closed-form linear column intervals)."""
        return self._mask("slider") & (self.axes[:, 0] == 0.0) & (self.axes[:, 1] == 0.0)

    @property
    def scale(self) -> float:
        span = self.stroke[1] - self.stroke[0]
        reach = np.where(self._mask("prismatic"), self.stroke[1],
                         np.where(self._mask("slider"), self.link_length + span,
                                  self.crank_length + self.link_length))
        return float(np.max(np.linalg.norm(self.base_points, axis=1))
                     + np.max(np.linalg.norm(self.platform_points, axis=1)) + np.max(reach))

    @cached_property
    def _sides(self) -> np.ndarray:
        """Working-mode side of each prismatic leg (:func:`.ups6.working_sides`)."""
        return working_sides(self)

    @cached_property
    def _slider_sides(self) -> np.ndarray:
        """Working-mode side of each slider leg: the sign of its link's vertical component
        ``a_z``, kept as at the nominal pose when it is given; otherwise +1 (platform joint
        above its slider), except on vertical rails, where ``a_z = -b·h·e_z`` has a fixed sign.
        A leg on the other side is ``OTHER_MODE`` (its link crossed the horizontal: the mirror
        assembly through the rails' plane)."""
        fixed = np.where(self._vertical, np.sign(-self.branch * self.axes[:, 2]), 1.0)
        fixed = np.where(fixed == 0, 1.0, fixed)
        if self.nominal is None:
            return fixed
        pose = np.asarray(self.nominal, dtype=float)
        d = pose[:3] + self.tool_points @ euler_to_matrix(pose[3:]).T - self.base_points
        t = np.sum(d * self.axes, axis=1)
        perp = d - t[:, None] * self.axes
        h = np.sqrt(np.clip(self.link_length**2 - np.sum(perp**2, axis=1), 0.0, None))
        az = perp[:, 2] - self.branch * h * self.axes[:, 2]
        return np.where(self._vertical | (az == 0), fixed, np.sign(az))

    @property
    def v_directions(self) -> np.ndarray:
        """``(6, 3)`` ``v = n × u`` of the crank legs (zero for the others)."""
        return np.cross(self.axes, self.zero_directions)

    def _gparams(self) -> np.ndarray:
        crank = self._mask("crank")
        a2 = 2.0 * self.crank_length[:, None]
        first = np.where(crank[:, None], a2 * self.zero_directions, self.axes)
        c = np.where(crank, self.crank_length**2 - self.link_length**2, self.link_length**2)
        b = np.where(self._mask("prismatic"), self._sides, self.branch)
        g = np.column_stack([self.base_points, self.tool_points, self.kinds, first,
                             a2 * self.v_directions, c,
                             np.where(crank, 1e-24 * self.crank_length**4, self._slider_sides),
                             b])
        return g.ravel()

    def _ik_kernel(self):
        """The per-pose IK function for this instance's leg kinds (:func:`.sixleg_ik.ik_function`:
        legs of one kind run only that kind's kernel)."""
        return ik_function(self.kinds)

    # ---- kinematics --------------------------------------------------------------------------
    def _legs(self, p, R, q):
        """``r = R·(P - O)`` and each leg's moving-link vector (prismatic: the leg) ``(N, 6, 3)``
        for actuator values ``q (N, 6)``."""
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        W = p[:, None, :] + r
        qq = q[..., None]
        start = self.base_points + np.where(
            self._mask("slider")[:, None], qq * self.axes,
            self.crank_length[:, None] * (np.cos(qq) * self.zero_directions
                                          + np.sin(qq) * self.v_directions))
        start = np.where(self._mask("prismatic")[:, None], self.base_points, start)
        return r, W - start, start

    def _jacobian(self, p, R):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        r, a, _ = self._legs(p, R, q)
        qq = q[..., None]
        dC = self.crank_length[:, None] * (-np.sin(qq) * self.zero_directions
                                           + np.cos(qq) * self.v_directions)
        with np.errstate(divide="ignore", invalid="ignore"):
            den = np.where(self._mask("prismatic"), np.linalg.norm(a, axis=-1),
                           np.where(self._mask("slider"), np.sum(a * self.axes, axis=-1),
                                    np.sum(a * dC, axis=-1)))
            return np.concatenate([a, np.cross(r, a)], axis=-1) / den[..., None]

    def _closure(self, p, R, q):
        r, a, _ = self._legs(p, R, np.broadcast_to(q, (len(p), 6)))
        norm = np.linalg.norm(a, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            n = a / norm[..., None]
        target = np.where(self._mask("prismatic"), q, self.link_length)
        return norm - target, np.concatenate([n, np.cross(r, n)], axis=-1)

    # ---- joints (:mod:`.joints`): UPS, PSU or RSS legs by kind -------------------------------
    _moving_rows, _crank_rows = (lambda m: ~m._mask("prismatic")), (lambda m: m._mask("crank"))
    parameter_fields = (
        joints.ParamField("base_points", "base", "mm", "leg {i}'s base U joint, slider position at "
                   "actuator value 0 or crank pivot (base frame)"),
        joints.DEFAULT_FIELDS[1],
        joints.ParamField("axes", "axis", "1", "leg {i}'s rail or servo axis direction",
                   rows=_moving_rows),
        joints.ParamField("zero_directions", "zero_direction", "1", "leg {i}'s crank direction at "
                   "angle 0 (the actuator zero)", rows=_crank_rows),
        joints.ParamField("crank_length", "crank_length", "mm", "leg {i}'s crank length",
                   rows=_crank_rows),
        joints.ParamField("link_length", "link_length", "mm", "leg {i}'s slider link or crank rod "
                   "length", rows=_moving_rows),
        *joints.DEFAULT_FIELDS[2:])

    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        _, a, start = self._legs(p, R, q)
        start = np.broadcast_to(start, a.shape)
        W = start + a          # the platform joints, as leg_segments always drew them
        if len(set(self.leg_kinds)) == 1:
            return joints.kind_arrays(self, self.leg_kinds[0], start, W, q, R, axes,
                                      rail=self.axes)
        centre = np.empty((3, len(p), 6, 3))
        ax = np.empty((len(p), 6, 3, 2, 3)) if axes else None
        for kind in KINDS:
            m = self._mask(kind)
            if m.any():
                part = joints.kind_arrays(self, kind, start[:, m], W[:, m], q, R, axes,
                                   legs=np.flatnonzero(m), rail=self.axes[m])
                centre[:, :, m] = part.centre
                if axes:
                    ax[:, m] = part.axes
        return joints.JointArrays(tuple(centre), ax, q)

    def _leg_templates(self):
        out = []
        for i, (kind, name) in enumerate(zip(self.leg_kinds, self.actuator_names, strict=True)):
            lengths = {"prismatic": (0.0, 0.0), "slider": (0.0, self.link_length[i]),
                       "crank": (self.crank_length[i], self.link_length[i])}[kind]
            out.append(joints.kind_template(kind, i, name, self.base_points[i],
                                     self.platform_points[i], lengths,
                                     zero=None if kind == "crank" else self.base_points[i],
                                     reference=self.zero_directions[i] if kind == "crank"
                                     else None))
        return tuple(out)

    def describe(self) -> dict:
        d = super().describe()
        if self.actuator_unit == "rad":
            d.pop("stroke_mm", None)
            d["servo_range_deg"] = np.degrees(self.stroke).tolist()
        d.update(leg_kinds=list(self.leg_kinds), axes=self.axes.tolist(),
                 link_length_mm=self.link_length.tolist(), branch=self.branch.tolist())
        if self._mask("crank").any():
            d.update(crank_length_mm=self.crank_length.tolist(),
                     zero_directions=self.zero_directions.tolist())
        return d

    # ---- workspace hooks -------------------------------------------------------------------
    @property
    def column_method(self) -> str | None:     # type: ignore[override]
        """``"crank"`` when every leg is a crank (exact set-valued legs, :mod:`._crank`);
        ``"quadratic"`` (any prismatic leg) or ``"linear"`` when every leg is prismatic or a
        vertical-rail slider; else ``None`` (sampled)."""
        if np.all(self._mask("crank")):
            return "crank"
        prism = self._mask("prismatic")
        if not np.all(prism | self._vertical):
            k = np.sum(self.axes[:, :2] ** 2, axis=1)
            ok = np.all(prism | self._vertical | (self._mask("slider") & (k >= K_MIN)))
            return "slider" if ok else None
        return "quadratic" if prism.any() else "linear"

    @property
    def column_invariant(self) -> bool:        # type: ignore[override]
        return bool(np.all(self._vertical))

    def column_params(self) -> np.ndarray:
        """``(6, 3)`` parameters of :func:`_sixleg_column_leg`, or for cranks the ``(6, 15)``
        rows of :func:`._crank.crank_column_leg` (only with a column method)."""
        method = self.column_method
        if method is None:
            raise ValueError(f"{self.name or 'this sixleg'} has legs without column intervals")
        if method == "crank":
            return crank_params(self.zero_directions, self.v_directions, self.crank_length,
                                self.link_length, self.branch, self.stroke)
        lo, hi = self.stroke
        if method == "slider":                 # rows of _sixleg_set_leg
            linear = self._vertical | self._mask("prismatic")
            k = self._linear_params(lo, hi)
            return np.where(linear[:, None], np.column_stack([np.zeros(6), k, np.zeros((6, 5))]),
                            np.column_stack([np.ones(6), self.axes, self.link_length,
                                             self.branch, self._slider_sides, np.full(6, lo),
                                             np.full(6, hi)]))
        return self._linear_params(lo, hi)

    def _linear_params(self, lo, hi) -> np.ndarray:
        """``(6, 3)`` rows ``(k, p1, p2)`` of :func:`_sixleg_column_leg` (meaningful for
        prismatic legs and vertical rails; zero rows for the other legs).

        Vertical rail: ``k = c·l²``, ``(p1, p2)`` the window along +z. Prismatic leg: ``k =
        side·inf`` and the squared length window ``(max(lo, 0)², hi²)``, ``p2 = -1`` (no
        length) when ``hi <= 0``. The actuator value of a prismatic leg is its length, which
        is >= 0, so a shared window whose lower limit is <= 0 (for the sliders it is a rail
        coordinate, which may be negative) puts no lower limit on the leg: the IK's
        ``qmin <= |d|`` holds for every length, and the column keeps every length down to 0.
        """
        sigma = self.axes[:, 2]                              # ±1 on vertical rails
        c = -sigma * self.branch
        prism = self._mask("prismatic")
        k = np.where(self._vertical, c * self.link_length**2,
                     np.where(prism, self._sides * np.inf, 0.0))
        lo2 = max(lo, 0.0) ** 2
        hi2 = hi * hi if hi > 0.0 else -1.0
        p1 = np.where(self._vertical, np.where(sigma > 0, lo, -hi), np.where(prism, lo2, 0.0))
        p2 = np.where(self._vertical, np.where(sigma > 0, hi, -lo), np.where(prism, hi2, 0.0))
        return np.stack([k, p1, p2], axis=1)

    def column_intervals(self, xs, ys, R, mode, allowed=None, K=8):
        """As :meth:`.base.Mechanism.column_intervals`; crank legs use the exact set-valued
        legs of :mod:`._crank` (as ``rss6``), whose dexterous sets have up to ``K`` pieces."""
        method = self.column_method
        if method in ("crank", "slider"):
            leg = crank_column_leg if method == "crank" else _sixleg_set_leg
            return set_column_intervals(leg, self.leg_offsets(R), self.column_params(), xs, ys,
                                        R, mode, allowed, K)
        return super().column_intervals(xs, ys, R, mode, allowed, K)

    def position_bounds(self, R):
        """Per orientation, the intersection over legs of each leg's reach box ``(M, 2, 3)``:
        prismatic within ``qmax`` on its working-mode side; slider: the half ball of radius
        ``l`` on its branch's side swept along the rail window, above (below) the slider on
        its working-mode side; crank within ``a + s``."""
        W = self.leg_offsets(R)                              # (M, 6, 3)
        lo_q, hi_q = self.stroke
        box_lo = np.empty((6, 3))
        box_hi = np.empty((6, 3))
        for i, kind in enumerate(self.leg_kinds):
            if kind == "prismatic":
                box_lo[i], box_hi[i] = -hi_q, hi_q
                if self._sides[i] > 0:
                    box_lo[i, 2] = 0.0
                else:
                    box_hi[i, 2] = 0.0
            elif kind == "slider":
                e, ep = self.axes[i], -self.branch[i] * self.axes[i]
                side = np.sqrt(np.clip(1.0 - ep**2, 0.0, None))
                ends = np.stack([lo_q * e, hi_q * e])
                lk = self.link_length[i]
                box_lo[i] = ends.min(axis=0) + lk * np.where(ep <= 0, -1.0, -side)
                box_hi[i] = ends.max(axis=0) + lk * np.where(ep >= 0, 1.0, side)
                if self._slider_sides[i] > 0:      # working mode: joint above its slider
                    box_lo[i, 2] = max(box_lo[i, 2], ends[:, 2].min())
                else:
                    box_hi[i, 2] = min(box_hi[i, 2], ends[:, 2].max())
            else:
                reach = self.crank_length[i] + self.link_length[i]
                box_lo[i], box_hi[i] = -reach, reach
        return np.stack([(box_lo - W).max(axis=1), (box_hi - W).min(axis=1)], axis=1)
