"""How pkmlab's parallel numba kernels share the cores with other work.

**The problem.** numba's default threading layer on Linux is OpenMP (GNU libgomp). When a
parallel region ends, libgomp's threads *spin* at the barrier before they sleep. On a quiet
machine that is the fastest choice. On a busy one it is the slowest: if the thread a region
waits for has been descheduled, the others burn their time slices spinning, and the region
costs a scheduler quantum instead of microseconds. Measured on this project's 2-core machine
with two busy processes beside it, a ``prange`` loop over 200,000 elements took 8.1 ms (median;
0.06 ms quiet), and over 1,000 elements 16 ms. With ``OMP_WAIT_POLICY=PASSIVE`` (threads sleep
at once) the same calls took 0.12 ms and 0.009 ms. ``benchmarks/bench_load.py`` measures the
effect on study candidates.

**The policy.**

* *Wait policy.* Importing this module sets ``OMP_WAIT_POLICY=PASSIVE`` (and Intel OpenMP's
  ``KMP_BLOCKTIME=0``) as *defaults*: a value the user has set is kept. libgomp reads them
  once, when numba first loads its OpenMP layer, which happens at the first parallel call;
  :mod:`pkmlab.runtime.jit` imports this module, so every pkmlab kernel runs after it. If another
  library launched numba's threads earlier, the defaults come too late for this process and a
  debug message says so. On a quiet machine the passive policy costs about 0.05 ms per
  parallel call (waking the threads), which is small next to a kernel's work.
* *Small kernels on one thread.* :func:`threads_for` runs a call on one thread when its work is
  below :data:`SMALL_WORK` items, where waking a second thread costs more than it saves.
* *One numba thread per worker.* Study workers (joblib/loky processes, Dask workers) each run
  their kernels on one thread (:func:`single_thread_worker`): the workers already fill the
  cores, and a second numba thread per worker would only compete with the other workers.

``numba.set_num_threads`` is thread-local, so none of this changes another thread's setting.
"""

from __future__ import annotations

import contextlib
import logging
import os

log = logging.getLogger(__name__)

__all__ = ["DEFAULTS", "SMALL_WORK", "threads_for", "single_thread_worker"]

#: environment defaults for the OpenMP runtimes numba may load (user values win)
DEFAULTS = {"OMP_WAIT_POLICY": "PASSIVE", "KMP_BLOCKTIME": "0"}
#: items of work below which a parallel kernel runs on one thread
SMALL_WORK = 4096


def _apply_defaults() -> None:
    for key, value in DEFAULTS.items():
        os.environ.setdefault(key, value)
    try:
        from numba.np.ufunc import parallel as _parallel

        if getattr(_parallel, "_is_initialized", False):
            log.debug("numba's threading layer was launched before pkmlab set its OpenMP "
                      "wait policy; this process keeps the runtime's defaults")
    except ImportError:  # pragma: no cover - numba internals moved
        pass


_apply_defaults()


@contextlib.contextmanager
def threads_for(work: int):
    """Run the enclosed kernel calls on one numba thread when ``work`` (items) is small."""
    if work >= SMALL_WORK:
        yield
        return
    import numba

    before = numba.get_num_threads()
    if before == 1:
        yield
        return
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(before)


def single_thread_worker() -> None:
    """In a study worker: this thread's numba kernels run on one thread."""
    import numba

    if numba.get_num_threads() != 1:
        numba.set_num_threads(1)
