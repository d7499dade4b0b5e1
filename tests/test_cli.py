"""The CLI commands run, speak mm/deg, and their --json parses."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import MECH_DIR
from typer.testing import CliRunner

import pkmlab
from pkmlab.cli import app

runner = CliRunner()
HOPKINS = str(MECH_DIR / "hopkins-williams-6psu.yaml")


@pytest.mark.parametrize("path", sorted(MECH_DIR.glob("*.yaml")), ids=lambda p: p.stem)
def test_inspect_json(path):
    r = runner.invoke(app, ["inspect", str(path), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    m = pkmlab.load_mechanism(path)
    assert d["nominal_pose"]["z"] == pytest.approx(m.nominal_pose[2])
    assert d["nominal_pose"]["theta_z"] == pytest.approx(math.degrees(m.nominal_pose[5]))
    assert list(d["nominal_actuators"]) == list(m.actuator_names)
    assert d["nominal_valid"] is True
    assert d["kappa"] > 1 and d["characteristic_length"]["status"] == "angeles"


def test_inspect_text():
    r = runner.invoke(app, ["inspect", HOPKINS])
    assert r.exit_code == 0
    assert "κ = " in r.stdout and "homogenised with L = " in r.stdout and "nominal pose" in r.stdout


def test_ik_json_in_mm_and_degrees():
    m = pkmlab.load_mechanism(HOPKINS)
    r = runner.invoke(app, ["ik", HOPKINS, "--pose", "5,-3,300,10,-5,20", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    expect = m.inverse(np.array([5, -3, 300, *np.radians([10, -5, 20])])).q[0]
    assert [d["actuators"][f"q{i}"] for i in range(1, 7)] == pytest.approx(expect)
    assert d["valid"] is True and d["reason"] == "ok"
    # κ of the Jacobian homogenised with the stated L (it was the unscaled condition number)
    L = d["characteristic_length"]["length_mm"]
    assert d["characteristic_length"]["status"] == "angeles"
    J = m.jacobian(np.array([5, -3, 300, *np.radians([10, -5, 20])]))[0]
    J[:, 3:] /= L
    assert d["kappa"] == pytest.approx(np.linalg.cond(J), rel=1e-10)


def test_ik_unreachable_is_data_not_error():
    r = runner.invoke(app, ["ik", HOPKINS, "--pose", "0,0,900,0,0,0", "--json"])
    assert r.exit_code == 0
    d = json.loads(r.stdout)
    assert d["valid"] is False and d["reason"] == "stroke above maximum"
    r = runner.invoke(app, ["ik", HOPKINS, "--pose", "0,0,900,0,0,0"])
    assert "stroke above maximum" in r.stdout


def test_fk_json_round_trip_and_all_modes():
    m = pkmlab.load_mechanism(HOPKINS)
    X = np.array([10, 5, 290, *np.radians([3, 4, -6])])
    q = m.inverse(X).q[0]
    r = runner.invoke(app, ["fk", HOPKINS, "--actuators", ",".join(f"{v:.12f}" for v in q),
                            "--all", "--starts", "300", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["converged"] is True
    got = [d["pose"][k] for k in ("x", "y", "z")]
    assert got == pytest.approx(X[:3], abs=1e-6)
    assert d["pose"]["theta_z"] == pytest.approx(-6.0, abs=1e-6)
    modes = d["assembly_modes"]
    assert modes and modes[0]["working_mode"] is True
    assert modes[0]["pose"]["z"] == pytest.approx(290.0, abs=1e-6)


@pytest.mark.parametrize("args, fragment", [
    (["ik", HOPKINS, "--pose", "1,2,3"], "--pose: must be 6 comma-separated values"),
    (["ik", HOPKINS, "--pose", "0,0,300,0,0,1 furlong"], "--pose[5]: must be"),
    (["fk", HOPKINS, "--actuators", "1,2"], "--actuators: must be 6 comma-separated values"),
    (["inspect", "no-such-file.yaml"], "path: must be an existing mechanism YAML file"),
])
def test_bad_input_exits_2_with_named_field(args, fragment):
    r = runner.invoke(app, args)
    assert r.exit_code == 2
    assert fragment in r.stderr.replace("\n", "")


def test_bad_mechanism_file_exits_2(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text((MECH_DIR / "hopkins-williams-6psu.yaml").read_text()
                 .replace("link_length: 225 mm", "link_length: -225 mm"))
    r = runner.invoke(app, ["inspect", str(f)])
    assert r.exit_code == 2
    assert "link_length: must be a length > 0 mm" in r.stderr
