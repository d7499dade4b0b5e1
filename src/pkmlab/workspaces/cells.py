"""Orientation cells: a cover of a continuous orientation set by parameter boxes, each with a
guaranteed bound on how far its rotations lie from the rotation at its centre.

An :class:`~pkmlab.workspaces.orientations.OrientationSet` is parametrised by three
coordinates (:meth:`~.OrientationSet.bounds`): Z-Y-X Euler offsets for ``box`` and ``fixed``,
(azimuth φ, tilt θ, torsion σ) for ``tilt-torsion``. A cell is a box ``centre ± half`` in those
coordinates; the cells of :func:`initial_cells` cover the whole set, and :func:`split` halves a
cell along every coordinate of non-zero width, so the children cover the parent.

**Angle bound** (:func:`angle_bound`). The rotation angle between ``R(P)`` and ``R(P0)`` is at
most the length of any path between them, ``∫ |ω| dt`` along the straight segment P0 → P:

* Euler box: ``R = Rz(θz)·Ry(θy)·Rx(θx)`` (centre angles added), so ``ω = θz'·e_z +
  θy'·Rz·e_y + θx'·Rz·Ry·e_x`` and ``|ω| <= |θx'| + |θy'| + |θz'|``: the angle is at most
  ``Σ_j |ΔP_j| <= Σ_j half_j``. The axes are orthogonal but for ``e_z·Rz·Ry·e_x = -sin θy``,
  so ``|ω|² = |θ'|² - 2θz'θx'·sin θy <= (1 + |sin θy|)·|θ'|²`` and the angle is also at most
  ``sqrt(1 + sin β)·|half|₂`` (β the cell's largest |θy|, the set's centre included, capped
  at 90°); the smaller of the two is used.
* tilt-torsion: ``R = R_c·Rz(φ)·Ry(θ)·Rz(σ - φ)``, ``ω = φ'·(e_z - Rz(φ)Ry(θ)e_z) +
  θ'·Rz(φ)e_y + σ'·Rz(φ)Ry(θ)e_z`` with ``|e_z - Rz(φ)Ry(θ)e_z| = 2 sin(θ/2)``: the angle is at
  most ``2 sin(θ_max/2)·half_φ + half_θ + half_σ`` (θ_max the cell's largest tilt), so cells
  at zero tilt do not pay for their azimuth.

A platform point ``u`` (about the tool origin) then lies within ``2 sin(α/2)·|u|`` of its
position at the centre rotation, α the bound (capped at π): :func:`chord`.

**Second order** (:func:`axes`, :func:`remainder`). At the centre, ``∂(R·u)/∂P_k = a_k ×
R·u`` with the axes ``a_k`` of the parametrisation: ``(Rz·Ry·e_x, Rz·e_y, e_z)`` for Euler
angles, ``R_c·(e_z - Rz(φ)Ry(θ)e_z, Rz(φ)e_y, Rz(φ)Ry(θ)e_z)`` for tilt-torsion. Along the
straight segment to any point of the cell, ``f(t) = R(t)·u`` has ``f'' = ω'×f + ω×(ω×f)``;
the axes turn at most as fast as the rotation built before them, which gives ``|ω'| <= S²/2``
for Euler angles (``S`` the sum of the half-widths). For tilt-torsion, with ``q =
Rz(φ)Ry(θ)e_z``, ``|q'| <= |φ'| sin θ + |θ'|`` and ``Rz(φ)e_y`` turns at ``|φ'|``, so
``|ω'| <= (|φ'| + |σ'|)(|φ'| sin θ_max + |θ'|) + |θ'||φ'|`` (θ_max capped at π/2; the
azimuth's width is scaled by the tilt, as in the angle bound). So
the linearisation ``R0·u + Σ_k a_k × R0·u · ΔP_k`` is within ``½(|ω'| + |ω|²)·|u|`` of
``R·u``: :func:`remainder` returns that factor of ``|u|``.

Single-axis boxes are the union of three segments (one angle at a time): their cells have
zero width on two coordinates.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["initial_cells", "split", "angle_bound", "chord", "axes", "remainder"]


def _axis_cells(lo: float, hi: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` equal cells covering ``[lo, hi]`` (one cell of zero width when lo == hi)."""
    if not hi > lo:
        return np.array([0.5 * (lo + hi)]), np.zeros(1)
    w = (hi - lo) / n
    return lo + w * (np.arange(n) + 0.5), np.full(n, 0.5 * w)


def initial_cells(oset, n: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """``(centres (L, 3), halves (L, 3))``: a cover of ``oset`` by ``n`` cells per coordinate
    (the tilt-torsion azimuth by ``4·n``)."""
    if oset.kind == "fixed":
        return np.array([oset.angles], dtype=float), np.zeros((1, 3))
    if oset.kind == "box" and oset.semantics == "single-axis":
        cs, hs = [np.zeros((1, 3))], [np.zeros((1, 3))]     # the centre orientation
        for k, a in enumerate(oset.angles):
            if a > 0:
                c, h = _axis_cells(-a, a, 2 * n)
                C = np.zeros((len(c), 3))
                H = np.zeros((len(c), 3))
                C[:, k], H[:, k] = c, h
                cs.append(C)
                hs.append(H)
        return np.concatenate(cs), np.concatenate(hs)
    if oset.kind == "box":
        axes = [_axis_cells(-a, a, n) for a in oset.angles]
    else:
        ranges = [(0.0, 2 * math.pi if oset.tilt > 0 else 0.0), (0.0, oset.tilt),
                  (-oset.torsion, oset.torsion)]
        axes = [_axis_cells(lo, hi, 4 * n if k == 0 else n)
                for k, (lo, hi) in enumerate(ranges)]
    gc = np.meshgrid(*[a[0] for a in axes], indexing="ij")
    gh = np.meshgrid(*[a[1] for a in axes], indexing="ij")
    return (np.stack([g.ravel() for g in gc], axis=1),
            np.stack([g.ravel() for g in gh], axis=1))


def split(centres: np.ndarray, halves: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Halve every cell along each coordinate of non-zero width.

    Returns ``(centres, halves, parent)``: the children (2, 4 or 8 per cell) and the index of
    each child's parent.
    """
    C, H = np.asarray(centres, float), np.asarray(halves, float)
    out_c, out_h, parent = [C], [H], [np.arange(len(C))]
    for k in range(3):
        cc, hh, pp = [], [], []
        for c, h, p in zip(out_c, out_h, parent, strict=True):
            wide = h[:, k] > 0
            cc.append(c[~wide])
            hh.append(h[~wide])
            pp.append(p[~wide])
            for s in (-0.5, 0.5):
                c2 = c[wide].copy()
                h2 = h[wide].copy()
                c2[:, k] += s * h2[:, k]
                h2[:, k] *= 0.5
                cc.append(c2)
                hh.append(h2)
                pp.append(p[wide])
        out_c, out_h, parent = [np.concatenate(cc)], [np.concatenate(hh)], [np.concatenate(pp)]
    return out_c[0], out_h[0], parent[0]


def angle_bound(oset, centres: np.ndarray, halves: np.ndarray) -> np.ndarray:
    """``(L,)`` bound (rad) on the rotation angle between any rotation of a cell and the
    rotation at its centre (module notes)."""
    H = np.abs(np.asarray(halves, float))
    if oset.kind != "tilt-torsion":
        cy = 0.0 if oset.centre is None else float(oset.centre[1])
        bmax = np.minimum(np.abs(cy + np.asarray(centres, float)[:, 1]) + H[:, 1], math.pi / 2)
        return np.minimum(H.sum(axis=1), np.sqrt(1 + np.sin(bmax)) * np.linalg.norm(H, axis=1))
    tmax = np.minimum(np.abs(centres[:, 1]) + H[:, 1], math.pi)
    return 2 * np.sin(0.5 * tmax) * H[:, 0] + H[:, 1] + H[:, 2]


def chord(angle: np.ndarray) -> np.ndarray:
    """Largest displacement of a unit vector rotated by at most ``angle`` (rad)."""
    return 2 * np.sin(0.5 * np.minimum(np.asarray(angle, float), math.pi))


def _rot(axis: int, a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(np.shape(a) + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R[..., axis, axis] = 1.0
    R[..., i, i], R[..., i, j], R[..., j, i], R[..., j, j] = c, -s, s, c
    return R


def axes(oset, centres: np.ndarray) -> np.ndarray:
    """``(L, 3, 3)``: the axes ``a_k`` (rows, base frame) with ``∂R/∂P_k = [a_k]× R`` at each
    cell centre."""
    P = np.asarray(centres, float)
    ez = np.array([0.0, 0.0, 1.0])
    ey = np.array([0.0, 1.0, 0.0])
    if oset.kind != "tilt-torsion":
        t = P + (np.zeros(3) if oset.centre is None else np.asarray(oset.centre))
        Rz = _rot(2, t[:, 2])
        a_z = np.broadcast_to(ez, (len(P), 3))
        a_y = Rz @ ey
        a_x = (Rz @ _rot(1, t[:, 1])) @ np.array([1.0, 0.0, 0.0])
        return np.stack([a_x, a_y, a_z], axis=1)
    from ..poses import euler_to_matrix

    Rc = euler_to_matrix(np.zeros(3) if oset.centre is None else np.asarray(oset.centre))
    Rz = _rot(2, P[:, 0])
    q = (Rz @ _rot(1, P[:, 1])) @ ez
    A = np.stack([ez - q, Rz @ ey, q], axis=1)              # local frame
    return A @ Rc.T


def remainder(oset, centres: np.ndarray, halves: np.ndarray) -> np.ndarray:
    """``(L,)``: the linearisation error of ``R·u`` over a cell, per unit ``|u|``."""
    H = np.abs(np.asarray(halves, float))
    S = H.sum(axis=1)
    w = np.minimum(angle_bound(oset, centres, halves), S)
    if oset.kind != "tilt-torsion":
        dw = 0.5 * S**2
    else:
        tmax = np.minimum(np.abs(np.asarray(centres, float)[:, 1]) + H[:, 1], 0.5 * math.pi)
        dw = np.minimum((H[:, 0] + H[:, 2]) * (H[:, 0] * np.sin(tmax) + H[:, 1])
                        + H[:, 1] * H[:, 0], S**2)
    return 0.5 * (dw + w**2)
