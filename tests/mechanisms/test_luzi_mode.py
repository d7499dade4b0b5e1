"""The luzi3 working mode (each upper link keeps the branch, sign of n·r, that it has at the
nominal pose; module notes of pkmlab.mechanisms.families.luzi3): the inverse kinematics reports the
mirror image below the base as outside it, and every workspace kind keeps to it
(docs/validation.md, "The luzi3 working mode"). The branch is recomputed here from its
geometric meaning, the sign of k · d_i with d_i the part of C_i - A_i1 normal to the base
chord A_i1 A_i2, and the leg lengths from the drawn legs (``leg_segments``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pkmlab.mechanisms import LEG_STATUS, NO_STROKE, Luzi3
from pkmlab.poses import as_frames, matrix_to_euler
from pkmlab.testing import cell_points
from pkmlab.workspaces import OrientationSet, workspace
from pkmlab.workspaces.bracket.columns import volume_bracket

OTHER = {v: k for k, v in LEG_STATUS.items()}["leg outside the working mode"]
BOX = OrientationSet.box((math.radians(5),) * 3, samples=3)


@pytest.fixture(scope="module")
def own():
    """The own geometry of benchmarks/validate_luzi_bracket.py, whose workspace comes close to
    its mirror image (the reachable one crossed the base plane before the working mode)."""
    return Luzi3.from_paper(base_diameter=700.0, phi=math.radians(30), platform_diameter=220.0,
                            upper_link=80.0, stroke=(600.0, 950.0))


def _feasible(mech, p, R):
    """``(N,)``: every chain on the branch +1 and every leg within the stroke."""
    A1, A2 = mech.base_points[0::2], mech.base_points[1::2]
    e = (A2 - A1) / np.linalg.norm(A2 - A1, axis=1, keepdims=True)
    d = p[:, None, :] + np.einsum("nij,kj->nki", R, mech.tool_points) - A1
    d_perp = d - np.einsum("nki,ki->nk", d, e)[..., None] * e
    branch_ok = np.all(np.einsum("ni,nki->nk", R[:, :, 2], d_perp) > 0, axis=1)
    a, b = mech.leg_segments(p, R)
    q = np.linalg.norm(b - a, axis=-1)
    lo, hi = mech.stroke
    return branch_ok & np.all((q >= lo) & (q <= hi), axis=1)


def test_mirror_image_below_the_base_is_outside_the_working_mode(own):
    X = own.nominal_pose
    Xm = X * np.array([1, 1, -1, 1, 1, 1])          # level: the mirror keeps the rotation
    ik = own.inverse(np.stack([X, Xm]))
    np.testing.assert_allclose(ik.q[1], ik.q[0], atol=1e-9)   # same lengths
    assert ik.reason_text.tolist() == ["ok", "leg outside the working mode"]
    assert np.all(ik.reason_text[1] == "leg outside the working mode")
    # a nominal pose below the base makes that side the working mode
    low = Luzi3(own.base_points, own.platform_points, own.upper_link, own.stroke,
                own.tool_offset, nominal=Xm)
    assert low.inverse(np.stack([X, Xm])).reason_text.tolist() == [
        "leg outside the working mode", "ok"]


def _grid_points(r):
    X, Y, Z = np.meshgrid(r.xs, r.ys, r.zs, indexing="ij")
    return np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)


@pytest.fixture(scope="module")
def reachable(own):
    return workspace(own, "reachable", BOX, resolution=20.0)


@pytest.mark.parametrize("kind", ["constant", "dexterous", "reachable"])
def test_workspace_keeps_to_the_working_mode(own, reachable, kind):
    box = None if kind == "constant" else BOX
    r = reachable if kind == "reachable" else workspace(own, kind, box, resolution=20.0)
    V = r.voxel_centres()
    # the constant and dexterous sets (z 150…910 / 310…910 mm) never came near the base; the
    # reachable one went down to z = -900 mm, the mirror image, before the working mode
    assert V[:, 2].min() > 0.0
    _, Rn = as_frames(own.nominal_pose)
    Rs = Rn if box is None else box.centred(tuple(matrix_to_euler(Rn[0]))).rotations()
    # independently: the grid points within the stroke at every (some) sampled rotation with
    # every link on its nominal branch; the engine keeps their component holding the nominal
    P = _grid_points(r)
    ok = np.ones(len(P), bool) if kind != "reachable" else np.zeros(len(P), bool)
    for R in Rs:
        f = _feasible(own, P, np.ascontiguousarray(np.broadcast_to(R, (len(P), 3, 3))))
        ok = ok | f if kind == "reachable" else ok & f
    occ = r.occupancy.ravel()
    assert np.all(ok[occ])                                        # nothing outside the mode
    # and (nearly) all of them: here the feasible set is one piece, but for at most 1 %
    # in separate bits
    assert occ.sum() >= 0.99 * ok.sum()


def test_reachable_bracket_keeps_to_the_working_mode(own, reachable):
    # the first step only (80 mm cubes, 0.5 s): the undecided cubes near the base plane, where
    # a link may flip within a cell, reach z = -160 mm; before the working mode the outer set
    # went down to z = -940 mm
    b = volume_bracket(own, "reachable", BOX, 20.0, budget_s=60, max_evaluations=5e5)
    # it holds the engine's sampled volume (samples under-estimate the reachable one) and
    # every voxel of it ...
    assert reachable.volume - reachable.volume_error <= b.upper
    V = reachable.voxel_centres()
    assert b.contains(V, "outer").all()
    # ... but not the mirror image of the workspace below the base
    mirror = V[V[:, 2] > 200.0] * np.array([1.0, 1.0, -1.0])
    assert len(mirror) > 10_000 and not b.contains(mirror, "outer").any()


def test_cell_mode_holds_on_random_cells(own):
    """``leg_cell_bounds(..., mode=True)``: +1 only where every point of the cell is in the
    working mode, -1 only where none is (checked at a random point of each cell, half of them
    on its boundary), over positions on both sides of the base plane."""
    rng = np.random.default_rng(11)
    n = 40_000
    p = rng.uniform([-700, -700, -900], [700, 700, 900], (n, 3))
    R = Rotation.from_rotvec(rng.normal(size=(n, 3)) * 0.2).as_matrix()
    delta, alpha = rng.uniform(0, 80, n), rng.uniform(0, 0.2, n)
    _, _, mode = own.leg_cell_bounds(p, R, delta, alpha, mode=True)
    p2, R2, _ = cell_points(rng, p, R, delta, alpha)
    st = own.inverse((p2, R2), stroke=NO_STROKE).leg_status[:, 0::2]       # one leg a chain
    other = st == OTHER
    assert not np.any(other[mode > 0]) and np.all(other[mode < 0])
    # every outcome occurs, and most cells are decided
    assert (mode > 0).mean() > 0.2 and (mode < 0).mean() > 0.2 and (mode == 0).any()
