"""The exact worst case (issue 28 item 1): the fused Jacobian + bounds kernel against the unfused
path (NumPy Jacobians, then ``sweep_bounds``), on sampled designs of the demo study, in one run.

For each valid design of a Sobol sample of the demo study's space: its ±15° dexterous
workspace (the study's request), then ``pkmlab.dexterity.worst_case`` with
``worst.FUSED = False`` (before) and ``True`` (now), alternately, ``--repeats`` times each.
Reported: CPU time (``time.process_time``, one numba thread as in a study worker) per design,
the median ratio, the load average, and whether every output of the two is identical (the
whole ``WorstCase.as_dict()`` but its wall time, compared with ``==``, NaN equal to NaN).

    python benchmarks/bench_worst_case.py [--designs N] [--repeats R]
"""

from __future__ import annotations

import math
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.stats import qmc

from pkmlab import dexterity as dx
from pkmlab.dexterity import worst
from pkmlab.errors import ParameterError
from pkmlab.runtime.threads import single_thread_worker
from pkmlab.study import load_study
from pkmlab.workspaces import workspace

ROOT = Path(__file__).resolve().parents[1]


def _arg(name, default):
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def same(a, b) -> bool:
    """Equal as JSON-like values, NaN equal to NaN, floats compared exactly."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def summary(wc) -> dict:
    d = wc.as_dict()
    d.pop("seconds")
    return d


def main() -> None:
    n, repeats = _arg("--designs", 40), _arg("--repeats", 3)
    single_thread_worker()
    study = load_study(ROOT / "studies/hopkins-6psu-redesign.yaml")
    space, request = study.space, study.evaluation.request
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=0).random(n)
    cases = []
    for r in u:
        try:
            mech = space.decode(space.from_unit(r))
        except ParameterError:
            continue
        res = workspace(mech, **request)
        if res.empty:
            continue
        cases.append((res.mechanism, res, dx.resolve_length(res.mechanism)))
    load0 = os.getloadavg()
    mech, res, L = cases[0]
    for flag in (False, True):                                     # warm-up (compilation)
        worst.FUSED = flag
        dx.worst_case(mech, res, L, 150.0)
    cpu = {False: [], True: []}
    identical = 0
    sizes = []
    for mech, res, L in cases:
        t = {False: [], True: []}
        out = {}
        for _ in range(repeats):
            for flag in (False, True):
                worst.FUSED = flag
                c0 = time.process_time()
                out[flag] = dx.worst_case(mech, res, L, 150.0)
                t[flag].append(time.process_time() - c0)
        for flag in t:
            cpu[flag].append(min(t[flag]))
        identical += same(summary(out[False]), summary(out[True]))
        sizes.append(out[True].poses)
    worst.FUSED = True
    a, b = np.array(cpu[False]), np.array(cpu[True])
    print(f"exact worst case, {len(cases)} designs of the demo study (median "
          f"{np.median(sizes):,.0f} poses: units and column ends x orientations), best of "
          f"{repeats} per design, 1 numba thread; load average "
          f"{load0[0]:.2f} -> {os.getloadavg()[0]:.2f} (2 cores)")
    print(f"  unfused (before): {1e3 * np.median(a):.1f} ms CPU per design (median), "
          f"{1e3 * a.sum():.0f} ms in all")
    print(f"  fused   (now):    {1e3 * np.median(b):.1f} ms CPU per design (median), "
          f"{1e3 * b.sum():.0f} ms in all")
    print(f"  speed-up: {np.median(a / b):.2f}x per design (median; range "
          f"{np.min(a / b):.2f}-{np.max(a / b):.2f}), {a.sum() / b.sum():.2f}x in all")
    print(f"  identical results (every WorstCase field): {identical} of {len(cases)}")


if __name__ == "__main__":
    main()
