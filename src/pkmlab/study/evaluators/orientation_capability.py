"""``orientation_capability``: the largest simultaneous Euler box with a dexterous position,
bracketed (continuous positions for radial families, grid bisection otherwise)."""

from __future__ import annotations

import numpy as np

from ...limits import CAPABILITY_MAX_DEG
from ...workspaces import OrientationSet, workspace
from ...workspaces.optima.search import orientation_capability as continuous_capability
from ...workspaces.optima.search import supports_continuous
from .registry import Evaluator, finite, metric, register_evaluator

__all__ = ["OrientationCapability", "capability"]


def capability(mech, request: dict, iterations: int = 8) -> tuple[float, float, str]:
    """Largest ``a`` (deg) whose ±a simultaneous Euler box has a non-empty dexterous workspace
    on ``request``'s grid, by bisection → ``(a, bracket, note)``: the fallback for families
    without radial column intervals or with constraints beyond the stroke (radial families
    use :func:`pkmlab.workspaces.optima.search.orientation_capability`, continuous positions).

    The verified level ``a`` is non-empty and ``a + bracket`` was found empty (so the value is
    a lower bound of the grid's capability to within ``bracket``); ``note`` is non-empty when
    the search hit :data:`~pkmlab.limits.CAPABILITY_MAX_DEG` (bracket 0, the value a lower
    bound only) or the nominal orientation itself has no workspace.
    """
    oset = request["orientations"]
    samples = oset.samples if oset.kind == "box" else 7

    def ok(a_deg: float) -> bool:
        o = OrientationSet.box(np.radians([a_deg] * 3), "simultaneous", samples)
        return not workspace(mech, "dexterous", o, request["resolution"],
                             request["constraints"]).empty

    if not ok(0.0):
        return 0.0, 0.0, "no workspace at the nominal orientation"
    lo, hi = 0.0, 60.0
    if ok(hi):
        lo, hi = hi, CAPABILITY_MAX_DEG
        if ok(hi):
            return hi, 0.0, (f"not bounded by the search: the ±{hi:g}° box (all of SO(3)) "
                             "has a dexterous workspace")
        iterations += 1                             # same resolution over a 120° bracket
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo, hi - lo, ""


class OrientationCapability(Evaluator):
    name = "orientation_capability"
    block = bool
    description = ("the largest ±a simultaneous Euler box with a dexterous position, "
                   "bracketed")
    requires = frozenset({"rotations", "workspace"})
    after = ("workspace",)
    absent = False
    metrics = (
        metric("orientation_capability", "deg", "bound",
               "largest a such that the ±a simultaneous Euler box has a non-empty dexterous "
               "workspace: lower end of the bracket, a position certified for the continuous "
               "box (psu6, ups6, stroke only; other families: the largest grid level verified "
               "by bisection)"),
        metric("orientation_capability_upper", "deg", "bound",
               "upper end of the bracket: the box's orientation grid and the orientations of "
               "the box that refuted candidate points admit no position, proved by branch and "
               "bound over continuous positions (other families: the first grid level found "
               "empty)"),
        metric("orientation_capability_bracket", "deg", "bound",
               "orientation_capability_upper - orientation_capability (psu6, ups6: the search "
               "stops within 0.01° or notes why not; grid: the bisection runs to 0.01°)"),
    )

    def compute(self, mech, ctx) -> dict:
        req = ctx.evaluation.request
        oset = req["orientations"]
        samples = oset.samples if oset.kind == "box" else 7
        if supports_continuous(mech, req["constraints"]):
            # continuous positions, one compiled search, certified bracket (workspaces.optima)
            # the point is not reported here: its random-rotation check (notes only) runs
            # at the fine tolerance, not on a ladder's coarse rung
            b = continuous_capability(mech, samples,
                                      tol_deg=ctx.evaluation.angle_tolerance_deg,
                                      check=not ctx.evaluation.coarse)
            a, upper, note = b.lower, b.upper, b.note
        else:
            a, bracket, note = capability(mech, req)
            upper = a + bracket
            note = "; ".join(filter(None, [note, "grid bisection (no continuous search for "
                                           "this family or these constraints)"]))
        if note:
            ctx.notes["orientation_capability"] = note
        out = {"orientation_capability": a, "orientation_capability_upper": finite(upper),
               "orientation_capability_bracket": finite(upper - a)}
        for name in ("orientation_capability_upper", "orientation_capability_bracket"):
            if out[name] is None:
                ctx.notes[name] = ("no upper end: the search's largest box has a dexterous "
                                   "position")
        return out


register_evaluator(OrientationCapability())
