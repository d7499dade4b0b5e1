"""Certified bounds of the dexterity's worst case from a subset of its samples: the coarse
rung of a study's tolerance ladder (issue 28; :mod:`pkmlab.study.ladder`).

:func:`pkmlab.dexterity.worst_case` maximises κ (and minimises the all-direction force) over
*every* feasible (unit, orientation) sample of the workspace — a unit is an occupied voxel
centre, or the (x, y) column of a family whose Jacobian does not depend on z, evaluated at its
first voxel — and over the column ends. Any subset of those samples therefore gives

* a **lower bound** of ``worst_kappa``: the largest κ over the subset (``inf`` at a singular
  sample, which is then also a certificate: ``worst_kappa`` is inf, ``singularity_free`` 0);
* an **upper bound** of ``min_force``: the smallest force over the subset.

The subset: the units extreme along the 26 directions of ``{-1, 0, 1}³`` (where κ is largest
as a rule: the workspace's edges), and the unit nearest the centroid, × the orientation
samples whose every set coordinate is at its smallest, middle or largest value (the box's
corners, edge and face middles, and centre: 27 for a box). A pose counts only where the
inverse kinematics is valid at the unit's own position (so the (unit, orientation) pair is a
feasible one of the worst case). κ and the force come from the same functions, on the same
poses, as the worst case's (``mech.jacobian``, :func:`~pkmlab.dexterity.condition_number`,
:func:`~pkmlab.dexterity.max_force_all_directions`); a relative allowance of
:data:`ALLOWANCE` is kept anyway (a bound, not a copy).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ... import dexterity as dx
from ...dexterity.aggregate import _units, _voxels
from ...poses import POSE_SIZE

__all__ = ["WorstBound", "worst_bound", "ALLOWANCE"]

#: relative allowance of the bounds for rounding (the worst case's own κ of a sample is the
#: same computation, so it is only a margin)
ALLOWANCE = 1e-9


@dataclass(frozen=True)
class WorstBound:
    """``kappa_lower`` ≤ worst_kappa (inf: a singular sample, certified); ``force_upper`` ≥
    min_force (inf: no feasible pose in the subset); ``poses``: subset poses evaluated."""

    kappa_lower: float
    force_upper: float
    singular: bool
    poses: int

    def describe(self) -> str:
        return (f"certified bound from {self.poses} of the worst case's (unit, orientation) "
                "samples (extreme units × the orientation set's corner, edge and face "
                "samples); the exact worst case is computed when the candidate is re-certified")


def _extreme_units(pos: np.ndarray) -> np.ndarray:
    dirs = np.array([(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)
                     if (a, b, c) != (0, 0, 0)], dtype=float)
    centred = pos - pos.mean(axis=0)
    pick = np.argmax(centred @ dirs.T, axis=0)
    centre = np.argmin(np.einsum("ij,ij->i", centred, centred))
    return np.unique(np.append(pick, centre))


def _corner_orientations(oset) -> np.ndarray:
    P = np.asarray(oset.parameters(), dtype=float).reshape(-1, 3)
    keep = np.ones(len(P), dtype=bool)
    for k in range(3):
        vals = np.unique(P[:, k])
        mid = vals[len(vals) // 2]
        keep &= np.isin(P[:, k], [vals[0], mid, vals[-1]])
    return np.flatnonzero(keep)


def worst_bound(mech, result, length, effort) -> WorstBound:
    """Certified bounds of :func:`pkmlab.dexterity.worst_case` ``(mech, result, length,
    effort)`` (module notes; ``mech`` is ``result.mechanism``, as the worst case's);
    ``effort``: its force limit (None: no force bound)."""
    idx, centres = _voxels(result)
    pos = _units(mech, idx, centres)[0]           # the worst case's own units
    Rs = result.orientations.rotations()
    if not len(pos) or not len(Rs):
        return WorstBound(-math.inf, math.inf, False, 0)
    u = _extreme_units(pos)
    m = _corner_orientations(result.orientations)
    uu, mm = np.repeat(u, len(m)), np.tile(m, len(u))
    p, R = np.ascontiguousarray(pos[uu]), np.ascontiguousarray(Rs[mm])
    valid = mech.inverse((p, R)).valid
    if not valid.any():
        return WorstBound(-math.inf, math.inf, False, 0)
    J = mech.jacobian((p[valid], R[valid]))
    kap = dx.condition_number(J, length)
    singular = bool(np.any(~np.isfinite(kap)))
    k_low = math.inf if singular else float(np.max(kap)) * (1.0 - ALLOWANCE)
    f_up = math.inf
    if effort is not None and singular:
        f_up = 0.0                                    # the worst case's force there: 0
    elif effort is not None:
        # no sample is singular by κ: the force's singular rule (the same singular values
        # when both homogenise the same way) need not run again
        same = length.length is None or (J.shape[-1] == POSE_SIZE and
                                          length.rotational in (None, (3, 4, 5)))
        F = dx.max_force_all_directions(J, effort, L=length.length, mobility=mech.mobility,
                                        singular=np.zeros(len(J), bool) if same else None)
        F = np.where(np.isfinite(F), F, 0.0)          # the worst case's rule: 0 there
        f_up = float(np.min(F)) * (1.0 + ALLOWANCE)
    return WorstBound(k_low, f_up, singular, int(valid.sum()))
