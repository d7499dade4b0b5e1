"""Check a trajectory: stroke, speed and force limits, with the first violation of each.

:func:`check_trajectory` runs the inverse kinematics along a trajectory and reports actuator
values, speeds (finite differences) and the static actuator forces that hold a payload, the
conditioning κ of every sample, the first violation of each limit and the stroke margins
(:class:`TrajectoryReport`). Units: mm, rad, s, mm/s, N, N·mm.

κ and "singular" are pkmlab's one definition (:mod:`pkmlab.dexterity.metrics`): κ of the
Jacobian homogenised with a characteristic length ``L`` (default Angeles',
:func:`pkmlab.dexterity.resolve_length`, recorded with its status in the report), singular
where κ = inf. Nothing here prints; diagnostics go to ``logging.getLogger(__name__)``.
Numerical failures (no inverse-kinematics solution, singular Jacobian) are reported per sample
in the report's ``status``, never raised and never left as unexplained NaN.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..dexterity import _fused_exact
from ..dexterity.metrics import CharacteristicLength, condition_number, resolve_length
from ..dexterity.sweep import singular
from ..errors import ParameterError
from ..mechanisms.base import LEG_STATUS, Mechanism
from ..poses import POSE_SIZE, as_frames
from ..tolerances import TOL
from ._args import per_actuator as _per_actuator
from ._args import positive as _positive

log = logging.getLogger(__name__)

__all__ = ["Violation", "TrajectoryReport", "check_trajectory", "TrajectoryFit", "trajectory_fit"]


@dataclass(frozen=True)
class Violation:
    """The first sample at which one kind of limit is violated.

    Attributes:
        kind: ``"stroke"`` (the pose's inverse kinematics is not valid: a leg outside its
            stroke, or no real solution), ``"jacobian"`` (singular or undefined Jacobian, so
            no static forces), ``"speed"`` or ``"force"``.
        index: sample index into the trajectory.
        time: sample time in s.
        actuator: name of the worst actuator at that sample (``mech.actuator_names``), or
            ``None`` when the failure concerns the whole pose (e.g. a singular Jacobian).
        value: the offending value — actuator value in mm (stroke), signed speed in mm/s,
            signed force in N — or ``None`` where none exists (no IK solution, singular J).
        limit: the limit crossed (mm, mm/s or N; for speed and force the magnitude limit), or
            ``None``.
        reason: human-readable description (for stroke, the inverse-kinematics reason text).
    """

    kind: str
    index: int
    time: float
    actuator: str | None
    value: float | None
    limit: float | None
    reason: str

    def as_dict(self) -> dict:
        """Plain-Python dict (JSON-serialisable)."""
        return {"kind": self.kind, "index": self.index, "time_s": self.time,
                "actuator": self.actuator, "value": self.value, "limit": self.limit,
                "reason": self.reason}


@dataclass(frozen=True)
class TrajectoryReport:
    """Result of :func:`check_trajectory` for T samples of a mechanism with L actuators.

    Attributes:
        t: ``(T,)`` times in s.
        poses: ``(T, 6)`` tool poses (mm, rad).
        q: ``(T, L)`` actuator values in mm (from ``mech.inverse``; NaN only where the sample's
            ``status`` says the pose has no inverse-kinematics solution).
        qdot: ``(T, L)`` actuator speeds in mm/s, ``np.gradient(q, t)`` (second-order central
            differences inside, one-sided at the ends); NaN where a sample used for the
            difference has no solution (``status`` says so).
        force: ``(T, L)`` static actuator forces in N holding the payload: the force each
            actuator applies along its own +q direction (positive pushes the moving side
            towards larger q), from ``Jᵀ·force = −wrench``. NaN where the Jacobian is singular
            or undefined (``status`` says so).
        wrench: ``(T, 6)`` the payload's gravity wrench at the tool-frame origin, base frame:
            ``[m·g (N); (R·payload_com) × m·g (N·mm)]``.
        condition: ``(T,)`` κ, the condition number of the Jacobian homogenised with
            ``length`` (:func:`pkmlab.dexterity.condition_number`); inf where the sample is
            singular or its Jacobian undefined.
        ik_valid: ``(T,)`` ``mech.inverse(poses).valid``.
        ik_reason: ``(T,)`` ``mech.inverse(poses).reason_text``.
        status: ``(T,)`` ``"ok"`` or ``"; "``-joined list of the sample's problems.
        ok: ``(T,)`` True where ``status == "ok"``.
        violations: first :class:`Violation` per kind, keys ``"stroke"``, ``"jacobian"``,
            ``"speed"``, ``"force"`` (value ``None`` if that kind never occurs; speed and force
            are only checked when a limit was given).
        margin_low, margin_high: ``(L,)`` minimum over the samples with a solution of
            ``q − qmin`` and ``qmax − q`` in mm (negative: the stroke is exceeded by that much;
            NaN only if no sample has a solution).
        margin_low_index, margin_high_index: ``(L,)`` sample index of each minimum (−1 if none).
        actuator_names: actuator names, as ``mech.actuator_names``.
        actuator_limits: ``(L, 2)`` stroke [min, max] per actuator in mm.
        max_speed, max_force: ``(L,)`` limits used (mm/s, N), or ``None``.
        payload_mass_kg: payload mass in kg.
        fits: True when every sample is ``"ok"``: all poses valid and within stroke, no
            singular Jacobian, and no speed/force limit exceeded.
        length: the characteristic length of ``condition``, with its status and reason.
    """

    t: np.ndarray
    poses: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    force: np.ndarray
    wrench: np.ndarray
    condition: np.ndarray
    ik_valid: np.ndarray
    ik_reason: np.ndarray
    status: np.ndarray
    ok: np.ndarray
    violations: dict[str, Violation | None]
    margin_low: np.ndarray
    margin_high: np.ndarray
    margin_low_index: np.ndarray
    margin_high_index: np.ndarray
    actuator_names: tuple[str, ...]
    actuator_limits: np.ndarray
    max_speed: np.ndarray | None
    max_force: np.ndarray | None
    payload_mass_kg: float
    fits: bool = field(default=False)
    length: CharacteristicLength | None = None
    actuator_unit: str = "mm"

    @property
    def display(self):
        """The display convention of these actuators (:func:`pkmlab.units.actuator_display`):
        mm, mm/s, N for linear ones; deg, deg/s, N·m for rotary ones."""
        from ..units import actuator_display

        return actuator_display(self.actuator_unit)

    @property
    def min_margin(self) -> tuple[float, str, int, str]:
        """Tightest stroke margin: ``(margin mm, actuator name, sample index, "min"/"max")``."""
        both = np.concatenate([self.margin_low, self.margin_high])
        if not np.any(np.isfinite(both)):
            return math.nan, "", -1, ""
        k, n = int(np.nanargmin(both)), len(self.margin_low)
        side = "min" if k < n else "max"
        idx = (self.margin_low_index if k < n else self.margin_high_index)[k % n]
        return float(both[k]), self.actuator_names[k % n], int(idx), side

    def summary(self) -> dict:
        """Plain-Python dict (JSON-serialisable) of the result.

        Keys: ``fits``, ``samples``, ``duration_s``, ``failing_samples``, ``violations``
        (first per kind, dicts or ``None``), ``min_margin_mm`` (value, actuator, time, side),
        ``margin_low_mm`` / ``margin_high_mm`` (per actuator), ``q_range_mm`` (per actuator
        [min, max]), ``peak_speed_mm_s`` and ``peak_force_n`` (per actuator, max |·| over the
        samples where defined; ``None`` if never defined), ``payload_mass_kg``, ``kappa_max``
        (``None`` when a sample is singular or undefined: ``singular_samples`` counts them),
        ``characteristic_length`` (L of κ, its status and reason), ``limits``.
        """
        names = self.actuator_names

        def per_actuator(values: np.ndarray) -> dict:
            return {n: (None if not np.isfinite(v) else float(v)) for n, v in zip(names, values)}

        def peak(a: np.ndarray) -> np.ndarray:
            finite = np.isfinite(a)
            out = np.full(a.shape[1], np.nan)
            has = finite.any(axis=0)
            out[has] = np.max(np.where(finite, np.abs(a), -np.inf), axis=0)[has]
            return out

        finite_q = np.isfinite(self.q)
        qmin = np.where(finite_q, self.q, np.inf).min(axis=0)
        qmax = np.where(finite_q, self.q, -np.inf).max(axis=0)
        m, name, idx, side = self.min_margin
        return {
            "fits": bool(self.fits),
            "samples": int(len(self.t)),
            "duration_s": float(self.t[-1] - self.t[0]),
            "failing_samples": int(np.sum(~self.ok)),
            "violations": {k: (v.as_dict() if v is not None else None)
                           for k, v in self.violations.items()},
            "min_margin_mm": {"value": None if not math.isfinite(m) else m, "actuator": name,
                              "index": idx, "time_s": float(self.t[idx]) if idx >= 0 else None,
                              "side": side},
            "margin_low_mm": per_actuator(self.margin_low),
            "margin_high_mm": per_actuator(self.margin_high),
            "q_range_mm": {n: ([float(a), float(b)] if np.isfinite(a) else None)
                           for n, a, b in zip(names, qmin, qmax)},
            "peak_speed_mm_s": per_actuator(peak(self.qdot)),
            "peak_force_n": per_actuator(peak(self.force)),
            "payload_mass_kg": float(self.payload_mass_kg),
            "kappa_max": (float(np.max(self.condition)) if np.all(np.isfinite(self.condition))
                          else None),
            "singular_samples": int(np.sum(~np.isfinite(self.condition))),
            "characteristic_length": None if self.length is None else self.length.as_dict(),
            "display": self._display_summary(peak),
            "limits": {
                "stroke_mm": self.actuator_limits.tolist(),
                "max_speed_mm_s": None if self.max_speed is None else self.max_speed.tolist(),
                "max_force_n": None if self.max_force is None else self.max_force.tolist(),
            },
        }


    def _display_summary(self, peak) -> dict:
        """Margins, peaks and limits in the display convention (deg, deg/s, N·m for rotary
        actuators; the ``*_mm`` / ``*_n`` keys above are internal units: rad, N·mm)."""
        d, names = self.display, self.actuator_names

        def conv(values, scale) -> dict:
            return {n: (None if not np.isfinite(v) else float(v) * scale)
                    for n, v in zip(names, values)}

        a = d.ascii
        return {
            "units": {"value": d.value_unit, "rate": d.rate_unit, "effort": d.effort_unit},
            "effort": d.effort,
            f"margin_low_{a(d.value_unit)}": conv(self.margin_low, d.value_scale),
            f"margin_high_{a(d.value_unit)}": conv(self.margin_high, d.value_scale),
            f"peak_rate_{a(d.rate_unit)}": conv(peak(self.qdot), d.rate_scale),
            f"peak_{d.effort}_{a(d.effort_unit)}": conv(peak(self.force), d.effort_scale),
            f"limit_{d.value}_{a(d.value_unit)}": (self.actuator_limits
                                                   * d.value_scale).tolist(),
            f"limit_rate_{a(d.rate_unit)}": (None if self.max_speed is None else
                                             (self.max_speed * d.rate_scale).tolist()),
            f"limit_{d.effort}_{a(d.effort_unit)}": (None if self.max_force is None else
                                                    (self.max_force
                                                     * d.effort_scale).tolist()),
        }


def _readonly(*arrays: np.ndarray) -> None:
    for a in arrays:
        a.setflags(write=False)


def _times_and_poses(mech: Mechanism, t, poses) -> tuple[np.ndarray, np.ndarray]:
    """``(t (T,), poses (T, 6))`` checked: T >= 2 finite, strictly increasing times; poses
    ``(T, 6)`` or ``(T, width)`` in a lower mobility's free coordinates (made ``(T, 6)``)."""
    mob = mech.mobility
    t = np.array(t, dtype=float)
    if t.ndim != 1 or len(t) < 2:
        raise ParameterError("t", "an array of shape (T,) with T >= 2 (s)", t.shape)
    if not np.all(np.isfinite(t)):
        k = int(np.flatnonzero(~np.isfinite(t))[0])
        raise ParameterError(f"t[{k}]", "a finite time (s)", float(t[k]))
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0]) + 1
        raise ParameterError(f"t[{k}]", f"strictly increasing time (> {t[k - 1]:g} s)",
                             float(t[k]))
    X = np.array(poses, dtype=float)
    if X.ndim == 2 and X.shape == (len(t), mob.width) and not mob.is_spatial:
        X = mob.full(X, mech.nominal_pose)
    if X.shape != (len(t), POSE_SIZE):
        raise ParameterError("poses", f"an array of shape ({len(t)}, 6) or ({len(t)}, "
                             f"{mob.width}) matching t (mm, rad)", X.shape)
    return t, X


def _inverse(mech: Mechanism, X: np.ndarray, stroke_tolerance: float):
    """The inverse kinematics with the stroke window widened by ``stroke_tolerance`` (mm)."""
    tol = _positive(stroke_tolerance, "stroke_tolerance", "mm", allow_zero=True)
    qlo, qhi = mech.stroke
    return mech.inverse(X, stroke=(qlo - tol, qhi + tol))


def _margins(q: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Per actuator: the smallest ``q - lo`` and ``hi - q`` over the samples with a finite
    value and their sample indices (NaN and -1 for an actuator that never has one)."""
    n_act = q.shape[1]
    margin_low = np.full(n_act, np.nan)
    margin_high = np.full(n_act, np.nan)
    idx_low = np.full(n_act, -1)
    idx_high = np.full(n_act, -1)
    for i in range(n_act):
        fin = np.isfinite(q[:, i])
        if fin.any():
            dl = np.where(fin, q[:, i] - lo[i], np.inf)
            dh = np.where(fin, hi[i] - q[:, i], np.inf)
            idx_low[i], idx_high[i] = int(np.argmin(dl)), int(np.argmin(dh))
            margin_low[i], margin_high[i] = dl[idx_low[i]], dh[idx_high[i]]
    return margin_low, margin_high, idx_low, idx_high


@dataclass(frozen=True)
class TrajectoryFit:
    """What a study reads from a trajectory: :class:`TrajectoryReport`'s ``fits``,
    ``margin_low`` and ``margin_high`` (of a check without speed or force limits), from
    :func:`trajectory_fit`."""

    fits: bool
    margin_low: np.ndarray
    margin_high: np.ndarray


def trajectory_fit(mech: Mechanism, t: np.ndarray, poses: np.ndarray, *,
                   stroke_tolerance: float = TOL.stroke_roundoff_mm,
                   characteristic_length: float | CharacteristicLength | None = None
                   ) -> TrajectoryFit:
    """``fits``, ``margin_low`` and ``margin_high`` of :func:`check_trajectory` without speed
    and force limits (the payload then changes none of them), computing only what they need.

    ``fits`` there is "every sample ok": the inverse kinematics valid (within the stroke, with
    ``stroke_tolerance``), the speed defined (both neighbours solved) and κ finite. Here the
    Jacobians are formed only when every sample is solved, and κ is not computed: one LU per
    sample bounds it (:func:`pkmlab.dexterity.sweep.singular`), and only a sample whose
    certified bound reaches the singular threshold gets its exact κ. No static forces, speeds
    or per-sample statuses. Same arguments as :func:`check_trajectory`.
    """
    t, X = _times_and_poses(mech, t, poses)
    limits = np.asarray(mech.actuator_limits, dtype=float)
    ik = _inverse(mech, X, stroke_tolerance)
    q = np.array(ik.q, dtype=float)
    low, high, _, _ = _margins(q, limits[:, 0], limits[:, 1])
    fits = (bool(np.all(ik.valid)) and bool(np.all(np.isfinite(X)))
            and bool(np.all(np.isfinite(np.gradient(q, t, axis=0)))))
    if fits:
        length = resolve_length(mech, characteristic_length)
        if _fused_exact.serves(mech):          # the same decisions, Jacobians fused in
            fits = not bool(np.any(_fused_exact.fused_singular(mech, *mech._frames(X),
                                                               length.length)))
        else:
            with np.errstate(all="ignore"):
                J = mech.jacobian(X)
            fits = not bool(np.any(singular(J, length.length, mech.mobility)))
    return TrajectoryFit(fits, low, high)


def check_trajectory(mech: Mechanism, t: np.ndarray, poses: np.ndarray, *,
                     payload_mass_kg: float = 0.0, payload_com: Sequence[float] = (0.0, 0.0, 0.0),
                     gravity: Sequence[float] = (0.0, 0.0, -9810.0),
                     max_speed: float | Sequence[float] | None = None,
                     max_force: float | Sequence[float] | None = None,
                     stroke_tolerance: float = TOL.stroke_roundoff_mm,
                     characteristic_length: float | CharacteristicLength | None = None
                     ) -> TrajectoryReport:
    """Check a trajectory against the stroke, an optional speed and an optional force limit.

    Per sample: actuator values ``q`` from ``mech.inverse``; speeds ``q̇ = np.gradient(q, t)``;
    and static actuator forces from virtual work. With ``J = mech.jacobian(poses)``
    (``q̇ = J·[v; ω]``, base frame) the actuator forces ``f`` (along +q) balance the payload's
    gravity wrench ``w = [m·g; r × m·g]`` at the tool-frame origin, ``r = R·payload_com``:
    ``Jᵀ·f + w = 0``, i.e. ``f = solve(Jᵀ, −w)``; ``Σ f_i·δq_i = −w·δx`` for any small
    displacement. Only the given payload is loaded (include the platform's own mass in
    ``payload_mass_kg`` and its centre in ``payload_com`` if wanted); link masses, friction and
    dynamics are ignored.

    Args:
        mech: the mechanism.
        t: times ``(T,)`` in s, finite and strictly increasing, T >= 2.
        poses: tool poses ``(T, 6)``, or ``(T, width)`` in a lower mobility's free coordinates
            (mm, rad; non-finite entries are reported, not raised).
        payload_mass_kg: payload mass in kg (>= 0).
        payload_com: payload centre of mass ``(3,)`` in mm in the tool frame.
        gravity: gravitational acceleration ``(3,)`` in mm/s², base frame.
        max_speed: actuator speed limit in mm/s (rad/s for a rotary actuator), scalar or one
            per actuator, compared with ``|q̇|``.
        max_force: actuator force limit in N (torque limit in N·mm for a rotary actuator),
            scalar or one per actuator, compared with ``|f|``. On a lower-mobility mechanism
            the forces balance the wrench's free components (the constraint wrench takes the
            rest); with more actuators than free coordinates they are the least-norm
            solution.
        stroke_tolerance: round-off allowance in mm: an actuator value at most this far
            outside its window still counts as inside (a motion planned to touch a limit
            exactly, as the paper's z motion does, is not a violation).
        characteristic_length: L (mm) of κ; default :func:`pkmlab.dexterity.resolve_length`
            (Angeles'). A sample whose κ is inf (singular) gets no forces.

    Returns:
        :class:`TrajectoryReport`.

    Raises:
        ParameterError: for malformed inputs (shapes, non-monotonic time, negative mass, ...).
    """
    mob, n_act = mech.mobility, mech.n_actuators
    t, X = _times_and_poses(mech, t, poses)
    mass = _positive(payload_mass_kg, "payload_mass_kg", "kg", allow_zero=True)
    com = np.asarray(payload_com, dtype=float)
    if com.shape != (3,) or not np.all(np.isfinite(com)):
        raise ParameterError("payload_com", "[x, y, z] in mm, tool frame", payload_com)
    g = np.asarray(gravity, dtype=float)
    if g.shape != (3,) or not np.all(np.isfinite(g)):
        raise ParameterError("gravity", "[gx, gy, gz] in mm/s², base frame", gravity)
    vmax = _per_actuator(max_speed, "max_speed", "mm/s", n_act)
    fmax = _per_actuator(max_force, "max_force", "N", n_act)
    length = resolve_length(mech, characteristic_length)
    L = length.length

    names = tuple(mech.actuator_names)
    limits = np.asarray(mech.actuator_limits, dtype=float)
    lo, hi = limits[:, 0], limits[:, 1]
    T = len(t)

    # --- kinematics --------------------------------------------------------------------------
    ik = _inverse(mech, X, stroke_tolerance)
    q = np.array(ik.q, dtype=float)
    ik_valid = np.asarray(ik.valid, dtype=bool)
    ik_reason = ik.reason_text
    has_q = np.all(np.isfinite(q), axis=1)
    qdot = np.gradient(q, t, axis=0)
    has_qdot = np.all(np.isfinite(qdot), axis=1)

    # --- statics -----------------------------------------------------------------------------
    finite_pose = np.all(np.isfinite(X), axis=1)
    J = np.full((T, n_act, mob.width), np.nan)
    if _fused_exact.serves(mech):           # J and κ in one numba loop, the same values
        condition = np.full(T, np.inf)
        Jf = np.empty((int(finite_pose.sum()), n_act, mob.width))
        condition[finite_pose] = _fused_exact.fused_kappa(
            mech, *mech._frames(X[finite_pose]), L, jacobians=Jf)
        J[finite_pose] = Jf
    else:
        if np.any(finite_pose):
            with np.errstate(all="ignore"):
                J[finite_pose] = mech.jacobian(X[finite_pose])
        condition = condition_number(J, L)                      # inf: singular or undefined
    j_finite = np.all(np.isfinite(J), axis=(1, 2))
    j_ok = np.isfinite(condition)

    wrench = np.full((T, POSE_SIZE), np.nan)
    F = mass * g * 1e-3                                          # kg·mm/s² → N
    if np.any(finite_pose):
        _, R = as_frames(X[finite_pose])
        r = R @ com                                              # (N, 3) mm, base frame
        wrench[finite_pose, :3] = F
        wrench[finite_pose, 3:] = np.cross(r, F)                 # N·mm
    force = np.full((T, n_act), np.nan)
    if np.any(j_ok):
        Jt = np.swapaxes(J[j_ok], 1, 2)
        w_free = -wrench[j_ok][:, mob.twist_columns, None]
        force[j_ok] = (np.linalg.solve(Jt, w_free) if n_act == mob.width
                       else np.linalg.pinv(Jt) @ w_free)[..., 0]

    # --- per-sample status and first violations -------------------------------------------------
    issues: list[list[str]] = [[] for _ in range(T)]
    violations: dict[str, Violation | None] = {"stroke": None, "jacobian": None, "speed": None,
                                               "force": None}

    for k in np.flatnonzero(~ik_valid):
        st = ik.leg_status[k]
        legs = [names[i] for i in range(n_act) if st[i] != 0]
        issues[k].append(f"{ik_reason[k]} ({', '.join(legs)})")
    if not ik_valid.all():
        k = int(np.flatnonzero(~ik_valid)[0])
        st = ik.leg_status[k].astype(int)
        sev = st.max()
        cand = np.flatnonzero(st == sev)
        if LEG_STATUS[int(sev)] in ("stroke below minimum", "stroke above maximum"):
            excess = np.where(q[k] < lo, lo - q[k], q[k] - hi)
            worst = int(cand[np.argmax(excess[cand])])
            lim = float(lo[worst] if q[k, worst] < lo[worst] else hi[worst])
            value: float | None = float(q[k, worst])
        else:
            worst, lim, value = int(cand[0]), None, None
        violations["stroke"] = Violation("stroke", k, float(t[k]), names[worst], value, lim,
                                         str(ik_reason[k]))

    bad_j = ~j_ok
    for k in np.flatnonzero(bad_j):
        if j_finite[k]:
            issues[k].append(f"singular Jacobian (κ = inf: σmin <= {TOL.singular_rtol:g}·σmax "
                             f"with L = "
                             f"{L:.4g} mm), no forces")
        else:
            issues[k].append("Jacobian not finite (no solution or a link at a singularity), "
                             "no forces")
    if bad_j.any():
        k = int(np.flatnonzero(bad_j)[0])
        msg = issues[k][-1]
        violations["jacobian"] = Violation("jacobian", k, float(t[k]), None, None, None, msg)

    for k in np.flatnonzero(has_q & ~has_qdot):
        issues[k].append("speed undefined (a neighbouring sample has no solution)")

    def check_limit(kind: str, values: np.ndarray, limit: np.ndarray | None, unit: str):
        if limit is None:
            return
        with np.errstate(invalid="ignore"):
            ratio = np.abs(values) / limit
        over = np.where(np.isfinite(ratio), ratio, 0.0) > 1.0
        for k in np.flatnonzero(over.any(axis=1)):
            legs = [names[i] for i in np.flatnonzero(over[k])]
            issues[k].append(f"{kind} above limit ({', '.join(legs)})")
        if over.any():
            k = int(np.flatnonzero(over.any(axis=1))[0])
            i = int(np.nanargmax(np.where(over[k], ratio[k], -np.inf)))
            violations[kind] = Violation(
                kind, k, float(t[k]), names[i], float(values[k, i]), float(limit[i]),
                f"|{kind}| {abs(values[k, i]):.6g} {unit} > {limit[i]:.6g} {unit}")

    check_limit("speed", qdot, vmax, "mm/s")
    check_limit("force", force, fmax, "N")

    status = np.array(["; ".join(s) if s else "ok" for s in issues], dtype=object)
    ok = status == "ok"

    # --- stroke margins ------------------------------------------------------------------------
    margin_low, margin_high, idx_low, idx_high = _margins(q, lo, hi)

    fits = bool(ok.all())
    _readonly(t, X, q, qdot, force, wrench, condition, ik_valid, status, ok, margin_low,
              margin_high, idx_low, idx_high, limits)
    report = TrajectoryReport(
        t=t, poses=X, q=q, qdot=qdot, force=force, wrench=wrench, condition=condition,
        ik_valid=ik_valid, ik_reason=ik_reason, status=status, ok=ok, violations=violations,
        margin_low=margin_low, margin_high=margin_high, margin_low_index=idx_low,
        margin_high_index=idx_high, actuator_names=names, actuator_limits=limits,
        max_speed=vmax, max_force=fmax, payload_mass_kg=mass, fits=fits, length=length,
        actuator_unit=str(getattr(mech, "actuator_unit", "mm")))
    log.debug("trajectory check: %d samples, fits=%s, %d failing", T, fits, int(np.sum(~ok)))
    return report
