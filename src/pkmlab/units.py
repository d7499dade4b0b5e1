"""Unit parsing. Internal units are millimetres and radians; conversion happens once, at load.

A quantity is either a bare number, read in the field's documented unit, or a string with a unit
such as ``"225 mm"``, ``"4 in"``, ``"33.7 deg"`` or ``"0.5 rad"``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from .errors import ParameterError

__all__ = ["LENGTH_UNITS", "ANGLE_UNITS", "parse_length", "parse_angle", "parse_quantity",
           "parse_physical", "MASS_UNITS", "FORCE_UNITS", "TORQUE_UNITS", "SPEED_UNITS",
           "ANGULAR_SPEED_UNITS", "INERTIA_UNITS", "TIME_UNITS", "FREQUENCY_UNITS", "LEAD_UNITS",
           "ActuatorDisplay", "LINEAR_DISPLAY", "ROTARY_DISPLAY", "actuator_display",
           "effort_limit"]

LENGTH_UNITS = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "inch": 25.4, "ft": 304.8}
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0, "°": math.pi / 180.0}

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z°]*)\s*$")


def parse_quantity(value: Any, field: str, units: dict[str, float], default_unit: str) -> float:
    """Convert ``value`` to the internal unit of ``units`` (factor 1.0).

    Bare numbers are taken in ``default_unit``. Raises :class:`ParameterError` naming ``field``.
    """
    return _parse(value, field, units, default_unit, _QUANTITY, lambda u: u)


def _parse(value, field, units, default_unit, pattern, normalise) -> float:
    allowed = f"a number (in {default_unit}) or a string with a unit from {sorted(units)}"
    if isinstance(value, bool):
        raise ParameterError(field, allowed, value)
    if isinstance(value, int | float):
        number, unit = float(value), default_unit
    elif isinstance(value, str):
        match = pattern.match(value)
        if match is None:
            raise ParameterError(field, allowed, value)
        number = float(match.group(1))
        unit = normalise(match.group(2)) or default_unit
        if unit not in units:
            raise ParameterError(field, allowed, value)
    else:
        raise ParameterError(field, allowed, value)
    if not math.isfinite(number):
        raise ParameterError(field, "a finite " + allowed, value)
    return number * units[unit]


def parse_length(value: Any, field: str, default_unit: str = "mm") -> float:
    """Length in mm from a bare number (``default_unit``) or a string such as ``"4 in"``."""
    from .limits import LENGTH_MAX_MM

    mm = parse_quantity(value, field, LENGTH_UNITS, default_unit) / LENGTH_UNITS["mm"]
    if abs(mm) > LENGTH_MAX_MM:
        raise ParameterError(field, f"a length of at most {LENGTH_MAX_MM:g} mm (1 km) in "
                             "magnitude", value)
    return mm


def parse_angle(value: Any, field: str, default_unit: str = "deg") -> float:
    """Angle in rad from a bare number (``default_unit``) or a string such as ``"30 deg"``."""
    return parse_quantity(value, field, ANGLE_UNITS, default_unit)


# ---- other physical quantities (requirements: payloads, motions, actuators) --------------------
# Internal units: kg, mm, s, N, N·mm, rad. Unit spellings are normalised before lookup: "·" and
# " " → "*", "²" → "^2", so "kg·m²", "kg*m^2" and "N m" are the same unit.

MASS_UNITS = {"kg": 1.0, "g": 1e-3, "lb": 0.45359237}
FORCE_UNITS = {"N": 1.0, "kN": 1e3, "lbf": 4.4482216152605}
TORQUE_UNITS = {"N*mm": 1.0, "N*m": 1e3, "Nm": 1e3, "Nmm": 1.0, "mN*m": 1.0}
SPEED_UNITS = {"mm/s": 1.0, "m/s": 1e3, "in/s": 25.4}
ANGULAR_SPEED_UNITS = {"rad/s": 1.0, "deg/s": math.pi / 180.0, "rpm": 2.0 * math.pi / 60.0}
INERTIA_UNITS = {"kg*mm^2": 1.0, "kg*m^2": 1e6, "kg*cm^2": 1e2, "g*mm^2": 1e-3}
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
FREQUENCY_UNITS = {"Hz": 1.0}
LEAD_UNITS = {"mm/rev": 1.0, "mm": 1.0}

_ANY_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


def _normalise_unit(unit: str) -> str:
    unit = unit.replace("·", "*").replace("²", "^2").replace("×", "*")
    return re.sub(r"\s+", "*", unit.strip())


def parse_physical(value: Any, field: str, units: dict[str, float], default_unit: str) -> float:
    """Convert ``value`` (a bare number in ``default_unit`` or a string with a unit from
    ``units``, compound units allowed: ``"500 mm/s"``, ``"1.2 kg·m²"``, ``"3 N m"``) to the
    internal unit (factor 1.0). Raises :class:`ParameterError` naming ``field``."""
    return _parse(value, field, units, default_unit, _ANY_QUANTITY, _normalise_unit)


# ---- the one display convention for actuator quantities ---------------------------------
@dataclass(frozen=True)
class ActuatorDisplay:
    """How a person reads an actuator's quantities (tables, CSV headers, plots, CLI).

    Internal units stay mm, rad, N and N·mm. A linear actuator is read in mm, mm/s and N
    (its value is a *stroke*, its effort a *force*); a rotary one (servo / crank motor,
    ``actuator_unit`` rad) in deg, deg/s and N·m (its value is an *angle*, its effort a
    *torque*), and its stiffness in N·m/rad. Multiply an internal value by ``value_scale``,
    ``rate_scale``, ``effort_scale`` or ``stiffness_scale`` to get the displayed one.
    """

    rotary: bool
    value: str            # "stroke" / "angle"
    value_unit: str       # "mm" / "deg"
    value_scale: float
    rate: str             # "speed" / "angular speed"
    rate_unit: str        # "mm/s" / "deg/s"
    rate_scale: float
    effort: str           # "force" / "torque"
    effort_unit: str      # "N" / "N·m"
    effort_scale: float
    stiffness_unit: str   # "N/mm" / "N·m/rad"
    stiffness_scale: float

    @property
    def value_name(self) -> str:
        """Axis label of the actuator value: ``Leg length (mm)`` / ``Crank angle (deg)``."""
        return "Crank angle (deg)" if self.rotary else "Leg length (mm)"

    def ascii(self, unit: str) -> str:
        """A unit for a CSV header / JSON key: ``N·m`` → ``N_m``, ``deg/s`` → ``deg_s``."""
        return unit.replace("·", "_").replace("/", "_")


LINEAR_DISPLAY = ActuatorDisplay(False, "stroke", "mm", 1.0, "speed", "mm/s", 1.0, "force",
                                 "N", 1.0, "N/mm", 1.0)
ROTARY_DISPLAY = ActuatorDisplay(True, "angle", "deg", 180.0 / math.pi, "angular speed",
                                 "deg/s", 180.0 / math.pi, "torque", "N·m", 1e-3, "N·m/rad",
                                 1e-3)


def actuator_display(actuator_unit: str) -> ActuatorDisplay:
    """The display convention of a mechanism's ``actuator_unit`` (``"mm"`` or ``"rad"``)."""
    return ROTARY_DISPLAY if actuator_unit == "rad" else LINEAR_DISPLAY


def effort_limit(actuator_unit: str, force_limit: float | None,
                 torque_limit: float | None) -> float | None:
    """An actuator effort limit in internal units (N for ``mm`` actuators, N·mm for ``rad``
    ones) from a force limit in N and a servo torque limit in N·m. A linear force limit is
    never read as a torque: a servo without ``torque_limit`` gets ``None``."""
    if actuator_unit == "rad":
        return None if torque_limit is None else float(torque_limit) / ROTARY_DISPLAY.effort_scale
    return None if force_limit is None else float(force_limit)
