"""Dexterity metrics: conditioning, manipulability, singularities, force, stiffness, GCI."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import MECH_DIR
from scipy.optimize import linprog, minimize_scalar
from scipy.stats import kstest

import pkmlab
from pkmlab import PSU6
from pkmlab import dexterity as dx
from pkmlab.mechanisms import LEG_STATUS, NO_STROKE
from pkmlab.poses import as_frames, euler_to_matrix, exp_so3, frames_to_poses, matrix_to_euler
from pkmlab.workspaces import OrientationSet, workspace

REASON = {v: k for k, v in LEG_STATUS.items()}
PSU = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
UPS = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
LUZI = pkmlab.load_mechanism(MECH_DIR / "luzi-3chain.yaml")
THREE = {"psu6": PSU, "ups6": UPS, "luzi3": LUZI}


def transforms(X) -> np.ndarray:
    """Euler poses ``(N, 6)`` → ``(N, 4, 4)`` (inverse kinematics then takes the frames path,
    so each family compiles one numba driver, not two: this file stays fast on its own)."""
    p, R = as_frames(X)
    T = np.zeros((len(p), 4, 4))
    T[:, :3, :3] = R
    T[:, :3, 3] = p
    T[:, 3, 3] = 1.0
    return T


def random_valid_poses(mech, n: int, seed: int, lin: float = 25.0, ang_deg: float = 10.0):
    """``n`` poses ``(n, 6)`` near the nominal pose whose inverse kinematics is valid."""
    rng = np.random.default_rng(seed)
    X = mech.nominal_pose + np.concatenate(
        [rng.uniform(-lin, lin, (20 * n, 3)), np.radians(rng.uniform(-ang_deg, ang_deg,
                                                                      (20 * n, 3)))], axis=1)
    X = X[mech.inverse(transforms(X)).valid][:n]
    assert len(X) == n
    return X


def rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@pytest.fixture(scope="module")
def psu_dexterous():
    """6-PSU ±15° simultaneous dexterous workspace, 3 samples per angle, 5 mm."""
    return workspace(PSU, "dexterous", OrientationSet.box(np.radians([15, 15, 15]), samples=3),
                     resolution=5.0)


@pytest.fixture(scope="module")
def psu_L():
    return dx.characteristic_length(PSU).length


# ---- pointwise metrics -------------------------------------------------------------------------


def test_singular_value_kernel_matches_lapack():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(300, 6, 6))
    A[1] = np.outer(rng.normal(size=6), rng.normal(size=6))           # rank 1
    A[2, :, 4:] *= 1e-9                                                # graded
    A[3, 0, 0] = np.nan
    A[4, 2, 1] = np.inf
    s = dx.singular_values(A)
    ok = dx.jacobian_ok(A)
    assert ok.tolist()[:6] == [True, True, True, False, False, True]
    ref = np.linalg.svd(A[ok], compute_uv=False)
    np.testing.assert_allclose(s[ok], ref, rtol=0, atol=1e-13 * ref[:, :1].max())
    np.testing.assert_allclose(s[2, -2:], ref[np.cumsum(ok)[2] - 1, -2:], rtol=1e-10)
    assert np.all(np.isnan(s[~ok]))
    assert np.all(np.diff(s[ok], axis=1) <= 0)                         # descending
    tall = rng.normal(size=(5, 8, 6))                                  # r > c
    np.testing.assert_allclose(dx.singular_values(tall), np.linalg.svd(tall, compute_uv=False),
                               rtol=1e-12)


@pytest.mark.parametrize("family", sorted(THREE))
def test_condition_number_matches_independent_computation(family):
    mech = THREE[family]
    X = random_valid_poses(mech, 50, seed=11)
    J = mech.jacobian(X)
    L = dx.joint_radius(mech)
    Jh = dx.homogenised_jacobian(J, L)
    np.testing.assert_array_equal(Jh[..., :3], J[..., :3])
    np.testing.assert_allclose(Jh[..., 3:] * L, J[..., 3:], rtol=1e-15)
    k = dx.condition_number(J, L)
    np.testing.assert_allclose(k, np.linalg.cond(Jh), rtol=1e-10)
    lam = np.linalg.eigvalsh(np.swapaxes(Jh, 1, 2) @ Jh)
    np.testing.assert_allclose(k, np.sqrt(lam[:, -1] / lam[:, 0]), rtol=1e-7)
    np.testing.assert_allclose(dx.lci(J, L), 1 / k, rtol=1e-15)
    np.testing.assert_allclose(dx.smallest_singular_value(J, L), np.sqrt(lam[:, 0]), rtol=1e-7)
    # batched over extra leading axes
    np.testing.assert_allclose(dx.condition_number(J.reshape(5, 10, 6, 6), L), k.reshape(5, 10))


def test_undefined_and_singular_jacobians_are_masked_not_raised():
    J = PSU.jacobian(np.stack([PSU.nominal_pose] * 3))
    J[1, 2] = np.nan                                   # a leg with no real solution
    J[2, :, 5] = 0.0                                   # exactly singular
    ok = dx.jacobian_ok(J)
    assert ok.tolist() == [True, False, True]
    k = dx.condition_number(J, 50.0)
    assert np.isfinite(k[0]) and k[1] == np.inf and k[2] == np.inf
    assert dx.lci(J, 50.0)[1:].tolist() == [0.0, 0.0]
    s = dx.smallest_singular_value(J, 50.0)
    assert np.isnan(s[1]) and s[2] < 1e-12 and np.isfinite(s[0])
    wt, wr = dx.manipulability(J)
    assert np.isnan(wt[1]) and np.isnan(wr[1]) and wt[2] == np.inf and np.isfinite(wt[0])
    st = dx.stiffness(J, 100.0)
    assert np.isnan(st.translational_min[1]) and np.all(np.isfinite(st.K[[0, 2]]))
    with pytest.raises(pkmlab.ParameterError):
        dx.condition_number(J, -1.0)


@pytest.mark.parametrize("deg", [37.0, -75.0, 12.5])
def test_kappa_invariant_to_base_rotation_about_z(deg):
    Q = rz(math.radians(deg))
    rot = PSU6(base_points=PSU.base_points @ Q.T, platform_points=PSU.platform_points,
               link_length=PSU.link_length, stroke_window=PSU.stroke,
               tool_offset=PSU.tool_offset)
    X = random_valid_poses(PSU, 40, seed=5)
    p, R = as_frames(X)
    X2 = frames_to_poses(p @ Q.T, Q @ R)
    ik, ik2 = PSU.inverse(transforms(X)), rot.inverse(transforms(X2))
    np.testing.assert_allclose(ik2.q, ik.q, atol=1e-9)      # same machine, rotated
    J, J2 = PSU.jacobian(X), rot.jacobian(X2)
    # Twists rotate with the frame: J2 = J · blockdiag(Qᵀ, Qᵀ); κ must not change.
    np.testing.assert_allclose(J2[..., :3], J[..., :3] @ Q.T, atol=1e-9)
    for L in (30.0, dx.joint_radius(PSU)):
        np.testing.assert_allclose(dx.condition_number(J2, L), dx.condition_number(J, L),
                                   rtol=1e-9)
    np.testing.assert_allclose(dx.manipulability(J2), dx.manipulability(J), rtol=1e-9)
    assert not np.allclose(dx.condition_number(J, 30.0), dx.condition_number(J, 80.0))


@pytest.mark.parametrize("family", sorted(THREE))
def test_characteristic_length_minimises_kappa(family):
    mech = THREE[family]
    res = dx.characteristic_length(mech)
    assert res.ok and not res.at_bound
    L, kappa = res
    assert (L, kappa) == (res.length, res.kappa)
    J = mech.jacobian(mech.nominal_pose)
    np.testing.assert_allclose(dx.condition_number(J, res.length)[0], res.kappa, rtol=1e-12)
    r = dx.joint_radius(mech)
    kap = np.array([dx.condition_number(J, L)[0] for L in r * np.logspace(-3, 3, 601)])
    assert res.kappa <= kap.min() * (1 + 1e-9)
    for f in (0.99, 1.01):
        assert res.kappa < dx.condition_number(J, res.length * f)[0]
    other = dx.characteristic_length(mech, mech.nominal_pose + [5, -3, 2, 0.05, 0, 0.1])
    assert other.ok and other.length != res.length


def test_manipulability_matches_explicit_inverse():
    for mech in THREE.values():
        X = random_valid_poses(mech, 30, seed=9)
        J = mech.jacobian(X)
        Ji = np.linalg.inv(J)
        At, Ar = Ji[:, :3], Ji[:, 3:]
        wt_ref = np.sqrt(np.linalg.det(At @ np.swapaxes(At, 1, 2)))
        wr_ref = np.sqrt(np.linalg.det(Ar @ np.swapaxes(Ar, 1, 2)))
        wt, wr = dx.manipulability(J)
        np.testing.assert_allclose(wt, wt_ref, rtol=1e-9)
        np.testing.assert_allclose(wr, wr_ref, rtol=1e-9)
        # twice as fast actuators per unit twist → each semi-axis halves
        wt2, wr2 = dx.manipulability(2 * J)
        np.testing.assert_allclose(wt2, wt / 8, rtol=1e-12)
        np.testing.assert_allclose(wr2, wr / 8, rtol=1e-12)


# ---- singularities -----------------------------------------------------------------------------


def horizontal_link_pose(mech):
    """Level pose along +x just inside the reach boundary where one link turns horizontal."""
    base = mech.nominal_pose.copy()

    def beyond(x):
        X = base.copy()
        X[0] = x
        st = mech.inverse(transforms(X)).leg_status[0]
        return bool(np.any(st == REASON["no real solution"]))

    lo, hi = 0.0, 2 * float(np.max(mech.link_length))
    assert not beyond(lo) and beyond(hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if beyond(mid):
            hi = mid
        else:
            lo = mid
        if hi - lo < 1e-11:
            break
    X = base.copy()
    X[0] = lo
    return X


def test_serial_flag_fires_on_horizontal_link():
    X = horizontal_link_pose(PSU)
    a, _ = dx.link_vectors(PSU, X)
    horizontal = np.abs(a[0, :, 2]) / PSU.link_length
    assert horizontal.min() < 1e-4                     # one link is (numerically) horizontal
    np.testing.assert_allclose(np.linalg.norm(a[0], axis=1), PSU.link_length, rtol=1e-12)
    fl = dx.singularity_flags(PSU, np.stack([X, PSU.nominal_pose]), tol=1e-3)
    assert fl.serial.tolist() == [True, False]
    assert fl.parallel.tolist() == [False, False]
    assert fl.kind.tolist() == ["serial", "none"]
    assert fl.defined.all()
    assert dx.condition_number(PSU.jacobian(X), 50.0)[0] > 1e3    # J blows up there
    # slightly further out the leg has no solution at all: undefined, not singular
    Xout = X.copy()
    Xout[0] += 1e-3
    out = dx.singularity_flags(PSU, Xout)
    assert out.kind.tolist() == ["undefined"] and not out.serial[0]
    assert np.isnan(out.serial_measure[0]) and np.isnan(out.parallel_measure[0])


@pytest.mark.parametrize("name", ["psu6", "ups6", "luzi3"])
def test_no_singularity_flag_at_nominal_pose(name):
    mech = THREE[name]
    X = np.concatenate([mech.nominal_pose[None], random_valid_poses(mech, 20, seed=4, lin=5,
                                                                     ang_deg=3)])
    fl = dx.singularity_flags(mech, X)
    assert fl.defined.all()
    assert not fl.serial.any() and not fl.parallel.any()
    assert set(fl.kind) == {"none"}
    assert np.all(fl.serial_measure > 0.1) and np.all(fl.parallel_measure > 0.05)


def test_parallel_flag_fires_at_fichter_singularity_of_the_6ups():
    # A level Gough-Stewart platform rotated by 90° about the vertical is architecturally
    # singular (Fichter 1986).
    X = UPS.nominal_pose.copy()
    X[5] -= math.pi / 2
    fl = dx.singularity_flags(UPS, np.stack([X, UPS.nominal_pose]))
    assert fl.parallel.tolist() == [True, False]
    assert fl.kind.tolist() == ["parallel", "none"]
    assert fl.parallel_measure[0] < 1e-12


def test_parallel_flag_fires_at_a_6psu_direct_singularity():
    # Scanning torsion at the nominal position crosses a direct singularity near 51.6°.
    def measure(t):
        X = PSU.nominal_pose.copy()
        X[5] = t
        return dx.singularity_flags(PSU, X).parallel_measure[0]

    res = minimize_scalar(measure, bounds=(math.radians(50), math.radians(53)),
                          method="bounded", options={"xatol": 1e-12})
    X = PSU.nominal_pose.copy()
    X[5] = res.x
    fl = dx.singularity_flags(PSU, X, tol=1e-4)
    assert fl.parallel[0] and not fl.serial[0] and fl.kind[0] == "parallel"
    assert fl.parallel_measure[0] < 1e-6
    # J = diag(l / a_z) · J_x, so J inherits the rank loss
    Jx = dx.direct_kinematic_matrix(PSU, X)
    assert dx.condition_number(PSU.jacobian(X), 50.0)[0] > 1e5
    assert np.linalg.matrix_rank(Jx[0], tol=1e-5 * np.linalg.norm(Jx[0], 2)) == 5


def test_psu6_jacobian_factorises_into_direct_and_inverse_parts():
    X = random_valid_poses(PSU, 30, seed=8)
    a, _ = dx.link_vectors(PSU, X)
    Jx = dx.direct_kinematic_matrix(PSU, X)
    scale = PSU.link_length / a[..., 2]                               # l_i / a_iz
    np.testing.assert_allclose(scale[..., None] * Jx, PSU.jacobian(X), rtol=1e-10, atol=1e-10)
    np.testing.assert_array_equal(dx.direct_kinematic_matrix(UPS, X[:0]), np.empty((0, 6, 6)))


# ---- force capability ---------------------------------------------------------------------------


def lp_force(J, f_max, u, payload=None, moment=False):
    """Brute-force LP (scipy): max s with Jᵀ f = s·[u; 0] (+ payload), |f| ≤ f_max."""
    wd = np.concatenate([np.zeros(3), u]) if moment else np.concatenate([u, np.zeros(3)])
    A = np.hstack([J.T, -wd[:, None]])
    b = np.zeros(6) if payload is None else payload
    res = linprog(c=np.r_[np.zeros(6), -1.0], A_eq=A, b_eq=b,
                  bounds=[(-f, f) for f in f_max] + [(0, None)], method="highs")
    return res.x[-1] if res.status == 0 else np.nan


def test_isotropic_force_and_moment_match_brute_force_lp():
    rng = np.random.default_rng(3)
    f_max = np.array([800.0, 900.0, 1000.0, 1100.0, 1000.0, 950.0])
    for mech in (PSU, UPS):
        X = random_valid_poses(mech, 6, seed=12)
        J = mech.jacobian(X)
        F = dx.max_force_all_directions(J, f_max)
        M = dx.max_moment_all_directions(J, f_max)
        G = np.swapaxes(np.linalg.inv(J), 1, 2)
        for n in range(len(X)):
            for cols, cap, moment in ((slice(0, 3), F[n], False), (slice(3, 6), M[n], True)):
                rows = G[n][:, cols]
                i = np.argmin(f_max / np.linalg.norm(rows, axis=1))
                worst = rows[i] / np.linalg.norm(rows[i])
                np.testing.assert_allclose(lp_force(J[n], f_max, worst, moment=moment), cap,
                                           rtol=1e-7)
                dirs = rng.normal(size=(15, 3))
                dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
                brute = np.array([lp_force(J[n], f_max, u, moment=moment) for u in dirs])
                assert np.all(brute >= cap * (1 - 1e-9))
                assert brute.min() < 3 * cap                  # and the bound is not loose


def test_force_along_lp_closed_form_and_scipy_agree():
    rng = np.random.default_rng(4)
    X = random_valid_poses(PSU, 8, seed=13)
    J = PSU.jacobian(X)
    f_max = 1000.0
    u = rng.normal(size=(8, 3))
    payload = np.array([0.0, 0.0, 200.0, 1500.0, -800.0, 0.0])      # weight + offset moment
    for w in (None, payload):
        cf = dx.force_along_closed_form(J, f_max, u, payload=w)
        lp = dx.force_along(J, f_max, u, payload=w)
        assert cf.ok.all() and lp.ok.all(), (cf.status, lp.status)
        np.testing.assert_allclose(lp.force, cf.force, rtol=1e-6)
        ref = [lp_force(J[n], np.full(6, f_max), u[n] / np.linalg.norm(u[n]),
                        w) for n in range(8)]
        np.testing.assert_allclose(cf.force, ref, rtol=1e-7)
        # the reported actuator forces balance the wrench and respect the limits
        ud = u / np.linalg.norm(u, axis=1, keepdims=True)
        wrench = np.concatenate([cf.force[:, None] * ud, np.zeros((8, 3))], axis=1)
        wrench += 0 if w is None else w
        np.testing.assert_allclose(np.einsum("nji,nj->ni", J, cf.actuator_forces), wrench,
                                   atol=1e-6 * f_max)
        assert np.all(np.abs(cf.actuator_forces) <= f_max * (1 + 1e-9))
    free = dx.force_along_closed_form(J, f_max, u).force
    np.testing.assert_array_less(dx.max_force_all_directions(J, f_max), free * (1 + 1e-12))


def test_force_along_reports_infeasible_payload_and_undefined_jacobian():
    J = PSU.jacobian(np.stack([PSU.nominal_pose] * 2))
    J[1, 0] = np.nan
    heavy = np.array([0.0, 0.0, 1e6, 0.0, 0.0, 0.0])                 # far beyond the actuators
    cf = dx.force_along_closed_form(J, 1000.0, [1.0, 0.0, 0.0], payload=heavy)
    lp = dx.force_along(J, 1000.0, [1.0, 0.0, 0.0], payload=heavy)
    assert cf.status.tolist() == ["infeasible", "undefined"]
    assert lp.status.tolist() == ["infeasible", "undefined"]
    assert not lp.ok.any() and np.all(np.isnan(lp.force)) and np.all(np.isnan(cf.force))
    sing = J[:1].copy()
    sing[0, :, 5] = 0.0
    assert dx.force_along_closed_form(sing, 1000.0, [0, 0, 1]).status.tolist() == ["singular"]
    assert dx.max_force_all_directions(sing, 1000.0).tolist() == [0.0]
    with pytest.raises(pkmlab.ParameterError):
        dx.force_along_closed_form(J, 1000.0, [0.0, 0.0, 0.0])


# ---- stiffness ----------------------------------------------------------------------------------


def test_stiffness_symmetric_positive_definite_and_matches_ik_differences():
    k = np.array([2e4, 2.5e4, 3e4, 2e4, 1.5e4, 2e4])                   # N/mm
    for mech in THREE.values():
        X = random_valid_poses(mech, 25, seed=21)
        J = mech.jacobian(X)
        st = dx.stiffness(J, k)
        K = st.K
        np.testing.assert_array_equal(K, np.swapaxes(K, 1, 2))
        assert np.all(np.linalg.eigvalsh(K)[:, 0] > 0)
        np.testing.assert_allclose(st.translational_min, np.linalg.eigvalsh(K[:, :3, :3])[:, 0])
        np.testing.assert_allclose(st.rotational_min, np.linalg.eigvalsh(K[:, 3:, 3:])[:, 0])
        # restoring wrench of a small displacement twist, from inverse kinematics
        p, R = as_frames(X[:5])
        q0 = mech.inverse((p, R), stroke=NO_STROKE).q
        h = 1e-5
        for j in range(6):
            d = np.zeros(6)
            d[j] = h
            qp = mech.inverse((p + d[:3], exp_so3(d[3:]) @ R), stroke=NO_STROKE).q
            qm = mech.inverse((p - d[:3], exp_so3(-d[3:]) @ R), stroke=NO_STROKE).q
            dq = (qp - qm) / 2                                          # δq for δx = h·e_j
            w = np.einsum("nij,nj->ni", np.swapaxes(J[:5], 1, 2), k * dq)
            np.testing.assert_allclose(w / h, K[:5, :, j], rtol=1e-6,
                                       atol=1e-6 * np.abs(K[:5]).max())
        del q0
    with pytest.raises(pkmlab.ParameterError):
        dx.stiffness(J, -1.0)


# ---- orientation sampling and global indices --------------------------------------------------


def test_sample_orientations_follow_the_set_measures():
    rng = np.random.default_rng(7)
    n = 20000
    box = OrientationSet.box(np.radians([10, 20, 5]), centre=(0.0, 0.0, 0.0))
    E = matrix_to_euler(dx.sample_orientations(box, n, rng))
    for a, h in zip(E.T, np.radians([10, 20, 5])):
        assert np.all(np.abs(a) <= h + 1e-12)
        assert kstest(a, "uniform", args=(-h, 2 * h)).pvalue > 1e-3

    single = OrientationSet.box(np.radians([10, 20, 0]), semantics="single-axis",
                                centre=(0.0, 0.0, 0.0))
    E = matrix_to_euler(dx.sample_orientations(single, n, rng))
    nz = np.abs(E) > 1e-12
    assert np.all(nz.sum(axis=1) <= 1) and not nz[:, 2].any()
    assert abs(nz[:, 1].mean() - 2 / 3) < 0.02                        # ∝ half-range

    beta, gamma = math.radians(80), math.radians(20)      # wide: sin θ differs from θ
    tt = OrientationSet.tilt_torsion(beta, gamma, centre=(0.0, 0.0, 0.0))
    R = dx.sample_orientations(tt, n, rng)
    cos_t = R[:, 2, 2]
    assert kstest(cos_t, "uniform", args=(math.cos(beta), 1 - math.cos(beta))).pvalue > 1e-3
    phi = np.arctan2(R[:, 1, 2], R[:, 0, 2])
    assert kstest(phi, "uniform", args=(-math.pi, 2 * math.pi)).pvalue > 1e-3
    psi = np.arctan2(R[:, 2, 1], -R[:, 2, 0])                          # Z-Y-Z third angle
    sigma = np.angle(np.exp(1j * (psi + phi)))
    assert kstest(sigma, "uniform", args=(-gamma, 2 * gamma)).pvalue > 1e-3

    fixed = OrientationSet.fixed((0.1, 0.0, 0.2), centre=(0.0, 0.0, 0.0))
    np.testing.assert_allclose(dx.sample_orientations(fixed, 3, rng),
                               np.broadcast_to(euler_to_matrix([0.1, 0.0, 0.2]), (3, 3, 3)))


def test_kappa_grid_matches_direct_evaluation(psu_dexterous, psu_L):
    g = dx.kappa_grid(PSU, psu_dexterous, psu_L)
    assert g.valid.all()                                  # dexterous: every orientation valid
    rng = np.random.default_rng(0)
    vi = rng.choice(len(g.positions), 60, replace=False)
    for m in range(len(g.rotations)):
        p = g.positions[vi]
        R = np.broadcast_to(g.rotations[m], (len(vi), 3, 3))
        X = frames_to_poses(p, R)
        assert PSU.inverse(transforms(X)).valid.all()
        J = PSU.jacobian(X)
        np.testing.assert_allclose(g.kappa[vi, m], dx.condition_number(J, psu_L), rtol=1e-9)


def test_gci_grid_and_monte_carlo_agree_constant_orientation(psu_L):
    r5 = workspace(PSU, "constant", resolution=5.0)
    r25 = workspace(PSU, "constant", resolution=2.5)
    g5, g25 = dx.gci_grid(PSU, r5, psu_L), dx.gci_grid(PSU, r25, psu_L)
    mc = dx.gci_monte_carlo(PSU, r5, psu_L, samples=4000, seed=1)
    assert g5.ok and mc.ok and g5.rejected == 0 and g5.std_error == 0
    assert 0 < mc.rejected < 0.1 * 4000                    # boundary voxels, partly outside
    assert mc.samples + mc.rejected == 4000
    tol = 3 * mc.std_error + 2 * abs(g5.gci - g25.gci)
    assert abs(mc.gci - g5.gci) <= tol, (mc, g5.gci, g25.gci)
    # not trivially loose: a different characteristic length changes the index by far more
    assert abs(dx.gci_grid(PSU, r5, 2 * psu_L).gci - g5.gci) > 10 * tol


def test_gci_grid_and_monte_carlo_agree_dexterous(psu_dexterous, psu_L):
    # The equal-weight grid over n Euler samples per angle converges like I + C/n (its end
    # points are over-weighted); extrapolate from n = 5 and 9 on the same voxels and use the
    # size of that correction as the discretisation tolerance.
    grids = {n: dx.gci_grid(PSU, dataclasses.replace(
        psu_dexterous, orientations=psu_dexterous.orientations.with_samples(n)), psu_L).gci
        for n in (5, 9)}
    extrap = (9 * grids[9] - 5 * grids[5]) / 4
    tol_disc = abs(extrap - grids[9])
    mc = dx.gci_monte_carlo(PSU, psu_dexterous, psu_L, samples=4000, seed=2)
    assert mc.ok and mc.rejected < 40
    assert abs(mc.gci - extrap) <= 3 * mc.std_error + tol_disc, (mc, grids, extrap)
    assert grids[5] < grids[9] < extrap                   # the monotone convergence assumed


def test_monte_carlo_is_seeded_and_counts_rejections(psu_L):
    r = workspace(PSU, "reachable", OrientationSet.box(np.radians([20, 20, 20]), samples=3),
                  resolution=5.0)
    a = dx.gci_monte_carlo(PSU, r, psu_L, samples=500, seed=3)
    b = dx.gci_monte_carlo(PSU, r, psu_L, samples=500, seed=3)
    assert a == b
    # reachable: many (voxel, orientation) pairs are outside the stroke and must be rejected
    assert a.rejected > 50 and a.samples == 500 - a.rejected
    g = dx.gci_grid(PSU, r, psu_L)
    kg = dx.kappa_grid(PSU, r, psu_L)
    assert g.rejected == int((~kg.valid).sum()) > 0
    np.testing.assert_allclose(g.gci, np.mean(1 / kg.kappa[kg.valid]), rtol=1e-12)


def test_kappa_statistics():
    v = np.array([1.0, 2.0, 3.0, 4.0, np.inf, 10.0, np.nan])
    s = dx.kappa_statistics(v)
    fin = np.array([1.0, 2.0, 3.0, 4.0, 10.0])
    assert (s.min, s.max, s.count, s.non_finite) == (1.0, 10.0, 5, 2)
    assert s.mean == pytest.approx(4.0)
    assert [s.p5, s.p50, s.p95] == pytest.approx(np.percentile(fin, [5, 50, 95]).tolist())
    empty = dx.kappa_statistics([np.inf])
    assert empty.count == 0 and math.isnan(empty.mean)


def test_well_conditioned_volume(psu_dexterous, psu_L):
    g = dx.kappa_grid(PSU, psu_dexterous, psu_L)
    worst = g.kappa.max(axis=1)
    every = dx.well_conditioned_volume(PSU, psu_dexterous, 1e9, psu_L)
    assert every.fraction == 1.0 and every.volume == pytest.approx(psu_dexterous.volume)
    none = dx.well_conditioned_volume(PSU, psu_dexterous, 1.0, psu_L)
    assert none.volume == 0.0 and none.well_conditioned == 0
    km = float(np.median(worst))
    mid = dx.well_conditioned_volume(PSU, psu_dexterous, km, psu_L)
    np.testing.assert_array_equal(mid.worst_kappa, worst)
    assert mid.well_conditioned == int(np.sum(worst <= km))
    assert mid.volume == pytest.approx(psu_dexterous.volume * np.mean(worst <= km))
    assert 0.3 < mid.fraction < 0.7


# ---- characteristic length: statuses, no silent fallback ------------------------------------


@dataclasses.dataclass(frozen=True, eq=False)
class _SingularEverywhere(PSU6):
    """Hopkins geometry with two equal Jacobian columns at every pose: Angeles' length is
    undefined (κ = inf for every L)."""

    def _jacobian(self, p, R):
        J = super()._jacobian(p, R)
        J[..., 5] = J[..., 4]
        return J


def test_characteristic_length_failure_is_a_status_and_every_user_says_so():
    mech = _SingularEverywhere(PSU.base_points, PSU.platform_points, PSU.link_length,
                               PSU.stroke, PSU.tool_offset)
    cl = dx.characteristic_length(mech)
    assert cl.status == "failed" and not cl.ok and math.isnan(cl.length)
    assert "singular" in cl.reason and cl.kappa == math.inf
    r = dx.resolve_length(mech)
    radius = float(np.mean(np.linalg.norm(mech.platform_points - mech.tool_offset, axis=1)))
    assert r.status == "fallback" and r.length == pytest.approx(radius, rel=1e-12)
    assert "Angeles' length failed" in r.reason and cl.reason in r.reason
    d = r.as_dict()
    assert d["length_mm"] == pytest.approx(radius) and d["kappa_at_pose"] is None
    # the workspace κ constraint says which L it used and why (it fell back without a word)
    res = workspace(mech, "constant", resolution=10.0,
                    constraints=pkmlab.Constraints(kappa_max=50.0))
    assert res.empty                                   # singular everywhere: κ = inf > 50
    assert any("fallback" in n and "Angeles' length failed" in n for n in res.notes)
    assert res.constraints.characteristic_length == pytest.approx(radius)
    # aggregates and the trajectory check carry the record
    plain = workspace(mech, "dexterous", OrientationSet.box(np.radians([5] * 3), samples=3), 10.0)
    w = dx.worst_case(mech, plain)
    assert w.length.status == "fallback" and w.singular and w.worst_kappa == math.inf
    g = dx.gci_monte_carlo(mech, plain, samples=50)
    assert g.length.status == "fallback" and g.gci == 0.0 and g.singular == g.samples
    from pkmlab.motion import check_trajectory

    X = np.tile(mech.nominal_pose, (3, 1))
    rep = check_trajectory(mech, [0.0, 1.0, 2.0], X)
    assert rep.length.status == "fallback" and not np.isfinite(rep.condition).any()
    assert rep.summary()["characteristic_length"]["status"] == "fallback"


def test_characteristic_length_given_and_angeles_records():
    given = dx.resolve_length(PSU, 42.0)
    assert given.status == "given" and given.length == 42.0 and not given.ok
    J = PSU.jacobian(PSU.nominal_pose)
    assert given.kappa == pytest.approx(dx.condition_number(J, 42.0)[0])
    auto = dx.resolve_length(PSU)
    assert auto.status == "angeles" and auto.ok and auto == dx.characteristic_length(PSU)
    assert dx.resolve_length(PSU, auto) is auto
    with pytest.raises(pkmlab.ParameterError):
        dx.resolve_length(PSU, -1.0)
