"""Mechanism families, registered by name.

A built-in family adds one module defining a :class:`~pkmlab.mechanisms.base.Mechanism`
subclass and one entry in :data:`REGISTRY` (plus its YAML model in :mod:`pkmlab.config`).

Plugin families come from installed distributions through the entry point group
``pkmlab.families`` (see :data:`PLUGIN_GROUP`): each entry point names a ``Mechanism`` subclass
that carries ``spec_model``, a pydantic model with ``family: Literal["<name>"]`` and a
``build()`` returning the mechanism (subclass :class:`pkmlab.config.FamilySpec` to get the
common fields), and optionally ``design_aliases`` (named study variables, as in
:data:`pkmlab.study.spec.DESIGN_ALIASES`). :func:`load_plugins` registers them; ``import
pkmlab`` calls it once everything else is imported. A plugin that fails to load is logged and
listed in :data:`PLUGIN_ERRORS`, never fatal.
"""

from __future__ import annotations

from .base import LEG_STATUS, NO_STROKE, AssemblyModes, FKResult, IKResult, Mechanism
from .families.delta3 import Delta3
from .families.ldelta3 import LDelta3
from .joints import Joint, Leg, Link, Parameters
from .luzi3 import Luzi3
from .mobility import PLANAR, SPATIAL, TRANSLATIONAL, Mobility
from .psu6 import PSU6
from .rss6 import RSS6
from .sixleg import SixLeg
from .ups6 import UPS6

#: family name → mechanism class (built-in families, then plugins once loaded)
REGISTRY: dict[str, type[Mechanism]] = {cls.family: cls for cls in (PSU6, UPS6, Luzi3, RSS6,
                                                                  SixLeg, Delta3, LDelta3)}
BUILTIN = frozenset(REGISTRY)

#: entry point group of family plugins
PLUGIN_GROUP = "pkmlab.families"
#: entry point name → why it could not be loaded
PLUGIN_ERRORS: dict[str, str] = {}
_LOADED: set[str] = set()


def _check_plugin(cls) -> None:
    if not (isinstance(cls, type) and issubclass(cls, Mechanism)):
        raise TypeError(f"{cls!r} is not a pkmlab.mechanisms.Mechanism subclass")
    if not isinstance(cls.family, str) or not cls.family:
        raise TypeError(f"{cls.__name__}.family must be a non-empty name")
    if cls.family in REGISTRY and REGISTRY[cls.family] is not cls:
        raise ValueError(f"family {cls.family!r} is already registered "
                         f"({REGISTRY[cls.family].__module__})")
    spec = getattr(cls, "spec_model", None)
    if spec is None or "family" not in getattr(spec, "model_fields", {}) \
            or not callable(getattr(spec, "build", None)):
        raise TypeError(f"{cls.__name__}.spec_model must be a pydantic model with a 'family' "
                        "field and build()")
    if cls._ik_one is None:
        raise TypeError(f"{cls.__name__} has no _ik_one (per-pose numba inverse kinematics)")
    mob, names = cls.mobility, cls.actuator_names
    if len(names) < mob.width or len(set(names)) != len(names):
        raise TypeError(f"{cls.__name__}.actuator_names must name at least one distinct "
                        f"actuator per free coordinate of its mobility ({mob.name}: "
                        f"{', '.join(mob.coordinates)}); got {names}")


def register_family(cls) -> type[Mechanism]:
    """Register a family class (checked as a plugin is) under ``cls.family``; returns it.

    The entry points of :data:`PLUGIN_GROUP` go through this; a family defined in a script
    or a test may call it directly. Registering the same class again is a no-op.
    """
    _check_plugin(cls)
    REGISTRY[cls.family] = cls
    return cls


def load_plugins() -> dict[str, type[Mechanism]]:
    """Register the families of the ``pkmlab.families`` entry points (idempotent); returns
    the plugin families loaded so far."""
    from ..plugins import load_entry_points

    _LOADED.update(load_entry_points(PLUGIN_GROUP, register_family, PLUGIN_ERRORS, "family",
                                     skip=_LOADED))
    return {k: v for k, v in REGISTRY.items() if k not in BUILTIN}


__all__ = ["REGISTRY", "BUILTIN", "PLUGIN_GROUP", "PLUGIN_ERRORS", "load_plugins",
           "register_family", "NO_STROKE", "Mobility", "SPATIAL", "TRANSLATIONAL", "PLANAR",
           "Mechanism", "IKResult", "FKResult", "AssemblyModes", "LEG_STATUS", "PSU6", "UPS6",
           "Luzi3", "RSS6", "SixLeg", "Joint", "Leg", "Link", "Parameters"]
