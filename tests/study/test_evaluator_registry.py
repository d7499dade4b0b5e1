"""Issue 23 item 4: evaluators as objects in a public registry.

* ``pkmlab schema`` types every ``evaluate`` block from its evaluator's block model;
* ``load_study`` refuses a block the mechanism cannot serve, naming ``evaluate.<block>``
  (the three-leg translational plugin family of tests/data/plugin3), and what validates runs;
* an evaluator added from outside the package (one class + one ``register_evaluator`` call)
  is listed by ``pkmlab metrics``, described by ``pkmlab schema``, runs in a study and its
  metric reaches the store and the CSV.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import pytest
import yaml
from conftest import MECH_DIR, family_registered
from pydantic import BaseModel, ConfigDict, Field
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.errors import ParameterError
from pkmlab.study import load_study, study_schema
from pkmlab.study.evaluators import (
    EVALUATORS,
    Evaluator,
    metric,
    register_evaluator,
    unregister_evaluator,
)
from pkmlab.study.metrics import METRICS
from pkmlab.study.store import Store

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "data" / "plugin3"))
import pkmlab_tri3_family as tri3  # noqa: E402

HW = MECH_DIR / "hopkins-williams-6psu.yaml"


def write(tmp_path: Path, data: dict, name: str = "study.yaml") -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    return p


# ---- 1. the schema types every block ----


def test_schema_types_every_evaluate_block_from_its_model():
    schema = study_schema()
    ev = schema["properties"]["evaluate"]
    assert ev["additionalProperties"] is False
    assert set(ev["properties"]) == {n for n, e in EVALUATORS.items() if e.block is not None}

    def typed(name):
        s = ev["properties"][name]["anyOf"][0]
        if "$ref" in s:
            s = schema["$defs"][s["$ref"].rsplit("/", 1)[1]]
        if s.get("type") == "array":
            s = s["items"]
            s = schema["$defs"][s["$ref"].rsplit("/", 1)[1]] if "$ref" in s else s
        return s

    for name, field in (("workspace", "resolution"), ("workspace", "constraints"),
                        ("dexterity", "gci_samples"), ("volume_bracket", "budget"),
                        ("trajectory", "segment_time"), ("task", "shape"),
                        ("motions", "sinusoid"), ("payload", "mass"),
                        ("actuators", "catalogue")):
        assert field in typed(name)["properties"], (name, field)
    for name in ("inscribed", "orientation_capability", "needed_stroke"):
        assert typed(name)["type"] == "boolean", name
    # the schema refuses a misspelt block and a wrongly typed field
    jsonschema = pytest.importorskip("jsonschema")
    base = {"study": "s", "mechanism": {"file": "m.yaml"}, "design": {"a": {}},
            "objectives": [{"maximize": "z_span"}], "optimizer": {"method": "grid"}}
    jsonschema.validate({**base, "evaluate": {"workspace": {"resolution": "5 mm"}}}, schema)
    for bad in ({"workspce": {}}, {"dexterity": {"gci_samples": "many"}},
                {"inscribed": {"yes": 1}}):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate({**base, "evaluate": bad}, schema)


# ---- 2. requirements against the mechanism ----


@pytest.fixture
def tri3_family():
    with family_registered(tri3.Tri3):
        yield


def tri3_study(tmp_path, evaluate: dict, objective: str = "base_outer_radius") -> dict:
    return {"study": "tri3", "seed": 1, "output": str(tmp_path / "out"),
            "mechanism": {"inline": {"family": "tri3",
                                     "base_points": tri3.circle(300.0).tolist(),
                                     "platform_points": tri3.circle(60.0).tolist(),
                                     "stroke": [250, 600]}},
            "design": {"stroke_max": {"low": "500 mm", "high": "650 mm",
                                      "path": "stroke[1]", "quantity": "length"}},
            "evaluate": evaluate, "objectives": [{"maximize": objective}],
            "optimizer": {"method": "sobol", "samples": 4}}


def test_validate_refuses_what_a_translational_family_cannot_serve(tri3_family, tmp_path):
    """Before: every non-spatial mechanism was refused as 'mechanism.family', whatever it was
    asked; now the block is named with what it needs, rotations first."""
    ws = {"kind": "constant", "resolution": "10 mm"}
    runner = CliRunner()
    cases = [({"workspace": ws, "orientation_capability": True}, "orientation_capability",
              "orientation_capability",
              r"needs rotations \(a free orientation coordinate\); family 'tri3' has "
              r"translational mobility \(x, y, z\)\); got True"),
             ({"workspace": {"kind": "dexterous", "box": [5, 5, 5], "resolution": "10 mm"}},
              "dexterous_volume", "workspace", "needs rotations"),
             ({"workspace": ws, "volume_bracket": {}}, "constant_volume", "volume_bracket",
              "needs six free pose coordinates")]
    for evaluate, objective, block, need in cases:
        path = write(tmp_path, tri3_study(tmp_path, evaluate, objective))
        with pytest.raises(ParameterError, match=rf"^evaluate\.{block} \(study\.yaml, line "
                           rf"\d+, column \d+\): must be a block this "
                           rf"mechanism can serve \({block} {need}"):
            load_study(path)
        r = runner.invoke(app, ["validate", str(path)])
        assert r.exit_code == 2 and f"evaluate.{block} (study.yaml" in r.stderr, r.output


@pytest.mark.parametrize("evaluate, objective", [
    ({}, "base_outer_radius"),
    # a constant workspace and dexterity (refused before: "needs six free pose coordinates")
    ({"workspace": {"kind": "constant", "resolution": "20 mm"},
      "dexterity": {"gci_samples": 200}}, "worst_kappa"),
    # the paper's motion on the free coordinates (refused before: "needs rotations")
    ({"trajectory": {"segment_time": 2.0}}, "paper_motion_margin"),
    # Newton–Euler balanced on the free coordinates (refused before: "needs six free pose
    # coordinates")
    ({"motions": [{"name": "p", "paper": True, "rate": "20 Hz"}],
      "payload": {"mass": "2 kg"}}, "peak_actuator_force")])
def test_what_validates_for_a_translational_family_runs(tri3_family, tmp_path, evaluate,
                                                        objective):
    data = tri3_study(tmp_path, evaluate, objective)
    if evaluate:
        data["optimizer"]["samples"] = 2
    path = write(tmp_path, data)
    runner = CliRunner()
    r = runner.invoke(app, ["validate", str(path), "--check-space", "0"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["run", str(path)])
    assert r.exit_code == 0, r.output
    rows = Store(tmp_path / "out" / "evaluations.sqlite", read_only=True).all()
    assert len(rows) == (3 if evaluate else 5) and {row["status"] for row in rows} == {"ok"}
    for row in rows:      # the base joints lie on a 300 mm circle in the base plane
        assert row["metrics"]["base_outer_radius"] == pytest.approx(300.0, abs=1e-9)
        assert row["metrics"]["servo_range"] is None
        if "dexterity" in evaluate:      # κ of the unit leg directions, no characteristic length
            assert row["metrics"]["worst_kappa"] > row["metrics"]["nominal_kappa"] >= 1.0
            assert row["metrics"]["characteristic_length"] is None
        if "motions" in evaluate:        # 2 kg held by three inclined legs, and moved
            assert row["metrics"]["motions_feasible"] == 1.0
            assert row["metrics"]["peak_actuator_force"] > 2.0 * 9.80665 / 3
        if "trajectory" in evaluate:     # x, y, z by ±2 in: the stroke is far from binding
            assert row["metrics"]["paper_motion_fits"] == 1.0
            assert 0.0 < row["metrics"]["paper_motion_margin"] < 350.0


def test_an_actuator_of_the_wrong_kind_is_refused_at_load(tmp_path):
    data = {"study": "servo", "mechanism": {"file": str(MECH_DIR /
                                                        "instructables-servo-6rss.yaml")},
            "design": {"crank_length": {"low": "20 mm", "high": "30 mm"}},
            "evaluate": {"motions": [{"name": "p", "paper": True}],
                         "payload": {"mass": "0.2 kg"},
                         "actuators": {"spec": {"name": "lin", "force": "10 N",
                                                "speed": "10 mm/s"}}},
            "objectives": [{"minimize": "peak_actuator_torque"}],
            "optimizer": {"method": "grid"}}
    with pytest.raises(ParameterError, match=r"^evaluate\.actuators \(study\.yaml, line \d+, "
                       r"column \d+\): must be a block this mechanism can serve \(actuators "
                       r"needs linear actuators; family 'rss6' has rotary actuators"):
        load_study(write(tmp_path, data))
    # the needed stroke is a prismatic travel (mm): a servo family is refused, not given a
    # null with a note for every candidate
    data["evaluate"] = {"workspace": {"kind": "dexterous", "box": [5, 5, 5], "samples": 3},
                        "needed_stroke": True}
    data["objectives"] = [{"minimize": "needed_stroke"}]
    with pytest.raises(ParameterError, match=r"^evaluate\.needed_stroke \(study\.yaml, line "
                       r"\d+, column \d+\): must be a block this mechanism can serve "
                       r"\(needed_stroke needs linear actuators; family 'rss6' has rotary"):
        load_study(write(tmp_path, data))


# ---- 3. an evaluator from outside the package ----


class MidStrokeSpec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    scale: float = Field(1.0, gt=0, description="factor applied to the mid-stroke length")


class MidStroke(Evaluator):
    name = "mid_stroke"
    block = MidStrokeSpec
    description = "the actuators' mid-stroke length, scaled"
    metrics = (metric("scaled_mid_stroke", "mm", "exact",
                      "scale × (stroke min + stroke max) / 2"),)

    def compute(self, mech, ctx) -> dict:
        q0, q1 = mech.stroke
        return {"scaled_mid_stroke": ctx.evaluation.mid_stroke.scale * 0.5 * (q0 + q1)}


@pytest.fixture
def mid_stroke():
    ev = register_evaluator(MidStroke())
    yield ev
    unregister_evaluator("mid_stroke")
    assert "mid_stroke" not in EVALUATORS and "scaled_mid_stroke" not in METRICS


def test_an_evaluator_added_from_outside_is_listed_described_and_run(mid_stroke, tmp_path):
    runner = CliRunner()
    r = runner.invoke(app, ["metrics", "--json"])
    assert r.exit_code == 0, r.output
    listed = json.loads(r.stdout)["scaled_mid_stroke"]
    assert listed == {"unit": "mm", "evaluator": "mid_stroke", "statistic": "exact",
                      "description": "scale × (stroke min + stroke max) / 2"}
    assert "| `scaled_mid_stroke` | mm | mid_stroke | exact |" in \
        runner.invoke(app, ["metrics"]).stdout
    r = runner.invoke(app, ["schema"])
    block = json.loads(r.stdout)["properties"]["evaluate"]["properties"]["mid_stroke"]
    assert "scale" in json.dumps(block)
    data = {"study": "mid", "mechanism": {"file": str(HW)},
            "design": {"stroke_max": {"low": "90 mm", "high": "120 mm"}},
            "evaluate": {"mid_stroke": {"scale": 2.0}},
            "objectives": [{"maximize": "scaled_mid_stroke"}],
            "optimizer": {"method": "sobol", "samples": 4}, "seed": 1,
            "output": str(tmp_path / "out")}
    path = write(tmp_path, data)
    with pytest.raises(ParameterError, match=r"evaluate\.mid_stroke\.scale \(bad\.yaml, "
                       r"line \d+, column \d+\): must be a number > 0"):
        load_study(write(tmp_path, {**data, "evaluate": {"mid_stroke": {"scale": -1}}},
                         "bad.yaml"))
    r = runner.invoke(app, ["run", str(path)])
    assert r.exit_code == 0, r.output
    rows = Store(tmp_path / "out" / "evaluations.sqlite", read_only=True).all()
    q0, q1_base = load_mechanism(HW).stroke
    assert len(rows) == 5 and {row["status"] for row in rows} == {"ok"}
    for row in rows:                                  # independent: 2 × (q0 + q1) / 2
        q1 = row["params"].get("stroke_max", q1_base) if isinstance(row["params"], dict) \
            else q1_base
        assert row["metrics"]["scaled_mid_stroke"] == pytest.approx(q0 + q1, abs=1e-9)
    with (tmp_path / "out" / "evaluations.csv").open() as f:
        table = list(csv.DictReader(f))
    assert len(table) == 5
    assert sorted(float(t["scaled_mid_stroke (mm)"]) for t in table) == pytest.approx(
        sorted(row["metrics"]["scaled_mid_stroke"] for row in rows), abs=1e-6)


def test_registration_refuses_what_would_break_the_registry():
    class Clash(MidStroke):
        name = "clash"
        metrics = (metric("z_span", "mm", "exact", "taken"),)

    with pytest.raises(ValueError, match="already written by 'workspace'"):
        register_evaluator(Clash())

    class Orphan(MidStroke):
        name = "orphan"
        after = ("nowhere",)

    with pytest.raises(ValueError, match="'after' names 'nowhere'"):
        register_evaluator(Orphan())
    with pytest.raises(ValueError, match="already registered"):
        register_evaluator(EVALUATORS["workspace"].__class__())
    with pytest.raises(ValueError, match="needed by"):
        unregister_evaluator("workspace")
    assert "clash" not in EVALUATORS and "orphan" not in EVALUATORS
