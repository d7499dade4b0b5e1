"""``payload``: the mass the platform carries (used by ``motions``), and the peak static servo
torque holding it over the workspace (:mod:`pkmlab.requirements.static`)."""

from __future__ import annotations

from ...requirements.spec import PayloadSpec, build_payload
from ...requirements.static import static_loads
from ...units import ROTARY_DISPLAY
from .registry import Evaluator, metric, register_evaluator


class Payload(Evaluator):
    name = "payload"
    block = PayloadSpec
    description = "mass, com, inertia; platform; legs"
    requires = frozenset()     # the gravity wrench, balanced on the free coordinates
    after = ("workspace",)      # the static torque is computed over it (skipped without one)
    metrics = (
        metric("peak_servo_torque", "N·m", "worst-case",
               "largest |servo torque| holding the payload at rest (τ = J⁻ᵀ·w, w the gravity "
               "wrench of payload + platform + leg-end masses) over every voxel × orientation "
               "sample of the workspace; rotary actuators only (null for prismatic)"),
    )

    def plan(self, data, base):
        return build_payload(data)

    def written(self, plan):
        return plan.source

    def compute(self, mech, ctx) -> dict:
        """Peak static servo torque over the workspace."""
        res = ctx.result
        if mech.actuator_unit != "rad":
            ctx.notes["peak_servo_torque"] = ("prismatic actuators: no servo torque (forces: "
                                              "peak_actuator_force with evaluate.motions)")
            return {"peak_servo_torque": None}
        if res.empty:
            ctx.notes["peak_servo_torque"] = "workspace empty"
            return {"peak_servo_torque": None}
        loads = static_loads(res.mechanism, res, ctx.evaluation.payload.for_mechanism(mech))
        if loads.singular:
            ctx.notes["peak_servo_torque"] = ("singular pose inside the workspace: unbounded "
                                              "torque")
            return {"peak_servo_torque": None}
        if loads.poses == 0:
            ctx.notes["peak_servo_torque"] = "no valid pose on the workspace grid"
            return {"peak_servo_torque": None}
        return {"peak_servo_torque": ROTARY_DISPLAY.effort_scale * loads.peak}   # N·m


register_evaluator(Payload())
