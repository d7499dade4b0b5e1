"""Rigid-body mass properties of the moving platform: platform, payload and lumped leg masses.

Units: mass kg, lengths mm, inertia kg·mm². A :class:`MassProperties` is given in the
*platform frame* (the frame of ``mech.platform_points``): the centre of mass ``com`` (mm) and
the inertia tensor ``inertia`` (3×3, kg·mm², symmetric, positive semi-definite, about the
centre of mass, axes of the platform frame). :func:`combine` adds bodies with the parallel-axis
theorem, so the platform and the payload become one rigid body.

Gravity and inertia may act on different distributions: a body's *weight* (``weight_mass``
at ``weight_com``; by default its mass at its centre of mass) is what gravity pulls on through
the platform. The two differ only for the slender-rod legs below.

Leg masses (optional), two models (``evaluate.payload.legs.model``):

* ``ends`` — "mass at the ends": each leg's mass ``m`` is split into a share ``s·m`` at its
  platform joint, a point mass moving with the platform (inertia and weight), and the rest at
  its base / actuator end, which is not modelled (a fixed U joint of a 6-UPS carries it; for
  sliders it neglects the carriage's own inertia). :func:`leg_end_masses`.
* ``rod`` — the leg as a uniform slender rod from its base joint ``A`` (fixed) to its platform
  joint ``B``, stretching uniformly with the leg length (the material point at fraction
  ``σ ∈ [0, 1]`` is at ``A + σ(B − A)``; no inertia about the rod's own axis). Its kinetic
  energy is ``(m/2)∫₀¹|σḂ|² dσ = (m/6)|Ḃ|²`` and its potential energy
  ``m·g·(A_z + B_z)/2``: exactly those of a point mass ``m/3`` at ``B`` for inertia and a
  weight ``m/2`` at ``B`` (plus a constant). By Kane's method (virtual power of the rod's
  inertia and gravity forces over the platform twist) the rod adds the force
  ``m·(B̈/3 + g·ẑ/2)`` at ``B`` to the actuators' load, which is what
  :func:`leg_rod_masses` encodes (inertial mass ``m/3``, weight ``m/2`` per joint). It needs
  legs whose base joint does not move (``ups6``; checked on ``mech.leg_segments``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..poses import as_frames
from ..tolerances import TOL

__all__ = ["MassProperties", "combine", "leg_end_masses", "leg_rod_masses", "GRAVITY"]

#: standard gravity in mm/s², acting along −z of the base frame
GRAVITY = 9806.65


@dataclass(frozen=True)
class MassProperties:
    """Mass (kg), centre of mass (mm, platform frame), inertia about it (kg·mm²)."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray
    weight_mass: float | None = None       # kg gravity pulls on (default: mass)
    weight_com: np.ndarray | None = None   # where (mm, platform frame; default: com)

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
        if np.max(np.abs(J - J.T)) > TOL.symmetric_rel * max(1.0, np.max(np.abs(J))):
            raise ParameterError("inertia", "a symmetric tensor", J.tolist())
        ev = np.linalg.eigvalsh(J)
        tol = TOL.symmetric_rel * max(1.0, float(np.max(np.abs(ev))))
        if ev[0] < -tol:
            raise ParameterError("inertia", "a positive semi-definite tensor (principal "
                                 "moments >= 0)", ev.tolist())
        s = np.sort(ev)
        if s[0] + s[1] < s[2] - tol:
            raise ParameterError("inertia", "a physical tensor (triangle inequality of the "
                                 "principal moments)", ev.tolist())
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "inertia", J)
        wm = self.mass if self.weight_mass is None else float(self.weight_mass)
        if not (np.isfinite(wm) and wm >= 0):
            raise ParameterError("weight_mass", "a mass >= 0 kg", wm)
        wc = com if self.weight_com is None else np.asarray(self.weight_com, dtype=float)
        if wc.shape != (3,) or not np.all(np.isfinite(wc)):
            raise ParameterError("weight_com", "[x, y, z] in mm", self.weight_com)
        object.__setattr__(self, "weight_mass", float(wm))
        object.__setattr__(self, "weight_com", wc)

    @classmethod
    def none(cls) -> MassProperties:
        return cls(0.0, np.zeros(3), np.zeros((3, 3)))


def combine(*bodies: MassProperties) -> MassProperties:
    """One rigid body from several (parallel-axis theorem); all in the platform frame."""
    m = sum(b.mass for b in bodies)
    mw = sum(b.weight_mass for b in bodies)
    cw = sum(b.weight_mass * b.weight_com for b in bodies) / mw if mw > 0 else np.zeros(3)
    if m <= 0:
        return MassProperties(0.0, np.zeros(3), np.zeros((3, 3)), mw, cw)
    c = sum(b.mass * b.com for b in bodies) / m
    J = np.zeros((3, 3))
    for b in bodies:
        d = b.com - c
        J += b.inertia + b.mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return MassProperties(float(m), c, 0.5 * (J + J.T), mw, cw)


def leg_end_masses(mech, mass_each: float) -> MassProperties:
    """Point masses ``mass_each`` (kg) at the six platform joints, as one body."""
    P = np.asarray(mech.platform_points, dtype=float)
    return combine(*[MassProperties(mass_each, p, np.zeros((3, 3))) for p in P])


def leg_rod_masses(mech, mass_each: float) -> MassProperties:
    """The six legs as uniform slender rods of ``mass_each`` kg from fixed base joints
    (module docstring): inertial mass ``m/3`` and weight ``m/2`` at each platform joint."""
    start, _ = mech.leg_segments(*_two_poses(mech))
    if not np.allclose(start[0], start[1], rtol=0, atol=TOL.same_point_rel * mech.scale):
        raise ParameterError("evaluate.payload.legs.model", "'ends' for family "
                             f"{mech.family!r} ('rod' needs legs whose base joint does not "
                             "move, such as ups6)", "rod")
    P = np.asarray(mech.platform_points, dtype=float)
    return combine(*[MassProperties(mass_each / 3, p, np.zeros((3, 3)), mass_each / 2, p)
                     for p in P])


def _two_poses(mech):
    """Two distinct poses near the nominal one, as frames (for the fixed-base-joint test)."""
    X = np.array([mech.nominal_pose, mech.nominal_pose + [1.0, -2.0, 1.5, 0.02, -0.01, 0.03]])
    return as_frames(X)
