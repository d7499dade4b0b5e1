"""Cold compile cost of the demo study's numba kernels, kernel by kernel (issue 28, session 6).

In a fresh ``NUMBA_CACHE_DIR`` (a new temporary folder, unless ``--cache DIR``), one process
builds every kernel warmer that applies to a study's baseline (:mod:`pkmlab.runtime.warmers`),
one after the other, then evaluates the baseline (:func:`pkmlab.study.run.compile_baseline`),
as ``python -m pkmlab.study.warm`` does in two processes. Every numba compile (a cache miss) is
recorded with its wall time and its CPU time (``time.process_time`` of this process: numba
compiles in one thread, so this is the compile's own CPU under any load). Printed: one line per
compiled function (the outermost compile: a helper compiled inside a kernel counts in it),
grouped by the warmer that built it, the totals, and the load average before and after.

    python benchmarks/bench_compile.py [STUDY.yaml] [--cache DIR] [--json OUT]
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _arg(name, default=None):
    return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default


def main() -> None:
    cache = _arg("--cache") or tempfile.mkdtemp(prefix="pkmlab-compile-")
    os.environ["NUMBA_CACHE_DIR"] = cache          # before numba is imported
    from numba.core import event

    from pkmlab.runtime.jit import _short, kernel_group
    from pkmlab.runtime.warmers import applicable
    from pkmlab.study import load_study
    from pkmlab.study.run import compile_baseline
    from pkmlab.study.warm import DEMO_STUDY, _builtin_warmers

    class Rec(event.Listener):
        def __init__(self):
            self.rows, self.stack, self.stage = [], [], "?"

        def on_start(self, ev):
            self.stack.append((time.perf_counter(), time.process_time()))

        def on_end(self, ev):
            w0, c0 = self.stack.pop()
            if self.stack:
                return
            fn = getattr(ev.data.get("dispatcher"), "py_func", None)
            self.rows.append((self.stage, _short(getattr(fn, "__name__", "?")),
                              kernel_group(getattr(fn, "__module__", None) or "?"),
                              time.perf_counter() - w0, time.process_time() - c0))

    args = [a for i, a in enumerate(sys.argv[1:], 1)
            if not a.startswith("--") and sys.argv[i - 1] not in ("--cache", "--json")]
    path = ROOT / (args[0] if args else DEMO_STUDY)
    load0 = os.getloadavg()
    rec = Rec()
    t0, c0 = time.perf_counter(), time.process_time()
    with event.install_listener("numba:compile", rec):
        rec.stage = "load the study"
        study = load_study(path)
        _builtin_warmers()
        mech = study.space.decode(None)
        for w in applicable(mech):
            rec.stage = f"warmer: {w.name} (weight {w.weight:g})"
            w.build(mech)
        rec.stage = "the baseline's evaluation"
        compile_baseline(study.space, study.evaluation, study.seed)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"study {path.name}; cache {cache}; load before {load0[0]:.2f} "
          f"{load0[1]:.2f}, after {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f}")
    stage = None
    for st, name, group, w, c in rec.rows:
        if st != stage:
            stage = st
            tot = sum(r[4] for r in rec.rows if r[0] == st)
            print(f"{st}: {tot:.1f} s CPU")
        print(f"    {name:<34} {group:<20} {c:7.2f} s CPU  {w:7.2f} s wall")
    print(f"compiled {len(rec.rows)} functions: {sum(r[4] for r in rec.rows):.1f} s CPU "
          f"in compiles; the whole run {cpu:.1f} s CPU, {wall:.1f} s wall")
    if _arg("--json"):
        Path(_arg("--json")).write_text(json.dumps(
            {"rows": rec.rows, "cpu": cpu, "wall": wall, "load": [load0, os.getloadavg()]}))


if __name__ == "__main__":
    main()
