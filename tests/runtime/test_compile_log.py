"""``runtime.jit.compile_log`` records numba compiles, and only compiles (issue 28 item 4: the
first run says what it compiled)."""

from __future__ import annotations

from numba import njit

from pkmlab.runtime.jit import compile_log


def test_compile_log_records_compiles_not_reuse():
    @njit
    def twice(x):
        return 2.0 * x

    @njit
    def outer(x):
        return twice(x) + 1.0

    with compile_log() as first:
        assert outer(1.0) == 3.0
    assert [n for n, _ in first.compiled] == ["outer"]      # twice compiled inside outer
    assert first.seconds > 0 and "compiled 1 numba function(s)" in first.summary()
    with compile_log() as again:
        assert outer(2.0) == 5.0                             # already compiled
        assert twice(3.0) == 6.0
    assert again.compiled == []
    assert again.summary().startswith("no numba kernel compiled")
    with compile_log() as other:
        assert outer(2) == 5.0                               # a new signature compiles
    assert [n for n, _ in other.compiled] == ["outer"]
