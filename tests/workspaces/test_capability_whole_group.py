"""Issue 22 item 4: ``optimum capability`` on machines whose whole rotation group is feasible.

Before the fix the 6-UPS below gave ``[0, inf]`` and a "certified point" that failed 4,541 of
200,000 random rotations. A ±180° Euler box is all of SO(3): the answer is 180°, proved by the
sphere argument, and the point is checked here independently: for a 6-UPS, the leg lengths
over all rotations fill exactly ``[|p - b_i| - |u_i|, |p - b_i| + |u_i|]`` (numpy, no pkmlab),
and 200,000 uniformly random rotations (scipy) keep every leg in its window.
"""

from __future__ import annotations

import json
import math

import numpy as np
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

from pkmlab import PSU6, UPS6
from pkmlab.cli import app
from pkmlab.workspaces.optima import search as optima
from pkmlab.workspaces.optima.search import orientation_capability

BASE = [[-304.0559, 304.0559, 0.0], [304.0559, 304.0559, 0.0], [415.3481, 111.2922, 0.0],
        [111.2922, -415.3481, 0.0], [-111.2922, -415.3481, 0.0], [-415.3481, 111.2922, 0.0]]
PLATFORM = [[-24.0, 88.0, 0.0], [24.0, 88.0, 0.0], [88.0, -24.0, 0.0], [64.0, -64.0, 0.0],
            [-64.0, -64.0, 0.0], [-88.0, -24.0, 0.0]]


def _ups():
    # kotlarski-2012 base, a small platform (|u| <= 91.2 mm), window [400, 600] mm: at
    # (0, 0, 255) every |p - b_i| ± |u_i| lies inside with 8.6 mm to spare
    return UPS6(np.array(BASE), np.array(PLATFORM), (400.0, 600.0), (0.0, 0.0, 0.0),
                name="whole-group-6ups")


def _random_lengths(mech, p, n=200_000, seed=1):
    R = Rotation.random(n, random_state=seed).as_matrix()
    return np.linalg.norm(np.asarray(p) + np.einsum("nij,kj->nki", R, mech.tool_points)
                          - mech.base_points, axis=-1)


def test_whole_group_is_180_with_a_point_that_holds(tmp_path):
    mech = _ups()
    b = orientation_capability(mech, 5)
    assert b.lower == b.upper == 180.0 and "sphere argument" in b.method
    p = np.asarray(b.point)
    lo, hi = mech.stroke
    c = np.linalg.norm(p - mech.base_points, axis=1)
    r = np.linalg.norm(mech.tool_points, axis=1)
    assert np.min(np.minimum(c - r - lo, hi - (c + r))) > 0          # the sphere argument
    L = _random_lengths(mech, p)
    assert np.all((L >= lo) & (L <= hi)), np.sum((L < lo) | (L > hi))
    # the CLI prints the proved answer, no infinity, and the point for the ±180° box
    f = tmp_path / "m.yaml"
    f.write_text(json.dumps({"name": "wg", "family": "ups6", "base_points": BASE,
                             "platform_points": PLATFORM, "stroke": ["400 mm", "600 mm"],
                             "tool_offset": [0, 0, 0]}))
    res = CliRunner().invoke(app, ["optimum", "capability", str(f)])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "[180.0000, 180.0000]" in text and "inf" not in text
    assert "certified point for the ±180.0000° box" in text


def test_psu6_whole_group_is_180():
    mech = PSU6.from_circles(base_radii=(100.0, 165.0), platform_radii=(10.0, 16.0),
                             platform_rotation=0.5, base_pair_angle=math.radians(90),
                             link_length=225.0, stroke=(0.0, 300.0))
    b = orientation_capability(mech, 5)
    assert b.lower == b.upper == 180.0
    R = Rotation.random(200_000, random_state=2).as_matrix()
    P = np.broadcast_to(np.asarray(b.point), (len(R), 3)).copy()
    assert np.all(mech.inverse((P, R)).valid)


def test_without_the_proof_no_uncertified_point_and_upper_180(monkeypatch):
    """With the sphere argument switched off the upper end is still 180° (the whole group),
    and the reported point holds at every checked rotation of its own box (or is not
    reported)."""
    mech = _ups()
    monkeypatch.setattr(optima, "best_whole_group_point", lambda m, c: (-1.0, c[0]))
    b = orientation_capability(mech, 5)
    assert b.upper == 180.0 and b.lower < 180.0
    if np.all(np.isfinite(b.point)):
        lo, hi = mech.stroke
        th = math.radians(b.lower)
        rng = np.random.default_rng(7)
        E = rng.uniform(-th, th, (50_000, 3))
        R = Rotation.from_euler("ZYX", E[:, ::-1]).as_matrix()     # R = Rz·Ry·Rx
        L = np.linalg.norm(np.asarray(b.point) + np.einsum("nij,kj->nki", R, mech.tool_points)
                           - mech.base_points, axis=-1)
        assert np.all((L >= lo) & (L <= hi))
    # a point that fails the check is never reported
    monkeypatch.setattr(optima, "point_failures", lambda *a, **k: 3)
    b = orientation_capability(mech, 5)
    assert not np.any(np.isfinite(b.point)) and "not reported" in b.note
