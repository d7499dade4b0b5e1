"""Joints and geometric parameters as data: what a mechanism is made of, for the exports
(simulators, CAD), calibration, tolerance analysis and the drawings.

**Joints.** ``mech.legs(pose=None)`` gives each leg's chain of :class:`Joint` from the base to
the platform at a pose (default: the nominal pose), one :class:`Leg` per actuator, in the order
of ``actuator_names``, each with exactly one actuated joint. All locations and axes are in the
base frame (mm) at that pose. Conventions:

* a joint joins two bodies, ``parent`` (base side) and ``child`` (platform side): ``"base"``,
  ``"platform"``, or a named link (``"leg3.rod"``; a link two legs share, luzi3's upper links,
  is named after its chain, ``"chain2.upper_link"``, and so is the joint it carries);
* ``location`` is the joint centre (R: a point of the axis; U: the crossing of its two axes;
  S: the ball centre). A P joint has two points: ``zero``, fixed in the parent, where its
  coordinate is 0, and ``location``, carried by the child, with ``location - zero =
  coordinate·axis``;
* ``axes``: R and P one unit row (P: the direction of increasing coordinate; R: positive
  coordinate by the right-hand rule), U two orthogonal unit rows, the first fixed in the
  parent and the second in the child, S none. An actuated R joint carries ``reference``,
  the unit direction (⟂ axis) from its centre towards the next joint at coordinate 0;
* a joint fixed to the base or the platform has ``mount`` = ``"base"`` / ``"platform"`` and
  ``mount_location``, its centre in that body's frame (the platform frame, not the tool frame:
  a row of ``platform_points``);
* link ``k`` of a leg joins joint ``k`` and joint ``k + 1``: its ``length`` is the fixed
  distance from joint ``k``'s location to joint ``k + 1``'s location (its ``zero`` when it is
  a P joint);
* ``segment``: the joints whose centres bound the leg's moving link as ``leg_segments`` gives
  it (interference, joint cones, singularity checks; ``link_segments`` adds the positive-length
  links on its base side, the cranks: :func:`link_segments_of`). The report draws the whole
  chain (:func:`chain_points`, :mod:`pkmlab.webreport.mechanism3d`).

A family provides ``_joint_arrays(p, R, axes=True)`` (:class:`JointArrays`: all the legs'
joint centres and, with ``axes``, axes over N poses, vectorised) and ``_leg_templates()`` (one
:class:`LegTemplate` a leg: the joint types, bodies, fixed link lengths, actuated joint, P zero
points, R references, base and platform points). :func:`build_legs` assembles the
:class:`Leg` objects; the family's ``leg_segments`` reads the same arrays
(:func:`joint_segments`).

**Parameters.** ``mech.parameters()`` is the geometry as one named vector (:class:`Parameters`:
names, values, units ``"mm"`` / ``"rad"`` / ``"1"``, descriptions): every base and platform
joint location, every axis (as three components, normalised by the family, so one direction
per axis is redundant), every fixed link length, the actuator window and zero (a slider's zero
position, a crank's zero direction) and the tool offset. ``mech.with_parameters(values)`` is the
mechanism of the same family with those values (everything else, including the nominal pose
when it was given, kept): ``m.with_parameters(m.parameters().values) == m``. A family declares
its vector as :class:`ParamField` rows (``parameter_fields``); the default is the protocol's
own fields, ``base_points``, ``platform_points``, ``stroke_window`` and ``tool_offset``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property
from typing import Any, ClassVar, NamedTuple

import numpy as np

from ..errors import ParameterError
from ..tolerances import TOL

__all__ = ["Joint", "Link", "Leg", "LegTemplate", "JointArrays", "Parameters", "ParamField",
           "JointsMixin", "build_legs", "joint_segments", "link_segments_of",
           "base_joint_axes_of", "chain_points", "hinge_axis", "chain_errors",
           "kind_template", "kind_arrays", "platform_joints", "KIND_CHAINS"]

JOINT_TYPES = ("R", "P", "U", "S")
_XYZ = ("x", "y", "z")


@dataclass(frozen=True, eq=False)
class Joint:
    """One joint of a leg at a pose (module docstring for the conventions)."""

    name: str
    type: str
    location: np.ndarray
    axes: np.ndarray
    parent: str
    child: str
    actuated: bool = False
    mount: str | None = None
    mount_location: np.ndarray | None = None
    zero: np.ndarray | None = None
    reference: np.ndarray | None = None


@dataclass(frozen=True)
class Link:
    """A link of a leg and the fixed distance (mm) between the joints it joins."""

    name: str
    length: float


@dataclass(frozen=True, eq=False)
class Leg:
    """A leg: its joints from the base to the platform, the links between them, its actuated
    joint's index and value (mm or rad, the IK's) and the joints bounding its moving link."""

    name: str
    joints: tuple[Joint, ...]
    links: tuple[Link, ...]
    actuated_index: int
    value: float
    segment: tuple[int, int]

    @property
    def actuated(self) -> Joint:
        return self.joints[self.actuated_index]


class LegTemplate(NamedTuple):
    """What a family declares of a leg, independent of the pose (module docstring)."""

    name: str                                 # the actuator name
    types: tuple[str, ...]
    joint_names: tuple[str, ...]
    bodies: tuple[str, ...]                   # len(types) + 1, "base" first, "platform" last
    lengths: tuple[float, ...]                # len(types) - 1
    actuated: int
    segment: tuple[int, int]
    base_point: np.ndarray                    # the first joint's centre (P: zero), base frame
    platform_point: np.ndarray                # the last joint's centre, platform frame
    zero: np.ndarray | None = None            # P joint zero point (base frame, fixed)
    reference: np.ndarray | None = None       # actuated R joint's zero direction


class JointArrays(NamedTuple):
    """All legs' joints over N poses: ``centre``, a tuple of J arrays ``(N, L, 3)``, joint
    j's centres (P joints: ``location``; read-only broadcast views allowed),
    ``axes (N, L, J, 2, 3)`` (unused rows NaN; ``None`` when not asked for) and the actuator
    values ``q (N, L)`` (``None`` allowed when the axes are not asked for)."""

    centre: tuple[np.ndarray, ...]
    axes: np.ndarray | None
    q: np.ndarray | None


def unit(v: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return v / np.linalg.norm(v, axis=-1, keepdims=True)


def hinge_axis(d: np.ndarray, hint: np.ndarray) -> np.ndarray:
    """Unit ``hint × d`` (⟂ both), or ``x̂ × d`` where ``hint ∥ d``: the first axis of a U
    joint whose link leaves along ``d``, chosen at the nominal pose."""
    a = np.cross(hint, d)
    n = np.linalg.norm(a, axis=-1, keepdims=True)
    alt = np.cross(np.array([1.0, 0.0, 0.0]), d)
    alt = np.where(np.linalg.norm(alt, axis=-1, keepdims=True) > TOL.direction_norm, alt,
                   np.cross(np.array([0.0, 1.0, 0.0]), d))
    return unit(np.where(n > TOL.direction_norm * np.linalg.norm(d, axis=-1, keepdims=True), a,
                         alt))


_Z = np.array([0.0, 0.0, 1.0])

#: the leg kinds the families share: joint types, link names, actuated joint, segment, joint
#: names (prismatic UPS, slider PSU, crank RSS; tri3's UPU adds its own)
KIND_CHAINS = {
    "prismatic": (("U", "P", "S"), ("cylinder", "rod"), 1, (0, 2),
                  ("base_U", "P", "platform_S")),
    "slider": (("P", "S", "U"), ("slider", "link"), 0, (1, 2), ("P", "slider_S", "platform_U")),
    "crank": (("R", "S", "S"), ("crank", "rod"), 0, (1, 2), ("R", "crank_S", "platform_S")),
}


def kind_template(kind: str, i: int, name: str, base_point, platform_point, lengths,
                  zero=None, reference=None, types=None) -> LegTemplate:
    """The :class:`LegTemplate` of leg ``i`` (from 0) of a kind of :data:`KIND_CHAINS`."""
    t, links, act, seg, jn = KIND_CHAINS[kind]
    t = t if types is None else types
    leg = f"leg{i + 1}"
    return LegTemplate(name, t, tuple(f"{leg}.{n}" for n in jn),
                       ("base", *(f"{leg}.{b}" for b in links), "platform"),
                       tuple(float(v) for v in lengths), act, seg,
                       np.asarray(base_point, float), np.asarray(platform_point, float),
                       None if zero is None else np.asarray(zero, float),
                       None if reference is None else np.asarray(reference, float))


def platform_joints(mech, p, R) -> np.ndarray:
    """``(N, K, 3)`` platform joint centres ``p + R·(P_k - O)`` in the base frame."""
    return p[:, None, :] + np.einsum("nij,kj->nki", R, mech.tool_points)


def kind_arrays(mech, kind, start, W, q, R, axes, legs=None, rail=None) -> JointArrays:
    """:class:`JointArrays` of legs of one kind: ``start (L, 3)`` or ``(N, L, 3)`` the base U
    centre (prismatic), the slider (slider) or the crank end (crank), ``W (N, L, 3)`` the
    platform joints, ``rail (L, 3)`` the slider rails or servo axes (a crank's pivot is its
    ``base_points`` row). U axes: the base U of a
    prismatic leg has its base axis horizontal and ⟂ the leg at the nominal pose
    (:func:`hinge_axis`), its second ⟂ the leg; the platform U of a slider leg has its
    platform axis ⟂ the platform normal and the link at the nominal pose, fixed in the
    platform, and its link axis ⟂ both. ``legs`` selects the rows of the nominal centres."""
    n, L = W.shape[:2]
    start = np.broadcast_to(start, W.shape)
    first = (np.broadcast_to(mech.base_points if legs is None else mech.base_points[legs],
                             W.shape) if kind == "crank" else start)
    centre = (first, W if kind == "prismatic" else start, W)
    ax = np.full((n, L, 3, 2, 3), np.nan) if axes else None
    if axes:
        nom = mech._nominal_centres if legs is None else mech._nominal_centres[legs]
        d = W - start
        if kind == "prismatic":
            a = hinge_axis(nom[:, 2] - nom[:, 0], _Z)
            ax[:, :, 0, 0] = a
            ax[:, :, 0, 1] = unit(np.cross(d, a))
            ax[:, :, 1, 0] = unit(d)
        else:
            ax[:, :, 0, 0] = rail
            if kind == "slider":
                Rn = mech._frames(mech.nominal_pose)[1][0]
                local = hinge_axis(nom[:, 2] - nom[:, 1], Rn[:, 2]) @ Rn
                a = np.einsum("nij,kj->nki", R, local)
                ax[:, :, 2, 0] = unit(np.cross(a, d))
                ax[:, :, 2, 1] = a
    return JointArrays(centre, ax, q)


def _frame(mech, pose) -> tuple[np.ndarray, np.ndarray]:
    p, R = mech._frames(mech.nominal_pose if pose is None else pose)
    if len(p) != 1:
        raise ParameterError("pose", "one pose", f"{len(p)} poses")
    return p, R


def build_legs(mech, pose=None) -> tuple[Leg, ...]:
    """The :class:`Leg` objects of ``mech`` at one pose (module docstring)."""
    p, R = _frame(mech, pose)
    arr = mech._joint_arrays(p, R)
    centre = np.stack([c[0] for c in arr.centre], axis=1)             # (L, J, 3)
    axes, q = arr.axes[0], arr.q[0]
    nrows = {"R": 1, "P": 1, "U": 2, "S": 0}
    legs = []
    for i, t in enumerate(mech._leg_templates()):
        joints = []
        for j, kind in enumerate(t.types):
            mount = ("base" if j == 0 and kind != "P" else
                     "platform" if j == len(t.types) - 1 else None)
            local = (t.base_point if mount == "base" else
                     t.platform_point if mount == "platform" else None)
            joints.append(Joint(
                name=t.joint_names[j], type=kind, location=centre[i, j].copy(),
                axes=axes[i, j, :nrows[kind]].copy(), parent=t.bodies[j], child=t.bodies[j + 1],
                actuated=j == t.actuated, mount=mount,
                mount_location=None if local is None else np.array(local, dtype=float),
                zero=t.zero if kind == "P" else None,
                reference=t.reference if kind == "R" and j == t.actuated else None))
        links = tuple(Link(t.bodies[k + 1], float(t.lengths[k])) for k in range(len(t.lengths)))
        legs.append(Leg(t.name, tuple(joints), links, t.actuated, float(q[i]), t.segment))
    return tuple(legs)


def joint_segments(mech, p: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``leg_segments`` from the joints: each leg's ``segment`` joint centres ``(N, L, 3)``."""
    return _segments(mech._joint_arrays(p, R, axes=False).centre, mech._leg_templates())


def _segments(centre, templates, copy: bool = True) -> tuple[np.ndarray, np.ndarray]:
    seg = np.array([t.segment for t in templates])
    out = []
    for k in (0, 1):
        if np.all(seg[:, k] == seg[0, k]):
            x = centre[seg[0, k]]
        else:                                   # legs of different kinds (sixleg)
            x = np.choose(seg[:, k][None, :, None], centre)
        out.append(x.copy() if copy and not x.flags.writeable else x)
    return tuple(out)


def link_segments_of(mech, p: np.ndarray, R: np.ndarray):
    """``link_segments`` from the joints: each leg's links of positive length on the base
    side of its ``segment`` (a crank: pivot → crank end), legs in order, then every leg's
    ``segment``; ``(start, end)`` each ``(N, S, 3)`` and ``leg (S,)``. Links on the platform
    side of the segment (luzi3's shared upper links) are not interference segments."""
    centre = mech._joint_arrays(p, R, axes=False).centre
    templates = mech._leg_templates()
    start, end = _segments(centre, templates, copy=False)
    extra = [(i, k) for i, t in enumerate(templates) for k in range(t.segment[0])
             if t.lengths[k] > 0.0]
    if not extra:
        return (*(x if x.flags.writeable else x.copy() for x in (start, end)),
                np.arange(start.shape[1]))
    idx = [i for i, _ in extra]
    ks = {k for _, k in extra}
    if len(ks) == 1 and all(templates[i].types[k + 1] != "P" for i, k in extra):
        k = ks.pop()                            # one link a leg at the same place (cranks)
        every = idx == list(range(start.shape[1]))
        a, b = (centre[k], centre[k + 1]) if every else (centre[k][:, idx],
                                                          centre[k + 1][:, idx])
    else:
        shape = (len(p), 3)
        a = np.stack([np.broadcast_to(centre[k][:, i], shape) for i, k in extra], axis=1)
        b = np.stack([np.broadcast_to(templates[i].zero, shape)          # P: its zero
                      if templates[i].types[k + 1] == "P"
                      else np.broadcast_to(centre[k + 1][:, i], shape) for i, k in extra],
                     axis=1)
    leg = np.array(idx + list(range(start.shape[1])))
    return np.concatenate([a, start], axis=1), np.concatenate([b, end], axis=1), leg


def base_joint_axes_of(mech, p: np.ndarray, R: np.ndarray, axes) -> np.ndarray:
    """``base_joint_axes`` from the joints: the mounting axis (given at the nominal pose) of a
    leg's ``segment`` base-side joint is fixed in the body that carries it; when that body is
    turned by the leg's actuated R joint (a crank), the axis turns with it about the R axis
    by ``q − q_nominal`` (Rodrigues); otherwise it is fixed to the base."""
    axes = np.asarray(axes, dtype=float)
    out = np.array(np.broadcast_to(axes, (len(p), *axes.shape)))
    templates = mech._leg_templates()
    turned = np.array([i for i, t in enumerate(templates)
                       if t.segment[0] > 0 and t.actuated == t.segment[0] - 1
                       and t.types[t.actuated] == "R"], dtype=int)
    if not len(turned):
        return out
    legs0 = mech.legs()                         # the nominal pose
    q = mech.inverse((p, R), stroke=(-np.inf, np.inf)).q
    d = (q[:, turned] - np.array([legs0[i].value for i in turned]))[..., None]
    if all(legs0[i].actuated.parent == "base" for i in turned):   # axes fixed in the base
        n = np.array([legs0[i].actuated.axes[0] for i in turned])[None]
    else:
        act = np.array([templates[i].actuated for i in turned])
        n = mech._joint_arrays(p, R).axes[:, turned, act, 0]                # (N, T, 3)
    a = out[:, turned]
    out[:, turned] = (a * np.cos(d) + np.cross(n, a) * np.sin(d)
                      + n * np.sum(n * a, axis=-1, keepdims=True) * (1.0 - np.cos(d)))
    return out


def chain_points(leg: Leg) -> np.ndarray:
    """``(K, 3)`` the points a leg's chain passes through, base to platform: each joint's
    ``location``, a P joint's ``zero`` then its ``location`` (its travel is part of the
    chain). Consecutive points are joined by a link or a P joint's travel."""
    pts = []
    for j in leg.joints:
        if j.type == "P":
            pts.append(j.zero)
        pts.append(j.location)
    return np.array(pts, dtype=float)


def coordinate(joint: Joint, following: Joint) -> float:
    """The joint coordinate of a P or R joint from the joint locations alone: P ``(location -
    zero)·axis``; R the angle from ``reference`` to the direction of the next joint's centre
    (``following.zero`` for a P joint), about the axis."""
    if joint.type == "P":
        return float((joint.location - joint.zero) @ joint.axes[0])
    n, u = joint.axes[0], joint.reference
    d = (following.zero if following.type == "P" else following.location) - joint.location
    return float(np.arctan2(d @ np.cross(n, u), d @ u))


def chain_errors(mech, pose) -> dict[str, float]:
    """How far the joints of ``mech`` at one pose are from a closed, consistent chain: the
    largest, over legs, of each property the protocol promises (mm, rad, or unitless); all
    0 up to rounding for a correct family."""
    p, R = _frame(mech, pose)
    legs = mech.legs((p, R))
    q = mech.inverse((p, R), stroke=(-np.inf, np.inf)).q[0]
    P = np.asarray(mech.platform_points, dtype=float)
    err = dict.fromkeys(("link_mm", "platform_mm", "platform_point_mm", "base_mm",
                         "coordinate", "p_direction", "axis_norm", "u_orthogonal",
                         "r_reference"), 0.0)
    assert len(legs) == mech.n_actuators, (len(legs), mech.n_actuators)

    def worse(key, value):
        err[key] = max(err[key], float(value))

    for i, leg in enumerate(legs):
        assert leg.name == mech.actuator_names[i], (leg.name, mech.actuator_names[i])
        assert sum(j.actuated for j in leg.joints) == 1, f"{leg.name}: one actuated joint"
        assert all(j.type in JOINT_TYPES for j in leg.joints)
        assert leg.joints[0].parent == "base" and leg.joints[-1].child == "platform"
        for k, link in enumerate(leg.links):
            a, b = leg.joints[k], leg.joints[k + 1]
            assert a.child == b.parent == link.name, (a.child, b.parent, link.name)
            end = b.zero if b.type == "P" else b.location
            worse("link_mm", abs(np.linalg.norm(end - a.location) - link.length))
        last = leg.joints[-1]
        worse("platform_mm", np.linalg.norm(p[0] + R[0] @ (last.mount_location
                                                            - mech.tool_offset)
                                            - last.location))
        worse("platform_point_mm", np.min(np.linalg.norm(P - last.mount_location, axis=1)))
        first = leg.joints[0]
        fixed = first.zero if first.type == "P" else first.location
        worse("base_mm", np.min(np.linalg.norm(np.asarray(mech.base_points) - fixed, axis=1)))
        if first.mount_location is not None:
            worse("base_mm", np.linalg.norm(first.mount_location - first.location))
        act = leg.actuated
        worse("coordinate", abs(coordinate(act, leg.joints[leg.actuated_index + 1]) - q[i]))
        worse("coordinate", abs(leg.value - q[i]))
        for j in leg.joints:
            assert j.axes.shape == ({"R": 1, "P": 1, "U": 2, "S": 0}[j.type], 3), j
            if len(j.axes):
                worse("axis_norm", np.max(np.abs(np.linalg.norm(j.axes, axis=1) - 1.0)))
            if j.type == "U":
                worse("u_orthogonal", abs(j.axes[0] @ j.axes[1]))
            if j.type == "P":
                d = j.location - j.zero
                worse("p_direction", np.linalg.norm(d - (d @ j.axes[0]) * j.axes[0]))
            if j.reference is not None:
                worse("r_reference", abs(j.reference @ j.axes[0])
                      + abs(np.linalg.norm(j.reference) - 1.0))
    return err


# ---- parameters ------------------------------------------------------------------------------
@dataclass(frozen=True)
class ParamField:
    """A dataclass field of a family in its parameter vector: ``label`` the name stem (or a
    tuple of the elements' names), ``unit`` ``"mm"``, ``"rad"``, ``"1"`` or ``"actuator"``
    (the mechanism's actuator unit), ``text`` the description (``{i}`` the row number, from
    1), ``rows`` a function of the mechanism giving the ``(K,)`` mask of rows that are
    parameters (the others are kept)."""

    field: str
    label: Any
    unit: str
    text: str
    rows: Any = None


#: the protocol's fields, every family's default parameter vector
DEFAULT_FIELDS = (
    ParamField("base_points", "base", "mm", "leg {i}'s base joint centre (base frame)"),
    ParamField("platform_points", "platform", "mm",
               "platform joint {i}'s centre (platform frame)"),
    ParamField("stroke_window", ("stroke_min", "stroke_max"), "actuator",
               "actuator window limit"),
    ParamField("tool_offset", "tool_offset", "mm", "tool-frame origin (platform frame)"),
)


@dataclass(frozen=True, eq=False)
class Parameters:
    """A mechanism's geometry as one named vector (module docstring)."""

    names: tuple[str, ...]
    values: np.ndarray
    units: tuple[str, ...]
    descriptions: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise ParameterError("parameter", f"one of {len(self.names)} names such as "
                                 f"{list(self.names[:3])}", name) from None

    def __getitem__(self, name: str) -> float:
        return float(self.values[self.index(name)])

    def as_dict(self) -> dict[str, float]:
        return dict(zip(self.names, self.values.tolist(), strict=True))


def _field_entries(mech, f: ParamField):
    """``(array, mask, names, descriptions)`` of one field (flattened in C order)."""
    value = getattr(mech, f.field)
    arr = np.array(value, dtype=float)
    mask = np.ones(arr.shape[:1] if arr.ndim else (), dtype=bool)
    if f.rows is not None:
        mask = np.asarray(f.rows(mech), dtype=bool)
    names, texts, take = [], [], []
    if isinstance(f.label, tuple):
        names, texts = list(f.label), [f"{f.text} ({n})" for n in f.label]
        take = list(range(arr.size))
    elif arr.ndim == 0:
        names, texts, take = [f.label], [f.text], [0]
    else:
        cols = arr.shape[1] if arr.ndim == 2 else 1
        for r in range(arr.shape[0]):
            if arr.ndim == 1 and arr.shape[0] == 3 and f.rows is None:     # a 3-vector
                names.append(f"{f.label}.{_XYZ[r]}")
                texts.append(f"{f.text}, {_XYZ[r]}")
                take.append(r)
                continue
            if not mask[r]:
                continue
            for c in range(cols):
                sfx = f".{_XYZ[c]}" if arr.ndim == 2 else ""
                names.append(f"{f.label}{r + 1}{sfx}")
                texts.append(f.text.format(i=r + 1) + (f", {_XYZ[c]}" if sfx else ""))
                take.append(r * cols + c)
    return arr, np.array(take, dtype=int), names, texts


def parameters_of(mech) -> Parameters:
    names, values, units, texts = [], [], [], []
    for f in mech.parameter_fields:
        arr, take, n, t = _field_entries(mech, f)
        unit_ = mech.actuator_unit if f.unit == "actuator" else f.unit
        names += n
        texts += t
        units += [unit_] * len(n)
        values.append(arr.ravel()[take])
    return Parameters(tuple(names), np.concatenate(values), tuple(units), tuple(texts))


def with_parameters_of(mech, values):
    """The mechanism of ``mech``'s family with the parameter ``values``: an array in the order
    of ``mech.parameters()``, or a mapping ``name → value`` changing those only."""
    current = mech.parameters()
    if isinstance(values, dict):
        new = current.values.copy()
        for k, v in values.items():
            new[current.index(k)] = float(v)
        values = new
    values = np.asarray(values, dtype=float)
    if values.shape != current.values.shape:
        raise ParameterError("parameters", f"{len(current)} values (mech.parameters())",
                             values.shape)
    changes, at = {}, 0
    for f in mech.parameter_fields:
        arr, take, _, _ = _field_entries(mech, f)
        flat = arr.ravel().copy()
        flat[take] = values[at:at + len(take)]
        at += len(take)
        if f.field == "stroke_window":
            changes[f.field] = (float(flat[0]), float(flat[1]))
        elif arr.ndim == 0:
            changes[f.field] = float(flat[0])
        else:
            changes[f.field] = flat.reshape(arr.shape)
    return dataclasses.replace(mech, **changes)


class JointsMixin:
    """The joint and parameter protocol of :class:`~.base.Mechanism` (module docstring)."""

    #: the parameter vector's fields (:class:`ParamField`)
    parameter_fields: ClassVar[tuple[ParamField, ...]] = DEFAULT_FIELDS

    def legs(self, pose=None) -> tuple[Leg, ...]:
        """Each leg's joint chain at ``pose`` (one pose in any form ``inverse`` takes;
        default the nominal pose), in the base frame, in the order of ``actuator_names``."""
        return build_legs(self, pose)

    def parameters(self) -> Parameters:
        """The geometry as one named vector with units (module docstring)."""
        return parameters_of(self)

    def with_parameters(self, values):
        """A mechanism of the same family with these parameter values (an array in the order
        of :meth:`parameters`, or a mapping name → value)."""
        return with_parameters_of(self, values)

    def leg_segments(self, p: np.ndarray, R: np.ndarray):
        """End points ``(start, end)``, each ``(N, L, 3)``, of each leg's moving link, read
        from the joints (each leg's ``segment``): ``start`` carries the base-side joint and
        ``end`` the platform-side one."""
        return joint_segments(self, p, R)

    def _joint_arrays(self, p, R, axes: bool = True) -> JointArrays:  # pragma: no cover
        raise NotImplementedError(f"{type(self).__name__} declares no joints "
                                  "(_joint_arrays, _leg_templates; pkmlab.mechanisms.joints)")

    def _leg_templates(self) -> tuple[LegTemplate, ...]:  # pragma: no cover - abstract
        raise NotImplementedError

    @cached_property
    def _nominal_centres(self) -> np.ndarray:
        """``(L, J, 3)`` joint centres at the nominal pose (U axes are chosen there)."""
        c = self._joint_arrays(*self._frames(self.nominal_pose), axes=False).centre
        return np.stack([x[0] for x in c], axis=1)
