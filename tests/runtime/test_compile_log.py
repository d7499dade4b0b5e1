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


def test_compile_lines_are_one_per_group_slowest_first():
    from pkmlab.runtime.jit import compile_lines, kernel_group

    assert kernel_group("pkmlab.mechanisms.kernels.ik") == "kinematics"
    assert kernel_group("pkmlab.mechanisms.kernels.tiles") == "workspace columns"
    assert kernel_group("pkmlab.mechanisms.kernels.search") == "capability search"
    assert kernel_group("pkmlab.dexterity._cells") == "dexterity"
    assert kernel_group("pkmlab.requirements.task") == "requirements"
    entries = [("drive_frames", 9.0, "kinematics"), ("cell_bounds_loop", 80.0, "dexterity"),
               ("drive_euler", 5.0, "kinematics"), ("_sweep_loop", 20.0, "dexterity")]
    lines = compile_lines(entries, "before the workers start")
    assert lines == [
        "compiled the dexterity kernels before the workers start in 100.0 s "
        "(cell_bounds_loop 80.0 s, _sweep_loop 20.0 s)",
        "compiled the kinematics kernels before the workers start in 14.0 s "
        "(drive_frames 9.0 s, drive_euler 5.0 s)"]
    assert compile_lines([], "anywhere") == []


def _compiles_in_task(x):
    """A task that compiles a new function wherever it runs (a kernel missing from the cache,
    as far as the runner can tell)."""
    @njit
    def fresh_in_worker(y):
        return y + 1.0

    return fresh_in_worker(x)


def test_a_compile_in_a_worker_is_reported_by_the_parent(caplog):
    """The parent compiles (or loads) every kernel before the workers start; a compile in a
    worker (a kernel the warm-up missed) is said by the parent, one line per group."""
    import logging

    from pkmlab.study.runners import JoblibRunner, SerialRunner

    r = JoblibRunner(2)
    with caplog.at_level(logging.INFO, logger="pkmlab.study.runners"):
        out = dict(r.map(_compiles_in_task, [(i, (float(i),)) for i in range(2)]))
    r.close()
    assert out == {0: 1.0, 1: 2.0}
    said = [m for m in caplog.messages if "in a worker" in m]
    assert said and all(m.startswith("compiled the ") and "fresh_in_worker" in m
                        for m in said), caplog.messages
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="pkmlab.study.runners"):
        assert dict(SerialRunner().map(_threads_free, [(0, (1.0,))])) == {0: 1.0}
    assert caplog.messages == []


def _threads_free(x):
    return x
