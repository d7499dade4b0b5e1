"""Numerical tolerances, in one documented place.

Every tolerance a result depends on is named here with its unit and meaning; library code
refers to :data:`TOL` instead of repeating literals. (The numba kernels inline the same values
as compile-time constants; their docstrings point here.)
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Tolerances", "TOL"]


@dataclass(frozen=True)
class Tolerances:
    #: Two joint centres closer than this (mm) are the same point: the geometry is rejected.
    coincident_mm: float = 1e-6
    #: Forward kinematics converges when the largest loop-closure residual is below this (mm).
    fk_residual_mm: float = 1e-9
    #: A forward solution counts as the working mode when its inverse kinematics reproduces the
    #: actuator values to max(1000 × fk_residual_mm, this) mm.
    working_mode_mm: float = 1e-6
    #: Assembly modes closer than this × the mechanism's scale (mm) and this (rad) are one.
    mode_duplicate_rel: float = 1e-6
    #: Pseudo-inverse cut-off (relative singular value) in Newton steps.
    newton_rcond: float = 1e-13
    #: Nominal-pose search: z bracket tolerance (mm).
    nominal_z_mm: float = 1e-12
    #: A Jacobian with σmin ≤ this × σmax is numerically singular (κ = ∞).
    singular_rtol: float = 1e-12
    #: Trajectory checks: a computed actuator value outside the stroke by less than this (mm)
    #: is round-off, not a violation.
    stroke_roundoff_mm: float = 1e-9
    #: A direction (an axis, a link, a joint offset) shorter than this (mm, or unitless for a
    #: unit-vector candidate) is degenerate: it has no direction.
    direction_norm: float = 1e-9
    #: A zero direction whose part orthogonal to its axis is shorter than this fraction of its
    #: length lies along the axis: the crank has no zero angle.
    perpendicular_rel: float = 1e-6
    #: Two points closer than this × the mechanism's scale (mm) are the same point (a loop
    #: closure, two samples of a rigid body).
    same_point_rel: float = 1e-9
    #: An inertia matrix is symmetric and positive semi-definite to this × its largest entry.
    symmetric_rel: float = 1e-9
    #: Time steps equal to this × the mean step count as uniform sampling (differentiation).
    uniform_time_rel: float = 1e-6


#: The tolerances in force.
TOL = Tolerances()
