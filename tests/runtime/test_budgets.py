"""Time budget (PKMLAB_TIME_LIMIT) and lazily generated candidates: a request estimated over
the budget is refused in one line with a coarser setting before the long work starts; the
sampling optimisers hold one chunk of candidates at a time."""

from __future__ import annotations

import logging
import time
import tracemalloc

import numpy as np
import pytest
from clihelp import HW, LUZI, cli, one_line, small_study

import pkmlab
from pkmlab.errors import ParameterError
from pkmlab.runtime.time_budget import ENV, time_limit, workspace_seconds
from pkmlab.study import SerialRunner, load_study, run_study
from pkmlab.study.optimisers import lhs_chunks


@pytest.mark.parametrize("text,seconds", [("90", 90.0), ("90s", 90.0), ("20min", 1200.0),
                                          ("2h", 7200.0), ("1.5 d", 129600.0)])
def test_time_limit_units(monkeypatch, text, seconds):
    monkeypatch.setenv(ENV, text)
    assert time_limit() == seconds


@pytest.mark.parametrize("text", ["soon", "-5s", "0", "3 fortnights", "1e99"])
def test_a_bad_time_limit_names_the_variable(monkeypatch, text):
    monkeypatch.setenv(ENV, text)
    with pytest.raises(ParameterError, match=ENV):
        time_limit()


def test_workspace_over_the_time_budget_is_refused_with_a_coarser_resolution_that_fits(
        capsys, tmp_path, monkeypatch):
    """Luzi's sampled grid at 5 mm is estimated at ~20 s: refused under a 2 s budget, before
    any work (nothing written), naming --resolution and a spacing that then runs."""
    monkeypatch.setenv(ENV, "2s")
    assert pkmlab.load_mechanism(LUZI).nominal_pose is not None   # compiled before timing
    t = time.perf_counter()
    code, _, err = cli(capsys, "workspace", LUZI, "--resolution", "5", "--out", tmp_path / "a")
    line = one_line(code, err, "--resolution", "PKMLAB_TIME_LIMIT", "within 2 s", "try >=",
                    "got 5 mm")
    assert time.perf_counter() - t < 2.0 and not (tmp_path / "a").exists()
    suggested = float(line.split("try >= ")[1].split(" mm")[0])
    from pkmlab.workspaces import workspace

    res = workspace(pkmlab.load_mechanism(LUZI), "constant", resolution=suggested)
    assert res.volume > 0 and res.timings["total_s"] < 2 * 6      # the model's factor


def test_long_workspace_estimate_is_shown_before_the_work(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr("pkmlab.runtime.time_budget.LOG_FROM_S", 0.0)
    code, out, err = cli(capsys, "workspace", HW, "--resolution", "10", "--out", tmp_path)
    assert code == 0, err
    assert "pkmlab: resolution: 10 mm" in err and "estimated at" in err


def test_the_cost_model_is_the_right_order_of_magnitude():
    """The sampled-method model against a measured Luzi grid (~1 s): within a factor of 6
    either way. CPU time, not wall time: the model is for an unloaded core, and the test
    machine is shared."""
    from pkmlab.workspaces import workspace

    mech = pkmlab.load_mechanism(LUZI)
    workspace(mech, "constant", resolution=30.0)                  # compile first
    cpu = time.process_time()
    workspace(mech, "constant", resolution=12.0)
    cpu = time.process_time() - cpu
    bounds = mech.position_bounds(np.eye(3)[None])[0]
    cols = np.prod([len(np.arange(np.ceil(bounds[0, i] / 12), np.floor(bounds[1, i] / 12) + 1))
                    for i in range(2)])
    nz = int((bounds[1, 2] - bounds[0, 2]) / 12) + 1
    est = workspace_seconds(int(cols), 1, 6, nz, sampled=True)
    assert 1 / 6 < est / cpu < 6, (est, cpu)


def test_a_study_over_the_time_budget_stops_after_the_baseline(tmp_path, monkeypatch, caplog):
    """The remaining evaluations × the baseline's measured time exceed the budget: refused
    naming optimizer.samples with a count that fits; only the baseline is stored."""
    p = small_study(tmp_path, optimizer={"method": "sobol", "samples": 100_000})
    monkeypatch.setenv(ENV, "5s")
    with pytest.raises(ParameterError, match="optimizer.samples") as info:
        run_study(load_study(p), SerialRunner())
    msg = str(info.value)
    assert "100000 evaluations at" in msg and "try <= " in msg
    import sqlite3

    con = sqlite3.connect(tmp_path / "out" / "evaluations.sqlite")
    assert con.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0] == 1
    con.close()
    # within budget: the estimate is logged before the candidates, and the run completes
    monkeypatch.setenv(ENV, "1h")
    monkeypatch.setattr("pkmlab.runtime.time_budget.LOG_FROM_S", 0.0)
    ok = tmp_path / "ok"
    ok.mkdir()
    q = small_study(ok)
    with caplog.at_level(logging.INFO, logger="pkmlab.study.optimisers"):
        store = run_study(load_study(q), SerialRunner())
    assert len(store.all()) == 5
    store.close()
    assert any("4 evaluations at" in r.getMessage() and "estimated at" in r.getMessage()
               for r in caplog.records)


# ---- candidates generated lazily -----------------------------------------------------------

@pytest.mark.parametrize("n,d", [(1, 1), (2, 3), (7, 2), (1000, 3), (20_000, 2)])
def test_lazy_latin_hypercube_is_latin(n, d):
    """Every dimension has exactly one point per stratum [k/n, (k+1)/n)."""
    u = np.concatenate(list(lhs_chunks(n, d, seed=3)))
    assert u.shape == (n, d) and np.all((u >= 0) & (u < 1))
    for j in range(d):
        assert np.array_equal(np.sort(np.floor(u[:, j] * n).astype(int)), np.arange(n))


def test_lazy_latin_hypercube_is_reproducible_and_its_dimensions_independent():
    a = np.concatenate(list(lhs_chunks(2000, 3, seed=11)))
    b = np.concatenate(list(lhs_chunks(2000, 3, seed=11, size=37)))
    c = np.concatenate(list(lhs_chunks(2000, 3, seed=12)))
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    corr = np.corrcoef(a.T)[np.triu_indices(3, 1)]
    assert np.all(np.abs(corr) < 4 / np.sqrt(2000))       # 4 σ of independent columns
    assert not np.all(np.diff(np.floor(a[:, 0] * 2000)) == 1)   # not the identity order


@pytest.mark.parametrize("method", ["lhs", "sobol", "grid"])
def test_the_first_chunk_of_ten_million_candidates_is_small(tmp_path, method):
    """10⁷ candidates in 4 variables: generating the first chunk allocates under 8 MiB
    (scipy's all-at-once Latin hypercube took 1.1 GiB)."""
    from pkmlab.study.optimisers import OPTIMISERS

    opt = {"method": method, "samples": 10_000_000}
    design = {"link_length": {"low": "200 mm", "high": "260 mm"},
              "base_outer_radius": {"low": "150 mm", "high": "180 mm"},
              "platform_outer_radius": {"low": "70 mm", "high": "90 mm"},
              "platform_rotation": {"low": "20 deg", "high": "40 deg"}}
    if method == "grid":
        opt = {"method": "grid"}
        design = {k: {**v, "levels": 56} for k, v in design.items()}      # 56⁴ ≈ 10⁷
    study = load_study(small_study(tmp_path, optimizer=opt, design=design))

    class First(Exception):
        pass

    seen = []

    def evaluate_batch(batch):
        seen.append(len(batch))
        raise First

    tracemalloc.start()
    try:
        with pytest.raises(First):
            OPTIMISERS[method](study.space, evaluate_batch, study.optimizer, 1)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert seen == [256] and peak < 8 * 2**20, peak


def test_the_suggested_resolution_fits_both_budgets(monkeypatch):
    """A grid over the memory budget suggests a spacing whose estimate fits the time budget
    too (Luzi at 0.05 mm: 705 GiB; with a 1 h budget, 0.5 mm would fit memory but not time)."""
    import pkmlab.workspaces.engine as engine
    from pkmlab.runtime.memory import memory_limit

    monkeypatch.setenv(ENV, "1h")
    mech = pkmlab.load_mechanism(LUZI)
    with pytest.raises(ParameterError, match="fit in") as info:
        engine.workspace(mech, "constant", resolution=0.05)
    h = float(str(info.value).split("try >= ")[1].split(" mm")[0])

    class Stop(Exception):
        pass

    seen = {}

    def record_time(field, need, *a, **k):
        seen["seconds"] = need
        raise Stop

    monkeypatch.setattr(engine, "require", lambda f, need, *a, **k: seen.update(bytes=need))
    monkeypatch.setattr(engine, "require_time", record_time)
    with pytest.raises(Stop):
        engine.workspace(mech, "constant", resolution=h)
    assert seen["bytes"] <= memory_limit() and seen["seconds"] <= 3600.0, (h, seen)


def test_a_cost_that_fits_gets_no_hint_and_never_overflows():
    """An integer setting with zero need (a plugin's evaluator whose time model is 0 s) used to
    raise OverflowError while building the unused hint; a need over the limit still gets one."""
    from pkmlab.study.evaluators.registry import Cost, check_costs

    free = Cost("evaluate.x.samples", 5, "", 0.5, bytes=0.0, seconds=0.0, integer=True)
    assert free.fits(0.0, 10.0) == ""
    assert check_costs([free]) == [free]
    big = Cost("evaluate.x.samples", 100, "", 1.0, seconds=40.0, integer=True)
    assert big.fits(40.0, 10.0) == "try <= 22"
