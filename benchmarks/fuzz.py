"""Fuzz the mechanism pipeline with random psu6 / ups6 / luzi3 geometries.

    python benchmarks/fuzz.py [N=10000] [seed=0]

Each case is loaded, solved at its nominal pose, reported and given a coarse workspace
(:func:`pkmlab._fuzz.check_mapping`). Declared errors (ParameterError, NumericalError) are
counted as outcomes; anything else, or a NaN reported as valid, is a crash and is printed with
the seed that reproduces it.
"""

from __future__ import annotations

import collections
import sys
import time
import traceback

import numpy as np

from pkmlab._fuzz import check_mapping, random_mapping


def main(n: int = 10_000, seed: int = 0) -> int:
    counts: collections.Counter = collections.Counter()
    crashes = 0
    t0 = time.perf_counter()
    for i in range(n):
        case = seed + i
        data = random_mapping(np.random.default_rng(case))
        try:
            counts[check_mapping(data)] += 1
        except Exception:  # noqa: BLE001 - a crash is what this script looks for
            crashes += 1
            sys.stdout.write(f"CRASH seed={case} {data['family']}\n{traceback.format_exc()}\n")
        if (i + 1) % 500 == 0:
            sys.stdout.write(f"{i + 1} cases, {crashes} crashes, {dict(counts)}, "
                             f"{time.perf_counter() - t0:.0f} s\n")
            sys.stdout.flush()
    sys.stdout.write(f"done: {n} cases, {crashes} crashes, outcomes {dict(counts)}, "
                     f"{time.perf_counter() - t0:.0f} s\n")
    return 1 if crashes else 0


if __name__ == "__main__":
    args = [int(a) for a in sys.argv[1:3]]
    raise SystemExit(main(*args))
