"""Where candidate evaluations run: in process, in joblib workers, or on a Dask cluster.

A runner maps a function over tasks and hands each result back *as it finishes*, so the
caller can commit it to the store immediately. Runners are passed to the study driver, never
created inside it.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Iterator

from ..runtime.threads import single_thread_worker

__all__ = ["SerialRunner", "JoblibRunner", "DaskRunner", "make_runner"]

log = logging.getLogger(__name__)


#: seconds to reach a Dask scheduler before giving up
DASK_CONNECT_TIMEOUT = 5.0
_WATCHDOG = {"started": False}


def _watch_parent(parent: int, period: float = 0.5) -> None:
    """In a worker process: exit as soon as the process that started the run is gone (a
    killed ``pkmlab run`` must not leave workers evaluating for minutes)."""
    import os
    import threading
    import time

    if _WATCHDOG["started"] or parent == os.getpid():
        return
    _WATCHDOG["started"] = True
    ppid = os.getppid()

    def watch():
        while True:
            time.sleep(period)
            try:
                os.kill(parent, 0)
            except ProcessLookupError:
                os._exit(1)
            except PermissionError:
                pass
            if os.getppid() != ppid:
                os._exit(1)

    threading.Thread(target=watch, name="pkmlab-parent-watchdog", daemon=True).start()


#: glibc ``mallopt`` parameters (malloc.h) and the values a worker sets (bytes)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_WORKER_MMAP_THRESHOLD = 32 << 20       # glibc's own dynamic ceiling on 64-bit
_WORKER_TRIM_THRESHOLD = 128 << 20
_MALLOC = {"tuned": False}


def _tune_malloc() -> None:
    """In a worker process, once: let glibc serve arrays up to 32 MiB from its heap.

    Dask's nanny starts workers with ``MALLOC_TRIM_THRESHOLD_=65536``. Setting any malloc
    threshold turns off glibc's dynamic mmap threshold, so every array above 128 KiB is
    mapped and unmapped afresh, and a task thread takes a page fault for each page it then
    touches: measured on the demo study, 37,000 minor faults and 92 ms of system time per
    candidate in a Dask worker against 800 faults and 4.5 ms in a loky worker, the whole gap
    between the two runners. The thresholds set here are those glibc's dynamic rule reaches by
    itself (mmap above 32 MiB; the heap's top is trimmed above 128 MiB). A C library without
    ``mallopt`` (not glibc) is left alone.
    """
    if _MALLOC["tuned"]:
        return
    _MALLOC["tuned"] = True
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    mallopt(_M_MMAP_THRESHOLD, _WORKER_MMAP_THRESHOLD)
    mallopt(_M_TRIM_THRESHOLD, _WORKER_TRIM_THRESHOLD)


def _call(fn, task_id, args, parent=None, worker=False):
    """``(task_id, fn(*args), compiles)``; in a worker, ``compiles`` lists the numba compiles
    (``(name, seconds, group)``) the task made, which the parent reports (:func:`_result`):
    the parent loads or compiles every kernel before the workers start, so a compile in a
    worker means a kernel the warm-up missed."""
    if parent is not None:
        _watch_parent(parent)
    if not worker:
        return task_id, fn(*args), ()
    single_thread_worker()          # the workers fill the cores; one numba thread each
    _tune_malloc()
    from ..runtime.jit import compile_log

    with compile_log() as compiled:
        result = fn(*args)
    return task_id, result, tuple(compiled.entries)


def _result(item) -> tuple:
    """``(task_id, result)`` of :func:`_call`'s triple, logging (INFO, one line per group) what
    the worker compiled."""
    task_id, result, compiles = item
    if compiles:
        from ..runtime.jit import compile_lines

        for line in compile_lines(compiles, "in a worker (not in the cache yet)"):
            log.info("%s", line)
    return task_id, result


class SerialRunner:
    """Evaluate in this process, in order."""

    name = "serial"

    def map(self, fn: Callable, tasks: Iterable[tuple]) -> Iterator[tuple]:
        for task_id, args in tasks:
            yield task_id, fn(*args)

    def close(self) -> None:
        pass


class JoblibRunner:
    """Evaluate in ``jobs`` joblib (loky) worker processes; results in completion order."""

    name = "loky"

    def __init__(self, jobs: int = 2):
        from joblib import Parallel

        self.jobs = jobs
        self.pool = Parallel(n_jobs=jobs, backend="loky", return_as="generator_unordered")

    def map(self, fn, tasks):
        import os

        from joblib import delayed

        parent = os.getpid()
        for item in self.pool(delayed(_call)(fn, tid, args, parent, True) for tid, args in tasks):
            yield _result(item)

    def close(self) -> None:
        pass


class DaskRunner:
    """Evaluate on a Dask cluster (an existing scheduler address, or a given client)."""

    name = "dask"

    def __init__(self, scheduler: str | None = None, client=None):
        from distributed import Client

        self._own = client is None
        if client is None:
            import logging as _logging

            quiet = _logging.getLogger("distributed")
            level = quiet.level
            quiet.setLevel(_logging.CRITICAL)       # one line from us, not a page of retries
            try:
                client = Client(scheduler, timeout=DASK_CONNECT_TIMEOUT)
            except (OSError, TimeoutError, ValueError) as exc:
                from ..errors import ParameterError

                raise ParameterError("--scheduler", "a reachable Dask scheduler address "
                                     f"(connection within {DASK_CONNECT_TIMEOUT:g} s)",
                                     f"{scheduler}: {' '.join(str(exc).split())[:160]}") \
                    from None
            finally:
                quiet.setLevel(level)
        self.client = client

    def map(self, fn, tasks):
        from distributed import as_completed

        tasks = list(tasks)
        futures = [self.client.submit(_call, fn, tid, args, None, True, pure=False)
                   for tid, args in tasks]
        for fut in as_completed(futures):
            yield _result(fut.result())

    def close(self) -> None:
        if self._own:
            self.client.close()


def make_runner(backend: str, jobs: int = 1, scheduler: str | None = None):
    """Runner for the CLI's ``--backend`` / ``--jobs`` / ``--scheduler`` options."""
    from ..errors import ParameterError

    if backend == "dask":
        if not scheduler:
            raise ParameterError("--scheduler", "a Dask scheduler address (tcp://host:port) "
                                 "with --backend dask", scheduler)
        return DaskRunner(scheduler)
    if backend != "loky":
        raise ParameterError("--backend", "one of ['loky', 'dask']", backend)
    if jobs < 1:
        raise ParameterError("--jobs", "an integer >= 1", jobs)
    return SerialRunner() if jobs == 1 else JoblibRunner(jobs)
