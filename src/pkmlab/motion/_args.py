"""Argument validation shared by the trajectory modules (raises :class:`ParameterError`)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ParameterError


def positive(value: Any, name: str, unit: str, allow_zero: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise ParameterError(name, f"a finite number {bound} ({unit})", value)
    return v


def finite(value: Any, name: str, unit: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v):
        raise ParameterError(name, f"a finite number ({unit})", value)
    return v


def per_actuator(value: Any, name: str, unit: str, n: int) -> np.ndarray | None:
    """A limit given once or per actuator → ``(n,)`` positive finite values (None: no limit)."""
    if value is None:
        return None
    arr = np.asarray(value, dtype=float)
    if arr.shape == ():
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ParameterError(name, f"None, a number > 0 ({unit}) or one per actuator ({n})",
                             value if np.ndim(value) else float(arr.ravel()[0]))
    return arr
