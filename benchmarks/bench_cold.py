"""Cold start (issue 14 item 5): ``pkmlab workspace`` in a fresh process with a warm kernel
cache (target ≤ 1.5 s), and how long a fresh study worker takes to its first result (target
≤ 2 s).

Every figure is the minimum over ``--repeats`` fresh processes (default 5), after one run that
fills the kernel cache; wall time and CPU time (user + system, from ``os.wait4``) are both
reported, since wall time on a shared machine includes waiting for a core. The plain
baseline in the same run is the interpreter importing NumPy and exiting.

    python benchmarks/bench_cold.py [--repeats N]
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable
MECH = ROOT / "studies/mechanisms/hopkins-williams-6psu.yaml"

# a fresh worker: import, load the study, evaluate one candidate (the demo study's centre)
_WORKER = """
import numpy as np
from pathlib import Path
from pkmlab.study import evaluate_design, load_study
from pkmlab.runtime.threads import single_thread_worker
single_thread_worker()
study = load_study(Path({study!r}))
space = study.space
r = evaluate_design(space, space.from_unit(np.full(len(space.variables), 0.5)),
                    study.evaluation, study.seed)
assert r["status"] in ("ok", "invalid"), r
"""


def _run(argv: list[str]) -> tuple[float, float]:
    """Wall and CPU seconds of one fresh process (stdout discarded)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    t = time.perf_counter()
    p = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    err = p.stderr.read().decode() if p.stderr else ""
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(argv[:4])} failed:\n{err}")
    return wall, usage.ru_utime + usage.ru_stime


def _best(argv, repeats):
    runs = [_run(argv) for _ in range(repeats)]
    return min(w for w, _ in runs), min(c for _, c in runs)


def main() -> None:
    repeats = int(sys.argv[sys.argv.index("--repeats") + 1]) if "--repeats" in sys.argv else 5
    with tempfile.TemporaryDirectory() as tmp:
        ws = [PY, "-m", "pkmlab.cli", "workspace", str(MECH), "--out", str(Path(tmp) / "ws")]
        worker = [PY, "-c", _WORKER.format(study=str(ROOT / "studies/hopkins-6psu-redesign.yaml"))]
        _run(ws)                                  # fill the kernel caches
        _run(worker)
        print(f"load average {os.getloadavg()[0]:.2f} (2 cores); best of {repeats} fresh "
              "processes, warm kernel cache")
        base = _best([PY, "-c", "import numpy"], repeats)
        for name, argv, target in (("pkmlab workspace (6-PSU, 2.5 mm, PNG + STL)", ws, 1.5),
                                   ("worker: start to first demo candidate", worker, 2.0)):
            wall, cpu = _best(argv, repeats)
            print(f"  {name}: {wall:.2f} s wall, {cpu:.2f} s CPU (target <= {target:g} s; "
                  f"{wall / base[0]:.1f}x the baseline)")
        print(f"  baseline (python -c 'import numpy'): {base[0]:.2f} s wall, {base[1]:.2f} s CPU")


if __name__ == "__main__":
    main()
