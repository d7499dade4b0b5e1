"""``workspace``: the requested workspace (kind, orientation set, grid, constraints) and its
volume; the :class:`~pkmlab.workspaces.WorkspaceResult` is kept in the context for the
evaluators computed over it."""

from __future__ import annotations

from ...config import WorkspaceSpec, to_display, workspace_spec
from ...workspaces import workspace
from ...workspaces.engine import SINGULAR_NOTE, request_cost
from .registry import Cost, Evaluator, metric, register_evaluator


class Workspace(Evaluator):
    name = "workspace"
    block = WorkspaceSpec
    description = "a workspace request (see 'pkmlab workspace'): kind, box or tilt, ..."
    #: a constant workspace at the nominal orientation serves any mobility; other kinds and
    #: orientations need a free rotation (:meth:`requirements`)
    requires = frozenset()
    absent = None
    metrics = (
        metric("workspace_volume", "cm³", "grid",
               "volume of the requested workspace (exact in z, x-y grid and sampled "
               "orientation set; error in workspace_volume_error)"),
        metric("workspace_volume_error", "cm³", "grid",
               "error estimate of workspace_volume: content of the boundary columns"),
        metric("constant_volume", "cm³", "grid",
               "workspace_volume when the requested kind is 'constant'"),
        metric("reachable_volume", "cm³", "grid",
               "workspace_volume when the requested kind is 'reachable'"),
        metric("dexterous_volume", "cm³", "grid",
               "workspace_volume when the requested kind is 'dexterous'"),
        metric("workspace_empty", "", "flag", "1 if the requested workspace is empty"),
        metric("z_span", "mm", "grid", "height of the workspace (0 when empty)"),
    )

    def plan(self, data, base):
        return workspace_spec(data, prefix="evaluate.workspace.")

    def written(self, plan):
        return to_display(plan)

    def requirements(self, plan) -> frozenset[str]:
        """An orientation set, or a constant orientation off the nominal one, needs a free
        rotation (a translational mechanism has constant-orientation workspaces only)."""
        turned = plan.orientation is not None and any(a != 0 for a in plan.orientation)
        return frozenset({"rotations"}) if plan.kind != "constant" or turned else frozenset()

    def cost(self, plan, evaluation, mech) -> list[Cost]:
        """The grid's arrays and leg evaluations (:func:`~pkmlab.workspaces.engine.request_cost`)
        scale as ``resolution ** -2`` (exact columns) or ``** -3`` (sampled voxels)."""
        need, secs, got, exponent = request_cost(mech, **evaluation.request)
        return [Cost("evaluate.workspace.resolution", plan.resolution, "mm", -exponent, need,
                     secs, got)]

    def compute(self, mech, ctx) -> dict:
        res = workspace(mech, **ctx.evaluation.request)
        ctx.result = res
        vol = res.volume / 1e3
        zr = res.metrics()["z_range_mm"]
        out = {"workspace_volume": vol, "workspace_volume_error": res.volume_error / 1e3,
               "workspace_empty": float(res.empty),
               "z_span": 0.0 if zr is None else float(zr[1] - zr[0])}
        out[f"{res.kind}_volume"] = vol
        for note in res.notes:
            if note.startswith(SINGULAR_NOTE):
                ctx.notes["workspace_volume"] = note
        return out


register_evaluator(Workspace())
