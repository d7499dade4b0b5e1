"""The planar five-bar (issue 24, item 4): contract suite, inverse kinematics against the
law of cosines, both assembly modes against multi-start Newton, the four working modes,
singularity classification, workspace area per working mode (bracket soundness, exact area,
dense brute force) and the resolution map against forward-kinematics differences."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab import testing
from pkmlab.mechanisms import REGISTRY
from pkmlab.mechanisms.families.fivebar import FiveBar
from pkmlab.mechanisms.solvers import multistart_modes
from pkmlab.workspaces.planar import areas_per_working_mode, planar_workspace, resolution_map


@pytest.fixture(scope="module")
def mech():
    return pkmlab.load_mechanism(MECH_DIR / "fivebar-scara.yaml")


def _free(m):
    return FiveBar(m.base_points, m.proximal, m.distal, (-math.pi, math.pi), m.branch)


def test_registered_and_contract_suite(mech):
    assert REGISTRY["fivebar"] is FiveBar
    assert testing.run_contract(mech) == list(testing.CHECKS)
    assert mech.mobility.coordinates == ("x", "y") and mech.actuator_unit == "rad"
    assert mech.jacobian(mech.nominal_pose).shape == (1, 2, 2)


def test_ik_against_the_law_of_cosines(mech):
    """Elbow C_i from θ_i: |C_i - A_i| = l1, |P - C_i| = l2, C_i on the side of A_i→P that
    the branch says (sign of the cross product), θ in the window's frame."""
    rng = np.random.default_rng(0)
    X = np.zeros((400, 6))
    X[:, :2] = rng.uniform(-550, 550, (400, 2))
    ik = mech.inverse(X)
    A = mech.base_points[:, :2]
    D = np.hypot(*(X[:, None, :2] - A).transpose(2, 0, 1))
    reach = (D >= 50.0) & (D <= 550.0)
    assert np.array_equal(np.isnan(ik.q), ~reach)
    assert np.array_equal(ik.leg_status == 4, ~reach)
    q = ik.q
    C = A + 250.0 * np.stack([np.cos(q), np.sin(q)], -1)
    ok = reach
    np.testing.assert_allclose(np.hypot(*(X[:, None, :2] - C).transpose(2, 0, 1))[ok], 300.0,
                               atol=1e-9)
    cross = ((X[:, None, 0] - A[:, 0]) * (C[..., 1] - A[:, 1])
             - (X[:, None, 1] - A[:, 1]) * (C[..., 0] - A[:, 0]))
    assert np.all(np.sign(cross[ok]) == np.broadcast_to(mech.branch, cross.shape)[ok])
    lo, hi = np.radians([-45.0, 225.0])
    assert np.all((q[ok] >= lo - math.pi) & (q[ok] < lo + 3 * math.pi))
    inside = ok & (q >= lo) & (q <= hi)
    assert np.array_equal(ik.leg_status == 0, inside)


def test_assembly_modes_against_multistart_newton(mech):
    """Both circle intersections close the loops, and multi-start Newton (the protocol's
    generic search, 600 starts) finds the same two poses."""
    rng = np.random.default_rng(1)
    X = testing.random_valid_poses(mech, 10, seed=2, lin=150.0)
    for q in mech.inverse(X).q:
        a = mech.assembly_modes(q)
        b = multistart_modes(mech, q, starts=600, seed=int(rng.integers(1000)), tol=1e-9)
        assert len(a.pose) == len(b.pose) == 2
        for x in b.pose:
            assert np.abs(a.pose[:, :2] - x[:2]).max(axis=1).min() < 1e-6
        assert np.all(a.residual < 1e-9) and a.working_mode[0]
    # no assembly: elbows farther apart than the two distal links
    assert len(mech.assembly_modes([math.pi, 0.0]).pose) == 0


def test_four_working_modes_each_reproduce_the_point(mech):
    P = np.array([[40.0, 320.0, 0, 0, 0, 0]])
    qs = []
    for mode in mech.working_modes():
        m = mech.with_working_mode(mode)
        q = m.inverse(P, stroke=(-np.inf, np.inf)).q[0]
        poses, in_mode = m.forward_all(q)
        k = np.nanargmin(np.abs(poses[0, :, :2] - P[0, :2]).max(axis=1))
        assert np.abs(poses[0, k, :2] - P[0, :2]).max() < 1e-9 and in_mode[0, k]
        qs.append(q)
    assert len({tuple(np.round(q, 9)) for q in qs}) == 4
    assert mech.working_modes() == ("++", "+-", "-+", "--")


def test_singularity_classification(mech):
    assert mech.singularity(mech.nominal_pose).tolist() == [0]
    # type I: arm 1 stretched (|P - A1| = l1 + l2)
    A1 = mech.base_points[0, :2]
    X = np.zeros((1, 6))
    X[0, :2] = A1 + 550.0 * np.array([math.cos(1.2), math.sin(1.2)])
    assert mech.singularity(X).tolist() == [1]
    # type II: the two distal links aligned: elbows 600 mm apart, the point between them
    m = mech.with_working_mode("+-")
    th = 2.0
    C1 = A1 + 250.0 * np.array([math.cos(th), math.sin(th)])
    A2 = mech.base_points[1, :2]
    # C2 on the circle |C2 - A2| = 250 at 600 mm from C1: bisect the angle
    def f(t):
        return np.hypot(*(A2 + 250 * np.array([math.cos(t), math.sin(t)]) - C1)) - 600.0

    a, b = -1.0, 1.5
    assert f(a) * f(b) < 0
    for _ in range(80):
        c = 0.5 * (a + b)
        a, b = (c, b) if f(a) * f(c) > 0 else (a, c)
    C2 = A2 + 250 * np.array([math.cos(a), math.sin(a)])
    X[0, :2] = 0.5 * (C1 + C2)
    codes = [mm.singularity(X)[0] for mm in (m.with_working_mode(k) for k in m.working_modes())
             if np.allclose(mm._elbows(None, mm.inverse(X, stroke=(-np.inf, np.inf)).q)[0],
                            [C1, C2], atol=1e-6)]
    assert codes == [2]


def test_workspace_per_working_mode_bracket_sound_and_brute_force(mech):
    """Motor windows: margins proved in / out agree with sampled points of random cells;
    each mode's bracket holds a 2.5 mm brute-force count; without motor windows every mode
    has the same exact area (the annuli) inside its bracket."""
    rng = np.random.default_rng(3)
    n, k = 3000, 30
    c = rng.uniform(-550, 550, (n, 2))
    half = rng.uniform(0.5, 25.0, n)
    for mode in mech.working_modes():
        m = mech.with_working_mode(mode)
        mar, eps = m.planar_cell_margins(c, np.zeros(n), half * math.sqrt(2), np.zeros(n))
        cin, cout = np.all(mar > eps, axis=1), np.any(mar < -eps, axis=1)
        assert cin.sum() > 200 and cout.sum() > 200
        P = c[:, None, :] + rng.uniform(-1, 1, (n, k, 2)) * half[:, None, None]
        X = np.zeros((n * k, 6))
        X[:, :2] = P.reshape(-1, 2)
        ok = m.inverse(X).valid.reshape(n, k)
        assert ok[cin].all() and not ok[cout].any(), mode
    areas = areas_per_working_mode(mech, 10.0)
    h = 2.5
    x = np.arange(-560.0, 560.0, h)
    G = np.zeros((len(x) ** 2, 6))
    G[:, 0], G[:, 1] = (g.ravel() for g in np.meshgrid(x, x, indexing="ij"))
    for mode, res in areas.items():
        brute = mech.with_working_mode(mode).inverse(G).valid.sum() * h * h
        assert res.lower * 0.995 <= brute <= res.upper * 1.005, (mode, res.bracket, brute)
    assert areas["-+"].upper < areas["+-"].lower < areas["++"].lower
    free = areas_per_working_mode(_free(mech), 10.0)
    exact = {r.exact for r in free.values()}
    assert len(exact) == 1
    assert all(r.lower <= r.exact <= r.upper for r in free.values())


def test_resolution_map_against_forward_kinematics(mech):
    res = planar_workspace(mech, "constant", None, 25.0)
    step = 1e-8          # rad: second-order terms stay below 1e-4 of the first near type II
    rm = resolution_map(mech, res, step)
    idx = np.argwhere(res.occupancy)[::7]
    for i, j in idx:
        P = np.array([res.xs[i], res.ys[j], 0, 0, 0, 0])
        q = mech.inverse(P).q[0]
        d = []
        for s in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            poses, in_mode = mech.forward_all(q + step * np.array(s))
            k = np.nanargmin(np.abs(poses[0, :, :2] - P[:2]).max(axis=1))
            d.append(poses[0, k, :2] - P[:2])
        d = np.array(d)
        worst = np.max(np.hypot(d[:, 0], d[:, 1]))
        assert rm["worst"][i, j] == pytest.approx(worst, rel=1e-3)
        assert rm["x"][i, j] == pytest.approx(np.max(np.abs(d[:, 0])), rel=1e-3)


def test_vectorisable_atan2_against_math_atan2():
    """The kernels' atan2 (fdlibm's polynomial, branch-free) against math.atan2 on 200,000
    random pairs over many magnitudes, the axes and the octant edges: within 2 ulp of π."""
    from numba import njit

    from pkmlab.mechanisms.families import _fastmath

    @njit
    def many(y, x, out):
        for k in range(len(y)):
            out[k] = _fastmath.atan2(y[k], x[k])

    rng = np.random.default_rng(9)
    n = 200_000
    y = rng.standard_normal(n) * 10.0 ** rng.uniform(-8, 8, n)
    x = rng.standard_normal(n) * 10.0 ** rng.uniform(-8, 8, n)
    edge = np.array([[0.0, 1.0], [0.0, -1.0], [1.0, 0.0], [-1.0, 0.0], [1.0, 1.0],
                     [-1.0, -1.0], [1.0, -1.0], [math.tan(math.pi / 8), 1.0],
                     [np.nextafter(math.tan(math.pi / 8), 1), 1.0], [3.0, 3.0 + 1e-12]])
    y, x = np.concatenate([y, edge[:, 0]]), np.concatenate([x, edge[:, 1]])
    out = np.empty_like(y)
    many(y, x, out)
    ref = np.arctan2(y, x)
    assert np.max(np.abs(out - ref)) <= 2 * np.spacing(math.pi)


def test_dexterity_needs_no_characteristic_length(mech):
    from pkmlab import dexterity as dx

    L = dx.resolve_length(mech)
    assert L.status == "not-applicable" and L.length is None
    X = testing.random_valid_poses(mech, 20, seed=12, lin=100.0)
    J = mech.jacobian(X)
    np.testing.assert_allclose(dx.condition_number(J, L), np.linalg.cond(J), rtol=1e-12)
