"""Mechanism families, registered by name.

A new family adds one module defining a :class:`~pkmlab.mechanisms.base.Mechanism` subclass and
one entry in :data:`REGISTRY` (plus its YAML model in :mod:`pkmlab.config`).
"""

from __future__ import annotations

from .base import LEG_STATUS, NO_STROKE, AssemblyModes, FKResult, IKResult, Mechanism
from .luzi3 import Luzi3
from .psu6 import PSU6
from .rss6 import RSS6
from .ups6 import UPS6

#: family name → mechanism class
REGISTRY: dict[str, type[Mechanism]] = {cls.family: cls for cls in (PSU6, UPS6, Luzi3, RSS6)}

__all__ = ["REGISTRY", "NO_STROKE", "Mechanism", "IKResult", "FKResult", "AssemblyModes",
           "LEG_STATUS", "PSU6", "UPS6", "Luzi3", "RSS6"]
