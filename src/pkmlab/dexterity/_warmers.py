"""The dexterity kernels' warmers (:mod:`pkmlab.runtime.warmers`): the worst case's cell
bounds and cell pass (:mod:`._cells`), the fused per-pose pass at listed poses
(:mod:`._fused`), the fused exact κ of the maps, GCI and trajectory check
(:mod:`._fused_exact`), the pose sweep and the parallel singular values (:mod:`._linalg`, a large
design's κ export). Each calls the factory the evaluation calls, with the same arguments.
Weights: CPU seconds of a cold compile for the 6-PSU family, one after the other in one
process (``benchmarks/bench_compile.py``, session 6, after ``sweep_one`` and its parts became
functions the kernels call rather than inline; relative only).
"""

from __future__ import annotations

import numpy as np

from ..runtime.warmers import register_warmer
from . import _cells, _fused, _fused_exact, _linalg

__all__: list[str] = []


def _spatial(mech) -> bool:
    return mech.mobility.is_spatial


def _bounds(mech) -> None:
    _cells.bounds_kernel(mech)


def _cell_pass(mech) -> None:
    jac, g = mech.jacobian_kernel()
    _cells._eval_kernel(jac, len(g))


def _fused_at(mech) -> None:
    jac, g = mech.jacobian_kernel()
    _fused._kernel_at(jac, len(g))


register_warmer("worst case: cell bounds", 14.4, _cells.cells_available, _bounds)
register_warmer("worst case: cell pass", 2.6, _cells.cells_available, _cell_pass)
register_warmer("worst case: fused pass at poses", 1.8, _fused.fused_available, _fused_at)
# the κ maps of an export and a trajectory check the baseline does not reach: the family's
# exact-κ loop (2.8 s) and the fused worst-case loop it takes (1.7 s)
register_warmer("fused exact κ (maps, GCI, trajectory check)", 4.5, _fused.fused_available,
                _fused_exact.warm)
register_warmer("pose sweep", 0.9, _spatial, lambda mech: _linalg._sweep())
register_warmer("parallel singular values", 1.2, lambda mech: True,
                lambda mech: _linalg.singular_values(np.zeros((_linalg._PARALLEL_FROM, 6, 6))))
