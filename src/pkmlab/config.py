"""The one module that turns YAML into typed, validated objects (pydantic v2).

Everything downstream trusts what this module returns. Quantities are converted once, here:
a bare number is read in the field's documented unit (mm for lengths, deg for angles), or a
string carries its unit (``"225 mm"``, ``"4 in"``, ``"33.7 deg"``, ``"0.5 rad"``). Every error
is a :class:`~pkmlab.errors.ParameterError` reading ``<field path>: must be …; got …``.
"""

from __future__ import annotations

import typing
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    BeforeValidator,
    Field,
    TypeAdapter,
    ValidationError,
    WithJsonSchema,
)

from . import limits
from .errors import ParameterError, format_value, from_validation_error
from .mechanisms import Mechanism
from .quantities import (  # noqa: F401 (re-exported for plugins' spec models)
    _NUMBER_OR_UNIT,
    Angle,
    AngleWindow,
    AutoAngle,
    AutoLength,
    Branches,
    Directions,
    LinkLengths,
    Points,
    Pose,
    PositiveLength,
    Radii,
    Stroke,
    Vector3,
    _angle,
    _angle_window,
    _auto_angle,
    _auto_positive_length,
    _Invalid,
    _json_list,
    _length,
    _length_list,
    _link_lengths,
    _points,
    _pose,
    _positive_length,
    _Shown,
    _stroke,
)
from .specbase import FamilySpec, PairedCircles, _Common, _Model  # noqa: F401
from .units import ANGLE_UNITS, LENGTH_UNITS, parse_angle, parse_length
from .workspaces.constraints import ActuatorWindow
from .yamlio import load_yaml, remember, where

__all__ = ["load_mechanism", "mechanism_spec", "FamilySpec", "mechanism_specs",
           "workspace_spec", "WorkspaceSpec",
           "load_workspace_study", "WorkspaceStudySpec", "to_display", "read_yaml",
           "validate_model"]


_ADAPTERS: dict[tuple, tuple[Any, TypeAdapter]] = {}


def mechanism_specs() -> tuple[type[BaseModel], ...]:
    """The YAML models of every registered family, built-in or plugin (each family class's
    ``spec_model``), in registration order."""
    from .mechanisms import REGISTRY, load_plugins

    load_plugins()
    return tuple(cls.spec_model for cls in REGISTRY.values()
                 if getattr(cls, "spec_model", None) is not None)


def _mechanism_adapter() -> tuple[Any, TypeAdapter]:
    """``(union annotation, TypeAdapter)`` over :func:`mechanism_specs`, cached per set."""
    specs = mechanism_specs()
    if specs not in _ADAPTERS:
        union = Annotated[typing.Union[specs], Field(discriminator="family")]  # noqa: UP007
        _ADAPTERS[specs] = (union, TypeAdapter(union))
    return _ADAPTERS[specs]


def _generator_fields(spec: BaseModel) -> set[str]:
    """Fields of the spec's ``generator`` model, if it has one (errors on them are reported
    under ``generator.``)."""
    generator = getattr(spec, "generator", None)
    return set(type(generator).model_fields) | {"phi"} \
        if isinstance(generator, BaseModel) else set()


def _translate(exc: ValidationError, prefix: str = "") -> ParameterError:
    """Pydantic's errors → ``<field> (<file>, line, column): must be …; got …``."""
    # a model's name, or the mechanism union
    root = globals().get(exc.title) or _mechanism_adapter()[0]
    return from_validation_error(exc, root, prefix, where)


# ---- workspace requests ------------------------------------------------------------------------


def _angle_triple(v: Any) -> list[float]:
    if not isinstance(v, list | tuple) or len(v) != 3:
        raise _Invalid(f"must be three angles [θx, θy, θz] (deg or with units); got "
                       f"{format_value(v)}")
    return [_angle(x) for x in v]


AngleTriple = Annotated[list[float], BeforeValidator(_angle_triple), _json_list(3)]


class JointLimitsSpec(_Model):
    """Passive joint cone half-angles; axes default to the link directions at nominal."""

    base: Angle | None = Field(None, description="base-side joint cone half-angle (deg)")
    platform: Angle | None = Field(None, description="platform-side joint cone half-angle")
    base_axes: Points | None = Field(None, description="6 mounting axes, base frame")
    platform_axes: Points | None = Field(None, description="6 mounting axes, platform frame")


def _stroke_item(x: Any) -> tuple[float, str]:
    """One actuator value as written: ``(value, unit)`` with unit "bare" (a plain number),
    "mm" (a length with units, in mm) or "rad" (an angle with units, in rad)."""
    if isinstance(x, int | float) and not isinstance(x, bool):
        return float(x), "bare"
    if isinstance(x, str):
        try:
            return float(x), "bare"
        except ValueError:
            pass
        for parse, unit in ((parse_length, "mm"), (parse_angle, "rad")):
            try:
                return parse(x, ""), unit
            except ParameterError:
                pass
    raise _Invalid("must be a window [min, max] of actuator values: lengths (mm or with "
                   "units) or, for rotary actuators, servo angles (deg or with units); got "
                   f"{format_value(x)}")


def _stroke_choice(v: Any) -> bool | ActuatorWindow:
    if v is True:
        return True
    if v is False:
        raise _Invalid("must be true or a window [min, max] (without a stroke limit the "
                       "workspace is unbounded); got False")
    if isinstance(v, ActuatorWindow):
        return v
    if not isinstance(v, list | tuple) or len(v) != 2:
        raise _Invalid(f"must be true or a window [min, max]; got {format_value(v)}")
    (lo, u0), (hi, u1) = _stroke_item(v[0]), _stroke_item(v[1])
    if {u0, u1} == {"mm", "rad"}:
        raise _Invalid(f"must be two lengths or two angles, not one of each; got "
                       f"{format_value(v)}")
    unit = u0 if u0 != "bare" else u1
    if unit != "bare":   # a bare number beside a quantity takes the quantity's default unit
        lo = lo if u0 != "bare" else (lo if unit == "mm" else float(np.radians(lo)))
        hi = hi if u1 != "bare" else (hi if unit == "mm" else float(np.radians(hi)))
    if not lo < hi:
        raise _Invalid(f"must be [min, max] with min < max; got {format_value(v)}")
    return ActuatorWindow(lo, hi, unit)


StrokeChoice = Annotated[Any, BeforeValidator(_stroke_choice),
                         WithJsonSchema({"anyOf": [{"type": "boolean"},
                                                   {"type": "array", "items": _NUMBER_OR_UNIT,
                                                    "minItems": 2, "maxItems": 2}]})]


class ConstraintsSpec(_Model):
    stroke: StrokeChoice = Field(
        True, description="true (the mechanism's window) or [min, max] to try another: "
        "lengths (mm or with units), or servo angles (deg or with units) for rotary actuators")
    joint_limits: JointLimitsSpec | None = None
    link_diameter: PositiveLength | None = Field(None, description="leg diameter (mm)")
    kappa_max: float | None = Field(None, ge=1, description="largest condition number")
    characteristic_length: PositiveLength | None = None
    connected: bool = True


class WorkspaceSpec(_Model):
    """One workspace request (YAML ``workspace:`` block or the CLI options)."""

    kind: Literal["constant", "reachable", "dexterous"] = "constant"
    orientation: AngleTriple | None = Field(
        None, description="constant kind: [θx, θy, θz] relative to nominal (deg)")
    box: AngleTriple | None = Field(None, description="Euler half-ranges [a, b, c] (deg)")
    semantics: Literal["simultaneous", "single-axis"] = "simultaneous"
    tilt: Angle | None = Field(None, description="tilt-and-torsion set: largest tilt (deg)")
    torsion: Angle = Field(0.0, description="tilt-and-torsion set: torsion half-range (deg)")
    samples: int = Field(7, ge=limits.SAMPLES_PER_ANGLE[0], le=limits.SAMPLES_PER_ANGLE[1],
                         description="orientation samples per angle")
    resolution: PositiveLength = Field(2.5, description="grid spacing (mm)")
    constraints: ConstraintsSpec = ConstraintsSpec()
    slice_layout: Literal["auto", "paper"] = Field(
        "auto", description="slice plots: 'auto' (window and spacing from the workspace's "
        "bounding box, at most 16 sections) or 'paper' (Hopkins & Williams: 152.4 mm every "
        "12.7 mm)")
    slice_window: AutoLength = Field(None, description="slice plot window edge (mm; 'auto': "
                                     "the layout's)")
    slice_spacing: AutoLength = Field(None, description="slice plot spacing (mm; 'auto': the "
                                      "layout's)")

    def slice_options(self) -> dict:
        """Keyword arguments of :func:`pkmlab.workspaces.output.plots.slice_figure`."""
        return {"layout": self.slice_layout, "window": self.slice_window,
                "spacing": self.slice_spacing}

    def build(self):
        """→ ``dict(kind, orientations, resolution, constraints)`` for :func:`pkmlab.workspace`."""
        from .workspaces import Constraints, JointLimits, OrientationSet

        if self.box is not None and self.tilt is not None:
            raise ParameterError("box", "absent when tilt is given (choose one orientation "
                                 "set)", "both given")
        if self.kind == "constant" and (self.box is not None or self.tilt is not None):
            raise ParameterError("kind", "'reachable' or 'dexterous' when an orientation set "
                                 "(box or tilt) is given", self.kind)
        if self.kind != "constant" and self.box is None and self.tilt is None:
            raise ParameterError("box", "given (or tilt) for kind " + repr(self.kind),
                                 None)
        if self.orientation is not None and self.kind != "constant":
            raise ParameterError("orientation", "only given for kind 'constant'",
                                 self.orientation)
        lo_h, hi_h = limits.RESOLUTION_MM
        if not lo_h <= self.resolution <= hi_h:
            raise ParameterError("resolution", f"a grid spacing in [{lo_h:g}, {hi_h:g}] mm",
                                 _Shown(f"{self.resolution:g} mm"))
        lo_a, hi_a = limits.EULER_HALF_RANGE_DEG
        if self.box is not None:
            if any(not np.radians(lo_a) <= a <= np.radians(hi_a) for a in self.box):
                raise ParameterError("box", f"half-ranges in [{lo_a:g}, {hi_a:g}] deg",
                                     [float(np.degrees(a)) for a in self.box])
            oset = OrientationSet.box(tuple(self.box), self.semantics, self.samples)
        elif self.tilt is not None:
            oset = OrientationSet.tilt_torsion(self.tilt, self.torsion, self.samples)
        else:
            oset = OrientationSet.fixed(tuple(self.orientation or (0.0, 0.0, 0.0)))
        c = self.constraints
        jl = None
        if c.joint_limits is not None:
            j = c.joint_limits
            jl = JointLimits(j.base, j.platform, j.base_axes, j.platform_axes)
        cons = Constraints(stroke=c.stroke,
                           joint_limits=jl, link_diameter=c.link_diameter,
                           kappa_max=c.kappa_max, characteristic_length=c.characteristic_length,
                           connected=c.connected)
        return {"kind": self.kind, "orientations": oset, "resolution": self.resolution,
                "constraints": cons}


def workspace_spec(data: dict, prefix: str = "") -> WorkspaceSpec:
    """Validate a workspace request mapping (errors name ``prefix + field``)."""
    if not isinstance(data, dict):
        raise ParameterError(prefix.rstrip(".") or "(workspace)", "a mapping of workspace "
                             "fields", type(data).__name__)
    try:
        spec = WorkspaceSpec.model_validate(data)
    except ValidationError as exc:
        raise _translate(exc, prefix) from None
    try:
        spec.build()
    except ParameterError as exc:
        raise ParameterError(prefix + exc.field, exc.allowed, exc.got) from None
    return spec


class MechanismRef(_Model):
    file: str = Field(description="mechanism YAML, relative to the study file")


class WorkspaceStudySpec(_Model):
    """A named set of workspace requests on one mechanism (e.g. a paper's figures)."""

    study: str = Field(description="study name (output sub-folder)")
    description: str = ""
    mechanism: MechanismRef
    workspaces: dict[str, WorkspaceSpec] = Field(min_length=1)


def _read_yaml(path: Path, what: str) -> Any:
    if not path.is_file():
        raise ParameterError("path", f"an existing {what} YAML file", str(path))
    return remember(*load_yaml(path))  # bounded, positions kept for the caller's errors


def load_workspace_study(source: str | Path):
    """A workspace study file → ``(spec, mechanism, {name: request})``."""
    path = Path(source)
    data = _read_yaml(path, "workspace study")
    if not isinstance(data, dict):
        raise ParameterError("(study)", "a mapping with study, mechanism, workspaces",
                             type(data).__name__)
    try:
        spec = WorkspaceStudySpec.model_validate(data)
    except ValidationError as exc:
        raise _translate(exc) from None
    for name, ws in spec.workspaces.items():
        try:
            ws.build()
        except ParameterError as exc:
            raise ParameterError(f"workspaces.{name}.{exc.field}", exc.allowed, exc.got) \
                from None
    mech_path = (path.parent / spec.mechanism.file).resolve()
    try:
        mech = load_mechanism(mech_path)
    except ParameterError as exc:
        if exc.field == "path":
            raise ParameterError("mechanism.file", exc.allowed, spec.mechanism.file) from None
        raise ParameterError(f"mechanism ({spec.mechanism.file}): {exc.field}", exc.allowed,
                             exc.got) from None
    return spec, mech, {name: ws.build() for name, ws in spec.workspaces.items()}


def mechanism_spec(data: dict, prefix: str = ""):
    """Validate a mechanism mapping into its typed spec (no geometry checks yet)."""
    if not isinstance(data, dict):
        raise ParameterError(prefix or "(mechanism)", "a mapping of mechanism fields",
                             type(data).__name__)
    try:
        return _mechanism_adapter()[1].validate_python(data)
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
        data = _read_yaml(Path(source), "mechanism")
    spec = mechanism_spec(data)
    try:
        return spec.build()
    except ParameterError as exc:
        if exc.field in _generator_fields(spec):
            raise ParameterError(f"generator.{exc.field}", exc.allowed, exc.got) from None
        raise


# Units accepted, for documentation and the CLI's help text.
UNITS_HELP = (f"lengths: bare numbers in mm or strings with {sorted(LENGTH_UNITS)}; "
              f"angles: bare numbers in deg or strings with {sorted(ANGLE_UNITS)}")


# ---- display form: typed specs back to YAML with explicit units --------------------------------


def _fmt_length(v: float) -> str:
    return f"{v:.12g} mm"


def _fmt_angle(v: float) -> str:
    return f"{np.degrees(v):.12g} deg"


def _display_of(validator):
    """Formatter of a field's parsed value, by the validator that parsed it (None: as is)."""
    table = {_length: _fmt_length, _positive_length: _fmt_length, _angle: _fmt_angle,
             _stroke: lambda v: [_fmt_length(x) for x in v],
             _angle_triple: lambda v: [_fmt_angle(x) for x in v],
             _angle_window: lambda v: [_fmt_angle(x) for x in v],
             _points: lambda v: [[_fmt_length(x) for x in row] for row in v],
             _pose: lambda v: [_fmt_length(x) for x in v[:3]] + [_fmt_angle(x) for x in v[3:]],
             _auto_angle: lambda v: "auto" if v is None else _fmt_angle(v),
             _auto_positive_length: lambda v: "auto" if v is None else _fmt_length(v),
             _link_lengths: lambda v: ([_fmt_length(x) for x in v] if isinstance(v, list)
                                       else _fmt_length(v)),
             _stroke_choice: lambda v: v if v is True else v.shown()}
    if validator in table:
        return table[validator]
    if getattr(validator, "__qualname__", "").startswith("_length_list"):
        return lambda v: [_fmt_length(x) for x in v]
    return None


def to_display(model: BaseModel) -> dict:
    """A validated spec as a YAML mapping with every default filled in and every quantity
    written with its unit (``"225 mm"``, ``"33.7 deg"``); loading it gives the same spec."""
    out: dict = {}
    for name, info in type(model).model_fields.items():
        value = getattr(model, name)
        metadata = list(info.metadata)
        for arg in typing.get_args(info.annotation):       # Optional[Annotated[...]]
            metadata += list(getattr(arg, "__metadata__", ()))
        validator = next((m.func for m in metadata if isinstance(m, BeforeValidator)), None)
        fmt = _display_of(validator)
        if value is None:
            out[name] = "auto" if validator in (_auto_angle, _auto_positive_length) else None
        elif isinstance(value, BaseModel):
            out[name] = to_display(value)
        elif isinstance(value, dict):
            out[name] = {k: to_display(v) if isinstance(v, BaseModel) else v
                         for k, v in value.items()}
        elif fmt is not None and not isinstance(value, str):
            out[name] = fmt(value)
        else:
            out[name] = value
    return out


#: ``read_yaml(path, what)``: the YAML file ``path`` (a ``what`` file), parsed and bounded;
#: while the calling function runs, errors on its values can name their line and column.
read_yaml = _read_yaml


def validate_model(model: type[BaseModel], data: Any, prefix: str = ""):
    """``model.model_validate(data)`` with errors as :class:`ParameterError` (field path
    prefixed with ``prefix``)."""
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise from_validation_error(exc, model, prefix, where) from None
