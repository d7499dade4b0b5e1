"""The built-in column and search kernels' warmers (:mod:`pkmlab.runtime.warmers`).

Kernels that designs other than a study's baseline may use and the baseline need not: the
tiled column kernel serves large footprints only, and the "all"/"any" column kernels, the
capability search, its branch and bound and its certification serve a family whose columns
are solved per leg (``column_method`` "linear" or "quadratic"). Weights: CPU seconds of a
cold compile for the 6-PSU family (2 cores, load 5, scaled from wall time; relative only).
"""

from __future__ import annotations

from ...runtime.warmers import register_warmer
from . import columns, search, tiles

__all__: list[str] = []


def _per_leg_columns(mech) -> bool:
    return getattr(type(mech), "column_method", None) in ("linear", "quadratic")


def _leg(mech):
    return type(mech).column_leg


for _name, _weight, _build in (
        ("capability search", 13.5, lambda m: search.make_capability(_leg(m))),
        ("tiled columns (all)", 3.2, lambda m: tiles.make_tiled_all(_leg(m))),
        ("columns (any)", 2.7, lambda m: columns.make_column_kernel(_leg(m), "any")),
        ("columns (all)", 1.5, lambda m: columns.make_column_kernel(_leg(m), "all")),
        ("capability branch and bound", 0.4, lambda m: search.make_branch_bound(_leg(m))),
        ("capability certification", 0.4, lambda m: search.make_certify(_leg(m)))):
    register_warmer(_name, _weight, _per_leg_columns, _build)
