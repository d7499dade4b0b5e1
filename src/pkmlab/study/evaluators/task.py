"""``task``: a required workspace (a region of tool positions × an orientation set) and how
far it is contained (:mod:`pkmlab.requirements.task`)."""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from ...requirements.placement import TASK_KAPPA_WARN, place_task, task_kappa
from ...requirements.spec import TaskSpec, build_task
from ...requirements.task import task_margins
from .registry import Cost, Evaluator, metric, register_evaluator

#: the task's cost model: bytes and seconds per orientation sample, fixed seconds
TASK_BYTES_PER_ORIENTATION = 4096.0
TASK_SECONDS_PER_ORIENTATION = 4e-4
TASK_SECONDS = 1.0

log = logging.getLogger(__name__)


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
        *(metric(f"task_centre_{c}", "mm", "search",
                 f"{c} of the task's centre in its frame: the given value, or with "
                 "task.centre: auto the best a search found (pkmlab.requirements.placement; "
                 "the position margin maximised, not a proven optimum)") for c in "xyz"),
        metric("sampled_task_kappa", "", "sampled",
               "worst κ (Jacobian homogenised with Angeles' length) at the task's corners "
               f"and centre × its orientation samples; above {TASK_KAPPA_WARN:g} the summary "
               "and report flag poor conditioning at the task"),
    )

    def plan(self, data, base):
        return build_task(data, base)

    def written(self, plan):
        return plan.source

    def cost(self, plan, evaluation, mech) -> list[Cost]:
        """The containment proof and the margin searches work orientation by orientation:
        memory and time grow with the orientation samples (``samples ** d`` for a set of
        ``d`` angles; measured on the 6-UPS: 1.9 kB and 0.11 ms per orientation beyond
        0.8 s; the constants err large)."""
        params = plan.orientations.parameters()
        M = len(params)
        d = max(1, int(np.sum(np.ptp(params, axis=0) > 0))) if M > 1 else 1
        n = plan.orientations.samples
        return [Cost("evaluate.task.samples", float(n), "", float(d),
                     M * TASK_BYTES_PER_ORIENTATION,
                     TASK_SECONDS + M * TASK_SECONDS_PER_ORIENTATION,
                     f"{n} samples per angle ({M} orientations)", integer=True)]

    def compute(self, mech, ctx) -> dict:
        plan = ctx.evaluation.task
        region = plan.region
        if any(plan.auto):
            placed = place_task(mech, region, plan.auto, plan.orientations, plan.resolution)
            region = dataclasses.replace(region, centre=placed.centre)
            for c, a in zip("xyz", plan.auto):
                if a:
                    ctx.notes[f"task_centre_{c}"] = placed.note
        ctx.task_centre = np.asarray(region.centre, dtype=float) + region.offset(mech)
        m = task_margins(mech, region, plan.orientations, plan.resolution)
        chk = m["check"]
        if chk.note:
            ctx.notes["task_contained"] = chk.note
        ctx.notes.update(m["notes"])
        kappa, _, knote = task_kappa(mech, region, plan.orientations)
        ctx.notes["sampled_task_kappa"] = knote
        if not kappa <= TASK_KAPPA_WARN:
            log.debug("poor conditioning at the task: κ %.3g above %g (%s)", kappa,
                        TASK_KAPPA_WARN, knote)
        out = {"task_contained": float(chk.contained), "task_margin": m["margin_mm"],
               "task_orientation_margin": m["orientation_margin_deg"],
               "sampled_task_kappa": kappa if np.isfinite(kappa) else None}
        if not np.isfinite(kappa):
            ctx.notes["sampled_task_kappa"] = ("singular at a probe pose of the task; "
                                               if kappa == np.inf else "") + knote
        out.update({f"task_centre_{c}": float(v) for c, v in zip("xyz", region.centre)})
        return out


register_evaluator(Task())
