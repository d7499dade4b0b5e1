"""``trajectory``: Hopkins & Williams' ±2 in / ±30° paper motion against the stroke."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from ...limits import MASS_MAX_KG, SEGMENT_TIME_S
from ...motion import costs, trajectory_fit
from ...motion.costs import paper_samples
from ...motion.paper import paper_motion_poses
from ...tolerances import TOL
from ...units import actuator_display
from .registry import Cost, Evaluator, finite, metric, register_evaluator

#: sample rate of the paper motion checked (paper_motion's default)
PAPER_RATE_HZ = 100.0


class TrajectorySpec(BaseModel):
    """The paper motion: seconds per segment. The metrics are kinematic (stroke fit and
    margin): ``payload`` is accepted only as 0 kg, since a mass would change neither; forces
    along the paper's motion come from ``motions: [{paper: true}]`` with ``payload:``."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    paper_motion: Literal[True] = True
    segment_time: float = Field(1.0, ge=SEGMENT_TIME_S[0], le=SEGMENT_TIME_S[1],
                                allow_inf_nan=False, description="s per segment")
    payload: float = Field(0.0, ge=0, le=MASS_MAX_KG, allow_inf_nan=False,
                           description="0 kg only: the paper-motion metrics are kinematic")

    @field_validator("payload")
    @classmethod
    def _kinematic(cls, v: float) -> float:
        if v != 0.0:
            raise ValueError("must be 0 kg (paper_motion_fits and its margin are kinematic: a "
                             "payload changes neither; for forces along the paper's motion use "
                             f"motions: [{{paper: true}}] with payload:); got {v:g} kg")
        return v


class Trajectory(Evaluator):
    name = "trajectory"
    block = TrajectorySpec
    description = TrajectorySpec.__doc__
    # the motion moves each of the mechanism's free coordinates in turn (±30° for an angle)
    requires = frozenset()
    absent = None
    metrics = (
        metric("paper_motion_fits", "", "flag",
               "1 if Hopkins & Williams' ±2 in / ±30° motion stays within the stroke"),
        metric("paper_motion_margin", "mm", "exact",
               "smallest stroke margin along that motion (negative: the overshoot); linear "
               "actuators only, null for rotary ones (paper_motion_angle_margin)"),
        metric("paper_motion_angle_margin", "deg", "exact",
               "smallest servo angle margin along that motion (negative: the overshoot); "
               "rotary actuators only"),
    )

    def cost(self, plan, evaluation, mech) -> list[Cost]:
        """The paper motion at 100 Hz, checked sample by sample: time and memory scale with
        ``segment_time`` (:func:`~pkmlab.motion.costs.paper_samples`)."""
        n = paper_samples(plan.segment_time, PAPER_RATE_HZ)
        return [Cost("evaluate.trajectory.segment_time", plan.segment_time, "s", 1.0,
                     n * costs.TRAJECTORY_BYTES_PER_SAMPLE,
                     n * costs.TRAJECTORY_SECONDS_PER_SAMPLE,
                     f"{plan.segment_time:g} s ({n:.3g} samples at {PAPER_RATE_HZ:g} Hz)")]

    def compute(self, mech, ctx) -> dict:
        plan = ctx.evaluation.trajectory
        # the motion's times and poses (its rates and twists are not read here)
        t, X = paper_motion_poses(mech, segment_time=plan.segment_time, rate_hz=PAPER_RATE_HZ)
        # check_trajectory's fits and margins only (no limits: the payload changes neither)
        rep = trajectory_fit(mech, t, X)
        margins = np.concatenate([rep.margin_low, rep.margin_high])
        # a motion that uses exactly 100 % of the stroke has a margin of round-off size
        # (−1.4e-13 mm): within the stroke round-off tolerance it reads 0
        margin = float(np.min(margins)) if np.all(np.isfinite(margins)) else None
        if margin is not None and abs(margin) <= TOL.stroke_roundoff_mm:
            margin = 0.0
        # one convention (pkmlab.units.actuator_display): a servo's margin is an angle in deg
        shown = actuator_display(mech.actuator_unit)
        name, other = (("paper_motion_angle_margin", "paper_motion_margin") if shown.rotary
                       else ("paper_motion_margin", "paper_motion_angle_margin"))
        out = {"paper_motion_fits": float(rep.fits),
               name: None if margin is None else finite(shown.value_scale * margin),
               other: None}
        if out[name] is None:
            ctx.notes[name] = "a pose of the motion has no inverse kinematics"
        ctx.notes[other] = (f"{'rotary' if shown.rotary else 'linear'} actuators: "
                            f"see {name}")
        return out


register_evaluator(Trajectory())
