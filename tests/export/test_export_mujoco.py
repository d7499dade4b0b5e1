"""Issue 25: the MJCF round trip in MuJoCo (the core bindings, ``mujoco-core``; headless).

For every registered family (and the baseline design of every shipped study, and a design a
study exported): load the MJCF export, drive the position servos along pkmlab's IK of the
straight pose path from the nominal pose to a pose, gravity and contacts off, let it settle
with the file's own solver settings, and compare with pkmlab: the tool site's position and
orientation, every loop gap, and every joint's centre against ``mech.legs(pose)`` (which is
also the working mode: every leg's assembly). With gravity on, the sag is reported (docs).

The tool's rotation is compared where the platform's orientation is a property of the
mechanism (``roundtrip.orientation_defined``: its joint centres are not on one line). The
five-bar's tool is a point where both distal links meet: it has no orientation, so there the
free coordinates (the tool point's position), every loop gap and every joint centre are
compared, and the rotation only reported (the export's orientation guide holds it anyway).
A mechanism whose mobility frees no tilt (the deltas, translational; planar ones) has its
platform orientation held by the MJCF's declared guide (``pkmlab.export.mjcf``); its tool
rotation is compared like any other.
"""

from __future__ import annotations

import pytest
from export_samples import FAMILIES, sample

mujoco = pytest.importorskip("mujoco", reason="the MuJoCo round trip needs the simulator "
                             "(pip install 'pkmlab[sim]': mujoco-core)")

from pkmlab.export import roundtrip as rt  # noqa: E402
from pkmlab.export.mjcf import mjcf_text  # noqa: E402
from pkmlab.testing import random_valid_poses  # noqa: E402

TOL_MM, TOL_RAD = 1e-6, 1e-6
N_POSES = 3


def _round_trip(mech, poses, settle=4.0):
    worst = dict.fromkeys(("position_mm", "rotation_rad", "loop_gap_mm", "joint_mm"), 0.0)
    for X in poses:
        model, data = rt.load(mech)
        rt.drive(mech, model, data, X, settle=settle)
        got = rt.compare(mech, model, data, X)
        for k in worst:
            worst[k] = max(worst[k], got[k])
    return worst


def _assert_exact(worst, what, mech):
    assert worst["position_mm"] <= TOL_MM, (what, worst)
    if rt.orientation_defined(mech):
        assert worst["rotation_rad"] <= TOL_RAD, (what, worst)
    assert worst["loop_gap_mm"] <= TOL_MM, (what, worst)
    assert worst["joint_mm"] <= TOL_MM, (what, worst)        # the working mode is kept


@pytest.mark.parametrize("family", FAMILIES)
def test_mujoco_reaches_pkmlabs_poses_with_closed_loops(family):
    mech = sample(family)
    model, data = rt.load(mech)
    home = rt.compare(mech, model, data, mech.nominal_pose)
    assert home["position_mm"] <= 1e-9 and home["loop_gap_mm"] <= 1e-9
    poses = random_valid_poses(mech, N_POSES, seed=25)
    _assert_exact(_round_trip(mech, poses), family, mech)


@pytest.mark.parametrize("family", FAMILIES)
def test_gravity_sag_is_small_and_settles(family):
    """The documented figure: holding the nominal pose against gravity, the servos and the
    soft loop constraints give a little (docs/validation.md); bounded here at 1 % of the
    mechanism's size."""
    mech = sample(family)
    model, data = rt.load(mech)
    s = rt.sag(mech, model, data)
    assert 0 < s["tool_mm"] < 0.01 * mech.scale, s
    assert s["loop_gap_mm"] < 0.01 * mech.scale and s["velocity"] < 1e-6, s


def test_the_round_trip_can_fail_without_the_loop_closures():
    """Dropping the equalities leaves the legs open: the check sees it."""
    mech = sample("psu6")
    xml = mjcf_text(mech)
    start, end = xml.index("  <equality>"), xml.index("  </equality>") + len("  </equality>")
    model, data = rt.load(mech, xml=xml[:start] + xml[end:])
    X = random_valid_poses(mech, 1, seed=3)[0]
    rt.drive(mech, model, data, X, settle=0.5)
    got = rt.compare(mech, model, data, X)
    assert got["position_mm"] > 1e-3 or got["joint_mm"] > 1e-3


def test_projection_closes_the_loops_to_rounding():
    """MuJoCo's own kinematics with the actuated joints held at pkmlab's IK: Gauss-Newton
    on its equality residuals lands on pkmlab's pose to 1e-9 mm."""
    mech = sample("luzi3")
    X = random_valid_poses(mech, 1, seed=7)[0]
    model, data = rt.load(mech)
    data.qpos[:] = model.key_qpos[0]
    rt.project(model, data, rt.actuator_targets(mech, X)[0])
    got = rt.compare(mech, model, data, X)
    assert got["position_mm"] <= 1e-9 and got["rotation_rad"] <= 1e-9
    assert got["loop_gap_mm"] <= 1e-9 and got["joint_mm"] <= 1e-9


def test_only_the_point_tool_has_no_orientation_to_compare():
    """The criterion reads the declared joints: the five-bar's platform joints meet at one
    point; every other family's span a plane."""
    undefined = [f for f in FAMILIES if not rt.orientation_defined(sample(f))]
    assert undefined == ["fivebar"], undefined


def test_without_the_orientation_guide_a_delta_platform_turns():
    """Without the orientation guide (its body and weld cut out), a delta's S–S rods let the
    platform turn: the round trip sees it. With it, a pose is reached exactly (above)."""
    import xml.etree.ElementTree as ET

    mech = sample("delta3")
    root = ET.fromstring(mjcf_text(mech))
    base = root.find("worldbody/body[@name='base']")
    guide = base.find("body[@name='platform.guide']")
    n = len(guide.findall("joint"))                         # slides, one qpos each
    base.remove(guide)
    eq = root.find("equality")
    eq.remove(eq.find("weld[@name='platform.guide']"))
    key = root.find("keyframe/key")
    key.set("qpos", " ".join(key.get("qpos").split()[:-n]))
    xml = ET.tostring(root, encoding="unicode")
    model, data = rt.load(mech, xml=xml)
    X = random_valid_poses(mech, 1, seed=25)[0]
    rt.drive(mech, model, data, X)
    got = rt.compare(mech, model, data, X)
    assert got["rotation_rad"] > 1e-3 or got["joint_mm"] > 1e-3, got


def _study_baselines():
    from conftest import ROOT

    return sorted((ROOT / "studies").glob("*.yaml"))


@pytest.mark.parametrize("path", _study_baselines(), ids=lambda p: p.stem)
def test_round_trip_on_each_shipped_studys_baseline_design(path):
    from pkmlab.study import load_study
    from pkmlab.study.candidates import mass_model

    study = load_study(path)
    mech = study.space.spec_of(None).build()
    poses = random_valid_poses(mech, 1, seed=11)
    worst = dict.fromkeys(("position_mm", "rotation_rad", "loop_gap_mm", "joint_mm"), 0.0)
    for X in poses:
        model, data = rt.load(mech, mass=mass_model(study))
        rt.drive(mech, model, data, X)
        got = rt.compare(mech, model, data, X)
        worst = {k: max(v, got[k]) for k, v in worst.items()}
    _assert_exact(worst, path.stem, mech)


def test_round_trip_on_a_design_a_study_exported(tiny_report):
    import pkmlab

    out, _ = tiny_report
    design = sorted((out / "designs").glob("01-*"))[0]
    mech = pkmlab.load_mechanism(design / "mechanism.yaml")
    xml = (design / "mechanism.mjcf.xml").read_text()
    X = random_valid_poses(mech, 1, seed=13)[0]
    model, data = rt.load(mech, xml=xml)
    rt.drive(mech, model, data, X)
    _assert_exact(rt.compare(mech, model, data, X), design.name, mech)
