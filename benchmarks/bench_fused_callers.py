"""The κ maps, the GCI and the trajectory check with the fused Jacobian + κ kernel (issue 28
item 1, :mod:`pkmlab.dexterity._fused_exact`) against the unfused NumPy path, in one run.

Designs: a Sobol sample of the demo study's space (6-PSU, its ±15° dexterous workspace at
2.5 mm, 125 orientations) and of the 6-UPS layout study's (±10°, 20 mm, 27 orientations). For
each design, each caller runs with ``_fused_exact.FUSED`` off ("before") and on ("fused"),
alternately, ``--repeats`` times; the best CPU time (``time.process_time``, one numba thread as
in a study worker) of each counts. Callers:

* ``kappa map``: ``metric_map(mech, res, "kappa", L)`` over every occupied voxel (the export
  evaluates the drawn voxels only, the same function);
* ``GCI grid``: ``gci_grid`` (``kappa_grid``: κ at every voxel (column for the 6-PSU) ×
  orientation, and the inverse kinematics of every voxel × orientation, unchanged);
* ``GCI Monte Carlo``: ``gci_monte_carlo`` of the study's 2,000 sampled poses;
* ``check_trajectory`` and ``trajectory_fit`` (the study's trajectory evaluator) of the paper
  motion (3,100 samples).

Every output is compared with ``==`` (NaN equal to NaN) between the two paths.

    python benchmarks/bench_fused_callers.py [--designs N] [--repeats R]
"""

from __future__ import annotations

import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from _timing import identical
from scipy.stats import qmc

from pkmlab import dexterity as dx
from pkmlab.dexterity import _fused_exact, maps
from pkmlab.dexterity.aggregate import sample_poses
from pkmlab.errors import ParameterError
from pkmlab.motion import check_trajectory, paper_motion, trajectory_fit
from pkmlab.runtime.threads import single_thread_worker
from pkmlab.study import load_study
from pkmlab.workspaces import workspace

ROOT = Path(__file__).resolve().parents[1]
STUDIES = {"psu6": "studies/hopkins-6psu-redesign.yaml",
           "ups6": "studies/gough-stewart-6ups-layout.yaml"}


def _arg(name, default):
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def _callers(mech, res, length, poses, motion):
    t, X = motion.t, motion.poses
    return {
        "kappa map": lambda: maps.metric_map(mech, res, "kappa", length).values,
        "GCI grid": lambda: dx.gci_grid(mech, res, length).__dict__,
        "GCI Monte Carlo": lambda: dx.gci_monte_carlo(mech, res, length,
                                                      poses=poses).__dict__,
        "check_trajectory": lambda: (lambda r: (r.condition, r.force, r.status, r.summary()))(
            check_trajectory(mech, t, X, characteristic_length=length)),
        "trajectory_fit": lambda: (lambda f: (f.fits, f.margin_low, f.margin_high))(
            trajectory_fit(mech, t, X, characteristic_length=length)),
    }


def _cases(n: int):
    cases = []
    for fam, path in STUDIES.items():
        study = load_study(ROOT / path)
        space, request = study.space, study.evaluation.request
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            u = qmc.Sobol(d=len(space.variables), scramble=True, seed=0).random(4 * n)
        got = 0
        for r in u:
            if got == n:
                break
            try:
                mech = space.decode(space.from_unit(r))
            except ParameterError:
                continue
            res = workspace(mech, **request)
            if res.empty or res.mesh_problem is not None:
                continue
            mech = res.mechanism
            poses = sample_poses(res, 2000, np.random.default_rng(0))
            cases.append((fam, mech, res, dx.resolve_length(mech), poses, paper_motion(mech)))
            got += 1
    return cases


def main() -> None:
    n, repeats = _arg("--designs", 6), _arg("--repeats", 3)
    single_thread_worker()
    cases = _cases(n)
    for fam in STUDIES:                                       # warm-up (compilation)
        case = next(c for c in cases if c[0] == fam)
        for flag in (False, True):
            _fused_exact.FUSED = flag
            for f in _callers(*case[1:]).values():
                f()
    load0 = os.getloadavg()
    names = list(_callers(*cases[0][1:]))
    cpu = {(fam, k, flag): [] for fam in STUDIES for k in names for flag in (False, True)}
    same = {(fam, k): 0 for fam in STUDIES for k in names}
    count = {fam: 0 for fam in STUDIES}
    for fam, *case in cases:
        count[fam] += 1
        for name, f in _callers(*case).items():
            best, out = {False: np.inf, True: np.inf}, {}
            for _ in range(repeats):
                for flag in (False, True):
                    _fused_exact.FUSED = flag
                    c0 = time.process_time()
                    out[flag] = f()
                    best[flag] = min(best[flag], time.process_time() - c0)
            for flag in (False, True):
                cpu[fam, name, flag].append(best[flag])
            same[fam, name] += identical(out[False], out[True])
    _fused_exact.FUSED = True
    print(f"fused κ kernels vs the NumPy path: best of {repeats} per design and caller, "
          f"1 numba thread, CPU time; load average {load0[0]:.2f} -> "
          f"{os.getloadavg()[0]:.2f} (2 cores)")
    for fam in STUDIES:
        c = next(c for c in cases if c[0] == fam)
        print(f"{fam}: {count[fam]} designs of {STUDIES[fam]} (first: "
              f"{int(c[2].occupancy.sum())} voxels × {len(c[2].orientations.rotations())} "
              f"orientations, {len(c[5].t)} motion samples)")
        for name in names:
            a, b = np.array(cpu[fam, name, False]), np.array(cpu[fam, name, True])
            print(f"  {name:17s} before {1e3 * np.median(a):8.2f} ms, fused "
                  f"{1e3 * np.median(b):8.2f} ms (medians); {np.median(a / b):.2f}x per design "
                  f"(range {np.min(a / b):.2f}-{np.max(a / b):.2f}); identical "
                  f"{same[fam, name]} of {count[fam]}")


if __name__ == "__main__":
    main()
