"""The planar 3-RPR family (issue 24, item 3): contract suite, the sextic's assembly modes
against a published count and an independent multi-start loop-closure solve of the declared
joints, working modes and the singularity classification."""

from __future__ import annotations

import numpy as np
import pytest

from pkmlab import testing
from pkmlab.mechanisms import REGISTRY
from pkmlab.mechanisms.families import planar_fk
from pkmlab.mechanisms.families.rpr3 import Rpr3, triangle_layout


def published():
    """Zein, Wenger & Chablat (2008), "Non-singular assembly-mode changing motions for 3-RPR
    parallel manipulators", Mech. Mach. Theory 43(4), after Innocenti & Parenti-Castelli:
    A1 = (0, 0), A2 = (15.91, 0), A3 = (0, 10); platform sides d1 = |B1B2| = 17.04,
    d2 = |B2B3| = 16.54, d3 = |B3B1| = 20.84; at ρ = (14.98, 15.38, 12) the direct
    kinematics has six real solutions. Reading: B1 at the platform origin, B2 on its x axis,
    B3 on the positive-y side (a mirror platform gives the mirrored six)."""
    d1, d2, d3 = 17.04, 16.54, 20.84
    x = (d1 ** 2 + d3 ** 2 - d2 ** 2) / (2 * d1)
    U = np.array([[0.0, 0.0, 0.0], [d1, 0.0, 0.0], [x, np.sqrt(d3 ** 2 - x ** 2), 0.0]])
    A = np.array([[0.0, 0.0, 0.0], [15.91, 0.0, 0.0], [0.0, 10.0, 0.0]])
    return Rpr3(A, U, (1.0, 40.0), nominal=np.zeros(6)), np.array([14.98, 15.38, 12.0])


@pytest.fixture(scope="module")
def mech():
    b, u = triangle_layout(300.0, 80.0, np.radians(60.0))
    return Rpr3(b, u, (150.0, 450.0))


def test_registered_and_contract_suite(mech):
    assert REGISTRY["rpr3"] is Rpr3
    assert testing.run_contract(mech) == list(testing.CHECKS)
    assert mech.jacobian(mech.nominal_pose).shape == (1, 3, 3)
    assert mech.mobility.coordinates == ("x", "y", "theta_z")


def test_ik_against_plain_distances_and_status_per_actuator(mech):
    rng = np.random.default_rng(0)
    X = np.zeros((200, 6))
    X[:, :2] = rng.uniform(-300, 300, (200, 2))
    X[:, 5] = rng.uniform(-np.pi, np.pi, 200)
    ik = mech.inverse(X)
    c, s = np.cos(X[:, 5]), np.sin(X[:, 5])
    u = mech.platform_points[:, :2]
    B = np.stack([X[:, None, 0] + c[:, None] * u[:, 0] - s[:, None] * u[:, 1],
                  X[:, None, 1] + s[:, None] * u[:, 0] + c[:, None] * u[:, 1]], axis=-1)
    rho = np.linalg.norm(B - mech.base_points[:, :2], axis=-1)
    np.testing.assert_allclose(ik.q, rho, rtol=1e-14, atol=1e-12)
    expect = np.where(rho < 150.0, 1, np.where(rho > 450.0, 2, 0))
    np.testing.assert_array_equal(ik.leg_status, expect)
    assert ik.valid.tolist() == (expect.max(axis=1) == 0).tolist()
    assert 0 < ik.valid.sum() < 200


def test_sextic_fourth_harmonic_cancels(mech):
    rng = np.random.default_rng(1)
    rho = rng.uniform(150, 450, (50, 3))
    C = planar_fk.rpr3_polynomial(mech.base_points[:, :2], mech.tool_points[:, :2], rho)
    rel = np.maximum(np.abs(C[:, 0]), np.abs(C[:, 8])) / np.abs(C).max(axis=1)
    assert rel.max() < 1e-12


def test_published_example_has_six_assembly_modes_each_closing_the_legs():
    m, rho = published()
    modes = m.assembly_modes(rho)
    assert len(modes.pose) == 6 and modes.starts == 0 and modes.working_mode.all()
    # independent check of each mode: the three leg equations in plain numpy
    for x, y, phi in modes.pose[:, [0, 1, 5]]:
        c, s = np.cos(phi), np.sin(phi)
        B = np.array([x, y]) + m.platform_points[:, :2] @ np.array([[c, s], [-s, c]])
        np.testing.assert_allclose(np.linalg.norm(B - m.base_points[:, :2], axis=1), rho,
                                   atol=1e-9)
    # the six are distinct
    d = np.abs(modes.pose[:, None, [0, 1, 5]] - modes.pose[None, :, [0, 1, 5]]).sum(-1)
    assert np.min(d[np.triu_indices(6, 1)]) > 0.1


def _joint_solve(m, rho, starts=400, seed=0):
    """Independent multi-start loop closure from the declared joints (``legs()``): base R
    centres and platform R mount points; Newton with a finite-difference Jacobian in plain
    numpy from ``starts`` random poses; distinct converged solutions (1e-6 mm / rad)."""
    legs = m.legs()
    a = np.array([leg.joints[0].location[:2] for leg in legs])
    u = np.array([leg.joints[-1].mount_location[:2] for leg in legs]) - m.tool_offset[:2]
    rng = np.random.default_rng(seed)
    S = m.scale
    Z = np.column_stack([rng.uniform(-S, S, (starts, 2)), rng.uniform(-np.pi, np.pi, starts)])

    def f(Z):
        c, s = np.cos(Z[:, 2:]), np.sin(Z[:, 2:])
        B = np.stack([Z[:, :1] + c * u[:, 0] - s * u[:, 1], Z[:, 1:2] + s * u[:, 0]
                      + c * u[:, 1]], -1)
        return np.sum((B - a) ** 2, axis=-1) - rho ** 2

    for _ in range(60):
        F = f(Z)
        J = np.stack([(f(Z + h) - f(Z - h)) / 2e-6 for h in 1e-6 * np.eye(3)], axis=-1)
        with np.errstate(all="ignore"):
            dz = np.linalg.solve(J + 1e-12 * np.eye(3), F[..., None])[..., 0]
        n = np.linalg.norm(dz[:, :2], axis=1) / (0.2 * S) + np.abs(dz[:, 2]) / 0.5
        Z = Z - dz / np.maximum(1.0, n)[:, None]
    ok = np.max(np.abs(f(Z)), axis=1) < 1e-6 * np.max(rho) ** 2
    Z = Z[ok & np.all(np.isfinite(Z), axis=1)]
    Z[:, 2] = np.angle(np.exp(1j * Z[:, 2]))
    out = []
    for z in Z:
        if not any(np.abs(z[:2] - w[:2]).max() < 1e-5 and
                   abs(np.angle(np.exp(1j * (z[2] - w[2])))) < 1e-6 for w in out):
            out.append(z)
    return np.array(out)


def test_sextic_against_multistart_loop_closure_of_the_joints(mech):
    """The published vector, 12 from random valid poses of the shipped layout and 12 near the
    published vector (±3 on each leg): the same number of real modes and the same poses
    (1e-6 mm / rad) as 400-start Newton on the joints."""
    m0, rho0 = published()
    cases = [(m0, rho0)]
    rng = np.random.default_rng(3)
    X = np.zeros((12, 6))
    X[:, :2] = rng.uniform(-120, 120, (12, 2))
    X[:, 5] = rng.uniform(-1.0, 1.0, 12)
    cases += [(mech, q) for q in mech.inverse(X).q]
    cases += [(m0, rho0 + rng.uniform(-3.0, 3.0, 3)) for _ in range(12)]
    counts = []
    for m, q in cases:
        sext = m.assembly_modes(q).pose[:, [0, 1, 5]]
        ref = _joint_solve(m, q)
        counts.append(len(sext))
        assert len(sext) == len(ref), (q, len(sext), len(ref))
        for z in ref:
            d = np.abs(sext[:, :2] - z[:2]).max(axis=1) + np.abs(
                np.angle(np.exp(1j * (sext[:, 2] - z[2]))))
            assert d.min() < 1e-6
    assert counts[0] == 6 and all(c % 2 == 0 for c in counts), counts
    assert max(counts[1:]) >= 4, counts


def test_forward_all_contains_the_pose_of_every_round_trip(mech):
    X = testing.random_valid_poses(mech, 300, seed=4, lin=150.0, ang_deg=40.0)
    q = mech.inverse(X).q
    poses, count = mech.forward_all(q)
    assert np.all(count >= 1) and np.all(count <= 6) and np.all(count % 2 == 0)
    err = np.abs(poses[:, :, [0, 1]] - X[:, None, [0, 1]]).max(axis=-1) + np.abs(
        np.angle(np.exp(1j * (poses[:, :, 5] - X[:, None, 5]))))
    assert np.nanmin(err, axis=1).max() < 1e-9


def test_working_modes_and_singularity_classification(mech):
    assert mech.working_modes() == ("+++",)
    # type II: the symmetric layout without platform rotation, centred at φ = 0: every leg
    # line passes through the centre (concurrent)
    b, u = triangle_layout(300.0, 80.0, 0.0)
    radial = Rpr3(b, u, (150.0, 450.0))
    assert radial.singularity(radial.nominal_pose).tolist() == [2]
    from pkmlab.dexterity import condition_number, resolve_length

    assert np.isinf(condition_number(radial.jacobian(radial.nominal_pose),
                                     resolve_length(radial, 100.0)))[0]
    # type I: a platform pivot on its base pivot (a leg length 0)
    X = np.zeros(6)
    X[:2] = mech.base_points[0, :2] - mech.platform_points[0, :2]
    assert mech.singularity(X).tolist() == [1]
    assert mech.singularity(mech.nominal_pose).tolist() == [0]
    # det A changes sign across the type II locus: along φ at the radial design's centre
    phis = np.linspace(-0.2, 0.2, 41)
    P = np.zeros((41, 6))
    P[:, 5] = phis
    det = radial.parallel_determinant(P)
    assert det[0] * det[-1] < 0 and abs(det[20]) < 1e-12
