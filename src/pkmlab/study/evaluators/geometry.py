"""``geometry``: the footprint and the actuator travel, always evaluated (no block)."""

from __future__ import annotations

import math

from .registry import Evaluator, metric, register_evaluator


class Geometry(Evaluator):
    name = "geometry"
    block = None
    description = "footprint and actuator travel (always)"
    metrics = (
        metric("base_outer_radius", "mm", "exact",
               "footprint: largest horizontal distance of a base joint from the base z axis"),
        metric("platform_outer_radius", "mm", "exact",
               "largest distance of a platform joint from the platform joints' centroid"),
        metric("stroke_length", "mm", "exact",
               "prismatic actuator travel (max - min); null for rotary actuators "
               "(servo_range)"),
        metric("servo_range", "deg", "exact",
               "rotary actuator travel (max - min of the servo angle); null for prismatic "
               "actuators (stroke_length)"),
    )

    def compute(self, mech, ctx) -> dict:
        fp = mech.footprint()
        travel = float(mech.stroke[1] - mech.stroke[0])
        rotary = mech.actuator_unit == "rad"
        notes = {} if ctx is None else ctx.notes          # the geometry needs no context
        if rotary:
            notes["stroke_length"] = "rotary actuators: their travel is servo_range (deg)"
        else:
            notes["servo_range"] = "prismatic actuators: their travel is stroke_length (mm)"
        return {"base_outer_radius": fp["base_radius"],
                "platform_outer_radius": fp["platform_radius"],
                "stroke_length": None if rotary else travel,
                "servo_range": math.degrees(travel) if rotary else None}


register_evaluator(Geometry())
