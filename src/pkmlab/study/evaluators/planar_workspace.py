"""``planar_workspace``: the workspace area of a planar mechanism (3-RPR, five-bar) with its
guaranteed bracket (:mod:`pkmlab.workspaces.planar`) and its conditioning over the sampled
cells (κ of the Jacobian homogenised with Angeles' characteristic length where a rotation is
free, of J itself otherwise)."""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ... import dexterity as dx
from ...errors import NumericalError, ParameterError
from ...quantities import Angle, PositiveLength
from .registry import Evaluator, finite, metric, register_evaluator


class PlanarWorkspaceSpec(BaseModel):
    """The ``evaluate.planar_workspace`` block."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    kind: Literal["constant", "reachable", "dexterous"] = "constant"
    phi: list[Angle] | None = Field(None, description="constant: [φ]; reachable / "
                                    "dexterous: [min, max] (deg); default the nominal φ")
    resolution: PositiveLength = Field(5.0, description="grid spacing (mm)")
    samples: int = Field(9, ge=1, le=181, description="orientations of the range sampled")
    target: float = Field(0.01, gt=0, description="relative width of the area bracket")
    max_depth: int = Field(6, ge=0, le=10, description="bracket refinement levels at most")


def _phi(plan):
    if plan.phi is None:
        return None
    if len(plan.phi) not in (1, 2) or (plan.kind == "constant") != (len(plan.phi) == 1):
        raise ParameterError("evaluate.planar_workspace.phi", "[φ] for kind 'constant', "
                             "[min, max] otherwise", [math.degrees(a) for a in plan.phi])
    return plan.phi[0] if len(plan.phi) == 1 else tuple(plan.phi)


class PlanarWorkspace(Evaluator):
    name = "planar_workspace"
    block = PlanarWorkspaceSpec
    description = "area of a planar mechanism's workspace, bracket and conditioning"
    metrics = (
        metric("planar_area", "cm²", "grid",
               "area estimate: the grid count of feasible cell centres × h² (reachable / "
               "dexterous: at the sampled orientations)"),
        metric("planar_area_lower", "cm²", "guaranteed",
               "lower end of the guaranteed area bracket (cells proved feasible)"),
        metric("planar_area_upper", "cm²", "guaranteed",
               "upper end of the guaranteed area bracket"),
        metric("planar_area_exact", "cm²", "exact",
               "exact area where the set is an intersection of annuli (constant kind); null "
               "otherwise"),
        metric("gci_planar", "", "sampled",
               "mean 1/κ over the feasible sampled cells and orientations"),
        metric("sampled_planar_worst_kappa", "", "sampled",
               "largest κ over the feasible sampled cells and orientations"),
    )

    def written(self, plan):
        """Units explicit: φ is held in rad, and a bare number in the file means degrees."""
        d = plan.model_dump()
        if d["phi"] is not None:
            d["phi"] = [f"{a:.17g} rad" for a in d["phi"]]
        d["resolution"] = f"{d['resolution']:.17g} mm"
        return d

    def check(self, plan, evaluation, mech) -> None:
        mob = mech.mobility.coordinates
        if mob[:2] != ("x", "y") or "z" in mob or not hasattr(mech, "planar_cell_margins"):
            raise ParameterError("evaluate.planar_workspace", "a block for a planar mechanism "
                                 "(free x, y and optionally theta_z)",
                                 f"family {mech.family!r} ({', '.join(mob)})")
        if plan.kind != "constant" and "theta_z" not in mob:
            raise ParameterError("evaluate.planar_workspace.kind", "'constant' for a "
                                 "mechanism without a free rotation", plan.kind)
        _phi(plan)

    def compute(self, mech, ctx) -> dict:
        from ...workspaces.planar import planar_workspace

        plan = ctx.evaluation.planar_workspace
        res = planar_workspace(mech, plan.kind, _phi(plan), plan.resolution,
                               samples=plan.samples, target=plan.target,
                               max_depth=plan.max_depth)
        for note in res.notes:
            ctx.notes["planar_area_upper"] = note
        out = {"planar_area": res.estimate / 100, "planar_area_lower": res.lower / 100,
               "planar_area_upper": res.upper / 100,
               "planar_area_exact": None if res.exact is None else res.exact / 100}
        if res.exact is None:
            ctx.notes["planar_area_exact"] = "not an intersection of annuli, or not constant"
        length = dx.resolve_length(mech)
        if length.status == "fallback":
            raise NumericalError("characteristic length", length.reason)
        idx = np.argwhere(res.occupancy)
        if not len(idx):
            ctx.notes["gci_planar"] = ctx.notes["sampled_planar_worst_kappa"] = "empty workspace"
            return {**out, "gci_planar": None, "sampled_planar_worst_kappa": None}
        lo, hi = res.phi
        phis = np.linspace(lo, hi, plan.samples) if hi > lo else np.array([lo])
        X = np.repeat(mech.nominal_pose[None], len(idx) * len(phis), axis=0)
        X[:, 0] = np.repeat(res.xs[idx[:, 0]], len(phis))
        X[:, 1] = np.repeat(res.ys[idx[:, 1]], len(phis))
        X[:, 5] = np.tile(phis, len(idx))
        ok = mech.inverse(X).valid
        kap = dx.condition_number(mech.jacobian(X[ok]), length)
        out["gci_planar"] = float(np.mean(1.0 / kap))
        out["sampled_planar_worst_kappa"] = finite(np.max(kap))
        if out["sampled_planar_worst_kappa"] is None:
            ctx.notes["sampled_planar_worst_kappa"] = "a sampled pose is singular"
        return out


register_evaluator(PlanarWorkspace())
