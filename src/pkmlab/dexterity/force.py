"""Force and moment capability from actuator force limits.

Statics (virtual work with ``q̇ = J t``): actuator forces ``f`` (N, along each actuator's
direction of motion, positive where ``q`` grows) balance the wrench

    w = Jᵀ f,   w = [F; M]   (F in N, M in N·mm, both base frame, about the tool point),

where ``w`` is the wrench the actuators exert on the platform — equal and opposite to the
external load they hold. Each actuator is limited to ``|f_i| ≤ f_max_i``.

For a square, invertible ``J`` the actuator forces are unique, ``f = G w`` with ``G = J⁻ᵀ``
(columns 0:3 dimensionless, 3:6 in 1/mm), which gives closed forms:

* pure force ``F·u`` (``|u| = 1``, zero moment): ``f_i = F · G_{i,0:3}·u``, so the largest
  force along ``u`` is ``min_i f_max_i / |G_{i,0:3}·u|`` and *every* direction of magnitude
  ``F`` can be held iff ``F ‖G_{i,0:3}‖ ≤ f_max_i`` for all i:
  ``F_iso = min_i f_max_i / ‖G_{i,0:3}‖`` (:func:`max_force_all_directions`), attained along
  ``u* = G_{i*,0:3} / ‖G_{i*,0:3}‖``;
* pure moment: the same with columns 3:6 (:func:`max_moment_all_directions`, N·mm);
* along ``u`` while also exerting a payload wrench ``w_p``: ``f = s·G[:, :3] u + G w_p`` is
  affine in ``s``; each actuator bounds ``s`` to an interval (:func:`force_along_closed_form`).

:func:`force_along` solves the same problem as a linear programme with cvxpy (valid for any
number of actuators m ≥ 6); the closed form is its exact square-case solution.

Every function takes a stack ``(N, 6, 6)`` (a single ``(6, 6)`` counts as N = 1) and returns
per-pose arrays of length N. "Singular" is pkmlab's one rule
(:func:`pkmlab.dexterity.is_singular`) applied with the characteristic length ``L`` the caller
passes (``None``: ``J`` as given, i.e. ``L = 1 mm``); a singular pose holds no force in some
direction and is reported as 0 N.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..poses import POSE_SIZE
from .metrics import block_columns, is_singular

log = logging.getLogger(__name__)

__all__ = ["ForceAlong", "max_force_all_directions", "max_moment_all_directions",
           "force_along", "force_along_closed_form", "transpose_inverse"]


def _jac(J, square: bool = True, any_width: bool = False) -> np.ndarray:
    J = np.asarray(J, dtype=float)
    if J.ndim == 2:
        J = J[None]
    w = J.shape[-1] if any_width and J.ndim == 3 and 1 <= J.shape[-1] <= POSE_SIZE else POSE_SIZE
    ok = J.ndim == 3 and J.shape[-1] == w and (J.shape[-2] == w if square else
                                                 J.shape[-2] >= w)
    if not ok:
        what = "(6, 6) or (N, 6, 6)" if square else "(m, 6) or (N, m, 6) with m >= 6"
        raise ParameterError("J", f"an array of shape {what}", J.shape)
    return J


def _fmax(f_max, m: int) -> np.ndarray:
    f = np.asarray(f_max, dtype=float)
    if f.ndim == 0:
        f = np.full(m, float(f))
    if f.shape != (m,) or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ParameterError("f_max", f"actuator force limits > 0 N, a scalar or {m} values",
                             f_max)
    return f


def _directions(direction, n: int) -> np.ndarray:
    d = np.asarray(direction, dtype=float)
    if d.shape not in ((3,), (n, 3)):
        raise ParameterError("direction", f"a vector (3,) or an array ({n}, 3)", d.shape)
    d = np.broadcast_to(d, (n, 3))
    norm = np.linalg.norm(d, axis=1)
    if not np.all(np.isfinite(norm)) or np.any(norm < 1e-300):   # algorithm constant: zero
        raise ParameterError("direction", "non-zero finite vectors", direction)
    return d / norm[:, None]


def _payload(payload, n: int) -> np.ndarray:
    if payload is None:
        return np.zeros((n, POSE_SIZE))
    w = np.asarray(payload, dtype=float)
    if w.shape not in ((POSE_SIZE,), (n, POSE_SIZE)) or not np.all(np.isfinite(w)):
        raise ParameterError("payload", f"a finite wrench [F (N); M (N·mm)], (6,) or ({n}, 6)",
                             w.shape)
    return np.broadcast_to(w, (n, POSE_SIZE)).copy()


def transpose_inverse(J: np.ndarray, L: float | None = None, *,
                      singular: np.ndarray | None = None
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``G = J⁻ᵀ`` for a stack of square Jacobians, with masks.

    Args:
        J: ``(N, 6, 6)`` twist-to-joint Jacobians (or ``(N, w, w)``, a lower mobility's).
        L: characteristic length (mm) of the singular rule; ``None``: ``J`` as given.
        singular: ``(N,)`` :func:`pkmlab.dexterity.is_singular` ``(J, L)`` when the caller
            already has it (from κ of the same ``J`` with the same ``L``): the singular values
            are then not computed again. It must be that rule's result.

    Returns:
        ``(G, finite, singular)``: ``G (N, 6, 6)`` (NaN where not computed), ``finite (N,)``
        every entry of ``J`` finite, ``singular (N,)`` finite but singular by
        :func:`pkmlab.dexterity.is_singular`.
    """
    J = _jac(J, any_width=True)
    finite = np.all(np.isfinite(J), axis=(1, 2))
    singular = finite & (is_singular(J, L) if singular is None
                         else np.asarray(singular, dtype=bool))
    G = np.full(J.shape, np.nan)
    good = finite & ~singular
    if np.any(good):
        G[good] = np.swapaxes(np.linalg.inv(J[good]), -1, -2)
    return G, finite, singular


def _isotropic(J, f_max, rotational: bool, L, mobility=None, singular=None) -> np.ndarray:
    G, finite, singular = transpose_inverse(J, L, singular=singular)
    cols = block_columns(G, mobility, rotational)
    if not isinstance(cols, slice) and len(cols) == 0:
        raise ParameterError("mobility", "a mechanism with a free "
                             f"{'rotation' if rotational else 'translation'}",
                             getattr(mobility, "name", None))
    f = _fmax(f_max, G.shape[-2])
    norm = np.linalg.norm(G[:, :, cols], axis=-1)                      # (N, 6)
    with np.errstate(divide="ignore", invalid="ignore"):
        cap = np.min(np.where(norm > 0, f / norm, np.inf), axis=1)
    cap = np.where(singular, 0.0, cap)
    return np.where(finite, cap, np.nan)


def max_force_all_directions(J: np.ndarray, f_max, L: float | None = None,
                             mobility=None, *, singular: np.ndarray | None = None
                             ) -> np.ndarray:
    """Largest force magnitude (N) that can be held in *every* direction with zero moment.

    ``F_iso = min_i f_max_i / ‖(J⁻ᵀ)_{i,0:3}‖`` (exact for a square invertible J; see the
    module docstring).

    Args:
        J: ``(6, 6)`` or ``(N, 6, 6)`` twist-to-joint Jacobian, or ``(N, w, w)`` over a lower
            mobility's free twist columns (then ``mobility`` says which translate: a
            translational mechanism's wrench is a force only, ``G`` is 3 × 3).
        f_max: actuator force limit(s) in N, scalar or one per actuator.
        L: characteristic length (mm) of the singular rule; ``None``: ``J`` as given.
        mobility: the mechanism's :class:`~pkmlab.mechanisms.Mobility` (needed unless J has
            six columns).
        singular: the singular rule's ``(N,)`` result for these ``J`` and ``L``, when the
            caller has it (:func:`transpose_inverse`).

    Returns:
        ``(N,)`` force in N; 0 where J is singular (a parallel singularity leaves some wrench
        unbalanced — reported conservatively as no capability); NaN exactly where J has a
        non-finite entry.
    """
    return _isotropic(J, f_max, False, L, mobility, singular)


def max_moment_all_directions(J: np.ndarray, f_max, L: float | None = None,
                              mobility=None) -> np.ndarray:
    """Largest moment magnitude (N·mm) that can be held about every axis with zero force.

    ``M_iso = min_i f_max_i / ‖(J⁻ᵀ)_{i,3:6}‖``; conventions as
    :func:`max_force_all_directions`.
    """
    return _isotropic(J, f_max, True, L, mobility)


@dataclass(frozen=True)
class ForceAlong:
    """Largest force along a direction, per pose (arrays ``(N,)`` unless noted).

    Attributes:
        force: largest ``s ≥ 0`` (N) such that ``Jᵀ f = s·[u; 0] + w_payload`` with
            ``|f_i| ≤ f_max_i``; NaN exactly where ``ok`` is False.
        actuator_forces: ``(N, m)`` actuator forces (N) at that optimum; NaN where not ok.
        status: ``'optimal'``; ``'infeasible'`` (the payload alone cannot be held);
            ``'undefined'`` (non-finite J); ``'singular'`` (closed form only: J singular by
            :func:`pkmlab.dexterity.is_singular` — use :func:`force_along`); otherwise the
            solver's status string
            (``'optimal_inaccurate'``, ``'solver_error'``, ...).
        ok: ``status == 'optimal'``.
    """

    force: np.ndarray
    actuator_forces: np.ndarray
    status: np.ndarray
    ok: np.ndarray


def force_along_closed_form(J: np.ndarray, f_max, direction, payload=None,
                            L: float | None = None) -> ForceAlong:
    """Largest force along ``direction`` for square, invertible Jacobians (vectorised).

    With ``G = J⁻ᵀ``, ``g = G[:, :3] u`` and ``f_p = G w_p``, actuator i requires
    ``-f_max_i ≤ s g_i + f_p_i ≤ f_max_i``; the answer is the smallest upper bound on ``s``
    provided it is ≥ the largest lower bound and ≥ 0.

    Args:
        J: ``(6, 6)`` or ``(N, 6, 6)`` twist-to-joint Jacobian.
        f_max: actuator force limit(s) in N, scalar or ``(6,)``.
        direction: ``(3,)`` or ``(N, 3)`` force direction (normalised here), base frame.
        payload: optional wrench ``(6,)`` or ``(N, 6)`` ``[F (N); M (N·mm)]`` the actuators
            must exert at the same time (e.g. ``[0, 0, m·g, 0, 0, 0]`` to carry a weight
            ``m·g`` acting at the tool point).
        L: characteristic length (mm) of the singular rule; ``None``: ``J`` as given.

    Returns:
        :class:`ForceAlong`.
    """
    J = _jac(J)
    n = len(J)
    f = _fmax(f_max, J.shape[1])
    u = _directions(direction, n)
    wp = _payload(payload, n)
    G, finite, singular = transpose_inverse(J, L)
    g = np.einsum("nij,nj->ni", G[:, :, :3], u)                      # (N, 6)
    fp = np.einsum("nij,nj->ni", G, wp)
    with np.errstate(divide="ignore", invalid="ignore"):
        up = np.where(g > 0, (f - fp) / g, np.where(g < 0, (-f - fp) / g, np.inf))
        dn = np.where(g > 0, (-f - fp) / g, np.where(g < 0, (f - fp) / g, -np.inf))
    s_hi = np.min(up, axis=1)
    s_lo = np.maximum(np.max(dn, axis=1), 0.0)
    tol = 1e-12 * (1.0 + np.abs(s_hi))     # algorithm constant: round-off of s
    zero_ok = np.all((g != 0) | (np.abs(fp) <= f * (1 + 1e-12)), axis=1)
    feasible = (s_lo <= s_hi + tol) & zero_ok
    status = np.full(n, "optimal", dtype=object)
    status[~feasible] = "infeasible"
    status[singular] = "singular"
    status[~finite] = "undefined"
    ok = status == "optimal"
    force = np.where(ok, s_hi, np.nan)
    act = np.where(ok[:, None], force[:, None] * g + fp, np.nan)
    return ForceAlong(force=force, actuator_forces=act, status=status, ok=ok)


def _solver():
    import cvxpy as cp

    installed = set(cp.installed_solvers())
    for name in ("HIGHS", "CLARABEL", "ECOS", "SCIPY"):
        if name in installed:
            return name
    return None


def force_along(J: np.ndarray, f_max, direction, payload=None, *,
                solver: str | None = None) -> ForceAlong:
    """Largest force along ``direction`` (zero moment, optional payload) by linear programming.

    For each pose: variables ``f (m,)`` and ``s``; maximise ``s`` subject to
    ``Jᵀ f = s·[u; 0] + w_p``, ``-f_max ≤ f ≤ f_max``, ``s ≥ 0``. Solved with cvxpy
    (one parametrised problem, re-solved per pose; default solver HiGHS when installed).
    Handles redundant actuation (``m > 6``); for square J it agrees with
    :func:`force_along_closed_form`.

    Args:
        J: ``(m, 6)`` or ``(N, m, 6)`` twist-to-joint Jacobian(s), m ≥ 6.
        f_max: actuator force limit(s) in N, scalar or ``(m,)``.
        direction: ``(3,)`` or ``(N, 3)`` force direction (normalised here), base frame.
        payload: optional wrench ``(6,)`` or ``(N, 6)`` in [N, N·mm] exerted at the same time.
        solver: a cvxpy solver name; default the first installed of HiGHS, Clarabel, ECOS,
            SciPy.

    Returns:
        :class:`ForceAlong`; solver failures are reported in ``status``, never raised.
    """
    import cvxpy as cp

    J = _jac(J, square=False)
    n, m = J.shape[0], J.shape[1]
    f = _fmax(f_max, m)
    u = _directions(direction, n)
    wp = _payload(payload, n)
    JT = cp.Parameter((POSE_SIZE, m))
    wdir = cp.Parameter(POSE_SIZE)
    wpay = cp.Parameter(POSE_SIZE)
    fv = cp.Variable(m)
    s = cp.Variable()
    prob = cp.Problem(cp.Maximize(s), [JT @ fv == s * wdir + wpay, fv <= f, fv >= -f, s >= 0])
    name = solver or _solver()
    force = np.full(n, np.nan)
    act = np.full((n, m), np.nan)
    status = np.full(n, "undefined", dtype=object)
    for k in range(n):
        if not np.all(np.isfinite(J[k])):
            continue
        JT.value = J[k].T
        wdir.value = np.concatenate([u[k], np.zeros(3)])
        wpay.value = wp[k]
        try:
            prob.solve(solver=name)
        except cp.error.SolverError as exc:
            log.debug("force_along: pose %d: %s", k, exc)
            status[k] = "solver_error"
            continue
        status[k] = str(prob.status)
        if prob.status == cp.OPTIMAL:
            force[k] = float(s.value)
            act[k] = fv.value
    ok = status == "optimal"
    force[~ok] = np.nan
    act[~ok] = np.nan
    return ForceAlong(force=force, actuator_forces=act, status=status, ok=ok)
