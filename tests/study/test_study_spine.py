"""The typed study spine: validate = run, resolved files, metric registry, failure policy,
re-runs, derived parametrisations, footprint, CLI conventions (issue "Trustworthy numbers")."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.errors import ParameterError
from pkmlab.study import (
    METRICS,
    CandidateError,
    SerialRunner,
    load_study,
    run_study,
    study_from_mapping,
    study_schema,
)
from pkmlab.study import evaluators as ev_mod

ROOT = Path(__file__).resolve().parents[2]
HOPKINS = MECH_DIR / "hopkins-williams-6psu.yaml"
SHIPPED = sorted((ROOT / "studies").glob("*.yaml")) + sorted(
    (ROOT / "studies" / "templates").glob("*.yaml"))


def study(tmp_path: Path, **over) -> dict:
    data = {
        "study": "spine",
        "mechanism": {"file": str(HOPKINS)},
        "design": {"platform_outer_radius": {"low": "55 mm", "high": "90 mm"},
                   "link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "dexterous", "box": ["8 deg"] * 3, "samples": 2,
                                   "resolution": "8 mm"}},
        "objectives": [{"maximize": "dexterous_volume"}],
        "optimizer": {"method": "sobol", "samples": 4},
        "seed": 1,
        "output": str(tmp_path / "out"),
        "top": 1,
    }
    data.update(over)
    return data


def write(tmp_path: Path, data: dict, name: str = "study.yaml") -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return p


# ---- whatever validates, runs ----------------------------------------------------------------

WS = {"kind": "dexterous", "box": ["8 deg"] * 3, "samples": 2, "resolution": "8 mm"}
VALIDATE_EQUALS_RUN = [
    ("constant kind with a box", {"evaluate": {"workspace": {**WS, "kind": "constant"}}},
     "evaluate.workspace.kind"),
    ("resolution below the engine's range",
     {"evaluate": {"workspace": {**WS, "resolution": "0.01 mm"}}},
     "evaluate.workspace.resolution"),
    ("negative characteristic length",
     {"evaluate": {"workspace": WS, "dexterity": {"characteristic_length": "-5 mm"}}},
     "evaluate.dexterity.characteristic_length"),
    ("zero characteristic length (was silently 'auto')",
     {"evaluate": {"workspace": WS, "dexterity": {"characteristic_length": 0}}},
     "evaluate.dexterity.characteristic_length"),
    ("Euler half-range of 200 deg",
     {"evaluate": {"workspace": {**WS, "box": ["200 deg", "5 deg", "5 deg"]}}},
     "evaluate.workspace.box"),
    ("the same objective twice",
     {"objectives": [{"maximize": "dexterous_volume"}, {"maximize": "dexterous_volume"}]},
     "objectives[1].maximize"),
    ("constraint min above max",
     {"constraints": [{"dexterous_volume": {"min": 500, "max": 100}}]}, "constraints[0]"),
    ("negative seed", {"seed": -1}, "seed"),
    ("flag shorthand on a non-flag", {"constraints": [{"dexterous_volume": True}]},
     "constraints[0].dexterous_volume"),
]


@pytest.mark.parametrize("label, over, field", VALIDATE_EQUALS_RUN,
                         ids=[c[0] for c in VALIDATE_EQUALS_RUN])
def test_validate_rejects_what_run_would_reject(tmp_path, label, over, field):
    path = write(tmp_path, study(tmp_path, **over))
    with pytest.raises(ParameterError) as exc:
        load_study(path)
    assert exc.value.field.startswith(field), str(exc.value)
    r = CliRunner().invoke(app, ["validate", str(path)])
    assert r.exit_code == 2 and field in r.stderr, r.output
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("path", SHIPPED, ids=[p.name for p in SHIPPED])
def test_every_shipped_study_validates_and_its_baseline_runs(path):
    s = load_study(path)
    rec = ev_mod.evaluate_design(s.space, None, s.evaluation, s.seed)
    assert rec["status"] in ("ok", "invalid", "failed"), rec["reason"]
    if rec["status"] == "ok":
        assert set(rec["metrics"]) == set(s.evaluation.metrics)
    # and the schema editors use accepts it
    jsonschema = pytest.importorskip("jsonschema")
    jsonschema.validate(yaml.safe_load(path.read_text()), study_schema())


def test_schema_rejects_an_unknown_metric():
    jsonschema = pytest.importorskip("jsonschema")
    data = yaml.safe_load((ROOT / "studies/hopkins-6psu-redesign.yaml").read_text())
    data["objectives"] = [{"maximize": "beauty"}]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(data, study_schema())


# ---- study.resolved.yaml -----------------------------------------------------------------------


def test_resolved_study_reloads_to_the_same_study_in_its_stated_units(tmp_path):
    data = study(tmp_path, design={"platform_rotation": {"low": "10 deg", "high": "50 deg"},
                                   "link_length": {"low": "200 mm", "high": "260 mm"}})
    s = load_study(write(tmp_path, data))
    r = s.resolved()
    # angles labelled deg are degrees; the workspace block is resolved with its defaults
    assert r["design"]["platform_rotation"]["low"] == "10 deg"
    ws = r["evaluate"]["workspace"]
    assert ws["box"] == ["8 deg"] * 3 and ws["slice_window"] == "auto"
    assert ws["slice_layout"] == "auto" and ws["slice_spacing"] == "auto"
    assert ws["constraints"]["connected"] is True and ws["semantics"] == "simultaneous"
    assert r["mechanism"]["inline"]["generator"]["platform_rotation"] == "33.7 deg"
    back = study_from_mapping(yaml.safe_load(yaml.safe_dump(r)))
    assert back.fingerprint() == s.fingerprint() and back.resolved() == r
    assert back.baseline() == s.baseline()


# ---- metric registry ---------------------------------------------------------------------------


def test_readme_metric_table_is_the_registry():
    from pkmlab.study.evaluators.registry import metrics_markdown

    readme = (ROOT / "README.md").read_text()
    assert metrics_markdown() in readme, "regenerate the README table: pkmlab metrics"


def test_docs_evaluate_table_has_a_row_for_every_evaluator_and_its_metrics():
    """docs/studies.md's `evaluate` table names every registered block and every metric it
    declares (planar_workspace, printer, delta_task and volume_bracket had no row)."""
    import re

    from pkmlab.study.evaluators.registry import EVALUATORS

    text = (ROOT / "docs" / "studies.md").read_text()
    rows = {m.group(1): m.group(0) for m in re.finditer(r"^\| `([a-z_0-9]+)` \|.*$", text,
                                                          re.M)}
    for name, ev in EVALUATORS.items():
        if name == "geometry":                      # the "(always)" row
            continue
        assert name in rows, f"docs/studies.md: no row for evaluate.{name}"
        for m in ev.metrics:
            kind = re.sub(r"^(constant|reachable|dexterous)_", "<kind>_", m.name)
            assert m.name in rows[name] or kind in rows[name], (name, m.name)


def test_every_evaluator_writes_exactly_its_declared_metrics(monkeypatch, tmp_path):
    s = load_study(write(tmp_path, study(tmp_path)))
    metrics, _ = ev_mod.evaluate_mechanism(s.baseline(), s.evaluation, 0)
    assert set(metrics) == set(s.evaluation.metrics)
    real = ev_mod.EVALUATORS["workspace"].compute
    monkeypatch.setattr(ev_mod.EVALUATORS["workspace"], "compute",
                        lambda m, c: {**real(m, c), "bogus": 1.0})
    with pytest.raises(AssertionError, match="bogus"):
        ev_mod.evaluate_mechanism(s.baseline(), s.evaluation, 0)


def test_sampled_statistics_say_so_in_their_names():
    for m in METRICS.values():
        if m.statistic == "sampled":
            assert m.name.startswith("sampled_") or m.name.startswith("gci"), m.name
        if re.search(r"(^|_)(worst|max|min)(_|$)", m.name) and not m.name.startswith("sampled"):
            assert m.statistic in ("worst-case", "exact", "bound"), m.name


# ---- footprint ---------------------------------------------------------------------------------


def test_luzi_platform_radius_is_measured_from_the_platform_centre():
    mech = load_mechanism(MECH_DIR / "luzi-3chain.yaml")   # 280 mm platform diameter
    assert mech.footprint()["platform_radius"] == pytest.approx(140.0, abs=1e-9)
    assert mech.footprint()["base_radius"] == pytest.approx(420.0, abs=1e-9)
    metrics = ev_mod.EVALUATORS["geometry"](mech, None)
    assert metrics["platform_outer_radius"] == pytest.approx(140.0, abs=1e-9)


# ---- failure policy ----------------------------------------------------------------------------


def test_a_programming_error_stops_the_run_after_it_is_recorded(monkeypatch, tmp_path):
    s = load_study(write(tmp_path, study(tmp_path)))

    def broken(mech, ctx):
        raise TypeError("unsupported operand")            # a bug, not a numerical failure

    monkeypatch.setattr(ev_mod.EVALUATORS["workspace"], "compute", broken)
    with pytest.raises(CandidateError) as exc:
        run_study(s, SerialRunner())
    assert "TypeError" in str(exc.value) and "Traceback" in exc.value.details
    from pkmlab.study.store import Store

    rows = Store(s.output / "evaluations.sqlite", read_only=True).all()
    assert len(rows) == 1 and rows[0]["status"] == "error"
    assert "broken" in rows[0]["reason"]                   # the traceback is kept


def test_declared_failures_are_data_with_a_reason(tmp_path):
    data = study(tmp_path, design={"platform_inner_radius": {"low": "40 mm", "high": "120 mm"}})
    s = load_study(write(tmp_path, data))
    rec = ev_mod.evaluate_design(s.space, {"platform_inner_radius": 110.0}, s.evaluation, 0)
    assert rec["status"] == "invalid" and "platform_radii" in rec["reason"]


def test_capability_search_is_not_capped_silently(monkeypatch):
    """The old search stopped at 60° without a word; the bracket and note are reported."""
    from pkmlab import OrientationSet

    class Fake:
        def __init__(self, empty):
            self.empty = empty

    def fake_workspace(limit):
        return lambda mech, kind, o, h, c: Fake(o.angles[0] > np.radians(limit) + 1e-12)

    req = {"orientations": OrientationSet.box(np.radians([5.0] * 3), samples=3),
           "resolution": 5.0, "constraints": None}
    monkeypatch.setattr(ev_mod.orientation_capability, "workspace", fake_workspace(75.0))
    a, bracket, note = ev_mod.capability(None, req)
    assert a <= 75.0 < a + bracket and bracket <= 0.25 and note == ""
    monkeypatch.setattr(ev_mod.orientation_capability, "workspace", fake_workspace(1000.0))
    a, bracket, note = ev_mod.capability(None, req)
    assert a == 180.0 and "not bounded" in note


# ---- re-runs -----------------------------------------------------------------------------------


def test_a_rerun_never_mixes_with_or_deletes_an_earlier_run(tmp_path):
    path = write(tmp_path, study(tmp_path))
    r = CliRunner().invoke(app, ["run", str(path), "--json"])
    assert r.exit_code == 0, r.output
    before = (tmp_path / "out" / "evaluations.sqlite").read_bytes()
    r = CliRunner().invoke(app, ["run", str(path)])
    assert r.exit_code == 2 and "--overwrite" in r.stderr
    assert (tmp_path / "out" / "evaluations.sqlite").read_bytes() == before
    stale = tmp_path / "out" / "designs" / "99-0123abcd"     # a design of the earlier run
    stale.mkdir(parents=True)
    (stale / "design.json").write_text("{}")
    r = CliRunner().invoke(app, ["run", str(path), "--overwrite", "--json"])
    assert r.exit_code == 0, r.output
    assert not stale.exists()


def test_a_second_run_into_a_folder_in_use_refuses_naming_the_holder(tmp_path):
    from pkmlab.study.run import OutputLock

    s = load_study(write(tmp_path, study(tmp_path)))
    code = ("import sys, time; from pkmlab.study.run import OutputLock; "
            f"l = OutputLock({str(s.output)!r}).__enter__(); print('locked', flush=True); "
            "time.sleep(30)")
    holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(ParameterError, match=f"pid {holder.pid}"):
            run_study(s, SerialRunner())
        with pytest.raises(ParameterError):
            with OutputLock(s.output):
                pass
    finally:
        holder.kill()
        holder.wait()
    assert not (s.output / "evaluations.sqlite").exists()


# ---- coupled variables -------------------------------------------------------------------------


def test_derived_parametrisation_removes_the_invalid_share(tmp_path):
    ups = MECH_DIR / "gough-stewart-6ups.yaml"
    over = {"base_points": None, "platform_points": None,
            "generator": {"base_radii": ["430 mm", "430 mm"], "platform_radii": [90, 90],
                          "platform_rotation": "60 deg", "base_pair_separation": "30 deg",
                          "platform_pair_separation": "30 deg", "base_pair_angle": "90 deg"}}
    base = study(tmp_path, mechanism={"file": str(ups), "overrides": over},
                 evaluate={"workspace": {**WS, "resolution": "25 mm"}})
    coupled = dict(base, design={"base_outer_radius": {"low": "300 mm", "high": "500 mm"},
                                 "base_inner_radius": {"low": "300 mm", "high": "500 mm"}})
    ratio = dict(base, design={"base_outer_radius": {"low": "300 mm", "high": "500 mm"},
                               "base_inner_ratio": {"low": 0.6, "high": 1.0,
                                                    "quantity": "number"}},
                 derived={"base_inner_radius": "base_inner_ratio * base_outer_radius"})
    bad_coupled, _ = load_study(write(tmp_path, coupled, "c.yaml")).space.validity(64)
    s = load_study(write(tmp_path, ratio, "r.yaml"))
    bad_ratio, _ = s.space.validity(64)
    assert bad_coupled > 0.3 and bad_ratio == 0.0
    mech = s.space.decode({"base_outer_radius": 400.0, "base_inner_ratio": 0.75})
    r = np.linalg.norm(mech.base_points[:, :2], axis=1)
    assert sorted(set(np.round(r, 9))) == [300.0, 400.0]
    # study.resolved.yaml keeps the derived field's name (a rebuilt report's card showed the
    # path generator.base_radii[0]); the alias and its path are the same study
    res = s.resolved()
    assert res["derived"] == {"base_inner_radius": "base_inner_ratio * base_outer_radius"}
    again = load_study(write(tmp_path, {**res, "output": str(tmp_path / "out")}, "res.yaml"))
    assert [d.name for d in again.space.derived] == ["base_inner_radius"]
    by_path = dict(ratio, derived={"generator.base_radii[0]":
                                   "base_inner_ratio * base_outer_radius"})
    assert load_study(write(tmp_path, by_path, "p.yaml")).fingerprint() == s.fingerprint()
    r = CliRunner().invoke(app, ["validate", str(tmp_path / "c.yaml"), "--json"])
    assert r.exit_code == 0 and json.loads(r.stdout)["warnings"], r.output


@pytest.mark.parametrize("expr, field", [("base_outer_radius *", "derived.base_inner_radius"),
                                         ("__import__('os')", "derived.base_inner_radius"),
                                         ("wheel * 2", "derived.base_inner_radius")])
def test_derived_expressions_are_checked_at_load(tmp_path, expr, field):
    data = study(tmp_path, design={"base_outer_radius": {"low": "150 mm", "high": "170 mm"}},
                 derived={"base_inner_radius": expr})
    with pytest.raises(ParameterError) as exc:
        load_study(write(tmp_path, data))
    assert exc.value.field == field


# ---- CLI conventions ---------------------------------------------------------------------------


def test_version_and_json_on_validate_and_report(tmp_path):
    from pkmlab import __version__

    r = CliRunner().invoke(app, ["--version"])
    assert r.exit_code == 0 and r.stdout.strip() == f"pkmlab {__version__}"
    path = write(tmp_path, study(tmp_path))
    r = CliRunner().invoke(app, ["validate", str(path), "--json"])
    assert r.exit_code == 0 and json.loads(r.stdout)["valid"] is True
    assert CliRunner().invoke(app, ["run", str(path)]).exit_code == 0
    r = CliRunner().invoke(app, ["report", str(tmp_path / "out"), "--json"])
    assert r.exit_code == 0 and json.loads(r.stdout)["evaluations"] == 5


def test_unexpected_errors_print_one_line_unless_debug(tmp_path):
    code = ("import sys; import pkmlab.mechanisms.base as b\n"
            "def boom(*a, **k): raise RuntimeError('kaput')\n"
            "b.Mechanism.inverse = boom\n"
            "from pkmlab.cli import main\n"
            "sys.argv = ['pkmlab'] + sys.argv[1:]\nmain()\n")
    args = ["ik", str(HOPKINS), "--pose", "0,0,300,0,0,0"]
    r = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "kaput" in r.stderr
    r = subprocess.run([sys.executable, "-c", code, "--debug", *args], capture_output=True,
                       text=True)
    assert r.returncode != 0 and "Traceback" in r.stderr and "kaput" in r.stderr


@pytest.mark.parametrize("args", [["ik", str(HOPKINS)], ["workspace", str(HOPKINS), "--samples",
                                                         "abc"], ["nosuch"]])
def test_usage_errors_are_one_line_with_exit_2(args):
    code = "import sys; from pkmlab.cli import main; sys.argv = ['pkmlab'] + sys.argv[1:]; main()"
    r = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True)
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and r.stderr.startswith("error: ")


def test_study_worst_kappa_is_the_workspace_worst_not_a_random_samples(tmp_path):
    """The 6-UPS layout that passed worst_kappa <= 50 with a 500-pose sample has a singularity
    inside its ±10° dexterous workspace: the study metric now says so."""
    ups = MECH_DIR / "gough-stewart-6ups.yaml"
    over = {"base_points": None, "platform_points": None,
            "generator": {"base_radii": ["240 mm", "400 mm"], "platform_radii": [90, 90],
                          "base_pair_angle": "90 deg", "platform_rotation": "60 deg",
                          "base_pair_separation": "10 deg",
                          "platform_pair_separation": "10 deg"}}
    data = study(tmp_path, mechanism={"file": str(ups), "overrides": over},
                 design={"base_outer_radius": {"low": "380 mm", "high": "420 mm"}},
                 evaluate={"workspace": {**WS, "box": ["10 deg"] * 3, "samples": 3,
                                         "resolution": "20 mm"},
                           "dexterity": {"gci_samples": 500}},
                 constraints=[{"worst_kappa": {"max": 50}}, {"singularity_free": True}])
    s = load_study(write(tmp_path, data))
    rec = ev_mod.evaluate_design(s.space, None, s.evaluation, 4)
    assert rec["status"] == "ok", rec["reason"]
    m = rec["metrics"]
    assert m["sampled_max_kappa"] < 1e6                       # what the old metric reported
    assert m["worst_kappa"] is None and "singular" in rec["notes"]["worst_kappa"]
    assert m["singularity_free"] == 0.0 and m["min_force"] == 0.0
    from pkmlab.study.run import feasible

    assert not feasible(s, [{"status": "ok", "metrics": m}])[0]
