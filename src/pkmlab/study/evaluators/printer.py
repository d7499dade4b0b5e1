"""``printer``: a linear-delta printer's largest printable cylinder on the bed, and the worst
tool motion per step and tower/XY speed ratio inside it
(:mod:`pkmlab.mechanisms.families.delta_printer`)."""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from ...errors import ParameterError
from ...mechanisms.families import delta_printer as dp
from .registry import Evaluator, metric, register_evaluator


class PrinterSpec(BaseModel):
    """The printer block: the bed's height (mm), the carriages' steps per mm, an optional
    required print height (mm: the cylinder is then the widest of that height; default the
    largest-volume one) and the grid side of the sampled maps."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    bed: float = Field(0.0, allow_inf_nan=False, description="bed height z (mm)")
    steps_per_mm: float = Field(80.0, gt=0, allow_inf_nan=False,
                                description="carriage steps per mm")
    height: float | None = Field(None, gt=0, allow_inf_nan=False,
                                 description="required print height (mm); default: the "
                                 "largest-volume cylinder")
    grid: int = Field(21, ge=5, le=201, description="samples per side of the maps")


class Printer(Evaluator):
    name = "printer"
    block = PrinterSpec
    description = PrinterSpec.__doc__
    requires = frozenset({"linear actuator"})
    metrics = (
        metric("printable_radius", "mm", "exact",
               "radius of the largest printable cylinder standing on the bed (closed form)"),
        metric("printable_height", "mm", "exact",
               "its height (given, or of the largest-volume cylinder, to 1e-6 mm)"),
        metric("printable_volume", "cm³", "exact", "its volume π·r²·h"),
        metric("sampled_printer_step_xy", "mm", "sampled",
               "worst tool motion in x or y for one carriage step over a grid of the "
               "cylinder's mid-height disc"),
        metric("sampled_printer_step_z", "mm", "sampled", "the same in z"),
        metric("sampled_printer_speed_ratio", "", "sampled",
               "largest tower/XY speed ratio (carriage speed per unit XY tool speed) over "
               "the same grid; empty with a note on a serial singularity (a rod at right angles "
               "to its tower)"),
    )

    def check(self, plan, evaluation, mech) -> None:
        if mech.family != "ldelta3" or not np.all(mech.vertical):
            raise ParameterError("evaluate.printer", "used with a linear delta (family "
                                 "'ldelta3') with vertical towers", mech.family)

    def compute(self, mech, ctx) -> dict:
        plan = ctx.evaluation.printer
        cyl = dp.printable_cylinder(mech, plan.bed, plan.height)
        out = {"printable_radius": cyl.radius, "printable_height": cyl.height,
               "printable_volume": cyl.volume_mm3 / 1e3}
        names = ("sampled_printer_step_xy", "sampled_printer_step_z",
                 "sampled_printer_speed_ratio")
        if cyl.radius <= 0:
            for n in names:
                out[n] = None
                ctx.notes[n] = cyl.method
            return out
        zm = plan.bed + 0.5 * cyl.height
        res = dp.resolution_map(mech, zm, cyl.radius, plan.steps_per_mm, n=plan.grid)
        ratio = dp.speed_ratio_map(mech, zm, cyl.radius, n=plan.grid)["ratio"]
        disc = np.hypot(*np.meshgrid(res["x"], res["y"], indexing="ij")) <= cyl.radius
        worst = float(np.nanmax(np.where(disc, ratio, np.nan)))
        out.update(sampled_printer_step_xy=float(max(res["worst"][:2])),
                   sampled_printer_step_z=float(res["worst"][2]),
                   sampled_printer_speed_ratio=worst if math.isfinite(worst) else None)
        if out["sampled_printer_speed_ratio"] is None:
            ctx.notes["sampled_printer_speed_ratio"] = (
                "unbounded: a rod is at right angles to its tower (a serial singularity) at a "
                f"grid point of the disc at z = {zm:.2f} mm")
        return out


register_evaluator(Printer())
