"""The 3-PRS tripod (issue 24, item 5): dependent coordinates in the mobility, the parasitic
motions against a scipy solve of the constraints, the inverse kinematics against a root
search of each link, the contract suite, singularity flags and the free-coordinate workspace
against an independent NumPy count."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR
from scipy.optimize import brentq, fsolve

import pkmlab
from pkmlab import testing
from pkmlab.mechanisms import REGISTRY
from pkmlab.mechanisms.families.prs3 import TRIPOD, Prs3, tripod_layout
from pkmlab.mechanisms.mobility import Mobility
from pkmlab.poses import euler_to_matrix
from pkmlab.workspaces.tripod import plot_tripod, tripod_workspace


@pytest.fixture(scope="module")
def mech():
    return pkmlab.load_mechanism(MECH_DIR / "tripod-3prs.yaml")


def test_mobility_with_dependent_coordinates():
    assert TRIPOD.coordinates == ("z", "theta_x", "theta_y")
    assert TRIPOD.dependent == ("x", "y", "theta_z")
    assert TRIPOD.twist_columns.tolist() == [2, 3, 4] and TRIPOD.rotations
    with pytest.raises(ValueError, match="free or dependent, not both"):
        Mobility("bad", ("z",), dependent=("z",))
    with pytest.raises(ValueError, match="all three angles free or dependent"):
        Mobility("bad", ("z", "theta_x"), dependent=("x",))
    assert Mobility("tripod", ("z", "theta_x", "theta_y"), ("x", "y", "theta_z")) == TRIPOD


def test_registered_and_contract_suite(mech):
    assert REGISTRY["prs3"] is Prs3
    assert testing.run_contract(mech) == list(testing.CHECKS)
    assert mech.jacobian(mech.nominal_pose).shape == (1, 3, 3)


def _random_free(n, seed, tilt=25.0):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-150, 120, n), np.radians(rng.uniform(-tilt, tilt, n)),
                            np.radians(rng.uniform(-tilt, tilt, n))])


def test_parasitic_motions_against_scipy_and_their_properties(mech):
    """fsolve on n_i·(p + R·b_i) = n_i·a_i for (x, y, θz) from 0: the same to 1e-9; on the
    symmetric layout they do not depend on z and vanish when level."""
    F = _random_free(40, 0)
    par = mech.parasitic(F)
    for (z, a, b), mine in zip(F, par):
        def eqs(u, z=z, a=a, b=b):
            R = euler_to_matrix(np.array([a, b, u[2]]))
            S = np.array([u[0], u[1], z]) + mech.platform_points @ R.T
            return np.sum(mech.hinge_axes * (S - mech.base_points), axis=1)
        ref = fsolve(eqs, np.zeros(3), xtol=1e-12)
        np.testing.assert_allclose(mine, ref, atol=1e-9)
    G = F.copy()
    G[:, 0] += 57.0
    np.testing.assert_allclose(mech.parasitic(G), par, atol=1e-12)
    np.testing.assert_allclose(mech.parasitic([[10.0, 0.0, 0.0]]), 0.0, atol=1e-12)
    assert np.abs(par[:, :2]).max() > 1.0 and np.abs(par[:, 2]).max() > 1e-3   # not trivial


def test_ik_against_a_root_search_of_each_link(mech):
    F = _random_free(30, 1)
    X = mech.complete(np.column_stack([np.zeros(len(F)), np.zeros(len(F)), F[:, 0], F[:, 1],
                                       F[:, 2], np.zeros(len(F))]))
    ik = mech.inverse(F)                      # free coordinates in
    np.testing.assert_array_equal(ik.q, mech.inverse(X).q)
    for x, q in zip(X, ik.q):
        S = x[:3] + mech.platform_points @ euler_to_matrix(x[3:]).T
        for i in range(3):
            def f(t, s=S[i], i=i):
                return np.linalg.norm(s - mech.base_points[i] - t * mech.rail_axes[i]) - 250.0

            top = S[i][2] + 300.0                   # the slider above the joint (branch +1)
            ref = brentq(f, S[i][2], top, xtol=1e-13)
            assert q[i] == pytest.approx(ref, abs=1e-9)


def test_singularity_flags():
    a, d, n, b = tripod_layout(200.0, 100.0)
    short = Prs3(a, b, d, n, [100.0] * 3, (-300.0, 300.0), nominal=np.array(
        [0, 0, 0.0, 0, 0, 0]))
    # links of 100 mm from rails 100 mm away: level, every link is horizontal (type I)
    assert short.singularity(np.zeros(6)).tolist() == [1]
    m = pkmlab.load_mechanism(MECH_DIR / "tripod-3prs.yaml")
    assert m.singularity(m.nominal_pose).tolist() == [0]


def test_workspace_count_and_parasitic_excursions_against_numpy(mech, tmp_path):
    """The feasible grid points, recounted with the NumPy closed form of the parasitic motions
    and the slider formula (not the numba kernel); the excursions are the largest parasitic
    magnitudes over them; the sampled volume converges as the resolutions are halved (the
    changes shrink, the last below 2.5 %)."""
    res = tripod_workspace(mech, math.radians(40.0), resolution_z=10.0,
                           resolution_angle=math.radians(4.0))
    Z, A, B = np.meshgrid(res.zs, res.angles, res.angles, indexing="ij")
    F = np.column_stack([Z.ravel(), A.ravel(), B.ravel()])
    X = np.zeros((len(F), 6))
    X[:, 2:5] = F
    pf, Rf, x, y, gam = mech._dependent_frames(*mech._frames(X))
    S = pf[:, None, :] + np.einsum("nij,kj->nki", Rf, mech.platform_points)
    D = S - mech.base_points
    t = np.sum(D * mech.rail_axes, -1)
    disc = 250.0 ** 2 - np.sum(D * D, -1) + t * t
    with np.errstate(invalid="ignore"):
        q = t + np.sqrt(disc)
    ok = np.all((disc >= 0) & (q >= 0.0) & (q <= 400.0), axis=1).reshape(Z.shape)
    assert np.array_equal(ok, res.occupancy) and 0 < ok.sum() < ok.size
    met = res.metrics()
    P = np.column_stack([x, y, gam])[ok.ravel()]
    assert met["parasitic_x_max_mm"] == pytest.approx(np.abs(P[:, 0]).max(), rel=1e-12)
    assert met["parasitic_theta_z_max_deg"] == pytest.approx(np.degrees(np.abs(P[:, 2]).max()),
                                                             rel=1e-12)
    vols = [tripod_workspace(mech, math.radians(20.0), resolution_z=10.0 / k,
                             resolution_angle=math.radians(4.0 / k)).volume for k in (1, 2, 4)]
    steps = np.abs(np.diff(vols)) / vols[-1]
    assert steps[1] < steps[0] and steps[1] < 0.025, vols
    assert plot_tripod(res, tmp_path / "t.png").stat().st_size > 10_000


def test_the_3d_engine_refuses_the_tripod_naming_its_workspace_module(mech):
    from pkmlab.errors import ParameterError

    with pytest.raises(ParameterError, match="pkmlab.workspaces.tripod"):
        pkmlab.workspace(mech, "constant", resolution=10.0)


def test_dexterity_on_its_own_mobility(mech):
    """Mixed translation (v_z) and rotation (ω_x, ω_y) columns: κ homogenised with Angeles'
    length on the two rotation columns, equal to numpy.linalg.cond by hand."""
    from pkmlab import dexterity as dx

    L = dx.resolve_length(mech)
    assert L.status == "angeles" and L.rotational == (1, 2)
    X = testing.random_valid_poses(mech, 20, seed=11)
    J = mech.jacobian(X)
    Jh = J.copy()
    Jh[:, :, 1:] /= L.length
    np.testing.assert_allclose(dx.condition_number(J, L), np.linalg.cond(Jh), rtol=1e-10)
    # Angeles' length minimises κ at the nominal pose: ±1 % of it does no better
    Jn = mech.jacobian(mech.nominal_pose)[0]
    for f in (0.99, 1.01):
        Jf = Jn.copy()
        Jf[:, 1:] /= f * L.length
        assert np.linalg.cond(Jf) >= L.kappa - 1e-9


def test_a_type_ii_singularity_inside_the_stroke_is_classified(mech):
    """det(J)·Π(L_i·d_i) (the actuation matrix; the constraint part stays regular) changes
    sign between the nominal pose and a pose tilted 54° about x: bisection finds a valid pose
    (tilted about 51°) that the flags call type II only."""
    def det_a(F):
        p, R = mech._frames(np.atleast_2d(F))
        _, C, L = mech._rows(p, R)
        assert np.linalg.det(C[:, :, [0, 1, 5]]).min() > 0        # no constraint singularity
        return (np.linalg.det(mech.jacobian(np.atleast_2d(F)))
                * np.prod(np.sum(L * mech.rail_axes, -1), axis=1))[0]

    a = mech.nominal_pose[[2, 3, 4]]
    b = np.array([-37.6638275, np.radians(54.24431016), np.radians(-0.96684155)])
    fa = det_a(a)
    assert fa * det_a(b) < 0 and mech.singularity(a).tolist() == [0]
    for _ in range(80):
        c = 0.5 * (a + b)
        if np.sign(det_a(c)) == np.sign(fa):
            a, fa = c, det_a(c)
        else:
            b = c
    assert mech.inverse(c).valid[0] and mech.singularity(c).tolist() == [2]
    assert 50.0 < np.degrees(c[1]) < 53.0


def test_cli_ik_reports_the_parasitic_motions(mech):
    import json

    from typer.testing import CliRunner

    from pkmlab.cli import app

    r = CliRunner().invoke(app, ["ik", str(MECH_DIR / "tripod-3prs.yaml"), "--pose",
                                 "0,0,-20,10,5,0", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)["dependent"]
    par = mech.parasitic([[-20.0, math.radians(10.0), math.radians(5.0)]])[0]
    assert [d["x"], d["y"], math.radians(d["theta_z"])] == pytest.approx(par.tolist(),
                                                                         abs=1e-12)
