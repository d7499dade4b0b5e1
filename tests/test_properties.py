"""Property suite: random psu6 / ups6 / luzi3 geometries raise only the declared errors and
never report a NaN as a valid number (50 examples here; benchmarks/fuzz.py runs 10,000)."""

from __future__ import annotations

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from pkmlab._fuzz import check_mapping, random_mapping  # noqa: E402


@settings(max_examples=50, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(min_value=0, max_value=2**32 - 1))
def test_random_geometries_fail_only_in_declared_ways(seed):
    outcome = check_mapping(random_mapping(np.random.default_rng(seed)))
    assert outcome in ("ok", "ParameterError", "NumericalError")
