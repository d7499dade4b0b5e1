"""Measured memory peaks, to check the budgets' cost models against (tests, benchmarks).

What is measured (issue 27): the **rise of the peak resident set of a fresh ``pkmlab``
process over its resident set once the CLI is imported** (``import pkmlab.cli``: the
interpreter, numpy, scipy, numba, typer, rich — :data:`pkmlab.runtime.memory.PROCESS_BYTES`),
with the kernels already compiled in the on-disk cache (:func:`warm` compiles them in another
process first). That rise is what the command itself adds — loading its kernels from the
cache, importing its late modules, its arrays, plots and files — and what its estimate
(:func:`pkmlab.runtime.memory.largest_checked`: the command's fixed memory plus the largest
array request it checked against the budget) is meant to cover. Linux only:
``/proc/self/clear_refs`` resets ``VmHWM``; elsewhere :func:`available` is False.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

__all__ = ["available", "measure", "warm"]

_CHILD = r"""
import json, re, sys
def status(key):
    return int(re.search(key + r':\s+(\d+)', open('/proc/self/status').read()).group(1)) * 1024
ARGV = json.loads(sys.argv[1])
from pkmlab.cli import run_cli
from pkmlab.runtime import memory
import gc; gc.collect()
open('/proc/self/clear_refs', 'w').write('5')
base = status('VmRSS')
sys.argv = ['pkmlab', *ARGV]
code = 0
try:
    run_cli()
except SystemExit as exc:
    code = exc.code
field, est = memory.largest_checked()
sys.__stderr__.write('PEAK ' + json.dumps({'code': code, 'rise': status('VmHWM') - base,
                                            'base': base, 'estimate': est,
                                            'field': field}) + chr(10))
"""

_WARM = r"""
import json, sys
from pkmlab.cli import run_cli
for argv in json.loads(sys.argv[1]):
    sys.argv = ['pkmlab', *argv]
    try:
        run_cli()
    except SystemExit:
        pass
"""


def available() -> bool:
    """Whether peaks can be measured here (Linux with a resettable VmHWM)."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def _env(env: dict | None) -> dict:
    e = dict(os.environ)
    e.update(env or {})
    return e


def warm(commands: list[list], env: dict | None = None, timeout: float = 1800.0) -> None:
    """Run the command lines ``commands`` in one other interpreter, so that the kernels they
    use are compiled into the on-disk cache before :func:`measure`."""
    subprocess.run([sys.executable, "-c", _WARM,
                    json.dumps([list(map(str, a)) for a in commands])],
                   capture_output=True, text=True, env=_env(env), timeout=timeout)


def measure(argv: list, env: dict | None = None, timeout: float = 600.0) -> dict:
    """Run ``pkmlab <argv>`` in a fresh interpreter → ``{"code", "rise", "base", "estimate",
    "field", "stderr"}``: ``rise``, the bytes the peak resident set rose over the resident
    set once the CLI was imported; ``estimate``, the largest need the command checked against
    the memory budget (its fixed memory included; 0 if it checked none) and its ``field``."""
    p = subprocess.run([sys.executable, "-c", _CHILD, json.dumps(list(map(str, argv)))],
                       capture_output=True, text=True, env=_env(env), timeout=timeout)
    for line in p.stderr.splitlines():
        if line.startswith("PEAK "):
            out = json.loads(line[5:])
            out["stderr"] = p.stderr
            return out
    raise RuntimeError(f"pkmlab {' '.join(map(str, argv))} did not report its peak:\n"
                       f"{p.stderr[-3000:]}")
