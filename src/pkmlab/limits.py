"""Allowed ranges of request parameters, declared once.

The YAML validators (and so ``pkmlab validate`` and the JSON Schema) and the library functions
check against the same numbers, so that whatever validates also runs.
"""

from __future__ import annotations

__all__ = ["SEGMENT_TIME_S", "MEMORY_FRACTION", "TIME_LIMIT_S", "LENGTH_MAX_MM", "RESOLUTION_MM",
           "EULER_HALF_RANGE_DEG", "SAMPLES_PER_ANGLE", "GCI_SAMPLES", "CAPABILITY_MAX_DEG",
           "CSV_MAX_BYTES", "CSV_MAX_ROWS", "MOTION_TIME_S", "MASS_MAX_KG", "INERTIA_MAX"]

#: Duration of one leg of the paper's lobe motion (s): 1 ms .. 1 day.
SEGMENT_TIME_S = (1e-3, 86400.0)
#: Default memory budget of one command: this share of the machine's physical memory
#: (``PKMLAB_MEMORY_LIMIT`` overrides it; see :mod:`pkmlab.runtime.memory`).
MEMORY_FRACTION = 0.5
#: Default time budget of one command (s): one day (``PKMLAB_TIME_LIMIT`` overrides it; see
#: :mod:`pkmlab.runtime.time_budget`).
TIME_LIMIT_S = 86400.0
#: Largest length magnitude anywhere (mm): 1 km; beyond it products of lengths overflow and
#: printed values become unreadable.
LENGTH_MAX_MM = 1.0e6
#: Workspace grid spacing h (mm): finer grids exceed memory on any machine pkmlab targets.
RESOLUTION_MM = (0.05, 100.0)
#: Half-range of an Euler-box orientation set (deg).
EULER_HALF_RANGE_DEG = (0.0, 180.0)
#: Orientation samples per angle of an orientation set.
SAMPLES_PER_ANGLE = (1, 101)
#: Monte-Carlo samples of the GCI.
GCI_SAMPLES = (10, 1_000_000)
#: Upper end of the orientation-capability search (deg): the Euler box covers SO(3) there.
CAPABILITY_MAX_DEG = 180.0
#: Largest CSV input (bytes) and its most data rows: a million samples is 17 min at 1 kHz.
CSV_MAX_BYTES = 256 * 2**20
CSV_MAX_ROWS = 1_000_000
#: Time stamps of recorded motions (s): magnitudes at most this (about 116 days), so that
#: differences and rates stay finite.
MOTION_TIME_S = 1.0e7
#: Largest mass (kg) of a payload, platform or leg: 1000 t; beyond it forces overflow.
MASS_MAX_KG = 1.0e6
#: Largest magnitude of an inertia entry (kg·mm²): 1e9 kg·m².
INERTIA_MAX = 1.0e15
