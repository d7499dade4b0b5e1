"""Threading policy (pkmlab.runtime.threads): OpenMP threads sleep, small calls and workers use one
numba thread. The busy-machine timings themselves are in benchmarks/bench_load.py."""

from __future__ import annotations

import os
import subprocess
import sys

import numba
import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab.runtime.threads import SMALL_WORK, threads_for
from pkmlab.study import runners

_PROBE = ("import os, pkmlab, numpy as np; "
          "m = pkmlab.load_mechanism({f!r}); m.inverse(np.tile(m.nominal_pose, (50000, 1))); "
          "print(os.environ.get('OMP_WAIT_POLICY'), os.environ.get('KMP_BLOCKTIME'))")


def _probe(env_extra: dict) -> str:
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_WAIT_POLICY", "KMP_BLOCKTIME")}
    env.update(env_extra)
    code = _PROBE.format(f=str(MECH_DIR / "hopkins-williams-6psu.yaml"))
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       timeout=120, check=True)
    return r.stdout.split()


def test_openmp_threads_sleep_by_default_and_user_setting_wins():
    assert _probe({}) == ["PASSIVE", "0"]
    assert _probe({"OMP_WAIT_POLICY": "ACTIVE"}) == ["ACTIVE", "0"]


def _threads_seen(work: int) -> int:
    with threads_for(work):
        return numba.get_num_threads()


def test_small_work_runs_on_one_thread_and_restores():
    before = numba.get_num_threads()
    assert _threads_seen(SMALL_WORK - 1) == 1
    assert _threads_seen(SMALL_WORK) == before
    assert numba.get_num_threads() == before


def test_small_ik_call_uses_one_thread(monkeypatch):
    """The IK driver runs under threads_for(n): a 10-pose call sees one thread, a large one
    keeps all of them (the driver is wrapped, not its results)."""
    mech = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
    seen = []
    real = numba.set_num_threads
    monkeypatch.setattr(numba, "set_num_threads", lambda n: (seen.append(n), real(n))[1])
    mech.inverse(np.tile(mech.nominal_pose, (10, 1)))
    if numba.config.NUMBA_NUM_THREADS > 1:
        assert seen[:1] == [1]
    seen.clear()
    mech.inverse(np.tile(mech.nominal_pose, (SMALL_WORK, 1)))
    assert seen == []


def _threads_in_task():
    return numba.get_num_threads()


def test_worker_tasks_run_on_one_numba_thread():
    assert runners._call(_threads_in_task, 7, (), None, True)[:2] == (7, 1)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    r = runners.JoblibRunner(2)
    try:
        out = dict(r.map(_threads_in_task, [(i, ()) for i in range(2)]))
    finally:
        r.close()
    assert out == {0: 1, 1: 1}


_HEAVY = ("pkmlab.study", "scipy.optimize", "scipy.signal", "scipy.spatial", "matplotlib",
          "trimesh", "distributed", "plotly", "pymoo", "pandas", "joblib")
#: what a study worker must not import before it needs it (its first result, issue 14)
_WORKER_HEAVY = ("scipy.optimize", "scipy.signal", "scipy.spatial", "scipy.sparse.csgraph",
                 "matplotlib", "trimesh", "plotly", "pymoo")


def test_cli_import_leaves_heavy_modules_for_the_commands_that_use_them():
    """Cold start (issue 14): the CLI's import stays light; scipy.optimize alone took 0.28 s
    and the study package (evaluators → requirements → scipy.signal) more."""
    code = ("import sys, pkmlab.cli; "
            f"print(' '.join(m for m in {_HEAVY!r} if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=120, check=True)
    assert r.stdout.split() == []
    # a study worker imports the study package: the stroke search's scipy.optimize and the
    # cell bracket's k-d trees (0.12 s together) wait until they are used
    code = ("import sys, pkmlab.study; "
            f"print(' '.join(m for m in {_WORKER_HEAVY!r} if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=120, check=True)
    assert r.stdout.split() == []


_FAULTS = """
import resource, sys, threading
import numpy as np
from pkmlab.study import runners

def churn():
    for _ in range(200):                  # a 1 MiB temporary, touched, freed: numpy's pattern
        a = np.empty(1 << 17)
        a[:] = 1.0
    return 0

out = {}
def task():                               # a Dask task runs in a worker's executor thread
    runners._call(lambda: None, 0, (), None, sys.argv[1] == "worker")   # set-up of a task
    r0 = resource.getrusage(resource.RUSAGE_THREAD).ru_minflt
    churn()
    out["faults"] = resource.getrusage(resource.RUSAGE_THREAD).ru_minflt - r0

t = threading.Thread(target=task)
t.start(); t.join()
print(out["faults"])
"""


def test_worker_tasks_do_not_page_fault_under_dasks_malloc_setting():
    """Dask's nanny sets MALLOC_TRIM_THRESHOLD_=65536, which turns off glibc's dynamic mmap
    threshold: every array above 128 KiB was mapped afresh and faulted in page by page (37,000
    faults and 92 ms of system time per demo candidate, the whole Dask/joblib gap). A worker's
    task set-up restores heap allocation; outside a worker nothing changes."""
    if not sys.platform.startswith("linux"):
        pytest.skip("glibc malloc behaviour (Linux)")
    env = dict(os.environ, MALLOC_TRIM_THRESHOLD_="65536")
    faults = {}
    for mode in ("plain", "worker"):
        r = subprocess.run([sys.executable, "-c", _FAULTS, mode], env=env, capture_output=True,
                           text=True, check=True)
        faults[mode] = int(r.stdout.strip().splitlines()[-1])
    assert faults["plain"] > 20_000, faults        # 200 × 256 pages: the defect reproduces
    assert faults["worker"] < 2_000, faults
