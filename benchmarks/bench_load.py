"""Study speed on a busy machine: candidates/s with and without a competing OpenMP load.

Each measurement runs in a fresh child process (the OpenMP runtime reads its wait policy once,
at start-up), with the kernels already cached:

* **small calls**: the median time of one parallel IK call on 1,000 and on 200,000 poses;
* **candidates**: the median time of one demo-study candidate (studies/hopkins-6psu-redesign
  .yaml: ±15° dexterous workspace, capability, GCI, the paper's motion), evaluated serially;
* **runners**: candidates/s of 2 joblib (loky) workers and of a local Dask cluster with 2
  single-thread worker processes, on the same candidates.

Each is measured quiet and beside a competing load: another process running a parallel numba
loop on both cores under libgomp's default (spinning) wait policy, as another OpenMP program
would. "before" is libgomp's default wait policy (``OMP_WAIT_POLICY`` set to an empty value,
which libgomp ignores with a warning, so pkmlab's default does not apply); "after" is pkmlab's
default (:mod:`pkmlab.runtime.threads`). Targets (issue 14): the per-candidate time loaded
within 1.5× of quiet, and Dask at least as fast as joblib. "Quiet" means no load of ours; the
load average printed first says how quiet the machine was.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable

_LOAD = textwrap.dedent("""
    import numpy as np
    from numba import njit, prange
    @njit(parallel=True)
    def spin(a):
        for i in prange(a.size):
            a[i] = np.sqrt(a[i] + 1.0)
    a = np.ones(20_000)
    while True:
        spin(a)
""")

_CHILD = textwrap.dedent("""
    import json, sys, time, warnings
    import numpy as np
    from pathlib import Path
    from scipy.stats import qmc
    import pkmlab
    from pkmlab.study import evaluate_design, load_study
    what, n = sys.argv[1], int(sys.argv[2])
    root = Path(sys.argv[3])
    out = {}
    if what == "calls":
        mech = pkmlab.load_mechanism(root / "studies/mechanisms/hopkins-williams-6psu.yaml")
        for size in (1_000, 200_000):
            X = np.tile(mech.nominal_pose, (size, 1))
            mech.inverse(X)
            ts = []
            for _ in range(n):
                t = time.perf_counter(); mech.inverse(X); ts.append(time.perf_counter() - t)
            out[f"ik_{size}_ms"] = 1e3 * float(np.median(ts))
    else:
        study = load_study(root / "studies/hopkins-6psu-redesign.yaml")
        space = study.space
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            u = qmc.Sobol(d=len(space.variables), scramble=True, seed=0).random(n + 4)
        tasks = [(i, (space, space.from_unit(r), study.evaluation, study.seed))
                 for i, r in enumerate(u)]
        if what == "serial":
            for _, args in tasks[:4]:
                evaluate_design(*args)
            ts = []
            for _, args in tasks[4:]:
                t = time.perf_counter(); evaluate_design(*args); ts.append(time.perf_counter() - t)
            out["candidate_ms"] = 1e3 * float(np.median(ts))
        else:
            if what == "joblib":
                from pkmlab.study.runners import JoblibRunner
                runner = JoblibRunner(2)
            else:
                from distributed import Client, LocalCluster
                cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
                from pkmlab.study.runners import DaskRunner
                runner = DaskRunner(client=Client(cluster))
            list(runner.map(evaluate_design, tasks[:8]))        # warm-up
            t = time.perf_counter()
            list(runner.map(evaluate_design, tasks[4:]))
            out["candidates_per_s"] = n / (time.perf_counter() - t)
            runner.close()
    print(json.dumps(out))
""")


def _child(what: str, n: int, policy: str | None) -> dict:
    env = dict(os.environ)
    env.pop("OMP_WAIT_POLICY", None)
    if policy is not None:
        env["OMP_WAIT_POLICY"] = policy
    env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    r = subprocess.run([PY, "-c", _CHILD, what, str(n), str(ROOT)], env=env,
                       capture_output=True, text=True)
    if r.returncode:
        sys.exit(f"{what} child failed:\n{r.stderr}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def _measure(what, n, policy, loaded):
    load = None
    if loaded:
        env = dict(os.environ, OMP_WAIT_POLICY="")
        load = subprocess.Popen([PY, "-c", _LOAD], env=env, stderr=subprocess.DEVNULL)
        time.sleep(2.0)                         # its kernel compiles before we measure
    try:
        return _child(what, n, policy)
    finally:
        if load is not None:
            load.kill()
            load.wait()


def main() -> None:
    quick = "--quick" in sys.argv
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores)")
    policies = {"before (libgomp default)": "", "after (pkmlab default)": None}
    rows = []
    for label, pol in policies.items():
        for loaded in (False, True):
            calls = _measure("calls", 200, pol, loaded)
            cand = _measure("serial", 12 if quick else 30, pol, loaded)
            rows.append((label, loaded, calls, cand))
            print(f"{label:26s} {'loaded' if loaded else 'quiet ':6s}  "
                  f"IK 1k poses {calls['ik_1000_ms']:7.3f} ms  "
                  f"IK 200k {calls['ik_200000_ms']:7.3f} ms  "
                  f"candidate {cand['candidate_ms']:7.1f} ms", flush=True)
    for label in policies:
        q, lo = [r[3]["candidate_ms"] for r in rows if r[0] == label]
        print(f"{label}: candidate time loaded/quiet = {lo / q:.2f} (target <= 1.5 after)")
    n = 40 if quick else 120
    for loaded in (False, True):
        jl = _measure("joblib", n, None, loaded)["candidates_per_s"]
        dk = _measure("dask", n, None, loaded)["candidates_per_s"]
        print(f"runners {'loaded' if loaded else 'quiet '}: joblib {jl:5.1f} candidates/s, "
              f"dask {dk:5.1f} candidates/s (dask/joblib {dk / jl:.2f}, target >= 1)",
              flush=True)


if __name__ == "__main__":
    main()
