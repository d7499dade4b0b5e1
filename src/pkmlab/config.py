"""The one module that turns YAML into typed, validated objects (pydantic v2).

Everything downstream trusts what this module returns. Quantities are converted once, here:
a bare number is read in the field's documented unit (mm for lengths, deg for angles), or a
string carries its unit (``"225 mm"``, ``"4 in"``, ``"33.7 deg"``, ``"0.5 rad"``). Every error
is a :class:`~pkmlab.errors.ParameterError` reading ``<field path>: must be …; got …``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import yaml
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, TypeAdapter, ValidationError

from .errors import ParameterError, format_value
from .mechanisms import PSU6, UPS6, Luzi3, Mechanism
from .units import ANGLE_UNITS, LENGTH_UNITS, parse_angle, parse_length

__all__ = ["load_mechanism", "mechanism_spec", "MechanismSpec"]


class _Invalid(ValueError):
    """Raised inside validators; the loader prefixes the field path."""


def _checked(parse, *args):
    try:
        return parse(*args)
    except ParameterError as exc:
        raise _Invalid(f"must be {exc.allowed}; got {format_value(exc.got)}") from None


def _length(v: Any) -> float:
    return _checked(parse_length, v, "")


def _angle(v: Any) -> float:
    return _checked(parse_angle, v, "")


def _length_list(n: int | None):
    def parse(v: Any) -> list[float]:
        if not isinstance(v, list | tuple) or (n is not None and len(v) != n):
            what = f"a list of {n} lengths" if n else "a list of lengths"
            raise _Invalid(f"must be {what} (mm or with units); got {format_value(v)}")
        return [_length(x) for x in v]
    return parse


def _points(v: Any) -> list[list[float]]:
    if not isinstance(v, list | tuple) or not all(isinstance(r, list | tuple) for r in v):
        raise _Invalid(f"must be a list of [x, y, z] points (mm); got {format_value(v)}")
    rows = []
    for row in v:
        if len(row) != 3:
            raise _Invalid(f"must be a list of [x, y, z] points (mm); got the point "
                           f"{format_value(row)}")
        rows.append([_length(x) for x in row])
    return rows


def _pose(v: Any) -> list[float]:
    if not isinstance(v, list | tuple) or len(v) != 6:
        raise _Invalid("must be [x, y, z, θx, θy, θz] (lengths in mm, angles in deg or with "
                       f"units); got {format_value(v)}")
    return [_length(x) for x in v[:3]] + [_angle(x) for x in v[3:]]


def _stroke(v: Any) -> list[float]:
    vals = _length_list(2)(v)
    if vals[0] >= vals[1]:
        raise _Invalid(f"must be [min, max] with min < max; got {format_value(v)}")
    return vals


def _positive_length(v: Any) -> float:
    x = _length(v)
    if x <= 0:
        raise _Invalid(f"must be a length > 0 mm; got {format_value(v)}")
    return x


def _link_lengths(v: Any) -> float | list[float]:
    if isinstance(v, list | tuple):
        vals = _length_list(6)(v)
        if min(vals) <= 0:
            raise _Invalid(f"must be lengths > 0 mm; got {format_value(v)}")
        return vals
    return _positive_length(v)


def _auto_angle(v: Any) -> float | None:
    return None if v == "auto" else _angle(v)


Length = Annotated[float, BeforeValidator(_length)]
PositiveLength = Annotated[float, BeforeValidator(_positive_length)]
Angle = Annotated[float, BeforeValidator(_angle)]
AutoAngle = Annotated[float | None, BeforeValidator(_auto_angle)]
Radii = Annotated[list[float], BeforeValidator(_length_list(2))]
Stroke = Annotated[list[float], BeforeValidator(_stroke)]
Points = Annotated[list[list[float]], BeforeValidator(_points)]
Vector3 = Annotated[list[float], BeforeValidator(_length_list(3))]
Pose = Annotated[list[float], BeforeValidator(_pose)]
LinkLengths = Annotated[float | list[float], BeforeValidator(_link_lengths)]


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


class PSU6Spec(_Common):
    family: Literal["psu6"]
    generator: PairedCircles | None = None
    link_length: LinkLengths

    def build(self) -> Mechanism:
        if self._explicit("generator"):
            return PSU6(self.base_points, self.platform_points, self.link_length, self.stroke,
                        self.tool_offset, **self._kw())
        return PSU6.from_circles(**self.generator.model_dump(), link_length=self.link_length,
                                 stroke=self.stroke, tool_offset=self.tool_offset, **self._kw())


class UPS6Spec(_Common):
    family: Literal["ups6"]
    generator: PairedCircles | None = None

    def build(self) -> Mechanism:
        if self._explicit("generator"):
            return UPS6(self.base_points, self.platform_points, self.stroke, self.tool_offset,
                        **self._kw())
        return UPS6.from_circles(**self.generator.model_dump(), stroke=self.stroke,
                                 tool_offset=self.tool_offset, **self._kw())


class Luzi3Generator(_Model):
    base_diameter: PositiveLength
    phi: Angle = Field(description="angle between consecutive base points of different chains")
    platform_diameter: PositiveLength


class Luzi3Spec(_Common):
    family: Literal["luzi3"]
    generator: Luzi3Generator | None = None
    upper_link: PositiveLength
    tool_offset: Vector3 | Literal["centroid"] = "centroid"  # type: ignore[assignment]

    def build(self) -> Mechanism:
        explicit = self._explicit("generator")
        offset = self.tool_offset
        if explicit:
            if offset == "centroid":
                offset = np.mean(np.asarray(self.platform_points), axis=0)
            return Luzi3(self.base_points, self.platform_points, self.upper_link, self.stroke,
                         offset, **self._kw())
        return Luzi3.from_paper(**self.generator.model_dump(), upper_link=self.upper_link,
                                stroke=self.stroke,
                                tool_offset=None if offset == "centroid" else offset,
                                **self._kw())


MechanismSpec = Annotated[PSU6Spec | UPS6Spec | Luzi3Spec, Field(discriminator="family")]
_ADAPTER = TypeAdapter(MechanismSpec)
_GENERATOR_FIELDS = set(PairedCircles.model_fields) | set(Luzi3Generator.model_fields) | {"phi"}


def _loc(loc: tuple) -> str:
    parts = [str(p) for p in loc if p not in ("psu6", "ups6", "luzi3")]
    out = ""
    for p in parts:
        out += f"[{p}]" if p.isdigit() else (f".{p}" if out else p)
    return out or "(top level)"


def _translate(exc: ValidationError, prefix: str = "") -> ParameterError:
    err = exc.errors()[0]
    field = prefix + _loc(err["loc"])
    kind, msg, got = err["type"], err["msg"], err.get("input")
    if kind == "value_error":
        text = msg.removeprefix("Value error, ")
        allowed, _, given = text.removeprefix("must be ").partition("; got ")
        return ParameterError(field, allowed, given or got)
    if kind == "missing":
        return ParameterError(field, "given (required)", None)
    if kind == "extra_forbidden":
        return ParameterError(field, "a known key (unknown keys are not allowed)",
                              field.rsplit(".", 1)[-1])
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        return ParameterError(prefix + "family", "one of ['luzi3', 'psu6', 'ups6']",
                              err.get("ctx", {}).get("tag", got))
    if kind == "literal_error":
        return ParameterError(field, msg.removeprefix("Input should be "), got)
    return ParameterError(field, msg, got)


def mechanism_spec(data: dict, prefix: str = "") -> PSU6Spec | UPS6Spec | Luzi3Spec:
    """Validate a mechanism mapping into its typed spec (no geometry checks yet)."""
    if not isinstance(data, dict):
        raise ParameterError(prefix or "(mechanism)", "a mapping of mechanism fields",
                             type(data).__name__)
    try:
        return _ADAPTER.validate_python(data)
    except ValidationError as exc:
        raise _translate(exc, prefix) from None


def load_mechanism(source: str | Path | dict) -> Mechanism:
    """Build a mechanism from a YAML file path or an already-parsed mapping.

    Raises:
        ParameterError: naming the field path, the allowed values and the value given.
    """
    if isinstance(source, dict):
        data = source
    else:
        path = Path(source)
        if not path.is_file():
            raise ParameterError("path", "an existing mechanism YAML file", str(path))
        try:
            data = yaml.safe_load(path.read_text())
        except yaml.YAMLError as exc:
            raise ParameterError(str(path), "valid YAML", str(exc).splitlines()[0]) from None
    spec = mechanism_spec(data)
    try:
        return spec.build()
    except ParameterError as exc:
        if exc.field in _GENERATOR_FIELDS and getattr(spec, "generator", None) is not None:
            raise ParameterError(f"generator.{exc.field}", exc.allowed, exc.got) from None
        raise


# Units accepted, for documentation and the CLI's help text.
UNITS_HELP = (f"lengths: bare numbers in mm or strings with {sorted(LENGTH_UNITS)}; "
              f"angles: bare numbers in deg or strings with {sorted(ANGLE_UNITS)}")
