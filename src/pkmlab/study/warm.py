"""Fill numba's disk cache with the kernels a study's evaluation uses (``make`` runs this after
installing, so that the first ``make demo`` loads its kernels instead of compiling them).

    python -m pkmlab.study.warm [--jobs N] [STUDY.yaml ...]     (default: the demo study)

For each study, the kernel warmers that apply to its baseline design
(:mod:`pkmlab.runtime.warmers`: kernels built without evaluating anything) are spread over
``N`` processes by their weights (default: 2, or the cores available when fewer); then the
baseline design is evaluated once in this process (:func:`pkmlab.study.run.compile_baseline`),
which compiles what no warmer covers and loads the rest. numba compiles in one thread per
process (its compiler lock), so the processes are what makes the warm-up parallel. Every kernel
compiled is saved in the cache (``NUMBA_CACHE_DIR``, or ``__pycache__`` beside the sources),
keyed by its source, so an edit recompiles only what it touches. One line per group of
kernels says what was compiled, and one line per study how long it took. A study that cannot
be loaded is reported and skipped (exit status 1); a warmer process that fails is reported and
its kernels are compiled by the baseline's evaluation instead.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import multiprocessing
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from ..runtime.jit import compile_lines, compile_log
from ..runtime.warmers import WARMERS, applicable, partition

log = logging.getLogger(__name__)

__all__ = ["warm_study", "extra_kernels", "DEMO_STUDY", "default_jobs"]

#: the study ``make demo`` runs, relative to the repository root
DEMO_STUDY = Path("studies/hopkins-6psu-redesign.yaml")


def _builtin_warmers() -> None:
    """Import the modules that register the built-in warmers."""
    from ..dexterity import _warmers  # noqa: F401
    from ..mechanisms.kernels import warmers  # noqa: F401


def default_jobs() -> int:
    """2, or the cores this process may use when fewer."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:          # not on Linux
        cores = os.cpu_count() or 1
    return max(1, min(2, cores))


def extra_kernels(mech) -> None:
    """Build, in this process, every kernel the warmers that apply to ``mech`` build: the
    kernels that designs other than the baseline may use and the baseline does not (the
    tiled column kernel serves large footprints only, for example), and those the baseline's
    evaluation would build anyway."""
    _builtin_warmers()
    for w in applicable(mech):
        w.build(mech)


def _build(space, names: list[str]) -> list[tuple[str, float, str]]:
    """In a warm-up process: the warmers ``names`` on ``space``'s baseline → the compiles
    (:attr:`pkmlab.runtime.jit.CompileLog.entries`)."""
    _builtin_warmers()
    mech = space.decode(None)
    with compile_log() as compiled:
        for name in names:
            w = WARMERS.get(name)       # a plugin's warmer not registered here: left to the
            if w is not None:           # baseline's evaluation in the parent
                w.build(mech)
    return compiled.entries


def warm_study(path, jobs: int | None = None) -> tuple[float, list[str]]:
    """Build the warmers' kernels for the study's baseline in ``jobs`` processes, then
    evaluate the baseline in this process → ``(seconds, one line per group of kernels
    compiled)``."""
    from . import load_study
    from .run import compile_baseline

    _builtin_warmers()
    jobs = default_jobs() if jobs is None else max(1, int(jobs))
    t0 = time.perf_counter()
    entries: list[tuple[str, float, str]] = []
    # spawn: no numba state forked. The other processes start (and import pkmlab, about 2 s
    # of CPU) while this one loads the study, whose checks compile the kinematics already
    pool = (ProcessPoolExecutor(jobs - 1, mp_context=multiprocessing.get_context("spawn"))
            if jobs > 1 else contextlib.nullcontext())
    with compile_log() as compiled:
        with pool:
            for _ in range(jobs - 1):
                pool.submit(_builtin_warmers)
            study = load_study(Path(path))
            mech = study.space.decode(None)
            here, *others = partition(applicable(mech), jobs)
            others = [b for b in others if b]
            futures = [pool.submit(_build, study.space, [w.name for w in b]) for b in others]
            for w in here:
                w.build(mech)
            for f, b in zip(futures, others, strict=True):
                try:
                    entries += f.result()
                except Exception as exc:  # noqa: BLE001 - the baseline compiles them
                    log.warning("a kernel warm-up process failed (%s: %s); its kernels (%s) "
                                "compile with the baseline", type(exc).__name__, exc,
                                ", ".join(w.name for w in b))
        compile_baseline(study.space, study.evaluation, study.seed, where="into the cache")
    entries += compiled.entries
    return time.perf_counter() - t0, compile_lines(entries, "into the cache")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pkmlab.study.warm",
                                     description="Fill numba's kernel cache for studies.")
    parser.add_argument("--jobs", type=int, default=None,
                        help="processes that compile at once (default: 2, or fewer cores)")
    parser.add_argument("studies", nargs="*", default=[str(DEMO_STUDY)])
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if args.jobs is not None and args.jobs < 1:
        parser.error(f"--jobs: an integer >= 1, got {args.jobs}")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("pkmlab: %(message)s"))
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    status = 0
    for path in args.studies:
        try:
            seconds, lines = warm_study(path, args.jobs)
        except Exception as exc:  # noqa: BLE001 - a warm-up failure must not fail the install
            log.warning("kernel cache not warmed for %s: %s", path, exc)
            status = 1
            continue
        for line in lines:
            log.info("%s", line)
        log.info("kernel cache for %s: %s in %.1f s", path,
                 "filled" if lines else "already warm (nothing compiled)", seconds)
    return status


if __name__ == "__main__":
    sys.exit(main())
