"""CPU cost of the orientation capability's compiled search (issue 28, session 4).

Runs the ``cap`` kernel (:func:`pkmlab.mechanisms.kernels.search.make_capability`) with the
demo study's settings (5³ samples, 0.01°, the evaluator's tiles and cell budget) on ``N``
Sobol designs of a study (default the demo, ``studies/hopkins-6psu-redesign.yaml``), one numba
thread, and reports the CPU time per design (``time.process_time``).

``--compare SRC`` runs it in fresh processes with the sources in ``SRC`` (a baseline
checkout's ``src``) and with this checkout's, alternately, twice each after a round that
fills the kernel caches, and reports the ratio in that one run, the load average, and whether
the 13 outputs and the cut orientations are bit-identical for every design.
``--phases`` times the phases of the search instead (sampling, the branch and bound deciding
levels, the local branch and bound that picks the point to certify, the certification, the
upper end's bisection with the cuts), by running the kernel's own building blocks from a
Python copy of its driver; the outputs are checked against the kernel's.

    python benchmarks/bench_capability.py [--compare SRC | --phases] [N] [--study PATH]
        [--seed S]
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.stats import qmc

ROOT = Path(__file__).resolve().parents[1]
DEMO = "studies/hopkins-6psu-redesign.yaml"


def designs(study_path: str, n: int, seed: int = 0) -> list:
    """Mechanisms of ``n`` scrambled-Sobol points (after the first 16) of the study's space
    that the continuous search serves."""
    from pkmlab.study import load_study
    from pkmlab.workspaces.optima.search import supports_continuous

    space = load_study(ROOT / study_path).space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=seed).random(n + 16)
    out = []
    for r in u[16:]:
        try:
            m = space.decode(space.from_unit(r))
        except Exception:  # noqa: BLE001 - an invalid design is skipped
            continue
        if supports_continuous(m):
            out.append(m)
    return out


def _args(m):
    from pkmlab.mechanisms.kernels import ik
    from pkmlab.workspaces.optima import search as S

    e0, U, B, box = S._inputs(m)
    return (U, B, ik.carray(m.column_params()), S._profile(m), e0, 5, box, S.FIRST_TILE_MM,
            math.pi, math.radians(0.01), S.MIN_TILE_MM, S.MIN_HALF_RAD,
            S.CAPABILITY_CELL_BUDGET)


def run(study_path: str, n: int, seed: int) -> dict:
    """CPU seconds and outputs of the kernel per design, this process."""
    from pkmlab.mechanisms.kernels import search as K
    from pkmlab.runtime.threads import single_thread_worker

    single_thread_worker()
    mechs = designs(study_path, n, seed)
    cpu, outs = [], []
    for i, m in enumerate([mechs[0]] + mechs):          # the first call loads the kernel
        cap = K.make_capability(type(m).column_leg)
        out, cuts = np.full(13, np.nan), np.full((K.CUTS, 3), np.nan)
        a = _args(m)
        c0 = time.process_time()
        cap(*a, out, cuts)
        if i:
            cpu.append(time.process_time() - c0)
            outs.append([v.hex() for v in np.concatenate([out, cuts.ravel()]).tolist()])
    return {"cpu": cpu, "outs": outs}


def compare(base_src: str, n: int, study_path: str, seed: int) -> None:
    here = str(ROOT / "src")
    runs, outs, loads = {"before": [], "now": []}, {}, [os.getloadavg()[0]]
    for rep in range(3):                       # the first round only fills the kernel caches
        for name, src in (("before", base_src), ("now", here)):
            env = {**os.environ, "PYTHONPATH": src,
                   "NUMBA_CACHE_DIR": f"/tmp/numba-bench-cap-{name}-{os.getuid()}"}
            proc = subprocess.run([sys.executable, __file__, "--json", str(n), "--study",
                                   study_path, "--seed", str(seed)], env=env,
                                  capture_output=True, text=True, check=True)
            res = json.loads(proc.stdout.splitlines()[-1])
            if rep:
                runs[name].append(res["cpu"])
                outs[name] = res["outs"]
                loads.append(os.getloadavg()[0])
    med = {k: np.median([np.median(r) for r in v]) for k, v in runs.items()}
    tot = {k: np.median([np.sum(r) for r in v]) / len(v[0]) for k, v in runs.items()}
    print(f"{study_path}: the capability kernel on {len(outs['now'])} designs, one numba "
          f"thread, CPU per design (2 runs each, alternating); load average "
          f"{min(loads):.2f}-{max(loads):.2f} (2 cores)")
    for k, src in (("before", base_src), ("now", here)):
        print(f"  {k:6s} ({src}): median {1e3 * med[k]:.1f} ms, mean {1e3 * tot[k]:.1f} ms")
    print(f"  ratio: median {med['before'] / med['now']:.2f}x, mean "
          f"{tot['before'] / tot['now']:.2f}x; bit-identical outputs and cuts for every "
          f"design: {outs['before'] == outs['now']}")


def phases(n: int, study_path: str, seed: int) -> None:
    """CPU per phase (module notes) from a Python copy of the kernel's driver."""
    from pkmlab.mechanisms.kernels import search as K
    from pkmlab.runtime.threads import single_thread_worker

    single_thread_worker()
    mechs = designs(study_path, n, seed)
    T: dict = {}
    same = 0
    for i, m in enumerate([mechs[0]] + mechs):
        a = _args(m)
        out = _driver(K, type(m).column_leg, *a, T)
        if i == 0:                                  # compilation and loading
            T.clear()
        ref, cuts = np.full(13, np.nan), np.full((K.CUTS, 3), np.nan)
        K.make_capability(type(m).column_leg)(*a, ref, cuts)
        keep = [0, 1, 2, 9, 10, 11, 12]            # the ends, flags and counts
        same += bool(i and np.array_equal(out[keep], ref[keep], equal_nan=True))
    k = len(mechs)
    total = sum(v for key, v in T.items() if not key.endswith("#"))
    print(f"{study_path}: {k} designs, CPU per design by phase (Python driver; load "
          f"{os.getloadavg()[0]:.2f}); driver output = kernel output on {same} of {k}")
    for key in ("sample", "bb_levels", "bb_local", "certify", "bb_recut"):
        print(f"  {key:10s} {1e3 * T.get(key, 0.0) / k:7.2f} ms  {T.get(key + '#', 0) / k:9.1f}"
              f" {'cells' if key == 'certify' else 'calls'} per design")
    print(f"  {'total':10s} {1e3 * total / k:7.2f} ms")


_WRAPPERS: dict = {}


def _driver(K, leg, U, Bp, P, PR, e0, n, box, h0, theta_max, tol, min_size, min_half, budget,
            T):
    """The kernel's driver (search.make_capability's ``cap``) in Python over its compiled
    building blocks, with CPU time per phase added to ``T``."""
    import numba
    from numba.core.errors import NumbaIRAssumptionWarning

    warnings.simplefilter("ignore", NumbaIRAssumptionWarning)     # numba's pedantic check
    core = K._core(leg)
    if leg not in _WRAPPERS:
        smc, bbf, cf = core["sample_cuts"], core["branch_bound"], core["certify"]
        _WRAPPERS[leg] = (
            numba.njit(lambda U, Bp, e0, th, n, ex, ne, X: smc(U, Bp, e0, th, n, ex, ne, X)),
            numba.njit(lambda W, M, P, bx, h, ms, e, d, o: bbf(W, M, P, bx, h, ms, e, d, o)),
            numba.njit(lambda U, Bp, P, PR, e0, th, x, y, z, mh, b, bad:
                       cf(U, Bp, P, PR, e0, th, x, y, z, mh, b, bad)))
    sample_cuts, bb, cert = _WRAPPERS[leg]
    none = np.empty((0, 3))

    def timed(name, fn, *args, count=1):
        c0 = time.process_time()
        r = fn(*args)
        T[name] = T.get(name, 0.0) + time.process_time() - c0
        T[name + "#"] = T.get(name + "#", 0) + (count if count != "ret" else r[1])
        return r

    M = n ** 3
    W, r, out = np.empty((M, 6, 3)), np.empty(8), np.full(13, np.nan)
    flags = calls = 0
    timed("sample", sample_cuts, U, Bp, e0, 0.0, 1, none, 0, W)
    timed("bb_levels", bb, W, 1, P, box, h0, min_size, 0.0, True, r)
    calls += 1
    if r[0] != K.FEASIBLE:
        return out
    wx, wy = r[2], r[3]
    lo, hi = 0.0, theta_max
    timed("sample", sample_cuts, U, Bp, e0, hi, n, none, 0, W)
    timed("bb_levels", bb, W, M, P, box, h0, min_size, 0.0, True, r)
    calls += 1
    if r[0] == K.FEASIBLE:
        flags |= 1
        lo = hi
    elif r[0] == K.UNDECIDED:
        flags |= 4
    while hi - lo > 0.5 * tol and not flags & 1:
        mid = 0.5 * (lo + hi)
        timed("sample", sample_cuts, U, Bp, e0, mid, n, none, 0, W)
        timed("bb_levels", bb, W, M, P, box, h0, min_size, 0.0, True, r)
        calls += 1
        if r[0] == K.FEASIBLE:
            lo = mid
            wx, wy = r[2], r[3]
        elif r[0] == K.EMPTY:
            hi = mid
        else:
            flags |= 4
            break
    out[1], out[2] = hi, lo
    clo, chi, cells, first, found, step = 0.0, lo, 0, True, False, 10.0 * tol
    near = np.array([max(box[0], wx - K.LOCAL_MM), min(box[1], wx + K.LOCAL_MM),
                     max(box[2], wy - K.LOCAL_MM), min(box[3], wy + K.LOCAL_MM)])
    X, extra, ne, bad = np.empty((M + K.CUTS, 6, 3)), np.empty((K.CUTS, 3)), 0, np.empty(3)
    while (chi - clo > 0.5 * tol and hi - clo > tol) or first:
        if first:
            mid = chi
        elif found:
            mid = 0.5 * (clo + chi)
        else:
            mid = max(chi - step, 0.5 * (clo + chi) if clo > 0.0 else 0.0, 0.0)
            step *= 2.0
        ok = False
        for _ in range(K.CUTS_PER_LEVEL):
            timed("sample", sample_cuts, U, Bp, e0, mid, n, extra, ne, X)
            timed("bb_local", bb, X, M + ne, P, near, 0.5 * K.LOCAL_MM, min_size, K.MAX_EPS,
                  False, r)
            calls += 1
            if not r[1] >= 0.0:
                break
            px, py, pz = r[2], r[3], 0.5 * (r[4] + r[5])
            st, c = timed("certify", cert, U, Bp, P, PR, e0, mid, px, py, pz, min_half,
                          budget // 8, bad, count="ret")
            cells += c
            if st == 1:
                ok = found = True
                clo = mid
                break
            if st == -1:
                flags |= 8
                break
            if ne == K.CUTS or mid == 0.0:
                break
            extra[ne] = (bad - e0) / mid
            ne += 1
            if cells > budget:
                break
        if not ok:
            chi = mid
        first = False
        if cells > budget:
            flags |= 8
            break
    if ne > 0 and not flags & 5:
        slo = max(clo, 0.0)
        while hi - slo > 0.5 * tol and hi - clo > tol:
            mid = 0.5 * (slo + hi)
            timed("sample", sample_cuts, U, Bp, e0, mid, n, extra, ne, X)
            timed("bb_recut", bb, X, M + ne, P, box, h0, min_size, 0.0, True, r)
            calls += 1
            if r[0] == K.FEASIBLE:
                slo = mid
            elif r[0] == K.EMPTY:
                hi = mid
            else:
                flags |= 4
                break
        out[1] = hi
    out[0], out[9], out[10], out[11], out[12] = clo, flags, calls, cells, ne
    return out


def main(argv: list[str]) -> None:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", nargs="?", type=int, default=40)
    ap.add_argument("--study", default=DEMO)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--compare", metavar="SRC")
    ap.add_argument("--phases", action="store_true")
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.json:
        print(json.dumps(run(a.study, a.n, a.seed)))
    elif a.compare:
        compare(a.compare, a.n, a.study, a.seed)
    elif a.phases:
        phases(a.n, a.study, a.seed)
    else:
        cpu = run(a.study, a.n, a.seed)["cpu"]
        print(f"{a.study}: {len(cpu)} designs, CPU per design median "
              f"{1e3 * np.median(cpu):.1f} ms, mean {1e3 * np.mean(cpu):.1f} ms (load "
              f"{os.getloadavg()[0]:.2f})")

if __name__ == "__main__":
    main(sys.argv[1:])
