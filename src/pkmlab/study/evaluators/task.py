"""``task``: a required workspace (a region of tool positions × an orientation set) and how
far it is contained (:mod:`pkmlab.requirements.task`)."""

from __future__ import annotations

from ...requirements.spec import TaskSpec, build_task
from ...requirements.task import task_margins
from .registry import Evaluator, metric, register_evaluator


class Task(Evaluator):
    name = "task"
    block = TaskSpec
    description = ("a required workspace: shape (box, cylinder, points), size / radius + "
                   "height / points or file, frame, centre, and an orientation set")
    requires = frozenset({"spatial"})        # an orientation set on six coordinates
    metrics = (
        metric("task_contained", "", "flag",
               "1 if every position of the task region works at every orientation of its "
               "set (psu6/ups6: proved over the continuous region and the continuous "
               "orientation set, 0 with a note if undecided; luzi3: sampled, see notes)"),
        metric("task_margin", "mm", "bound",
               "largest growth of the task region that stays contained (a lower bound of its "
               "distance to the workspace boundary, bracket 0.01 mm); negative: the erosion "
               "needed"),
        metric("task_orientation_margin", "deg", "bound",
               "largest widening of the task's orientation set that stays contained (bracket "
               "0.01°); negative: the narrowing needed"),
    )

    def plan(self, data, base):
        return build_task(data, base)

    def written(self, plan):
        return plan.source

    def compute(self, mech, ctx) -> dict:
        plan = ctx.evaluation.task
        m = task_margins(mech, plan.region, plan.orientations, plan.resolution)
        chk = m["check"]
        if chk.note:
            ctx.notes["task_contained"] = chk.note
        ctx.notes.update(m["notes"])
        return {"task_contained": float(chk.contained), "task_margin": m["margin_mm"],
                "task_orientation_margin": m["orientation_margin_deg"]}


register_evaluator(Task())
