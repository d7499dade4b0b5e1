"""Rigid-body mass properties of the moving platform: platform, payload and lumped leg masses.

Units: mass kg, lengths mm, inertia kg·mm². A :class:`MassProperties` is given in the
*platform frame* (the frame of ``mech.platform_points``): the centre of mass ``com`` (mm) and
the inertia tensor ``inertia`` (3×3, kg·mm², symmetric, positive semi-definite, about the
centre of mass, axes of the platform frame). :func:`combine` adds bodies with the parallel-axis
theorem, so the platform and the payload become one rigid body.

Leg masses (optional, the "mass at the ends" model): each leg's mass is split into a share at
its platform end and a share at its base / actuator end. The platform-end share is a point
mass at the platform joint, moving with the platform: :func:`leg_end_masses` turns it into a
rigid body to :func:`combine` with the platform. The base-end share is not modelled (a fixed U
joint of a 6-UPS carries it; for sliders it neglects the carriage's own inertia — say so when
it matters).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

__all__ = ["MassProperties", "combine", "leg_end_masses", "GRAVITY"]

#: standard gravity in mm/s², acting along −z of the base frame
GRAVITY = 9806.65


@dataclass(frozen=True)
class MassProperties:
    """Mass (kg), centre of mass (mm, platform frame), inertia about it (kg·mm²)."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray

    def __post_init__(self):
        if not (np.isfinite(self.mass) and self.mass >= 0):
            raise ParameterError("mass", "a mass >= 0 kg", self.mass)
        com = np.asarray(self.com, dtype=float)
        J = np.asarray(self.inertia, dtype=float)
        if com.shape != (3,) or not np.all(np.isfinite(com)):
            raise ParameterError("com", "[x, y, z] in mm", self.com)
        if J.shape == (3,):
            J = np.diag(J)
        if J.shape != (3, 3) or not np.all(np.isfinite(J)):
            raise ParameterError("inertia", "[Ixx, Iyy, Izz] or a 3×3 tensor in kg·mm²",
                                 self.inertia)
        if np.max(np.abs(J - J.T)) > 1e-9 * max(1.0, np.max(np.abs(J))):
            raise ParameterError("inertia", "a symmetric tensor", J.tolist())
        ev = np.linalg.eigvalsh(J)
        tol = 1e-9 * max(1.0, float(np.max(np.abs(ev))))
        if ev[0] < -tol:
            raise ParameterError("inertia", "a positive semi-definite tensor (principal "
                                 "moments >= 0)", ev.tolist())
        s = np.sort(ev)
        if s[0] + s[1] < s[2] - tol:
            raise ParameterError("inertia", "a physical tensor (triangle inequality of the "
                                 "principal moments)", ev.tolist())
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "inertia", J)

    @classmethod
    def none(cls) -> MassProperties:
        return cls(0.0, np.zeros(3), np.zeros((3, 3)))


def combine(*bodies: MassProperties) -> MassProperties:
    """One rigid body from several (parallel-axis theorem); all in the platform frame."""
    m = sum(b.mass for b in bodies)
    if m <= 0:
        return MassProperties.none()
    c = sum(b.mass * b.com for b in bodies) / m
    J = np.zeros((3, 3))
    for b in bodies:
        d = b.com - c
        J += b.inertia + b.mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return MassProperties(float(m), c, 0.5 * (J + J.T))


def leg_end_masses(mech, mass_each: float) -> MassProperties:
    """Point masses ``mass_each`` (kg) at the six platform joints, as one body."""
    P = np.asarray(mech.platform_points, dtype=float)
    return combine(*[MassProperties(mass_each, p, np.zeros((3, 3))) for p in P])
