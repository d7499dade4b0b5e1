"""Shared helpers of the benchmark scripts: timing and bit-for-bit comparison."""

from __future__ import annotations

import math
import time

import numpy as np


def timed(fn, repeats: int = 7):
    """Median wall time of ``repeats`` calls of ``fn`` after one warm-up call (compilation,
    caches) → ``(seconds, last result)``."""
    fn()
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), out


def cpu_best(fns: dict, repeats: int = 7) -> dict:
    """Least CPU time (``time.process_time``) of each of ``fns`` over ``repeats`` rounds, the
    functions timed in turn within a round (so a change of load affects them alike), after one
    warm-up call each."""
    for fn in fns.values():
        fn()
    best = dict.fromkeys(fns, math.inf)
    for _ in range(repeats):
        for key, fn in fns.items():
            c = time.process_time()
            fn()
            best[key] = min(best[key], time.process_time() - c)
    return best


def identical(a, b) -> bool:
    """Equal nested results (dicts, lists, tuples, arrays, numbers), NaN equal to NaN, floats
    compared exactly."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(identical(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(identical(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc")
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b
