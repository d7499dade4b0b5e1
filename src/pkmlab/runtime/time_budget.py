"""Time budget: long requests estimate their run time before they start, log the estimate, and
a request estimated over the budget is refused as bad input (with a coarser setting that would
fit), like the memory budget of :mod:`pkmlab.runtime.memory`.

The budget is ``PKMLAB_TIME_LIMIT`` (seconds, or with a unit: ``"90s"``, ``"20min"``, ``"2h"``,
``"1d"``) or, by default, :data:`pkmlab.limits.TIME_LIMIT_S`.

The estimates are cost models, not promises:

* a workspace grid (:func:`workspace_seconds`) counts leg evaluations — columns × orientations
  × legs on the column method, voxels × orientations × legs on the sampled method — at the
  per-evaluation costs :data:`NS_PER_COLUMN_LEG` and :data:`NS_PER_VOXEL_LEG`, measured on one
  core by ``benchmarks/time_model.py`` (which re-measures them and compares the model with
  measured times; the constants are the slower end of those measurements, so the estimate is
  meant to err long, within a factor of about 3);
* a design study (:func:`study_seconds`) multiplies the evaluations still to do by the
  baseline design's measured evaluation time and divides by the parallel workers.
"""

from __future__ import annotations

import logging
import math
import os
import re

from ..errors import Shown
from ..limits import TIME_LIMIT_S
from .memory import BudgetError, readable_step

__all__ = ["time_limit", "format_seconds", "require_time", "workspace_seconds",
           "study_seconds", "coarser_for_time", "ENV", "NS_PER_COLUMN_LEG", "NS_PER_VOXEL_LEG"]

log = logging.getLogger(__name__)

ENV = "PKMLAB_TIME_LIMIT"
#: ns per (column, orientation, leg) on the column method (exact stroke intervals)
NS_PER_COLUMN_LEG = 10.0
#: ns per (voxel, orientation, leg) on the sampled method (inverse kinematics per voxel)
NS_PER_VOXEL_LEG = 60.0
#: fixed cost of one workspace request (set-up, components, cropping), s
OVERHEAD_S = 0.05
#: estimates at least this long are logged before the work starts
LOG_FROM_S = 5.0

_UNITS = {"": 1.0, "s": 1.0, "sec": 1.0, "m": 60.0, "min": 60.0, "h": 3600.0, "hr": 3600.0,
          "d": 86400.0, "day": 86400.0, "days": 86400.0}


def time_limit() -> float:
    """The time budget in seconds (``PKMLAB_TIME_LIMIT`` or :data:`TIME_LIMIT_S`)."""
    text = os.environ.get(ENV, "").strip()
    if not text:
        return float(TIME_LIMIT_S)
    m = re.fullmatch(r"([0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?)\s*([A-Za-z]*)", text)
    unit = m.group(2).lower() if m else None
    if m is None or unit not in _UNITS or not 0 < float(m.group(1)) * _UNITS[unit] < 1e9:
        raise BudgetError(ENV, "a duration in seconds or with a unit (e.g. 90s, 20min, "
                             "2h, 1d)", text)
    return float(m.group(1)) * _UNITS[unit]


def format_seconds(s: float) -> str:
    if not math.isfinite(s):
        return "forever"
    for unit, size in (("d", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if s >= size:
            return f"{s / size:.3g} {unit}"
    return f"{s:.2g} s"


def workspace_seconds(columns: int, orientations: int, legs: int, nz: int,
                      sampled: bool) -> float:
    """Estimated seconds of a workspace grid evaluation: ``columns`` (x, y) columns,
    ``orientations`` samples, ``legs`` legs and, on the sampled method, ``nz`` z levels."""
    n = float(columns) * orientations * legs
    if sampled:
        return OVERHEAD_S + n * max(nz, 1) * NS_PER_VOXEL_LEG * 1e-9
    return OVERHEAD_S + n * NS_PER_COLUMN_LEG * 1e-9


def study_seconds(remaining: int, seconds_per_evaluation: float, workers: int) -> float:
    """Estimated seconds of ``remaining`` evaluations at the measured ``seconds_per_evaluation``
    over ``workers`` parallel workers."""
    return remaining * max(seconds_per_evaluation, 0.0) / max(workers, 1)


def require_time(field: str, need: float, what: str, got: str, hint: str = "",
                 logger: logging.Logger | None = None) -> None:
    """Log an estimate of ``need`` seconds when it is long (on ``logger``, default this
    module's); raise :class:`ParameterError` on ``field`` if it exceeds the budget.

    The message reads ``<field>: must be <what> estimated to finish within <limit>
    (PKMLAB_TIME_LIMIT; <hint>); got <got> estimated at <need>``.
    """
    limit = time_limit()
    if need > limit:
        hint = f"; {hint}" if hint else ""
        raise BudgetError(field, f"{what} estimated to finish within "
                          f"{format_seconds(limit)} ({ENV}{hint})",
                          Shown(f"{got} estimated at {format_seconds(need)}"))
    if need >= LOG_FROM_S:
        (logger or log).info("%s: %s estimated at %s (budget %s, %s)", field, got,
                             format_seconds(need), format_seconds(limit), ENV)


def coarser_for_time(h: float, need: float, exponent: float) -> float:
    """A grid spacing whose estimate would fit: time scales as ``h**-exponent`` (2 on the
    column method, 3 on the sampled one); rounded up to a readable value."""
    target = h * (max(need - OVERHEAD_S, 1e-9) / max(time_limit() - OVERHEAD_S, 1e-9)) \
        ** (1.0 / exponent) * 1.05
    return readable_step(target, h)
