"""The study's trajectory evaluator (issue 28 item 5): the full ``check_trajectory`` it called
before against the lean ``trajectory_fit`` it calls now, on the paper motion of sampled designs
of the demo study, in one run. CPU time (``time.process_time``) per design, one numba thread;
the verdict and margins of both are compared (they must be identical).

    python benchmarks/bench_trajectory_check.py [--designs N]
"""

from __future__ import annotations

import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.stats import qmc

from pkmlab.errors import ParameterError
from pkmlab.motion import check_trajectory, paper_motion, trajectory_fit
from pkmlab.runtime.threads import single_thread_worker
from pkmlab.study import load_study

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    n = int(sys.argv[sys.argv.index("--designs") + 1]) if "--designs" in sys.argv else 40
    single_thread_worker()
    space = load_study(ROOT / "studies/hopkins-6psu-redesign.yaml").space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=0).random(n)
    cases = []
    for r in u:
        try:
            mech = space.decode(space.from_unit(r))
        except ParameterError:
            continue
        m = paper_motion(mech)
        cases.append((mech, m.t, m.poses))
    for mech, t, X in cases[:2]:                                   # warm-up (compilation)
        check_trajectory(mech, t, X), trajectory_fit(mech, t, X)
    load0 = os.getloadavg()[0]
    cpu = {"check_trajectory": [], "trajectory_fit": []}
    same = 0
    for _ in range(3):                                             # interleaved repeats
        for mech, t, X in cases:
            c0 = time.process_time()
            rep = check_trajectory(mech, t, X)
            c1 = time.process_time()
            fit = trajectory_fit(mech, t, X)
            c2 = time.process_time()
            cpu["check_trajectory"].append(c1 - c0)
            cpu["trajectory_fit"].append(c2 - c1)
            same += (rep.fits == fit.fits and np.array_equal(rep.margin_low, fit.margin_low)
                     and np.array_equal(rep.margin_high, fit.margin_high))
    a, b = (1e3 * np.median(cpu[k]) for k in ("check_trajectory", "trajectory_fit"))
    print(f"trajectory evaluator, {len(cases)} designs x 3, {len(cases[0][1])} samples each; "
          f"load average {load0:.2f} -> {os.getloadavg()[0]:.2f} (2 cores)")
    print(f"  check_trajectory (before): {a:.2f} ms CPU per design (median)")
    print(f"  trajectory_fit   (now):    {b:.2f} ms CPU per design (median); {a / b:.2f}x")
    print(f"  identical fits and margins: {same} of {3 * len(cases)}")


if __name__ == "__main__":
    main()
