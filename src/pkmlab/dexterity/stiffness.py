"""Cartesian stiffness from actuator stiffnesses.

With actuator stiffnesses ``k_i`` (N/mm, e.g. ball screw + motor servo stiffness) and the
twist-to-joint Jacobian ``J`` (``δq = J δx`` for a small displacement twist
``δx = [δp (mm); δθ (rad)]``), the actuator forces are ``f = diag(k) J δx`` and the restoring
wrench is ``w = Jᵀ f = K δx`` with

    K = Jᵀ diag(k) J.

Only the actuators are compliant (links and joints rigid) and the term from external preload
(the derivative of ``Jᵀ`` under load) is neglected: ``K`` is the unloaded stiffness.
Units: ``K[:3, :3]`` N/mm, ``K[3:, 3:]`` N·mm/rad, off-diagonal blocks N/rad (= N·mm/(mm·rad)).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..errors import ParameterError
from .metrics import _as_jacobian, block_columns

__all__ = ["Stiffness", "stiffness"]


class Stiffness(NamedTuple):
    """Result of :func:`stiffness`.

    Attributes:
        K: ``(..., 6, 6)`` symmetric Cartesian stiffness (units in the module docstring).
        translational_min: ``(...,)`` smallest eigenvalue of ``K[:3, :3]`` in N/mm: the
            stiffness along the weakest direction with the rotation held (not the Schur
            complement, which would let the platform rotate).
        rotational_min: ``(...,)`` smallest eigenvalue of ``K[3:, 3:]`` in N·mm/rad, with the
            position held.

    All NaN exactly where the Jacobian has a non-finite entry (:func:`jacobian_ok`).
    """

    K: np.ndarray
    translational_min: np.ndarray
    rotational_min: np.ndarray


def stiffness(J: np.ndarray, k, mobility=None) -> Stiffness:
    """Cartesian stiffness ``K = Jᵀ diag(k) J`` and its weakest block eigenvalues.

    Args:
        J: ``(..., 6, 6)`` twist-to-joint Jacobian.
        k: actuator stiffness in N/mm, a scalar or one per actuator, all > 0.
        mobility: the mechanism's mobility for a J that is not six columns wide (``(..., L,
            w)``: K is w × w over its free twist columns; ``rotational_min`` NaN without a
            free rotation).

    Returns:
        :class:`Stiffness`. ``K`` is positive definite wherever ``J`` is invertible.
    """
    J = _as_jacobian(J)
    n = J.shape[-2]
    kk = np.asarray(k, dtype=float)
    if kk.ndim == 0:
        kk = np.full(n, float(kk))
    if kk.shape != (n,) or not np.all(np.isfinite(kk)) or np.any(kk <= 0):
        raise ParameterError("k", f"actuator stiffness > 0 N/mm, a scalar or {n} values", k)
    tr, rot = block_columns(J, mobility), block_columns(J, mobility, rotational=True)
    K = np.einsum("...ki,k,...kj->...ij", J, kk, J)
    K = 0.5 * (K + np.swapaxes(K, -1, -2))              # exact symmetry despite rounding
    ok = np.all(np.isfinite(J), axis=(-2, -1))
    kt = np.full(ok.shape, np.nan)
    kr = np.full(ok.shape, np.nan)
    if np.any(ok):
        Kok = K[ok]
        kt[ok] = np.linalg.eigvalsh(Kok[:, tr][:, :, tr])[:, 0]
        if isinstance(rot, slice) or len(rot):
            kr[ok] = np.linalg.eigvalsh(Kok[:, rot][:, :, rot])[:, 0]
    K = np.where(ok[..., None, None], K, np.nan)
    return Stiffness(K=K, translational_min=kt, rotational_min=kr)
