"""``step``: a CAD skeleton of the mechanism at one pose (default nominal) as STEP (AP214),
in mm, through build123d (the optional extra ``cad``: ``pip install 'pkmlab[cad]'``).

Solids, each labelled: the base plate and the platform plate (discs through their joint
centres, as the simulator exports draw them), one sphere per joint centre (diameter 1.6 × the
link diameter) and one cylinder per link segment of :mod:`.model` (the link diameter; a P
joint's cylinder and rod each reach half the extension). Everything is written from
``mech.legs(pose)`` through :func:`.model.build_model`.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np

from ..tolerances import TOL
from .mjcf import _masses, _platform_disc
from .model import MassModel, build_model

__all__ = ["step_bytes", "JOINT_SPHERE"]

#: joint sphere diameter as a multiple of the link diameter
JOINT_SPHERE = 1.6


def _solids(mech, pose=None, mass: MassModel | None = None):
    import build123d as bd

    model = build_model(mech, pose, mass)
    geoms, _ = _masses(model)
    d = model.link_diameter
    out = []

    def disc(name, centre, normal, radius, thick):
        plane = bd.Plane(origin=tuple(centre - 0.5 * thick * normal), z_dir=tuple(normal))
        s = bd.Solid.make_cylinder(radius, thick, plane)
        s.label = name
        out.append(s)

    B = np.array([j.zero if j.type == "P" and j.zero is not None else j.location
                  for leg in model.legs for j in leg.joints[:1]])
    bc = B.mean(axis=0)
    disc("base_plate", bc - [0, 0, 0.05 * d], np.array([0, 0, 1.0]),
         max(float(np.max(np.linalg.norm(B - bc, axis=1))), d), 0.1 * d + 1e-3)
    c, rad, th = _platform_disc(model)
    disc("platform_plate", c, model.R[:, 2], rad, th)
    seen = set()
    for leg in model.legs:
        for j in leg.joints:
            if j.name in seen:
                continue
            seen.add(j.name)
            s = bd.Solid.make_sphere(0.5 * JOINT_SPHERE * d).moved(
                bd.Location(tuple(map(float, j.location))))
            s.label = f"joint {j.name} ({j.type})"
            out.append(s)
    for name, gs in geoms.items():
        if model.bodies[name].kind != "link":
            continue
        for k, (a, b, r) in enumerate(gs):
            L = float(np.linalg.norm(b - a))
            if L < TOL.direction_norm:
                continue
            s = bd.Solid.make_cylinder(r, L, bd.Plane(origin=tuple(map(float, a)),
                                                      z_dir=tuple((b - a) / L)))
            s.label = f"link {name} #{k + 1}"
            out.append(s)
    return out


def step_bytes(mech, pose=None, mass: MassModel | None = None) -> bytes:
    """The STEP file's bytes (build123d writes to a path: a temporary file)."""
    import build123d as bd

    comp = bd.Compound(children=_solids(mech, pose, mass))
    comp.label = mech.name or mech.family
    fd, path = tempfile.mkstemp(suffix=".step")
    os.close(fd)
    try:
        if not bd.export_step(comp, path, unit=bd.Unit.MM):
            raise OSError(f"build123d could not write {path}")
        with open(path, "rb") as f:
            return f.read()
    finally:
        os.unlink(path)
