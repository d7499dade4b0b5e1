"""Quantity types of the YAML models: pydantic ``Annotated`` types whose validators convert a
bare number in the field's documented unit (mm, deg) or a string with its unit, once, at load
(used by :mod:`pkmlab.config` and by family plugins' spec models)."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BeforeValidator, WithJsonSchema

from .errors import ParameterError, format_value
from .poses import POSE_SIZE
from .units import parse_angle, parse_length


class _Shown(str):
    """A value already rendered for an error message (not quoted again)."""

    def __repr__(self) -> str:
        return str(self)


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
    if not isinstance(v, list | tuple) or len(v) != POSE_SIZE:
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


def _auto_positive_length(v: Any) -> float | None:
    return None if v in ("auto", None) else _positive_length(v)


# JSON Schema of the quantity types: a bare number (in the documented unit) or a string with
# its unit, so that editors accept what the loader accepts.
_NUMBER_OR_UNIT = {"anyOf": [{"type": "number"}, {"type": "string"}]}


def _json_list(n: int | None, item: dict = _NUMBER_OR_UNIT) -> WithJsonSchema:
    schema: dict = {"type": "array", "items": item}
    if n is not None:
        schema.update(minItems=n, maxItems=n)
    return WithJsonSchema(schema)


_LENGTH_JSON = WithJsonSchema({**_NUMBER_OR_UNIT, "description": "mm, or a string with units "
                               "('225 mm', '4 in')"})
_ANGLE_JSON = WithJsonSchema({**_NUMBER_OR_UNIT, "description": "deg, or a string with units "
                              "('33.7 deg', '0.5 rad')"})

Length = Annotated[float, BeforeValidator(_length), _LENGTH_JSON]
PositiveLength = Annotated[float, BeforeValidator(_positive_length), _LENGTH_JSON]
Angle = Annotated[float, BeforeValidator(_angle), _ANGLE_JSON]
AutoAngle = Annotated[float | None, BeforeValidator(_auto_angle), _ANGLE_JSON]
AutoLength = Annotated[float | None, BeforeValidator(_auto_positive_length),
                       WithJsonSchema({**_NUMBER_OR_UNIT,
                                       "description": "'auto', mm, or a string with units"})]
Radii = Annotated[list[float], BeforeValidator(_length_list(2)), _json_list(2)]
Stroke = Annotated[list[float], BeforeValidator(_stroke), _json_list(2)]
Points = Annotated[list[list[float]], BeforeValidator(_points),
                   _json_list(None, {"type": "array", "items": _NUMBER_OR_UNIT})]
Vector3 = Annotated[list[float], BeforeValidator(_length_list(3)), _json_list(3)]
Pose = Annotated[list[float], BeforeValidator(_pose), _json_list(POSE_SIZE)]
LinkLengths = Annotated[float | list[float], BeforeValidator(_link_lengths),
                        WithJsonSchema({"anyOf": [_NUMBER_OR_UNIT,
                                                  {"type": "array", "items": _NUMBER_OR_UNIT}]})]


def _angle_window(v: Any) -> list[float]:
    if not isinstance(v, list | tuple) or len(v) != 2:
        raise _Invalid(f"must be [min, max], two servo angles (deg or with units); got "
                       f"{format_value(v)}")
    vals = [_angle(x) for x in v]
    if vals[0] >= vals[1]:
        raise _Invalid(f"must be [min, max] with min < max; got {format_value(v)}")
    return vals


def _directions(v: Any) -> list[list[float]]:
    if (not isinstance(v, list | tuple) or len(v) != 6
            or not all(isinstance(r, list | tuple) and len(r) == 3 for r in v)):
        raise _Invalid(f"must be six [x, y, z] directions; got {format_value(v)}")
    return [[float(x) for x in row] for row in v]


def _branches(v: Any) -> list[float]:
    vals = v if isinstance(v, list | tuple) else [v] * 6
    if len(vals) != 6 or any(x not in (-1, 1) for x in vals):
        raise _Invalid(f"must be -1 or +1, or a list of six of them; got {format_value(v)}")
    return [float(x) for x in vals]


AngleWindow = Annotated[list[float], BeforeValidator(_angle_window), _json_list(2)]
Directions = Annotated[list[list[float]], BeforeValidator(_directions),
                       _json_list(6, {"type": "array", "items": {"type": "number"}})]
Branches = Annotated[list[float], BeforeValidator(_branches),
                     WithJsonSchema({"anyOf": [{"enum": [-1, 1]},
                                               {"type": "array", "items": {"enum": [-1, 1]}}]})]
