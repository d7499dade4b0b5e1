"""Candidates per second for the demo study's evaluation (studies/hopkins-6psu-redesign.yaml).

Evaluates Sobol samples of the demo study's design space with its full evaluation (±15°
dexterous workspace, orientation capability over continuous positions, Monte-Carlo GCI, the
paper's motion) on 2 joblib workers, after one warm-up batch per worker (numba
compilation), and prints the rate and the time 5,000 candidates take at that rate.
``--full`` evaluates all 5,000.
Target on 2 cores: 5,000 candidates in ≤ 5 minutes.

On a shared machine wall time measures the other users too. ``--cpu`` evaluates the same
candidates in this process instead, one numba thread (as a study worker), and reports the CPU
time per candidate (``time.process_time``) and the rate two idle cores would give.
``--compare SRC`` runs ``--cpu`` alternately with the sources in ``SRC`` (a baseline checkout's
``src``) and with this checkout's, twice each, in fresh processes with their own kernel caches,
and reports the ratio in that one run (issue 28), with the load average and whether the two
give identical metrics for every candidate.
``--ladder [G]`` runs the demo study (its NSGA-II, ``G`` generations, default its own) in this
process, one numba thread, twice: as it is and with ``tolerance_ladder: {coarse: {angle: A,
length: 0.1 mm, worst_case: W}}`` (``--coarse A W``: A in deg, default 0.1; W ``bound``, the
default, or ``exact``); it reports the CPU time per candidate of each (the ladder's includes
its re-certification), the ratio in that one run, how many candidates were refined and pruned,
and whether every candidate both runs evaluated has identical final metrics (issue 28).
``--ladder-compare SRC [G]`` runs ``--ladder`` in fresh processes alternately with the sources
in ``SRC`` and this checkout's (twice each, after a round that fills the kernel caches) and
reports both rates of each and the ratios in that one run, and whether the ladder runs' Pareto
records are identical (issue 28, session 5).
``--ladder-sobol N`` does the same with the demo's evaluation on N Sobol candidates instead
of its NSGA-II (the same candidates in both runs: the fronts and the exported designs must be
the same).

    python benchmarks/bench_study.py [--full | --cpu [N] | --compare SRC [N] | --ladder [G]
                                      | --ladder-compare SRC [G] | --ladder-sobol N]
                                      [--coarse A W]
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
from scipy.stats import qmc

from pkmlab.study import evaluate_design, load_study
from pkmlab.study.runners import JoblibRunner

ROOT = Path(__file__).resolve().parents[1]


def _tasks(study, n):
    space = study.space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)        # n need not be a power of 2
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=0).random(n + 16)
    return [(i, (space, space.from_unit(r), study.evaluation, study.seed))
            for i, r in enumerate(u)]


def cpu_mode(n: int) -> dict:
    """CPU seconds per candidate in this process (one numba thread), after 4 warm-ups."""
    from pkmlab.runtime.threads import single_thread_worker

    single_thread_worker()
    study = load_study(ROOT / "studies/hopkins-6psu-redesign.yaml")
    tasks = _tasks(study, n)
    for _, args in tasks[:4]:
        evaluate_design(*args)
    cpu, metrics = [], []
    for _, args in tasks[16:16 + n]:
        c0 = time.process_time()
        r = evaluate_design(*args)
        cpu.append(time.process_time() - c0)
        metrics.append({k: r[k] for k in sorted(r) if k not in ("seconds", "timings")})
    return {"cpu": cpu, "metrics": json.dumps(metrics, sort_keys=True, default=str)}


def compare(base_src: str, n: int) -> None:
    here = str(ROOT / "src")
    runs = {"before": [], "now": []}
    out = {}
    loads = [os.getloadavg()[0]]
    for rep in range(3):                       # the first round only fills the kernel caches
        for name, src in (("before", base_src), ("now", here)):
            env = {**os.environ, "PYTHONPATH": src,
                   "NUMBA_CACHE_DIR": f"/tmp/numba-bench-study-{name}-{os.getuid()}"}
            proc = subprocess.run([sys.executable, __file__, "--cpu-json", str(n)], env=env,
                                  capture_output=True, text=True, check=True)
            res = json.loads(proc.stdout.splitlines()[-1])
            if rep:
                runs[name].append(np.median(res["cpu"]))
                out[name] = res["metrics"]
                loads.append(os.getloadavg()[0])
    a, b = np.median(runs["before"]), np.median(runs["now"])
    print(f"demo study, {n} candidates per run, one numba thread, CPU time per candidate "
          f"(median; 2 runs each, alternating); load average {min(loads):.2f}-{max(loads):.2f}"
          " (2 cores)")
    print(f"  before ({base_src}): {1e3 * a:.0f} ms -> {2 / a:.1f} candidates/s on 2 idle cores")
    print(f"  now    ({here}): {1e3 * b:.0f} ms -> {2 / b:.1f} candidates/s on 2 idle cores")
    print(f"  ratio: {a / b:.2f}x; identical metrics for every candidate: "
          f"{out['before'] == out['now']}")


def _run_demo(tmp: Path, name: str, generations: int | None, ladder: dict | None,
              sobol: int | None = None):
    import yaml

    from pkmlab.study import SerialRunner, run_study
    from pkmlab.study.report import pareto_records

    data = yaml.safe_load((ROOT / "studies/hopkins-6psu-redesign.yaml").read_text())
    data["mechanism"]["file"] = str(ROOT / "studies" / data["mechanism"]["file"])
    data["output"] = str(tmp / name)
    if generations:
        data["optimizer"]["generations"] = generations
    if sobol:
        data["optimizer"] = {"method": "sobol", "samples": sobol}
    if ladder:
        data["tolerance_ladder"] = ladder
    path = tmp / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    study = load_study(path)
    c0 = time.process_time()
    store = run_study(study, SerialRunner())
    cpu = time.process_time() - c0
    records = store.all()
    meta = store.get_meta("ladder")
    store.close()
    return cpu, records, pareto_records(study, records), meta


def ladder_mode(generations: int | None, coarse: dict, sobol: int | None = None,
                json_out: bool = False) -> None:
    import tempfile

    from pkmlab.runtime.threads import single_thread_worker

    single_thread_worker()
    loads = [os.getloadavg()[0]]
    with tempfile.TemporaryDirectory() as tmp:
        _run_demo(Path(tmp), "warm", 1, None)              # kernels loaded / compiled
        loads.append(os.getloadavg()[0])
        c0, r0, f0, _ = _run_demo(Path(tmp), "plain", generations, None, sobol)
        loads.append(os.getloadavg()[0])
        c1, r1, f1, meta = _run_demo(Path(tmp), "ladder", generations, {"coarse": coarse},
                                     sobol)
        loads.append(os.getloadavg()[0])
    fine = {json.dumps(r["params"], sort_keys=True): r for r in r0}

    def final(r):            # without the ladder's coarse copies
        return {m: v for m, v in r["metrics"].items() if not m.endswith("_coarse")}
    same = [fine[k]["metrics"] == final(r) for r in r1 if r["status"] == "ok"
            and (k := json.dumps(r["params"], sort_keys=True)) in fine]
    fsame = [fine[k]["metrics"] == final(r) for r in f1
             if (k := json.dumps(r["params"], sort_keys=True)) in fine]
    n0, n1 = len(r0), len(r1)
    if json_out:
        print(json.dumps({"plain": c0 / n0, "ladder": c1 / n1, "n": [n0, n1], "meta": meta,
                          "same": [sum(same), len(same)], "load": [min(loads), max(loads)],
                          "pareto": {json.dumps(r["params"], sort_keys=True): final(r)
                                     for r in f1}}, default=str))
        return
    how = (f"{sobol} Sobol candidates" if sobol else
           f"NSGA-II, {generations or 'its own'} generations")
    print(f"demo study ({how}), one numba thread, CPU per candidate; ladder {coarse}; load "
          f"average {min(loads):.2f}-{max(loads):.2f} (2 cores)")
    print(f"  without the ladder: {n0} evaluations, {c0:.1f} s CPU, {1e3 * c0 / n0:.0f} ms "
          f"-> {2 * n0 / c0:.1f} candidates/s on 2 idle cores")
    print(f"  with the ladder:    {n1} evaluations, {c1:.1f} s CPU, {1e3 * c1 / n1:.0f} ms "
          f"-> {2 * n1 / c1:.1f} candidates/s on 2 idle cores ({meta})")
    print(f"  ratio {(c0 / n0) / (c1 / n1):.2f}x; candidates in both runs with identical final "
          f"metrics: {sum(same)} of {len(same)}; Pareto records of the ladder run with the "
          f"plain run's metrics: {sum(fsame)} of {len(fsame)} found in it (fronts: {len(f0)} "
          f"and {len(f1)} records); same Pareto designs: "
          f"{sorted(_key(r) for r in f0) == sorted(_key(r) for r in f1)}")


def ladder_compare(base_src: str, generations: int | None, rounds: int = 2) -> None:
    """``--ladder`` in fresh processes, alternately with the sources in ``base_src`` and this
    checkout's (own kernel caches; a first round fills them), ``rounds`` times each."""
    here = str(ROOT / "src")
    runs = {"before": [], "now": []}
    args = [str(generations)] if generations else []
    for rep in range(rounds + 1):
        for name, src in (("before", base_src), ("now", here)):
            env = {**os.environ, "PYTHONPATH": src,
                   "NUMBA_CACHE_DIR": f"/tmp/numba-bench-study-{name}-{os.getuid()}"}
            proc = subprocess.run([sys.executable, __file__, "--ladder-json", *args], env=env,
                                  capture_output=True, text=True, check=True)
            if rep:
                runs[name].append(json.loads(proc.stdout.splitlines()[-1]))
    loads = [x for v in runs.values() for r in v for x in r["load"]]
    print(f"demo study (NSGA-II, {generations or 'its own'} generations), one numba thread, CPU "
          f"per candidate, {rounds} runs of each source alternating, fresh processes; load "
          f"average {min(loads):.2f}-{max(loads):.2f} (2 cores)")
    med = {}
    for name, src in (("before", base_src), ("now", here)):
        v = runs[name]
        plain = float(np.median([r["plain"] for r in v]))
        lad = float(np.median([r["ladder"] for r in v]))
        med[name] = (plain, lad)
        print(f"  {name:6s} ({src}): without the ladder {1e3 * plain:.1f} ms ({2 / plain:.1f}/s), "
              f"with it {1e3 * lad:.1f} ms ({2 / lad:.1f}/s, {plain / lad:.2f}x); runs "
              + ", ".join(f"{1e3 * r['plain']:.1f}/{1e3 * r['ladder']:.1f} ms {r['meta']}"
                          for r in v))
    print(f"  now / before: without the ladder {med['before'][0] / med['now'][0]:.2f}x, with it "
          f"{med['before'][1] / med['now'][1]:.2f}x; identical ladder Pareto records (designs "
          f"and final metrics) before and now in every run: "
          f"{all(a['pareto'] == b['pareto'] for a, b in zip(runs['before'], runs['now']))}")


def _key(r) -> str:
    return json.dumps(r["params"], sort_keys=True)


def main() -> None:
    coarse = {"angle": "0.1 deg", "length": "0.1 mm", "worst_case": "bound"}
    if "--coarse" in sys.argv:
        i = sys.argv.index("--coarse")
        coarse.update(angle=f"{sys.argv[i + 1]} deg", worst_case=sys.argv[i + 2])
    if "--ladder-sobol" in sys.argv:
        ladder_mode(None, coarse, int(sys.argv[sys.argv.index("--ladder-sobol") + 1]))
        return
    if "--ladder-compare" in sys.argv:
        i = sys.argv.index("--ladder-compare")
        g = sys.argv[i + 2] if len(sys.argv) > i + 2 else ""
        ladder_compare(sys.argv[i + 1], int(g) if g.isdigit() else None)
        return
    if "--ladder-json" in sys.argv:
        i = sys.argv.index("--ladder-json")
        g = sys.argv[i + 1] if len(sys.argv) > i + 1 else ""
        ladder_mode(int(g) if g.isdigit() else None, coarse, json_out=True)
        return
    if "--ladder" in sys.argv:
        i = sys.argv.index("--ladder")
        g = sys.argv[i + 1] if len(sys.argv) > i + 1 else ""
        ladder_mode(int(g) if g.isdigit() else None, coarse)
        return
    if "--cpu-json" in sys.argv:
        print(json.dumps(cpu_mode(int(sys.argv[sys.argv.index("--cpu-json") + 1]))))
        return
    if "--compare" in sys.argv:
        i = sys.argv.index("--compare")
        n = int(sys.argv[i + 2]) if len(sys.argv) > i + 2 else 60
        compare(sys.argv[i + 1], n)
        return
    if "--cpu" in sys.argv:
        i = sys.argv.index("--cpu")
        n = int(sys.argv[i + 1]) if len(sys.argv) > i + 1 else 100
        cpu = np.array(cpu_mode(n)["cpu"])
        print(f"demo study, {n} candidates in this process, one numba thread: "
              f"{1e3 * np.median(cpu):.0f} ms CPU per candidate (median) -> "
              f"{2 / np.median(cpu):.1f} candidates/s on 2 idle cores; load average "
              f"{os.getloadavg()[0]:.2f}")
        return
    n = 5000 if "--full" in sys.argv else 400
    study = load_study(ROOT / "studies/hopkins-6psu-redesign.yaml")
    space = study.space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)        # n need not be a power of 2
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=0).random(n + 16)
    tasks = [(i, (space, space.from_unit(r), study.evaluation, study.seed))
             for i, r in enumerate(u)]
    runner = JoblibRunner(2)
    t0 = time.perf_counter()
    list(runner.map(evaluate_design, tasks[:16]))          # warm-up: compile in workers
    warm = time.perf_counter() - t0
    t0 = time.perf_counter()
    results = [r for _, r in runner.map(evaluate_design, tasks[16:])]
    dt = time.perf_counter() - t0
    ok = sum(r["status"] == "ok" for r in results)
    rate = n / dt
    print(f"demo study evaluation, 2 joblib workers: {n} candidates in {dt:.1f} s "
          f"({ok} ok, {n - ok} invalid or failed)")
    print(f"  {rate:.1f} candidates/s -> 5,000 candidates in {5000 / rate / 60:.2f} min "
          f"(target <= 5 min); worker warm-up {warm:.1f} s once")


if __name__ == "__main__":
    main()
