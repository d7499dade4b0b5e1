"""``needed_stroke``: the smallest actuator travel at which the workspace's simultaneous Euler
box has a dexterous position, bracketed over continuous positions."""

from __future__ import annotations

import dataclasses

from ...errors import ParameterError
from ...workspaces.optima.search import stroke_needed, supports_continuous
from .registry import Evaluator, metric, register_evaluator


class NeededStroke(Evaluator):
    name = "needed_stroke"
    block = bool
    description = ("the smallest actuator travel at which the workspace's simultaneous Euler "
                   "box (equal half-ranges) has a dexterous position, bracketed "
                   "(needed_stroke, _lower, _bracket)")
    # a travel in mm of prismatic actuators over an orientation box
    requires = frozenset({"rotations", "linear actuator", "workspace"})
    after = ("workspace",)
    metrics = (
        metric("needed_stroke", "mm", "bound",
               "smallest actuator travel (upper limit − lower limit, the lower limit kept) at "
               "which the workspace's simultaneous Euler box has a dexterous position: upper "
               "end of the bracket, a position certified for the continuous box (psu6, ups6, "
               "stroke only; null with a note otherwise): the one to minimise"),
        metric("needed_stroke_lower", "mm", "bound",
               "lower end of the bracket: below it a sample of the box (grid plus binding "
               "orientations found by local optimisation) admits no position, proved by "
               "branch and bound over continuous positions"),
        metric("needed_stroke_bracket", "mm", "bound",
               "needed_stroke - needed_stroke_lower (the search stops at 0.01 mm, or says in "
               "a note why it stopped wider)"),
    )

    def check(self, plan, evaluation, mech) -> None:
        o = evaluation.request["orientations"]
        if o.kind != "box" or o.semantics != "simultaneous" or len(set(o.angles)) != 1:
            raise ParameterError("evaluate.needed_stroke", "used with a simultaneous Euler "
                                 "box with equal half-ranges in evaluate.workspace",
                                 o.describe())

    def compute(self, mech, ctx) -> dict:
        """The needed travel over continuous positions (:func:`pkmlab.workspaces.optima.search.
        stroke_needed`), the lower limit of the workspace's actuator window kept; null with a
        note for other families or constraints, or when no upper limit up to the search's cap
        gives a position."""
        req = ctx.evaluation.request
        names = [m.name for m in self.metrics]
        why = None
        cons = req["constraints"].resolved(mech)
        if cons.stroke is not True:          # the workspace's window: its lower limit is kept
            mech = dataclasses.replace(mech, stroke_window=cons.stroke)
        if not supports_continuous(mech, req["constraints"]):
            why = (f"no continuous search for family {mech.family!r} or constraints beyond "
                   "the stroke")
        else:
            try:
                b = stroke_needed(mech, req["orientations"],
                                  tol_mm=ctx.evaluation.length_tolerance_mm)
            except ParameterError as exc:
                why = f"no needed stroke: {exc}"
        if why is not None:
            for n in names:
                ctx.notes[n] = why
            return dict.fromkeys(names)
        q0 = float(mech.stroke[0])
        if b.note:
            ctx.notes["needed_stroke_bracket"] = b.note
        return {"needed_stroke": b.upper - q0, "needed_stroke_lower": b.lower - q0,
                "needed_stroke_bracket": b.width}


register_evaluator(NeededStroke())
