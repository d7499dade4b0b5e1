"""YAML model of the generic six-leg family (``family: sixleg``).

Either six explicit ``legs``, each ``{base, platform, actuator}``, or a ``generator`` (three
pairs on two circles, :func:`pkmlab.mechanisms.families.sixleg_layout.paired_sixleg`) with one
``actuator`` template. Quantities carry units and are converted once, here: lengths in mm,
angles in deg when bare. The shared actuator window is ``stroke`` (lengths) when the legs are
prismatic or sliders and ``servo_range`` (angles) when they are cranks; both are typed
quantities, so study variables and exported files keep their units::

    family: sixleg
    stroke: [0 mm, 300 mm]
    legs:
      - base: [300 mm, 0 mm, 0 mm]           # slider position at actuator value 0
        platform: [80 mm, 0 mm, 0 mm]
        actuator: {kind: slider, axis: [-1, 0, 0], link_length: 400 mm, branch: 1}
      - ...
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from ...errors import ParameterError
from ...quantities import Angle, AngleWindow, PositiveLength, Stroke, Vector3
from ...specbase import PairedCircles, _Common, _Model
from ..base import Mechanism
from .sixleg import SixLeg
from .sixleg_layout import paired_sixleg

__all__ = ["SixLegSpec"]

Direction = Annotated[list[float], Field(min_length=3, max_length=3,
                                         description="direction [x, y, z] (any length > 0)")]
Branch = Literal[-1, 1]


class PrismaticActuator(_Model):
    """Prismatic leg (UPS): the leg length is the actuator value."""

    kind: Literal["prismatic"]


class SliderActuator(_Model):
    """Slider along ``axis`` from the base point (actuator value 0 there) and a link."""

    kind: Literal["slider"]
    axis: Direction
    link_length: PositiveLength
    branch: Branch = Field(-1, description="-1: platform joint ahead of the slider along the "
                           "axis; +1: behind it")


class CrankActuator(_Model):
    """Crank about ``axis`` through the base point, then a rod to the platform joint."""

    kind: Literal["crank"]
    axis: Direction
    zero_direction: Direction = Field(description="crank direction at angle 0 (made "
                                      "perpendicular to the axis); positive angles turn by "
                                      "the right-hand rule about the axis")
    crank_length: PositiveLength
    rod_length: PositiveLength
    branch: Branch = -1


Actuator = Annotated[PrismaticActuator | SliderActuator | CrankActuator,
                     Field(discriminator="kind")]


class LegSpec(_Model):
    base: Vector3 = Field(description="base-side point (mm): U joint, slider zero, crank pivot")
    platform: Vector3 = Field(description="platform joint in the platform frame (mm)")
    actuator: Actuator


class ActuatorTemplate(_Model):
    """The actuator of the six generated legs."""

    kind: Literal["prismatic", "slider", "crank"]
    link_length: PositiveLength | None = Field(None, description="slider link length")
    rail_inclination: Angle = Field(1.5707963267948966, description="rail angle above the "
                                    "horizontal (deg; 90 = vertical)")
    rail_heading: Literal["outward", "inward", "parallel"] = "outward"
    crank_length: PositiveLength | None = None
    rod_length: PositiveLength | None = None
    crank_plane: Literal["radial", "tangential"] = "radial"
    zero_direction: Literal["outward", "inward"] = "outward"
    branch: Literal["auto", -1, 1] = "auto"


class SixLegCircles(PairedCircles):
    actuator: ActuatorTemplate


class SixLegSpec(_Common):
    """Generic six-leg mechanism: explicit ``legs`` or a ``generator``."""

    family: Literal["sixleg"]
    stroke: Stroke | None = Field(None, description="shared actuator window [min, max] of "
                                  "prismatic and slider legs (lengths)")
    servo_range: AngleWindow | None = Field(None, description="shared servo-angle window "
                                            "[min, max] of crank legs (deg or with units)")
    legs: list[LegSpec] | None = Field(None, min_length=6, max_length=6)
    generator: SixLegCircles | None = None

    def build(self) -> Mechanism:
        if self.base_points is not None or self.platform_points is not None:
            raise ParameterError("base_points", "absent for family sixleg (declare 'legs' or "
                                 "a 'generator')", "given")
        if (self.legs is None) == (self.generator is None):
            raise ParameterError("legs", "given alone: either six legs or a generator",
                                 "both" if self.legs else "neither")
        kw = self._kw()
        if self.generator is not None:
            g = self.generator.model_dump()
            a = g.pop("actuator")
            stroke = self._window(a["kind"] == "crank")
            b = a.pop("branch")
            branch = None if b == "auto" else float(b)
            return paired_sixleg(actuator=a.pop("kind"), **g, **a, branch=branch,
                                 stroke=stroke, tool_offset=self.tool_offset, **kw)
        acts = [leg.actuator for leg in self.legs]
        kinds = [a.kind for a in acts]
        stroke = self._window(all(k == "crank" for k in kinds))
        z3 = [0.0, 0.0, 0.0]
        return SixLeg([leg.base for leg in self.legs], [leg.platform for leg in self.legs],
                      kinds, [getattr(a, "axis", z3) for a in acts],
                      [getattr(a, "zero_direction", z3) for a in acts],
                      [getattr(a, "crank_length", 0.0) for a in acts],
                      [getattr(a, "link_length", getattr(a, "rod_length", 0.0)) for a in acts],
                      stroke, [float(getattr(a, "branch", -1)) for a in acts],
                      self.tool_offset, **kw)

    def _window(self, cranks: bool) -> list[float]:
        given, other = ("servo_range", "stroke") if cranks else ("stroke", "servo_range")
        if getattr(self, other) is not None:
            raise ParameterError(other, f"absent: these legs take '{given}' (" + (
                "servo angles" if cranks else "lengths") + ")", "given")
        if getattr(self, given) is None:
            raise ParameterError(given, "given: the legs' shared actuator window [min, max]",
                                 None)
        return getattr(self, given)
