"""Fill numba's disk cache with the kernels a study's evaluation uses (``make`` runs this after
installing, so that the first ``make demo`` loads its kernels instead of compiling them).

    python -m pkmlab.study.warm [STUDY.yaml ...]     (default: the demo study)

Each study's baseline design is evaluated once in this process
(:func:`pkmlab.study.run.compile_baseline`), and the kernels other designs may use are built
(:func:`extra_kernels`: a larger footprint takes the tiled column kernel); every kernel compiled
is saved in the cache (``NUMBA_CACHE_DIR``, or ``__pycache__`` beside the sources), keyed
by its source, so an edit recompiles only what it touches. One line per group of kernels says
what was compiled, and one line per study how long it took. A study that cannot be loaded is
reported and skipped (exit status 1).
"""

from __future__ import annotations

import logging
import sys
import time
from pathlib import Path

from ..runtime.jit import compile_lines, compile_log

log = logging.getLogger(__name__)

__all__ = ["warm_study", "extra_kernels", "DEMO_STUDY"]

#: the study ``make demo`` runs, relative to the repository root
DEMO_STUDY = Path("studies/hopkins-6psu-redesign.yaml")


def warm_study(path) -> tuple[float, list[str]]:
    """Evaluate the study's baseline design in this process and build its family's column
    kernels → ``(seconds, one line per group of kernels compiled)``."""
    from . import load_study
    from .run import compile_baseline

    t0 = time.perf_counter()
    with compile_log() as compiled:
        study = load_study(Path(path))      # its checks compile the kinematics already
        compile_baseline(study.space, study.evaluation, study.seed, every=True,
                         where="into the cache")
    return time.perf_counter() - t0, compile_lines(compiled.entries, "into the cache")


def extra_kernels(family, mech=None) -> None:
    """The kernels that designs other than the baseline may use and the baseline does not:
    the family's column and search kernels (the tiled column kernel serves large footprints
    only, for example), the parallel singular values (stacks of 50,000 matrices and more:
    the κ of a large design's export) and, given the baseline ``mech``, its family's fused
    κ kernels (:func:`pkmlab.dexterity._fused_exact.warm`: the κ maps of an export, a
    trajectory check the baseline does not reach)."""
    import numpy as np

    from ..dexterity import _fused_exact, _linalg

    _linalg.singular_values(np.zeros((_linalg._PARALLEL_FROM, 6, 6)))
    if mech is not None:
        _fused_exact.warm(mech)
    if getattr(family, "column_method", None) not in ("linear", "quadratic"):
        return
    from ..mechanisms.kernels import columns, search, tiles

    leg = family.column_leg
    for build in (lambda: tiles.make_tiled_all(leg),
                  lambda: columns.make_column_kernel(leg, "all"),
                  lambda: columns.make_column_kernel(leg, "any"),
                  lambda: search.make_capability(leg), lambda: search.make_branch_bound(leg),
                  lambda: search.make_certify(leg)):
        build()


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("pkmlab: %(message)s"))
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    status = 0
    for path in argv or [str(DEMO_STUDY)]:
        try:
            seconds, lines = warm_study(path)
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
