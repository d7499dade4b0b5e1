"""Issue 25: the mechanism formats (URDF, joint frames, MJCF text, STEP) of every registered
family, checked against pkmlab's declared joints at several poses, and ``pkmlab export``."""

from __future__ import annotations

import csv
import io
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from export_samples import FAMILIES, sample

from pkmlab.export import EXPORTERS, export_mechanism, mechanism_formats
from pkmlab.export.jointframes import joints_csv, joints_json
from pkmlab.export.mjcf import mjcf_text
from pkmlab.export.urdf import urdf_text
from pkmlab.poses import euler_to_matrix
from pkmlab.testing import random_valid_poses

TOL_MM = 1e-9
N_POSES = 3


def _poses(mech):
    return np.vstack([mech.nominal_pose, random_valid_poses(mech, N_POSES, seed=25)])


def _centres(mech, X):
    return {j.name: j.location for leg in mech.legs(X) for j in leg.joints}


def test_the_registry_has_the_four_mechanism_formats():
    assert list(mechanism_formats()) == ["mjcf", "urdf", "joints", "step"]
    assert all(EXPORTERS[f].subject == "mechanism" for f in mechanism_formats())


@pytest.mark.parametrize("family", FAMILIES)
def test_joint_frames_agree_with_the_legs_and_segments(family):
    mech = sample(family)
    for X in _poses(mech):
        rows = list(csv.DictReader(io.StringIO(joints_csv(mech, X).decode())))
        centres = _centres(mech, X)
        assert len(rows) == sum(len(leg.joints) for leg in mech.legs(X))
        for r in rows:
            loc = np.array([float(r[k]) for k in ("x_mm", "y_mm", "z_mm")])
            assert np.linalg.norm(loc - centres[r["joint"]]) <= TOL_MM, r["joint"]
            F = np.array([float(r[f"R{i}{j}"]) for i in range(3) for j in range(3)]).reshape(3, 3)
            assert np.allclose(F.T @ F, np.eye(3), atol=1e-12) and np.linalg.det(F) > 0
        # the moving links' segments (mech.leg_segments) are joint centres of the export
        p, R = mech._frames(X)
        a, b = mech.leg_segments(p, R)
        by_leg = {}
        for r in rows:
            by_leg.setdefault(r["leg"], []).append(
                np.array([float(r[k]) for k in ("x_mm", "y_mm", "z_mm")]))
        for i, leg in enumerate(mech.legs(X)):
            s0, s1 = leg.segment
            assert np.linalg.norm(by_leg[leg.name][s0] - a[0, i]) <= TOL_MM
            assert np.linalg.norm(by_leg[leg.name][s1] - b[0, i]) <= TOL_MM
        doc = json.loads(joints_json(mech, X))
        assert doc["actuators"] == pytest.approx(
            dict(zip(mech.actuator_names, mech.inverse(X).q[0])), abs=1e-9)
        assert len(doc["parameters"]) == len(mech.parameters())


def _urdf_frames(text: str) -> tuple[dict, dict]:
    """World frames (m) of every link at zero joint values, composing the joint origins, and
    the loop closures."""
    root = ET.fromstring(text)
    ns = "{urn:pkmlab:urdf-loops}"
    joints = {j.find("child").get("link"): j for j in root.findall("joint")}
    frames = {}

    def frame(link):
        if link in frames:
            return frames[link]
        j = joints.get(link)
        if j is None:
            frames[link] = (np.zeros(3), np.eye(3))
            return frames[link]
        p0, R0 = frame(j.find("parent").get("link"))
        o = j.find("origin")
        xyz = np.array(o.get("xyz").split(), float)
        r, pch, y = map(float, o.get("rpy").split())
        R = euler_to_matrix(np.array([r, pch, y]))          # Rz(y)·Ry(p)·Rx(r), as URDF
        frames[link] = (p0 + R0 @ xyz, R0 @ R)
        return frames[link]

    for link in root.findall("link"):
        frame(link.get("name"))
    closures = {c.get("name"): (c.get("frame_a"), c.get("frame_b"))
                for c in root.findall(f"{ns}loop_closure")}
    return frames, closures, joints


_NUMERIC = {"xyz", "rpy", "value", "ixx", "ixy", "ixz", "iyy", "iyz", "izz", "radius",
            "length", "lower", "upper", "effort", "velocity", "offset", "pos", "quat", "size",
            "fromto", "axis", "ref", "range", "kp", "ctrlrange", "anchor", "relpose", "mass",
            "density", "fullinertia", "qpos", "ctrl", "timestep", "tolerance", "gravity",
            "solref", "damping", "armature"}


@pytest.mark.parametrize("family", FAMILIES)
def test_every_number_written_parses_as_a_number(family):
    """URDF and MJCF readers (urdfdom, MuJoCo) need plain decimal numbers in every numeric
    attribute (a numpy repr such as 'np.float64(1.0)' was once written for inertias)."""
    from pkmlab.export.model import MassModel
    from pkmlab.motion.payload import MassProperties

    mech = sample(family)
    payload = MassModel(platform=MassProperties(1.5, [0, 0, 10.0], [0.0, 0.0, 0.0]),
                        leg_mass=0.2)
    for text in (urdf_text(mech), mjcf_text(mech), urdf_text(mech, mass=payload),
                 mjcf_text(mech, mass=payload)):
        for el in ET.fromstring(text).iter():
            for k, v in el.attrib.items():
                if k in _NUMERIC:
                    [float(x) for x in v.split()]


@pytest.mark.parametrize("family", FAMILIES)
def test_urdf_joint_frames_and_loop_closures_at_several_poses(family):
    mech = sample(family)
    for X in _poses(mech):
        frames, closures, joints = _urdf_frames(urdf_text(mech, X))
        centres = _centres(mech, X)
        checked = 0
        for child, j in joints.items():
            base = j.get("name").rsplit(".", 1)[0]
            name = j.get("name") if j.get("name") in centres else base
            if name in centres and j.get("type") != "fixed":
                # a joint's child link frame has its origin on the joint (URDF's rule)
                assert np.linalg.norm(frames[child][0] * 1e3 - centres[name]) <= TOL_MM, name
                checked += 1
        assert checked >= len(mech.legs(X))
        for a, b in closures.values():             # the two frames of every cut coincide
            assert np.linalg.norm(frames[a][0] - frames[b][0]) * 1e3 <= TOL_MM
        p, R = mech._frames(X)
        assert np.linalg.norm(frames["tool"][0] * 1e3 - p[0]) <= TOL_MM
        assert np.allclose(frames["tool"][1], R[0], atol=1e-12)
        assert len(closures) >= 1


def test_the_urdf_check_can_fail():
    """A platform joint moved by 1e-6 mm in the legs is seen (the check is not vacuous)."""
    mech = sample("ups6")
    frames, closures, _ = _urdf_frames(urdf_text(mech))
    a, b = next(iter(closures.values()))
    text = urdf_text(mech).replace(f'<child link="{b}"/>', f'<child link="{b}"/>', 1)
    root = ET.fromstring(text)
    for j in root.findall("joint"):
        if j.find("child").get("link") == b:
            o = j.find("origin")
            xyz = np.array(o.get("xyz").split(), float) + [1e-9, 0, 0]
            o.set("xyz", " ".join(repr(float(v)) for v in xyz))
    frames2, _, _ = _urdf_frames(ET.tostring(root, encoding="unicode"))
    assert np.linalg.norm(frames2[a][0] - frames2[b][0]) * 1e3 > TOL_MM


@pytest.mark.parametrize("family", FAMILIES)
def test_mjcf_is_one_tree_under_one_root_body_with_an_actuator_per_leg(family):
    mech = sample(family)
    root = ET.fromstring(mjcf_text(mech))
    world = root.find("worldbody")
    assert [b.get("name") for b in world.findall("body")] == ["base"]
    acts = root.find("actuator").findall("position")
    assert [a.get("name") for a in acts] == list(mech.actuator_names)
    lo, hi = mech.stroke
    f = 1e-3 if mech.actuator_unit == "mm" else 1.0
    for a in acts:
        assert np.allclose(np.array(a.get("ctrlrange").split(), float), [lo * f, hi * f])
    assert root.find(".//site[@name='tool']") is not None
    assert root.find("equality") is not None and len(root.find("equality")) >= 1
    excl = {(e.get("body1"), e.get("body2")) for e in root.find("contact")}
    for leg in mech.legs():                      # no contact between a chain's bodies
        for j in leg.joints:
            assert tuple(sorted((j.parent, j.child))) in excl


def test_step_skeleton_or_the_reason_it_is_skipped(tmp_path):
    bd = pytest.importorskip("build123d", reason="STEP needs the optional extra cad "
                             "(build123d)")
    from pkmlab.export.step import JOINT_SPHERE

    mech = sample("rss6")
    [path] = export_mechanism(mech, "step", tmp_path)
    assert path.read_text(errors="replace").startswith("ISO-10303-21;")
    shape = bd.import_step(str(path))
    # two plates, a sphere per joint, a cylinder per crank and per rod
    n_joints = len({j.name for leg in mech.legs() for j in leg.joints})
    assert len(shape.solids()) == 2 + n_joints + 2 * len(mech.legs())
    # in mm: the joint centres, padded by the joint spheres, bound the skeleton
    P = np.array([j.location for leg in mech.legs() for j in leg.joints])
    bb = shape.bounding_box()
    pad = 0.5 * JOINT_SPHERE * 0.025 * mech.scale
    assert np.allclose([bb.min.Z, bb.max.Z], [P[:, 2].min() - pad, P[:, 2].max() + pad],
                       atol=1e-3)


def test_cli_export_of_a_mechanism_file(tmp_path):
    from conftest import MECH_DIR
    from typer.testing import CliRunner

    from pkmlab.cli import app

    r = CliRunner().invoke(app, ["export", str(MECH_DIR / "luzi-3chain.yaml"), "--format",
                                 "joints", "-o", str(tmp_path), "--json"])
    assert r.exit_code == 0, r.output
    files = json.loads(r.output)["files"]
    assert sorted(p.rsplit("/", 1)[1] for p in files) == ["luzi-3chain.joints.csv",
                                                          "luzi-3chain.joints.json"]
    r = CliRunner().invoke(app, ["export", str(MECH_DIR / "luzi-3chain.yaml"), "--format",
                                 "obj", "-o", str(tmp_path)])
    assert r.exit_code == 2 and "mjcf, urdf, joints, step" in r.output


def test_cli_exports_any_candidate_of_a_study_feasible_or_not(tiny_report, tmp_path):
    from typer.testing import CliRunner

    from pkmlab.cli import app
    from pkmlab.cli.study import _open_results
    from pkmlab.study.run import feasible

    out, _ = tiny_report
    study, records = _open_results(out)
    ok = [r for r in records if r["status"] == "ok"]
    good = feasible(study, ok)
    picks = {"feasible": ok[int(np.flatnonzero(good)[0])],
             "infeasible": ok[int(np.flatnonzero(~good)[0])]}
    for what, rec in picks.items():
        seq = str(rec["seq"])
        r = CliRunner().invoke(app, ["export", str(out), "--seq", seq, "--format", "urdf",
                                     "-o", str(tmp_path), "--json"])
        assert r.exit_code == 0, (what, r.output)
        files = json.loads(r.output)["files"]
        yaml_file = next(f for f in files if f.endswith(f"-seq{seq}.yaml"))
        assert any(f.endswith(f"-seq{seq}.urdf") for f in files)
        # the candidate's own geometry: its mechanism file rebuilds the same mechanism
        import pkmlab
        from pkmlab.study.candidates import candidate_mechanism

        got, want = pkmlab.load_mechanism(yaml_file), candidate_mechanism(study, rec)
        assert np.allclose(got.parameters().values, want.parameters().values, atol=1e-9)
    invalid = [r for r in records if r["status"] == "invalid"]
    if invalid:                 # a candidate whose geometry cannot be built: said, exit 2
        r = CliRunner().invoke(app, ["export", str(out), "--seq", str(invalid[0]["seq"]),
                                     "--format", "urdf", "-o", str(tmp_path)])
        assert r.exit_code == 2 and "error" in r.output
    r = CliRunner().invoke(app, ["export", str(out), "--seq", "99999", "--format", "urdf",
                                 "-o", str(tmp_path)])
    assert r.exit_code == 2 and "--seq" in r.output


def test_the_study_export_writes_the_formats_and_the_report_names_them(tiny_report):
    from pkmlab.webreport.study_page import _what

    out, _ = tiny_report
    design = sorted((out / "designs").glob("01-*"))[0]
    info = json.loads((design / "design.json").read_text())
    for name in ("mechanism.mjcf.xml", "mechanism.urdf", "mechanism.joints.csv",
                 "mechanism.joints.json"):
        assert (design / name).is_file() and name in info["files"]
        assert _what(name).startswith("mechanism, ")
    assert ("mechanism.step" in info["files"]) != ("step" in info.get("formats_skipped", {}))
