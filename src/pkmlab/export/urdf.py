"""``urdf``: the spanning tree of :mod:`.model` as URDF, plus the loop closures by a stated
convention.

URDF describes trees only (its loop-closing constraint element is still a proposal), so:

* **the tree** is the one the MJCF export uses (actuated joints kept in it; a link that
  hangs from the platform is reached through the platform): P → ``prismatic``, R →
  ``revolute``, U → two ``revolute`` joints, S → three ``revolute`` joints about the base
  frame's x, y, z at the exported pose (with massless intermediate links, as common URDF
  practice for a ball). Every link frame has its origin on its joint's axis (URDF's rule);
  the platform link's frame has the platform's orientation; a fixed joint carries the link
  ``tool`` at the tool point. SI units (m, rad), as URDF requires.
* **the joint values**: 0 at the exported pose for every joint; an actuated joint's value is
  pkmlab's actuator value *minus* its value at the exported pose (``<limit>`` is the stroke
  or servo window shifted the same way; the offsets are in ``<pkmlab:actuator>`` below).
* **the loop closures**: each cut joint gets two fixed frame links, ``<cut>__a`` on the body
  of its parent side and ``<cut>__b`` on the body of its child side, coinciding at the
  exported pose, and one element ``<pkmlab:loop_closure>`` naming them and the constraint:
  ``point`` (the two frame origins coincide: a spherical joint, one per anchor; an R joint
  is two such points on its axis) or ``weld``. Why this convention: it is what constraint
  models of tree-based libraries take (Pinocchio's ``RigidConstraintModel``: two frames and
  a 3-D or 6-D contact; Drake's distance and weld constraints), every standard URDF parser
  reads the file as a plain tree (unknown elements are ignored), and a user sees where each
  loop was cut. The same closures are in the ``joints`` JSON (``closures``).
* **a held orientation**: a mechanism whose mobility frees no tilt (translational, planar, a
  point; :func:`.model.orientation_guide`) gets one element ``<pkmlab:orientation_hold
  link="platform" free_rotation="z"|"none"/>``: the platform keeps the exported pose's
  orientation except for that rotation about the base frame's z, with no constraint on its
  translations. The declared joints need not hold it (a delta's parallelogram forearm is one
  S–S rod); the MJCF export realises it as its ``platform.guide`` chain and weld.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

import numpy as np

from ..tolerances import TOL
from .mjcf import M, _masses, _platform_disc, _regular_inertia
from .model import MassModel, build_model, orientation_guide

__all__ = ["urdf_text", "rpy"]


def rpy(R: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw (fixed x, y, z) of a rotation matrix: ``R = Rz(y)·Ry(p)·Rx(r)``."""
    R = np.asarray(R, dtype=float)
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    return np.array([math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0])])


def _r(x) -> str:
    return repr(float(x))


def _v(x) -> str:
    return " ".join(_r(v) for v in np.ravel(x))


def _a(**kw) -> str:
    return "".join(f" {k}={quoteattr(str(v))}" for k, v in kw.items())


def _tag(pad: str, element: str, /, **attrs) -> str:
    return f"{pad}<{element}{_a(**attrs)}/>"


def _inertial(mass: float, com_local, radius: float) -> list[str]:
    I = float(0.4 * mass * radius * radius)   # a solid sphere's (kg m²): a documented stand-in
    return ["    <inertial>", f"      <origin{_a(xyz=_v(com_local), rpy='0 0 0')}/>",
            f"      <mass{_a(value=_r(mass))}/>",
            _tag("      ", "inertia", ixx=_r(I), ixy="0", ixz="0", iyy=_r(I), iyz="0",
                 izz=_r(I)),
            "    </inertial>"]


def urdf_text(mech, pose=None, mass: MassModel | None = None) -> str:
    """The URDF document of ``mech`` exported at ``pose`` (default nominal)."""
    model = build_model(mech, pose, mass)
    geoms, link_mass = _masses(model)
    dens = model.mass.density
    links, joints, extra = [], [], []

    def link(name, body=None):
        lines = [f"  <link{_a(name=name)}>"]
        if body is not None and body.name in geoms:
            gs = geoms[body.name]
            vol = [(math.pi * r * r * np.linalg.norm(c - a) + 4 / 3 * math.pi * r ** 3) * M ** 3
                   for a, c, r in gs]
            m = link_mass.get(body.name, dens * sum(vol))
            com = sum(v * 0.5 * (a + c) for v, (a, c, _) in zip(vol, gs)) / sum(vol)
            lines += _inertial(m, body.R.T @ (com - body.pos) * M, gs[0][2] * M)
            for a, c, r in gs:
                L = np.linalg.norm(c - a)
                mid = body.R.T @ (0.5 * (a + c) - body.pos) * M
                if L < TOL.direction_norm:
                    shape = f"<sphere{_a(radius=_r(r * M))}/>"
                    rot = np.eye(3)
                else:
                    shape = f"<cylinder{_a(radius=_r(r * M), length=_r(L * M))}/>"
                    z = body.R.T @ ((c - a) / L)
                    x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
                    x /= np.linalg.norm(x)
                    rot = np.column_stack([x, np.cross(z, x), z])
                for tag in ("visual", "collision"):
                    lines += [f"    <{tag}>", f"      <origin{_a(xyz=_v(mid), rpy=_v(rpy(rot)))}/>",
                              f"      <geometry>{shape}</geometry>", f"    </{tag}>"]
        elif body is not None and body.kind == "platform":
            pm = model.mass.platform
            c, rad, th = _platform_disc(model)
            loc = body.R.T @ (c - body.pos) * M
            if pm is None:
                m = dens * math.pi * rad ** 2 * th * M ** 3
                lines += _inertial(m, loc, rad * M)
            else:
                com = body.R.T @ (model.p + model.R @ (np.asarray(pm.com) - mech.tool_offset)
                                  - body.pos) * M
                J = _regular_inertia(pm, model.link_diameter) * M * M
                lines += ["    <inertial>", f"      <origin{_a(xyz=_v(com), rpy='0 0 0')}/>",
                          f"      <mass{_a(value=_r(pm.mass))}/>",
                          _tag("      ", "inertia", **{
                              k: _r(J[i, j]) for k, (i, j) in (
                                  ("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)),
                                  ("iyy", (1, 1)), ("iyz", (1, 2)), ("izz", (2, 2)))}),
                          "    </inertial>"]
            lines += ["    <visual>", f"      <origin{_a(xyz=_v(loc), rpy='0 0 0')}/>",
                      "      <geometry>" + _tag("", "cylinder", radius=_r(rad * M),
                                                 length=_r(th * M)) + "</geometry>",
                      "    </visual>"]
        elif body is None or body.kind != "base":
            lines += _inertial(1e-6, np.zeros(3), 1e-3)          # a massless frame link
        lines.append("  </link>")
        links.extend(lines)

    def joint(name, kind, parent, child, xyz, R, axis=None, limit=None):
        lines = [f"  <joint{_a(name=name, type=kind)}>", f"    <parent{_a(link=parent)}/>",
                 f"    <child{_a(link=child)}/>",
                 f"    <origin{_a(xyz=_v(xyz), rpy=_v(rpy(R)))}/>"]
        if axis is not None:
            lines.append(f"    <axis{_a(xyz=_v(axis))}/>")
        if limit is not None:
            lo, hi = limit
            lines.append(_tag("    ", "limit", lower=_r(lo), upper=_r(hi), effort="1000",
                              velocity="10"))
        lines.append("  </joint>")
        joints.extend(lines)

    for b in model.bodies.values():
        if b.parent is None:
            link(b.name, b)
            continue
        parent = model.bodies[b.parent]
        pos = parent.R.T @ (b.pos - parent.pos) * M
        Rrel = parent.R.T @ b.R
        if len(b.joints) == 1 and b.joints[0].kind == "ball":
            tj = b.joints[0]
            prev = b.parent
            for k, ax in enumerate(("x", "y")):
                mid = f"{tj.name}.{ax}_link"
                link(mid)
                joint(f"{tj.name}.{ax}", "continuous", prev, mid, pos if k == 0 else np.zeros(3),
                      parent.R.T if k == 0 else np.eye(3), np.eye(3)[k])
                prev = mid
            link(b.name, b)
            joint(f"{tj.name}.z", "continuous", prev, b.name, np.zeros(3), b.R, [0, 0, 1.0])
            continue
        link(b.name, b)
        tj = b.joints[0]
        kind = "prismatic" if tj.kind == "slide" else "revolute" if tj.actuated else "continuous"
        limit = None
        if tj.actuated:
            f = M if tj.kind == "slide" else 1.0
            lo, hi = mech.stroke
            limit = ((lo - tj.value) * f, (hi - tj.value) * f)
            extra.append(_tag("  ", "pkmlab:actuator", name=tj.actuator, joint=tj.name,
                              offset=_r(tj.value * f), unit="m" if f == M else "rad"))
        joint(tj.name, kind, b.parent, b.name, pos, Rrel, b.R.T @ tj.axis, limit)
    tool = model.bodies["platform"]
    link("tool")
    joint("tool", "fixed", "platform", "tool", tool.R.T @ (model.p - tool.pos) * M, np.eye(3))
    for cl in model.closures:
        for side, body in (("a", cl.body1), ("b", cl.body2)):
            b = model.bodies[body]
            link(f"{cl.name}__{side}")
            joint(f"{cl.name}__{side}", "fixed", body, f"{cl.name}__{side}",
                  b.R.T @ (cl.anchor - b.pos) * M, b.R.T)
        extra.append(_tag("  ", "pkmlab:loop_closure", name=cl.name,
                          type="point" if cl.kind == "connect" else "weld",
                          frame_a=cl.name + "__a", frame_b=cl.name + "__b",
                          cut_joint_type=cl.protocol_type))
    guide = orientation_guide(mech)
    if guide:
        extra.append(_tag("  ", "pkmlab:orientation_hold", link="platform",
                          free_rotation="z" if len(guide) > 3 else "none"))
    head = ['<?xml version="1.0" encoding="utf-8"?>',
            f"<!-- pkmlab {mech.family} mechanism {mech.name or '(unnamed)'}: exported by pkmlab "
            "export, format urdf. SI units (m, kg, rad). A spanning tree; loops closed by "
            "the <pkmlab:loop_closure> elements (frames __a and __b coincide: 'point' their "
            "origins, 'weld' their poses). Actuated joint value = pkmlab actuator value - "
            f"offset. Masses: {model.mass.source}. -->",
            f'<robot{_a(name=mech.name or mech.family)} '
            'xmlns:pkmlab="urn:pkmlab:urdf-loops">']
    return "\n".join(head + links + joints + extra + ["</robot>"]) + "\n"
