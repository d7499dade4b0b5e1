"""Static actuator loads holding a payload over a whole workspace (servo torque sizing).

At rest the actuators exert on the platform the wrench ``w`` that balances gravity on the
moving body (payload + platform + lumped leg-end masses, :mod:`.payload`): the Newton–Euler
wrench of :func:`.dynamics.platform_wrench` with zero velocity and acceleration,
``w = [m g ẑ; r_c × m g ẑ]`` (N; N·mm, about the tool origin, ``r_c`` the centre of mass
offset). The actuator loads are ``τ = J⁻ᵀ w`` (virtual work, ``τ·q̇ = w·[v; ω]``): newtons for
prismatic actuators, N·mm for rotary ones (actuator values in rad).

:func:`static_loads` evaluates *every* occupied voxel centre of a workspace result × *every*
sample of its orientation set whose inverse kinematics is valid (the poses of
:func:`pkmlab.dexterity.worst_case`), so its peak is the extreme over that grid — a lower
bound of the supremum over the continuous workspace, converging as the grid is refined. A
singular pose inside makes the peak unbounded: it is reported, not averaged away.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dexterity.metrics import is_singular
from ..motion.dynamics import platform_wrench
from ..motion.payload import GRAVITY, MassProperties
from ..poses import POSE_SIZE, matrix_to_euler

__all__ = ["StaticLoads", "static_loads"]

_CHUNK = 50_000


@dataclass(frozen=True)
class StaticLoads:
    """Peak static actuator load over a workspace grid.

    Attributes:
        peak: largest ``|τ_i|`` (N, or N·mm for rotary actuators); ``inf`` when singular.
        pose: ``(6,)`` Euler pose (mm, rad) where it occurs (NaN when no pose was valid).
        actuator: index of the actuator that carries it.
        poses: number of (voxel, orientation) poses evaluated.
        singular: a singular pose lies on the grid (the load there is unbounded).
        unit: ``"N"`` or ``"N·mm"``.
    """

    peak: float
    pose: np.ndarray
    actuator: int
    poses: int
    singular: bool
    unit: str


def static_loads(mech, result, body: MassProperties, gravity: float = GRAVITY) -> StaticLoads:
    """Static actuator loads holding ``body`` at every voxel × orientation sample of the
    workspace ``result`` (see the module notes)."""
    unit = "N·mm" if mech.actuator_unit == "rad" else "N"
    P = result.voxel_centres()
    Rs = result.orientations.rotations()
    peak, pose, leg, count, singular = 0.0, np.full(POSE_SIZE, np.nan), -1, 0, False
    for Rm in Rs:
        for s in range(0, len(P), _CHUNK):
            p = P[s:s + _CHUNK]
            R = np.ascontiguousarray(np.broadcast_to(Rm, (len(p), 3, 3)))
            ok = mech.inverse((p, R)).valid
            p, R = p[ok], R[ok]
            if len(p) == 0:
                continue
            count += len(p)
            J = mech.jacobian((p, R))
            sing = is_singular(J, mech.scale)
            if np.any(sing):
                singular = True
                k = int(np.argmax(sing))
                peak, leg = np.inf, -1
                pose = np.concatenate([p[k], matrix_to_euler(R[k])])
            good = ~sing
            if not np.any(good):
                continue
            zero = np.zeros((int(good.sum()), POSE_SIZE))
            w = platform_wrench(p[good], R[good], zero, zero, body, mech.tool_offset, gravity)
            Jt = np.transpose(J[good], (0, 2, 1))     # (n, free, L): the free wrench parts
            rhs = w[:, mech.mobility.twist_columns, None]
            tau = (np.linalg.solve(Jt, rhs) if Jt.shape[1] == Jt.shape[2]
                   else np.linalg.pinv(Jt) @ rhs)[..., 0]
            a = np.abs(tau)
            k = int(np.argmax(a.max(axis=1)))
            if not singular and a[k].max() > peak:
                peak, leg = float(a[k].max()), int(np.argmax(a[k]))
                pose = np.concatenate([p[good][k], matrix_to_euler(R[good][k])])
    return StaticLoads(peak, pose, leg, count, singular, unit)
