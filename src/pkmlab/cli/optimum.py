"""Continuous optima with their brackets: ``pkmlab optimum stroke`` and ``pkmlab optimum
capability`` (the analysis is :mod:`pkmlab.workspaces.optima.search`)."""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
import typer
from rich.markup import escape

from ..errors import ParameterError
from ..units import parse_angle, parse_length
from .common import JsonOpt, MechArg, _emit, _fail, _load, app, out

optimum = typer.Typer(no_args_is_help=True, help="Continuous optima of a geometry, each with a "
                      "bracket that contains the true value (psu6, ups6; stroke only).")
app.add_typer(optimum, name="optimum")

#: library argument names → the options of these commands
_OPTIONS = {"samples": "--samples", "orientations": "--box", "tol_mm": "--tol",
            "q_max_limit": "--max-limit", "rounds": "--rounds"}


def _lines(b, head: str, value: str) -> None:
    out.print(head)
    out.print(value)
    out.print(f"  method: {escape(b.method)}")
    if b.note:
        out.print(f"  note: {escape(b.note)}")
    out.print(f"  {b.seconds:.2f} s")


@optimum.command()
def stroke(
    mech_file: MechArg,
    box: Annotated[str, typer.Option(
        help="half-range of the simultaneous Euler box (deg or with units), about the "
        "nominal orientation")] = "30",
    samples: Annotated[int, typer.Option(help="orientation samples per angle of the "
                                         "starting grid")] = 5,
    tol: Annotated[str, typer.Option(help="bracket width to reach (mm or with units)")]
    = "0.01",
    max_limit: Annotated[str | None, typer.Option(
        help="largest upper actuator limit searched (default: lower limit + 4 × scale)")]
    = None,
    rounds: Annotated[int, typer.Option(help="exchange rounds that add binding "
                                        "orientations")] = 8,
    as_json: JsonOpt = False,
) -> None:
    """The smallest upper actuator limit (lower limit kept) at which the continuous ±box
    simultaneous Euler box has a dexterous position, bracketed: lower end proved (branch and
    bound over continuous positions for a sample of the box), upper end a certified point."""
    from ..workspaces import OrientationSet
    from ..workspaces.optima.search import stroke_needed

    mech = _load(mech_file)
    try:
        half = parse_angle(box, "--box")
        tol_mm = parse_length(tol, "--tol")
        limit = None if max_limit is None else parse_length(max_limit, "--max-limit")
        if not 0.0 < half <= math.pi:
            raise ParameterError("--box", "a half-range in (0, 180] deg", box)
        if not 2 <= samples <= 41:
            raise ParameterError("--samples", "an integer in [2, 41]", samples)
        oset = OrientationSet.box(np.full(3, half), "simultaneous", samples)
        b = stroke_needed(mech, oset, tol_mm=tol_mm, q_max_limit=limit, rounds=rounds)
    except ParameterError as exc:
        _fail(exc, _OPTIONS)
    qmin = float(mech.stroke[0])
    if as_json:
        _emit(b.as_dict() | {"mechanism": mech.name, "family": mech.family,
                             "box_deg": round(math.degrees(half), 9), "lower_limit_mm": qmin,
                             "travel_mm": [b.lower - qmin, b.upper - qmin]})
        return
    x, y, z = b.point
    _lines(b, f"{escape(mech.name or mech.family)}: stroke needed for the ±{math.degrees(half):g}° "
           f"simultaneous box (lower limit {qmin:g} mm kept)",
           f"  upper actuator limit in [{b.lower:.4f}, {b.upper:.4f}] mm (width "
           f"{b.width:.4f} mm; travel {b.lower - qmin:.4f} … {b.upper - qmin:.4f} mm; "
           f"{samples}³ grid alone: {b.sampled:.4f} mm)\n"
           f"  certified point ({x:.4f}, {y:.4f}, {z:.4f}) mm")


@optimum.command()
def capability(
    mech_file: MechArg,
    samples: Annotated[int, typer.Option(help="orientation samples per angle")] = 5,
    as_json: JsonOpt = False,
) -> None:
    """The largest ±a simultaneous Euler box with a dexterous position, bracketed: lower end a
    point certified for the continuous box, upper end a box whose sample admits no position
    (branch and bound over continuous positions)."""
    from ..workspaces.optima.search import orientation_capability

    mech = _load(mech_file)
    try:
        if not 2 <= samples <= 41:
            raise ParameterError("--samples", "an integer in [2, 41]", samples)
        b = orientation_capability(mech, samples)
    except ParameterError as exc:
        _fail(exc, _OPTIONS)
    certified = bool(np.all(np.isfinite(b.point)))
    if as_json:
        _emit(b.as_dict() | {"mechanism": mech.name, "family": mech.family,
                             "upper": None if math.isinf(b.upper) else b.upper,
                             "width": None if math.isinf(b.upper) else b.width,
                             "point": list(b.point) if certified else None})
        return
    x, y, z = b.point
    _lines(b, f"{escape(mech.name or mech.family)}: orientation capability (largest ±a "
           "simultaneous Euler box with a dexterous position)",
           f"  a in [{b.lower:.4f}, {b.upper:.4f}] deg (width {b.width:.4f} deg; "
           f"{samples}³ grid alone: {b.sampled:.4f} deg)\n" +
           (f"  certified point for the ±{b.lower:.4f}° box ({x:.4f}, {y:.4f}, {z:.4f}) mm"
            if certified else "  no certified point (see the note)"))
