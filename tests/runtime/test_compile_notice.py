"""Issue 26 item 5: a command that compiles numba kernels says so, with an estimate, keeps
saying so while it compiles, and says how long it took; one that loads them from the cache
says nothing (numba's compile event fires on a cache miss only)."""

from __future__ import annotations

import itertools

import numpy as np
from clihelp import HW, cli
from numba import njit

from pkmlab.runtime.compilenotice import compile_notice, estimate_text

_N = itertools.count()


def _fresh():
    """A function numba has never compiled in this process (a new closure each time)."""
    k = next(_N)

    def f(x):
        return x * 2.0 + k
    return njit(cache=False)(f)


def test_notice_on_a_compile_with_an_estimate_and_a_closing_line():
    said = []
    with compile_notice(said.append, "rss6 ", "kinematics", every=1e6):
        _fresh()(np.ones(3))
        _fresh()(np.ones(3))
    assert len(said) == 2, said
    assert said[0].startswith("compiling rss6 kernels, one-off (cached for later runs), "
                              + estimate_text("kinematics"))
    assert said[-1].startswith("compiled 2 numba function(s) in ")


def test_no_notice_without_a_compile():
    f = _fresh()
    f(np.ones(3))                                   # compiled before the notice listens
    said = []
    with compile_notice(said.append, "x ", "study"):
        f(np.ones(3))
    assert said == []


def test_still_compiling_lines_while_it_goes_on():
    import time

    from numba.core import event

    said = []
    with compile_notice(said.append, "", "study", every=0.05):
        event.start_event("numba:compile", data={})     # a long compile, simulated
        time.sleep(0.3)
        event.end_event("numba:compile", data={})
    assert said[0].startswith("compiling kernels, one-off")
    assert any(s.startswith("still compiling kernels (0 function(s), ") for s in said)
    assert said[-1].startswith("compiled 1 numba function(s)")


def test_every_command_announces_its_compile(capsys, monkeypatch):
    """Through the console entry point (any command): ik on the 6-PSU, with a compile forced
    inside the command, names the family and the kinematics estimate on stderr."""
    import pkmlab.cli.kinematics as kin

    real = kin._load

    def load_and_compile(path):
        _fresh()(np.ones(2))
        return real(path)

    monkeypatch.setattr(kin, "_load", load_and_compile)
    code, _, err = cli(capsys, "ik", HW, "--pose", "0,0,300,0,0,0")
    assert code == 0, err
    lines = [ln for ln in err.splitlines() if ln.startswith("pkmlab: ")]
    assert lines[0] == ("pkmlab: compiling psu6 kernels, one-off (cached for later runs), "
                        f"{estimate_text('kinematics')}, longer on a loaded machine; the "
                        "time estimates leave it out")
    assert lines[-1].startswith("pkmlab: compiled ")
