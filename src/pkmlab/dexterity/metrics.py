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

Definitions used everywhere in pkmlab (there is no second copy anywhere else):

* **Homogenised Jacobian.** With a characteristic length ``L`` (mm), ``ω' = L·ω`` has units of
  mm/s and ``q̇ = J_v v + (J_ω / L) ω'``, so ``J_h`` divides columns 3:6 by ``L``
  (:func:`homogenised_jacobian`).
* **κ** (:func:`condition_number`) is the 2-norm condition number ``σmax / σmin`` of ``J_h``;
  every κ pkmlab reports states the ``L`` it used.
* **Singular** (:func:`is_singular`): ``J`` has a non-finite entry (a leg at a serial
  singularity or without a real solution) or ``σmin(J_h) <= SINGULAR_RTOL · σmax(J_h)``
  (``SINGULAR_RTOL = 1e-12``); equivalently ``κ = inf``, ``LCI = 1/κ = 0``. Functions that
  have no ``L`` (force capability, manipulability) apply the same rule to ``J`` as given
  (``L = 1 mm``) unless one is passed. The proximity flags of
  :func:`pkmlab.dexterity.singularity_flags` (serial / parallel *within a tolerance*) are a
  classification of near-singular poses, not this rule.
* **Default L** (:func:`resolve_length`): Angeles' characteristic length, the ``L`` that
  minimises κ at the nominal pose (:func:`characteristic_length`). When that optimisation
  fails (Jacobian singular or undefined at the nominal pose) the mean platform joint radius
  (:func:`joint_radius`) is used instead, and the returned :class:`CharacteristicLength` says
  so in its ``status`` and ``reason``; every output that uses ``L`` carries that record.
* **GCI**: see :mod:`pkmlab.dexterity.aggregate` (mean of ``1/κ`` over the workspace ×
  orientation set, singular poses counting 0).
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..poses import POSE_SIZE, as_frames
from ..tolerances import TOL
from ._linalg import singular_values

log = logging.getLogger(__name__)

__all__ = [
    "block_columns",
    "SINGULAR_RTOL",
    "KAPPA_SINGULAR",
    "jacobian_ok",
    "is_singular",
    "homogenised_jacobian",
    "singular_values",
    "condition_number",
    "lci",
    "smallest_singular_value",
    "manipulability",
    "CharacteristicLength",
    "characteristic_length",
    "resolve_length",
    "joint_radius",
    "rotational_columns",
    "LENGTH_STATUS",
]

#: A Jacobian counts as singular when σmin(J_h) <= SINGULAR_RTOL · σmax(J_h)
#: (:data:`pkmlab.tolerances.TOL`'s ``singular_rtol``).
SINGULAR_RTOL = TOL.singular_rtol
#: κ at and above which a Jacobian is singular (``1 / SINGULAR_RTOL``); reported as ``inf``.
KAPPA_SINGULAR = 1.0 / SINGULAR_RTOL


def _as_jacobian(J) -> np.ndarray:
    J = np.asarray(J, dtype=float)
    if J.ndim < 2 or not (1 <= J.shape[-1] <= POSE_SIZE and J.shape[-2] >= J.shape[-1]):
        raise ParameterError("J", "an array of shape (6, 6) or (..., 6, 6), or (..., n, w) "
                             "with 1 <= w <= 6 and w <= n (a lower mobility's free twist "
                             "columns)", J.shape)
    return J


def rotational_columns(mobility) -> tuple[int, ...]:
    """Positions, among a mechanism's Jacobian columns (its free twist components,
    :attr:`pkmlab.mechanisms.Mobility.twist_columns`), of the rotational ones (ω): ``(3, 4, 5)``
    for a spatial mechanism, ``()`` for a translational one, ``(2,)`` for a planar one."""
    return tuple(int(i) for i, c in enumerate(mobility.twist_columns) if c >= 3)


def _rotational(J: np.ndarray, L, rotational=None) -> tuple[tuple[int, ...], float | None]:
    """The columns to homogenise and the length: ``L`` a length in mm, ``None`` (J as given)
    or a :class:`CharacteristicLength` (its own ``rotational`` columns). A bare length needs
    ``rotational`` unless J is six columns wide (columns 3:6)."""
    if isinstance(L, CharacteristicLength):
        rotational = L.rotational if rotational is None else rotational
        L = L.length
    if L is None:
        return (), None
    if rotational is None:
        if J.shape[-1] != POSE_SIZE:
            raise ParameterError("L", "None or a CharacteristicLength (whose rotational columns "
                                 f"say what to homogenise) for a {J.shape[-1]}-column Jacobian",
                                 L)
        rotational = (3, 4, 5)
    return tuple(rotational), (_as_length(L) if rotational else None)


def _as_length(L) -> float:
    """A length argument (mm, or a :class:`CharacteristicLength`) as a float > 0."""
    if isinstance(L, CharacteristicLength):
        L = L.length
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


def joint_radius(mech) -> float:
    """Mean distance (mm) of the platform joints from the tool point.

    Not a default ``L`` (that is :func:`resolve_length`): the scale that brackets the search of
    :func:`characteristic_length`, and the documented fallback when Angeles' length is
    undefined.
    """
    return float(np.linalg.norm(mech.tool_points, axis=1).mean())


def homogenised_jacobian(J: np.ndarray, L, rotational=None) -> np.ndarray:
    """Dimensionally homogeneous Jacobian ``J_h = J · diag(1, 1, 1, 1/L, 1/L, 1/L)``.

    Args:
        J: ``(..., 6, 6)`` twist-to-joint Jacobian (columns 3:6 in mm/rad), or ``(..., n, w)``
            over a lower mobility's free twist columns.
        L: characteristic length in mm (> 0), or a :class:`CharacteristicLength` (which names
            its rotational columns), or ``None`` (no homogenisation: a purely translational
            Jacobian needs none).
        rotational: the rotational columns of ``J`` (:func:`rotational_columns`); default
            3:6 of a six-column J, else those of the ``CharacteristicLength``.

    Returns:
        ``(..., n, w)`` new array, all entries dimensionless (q̇ in mm/s per mm/s of
        ``[v; L·ω]``). Non-finite entries stay non-finite.
    """
    J = _as_jacobian(J)
    cols, val = _rotational(J, L, rotational)
    Jh = J.copy()
    if cols == (3, 4, 5) and J.shape[-1] == POSE_SIZE:
        Jh[..., 3:] /= val
    elif cols:
        Jh[..., list(cols)] /= val
    return Jh


def _sv(J: np.ndarray, L) -> np.ndarray:
    J = _as_jacobian(J)
    return singular_values(J if L is None else homogenised_jacobian(J, L))


def _kappa_from_sv(s: np.ndarray) -> np.ndarray:
    """κ from descending singular values ``(..., n)``: the singular rule in one place."""
    smax, smin = s[..., 0], s[..., -1]
    with np.errstate(divide="ignore", invalid="ignore"):
        k = smax / smin
    return np.where(np.isfinite(smax) & (smin > SINGULAR_RTOL * smax), k, np.inf)


def condition_number(J: np.ndarray, L) -> np.ndarray:
    """2-norm condition number κ = σmax / σmin of the homogenised Jacobian.

    Args:
        J: ``(..., 6, 6)`` twist-to-joint Jacobian, or ``(..., n, w)`` over a lower mobility's
            free twist columns.
        L: characteristic length in mm, a :class:`CharacteristicLength`, or ``None``: κ of
            ``J`` as given (a purely translational J: σmax/σmin of J itself).

    Returns:
        ``(...,)`` κ ≥ 1; ``inf`` exactly where the pose is singular (:func:`is_singular`: a
        non-finite entry, or σmin ≤ 1e-12·σmax).
    """
    return _kappa_from_sv(_sv(J, L))


def is_singular(J: np.ndarray, L: float | None = None) -> np.ndarray:
    """``(...,)`` bool: the pose is singular by pkmlab's one rule (module docstring).

    True where ``J`` has a non-finite entry or ``σmin(J_h) <= SINGULAR_RTOL · σmax(J_h)``,
    i.e. exactly where :func:`condition_number` is ``inf``.

    Args:
        J: ``(..., 6, 6)`` twist-to-joint Jacobian.
        L: characteristic length in mm; ``None`` applies the rule to ``J`` as given
            (``L = 1 mm``).
    """
    J = _as_jacobian(J)
    return ~np.isfinite(condition_number(J, 1.0 if L is None and J.shape[-1] == POSE_SIZE else L))


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


def manipulability(J: np.ndarray, mobility=None) -> tuple[np.ndarray, np.ndarray]:
    """Yoshikawa manipulability of the translational and rotational velocity ellipsoids.

    With the twist-to-joint map ``q̇ = J t``, the twists reachable with ``‖q̇‖ ≤ 1`` form the
    ellipsoid ``t = J⁻¹ q̇``. Its projections on ``v`` and on ``ω`` are the images of the unit
    ball under ``A_t = (J⁻¹)[0:3, :]`` and ``A_r = (J⁻¹)[3:6, :]``, and the manipulabilities are

        w_t = sqrt(det(A_t A_tᵀ)),   w_r = sqrt(det(A_r A_rᵀ)),

    the products of the semi-axes (proportional to the ellipsoid volumes). Translation and
    rotation are kept apart so that no characteristic length is needed. Computed from the SVD
    ``J = U S Vᵀ`` as ``A A ᵀ = V_b S⁻² V_bᵀ`` (``V_b`` the rows of V for the block).

    Args:
        J: ``(..., 6, 6)`` twist-to-joint Jacobian, or a square ``(..., w, w)`` one over a
            lower mobility's free twist columns (then pass ``mobility``; ``w_r`` is NaN
            without a free rotation).

    Returns:
        ``(w_t, w_r)``, each ``(...,)``. ``w_t`` is dimensionless ((mm/s)³ per (mm/s)³), ``w_r``
        in (rad/mm)³. NaN exactly where :func:`jacobian_ok` is False; ``inf`` where ``J`` is
        singular (:func:`is_singular` with ``L = 1 mm``: the ellipsoid is unbounded — in the
        rare case that its unbounded axis is purely rotational, ``w_t`` is in truth finite).
    """
    J = _as_jacobian(J)
    lead = J.shape[:-2]
    flat = J.reshape((-1,) + J.shape[-2:])
    blocks = (block_columns(J, mobility), block_columns(J, mobility, rotational=True))
    ok = np.all(np.isfinite(flat), axis=(1, 2))
    wt = np.full(flat.shape[0], np.nan)
    wr = np.full(flat.shape[0], np.nan)
    if np.any(ok):
        _, s, Vh = np.linalg.svd(flat[ok])
        sing = ~np.isfinite(_kappa_from_sv(s))                    # the rule at L = 1 mm
        inv2 = 1.0 / np.where(sing[:, None], 1.0, s) ** 2        # (n, w)
        V = np.swapaxes(Vh, -1, -2)                               # columns = right sing. vectors
        out = []
        for rows in blocks:
            if not isinstance(rows, slice) and len(rows) == 0:
                out.append(np.full(len(s), np.nan))
                continue
            Vb = V[:, rows, :]                                    # (n, 3, 6)
            M = np.einsum("nik,nk,njk->nij", Vb, inv2, Vb)
            w = np.sqrt(np.clip(np.linalg.det(M), 0.0, None))
            out.append(np.where(sing, np.inf, w))
        wt[ok], wr[ok] = out
    return wt.reshape(lead), wr.reshape(lead)


#: ``CharacteristicLength.status`` values.
LENGTH_STATUS = {
    "angeles": "Angeles' length: the L minimising κ at the pose",
    "angeles-at-bound": "Angeles' length on the edge of its search bracket",
    "given": "given by the caller",
    "fallback": "Angeles' length undefined: mean platform joint radius used instead",
    "failed": "Angeles' length undefined",
    "not-applicable": "no rotational Jacobian column: κ of J itself, no characteristic length",
}


@dataclass(frozen=True)
class CharacteristicLength:
    """A characteristic length and why it is what it is; unpacks as ``L, kappa = ...``.

    Attributes:
        length: L in mm; NaN only when ``status == "failed"``; ``None`` when
            ``status == "not-applicable"`` (a purely translational mechanism: its Jacobian has
            no rotational column, κ is that of J itself).
        kappa: κ of ``J_h`` at that L at the pose it was determined for (the nominal pose by
            default); ``inf`` where the Jacobian is singular there.
        ok: Angeles' optimisation succeeded (``status`` is ``"angeles"`` or
            ``"angeles-at-bound"``).
        at_bound: the minimum lies on the edge of the search bracket (the optimum may be
            outside it; κ is then monotone in L over the bracket).
        status: a key of :data:`LENGTH_STATUS`: ``"angeles"``, ``"angeles-at-bound"``,
            ``"given"``, ``"fallback"`` (:func:`resolve_length` only) or ``"failed"``
            (:func:`characteristic_length` only).
        reason: one sentence on how L was obtained, or why Angeles' length failed.
        rotational: the Jacobian columns L divides (:func:`rotational_columns` of the
            mechanism's mobility); ``None``: columns 3:6 of a six-column Jacobian.
    """

    length: float | None
    kappa: float
    ok: bool
    at_bound: bool
    status: str = "angeles"
    reason: str = ""
    rotational: tuple[int, ...] | None = None

    def __iter__(self):
        return iter((self.length, self.kappa))

    @property
    def source(self) -> str:
        """Short human-readable source of L (``LENGTH_STATUS[status]``)."""
        return LENGTH_STATUS.get(self.status, self.status)

    def as_dict(self) -> dict:
        """JSON-ready record: ``length_mm``, ``status``, ``source``, ``reason``,
        ``kappa_at_pose`` (``None`` where not finite)."""
        def fin(v):
            return float(v) if v is not None and math.isfinite(v) else None

        return {"length_mm": fin(self.length), "status": self.status, "source": self.source,
                "reason": self.reason, "kappa_at_pose": fin(self.kappa)}


def characteristic_length(mech, pose=None) -> CharacteristicLength:
    """Angeles' characteristic length: the L minimising κ(J_h(L)) at one pose.

    Search in ``log L`` over ``[1e-3, 1e3] × r̄``, with ``r̄`` the mean platform joint radius
    about the tool point (:func:`joint_radius`): a 121-point scan locates the basin (κ(L)
    need not be unimodal), then ``scipy.optimize.minimize_scalar`` (bounded) refines it
    between the scan neighbours.

    Args:
        mech: a mechanism.
        pose: ``(6,)`` pose (mm, rad) or ``(4, 4)`` transform; default ``mech.nominal_pose``.

    Returns:
        :class:`CharacteristicLength` with status ``"angeles"``, ``"angeles-at-bound"``, or
        ``"failed"`` (length NaN, κ inf, ``ok`` False, and the reason: the Jacobian is
        undefined or singular for every L at the pose). Never raises for a numerical failure.
    """
    X = mech.nominal_pose if pose is None else pose
    p, R = as_frames(X, "pose")
    if len(p) != 1:
        raise ParameterError("pose", "a single pose, shape (6,) or (4, 4)", np.shape(X))
    where = "the nominal pose" if pose is None else f"pose {np.round(np.asarray(X), 6)}"
    J = mech.jacobian((p, R))[0]
    rot = rotational_columns(mech.mobility)
    if not rot:
        return _not_applicable(mech, J, where)
    spatial = rot == (3, 4, 5) and J.shape[-1] == POSE_SIZE
    r = joint_radius(mech)
    if not np.all(np.isfinite(J)):
        reason = (f"the Jacobian is undefined at {where} (a leg has no real solution or is at "
                  "a serial singularity)")
        log.warning("characteristic_length: %s", reason)
        return CharacteristicLength(float("nan"), float("inf"), False, False, "failed", reason)
    lo, hi = math.log(1e-3 * r), math.log(1e3 * r)
    grid = np.linspace(lo, hi, 121)
    Js = np.broadcast_to(J, (len(grid),) + J.shape).copy()
    if spatial:
        Js[..., 3:] /= np.exp(grid)[:, None, None]
    else:
        Js[..., list(rot)] /= np.exp(grid)[:, None, None]
    kap = _kappa_from_sv(singular_values(Js))
    if not np.any(np.isfinite(kap)):
        reason = (f"the Jacobian is singular at {where} for every L in [1e-3, 1e3] × "
                  f"{r:.4g} mm (σmin <= {SINGULAR_RTOL:g}·σmax)")
        log.warning("characteristic_length: %s", reason)
        return CharacteristicLength(float("nan"), float("inf"), False, False, "failed", reason)
    k = int(np.argmin(kap))

    def f(logL: float) -> float:
        Jh = J.copy()
        if spatial:
            Jh[:, 3:] /= math.exp(logL)
        else:
            Jh[:, list(rot)] /= math.exp(logL)
        return float(_kappa_from_sv(singular_values(Jh)))

    a, b = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    from scipy.optimize import minimize_scalar  # lazy: 0.3 s at import

    res = minimize_scalar(f, bounds=(a, b), method="bounded",
                          options={"xatol": 1e-10, "maxiter": 200})
    x, val = (float(res.x), float(res.fun)) if res.fun <= kap[k] else (float(grid[k]),
                                                                         float(kap[k]))
    at_bound = bool(min(x - lo, hi - x) < 1e-3 * (hi - lo))   # algorithm constant: 0.1 %
    L = math.exp(x)
    if at_bound:
        reason = (f"κ at {where} is smallest on the edge of the search bracket [1e-3, 1e3] × "
                  f"{r:.4g} mm (L = {L:.6g} mm, κ = {val:.6g}); the optimum may lie outside")
        log.warning("characteristic_length: %s", reason)
        return CharacteristicLength(L, val, True, True, "angeles-at-bound", reason,
                                    None if spatial else rot)
    return CharacteristicLength(L, val, True, False, "angeles",
                                f"Angeles: L = {L:.6g} mm minimises κ at {where} "
                                f"(κ = {val:.6g})", None if spatial else rot)


def _not_applicable(mech, J, where) -> CharacteristicLength:
    """The record of a mechanism whose Jacobian has no rotational column."""
    mob = mech.mobility
    kappa = float(condition_number(J, None)) if J.ndim == 2 else float("inf")
    return CharacteristicLength(
        None, kappa, False, False, "not-applicable",
        f"{mob.name} mobility ({', '.join(mob.coordinates)}): the Jacobian has no rotational "
        f"column, so κ = σmax/σmin of J itself needs no characteristic length (κ = "
        f"{kappa:.6g} at {where})", ())


def resolve_length(mech, L=None) -> CharacteristicLength:
    """The characteristic length every pkmlab output uses, with its status and reason.

    Args:
        mech: a mechanism.
        L: ``None`` for the default (Angeles' length at the nominal pose), a length in mm
            (> 0), or a :class:`CharacteristicLength` (returned unchanged when it has a length).

    Returns:
        :class:`CharacteristicLength`: status ``"given"`` for a given length; ``"angeles"``
        or ``"angeles-at-bound"`` for the default; ``"fallback"`` when Angeles' length fails:
        L is then :func:`joint_radius` and ``reason`` says why Angeles' failed. Never NaN.
        ``"not-applicable"`` (length ``None``) for a mechanism without a free rotation: κ is
        that of J itself, whatever ``L`` is given.
    """
    if isinstance(L, CharacteristicLength):
        if L.status == "not-applicable" or math.isfinite(L.length) and L.length > 0:
            return L
        L = None
    rot = rotational_columns(mech.mobility)
    if not rot:
        cl = _not_applicable(mech, mech.jacobian(mech.nominal_pose)[0], "the nominal pose")
        if L is None:
            return cl
        return dataclasses.replace(cl, reason=f"{cl.reason}; the given L = {_as_length(L):.6g} "
                                   "mm is not used")
    spatial = rot == (3, 4, 5)
    if L is not None:
        val = _as_length(L)
        J = mech.jacobian(mech.nominal_pose)
        cols = None if spatial else rot
        k = condition_number(J, CharacteristicLength(val, 0.0, False, False, rotational=cols))
        return CharacteristicLength(val, float(k[0]), False, False, "given",
                                    f"L = {val:.6g} mm given by the caller", cols)
    # the default is a property of the (frozen) mechanism: one Angeles search per instance,
    # however many evaluators ask (three per study candidate: dexterity, task, paper motion)
    memo = getattr(mech, "__dict__", None)
    if memo is not None and _DEFAULT_LENGTH in memo:
        return memo[_DEFAULT_LENGTH]
    cl = _default_length(mech, spatial, rot)
    if memo is not None:
        memo[_DEFAULT_LENGTH] = cl
    return cl


#: where :func:`resolve_length` keeps a mechanism's default length (its instance ``__dict__``,
#: as ``functools.cached_property`` does)
_DEFAULT_LENGTH = "_pkmlab_default_length"


def _default_length(mech, spatial: bool, rot) -> CharacteristicLength:
    """Angeles' length at the nominal pose, or the joint-radius fallback (resolve_length)."""
    cl = characteristic_length(mech)
    if cl.ok:
        return cl
    r = joint_radius(mech)
    J = mech.jacobian(mech.nominal_pose)
    reason = (f"Angeles' length failed ({cl.reason}); using the mean platform joint radius "
              f"about the tool point, {r:.6g} mm")
    log.warning("resolve_length: %s", reason)
    cols = None if spatial else rot
    k = condition_number(J, CharacteristicLength(r, 0.0, False, False, rotational=cols))
    return CharacteristicLength(r, float(k[0]), False, False, "fallback", reason, cols)


def block_columns(J: np.ndarray, mobility=None, rotational: bool = False):
    """The columns of ``J`` that act on the platform's translation (or rotation): 0:3 (3:6) of
    a six-column J; for a lower mobility (``mobility``, :mod:`pkmlab.mechanisms.mobility`) the
    positions of its free twist columns below (at and above) 3. A J of another width without
    its mobility is refused."""
    if mobility is None:
        if J.shape[-1] != POSE_SIZE:
            raise ParameterError("mobility", f"the mechanism's mobility for a {J.shape[-1]}-"
                                 "column Jacobian (which columns translate)", None)
        return slice(3, POSE_SIZE) if rotational else slice(0, 3)
    tc = np.asarray(mobility.twist_columns)
    if len(tc) != J.shape[-1]:
        raise ParameterError("mobility", f"a mobility with {J.shape[-1]} free coordinates",
                             f"{mobility.name} ({len(tc)})")
    if len(tc) == POSE_SIZE:
        return slice(3, POSE_SIZE) if rotational else slice(0, 3)
    return np.nonzero(tc >= 3 if rotational else tc < 3)[0]
