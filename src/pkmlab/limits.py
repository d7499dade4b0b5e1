"""Allowed ranges of request parameters, declared once.

The YAML validators (and so ``pkmlab validate`` and the JSON Schema) and the library functions
check against the same numbers, so that whatever validates also runs.
"""

from __future__ import annotations

__all__ = ["RESOLUTION_MM", "EULER_HALF_RANGE_DEG", "SAMPLES_PER_ANGLE", "GCI_SAMPLES",
           "CAPABILITY_MAX_DEG"]

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
