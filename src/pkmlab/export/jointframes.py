"""``joints``: every joint's frame at one pose (default nominal), as CSV and JSON, for CAD and
controllers, straight from ``mech.legs(pose)`` in the base frame (mm, unit axes).

A joint's frame: origin at its centre (a P joint: ``location``, the child's point; its
``zero`` is written too); z along its axis (R, P), its first axis (U) or the base z (S);
x along, in order of availability, a U's second axis, an actuated R's ``reference``, the
direction to the next joint's centre made orthogonal to z, or the base x (then y, if parallel
to z); y = z × x. The rotation matrix is written row-major with its columns the frame's x, y
and z axes in the base frame. The JSON adds the pose, the units, the actuator values, the
mechanism's parameter vector (``mech.parameters()``) and the spanning tree and loop closures
of the simulator exports (:mod:`.model`).
"""

from __future__ import annotations

import csv
import io
import json

import numpy as np

from ..tolerances import TOL
from .model import MassModel, build_model

__all__ = ["joint_rows", "joints_csv", "joints_json", "frame_of"]

_COLUMNS = ("leg", "joint", "type", "parent", "child", "actuated", "value", "x_mm", "y_mm",
            "z_mm", "axis1_x", "axis1_y", "axis1_z", "axis2_x", "axis2_y", "axis2_z",
            "zero_x_mm", "zero_y_mm", "zero_z_mm", "R00", "R01", "R02", "R10", "R11", "R12",
            "R20", "R21", "R22")


def _perp(z: np.ndarray, v) -> np.ndarray | None:
    if v is None:
        return None
    v = np.asarray(v, dtype=float) - (np.asarray(v, dtype=float) @ z) * z
    n = np.linalg.norm(v)
    return v / n if n > TOL.direction_norm else None


def frame_of(joint, following=None) -> np.ndarray:
    """The joint's frame rotation (columns x, y, z in the base frame; module docstring)."""
    z = np.asarray(joint.axes[0], float) if len(joint.axes) else np.array([0.0, 0.0, 1.0])
    z = z / np.linalg.norm(z)
    nxt = None if following is None else following.location - joint.location
    for cand in ((joint.axes[1] if len(joint.axes) > 1 else None), joint.reference, nxt,
                 (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)):
        x = _perp(z, cand)
        if x is not None:
            break
    return np.column_stack([x, np.cross(z, x), z])


def joint_rows(mech, pose=None) -> list[dict]:
    """One row per (leg, joint), in leg order (a shared joint in each of its legs)."""
    X = np.asarray(mech.nominal_pose if pose is None else pose, dtype=float)
    rows = []
    for leg in mech.legs(X):
        for k, j in enumerate(leg.joints):
            nxt = leg.joints[k + 1] if k + 1 < len(leg.joints) else None
            ax = np.full((2, 3), np.nan)
            ax[:len(j.axes)] = j.axes
            zero = j.zero if j.zero is not None else np.full(3, np.nan)
            rows.append({
                "leg": leg.name, "joint": j.name, "type": j.type, "parent": j.parent,
                "child": j.child, "actuated": bool(j.actuated),
                "value": float(leg.value) if j.actuated else None,
                "location": j.location, "axes": ax, "zero": zero,
                "frame": frame_of(j, nxt)})
    return rows


def _num(v) -> str:
    return "" if v is None or not np.isfinite(v) else repr(float(v))


def joints_csv(mech, pose=None, mass: MassModel | None = None) -> bytes:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(_COLUMNS)
    for r in joint_rows(mech, pose):
        w.writerow([r["leg"], r["joint"], r["type"], r["parent"], r["child"],
                    int(r["actuated"]), _num(r["value"])]
                   + [_num(v) for v in r["location"]] + [_num(v) for v in r["axes"].ravel()]
                   + [_num(v) for v in r["zero"]] + [_num(v) for v in r["frame"].ravel()])
    return buf.getvalue().encode()


def _list(a):
    a = np.asarray(a, dtype=float)
    return None if np.all(np.isnan(a)) else np.where(np.isnan(a), None, a).tolist()


def joints_json(mech, pose=None, mass: MassModel | None = None) -> bytes:
    X = np.asarray(mech.nominal_pose if pose is None else pose, dtype=float)
    model = build_model(mech, X, mass)
    par = mech.parameters()
    doc = {
        "mechanism": mech.name, "family": mech.family,
        "units": {"length": "mm", "angle": "rad", "actuator": mech.actuator_unit},
        "pose": dict(zip(("x", "y", "z", "theta_x", "theta_y", "theta_z"), X.tolist())),
        "actuators": {leg.name: float(leg.value) for leg in model.legs},
        "joints": [{**{k: r[k] for k in ("leg", "joint", "type", "parent", "child",
                                         "actuated", "value")},
                    "location": r["location"].tolist(),
                    "axes": [a.tolist() for a in r["axes"] if np.all(np.isfinite(a))],
                    "zero": _list(r["zero"]), "frame": r["frame"].tolist()}
                   for r in joint_rows(mech, X)],
        "tree": [{"body": b.name, "parent": b.parent,
                  "joints": [{"name": t.name, "kind": t.kind, "protocol": t.protocol}
                             for t in b.joints]}
                 for b in model.bodies.values()],
        "closures": [{"name": c.name, "kind": c.kind, "body1": c.body1, "body2": c.body2,
                      "anchor": c.anchor.tolist(), "cut_joint_type": c.protocol_type}
                     for c in model.closures],
        "parameters": [{"name": n, "value": float(v), "unit": u, "description": d}
                       for n, v, u, d in zip(par.names, par.values, par.units,
                                             par.descriptions)],
    }
    return (json.dumps(doc, indent=1) + "\n").encode()


def joints_files(mech, pose=None, mass: MassModel | None = None) -> dict[str, bytes]:
    return {".joints.csv": joints_csv(mech, pose, mass),
            ".joints.json": joints_json(mech, pose, mass)}
