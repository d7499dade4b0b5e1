"""Workspace constraints beyond the actuator stroke, as pure batched checks.

Each check takes tool positions ``p (N, 3)`` and rotations ``R (N, 3, 3)`` and returns a boolean
``(N,)`` mask (True = satisfied); poses whose legs have no real solution fail every check.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..dexterity.metrics import condition_number, resolve_length
from ..errors import ParameterError
from ..poses import as_frames
from ..tolerances import TOL

__all__ = ["ActuatorWindow", "Constraints", "JointLimits", "check", "segment_distances",
           "joint_angles"]


@dataclass(frozen=True)
class ActuatorWindow:
    """An actuator window as the user wrote it (YAML ``constraints.stroke``, ``--stroke``),
    resolved against a mechanism by :meth:`Constraints.resolved`.

    Attributes:
        lo, hi: the two values, in ``unit``.
        unit: ``"mm"`` (lengths given with units, converted to mm), ``"rad"`` (angles given
            with units, converted to rad) or ``"bare"`` (plain numbers: mm for prismatic
            actuators, deg for rotary ones, the YAML conventions).
    """

    lo: float
    hi: float
    unit: str

    def __post_init__(self):
        if self.unit not in ("mm", "rad", "bare"):
            raise ValueError(f"unit must be 'mm', 'rad' or 'bare', got {self.unit!r}")

    def shown(self) -> list[str]:
        if self.unit == "rad":
            return [f"{math.degrees(v):.12g} deg" for v in (self.lo, self.hi)]
        return [f"{v:.12g}" + (" mm" if self.unit == "mm" else "") for v in (self.lo, self.hi)]

    def window(self, mech) -> tuple[float, float]:
        """``(lo, hi)`` in the internal unit of ``mech``'s actuators (mm, or rad for rotary
        ones); a length for a rotary actuator (or an angle for a prismatic one) is refused."""
        rotary = mech.actuator_unit == "rad"
        if self.unit == ("mm" if rotary else "rad"):
            want = ("servo angles (deg or with units)" if rotary else
                    "lengths (mm or with units)")
            kind = "rotary" if rotary else "prismatic"
            raise ParameterError("constraints.stroke", f"{want} for family {mech.family!r}, "
                                 f"whose actuators are {kind}", self.shown())
        lo, hi = self.lo, self.hi
        if rotary and self.unit == "bare":
            lo, hi = math.radians(lo), math.radians(hi)
        if rotary and not -math.pi <= lo < hi <= math.pi:
            raise ParameterError("constraints.stroke", "[min, max] servo angles with -180 deg "
                                 "<= min < max <= 180 deg", self.shown())
        return lo, hi


@dataclass(frozen=True)
class JointLimits:
    """Passive joint cones: the angle between a link and its joint's mounting axis.

    Attributes:
        base: half-angle of the base-side joint cones (rad), ``None`` = unlimited.
        platform: half-angle of the platform-side joint cones (rad), ``None`` = unlimited.
        base_axes: ``(6, 3)`` mounting axes in the base frame; ``None`` = each link's
            direction at the nominal pose (the joint mounted to centre its cone there).
        platform_axes: ``(6, 3)`` mounting axes in the platform frame; ``None`` = likewise.
    """

    base: float | None = None
    platform: float | None = None
    base_axes: np.ndarray | None = None
    platform_axes: np.ndarray | None = None

    def __post_init__(self):
        for name in ("base", "platform"):
            v = getattr(self, name)
            if v is not None and not (0 < v <= math.pi):
                raise ParameterError(f"joint_limits.{name}", "a cone half-angle in (0, 180] deg",
                                     math.degrees(v))
        for name in ("base_axes", "platform_axes"):
            v = getattr(self, name)
            if v is not None:
                a = np.asarray(v, dtype=float)
                n = np.linalg.norm(a, axis=-1) if a.shape == (6, 3) else None
                if n is None or not np.all(np.isfinite(a)) or np.any(n < TOL.direction_norm):
                    raise ParameterError(f"joint_limits.{name}",
                                         "six non-zero direction vectors, shape (6, 3)", v)
                object.__setattr__(self, name, a / n[:, None])


@dataclass(frozen=True)
class Constraints:
    """Which constraints a workspace request applies.

    Attributes:
        stroke: ``True`` = the mechanism's actuator window, or ``(min, max)`` in the
            actuators' internal unit (mm, or rad for rotary actuators) to evaluate the same
            geometry with another window (what-if strokes), or an :class:`ActuatorWindow` as
            the user wrote it (resolved against the mechanism by :meth:`resolved`). It cannot
            be switched off: without it a workspace is unbounded.
        joint_limits: passive joint cones, or ``None``.
        link_diameter: legs are cylinders of this diameter (mm); two legs interfere when
            their axes come closer than it. ``None`` = not checked.
        kappa_max: largest admissible κ (:func:`pkmlab.dexterity.condition_number`), or
            ``None``.
        characteristic_length: L_c (mm) dividing the rotational Jacobian columns for κ;
            ``None`` = pkmlab's default (:func:`pkmlab.dexterity.resolve_length`: Angeles',
            resolved by :func:`pkmlab.workspace`, which states the L used and its status in
            the result's notes).
        connected: keep only the region connected to the nominal position (drops mirror
            regions that the stroke alone admits).
    """

    stroke: bool | tuple[float, float] | ActuatorWindow = True
    joint_limits: JointLimits | None = None
    link_diameter: float | None = None
    kappa_max: float | None = None
    characteristic_length: float | None = None
    connected: bool = True
    #: unit of a ``(min, max)`` stroke (``"mm"`` or ``"rad"``), set by :meth:`resolved`
    stroke_unit: str | None = None

    def __post_init__(self):
        if self.stroke is not True:
            w = self.stroke
            win = (np.asarray([w.lo, w.hi] if isinstance(w, ActuatorWindow) else w,
                              dtype=float) if w is not False else None)
            if win is None or win.shape != (2,) or not np.all(np.isfinite(win)) \
                    or win[0] >= win[1]:
                raise ParameterError("constraints.stroke", "true or a window [min, max] "
                                     "(mm, or servo angles for rotary actuators) with min < "
                                     "max (without a stroke limit the workspace is "
                                     "unbounded)", self.stroke)
            if not isinstance(w, ActuatorWindow):
                object.__setattr__(self, "stroke", (float(win[0]), float(win[1])))
        if self.link_diameter is not None and not (self.link_diameter > 0):
            raise ParameterError("constraints.link_diameter", "a length > 0 mm",
                                 self.link_diameter)
        if self.kappa_max is not None and not (self.kappa_max >= 1):
            raise ParameterError("constraints.kappa_max", "a number >= 1", self.kappa_max)
        if self.characteristic_length is not None and not (self.characteristic_length > 0):
            raise ParameterError("constraints.characteristic_length", "a length > 0 mm",
                                 self.characteristic_length)

    def resolved(self, mech) -> Constraints:
        """These constraints with the stroke in ``mech``'s internal actuator unit (an
        :class:`ActuatorWindow` converted, refused when its dimension does not fit)."""
        if isinstance(self.stroke, ActuatorWindow):
            return dataclasses.replace(self, stroke=self.stroke.window(mech),
                                       stroke_unit=mech.actuator_unit)
        if self.stroke is not True and self.stroke_unit is None:
            return dataclasses.replace(self, stroke_unit=mech.actuator_unit)
        return self

    @property
    def extra(self) -> bool:
        """True when any constraint other than the stroke is active."""
        return (self.joint_limits is not None or self.link_diameter is not None
                or self.kappa_max is not None)

    def describe(self) -> dict:
        jl = self.joint_limits
        return {
            "stroke": (self.stroke if self.stroke is True else self.stroke.shown()
                       if isinstance(self.stroke, ActuatorWindow) else
                       [f"{math.degrees(v):.12g} deg" for v in self.stroke]
                       if self.stroke_unit == "rad" else list(self.stroke)),
            "joint_limits_deg": None if jl is None else {
                "base": None if jl.base is None else math.degrees(jl.base),
                "platform": None if jl.platform is None else math.degrees(jl.platform)},
            "link_diameter_mm": self.link_diameter,
            "kappa_max": self.kappa_max,
            "characteristic_length_mm": self.characteristic_length,
            "connected": self.connected,
        }


def joint_angles(mech, p, R, limits: JointLimits) -> tuple[np.ndarray, np.ndarray]:
    """Angles (rad) ``(N, 6)`` between each link and its base / platform mounting axis."""
    start, end = mech.leg_segments(p, R)
    d = end - start
    with np.errstate(invalid="ignore", divide="ignore"):
        d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    nb, npl = _mounting_axes(mech, limits)
    nb = mech.base_joint_axes(p, R, nb)       # joints riding on a crank turn with it
    cb = np.einsum("nki,nki->nk", d, nb)
    cp = np.einsum("nki,nij,kj->nk", d, R, npl)
    return np.arccos(np.clip(cb, -1, 1)), np.arccos(np.clip(cp, -1, 1))


def _mounting_axes(mech, limits: JointLimits):
    if limits.base_axes is not None and limits.platform_axes is not None:
        return limits.base_axes, limits.platform_axes
    pn, Rn = as_frames(mech.nominal_pose)
    s, e = mech.leg_segments(pn, Rn)
    d = (e - s)[0]
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    nb = limits.base_axes if limits.base_axes is not None else d
    npl = limits.platform_axes if limits.platform_axes is not None else d @ Rn[0]
    return nb, npl


def segment_distances(start: np.ndarray, end: np.ndarray, leg=None) -> np.ndarray:
    """Smallest distance between every pair of the segments ``(N, S, 3)``: ``(N, 15)`` for
    six; with ``leg (S,)`` only pairs of segments of different legs."""
    i, j = np.triu_indices(start.shape[1], 1)
    if leg is not None:
        keep = np.asarray(leg)[i] != np.asarray(leg)[j]
        i, j = i[keep], j[keep]
    p1, q1, p2, q2 = start[:, i], end[:, i], start[:, j], end[:, j]
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.einsum("...i,...i", d1, d1)
    e = np.einsum("...i,...i", d2, d2)
    f = np.einsum("...i,...i", d2, r)
    c = np.einsum("...i,...i", d1, r)
    b = np.einsum("...i,...i", d1, d2)
    den = a * e - b * b
    with np.errstate(invalid="ignore", divide="ignore"):
        # algorithm constant: segments this close to parallel take s = 0 (any s is closest)
        s = np.where(den > 1e-12 * a * e, np.clip((b * f - c * e) / den, 0, 1), 0.0)
        t = (b * s + f) / e
        # Clamp t and recompute s where t leaves [0, 1] (closest points of two segments).
        t_lo, t_hi = t < 0, t > 1
        t = np.clip(t, 0, 1)
        s = np.where(t_lo, np.clip(-c / a, 0, 1), s)
        s = np.where(t_hi, np.clip((b - c) / a, 0, 1), s)
    c1 = p1 + s[..., None] * d1
    c2 = p2 + t[..., None] * d2
    return np.linalg.norm(c1 - c2, axis=-1)


def check(mech, p: np.ndarray, R: np.ndarray, cons: Constraints) -> np.ndarray:
    """``(N,)`` True where every non-stroke constraint of ``cons`` holds."""
    ok = np.ones(len(p), dtype=bool)
    if not cons.extra or len(p) == 0:
        return ok
    if cons.joint_limits is not None:
        ab, ap = joint_angles(mech, p, R, cons.joint_limits)
        jl = cons.joint_limits
        if jl.base is not None:
            ok &= np.all(ab <= jl.base, axis=1)      # NaN (no solution) fails
        if jl.platform is not None:
            ok &= np.all(ap <= jl.platform, axis=1)
    if cons.link_diameter is not None:
        start, end, leg = mech.link_segments(p, R)
        d = segment_distances(start, end, leg)
        ok &= np.all(d >= cons.link_diameter, axis=1)
    if cons.kappa_max is not None:
        L = resolve_length(mech, cons.characteristic_length)      # with its columns
        idx = np.nonzero(ok)[0]
        k = condition_number(mech.jacobian((p[idx], R[idx])), L)
        ok[idx] &= k <= cons.kappa_max
    return ok
