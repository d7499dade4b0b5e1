"""6-RSS (rotary servo Stewart platform): the leg model checked against independent numerics."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import pkmlab
from pkmlab.config import mechanism_spec, to_display
from pkmlab.mechanisms import LEG_STATUS, NO_STROKE, RSS6
from pkmlab.poses import as_frames
from pkmlab.testing import random_valid_poses

REASON = {v: k for k, v in LEG_STATUS.items()}
FILE = Path(__file__).resolve().parents[2] / "studies" / "mechanisms" / \
    "instructables-servo-6rss.yaml"

GEOMETRIES = {
    "file": lambda: pkmlab.load_mechanism(FILE),
    "radial-inward": lambda: RSS6.from_circles(
        base_radii=(90.0, 110.0), platform_radii=(60.0, 70.0), crank_length=30.0,
        rod_length=140.0, crank_plane="radial", zero_direction="inward"),
    "tangential-mixed-branch": lambda: RSS6.from_circles(
        crank_plane="tangential", branch=[-1, 1, -1, 1, -1, 1],
        stroke=(-math.pi, math.pi)),
}


@pytest.fixture(params=sorted(GEOMETRIES), ids=sorted(GEOMETRIES))
def rss(request):
    return GEOMETRIES[request.param]()


def _joints(m, X):
    p, R = as_frames(X)
    return p[:, None, :] + np.einsum("nij,kj->nki", R, m.tool_points)


def test_ik_is_a_root_of_the_rod_equation_on_the_declared_branch(rss):
    """Brute force: scan α over the circle for |P - C(α)| = s, then check the kernel returned
    one of the roots, the one on the declared side of the line from the axis to P."""
    X = random_valid_poses(rss, 30, seed=11)
    q = rss.inverse(X, stroke=NO_STROKE).q
    P = _joints(rss, X)
    grid = np.linspace(-math.pi, math.pi, 2001)
    for n in range(len(X)):
        for i in range(6):
            def f(a, n=n, i=i):
                return np.linalg.norm(P[n, i] - rss.crank_ends(np.full(6, a))[i]) \
                    - rss.rod_length[i]
            vals = np.array([f(a) for a in grid])
            roots = [brentq(f, grid[k], grid[k + 1], xtol=1e-14)
                     for k in range(len(grid) - 1) if vals[k] * vals[k + 1] < 0]
            assert len(roots) == 2
            assert min(abs(q[n, i] - r) for r in roots) < 1e-9
            # branch: b = -1 ⇔ the crank is clockwise of W in the (u, v) plane
            W = P[n, i] - rss.base_points[i]
            w = np.array([W @ rss.zero_directions[i], W @ rss.v_directions[i]])
            c = np.array([math.cos(q[n, i]), math.sin(q[n, i])])
            assert np.sign(c[0] * w[1] - c[1] * w[0]) == -rss.branch[i]


def test_generator_conventions():
    for plane in ("radial", "tangential"):
        m = RSS6.from_circles(crank_plane=plane)
        np.testing.assert_allclose(m.v_directions, np.tile([0.0, 0.0, 1.0], (6, 1)),
                                   atol=1e-15)          # positive angle raises the crank end
        radial = m.base_points / np.linalg.norm(m.base_points, axis=1, keepdims=True)
        dot = np.abs(np.sum(m.servo_axes * radial, axis=1))
        np.testing.assert_allclose(dot, 0.0 if plane == "radial" else 1.0, atol=1e-12)
    # Level nominal pose at mid-range: horns horizontal, rods exactly s long.
    m = RSS6.from_circles()
    q = m.inverse(m.nominal_pose).q[0]
    np.testing.assert_allclose(q, 0.0, atol=1e-12)
    C = m.crank_ends(q[None])[0]
    np.testing.assert_allclose(np.linalg.norm(_joints(m, m.nominal_pose)[0] - C, axis=1),
                               m.rod_length, atol=1e-9)
    np.testing.assert_allclose(C - m.base_points, 25.0 * m.zero_directions, atol=1e-12)


def test_unreachable_and_degenerate_legs_are_flagged_never_valid():
    m = RSS6.from_circles()
    far = m.nominal_pose + [0.0, 0.0, 200.0, 0.0, 0.0, 0.0]     # beyond a + s
    ik = m.inverse(far)
    assert not ik.valid[0] and ik.reason_text[0] == "no real solution"
    assert np.all(np.isnan(ik.q)) and np.all(ik.leg_status == REASON["no real solution"])
    # Platform joint 1 placed on servo 1's axis: E = F = 0.
    p = m.base_points[0] + 40.0 * m.servo_axes[0] - m.tool_points[0]
    ik = m.inverse(np.array([[*p, 0.0, 0.0, 0.0]]), stroke=NO_STROKE)
    assert ik.leg_status[0, 0] == REASON["degenerate leg geometry"]
    assert np.isnan(ik.q[0, 0]) and not ik.valid[0]


def test_servo_range_status_and_window_validation():
    m = RSS6.from_circles(stroke=(-0.2, 0.2))
    up = m.nominal_pose + [0.0, 0.0, 12.0, 0.0, 0.0, 0.0]
    down = m.nominal_pose - [0.0, 0.0, 12.0, 0.0, 0.0, 0.0]
    assert m.inverse(up).reason_text[0] == "stroke above maximum"
    assert m.inverse(down).reason_text[0] == "stroke below minimum"
    with pytest.raises(pkmlab.ParameterError, match="stroke"):
        RSS6.from_circles(stroke=(-4.0, 0.5))
    with pytest.raises(pkmlab.ParameterError, match="branch"):
        RSS6.from_circles(branch=0.5)


def test_servo_torques_by_virtual_work(rss):
    X = random_valid_poses(rss, 10, seed=12)
    w = np.array([3.0, -2.0, -20.0, 150.0, -80.0, 40.0])        # N and N·mm
    tau = rss.servo_torques(X, w)
    J = rss.jacobian(X)
    twist = np.random.default_rng(0).normal(size=(10, 6))
    np.testing.assert_allclose(np.einsum("ni,ni->n", tau, np.einsum("nij,nj->ni", J, twist)),
                               twist @ w, rtol=1e-9)


def test_hand_torque_at_level_pose():
    """Vertical load on the symmetric pose: every servo carries a sixth, and with the horn
    horizontal the torque is (F/6)·a·(d_z / d·t) · ... checked against J⁻ᵀ by hand."""
    m = RSS6.from_circles()
    X = m.nominal_pose
    tau = m.servo_torques(X, [0.0, 0.0, -60.0, 0.0, 0.0, 0.0])[0]
    # Hand: each rod carries tension T along d with 6·T·d_z/|d| = 60 N; the crank end moves
    # along t = ∂C/∂α = a·v = a·ẑ, so τ = T·(d·t)/|d| = 10 N · a · |d| / d_z · d_z / |d|.
    np.testing.assert_allclose(tau, -10.0 * 25.0, rtol=1e-12)


def test_yaml_round_trip_and_explicit_form():
    import yaml

    m = pkmlab.load_mechanism(FILE)
    data = yaml.safe_load(FILE.read_text())
    shown = to_display(mechanism_spec(data))
    assert shown["stroke"] == ["-80 deg", "80 deg"]
    assert pkmlab.load_mechanism(shown) == m
    explicit = {"family": "rss6", "stroke": ["-80 deg", "80 deg"],
                "base_points": m.base_points.tolist(),
                "platform_points": m.platform_points.tolist(),
                "servo_axes": m.servo_axes.tolist(), "zero_directions": m.zero_directions.tolist(),
                "crank_length": m.crank_length.tolist(), "rod_length": m.rod_length.tolist()}
    e = pkmlab.load_mechanism(explicit)
    X = random_valid_poses(m, 20, seed=3)
    np.testing.assert_allclose(e.inverse(X).q, m.inverse(X).q, atol=1e-12)
    with pytest.raises(pkmlab.ParameterError, match="servo_axes"):
        pkmlab.load_mechanism({k: v for k, v in explicit.items() if k != "servo_axes"})


def test_cli_reports_servo_angles_in_degrees():
    from typer.testing import CliRunner

    from pkmlab.cli import app

    m = pkmlab.load_mechanism(FILE)
    X = m.nominal_pose + [2.0, -3.0, 4.0, 0.05, 0.0, 0.02]
    pose = ",".join(f"{v:.12g}" for v in [*X[:3], *np.degrees(X[3:])])
    res = CliRunner().invoke(app, ["ik", str(FILE), "--pose", pose, "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.output)
    assert data["actuator_unit"] == "deg"
    np.testing.assert_allclose(list(data["actuators"].values()), np.degrees(m.inverse(X).q[0]),
                               atol=1e-9)
    q = ",".join(f"{v:.12g}" for v in data["actuators"].values())
    res = CliRunner().invoke(app, ["fk", str(FILE), "--actuators", q, "--json"])
    fk = json.loads(res.output)
    assert fk["converged"] and abs(fk["pose"]["z"] - X[2]) < 1e-6


def test_sampled_workspace_matches_independent_voxel_count():
    """The engine's sampled method: its count equals an independent numpy evaluation of the
    closed form (|G| <= ρ and the angle in range) on the same grid (the exact column method
    is checked in ``test_rss6_columns.py``)."""
    m = RSS6.from_circles(stroke=(-1.0, 1.0))
    cons = pkmlab.Constraints(connected=False)
    ws = pkmlab.workspace(m, "constant", resolution=4.0, constraints=cons, method="sampled")
    assert ws.method == "sampled voxels"
    X, Y, Z = np.meshgrid(ws.xs, ws.ys, ws.zs, indexing="ij")
    p = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    W = p[:, None, :] + m.tool_points - m.base_points
    a, s = m.crank_length, m.rod_length
    E = 2 * a * np.einsum("nki,ki->nk", W, m.zero_directions)
    F = 2 * a * np.einsum("nki,ki->nk", W, m.v_directions)
    G = np.sum(W * W, axis=-1) + a * a - s * s
    rho = np.hypot(E, F)
    with np.errstate(invalid="ignore"):
        alpha = np.arctan2(F, E) + m.branch * np.arccos(np.clip(G / rho, -1, 1))
    alpha = (alpha + np.pi) % (2 * np.pi) - np.pi
    ok = np.all((np.abs(G) <= rho) & (alpha >= -1.0) & (alpha <= 1.0), axis=1)
    assert ok.sum() > 1000
    assert ws.occupancy.sum() == ok.sum()
