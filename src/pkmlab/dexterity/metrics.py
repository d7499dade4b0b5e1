"""Pointwise dexterity metrics of the velocity Jacobian (pure, batched, vectorised).

Conventions (all of :mod:`pkmlab.dexterity`):

* internal units mm, rad, N, N·mm;
* ``J`` is the twist-to-joint Jacobian of :meth:`pkmlab.Mechanism.jacobian`, shape
  ``(..., 6, 6)``: ``q̇ = J · t`` with the twist ``t = [v; ω]``, ``v`` (mm/s) the velocity of the
  tool point and ``ω`` (rad/s) the angular velocity, both in the base frame. Columns 0:3 are
  dimensionless (mm/s per mm/s), columns 3:6 in mm/rad;
* a leg without a real solution makes its row NaN (a serial singularity can make it ±inf).
  Every function here treats a matrix with any non-finite entry as *undefined*; the mask is
  :func:`jacobian_ok`. Where a result is a float array, undefined matrices give the documented
  sentinel (κ = inf, LCI = 0) or NaN exactly where ``jacobian_ok`` is False — never elsewhere.

Homogenisation: with a characteristic length ``L`` (mm), ``ω' = L·ω`` has units of mm/s and
``q̇ = J_v v + (J_ω / L) ω'``, so the homogenised Jacobian ``J_h`` divides columns 3:6 by ``L``
(:func:`homogenised_jacobian`). Its condition number is the usual isotropy measure; Angeles'
characteristic length (:func:`characteristic_length`) is the ``L`` that minimises it at the
nominal pose.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from ..errors import ParameterError
from ..poses import as_frames
from ._linalg import singular_values

log = logging.getLogger(__name__)

__all__ = [
    "SINGULAR_RTOL",
    "jacobian_ok",
    "homogenised_jacobian",
    "singular_values",
    "condition_number",
    "lci",
    "smallest_singular_value",
    "manipulability",
    "CharacteristicLength",
    "characteristic_length",
    "default_length",
]

#: A matrix counts as numerically singular when σmin <= SINGULAR_RTOL · σmax.
SINGULAR_RTOL = 1e-12


def _as_jacobian(J) -> np.ndarray:
    J = np.asarray(J, dtype=float)
    if J.ndim < 2 or J.shape[-2:] != (6, 6):
        raise ParameterError("J", "an array of shape (6, 6) or (..., 6, 6)", J.shape)
    return J


def _as_length(L) -> float:
    try:
        val = float(L)
    except (TypeError, ValueError):
        raise ParameterError("L", "a characteristic length > 0 mm", L) from None
    if not (math.isfinite(val) and val > 0):
        raise ParameterError("L", "a characteristic length > 0 mm", L)
    return val


def jacobian_ok(J: np.ndarray) -> np.ndarray:
    """``(...,)`` bool: True where the Jacobian ``(..., 6, 6)`` is entirely finite."""
    return np.all(np.isfinite(_as_jacobian(J)), axis=(-2, -1))


def default_length(mech) -> float:
    """Mean distance (mm) of the platform joints from the tool point.

    The scale used to bracket :func:`characteristic_length` and the default homogenising
    length of :func:`pkmlab.dexterity.singularity_flags` (the workspace constraint
    ``kappa_max`` uses the same default).
    """
    return float(np.linalg.norm(mech.tool_points, axis=1).mean())


def homogenised_jacobian(J: np.ndarray, L: float) -> np.ndarray:
    """Dimensionally homogeneous Jacobian ``J_h = J · diag(1, 1, 1, 1/L, 1/L, 1/L)``.

    Args:
        J: ``(..., 6, 6)`` twist-to-joint Jacobian (columns 3:6 in mm/rad).
        L: characteristic length in mm (> 0).

    Returns:
        ``(..., 6, 6)`` new array, all entries dimensionless (q̇ in mm/s per mm/s of
        ``[v; L·ω]``). Non-finite entries stay non-finite.
    """
    Jh = _as_jacobian(J).copy()
    Jh[..., 3:] /= _as_length(L)
    return Jh


def _sv(J: np.ndarray, L: float | None) -> np.ndarray:
    J = _as_jacobian(J)
    return singular_values(J if L is None else homogenised_jacobian(J, L))


def condition_number(J: np.ndarray, L: float) -> np.ndarray:
    """2-norm condition number κ = σmax / σmin of the homogenised Jacobian.

    Args:
        J: ``(..., 6, 6)`` twist-to-joint Jacobian.
        L: characteristic length in mm.

    Returns:
        ``(...,)`` κ ≥ 1; ``inf`` where ``J`` has a non-finite entry (no real leg solution or a
        serial singularity) or is numerically singular (σmin ≤ 1e-12·σmax).
    """
    s = _sv(J, L)
    smax, smin = s[..., 0], s[..., -1]
    with np.errstate(divide="ignore", invalid="ignore"):
        k = smax / smin
    return np.where(np.isfinite(smax) & (smin > SINGULAR_RTOL * smax), k, np.inf)


def lci(J: np.ndarray, L: float) -> np.ndarray:
    """Local conditioning index ``1/κ`` ∈ [0, 1] ``(...,)``; 0 where κ is inf."""
    return 1.0 / condition_number(J, L)


def smallest_singular_value(J: np.ndarray, L: float) -> np.ndarray:
    """σmin of the homogenised Jacobian ``(...,)`` (dimensionless, mm/s per mm/s).

    The smallest joint speed produced by a unit homogenised twist ``‖[v; L·ω]‖ = 1`` — the
    distance of ``J_h`` from the nearest singular matrix. NaN exactly where
    :func:`jacobian_ok` is False.
    """
    return _sv(J, L)[..., -1]


def manipulability(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Yoshikawa manipulability of the translational and rotational velocity ellipsoids.

    With the twist-to-joint map ``q̇ = J t``, the twists reachable with ``‖q̇‖ ≤ 1`` form the
    ellipsoid ``t = J⁻¹ q̇``. Its projections on ``v`` and on ``ω`` are the images of the unit
    ball under ``A_t = (J⁻¹)[0:3, :]`` and ``A_r = (J⁻¹)[3:6, :]``, and the manipulabilities are

        w_t = sqrt(det(A_t A_tᵀ)),   w_r = sqrt(det(A_r A_rᵀ)),

    the products of the semi-axes (proportional to the ellipsoid volumes). Translation and
    rotation are kept apart so that no characteristic length is needed. Computed from the SVD
    ``J = U S Vᵀ`` as ``A A ᵀ = V_b S⁻² V_bᵀ`` (``V_b`` the rows of V for the block).

    Args:
        J: ``(..., 6, 6)`` twist-to-joint Jacobian.

    Returns:
        ``(w_t, w_r)``, each ``(...,)``. ``w_t`` is dimensionless ((mm/s)³ per (mm/s)³), ``w_r``
        in (rad/mm)³. NaN exactly where :func:`jacobian_ok` is False; ``inf`` where ``J`` is
        numerically singular (σmin ≤ 1e-12·σmax: the ellipsoid is unbounded — in the rare case
        that its unbounded axis is purely rotational, ``w_t`` is in truth finite).
    """
    J = _as_jacobian(J)
    lead = J.shape[:-2]
    flat = J.reshape(-1, 6, 6)
    ok = np.all(np.isfinite(flat), axis=(1, 2))
    wt = np.full(flat.shape[0], np.nan)
    wr = np.full(flat.shape[0], np.nan)
    if np.any(ok):
        _, s, Vh = np.linalg.svd(flat[ok])
        sing = s[:, -1] <= SINGULAR_RTOL * s[:, 0]
        inv2 = 1.0 / np.where(sing[:, None], 1.0, s) ** 2        # (n, 6)
        V = np.swapaxes(Vh, -1, -2)                               # columns = right sing. vectors
        out = []
        for rows in (slice(0, 3), slice(3, 6)):
            Vb = V[:, rows, :]                                    # (n, 3, 6)
            M = np.einsum("nik,nk,njk->nij", Vb, inv2, Vb)
            w = np.sqrt(np.clip(np.linalg.det(M), 0.0, None))
            out.append(np.where(sing, np.inf, w))
        wt[ok], wr[ok] = out
    return wt.reshape(lead), wr.reshape(lead)


@dataclass(frozen=True)
class CharacteristicLength:
    """Result of :func:`characteristic_length`; unpacks as ``L, kappa = ...``.

    Attributes:
        length: L in mm (NaN when ``ok`` is False).
        kappa: κ of ``J_h`` at that L (inf when ``ok`` is False).
        ok: the pose has a finite, non-singular Jacobian.
        at_bound: the minimum lies on the edge of the search bracket (the optimum may be
            outside it; κ is then monotone in L over the bracket).
    """

    length: float
    kappa: float
    ok: bool
    at_bound: bool

    def __iter__(self):
        return iter((self.length, self.kappa))


def characteristic_length(mech, pose=None) -> CharacteristicLength:
    """Angeles' characteristic length: the L minimising κ(J_h(L)) at one pose.

    Search in ``log L`` over ``[1e-3, 1e3] × r̄``, with ``r̄`` the mean platform joint radius
    about the tool point (:func:`default_length`): a 121-point scan locates the basin (κ(L)
    need not be unimodal), then ``scipy.optimize.minimize_scalar`` (bounded) refines it
    between the scan neighbours.

    Args:
        mech: a mechanism.
        pose: ``(6,)`` pose (mm, rad) or ``(4, 4)`` transform; default ``mech.nominal_pose``.

    Returns:
        :class:`CharacteristicLength` ``(length, kappa, ok, at_bound)``.
    """
    X = mech.nominal_pose if pose is None else pose
    p, R = as_frames(X, "pose")
    if len(p) != 1:
        raise ParameterError("pose", "a single pose, shape (6,) or (4, 4)", np.shape(X))
    J = mech.jacobian((p, R))[0]
    r = default_length(mech)
    if not np.all(np.isfinite(J)):
        log.warning("characteristic_length: Jacobian undefined at pose %s", np.asarray(X))
        return CharacteristicLength(float("nan"), float("inf"), False, False)
    lo, hi = math.log(1e-3 * r), math.log(1e3 * r)
    grid = np.linspace(lo, hi, 121)
    Js = np.broadcast_to(J, (len(grid), 6, 6)).copy()
    Js[..., 3:] /= np.exp(grid)[:, None, None]
    s = singular_values(Js)
    with np.errstate(divide="ignore"):
        kap = np.where(s[:, -1] > SINGULAR_RTOL * s[:, 0], s[:, 0] / s[:, -1], np.inf)
    if not np.any(np.isfinite(kap)):
        log.warning("characteristic_length: Jacobian singular at pose %s", np.asarray(X))
        return CharacteristicLength(float("nan"), float("inf"), False, False)
    k = int(np.argmin(kap))

    def f(logL: float) -> float:
        Jh = J.copy()
        Jh[:, 3:] /= math.exp(logL)
        sv = singular_values(Jh)
        return float(sv[0] / sv[-1]) if sv[-1] > SINGULAR_RTOL * sv[0] else math.inf

    a, b = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    res = minimize_scalar(f, bounds=(a, b), method="bounded",
                          options={"xatol": 1e-10, "maxiter": 200})
    x, val = (float(res.x), float(res.fun)) if res.fun <= kap[k] else (float(grid[k]),
                                                                         float(kap[k]))
    at_bound = bool(min(x - lo, hi - x) < 1e-3 * (hi - lo))
    if at_bound:
        log.warning("characteristic_length: minimum at the bracket edge (L = %.6g mm)",
                    math.exp(x))
    return CharacteristicLength(math.exp(x), val, True, at_bound)
