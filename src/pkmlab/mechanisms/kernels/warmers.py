"""The built-in kinematics, column and search kernels' warmers (:mod:`pkmlab.runtime.warmers`).

The inverse kinematics' Euler and frames drivers and the Jacobian driver serve every
evaluation of a family whose IK and Jacobian are its numba per-pose functions (the base
class's ``_run_ik`` and ``_jacobian``): built here, they compile in the warm-up's parallel
phase rather than in the baseline's evaluation after it.

Kernels that designs other than a study's baseline may use and the baseline need not: the
tiled column kernel serves large footprints only, and the "all"/"any" column kernels, the
capability search, its branch and bound and its certification serve a family whose columns
are solved per leg (``column_method`` "linear" or "quadratic"). Weights: CPU seconds of a
cold compile for the 6-PSU family, one after the other in one process
(``benchmarks/bench_compile.py``, session 6; relative only).
"""

from __future__ import annotations

from ...runtime.warmers import register_warmer
from ..base import Mechanism
from . import columns, ik, search, tiles

__all__: list[str] = []


def _per_leg_columns(mech) -> bool:
    return getattr(type(mech), "column_method", None) in ("linear", "quadratic")


def _leg(mech):
    return type(mech).column_leg


def _capability(mech) -> None:
    """The search, its branch and bound and its certification: one warmer, so that the
    jitable building blocks they share (:func:`.search._core`, compiled once per process, not
    cached on disk) compile in one process only (apart, the last two cost 11 s more)."""
    leg = _leg(mech)
    search.make_capability(leg)
    search.make_branch_bound(leg)
    search.make_certify(leg)


for _name, _weight, _build in (
        ("capability search, branch and bound, certification", 12.3, _capability),
        ("tiled columns (all)", 3.0, lambda m: tiles.make_tiled_all(_leg(m))),
        ("columns (any)", 2.3, lambda m: columns.make_column_kernel(_leg(m), "any")),
        ("columns (all)", 1.3, lambda m: columns.make_column_kernel(_leg(m), "all"))):
    register_warmer(_name, _weight, _per_leg_columns, _build)


def _numba_ik(mech) -> bool:
    cls = type(mech)
    return getattr(cls, "_ik_one", None) is not None and cls._run_ik is Mechanism._run_ik


def _kinematics(mech) -> None:
    """The drivers ``Mechanism._run_ik`` and ``Mechanism._jacobian`` build, with the same
    arguments."""
    cls, g, L = type(mech), mech._ik_geometry, mech.n_actuators
    one = mech._ik_kernel()
    ik.make_driver(one, len(g), "euler", L)
    ik.make_driver(one, len(g), "frames", L)
    if cls._jac_one is not None and cls._jacobian is Mechanism._jacobian:
        ik.make_jacobian_driver(cls._jac_one, len(g))


register_warmer("kinematics drivers (Euler, frames, Jacobian)", 3.7, _numba_ik, _kinematics)
