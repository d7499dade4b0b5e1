"""A minimal pkmlab family plugin: ``legs6``, six extensible legs (a bare 6-UPS without a
working-mode check), used by tests/mechanisms/test_plugins.py and shown in the README."""

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba.extending import register_jitable

from pkmlab.config import FamilySpec, Points
from pkmlab.mechanisms import NO_STROKE, Mechanism, joints
from pkmlab.mechanisms.base import as_points, as_stroke
from pkmlab.mechanisms.kernels import ik


@register_jitable(inline="always")
def _legs_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    for i in range(6):
        ux, uy, uz = g[18 + 3 * i], g[19 + 3 * i], g[20 + 3 * i]
        sx = px + r00 * ux + r01 * uy + r02 * uz - g[3 * i]
        sy = py + r10 * ux + r11 * uy + r12 * uz - g[3 * i + 1]
        sz = pz + r20 * ux + r21 * uy + r22 * uz - g[3 * i + 2]
        v = math.sqrt(sx * sx + sy * sy + sz * sz)
        q[i * ik.ROW + j] = v
        st[i * ik.ROW + j] = ik.stroke_status(v, qmin, qmax)


class Legs6Spec(FamilySpec):
    family: Literal["legs6"]
    base_points: Points
    platform_points: Points

    def build(self):
        return Legs6(self.base_points, self.platform_points, self.stroke, self.tool_offset,
                     **self.explicit_kw())


@dataclass(frozen=True, eq=False)
class Legs6(Mechanism):
    family = "legs6"
    spec_model = Legs6Spec
    design_aliases = {"stroke_max": ("stroke[1]", "length")}

    base_points: np.ndarray
    platform_points: np.ndarray
    stroke_window: tuple
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)

    _ik_one = _legs_one

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 6))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 6))
        set_(self, "stroke_window", as_stroke(self.stroke_window, "stroke", positive=True))
        set_(self, "tool_offset", np.asarray(self.tool_offset, dtype=float))

    @property
    def scale(self):
        return float(np.abs(self.base_points).max() + np.abs(self.platform_points).max()
                     + self.stroke[1])

    def _gparams(self):
        return np.concatenate([self.base_points.ravel(), self.tool_points.ravel()])

    def _legs(self, p, R):
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        s = p[:, None, :] + r - self.base_points
        length = np.linalg.norm(s, axis=-1)
        n = s / length[..., None]
        return r, n, length

    def _jacobian(self, p, R):
        r, n, _ = self._legs(p, R)
        return np.concatenate([n, np.cross(r, n)], axis=-1)

    def _closure(self, p, R, q):
        r, n, length = self._legs(p, R)
        return length - q, np.concatenate([n, np.cross(r, n)], axis=-1)

    # joints (pkmlab.mechanisms.joints): U on the base, the actuated P along the leg, S on
    # the platform; the parameter vector is the protocol's default (joints, stroke, tool)
    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        W = joints.platform_joints(self, p, R)
        return joints.kind_arrays(self, "prismatic", self.base_points, W, q, R, axes)

    def _leg_templates(self):
        return tuple(joints.kind_template("prismatic", i, n, self.base_points[i],
                                          self.platform_points[i], (0.0, 0.0),
                                          zero=self.base_points[i])
                     for i, n in enumerate(self.actuator_names))
