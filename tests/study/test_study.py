"""Design studies: validation corpus, Pareto filter, resume after kill -9, runners agree."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR
from typer.testing import CliRunner

from pkmlab.cli import app
from pkmlab.errors import ParameterError
from pkmlab.study import SerialRunner, load_study, pareto_mask, pareto_records, run_study
from pkmlab.study.runners import DaskRunner, JoblibRunner

HOPKINS = MECH_DIR / "hopkins-williams-6psu.yaml"


def small_study(tmp_path: Path, **over) -> dict:
    data = {
        "study": "tiny",
        "mechanism": {"file": str(HOPKINS)},
        "design": {"platform_outer_radius": {"low": "55 mm", "high": "90 mm"},
                   "platform_rotation": {"low": "10 deg", "high": "50 deg"},
                   "link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "dexterous", "box": ["10 deg"] * 3, "samples": 2,
                                   "resolution": "6 mm"},
                     "dexterity": {"gci_samples": 100}},
        "objectives": [{"maximize": "dexterous_volume"}, {"maximize": "gci"}],
        "constraints": [{"worst_kappa": {"max": 20}}],
        "optimizer": {"method": "sobol", "samples": 8},
        "seed": 3,
        "output": str(tmp_path / "out"),
        "top": 1,
    }
    for k, v in over.items():
        data[k] = v
    return data


def write(tmp_path: Path, data: dict, name="study.yaml") -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return p


def _drop(d, key):
    d = dict(d)
    d.pop(key)
    return d


# ---- validation corpus -------------------------------------------------------------------------

BAD = [
    ("unknown key", {"colour": "red"}, "colour"),
    ("wrong unit", {"design": {"link_length": {"low": "200 furlong", "high": "260 mm"}}},
     "design.link_length.low"),
    ("low > high", {"design": {"link_length": {"low": "260 mm", "high": "200 mm"}}},
     "design.link_length"),
    ("non-numeric bound", {"design": {"link_length": {"low": "long", "high": "260 mm"}}},
     "design.link_length.low"),
    ("unknown variable", {"design": {"wheel_base": {"low": 1, "high": 2}}},
     "design.wheel_base"),
    ("empty design space", {"design": {}}, "design"),
    ("unknown family", {"mechanism": {"file": str(HOPKINS), "overrides": {"family": "hexa"}}},
     "mechanism.family"),
    ("unknown metric", {"objectives": [{"maximize": "beauty"}]}, "objectives[0].maximize"),
    ("metric not computed", {"objectives": [{"maximize": "paper_motion_margin"}]},
     "objectives[0].maximize"),
    ("wrong kind volume", {"objectives": [{"maximize": "reachable_volume"}]},
     "objectives[0].maximize"),
    ("bad constraint", {"constraints": [{"worst_kappa": {"below": 3}}]},
     "constraints[0].worst_kappa"),
    ("bad optimizer", {"optimizer": {"method": "annealing"}}, "optimizer.method"),
    ("de with two objectives", {"optimizer": {"method": "de"}}, "optimizer.method"),
]


@pytest.mark.parametrize("label, over, field", BAD, ids=[b[0] for b in BAD])
def test_bad_study_files_name_the_field_and_write_nothing(tmp_path, label, over, field):
    path = write(tmp_path, small_study(tmp_path, **over))
    with pytest.raises(ParameterError) as exc:
        load_study(path)
    assert exc.value.field == field, str(exc.value)
    for cmd in ("validate", "run"):
        r = CliRunner().invoke(app, [cmd, str(path)])
        assert r.exit_code == 2 and field in r.stderr
    assert not (tmp_path / "out").exists()


def test_missing_section_and_schema(tmp_path):
    path = write(tmp_path, _drop(small_study(tmp_path), "objectives"))
    with pytest.raises(ParameterError, match="objectives"):
        load_study(path)
    r = CliRunner().invoke(app, ["schema"])
    assert r.exit_code == 0
    schema = json.loads(r.stdout)
    assert {"study", "design", "evaluate", "objectives", "optimizer"} <= set(
        schema["properties"])


def test_study_converts_units_once(tmp_path):
    study = load_study(write(tmp_path, small_study(tmp_path)))
    v = {x.name: x for x in study.variables}
    assert v["platform_rotation"].low == pytest.approx(np.radians(10))
    assert v["link_length"].high == 260.0
    assert (study.objectives[0].metric, study.objectives[0].sense) == ("dexterous_volume",
                                                                       "maximize")


# ---- Pareto ----------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(5))
def test_pareto_mask_equals_brute_force(seed):
    rng = np.random.default_rng(seed)
    F = rng.integers(0, 6, size=(60, 3)).astype(float)      # ties on purpose
    brute = np.array([not any(np.all(F[j] <= F[i]) and np.any(F[j] < F[i])
                              for j in range(len(F))) for i in range(len(F))])
    np.testing.assert_array_equal(pareto_mask(F), brute)


# ---- running ---------------------------------------------------------------------------------


def _snapshot(store_path: Path) -> dict:
    con = sqlite3.connect(store_path)
    rows = con.execute("SELECT key, status, metrics FROM evaluations").fetchall()
    con.close()
    return {k: (s, json.loads(m)) for k, s, m in rows}


@pytest.fixture(scope="module")
def serial_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("serial")
    res = load_study(write(tmp, small_study(tmp)))
    store = run_study(res, SerialRunner())
    records = store.all()
    store.close()
    return res, records, _snapshot(Path(res.output) / "evaluations.sqlite")


def test_serial_run_records_every_candidate(serial_run):
    res, records, snap = serial_run
    assert len(records) == 9                                 # 8 sobol + the baseline
    assert sum(r["role"] == "baseline" for r in records) == 1
    assert all(r["status"] in ("ok", "invalid", "failed") for r in records)
    assert all(r["status"] == "ok" or r["reason"] for r in records)
    front = pareto_records(res, records)
    assert front and all(r["status"] == "ok" for r in front)


def test_joblib_and_dask_give_the_same_store(serial_run, tmp_path):
    from distributed import Client, LocalCluster

    res, _, snap = serial_run
    for name in ("joblib", "dask"):
        r2 = res.with_output(tmp_path / name)
        if name == "joblib":
            runner = JoblibRunner(2)
            run_study(r2, runner).close()
        else:
            with LocalCluster(n_workers=2, processes=False, dashboard_address=None) as c, \
                    Client(c) as client:
                run_study(r2, DaskRunner(client=client)).close()
        other = _snapshot(tmp_path / name / "evaluations.sqlite")
        assert other == snap, name


NSGA = {"optimizer": {"method": "nsga2", "population": 6, "generations": 4}, "seed": 5}


def test_resume_after_kill_loses_and_repeats_nothing(tmp_path):
    data = small_study(tmp_path, **NSGA)
    data["output"] = str(tmp_path / "killed")
    path = write(tmp_path, data)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "pkmlab.cli", "run", str(path)], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    db = tmp_path / "killed" / "evaluations.sqlite"
    deadline = time.time() + 120
    n_before = 0
    while time.time() < deadline:
        if db.exists():
            try:
                con = sqlite3.connect(db)
                n_before = con.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0]
                con.close()
            except sqlite3.Error:
                n_before = 0
            if n_before >= 6:
                break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = _snapshot(db)
    assert 6 <= len(before), "the run was killed before it stored anything"

    res = load_study(path)
    done = []
    store = run_study(res, SerialRunner(), resume=True, progress=done.append)
    after = store.all()
    store.close()
    # nothing lost: every stored row is still there, unchanged
    snap = _snapshot(db)
    assert all(snap[k] == v for k, v in before.items())
    # nothing repeated: only the missing candidates were evaluated
    assert len(before) < len(after), "the run finished before it was killed"
    assert len(done) == len(after) - len(before)
    # the same result as an uninterrupted run with the same seed
    data["output"] = str(tmp_path / "straight")
    res2 = load_study(write(tmp_path, data, "straight.yaml"))
    store2 = run_study(res2, SerialRunner())
    straight = store2.all()
    store2.close()
    assert {r["key"] for r in straight} == {r["key"] for r in after}
    assert [r["key"] for r in pareto_records(res2, straight)] == \
        [r["key"] for r in pareto_records(res, after)]


def test_resume_refuses_a_changed_study(tmp_path):
    data = small_study(tmp_path)
    res = load_study(write(tmp_path, data))
    run_study(res, SerialRunner()).close()
    data["seed"] = 99
    res2 = load_study(write(tmp_path, data))
    with pytest.raises(ParameterError, match="--resume"):
        run_study(res2, SerialRunner(), resume=True)


def test_cli_run_end_to_end_and_report(tmp_path):
    data = small_study(tmp_path)
    data["evaluate"]["trajectory"] = {"paper_motion": True}
    data["constraints"].append({"paper_motion_fits": True})
    path = write(tmp_path, data)
    t0 = time.perf_counter()
    r = CliRunner().invoke(app, ["run", str(path), "--json"])
    assert r.exit_code == 0, r.output
    assert time.perf_counter() - t0 < 60
    info = json.loads(r.stdout)
    out = tmp_path / "out"
    for name in ("evaluations.csv", "pareto.csv", "pareto.png", "summary.md",
                 "study.resolved.yaml", "evaluations.sqlite"):
        assert (out / name).exists(), name
    assert info["evaluations"] == 9
    parts = info["timings_s"]                 # where the command's time went, in seconds
    assert set(parts) == {"evaluation_s", "summary_s", "export_s", "page_s"}
    assert all(v > 0 for v in parts.values())
    assert sum(parts.values()) < time.perf_counter() - t0
    lines = (out / "evaluations.csv").read_text().splitlines()
    assert len(lines) == 10
    designs = [d for d in (out / "designs").iterdir() if d.is_dir()]
    assert len(designs) == 1 and (designs[0] / "mechanism.yaml").exists()
    assert "baseline" in (out / "summary.md").read_text()
    (out / "pareto.png").unlink()
    r = CliRunner().invoke(app, ["report", str(out)])
    assert r.exit_code == 0 and (out / "pareto.png").exists()
    # the exported design is a valid mechanism file
    r = CliRunner().invoke(app, ["inspect", str(designs[0] / "mechanism.yaml"), "--json"])
    assert r.exit_code == 0, r.output


def test_compare_files_and_pareto_rows(tmp_path, serial_run):
    res, records, _ = serial_run
    from pkmlab.study.report import write_report

    out = Path(res.output)
    write_report(out, res, records)
    r = CliRunner().invoke(app, ["compare", str(HOPKINS), "--pareto", str(out / "pareto.csv"),
                                 "--rows", "1", "--box", "10", "--samples", "5",
                                 "--resolution", "5",
                                 "--out", str(tmp_path / "cmp"), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)["designs"]
    front = pareto_records(res, records)
    # the one numbering: the design is named by its evaluation number #seq (not its row)
    assert [x["label"] for x in d] == ["hopkins-williams-6psu", f"tiny #{front[0]['seq']}"]
    # the Pareto row is the study's rank-1 candidate, evaluated with the compare protocol
    from pkmlab import OrientationSet, workspace

    mech = res.space.decode(front[0]["params"])
    ref = workspace(mech, "dexterous", OrientationSet.box(np.radians([10.0] * 3), samples=5),
                    5.0)
    assert d[1]["dexterous_volume_cm3"] == pytest.approx(ref.volume / 1e3)
    assert (tmp_path / "cmp" / "compare.md").read_text().count("|") > 20
    assert "plotly" in (tmp_path / "cmp" / "compare.html").read_text()
    r = CliRunner().invoke(app, ["compare", "--pareto", str(out / "pareto.csv"), "--rows", "99"])
    assert r.exit_code == 2 and "--rows" in r.stderr


@pytest.mark.parametrize("optimizer, n", [({"method": "grid"}, 3 * 2 + 1),
                                          ({"method": "lhs", "samples": 5}, 6),
                                          ({"method": "de", "population": 4, "generations": 1},
                                           None)])
def test_other_optimisers_and_inline_mechanism(tmp_path, optimizer, n):
    data = small_study(tmp_path, optimizer=optimizer)
    data["mechanism"] = {"inline": {"name": "inline-6psu", "family": "psu6",
                                    "generator": {"base_radii": [100, 165],
                                                  "platform_radii": [50, 80],
                                                  "platform_rotation": "33.7 deg"},
                                    "link_length": "225 mm", "stroke": [0, "4 in"],
                                    "tool_offset": [0, 0, 47]}}
    data["design"] = {"platform_outer_radius": {"low": "60 mm", "high": "90 mm", "levels": 3},
                      "link_length": {"type": "integer", "low": 220, "high": 230, "levels": 2}}
    if optimizer["method"] == "lhs":
        data["design"]["pairing"] = {"choices": ["same", "crossed"]}
    if optimizer["method"] == "de":
        data["objectives"] = [{"maximize": "dexterous_volume"}]
    res = load_study(write(tmp_path, data))
    store = run_study(res, SerialRunner())
    recs = store.all()
    store.close()
    if n is not None:
        assert len(recs) == n
    cand = [r for r in recs if r["role"] == "candidate"]
    assert cand and all(isinstance(r["params"]["link_length"], int) for r in cand)
    assert all(220 <= r["params"]["link_length"] <= 230 for r in cand)
    if optimizer["method"] == "lhs":
        assert {r["params"]["pairing"] for r in cand} == {"same", "crossed"}
