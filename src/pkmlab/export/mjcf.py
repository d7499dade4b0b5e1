"""``mjcf``: the mechanism as a closed-loop MuJoCo model (MJCF XML), from its declared joints.

Conventions (MuJoCo XML reference, mujoco.readthedocs.io/en/stable/XMLreference.html):

* SI units, as MuJoCo's defaults assume: metres, kilograms, seconds, radians
  (``<compiler angle="radian">``); gravity 9.80665 m/s² along −z of the base frame;
* one root body ``base`` under ``<worldbody>`` (fixed), everything else below it, so that
  parsers that expect one kinematic tree (Pinocchio's MJCF reader) read it;
* the spanning tree and closures of :mod:`.model`: P → ``slide``, R → ``hinge``, U → two
  hinges, S → ``ball``; a cut spherical joint is a ``connect`` equality (anchor in ``body1``'s
  frame), any other cut joint lives on a closure body welded (``weld``, explicit ``relpose``)
  to the joint's other body;
* every tree joint's coordinate is 0 at the exported pose except the actuated ones, whose
  ``ref`` is pkmlab's actuator value there (m or rad): ``qpos`` of an actuated joint *is*
  pkmlab's actuator value (mm / 1000 for a slide), also under ``ctrl``;
* a mechanism whose mobility frees no tilt (translational, planar, a point: see
  :func:`.model.orientation_guide`) has its platform's orientation held by a declared guide:
  the body ``platform.guide``, the last child of ``base``, with slides along the base frame's
  x, y, z (and a hinge about z when ``theta_z`` is free or dependent), welded (equality
  ``platform.guide``) to the platform. It carries no geometry, a mass of
  :data:`GUIDE_MASS` kg with gravity compensated (``gravcomp="1"``) and undamped joints, so
  it frees the translations and that rotation and acts on nothing else (MuJoCo has no
  orientation-only equality; a delta's parallelogram forearms are declared as S–S rods, which
  alone would let the platform turn);
* actuators are ``position`` servos named after pkmlab's actuators, ``ctrlrange`` and the
  joint's ``range`` the stroke or servo window, ``kp`` giving a :data:`SERVO_HZ` servo on its
  *design inertia* (an equal share of the moving mass; for a crank, that share at the crank's
  arm), damped with ``dampratio="1"``;
* each actuated joint carries the drive's reflected inertia as ``armature``:
  :data:`DRIVE_INERTIA_SHARE` × the servo's design inertia (an inertia-matched drive). Without
  it the tree inertia of an actuated joint is only its own body's (a 46 g slider carriage on a
  10 kg Hexaglide), MuJoCo's ``dampratio`` sizes ``kv`` on that, and the implicit integrator
  applies ``kv`` after the constraint solver sized the loop forces with the undamped mass
  matrix (MuJoCo's documented limitation); with ``timestep·kv·(M⁻¹)ᵢᵢ`` at 3.7 the closed
  loops went unstable (docs/validation.md, "the hexaglide instability");
* contacts are excluded between every two bodies of one leg's chain (base and platform
  included) and between two bodies whose shapes already touch at the exported pose (links
  meeting at neighbouring joints); legs can still touch each other elsewhere;
* a site ``tool`` at the tool point with the platform's orientation; sensors ``tool_pos``
  and ``tool_quat`` read it; a keyframe ``home`` holds the exported pose.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import quoteattr

import numpy as np

from ..tolerances import TOL
from .model import MassModel, build_model, orientation_guide, relative, segments

__all__ = ["mjcf_text", "quat", "GRAVITY", "SERVO_HZ", "DRIVE_INERTIA_SHARE", "M"]

#: metres per mm
M = 1e-3
#: standard gravity, m/s²
GRAVITY = 9.80665
#: position servo bandwidth (Hz) used for kp
SERVO_HZ = 50.0
#: time constant (s) of the loop-closing equalities (MuJoCo's default 0.02 lets a loop open
#: by about g·0.02² under gravity; 2 time steps is the stiffest MuJoCo recommends)
EQ_TIMECONST = 0.002
#: kg: the orientation guide's mass (MuJoCo needs a positive one for a body with joints)
GUIDE_MASS = 1e-6
#: the actuated joints' armature (the drive's reflected inertia) as a multiple of the inertia
#: their servo is tuned for (module docstring)
DRIVE_INERTIA_SHARE = 1.0


def quat(R: np.ndarray) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` of a rotation matrix (w ≥ 0)."""
    R = np.asarray(R, dtype=float)
    t = np.trace(R)
    if t > 0:
        s = 2.0 * math.sqrt(1.0 + t)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
        q = [0.0] * 4
        q[0] = (R[k, j] - R[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (R[j, i] + R[i, j]) / s
        q[1 + k] = (R[k, i] + R[i, k]) / s
    q = np.array(q)
    q /= np.linalg.norm(q)
    return q if q[0] >= 0 else -q


def _f(x) -> str:
    return repr(float(x))


def _v(x) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(x))


def _a(**kw) -> str:
    return "".join(f" {k.rstrip('_')}={quoteattr(str(v))}" for k, v in kw.items()
                   if v is not None)


def _tag(pad: str, element: str, /, **attrs) -> str:
    return f"{pad}<{element}{_a(**attrs)}/>"


def _masses(model):
    """Per link body the geoms ``[(fromto m | None, pos m, radius m)]`` and its mass (kg) or
    None (MuJoCo's density); the platform's explicit inertial or None."""
    r = 0.5 * model.link_diameter
    geoms, vol = {}, {}
    for b in model.bodies.values():
        if b.kind in ("base", "platform"):
            continue
        if b.kind in ("cross", "closure"):
            segs = [(b.pos, b.pos)]
            rad = 0.5 * r
        else:
            segs, rad = segments(model, b), r
        geoms[b.name] = [(a, c, rad) for a, c in segs]
        vol[b.name] = sum(math.pi * rad ** 2 * np.linalg.norm(c - a) + 4 / 3 * math.pi * rad ** 3
                          for a, c in segs)
    mass = {}
    m = model.mass
    if m.leg_mass is not None:
        links = [n for n in geoms if model.bodies[n].kind == "link"]
        total = m.leg_mass * len(model.legs)
        vsum = sum(vol[n] for n in links)
        for n in links:
            mass[n] = total * vol[n] / vsum
    return geoms, mass


def _platform_disc(model):
    P = np.array([j.location for leg in model.legs for j in leg.joints
                  if j.child == "platform"])
    c = P.mean(axis=0)
    rad = max(float(np.max(np.linalg.norm(P - c, axis=1))), model.link_diameter)
    return c, rad, max(0.1 * rad, 0.5 * model.link_diameter)


def mjcf_text(mech, pose=None, mass: MassModel | None = None) -> str:
    """The MJCF document of ``mech`` exported at ``pose`` (default nominal)."""
    model = build_model(mech, pose, mass)
    geoms, link_mass = _masses(model)
    density = model.mass.density
    out = ['<?xml version="1.0" encoding="utf-8"?>',
           f"<!-- pkmlab {mech.family} mechanism {mech.name or '(unnamed)'}: exported by "
           "pkmlab export, format mjcf. SI units (m, kg, s, rad); pkmlab works in mm. "
           "Actuated joint qpos = pkmlab actuator value (slide: mm/1000). Closed loops: "
           "equality connect (cut spherical joints) and weld (other cut joints). "
           f"Masses: {model.mass.source}. Link diameter {model.link_diameter:.6g} mm. -->",
           f"<mujoco{_a(model=mech.name or mech.family)}>",
           '  <compiler angle="radian" autolimits="true"/>',
           f'  <option timestep="0.001" integrator="implicitfast" tolerance="1e-10" '
           f'gravity="0 0 {-GRAVITY!r}"/>',
           "  <default>",
           '    <joint damping="0.01" armature="1e-6"/>',
           f'    <equality solref="{EQ_TIMECONST!r} 1"/>',
           '    <geom rgba="0.6 0.65 0.7 1"/>',
           "  </default>",
           "  <worldbody>"]
    qpos0: list[float] = []
    moving = _moving_mass(model, geoms, link_mass, density)
    share = moving / max(1, len(model.actuated))
    # base plate (visual: the base is fixed)
    B = np.array([j.location if j.type != "P" else j.zero for leg in model.legs
                  for j in leg.joints[:1]])
    bc = B.mean(axis=0)
    brad = max(float(np.max(np.linalg.norm(B - bc, axis=1))), model.link_diameter)
    bt = max(0.05 * brad, 0.5 * model.link_diameter)

    def body_xml(b, depth):
        pad = "  " * depth
        lines = []
        if b.name == "base":
            lines.append(f"{pad}<body{_a(name='base')}>")
            lines.append(_tag(pad + "  ", "geom", name="base_plate", type="cylinder",
                              pos=_v((bc - [0, 0, bt]) * M), size=_v([brad * M, bt * M]),
                              rgba="0.3 0.3 0.35 1", contype="0", conaffinity="0"))
        else:
            pos, Rr = relative(model.bodies[b.parent], b)
            lines.append(f"{pad}<body{_a(name=b.name, pos=_v(pos * M), quat=_v(quat(Rr)))}>")
            for tj in b.joints:
                loc = b.R.T @ (tj.location - b.pos) * M
                if tj.kind == "ball":
                    lines.append(f"{pad}  <joint{_a(name=tj.name, type='ball', pos=_v(loc))}/>")
                    qpos0.extend([1.0, 0.0, 0.0, 0.0])
                    continue
                axis = b.R.T @ tj.axis
                kw = {}
                if tj.actuated:
                    lo, hi = mech.stroke
                    f = M if tj.kind == "slide" else 1.0
                    drive = DRIVE_INERTIA_SHARE * _design_inertia(model, tj, share)
                    kw = dict(ref=_f(tj.value * f), range_=_v([lo * f, hi * f]),
                              damping="0", armature=_f(drive))
                lines.append(_tag(pad + "  ", "joint", name=tj.name, type=tj.kind, pos=_v(loc),
                                  axis=_v(axis), **kw))
                qpos0.append(tj.value * (M if tj.kind == "slide" else 1.0) if tj.actuated
                             else 0.0)
            if b.kind == "platform":
                pm = model.mass.platform
                c, rad, th = _platform_disc(model)
                zloc = b.R.T @ (c - b.pos) * M
                gkw = dict(density=_f(density)) if pm is None else dict(mass="0")
                lines.append(_tag(pad + "  ", "geom", name="platform_plate", type="cylinder",
                                  pos=_v(zloc), size=_v([rad * M, 0.5 * th * M]),
                                  rgba="0.85 0.55 0.2 1", **gkw))
                if pm is not None:
                    com = model.p + model.R @ (np.asarray(pm.com) - mech.tool_offset)
                    com = b.R.T @ (com - b.pos)         # platform frame → body frame
                    J = _regular_inertia(pm, model.link_diameter) * M * M
                    full = [J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]]
                    lines.append(_tag(pad + "  ", "inertial", pos=_v(com * M),
                                      mass=_f(pm.mass), fullinertia=_v(full)))
                tool = b.R.T @ (model.p - b.pos) * M
                lines.append(f"{pad}  <site{_a(name='tool', pos=_v(tool), size='0.005')}/>")
            for k, (a, c, rad) in enumerate(geoms.get(b.name, ())):
                la, lc = b.R.T @ (a - b.pos) * M, b.R.T @ (c - b.pos) * M
                gkw = (dict(mass=_f(link_mass[b.name] / len(geoms[b.name])))
                       if b.name in link_mass else dict(density=_f(density)))
                shape = (dict(type="sphere", pos=_v(la), size=_f(rad * M))
                         if np.allclose(a, c) else
                         dict(type="capsule", fromto=_v(np.r_[la, lc]), size=_f(rad * M)))
                lines.append(f"{pad}  <geom{_a(name=f'{b.name}.geom{k + 1}', **shape, **gkw)}/>")
        for child in model.children(b.name):
            lines += body_xml(child, depth + 1)
        if b.name == "base" and guide:
            lines += guide_xml(pad + "  ")
        lines.append(f"{pad}</body>")
        return lines

    guide = orientation_guide(mech)
    plat = model.bodies["platform"]

    def guide_xml(pad):
        """The orientation guide (module docstring): at the platform's frame."""
        head = _a(name="platform.guide", pos=_v(plat.pos * M), quat=_v(quat(plat.R)),
                  gravcomp="1")
        lines = [f"{pad}<body{head}>",
                 _tag(pad + "  ", "inertial", pos="0 0 0", mass=_f(GUIDE_MASS),
                      diaginertia=_v([GUIDE_MASS * (0.5 * model.link_diameter * M) ** 2] * 3))]
        for name, kind, axis in guide:
            lines.append(_tag(pad + "  ", "joint", name=name, type=kind, pos="0 0 0",
                              axis=_v(plat.R.T @ axis), damping="0"))
            qpos0.append(0.0)
        lines.append(f"{pad}</body>")
        return lines

    out += body_xml(model.bodies["base"], 2)
    out.append("  </worldbody>")
    # contacts: none between the bodies of one chain, nor between two that already touch at
    # the exported pose (links meeting at neighbouring joints)
    pairs = []
    for chain in model.chains.values():
        for i, a in enumerate(chain):
            for c in chain[i + 1:]:
                key = tuple(sorted((a, c)))
                if key not in pairs and a != c:
                    pairs.append(key)
    names = sorted(geoms)
    for i, a in enumerate(names):
        for c in names[i + 1:]:
            key = tuple(sorted((a, c)))
            if key not in pairs and min(
                    _segment_distance(g[0], g[1], h[0], h[1]) - g[2] - h[2]
                    for g in geoms[a] for h in geoms[c]) <= 0:
                pairs.append(key)
    out.append("  <contact>")
    out += [f"    <exclude{_a(body1=a, body2=c)}/>" for a, c in pairs]
    out.append("  </contact>")
    out.append("  <equality>")
    for cl in model.closures:
        b1, b2 = model.bodies[cl.body1], model.bodies[cl.body2]
        if cl.kind == "connect":
            anchor = b1.R.T @ (cl.anchor - b1.pos) * M
            out.append(_tag("    ", "connect", name=cl.name, body1=cl.body1, body2=cl.body2,
                            anchor=_v(anchor)))
        else:
            pos, Rr = relative(b1, b2)
            out.append(_tag("    ", "weld", name=cl.name, body1=cl.body1, body2=cl.body2,
                            relpose=_v(np.r_[pos * M, quat(Rr)])))
    if guide:
        out.append(_tag("    ", "weld", name="platform.guide", body1="platform.guide",
                        body2="platform", relpose="0 0 0 1 0 0 0"))
    out.append("  </equality>")
    out.append("  <actuator>")
    w = 2 * math.pi * SERVO_HZ
    for tj in model.actuated:
        lo, hi = mech.stroke
        kp, f = _design_inertia(model, tj, share) * w * w, (M if tj.kind == "slide" else 1.0)
        out.append(_tag("    ", "position", name=tj.actuator, joint=tj.name, kp=_f(kp),
                        dampratio="1", ctrlrange=_v([lo * f, hi * f])))
    out.append("  </actuator>")
    out.append("  <sensor>")
    out.append('    <framepos name="tool_pos" objtype="site" objname="tool"/>')
    out.append('    <framequat name="tool_quat" objtype="site" objname="tool"/>')
    out.append("  </sensor>")
    ctrl = [tj.value * (M if tj.kind == "slide" else 1.0) for tj in model.actuated]
    out.append("  <keyframe>")
    out.append(f"    <key{_a(name='home', qpos=_v(qpos0), ctrl=_v(ctrl))}/>")
    out.append("  </keyframe>")
    out.append("</mujoco>")
    return "\n".join(out) + "\n"


def _segment_distance(a, b, c, d) -> float:
    """Shortest distance (mm) between the segments ``ab`` and ``cd`` (a point when its ends
    coincide): the minimum over a fine grid of the first segment of the exact point-segment
    distance to the second (to 1e-3 of the first's length: a contact filter)."""
    u, v = b - a, d - c
    vv = float(v @ v)
    P = a + np.linspace(0.0, 1.0, 1001)[:, None] * u
    t = np.zeros(len(P)) if vv == 0 else np.clip((P - c) @ v / vv, 0.0, 1.0)
    return float(np.min(np.linalg.norm(P - (c + t[:, None] * v), axis=1)))


def _regular_inertia(pm, link_diameter: float) -> np.ndarray:
    """The payload's inertia (kg·mm²), plus that of a solid sphere of its mass and the link
    diameter when it is not positive definite (a point mass, which MuJoCo refuses)."""
    J = np.asarray(pm.inertia, dtype=float)
    if np.linalg.eigvalsh(J)[0] <= TOL.symmetric_rel * max(1.0, float(np.abs(J).max())):
        J = J + 0.4 * float(pm.mass) * (0.5 * link_diameter) ** 2 * np.eye(3)
    return J


def _design_inertia(model, tj, share: float) -> float:
    """The inertia an actuated joint's servo is tuned for: ``share`` kg for a slide, that mass
    at the crank's arm (kg·m²) for a hinge."""
    if tj.kind == "slide":
        return share
    arm = _arm(model, tj) * M       # a crank: the share of the mass at the next joint's centre
    return share * arm * arm


def _arm(model, tj) -> float:
    """Distance (mm) from an actuated hinge's axis to the farthest joint centre of its body."""
    b = next(b for b in model.bodies.values() if tj in b.joints)
    d = [np.linalg.norm(np.cross(x - tj.location, tj.axis)) for x in b.points]
    return max(max(d, default=0.0), model.link_diameter)


def _moving_mass(model, geoms, link_mass, density) -> float:
    """kg: the platform and the links (for the servo gains)."""
    total = 0.0
    for name, gs in geoms.items():
        if name in link_mass:
            total += link_mass[name]
            continue
        for a, c, rad in gs:
            v = (math.pi * rad ** 2 * np.linalg.norm(c - a) + 4 / 3 * math.pi * rad ** 3) * M ** 3
            total += density * v
    pm = model.mass.platform
    if pm is not None:
        total += float(pm.mass)
    else:
        _, rad, th = _platform_disc(model)
        total += density * math.pi * rad ** 2 * th * M ** 3
    return total
