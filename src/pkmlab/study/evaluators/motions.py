"""``motions``: required motions with the payload, by inverse dynamics
(:mod:`pkmlab.motion.dynamics`); the results are kept in the context for ``actuators``."""

from __future__ import annotations

import numpy as np

from ...errors import ParameterError
from ...motion import costs
from ...motion.dynamics import inverse_dynamics
from ...requirements.spec import MotionSpec, build_motions
from ...units import ROTARY_DISPLAY
from .registry import Cost, Evaluator, metric, register_evaluator

#: (linear actuators' metric, rotary actuators' metric, DynamicsResult.summary() key,
#: rotary display scale from internal units: :data:`pkmlab.units.ROTARY_DISPLAY`)
MOTION_METRICS = (("peak_actuator_force", "peak_actuator_torque", "peak_force",
                   ROTARY_DISPLAY.effort_scale),
                  ("rms_actuator_force", "rms_actuator_torque", "rms_force",
                   ROTARY_DISPLAY.effort_scale),
                  ("peak_actuator_speed", "peak_actuator_angular_speed", "peak_speed",
                   ROTARY_DISPLAY.rate_scale),
                  ("peak_actuator_power", "peak_actuator_power", "peak_power", 1.0))


class Motions(Evaluator):
    name = "motions"
    block = list[MotionSpec]
    description = "required motions: [{name, file | sinusoid | paper: true}]"
    requires = frozenset()        # Newton–Euler, balanced on the free coordinates
    metrics = (
        metric("motions_feasible", "", "flag",
               "1 if every sample of every required motion is within the stroke and not "
               "singular"),
        metric("peak_actuator_force", "N", "worst-case",
               "largest |actuator force| over every sample of every required motion "
               "(Newton–Euler of platform + payload + legs, f = J⁻ᵀ·w); linear actuators "
               "only, null for rotary ones (peak_actuator_torque)"),
        metric("rms_actuator_force", "N", "worst-case",
               "largest RMS actuator force (time-weighted, per actuator and motion); linear "
               "actuators only"),
        metric("peak_actuator_speed", "mm/s", "worst-case",
               "largest |actuator speed| over every sample of every required motion; linear "
               "actuators only, null for rotary ones (peak_actuator_angular_speed)"),
        metric("peak_actuator_torque", "N·m", "worst-case",
               "largest |servo torque| over every sample of every required motion "
               "(τ = J⁻ᵀ·w); rotary actuators only, null for linear ones"),
        metric("rms_actuator_torque", "N·m", "worst-case",
               "largest RMS servo torque (time-weighted, per actuator and motion); rotary "
               "actuators only"),
        metric("peak_actuator_angular_speed", "deg/s", "worst-case",
               "largest |servo angular speed| over every sample of every required motion; "
               "rotary actuators only"),
        metric("peak_actuator_power", "W", "worst-case",
               "largest |actuator force × speed| (rotary: torque × angular speed) over every "
               "sample of every required motion"),
    )

    def plan(self, data, base):
        return build_motions(data, base)

    def written(self, plan):
        return plan.source

    def check(self, plan, evaluation, mech) -> None:
        if evaluation.payload is None:
            raise ParameterError("evaluate.payload", "given with evaluate.motions (the mass "
                                 "the motions move: payload and platform)", None)
        plan.check_mobility(mech)
        for s in plan.specs:
            if s.frame == "task" and evaluation.task is None:
                raise ParameterError(f"evaluate.motions.{s.name}.frame", "'task' given with "
                                     "an evaluate.task block (the centre it is relative to)",
                                     s.frame)

    def cost(self, plan, evaluation, mech) -> list[Cost]:
        """Every motion and its inverse dynamics are kept for ``actuators``: memory and time
        scale with the samples of all motions; the motion with the most samples is named, with
        the setting that drives it (rate for the generators, duration for a sinusoid)."""
        n = [costs.motion_samples(s, plan.recorded) for s in plan.specs]
        total = sum(n)
        i = max(range(len(n)), key=n.__getitem__)
        s = plan.specs[i]
        need = (total * costs.MOTION_BYTES_PER_SAMPLE
                + max(n) * costs.DYNAMICS_PEAK_BYTES_PER_SAMPLE)
        secs = total * costs.DYNAMICS_SECONDS_PER_SAMPLE
        got = (f"{len(n)} motions, {total:.3g} samples in all ({s.name!r}: {n[i]:.3g})")
        if s.file is not None:       # rows are limited by the CSV reader; name the list
            return [Cost("evaluate.motions", float(len(n)), "motions", 1.0, need, secs, got,
                         integer=True)]
        if s.sinusoid is not None:
            return [Cost(f"evaluate.motions[{i}].duration", s.duration, "s", 1.0, need, secs,
                         got)]
        return [Cost(f"evaluate.motions[{i}].rate", s.rate, "Hz", 1.0, need, secs, got)]

    def compute(self, mech, ctx) -> dict:
        ev = ctx.evaluation
        body = ev.payload.for_mechanism(mech)
        ctx.dynamics = [inverse_dynamics(mech, m, body) for m in
                        ev.motions.motions(mech, getattr(ctx, "task_centre", None))]
        bad = [r.first_problem() for r in ctx.dynamics if not np.all(r.ok)]
        out = {"motions_feasible": float(not bad)}
        if bad:
            ctx.notes["motions_feasible"] = bad[0]
        sums = [r.summary() for r in ctx.dynamics if np.any(r.ok)]
        rotary = mech.actuator_unit == "rad"
        for linear, turning, key, scale in MOTION_METRICS:
            name, other = (turning, linear) if rotary else (linear, turning)
            k = scale if rotary else 1.0
            out[name] = float(max(np.max(s[key]) for s in sums)) * k if sums else None
            if not sums:
                ctx.notes[name] = "no feasible sample in any motion"
            elif not np.isfinite(out[name]):        # never a silent null
                out[name] = None
                out["motions_feasible"] = 0.0
                ctx.notes[name] = ctx.notes["motions_feasible"] = "a value is not finite"
            if other != name:
                out[other] = None
                ctx.notes[other] = (f"{'rotary' if rotary else 'linear'} actuators: see "
                                    f"{name}")
        return out


register_evaluator(Motions())
