"""``tripod_workspace``: the workspace of a mechanism with dependent coordinates (the 3-PRS
tripod: free ``z, θx, θy``; ``x, y, θz`` follow) over ``|θx|, |θy| <= tilt``, with the
guaranteed bracket of its (z, θx, θy) volume, the grid's sampled volume, and the parasitic
excursions: guaranteed upper bounds from interval enclosures over the bracket's boxes
(:mod:`pkmlab.workspaces.tripod_parasitic`) and the largest values over the grid's feasible
points (sampled, so never above the truth). Volumes are in mm·deg² (z in mm, both tilts in
degrees; 1 mm·rad² = 3282.8 mm·deg²)."""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...errors import ParameterError
from ...quantities import Angle, Length, PositiveLength
from .registry import Cost, Evaluator, metric, register_evaluator

#: mm·rad² → mm·deg²
DEG2 = math.degrees(1.0) ** 2
#: peak bytes per grid point (poses, IK values and statuses, occupancy, parasitic motions)
BYTES_PER_POINT = 240.0
#: seconds per grid point (3 legs' IK and the parasitic motions; slower end on one core)
SECONDS_PER_POINT = 1.5e-6
#: peak bytes per box of the bracket (live boxes, their split and the inner boxes kept)
BYTES_PER_BOX = 400.0


class TripodWorkspaceSpec(BaseModel):
    """The ``evaluate.tripod_workspace`` block: the tilt box, the optional z range, the
    grid's spacing and the bracket's target, wall-time budget and box budget."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    tilt: Angle = Field(description="half-range of θx and θy (deg), in (0, 90)")
    z_range: tuple[Length, Length] | None = Field(
        None, description="[min, max] z (mm); default every feasible z")
    resolution_z: PositiveLength = Field(5.0, description="grid spacing in z (mm)")
    resolution_angle: Angle = Field(math.radians(2.0), description="grid spacing of θx, θy "
                                    "(deg)")
    target: float = Field(0.02, gt=0, lt=1, allow_inf_nan=False,
                          description="relative width of the volume bracket to reach")
    budget: float = Field(10.0, gt=0, le=3600, allow_inf_nan=False,
                          description="wall-time budget of the bracket per candidate (s)")
    max_boxes: int = Field(1_000_000, ge=1000, le=50_000_000,
                           description="boxes of the bracket per level at most")
    parasitic_tolerance: float = Field(0.01, gt=0, lt=1, allow_inf_nan=False,
                                       description="relative gap of the parasitic bounds "
                                       "over the sampled values to refine to")


def _grid_points(plan, mech) -> int:
    if plan.z_range is not None:
        nz = math.floor(plan.z_range[1] / plan.resolution_z) - math.ceil(
            plan.z_range[0] / plan.resolution_z) + 1
    else:
        reach = float(mech.stroke[1] - mech.stroke[0]) + float(np.max(mech.link_length))
        nz = int(2 * reach / plan.resolution_z) + 2
    na = 2 * int(math.floor(plan.tilt / plan.resolution_angle + 1e-9)) + 1
    return max(nz, 0) * na * na


class TripodWorkspace(Evaluator):
    name = "tripod_workspace"
    block = TripodWorkspaceSpec
    description = TripodWorkspaceSpec.__doc__
    metrics = (
        metric("tripod_volume_lower", "mm·deg²", "guaranteed",
               "proven lower bound of the (z, θx, θy) volume of the feasible set with θx "
               "and θy within ±tilt (boxes proved feasible by interval arithmetic): the one "
               "to maximise"),
        metric("tripod_volume_upper", "mm·deg²", "guaranteed",
               "proven upper bound of the same volume"),
        metric("tripod_volume_bracket_width", "%", "guaranteed",
               "100·(upper − lower)/upper when the bracket stopped (target or budget; which "
               "one is in the notes)"),
        metric("sampled_tripod_volume", "mm·deg²", "sampled",
               "grid estimate of the same volume: feasible grid points × cell volume"),
        metric("parasitic_x_upper", "mm", "guaranteed",
               "proven upper bound of the largest magnitude of x (parasitic) over the "
               "feasible set (interval enclosure over the bracket's boxes)"),
        metric("parasitic_y_upper", "mm", "guaranteed",
               "proven upper bound of the largest magnitude of y (parasitic) over the "
               "feasible set"),
        metric("parasitic_theta_z_upper", "deg", "guaranteed",
               "proven upper bound of the largest magnitude of θz (parasitic) over the "
               "feasible set"),
        metric("sampled_parasitic_x_max", "mm", "sampled",
               "largest magnitude of x over the feasible grid points (a lower bound of the "
               "truth)"),
        metric("sampled_parasitic_y_max", "mm", "sampled",
               "largest magnitude of y over the feasible grid points"),
        metric("sampled_parasitic_theta_z_max", "deg", "sampled",
               "largest magnitude of θz over the feasible grid points"),
    )

    def written(self, plan):
        """Units explicit (a bare number in the file means degrees or mm)."""
        d = plan.model_dump()
        for k in ("tilt", "resolution_angle"):
            d[k] = f"{d[k]:.17g} rad"
        d["resolution_z"] = f"{d['resolution_z']:.17g} mm"
        if d["z_range"] is not None:
            d["z_range"] = [f"{z:.17g} mm" for z in d["z_range"]]
        return d

    def check(self, plan, evaluation, mech) -> None:
        mob = mech.mobility
        if not getattr(mob, "dependent", ()) or not hasattr(mech, "parasitic"):
            raise ParameterError("evaluate.tripod_workspace", "used with a mechanism with "
                                 "dependent coordinates (family 'prs3')",
                                 f"family {mech.family!r} ({mob.name} mobility: "
                                 f"{', '.join(mob.coordinates)}; none dependent)")
        if not 0 < plan.tilt < math.pi / 2:
            raise ParameterError("evaluate.tripod_workspace.tilt", "an angle in (0, 90) deg",
                                 f"{math.degrees(plan.tilt):g} deg")
        if not 0 < plan.resolution_angle <= plan.tilt:
            raise ParameterError("evaluate.tripod_workspace.resolution_angle",
                                 "an angle > 0 and at most the tilt",
                                 f"{math.degrees(plan.resolution_angle):g} deg")
        if plan.z_range is not None and not plan.z_range[0] < plan.z_range[1]:
            raise ParameterError("evaluate.tripod_workspace.z_range", "[min, max] with "
                                 "min < max", list(plan.z_range))

    def cost(self, plan, evaluation, mech) -> list[Cost]:
        """The grid (``resolution_z ** -1``, and ``resolution_angle ** -2``), the bracket's
        wall time (its ``budget``, which it does not overrun by more than a level) and its
        boxes (``max_boxes``)."""
        n = _grid_points(plan, mech)
        got = f"{n} grid points"
        return [Cost("evaluate.tripod_workspace.resolution_z", plan.resolution_z, "mm", -1,
                     n * BYTES_PER_POINT, n * SECONDS_PER_POINT, got),
                Cost("evaluate.tripod_workspace.budget", plan.budget, "s", 1,
                     0.0, plan.budget, f"{plan.budget:g} s"),
                Cost("evaluate.tripod_workspace.max_boxes", plan.max_boxes, "", 1,
                     plan.max_boxes * BYTES_PER_BOX, 0.0, f"{plan.max_boxes} boxes")]

    def compute(self, mech, ctx) -> dict:
        from ...workspaces.tripod import tripod_volume_bracket, tripod_workspace
        from ...workspaces.tripod_parasitic import parasitic_bounds

        plan = ctx.evaluation.tripod_workspace
        res = tripod_workspace(mech, plan.tilt, z_range=plan.z_range,
                               resolution_z=plan.resolution_z,
                               resolution_angle=plan.resolution_angle, bracket_target=None)
        br = tripod_volume_bracket(mech, plan.tilt, z_range=plan.z_range, target=plan.target,
                                   max_boxes=plan.max_boxes, budget_s=plan.budget)
        notes = ctx.notes
        out = {"tripod_volume_lower": br.lower * DEG2, "tripod_volume_upper": br.upper * DEG2,
               "tripod_volume_bracket_width": 100 * br.relative_width,
               "sampled_tripod_volume": res.volume * DEG2}
        if br.stop_reason != "converged":
            notes["tripod_volume_lower"] = (f"bracket stopped: {br.stop_reason} at "
                                            f"{100 * br.relative_width:.2f} % width")
        for note in res.notes:
            notes["sampled_tripod_volume"] = note
        P = res.parasitic[res.occupancy]
        if len(P):
            floor = np.max(np.abs(P), axis=0)
            out.update(sampled_parasitic_x_max=float(floor[0]),
                       sampled_parasitic_y_max=float(floor[1]),
                       sampled_parasitic_theta_z_max=math.degrees(floor[2]))
        else:
            floor = np.zeros(3)
            for n in ("sampled_parasitic_x_max", "sampled_parasitic_y_max",
                      "sampled_parasitic_theta_z_max"):
                out[n] = None
                notes[n] = "no feasible grid point (empty, or thinner than the grid)"
        names = ("parasitic_x_upper", "parasitic_y_upper", "parasitic_theta_z_upper")
        if br.upper == 0.0:
            for n in names:
                out[n] = None
                notes[n] = "the feasible set is proved empty (volume bracket [0, 0])"
            return out
        pb = parasitic_bounds(mech, np.concatenate([br.inner, br.undecided]), floor,
                              rtol=plan.parasitic_tolerance)
        if pb.empty:
            for n in names:
                out[n] = None
                notes[n] = "every box of the bracket is proved to hold no solution"
            return out
        out.update(parasitic_x_upper=float(pb.upper[0]), parasitic_y_upper=float(pb.upper[1]),
                   parasitic_theta_z_upper=math.degrees(pb.upper[2]))
        if not pb.converged:
            notes["parasitic_x_upper"] = (
                f"parasitic bounds stopped after {pb.levels} levels above the "
                f"{plan.parasitic_tolerance:.1%} tolerance: still guaranteed, less tight")
        return out


register_evaluator(TripodWorkspace())
