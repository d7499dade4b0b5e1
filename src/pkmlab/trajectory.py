"""Trajectories: the paper's Cartesian test motion, CSV input, and a stroke/speed/force check.

Units follow the rest of pkmlab: poses are ``(x, y, z, θx, θy, θz)`` of the tool frame in the
base frame in mm and rad (Z-Y-X Euler angles, :mod:`pkmlab.poses`), times in s, actuator values
in mm, actuator speeds in mm/s, forces in N and moments in N·mm.

* :func:`paper_motion` builds the coordinated Cartesian motion of Hopkins & Williams (2002),
  Sect. 6 / Fig. 13: from the nominal pose, "sinusoidal-like third-order polynomial" motions of
  ``x_H, y_H, z_H, θz, θy, θx`` one at a time, each a pair of lobes of ±2 in / ±30°.
* :func:`load_csv` reads a time-stamped pose list (``t,x,y,z,theta_x,theta_y,theta_z``; s, mm
  and deg).
* :func:`check_trajectory` runs the inverse kinematics along a trajectory and reports actuator
  values, speeds (finite differences) and the static actuator forces that hold a payload, with
  the first violation of each limit and the stroke margins (:class:`TrajectoryReport`).
* :func:`plot_actuators` draws actuator values against time in the style of the paper's Fig. 13.

Nothing here prints; diagnostics go to ``logging.getLogger(__name__)``. Numerical failures (no
inverse-kinematics solution, singular Jacobian) are reported per sample in the report's
``status``, never raised and never left as unexplained NaN.
"""

from __future__ import annotations

import csv
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .errors import ParameterError
from .mechanisms.base import LEG_STATUS, Mechanism
from .poses import as_frames

log = logging.getLogger(__name__)

__all__ = [
    "PAPER_AXES",
    "CSV_COLUMNS",
    "SINGULAR_CONDITION",
    "Violation",
    "TrajectoryReport",
    "lobe_profile",
    "paper_motion_phases",
    "paper_motion",
    "load_csv",
    "check_trajectory",
    "plot_actuators",
]

#: Order of the paper's Cartesian test motions (Sect. 6): name and index into the pose vector.
PAPER_AXES: tuple[tuple[str, int], ...] = (
    ("x", 0), ("y", 1), ("z", 2), ("theta_z", 5), ("theta_y", 4), ("theta_x", 3),
)

#: Columns of a trajectory CSV file and their units (converted to mm / rad on load).
CSV_COLUMNS: tuple[str, ...] = ("t", "x", "y", "z", "theta_x", "theta_y", "theta_z")

#: A Jacobian whose 2-norm condition number exceeds this is treated as singular (no forces).
SINGULAR_CONDITION = 1e10

_MM_PER_IN = 25.4


# ---------------------------------------------------------------------------------------------
# the paper's test motion


def _smoothstep(tau: np.ndarray) -> np.ndarray:
    """Cubic rest-to-rest blend ``s(τ) = 3τ² − 2τ³`` on [0, 1] (s' = 0 at both ends)."""
    return tau * tau * (3.0 - 2.0 * tau)


def _positive(value: Any, name: str, unit: str, allow_zero: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise ParameterError(name, f"a finite number {bound} ({unit})", value)
    return v


def _finite(value: Any, name: str, unit: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v):
        raise ParameterError(name, f"a finite number ({unit})", value)
    return v


def lobe_profile(t: np.ndarray, amplitude: float, segment_time: float) -> np.ndarray:
    """One "pair of lobes": 0 → +A → 0 → −A → 0, four cubic rest-to-rest legs.

    Args:
        t: times ``(T,)`` in s from the start of the pair (values outside
            ``[0, 4·segment_time]`` are clamped to the end points, i.e. 0).
        amplitude: A, in the unit of the returned offsets (mm or rad).
        segment_time: duration of each of the four legs in s.

    Returns:
        offsets ``(T,)`` from nominal. Each leg is ``start + (end − start)·s(τ)`` with
        ``s(τ) = 3τ² − 2τ³``, so position is continuous, velocity is zero at every knot, and the
        peak speed is ``1.5·A / segment_time`` (at the middle of each leg).
    """
    t = np.asarray(t, dtype=float)
    knots = np.array([0.0, amplitude, 0.0, -amplitude, 0.0])
    u = np.clip(t / segment_time, 0.0, 4.0)
    k = np.minimum(np.floor(u).astype(int), 3)
    tau = u - k
    return knots[k] + (knots[k + 1] - knots[k]) * _smoothstep(tau)


def paper_motion_phases(segment_time: float = 1.0, dwell: float = 1.0
                        ) -> list[tuple[str, float, float]]:
    """Time windows of :func:`paper_motion`: ``[(axis name, t_start, t_end), ...]`` in s.

    Axis names are those of :data:`PAPER_AXES` in the paper's order; each window is one pair of
    lobes (``4·segment_time`` long) and consecutive windows are separated by ``dwell``.
    """
    segment_time = _positive(segment_time, "segment_time", "s")
    dwell = _positive(dwell, "dwell", "s", allow_zero=True)
    out = []
    start = dwell
    for name, _ in PAPER_AXES:
        out.append((name, start, start + 4.0 * segment_time))
        start += 4.0 * segment_time + dwell
    return out


def paper_motion(mech: Mechanism, amplitude_mm: float = 2.0 * _MM_PER_IN,
                 amplitude_rad: float = math.radians(30.0), segment_time: float = 1.0,
                 dwell: float = 1.0, rate_hz: float = 100.0) -> tuple[np.ndarray, np.ndarray]:
    """The coordinated Cartesian test motion of Hopkins & Williams (2002), Sect. 6 / Fig. 13.

    Starting at ``mech.nominal_pose``, the axes ``x, y, z`` (by ``±amplitude_mm``) and then
    ``θz, θy, θx`` (by ``±amplitude_rad``, added to the nominal Z-Y-X Euler angles) move one
    at a time, each through a pair of lobes nominal → +A → nominal → −A → nominal (see
    :func:`lobe_profile`). The paper gives the amplitudes (±2 in, ±30°) and the shape
    ("sinusoidal-like third-order polynomial"), but not the time axis of Fig. 13.

    Timing assumption (defaults): each of the four cubic legs of a lobe pair takes
    ``segment_time = 1 s`` — the paper sized its motors to move the platform over the full range
    in 1 s — so one lobe lasts 2 s and one axis 4 s; the platform rests at nominal for
    ``dwell = 1 s`` before the first axis, between axes and after the last one (total
    ``6·4·segment_time + 7·dwell`` = 31 s). The paper's initial move from the bottom of the
    stroke to mid-workspace and the final return are not included.

    Sampling: each leg and each dwell is split into ``ceil(duration·rate_hz)`` equal steps, so
    every knot (nominal and the ±A peaks) is a sample; the step equals ``1/rate_hz`` whenever
    the durations are multiples of it (true for the defaults).

    Args:
        mech: the mechanism (only ``nominal_pose`` is used).
        amplitude_mm: translational amplitude in mm (default 50.8 mm = 2 in).
        amplitude_rad: rotational amplitude in rad (default 30°).
        segment_time: duration of one cubic leg (nominal ↔ peak) in s.
        dwell: rest at nominal between axes and at both ends, in s (may be 0).
        rate_hz: nominal sampling rate in Hz.

    Returns:
        ``(t, poses)``: times ``(T,)`` in s starting at 0, and tool poses ``(T, 6)`` (mm, rad).
    """
    amp_mm = _finite(amplitude_mm, "amplitude_mm", "mm")
    amp_rad = _finite(amplitude_rad, "amplitude_rad", "rad")
    rate = _positive(rate_hz, "rate_hz", "Hz")
    phases = paper_motion_phases(segment_time, dwell)
    segment_time, dwell = float(segment_time), float(dwell)

    # Knot times: dwell, then 4 legs per axis, then dwell, ...; each piece sampled uniformly.
    pieces = [dwell] + ([segment_time] * 4 + [dwell]) * len(PAPER_AXES)
    edges = np.concatenate([[0.0], np.cumsum(pieces)])
    chunks = [np.zeros(1)]
    for a, b in zip(edges[:-1], edges[1:]):
        if b > a:
            n = max(1, math.ceil((b - a) * rate - 1e-9))
            chunks.append(np.linspace(a, b, n + 1)[1:])
    t = np.concatenate(chunks)

    nominal = mech.nominal_pose
    poses = np.tile(nominal, (len(t), 1))
    for (name, t0, _t1), (_, idx) in zip(phases, PAPER_AXES):
        amp = amp_rad if name.startswith("theta") else amp_mm
        inside = (t >= t0) & (t <= t0 + 4.0 * segment_time)
        poses[inside, idx] += lobe_profile(t[inside] - t0, amp, segment_time)
    log.debug("paper motion: %d samples over %.3f s", len(t), t[-1])
    return t, poses


# ---------------------------------------------------------------------------------------------
# CSV input


def load_csv(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Read a trajectory from a CSV file.

    The first non-comment line is the header and must name exactly the columns
    ``t,x,y,z,theta_x,theta_y,theta_z`` (any order): time in s, position in mm, Z-Y-X Euler
    angles in deg. Blank lines and lines starting with ``#`` are skipped. Time must be finite
    and strictly increasing, and there must be at least two samples.

    Returns:
        ``(t, poses)``: times ``(T,)`` in s and poses ``(T, 6)`` in mm and rad.

    Raises:
        ParameterError: naming the file, line and column of the first problem (missing or
            unknown column, wrong field count, non-numeric or non-finite entry, time not
            increasing, fewer than two samples). ``FileNotFoundError`` if the file is missing.
    """
    path = Path(path)
    with path.open(newline="") as fh:
        lines = [(n, line) for n, line in enumerate(fh, start=1)
                 if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ParameterError(f"{path}", "a CSV file with header " + ",".join(CSV_COLUMNS),
                             "an empty file")
    rows = list(csv.reader([line for _, line in lines]))
    header_line = lines[0][0]
    header = [h.strip() for h in rows[0]]
    where = f"{path}:{header_line} (header)"
    dupes = sorted({h for h in header if header.count(h) > 1})
    if dupes:
        raise ParameterError(where, "each column named once", f"duplicate {dupes}")
    unknown = [h for h in header if h not in CSV_COLUMNS]
    if unknown:
        raise ParameterError(where, f"only the columns {list(CSV_COLUMNS)} (s, mm, deg)",
                             f"unknown column(s) {unknown}")
    missing = [c for c in CSV_COLUMNS if c not in header]
    if missing:
        raise ParameterError(where, f"all of the columns {list(CSV_COLUMNS)} (s, mm, deg)",
                             f"missing column(s) {missing}")
    order = [header.index(c) for c in CSV_COLUMNS]

    data = np.empty((len(rows) - 1, len(CSV_COLUMNS)))
    for r, (row, (lineno, _)) in enumerate(zip(rows[1:], lines[1:])):
        if len(row) != len(header):
            raise ParameterError(f"{path}:{lineno}", f"{len(header)} comma-separated fields",
                                 f"{len(row)} fields: {row}")
        for j, col in enumerate(order):
            text = row[col].strip()
            try:
                value = float(text)
            except ValueError:
                value = None
            if value is None or not math.isfinite(value):
                raise ParameterError(f"{path}:{lineno} column '{CSV_COLUMNS[j]}'",
                                     "a finite number", text)
            data[r, j] = value
    if len(data) < 2:
        raise ParameterError(f"{path}", "at least two data rows", len(data))
    t = data[:, 0]
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        k = int(bad[0]) + 1
        raise ParameterError(f"{path}:{lines[k + 1][0]} column 't'",
                             f"strictly increasing time (> {t[k - 1]:g} s on the previous row)",
                             float(t[k]))
    poses = np.concatenate([data[:, 1:4], np.radians(data[:, 4:7])], axis=1)
    log.debug("loaded %d samples from %s", len(t), path)
    return t.copy(), poses


# ---------------------------------------------------------------------------------------------
# checking


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
    """Result of :func:`check_trajectory` for T samples of a 6-actuator mechanism.

    Attributes:
        t: ``(T,)`` times in s.
        poses: ``(T, 6)`` tool poses (mm, rad).
        q: ``(T, 6)`` actuator values in mm (from ``mech.inverse``; NaN only where the sample's
            ``status`` says the pose has no inverse-kinematics solution).
        qdot: ``(T, 6)`` actuator speeds in mm/s, ``np.gradient(q, t)`` (second-order central
            differences inside, one-sided at the ends); NaN where a sample used for the
            difference has no solution (``status`` says so).
        force: ``(T, 6)`` static actuator forces in N holding the payload: the force each
            actuator applies along its own +q direction (positive pushes the moving side
            towards larger q), from ``Jᵀ·force = −wrench``. NaN where the Jacobian is singular
            or undefined (``status`` says so).
        wrench: ``(T, 6)`` the payload's gravity wrench at the tool-frame origin, base frame:
            ``[m·g (N); (R·payload_com) × m·g (N·mm)]``.
        condition: ``(T,)`` 2-norm condition number of the Jacobian (inf where undefined).
        ik_valid: ``(T,)`` ``mech.inverse(poses).valid``.
        ik_reason: ``(T,)`` ``mech.inverse(poses).reason_text``.
        status: ``(T,)`` ``"ok"`` or ``"; "``-joined list of the sample's problems.
        ok: ``(T,)`` True where ``status == "ok"``.
        violations: first :class:`Violation` per kind, keys ``"stroke"``, ``"jacobian"``,
            ``"speed"``, ``"force"`` (value ``None`` if that kind never occurs; speed and force
            are only checked when a limit was given).
        margin_low, margin_high: ``(6,)`` minimum over the samples with a solution of
            ``q − qmin`` and ``qmax − q`` in mm (negative: the stroke is exceeded by that much;
            NaN only if no sample has a solution).
        margin_low_index, margin_high_index: ``(6,)`` sample index of each minimum (−1 if none).
        actuator_names: actuator names, as ``mech.actuator_names``.
        actuator_limits: ``(6, 2)`` stroke [min, max] per actuator in mm.
        max_speed, max_force: ``(6,)`` limits used (mm/s, N), or ``None``.
        payload_mass_kg: payload mass in kg.
        fits: True when every sample is ``"ok"``: all poses valid and within stroke, no
            singular Jacobian, and no speed/force limit exceeded.
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

    @property
    def min_margin(self) -> tuple[float, str, int, str]:
        """Tightest stroke margin: ``(margin mm, actuator name, sample index, "min"/"max")``."""
        both = np.concatenate([self.margin_low, self.margin_high])
        if not np.any(np.isfinite(both)):
            return math.nan, "", -1, ""
        k = int(np.nanargmin(both))
        side = "min" if k < 6 else "max"
        idx = (self.margin_low_index if k < 6 else self.margin_high_index)[k % 6]
        return float(both[k]), self.actuator_names[k % 6], int(idx), side

    def summary(self) -> dict:
        """Plain-Python dict (JSON-serialisable) of the result.

        Keys: ``fits``, ``samples``, ``duration_s``, ``failing_samples``, ``violations``
        (first per kind, dicts or ``None``), ``min_margin_mm`` (value, actuator, time, side),
        ``margin_low_mm`` / ``margin_high_mm`` (per actuator), ``q_range_mm`` (per actuator
        [min, max]), ``peak_speed_mm_s`` and ``peak_force_n`` (per actuator, max |·| over the
        samples where defined; ``None`` if never defined), ``payload_mass_kg``, ``limits``.
        """
        names = self.actuator_names

        def per_actuator(values: np.ndarray) -> dict:
            return {n: (None if not np.isfinite(v) else float(v)) for n, v in zip(names, values)}

        def peak(a: np.ndarray) -> np.ndarray:
            finite = np.isfinite(a)
            out = np.full(6, np.nan)
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
            "limits": {
                "stroke_mm": self.actuator_limits.tolist(),
                "max_speed_mm_s": None if self.max_speed is None else self.max_speed.tolist(),
                "max_force_n": None if self.max_force is None else self.max_force.tolist(),
            },
        }


def _limit6(value: Any, name: str, unit: str) -> np.ndarray | None:
    if value is None:
        return None
    arr = np.asarray(value, dtype=float)
    if arr.shape == ():
        arr = np.full(6, float(arr))
    if arr.shape != (6,) or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ParameterError(name, f"None, a number > 0 ({unit}) or six of them",
                             value if np.ndim(value) else float(arr.ravel()[0]))
    return arr


def _readonly(*arrays: np.ndarray) -> None:
    for a in arrays:
        a.setflags(write=False)


def check_trajectory(mech: Mechanism, t: np.ndarray, poses: np.ndarray, *,
                     payload_mass_kg: float = 0.0, payload_com: Sequence[float] = (0.0, 0.0, 0.0),
                     gravity: Sequence[float] = (0.0, 0.0, -9810.0),
                     max_speed: float | Sequence[float] | None = None,
                     max_force: float | Sequence[float] | None = None,
                     stroke_tolerance: float = 1e-9) -> TrajectoryReport:
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
        poses: tool poses ``(T, 6)`` (mm, rad; non-finite entries are reported, not raised).
        payload_mass_kg: payload mass in kg (>= 0).
        payload_com: payload centre of mass ``(3,)`` in mm in the tool frame.
        gravity: gravitational acceleration ``(3,)`` in mm/s², base frame.
        max_speed: actuator speed limit in mm/s, scalar or ``(6,)``, compared with ``|q̇|``.
        max_force: actuator force limit in N, scalar or ``(6,)``, compared with ``|f|``.
        stroke_tolerance: round-off allowance in mm: an actuator value at most this far
            outside its window still counts as inside (a motion planned to touch a limit
            exactly, as the paper's z motion does, is not a violation).

    Returns:
        :class:`TrajectoryReport`.

    Raises:
        ParameterError: for malformed inputs (shapes, non-monotonic time, negative mass, ...).
    """
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
    if X.shape != (len(t), 6):
        raise ParameterError("poses", f"an array of shape ({len(t)}, 6) matching t (mm, rad)",
                             X.shape)
    mass = _positive(payload_mass_kg, "payload_mass_kg", "kg", allow_zero=True)
    com = np.asarray(payload_com, dtype=float)
    if com.shape != (3,) or not np.all(np.isfinite(com)):
        raise ParameterError("payload_com", "[x, y, z] in mm, tool frame", payload_com)
    g = np.asarray(gravity, dtype=float)
    if g.shape != (3,) or not np.all(np.isfinite(g)):
        raise ParameterError("gravity", "[gx, gy, gz] in mm/s², base frame", gravity)
    vmax = _limit6(max_speed, "max_speed", "mm/s")
    fmax = _limit6(max_force, "max_force", "N")

    names = tuple(mech.actuator_names)
    limits = np.asarray(mech.actuator_limits, dtype=float)
    lo, hi = limits[:, 0], limits[:, 1]
    T = len(t)

    # --- kinematics --------------------------------------------------------------------------
    tol = _positive(stroke_tolerance, "stroke_tolerance", "mm", allow_zero=True)
    qlo, qhi = mech.stroke
    ik = mech.inverse(X, stroke=(qlo - tol, qhi + tol))
    q = np.array(ik.q, dtype=float)
    ik_valid = np.asarray(ik.valid, dtype=bool)
    ik_reason = ik.reason_text
    has_q = np.all(np.isfinite(q), axis=1)
    qdot = np.gradient(q, t, axis=0)
    has_qdot = np.all(np.isfinite(qdot), axis=1)

    # --- statics -----------------------------------------------------------------------------
    finite_pose = np.all(np.isfinite(X), axis=1)
    J = np.full((T, 6, 6), np.nan)
    if np.any(finite_pose):
        with np.errstate(all="ignore"):
            J[finite_pose] = mech.jacobian(X[finite_pose])
    j_finite = np.all(np.isfinite(J), axis=(1, 2))
    condition = np.full(T, np.inf)
    if np.any(j_finite):
        condition[j_finite] = np.linalg.cond(J[j_finite])
    j_ok = j_finite & (condition < SINGULAR_CONDITION)

    wrench = np.full((T, 6), np.nan)
    F = mass * g * 1e-3                                          # kg·mm/s² → N
    if np.any(finite_pose):
        _, R = as_frames(X[finite_pose])
        r = R @ com                                              # (N, 3) mm, base frame
        wrench[finite_pose, :3] = F
        wrench[finite_pose, 3:] = np.cross(r, F)                 # N·mm
    force = np.full((T, 6), np.nan)
    if np.any(j_ok):
        Jt = np.swapaxes(J[j_ok], 1, 2)
        force[j_ok] = np.linalg.solve(Jt, -wrench[j_ok][..., None])[..., 0]

    # --- per-sample status and first violations -------------------------------------------------
    issues: list[list[str]] = [[] for _ in range(T)]
    violations: dict[str, Violation | None] = {"stroke": None, "jacobian": None, "speed": None,
                                               "force": None}

    for k in np.flatnonzero(~ik_valid):
        st = ik.leg_status[k]
        legs = [names[i] for i in range(6) if st[i] != 0]
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
            issues[k].append(f"singular Jacobian (condition {condition[k]:.3g}), no forces")
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
    margin_low = np.full(6, np.nan)
    margin_high = np.full(6, np.nan)
    idx_low = np.full(6, -1)
    idx_high = np.full(6, -1)
    for i in range(6):
        fin = np.isfinite(q[:, i])
        if fin.any():
            dl = np.where(fin, q[:, i] - lo[i], np.inf)
            dh = np.where(fin, hi[i] - q[:, i], np.inf)
            idx_low[i], idx_high[i] = int(np.argmin(dl)), int(np.argmin(dh))
            margin_low[i], margin_high[i] = dl[idx_low[i]], dh[idx_high[i]]

    fits = bool(ok.all())
    _readonly(t, X, q, qdot, force, wrench, condition, ik_valid, status, ok, margin_low,
              margin_high, idx_low, idx_high, limits)
    report = TrajectoryReport(
        t=t, poses=X, q=q, qdot=qdot, force=force, wrench=wrench, condition=condition,
        ik_valid=ik_valid, ik_reason=ik_reason, status=status, ok=ok, violations=violations,
        margin_low=margin_low, margin_high=margin_high, margin_low_index=idx_low,
        margin_high_index=idx_high, actuator_names=names, actuator_limits=limits,
        max_speed=vmax, max_force=fmax, payload_mass_kg=mass, fits=fits)
    log.debug("trajectory check: %d samples, fits=%s, %d failing", T, fits, int(np.sum(~ok)))
    return report


# ---------------------------------------------------------------------------------------------
# plotting


def plot_actuators(report: TrajectoryReport, path: str | Path, title: str | None = None,
                   phases: Sequence[tuple[str, float, float]] | None = None) -> Path:
    """Actuator values against time, as the paper's Fig. 13 (leg length in inches vs s).

    Draws one line per actuator (left axis in inches, right axis the same in mm), the stroke
    limits as dashed horizontal lines labelled in both units, samples whose status is not
    ``"ok"`` as red marks, and optionally the motion phases (e.g. :func:`paper_motion_phases`)
    as labelled bands. Writes a PNG with matplotlib's Agg canvas (pyplot and the global backend
    are not touched) and returns the path.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    path = Path(path)
    t = np.asarray(report.t)
    q_in = np.asarray(report.q) / _MM_PER_IN
    fig = Figure(figsize=(10, 5), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    for i, name in enumerate(report.actuator_names):
        ax.plot(t, q_in[:, i], lw=1.2, label=name)
    lim = np.asarray(report.actuator_limits)
    levels = sorted({(float(v), "min" if j == 0 else "max") for j in range(2)
                     for v in lim[:, j]})
    for v, side in levels:
        ax.axhline(v / _MM_PER_IN, color="k", ls="--", lw=0.9)
        ax.annotate(f"stroke {side} {v / _MM_PER_IN:.3g} in ({v:.4g} mm)",
                    xy=(1.0, v / _MM_PER_IN), xycoords=("axes fraction", "data"),
                    xytext=(-4, 3 if side == "max" else -11), textcoords="offset points",
                    ha="right", fontsize=8)
    bad = ~np.asarray(report.ok)
    if bad.any():
        # every actuator value of a failing sample; samples without a solution as bottom ticks
        tb = np.repeat(t[bad], 6)
        qb = q_in[bad].ravel()
        fin = np.isfinite(qb)
        ax.plot(tb[fin], qb[fin], "x", color="red", ms=5, mew=1.5, label="status not ok")
        none = bad & ~np.any(np.isfinite(q_in), axis=1)
        if none.any():
            ax.plot(t[none], np.zeros(int(none.sum())), "|", color="red", ms=10,
                    transform=ax.get_xaxis_transform(), label="no solution")
    if phases:
        for n, (name, a, b) in enumerate(phases):
            if n % 2 == 0:
                ax.axvspan(a, b, color="0.92", zorder=0)
            ax.annotate(name.replace("theta_", "θ"), xy=(0.5 * (a + b), 1.0),
                        xycoords=("data", "axes fraction"), xytext=(0, 2),
                        textcoords="offset points", ha="center", va="bottom", fontsize=8)
    ax.set_xlabel("Time (s)")
    ax.set_ylabel("Leg length L (in.)")
    lo_in, hi_in = ax.get_ylim()
    ax2 = ax.twinx()
    ax2.set_ylim(lo_in * _MM_PER_IN, hi_in * _MM_PER_IN)
    ax2.set_ylabel("Leg length L (mm)")
    ax.set_xlim(t[0], t[-1])
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), fontsize=8, ncol=8,
              frameon=False)
    if title:
        ax.set_title(title, pad=14 if phases else 6)
    fig.tight_layout()
    fig.savefig(path, format="png")
    log.debug("wrote %s", path)
    return path
