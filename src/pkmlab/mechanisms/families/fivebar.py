"""``fivebar``: the planar five-bar, a 2-DOF parallel SCARA (issue 24, item 4).

Two motors on the base at ``A_1, A_2`` (plane z = 0) turn proximal links of lengths ``l1_i``
to the elbows ``C_i = A_i + l1_i·(cos θ_i, sin θ_i)``; distal links of lengths ``l2_i`` join
the elbows to the end point ``P``, the tool. Every joint is a revolute with axis z; the
motor joints are actuated (``θ_i``, rad). Mobility: ``x, y`` (the end point; the other pose
coordinates stay 0), declared as ``Mobility("planar-point", ("x", "y"))``.

* **Inverse kinematics** (closed form): ``θ_i = atan2(P - A_i) + σ_i·acos((l1² + D² -
  l2²)/(2·l1·D))``, ``D = |P - A_i|``, wrapped to (-π, π]; ``σ_i = ±1`` is arm i's elbow
  branch (``branch``). Status per actuator: ``no real solution`` outside the annulus
  ``|l1 - l2| <= D <= l1 + l2``, else the motor window. The angle is given as its
  representative in ``(c - π, c + π]``, ``c`` the centre of the motor window (a window may
  cross ±180°, e.g. [-45°, 225°]).
* **Working modes**: the four branch pairs (``working_modes``, ``with_working_mode``).
* **Jacobian** ``(N, 2, 2)``: ``θ̇_i = (P - C_i)·v / (l1_i·(P - C_i)·e⊥_i)``, ``e⊥_i = (-sin θ_i,
  cos θ_i)``; in the form ``A·v = B·θ̇``: rows of ``A`` ``(P - C_i)ᵀ``, ``B = diag(l1_i·(P -
  C_i)·e⊥_i)``.
* **Singularities**: type I (serial) where ``B`` loses rank — proximal and distal link of an
  arm aligned, ``|P - A_i| = l1_i ± l2_i`` (circles); type II (parallel) where ``A`` does —
  the two distal links aligned.
* **Forward kinematics**: the end point is on the circles of radius ``l2_i`` about the
  elbows: zero, one or two points (:meth:`FiveBar.assembly_modes`); each is flagged in or out
  of the working mode (its inverse kinematics in this mechanism's branches reproduces θ).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numba.extending import register_jitable
from pydantic import Field

from ...errors import ParameterError
from ...quantities import AngleWindow, LinkLengths, PositiveLength
from ...specbase import FamilySpec
from ..base import AssemblyModes, Mechanism, as_stroke
from ..joints import JointArrays, LegTemplate, ParamField
from ..kernels import ik as _kernels
from ..mobility import Mobility
from . import _fastmath, planar_fk

__all__ = ["FiveBar", "FiveBarSpec", "POINT"]

#: the end point moves in its plane; no orientation is free
POINT = Mobility("planar-point", ("x", "y"))
_MODES = {(1.0, 1.0): "++", (1.0, -1.0): "+-", (-1.0, 1.0): "-+", (-1.0, -1.0): "--"}


@register_jitable(inline="always")
def _fivebar_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q,
                 st, j):
    for i in range(2):
        dx, dy = px - g[2 * i], py - g[2 * i + 1]
        l1, l2, b = g[4 + i], g[6 + i], g[8 + i]
        d2 = dx * dx + dy * dy
        # the elbow angle's cosine and sine times 2·l1·|AP| (atan2 below needs no scale): no
        # division, one square root; real where |cos| <= 1, i.e. c² <= (2·l1·|AP|)²
        c = l1 * l1 + d2 - l2 * l2
        r2 = 4.0 * l1 * l1 * d2
        ok = c * c <= r2
        s = b * math.sqrt(max(r2 - c * c, 0.0))
        # the elbow's direction: A→P turned by the elbow angle (cos c, sin s), then measured
        # from the motor window's centre g[10] (cos g[11], sin g[12]): one atan2, no wrap
        vx, vy = dx * c - dy * s, dx * s + dy * c
        t = g[10] + _fastmath.atan2(vy * g[11] - vx * g[12], vx * g[11] + vy * g[12])
        q[i * _kernels.ROW + j] = t if ok else math.nan
        st[i * _kernels.ROW + j] = (_kernels.stroke_status(t, qmin, qmax) if ok
                                    else _kernels.NO_SOLUTION)


class FiveBarSpec(FamilySpec):
    """YAML model of ``fivebar``: the motor pivots (``base_points``, two, z = 0, or
    ``base_separation`` for two pivots on the x axis symmetric about the origin), link
    lengths, the motor window (``stroke``, deg) and the working mode (elbow branches)."""

    family: Literal["fivebar"]
    base_separation: PositiveLength | None = Field(None, description="|A1A2| (mm)")
    proximal: LinkLengths = Field(description="proximal (motor) link length(s) (mm)")
    distal: LinkLengths = Field(description="distal link length(s) (mm)")
    stroke: AngleWindow = Field(default_factory=lambda: [-math.pi, math.pi],
                                description="motor angle window [min, max] (deg)")
    working_mode: list[Literal[-1, 1]] = Field(default_factory=lambda: [1, -1],
                                               description="elbow branch of arm 1 and 2")

    def build(self):
        if self.platform_points is not None:
            raise ParameterError("platform_points", "absent (the tool is the end point)",
                                 "given")
        if (self.base_points is None) == (self.base_separation is None):
            raise ParameterError("base_points", "given alone: base_points or base_separation",
                                 "both" if self.base_points is not None else "neither")
        base = self.base_points
        if base is None:
            s = 0.5 * self.base_separation
            base = [[-s, 0.0, 0.0], [s, 0.0, 0.0]]
        if len(self.working_mode) != 2:
            raise ParameterError("working_mode", "two branches (±1)", self.working_mode)
        return FiveBar(base, np.broadcast_to(self.proximal, 2), np.broadcast_to(self.distal, 2),
                       tuple(self.stroke), tuple(float(b) for b in self.working_mode),
                       **self.explicit_kw())


@dataclass(frozen=True, eq=False)
class FiveBar(Mechanism):
    """The planar five-bar (module docstring)."""

    family = "fivebar"
    spec_model = FiveBarSpec
    mobility = POINT
    actuator_names = ("theta1", "theta2")
    actuator_unit = "rad"
    #: forward kinematics and assembly modes are complete (closed form), not a search
    closed_form_modes = True
    design_aliases = {
        "base_separation": ("base_separation", "length"),
        "proximal": ("proximal", "length"),
        "distal": ("distal", "length"),
        "motor_min": ("stroke[0]", "angle"),
        "motor_max": ("stroke[1]", "angle"),
    }
    parameter_fields = (
        ParamField("base_points", "base", "mm", "motor {i}'s pivot (base frame)"),
        ParamField("proximal", "proximal", "mm", "arm {i}'s proximal link length"),
        ParamField("distal", "distal", "mm", "arm {i}'s distal link length"),
        ParamField("stroke_window", ("stroke_min", "stroke_max"), "actuator",
                   "motor angle window limit"),
    )

    base_points: np.ndarray
    proximal: np.ndarray
    distal: np.ndarray
    stroke_window: tuple = (-math.pi, math.pi)
    branch: tuple = (1.0, -1.0)
    platform_points: np.ndarray = dataclasses.field(default=None, repr=False)
    tool_offset: np.ndarray = dataclasses.field(default=None, repr=False)

    _ik_one = _fivebar_one

    def __post_init__(self):
        set_ = object.__setattr__
        A = np.array(self.base_points, dtype=float)
        if A.shape != (2, 3) or not np.all(np.isfinite(A)) or np.any(A[:, 2] != 0):
            raise ParameterError("base_points", "two pivots [x, y, 0] (mm)", A.tolist())
        if np.hypot(*(A[1, :2] - A[0, :2])) == 0.0:
            raise ParameterError("base_points", "two distinct motor pivots", A.tolist())
        A.setflags(write=False)
        set_(self, "base_points", A)
        for name in ("proximal", "distal"):
            v = np.array(np.broadcast_to(np.asarray(getattr(self, name), dtype=float), 2))
            if not np.all(np.isfinite(v) & (v > 0)):
                raise ParameterError(name, "two link lengths > 0 mm", v.tolist())
            v.setflags(write=False)
            set_(self, name, v)
        w = as_stroke(self.stroke_window, "stroke")
        if w[1] - w[0] > 2 * math.pi + 1e-12:
            raise ParameterError("stroke", "a motor window of at most 360 deg",
                                 np.degrees(w).tolist())
        set_(self, "stroke_window", w)
        b = tuple(float(x) for x in self.branch)
        if len(b) != 2 or any(x not in (-1.0, 1.0) for x in b):
            raise ParameterError("working_mode", "two elbow branches, each -1 or 1", b)
        set_(self, "branch", b)
        set_(self, "platform_points", np.zeros((2, 3)))
        set_(self, "tool_offset", np.zeros(3))

    @property
    def scale(self) -> float:
        return float(np.abs(self.base_points).max() + np.max(self.proximal + self.distal))

    def _gparams(self):
        c0 = 0.5 * (self.stroke[0] + self.stroke[1])
        return np.concatenate([self.base_points[:, :2].ravel(), self.proximal, self.distal,
                               self.branch, [c0, math.cos(c0), math.sin(c0)]])

    # ---- kinematics ---------------------------------------------------------------------------
    def _elbows(self, p, q):
        """``(N, 2, 2)`` elbow positions for motor angles ``q (N, 2)``."""
        return self.base_points[:, :2] + self.proximal[:, None] * np.stack(
            [np.cos(q), np.sin(q)], axis=-1)

    def _jacobian(self, p, R):
        q = self.inverse((p, R), stroke=(-np.inf, np.inf)).q
        C = self._elbows(p, q)
        d = p[:, None, :2] - C                                   # P - C_i
        eperp = np.stack([-np.sin(q), np.cos(q)], axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            rows = d / (self.proximal * np.sum(d * eperp, axis=-1))[..., None]
        J = np.zeros((len(p), 2, 6))
        J[:, :, :2] = rows
        return J

    def _closure(self, p, R, q):
        d = p[:, None, :2] - self._elbows(p, q)
        n = np.linalg.norm(d, axis=-1)
        G = np.zeros((len(p), 2, 6))
        with np.errstate(divide="ignore", invalid="ignore"):
            G[:, :, :2] = d / n[..., None]
        return n - self.distal, G

    def _mid_stroke_pose(self) -> np.ndarray:
        """On the perpendicular bisector of A1A2 (the +y side of it), the middle of the
        stretch where both motors are inside their window (give ``nominal`` otherwise)."""
        A = self.base_points[:, :2]
        mid, d = A.mean(axis=0), A[1] - A[0]
        nrm = np.array([-d[1], d[0]]) / max(np.hypot(*d), 1e-300)
        t = np.linspace(0.0, float(np.max(self.proximal + self.distal)), 2001)
        X = np.zeros((len(t), 6))
        X[:, :2] = mid + t[:, None] * nrm
        ok = self._run_ik(X, None, *self.stroke).valid
        if not ok.any():
            raise ParameterError("stroke", "a motor window reaching a point of the base's "
                                 "bisector (the nominal pose: give 'nominal_pose')",
                                 np.degrees(self.stroke).tolist())
        k = np.flatnonzero(ok)
        run = np.split(k, np.flatnonzero(np.diff(k) > 1) + 1)[0]
        return X[run[len(run) // 2]]

    def working_modes(self) -> tuple[str, ...]:
        """The four working modes: elbow branch signs of arm 1 and arm 2."""
        return tuple(_MODES.values())

    @property
    def working_mode(self) -> str:
        return _MODES[self.branch]

    def with_working_mode(self, mode: str) -> FiveBar:
        """The same geometry in another working mode (``"++"``, ``"+-"``, ``"-+"``, ``"--"``);
        its nominal pose is searched again unless given."""
        inv = {v: k for k, v in _MODES.items()}
        if mode not in inv:
            raise ParameterError("working_mode", f"one of {list(inv)}", mode)
        return dataclasses.replace(self, branch=inv[mode])

    def forward_all(self, q) -> tuple[np.ndarray, np.ndarray]:
        """Both assembly modes of each motor vector: ``(poses (N, 2, 6), in_mode (N, 2))``,
        NaN where the distal circles do not meet; ``in_mode`` where the pose's inverse
        kinematics in this working mode reproduces ``q`` (to 1e-9 rad)."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        if q.shape[1:] != (2,):
            raise ParameterError("q", "an array of shape (2,) or (N, 2) in rad", q.shape)
        C = self._elbows(None, q)
        P = planar_fk.circle_intersections(C[:, 0], C[:, 1], self.distal[0], self.distal[1])
        out = np.zeros((len(q), 2, 6))
        out[..., :2] = P
        out[np.isnan(P).any(axis=-1)] = np.nan
        ik = self.inverse(np.nan_to_num(out.reshape(-1, 6)), stroke=(-np.inf, np.inf)).q
        err = np.abs(np.angle(np.exp(1j * (ik - np.repeat(q, 2, axis=0))))).max(axis=1)
        in_mode = (err < 1e-9).reshape(-1, 2) & np.isfinite(P).all(axis=-1)
        return out, in_mode

    def assembly_modes(self, q, *, starts: int = 0, seed: int = 0, tol: float = 1e-9
                       ) -> AssemblyModes:
        """Both assembly modes (circle intersection; exact, no start search: ``starts`` and
        ``seed`` are ignored), nearest the nominal pose first."""
        q = np.asarray(q, dtype=float).reshape(2)
        X, in_mode = self.forward_all(q)
        X, in_mode = X[0], in_mode[0]
        keep = np.isfinite(X).all(axis=1)
        X, in_mode = X[keep], in_mode[keep]
        if len(X) == 2 and np.abs(X[0] - X[1]).max() < 1e-9 * self.scale:
            X, in_mode = X[:1], in_mode[:1] | in_mode[1:]          # tangent circles
        res = np.abs(self._closure(*self._frames(X), np.repeat(q[None], len(X), 0))[0]).max(
            axis=1) if len(X) else np.zeros(0)
        dist = np.hypot(*(X[:, :2] - self.nominal_pose[:2]).T) if len(X) else np.zeros(0)
        o = np.argsort(dist, kind="stable")
        return AssemblyModes(pose=X[o], residual=res[o], working_mode=in_mode[o],
                             distance=dist[o], starts=0)

    def singularity(self, poses, rtol: float = 1e-9) -> np.ndarray:
        """``(N,)`` codes of :data:`.rpr3.SINGULARITY` in this working mode: type I where an
        arm's links are aligned (``|sin|`` of the elbow angle below ``rtol``), type II where
        the distal links are (``|sin|`` of their angle below ``rtol``); NaN poses (outside
        the reach) give -1."""
        p, R = self._frames(poses)
        q = self.inverse((p, R), stroke=(-np.inf, np.inf)).q
        C = self._elbows(p, q)
        u = (p[:, None, :2] - C) / self.distal[:, None]
        e = np.stack([-np.sin(q), np.cos(q)], axis=-1)
        s1 = np.abs(np.sum(u * e, axis=-1)).min(axis=1)
        s2 = np.abs(u[:, 0, 0] * u[:, 1, 1] - u[:, 0, 1] * u[:, 1, 0])
        code = (s1 < rtol).astype(int) + 2 * ((s2 < rtol) & ~(s1 < rtol)).astype(int)
        return np.where(np.isfinite(q).all(axis=1), code, -1)

    # ---- planar workspace hooks (:mod:`pkmlab.workspaces.planar`) ----------------------------
    def position_box(self, phi_lo: float = 0.0, phi_hi: float = 0.0):
        r = self.proximal + self.distal
        a = self.base_points[:, :2]
        return (float(np.max(a[:, 0] - r)), float(np.min(a[:, 0] + r)),
                float(np.max(a[:, 1] - r)), float(np.min(a[:, 1] + r)))

    @property
    def _limited(self) -> bool:
        lo, hi = self.stroke
        return hi - lo < 2 * math.pi - 1e-12

    def annuli(self, phi: float = 0.0):
        """Without a motor window, the reachable set is the intersection of the arms'
        annuli ``|l1 - l2| <= |P - A_i| <= l1 + l2`` (any working mode); ``None`` otherwise."""
        if self._limited:
            return None
        return (self.base_points[:, :2], np.abs(self.proximal - self.distal),
                self.proximal + self.distal)

    def planar_cell_margins(self, xy, phi, delta, alpha):
        """Margins of each arm's reach (``min(D - |l1 - l2|, l1 + l2 - D)``, 1-Lipschitz) and,
        with a motor window, of its motor angle (half-width minus the circular distance to the
        window's centre), bounded over the cell by ``delta·max |∇θ_i|``, ``|∇θ_i| = 1/(l1·sin
        γ)`` with γ the elbow angle, smallest at an end of the cell's range of D (γ is
        monotone in D, sin concave on [0, π]); infinite where that range leaves the
        annulus."""
        xy = np.asarray(xy, dtype=float)
        delta = np.asarray(delta, dtype=float)
        D = np.hypot(*(xy[:, None, :] - self.base_points[:, :2]).transpose(2, 0, 1))
        lo_r, hi_r = np.abs(self.proximal - self.distal), self.proximal + self.distal
        m = [np.minimum(D - lo_r, hi_r - D)]
        eps = [np.repeat(delta[:, None], 2, axis=1)]
        if self._limited:
            X = np.zeros((len(xy), 6))
            X[:, :2] = xy
            q = self.inverse(X, stroke=(-np.inf, np.inf)).q
            lo, hi = self.stroke
            c, w = 0.5 * (lo + hi), 0.5 * (hi - lo)
            m.append(w - np.abs(np.angle(np.exp(1j * (q - c)))))
            l1, l2 = self.proximal, self.distal
            sins = []
            for Dk in (D - delta[:, None], D + delta[:, None]):
                cg = (l1 * l1 + l2 * l2 - Dk * Dk) / (2 * l1 * l2)
                sins.append(np.sqrt(np.clip(1 - cg * cg, 0, 1)))
            inside = (D - delta[:, None] > lo_r) & (D + delta[:, None] < hi_r)
            smin = np.minimum(*sins)
            with np.errstate(divide="ignore"):
                e = np.where(inside & (smin > 0), delta[:, None] / (l1 * smin), np.inf)
            m.append(np.nan_to_num(m.pop(), nan=-np.inf))
            eps.append(e)
        return np.concatenate(m, axis=1), np.concatenate(eps, axis=1)

    def singular_fields(self, poses) -> dict:
        """Zero levels of the singularity loci in this working mode, for drawing: type I,
        each arm's ``|P - A_i| - (l1 ± l2)``; type II, ``sin`` of the distal links' angle."""
        p, R = self._frames(poses)
        D = np.hypot(*(p[:, None, :2] - self.base_points[:, :2]).transpose(2, 0, 1))
        lo, hi = np.abs(self.proximal - self.distal), self.proximal + self.distal
        q = self.inverse((p, R), stroke=(-np.inf, np.inf)).q
        u = (p[:, None, :2] - self._elbows(p, q)) / self.distal[:, None]
        out = {"type I (serial), outer": np.min(hi - D, axis=1)}
        if np.any(lo > 0):
            out["type I (serial), inner"] = np.min(np.where(lo > 0, D - lo, np.inf), axis=1)
        out["type II (parallel)"] = u[:, 0, 0] * u[:, 1, 1] - u[:, 0, 1] * u[:, 1, 0]
        return out

    # ---- joints ------------------------------------------------------------------------------
    def _joint_arrays(self, p, R, axes=True):
        q = self.inverse((p, R), stroke=(-np.inf, np.inf)).q
        n = len(p)
        C = np.zeros((n, 2, 3))
        C[..., :2] = self._elbows(p, q)
        P = np.repeat(p[:, None, :], 2, axis=1)
        A = np.broadcast_to(self.base_points, (n, 2, 3))
        ax = None
        if axes:
            ax = np.full((n, 2, 3, 2, 3), np.nan)
            ax[:, :, :, 0] = (0.0, 0.0, 1.0)
        return JointArrays((A, C, P), ax, q if axes else None)

    def _leg_templates(self):
        out = []
        for i, name in enumerate(self.actuator_names):
            arm = f"arm{i + 1}"
            out.append(LegTemplate(
                name, ("R", "R", "R"), (f"{arm}.motor_R", f"{arm}.elbow_R", f"{arm}.tool_R"),
                ("base", f"{arm}.proximal", f"{arm}.distal", "platform"),
                (float(self.proximal[i]), float(self.distal[i])), 0, (1, 2),
                self.base_points[i].copy(), np.zeros(3), None, np.array([1.0, 0.0, 0.0])))
        return tuple(out)

    def describe(self) -> dict:
        return {**super().describe(), "proximal_mm": self.proximal.tolist(),
                "distal_mm": self.distal.tolist(), "working_mode": self.working_mode,
                "motor_window_deg": np.degrees(self.stroke).tolist()}
