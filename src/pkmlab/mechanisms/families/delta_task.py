"""Does a delta robot's feasible set contain a vertical task cylinder? Decided by the signed
leg margins (:mod:`pkmlab.workspaces.bracket_octree`) on cubes covering the cylinder: a cube
whose every leg margin exceeds its circumradius is inside the feasible set; a point of the
cylinder whose inverse kinematics is invalid proves the cylinder is not contained; cubes
neither proven nor refuted are halved, down to a depth limit (then the answer is
"undecided", with the reason).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["contains_cylinder", "cylinder_samples"]


def _closest(C, centre, radius, z0, z1):
    """The point of the cylinder nearest each cube centre ``C (N, 3)``, and its distance."""
    d = C[:, :2] - centre
    r = np.linalg.norm(d, axis=1)
    scale = np.where(r > radius, radius / np.maximum(r, 1e-300), 1.0)
    xy = centre + d * scale[:, None]
    z = np.clip(C[:, 2], z0, z1)
    P = np.column_stack([xy, z])
    return P, np.linalg.norm(P - C, axis=1)


def contains_cylinder(mech, centre, radius, z0, z1, max_depth: int = 9,
                      max_cubes: int = 2_000_000):
    """``(True | False | None, reason)``: the cylinder ``|(x, y) - centre| <= radius``, ``z0
    <= z <= z1`` (mm, tool point) inside the feasible set of ``mech`` (a delta family),
    proven (True), refuted by a point of it whose IK is invalid (False, the point in the
    reason) or undecided at ``max_depth`` halvings (None)."""
    centre = np.asarray(centre, dtype=float)
    lo = np.array([centre[0] - radius, centre[1] - radius, z0])
    hi = np.array([centre[0] + radius, centre[1] + radius, z1])
    e = float(max(hi - lo)) / 4
    n = np.maximum(np.ceil((hi - lo) / e).astype(int), 1)
    g = [lo[k] + e * (np.arange(n[k]) + 0.5) for k in range(3)]
    C = np.stack(np.meshgrid(*g, indexing="ij"), axis=-1).reshape(-1, 3)
    slack = 1e-9 + 1e-12 * mech.scale
    R = np.broadcast_to(mech._rotation, (1, 3, 3))
    for _ in range(max_depth + 1):
        d = 0.5 * e * math.sqrt(3.0) + slack
        P, dist = _closest(C, centre, radius, z0, z1)
        C, P = C[dist <= d], P[dist <= d]                 # cubes that meet the cylinder
        if len(C) == 0:
            return True, None
        bad = ~mech.inverse((P, np.broadcast_to(R, (len(P), 3, 3)))).valid
        if bad.any():
            x = P[np.argmax(bad)]
            return False, (f"the cylinder's point ({x[0]:.6g}, {x[1]:.6g}, {x[2]:.6g}) mm is "
                           "outside the feasible set")
        m = mech.leg_margins(C).min(axis=1)
        C = C[~(m > d)]
        if len(C) == 0:
            return True, None
        if 8 * len(C) > max_cubes:
            break
        q = 0.25 * e
        off = np.array([[i, j, k] for i in (-q, q) for j in (-q, q) for k in (-q, q)])
        C = (C[:, None, :] + off).reshape(-1, 3)
        e *= 0.5
    return None, (f"undecided: {len(C)} cubes of {2 * e:.3g} mm near the set's boundary "
                  "meet the cylinder")


def cylinder_samples(centre, radius, z0, z1, n: int) -> np.ndarray:
    """``(m, 3)`` grid points of the cylinder: ``n`` radii (the axis included) × ``4n``
    angles × ``n`` heights."""
    r = np.linspace(0.0, radius, n)
    a = np.linspace(0.0, 2 * np.pi, 4 * n, endpoint=False)
    z = np.linspace(z0, z1, n)
    Rr, A, Z = np.meshgrid(r, a, z, indexing="ij")
    P = np.column_stack([centre[0] + (Rr * np.cos(A)).ravel(),
                         centre[1] + (Rr * np.sin(A)).ravel(), Z.ravel()])
    return np.unique(np.round(P, 12), axis=0)
