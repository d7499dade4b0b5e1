"""Base pieces of the mechanism YAML models (pydantic v2), shared by :mod:`pkmlab.config` and
the families' own YAML models (each in its family's module,
:mod:`pkmlab.mechanisms.families`): the frozen model base, the paired-circles generator and the
fields common to every family."""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from .errors import ParameterError
from .quantities import Angle, AutoAngle, Points, Pose, Radii, Stroke, Vector3

__all__ = ["PairedCircles", "FamilySpec"]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class PairedCircles(_Model):
    """Generator of the paired concentric-circle layout (6-PSU and 6-UPS)."""

    base_radii: Radii = Field(description="[inner, outer] base joint radii (mm)")
    platform_radii: Radii = Field(description="[inner, outer] platform joint radii (mm)")
    base_pair_angle: AutoAngle = Field(None, description="β (deg) or 'auto' (equal legs)")
    platform_rotation: Angle = Field(description="ρ, clockwise from the platform y axis (deg)")
    base_pair_separation: Angle = 0.0
    platform_pair_separation: Angle = 0.0
    pairing: Literal["same", "crossed"] = "same"


class _Common(_Model):
    name: str = ""
    source: str = ""
    stroke: Stroke
    tool_offset: Vector3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    nominal_pose: Pose | None = None
    base_points: Points | None = None
    platform_points: Points | None = None

    def _explicit(self, field_gen: str) -> bool:
        gen = getattr(self, field_gen)
        have = [self.base_points is not None, self.platform_points is not None]
        if gen is not None and any(have):
            raise ParameterError(field_gen, "given alone: either a generator or explicit "
                                 "base_points/platform_points, not both", "both")
        if gen is None and not all(have):
            missing = "base_points" if not have[0] else "platform_points"
            raise ParameterError(missing, "given (or use a 'generator' block)", None)
        return gen is None

    def _kw(self) -> dict:
        nominal = None if self.nominal_pose is None else np.array(self.nominal_pose)
        return {"name": self.name, "nominal": nominal}


class FamilySpec(_Common):
    """Base of a plugin family's YAML model: ``name``, ``source``, ``stroke`` (mm),
    ``tool_offset``, ``nominal_pose``, ``base_points``, ``platform_points`` — declare
    ``family: Literal["<name>"]``, the family's own fields and ``build()``."""

    def explicit_kw(self) -> dict:
        """``name`` and ``nominal`` keyword arguments of the mechanism constructor."""
        return self._kw()
