"""Cost models of motions: samples, memory and time per sample of the motion generators, the
inverse dynamics and the stroke check (for the budgets, :mod:`pkmlab.runtime.memory` and
:mod:`pkmlab.runtime.time_budget`).

The per-sample constants were measured with ``tracemalloc`` and ``time.perf_counter`` on the
6-UPS (``benchmarks/budget_estimates.py`` compares the commands' estimates with their peaks): a
generated motion keeps about 150 B per sample, an inverse-dynamics result about 240 B (and
about 700 B while it is computed), the stroke check of a trajectory about 1.5 kB; the
constants below round these up so that the estimate errs large.
"""

from __future__ import annotations

import math

__all__ = ["paper_samples", "motion_samples", "MOTION_BYTES_PER_SAMPLE",
           "DYNAMICS_PEAK_BYTES_PER_SAMPLE", "DYNAMICS_SECONDS_PER_SAMPLE",
           "TRAJECTORY_BYTES_PER_SAMPLE", "TRAJECTORY_SECONDS_PER_SAMPLE",
           "TRAJECTORY_COMMAND_BYTES_PER_SAMPLE"]

#: bytes kept per sample of a required motion: the motion (t, pose, twist, acceleration) and
#: its inverse-dynamics result (forces, speeds, powers, flags)
MOTION_BYTES_PER_SAMPLE = 600.0
#: transient bytes per sample while one motion's inverse dynamics is computed
DYNAMICS_PEAK_BYTES_PER_SAMPLE = 1000.0
#: seconds per sample of the inverse dynamics (measured 1 µs on one core)
DYNAMICS_SECONDS_PER_SAMPLE = 5e-6
#: bytes and seconds per sample of the stroke check of a trajectory (measured 1.5 kB, 0.44 ms)
TRAJECTORY_BYTES_PER_SAMPLE = 2500.0
TRAJECTORY_SECONDS_PER_SAMPLE = 6e-4
#: bytes per sample of the ``trajectory`` command beyond its fixed memory: the motion, the
#: stroke check, the inverse dynamics, the report's arrays, the CSV rows as text and the
#: plot's lines (measured 0.8 kB: the peak rose 16.4 MiB from 3,101 to 24,701 samples,
#: ``benchmarks/budget_estimates.py``)
TRAJECTORY_COMMAND_BYTES_PER_SAMPLE = 1000.0
#: the paper motion: 6 axes × 4 cubic legs, 7 dwells of 1 s
_PAPER_LEGS, _PAPER_DWELLS = 24, 7


def paper_samples(segment_time: float, rate_hz: float, dwell: float = 1.0) -> float:
    """Samples of :func:`pkmlab.motion.paper.paper_motion` (each leg and dwell split into
    ``ceil(duration·rate)`` steps)."""
    return (_PAPER_LEGS * math.ceil(segment_time * rate_hz)
            + _PAPER_DWELLS * math.ceil(dwell * rate_hz) + 1.0)


def motion_samples(spec, recorded: dict) -> float:
    """Samples of one required motion (a :class:`~pkmlab.requirements.spec.MotionSpec`;
    ``recorded``: the CSV motions loaded, by name)."""
    if spec.paper:
        return paper_samples(spec.segment_time, spec.rate)
    if spec.sinusoid is not None:
        return max(2.0, round(spec.duration * spec.rate) + 1.0)
    return float(len(recorded[spec.name].t))
