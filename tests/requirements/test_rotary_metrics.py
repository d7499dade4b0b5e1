"""Issue 26 item 1: a study on a servo family writes a servo's size as a torque in N·m
(``actuator_torque_rating``) and its travel margin as an angle in deg
(``actuator_angle_margin``); the linear names (``actuator_force_rating`` N,
``actuator_stroke_margin`` mm) stay null with a note, and a linear family the other way round.
Checked against :func:`pkmlab.requirements.actuators.fit` in internal units (rad, N·mm)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR

from pkmlab.motion.dynamics import inverse_dynamics
from pkmlab.requirements.actuators import fit
from pkmlab.study import study_from_mapping
from pkmlab.study.evaluators import evaluate_design
from pkmlab.study.metrics import METRICS

MOTION = [{"name": "s", "sinusoid": {"amplitude": {"z": "3 mm"}, "frequency": {"z": "1 Hz"}},
           "duration": "0.2 s", "rate": "50 Hz"}]


def test_servo_study_metrics_say_torque_and_angle(tmp_path):
    data = {"study": "servo", "mechanism": {"file": str(MECH_DIR /
                                                        "instructables-servo-6rss.yaml")},
            "design": {"crank_length": {"low": "20 mm", "high": "30 mm"}},
            "evaluate": {"motions": MOTION, "payload": {"mass": "0.2 kg"},
                         "actuators": {"spec": {"name": "MG996R", "kind": "rotary",
                                                "torque": "1.1 N*m",
                                                "angular_speed": "6 rad/s",
                                                "range": "160 deg"}}},
            "objectives": [{"minimize": "actuator_torque_rating"}],
            "optimizer": {"method": "grid"}}
    s = study_from_mapping(data, tmp_path)
    rec = evaluate_design(s.space, None, s.evaluation, 0)
    assert rec["status"] == "ok", rec.get("reason")
    m, notes = rec["metrics"], rec["notes"]
    assert m["actuator_torque_rating"] == pytest.approx(1.1, rel=1e-12)       # N·m, not 1100
    assert m["actuator_force_rating"] is None
    assert "actuator_torque_rating" in notes["actuator_force_rating"]
    mech = s.space.decode(None)
    dyn = inverse_dynamics(mech, s.evaluation.motions.motions(mech)[0],
                           s.evaluation.payload.for_mechanism(mech))
    ref = fit(s.evaluation.actuators.catalogue["MG996R"], [dyn])
    used = float(np.max(dyn.q.max(0) - dyn.q.min(0)))                         # rad
    assert m["actuator_angle_margin"] == pytest.approx(160 - math.degrees(used), rel=1e-9)
    assert m["actuator_angle_margin"] == pytest.approx(ref.stroke_margin, rel=1e-12)
    assert m["actuator_stroke_margin"] is None
    assert "actuator_angle_margin" in notes["actuator_stroke_margin"]
    assert m["peak_actuator_angular_speed"] == pytest.approx(
        math.degrees(float(np.max(np.abs(dyn.qdot)))), rel=1e-9)              # deg/s
    assert (METRICS["actuator_torque_rating"].unit, METRICS["actuator_angle_margin"].unit,
            METRICS["peak_actuator_torque"].unit,
            METRICS["peak_actuator_angular_speed"].unit, METRICS["peak_servo_torque"].unit
            ) == ("N·m", "deg", "N·m", "deg/s", "N·m")


def test_linear_study_leaves_the_servo_metrics_null(tmp_path):
    data = {"study": "lin", "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
            "design": {"link_length": {"low": "200 mm", "high": "300 mm"}},
            "evaluate": {"motions": MOTION, "payload": {"mass": "0.2 kg"},
                         "actuators": {"spec": {"name": "lin", "force": "500 N",
                                                "speed": "500 mm/s", "stroke": "300 mm"}}},
            "objectives": [{"minimize": "actuator_force_rating"}],
            "optimizer": {"method": "grid"}}
    s = study_from_mapping(data, tmp_path)
    rec = evaluate_design(s.space, None, s.evaluation, 0)
    assert rec["status"] == "ok", rec.get("reason")
    m, notes = rec["metrics"], rec["notes"]
    assert m["actuator_force_rating"] == 500.0 and m["actuator_torque_rating"] is None
    assert m["actuator_angle_margin"] is None and m["actuator_stroke_margin"] is not None
    assert "actuator_stroke_margin" in notes["actuator_angle_margin"]
