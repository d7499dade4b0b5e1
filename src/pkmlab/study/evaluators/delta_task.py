"""``delta_task``: whether a delta robot's feasible set contains a required task cylinder
(guaranteed, by the octree of the delta volume bracket), and its conditioning and speed over
that cylinder (sampled)."""

from __future__ import annotations

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...errors import ParameterError
from ...mechanisms.families.delta_task import contains_cylinder, cylinder_samples
from .registry import Evaluator, metric, register_evaluator


class DeltaTaskSpec(BaseModel):
    """A vertical task cylinder (mm): its radius, its bottom and top heights (tool point) and
    its axis (x, y); ``samples`` per radius of the conditioning grid."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    radius: float = Field(gt=0, allow_inf_nan=False, description="cylinder radius (mm)")
    z_min: float = Field(allow_inf_nan=False, description="bottom height (mm)")
    z_max: float = Field(allow_inf_nan=False, description="top height (mm)")
    centre: tuple[float, float] = Field((0.0, 0.0), description="axis position x, y (mm)")
    samples: int = Field(6, ge=2, le=40, description="grid points per radius and height")


class DeltaTask(Evaluator):
    name = "delta_task"
    block = DeltaTaskSpec
    description = DeltaTaskSpec.__doc__
    metrics = (
        metric("delta_task_contained", "", "guaranteed",
               "1 if the task cylinder is proven inside the feasible set, 0 if a position of "
               "it is proven outside (null with a note when the search stops undecided)"),
        metric("sampled_delta_task_kappa_max", "", "sampled",
               "largest condition number of the 3 × 3 Jacobian over a grid of the cylinder"),
        metric("sampled_delta_task_speed_max", "mm/s per unit/s", "sampled",
               "largest tool speed per unit actuator speed (the largest column norm of J⁻¹) "
               "over the same grid"),
    )

    def check(self, plan, evaluation, mech) -> None:
        if mech.family not in ("delta3", "ldelta3"):
            raise ParameterError("evaluate.delta_task", "used with a delta robot (families "
                                 "'delta3', 'ldelta3')", mech.family)
        if not plan.z_min < plan.z_max:
            raise ParameterError("evaluate.delta_task.z_max", "above z_min",
                                 [plan.z_min, plan.z_max])

    def compute(self, mech, ctx) -> dict:
        plan = ctx.evaluation.delta_task
        ok, why = contains_cylinder(mech, plan.centre, plan.radius, plan.z_min, plan.z_max)
        out = {"delta_task_contained": None if ok is None else float(ok)}
        if why:
            ctx.notes["delta_task_contained"] = why
        P = cylinder_samples(plan.centre, plan.radius, plan.z_min, plan.z_max, plan.samples)
        ik = mech.inverse(P)
        J = mech.jacobian(P)
        good = ik.valid & np.all(np.isfinite(J), axis=(1, 2))
        if not good.any():
            for n in ("sampled_delta_task_kappa_max", "sampled_delta_task_speed_max"):
                out[n] = None
                ctx.notes[n] = "no sample of the cylinder is feasible"
            return out
        s = np.linalg.svd(J[good], compute_uv=False)
        kappa = s[:, 0] / s[:, -1]
        out["sampled_delta_task_kappa_max"] = float(np.max(kappa)) if good.all() else None
        speed = np.linalg.norm(np.linalg.inv(J[good]), axis=1)
        out["sampled_delta_task_speed_max"] = float(np.max(speed))
        if not good.all():
            ctx.notes["sampled_delta_task_kappa_max"] = (
                f"{int((~good).sum())} of {len(P)} samples are infeasible")
        return out


register_evaluator(DeltaTask())
