"""``rpr3``: the planar 3-RPR parallel manipulator (issue 24, item 3).

Three legs join base pivots ``a_i`` to platform pivots ``u_i`` (all in the plane z = 0); each
leg is a passive revolute joint on the base (axis z), an actuated prismatic joint (the leg
length ``ρ_i``, mm) and a passive revolute joint on the platform (axis z). The platform moves
in its plane: mobility :data:`~pkmlab.mechanisms.mobility.PLANAR`, pose ``(x, y, φ)`` with
``φ = theta_z`` (the other pose coordinates stay at the nominal pose's, 0).

* **Inverse kinematics** (closed form, one solution per leg): ``ρ_i = |p + R(φ)·u_i - a_i|``;
  status per actuator: ``ok`` / ``stroke below minimum`` / ``stroke above maximum``.
* **Jacobian** ``(N, 3, 3)`` over ``(v_x, v_y, ω_z)``: row ``i`` is ``[n_i, (r_i × n_i)_z]``,
  ``n_i`` the unit leg direction, ``r_i = R·u_i`` (the legs' unit-direction form ``J =
  diag(ρ)⁻¹·A``).
* **Forward kinematics**: :meth:`Rpr3.forward` (Newton, the protocol's) and every real
  assembly mode from the sextic, :meth:`Rpr3.assembly_modes` / :meth:`Rpr3.forward_all`
  (:mod:`.planar_fk`): up to six.
* **Working modes**: with ``ρ_i > 0`` each leg's inverse kinematics has one solution, so the
  3-RPR has a single working mode (:meth:`Rpr3.working_modes`); a negative ``ρ_i`` (the
  platform pivot passing through the base pivot) is not a configuration of a prismatic leg.
* **Singularities** (:meth:`Rpr3.singularity`, Gosselin & Angeles 1990 in the form ``A·t =
  B·ρ̇``, ``B = diag(ρ_i)``, rows of ``A`` ``[s_i, (r_i × s_i)_z]`` with ``s_i`` the leg
  vector): type I (serial) where a leg length vanishes, type II (parallel) where ``A`` loses
  rank — the three leg lines meet in one point or are parallel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba.extending import register_jitable
from pydantic import Field

from ...errors import ParameterError
from ...quantities import Angle, PositiveLength
from ...specbase import FamilySpec, _Model
from ..base import AssemblyModes, Mechanism, as_points, as_stroke
from ..joints import JointArrays, LegTemplate, platform_joints, unit
from ..kernels import ik as _kernels
from ..mobility import PLANAR
from ..solvers import newton
from . import planar_fk

__all__ = ["Rpr3", "Rpr3Spec", "Rpr3Layout", "triangle_layout", "SINGULARITY"]

#: codes of :meth:`Rpr3.singularity` (shared by the five-bar)
SINGULARITY = {0: "regular", 1: "type I (serial)", 2: "type II (parallel)",
               3: "type I and type II"}


@register_jitable(inline="always")
def _rpr3_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
              j):
    for i in range(3):
        ux, uy, uz = g[9 + 3 * i], g[10 + 3 * i], g[11 + 3 * i]
        sx = px + r00 * ux + r01 * uy + r02 * uz - g[3 * i]
        sy = py + r10 * ux + r11 * uy + r12 * uz - g[3 * i + 1]
        sz = pz + r20 * ux + r21 * uy + r22 * uz - g[3 * i + 2]
        v = math.sqrt(sx * sx + sy * sy + sz * sz)
        q[i * _kernels.ROW + j] = v
        st[i * _kernels.ROW + j] = _kernels.stroke_status(v, qmin, qmax)


def triangle_layout(base_radius: float, platform_radius: float, platform_rotation: float = 0.0,
                    base_angles=(90.0, 210.0, 330.0)) -> tuple[np.ndarray, np.ndarray]:
    """The usual symmetric layout: base pivots on a circle at ``base_angles`` (deg), platform
    pivots on a circle at the same angles turned by ``platform_rotation`` (rad)."""
    a = np.radians(np.asarray(base_angles, dtype=float))
    b = a + platform_rotation
    z = np.zeros(3)
    return (np.stack([base_radius * np.cos(a), base_radius * np.sin(a), z], axis=1),
            np.stack([platform_radius * np.cos(b), platform_radius * np.sin(b), z], axis=1))


class Rpr3Layout(_Model):
    """Generator of the symmetric 3-RPR layout (:func:`triangle_layout`)."""

    base_radius: PositiveLength = Field(description="base pivot circle radius (mm)")
    platform_radius: PositiveLength = Field(description="platform pivot circle radius (mm)")
    platform_rotation: Angle = Field(0.0, description="platform pivots turned by (deg)")


class Rpr3Spec(FamilySpec):
    """YAML model of ``rpr3``: explicit ``base_points`` / ``platform_points`` (z = 0) or a
    ``generator`` (:class:`Rpr3Layout`); ``stroke`` the leg-length window (mm)."""

    family: Literal["rpr3"]
    generator: Rpr3Layout | None = None

    def build(self):
        if self._explicit("generator"):
            base, plat = self.base_points, self.platform_points
        else:
            g = self.generator
            base, plat = triangle_layout(g.base_radius, g.platform_radius, g.platform_rotation)
        return Rpr3(base, plat, tuple(self.stroke), self.tool_offset, **self.explicit_kw())


def _planar_points(arr: np.ndarray, field: str) -> np.ndarray:
    if np.any(np.abs(arr[..., 2]) > 0.0):
        raise ParameterError(field, "points in the plane z = 0 (a planar mechanism)",
                             np.asarray(arr).tolist())
    return arr


@dataclass(frozen=True, eq=False)
class Rpr3(Mechanism):
    """The planar 3-RPR (module docstring)."""

    family = "rpr3"
    spec_model = Rpr3Spec
    mobility = PLANAR
    actuator_names = ("q1", "q2", "q3")
    #: forward kinematics and assembly modes are complete (closed form), not a search
    closed_form_modes = True
    design_aliases = {
        "base_radius": ("generator.base_radius", "length"),
        "platform_radius": ("generator.platform_radius", "length"),
        "platform_rotation": ("generator.platform_rotation", "angle"),
        "stroke_min": ("stroke[0]", "length"),
        "stroke_max": ("stroke[1]", "length"),
    }

    base_points: np.ndarray
    platform_points: np.ndarray
    stroke_window: tuple
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)

    _ik_one = _rpr3_one

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", _planar_points(as_points(self.base_points, "base_points", 3),
                                                 "base_points"))
        set_(self, "platform_points", _planar_points(
            as_points(self.platform_points, "platform_points", 3), "platform_points"))
        set_(self, "stroke_window", as_stroke(self.stroke_window, "stroke", positive=True))
        off = np.asarray(self.tool_offset, dtype=float)
        if off.shape != (3,) or not np.all(np.isfinite(off)) or off[2] != 0.0:
            raise ParameterError("tool_offset", "[x, y, 0] mm (in the platform plane)",
                                 off.tolist())
        set_(self, "tool_offset", off)

    @property
    def scale(self) -> float:
        return float(np.abs(self.base_points).max() + np.abs(self.platform_points).max()
                     + self.stroke[1])

    def _gparams(self):
        return np.concatenate([self.base_points.ravel(), self.tool_points.ravel()])

    # ---- kinematics ---------------------------------------------------------------------------
    def _legs(self, p, R):
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        s = p[:, None, :] + r - self.base_points
        length = np.linalg.norm(s, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            return r, s / length[..., None], length

    def _jacobian(self, p, R):
        r, n, _ = self._legs(p, R)
        return np.concatenate([n, np.cross(r, n)], axis=-1)

    def _closure(self, p, R, q):
        r, n, length = self._legs(p, R)
        return length - q, np.concatenate([n, np.cross(r, n)], axis=-1)

    def _mid_stroke_pose(self) -> np.ndarray:
        """The platform centred over the base pivots' centroid with φ = 0 when every leg is
        then inside its window (give ``nominal`` otherwise)."""
        c = self.base_points.mean(axis=0) - self.platform_points.mean(axis=0) + self.tool_offset
        X = np.array([c[0], c[1], 0.0, 0.0, 0.0, 0.0])
        ik = self._run_ik(X[None], None, *self.stroke)
        if not ik.valid[0]:
            raise ParameterError("stroke", "a window holding the leg lengths of the centred "
                                 "platform at φ = 0 (the nominal pose: give 'nominal_pose' "
                                 "or change the stroke)", f"{list(self.stroke)}, legs "
                                 f"{np.round(ik.q[0], 6).tolist()} mm")
        return X

    def working_modes(self) -> tuple[str, ...]:
        """The working modes (module docstring): one, every leg length positive."""
        return ("+++",)

    def forward_all(self, q, *, tol: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
        """Every real assembly mode of each actuator vector, from the sextic
        (:mod:`.planar_fk`): ``(poses (N, 6, 6), count (N,))``, the poses six-coordinate,
        NaN-padded after ``count``, sorted by distance from the nominal pose; a mode is kept
        when Newton's polish leaves a loop-closure residual below ``tol`` mm."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        if q.shape[1:] != (3,):
            raise ParameterError("q", "an array of shape (3,) or (N, 3) in mm", q.shape)
        n = len(q)
        cand, _ = planar_fk.rpr3_candidates(self.base_points[:, :2], self.tool_points[:, :2], q)
        X = np.zeros((n * 6, 6))
        X[:, [0, 1, 5]] = cand.reshape(-1, 3)
        have = np.all(np.isfinite(X), axis=1)
        from ...poses import as_frames, frames_to_poses

        out = np.full((n, 6, 6), np.nan)
        count = np.zeros(n, dtype=int)
        if not have.any():
            return out, count
        p, R = as_frames(X[have])
        p, R, res, _, _ = newton(self, p, R, np.repeat(q, 6, axis=0)[have], tol=tol,
                                 max_iter=20)
        poses = frames_to_poses(p, R)
        poses[:, 5] = np.angle(np.exp(1j * poses[:, 5]))
        owner = np.repeat(np.arange(n), 6)[have]
        good = res < tol
        from ...tolerances import TOL

        lin = TOL.mode_duplicate_rel * self.scale
        for k in range(n):
            sel = poses[(owner == k) & good]
            keep: list[np.ndarray] = []
            for x in sel:
                if not any(abs(x[0] - y[0]) + abs(x[1] - y[1]) < lin
                           and abs(np.angle(np.exp(1j * (x[5] - y[5])))) < TOL.mode_duplicate_rel
                           for y in keep):
                    keep.append(x)
            if keep:
                K = np.array(keep)
                d = self._mode_distance(K)
                K = K[np.argsort(d, kind="stable")]
                out[k, :len(K)] = K
                count[k] = len(K)
        return out, count

    def _mode_distance(self, X: np.ndarray) -> np.ndarray:
        nom = self.nominal_pose
        dphi = np.abs(np.angle(np.exp(1j * (X[:, 5] - nom[5]))))
        return np.hypot(X[:, 0] - nom[0], X[:, 1] - nom[1]) + self.scale * dphi

    def assembly_modes(self, q, *, starts: int = 0, seed: int = 0, tol: float = 1e-9
                       ) -> AssemblyModes:
        """Every real assembly mode of one actuator vector from the sextic (exact: no
        start-point search, ``starts`` and ``seed`` are ignored; ``starts`` of the result is
        0). Sorted by distance from the nominal pose; all in the single working mode."""
        q = np.asarray(q, dtype=float).reshape(3)
        poses, count = self.forward_all(q, tol=tol)
        X = poses[0, :count[0]]
        f, _ = self._closure(*self._frames(X), np.repeat(q[None], len(X), 0)) if len(X) \
            else (np.zeros((0, 3)), None)
        res = np.max(np.abs(f), axis=1) if len(X) else np.zeros(0)
        return AssemblyModes(pose=X, residual=res, working_mode=np.ones(len(X), dtype=bool),
                             distance=self._mode_distance(X), starts=0)

    def singularity(self, poses, rtol: float = 1e-9) -> np.ndarray:
        """``(N,)`` codes of :data:`SINGULARITY` at poses (any form :meth:`inverse` takes):
        type I where a leg length is below ``rtol``·scale (its direction, and so the parallel
        matrix, is then undefined: type I only), type II where the parallel matrix with unit
        leg directions, rows ``[n_i, (r_i × n_i)_z / scale]``, has ``σmin < rtol·σmax``."""
        p, R = self._frames(poses)
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        s = p[:, None, :] + r - self.base_points
        rho = np.linalg.norm(s, axis=-1)
        type1 = np.any(rho < rtol * self.scale, axis=1)
        n = s / np.where(rho > 0, rho, 1.0)[..., None]
        A = np.concatenate([n[..., :2], np.cross(r, n)[..., 2:] / self.scale], axis=-1)
        sv = np.linalg.svd(A, compute_uv=False)
        type2 = (sv[:, -1] < rtol * sv[:, 0]) & ~type1
        return type1.astype(int) + 2 * type2.astype(int)

    def parallel_determinant(self, poses) -> np.ndarray:
        """``det A / scale³`` (``A`` of :meth:`singularity`, dimensionless): its sign tells the
        two sides of the type II singularity locus (used to draw it)."""
        p, R = self._frames(poses)
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        s = p[:, None, :] + r - self.base_points
        A = np.concatenate([s[..., :2], np.cross(r, s)[..., 2:] / self.scale], axis=-1)
        return np.linalg.det(A) / self.scale ** 2

    # ---- planar workspace hooks (:mod:`pkmlab.workspaces.planar`) ----------------------------
    def position_box(self, phi_lo: float, phi_hi: float) -> tuple[float, float, float, float]:
        """A box holding every stroke-feasible position: leg i's tool point lies within
        ``ρ_max + |u_i|`` of its base pivot, whatever φ."""
        r = self.stroke[1] + np.linalg.norm(self.tool_points[:, :2], axis=1)
        a = self.base_points[:, :2]
        return (float(np.max(a[:, 0] - r)), float(np.min(a[:, 0] + r)),
                float(np.max(a[:, 1] - r)), float(np.min(a[:, 1] + r)))

    def planar_cell_margins(self, xy, phi, delta, alpha):
        """Stroke margins ``min(ρ_i - ρmin, ρmax - ρ_i)`` at the cell centres and their bound
        over the cell: a leg length is 1-Lipschitz in the position and moves by at most
        ``|u_i|·α`` when the platform turns by α (the chord of its pivot's arc)."""
        X = np.zeros((len(xy), 6))
        X[:, :2], X[:, 5] = xy, phi
        q = self.inverse(X, stroke=(-np.inf, np.inf)).q
        lo, hi = self.stroke
        m = np.minimum(q - lo, hi - q)
        u = np.linalg.norm(self.tool_points[:, :2], axis=1)
        eps = np.asarray(delta)[:, None] + np.asarray(alpha)[:, None] * u[None, :]
        return m, eps

    def annuli(self, phi: float):
        """At orientation φ, the stroke-feasible positions are ``∩_i {p : ρmin <= |p - c_i|
        <= ρmax}`` with ``c_i = a_i - R(φ)·u_i``."""
        c, s = math.cos(phi), math.sin(phi)
        u = self.tool_points[:, :2]
        Ru = np.stack([c * u[:, 0] - s * u[:, 1], s * u[:, 0] + c * u[:, 1]], axis=1)
        lo, hi = self.stroke
        return self.base_points[:, :2] - Ru, np.full(3, lo), np.full(3, hi)

    def singular_fields(self, poses) -> dict:
        """Fields whose zero level is a singularity locus, for drawing: type II, ``det A``."""
        return {"type II (parallel)": self.parallel_determinant(poses)}

    def singular_points(self, phi: float) -> dict:
        """Type I loci at orientation φ: the positions where a platform pivot lies on its base
        pivot (a leg length 0)."""
        c, _, _ = self.annuli(phi)
        return {"type I (serial)": c}

    # ---- joints ------------------------------------------------------------------------------
    def _joint_arrays(self, p, R, axes=True):
        W = platform_joints(self, p, R)
        a = np.broadcast_to(self.base_points, W.shape)
        n = len(p)
        ax = None
        q = None
        if axes:
            ax = np.full((n, 3, 3, 2, 3), np.nan)
            ax[:, :, 0, 0] = (0.0, 0.0, 1.0)
            ax[:, :, 1, 0] = unit(W - a)
            ax[:, :, 2, 0] = (0.0, 0.0, 1.0)
            q = np.linalg.norm(W - a, axis=-1)
        return JointArrays((a, W, W), ax, q)

    def _leg_templates(self):
        out = []
        for i, name in enumerate(self.actuator_names):
            leg = f"leg{i + 1}"
            out.append(LegTemplate(
                name, ("R", "P", "R"), (f"{leg}.base_R", f"{leg}.P", f"{leg}.platform_R"),
                ("base", f"{leg}.cylinder", f"{leg}.rod", "platform"), (0.0, 0.0), 1, (0, 2),
                self.base_points[i].copy(), self.platform_points[i].copy(),
                self.base_points[i].copy(), None))
        return tuple(out)
