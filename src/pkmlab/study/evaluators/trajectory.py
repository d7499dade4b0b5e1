"""``trajectory``: Hopkins & Williams' ±2 in / ±30° paper motion against the stroke."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...motion import check_trajectory, paper_motion
from ...tolerances import TOL
from .registry import Evaluator, finite, metric, register_evaluator


class TrajectorySpec(BaseModel):
    """The paper motion: seconds per segment, payload mass."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    paper_motion: Literal[True] = True
    segment_time: float = Field(1.0, gt=0, allow_inf_nan=False, description="s per segment")
    payload: float = Field(0.0, ge=0, allow_inf_nan=False, description="payload mass (kg)")


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
               "smallest stroke margin along that motion (negative: the overshoot)"),
    )

    def compute(self, mech, ctx) -> dict:
        plan = ctx.evaluation.trajectory
        motion = paper_motion(mech, segment_time=plan.segment_time)
        t, X = motion.t, motion.poses
        rep = check_trajectory(mech, t, X, payload_mass_kg=plan.payload)
        margins = np.concatenate([rep.margin_low, rep.margin_high])
        # a motion that uses exactly 100 % of the stroke has a margin of round-off size
        # (−1.4e-13 mm): within the stroke round-off tolerance it reads 0
        margin = float(np.min(margins)) if np.all(np.isfinite(margins)) else None
        if margin is not None and abs(margin) <= TOL.stroke_roundoff_mm:
            margin = 0.0
        out = {"paper_motion_fits": float(rep.fits),
               "paper_motion_margin": None if margin is None else finite(margin)}
        if out["paper_motion_margin"] is None:
            ctx.notes["paper_motion_margin"] = "a pose of the motion has no inverse kinematics"
        return out


register_evaluator(Trajectory())
