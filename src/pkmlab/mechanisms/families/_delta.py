"""What the two delta families (:mod:`.delta3`, rotary; :mod:`.ldelta3`, linear) share.

Both are three legs ending in a parallelogram of two rods with ball joints at both ends
(modelled as one S–S rod of the same length: the parallelogram keeps the platform's
orientation, so the platform only translates, :data:`~pkmlab.mechanisms.TRANSLATIONAL`). Leg i
drives a point ``C_i`` (the elbow of a rotary arm, the carriage of a linear tower); the rod of
length ``l_i`` joins it to the platform joint ``P_i = p + R·t_i`` (``t_i`` the platform point
about the tool, ``R`` the nominal orientation).

**Forward kinematics** (closed form, every assembly mode). With the actuators given, every
``C_i`` is known and ``p`` lies on the three spheres ``|p - (C_i - R·t_i)| = l_i``: the
intersection of three spheres (trilateration), two points mirrored in the plane of the
centres, one double point on it (the parallel singularity) or none. :func:`trilaterate`
returns both; the working mode is the one whose inverse kinematics gives the actuator values
back (the other is the mirror through the centres' plane: the platform above the carriages,
or the forearms folded through the elbows' plane).

**Singularities** (:meth:`DeltaFamily.singularities`). Differentiating ``|P_i - C_i|² = l_i²``
gives ``A·v = B·q̇`` with ``A`` the ``3 × 3`` matrix of rod vectors ``d_i = P_i - C_i`` (rows)
and ``B = diag(d_i·∂C_i/∂q_i)``. ``J = B⁻¹A`` is the inverse Jacobian. A *serial* (inverse,
type I) singularity is a zero ``B_ii``: the rod is perpendicular to the velocity of the point
it is driven by (a linear tower's rod perpendicular to the rail; a rotary arm and its forearm
aligned); the platform loses a direction of motion there. A *parallel* (direct, type II)
singularity is ``det A = 0``: the three rods parallel to one plane; the platform gains an
uncontrolled motion there, and the two assembly modes merge.

**Exact columns**. Each leg's feasible z set on a vertical column is closed form (the family
modules). For the one orientation a translational mechanism has (the engine's constant
workspace, mode ``"all"``), the legs' sets are intersected column by column by the shared
set-leg kernel (:mod:`..kernels.set_columns`, sized from the leg count), or by
:func:`make_columns` when every leg's set is one interval (the towers).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import NamedTuple

import numpy as np
from numba import prange
from numba import types as nt

from ...errors import ParameterError
from ...poses import as_frames, frames_to_poses
from ...runtime.jit import cached_kernel
from ...tolerances import TOL
from ..base import NO_STROKE, Mechanism
from ..kernels import ik as _kernels
from ..kernels.columns import inlined
from ..kernels.set_columns import make_set_column_kernel
from ..legs.crank import PIECES
from ..mobility import POSE, TRANSLATIONAL
from ..results import AssemblyModes, FKResult

__all__ = ["trilaterate", "DeltaFamily", "Singularities", "make_columns"]

#: relative |det A| (unit rod rows) and |cos| (rod against the driven point's velocity) below
#: which :meth:`DeltaFamily.singularities` calls a pose singular (algorithm constants)
PARALLEL_TOL = 1e-6
SERIAL_TOL = 1e-6
#: interval slots of a column in the first pass of :meth:`DeltaFamily.column_intervals`
#: (a rotary delta's columns hold one or two pieces; more is rare and triggers a second pass)
COLUMN_SLOTS = 2


def trilaterate(c: np.ndarray, r: np.ndarray):
    """The intersection of three spheres, centres ``c (N, 3, 3)`` (mm) and radii ``r (N, 3)``.

    Returns ``(x (N, 2, 3), h2 (N,))``: the two points ``c_0 + a·e_x + b·e_y ± h·e_z`` in the
    frame of the centres (``e_z = e_x × e_y`` the normal of their plane, the ``+`` point first)
    and ``h² `` (negative: no intersection, the points are NaN; zero: one double point). The
    centres must not be collinear (NaN otherwise)."""
    c = np.asarray(c, dtype=float)
    r = np.asarray(r, dtype=float)
    d1, d2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        D = np.linalg.norm(d1, axis=1)
        ex = d1 / D[:, None]
        i = np.sum(ex * d2, axis=1)
        ey = d2 - i[:, None] * ex
        J = np.linalg.norm(ey, axis=1)
        ey = ey / J[:, None]
        ez = np.cross(ex, ey)
        a = (r[:, 0] ** 2 - r[:, 1] ** 2 + D ** 2) / (2 * D)
        b = (r[:, 0] ** 2 - r[:, 2] ** 2 + i ** 2 + J ** 2) / (2 * J) - i * a / J
        h2 = r[:, 0] ** 2 - a ** 2 - b ** 2
        # a double point rounded a hair below zero (algorithm constant, relative to r²)
        h2 = np.where((h2 < 0) & (h2 >= -1e-12 * r[:, 0] ** 2), 0.0, h2)
        h = np.sqrt(np.where(h2 >= 0, h2, np.nan))
    base = c[:, 0] + a[:, None] * ex + b[:, None] * ey
    x = np.stack([base + h[:, None] * ez, base - h[:, None] * ez], axis=1)
    return x, h2


class Singularities(NamedTuple):
    """Singularity measures of N poses (:meth:`DeltaFamily.singularities`).

    Attributes:
        serial: ``(N, L)`` ``|cos|`` of the angle between each rod and the velocity of the
            point that drives it (0: serial / inverse singularity of that leg).
        parallel: ``(N,)`` ``|det|`` of the unit rod directions (0: parallel / direct
            singularity; 1: mutually orthogonal rods).
        kind: ``(N,)`` ``"regular"``, ``"serial"``, ``"parallel"``, ``"both"`` or ``"no
            solution"`` (some rod cannot close).
    """

    serial: np.ndarray
    parallel: np.ndarray
    kind: np.ndarray


@dataclass(frozen=True, eq=False)
class DeltaFamily(Mechanism):
    """Base of the delta families: a translating platform on three rod legs (module notes)."""

    mobility = TRANSLATIONAL
    #: forward kinematics and assembly modes are complete (closed form), not a search
    closed_form_modes = True

    # ---- what a delta family provides --------------------------------------------------------
    def driven_points(self, q: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        """``(N, 3, 3)`` the points C_i (elbows or carriages) for actuator values ``(N, 3)``."""
        raise NotImplementedError

    def driven_velocity(self, q: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        """``(N, 3, 3)`` ``∂C_i/∂q_i`` (mm per actuator unit)."""
        raise NotImplementedError

    def _q_domain(self, q: np.ndarray) -> np.ndarray:
        """``(N,)`` True where ``q`` can be actuator values at all (finite; rotary: in
        (-π, π])."""
        return np.all(np.isfinite(q), axis=1)

    # ---- velocity and loop closure (the protocol's generic Newton uses _closure) -------------
    def _rods(self, p, R, q):
        r = np.einsum("nij,kj->nki", R, self.tool_points)
        return r, p[:, None, :] + r - self.driven_points(q)

    def _jacobian(self, p, R):
        q = self.inverse((p, R), stroke=NO_STROKE).q
        r, d = self._rods(p, R, q)
        den = np.sum(d * self.driven_velocity(q), axis=-1)[..., None]
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.concatenate([d, np.cross(r, d)], axis=-1) / den

    def _closure(self, p, R, q):
        r, d = self._rods(p, R, np.broadcast_to(q, (len(p), 3)))
        norm = np.linalg.norm(d, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            n = d / norm[..., None]
        return norm - self.rod_length, np.concatenate([n, np.cross(r, n)], axis=-1)

    # ---- forward kinematics: three spheres ---------------------------------------------------
    @property
    def _rotation(self) -> np.ndarray:
        """The platform's one orientation ``(3, 3)``: the given nominal pose's, else level."""
        if self.nominal is None:
            return np.eye(3)
        return as_frames(np.asarray(self.nominal, dtype=float))[1][0]

    def _fk_candidates(self, q):
        """Both trilateration points ``(N, 2, 3)`` (tool positions), ``h² (N,)`` and the
        platform's rotation."""
        Rn = self._rotation
        c = self.driven_points(q) - self.tool_points @ Rn.T
        x, h2 = trilaterate(c, np.broadcast_to(self.rod_length, q.shape))
        return x, h2, Rn

    def _mid_stroke_pose(self) -> np.ndarray:
        """The working-mode pose with every actuator at mid-window (closed form), level."""
        mid = 0.5 * (self.stroke[0] + self.stroke[1])
        fk = self.forward(np.full(3, mid))
        if not fk.converged[0]:
            raise ParameterError("stroke", "a window whose mid-point every leg reaches in the "
                                 "working mode (the nominal pose: give 'nominal' or change "
                                 "the window or the links)", list(self.stroke))
        pose = fk.pose[0]
        pose[np.abs(pose) < 1e-12 * self.scale] = 0.0          # rounding of a centred pose
        return pose

    def _working(self, x, R, q, tol):
        """``(N,)`` True where the IK at positions ``x (N, 3)`` reproduces ``q`` in the working
        mode (no leg outside it)."""
        n = len(x)
        ik = self.inverse((x, np.broadcast_to(R, (n, 3, 3))), stroke=NO_STROKE)
        with np.errstate(invalid="ignore"):
            err = np.max(np.abs(ik.q - q), axis=1)
        other = np.any(ik.leg_status == _kernels.OTHER_MODE, axis=1)
        return np.isfinite(err) & (err <= tol) & ~other

    def forward(self, q, guess=None, *, tol: float = TOL.fk_residual_mm, max_iter: int = 50,
                modes: bool = False) -> FKResult:
        """Forward kinematics in closed form: the three-sphere intersection (module notes),
        the working-mode point (``guess`` and ``max_iter`` are not used: nothing iterates).
        With ``modes``, the other point is reported as ``next_mode`` when it, too, is in the
        working mode (``ambiguous``); it never is for a delta whose working mode is fixed by
        the legs' branches, so ``status`` stays ``"ok"``."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        if q.ndim != 2 or q.shape[1:] != (3,):
            raise ParameterError("q", f"an array of shape (3,) or (N, 3) in {self.actuator_unit}",
                                 q.shape)
        n = len(q)
        x, h2, Rn = self._fk_candidates(q)
        tol_mode = max(1e3 * tol, TOL.working_mode_mm)
        good = self._q_domain(q) & (h2 >= 0)
        work = np.zeros((n, 2), dtype=bool)
        for k in (0, 1):
            idx = np.flatnonzero(good)
            work[idx, k] = self._working(x[idx, k], Rn, q[idx], tol_mode)
        k = np.where(work[:, 0], 0, 1)
        ok = work[np.arange(n), k]
        p = x[np.arange(n), k]
        R = np.broadcast_to(Rn, (n, 3, 3))
        res = np.full(n, np.inf)
        if ok.any():
            f, _ = self._closure(p[ok], np.ascontiguousarray(R[ok]), q[ok])
            res[ok] = np.max(np.abs(f), axis=1)
        ok &= res < max(tol, 1e-9 * self.scale)
        pose = frames_to_poses(p, np.ascontiguousarray(R))
        pose[~ok] = np.nan
        singular = good & (h2 <= (1e-12 * self.scale) ** 2)
        status = np.where(ok, "ok", np.where(singular, "singular", "not converged"))
        it = np.zeros(n, dtype=int)
        if not modes:
            return FKResult(pose=pose, converged=ok, residual=res, iterations=it,
                            status=status.astype(object))
        other = ok & work[np.arange(n), 1 - k]
        nxt = np.full((n, len(POSE)), np.nan)
        nxt[other] = frames_to_poses(x[other, 1 - k[other]],
                                     np.ascontiguousarray(R[other]))
        dmm = np.where(other, np.linalg.norm(x[:, 0] - x[:, 1], axis=1), np.inf)
        ddeg = np.where(other, 0.0, np.inf)
        status = np.where(other, "ambiguous", status)
        return FKResult(pose=pose, converged=ok, residual=res, iterations=it,
                        status=status.astype(object), ambiguous=other, next_mode=nxt,
                        next_mode_mm=dmm, next_mode_deg=ddeg, mode_starts=0)

    def assembly_modes(self, q, *, starts: int = 0, seed: int = 0,
                       tol: float = TOL.fk_residual_mm) -> AssemblyModes:
        """Every real assembly mode of one actuator vector, in closed form (two points, one
        on a parallel singularity, or none), nearest the nominal pose first; ``starts`` and
        ``seed`` are not used (``starts`` reports 0: nothing was searched)."""
        q = np.asarray(q, dtype=float).reshape(1, 3)
        x, h2, Rn = self._fk_candidates(q)
        if not (self._q_domain(q)[0] and h2[0] >= 0):
            return AssemblyModes(np.zeros((0, len(POSE))), np.zeros(0), np.zeros(0, bool),
                                 np.zeros(0), 0)
        p = x[0] if h2[0] > 0 else x[0, :1]
        R = np.ascontiguousarray(np.broadcast_to(Rn, (len(p), 3, 3)))
        f, _ = self._closure(p, R, np.repeat(q, len(p), axis=0))
        res = np.max(np.abs(f), axis=1)
        work = self._working(p, Rn, np.repeat(q, len(p), axis=0),
                             max(1e3 * tol, TOL.working_mode_mm))
        dist = self._pose_distance(p, R)
        o = np.argsort(dist, kind="stable")
        return AssemblyModes(frames_to_poses(p[o], R[o]), res[o], work[o], dist[o], 0)

    # ---- singularities ---------------------------------------------------------------------
    def singularities(self, poses, *, serial_tol: float = SERIAL_TOL,
                      parallel_tol: float = PARALLEL_TOL) -> Singularities:
        """Serial and parallel singularity measures of poses (module notes): per leg ``|cos|``
        of the rod against its driven point's velocity, and ``|det|`` of the unit rods;
        a pose is called singular of a kind where its measure is below the tolerance."""
        p, R = self._frames(poses)
        q = self.inverse((p, R), stroke=NO_STROKE).q
        _, d = self._rods(p, R, q)
        v = self.driven_velocity(q)
        with np.errstate(invalid="ignore", divide="ignore"):
            du = d / np.linalg.norm(d, axis=-1, keepdims=True)
            vu = v / np.linalg.norm(v, axis=-1, keepdims=True)
            serial = np.abs(np.sum(du * vu, axis=-1))
            parallel = np.abs(np.linalg.det(du))
        ser = np.any(serial <= serial_tol, axis=1)
        par = parallel <= parallel_tol
        kind = np.where(ser & par, "both", np.where(ser, "serial", np.where(par, "parallel",
                                                                              "regular")))
        kind = np.where(np.all(np.isfinite(q), axis=1), kind, "no solution")
        return Singularities(serial, parallel, kind.astype(object))

    # ---- guaranteed volume bracket (:mod:`pkmlab.workspaces.bracket_octree`) -------------
    def leg_margins(self, p: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        """``(N, 3)`` signed margins of the legs at positions ``p (N, 3)`` (the platform's
        orientation): see :mod:`pkmlab.workspaces.bracket_octree`."""
        raise NotImplementedError

    def check_bracket(self) -> None:
        """Refuse, naming the field, a geometry the bracket's margins do not cover."""

    # ---- exact columns -------------------------------------------------------------------
    column_method = "delta"
    #: the family's set leg ``leg(x, y, wx, wy, wz, p, zlo, zhi, out_lo, out_hi) -> n``
    column_set_leg = None
    #: most pieces a column's set can have (``ldelta3``: 1, every leg's set is one interval),
    #: so that the engine's arrays hold no empty slots
    column_pieces = 8

    def column_params(self) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def column_intervals(self, xs, ys, R, mode, allowed=None, K=8):
        """Exact feasible z sets of the columns ``xs × ys`` at the one orientation ``R (1, 3,
        3)`` (same contract as :meth:`.base.Mechanism.column_intervals`; ``mode`` "all" or
        "any" agree for one orientation, ``allowed`` masks columns)."""
        R = np.asarray(R, dtype=float).reshape(-1, 3, 3)
        if len(R) != 1:
            raise ParameterError("orientations", "one orientation (a delta platform only "
                                 "translates)", f"{len(R)} rotations")
        xs, ys = _kernels.carray(xs), _kernels.carray(ys)
        K = min(K, self.column_pieces)
        W = _kernels.carray(self.leg_offsets(R)[0])
        P = _kernels.carray(self.column_params())
        if K == 1:          # every leg's set is one interval: no set machinery
            lo, hi, count = self._columns(xs, ys, W, P, 1, single=True)
        else:
            # the shared set-leg kernel, one orientation, first with the slots most columns
            # need (COLUMN_SLOTS: the engine's components, crop and z range then scan 2
            # slots, not 8); again with K only if a column (or an intermediate
            # intersection) needed more
            lo, hi, count = self._columns(xs, ys, W, P, min(K, COLUMN_SLOTS))
            if K > COLUMN_SLOTS and np.any(count > COLUMN_SLOTS):
                lo, hi, count = self._columns(xs, ys, W, P, K)
        if allowed is not None:
            off = ~np.asarray(allowed, dtype=bool).reshape(len(xs), len(ys), -1)[..., 0]
            lo[off], hi[off] = np.inf, -np.inf
        return lo, hi, int(np.sum(count > K))

    def _columns(self, xs, ys, W, P, K, single=False):
        lo, hi = np.empty((len(xs), len(ys), K)), np.empty((len(xs), len(ys), K))
        count = np.empty((len(xs), len(ys)), dtype=np.int64)
        if single:
            make_columns(type(self).column_set_leg)(xs, ys, W, P, lo, hi, count)
        else:
            make_set_column_kernel(type(self).column_set_leg, "all")(
                xs, ys, _kernels.carray(W[None]), P, lo, hi, count)
        return lo, hi, count


_F1, _F2, _F3 = nt.float64[::1], nt.float64[:, ::1], nt.float64[:, :, ::1]


@cache
def make_columns(leg):
    """Parallel ``columns(xs (nx,), ys (ny,), W (L, 3), P (L, np), out_lo, out_hi (nx, ny,
    1), count (nx, ny) int64)``: the intersection over the ``L`` legs of the set leg ``leg``
    on every column when each leg's set is one interval (one orientation), without the set
    machinery; cached by :func:`pkmlab.runtime.jit.cached_kernel`. Sets of several pieces go
    through :func:`~pkmlab.mechanisms.kernels.set_columns.make_set_column_kernel`."""
    leg = inlined(leg)

    def columns_single(xs, ys, W, P, out_lo, out_hi, count):
        nx, ny, L = xs.shape[0], ys.shape[0], W.shape[0]
        for ix in prange(nx):
            llo = np.empty(PIECES)
            lhi = np.empty(PIECES)
            for iy in range(ny):
                a = -np.inf
                b = np.inf
                for i in range(L):
                    if leg(xs[ix], ys[iy], W[i, 0], W[i, 1], W[i, 2], P[i], a, b, llo,
                           lhi) == 0:
                        a = np.inf
                        b = -np.inf
                        break
                    a = llo[0]
                    b = lhi[0]
                out_lo[ix, iy, 0] = a
                out_hi[ix, iy, 0] = b
                count[ix, iy] = 1 if a <= b else 0

    return cached_kernel(columns_single, nt.void(_F1, _F1, _F2, _F2, _F3, _F3, nt.int64[:, ::1]),
                         parallel=True)

