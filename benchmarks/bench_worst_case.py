"""The exact worst case (issue 28 item 2), on sampled designs of the demo study, in one run:
the pass of the previous stop (the fused kernel, every sample evaluated, ``worst.CELLS =
False``) and the branch and bound over cells (:mod:`pkmlab.dexterity._cells`), with the
interval cell bounds only (``_cells.LINEAR = False``, the previous session's cells) and with
the first-order bounds (the default).

For each valid design of a Sobol sample of the demo study's space: its ±15° dexterous
workspace (the study's request), then ``pkmlab.dexterity.worst_case`` in the three modes,
alternately, ``--repeats`` times each. Reported: CPU time (``time.process_time``, one numba
thread as in a study worker) per design, the median ratios, the load average, and whether the
outputs are identical (the whole ``WorstCase.as_dict()`` but its wall time, compared with
``==``, NaN equal to NaN; for the cells also without ``exact``, the count of exact κ
evaluations, which pruning changes, and its mention in ``method``).

``--compare SRC`` instead runs the default mode (cells, first-order bounds) in fresh processes
with the sources in ``SRC`` (a baseline checkout's ``src``) and with this checkout's,
alternately, twice each after a round that fills their kernel caches, and reports the median
per-design ratio of the CPU times in that one run, the load average, and whether the two give
the same ``WorstCase.as_dict()`` (but its wall time) for every design, compared with ``==``
(session 6: the kernels call ``sweep_one`` instead of inlining it).

    python benchmarks/bench_worst_case.py [--designs N] [--repeats R] [--compare SRC]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from _timing import identical
from scipy.stats import qmc

from pkmlab import dexterity as dx
from pkmlab.dexterity import _cells, worst
from pkmlab.errors import ParameterError
from pkmlab.runtime.threads import single_thread_worker
from pkmlab.study import load_study
from pkmlab.workspaces import workspace

ROOT = Path(__file__).resolve().parents[1]


def _arg(name, default):
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def summary(wc, exact=True) -> dict:
    d = wc.as_dict()
    d.pop("seconds")
    if not exact:
        d.pop("exact_kappa_evaluations")
        d["method"] = d["method"].split("; exact κ at")[0]
    return d


#: mode -> (worst.CELLS, _cells.LINEAR): every sample; cells with the interval bounds only
#: (the previous stop's bound, on 3-column cells); cells with the first-order bounds where the
#: family has them (the default)
MODES = {"before": (False, False), "interval": (True, False), "cells": (True, True)}


def _mode(name):
    worst.CELLS, _cells.LINEAR = MODES[name]


def _cases(study, n):
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
    return cases


def _json_run(n: int, repeats: int) -> None:
    """The default mode on the designs, best of ``repeats``: one JSON line (CPU, summaries)."""
    single_thread_worker()
    cases = _cases(load_study(ROOT / "studies/hopkins-6psu-redesign.yaml"), n)
    dx.worst_case(*cases[0], 150.0)                                  # compilation
    cpu, out = [], []
    for mech, res, L in cases:
        t = []
        for _ in range(repeats):
            c0 = time.process_time()
            wc = dx.worst_case(mech, res, L, 150.0)
            t.append(time.process_time() - c0)
        cpu.append(min(t))
        out.append(summary(wc))
    print(json.dumps({"cpu": cpu, "out": out}, default=repr))


def compare(base_src: str, n: int, repeats: int) -> None:
    here = str(ROOT / "src")
    cpu = {"before": [], "now": []}
    outs = {}
    loads = [os.getloadavg()[0]]
    for rep in range(3):                       # the first round only fills the kernel caches
        for name, src in (("before", base_src), ("now", here)):
            env = {**os.environ, "PYTHONPATH": src,
                   "NUMBA_CACHE_DIR": f"/tmp/numba-bench-worst-{name}-{os.getuid()}"}
            proc = subprocess.run([sys.executable, __file__, "--json-run", "--designs", str(n),
                                   "--repeats", str(repeats)], env=env, capture_output=True,
                                  text=True, check=True)
            res = json.loads(proc.stdout.splitlines()[-1])
            if rep:
                cpu[name].append(res["cpu"])
                outs[name] = res["out"]
                loads.append(os.getloadavg()[0])
    a = np.min(np.array(cpu["before"]), axis=0)          # per design, best of the runs
    b = np.min(np.array(cpu["now"]), axis=0)
    print(f"exact worst case (cells, first-order bounds), {len(a)} designs of the demo study, "
          f"1 numba thread, CPU per design (best of {repeats} x 2 runs each, alternating); "
          f"load average {min(loads):.2f}-{max(loads):.2f} (2 cores)")
    print(f"  before ({base_src}): {1e3 * np.median(a):.1f} ms per design (median), "
          f"{1e3 * a.sum():.0f} ms in all")
    print(f"  now    ({here}): {1e3 * np.median(b):.1f} ms per design (median), "
          f"{1e3 * b.sum():.0f} ms in all")
    print(f"  ratio before/now: {np.median(a / b):.3f} per design (median; range "
          f"{np.min(a / b):.2f}-{np.max(a / b):.2f}), {a.sum() / b.sum():.3f} in all")
    print(f"  identical results (every field but the wall time), designs: "
          f"{sum(identical(x, y) for x, y in zip(outs['before'], outs['now']))} of {len(a)}")


def main() -> None:
    n, repeats = _arg("--designs", 40), _arg("--repeats", 3)
    if "--json-run" in sys.argv:
        return _json_run(n, repeats)
    if "--compare" in sys.argv:
        return compare(sys.argv[sys.argv.index("--compare") + 1], n, repeats)
    single_thread_worker()
    cases = _cases(load_study(ROOT / "studies/hopkins-6psu-redesign.yaml"), n)
    load0 = os.getloadavg()
    mech, res, L = cases[0]
    for name in MODES:                                             # warm-up (compilation)
        _mode(name)
        dx.worst_case(mech, res, L, 150.0)
    cpu = {name: [] for name in MODES}
    identical = {"cells": 0, "cells, every field": 0, "interval": 0}
    sizes = []
    for mech, res, L in cases:
        t = {name: [] for name in MODES}
        out = {}
        for _ in range(repeats):
            for name in MODES:
                _mode(name)
                c0 = time.process_time()
                out[name] = dx.worst_case(mech, res, L, 150.0)
                t[name].append(time.process_time() - c0)
        for name in t:
            cpu[name].append(min(t[name]))
        identical["cells"] += identical(summary(out["before"], False), summary(out["cells"], False))
        identical["cells, every field"] += identical(summary(out["before"]), summary(out["cells"]))
        identical["interval"] += identical(summary(out["before"], False),
                                      summary(out["interval"], False))
        sizes.append(out["before"].poses)
    _mode("cells")
    a = np.array(cpu["before"])
    print(f"exact worst case, {len(cases)} designs of the demo study (median "
          f"{np.median(sizes):,.0f} poses: units and column ends x orientations), best of "
          f"{repeats} per design, 1 numba thread; load average "
          f"{load0[0]:.2f} -> {os.getloadavg()[0]:.2f} (2 cores)")
    for name, label in (("before", "every sample (before)"),
                        ("interval", "cells, interval bounds"), ("cells", "cells (now)")):
        b = np.array(cpu[name])
        print(f"  {label:28s} {1e3 * np.median(b):6.1f} ms CPU per design (median), "
              f"{1e3 * b.sum():6.0f} ms in all; speed-up {np.median(a / b):.2f}x per design "
              f"(median; range {np.min(a / b):.2f}-{np.max(a / b):.2f}), "
              f"{a.sum() / b.sum():.2f}x in all")
    for k, v in identical.items():
        print(f"  identical results, {k}: {v} of {len(cases)}")


if __name__ == "__main__":
    main()
