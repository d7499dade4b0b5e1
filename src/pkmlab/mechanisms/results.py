"""Result types of the mechanism protocol (inverse and forward kinematics, assembly modes)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..poses import exp_so3
from .kernels import ik as _kernels

#: Stroke override of :meth:`Mechanism.inverse` that checks geometry only.
NO_STROKE = (-math.inf, math.inf)

__all__ = ["NO_STROKE", "LEG_STATUS", "IKResult", "FKResult", "AssemblyModes", "step_frames"]

#: Leg status / pose reason codes of :meth:`Mechanism.inverse`, by severity.
LEG_STATUS = {
    _kernels.OK: "ok",
    _kernels.BELOW_STROKE: "stroke below minimum",
    _kernels.ABOVE_STROKE: "stroke above maximum",
    _kernels.DEGENERATE: "degenerate leg geometry",
    _kernels.NO_SOLUTION: "no real solution",
    _kernels.INVALID_INPUT: "non-finite pose",
    _kernels.OTHER_MODE: "leg outside the working mode",
    _kernels.JOINT_LIMIT: "passive joint beyond its limit",
}


@dataclass(frozen=True)
class IKResult:
    """Inverse kinematics of N poses.

    Attributes:
        q: actuator values ``(N, 6)`` in mm; NaN only where ``leg_status`` is
            ``no real solution``, ``degenerate leg geometry`` or ``non-finite pose``.
        valid: ``(N,)`` True where every leg is solvable and within its stroke.
        reason: ``(N,)`` int code, the most severe leg status (keys of ``LEG_STATUS``).
        leg_status: ``(N, 6)`` int code per leg.
    """

    q: np.ndarray
    valid: np.ndarray
    reason: np.ndarray
    leg_status: np.ndarray

    @property
    def reason_text(self) -> np.ndarray:
        """``(N,)`` human-readable reason per pose."""
        return np.array([LEG_STATUS[int(c)] for c in self.reason], dtype=object)


@dataclass(frozen=True)
class FKResult:
    """Forward kinematics of N actuator vectors.

    Attributes:
        pose: ``(N, 6)`` tool pose (mm, rad); NaN where not converged.
        converged: ``(N,)`` residual below tolerance in the mechanism's working mode.
        residual: ``(N,)`` largest loop-closure error in mm.
        iterations: ``(N,)`` Newton iterations used (continuation steps add up).
        status: ``(N,)`` ``"ok"``, ``"not converged"`` or ``"singular"``; with the mode check
            (``forward(..., modes=True)``) ``"ambiguous"`` where the solution converged but
            another working-mode assembly mode exists for the same actuator values.
        ambiguous: ``(N,)`` True where another working-mode assembly mode was found by Newton
            from the mode-check starts (:func:`pkmlab.mechanisms.solvers.other_modes`);
            ``None`` when the check was not run.
        next_mode: ``(N, 6)`` that mode nearest the solution (NaN where none was found).
        next_mode_mm, next_mode_deg: ``(N,)`` its distance from the solution: position (mm)
            and rotation angle (deg); inf where none was found.
        mode_starts: starting poses of the mode check per actuator vector (0: not run).
    """

    pose: np.ndarray
    converged: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    status: np.ndarray
    ambiguous: np.ndarray | None = None
    next_mode: np.ndarray | None = None
    next_mode_mm: np.ndarray | None = None
    next_mode_deg: np.ndarray | None = None
    mode_starts: int = 0


@dataclass(frozen=True)
class AssemblyModes:
    """All assembly modes found for one actuator vector, nominal-closest first.

    Attributes:
        pose: ``(M, 6)`` tool poses (mm, rad).
        residual: ``(M,)`` largest loop-closure error in mm.
        working_mode: ``(M,)`` True where the pose's inverse kinematics (the family's working
            branch, e.g. the positive root of the 6-PSU) reproduces the actuator values.
        distance: ``(M,)`` distance to the nominal pose (mm + characteristic length · rad).
        starts: number of starting points used.
    """

    pose: np.ndarray
    residual: np.ndarray
    working_mode: np.ndarray
    distance: np.ndarray
    starts: int


def step_frames(p: np.ndarray, R: np.ndarray, twist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Apply a base-frame twist displacement ``(N, 6)`` to frames: p += v, R ← exp(ω)·R."""
    return p + twist[:, :3], exp_so3(twist[:, 3:]) @ R
