"""Binding orientations of a continuous Euler box at one column, by local optimisation.

For a family with radial column intervals (``column_leg``: ``psu6``, ``ups6``) each leg ``i``
and orientation ``R`` give the column ``(x, y)`` a z interval ``[a_i(R), b_i(R)]``; over an
orientation set the column keeps ``[max a, min b]``. A finite sample of the box can miss the
orientations where a leg's ``b_i`` is smallest (its upper actuator limit binds) or its ``a_i``
largest (the lower limit binds). :func:`binding_orientations` looks for them: for every leg
and each end it starts L-BFGS-B (scipy, bounded to the box) from the sample's ``starts`` most
binding orientations and keeps the optima that bind harder than the whole sample does.

The result is a heuristic *choice* of orientations, not a proof: whatever it returns lies in
the box, so a sample enlarged with it is still a subset of the continuous box, and any bound
proved for that subset (:func:`pkmlab.workspaces.optima.search.stroke_needed`, lower end) still
holds. Adding the binding orientations is the exchange (cutting-plane) step of semi-infinite
programming: the enlarged sample's optimum approaches the continuous one.
"""

from __future__ import annotations

import logging

import numpy as np

from ...mechanisms.kernels.columns import make_leg_eval
from ...poses import euler_to_matrix

log = logging.getLogger(__name__)

__all__ = ["column_ends", "binding_orientations"]

#: an optimum joins the sample when it binds harder than the sample by more than this (mm)
GAIN_MM = 1e-6


def column_ends(mech, P, x, y, e0, E):
    """``(a, b, ok)``, each ``(len(E), 6)``: the column ``(x, y)``'s leg intervals at the
    orientations ``e0 + E`` (Z-Y-X Euler angles, rad) with column parameters ``P (6, 3)``."""
    E = np.atleast_2d(np.asarray(E, dtype=float))
    W = mech.leg_offsets(euler_to_matrix(np.asarray(e0) + E)).reshape(-1, 3)
    n = len(W)
    a, b, ok = make_leg_eval(type(mech).column_leg)(
        np.full(n, float(x)), np.full(n, float(y)), W, np.tile(P, (len(E), 1)))
    return a.reshape(-1, 6), b.reshape(-1, 6), ok.reshape(-1, 6)


def binding_orientations(mech, P, x, y, e0, theta, E, starts: int = 2) -> tuple:
    """Orientations (offsets from ``e0`` in ``[-theta, theta]³``) where a leg binds the column
    ``(x, y)`` harder than every orientation of the sample ``E (M, 3)`` → ``(new (K, 3),
    gain)``; ``gain`` (mm) is how much they shrink the column's interval ``min b - max a``
    (0 when none binds harder)."""
    from scipy.optimize import minimize  # lazy: 0.07 s at import, only when used

    E = np.asarray(E, dtype=float)
    a, b, ok = column_ends(mech, P, x, y, e0, E)
    if not ok.all():
        log.debug("binding: the sample itself cannot reach the column")
    lo, hi = float(np.max(a)), float(np.min(b))
    bounds = [(-theta, theta)] * 3
    found, a_new, b_new = [], lo, hi
    for i in range(6):
        for end, col in ((1, b[:, i]), (-1, -a[:, i])):
            # minimise b_i (upper end) or -a_i (lower end) from the sample's most binding
            def f(e, i=i, end=end):
                ai, bi, _ = column_ends(mech, P, x, y, e0, e)
                return float(bi[0, i] if end == 1 else -ai[0, i])

            best = float(np.min(col))
            for k in np.argsort(col)[:starts]:
                res = minimize(f, E[k], method="L-BFGS-B", bounds=bounds,
                               options={"ftol": 1e-12, "gtol": 1e-9, "maxiter": 200})
                e = np.clip(res.x, -theta, theta)
                ai, bi, oki = column_ends(mech, P, x, y, e0, e)
                v = float(bi[0, i] if end == 1 else -ai[0, i])
                if v < best - GAIN_MM or not oki[0, i]:
                    found.append(e)
                    best = v
                    if end == 1:
                        b_new = min(b_new, float(bi[0, i]))
                    else:
                        a_new = max(a_new, float(ai[0, i]))
    gain = (hi - lo) - (b_new - a_new)
    return (np.array(found).reshape(-1, 3), max(gain, 0.0))
