"""The console entry point ends the process without the interpreter's module teardown (a
fifth of a short command's wall time) but otherwise as the interpreter would: threads that
are not daemons are waited for, exit handlers run, the streams are flushed, and the status is
the command's."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

_SCRIPT = """
import atexit, sys, threading, time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from pkmlab.cli import main

class Teardown:                       # freed only by the module teardown
    def __del__(self):
        sys.stderr.write("module teardown\\n")

kept = Teardown()
atexit.register(lambda: sys.stderr.write("exit handler ran\\n"))
flag = Path(sys.argv[1])
def late():
    time.sleep(0.3)
    flag.write_text("thread finished")
threading.Thread(target=late).start()
pool = ThreadPoolExecutor(1)          # never shut down: its exit hook stops its thread
pool.submit(time.sleep, 0.1)
sys.stdout.write("x" * 200000)
sys.stdout.write("tail\\n")            # small: still in the buffer when the command ends
sys.argv = ["pkmlab"] + sys.argv[2:]
main()
"""


@pytest.mark.parametrize(("args", "status"), [(["--version"], 0), (["nosuch"], 2)])
def test_entry_point_skips_the_module_teardown_only(tmp_path, args, status):
    flag = tmp_path / "flag"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}   # buffered stdout
    r = subprocess.run([sys.executable, "-c", _SCRIPT, str(flag), *args], capture_output=True,
                       text=True, timeout=120, env=env)
    assert r.returncode == status, r.stderr
    assert "module teardown" not in r.stderr            # before: printed at every exit
    assert "exit handler ran" in r.stderr
    assert flag.read_text() == "thread finished"         # the thread was waited for
    assert r.stdout.startswith("x" * 200000 + "tail\n")  # the buffered output arrived
    if status == 0:
        assert r.stdout.endswith("\n") and "pkmlab" in r.stdout.splitlines()[-1]
