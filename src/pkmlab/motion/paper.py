"""Trajectories to check: the paper's Cartesian test motion and time-stamped poses from CSV.

Units follow the rest of pkmlab: poses are ``(x, y, z, θx, θy, θz)`` of the tool frame in the
base frame in mm and rad (Z-Y-X Euler angles, :mod:`pkmlab.poses`), times in s.

* :func:`paper_motion` builds the coordinated Cartesian motion of Hopkins & Williams (2002),
  Sect. 6 / Fig. 13: from the nominal pose, "sinusoidal-like third-order polynomial" motions of
  ``x_H, y_H, z_H, θz, θy, θx`` one at a time, each a pair of lobes of ±2 in / ±30°.
* :func:`load_csv` reads a time-stamped pose list (``t,x,y,z,theta_x,theta_y,theta_z``; s, mm
  and deg).
"""

from __future__ import annotations

import csv
import logging
import math
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..limits import SEGMENT_TIME_S
from ..mechanisms.base import Mechanism
from ._args import finite as _finite
from ._args import positive as _positive

log = logging.getLogger(__name__)

__all__ = ["PAPER_AXES", "CSV_COLUMNS", "MM_PER_IN", "lobe_profile", "paper_motion_phases",
           "paper_motion", "load_csv"]

#: Order of the paper's Cartesian test motions (Sect. 6): name and index into the pose vector.
PAPER_AXES: tuple[tuple[str, int], ...] = (
    ("x", 0), ("y", 1), ("z", 2), ("theta_z", 5), ("theta_y", 4), ("theta_x", 3),
)

#: Columns of a trajectory CSV file and their units (converted to mm / rad on load).
CSV_COLUMNS: tuple[str, ...] = ("t", "x", "y", "z", "theta_x", "theta_y", "theta_z")

MM_PER_IN = 25.4


# ---------------------------------------------------------------------------------------------
# the paper's test motion


def _smoothstep(tau: np.ndarray) -> np.ndarray:
    """Cubic rest-to-rest blend ``s(τ) = 3τ² − 2τ³`` on [0, 1] (s' = 0 at both ends)."""
    return tau * tau * (3.0 - 2.0 * tau)


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
    lo_t, hi_t = SEGMENT_TIME_S
    if not lo_t <= segment_time <= hi_t:   # shorter: the motion collapses below the sampling
        raise ParameterError("segment_time", f"a duration in [{lo_t:g}, {hi_t:g}] s",
                             segment_time)
    dwell = _positive(dwell, "dwell", "s", allow_zero=True)
    out = []
    start = dwell
    for name, _ in PAPER_AXES:
        out.append((name, start, start + 4.0 * segment_time))
        start += 4.0 * segment_time + dwell
    return out


def paper_motion(mech: Mechanism, amplitude_mm: float = 2.0 * MM_PER_IN,
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
