"""The kernel warmers and the parallel warm-up (issue 28 item 4, :mod:`pkmlab.runtime.warmers`,
:mod:`pkmlab.study.warm`).

* ``partition`` spreads warmers over processes with every warmer exactly once, by weight
  (longest first to the lightest: each process's total is within the largest weight of any
  other's), deterministically;
* the registry refuses a name twice and a weight that is not positive;
* the built-in warmers that apply follow the mechanism's declaration: the worst case's cell
  kernels for the 6-PSU (a numba Jacobian with a box enclosure), not for a planar five-bar;
* the kinematics warmer builds the drivers the IK and the Jacobian call (nothing compiles
  after it);
* a warm-up process that fails is reported, and the baseline's evaluation still fills the
  cache (the warm-up does not fail); the end-to-end check that a run after the warm-up
  compiles nothing is ``test_compile_once.py`` (which runs the warm-up in two processes).
"""

from __future__ import annotations

import logging
from concurrent.futures import Future

import pytest
from clihelp import small_study
from conftest import MECH_DIR

from pkmlab.config import load_mechanism
from pkmlab.runtime import warmers
from pkmlab.runtime.warmers import Warmer, partition, register_warmer, unregister_warmer
from pkmlab.study import warm


def _w(name, weight):
    return Warmer(name, weight, lambda m: True, lambda m: None)


def test_partition_is_balanced_complete_and_deterministic():
    ws = [_w(n, x) for n, x in [("a", 5), ("b", 4), ("c", 3), ("d", 3), ("e", 2), ("f", 1)]]
    bins = partition(ws, 2)
    names = sorted(w.name for b in bins for w in b)
    assert names == list("abcdef")
    totals = [sum(w.weight for w in b) for b in bins]
    assert totals == [9.0, 9.0]          # {a, c, f} / {b, d, e}: the exact split exists here
    assert partition(list(reversed(ws)), 2) == bins
    assert partition(ws, 1) == [sorted(ws, key=lambda w: -w.weight)]
    three = partition(ws, 3)
    loads = [sum(w.weight for w in b) for b in three]
    assert max(loads) - min(loads) <= 5


def test_the_registry_refuses_a_name_twice_and_a_weight_not_positive():
    register_warmer("test: a warmer", 1.0, lambda m: True, lambda m: None)
    try:
        with pytest.raises(ValueError, match="already registered"):
            register_warmer("test: a warmer", 1.0, lambda m: True, lambda m: None)
    finally:
        unregister_warmer("test: a warmer")
    with pytest.raises(ValueError, match="weight"):
        register_warmer("test: weightless", 0.0, lambda m: True, lambda m: None)
    assert "test: weightless" not in warmers.WARMERS


def test_the_built_in_warmers_follow_the_declaration():
    warm._builtin_warmers()
    psu = {w.name for w in warmers.applicable(load_mechanism(MECH_DIR /
                                                             "hopkins-williams-6psu.yaml"))}
    assert {"worst case: cell bounds", "worst case: cell pass",
            "capability search, branch and bound, certification",
            "tiled columns (all)"} <= psu
    bar = {w.name for w in warmers.applicable(load_mechanism(MECH_DIR / "fivebar-scara.yaml"))}
    assert not {n for n in bar if n.startswith("worst case") or "columns" in n}


def test_the_kinematics_warmer_builds_the_drivers_the_evaluation_calls():
    """After the kinematics warmer, the IK (Euler poses and frames) and the Jacobian of the
    6-PSU compile nothing: the warmer builds the very kernels they use (same factory, same
    arguments), so the warm-up's parallel phase covers them."""
    import numpy as np

    from pkmlab.runtime.jit import compile_log

    warm._builtin_warmers()
    mech = load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
    w = warmers.WARMERS["kinematics drivers (Euler, frames, Jacobian)"]
    assert w.applies(mech)
    w.build(mech)
    X = np.tile(mech.nominal_pose, (3, 1))
    with compile_log() as compiled:
        mech.inverse(X)
        mech.inverse(np.tile(np.eye(4), (3, 1, 1)))
        mech.jacobian(X)
    assert compiled.entries == []


class _FailingPool:
    """A process pool whose every task fails (a warm-up process that died)."""

    def __init__(self, *args, **kw):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def submit(self, fn, *args):
        f = Future()
        f.set_exception(RuntimeError("the process died"))
        return f


def test_a_failed_warm_up_process_is_reported_and_the_baseline_still_warms(
        tmp_path, monkeypatch, caplog):
    study = small_study(tmp_path)
    heavy = Warmer("test: heavy", 1e6, lambda m: True, lambda m: None)
    monkeypatch.setitem(warmers.WARMERS, heavy.name, heavy)  # alone here; the rest elsewhere
    monkeypatch.setattr(warm, "ProcessPoolExecutor", _FailingPool)
    with caplog.at_level(logging.WARNING, logger="pkmlab.study.warm"):
        seconds, lines = warm.warm_study(study, jobs=2)
    assert seconds > 0
    failed = [r.getMessage() for r in caplog.records if "warm-up process failed" in
              r.getMessage()]
    assert len(failed) == 1 and "worst case: cell bounds" in failed[0], failed
    assert "test: heavy" not in failed[0]
