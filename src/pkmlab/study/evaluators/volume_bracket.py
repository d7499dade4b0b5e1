"""``volume_bracket``: a guaranteed bracket of the workspace's volume over the continuous
orientation set and positions (:mod:`pkmlab.workspaces.bracket.columns`)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from ...workspaces.bracket.columns import volume_bracket
from .registry import Evaluator, metric, register_evaluator

KINDS = ("constant", "reachable", "dexterous")


class VolumeBracketSpec(BaseModel):
    """Guaranteed volume bracket over the continuous orientation set (workspace_volume_lower /
    _upper): budget (s), target (relative width)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    budget: float = Field(2.0, gt=0, le=3600, allow_inf_nan=False,
                          description="wall-time budget per candidate (s)")
    target: float = Field(0.01, gt=0, lt=1, allow_inf_nan=False,
                          description="relative width (upper - lower) / upper to reach")


class VolumeBracket(Evaluator):
    name = "volume_bracket"
    block = VolumeBracketSpec
    description = VolumeBracketSpec.__doc__
    # six coordinates, or a family with its own position bracket (delta3, ldelta3)
    requires = frozenset({"bracket", "workspace"})
    after = ("workspace",)
    metrics = (
        metric("workspace_volume_lower", "cm³", "guaranteed",
               "proven lower bound of the requested workspace's volume over the continuous "
               "orientation set and positions (stroke and connectivity; psu6, ups6, luzi3, "
               "rss6): the one to maximise"),
        metric("workspace_volume_upper", "cm³", "guaranteed",
               "proven upper bound of the same volume: the one to constrain from above"),
        metric("workspace_volume_bracket_width", "%", "guaranteed",
               "100·(upper − lower)/upper when the bracket stopped (target or budget; which "
               "one is in the notes)"),
        *[metric(f"{k}_volume_{b}", "cm³", "guaranteed",
                 f"workspace_volume_{b} when the requested kind is '{k}'")
          for k in KINDS for b in ("lower", "upper")],
    )

    def compute(self, mech, ctx) -> dict:
        plan = ctx.evaluation.volume_bracket
        req = ctx.evaluation.request
        b = volume_bracket(mech, req["kind"], req["orientations"], req["resolution"],
                           req["constraints"], target=plan.target, budget_s=plan.budget)
        lo, hi = b.lower / 1e3, b.upper / 1e3
        k = req["kind"]
        if b.stop_reason != "converged":
            ctx.notes["workspace_volume_lower"] = (
                f"bracket stopped: {b.stop_reason} at {100 * b.relative_width:.2f} % width "
                f"(final cell {b.resolution:g} mm)")
        for n in b.notes:
            ctx.notes["workspace_volume_upper"] = n
        return {"workspace_volume_lower": lo, "workspace_volume_upper": hi,
                "workspace_volume_bracket_width": 100 * b.relative_width,
                f"{k}_volume_lower": lo, f"{k}_volume_upper": hi}


register_evaluator(VolumeBracket())
