"""``prs3``: the 3-PRS tripod (issue 24, item 5); free ``z, θx, θy``, dependent ``x, y, θz``.

Leg i: an actuated slider on a rail (point ``a_i``, unit direction ``d_i``; the actuator value
``q_i`` is the slider's distance from ``a_i`` along the rail), a revolute joint on the slider
with a horizontal axis ``n_i``, a link of fixed length ``l_i`` and a spherical joint at the
platform point ``b_i`` (platform frame). The revolute joint keeps the link, and so the
platform joint ``S_i``, in the vertical plane through the rail with normal ``n_i``:

    n_i · S_i = n_i · a_i,        S_i = p + R·b_i,    R = Rz(θz)·Ry(θy)·Rx(θx).

**Parasitic motions in closed form.** Row 3 of R is ``(-sin θy, cos θy sin θx, cos θy cos θx)``
whatever θz, so ``M = Ry·Rx`` and ``w_i = M·b_i`` are known from the free coordinates. With
``A_i = n_i·w_i`` and ``B_i = (n_i × w_i)·ẑ``... written out, the constraints are ``N·(x, y) +
cos θz·A + sin θz·B = h`` (``N`` rows ``(n_ix, n_iy)``, ``h_i = n_i·a_i``); multiplying by the
left null vector ``k`` of ``N`` leaves ``a·cos θz + b·sin θz = e`` (``a = k·A``, ``b = k·B``,
``e = k·h``): ``θz = atan2(b, a) ± acos(e / hypot(a, b))``, the root nearer the nominal θz
(0 for the symmetric layout) taken; then ``(x, y)`` from ``N`` by least squares (exactly
consistent). :meth:`Prs3.parasitic` returns ``(x, y, θz)``; :meth:`Prs3.complete` the
six-coordinate poses. The inverse kinematics reads ``z`` and row 3 of R only (a given pose's
x, y, θz are replaced by the dependent values): see :mod:`..mobility`.

**Inverse kinematics.** ``q_i = d_i·D_i + σ_i·sqrt(l_i² - |D_i|² + (d_i·D_i)²)``, ``D_i = S_i -
a_i``; ``σ_i = +1`` puts the slider above the joint's foot on the rail (the usual tripod head).
Status per actuator: ``no real solution`` where the link cannot reach, else the stroke.

**Jacobian** ``(N, 3, 3)`` over ``(v_z, ω_x, ω_y)``: from ``|S - a - q·d| = l``, ``q̇_i = L_i·Ṡ_i /
(L_i·d_i)`` (``L_i`` the link vector), i.e. full rows ``[L_i, r_i × L_i] / (L_i·d_i)``; the
dependent twist ``(v_x, v_y, ω_z)`` follows from the constraint rows ``[n_i, r_i × n_i]``:
``J = J_free + J_dep·(-C_dep⁻¹·C_free)``.

**Singularities** (:meth:`Prs3.singularity`, bit flags): 1 type I (serial: a link ⟂ its rail,
``L·d = 0``), 2 type II (parallel: ``J`` singular with the constraint regular), 4 constraint
singularity (``C_dep`` singular: the platform gains a parasitic motion).

**Assembly modes**: multi-start Newton on the free coordinates (the protocol's), the poses
completed; not known to be complete.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba import njit
from numba.extending import register_jitable
from pydantic import Field

from ...errors import ParameterError
from ...poses import frames_to_poses
from ...quantities import Angle, LinkLengths, PositiveLength
from ...specbase import FamilySpec, _Model
from ..base import AssemblyModes, Mechanism, as_points, as_stroke
from ..joints import JointArrays, LegTemplate, ParamField, platform_joints, unit
from ..kernels import ik as _kernels
from ..mobility import Mobility
from ..solvers import multistart_modes

__all__ = ["Prs3", "Prs3Spec", "TRIPOD", "tripod_layout"]

#: free z, θx, θy; x, y, θz dependent (the parasitic motions)
TRIPOD = Mobility("tripod", ("z", "theta_x", "theta_y"), dependent=("x", "y", "theta_z"))
_FREE, _DEP = [2, 3, 4], [0, 1, 5]

# geometry tuple layout (see Prs3._gparams)
_A, _D, _N, _B, _L, _S, _P, _K, _H = 0, 9, 18, 27, 36, 39, 42, 48, 51


@njit(cache=True, forceinline=True)
def _w(g, i, cb, sb, ca, sa):
    """``w_i = Ry·Rx·b_i`` and its ``A_i``, ``B_i`` (module docstring)."""
    bx, by, bz = g[_B + 3 * i], g[_B + 3 * i + 1], g[_B + 3 * i + 2]
    wx = cb * bx + sb * sa * by + sb * ca * bz
    wy = ca * by - sa * bz
    wz = -sb * bx + cb * sa * by + cb * ca * bz
    nx, ny = g[_N + 3 * i], g[_N + 3 * i + 1]
    return wx, wy, wz, nx * wx + ny * wy, ny * wx - nx * wy


@njit(cache=True, forceinline=True)
def _leg(g, i, x, y, pz, cg, sg, wx, wy, wz, qmin, qmax, okc, q, st, j):
    Dx = x + cg * wx - sg * wy - g[_A + 3 * i]
    Dy = y + sg * wx + cg * wy - g[_A + 3 * i + 1]
    Dz = pz + wz - g[_A + 3 * i + 2]
    t = g[_D + 3 * i] * Dx + g[_D + 3 * i + 1] * Dy + g[_D + 3 * i + 2] * Dz
    disc = g[_L + i] * g[_L + i] - (Dx * Dx + Dy * Dy + Dz * Dz) + t * t
    ok = okc & (disc >= 0.0)
    v = t + g[_S + i] * math.sqrt(max(disc, 0.0))
    q[i * _kernels.ROW + j] = v if ok else math.nan
    st[i * _kernels.ROW + j] = (_kernels.stroke_status(v, qmin, qmax) if ok
                                else _kernels.NO_SOLUTION)


@register_jitable(inline="always")
def _prs3_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
              j):
    sb = -r20
    cb = math.sqrt(r21 * r21 + r22 * r22)
    sa, ca = r21 / cb, r22 / cb
    w0x, w0y, w0z, A0, B0 = _w(g, 0, cb, sb, ca, sa)
    w1x, w1y, w1z, A1, B1 = _w(g, 1, cb, sb, ca, sa)
    w2x, w2y, w2z, A2, B2 = _w(g, 2, cb, sb, ca, sa)
    a = g[_K] * A0 + g[_K + 1] * A1 + g[_K + 2] * A2
    b = g[_K] * B0 + g[_K + 1] * B1 + g[_K + 2] * B2
    rho = math.sqrt(a * a + b * b)
    ce = g[_H + 3] / rho
    okc = abs(ce) <= 1.0
    ce = min(1.0, max(-1.0, ce))
    se = math.sqrt(1.0 - ce * ce)
    # θz = atan2(b, a) ± acos(ce), the root nearer 0 (the larger cosine), as cos and sin
    c1, s1 = (a * ce - b * se) / rho, (b * ce + a * se) / rho
    c2, s2 = (a * ce + b * se) / rho, (b * ce - a * se) / rho
    cg = c1 if c1 >= c2 else c2
    sg = s1 if c1 >= c2 else s2
    r0 = g[_H] - cg * A0 - sg * B0
    r1 = g[_H + 1] - cg * A1 - sg * B1
    r2 = g[_H + 2] - cg * A2 - sg * B2
    x = g[_P] * r0 + g[_P + 1] * r1 + g[_P + 2] * r2
    y = g[_P + 3] * r0 + g[_P + 4] * r1 + g[_P + 5] * r2
    _leg(g, 0, x, y, pz, cg, sg, w0x, w0y, w0z, qmin, qmax, okc, q, st, j)
    _leg(g, 1, x, y, pz, cg, sg, w1x, w1y, w1z, qmin, qmax, okc, q, st, j)
    _leg(g, 2, x, y, pz, cg, sg, w2x, w2y, w2z, qmin, qmax, okc, q, st, j)


def tripod_layout(base_radius, platform_radius, rail_inclination=0.0,
                  angles=(90.0, 210.0, 330.0)):
    """The symmetric tripod: rails at ``base_radius`` (z = 0) at ``angles`` (deg), inclined by
    ``rail_inclination`` (rad) towards the centre as they rise, R axes tangential; platform
    joints at ``platform_radius`` at the same angles. Returns ``(a, d, n, b)``."""
    t = np.radians(np.asarray(angles, dtype=float))
    u = np.stack([np.cos(t), np.sin(t), np.zeros(3)], axis=1)
    n = np.stack([-np.sin(t), np.cos(t), np.zeros(3)], axis=1)
    d = math.cos(rail_inclination) * np.array([0.0, 0.0, 1.0]) - math.sin(rail_inclination) * u
    return base_radius * u, d, n, platform_radius * u


class Prs3Layout(_Model):
    """Generator of the symmetric tripod (:func:`tripod_layout`)."""

    base_radius: PositiveLength = Field(description="rail foot circle radius (mm)")
    platform_radius: PositiveLength = Field(description="platform joint circle radius (mm)")
    rail_inclination: Angle = Field(0.0, description="rails inclined towards the centre (deg)")


class Prs3Spec(FamilySpec):
    """YAML model of ``prs3``: a ``generator`` (:class:`Prs3Layout`), the link length(s),
    the slider window ``stroke`` (mm along the rail) and the slider branches."""

    family: Literal["prs3"]
    generator: Prs3Layout
    link_length: LinkLengths
    branch: list[Literal[-1, 1]] = Field(default_factory=lambda: [1, 1, 1])

    def build(self):
        if self.base_points is not None or self.platform_points is not None:
            raise ParameterError("base_points", "absent (the generator sets the joints)",
                                 "given")
        g = self.generator
        a, d, n, b = tripod_layout(g.base_radius, g.platform_radius, g.rail_inclination)
        return Prs3(a, b, d, n, np.broadcast_to(self.link_length, 3), tuple(self.stroke),
                    tuple(float(s) for s in self.branch), self.tool_offset,
                    **self.explicit_kw())


@dataclass(frozen=True, eq=False)
class Prs3(Mechanism):
    """The 3-PRS tripod (module docstring)."""

    family = "prs3"
    spec_model = Prs3Spec
    mobility = TRIPOD
    actuator_names = ("q1", "q2", "q3")
    design_aliases = {
        "base_radius": ("generator.base_radius", "length"),
        "platform_radius": ("generator.platform_radius", "length"),
        "rail_inclination": ("generator.rail_inclination", "angle"),
        "link_length": ("link_length", "length"),
        "stroke_min": ("stroke[0]", "length"),
        "stroke_max": ("stroke[1]", "length"),
    }
    parameter_fields = (
        ParamField("base_points", "base", "mm", "rail {i}'s foot (slider zero, base frame)"),
        ParamField("platform_points", "platform", "mm", "platform joint {i} (platform frame)"),
        ParamField("rail_axes", "rail", "1", "rail {i}'s direction"),
        ParamField("hinge_axes", "hinge", "1", "slider {i}'s revolute axis (horizontal)"),
        ParamField("link_length", "link", "mm", "leg {i}'s link length"),
        ParamField("stroke_window", ("stroke_min", "stroke_max"), "actuator",
                   "slider window limit"),
        ParamField("tool_offset", "tool_offset", "mm", "tool-frame origin (platform frame)"),
    )

    base_points: np.ndarray
    platform_points: np.ndarray
    rail_axes: np.ndarray
    hinge_axes: np.ndarray
    link_length: np.ndarray
    stroke_window: tuple
    branch: tuple = (1.0, 1.0, 1.0)
    tool_offset: np.ndarray = (0.0, 0.0, 0.0)

    _ik_one = _prs3_one

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_points", as_points(self.base_points, "base_points", 3))
        set_(self, "platform_points", as_points(self.platform_points, "platform_points", 3))
        d = unit(np.asarray(self.rail_axes, dtype=float).reshape(3, 3))
        n = np.asarray(self.hinge_axes, dtype=float).reshape(3, 3)
        if np.any(np.abs(n[:, 2]) > 1e-12) or not np.all(np.isfinite(d)):
            raise ParameterError("hinge_axes", "horizontal revolute axes (rails in vertical "
                                 "planes)", n.tolist())
        n = unit(n)
        if np.any(np.abs(np.sum(n * d, axis=1)) > 1e-9):
            raise ParameterError("rail_axes", "rails perpendicular to their revolute axes",
                                 d.tolist())
        for name, v in (("rail_axes", d), ("hinge_axes", n)):
            v.setflags(write=False)
            set_(self, name, v)
        ll = np.array(np.broadcast_to(np.asarray(self.link_length, dtype=float), 3))
        if not np.all(np.isfinite(ll) & (ll > 0)):
            raise ParameterError("link_length", "three lengths > 0 mm", ll.tolist())
        ll.setflags(write=False)
        set_(self, "link_length", ll)
        set_(self, "stroke_window", as_stroke(self.stroke_window, "stroke"))
        br = tuple(float(s) for s in self.branch)
        if len(br) != 3 or any(s not in (-1.0, 1.0) for s in br):
            raise ParameterError("branch", "three slider branches, each -1 or 1", br)
        set_(self, "branch", br)
        set_(self, "tool_offset", np.asarray(self.tool_offset, dtype=float).reshape(3))
        N = self.hinge_axes[:, :2]
        if np.linalg.matrix_rank(N) < 2:
            raise ParameterError("hinge_axes", "revolute axes not all parallel (the platform "
                                 "would slide)", self.hinge_axes.tolist())

    @property
    def scale(self) -> float:
        return float(np.abs(self.base_points).max() + np.abs(self.platform_points).max()
                     + self.link_length.max() + np.abs(self.stroke).max())

    def _gparams(self):
        N = self.hinge_axes[:, :2]
        k = np.cross(N[:, 0], N[:, 1])                          # left null vector of N
        h = np.sum(self.hinge_axes * self.base_points, axis=1)
        P = np.linalg.pinv(N)                                   # (2, 3)
        return np.concatenate([self.base_points.ravel(), self.rail_axes.ravel(),
                               self.hinge_axes.ravel(), self.tool_points.ravel(),
                               self.link_length, self.branch, P.ravel(), k, h,
                               [float(k @ h)]])

    # ---- dependent coordinates ---------------------------------------------------------------
    def _tilt(self, R):
        """``M = Ry·Rx`` from row 3 of R (whatever θz)."""
        r20, r21, r22 = R[:, 2, 0], R[:, 2, 1], R[:, 2, 2]
        sb, cb = -r20, np.hypot(r21, r22)
        sa, ca = r21 / cb, r22 / cb
        z0 = np.zeros_like(sb)
        return np.stack([np.stack([cb, sb * sa, sb * ca], -1), np.stack([z0, ca, -sa], -1),
                         np.stack([-sb, cb * sa, cb * ca], -1)], axis=-2)

    def _dependent_frames(self, p, R):
        """``(p_full, R_full, x, y, θz)`` with the dependent coordinates of ``(z, row 3 of
        R)``, in NumPy (an implementation of its own of the kernel's closed form)."""
        M = self._tilt(R)
        w = np.einsum("nij,kj->nki", M, self.tool_points)               # (N, 3, 3)
        n = self.hinge_axes[:, :2]
        A = np.sum(n * w[..., :2], axis=-1)
        B = n[:, 1] * w[..., 0] - n[:, 0] * w[..., 1]
        k = np.cross(n[:, 0], n[:, 1])
        h = np.sum(self.hinge_axes * self.base_points, axis=1)
        a, b, e = A @ k, B @ k, k @ h
        with np.errstate(invalid="ignore", divide="ignore"):
            wdt = np.arccos(e / np.hypot(a, b))
        cands = np.angle(np.exp(1j * (np.arctan2(b, a)[:, None] + np.stack([wdt, -wdt], -1))))
        gam = np.take_along_axis(cands, np.argmin(np.abs(cands), axis=1)[:, None], 1)[:, 0]
        c, s = np.cos(gam), np.sin(gam)
        rhs = h - c[:, None] * A - s[:, None] * B
        xy = rhs @ np.linalg.pinv(n).T
        Rz = np.zeros((len(p), 3, 3))
        Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1], Rz[:, 2, 2] = c, -s, s, c, 1.0
        pf = np.stack([xy[:, 0], xy[:, 1], p[:, 2]], axis=1)
        return pf, Rz @ M, xy[:, 0], xy[:, 1], gam

    def parasitic(self, poses) -> np.ndarray:
        """The dependent coordinates ``(N, 3)``: ``x, y`` (mm) and ``θz`` (rad) of poses given by
        their free coordinates (``(N, 3)`` z, θx, θy) or in any form :meth:`inverse` takes;
        NaN where the constraint has no solution."""
        _, _, x, y, gam = self._dependent_frames(*self._frames(poses))
        return np.stack([x, y, gam], axis=1)

    def complete(self, poses) -> np.ndarray:
        """Six-coordinate poses with the dependent coordinates filled in (Euler poses keep
        their free coordinates bit for bit: the Z-Y-X angles θx, θy of ``Rz(θz)·Ry·Rx`` are
        those of ``Ry·Rx``)."""
        if not isinstance(poses, tuple):
            X = np.asarray(poses, dtype=float)
            if X.ndim in (1, 2) and X.shape[-1] == 6:
                out = X.reshape(-1, 6).copy()
                out[:, _DEP] = self.parasitic(out)
                return out
        pf, Rf, *_ = self._dependent_frames(*self._frames(poses))
        return frames_to_poses(pf, Rf)

    def _free_to_full(self, X: np.ndarray) -> np.ndarray:
        if X.ndim in (1, 2) and X.shape[-1] == 3:
            full = np.zeros((X.reshape(-1, 3).shape[0], 6))
            full[:, _FREE] = X.reshape(-1, 3)
            return self.complete(full)
        return X

    # ---- kinematics ---------------------------------------------------------------------------
    def _rows(self, p, R):
        """Full rows ``[L, r × L] / (L·d)`` and constraint rows ``[n, r × n]`` at the
        completed poses."""
        pf, Rf, *_ = self._dependent_frames(p, R)
        q = self.inverse((p, R), stroke=(-np.inf, np.inf)).q
        r = np.einsum("nij,kj->nki", Rf, self.tool_points)
        S = pf[:, None, :] + r
        L = S - self.base_points - q[..., None] * self.rail_axes
        with np.errstate(divide="ignore", invalid="ignore"):
            Jf = np.concatenate([L, np.cross(r, L)], -1) / np.sum(L * self.rail_axes, -1)[
                ..., None]
        n = np.broadcast_to(self.hinge_axes, r.shape)
        C = np.concatenate([n, np.cross(r, n)], -1)
        return Jf, C, L

    def _jacobian(self, p, R):
        Jf, C, _ = self._rows(p, R)
        out = np.zeros_like(Jf)
        with np.errstate(all="ignore"):
            T = -np.linalg.solve(C[:, :, _DEP], C[:, :, _FREE])           # (N, 3, 3)
            out[:, :, _FREE] = Jf[:, :, _FREE] + Jf[:, :, _DEP] @ T
        return out

    def _closure(self, p, R, q):
        qq = self.inverse((p, R), stroke=(-np.inf, np.inf)).q
        return qq - q, self._jacobian(p, R)

    def _mid_stroke_pose(self) -> np.ndarray:
        return self.complete(super()._mid_stroke_pose())[0]

    def forward(self, q, guess=None, **kw):
        """The protocol's Newton on the free coordinates, the poses completed."""
        res = super().forward(q, guess, **kw)
        ok = res.converged
        if ok.any():
            res.pose[ok] = self.complete(res.pose[ok])
        return res

    def assembly_modes(self, q, *, starts: int = 1500, seed: int = 0, tol: float = 1e-9
                       ) -> AssemblyModes:
        """Multi-start Newton (the protocol's) with the poses completed and de-duplicated on
        the free coordinates: a search, not known to be complete."""
        m = multistart_modes(self, q, starts=starts, seed=seed, tol=tol)
        if not len(m.pose):
            return m
        X = self.complete(m.pose)
        keep = []
        for i, x in enumerate(X):
            if all(np.abs(x[_FREE] - X[j][_FREE]).max() > 1e-6 for j in keep):
                keep.append(i)
        return AssemblyModes(pose=X[keep], residual=m.residual[keep],
                             working_mode=m.working_mode[keep], distance=m.distance[keep],
                             starts=m.starts)

    def singularity(self, poses, rtol: float = 1e-9) -> np.ndarray:
        """``(N,)`` bit flags (module docstring): 1 type I, 2 type II, 4 constraint."""
        p, R = self._frames(poses)
        Jf, C, L = self._rows(p, R)
        cosang = np.abs(np.sum(unit(L) * self.rail_axes, -1)).min(axis=1)
        s = self.scale
        Cd = C[:, :, _DEP] * np.array([1.0, 1.0, 1.0 / s])
        sc = np.linalg.svd(Cd, compute_uv=False)
        cons = sc[:, -1] < rtol * sc[:, 0]
        J = self._jacobian(p, R)[:, :, _FREE] * np.array([1.0, 1.0 / s, 1.0 / s])
        with np.errstate(invalid="ignore"):
            sj = np.linalg.svd(np.nan_to_num(J, nan=0.0, posinf=0.0), compute_uv=False)
        serial = cosang < rtol
        par = (sj[:, -1] < rtol * sj[:, 0]) & ~cons & ~serial
        return serial.astype(int) + 2 * par.astype(int) + 4 * cons.astype(int)

    # ---- joints ------------------------------------------------------------------------------
    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=(-np.inf, np.inf)).q
        W = platform_joints(self, p, R)
        slider = self.base_points + q[..., None] * self.rail_axes
        ax = None
        if axes:
            ax = np.full((len(p), 3, 3, 2, 3), np.nan)
            ax[:, :, 0, 0] = self.rail_axes
            ax[:, :, 1, 0] = self.hinge_axes
        return JointArrays((slider, slider, W), ax, q if axes else None)

    def _leg_templates(self):
        return tuple(LegTemplate(
            name, ("P", "R", "S"), (f"leg{i + 1}.P", f"leg{i + 1}.R", f"leg{i + 1}.S"),
            ("base", f"leg{i + 1}.slider", f"leg{i + 1}.link", "platform"),
            (0.0, float(self.link_length[i])), 0, (1, 2), self.base_points[i].copy(),
            self.platform_points[i].copy(), self.base_points[i].copy(), None)
            for i, name in enumerate(self.actuator_names))
