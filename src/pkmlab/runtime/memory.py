"""Memory budget: every request estimates the memory it needs before it allocates, and a
request that would not fit is refused as bad input (with a coarser setting that would fit).

The budget is ``PKMLAB_MEMORY_LIMIT`` (bytes, or with a unit: ``"2GiB"``, ``"500 MB"``) or, by
default, :data:`pkmlab.limits.MEMORY_FRACTION` of the machine's physical memory.
"""

from __future__ import annotations

import math
import os
import re

from ..errors import ParameterError, Shown
from ..limits import MEMORY_FRACTION

__all__ = ["memory_limit", "format_bytes", "require", "coarser_resolution",
           "readable_step", "BudgetError", "PROCESS_BYTES", "OUTPUT_BYTES"]

_UNITS = {"": 1, "b": 1, "k": 1e3, "kb": 1e3, "m": 1e6, "mb": 1e6, "g": 1e9, "gb": 1e9,
          "t": 1e12, "tb": 1e12, "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}
ENV = "PKMLAB_MEMORY_LIMIT"
#: resident set of a command before its own arrays (interpreter, numpy, scipy, numba, plotly
#: and the kernels loaded from the cache): measured 215-240 MB (benchmarks/memory_model.py);
#: a first run after an install also compiles the kernels, up to 0.75 GB once
PROCESS_BYTES = 240 * 2**20
#: fixed cost of a command beside the arrays its budget checks (small work arrays, plots,
#: meshes): a few MB (benchmarks/memory_model.py)
OUTPUT_BYTES = 8 * 2**20


class BudgetError(ParameterError):
    """A request does not fit the memory or time budget, or the budget's environment variable
    is not readable: a property of the machine and its settings, never of a design (a study
    run stops on it; it is never stored as a candidate's result)."""


def _physical() -> int:
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):       # pragma: no cover - not POSIX
        return 8 * 2**30


def memory_limit() -> int:
    """The memory budget in bytes (``PKMLAB_MEMORY_LIMIT`` or a share of physical memory)."""
    text = os.environ.get(ENV, "").strip()
    if not text:
        return int(MEMORY_FRACTION * _physical())
    m = re.fullmatch(r"([0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?)\s*([A-Za-z]*)", text)
    unit = m.group(2).lower() if m else None
    if m is None or unit not in _UNITS or not 0 < float(m.group(1)) * _UNITS[unit] < 2**62:
        raise BudgetError(ENV, "a size in bytes or with a unit (e.g. 2GiB, 500MB)", text)
    return int(float(m.group(1)) * _UNITS[unit])


def format_bytes(n: float) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} B"


def require(field: str, need: float, what: str, got: str, hint: str = "") -> None:
    """Raise :class:`ParameterError` on ``field`` if ``need`` bytes exceed the budget.

    The message reads ``<field>: must be <what> fit in <limit> (<hint>); got <got> needing
    <need>``.
    """
    limit = memory_limit()
    if need > limit:
        hint = f" ({hint})" if hint else ""
        raise BudgetError(field, f"{what} fit in {format_bytes(limit)}{hint}",
                          Shown(f"{got} needing {format_bytes(need)}"))


def coarser_resolution(h: float, need: float, exponent: float = 2.0) -> float:
    """A grid spacing that would fit: memory scales as ``h**-exponent``; rounded up to a
    readable value."""
    limit = memory_limit()
    return readable_step(h * (max(need, 1.0) / max(limit, 1)) ** (1.0 / exponent) * 1.05, h)


def readable_step(target: float, fallback: float) -> float:
    """The smallest of 1, 1.25, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k at least ``target``
    (``fallback`` when ``target`` is not a positive finite number)."""
    if not math.isfinite(target) or target <= 0:
        return fallback
    mag = 10 ** math.floor(math.log10(target))
    for step in (1, 1.25, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10):
        if step * mag >= target:
            return step * mag
    return 10 * mag                               # pragma: no cover
