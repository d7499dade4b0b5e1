"""Validation of the geometry every family's constructor checks: joint points, actuator
windows, positive lengths and vectors (each raising a ParameterError that names the field)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ParameterError
from ..tolerances import TOL

__all__ = ["as_points", "as_stroke", "as_positive", "as_vector3", "unit_rows",
           "without_component"]

#: a row whose norm is within this of 1 is already a unit vector and is kept as given, so that
#: normalising is idempotent: a mechanism rebuilt from its own fields (``with_parameters``) is
#: equal to it, bit for bit (x/|x| has a norm within a few ulp of 1, not exactly 1)
_UNIT_ULP = 8.0 * np.finfo(float).eps

def as_points(value: Any, field: str, count: int) -> np.ndarray:
    """Validate a ``(count, 3)`` array of finite coordinates with no two points coincident."""
    arr = np.asarray(value, dtype=float)
    if arr.shape != (count, 3):
        raise ParameterError(field, f"an array of shape ({count}, 3) in mm", arr.shape)
    if not np.all(np.isfinite(arr)):
        raise ParameterError(field, "finite coordinates", arr.tolist())
    d = np.linalg.norm(arr[:, None, :] - arr[None, :, :], axis=-1)
    i, j = np.triu_indices(count, 1)
    close = d[i, j] < TOL.coincident_mm
    if np.any(close):
        a, b = i[close][0], j[close][0]
        raise ParameterError(field, "distinct joint centres (no two closer than "
                             f"{TOL.coincident_mm:g} mm)",
                             f"points {a + 1} and {b + 1} coincide at {arr[a].tolist()}")
    arr = arr.copy()
    arr.setflags(write=False)
    return arr


def as_stroke(value: Any, field: str = "stroke", positive: bool = False) -> tuple[float, float]:
    """Validate an actuator window ``[min, max]`` with min < max (and min > 0 if ``positive``)."""
    arr = np.asarray(value, dtype=float)
    if arr.shape != (2,) or not np.all(np.isfinite(arr)):
        raise ParameterError(field, "[min, max], two finite numbers in mm", value)
    if arr[0] >= arr[1]:
        raise ParameterError(field, "[min, max] with min < max", arr.tolist())
    if positive and arr[0] <= 0:
        raise ParameterError(field, "[min, max] with 0 < min (a length)", arr.tolist())
    return float(arr[0]), float(arr[1])


def as_positive(value: Any, field: str, shape: tuple[int, ...] = ()) -> np.ndarray | float:
    arr = np.asarray(value, dtype=float)
    if shape and arr.shape == ():
        arr = np.full(shape, float(arr))
    if arr.shape != shape or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        what = "a length > 0 mm" if not shape else f"a length > 0 mm or {shape[0]} of them"
        raise ParameterError(field, what, value if arr.size > 1 else float(arr))
    return float(arr) if not shape else arr


def as_vector3(value: Any, field: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ParameterError(field, "[x, y, z], three finite numbers in mm", value)
    arr = arr.copy()
    arr.setflags(write=False)
    return arr


# ---------------------------------------------------------------------------------------------


def unit_rows(arr: np.ndarray) -> np.ndarray:
    """``arr (K, 3)`` with each non-zero row divided by its norm, except rows already of unit
    norm to 8 ulp (kept bit for bit: idempotent); zero rows stay zero."""
    arr = np.asarray(arr, dtype=float)
    n = np.linalg.norm(arr, axis=1)
    keep = (np.abs(n - 1.0) <= _UNIT_ULP) | (n == 0)
    return np.where(keep[:, None], arr, arr / np.where(keep, 1.0, n)[:, None])


def without_component(u: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Rows of ``u`` minus their component along the unit rows ``n`` (Gram-Schmidt), except
    rows already perpendicular to 8 ulp (kept bit for bit: idempotent)."""
    c = np.sum(u * n, axis=1, keepdims=True)
    small = np.abs(c) <= _UNIT_ULP * np.linalg.norm(u, axis=1, keepdims=True)
    return np.where(small, u, u - c * n)

