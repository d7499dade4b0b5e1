"""Progress of long steps as log lines, for runs without a terminal (a log file, CI, a batch
job): no step longer than a couple of seconds is silent.

Library code reports through ``logging.getLogger(__name__)`` at INFO (design export, report
building) and through ``progress`` callbacks; the command line shows them with
:func:`log_lines` and, without a terminal, counts evaluations with :class:`ProgressLines`.
"""

from __future__ import annotations

import contextlib
import logging
import sys
import time
from collections.abc import Iterator

__all__ = ["ProgressLines", "log_lines"]


class ProgressLines:
    """``advance(n)`` callable writing ``pkmlab: evaluated k/~N candidates (rate, ETA)`` to
    ``stream`` every ``seconds`` or every tenth of ``total``, and at the end."""

    def __init__(self, total: int, stream=None, seconds: float = 5.0, what: str = "candidates"):
        self.total = max(int(total), 1)
        self.stream = stream or sys.stderr
        self.seconds = seconds
        self.what = what
        self.done = 0
        self.t0 = self.last = time.perf_counter()
        self.step = max(1, self.total // 10)
        self._write(f"pkmlab: evaluating ~{self.total} {what}")

    def _write(self, line: str) -> None:
        self.stream.write(line + "\n")
        self.stream.flush()

    def __call__(self, n: int = 1) -> None:
        self.done += n
        now, done = time.perf_counter(), self.done
        if now - self.last >= self.seconds or done % self.step == 0 or done == self.total:
            self.last = now
            rate = done / max(now - self.t0, 1e-9)
            eta = (f", ETA {max(self.total - done, 0) / rate:.0f} s"
                   if 0 < done < self.total else "")
            self._write(f"pkmlab: evaluated {done}/~{self.total} {self.what} "
                        f"({rate:.2f}/s{eta})")


@contextlib.contextmanager
def log_lines(stream=None, level: int = logging.INFO) -> Iterator[None]:
    """Within ``with``: pkmlab's log lines at ``level`` and above on ``stream`` (stderr),
    each prefixed ``pkmlab:``."""
    logger = logging.getLogger("pkmlab")
    handler = logging.StreamHandler(stream or sys.stderr)
    handler.setFormatter(logging.Formatter("pkmlab: %(message)s"))
    old = logger.level
    logger.addHandler(handler)
    logger.setLevel(level)
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(old)
