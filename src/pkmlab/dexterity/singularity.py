"""Serial and parallel singularity detection (Gosselin & Angeles' classification).

Writing the velocity relation of a parallel mechanism as ``J_x · t = J_q · q̇`` (``t = [v; ω]``
the tool twist), a **serial** (inverse-kinematic) singularity is where ``J_q`` loses rank — a leg
reaches the edge of its reach and the platform can no longer move along some direction however
the actuator moves — and a **parallel** (direct-kinematic) singularity is where ``J_x`` loses
rank — the platform gains a motion with the actuators locked.

* 6-PSU family (``psu6``): leg i has link vector ``a_i`` (slider S joint → platform U joint,
  ``|a_i| = l_i``) and ``r_i`` from the tool point to the U joint; ``J_q = diag(a_iz)`` and
  ``J_x`` has rows ``[a_iᵀ, (r_i × a_i)ᵀ]``, so ``J = J_q⁻¹ J_x``. Here ``J_x`` is built with
  unit link directions ``â_i = a_i / l_i`` (the Plücker coordinates of the link lines; rank and
  singular directions are unchanged, but κ no longer depends on the link lengths).
  Serial measure: ``min_i |a_iz| / l_i`` (a link horizontal).
* 6-UPS and Luzi three-chain families, and any other family: ``J`` itself is used as the direct
  matrix (for the 6-UPS its rows are already the unit leg lines). Serial measure: the median
  row norm of ``J`` over the largest (0 if a row is non-finite), i.e. a leg whose joint speed
  per unit twist blows up relative to the others.

Parallel measure: ``1/κ`` of the homogenised direct matrix (columns 3:6 divided by ``L``,
by default pkmlab's default length, :func:`pkmlab.dexterity.resolve_length`).

These flags classify poses *near* a singularity, within a tolerance. Whether a pose *is*
singular is decided by one rule everywhere else in pkmlab (κ, GCI, forces, worst cases,
trajectories): :func:`pkmlab.dexterity.is_singular`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..mechanisms import NO_STROKE
from ..mechanisms.kernels import ik as _kernels
from ..poses import as_frames
from .metrics import CharacteristicLength, lci, resolve_length

log = logging.getLogger(__name__)

__all__ = ["SingularityFlags", "singularity_flags", "direct_kinematic_matrix", "link_vectors",
           "as_pose_frames"]


def as_pose_frames(poses) -> tuple[np.ndarray, np.ndarray]:
    """Poses as positions ``(N, 3)`` and rotations ``(N, 3, 3)``.

    Accepts what :func:`pkmlab.poses.as_frames` accepts (``(6,)``, ``(N, 6)``, ``(4, 4)``,
    ``(N, 4, 4)``) or a tuple ``(p, R)`` of shapes ``(N, 3)`` and ``(N, 3, 3)``.
    """
    if isinstance(poses, tuple) and len(poses) == 2:
        p = np.asarray(poses[0], dtype=float).reshape(-1, 3)
        R = np.asarray(poses[1], dtype=float).reshape(-1, 3, 3)
        if len(p) != len(R):
            raise ParameterError("poses", "(p, R) with shapes (N, 3) and (N, 3, 3)",
                                 (np.shape(poses[0]), np.shape(poses[1])))
        return np.ascontiguousarray(p), np.ascontiguousarray(R)
    return as_frames(poses)


def _defined(mech, p, R) -> np.ndarray:
    """``(N,)`` every leg has a real solution (stroke ignored); degenerate legs count."""
    st = mech.inverse((p, R), stroke=NO_STROKE).leg_status
    return ~np.any((st == _kernels.NO_SOLUTION) | (st == _kernels.INVALID_INPUT), axis=1)


def link_vectors(mech, poses) -> tuple[np.ndarray, np.ndarray]:
    """Each leg's moving-link vector and its platform joint relative to the tool point.

    Args:
        mech: a mechanism (any family with ``leg_segments``).
        poses: see :func:`as_pose_frames`.

    Returns:
        ``(a, r)``, each ``(N, 6, 3)`` in mm, base frame: ``a = end - start`` from the
        base-side passive joint to the platform joint (6-PSU: slider S joint → U joint, length
        ``l_i``) and ``r = end - p``. NaN where the leg has no real solution.
    """
    p, R = as_pose_frames(poses)
    start, end = mech.leg_segments(p, R)
    return end - start, end - p[:, None, :]


def direct_kinematic_matrix(mech, poses) -> np.ndarray:
    """The direct-kinematic matrix ``J_x`` ``(N, 6, 6)`` (see the module docstring).

    6-PSU: rows ``[â_iᵀ, (r_i × â_i)ᵀ]`` with unit link directions, so that
    ``J = diag(l_i / a_iz) · J_x``. Other families: ``mech.jacobian`` itself. Columns 0:3 are
    dimensionless, 3:6 in mm; NaN rows where a leg has no real solution.
    """
    p, R = as_pose_frames(poses)
    if mech.family == "psu6":
        a, r = link_vectors(mech, (p, R))
        u = a / np.asarray(mech.link_length)[:, None]
        return np.concatenate([u, np.cross(r, u)], axis=-1)
    return mech.jacobian((p, R))


@dataclass(frozen=True)
class SingularityFlags:
    """Per-pose singularity classification, all arrays ``(N,)``.

    Attributes:
        serial: serial (inverse-kinematic, leg) singularity: ``serial_measure < tol``.
        parallel: parallel (direct-kinematic) singularity: ``parallel_measure < parallel_tol``.
        kind: ``'none'``, ``'serial'``, ``'parallel'``, ``'both'`` or ``'undefined'``
            (object array).
        defined: every leg has a real solution at the pose (stroke ignored). Where False,
            ``serial`` and ``parallel`` are False, ``kind`` is ``'undefined'`` and both measures
            are NaN.
        serial_measure: psu6 ``min_i |a_iz| / l_i``; other families median / max row norm of
            ``J`` (0 for a non-finite row). In [0, 1], 0 at the singularity.
        parallel_measure: ``1/κ`` of the homogenised direct matrix, in [0, 1]. NaN also where
            the direct matrix is not finite (only possible for families that use ``J`` itself,
            at a serial singularity; ``parallel`` is then False).
        length: the characteristic length used for the parallel measure, with its status.
    """

    serial: np.ndarray
    parallel: np.ndarray
    kind: np.ndarray
    defined: np.ndarray
    serial_measure: np.ndarray
    parallel_measure: np.ndarray
    length: CharacteristicLength | None = None


def singularity_flags(mech, poses, tol: float = 1e-3, *, parallel_tol: float | None = None,
                      L: float | CharacteristicLength | None = None) -> SingularityFlags:
    """Classify poses as serial / parallel singular (see the module docstring).

    Args:
        mech: a mechanism.
        poses: ``(N, 6)`` poses (mm, rad), ``(N, 4, 4)`` transforms or a tuple ``(p, R)``.
        tol: threshold of the serial measure (dimensionless, e.g. 1e-3 ≈ a link within
            0.06° of horizontal on the 6-PSU).
        parallel_tol: threshold of the parallel measure (``1/κ`` of the direct matrix);
            default ``tol``.
        L: homogenising length in mm for the direct matrix; default pkmlab's default length
            (:func:`pkmlab.dexterity.resolve_length`: Angeles').

    Returns:
        :class:`SingularityFlags`. The stroke window is ignored: singularities are geometric.
    """
    if not (np.isfinite(tol) and tol > 0):
        raise ParameterError("tol", "a threshold > 0", tol)
    ptol = tol if parallel_tol is None else float(parallel_tol)
    if not (np.isfinite(ptol) and ptol > 0):
        raise ParameterError("parallel_tol", "a threshold > 0", parallel_tol)
    length = resolve_length(mech, L)
    L = length.length
    p, R = as_pose_frames(poses)
    n = len(p)
    defined = _defined(mech, p, R)
    s_meas = np.full(n, np.nan)
    p_meas = np.full(n, np.nan)
    Jx = direct_kinematic_matrix(mech, (p, R))
    if mech.family == "psu6":
        a, _ = link_vectors(mech, (p, R))
        with np.errstate(invalid="ignore"):
            s_meas[defined] = np.min(np.abs(a[defined, :, 2]) / mech.link_length, axis=1)
    else:
        rn = np.linalg.norm(Jx[defined], axis=-1)                 # (n_def, 6)
        finite = np.all(np.isfinite(rn), axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.median(rn, axis=1) / np.max(rn, axis=1)
        s_meas[defined] = np.where(finite, np.nan_to_num(ratio, nan=0.0), 0.0)
    comp = defined & np.all(np.isfinite(Jx), axis=(1, 2))
    # the CharacteristicLength names its rotational columns (a lower mobility's J is narrower)
    p_meas[comp] = lci(Jx[comp], length if L is not None else None)
    serial = defined & (s_meas < tol)
    parallel = comp & (p_meas < ptol)
    kind = np.full(n, "none", dtype=object)
    kind[serial & ~parallel] = "serial"
    kind[parallel & ~serial] = "parallel"
    kind[serial & parallel] = "both"
    kind[~defined] = "undefined"
    if np.any(~defined):
        log.debug("singularity_flags: %d of %d poses have a leg without a real solution",
                  int(np.sum(~defined)), n)
    return SingularityFlags(serial=serial, parallel=parallel, kind=kind, defined=defined,
                            serial_measure=s_meas, parallel_measure=p_meas, length=length)
