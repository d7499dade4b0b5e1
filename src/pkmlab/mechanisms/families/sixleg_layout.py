"""Layout generator of the generic six-leg family: three leg pairs on two circles.

Joint centres come from :func:`.layout.build_paired` (the numbering and angles of the 6-PSU and
6-UPS generators). The actuator template is the same for the six legs:

* ``prismatic``: the 6-UPS generator (:meth:`UPS6.from_circles`), declared generically;
* ``crank``: the 6-RSS generator (:meth:`RSS6.from_circles`: servo axes tangent to the base
  circle for ``crank_plane="radial"``, radial for ``"tangential"``), declared generically;
* ``slider``: each base joint is the slider's position at actuator value 0, on a rail inclined
  by ``rail_inclination`` above the horizontal (90° = vertical, the 6-PSU generator exactly).
  The rail's horizontal component points ``"outward"`` (radially away from the base centre),
  ``"inward"``, or ``"parallel"``: along ``±x``, the sign of the base joint's x coordinate
  (of its pair centre when that is 0), so all rails are parallel to the x axis, pair by pair
  (the Hexaglide arrangement when horizontal). ``branch="auto"`` puts the platform joint on
  the side of the slider, along the rail, where the platform centre is: ``-1`` (joint ahead)
  when ``sin γ - o·cos γ >= 0`` with ``o = +1`` for outward/parallel rails and ``-1`` for
  inward ones, else ``+1``.

Lengths in mm, angles in rad.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import ParameterError
from ...tolerances import TOL
from ..legs.layout import build_paired
from .psu6 import PSU6, _radii
from .rss6 import RSS6
from .sixleg import SixLeg
from .ups6 import UPS6

__all__ = ["paired_sixleg", "rail_axes"]

HEADINGS = ("outward", "inward", "parallel")


def rail_axes(base_points: np.ndarray, inclination: float, heading: str,
              pair_angles: np.ndarray | None = None) -> np.ndarray:
    """``(6, 3)`` unit rail axes inclined by ``inclination`` (rad) above the horizontal."""
    if heading not in HEADINGS:
        raise ParameterError("rail_heading", f"one of {list(HEADINGS)}", heading)
    if not -math.pi / 2 <= inclination <= math.pi / 2:
        raise ParameterError("rail_inclination", "an angle in [-90, 90] deg above the "
                             "horizontal", math.degrees(inclination))
    B = np.asarray(base_points, dtype=float)
    if heading == "parallel":
        sx = np.sign(B[:, 0])
        if pair_angles is not None:
            sx = np.where(np.abs(B[:, 0]) < TOL.direction_norm, np.sign(np.cos(pair_angles)),
                          sx)
        sx = np.where(sx == 0, 1.0, sx)
        h = np.stack([sx, np.zeros(6), np.zeros(6)], axis=1)
    else:
        ang = np.arctan2(B[:, 1], B[:, 0])
        h = np.stack([np.cos(ang), np.sin(ang), np.zeros(6)], axis=1)
        h = h if heading == "outward" else -h
    e = math.cos(inclination) * h + math.sin(inclination) * np.array([0.0, 0.0, 1.0])
    e[np.abs(e) < 1e-15] = 0.0        # algorithm constant: clear round-off of cos/sin
    return e / np.linalg.norm(e, axis=1, keepdims=True)


def paired_sixleg(*, actuator: str, base_radii, platform_radii, base_pair_angle=None,
                  platform_rotation: float, base_pair_separation: float = 0.0,
                  platform_pair_separation: float = 0.0, pairing: str = "same", stroke,
                  tool_offset=(0.0, 0.0, 0.0), link_length=None, rail_inclination=math.pi / 2,
                  rail_heading: str = "outward", crank_length=None, rod_length=None,
                  crank_plane: str = "radial", zero_direction: str = "outward",
                  branch=None, name: str = "", nominal=None) -> SixLeg:
    """A :class:`SixLeg` with three pairs on two circles and one actuator template (see the
    module docstring); ``branch=None`` is the template's default (``auto`` for sliders, -1 for
    cranks)."""
    layout = dict(base_radii=base_radii, platform_radii=platform_radii,
                  base_pair_angle=base_pair_angle, platform_rotation=platform_rotation,
                  base_pair_separation=base_pair_separation,
                  platform_pair_separation=platform_pair_separation, pairing=pairing)
    kw = dict(stroke=stroke, tool_offset=tool_offset, name=name, nominal=nominal)
    if actuator == "prismatic":
        return _declared(UPS6.from_circles(**layout, **kw), actuator)
    if actuator == "crank":
        _need(crank_length, "crank_length")
        _need(rod_length, "rod_length")
        try:
            rss = RSS6.from_circles(**layout, crank_length=crank_length, rod_length=rod_length,
                                    crank_plane=crank_plane, zero_direction=zero_direction,
                                    branch=-1.0 if branch is None else branch, **kw)
        except ParameterError as exc:       # the sixleg YAML calls the servo window so
            if exc.field != "stroke":
                raise
            raise ParameterError("servo_range", exc.allowed, exc.got) from None
        return _declared(rss, actuator)
    if actuator != "slider":
        raise ParameterError("actuator.kind", "one of ['prismatic', 'slider', 'crank']",
                             actuator)
    _need(link_length, "link_length")
    if rail_inclination == math.pi / 2 and branch in (None, -1.0):
        m = _declared(PSU6.from_circles(**layout, link_length=link_length, **kw), actuator)
        return m
    B, P, desc = build_paired(_radii(base_radii, "base_radii"),
                              _radii(platform_radii, "platform_radii"), base_pair_angle,
                              platform_rotation, base_pair_separation,
                              platform_pair_separation, pairing)
    centres = np.repeat(np.asarray(desc.get("base_pair_angle_deg", 0.0), dtype=float), 6)
    centres = np.radians(centres) + np.repeat(np.arange(3) * 2 * np.pi / 3, 2)
    e = rail_axes(B, rail_inclination, rail_heading, centres)
    if branch is None:
        o = -1.0 if rail_heading == "inward" else 1.0
        branch = -1.0 if math.sin(rail_inclination) - o * math.cos(rail_inclination) >= 0 \
            else 1.0
    desc.update(generator="paired rails", rail_inclination_deg=math.degrees(rail_inclination),
                rail_heading=rail_heading)
    z = np.zeros((6, 3))
    return SixLeg(B, P, ["slider"] * 6, e, z, 0.0, link_length, stroke, branch, tool_offset,
                  name=name, nominal=nominal, description=desc)


def _need(value, field: str) -> None:
    if value is None:
        raise ParameterError(f"actuator.{field}", "given for this actuator kind", None)


def _declared(mech, kind: str) -> SixLeg:
    out = SixLeg.from_mechanism(mech)
    desc = {k: v for k, v in out.description.items() if k != "declared_from"}
    desc["generator_actuator"] = kind
    return SixLeg(out.base_points, out.platform_points, out.kinds, out.axes,
                  out.zero_directions, out.crank_length, out.link_length, out.stroke,
                  out.branch, out.tool_offset, name=out.name, nominal=out.nominal,
                  description=desc)
