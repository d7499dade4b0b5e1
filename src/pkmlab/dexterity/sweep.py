"""The worst case's per-pose pass, for any Jacobian shape: the numba 6 × 6 kernel of
:mod:`._linalg` for spatial mechanisms, NumPy for a lower mobility's square Jacobians."""

from __future__ import annotations

import numpy as np

from . import _linalg
from .force import max_force_all_directions
from .metrics import KAPPA_SINGULAR, condition_number

__all__ = ["sweep_bounds", "singular"]


def sweep_bounds(J, L, fmax, kup, force, det, mobility=None) -> None:
    """:func:`._linalg.sweep_bounds` (the numba kernel) for a stack of 6 × 6 Jacobians; for
    another (square) shape, a lower mobility's ``(M, w, w)``, the same outputs in NumPy:
    ``kup`` the exact κ (:func:`pkmlab.dexterity.condition_number`, ``L`` as there: ``None``
    for a translational J), ``force`` :func:`pkmlab.dexterity.max_force_all_directions`
    (the columns that translate from ``mobility``) and ``det`` from ``numpy.linalg.det``; not
    finite: inf, NaN, NaN."""
    if np.shape(J)[1:] == (6, 6):
        _linalg.sweep_bounds(J, L, fmax, kup, force, det)
        return
    J = np.asarray(J, dtype=float)
    for name, a in (("kup", kup), ("force", force), ("det", det)):
        if a.shape != (len(J),):
            raise ValueError(f"sweep_bounds: {name} must have shape ({len(J)},), got {a.shape}")
    if len(J) == 0:
        return
    finite = np.all(np.isfinite(J), axis=(1, 2))
    kup[:] = condition_number(J, L)
    force[:] = max_force_all_directions(J, fmax, L, mobility)
    d = np.full(len(J), np.nan)
    d[finite] = np.linalg.det(J[finite])
    det[:] = d


def singular(J, L, mobility=None) -> np.ndarray:
    """``(M,)`` bool: ``~np.isfinite(condition_number(J, L))`` (pkmlab's one rule,
    :func:`pkmlab.dexterity.is_singular`), with exact κ only where it can decide.

    For a stack of 6 × 6 Jacobians one LU per matrix bounds κ from above
    (:func:`._linalg.sweep_bounds`, made safe for rounding by :func:`._linalg.kappa_upper`);
    a matrix whose bound is below :data:`~pkmlab.dexterity.KAPPA_SINGULAR` is certainly not
    singular, and only the others get their singular values. Other shapes (or ``L`` None):
    the exact κ of every matrix.
    """
    J = np.asarray(J, dtype=float)
    if J.shape[1:] != (6, 6) or L is None:
        return ~np.isfinite(condition_number(J, L))
    n = len(J)
    kup, force, det = np.empty(n), np.empty(n), np.empty(n)
    sweep_bounds(np.ascontiguousarray(J), L, np.ones(6), kup, force, det, mobility)
    out = np.zeros(n, dtype=bool)
    maybe = ~(_linalg.kappa_upper(kup) < KAPPA_SINGULAR)
    if maybe.any():
        out[maybe] = ~np.isfinite(condition_number(J[maybe], L))
    return out
