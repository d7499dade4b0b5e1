"""The mechanism protocol: what every family provides, result types and generic solvers.

Public protocol (what the rest of pkmlab uses; nothing outside :mod:`pkmlab.mechanisms` calls a
method whose name starts with ``_``):

* ``family``, ``mobility`` (the free pose coordinates, :mod:`.mobility`; spatial unless the
  family declares another), ``actuator_names`` (one per actuator: ``n_actuators``, the ``L``
  below), ``actuator_unit`` (``"mm"`` or ``"rad"``), ``name``, ``stroke``, ``actuator_limits``,
  ``scale``;
* ``base_points``, ``platform_points``, ``tool_offset`` and ``tool_points`` (mm);
* ``nominal_pose`` — level, centred, mid-stroke unless given;
* ``inverse(poses, stroke=None)``, ``jacobian(poses)`` and both at once,
  ``inverse_and_jacobian(poses, stroke=None)``: ``poses`` is ``(N, 6)`` Euler
  (mm, rad, R = Rz·Ry·Rx), ``(N, 4, 4)`` transforms, a tuple ``(p (N, 3), R (N, 3, 3))``, or,
  for a mechanism whose mobility is not spatial, ``(N, width)`` in its free coordinates (the
  others taken from the nominal pose); ``stroke`` overrides the actuator window
  (:data:`NO_STROKE` for geometry only). Actuator values are ``(N, L)``; the Jacobian is
  ``(N, L, width)``, its columns the free components of the twist ``[v; ω]``;
* ``forward(q)``, ``assembly_modes(q)`` (``q`` of ``L`` values; poses returned with six
  coordinates, the fixed ones those of the nominal pose);
* ``footprint()`` — base and platform radii measured from their centres;
* ``legs(pose=None)`` — each leg's joint chain at a pose (default nominal), base frame, one
  :class:`.joints.Leg` per actuator in the order of ``actuator_names``: its joints from base
  to platform (type R, P, U or S; ``location`` mm; unit ``axes``, R/P one, U two orthogonal,
  the parent's first; ``actuated``, exactly one a leg; ``parent`` / ``child`` bodies "base",
  a named link, "platform"; a P joint's ``zero``, ``location - zero = coordinate·axis``; an
  actuated R joint's ``reference`` direction at angle 0), the links between them with their
  fixed lengths, and the actuator value. Chains close: consecutive joints are the declared
  lengths apart, the last is the platform point moved by the pose, the actuated joint's
  coordinate is the IK's value (:func:`pkmlab.testing.check_joints`). Exports, calibration
  and the drawings read it;
* ``parameters()`` — the geometry as one named vector with units (:class:`.joints.Parameters`:
  names, values, units "mm" / "rad" / "1", descriptions): every base and platform joint, every
  axis, fixed link lengths, the actuator window and zero, the tool offset;
  ``with_parameters(values)`` — the same family with those values (an array, or a mapping name
  → value), ``m.with_parameters(m.parameters().values) == m``
  (:func:`pkmlab.testing.check_parameters`);
* ``leg_segments(p, R)`` — each leg's moving link, for interference and drawing, read from
  the joints (each leg's ``segment``); ``link_segments(p, R)`` — every moving link with the
  leg it belongs to (from the joints: the ``leg_segments`` and the cranks), for interference;
  ``base_joint_axes(p, R, axes)`` — the mounting axes of the base-side passive joints at each
  pose (from the joints: fixed, or turned with the crank that carries the joint), for joint
  cones;
* workspace hooks: ``position_bounds(R)``, and for families with exact column intervals
  ``column_method``, ``column_leg``, ``column_params()``, ``leg_offsets(R)`` and
  ``column_intervals(xs, ys, R, mode)`` (and ``column_radial`` when the leg intervals are
  monotone functions of the distance from the leg's column axis, with ``column_profile()``
  giving their closed form for the guaranteed volume bracket,
  :mod:`pkmlab.workspaces.bracket.columns`);
  families without column kernels may set ``cell_bounds`` and give ``leg_cell_bounds(p, R,
  delta, alpha)`` (each leg's length and a bound on its change over a position ball × rotation
  cell; ``leg_cell_margins`` when feasibility needs more than the window, rss6) for the cell
  bracket, :mod:`pkmlab.workspaces.bracket.cells`;
* equality and hashing by geometry (two mechanisms with the same family, joints, stroke, tool
  offset and nominal pose are equal, whatever their names).

What a new family implements (one module and a :data:`pkmlab.mechanisms.REGISTRY` entry; the
contract suite in ``tests/mechanisms/test_contract.py`` then runs on it):

* a frozen dataclass subclassing :class:`Mechanism`, declared with ``eq=False`` so that the
  geometric equality and hash defined here are kept, holding ``base_points``,
  ``platform_points``, ``stroke_window`` and ``tool_offset``, validated in ``__post_init__``;
* ``_ik_one`` — a numba per-pose inverse kinematics function (see :mod:`._kernels`) writing
  exactly ``L`` legs (the drivers check it and raise otherwise);
* ``_gparams()`` — the geometry packed as one float array for that function;
* ``_jacobian(p, R)`` — the analytic velocity Jacobian ``(N, L, 6)`` over the full twist
  (the protocol keeps the mobility's columns), or instead
  ``_jac_one``, a numba per-pose Jacobian (see :func:`._kernels.make_jacobian_driver`; with
  ``_jac_uses_q = True`` when it reads the actuator values), which the base ``_jacobian`` runs
  in parallel: ``psu6``, ``ups6`` and ``rss6`` do, at tens of M poses/s;
* ``_closure(p, R, q)`` — loop-closure residuals ``(N, L)`` in mm and their derivative with
  respect to the tool twist ``(N, L, 6)``, used by Newton's method (on the free columns);
* ``scale``; the joints, ``_joint_arrays(p, R, axes=True)`` (every leg's joint centres and
  axes over N poses, vectorised) and ``_leg_templates()`` (each leg's joint types, bodies,
  fixed link lengths, actuated joint), helped by :func:`.joints.kind_arrays` for UPS, PSU and
  RSS legs; ``parameter_fields`` when the geometry has more than the protocol's
  ``base_points``, ``platform_points``, ``stroke_window`` and ``tool_offset``
  (:class:`.joints.ParamField`); optionally the column hooks above.

Forward kinematics, the assembly-mode and nominal-pose searches: generic, here and :mod:`.solvers`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field, fields
from functools import cached_property
from typing import Any, ClassVar

import numpy as np

from ..errors import ParameterError
from ..poses import POSE_SIZE, as_frames, log_so3
from ..runtime.threads import threads_for
from ..tolerances import TOL
from .joints import JointsMixin, base_joint_axes_of, link_segments_of
from .kernels import columns as column_kernels
from .kernels import ik as _kernels
from .kernels import ik_free as _ik_free
from .kernels import tiles as _tiles
from .mobility import SPATIAL, Mobility
from .results import LEG_STATUS, NO_STROKE, AssemblyModes, FKResult, IKResult
from .solvers import forward_newton, mid_stroke_pose, multistart_modes
from .validation import as_points, as_positive, as_stroke, as_vector3

log = logging.getLogger(__name__)

#: starting poses of the forward-kinematics mode check (``forward(..., modes=True)``)
_MODE_STARTS = 64

__all__ = [
    "NO_STROKE",
    "LEG_STATUS",
    "IKResult",
    "FKResult",
    "AssemblyModes",
    "Mechanism",
    "as_points",
    "as_stroke",
    "as_positive",
    "as_vector3",
]


@dataclass(frozen=True, eq=False)
class Mechanism(JointsMixin):
    """Base of every mechanism family (geometry lives in the subclass; joints and parameters:
    :class:`.joints.JointsMixin`)."""

    family: ClassVar[str] = ""
    #: the free pose coordinates (:mod:`.mobility`)
    mobility: ClassVar[Mobility] = SPATIAL
    actuator_names: ClassVar[tuple[str, ...]] = ("q1", "q2", "q3", "q4", "q5", "q6")
    #: unit of the actuator values: ``"mm"`` (prismatic) or ``"rad"`` (rotary; the CLI and its
    #: JSON show these in degrees)
    actuator_unit: ClassVar[str] = "mm"
    name: str = field(default="", kw_only=True)
    nominal: np.ndarray | None = field(default=None, kw_only=True, repr=False)
    description: dict = field(default_factory=dict, kw_only=True, repr=False, compare=False)

    # ---- family hooks ----------------------------------------------------------------------
    _ik_one: ClassVar[Any] = None
    #: numba per-pose Jacobian ``jac(px, py, pz, r00, ..., r22, g, q, J, k)`` (optional; see
    #: :func:`._kernels.make_jacobian_driver`), ``g`` the IK geometry; ``q`` (the actuator
    #: values, from the IK without stroke) is computed only when ``_jac_uses_q``.
    _jac_one: ClassVar[Any] = None
    _jac_uses_q: ClassVar[bool] = False
    #: ``"linear"`` / ``"quadratic"`` when the family supplies exact column kernels
    #: (``column_leg``) for the workspace engine, ``"crank"`` for rss6's set-valued legs (it
    #: overrides ``column_intervals``, :mod:`._set_columns`), ``None`` for sampled evaluation.
    column_method: ClassVar[str | None] = None
    #: True when, at fixed (x, y, orientation), the leg geometry (link vectors, joint angles,
    #: Jacobian) does not depend on z, so non-stroke constraints act on whole columns.
    column_invariant: ClassVar[bool] = False

    #: True when ``column_leg``'s interval depends on (x, y) only through the horizontal
    #: distance ``d = |(x, y) + w_xy|`` from the leg's column axis, with both ends and the
    #: ``ok`` flag monotone in ``d`` (``ok`` true on ``d <= d_max``): a task region's
    #: containment is then decided exactly from the nearest and farthest ``d`` of its
    #: footprint (:mod:`pkmlab.requirements.task`). ``psu6`` and ``ups6`` declare it. Read it
    #: from the instance: ``sixleg`` turns it (and ``column_leg``) off per instance for cranks.
    column_radial: ClassVar[bool] = False

    #: numba per-leg column interval ``leg(x, y, wx, wy, wz, p0, p1, p2) -> (a, b, ok)`` (see
    #: :func:`.column_kernels.make_column_kernel`); families with it set ``column_method``. Test
    #: ``mech.column_leg is None`` (per instance); kernels are built from ``type(mech)``'s.
    column_leg: ClassVar[Any] = None

    #: True when the family gives :meth:`leg_cell_bounds` (luzi3): the volume bracket then
    #: works on position cells × orientation cells (:mod:`pkmlab.workspaces.bracket.cells`).
    cell_bounds: ClassVar[bool] = False
    #: True when the family also gives ``leg_position_curvature(p, R, delta)`` (each leg's
    #: gradient in the position and a bound on its second derivative over a ball): the cell
    #: bracket then bounds the volume inside undecided cubes to second order.
    position_curvature: ClassVar[bool] = False

    def leg_cell_bounds(self, p, R, delta, alpha, mode=False):  # pragma: no cover
        """``(q, eps)``, both ``(N, 6)``: for every position within ``delta (N,)`` mm of ``p``
        and every rotation within the angle ``alpha (N,)`` rad of ``R`` (``(p (N, 3), R (N,
        3, 3))`` the cell centres), each actuator value lies in ``q ± eps``; ``q`` is the value
        at the centre wherever the family can say so. With ``mode``, also an int array per
        chain: +1 where the whole cell is in the working mode, -1 where none of it is, 0
        where undecided; luzi3: see its docstring."""
        raise NotImplementedError

    def leg_cell_margins(self, p, R, delta, alpha, mode=False):
        """``(q, m, eps[, mode])``: the margins the cell bracket tests, ``m`` and ``eps``
        ``(N, K)`` such that ``m > eps`` proves that condition feasible at every point of the
        cell and ``m < -eps`` proves it infeasible (the item is certainly in when every
        ``m > eps``, certainly out when some ``m < -eps``). Default (K = 6):
        ``min(q - qmin, qmax - q)`` from :meth:`leg_cell_bounds` (1-Lipschitz in q, so
        ``|m' - m| <= eps`` with the same eps); rss6: a signed lower bound of the distance
        to the other status, which also covers the rod's closing (:mod:`._crank_cells`)."""
        out = self.leg_cell_bounds(p, R, delta, alpha, mode)
        lo, hi = self.stroke
        with np.errstate(invalid="ignore"):
            m = np.minimum(out[0] - lo, hi - out[0])
        return (out[0], m, *out[1:])

    def column_params(self) -> np.ndarray:  # pragma: no cover - optional
        """``(6, 3)`` per-leg parameters of ``column_leg``."""
        raise NotImplementedError

    def column_profile(self) -> np.ndarray | None:
        """``(6, 2, 3)`` or ``None``: for ``column_radial`` families whose leg ends have the
        form ``c + σ·sqrt(max(K - d², 0)) - w_z`` (``d`` the horizontal distance from the leg's
        column axis), ``(c, σ, K)`` of each leg's lower and upper end. The volume bracket then
        bounds each end over a cell to second order (a sphere's curvature is known);
        ``None``: first order only."""
        return None

    def leg_offsets(self, R: np.ndarray) -> np.ndarray:
        """``(M, 6, 3)`` offsets ``w_i = R·u_i - b_i`` (u_i platform joints about the tool)."""
        return np.ascontiguousarray(self.tool_points @ R.transpose(0, 2, 1)
                                    - self.base_points)

    def column_intervals(self, xs, ys, R, mode, allowed=None, K=8):
        """Stroke-feasible z sets of the columns ``xs × ys``: ``(lo, hi, overflow)``.

        ``lo, hi`` are ``(nx, ny, K)`` sorted disjoint intervals (empty slots ``inf, -inf``);
        ``mode="all"`` intersects over the orientations ``R (M, 3, 3)`` (K = 1), ``"any"``
        unites the orientations that ``allowed (nx, ny, M)`` permits. ``overflow`` counts
        columns whose union needed more than ``K`` pieces.
        """
        W = self.leg_offsets(R)
        P = _kernels.carray(self.column_params())
        xs, ys = _kernels.carray(xs), _kernels.carray(ys)
        nx, ny = len(xs), len(ys)
        if mode == "all":
            if allowed is not None:
                raise ValueError("mode 'all' takes no orientation mask; mask the columns")
            # Most tilted orientations first: dead columns then die after a few of them.
            W = W[np.argsort(-np.linalg.norm(R - np.eye(3), axis=(1, 2)), kind="stable")]
            lo, hi = np.empty((nx, ny, 1)), np.empty((nx, ny, 1))
            # large footprints of radial families: tiles of columns bounded first, most
            # leg × orientation pairs pruned (exact, :mod:`._tiles`)
            tiled = self.column_radial and nx * ny >= _tiles.MIN_COLUMNS
            columns_all = (_tiles.make_tiled_all(type(self).column_leg) if tiled
                           else column_kernels.make_column_kernel(type(self).column_leg, "all"))
            with threads_for(nx * ny * len(W)):
                columns_all(xs, ys, _kernels.carray(W), P, lo, hi)
            return lo, hi, 0
        if allowed is None:
            allowed = np.ones((nx, ny, len(R)), dtype=np.bool_)
        lo, hi = np.empty((nx, ny, K)), np.empty((nx, ny, K))
        count = np.empty((nx, ny), dtype=np.int64)
        columns_any = column_kernels.make_column_kernel(type(self).column_leg, "any")
        with threads_for(nx * ny * len(W)):
            columns_any(xs, ys, _kernels.carray(W), P, _kernels.carray(allowed, np.bool_), lo,
                        hi, count)
        return lo, hi, int(np.sum(count > K))

    def position_bounds(self, R: np.ndarray) -> np.ndarray:
        """``(M, 2, 3)`` per-orientation box [min; max] that contains every feasible position."""
        p = self.nominal_pose[:3]
        S = 2.0 * self.scale
        return np.broadcast_to(np.stack([p - S, p + S]), (len(R), 2, 3)).copy()

    def link_segments(self, p: np.ndarray, R: np.ndarray):
        """``(start, end, leg)``: end points ``(N, S, 3)`` of every moving link and the leg
        ``(S,)`` each belongs to; links of one leg share joints, so interference is checked
        between links of different legs only. Read from the joints
        (:func:`.joints.link_segments_of`): the ``leg_segments`` and, before them, every
        leg's links of positive length on the base side of its segment (cranks)."""
        return link_segments_of(self, p, R)

    def base_joint_axes(self, p: np.ndarray, R: np.ndarray, axes: np.ndarray) -> np.ndarray:
        """``(N, L, 3)`` base-frame mounting axes of the base-side passive joints at the poses,
        given ``axes (L, 3)`` at the nominal pose, read from the joints
        (:func:`.joints.base_joint_axes_of`): fixed to the base, or turned with the crank
        that carries the joint."""
        return base_joint_axes_of(self, p, R, axes)

    def _gparams(self) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def _ik_kernel(self):
        """The per-pose IK function: ``_ik_one`` (``sixleg`` picks one by its leg kinds)."""
        return type(self)._ik_one

    def _jacobian(self, p: np.ndarray, R: np.ndarray) -> np.ndarray:
        """``(N, L, 6)`` by the family's ``_jac_one`` kernel (families without one override
        this with their own formula)."""
        jac = type(self)._jac_one
        if jac is None:  # pragma: no cover - abstract
            raise NotImplementedError
        p, R = _kernels.carray(p), _kernels.carray(R)
        L = self.n_actuators
        q = (self._run_ik(p, R, *NO_STROKE).q if self._jac_uses_q
             else np.empty((len(p), L)))
        J = np.empty((len(p), L, POSE_SIZE))
        g = self._ik_geometry
        _kernels.make_jacobian_driver(jac, len(g))(p, R, g, q, J)
        return J

    def _closure(self, p, R, q):  # pragma: no cover - abstract
        raise NotImplementedError

    @property
    def stroke(self) -> tuple[float, float]:
        """Actuator window (min, max) in mm (every family stores it as ``stroke_window``)."""
        return self.stroke_window

    @property
    def tool_points(self) -> np.ndarray:
        """Platform joint centres in the tool frame (same orientation, origin at the offset)."""
        return self.platform_points - self.tool_offset

    def footprint(self) -> dict:
        """Footprint in mm: ``base_radius`` (largest horizontal distance of a base joint from
        the base z axis) and ``platform_radius`` (largest distance of a platform joint from the
        platform joints' centroid, in the platform frame)."""
        P = self.platform_points
        return {"base_radius": float(np.max(np.linalg.norm(self.base_points[:, :2], axis=1))),
                "platform_radius": float(np.max(np.linalg.norm(P - P.mean(axis=0), axis=1)))}

    # ---- equality and hashing by geometry ----------------------------------------------------
    def _key(self) -> tuple:
        parts: list = [self.family]
        for f in fields(self):
            if not f.compare or f.name == "name":
                continue
            v = getattr(self, f.name)
            if v is None:
                parts.append(None)
            else:
                a = np.asarray(v, dtype=float)
                parts.append((a.shape, a.tobytes()))
        return tuple(parts)

    def __eq__(self, other) -> bool:
        if not isinstance(other, Mechanism):
            return NotImplemented
        return type(self) is type(other) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    @property
    def scale(self) -> float:
        """Characteristic size in mm (tolerances and multi-start boxes scale with it)."""
        raise NotImplementedError  # pragma: no cover

    # ---- public API ------------------------------------------------------------------------
    @property
    def n_actuators(self) -> int:
        """Number of actuators (and legs of the inverse kinematics), ``L``."""
        return len(self.actuator_names)

    @property
    def actuator_limits(self) -> np.ndarray:
        """``(L, 2)`` actuator windows [min, max] in mm."""
        lo, hi = self.stroke
        return np.tile([lo, hi], (self.n_actuators, 1))

    @property
    def nominal_pose(self) -> np.ndarray:
        """``(6,)`` nominal tool pose (mm, rad): given, or level and centred at mid-stroke."""
        return self._nominal.copy()

    @cached_property
    def _nominal(self) -> np.ndarray:
        if self.nominal is not None:
            return np.array(self.nominal, dtype=float)
        return self._mid_stroke_pose()

    def inverse(self, poses, *, stroke: tuple[float, float] | None = None) -> IKResult:
        """Actuator values of poses → :class:`IKResult`.

        Args:
            poses: ``(N, 6)`` Euler poses (mm, rad), ``(N, 4, 4)`` transforms, a tuple
                ``(p (N, 3), R (N, 3, 3))`` of positions and rotation matrices, or ``(N,
                width)`` free coordinates of a mechanism whose mobility is not spatial.
            stroke: actuator window ``(min, max)`` in mm to check instead of the mechanism's;
                :data:`NO_STROKE` checks the geometry only.
        """
        lo, hi = self.stroke if stroke is None else (float(stroke[0]), float(stroke[1]))
        if isinstance(poses, tuple):
            p, R = _frames_tuple(poses)
            return self._run_ik(p, R, lo, hi)
        X = np.asarray(poses, dtype=float)
        if (free := _ik_free.free_rows(self.mobility, X)) is not None:
            return _ik_free.inverse_free(self, free, lo, hi)    # not expanded to six
        if X.ndim <= 2 and X.shape[-1] == POSE_SIZE:
            return self._run_ik(np.ascontiguousarray(X.reshape(-1, POSE_SIZE)), None, lo, hi)
        p, R = as_frames(X)
        return self._run_ik(p, R, lo, hi)

    def _free_to_full(self, X: np.ndarray) -> np.ndarray:
        """Poses given in a non-spatial mobility's free coordinates → six coordinates."""
        free = _ik_free.free_rows(self.mobility, X)
        return X if free is None else self.mobility.full(free, self.nominal_pose)

    def _frames(self, poses) -> tuple[np.ndarray, np.ndarray]:
        if isinstance(poses, tuple):
            return _frames_tuple(poses)
        return as_frames(self._free_to_full(np.asarray(poses, dtype=float)))

    def _run_ik(self, X_or_p, R, lo: float, hi: float) -> IKResult:
        g = self._ik_geometry
        n, L = X_or_p.shape[0], self.n_actuators
        q, st = np.empty((n, L)), np.empty((n, L), dtype=np.int8)
        reason = np.empty(n, dtype=np.int8)
        one, ng, lo, hi = self._ik_kernel(), len(g), float(lo), float(hi)
        with threads_for(n):
            if R is None:
                euler = _kernels.make_driver(one, ng, "euler", L)
                euler(_kernels.carray(X_or_p), g, lo, hi, q, st, reason)
            else:
                frames = _kernels.make_driver(one, ng, "frames", L)
                frames(_kernels.carray(X_or_p), _kernels.carray(R), g, lo, hi, q, st, reason)
        self._check_legs(reason)
        return IKResult(q=q, valid=reason == _kernels.OK, reason=reason, leg_status=st)

    def _check_legs(self, reason: np.ndarray) -> None:
        """A family's ``_ik_one`` that wrote another number of legs than it declares is a
        programming error: raise, never return its buffers as actuator values."""
        if np.any(reason == _kernels.LEG_FAULT):
            raise RuntimeError(
                f"{type(self).__name__}._ik_one did not write exactly the {self.n_actuators} "
                f"legs its actuator_names declare ({', '.join(self.actuator_names)}) for "
                f"{int(np.sum(reason == _kernels.LEG_FAULT))} pose(s): set actuator_names (and "
                "mobility) to what the kernel computes")

    @cached_property
    def _ik_geometry(self) -> tuple:
        """``_gparams()`` as a tuple of floats: the IK drivers' loops see its entries as
        constants (see :mod:`._kernels`)."""
        return tuple(self._gparams().tolist())

    def inverse_and_jacobian(self, poses, *, stroke: tuple[float, float] | None = None
                             ) -> tuple[IKResult, np.ndarray]:
        """:meth:`inverse` and :meth:`jacobian` of the same poses, ``(IKResult, J (N, L,
        width))``: one parallel pass for families with a numba Jacobian (inverse dynamics
        calls this per chunk of a trajectory)."""
        jac = type(self)._jac_one
        if jac is None or type(self)._jacobian is not Mechanism._jacobian:
            # no kernel, or a subclass's own formula: the two calls, which honour it
            return self.inverse(poses, stroke=stroke), self.jacobian(poses)
        p, R = self._frames(poses)
        p, R = _kernels.carray(p), _kernels.carray(R)
        lo, hi = self.stroke if stroke is None else (float(stroke[0]), float(stroke[1]))
        n, g, L = len(p), self._ik_geometry, self.n_actuators
        q, J = np.empty((n, L)), np.empty((n, L, POSE_SIZE))
        st, reason = np.empty((n, L), dtype=np.int8), np.empty(n, dtype=np.int8)
        drive = _kernels.make_kinematics_driver(self._ik_kernel(), jac, len(g), L)
        drive(p, R, g, float(lo), float(hi), q, st, reason, J)
        self._check_legs(reason)
        return (IKResult(q=q, valid=reason == _kernels.OK, reason=reason, leg_status=st),
                self._free_columns(J))

    def jacobian_kernel(self) -> tuple | None:
        """``(jac, g)``: the family's numba per-pose Jacobian ``_jac_one`` over all six twist
        components and its geometry tuple, when :meth:`jacobian` is exactly that; else None
        (fused loops, :mod:`pkmlab.dexterity._fused`)."""
        cls = type(self)
        if (cls._jac_one is None or cls._jac_uses_q or cls._jacobian is not Mechanism._jacobian
                or not self.mobility.is_spatial):
            return None
        return cls._jac_one, self._ik_geometry

    def jacobian(self, poses) -> np.ndarray:
        """Analytic velocity Jacobian ``(N, L, width)``: ``q̇ = J · t``, ``t`` the free
        components of the twist ``[v; ω]`` (all six for a spatial mechanism).

        ``poses`` as for :meth:`inverse`. ``v`` (mm/s) is the velocity of the tool-frame origin
        and ``ω`` (rad/s) the angular velocity, both in the base frame. Rows of legs with no
        real solution are NaN; use :meth:`inverse` for the mask and reason.
        """
        return self._free_columns(self._jacobian(*self._frames(poses)))

    def _free_columns(self, J: np.ndarray) -> np.ndarray:
        mob = self.mobility
        return J if mob.is_spatial else np.ascontiguousarray(J[:, :, mob.twist_columns])

    def forward(self, q: np.ndarray, guess: np.ndarray | None = None, *,
                tol: float = TOL.fk_residual_mm, max_iter: int = 50,
                modes: bool = False) -> FKResult:
        """Forward kinematics by Newton's method with the analytic Jacobian.

        Args:
            q: actuator values ``(L,)`` or ``(N, L)`` in mm.
            guess: starting pose(s) ``(6,)`` or ``(N, 6)``; default the nominal pose. Where
                Newton from the guess fails or lands outside the working mode, the solve is
                repeated by continuation from the nominal pose along a straight actuator path.
            tol: convergence tolerance on the loop-closure residual in mm.
            modes: also look for *other* working-mode assembly modes of the same actuator
                values (several can lie near the start, e.g. on the Hexaglide, and Newton
                then returns one of them with nothing to tell which): Newton from
                :attr:`_mode_starts` (64 poses of the working region, about 1 ms per actuator
                vector); the result's ``ambiguous``, ``next_mode``, ``next_mode_mm`` and
                ``next_mode_deg`` say what was found, and ``status`` is ``"ambiguous"``.
                Off by default (bulk use); ``pkmlab fk`` runs it.
        """
        return forward_newton(self, q, guess, tol=tol, max_iter=max_iter, modes=modes)

    def assembly_modes(self, q: np.ndarray, *, starts: int = 1500, seed: int = 0,
                       tol: float = TOL.fk_residual_mm) -> AssemblyModes:
        """All real assembly modes for one actuator vector ``(L,)``, by multi-start Newton.

        Starting points: the nominal pose, plus ``starts`` poses with positions uniform in a
        box of half-size ``2·scale`` around the base centre and orientations uniform on SO(3)
        (seeded); coordinates the mobility does not free keep their nominal values.
        Solutions are de-duplicated (``TOL.mode_duplicate_rel``·scale mm and rad) and sorted
        by distance to the nominal pose.
        """
        return multistart_modes(self, q, starts=starts, seed=seed, tol=tol)

    def describe(self) -> dict:
        """Plain-dict summary of the geometry for display and JSON."""
        return {"family": self.family, "name": self.name, **self.description,
                "stroke_mm": list(self.stroke),
                "tool_offset_mm": np.asarray(self.tool_offset).tolist(),
                "base_points_mm": np.asarray(self.base_points).tolist(),
                "platform_points_mm": np.asarray(self.platform_points).tolist()}

    # ---- helpers -----------------------------------------------------------------------------
    def _level_yaw(self) -> float:
        """Rotation about z (rad) of the platform frame at the symmetric, level pose."""
        return 0.0

    def _mid_stroke_pose(self) -> np.ndarray:
        """Level, centred pose whose mean actuator value is mid-stroke (highest such z)."""
        return mid_stroke_pose(self)

    def _random_starts(self, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
        rng = np.random.default_rng(seed)
        S = self.scale
        p = rng.uniform(-2 * S, 2 * S, size=(n, 3))         # box about the base centre
        mob = self.mobility
        if not mob.is_spatial:
            X = np.repeat(self.nominal_pose[None], n, axis=0)
            X[:, :3] = p
            X[:, 3:] += rng.uniform(-np.pi, np.pi, size=(n, 3))
            return as_frames(mob.full(mob.free(X), self.nominal_pose))
        # lazy: scipy.spatial costs 0.25 s at import, and only forward kinematics needs it
        from scipy.spatial.transform import Rotation

        R = Rotation.random(n, random_state=rng).as_matrix()
        return p, R

    @cached_property
    def _mode_starts(self) -> tuple[np.ndarray, np.ndarray]:
        """Starting poses of the FK mode check (``forward(..., modes=True)``): the nominal pose
        and up to 63 random poses within the stroke, positions within ±scale/8 and Euler
        angles within ±30° of the nominal pose (seeded; 20 batches of 4,096 draws at most)."""
        X0 = np.asarray(self.nominal_pose, float)
        rng = np.random.default_rng(20221)
        span = np.zeros(POSE_SIZE)              # the free coordinates only (:mod:`.mobility`)
        span[self.mobility.index] = np.array([self.scale / 8] * 3
                                             + [np.radians(30.0)] * 3)[self.mobility.index]
        keep = [X0[None]]
        count = 1
        for _ in range(20):
            X = X0 + rng.uniform(-1.0, 1.0, (4096, POSE_SIZE)) * span
            X = X[self.inverse(X).valid][:_MODE_STARTS - count]
            keep.append(X)
            count += len(X)
            if count >= _MODE_STARTS:
                break
        return as_frames(np.concatenate(keep))

    def _pose_distance(self, p: np.ndarray, R: np.ndarray) -> np.ndarray:
        pn, Rn = as_frames(self.nominal_pose)
        rot = np.linalg.norm(log_so3(np.einsum("ji,njk->nik", Rn[0], R)), axis=-1)
        return np.linalg.norm(p - pn, axis=-1) + self.scale * rot


def _frames_tuple(frames) -> tuple[np.ndarray, np.ndarray]:
    """Validate a ``(p, R)`` tuple: positions ``(N, 3)`` (or ``(3,)``) and rotations
    ``(N, 3, 3)`` (or ``(3, 3)``), C-contiguous float64."""
    if len(frames) != 2:
        raise ParameterError("poses", "a tuple (p (N, 3), R (N, 3, 3))", f"{len(frames)} items")
    p = np.ascontiguousarray(frames[0], dtype=float).reshape(-1, 3)
    R = np.ascontiguousarray(frames[1], dtype=float).reshape(-1, 3, 3)
    if len(p) != len(R):
        raise ParameterError("poses", "as many positions as rotations", f"{len(p)} and {len(R)}")
    return p, R
