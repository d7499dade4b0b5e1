"""Issue 26 item 4: ``ik`` and ``trajectory`` take ``--relative``; a trajectory CSV has one
meaning on the command line and in a study (its frame is stated: ``--relative`` ≡ ``frame:
nominal``, none ≡ ``frame: base``); a failed sample exits 1, without NumPy warnings."""

from __future__ import annotations

import json

import numpy as np
import pytest
from clihelp import GS, HW, cli
from conftest import MECH_DIR

import pkmlab
from pkmlab.errors import ParameterError
from pkmlab.requirements.spec import build_motions

RSS6 = MECH_DIR / "instructables-servo-6rss.yaml"
PRS3 = MECH_DIR / "tripod-3prs.yaml"


@pytest.mark.parametrize("path,offset", [(HW, "5,-3,10,2,1,-4"), (RSS6, "3,2,-5,1,-2,3"),
                                         (PRS3, "-6,2,1")])
def test_ik_relative_is_nominal_plus_offset(capsys, path, offset):
    mech = pkmlab.load_mechanism(path)
    off = np.array([float(v) for v in offset.split(",")])
    idx = mech.mobility.index
    absolute = mech.nominal_pose.copy()
    absolute[idx] += np.where(idx >= 3, np.radians(off), off)
    shown = np.where(idx >= 3, np.degrees(absolute[idx]), absolute[idx])
    code, rel, _ = cli(capsys, "ik", path, "--pose", offset, "--relative", "--json")
    assert code == 0
    code, ab, _ = cli(capsys, "ik", path, "--pose", ",".join(f"{v:.17g}" for v in shown),
                      "--json")
    assert code == 0
    a, b = json.loads(rel)["actuators"], json.loads(ab)["actuators"]
    assert max(abs(a[k] - b[k]) for k in a) <= 1e-9
    q = mech.inverse(absolute).q[0]
    unit = np.degrees if mech.actuator_unit == "rad" else (lambda v: v)
    assert np.allclose([a[k] for k in mech.actuator_names], unit(q), atol=1e-9, rtol=0)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("path,pose", [(HW, "0,0,900,0,0,0"), (RSS6, "0,0,2000,0,0,0"),
                                       (PRS3, "900,0,0"), (GS, "0,0,0,0,0,0")])
def test_ik_failed_pose_exits_1_without_warnings(capsys, path, pose):
    code, out, err = cli(capsys, "ik", path, "--pose", pose)
    assert code == 1, out
    assert "invalid" in out and "Warning" not in err


def _csv(path, t, X):
    rows = ["t,x,y,z,theta_x,theta_y,theta_z"] + [
        ",".join(f"{v:.12g}" for v in [ti, *x[:3], *np.degrees(x[3:])]) for ti, x in zip(t, X)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_trajectory_relative_and_study_frame_mean_the_same(capsys, tmp_path):
    mech = pkmlab.load_mechanism(HW)
    t = np.linspace(0, 1, 21)
    off = np.zeros((len(t), 6))
    off[:, 2] = 10 * np.sin(2 * np.pi * t)
    off[:, 3] = np.radians(3) * np.sin(2 * np.pi * t)
    rel = _csv(tmp_path / "rel.csv", t, off)
    ab = _csv(tmp_path / "abs.csv", t, off + mech.nominal_pose)
    outs = []
    for name, args in (("r", [rel, "--relative"]), ("a", [ab])):
        code, out, _ = cli(capsys, "trajectory", HW, "--csv", *args, "--out",
                           tmp_path / name, "--json")
        assert code == 0, out
        outs.append((tmp_path / name / "trajectory.csv").read_text())
    assert outs[0] == outs[1]
    # the study: frame nominal reads rel.csv as the CLI's --relative, frame base as without
    for frame, path in (("nominal", rel), ("base", ab)):
        plan = build_motions([{"name": "m", "file": str(path), "frame": frame}], tmp_path)
        m = plan.motions(mech)[0]
        assert np.allclose(m.poses, off + mech.nominal_pose, atol=1e-9, rtol=0)
    # and must say which: no default that differs from the command line's
    with pytest.raises(ParameterError, match="frame"):
        build_motions([{"name": "m", "file": str(rel)}], tmp_path)
    code, out, _ = cli(capsys, "trajectory", "--help")
    text = " ".join(out.replace("│", " ").split())
    assert "--relative" in text and "base frame" in text and "offsets from the nominal" in text


@pytest.mark.filterwarnings("error")
def test_trajectory_failed_sample_exits_1_without_warnings(capsys, tmp_path):
    mech = pkmlab.load_mechanism(RSS6)
    t = np.linspace(0, 1, 11)
    off = np.zeros((len(t), 6))
    off[:, 2] = np.linspace(0, 3000, len(t))          # leaves the reach: no solution
    path = _csv(tmp_path / "up.csv", t, off)
    code, out, err = cli(capsys, "trajectory", RSS6, "--csv", path, "--relative",
                         "--max-torque", "100", "--out", tmp_path / "o")
    assert code == 1, out
    assert "does not fit" in " ".join(out.split()) and "Warning" not in err
    code, _, err = cli(capsys, "trajectory", RSS6, "--paper-motion", "--relative", "--out",
                       tmp_path / "p")
    assert code == 2 and "--relative" in err
    assert mech.n_actuators == 6
