"""A guaranteed volume bracket on an octree of position cubes, for translational families that
give signed leg margins (``cube_margin``: the delta families ``delta3`` and ``ldelta3``,
:mod:`pkmlab.mechanisms.families`); constant orientation (the platform only translates).

Each family gives per leg a **signed margin** ``μ(p)`` (``leg_margins``): where the leg is
feasible (its IK valid: real, in the working mode, in the window, within the joint limit),
no infeasible position is closer than ``μ``; where it is not, no feasible position is closer
than ``-μ``. A cube of half-edge ``s`` lies in the ball of radius ``δ = s·√3`` about its
centre, so it is *inside* the workspace when every leg has ``μ > δ`` at its centre and
*outside* when some leg has ``μ < -δ``; otherwise it is *undecided* and split into eight.
``lower`` = volume of the inside cubes, ``upper`` = lower + volume of the undecided ones;
both are guaranteed, up to the rounding slack every margin gets (``1e-9 mm + 1e-12·scale``).

The margins are built from exact signed distances (to planes, spheres and cylinders) that
are combined by min (an intersection of conditions) and max (a union), which keeps them
lower bounds of the distance in both directions:

* ``ldelta3``, leg on rail ``e`` (``c = W·e``, ``W⊥ = W - c·e``): the rod reaches within the
  angle limit, ``ρ - |W⊥|`` with ``ρ = l·sin(limit)``; ``q <= q_max`` ⟺ ``c <= q_max`` and
  ``|W - q_max e| >= l``, margin ``min(q_max - c, |W - q_max e| - l)``; ``q >= q_min`` ⟺
  ``c >= q_min`` or ``|W - q_min e| <= l``, margin ``max(c - q_min, l - |W - q_min e|)``. The
  working mode (the rod going down from the carriage) holds everywhere when the tower's tilt
  plus the rod-angle limit is below 90°; inclined towers without such a limit are refused.
* ``delta3``: the crank leg's margin of :func:`.._crank_cells.crank_cell_terms` (the rod's
  closing limits and the window-edge spheres and half-spaces), and the cone slab
  ``b·sin(cone) - |W·n|``.

**Connectivity.** The bracket is of the whole feasible set. The engine keeps the component
that contains the nominal position; where the feasible set has more than one component
(a rotary delta's set above its motors' plane, for instance) the two differ, and the result
says so in its notes (compare with ``Constraints(connected=False)``).
"""

from __future__ import annotations

import math
import time
from functools import cache

import numpy as np
from numba import prange
from numba import types as nt

from ...errors import ParameterError
from ...mechanisms.kernels import ik as _kernels
from ...mechanisms.kernels.columns import inlined
from ...runtime.jit import cached_kernel
from ...runtime.threads import threads_for
from .result import VolumeBracket

__all__ = ["octree_volume_bracket", "make_octree"]

_SQRT3 = math.sqrt(3.0)


@cache
def make_octree(margin):
    """Parallel ``octree(C (N, 3), e0, depth, P, slack, vin (N,), vund (N,))``: for each cube
    of edge ``e0`` centred at a row of ``C``, depth-first down to ``depth`` halvings, the
    volume of its inside cubes and of its undecided cubes of the last level (module notes);
    ``margin(x, y, z, P)`` is the family's smallest signed leg margin. Built and cached by
    :func:`pkmlab._jit.cached_kernel`."""
    margin = inlined(margin)

    def octree(C, e0, depth, P, slack, vin, vund):
        for k in prange(C.shape[0]):
            stack = np.empty((7 * depth + 8, 4))
            stack[0, 0] = C[k, 0]
            stack[0, 1] = C[k, 1]
            stack[0, 2] = C[k, 2]
            stack[0, 3] = 0.0
            top = 1
            a = 0.0
            u = 0.0
            while top > 0:
                top -= 1
                x, y, z, lev = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
                e = e0 * 0.5 ** lev
                d = 0.5 * e * _SQRT3 + slack
                m = margin(x, y, z, P)
                if m > d:
                    a += e * e * e
                elif m < -d:
                    continue
                elif lev >= depth:
                    u += e * e * e
                else:
                    q = 0.25 * e
                    for c in range(8):
                        stack[top, 0] = x + (q if c & 1 else -q)
                        stack[top, 1] = y + (q if c & 2 else -q)
                        stack[top, 2] = z + (q if c & 4 else -q)
                        stack[top, 3] = lev + 1.0
                        top += 1
            vin[k] = a
            vund[k] = u

    return cached_kernel(octree, nt.void(_F1 := nt.float64[:, ::1], nt.float64, nt.int64, _F1,
                                         nt.float64, nt.float64[::1], nt.float64[::1]),
                         parallel=True)


def octree_volume_bracket(mech, kind: str = "constant", orientations=None,
                         resolution: float | None = None, constraints=None,
                         target: float = 0.01, budget_s: float = 30.0,
                         max_depth: int = 12) -> VolumeBracket:
    """Bracket the constant-orientation workspace volume of a family with ``cube_margin``
    (module notes).

    Args:
        mech: a ``delta3`` or ``ldelta3`` mechanism.
        kind, orientations, constraints: ``"constant"``, none, and the stroke only (the
            signature of :func:`pkmlab.workspaces.bracket.volume_bracket`).
        resolution: not used (the octree starts from cubes of 1/16 of the search box's
            largest side and halves them); kept for the common signature.
        target: stop when ``upper - lower <= target·upper``.
        budget_s: wall time (s) after the kernel is loaded; a level predicted (4× the last
            one) to end past it is not started, and the last completed level's bracket is
            returned.
        max_depth: most halvings.
    """
    t0 = time.perf_counter()
    if kind != "constant":
        raise ParameterError("kind", "'constant' for a mechanism without a free rotation",
                             kind)
    if orientations is not None and getattr(orientations, "kind", "fixed") != "fixed":
        raise ParameterError("orientations", "the nominal orientation for a mechanism "
                             "without a free rotation", orientations.kind)
    if constraints is not None and (constraints.extra or constraints.stroke is not True):
        raise ParameterError("constraints", "the stroke only: the delta bracket covers the "
                             "family's own limits (window, joint limits), not extra constraints",
                             constraints.describe())
    mech.check_bracket()
    kernel = make_octree(type(mech).cube_margin)
    setup = time.perf_counter() - t0
    t1 = time.perf_counter()
    box = mech.position_bounds(mech._rotation[None])[0]
    if np.any(box[0] >= box[1]):
        return VolumeBracket(0.0, 0.0, target, "empty", [], 0.0, 0, time.perf_counter() - t0,
                             ["no position is within every leg's reach"], setup_seconds=setup)
    span = box[1] - box[0]
    e0 = float(span.max()) / 16
    n = np.maximum(np.ceil(span / e0).astype(int), 1)
    g = [box[0][k] + e0 * (np.arange(n[k]) + 0.5) for k in range(3)]
    C = np.ascontiguousarray(np.stack(np.meshgrid(*g, indexing="ij"), axis=-1).reshape(-1, 3))
    P = _kernels.carray(mech.margin_params())
    slack = 1e-9 + 1e-12 * mech.scale
    vin, vund = np.empty(len(C)), np.empty(len(C))
    history: list[dict] = []
    lower, upper, stop, last = 0.0, math.inf, "budget: depth", 0.0
    for depth in range(max_depth + 1):
        t = time.perf_counter()
        if depth > 1 and t - t1 + 4 * last > budget_s:
            stop = "budget: seconds"
            break
        with threads_for(len(C) << (2 * depth)):
            kernel(C, e0, depth, P, slack, vin, vund)
        last = time.perf_counter() - t
        lo_d = float(vin.sum())
        up_d = lo_d + float(vund.sum())
        lower, upper = max(lower, lo_d), min(upper, up_d)
        history.append({"level": depth, "edge_mm": e0 / 2 ** depth, "lower_mm3": lo_d,
                        "upper_mm3": up_d, "seconds": time.perf_counter() - t0})
        if upper - lower <= target * upper:
            stop = "converged"
            break
    notes = ["the bracket is of the whole feasible set (every component); the engine keeps "
             "the component containing the nominal position"]
    return VolumeBracket(lower, upper, target, stop, history, history[-1]["edge_mm"], 0,
                         time.perf_counter() - t0, notes, setup_seconds=setup)
