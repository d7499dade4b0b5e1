"""The paper's Cartesian test motion (Hopkins & Williams 2002, Sect. 6 / Fig. 13).

Units follow the rest of pkmlab: poses are ``(x, y, z, θx, θy, θz)`` of the tool frame in the
base frame in mm and rad (Z-Y-X Euler angles, :mod:`pkmlab.poses`), times in s.

:func:`paper_motion` builds, from the nominal pose, "sinusoidal-like third-order polynomial"
motions of ``x_H, y_H, z_H, θz, θy, θx`` one at a time, each a pair of lobes of ±2 in / ±30°,
as a :class:`~pkmlab.motion.motions.Motion` with the exact derivatives of its cubic lobes (the
acceleration jumps at the knots: each side's value is exact on its own segment). It is the one
paper motion of pkmlab: the trajectory check, ``compare``, the study evaluators and the
requirement motions all use it.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from ..errors import ParameterError
from ..limits import SEGMENT_TIME_S
from ..mechanisms.base import Mechanism
from ._args import finite as _finite
from ._args import positive as _positive
from .motions import Motion, make_motion

log = logging.getLogger(__name__)

__all__ = ["PAPER_AXES", "MM_PER_IN", "lobe_profile", "paper_motion_phases", "paper_motion",
           "paper_motion_poses"]

#: Order of the paper's Cartesian test motions (Sect. 6): name and index into the pose vector.
PAPER_AXES: tuple[tuple[str, int], ...] = (
    ("x", 0), ("y", 1), ("z", 2), ("theta_z", 5), ("theta_y", 4), ("theta_x", 3),
)

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
    return _lobes(t, amplitude, segment_time)[0]


def _lobes(t, amplitude: float, segment_time: float):
    """:func:`lobe_profile` and its first and second time derivatives (exact per leg)."""
    t = np.asarray(t, dtype=float)
    knots = np.array([0.0, amplitude, 0.0, -amplitude, 0.0])
    u = np.clip(t / segment_time, 0.0, 4.0)
    k = np.minimum(np.floor(u).astype(int), 3)
    tau = u - k
    dk = knots[k + 1] - knots[k]
    return (knots[k] + dk * _smoothstep(tau), dk * (6.0 * tau - 6.0 * tau * tau) / segment_time,
            dk * (6.0 - 12.0 * tau) / segment_time ** 2)


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
                 dwell: float = 1.0, rate_hz: float = 100.0, name: str = "paper") -> Motion:
    """The coordinated Cartesian test motion of Hopkins & Williams (2002), Sect. 6 / Fig. 13.

    Starting at ``mech.nominal_pose``, the axes ``x, y, z`` (by ``±amplitude_mm``) and then
    ``θz, θy, θx`` (by ``±amplitude_rad``, added to the nominal Z-Y-X Euler angles) move one
    at a time, each through a pair of lobes nominal → +A → nominal → −A → nominal (see
    :func:`lobe_profile`). The paper gives the amplitudes (±2 in, ±30°) and the shape
    ("sinusoidal-like third-order polynomial"), but not the time axis of Fig. 13. On a
    lower-mobility mechanism only its free coordinates move; the others rest at nominal
    during their windows (the timing is the same).

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
        name: the motion's name.

    Returns:
        a :class:`Motion`: times ``(T,)`` in s starting at 0, tool poses ``(T, 6)`` (mm, rad)
        and their exact derivatives.
    """
    t, poses, d1, d2 = _paper(mech, amplitude_mm, amplitude_rad, segment_time, dwell,
                              rate_hz, True)
    return make_motion(name, t, poses, d1, d2, "analytic")


def paper_motion_poses(mech: Mechanism, amplitude_mm: float = 2.0 * MM_PER_IN,
                       amplitude_rad: float = math.radians(30.0), segment_time: float = 1.0,
                       dwell: float = 1.0, rate_hz: float = 100.0
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The times ``(T,)`` and poses ``(T, 6)`` of :func:`paper_motion` (the same arrays),
    without its derivatives and twists: what a stroke and singularity check reads
    (:func:`pkmlab.motion.check.trajectory_fit`)."""
    return _paper(mech, amplitude_mm, amplitude_rad, segment_time, dwell, rate_hz, False)[:2]


def _paper(mech, amplitude_mm, amplitude_rad, segment_time, dwell, rate_hz, rates):
    """``(t, poses, d1, d2)`` of :func:`paper_motion` (``rates`` False: d1, d2 None)."""
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
    d1, d2 = (np.zeros_like(poses), np.zeros_like(poses)) if rates else (None, None)
    free = set(mech.mobility.coordinates)
    for (axis, t0, _t1), (_, idx) in zip(phases, PAPER_AXES):
        if axis not in free:        # a lower mobility: the axis keeps its nominal value
            continue
        amp = amp_rad if axis.startswith("theta") else amp_mm
        inside = (t >= t0) & (t <= t0 + 4.0 * segment_time)
        s0, s1, s2 = _lobes(t[inside] - t0, amp, segment_time)
        poses[inside, idx] += s0
        if rates:
            d1[inside, idx] = s1
            d2[inside, idx] = s2
    log.debug("paper motion: %d samples over %.3f s", len(t), t[-1])
    return t, poses, d1, d2
