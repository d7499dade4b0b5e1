"""Issue 26 item 1: a servo is read as a servo. One display convention
(:func:`pkmlab.units.actuator_display`): deg, deg/s and N·m for rotary actuators in every
output a person reads; no linear default (150 N, 10000 N/mm) is ever applied to a servo.

Each figure is checked against an independent computation in internal units (rad, N·mm)
converted by hand (180/π, 1e-3), to 1e-9 relative unless said otherwise."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from conftest import MECH_DIR
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.motion import check_trajectory
from pkmlab.motion.plot import actuators_figure

RSS6 = MECH_DIR / "instructables-servo-6rss.yaml"


@pytest.fixture(scope="module")
def servo():
    return load_mechanism(RSS6)


def _motion(tmp_path, mech):
    """A small heave and roll about the nominal pose: 21 samples over 1 s."""
    t = np.linspace(0.0, 1.0, 21)
    z0 = mech.nominal_pose[2]
    rows = [f"{a:.6f},0,0,{z0 + 5 * math.sin(2 * math.pi * a):.9f},"
            f"{3 * math.sin(2 * math.pi * a):.9f},0,0" for a in t]
    p = tmp_path / "m.csv"
    p.write_text("t,x,y,z,theta_x,theta_y,theta_z\n" + "\n".join(rows) + "\n")
    poses = np.zeros((len(t), 6))
    poses[:, 2] = z0 + 5 * np.sin(2 * np.pi * t)
    poses[:, 3] = np.radians(3 * np.sin(2 * np.pi * t))
    return p, t, poses


def test_trajectory_on_a_servo_reads_degrees_and_torques(tmp_path, servo):
    path, t, poses = _motion(tmp_path, servo)
    ref = check_trajectory(servo, t, poses, payload_mass_kg=2.0)      # rad, rad/s, N·mm
    assert ref.ok.all()
    peak_nm = float(np.max(np.abs(ref.force))) / 1e3
    out = tmp_path / "tr"
    # a torque limit above the peak: every sample ok (before: the 150 "N" default was
    # compared with N·mm torques and every loaded sample was "not ok")
    r = CliRunner().invoke(app, ["trajectory", str(RSS6), "--csv", str(path), "--payload", "2",
                                 "--max-torque", f"{2 * peak_nm}", "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["fits"] and d["failing_samples"] == 0
    disp = d["display"]
    assert disp["units"] == {"value": "deg", "rate": "deg/s", "effort": "N·m"}
    for n, v in zip(servo.actuator_names, ref.margin_low):
        assert disp["margin_low_deg"][n] == pytest.approx(math.degrees(v), rel=1e-9)
    assert max(disp["peak_torque_N_m"].values()) == pytest.approx(peak_nm, rel=1e-9)
    assert disp["limit_torque_N_m"][0] == pytest.approx(2 * peak_nm, rel=1e-12)
    with (out / "trajectory.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert "theta1_deg" in rows[0] and "theta1_rate_deg_s" in rows[0]
    assert "theta1_torque_N_m" in rows[0] and not any("force" in k for k in rows[0])
    q = np.array([float(row["theta3_deg"]) for row in rows])
    assert np.allclose(q, np.degrees(ref.q[:, 2]), rtol=1e-5, atol=1e-5)   # 6 digits in CSV
    tau = np.array([float(row["theta3_torque_N_m"]) for row in rows])
    assert np.allclose(tau, ref.force[:, 2] / 1e3, rtol=1e-5, atol=1e-9)

    # a torque limit below the peak: a torque violation, printed in N·m
    r = CliRunner().invoke(app, ["trajectory", str(RSS6), "--csv", str(path), "--payload", "2",
                                 "--max-torque", f"{0.5 * peak_nm}", "--out", str(out)])
    assert r.exit_code == 1, r.output          # failed samples exit 1
    text = " ".join(r.output.split())
    assert "first torque violation" in text and "N·m" in text
    assert "angle margins (deg)" in text and "(mm)" not in text and " N," not in text


def test_trajectory_refuses_linear_limits_on_a_servo(tmp_path, servo):
    path, _, _ = _motion(tmp_path, servo)
    for opt in ("--max-force", "--max-speed"):
        r = CliRunner().invoke(app, ["trajectory", str(RSS6), "--csv", str(path), opt, "150",
                                     "--out", str(tmp_path / "x")])
        assert r.exit_code != 0
        assert "--max-torque" in " ".join(r.output.split())


def test_servo_plot_is_in_degrees_without_inches(tmp_path, servo):
    _, t, poses = _motion(tmp_path, servo)
    rep = check_trajectory(servo, t, poses)
    fig = actuators_figure(rep)
    axes = fig.get_axes()
    assert len(axes) == 1 and axes[0].get_ylabel() == "Crank angle (deg)"
    texts = [a.get_text() for a in axes[0].texts]
    assert texts and all(" in" not in s and "deg" in s for s in texts)
    hi = math.degrees(servo.stroke[1])
    assert any(f"angle max {hi:.4g} deg" == s for s in texts)
    line = axes[0].get_lines()[0]
    assert np.allclose(line.get_ydata(), np.degrees(rep.q[:, 0]), rtol=1e-12)
    assert not any(s.get_label() == "status not ok" for s in axes[0].get_lines())
