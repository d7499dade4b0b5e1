"""A three-leg translational family written as a plugin: ``tri3``, three extensible legs
between base points and platform points on a platform that only translates (a 3-UPU with its
universal joints arranged for pure translation). Used by tests/mechanisms/test_mobility.py."""

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba.extending import register_jitable

from pkmlab.config import FamilySpec
from pkmlab.mechanisms import NO_STROKE, TRANSLATIONAL, Mechanism, joints
from pkmlab.mechanisms.base import as_points, as_stroke
from pkmlab.mechanisms.kernels import ik


@register_jitable(inline="always")
def _tri3_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    for i in range(3):
        ux, uy, uz = g[9 + 3 * i], g[10 + 3 * i], g[11 + 3 * i]
        sx = px + r00 * ux + r01 * uy + r02 * uz - g[3 * i]
        sy = py + r10 * ux + r11 * uy + r12 * uz - g[3 * i + 1]
        sz = pz + r20 * ux + r21 * uy + r22 * uz - g[3 * i + 2]
        v = math.sqrt(sx * sx + sy * sy + sz * sz)
        q[i * ik.ROW + j] = v
        # the working mode: every leg rises from its base joint (the mirror below is the
        # other assembly mode, as on the 6-UPS)
        st[i * ik.ROW + j] = (ik.OTHER_MODE if sz <= 0.0
                                    else ik.stroke_status(v, qmin, qmax))


class Tri3Spec(FamilySpec):
    family: Literal["tri3"]

    def build(self):
        return Tri3(self.base_points, self.platform_points, self.stroke, self.tool_offset,
                    **self.explicit_kw())


@dataclass(frozen=True, eq=False)
class Tri3(Mechanism):
    family = "tri3"
    spec_model = Tri3Spec
    mobility = TRANSLATIONAL
    actuator_names = ("q1", "q2", "q3")

    base_points: np.ndarray
    platform_points: np.ndarray
    stroke_window: tuple
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)

    _ik_one = _tri3_one

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 3))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 3))
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
        return r, s / length[..., None], length

    def _jacobian(self, p, R):
        r, n, _ = self._legs(p, R)
        return np.concatenate([n, np.cross(r, n)], axis=-1)

    def _closure(self, p, R, q):
        r, n, length = self._legs(p, R)
        return length - q, np.concatenate([n, np.cross(r, n)], axis=-1)

    # joints (pkmlab.mechanisms.joints): U on the base, the actuated P along the leg, U on
    # the platform, arranged for translation (Tsai's 3-UPU): the platform U's axes parallel
    # to the base U's, in reverse order
    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        W = joints.platform_joints(self, p, R)
        arr = joints.kind_arrays(self, "prismatic", self.base_points, W, q, R, axes)
        if axes:
            arr.axes[:, :, 2] = arr.axes[:, :, 0, ::-1]
        return arr

    def _leg_templates(self):
        return tuple(joints.kind_template("prismatic", i, n, self.base_points[i],
                                          self.platform_points[i], (0.0, 0.0),
                                          zero=self.base_points[i], types=("U", "P", "U"))
                     for i, n in enumerate(self.actuator_names))


def circle(radius, degrees=(90.0, 210.0, 330.0)):
    a = np.radians(degrees)
    return np.stack([radius * np.cos(a), radius * np.sin(a), np.zeros(3)], axis=1)


def reporters_tripod(**kw):
    """The issue's example: base joints at 300 mm, platform joints at 60 mm, both at 90°,
    210° and 330°; stroke 250-600 mm."""
    return Tri3(circle(300.0), circle(60.0), (250.0, 600.0), **kw)
