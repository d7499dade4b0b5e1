"""6-RSS: rotary-actuator units of the stroke constraint and metrics, crank interference and
crank-mounted joint cones, and the static servo torque holding a payload."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from typer.testing import CliRunner

import pkmlab
from pkmlab.config import workspace_spec
from pkmlab.mechanisms import NO_STROKE, RSS6
from pkmlab.motion.payload import GRAVITY, MassProperties
from pkmlab.poses import as_frames
from pkmlab.requirements.static import static_loads
from pkmlab.study.evaluators import EVALUATORS, Context
from pkmlab.workspaces import Constraints, JointLimits, OrientationSet, workspace
from pkmlab.workspaces.constraints import check, joint_angles, segment_distances

ROOT = Path(__file__).resolve().parents[2]
FILE = ROOT / "studies" / "mechanisms" / "instructables-servo-6rss.yaml"
PSU = ROOT / "studies" / "mechanisms" / "hopkins-williams-6psu.yaml"


# ---- item: stroke units for rotary actuators ---------------------------------------------------
def test_stroke_constraint_takes_servo_angles_in_degrees():
    m = pkmlab.load_mechanism(FILE)
    ref = workspace(m, "constant", resolution=5.0,
                    constraints=Constraints(stroke=(-math.radians(40), math.radians(40))))
    for given in (["-40 deg", "40 deg"], [-40, 40], ["-40", "40"],
                  [f"{-math.radians(40)!r} rad", 40]):
        req = workspace_spec({"resolution": 5, "constraints": {"stroke": given}}).build()
        r = workspace(m, **req)
        assert r.mechanism.stroke == pytest.approx(ref.mechanism.stroke, abs=1e-15)
        assert r.volume == pytest.approx(ref.volume, rel=1e-12)
        assert r.constraints.describe()["stroke"] == ["-40 deg", "40 deg"]
    # a length for a servo, an angle for a slider: refused, naming the field
    req = workspace_spec({"resolution": 5, "constraints": {"stroke": ["0 mm", "50 mm"]}})
    with pytest.raises(pkmlab.ParameterError, match=r"constraints\.stroke.*rotary"):
        workspace(m, **req.build())
    req = workspace_spec({"resolution": 5, "constraints": {"stroke": ["0 deg", "50 deg"]}})
    with pytest.raises(pkmlab.ParameterError, match=r"constraints\.stroke.*prismatic"):
        workspace(pkmlab.load_mechanism(PSU), **req.build())
    with pytest.raises(pkmlab.ParameterError, match=r"constraints\.stroke.*-180 deg"):
        workspace(m, **workspace_spec({"constraints": {"stroke": [-200, 40]}}).build())
    with pytest.raises(pkmlab.ParameterError, match="one of each"):
        workspace_spec({"constraints": {"stroke": ["0 mm", "50 deg"]}})


def test_cli_stroke_option_in_degrees_and_mm_refused(tmp_path):
    from pkmlab.cli import app

    res = CliRunner().invoke(app, ["workspace", str(FILE), "--stroke", "0 mm,50 mm",
                                   "--resolution", "5", "--out", str(tmp_path)])
    assert res.exit_code == 2, res.output
    assert "constraints.stroke" in res.output and "rotary" in res.output


def test_travel_metrics_say_their_unit():
    ctx = Context(evaluation=None, seed=0)
    out = EVALUATORS["geometry"](pkmlab.load_mechanism(FILE), ctx)
    assert out["stroke_length"] is None and "servo_range" in ctx.notes["stroke_length"]
    assert out["servo_range"] == pytest.approx(160.0, abs=1e-12)
    ctx = Context(evaluation=None, seed=0)
    out = EVALUATORS["geometry"](pkmlab.load_mechanism(PSU), ctx)
    assert out["stroke_length"] == pytest.approx(101.6) and out["servo_range"] is None


# ---- item: crank and rod interference, crank-mounted ball-joint cones --------------------------
def _brute_distance(P0, P1, Q0, Q1, n=401):
    s = np.linspace(0, 1, n)[:, None]
    a = P0 + s * (P1 - P0)
    b = Q0 + s * (Q1 - Q0)
    return float(np.min(np.linalg.norm(a[:, None] - b[None], axis=-1)))


def test_cranks_are_interference_segments():
    """Servo 1's 40 mm crank turned towards its partner 34.7 mm away comes within 18 mm of the
    partner's crank and rod, while every rod stays 26 mm from the others: a 20 mm link
    diameter must fail on the crank, which a rods-only check misses."""
    b = RSS6.from_circles(crank_plane="tangential", crank_length=40.0, rod_length=160.0,
                          base_pair_separation=math.radians(20.0))
    u = b.zero_directions.copy()
    u[0] = -u[0]
    m = RSS6(b.base_points, b.platform_points, np.cross(u, [0.0, 0.0, 1.0]), u,
             b.crank_length, b.rod_length, b.stroke)
    pn, Rn = as_frames(m.nominal_pose)
    start, end, leg = m.link_segments(pn, Rn)
    np.testing.assert_allclose(np.linalg.norm(end - start, axis=-1)[0],
                               np.concatenate([m.crank_length, m.rod_length]), rtol=1e-12)
    d = segment_distances(start, end, leg)[0]
    i, j = np.triu_indices(12, 1)
    keep = leg[i] != leg[j]
    brute = [_brute_distance(start[0, a], end[0, a], start[0, b], end[0, b])
             for a, b in zip(i[keep], j[keep], strict=True)]
    np.testing.assert_allclose(d, brute, atol=0.3)      # grid of 401 points per segment
    rods = segment_distances(*m.leg_segments(pn, Rn))[0]
    assert rods.min() > 25.0 and d.min() < 19.0
    assert not check(m, pn, Rn, Constraints(link_diameter=20.0))[0]
    assert check(m, pn, Rn, Constraints(link_diameter=15.0))[0]


def test_base_cone_turns_with_the_crank():
    """The crank-end joint's cone axis is fixed in the crank: expressed in the crank's frame
    (crank direction, its velocity direction, servo axis) it keeps its nominal coordinates."""
    m = pkmlab.load_mechanism(FILE)
    pn, Rn = as_frames(m.nominal_pose)
    X = m.nominal_pose + [5.0, -4.0, 12.0, 0.05, -0.04, 0.03]
    p, R = as_frames(X)
    axes0 = np.random.default_rng(2).normal(size=(6, 3))
    axes0 /= np.linalg.norm(axes0, axis=1, keepdims=True)
    a = m.base_joint_axes(p, R, axes0)[0]

    def frame(q):
        c = np.cos(q)[:, None] * m.zero_directions + np.sin(q)[:, None] * m.v_directions
        t = -np.sin(q)[:, None] * m.zero_directions + np.cos(q)[:, None] * m.v_directions
        return np.stack([c, t, m.servo_axes], axis=1)          # (6, 3 rows, 3)

    q0 = m.inverse((pn, Rn), stroke=NO_STROKE).q[0]
    q = m.inverse((p, R), stroke=NO_STROKE).q[0]
    assert np.max(np.abs(q - q0)) > 0.05
    np.testing.assert_allclose(np.einsum("kij,kj->ki", frame(q), a),
                               np.einsum("kij,kj->ki", frame(q0), axes0), atol=1e-12)
    # the cone angle is measured against that moving axis
    lim = JointLimits(base=math.radians(60), platform=math.radians(60), base_axes=axes0,
                      platform_axes=np.tile([0.0, 0.0, 1.0], (6, 1)))
    ab, _ = joint_angles(m, p, R, lim)
    C, W = m.leg_segments(p, R)
    rod = (W - C)[0] / np.linalg.norm((W - C)[0], axis=1, keepdims=True)
    np.testing.assert_allclose(ab[0], np.arccos(np.sum(rod * a, axis=1)), atol=1e-12)


# ---- item: servo torque at a payload ----------------------------------------------------------
def test_static_servo_torque_by_hand_at_the_level_pose():
    """Default generator, level nominal pose, horns horizontal, v = ẑ: a payload of weight
    60 N at the tool origin loads every servo with (60/6) N × 25 mm = 250 N·mm."""
    m = RSS6.from_circles()
    body = MassProperties(60.0 / GRAVITY * 1e3, np.zeros(3), np.zeros((3, 3)))
    one = SimpleNamespace(voxel_centres=lambda: m.nominal_pose[None, :3],
                          orientations=SimpleNamespace(rotations=lambda: np.eye(3)[None]))
    loads = static_loads(m, one, body)
    assert loads.poses == 1 and not loads.singular and loads.unit == "N·mm"
    assert loads.peak == pytest.approx(250.0, rel=1e-12)


def test_static_servo_torque_is_the_extreme_over_the_grid():
    """Peak over every voxel × orientation against an independent virtual-work evaluation:
    servo displacements from finite differences of the IK (no Jacobian)."""
    m = RSS6.from_circles(crank_length=40.0, rod_length=160.0)
    res = workspace(m, "dexterous", OrientationSet.box(np.radians([4.0] * 3), samples=2), 12.0)
    body = MassProperties(0.7, np.array([3.0, -2.0, 15.0]), np.zeros((3, 3)))
    loads = static_loads(m, res, body)
    P, Rs = res.voxel_centres(), res.orientations.rotations()
    assert loads.poses == len(P) * len(Rs) and np.isfinite(loads.peak)
    mg = body.mass * GRAVITY * 1e-3
    p = np.repeat(P, len(Rs), axis=0)
    R = np.tile(Rs, (len(P), 1, 1))
    q0 = m.inverse((p, R)).q
    r = np.einsum("nij,j->ni", R, body.com)
    h = 1e-5
    dq, dw = np.empty((len(p), 6, 6)), np.empty((len(p), 6))
    for k in range(6):                  # translate along base axis k, or rotate about it
        xi = np.zeros(6)
        xi[k] = h
        dR = as_frames(np.concatenate([np.zeros(3), xi[3:]]))[1][0]
        Rk = np.einsum("ij,njk->nik", dR, R)
        dq[:, k] = m.inverse((p + xi[:3], Rk)).q - q0
        dw[:, k] = mg * (xi[2] + (np.einsum("nij,j->ni", Rk, body.com) - r)[:, 2])
    tau = np.linalg.solve(dq, dw[..., None])[..., 0]   # τ·δq = δ(potential energy)
    assert loads.peak == pytest.approx(float(np.max(np.abs(tau))), rel=1e-4)
