"""Issue 26 item 1: ``pkmlab dexterity`` on a servo family takes the servo's torque limit
(N·m) and torsional stiffness (N·m/rad); the linear defaults (150 N, 10000 N/mm) are never
applied to it. Nominal figures checked against :func:`pkmlab.dexterity.report.pose_report`
called in internal units (N·mm, N·mm/rad), to 1e-9 relative."""

from __future__ import annotations

import json

import pytest
from conftest import MECH_DIR
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.dexterity.report import pose_report

RSS6 = MECH_DIR / "instructables-servo-6rss.yaml"
SMALL = ["--box", "2,2,2", "--samples", "2", "--resolution", "10", "--gci-samples", "50"]


def test_dexterity_on_a_servo_needs_servo_limits(tmp_path):
    run = CliRunner().invoke
    r = run(app, ["dexterity", str(RSS6), *SMALL, "--out", str(tmp_path / "a")])
    assert r.exit_code != 0 and "--max-torque" in " ".join(r.output.split())
    for opt in ("--force-limit", "--actuator-stiffness"):
        r = run(app, ["dexterity", str(RSS6), *SMALL, opt, "150", "--max-torque", "1",
                      "--torsional-stiffness", "50", "--out", str(tmp_path / "b")])
        assert r.exit_code != 0 and "rotary" in " ".join(r.output.split())
    r = run(app, ["dexterity", str(RSS6), *SMALL, "--max-torque", "1.1",
                  "--torsional-stiffness", "50", "--characteristic-length", "60",
                  "--out", str(tmp_path / "c"), "--json"])
    assert r.exit_code == 0, r.output
    n = json.loads(r.stdout)["nominal"]
    mech = load_mechanism(RSS6)
    ref = pose_report(mech, mech.nominal_pose, L=60.0, force_limit=1100.0,
                      actuator_stiffness=50e3)
    assert n["force_all_directions_N"] == pytest.approx(ref["force_all_directions_N"], rel=1e-9)
    assert n["stiffness_translational_min_N_per_mm"] == pytest.approx(
        ref["stiffness_translational_min_N_per_mm"], rel=1e-9)
    # the text names the servo limit in N·m, not a force in N
    r = run(app, ["dexterity", str(RSS6), *SMALL, "--max-torque", "1.1",
                  "--torsional-stiffness", "50", "--out", str(tmp_path / "d")])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "servos ±1.1 N·m" in text and "±150 N" not in text
