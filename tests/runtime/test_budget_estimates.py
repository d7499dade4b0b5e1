"""The memory estimates against measured peaks (issue 27, item 3): each command runs in a fresh
interpreter (after a warm-up that loads the kernels), and the rise of its peak resident set
over the resident set before it is compared with the largest estimate it checked against the
budget plus its fixed output cost (OUTPUT_BYTES): within a factor of 2 either way. The
settings are small enough to be quick and large enough that the arrays weigh (tens to
hundreds of MB); the table at default settings is benchmarks/memory_model.py's (in
docs/validation.md)."""

from __future__ import annotations

import pytest
from clihelp import GS, LUZI

from pkmlab.runtime import peak
from pkmlab.runtime.memory import OUTPUT_BYTES

pytestmark = pytest.mark.skipif(not peak.available(), reason="needs Linux /proc/self/clear_refs")


@pytest.mark.parametrize("argv, warm, arrays_at_least", [
    (["workspace", LUZI, "--resolution", "10"], ["workspace", LUZI, "--resolution", "40"],
     20e6),
    (["workspace", GS, "--resolution", "5"], ["workspace", GS, "--resolution", "40"], 50e6),
])
def test_estimate_within_2x_of_the_measured_peak(tmp_path, argv, warm, arrays_at_least):
    r = peak.measure([*argv, "--out", tmp_path / "a"], [[*warm, "--out", tmp_path / "w"]])
    assert r["code"] == 0, r["stderr"][-2000:]
    est = max(b for _, b in r["estimates"])
    assert est >= arrays_at_least, r["estimates"]      # the arrays weigh in the comparison
    ratio = (est + OUTPUT_BYTES) / r["rise"]
    assert 0.5 <= ratio <= 2.0, (est / 2**20, r["rise"] / 2**20, ratio)
