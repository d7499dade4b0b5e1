"""The one module that turns YAML into typed, validated objects (pydantic v2).

Everything downstream trusts what this module returns. Quantities are converted once, here:
a bare number is read in the field's documented unit (mm for lengths, deg for angles), or a
string carries its unit (``"225 mm"``, ``"4 in"``, ``"33.7 deg"``, ``"0.5 rad"``). Every error
is a :class:`~pkmlab.errors.ParameterError` reading ``<field path>: must be …; got …``.
"""

from __future__ import annotations

import copy
import re
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, TypeAdapter, ValidationError

from .errors import ParameterError, format_value, from_validation_error
from .mechanisms import PSU6, UPS6, Luzi3, Mechanism
from .units import ANGLE_UNITS, LENGTH_UNITS, parse_angle, parse_length
from .yamlio import load_yaml, remember, where

__all__ = ["load_mechanism", "mechanism_spec", "MechanismSpec", "workspace_spec", "WorkspaceSpec",
           "load_workspace_study", "WorkspaceStudySpec", "load_study", "StudySpec",
           "study_schema", "set_path"]


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


def _translate(exc: ValidationError, prefix: str = "") -> ParameterError:
    """Pydantic's errors → ``<field> (<file>, line, column): must be …; got …``."""
    root = globals().get(exc.title, MechanismSpec)  # a model's name, or the mechanism union
    return from_validation_error(exc, root, prefix, where)


# ---- workspace requests ------------------------------------------------------------------------


def _angle_triple(v: Any) -> list[float]:
    if not isinstance(v, list | tuple) or len(v) != 3:
        raise _Invalid(f"must be three angles [θx, θy, θz] (deg or with units); got "
                       f"{format_value(v)}")
    return [_angle(x) for x in v]


AngleTriple = Annotated[list[float], BeforeValidator(_angle_triple)]


class JointLimitsSpec(_Model):
    """Passive joint cone half-angles; axes default to the link directions at nominal."""

    base: Angle | None = Field(None, description="base-side joint cone half-angle (deg)")
    platform: Angle | None = Field(None, description="platform-side joint cone half-angle")
    base_axes: Points | None = Field(None, description="6 mounting axes, base frame")
    platform_axes: Points | None = Field(None, description="6 mounting axes, platform frame")


def _stroke_choice(v: Any) -> bool | list[float]:
    if v is True:
        return True
    if v is False:
        raise _Invalid("must be true or a window [min, max] (without a stroke limit the "
                       "workspace is unbounded); got False")
    return _stroke(v)


class ConstraintsSpec(_Model):
    stroke: Annotated[bool | list[float], BeforeValidator(_stroke_choice)] = Field(
        True, description="true (the mechanism's window) or [min, max] to try another")
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
    samples: int = Field(7, ge=1, le=101, description="orientation samples per angle")
    resolution: PositiveLength = Field(2.5, description="grid spacing (mm)")
    constraints: ConstraintsSpec = ConstraintsSpec()
    slice_window: PositiveLength = Field(152.4, description="slice plot window edge (mm)")
    slice_spacing: PositiveLength = Field(12.7, description="slice plot spacing (mm)")

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
        if self.box is not None:
            if any(not 0 <= a <= np.pi for a in self.box):
                raise ParameterError("box", "half-ranges in [0, 180] deg",
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
        cons = Constraints(stroke=c.stroke if c.stroke is True else tuple(c.stroke),
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
        data = _read_yaml(Path(source), "mechanism")
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


# ---- design studies -----------------------------------------------------------------------------

#: named design variables → (path in the mechanism mapping, quantity), per family
DESIGN_ALIASES: dict[str, dict[str, tuple[str, str]]] = {
    fam: {
        "base_inner_radius": ("generator.base_radii[0]", "length"),
        "base_outer_radius": ("generator.base_radii[1]", "length"),
        "platform_inner_radius": ("generator.platform_radii[0]", "length"),
        "platform_outer_radius": ("generator.platform_radii[1]", "length"),
        "platform_rotation": ("generator.platform_rotation", "angle"),
        "base_pair_angle": ("generator.base_pair_angle", "angle"),
        "base_pair_separation": ("generator.base_pair_separation", "angle"),
        "platform_pair_separation": ("generator.platform_pair_separation", "angle"),
        "stroke_min": ("stroke[0]", "length"),
        "stroke_max": ("stroke[1]", "length"),
        "tool_offset_z": ("tool_offset[2]", "length"),
        "pairing": ("generator.pairing", "text"),
        **({"link_length": ("link_length", "length")} if fam == "psu6" else {}),
    } for fam in ("psu6", "ups6")
}
DESIGN_ALIASES["luzi3"] = {
    "base_diameter": ("generator.base_diameter", "length"),
    "platform_diameter": ("generator.platform_diameter", "length"),
    "phi": ("generator.phi", "angle"),
    "upper_link": ("upper_link", "length"),
    "stroke_min": ("stroke[0]", "length"),
    "stroke_max": ("stroke[1]", "length"),
}
_QUANTITY = {"length": (parse_length, "mm"), "angle": (parse_angle, "deg"),
             "number": (None, ""), "text": ("text", "")}


class DesignVariableSpec(_Model):
    """One design variable: a continuous or integer range, or a list of choices."""

    low: Any = None
    high: Any = None
    choices: list[Any] | None = None
    type: Literal["continuous", "integer", "choice"] | None = None
    path: str | None = Field(None, description="mechanism field, e.g. generator.base_radii[1]")
    quantity: Literal["length", "angle", "number", "text"] | None = None
    levels: int = Field(5, ge=2, le=1000, description="grid optimiser: values per variable")


class DexteritySpec(_Model):
    characteristic_length: Any = Field("auto", description="'auto' (Angeles) or a length")
    gci_samples: int = Field(2000, ge=10, le=1_000_000)
    force_limit: float = Field(150.0, gt=0, description="actuator force limit (N)")


class TrajectorySpec(_Model):
    paper_motion: Literal[True] = True
    segment_time: float = Field(1.0, gt=0, description="s per cubic segment")
    payload: float = Field(0.0, ge=0, description="payload mass (kg)")


class EvaluateSpec(_Model):
    workspace: WorkspaceSpec | None = None
    inscribed: bool = False
    orientation_capability: bool = False
    dexterity: DexteritySpec | None = None
    trajectory: TrajectorySpec | None = None


class OptimizerSpec(_Model):
    method: Literal["grid", "sobol", "lhs", "nsga2", "de"]
    samples: int = Field(64, ge=1, le=10_000_000, description="sobol / lhs designs")
    population: int = Field(32, ge=4, le=100_000)
    generations: int = Field(10, ge=1, le=100_000)


class MechanismSource(_Model):
    """A mechanism file plus overrides, or (``inline``) the mechanism mapping itself."""

    file: str | None = Field(None, description="mechanism YAML, relative to the study file")
    overrides: dict[str, Any] = Field(default_factory=dict)
    inline: dict[str, Any] | None = Field(None, description="a mechanism mapping (family, "
                                          "generator, ...) instead of a file")


class StudySpec(_Model):
    """A design study file (see README): what to vary, evaluate, optimise and keep."""

    study: str = Field(pattern=r"^[A-Za-z0-9._-]+$")
    description: str = ""
    mechanism: MechanismSource
    design: dict[str, DesignVariableSpec] = Field(min_length=1)
    evaluate: EvaluateSpec
    objectives: list[dict[Literal["maximize", "minimize"], str]] = Field(min_length=1)
    constraints: list[dict[str, Any]] = Field(default_factory=list)
    optimizer: OptimizerSpec
    seed: int = 0
    output: str | None = Field(None, description="output folder (default results/<study>)")
    top: int = Field(5, ge=0, le=100, description="Pareto designs exported in full")


def _design_variable(name: str, v: DesignVariableSpec, family: str) -> dict:
    field = f"design.{name}"
    alias = DESIGN_ALIASES[family].get(name)
    path = v.path or (alias[0] if alias else None)
    quantity = v.quantity or (alias[1] if alias else None)
    if path is None:
        raise ParameterError(field, f"a known variable of family {family!r} "
                             f"{sorted(DESIGN_ALIASES[family])} or one with 'path' and "
                             "'quantity'", name)
    if quantity is None:
        raise ParameterError(f"{field}.quantity", "one of ['length', 'angle', 'number']", None)
    kind = v.type or ("choice" if v.choices is not None else "continuous")
    parse, unit = _QUANTITY[quantity]

    if quantity == "text" and kind != "choice":
        raise ParameterError(f"{field}.choices", "a list of choices (a text variable has no "
                             "range)", None)

    def conv(x, which):
        if parse == "text":
            if not isinstance(x, str):
                raise ParameterError(f"{field}.{which}", "a text choice", x)
            return x
        try:
            if parse is None:
                if isinstance(x, bool) or not isinstance(x, int | float):
                    raise ParameterError("", "a number", x)
                return float(x)
            return parse(x, "")
        except ParameterError as exc:
            raise ParameterError(f"{field}.{which}", exc.allowed if parse else "a number",
                                 x) from None

    if kind == "choice":
        if not v.choices:
            raise ParameterError(f"{field}.choices", "a non-empty list", v.choices)
        return {"name": name, "path": path, "quantity": quantity, "type": "choice",
                "choices": [conv(c, "choices") for c in v.choices], "unit": unit}
    if v.low is None or v.high is None:
        raise ParameterError(f"{field}.{'low' if v.low is None else 'high'}",
                             "given (a bound of the range)", None)
    lo, hi = conv(v.low, "low"), conv(v.high, "high")
    if not lo < hi:
        raise ParameterError(field, "low < high", f"low {v.low!r}, high {v.high!r}")
    if kind == "integer" and (lo != int(lo) or hi != int(hi)):
        raise ParameterError(field, "integer bounds for an integer variable", [v.low, v.high])
    return {"name": name, "path": path, "quantity": quantity, "type": kind, "low": lo,
            "high": hi, "levels": v.levels, "unit": unit}


def load_study(source: str | Path):
    """Validate a study file → ``(spec, resolved)``.

    ``resolved`` is a plain dict with every default filled in and every quantity converted
    (mm, rad): ``mechanism`` (the mechanism mapping with overrides applied), ``variables``,
    ``evaluate`` (workspace request, flags), ``objectives``, ``constraints``, ``optimizer``,
    ``seed``, ``output``.
    """
    from .study.metrics import ALIASES, METRICS, needs_of

    path = Path(source)
    data = _read_yaml(path, "study")
    if not isinstance(data, dict):
        raise ParameterError("(study)", "a mapping with study, mechanism, design, evaluate, "
                             "objectives, optimizer", type(data).__name__)
    try:
        spec = StudySpec.model_validate(data)
    except ValidationError as exc:
        raise _translate(exc) from None
    src = spec.mechanism
    if (src.file is None) == (src.inline is None):
        raise ParameterError("mechanism", "exactly one of 'file' (with optional 'overrides') "
                             "or 'inline'", sorted(k for k in ("file", "inline")
                                                   if getattr(src, k) is not None))
    if src.file is not None:
        mech_path = (path.parent / src.file).resolve()
        mech_data = _read_yaml(mech_path, "mechanism") if mech_path.is_file() else None
        if not isinstance(mech_data, dict):
            raise ParameterError("mechanism.file", "an existing mechanism YAML file", src.file)
    else:
        mech_path, mech_data = path, dict(src.inline)
    mech_data = _merge(mech_data, src.overrides)
    try:
        mech = load_mechanism(mech_data)
    except ParameterError as exc:
        raise ParameterError(f"mechanism.{exc.field}", exc.allowed, exc.got) from None
    variables = [_design_variable(n, v, mech.family) for n, v in spec.design.items()]
    for var in variables:            # the path's parent must exist in the mechanism mapping
        try:
            parts = _path_parts(var["path"])
            node = mech_data
            for p in parts[:-1]:
                node = node[p]
            leaf = parts[-1]
            if isinstance(leaf, int):
                node[leaf]
            elif not isinstance(node, dict):
                raise TypeError(var["path"])
        except (KeyError, IndexError, TypeError):
            raise ParameterError(f"design.{var['name']}.path", "a field present in the "
                                 "mechanism file (generator block, stroke, ...)",
                                 var["path"]) from None
    ev = spec.evaluate
    blocks = {"workspace": ev.workspace is not None,
              "inscribed": ev.workspace is not None and ev.inscribed,
              "orientation_capability": ev.workspace is not None and ev.orientation_capability,
              "dexterity": ev.dexterity is not None and ev.workspace is not None,
              "trajectory": ev.trajectory is not None}
    if ev.dexterity is not None and ev.workspace is None:
        raise ParameterError("evaluate.dexterity", "used with an evaluate.workspace block "
                             "(its aggregates are over that workspace)", "no workspace")
    known = sorted(set(METRICS) | set(ALIASES))

    def check_metric(name, where):
        if name not in METRICS and name not in ALIASES:
            raise ParameterError(where, f"one of {known}", name)
        need = needs_of(name)
        if need is not None and not blocks[need]:
            raise ParameterError(where, f"a metric the evaluation computes (add evaluate."
                                 f"{need})", name)
        if name in ALIASES and ev.workspace.kind != ALIASES[name]:
            raise ParameterError(where, f"the volume of the evaluated kind "
                                 f"('{ev.workspace.kind}_volume')", name)

    objectives = []
    for i, o in enumerate(spec.objectives):
        if len(o) != 1:
            raise ParameterError(f"objectives[{i}]", "one of {maximize: metric} or "
                                 "{minimize: metric}", o)
        (sense, name), = o.items()
        check_metric(name, f"objectives[{i}].{sense}")
        objectives.append({"metric": name, "sense": sense})
    constraints = []
    for i, c in enumerate(spec.constraints):
        if not isinstance(c, dict) or len(c) != 1:
            raise ParameterError(f"constraints[{i}]", "{metric: {min: x} | {max: x}} or "
                                 "{metric: true}", c)
        (name, rule), = c.items()
        check_metric(name, f"constraints[{i}]")
        if rule is True:
            rule = {"min": 1.0}
        if not isinstance(rule, dict) or not rule or set(rule) - {"min", "max"}:
            raise ParameterError(f"constraints[{i}].{name}", "{min: x}, {max: x} or true",
                                 rule)
        for k, x in rule.items():
            if isinstance(x, bool) or not isinstance(x, int | float):
                raise ParameterError(f"constraints[{i}].{name}.{k}", "a number", x)
        constraints.append({"metric": name, **{k: float(x) for k, x in rule.items()}})
    opt = spec.optimizer
    if opt.method == "de" and len(objectives) != 1:
        raise ParameterError("optimizer.method", "'nsga2', 'grid', 'sobol' or 'lhs' for "
                             "several objectives ('de' takes one)", opt.method)
    if opt.method in ("nsga2", "de") and any(v["type"] == "choice" for v in variables):
        raise ParameterError("optimizer.method", "'grid', 'sobol' or 'lhs' with choice "
                             "variables", opt.method)
    dx = ev.dexterity
    evaluate = {
        # the validated block as written (units included): parsed again where it is used
        "workspace": None if ev.workspace is None else data["evaluate"]["workspace"],
        "inscribed": blocks["inscribed"],
        "orientation_capability": blocks["orientation_capability"],
        "dexterity": None if dx is None else {
            "characteristic_length": (None if str(dx.characteristic_length) == "auto"
                                      else parse_length(dx.characteristic_length,
                                                        "evaluate.dexterity."
                                                        "characteristic_length")),
            "gci_samples": dx.gci_samples, "force_limit": dx.force_limit},
        "trajectory": None if ev.trajectory is None else ev.trajectory.model_dump(),
    }
    resolved = {"study": spec.study, "description": spec.description,
                "mechanism": mech_data, "mechanism_file": str(mech_path),
                "variables": variables, "evaluate": evaluate, "objectives": objectives,
                "constraints": constraints, "optimizer": opt.model_dump(), "seed": spec.seed,
                "output": spec.output or f"results/{spec.study}", "top": spec.top}
    return spec, resolved


def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) \
            else v
    return out


_PATH_RE = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)")


def _path_parts(path: str) -> list:
    parts: list = []
    for piece in path.split("."):
        m = _PATH_RE.fullmatch(piece)
        if not m:
            raise KeyError(path)
        parts.append(m.group(1))
        parts += [int(i) for i in re.findall(r"\[(\d+)\]", m.group(2))]
    return parts


def set_path(data: dict, path: str, value) -> dict:
    """A deep copy of ``data`` with ``path`` (``a.b[1]``) set to ``value``."""
    out = copy.deepcopy(data)
    parts = _path_parts(path)
    node = out
    for p in parts[:-1]:
        node = node[p]
    node[parts[-1]] = value
    return out


def study_schema() -> dict:
    """JSON Schema of the study file (for editors)."""
    return StudySpec.model_json_schema()
