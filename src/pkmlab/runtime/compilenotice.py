"""Say so when a command compiles numba kernels, with an estimate, and keep saying so.

A fresh install (or an edit) compiles pkmlab's kernels on first use; numba then caches them
(``NUMBA_CACHE_DIR``). A command used to be silent for minutes while that happened.
:func:`compile_notice` listens to numba's ``numba:compile`` events, which fire only on a cache
miss (a cache load fires none), and on the first one says::

    compiling rss6 kernels, one-off (cached for later runs), about 1-5 min on 2 cores ...

then every ``EVERY_S`` seconds while compiles continue ``still compiling (… s so far; now
<kernel>)``, and at the end ``compiled N numba function(s) in S s``. The estimate is
:data:`ESTIMATES`, the cold-cache times measured for each kind of command (docs/validation.md,
issue 26), as a range; on a loaded machine it takes longer, and the notice says so.
"""

from __future__ import annotations

import contextlib
import threading
import time

from numba.core import event as _event

from .jit import _short

__all__ = ["ESTIMATES", "EVERY_S", "compile_notice", "estimate_text"]

#: seconds between "still compiling" lines
EVERY_S = 30.0
#: (low, high) seconds of a cold-cache compile per kind of command, measured on 2 cores
#: (docs/validation.md, issue 26): the kinematics commands compile one family's inverse and
#: forward kinematics; the study and analysis commands also the workspace, dexterity and
#: requirement kernels.
ESTIMATES = {"kinematics": (20.0, 90.0), "analysis": (60.0, 300.0), "study": (60.0, 300.0)}


def _span(seconds: float) -> str:
    return f"{seconds:.0f} s" if seconds < 90 else f"{seconds / 60:.0f} min"


def estimate_text(kind: str) -> str:
    lo, hi = ESTIMATES.get(kind, ESTIMATES["study"])
    if hi < 90:
        return f"about {lo:.0f}-{hi:.0f} s on 2 cores"
    return f"about {max(lo / 60, 1):.0f}-{hi / 60:.0f} min on 2 cores"


class _Listener(_event.Listener):
    def __init__(self, say, what: str, kind: str, every: float):
        self.say, self.what, self.kind, self.every = say, what, kind, every
        self.depth = 0
        self.count = 0
        self.now = "?"
        self.t0: float | None = None
        self.busy = 0.0
        self._started = 0.0
        self._timer: threading.Timer | None = None
        self._lock = threading.Lock()

    def _tick(self):
        with self._lock:
            if self.depth:
                self.say(f"still compiling {self.what}kernels ({self.count} function(s), "
                         f"{time.perf_counter() - self.t0:.0f} s so far; now {self.now})")
            self._arm()

    def _arm(self):
        self._timer = threading.Timer(self.every, self._tick)
        self._timer.daemon = True
        self._timer.start()

    def on_start(self, event):
        with self._lock:
            if self.depth == 0:
                self._started = time.perf_counter()
                fn = getattr(event.data.get("dispatcher"), "py_func", None)
                self.now = _short(getattr(fn, "__name__", "?"))
                if self.t0 is None:
                    self.t0 = self._started
                    self.say(f"compiling {self.what}kernels, one-off (cached for later runs), "
                             f"{estimate_text(self.kind)}, longer on a loaded machine; the "
                             "time estimates leave it out")
                    self._arm()
            self.depth += 1

    def on_end(self, event):
        with self._lock:
            self.depth -= 1
            if self.depth == 0:
                self.count += 1
                self.busy += time.perf_counter() - self._started

    def close(self):
        if self._timer is not None:
            self._timer.cancel()
        if self.count:
            self.say(f"compiled {self.count} numba function(s) in {_span(self.busy)} "
                     "(cached for later runs)")


@contextlib.contextmanager
def compile_notice(say, what: str = "", kind: str = "study", every: float = EVERY_S):
    """Within ``with``: ``say(line)`` when numba first compiles (``what``: e.g. the family's
    name and a space, or ''), every ``every`` s while it goes on, and once at the end (see
    the module notes)."""
    lis = _Listener(say, what, kind, every)
    with _event.install_listener("numba:compile", lis):
        try:
            yield lis
        finally:
            lis.close()
