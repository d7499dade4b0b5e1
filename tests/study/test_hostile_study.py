"""Hostile study files (issue 27, items 5, 6 and 8): ``derived:`` expressions that used to
crash, hang or take gigabytes; design variables or derived fields that set the family or the
name; values that validate but then fail every candidate. Each ends at ``validate`` in one
line naming the field (exit 2), within seconds."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest
import yaml
from clihelp import GS, cli, one_line, small_study

from pkmlab.errors import ParameterError
from pkmlab.study import load_study
from pkmlab.study.space import Expression

DESIGN = {"link_length": {"low": "200 mm", "high": "260 mm"},
          "k": {"low": 0.5, "high": 1.5, "quantity": "number"},
          "pairing": {"path": "generator.pairing", "quantity": "text",
                      "choices": ["same", "crossed"]}}


def _derived(tmp_path, expr):
    return small_study(tmp_path, design=DESIGN,
                       derived={"generator.platform_rotation": expr, "tool_offset[2]": "k * 47"})


# ---- item 5: derived expressions --------------------------------------------------------------

@pytest.mark.parametrize("expr, fragment", [
    ("max()", "max takes at least 2 arguments"),
    ("min(3)", "min takes at least 2 arguments"),
    ("sqrt(1, 2)", "sqrt takes 1 argument"),
    ("atan2(1)", "atan2 takes 2 arguments"),
    ("sqrt", "a call"),
    ("sqrt(k=1)", "positional"),
    ("pairing * 400000000", "text variable"),
    ("pairing + 1", "text variable"),
    ("-" * 500 + "k", "nested"),
    ("-" * 5000 + "1", "characters"),
    ("+".join(["k"] * 3000), "characters"),
    ("abs(" * 40 + "k" + ")" * 40, "nested"),
    ("9**9**7", "exponent"),
    ("2**2**2**2**2**2**2", "exponent"),
    ("k ** 400", "exponent"),
    ("1" * 5000, "characters"),
])
def test_bad_derived_expressions_are_one_line_errors_at_validate(capsys, tmp_path, expr,
                                                                 fragment):
    t0 = time.perf_counter()
    code, _, err = cli(capsys, "validate", _derived(tmp_path, expr), "--check-space", "4")
    line = one_line(code, err, "derived.generator.platform_rotation", fragment)
    assert len(line) < 400
    assert time.perf_counter() - t0 < 10


@pytest.mark.parametrize("expr", ["(-8) ** 0.5", "(-k) ** 0.5", "sqrt(-k)"])
def test_complex_results_are_refused_not_stored(expr):
    e = Expression.parse(expr, "derived.x", {"k"})
    with pytest.raises(ParameterError) as exc:
        e({"k": 1.0})
    assert "real" in str(exc.value) or "defined" in str(exc.value)


def test_a_power_tower_does_not_hang_validate(tmp_path):
    """Before the fix ``9**9**9`` computed a big integer for minutes; now refused at once."""
    p = _derived(tmp_path, "9**9**9**9")
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "pkmlab.cli", "validate", str(p),
                        "--check-space", "4"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "exponent" in r.stderr, r.stderr[-2000:]
    assert time.perf_counter() - t0 < 30


def test_good_derived_expressions_still_work(tmp_path):
    s = load_study(_derived(tmp_path, "k * 30 * deg + max(k, 1) * sqrt(4) * 0 + 2 ** 3 * 0"))
    spec = s.space.spec_of({"link_length": 220.0, "k": 1.0, "pairing": "same"})
    assert spec.generator.platform_rotation == pytest.approx(0.5235987755982988)


# ---- item 6: family and name -----------------------------------------------------------------

@pytest.mark.parametrize("design, derived, field", [
    ({"family": {"path": "family", "quantity": "text", "choices": ["ups6"]}}, {},
     "design.family.path"),
    ({"nm": {"path": "name", "quantity": "text", "choices": ["a", "b"]}}, {},
     "design.nm.path"),
    ({"link_length": {"low": "200 mm", "high": "260 mm"}}, {"name": "link_length"},
     "derived.name"),
    ({"link_length": {"low": "200 mm", "high": "260 mm"}}, {"family": "link_length"},
     "derived.family"),
])
def test_family_and_name_cannot_be_design_variables(capsys, tmp_path, design, derived, field):
    p = small_study(tmp_path, design=design, derived=derived)
    code, _, err = cli(capsys, "validate", p, "--check-space", "4")
    one_line(code, err, field, "family")


def test_a_derived_field_must_be_a_number_field(capsys, tmp_path):
    p = small_study(tmp_path, design={"link_length": {"low": "200 mm", "high": "260 mm"}},
                    derived={"generator.pairing": "link_length"})
    code, _, err = cli(capsys, "validate", p, "--check-space", "4")
    one_line(code, err, "derived.generator.pairing", "number")


# ---- item 8: whatever validates runs --------------------------------------------------------

def test_a_rotary_actuator_on_a_linear_mechanism_is_refused(capsys, tmp_path):
    p = small_study(tmp_path, mechanism={"file": str(GS)},
                    design={"stroke_max": {"path": "stroke[1]", "quantity": "length",
                                           "low": "900 mm", "high": "950 mm"}},
                    evaluate={"payload": {"mass": "1 kg"},
                              "motions": [{"name": "p", "paper": True}],
                              "actuators": {"spec": {"name": "servo", "kind": "rotary",
                                                     "torque": "1 N*m",
                                                     "angular_speed": "5 rad/s"}}},
                    objectives=[{"minimize": "peak_actuator_force"}])
    code, _, err = cli(capsys, "validate", p, "--check-space", "0")
    one_line(code, err, "evaluate.actuators", "linear")


def test_a_rotary_catalogue_choice_on_a_linear_mechanism_is_refused(capsys, tmp_path):
    cat = tmp_path / "cat.yaml"
    cat.write_text(yaml.safe_dump({"actuators": [
        {"name": "lin", "force": "500 N", "speed": "200 mm/s", "stroke": "120 mm"},
        {"name": "servo", "kind": "rotary", "torque": "1 N*m", "angular_speed": "5 rad/s"}]}))
    p = small_study(tmp_path, design={"link_length": {"low": "200 mm", "high": "260 mm"},
                                      "act": {"target": "actuator",
                                              "choices": ["lin", "servo"]}},
                    evaluate={"payload": {"mass": "1 kg"},
                              "motions": [{"name": "p", "paper": True}],
                              "actuators": {"catalogue": str(cat), "use": "lin"}},
                    objectives=[{"minimize": "peak_actuator_force"}])
    code, _, err = cli(capsys, "validate", p, "--check-space", "0")
    one_line(code, err, "design.act.choices[1]", "linear actuator", "servo")


def test_a_tiny_paper_segment_time_is_refused(capsys, tmp_path):
    p = small_study(tmp_path, evaluate={"trajectory": {"segment_time": 1e-300}},
                    objectives=[{"maximize": "paper_motion_margin"}])
    code, _, err = cli(capsys, "validate", p, "--check-space", "0")
    one_line(code, err, "evaluate.trajectory.segment_time")


def test_a_huge_leg_mass_is_refused(capsys, tmp_path):
    p = small_study(tmp_path, evaluate={"payload": {"mass": "1 kg", "legs": {"mass": "1e308 kg"}},
                              "motions": [{"name": "p", "paper": True}]},
                    objectives=[{"minimize": "peak_actuator_force"}])
    code, _, err = cli(capsys, "validate", p, "--check-space", "0")
    one_line(code, err, "evaluate.payload.legs.mass")


def test_a_tiny_motion_segment_time_is_refused(capsys, tmp_path):
    p = small_study(tmp_path, evaluate={"payload": {"mass": "1 kg"},
                                        "motions": [{"name": "p", "paper": True,
                                                     "segment_time": "1e-300 s"}]},
                    objectives=[{"minimize": "peak_actuator_force"}])
    code, _, err = cli(capsys, "validate", p, "--check-space", "0")
    one_line(code, err, "evaluate.motions[0].segment_time")
