"""``actuators``: the chosen catalogue actuator against force, speed, torque–speed and stroke
along every required motion (:mod:`pkmlab.requirements.actuators`)."""

from __future__ import annotations

from ...errors import ParameterError
from ...requirements.actuators import fit as actuator_fit
from ...requirements.spec import ActuatorsSpec, build_actuators
from ...units import ROTARY_DISPLAY
from .registry import Evaluator, metric, register_evaluator


class Actuators(Evaluator):
    name = "actuators"
    block = ActuatorsSpec
    description = "catalogue + use, or spec"
    requires = frozenset({"motions"})
    after = ("motions",)        # reads the inverse dynamics of the required motions
    metrics = (
        metric("actuators_fit", "", "flag",
               "1 if the chosen actuator meets force, speed, torque–speed and stroke along "
               "every required motion"),
        metric("actuator_force_margin", "%", "worst-case",
               "100·(1 − peak |force| / force limit); negative: exceeded"),
        metric("actuator_speed_margin", "%", "worst-case",
               "100·(1 − peak |speed| / speed limit); negative: exceeded"),
        metric("actuator_torque_speed_margin", "%", "worst-case",
               "100·min over samples of (available − required motor torque) / peak curve "
               "torque"),
        metric("actuator_stroke_margin", "mm", "worst-case",
               "actuator travel − the largest travel an actuator uses over the motions; "
               "linear actuators only, null for rotary ones (actuator_angle_margin)"),
        metric("actuator_force_rating", "N", "exact",
               "force limit of the chosen actuator (its size); linear actuators only, null "
               "for rotary ones (actuator_torque_rating)"),
        metric("actuator_angle_margin", "deg", "worst-case",
               "servo angle range − the largest angle range a servo uses over the motions; "
               "rotary actuators only"),
        metric("actuator_torque_rating", "N·m", "exact",
               "torque limit of the chosen servo (its size); rotary actuators only"),
    )

    def plan(self, data, base):
        return build_actuators(data, base)

    def written(self, plan):
        return plan.source

    def requirements(self, plan):
        """The motions, and actuators of the default entry's kind."""
        return frozenset({"motions", f"{plan.catalogue[plan.default].kind} actuator"})

    def compute(self, mech, ctx) -> dict:
        plan = ctx.evaluation.actuators
        name = ctx.choices.get("actuator", plan.default)
        spec = plan.catalogue[name]
        if (spec.kind == "rotary") != (mech.actuator_unit == "rad"):
            need = "rotary" if mech.actuator_unit == "rad" else "linear"
            raise ParameterError("evaluate.actuators", f"a {need} actuator for family "
                                 f"{mech.family!r}", f"{spec.name} ({spec.kind})")
        f = actuator_fit(spec, ctx.dynamics)
        ctx.notes.update(f.notes)
        out = {"actuators_fit": float(f.fits), "actuator_force_margin": f.force_margin,
               "actuator_speed_margin": f.speed_margin,
               "actuator_torque_speed_margin": f.torque_speed_margin}
        # one convention (pkmlab.units.actuator_display): a servo's size is a torque in
        # N·m and its travel an angle in deg (ActuatorFit gives the angle margin in deg)
        rotary = spec.kind == "rotary"
        size = ROTARY_DISPLAY.effort_scale * spec.force if rotary else spec.force
        pairs = (("actuator_stroke_margin", "actuator_angle_margin", f.stroke_margin),
                 ("actuator_force_rating", "actuator_torque_rating", size))
        for linear, turning, value in pairs:
            name, other = (turning, linear) if rotary else (linear, turning)
            out[name], out[other] = value, None
            if value is None and linear in f.notes:
                ctx.notes[name] = f.notes[linear]
            ctx.notes[other] = f"{spec.kind} actuator: see {name}"
        return out


register_evaluator(Actuators())
