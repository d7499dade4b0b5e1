"""Study-file blocks for requirements: ``evaluate.task``, ``evaluate.motions``,
``evaluate.payload`` and ``evaluate.actuators`` (pydantic, in the style of
:mod:`pkmlab.study.spec`), and the typed plans built from them once, at load.

Quantities carry units (bare numbers are read in the internal unit named in each field's
description: mm, deg for angles, kg, N, N·mm, mm/s, rad/s, kg·mm², s, Hz). Files (CSV
recordings, point sets, actuator catalogues) resolve relative to the study file and are read
and validated at load: whatever ``pkmlab validate`` accepts, ``pkmlab run`` runs. Errors name
the field: ``evaluate.task.size[0]: must be a length >= 0 mm; got '-5 mm'``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, WithJsonSchema, create_model

from ..config import read_yaml, validate_model
from ..errors import ParameterError, Shown, format_value
from ..limits import INERTIA_MAX, MASS_MAX_KG, SEGMENT_TIME_S
from ..motion import motions as mo
from ..motion.csvfile import load_motion_csv
from ..motion.paper import paper_motion
from ..motion.payload import MassProperties, combine, leg_end_masses, leg_rod_masses
from ..quantities import Angle, Length
from ..tables import read_table, shown
from ..units import (
    ANGULAR_SPEED_UNITS,
    FORCE_UNITS,
    FREQUENCY_UNITS,
    INERTIA_UNITS,
    LEAD_UNITS,
    MASS_UNITS,
    SPEED_UNITS,
    TIME_UNITS,
    TORQUE_UNITS,
    parse_length,
    parse_physical,
)
from ..workspaces.orientations import OrientationSet
from .actuators import ActuatorSpec
from .task import TaskRegion

__all__ = ["TaskSpec", "MotionSpec", "PayloadSpec", "ActuatorsSpec", "TaskPlan",
           "MotionsPlan", "PayloadPlan", "ActuatorsPlan", "build_task", "build_motions",
           "build_payload", "build_actuators"]

_JSON = WithJsonSchema({"anyOf": [{"type": "number"}, {"type": "string"}]})


def _quantity(units: dict, default: str, minimum: float | None = None, strict: bool = False,
              maximum: float | None = None):
    def parse(v: Any) -> float:
        try:
            x = parse_physical(v, "", units, default)
        except ParameterError as exc:
            raise ValueError(f"must be {exc.allowed}; got {format_value(v)}") from None
        if minimum is not None and (x <= minimum if strict else x < minimum):
            raise ValueError(f"must be a value {'>' if strict else '>='} {minimum:g} "
                             f"{default}; got {format_value(v)}")
        if maximum is not None and not abs(x) <= maximum:
            low = "" if minimum is None else f"{'>' if strict else '>='} {minimum:g} and "
            raise ValueError(f"must be a value {low}of magnitude <= {maximum:g} {default}; "
                             f"got {format_value(v)}")
        return x
    return Annotated[float, BeforeValidator(parse), _JSON]


def _nonneg_length(v: Any) -> float:
    try:
        x = parse_length(v, "")
    except ParameterError as exc:
        raise ValueError(f"must be {exc.allowed}; got {format_value(v)}") from None
    if x < 0:
        raise ValueError(f"must be a length >= 0 mm; got {format_value(v)}")
    return x


NonNegLength = Annotated[float, BeforeValidator(_nonneg_length), _JSON]
Mass = _quantity(MASS_UNITS, "kg", 0.0, maximum=MASS_MAX_KG)
PositiveForce = _quantity(FORCE_UNITS, "N", 0.0, strict=True)
PositiveSpeed = _quantity(SPEED_UNITS, "mm/s", 0.0, strict=True)
AngularSpeed = _quantity(ANGULAR_SPEED_UNITS, "rad/s", 0.0)
Torque = _quantity(TORQUE_UNITS, "N*mm", 0.0)
Inertia = _quantity(INERTIA_UNITS, "kg*mm^2", maximum=INERTIA_MAX)
PositiveTime = _quantity(TIME_UNITS, "s", 0.0, strict=True)
Frequency = _quantity(FREQUENCY_UNITS, "Hz", 0.0)
PositiveFrequency = _quantity(FREQUENCY_UNITS, "Hz", 0.0, strict=True)
Lead = _quantity(LEAD_UNITS, "mm/rev", 0.0, strict=True)
SegmentTime = _quantity(TIME_UNITS, "s", SEGMENT_TIME_S[0], maximum=SEGMENT_TIME_S[1])
PositiveLength = _quantity({"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}, "mm", 0.0,
                           strict=True)


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


# ---- task ----------------------------------------------------------------------------------


class TaskSpec(_Model):
    """A required workspace: a region of tool positions × an orientation set."""

    shape: Literal["box", "cylinder", "points"]
    frame: Literal["nominal", "base"] = Field("nominal", description="positions relative to "
                                              "the nominal pose's position, or the base frame")
    centre: Literal["auto"] | list[Length | Literal["auto"]] = Field(
        [0.0, 0.0, 0.0], description="box / cylinder centre [x, y, z] in the frame; 'auto' "
        "(or 'auto' for some coordinates): placed per candidate where the task fits best, "
        "a search (pkmlab.requirements.placement)")
    size: list[NonNegLength] | None = Field(None, min_length=3, max_length=3,
                                            description="box: full edges [x, y, z]")
    radius: NonNegLength | None = None
    height: NonNegLength | None = None
    points: list[list[Length]] | None = Field(None, description="point set [[x, y, z], ...]")
    file: str | None = Field(None, description="point set CSV x,y,z (mm), relative to the "
                             "study file")
    orientation: list[Angle] | None = Field(None, min_length=3, max_length=3,
                                            description="one orientation [θx, θy, θz]")
    box: list[Angle] | None = Field(None, min_length=3, max_length=3,
                                    description="Euler box half-ranges")
    semantics: Literal["simultaneous", "single-axis"] = "simultaneous"
    tilt: Angle | None = None
    torsion: Angle = 0.0
    samples: int = Field(7, ge=1, le=101, description="samples per angle")
    resolution: PositiveLength = Field(2.5, description="sample spacing of the sampled "
                                       "fallback (families without radial columns)")


@dataclass(frozen=True)
class TaskPlan:
    region: TaskRegion
    orientations: OrientationSet
    resolution: float
    source: dict
    #: coordinates of the centre placed per candidate (``centre: auto``)
    auto: tuple[bool, bool, bool] = (False, False, False)


def _read_points(path: Path, field: str) -> np.ndarray:
    table = read_table(path, field, what="a CSV file with the header x,y,z (mm), relative to "
                       "the study file")
    if sorted(table.header) != ["x", "y", "z"]:
        raise ParameterError(f"{field} header", "the columns x,y,z (mm)",
                             Shown(", ".join(shown(h) for h in table.header)),
                             where=table.where())
    if not len(table.values):
        raise ParameterError(field, "at least one point", 0, where=str(path))
    return np.stack([table.column(c) for c in "xyz"], axis=1)


def build_task(data: Any, base: Path) -> TaskPlan:
    f = "evaluate.task"
    t = validate_model(TaskSpec, data, prefix=f + ".")
    if t.shape == "box" and t.size is None:
        raise ParameterError(f"{f}.size", "given for a box: [x, y, z] edges", None)
    if t.shape == "cylinder" and (t.radius is None or t.height is None):
        raise ParameterError(f"{f}.radius", "given with 'height' for a cylinder", None)
    points = None
    source = t.model_dump(exclude_none=True)
    if t.shape == "points":
        if (t.points is None) == (t.file is None):
            raise ParameterError(f"{f}.points", "exactly one of 'points' or 'file' for a "
                                 "point set", None)
        if t.file is not None:
            path = (base / t.file).resolve()
            points = _read_points(path, f"{f}.file")
            source["file"] = str(path)
        else:
            points = np.array(t.points)
            if len(points) == 0:
                raise ParameterError(f"{f}.points", "at least one point", [])
    centre = ["auto"] * 3 if t.centre == "auto" else list(t.centre)
    if len(centre) != 3:
        raise ParameterError(f"{f}.centre", "three coordinates [x, y, z] or 'auto'", t.centre)
    auto = tuple(c == "auto" for c in centre)
    if any(auto) and t.shape == "points":
        raise ParameterError(f"{f}.centre", "a fixed centre for a point set (a point set "
                             "has no centre; give frame: nominal and shift the points)",
                             t.centre)
    region = TaskRegion(t.shape, t.frame, tuple(0.0 if a else float(c) for a, c in
                                                zip(auto, centre)),
                        tuple(t.size or (0, 0, 0)),
                        t.radius or 0.0, t.height or 0.0, points)
    given = [k for k in ("orientation", "box", "tilt") if getattr(t, k) is not None]
    if len(given) > 1:
        raise ParameterError(f"{f}.{given[1]}", f"not given with '{given[0]}' (one "
                             "orientation set)", getattr(t, given[1]))
    if t.box is not None:
        if min(t.box) < 0 or max(t.box) > math.pi:
            raise ParameterError(f"{f}.box", "half-ranges in [0, 180] deg",
                                 [math.degrees(a) for a in t.box])
        oset = OrientationSet.box(tuple(t.box), t.semantics, t.samples)
    elif t.tilt is not None:
        if not (0 <= t.tilt <= math.pi / 2) or not (0 <= t.torsion <= math.pi):
            raise ParameterError(f"{f}.tilt", "a tilt in [0, 90] deg and a torsion in "
                                 "[0, 180] deg", [math.degrees(t.tilt),
                                                  math.degrees(t.torsion)])
        oset = OrientationSet.tilt_torsion(t.tilt, t.torsion, t.samples)
    else:
        oset = OrientationSet.fixed(tuple(t.orientation or (0.0, 0.0, 0.0)))
    # angles back as text with units, so the resolved study reloads identically
    for k in ("orientation", "box"):
        if k in source:
            source[k] = [f"{math.degrees(a):.12g} deg" for a in source[k]]
    for k in ("tilt", "torsion"):
        if k in source:
            source[k] = f"{math.degrees(source[k]):.12g} deg"
    return TaskPlan(region, oset, t.resolution, source, auto)


# ---- motions ---------------------------------------------------------------------------------


def _per_coordinate(name: str, linear, angular) -> type[BaseModel]:
    """A model with one value per pose coordinate (x, y, z, theta_x, theta_y, theta_z), each
    defaulting to 0: ``linear`` is the type of x, y, z, ``angular`` that of the angles."""
    return create_model(name, __base__=_Model,
                        **{c: (linear if c in "xyz" else angular, 0.0)
                           for c in ("x", "y", "z", "theta_x", "theta_y", "theta_z")})


_Coords = _per_coordinate("_Coords", Length, Angle)
_Frequencies = _per_coordinate("_Frequencies", Frequency, Frequency)
_Phases = _per_coordinate("_Phases", Angle, Angle)


class SinusoidSpec(_Model):
    amplitude: _Coords
    frequency: _Frequencies
    phase: _Phases = Field(default_factory=_Phases, description="phase per coordinate (deg)")


class SmoothingSpec(_Model):
    window: PositiveTime = Field(0.05, description="Savitzky–Golay window (s)")
    polyorder: int = Field(3, ge=2, le=7)


class MotionSpec(_Model):
    name: str = Field(pattern=r"^[A-Za-z0-9._-]+$")
    file: str | None = Field(None, description="CSV t,x,y,z,theta_x,theta_y,theta_z (s, mm, "
                             "deg) [+ <coord>_dot, <coord>_ddot], relative to the study file")
    frame: Literal["nominal", "base", "task"] | None = Field(
        None, description="a file's frame, required with 'file': 'nominal' (poses relative to "
        "the nominal pose, as `pkmlab trajectory --csv F --relative`), 'base' (absolute, as "
        "`pkmlab trajectory --csv F`) or 'task' (relative to the task's centre as placed: "
        "needs evaluate.task; with task.centre auto the centre the search chose); generated "
        "motions are about the nominal pose, or the task's centre with 'task'")
    smoothing: SmoothingSpec = Field(default_factory=SmoothingSpec)
    sinusoid: SinusoidSpec | None = None
    paper: bool = Field(False, description="Hopkins & Williams' ±2 in / ±30° motion")
    segment_time: SegmentTime = Field(1.0, description="paper motion: s per cubic leg")
    duration: PositiveTime = Field(2.0, description="sinusoid: s")
    rate: PositiveFrequency = Field(200.0, description="generators: samples per s")


@dataclass(frozen=True)
class MotionsPlan:
    specs: tuple                                  # MotionSpec
    recorded: dict                                # name -> Motion (CSV, as recorded)
    source: list

    def motions(self, mech, task_centre=None) -> list:
        """The motions for one mechanism (generators and 'nominal' frames use its nominal
        pose; 'task' frames the task's centre ``task_centre`` (base frame, mm) at the nominal
        orientation)."""
        out = []
        home = mech
        if task_centre is not None:
            import dataclasses

            pose = mech.nominal_pose
            pose[:3] = task_centre
            home = dataclasses.replace(mech, nominal=pose)
        for s in self.specs:
            if s.frame == "task" and task_centre is None:
                raise ParameterError(f"evaluate.motions {s.name!r} frame", "'task' with an "
                                     "evaluate.task block", s.frame)
            mech = home if s.frame == "task" else mech
            if s.paper:
                out.append(paper_motion(mech, segment_time=s.segment_time, rate_hz=s.rate,
                                        name=s.name))
            elif s.sinusoid is not None:
                a, f, ph = (np.array([getattr(c, k) for k in mo.POSE_COLUMNS]) for c in
                            (s.sinusoid.amplitude, s.sinusoid.frequency, s.sinusoid.phase))
                out.append(mo.sinusoid_motion(mech, a, f, ph, s.duration, s.rate, s.name))
            else:
                m = self.recorded[s.name]
                if s.frame in ("nominal", "task"):
                    m = mo.Motion(m.name, m.t, m.poses + mech.nominal_pose, m.twist, m.accel,
                                  m.derivatives)
                out.append(m)
        mob = mech.mobility
        if mob.is_spatial:
            return out
        # a lower mobility: the other coordinates are the mechanism's own (its plane, its
        # orientation), whatever a recording says; check_mobility refused varying ones
        fixed = np.setdiff1d(np.arange(len(mech.nominal_pose)), mob.index)
        for m in out:
            m.poses[:, fixed] = mech.nominal_pose[fixed]
        return out

    def check_mobility(self, mech) -> None:
        """Refuse a motion that moves a coordinate the mechanism cannot move (a sinusoid's
        amplitude, a recording's column that varies), naming it."""
        mob = mech.mobility
        if mob.is_spatial:
            return
        for i, s in enumerate(self.specs):
            moving = []
            if s.sinusoid is not None:
                moving = [k for k in mo.POSE_COLUMNS if k not in mob.coordinates
                          and getattr(s.sinusoid.amplitude, k) != 0.0]
            elif s.file is not None:
                rec = self.recorded[s.name].poses
                moving = [k for j, k in enumerate(mo.POSE_COLUMNS) if k not in mob.coordinates
                          and np.ptp(rec[:, j]) > 1e-9]   # algorithm constant: CSV rounding
            if moving:
                raise ParameterError(f"evaluate.motions[{i}]", "a motion of the mechanism's "
                                     f"free coordinates ({', '.join(mob.coordinates)}) only",
                                     f"a motion of {', '.join(moving)}")


def build_motions(data: Any, base: Path) -> MotionsPlan:
    f = "evaluate.motions"
    if not isinstance(data, list) or not data:
        raise ParameterError(f, "a non-empty list of motions ({name, file | sinusoid | "
                             "paper: true})", data)
    specs, recorded, source = [], {}, []
    for i, d in enumerate(data):
        fi = f"{f}[{i}]"
        s = validate_model(MotionSpec, d, prefix=fi + ".")
        kinds = [k for k, on in (("file", s.file is not None),
                                 ("sinusoid", s.sinusoid is not None), ("paper", s.paper))
                 if on]
        if len(kinds) != 1:
            raise ParameterError(fi, "exactly one of 'file', 'sinusoid' or 'paper: true'",
                                 kinds or "none")
        if any(x.name == s.name for x in specs):
            raise ParameterError(f"{fi}.name", "a name no other motion has", s.name)
        raw = dict(d)
        if s.file is not None:
            if s.frame is None:         # one CSV, one meaning: the study states the frame
                raise ParameterError(f"{fi}.frame", "'nominal' (the CSV's poses are offsets "
                                     "from the nominal pose, as `pkmlab trajectory --csv FILE "
                                     "--relative`), 'base' (absolute base-frame poses, as "
                                     "`pkmlab trajectory --csv FILE`) or 'task' (offsets from "
                                     "the task's centre)", "missing")
            path = (base / s.file).resolve()
            recorded[s.name] = load_motion_csv(path, s.name, s.smoothing.window,
                                               s.smoothing.polyorder, field=f"{fi}.file")
            raw["file"] = str(path)
        specs.append(s)
        source.append(raw)
    return MotionsPlan(tuple(specs), recorded, source)


# ---- payload ----------------------------------------------------------------------------------


class BodySpec(_Model):
    mass: Mass
    com: list[Length] = Field([0.0, 0.0, 0.0], min_length=3, max_length=3,
                              description="centre of mass, platform frame (mm)")
    inertia: list[Any] = Field([0.0, 0.0, 0.0], description="[Ixx, Iyy, Izz] or 3×3 about "
                               "the centre of mass, platform axes (kg·mm², or with units "
                               "'2 kg*m^2')")


class LegsSpec(_Model):
    mass: Mass = Field(description="mass of one leg (kg)")
    model: Literal["ends", "rod"] = Field("ends", description="'ends': a share at the "
                                          "platform joint; 'rod': a uniform slender rod from "
                                          "a fixed base joint (ups6)")
    platform_share: float | None = Field(None, ge=0, le=1, description="ends: share lumped "
                                         "at the platform joint (default 0.5; the rest stays "
                                         "at the base end)")


class PayloadSpec(BodySpec):
    platform: BodySpec | None = Field(None, description="the platform's own mass properties")
    legs: LegsSpec | None = None


@dataclass(frozen=True)
class PayloadPlan:
    body: MassProperties                       # payload + platform
    leg_mass: float                            # kg: lumped at each platform joint (ends),
    source: dict                               # or each rod's mass (rod)
    leg_model: str = "ends"

    def for_mechanism(self, mech) -> MassProperties:
        if self.leg_mass <= 0:
            return self.body
        if self.leg_model == "rod":
            return combine(self.body, leg_rod_masses(mech, self.leg_mass))
        return combine(self.body, leg_end_masses(mech, self.leg_mass))


def _body(b: BodySpec, field: str) -> MassProperties:
    raw = b.inertia
    flat = raw if not raw or not isinstance(raw[0], list) else None
    try:
        if flat is not None and len(flat) == 3:
            J = np.diag([parse_physical(x, f"{field}.inertia[{k}]", INERTIA_UNITS,
                                        "kg*mm^2") for k, x in enumerate(flat)])
        elif len(raw) == 3 and all(isinstance(r, list) and len(r) == 3 for r in raw):
            J = np.array([[parse_physical(x, f"{field}.inertia[{i}][{j}]", INERTIA_UNITS,
                                          "kg*mm^2") for j, x in enumerate(r)]
                          for i, r in enumerate(raw)])
        else:
            raise ParameterError(f"{field}.inertia", "[Ixx, Iyy, Izz] or a 3×3 list", raw)
        return MassProperties(b.mass, np.array(b.com), J)
    except ParameterError as exc:
        name = exc.field if exc.field.startswith(field) else f"{field}.{exc.field}"
        raise ParameterError(name, exc.allowed, exc.got) from None


def build_payload(data: Any) -> PayloadPlan:
    f = "evaluate.payload"
    p = validate_model(PayloadSpec, data, prefix=f + ".")
    body = _body(p, f)
    if p.platform is not None:
        body = combine(body, _body(p.platform, f"{f}.platform"))
    if p.legs is not None and p.legs.model == "rod" and p.legs.platform_share is not None:
        raise ParameterError(f"{f}.legs.platform_share", "not given with model 'rod' (the "
                             "rod's inertia and weight shares follow from the model)",
                             p.legs.platform_share)
    if p.legs is None:
        return PayloadPlan(body, 0.0, dict(data))
    if p.legs.model == "rod":
        return PayloadPlan(body, p.legs.mass, dict(data), "rod")
    share = 0.5 if p.legs.platform_share is None else p.legs.platform_share
    return PayloadPlan(body, p.legs.mass * share, dict(data))


# ---- actuators ----------------------------------------------------------------------------------


PositiveTorque = _quantity(TORQUE_UNITS, "N*mm", 0.0, strict=True)
PositiveAngularSpeed = _quantity(ANGULAR_SPEED_UNITS, "rad/s", 0.0, strict=True)


class ActuatorItem(_Model):
    name: str = Field(pattern=r"^[A-Za-z0-9._-]+$")
    kind: Literal["linear", "rotary"] = Field("linear", description="linear (prismatic "
                                              "families) or rotary (servo on a crank, rss6)")
    force: PositiveForce | None = Field(None, description="linear: force limit (N)")
    speed: PositiveSpeed | None = Field(None, description="linear: speed limit (mm/s)")
    torque: PositiveTorque | None = Field(None, description="rotary: torque limit (N·mm)")
    angular_speed: PositiveAngularSpeed | None = Field(None, description="rotary: speed "
                                                       "limit (rad/s, or '60 rpm')")
    range: Angle | None = Field(None, description="rotary: angle range used (deg)")
    stroke: PositiveLength | None = Field(None, description="travel (mm)")
    lead: Lead | None = Field(None, description="screw lead (mm/rev), with torque_speed")
    efficiency: float = Field(1.0, gt=0, le=1)
    torque_speed: list[tuple[AngularSpeed, Torque]] | None = Field(
        None, description="motor curve [[speed (rad/s, or '3000 rpm'), torque (N·mm, or "
        "'2.5 N*m')], ...], speeds increasing from 0")
    note: str = ""


class ActuatorsSpec(_Model):
    catalogue: str | None = Field(None, description="catalogue YAML {actuators: [...]}, "
                                  "relative to the study file")
    use: str | None = Field(None, description="the catalogue entry used (the baseline's when "
                            "a design variable chooses)")
    spec: ActuatorItem | None = Field(None, description="one actuator given inline")


class _Catalogue(_Model):
    actuators: list[ActuatorItem] = Field(min_length=1)


@dataclass(frozen=True)
class ActuatorsPlan:
    catalogue: dict                                # name -> ActuatorSpec
    default: str
    source: dict


def _actuator(a: ActuatorItem, field: str) -> ActuatorSpec:
    curve = tuple((float(w), float(T)) for w, T in (a.torque_speed or ()))
    need = ("force", "speed") if a.kind == "linear" else ("torque", "angular_speed")
    wrong = ("torque", "angular_speed", "range") if a.kind == "linear" else \
        ("force", "speed", "stroke", "lead")
    for k in need:
        if getattr(a, k) is None:
            raise ParameterError(f"{field}.{k}", f"given for a {a.kind} actuator", None)
    for k in wrong:
        if getattr(a, k) is not None:
            raise ParameterError(f"{field}.{k}", f"not given for a {a.kind} actuator (use "
                                 f"{' and '.join(need)})", getattr(a, k))
    if a.kind == "rotary":
        if a.range is not None and not (0 < a.range <= 2 * math.pi):
            raise ParameterError(f"{field}.range", "an angle range in (0, 360] deg",
                                 math.degrees(a.range))
        if curve:
            ws = [w for w, _ in curve]
            if ws[0] != 0 or any(b <= c for c, b in zip(ws, ws[1:])):
                raise ParameterError(f"{field}.torque_speed", "speeds increasing from 0",
                                     [round(w * 60 / (2 * math.pi), 6) for w in ws])
        return ActuatorSpec(a.name, a.torque, a.angular_speed, a.range, None, a.efficiency,
                            curve, "rotary")
    if curve:
        ws = [w for w, _ in curve]
        if ws[0] != 0 or any(b <= c for c, b in zip(ws, ws[1:])):
            raise ParameterError(f"{field}.torque_speed", "speeds increasing from 0",
                                 [round(w * 60 / (2 * math.pi), 6) for w in ws])
        if a.lead is None:
            raise ParameterError(f"{field}.lead", "given with a torque_speed curve (the "
                                 "screw lead, mm/rev)", None)
    return ActuatorSpec(a.name, a.force, a.speed, a.stroke, a.lead, a.efficiency, curve)


def build_actuators(data: Any, base: Path) -> ActuatorsPlan:
    f = "evaluate.actuators"
    a = validate_model(ActuatorsSpec, data, prefix=f + ".")
    source = dict(data)
    cat: dict = {}
    if (a.catalogue is None) == (a.spec is None):
        raise ParameterError(f, "exactly one of 'catalogue' (with 'use' or a design variable "
                             "with target: actuator) or 'spec'", sorted(source))
    if a.spec is not None:
        cat[a.spec.name] = _actuator(a.spec, f"{f}.spec")
        default = a.spec.name
    else:
        path = (base / a.catalogue).resolve()
        if not path.is_file():
            raise ParameterError(f"{f}.catalogue", "an existing catalogue YAML file",
                                 a.catalogue)
        c = validate_model(_Catalogue, read_yaml(path, "catalogue"),
                           prefix=f"{f}.catalogue({path.name}).")
        for i, item in enumerate(c.actuators):
            fi = f"{f}.catalogue({path.name}).actuators[{i}]"
            if item.name in cat:
                raise ParameterError(f"{fi}.name", "a name no other entry has", item.name)
            cat[item.name] = _actuator(item, fi)
        source["catalogue"] = str(path)
        default = a.use if a.use is not None else c.actuators[0].name
        if default not in cat:
            raise ParameterError(f"{f}.use", f"a catalogue entry {sorted(cat)}", a.use)
    return ActuatorsPlan(cat, default, source)
