"""``pkmlab printer``: a linear-delta printer's envelope and firmware values from the exact
feasible set (:mod:`pkmlab.mechanisms.families.delta_printer`); thin."""

from __future__ import annotations

import sys
from typing import Annotated

import typer

from ..errors import ParameterError
from .common import JsonOpt, MechArg, _emit, _fail, _load, app

FORMATS = ("klipper", "marlin", "reprap")


@app.command()
def printer(mech_file: MechArg,
            bed: Annotated[float, typer.Option(help="bed height z (mm)")] = 0.0,
            steps_per_mm: Annotated[float, typer.Option(help="carriage steps per mm")] = 80.0,
            firmware: Annotated[str | None, typer.Option(
                help="print one firmware snippet: klipper, marlin or reprap")] = None,
            as_json: JsonOpt = False) -> None:
    """Largest printable cylinder, usable radius per height, resolution and speed ratio of a
    linear delta (ldelta3), and its firmware values."""
    import numpy as np

    from ..mechanisms.families import delta_printer as dp

    mech = _load(mech_file)
    try:
        if firmware is not None and firmware not in FORMATS:
            raise ParameterError("--firmware", f"one of {list(FORMATS)}", firmware)
        cyl = dp.printable_cylinder(mech, bed)
        fw = dp.firmware(mech, bed, steps_per_mm, cyl)
    except ParameterError as exc:
        _fail(exc)
        raise
    if firmware is not None:
        sys.stdout.write(fw[firmware])
        return
    zs = bed + np.linspace(0.0, cyl.height, 6)
    radius = dp.usable_radius(mech, zs)
    res = dp.resolution_map(mech, bed + 0.5 * cyl.height, cyl.radius, steps_per_mm, n=41)
    ratio = dp.speed_ratio_map(mech, bed + 0.5 * cyl.height, cyl.radius, n=41)["ratio"]
    out = {"cylinder": {"radius_mm": cyl.radius, "height_mm": cyl.height, "bed_mm": bed,
                        "volume_cm3": cyl.volume_mm3 / 1e3, "method": cyl.method},
           "usable_radius_mm": {f"{z:.3f}": float(r) for z, r in zip(zs, radius)},
           "step_mm_worst_xyz_mid_height": res["worst"].tolist(),
           "speed_ratio_max_mid_height": float(np.nanmax(ratio)),
           "firmware": fw["values"]}
    if as_json:
        _emit(out)
        return
    c = out["cylinder"]
    lines = [f"printable cylinder: r = {c['radius_mm']:.3f} mm, h = {c['height_mm']:.3f} mm "
             f"above z = {bed:g} mm ({c['volume_cm3']:.1f} cm³; {c['method']})",
             "usable radius: " + ", ".join(f"{r:.3f} mm at z = {z}"
                                           for z, r in out["usable_radius_mm"].items()),
             "worst tool motion per step at mid height (x, y, z): "
             + ", ".join(f"{v * 1e3:.2f} µm" for v in res["worst"]),
             f"largest tower/XY speed ratio at mid height: {out['speed_ratio_max_mid_height']:.3f}",
             "", fw["klipper"]]
    sys.stdout.write("\n".join(lines))
