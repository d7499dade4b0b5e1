"""Measured memory peaks, to check the budgets' cost models against (tests, benchmarks).

:func:`measure` runs one ``pkmlab`` command line in a fresh interpreter, after importing the
CLI and loading the compiled kernels, and returns the rise of the peak resident set over the
resident set before the command (Linux: ``/proc/self/clear_refs`` resets ``VmHWM``), together
with the estimate the command logged through :func:`pkmlab.runtime.memory.require` (the
largest one). Linux only; elsewhere :func:`available` is False.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

__all__ = ["available", "measure"]

_CHILD = r"""
import json, logging, os, re, sys
def status(key):
    return int(re.search(key + r':\s+(\d+)', open('/proc/self/status').read()).group(1)) * 1024
ARGV, WARM = json.loads(sys.argv[1]), json.loads(sys.argv[2])
from pkmlab.cli import run_cli
import pkmlab.runtime.memory as mem
seen = []
_require = mem.require
def spy(field, need, *a, **k):
    seen.append((field, float(need)))
    return _require(field, need, *a, **k)
mem.require = spy
for warm in WARM:
    sys.argv = ['pkmlab', *warm]
    try:
        run_cli()
    except SystemExit:
        pass
for m in list(sys.modules.values()):     # every module that imported require by name
    if getattr(m, '__name__', '').startswith('pkmlab') and getattr(m, 'require', None) is _require:
        m.require = spy
seen.clear()
import gc; gc.collect()
open('/proc/self/clear_refs', 'w').write('5')
base = status('VmRSS')
sys.argv = ['pkmlab', *ARGV]
code = 0
try:
    run_cli()
except SystemExit as exc:
    code = exc.code
sys.__stderr__.write('PEAK ' + json.dumps({'code': code, 'rise': status('VmHWM') - base,
                                            'base': base, 'estimates': seen}) + chr(10))
"""


def available() -> bool:
    """Whether peaks can be measured here (Linux with a resettable VmHWM)."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def measure(argv: list[str], warm: list[list[str]] = (), env: dict | None = None,
            timeout: float = 600.0) -> dict:
    """Run ``pkmlab <argv>`` in a fresh interpreter (after the command lines ``warm``, which
    compile or load the kernels) → ``{"code", "rise", "base", "estimates": [(field, bytes)]}``
    (``rise``: bytes the peak resident set rose over the resident set before the command)."""
    e = dict(os.environ)
    e.update(env or {})
    p = subprocess.run([sys.executable, "-c", _CHILD, json.dumps(list(map(str, argv))),
                        json.dumps([list(map(str, w)) for w in warm])],
                       capture_output=True, text=True, env=e, timeout=timeout)
    for line in p.stderr.splitlines():
        if line.startswith("PEAK "):
            out = json.loads(line[5:])
            out["estimates"] = [tuple(x) for x in out["estimates"]]
            out["stderr"] = p.stderr
            return out
    raise RuntimeError(f"pkmlab {' '.join(map(str, argv))} did not report its peak:\n"
                       f"{p.stderr[-3000:]}")
