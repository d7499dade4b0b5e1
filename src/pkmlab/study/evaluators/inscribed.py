"""``inscribed``: the largest inscribed box and vertical cylinder found in the workspace."""

from __future__ import annotations

from .registry import Evaluator, metric, register_evaluator


class Inscribed(Evaluator):
    name = "inscribed"
    block = bool
    description = "largest inscribed box and cylinder of the workspace"
    requires = frozenset({"spatial", "workspace"})   # not yet sized from the mobility
    after = ("workspace",)
    absent = False
    metrics = (
        metric("inscribed_box_volume", "cm³", "grid",
               "largest inscribed axis-aligned box found (verified by sampling)"),
        metric("inscribed_box_edge", "mm", "grid", "shortest edge of that box"),
        metric("inscribed_cylinder_radius", "mm", "grid",
               "largest inscribed vertical cylinder found (verified by sampling)"),
        metric("inscribed_cylinder_volume", "cm³", "grid", "volume of that cylinder"),
    )

    def compute(self, mech, ctx) -> dict:
        res = ctx.result
        names = [m.name for m in self.metrics]
        if res.empty:
            for n in names:
                ctx.notes[n] = "workspace empty"
            return dict.fromkeys(names, 0.0)
        box = res.inscribed_box(samples=2000, seed=ctx.seed)
        cyl = res.inscribed_cylinder(samples=2000, seed=ctx.seed)
        out = {"inscribed_box_volume": box.volume / 1e3,
               "inscribed_box_edge": float(box.size.min()),
               "inscribed_cylinder_radius": float(cyl.radius),
               "inscribed_cylinder_volume": cyl.volume / 1e3}
        if not box.volume > 0:
            for n in ("inscribed_box_volume", "inscribed_box_edge"):
                out[n] = None
                ctx.notes[n] = ("no box survived verification (the workspace is thinner "
                                "than a voxel)")
        if not cyl.volume > 0:
            for n in ("inscribed_cylinder_radius", "inscribed_cylinder_volume"):
                out[n] = None
                ctx.notes[n] = "no cylinder survived verification"
        return out


register_evaluator(Inscribed())
