"""A mechanism as a rigid-body model: bodies, a spanning tree and loop closures, read from the
declared joints only (``mech.legs(pose)``), for the simulator and CAD exports.

**Graph.** Every body a joint names (``"base"``, ``"platform"``, the links) is a node; every
joint (named once, even when two legs share it, luzi3's platform U) is an edge.

**Spanning tree.** Edges are taken in order of preference (Kruskal's algorithm with a
union-find): actuated joints first, then P, U, R and S joints, each group in leg order; an
edge closing a cycle is *cut*. So actuated joints are never cut when the graph allows it, and
a leg with a spherical joint is cut there (a spherical joint is exactly a point-to-point
constraint). The tree is rooted at ``"base"``; a joint traversed from its child to its parent
(a link that hangs from the platform) is *reversed*: its axes are negated, so that its
coordinate still increases as the protocol's does.

**Frames.** The model is built at one pose (default the nominal pose), where every joint
coordinate of the tree is zero except the actuated ones, which start at their values there
(MJCF ``ref``). Each body's frame has its origin at the centre of the joint through which the
tree reaches it (the base: the base frame's origin) and the axes of the base frame, except the
platform's, which has the platform's orientation at that pose. A U joint is two hinges with an
intermediate body ``<joint>.cross``.

**Closures** (:class:`Closure`), by the cut joint's type: S, one point-to-point constraint at
its centre; R, two at the points of its axis 5 % of ``mech.scale`` either side of its centre
(6 equations, 5 independent); U, its first hinge on a cross body of the parent and the second
closed as an R; P (never actuated: actuated joints are kept in the tree), on a closure body of
the parent that carries the slide, welded to the child. Point constraints need no extra body:
a weld to a light closure body carrying an R hinge did not settle in MuJoCo on luzi3's
over-constrained chains, two point constraints on the axis did (docs/validation.md).

**Mass model** (:class:`MassModel`). Each moving link is a capsule between the centres of the
joints it carries (a sphere when they coincide), of diameter ``link_diameter``; the platform a
disc through its joints. Default: solid aluminium (2700 kg/m³), ``link_diameter`` 2.5 % of the
mechanism's size (``mech.scale``), the platform disc 1/10 of its radius thick. A study's
payload (platform and payload as one rigid body) replaces the platform's, and its leg mass is
spread over each leg's links in proportion to their volumes. A payload given without inertia
(a point mass) gets that of a solid sphere of its mass and the link diameter, since MuJoCo
needs a positive-definite inertia. Joint bodies (U crosses, closure bodies) are spheres of
half the link diameter in the same material.

**Orientation guide** (:func:`orientation_guide`). The declared joints need not hold the
platform's orientation where the mobility says it is fixed: a delta's parallelogram forearm is
declared as one S–S rod (the kinematics needs no more), so three rods let the platform turn,
which the real parallelograms do not. A mechanism whose mobility frees (or makes dependent) no
tilt — translational, planar, a point — therefore gets, in the simulator export, a guide: a
light body under the base carrying slides along the base frame's x, y and z (and a hinge about
z when ``theta_z`` is free or dependent), welded to the platform. It frees every translation
and the rotation the mobility has, and holds the others at the exported pose's; it adds no
constraint to the free coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from ..tolerances import TOL

__all__ = ["MechanismModel", "MassModel", "Body", "TreeJoint", "Closure", "build_model",
           "DENSITY", "LINK_DIAMETER_SHARE", "orientation_guide"]

#: default density of links and platform, kg/m³ (aluminium)
DENSITY = 2700.0
#: default link diameter as a share of ``mech.scale``
LINK_DIAMETER_SHARE = 0.025
#: Kruskal's preference of a joint for the tree (lower first); actuated joints come first
_PREFERENCE = {"P": 1, "U": 2, "R": 3, "S": 4}


@dataclass(frozen=True)
class MassModel:
    """What the exports know of masses.

    Attributes:
        link_diameter: mm (None: :data:`LINK_DIAMETER_SHARE` of ``mech.scale``).
        density: kg/m³ of links and platform when no mass is given.
        platform: a :class:`pkmlab.motion.payload.MassProperties` of the platform and
            payload together (platform frame), or None for the default disc.
        leg_mass: kg per leg, spread over its links by volume, or None (density).
        source: a sentence saying where the masses come from (written into the files).
    """

    link_diameter: float | None = None
    density: float = DENSITY
    platform: object | None = None
    leg_mass: float | None = None
    source: str = ("default: solid aluminium links and platform disc (2700 kg/m³); no "
                   "payload or leg model given")


@dataclass
class TreeJoint:
    """One joint of the tree: ``kind`` ``hinge``/``slide``/``ball``; ``axis`` (base frame,
    unit, already negated when reversed); ``protocol`` the protocol joint's name."""

    name: str
    kind: str
    location: np.ndarray
    axis: np.ndarray | None
    protocol: str
    actuated: bool = False
    value: float = 0.0              # the actuated joint's coordinate at the model pose
    actuator: str | None = None     # its actuator name


@dataclass
class Body:
    """A body of the tree at the model pose: origin ``pos`` and orientation ``R`` in the base
    frame (mm), its parent body and the joints between them (several for a U)."""

    name: str
    parent: str | None
    pos: np.ndarray
    R: np.ndarray
    joints: list[TreeJoint] = field(default_factory=list)
    points: list[np.ndarray] = field(default_factory=list)    # joint centres it carries
    legs: set[str] = field(default_factory=set)
    kind: str = "link"              # base, platform, link, cross, closure


@dataclass
class Closure:
    """A cut joint: ``connect`` (a spherical joint: ``body1``'s point ``anchor`` stays on
    ``body2``'s) or ``weld`` (``body1`` a closure body carrying the joint, welded to
    ``body2``); ``anchor`` in the base frame at the model pose (mm)."""

    name: str
    kind: str
    body1: str
    body2: str
    anchor: np.ndarray
    protocol_type: str
    leg: str


@dataclass
class MechanismModel:
    """Bodies in tree order (parents first), closures, the actuated joints in actuator
    order, and what it was built from."""

    mech: object
    pose: np.ndarray
    p: np.ndarray
    R: np.ndarray
    bodies: dict[str, Body]
    closures: list[Closure]
    actuated: list[TreeJoint]
    legs: tuple
    mass: MassModel
    link_diameter: float
    chains: dict[str, list[str]]        # leg name -> the bodies of its chain

    def body(self, name: str) -> Body:
        return self.bodies[name]

    def children(self, name: str) -> list[Body]:
        return [b for b in self.bodies.values() if b.parent == name]

    @property
    def tool_point(self) -> np.ndarray:
        return self.p


class _UnionFind:
    def __init__(self):
        self.up: dict[str, str] = {}

    def find(self, x: str) -> str:
        self.up.setdefault(x, x)
        while self.up[x] != x:
            self.up[x] = self.up[self.up[x]]
            x = self.up[x]
        return x

    def union(self, a: str, b: str) -> bool:
        ra, rb = self.find(a), self.find(b)
        if ra == rb:
            return False
        self.up[ra] = rb
        return True


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _edges(legs):
    """The distinct joints ``[(joint, leg name)]`` in leg order; a joint named twice must
    join the same bodies."""
    seen: dict[str, tuple] = {}
    for leg in legs:
        for j in leg.joints:
            if j.name in seen:
                old = seen[j.name][0]
                if (old.parent, old.child, old.type) != (j.parent, j.child, j.type):
                    raise ParameterError(f"joint {j.name}", "one joint per name",
                                         f"two joints named {j.name!r}")
                continue
            seen[j.name] = (j, leg.name)
    return list(seen.values())


def _spanning_tree(edges):
    order = sorted(range(len(edges)), key=lambda k: (
        0 if edges[k][0].actuated else _PREFERENCE[edges[k][0].type], k))
    uf, tree, cut = _UnionFind(), [], []
    for k in order:
        j = edges[k][0]
        (tree if uf.union(j.parent, j.child) else cut).append(k)
    if len({uf.find(b) for e in edges for b in (e[0].parent, e[0].child)}) != 1:
        raise ParameterError("joints", "legs joining every body to the base",
                             "disconnected bodies")
    return sorted(tree), sorted(cut)


def _hinges(j, reversed_: bool):
    """``[(suffix, kind, axis)]`` of a protocol joint as tree joints, from the tree parent
    towards the tree child (a U's axis fixed in the tree parent first)."""
    sign = -1.0 if reversed_ else 1.0
    if j.type == "S":
        return [("", "ball", None)]
    if j.type == "U":
        ax = [sign * _unit(a) for a in j.axes]
        if reversed_:
            ax = ax[::-1]
        return [(".1", "hinge", ax[0]), (".2", "hinge", ax[1])]
    return [("", "slide" if j.type == "P" else "hinge", sign * _unit(j.axes[0]))]


def _leg_of(legs, name: str):
    for leg in legs:
        if any(j.name == name for j in leg.joints):
            return leg
    raise KeyError(name)


def build_model(mech, pose=None, mass: MassModel | None = None) -> MechanismModel:
    """The :class:`MechanismModel` of ``mech`` at ``pose`` (one pose; default nominal)."""
    mass = MassModel() if mass is None else mass
    pose_ = np.asarray(mech.nominal_pose if pose is None else pose, dtype=float)
    p, R = mech._frames(pose_)
    p, R = p[0], R[0]
    legs = mech.legs((p[None], R[None]))
    edges = _edges(legs)
    tree, cut = _spanning_tree(edges)
    actuator_of = {leg.actuated.name: leg for leg in legs}
    bodies: dict[str, Body] = {"base": Body("base", None, np.zeros(3), np.eye(3), kind="base")}
    adj: dict[str, list[int]] = {}
    for k in tree:
        j = edges[k][0]
        adj.setdefault(j.parent, []).append(k)
        adj.setdefault(j.child, []).append(k)
    actuated: dict[str, TreeJoint] = {}

    def tree_joints(j, reversed_, suffix_body):
        """Create the tree joints of protocol joint ``j`` below ``suffix_body``'s parent;
        returns the list and the intermediate (cross) body, if any."""
        out = []
        for sfx, kind, axis in _hinges(j, reversed_):
            tj = TreeJoint(j.name + sfx, kind, j.location.copy(), axis, j.name)
            if j.actuated:
                leg = actuator_of[j.name]
                tj.actuated, tj.value, tj.actuator = True, float(leg.value), leg.name
                actuated[leg.name] = tj
            out.append(tj)
        return out

    def add_body(name, parent, origin, joints, kind, orient=None):
        b = Body(name, parent, np.asarray(origin, float).copy(),
                 np.eye(3) if orient is None else orient, kind=kind)
        b.joints = joints
        bodies[name] = b
        return b

    def attach(parent: str, child: str, j, reversed_: bool, child_kind="link"):
        tjs = tree_joints(j, reversed_, child)
        orient = R if child == "platform" else None
        kind = "platform" if child == "platform" else child_kind
        if len(tjs) == 2:                   # U: an intermediate cross body
            add_body(j.name + ".cross", parent, j.location, [tjs[0]], "cross")
            add_body(child, j.name + ".cross", j.location, [tjs[1]], kind, orient)
        else:
            add_body(child, parent, j.location, tjs, kind, orient)

    # tree, breadth first from the base
    queue, done = ["base"], {"base"}
    while queue:
        b = queue.pop(0)
        for k in adj.get(b, []):
            j = edges[k][0]
            other, reversed_ = (j.child, False) if j.parent == b else (j.parent, True)
            if other in done:
                continue
            attach(b, other, j, reversed_)
            done.add(other)
            queue.append(other)

    closures = []
    for k in cut:
        j, leg_name = edges[k]
        if j.type == "S":
            closures.append(Closure(j.name, "connect", j.parent, j.child, j.location.copy(),
                                    "S", leg_name))
        elif j.type in ("R", "U"):  # a hinge: two points of its axis (6 rows, 5 independent)
            body1, axis = j.parent, j.axes[-1]
            if j.type == "U":       # its first hinge in the tree, on a cross body
                ax0 = _unit(j.axes[0])
                tj = TreeJoint(j.name + ".1", "hinge", j.location.copy(), ax0, j.name)
                add_body(j.name + ".cross", j.parent, j.location, [tj], "cross")
                body1 = j.name + ".cross"
            h = 0.05 * float(mech.scale) * _unit(axis)
            for sfx, anchor in ((".a", j.location - h), (".b", j.location + h)):
                closures.append(Closure(j.name + sfx, "connect", body1, j.child, anchor,
                                        j.type, leg_name))
        else:                       # P: on a closure body of its parent, welded to its child
            if j.actuated:
                raise ParameterError("joints", "a spanning tree holding every actuated "
                                     "joint", f"actuated {j.name} closes a loop")
            attach(j.parent, j.name + ".closure", j, False, "closure")
            closures.append(Closure(j.name, "weld", j.name + ".closure", j.child,
                                    j.location.copy(), j.type, leg_name))
    missing = [n for n in mech.actuator_names if n not in actuated]
    if missing:                                 # pragma: no cover - every leg has one
        raise ParameterError("joints", "one actuated joint per actuator", missing)

    # the joint centres each body carries (its geometry) and the chains
    chains: dict[str, list[str]] = {}
    for leg in legs:
        chain = ["base"]
        for j in leg.joints:
            if j.type == "P" and j.parent != "base":    # a cylinder and its rod, each half
                half = 0.5 * (j.location - j.zero)      # the extension at the model pose
                bodies[j.parent].points += [j.zero, j.zero + half]
                bodies[j.child].points += [j.location - half, j.location]
            else:
                bodies[j.parent].points.append(j.location)
                bodies[j.child].points.append(j.location)
            chain.append(j.child)
            for extra in (j.name + ".cross", j.name + ".closure"):
                if extra in bodies:
                    chain.append(extra)
                    bodies[extra].points.append(j.location)
        for name in chain:
            bodies[name].legs.add(leg.name)
        chains[leg.name] = list(dict.fromkeys(chain))
    d = mass.link_diameter if mass.link_diameter is not None else \
        LINK_DIAMETER_SHARE * float(mech.scale)
    if not (np.isfinite(d) and d > 0):
        raise ParameterError("link_diameter", "a length > 0 mm", d)
    return MechanismModel(mech, pose_, p, R, _tree_order(bodies), closures,
                          [actuated[n] for n in mech.actuator_names], legs, mass, float(d),
                          chains)


def _tree_order(bodies: dict[str, Body]) -> dict[str, Body]:
    out: dict[str, Body] = {}

    def visit(name):
        out[name] = bodies[name]
        for b in bodies.values():
            if b.parent == name:
                visit(b.name)
    visit("base")
    return out


def relative(parent: Body, child: Body) -> tuple[np.ndarray, np.ndarray]:
    """``(pos, R)`` of ``child``'s frame in ``parent``'s (mm)."""
    return parent.R.T @ (child.pos - parent.pos), parent.R.T @ child.R


def segments(model: MechanismModel, body: Body) -> list[tuple[np.ndarray, np.ndarray]]:
    """The capsules of a link body in the base frame (mm): from its first joint centre to
    each other distinct one; ``[(a, a)]`` (a sphere) when they all coincide."""
    pts = [np.asarray(x, float) for x in body.points]
    if not pts:
        return []
    tol = TOL.same_point_rel * max(1.0, float(model.mech.scale))
    far = [x for x in pts[1:] if np.linalg.norm(x - pts[0]) > tol]
    uniq: list[np.ndarray] = []
    for x in far:
        if all(np.linalg.norm(x - u) > tol for u in uniq):
            uniq.append(x)
    return [(pts[0], x) for x in uniq] or [(pts[0], pts[0])]


def orientation_guide(mech) -> list[tuple[str, str, np.ndarray]]:
    """The guide's joints ``[(name, kind, axis in the base frame)]`` (module docstring), or
    ``[]`` when the mobility frees or makes dependent a tilt (the joints then hold or free
    every rotation themselves, six-coordinate mechanisms included)."""
    mob = mech.mobility
    known = set(mob.coordinates) | set(mob.dependent)
    if known & {"theta_x", "theta_y"}:
        return []
    axes = np.eye(3)
    out = [(f"platform.guide.{c}", "slide", axes[k]) for k, c in enumerate("xyz")]
    if "theta_z" in known:
        out.append(("platform.guide.theta_z", "hinge", axes[2]))
    return out
