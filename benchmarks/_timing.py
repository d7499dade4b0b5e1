"""Shared timing helper of the benchmark scripts."""

from __future__ import annotations

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
