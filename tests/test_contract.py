"""Contract suite: runs against every registered mechanism family (see conftest.MECHANISMS)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import random_valid_poses

from pkmlab.mechanisms import LEG_STATUS, NO_STROKE
from pkmlab.poses import as_frames, euler_to_matrix, exp_so3, log_so3

REASON = {v: k for k, v in LEG_STATUS.items()}


def rotation_error(X1, X2):
    R1, R2 = euler_to_matrix(X1[:, 3:]), euler_to_matrix(X2[:, 3:])
    return np.linalg.norm(log_so3(np.einsum("nji,njk->nik", R1, R2)), axis=1)


def test_ik_fk_round_trip_1000_poses(mech):
    X = random_valid_poses(mech, 1000, seed=1)
    q = mech.inverse(X).q
    fk = mech.forward(q)                       # starts from the nominal pose
    assert fk.converged.all(), f"{(~fk.converged).sum()} of 1000 did not converge"
    assert np.max(np.abs(fk.pose[:, :3] - X[:, :3])) < 1e-9          # mm
    assert np.max(rotation_error(fk.pose, X)) < 1e-9                   # rad
    assert np.max(fk.residual) < 1e-9


def test_jacobian_matches_central_differences(mech):
    X = random_valid_poses(mech, 40, seed=2)
    p, R = as_frames(X)
    J = mech.jacobian(X)
    h = 1e-4
    Jfd = np.empty_like(J)
    for j in range(6):
        d = np.zeros(6)
        d[j] = h
        if j < 3:
            qp = mech.inverse((p + d[:3], R), stroke=NO_STROKE).q
            qm = mech.inverse((p - d[:3], R), stroke=NO_STROKE).q
        else:
            qp = mech.inverse((p, exp_so3(d[3:]) @ R), stroke=NO_STROKE).q
            qm = mech.inverse((p, exp_so3(-d[3:]) @ R), stroke=NO_STROKE).q
        Jfd[:, :, j] = (qp - qm) / (2 * h)
    # Relative to each pose's largest entry, column by column (translation vs rotation).
    for cols in (slice(0, 3), slice(3, 6)):
        scale = np.max(np.abs(J[:, :, cols]), axis=(1, 2), keepdims=True)
        rel = np.abs(J[:, :, cols] - Jfd[:, :, cols]) / scale
        assert rel.max() < 1e-6, rel.max()


def test_batched_equals_one_at_a_time(mech):
    X = random_valid_poses(mech, 12, seed=3)
    ik = mech.inverse(X)
    J = mech.jacobian(X)
    fk = mech.forward(ik.q)
    for i in range(len(X)):
        one = mech.inverse(X[i])
        np.testing.assert_array_equal(one.q[0], ik.q[i])
        np.testing.assert_array_equal(one.leg_status[0], ik.leg_status[i])
        np.testing.assert_array_equal(mech.jacobian(X[i])[0], J[i])
        np.testing.assert_allclose(mech.forward(ik.q[i]).pose[0], fk.pose[i], atol=1e-12)


def test_matrix_input_equals_euler_input(mech):
    X = random_valid_poses(mech, 20, seed=4)
    T = np.zeros((20, 4, 4))
    T[:, :3, :3] = euler_to_matrix(X[:, 3:])
    T[:, :3, 3] = X[:, :3]
    T[:, 3, 3] = 1.0
    np.testing.assert_allclose(mech.inverse(T).q, mech.inverse(X).q, atol=1e-10)
    np.testing.assert_allclose(mech.jacobian(T), mech.jacobian(X), atol=1e-10)


def test_stroke_violations_flagged_with_reason(mech):
    lo, hi = mech.stroke
    span = hi - lo
    X = np.repeat(mech.nominal_pose[None], 3, axis=0)
    X[1, 2] += 0.75 * span + 1.0         # every actuator pushed past its maximum
    X[2, 2] -= 0.75 * span + 1.0         # ... and below its minimum
    ik = mech.inverse(X)
    assert ik.valid.tolist() == [True, False, False]
    assert ik.reason_text[1] == "stroke above maximum"
    assert ik.reason_text[2] == "stroke below minimum"
    # Values outside the stroke are still reported (not NaN): they are the geometry's answer.
    assert np.all(np.isfinite(ik.q))


def test_non_finite_pose_is_flagged_not_crashing(mech):
    X = np.repeat(mech.nominal_pose[None], 2, axis=0)
    X[1, 4] = np.nan
    ik = mech.inverse(X)
    assert ik.valid.tolist() == [True, False]
    assert ik.reason_text[1] == "non-finite pose"
    assert np.all(ik.leg_status[1] == REASON["non-finite pose"])


def test_forward_reports_failure_as_data(mech):
    q = mech.inverse(mech.nominal_pose).q[0]
    # Adjacent legs 1 mm and 5 m long cannot close any loop (triangle inequality).
    impossible = np.array([1.0, 5000.0, 1.0, 5000.0, 1.0, 5000.0])
    bad = np.array([q, impossible, np.full(6, np.nan)])
    fk = mech.forward(bad)
    assert fk.converged.tolist() == [True, False, False]
    assert np.all(np.isnan(fk.pose[1:]))
    assert all(s in ("not converged", "singular") for s in fk.status[1:])


def test_assembly_modes_nominal_first_and_doubling_starts_finds_nothing_new(mech):
    q = mech.inverse(mech.nominal_pose).q[0]
    a = mech.assembly_modes(q, starts=1000, seed=0)
    b = mech.assembly_modes(q, starts=2000, seed=1)
    assert np.allclose(a.pose[0], mech.nominal_pose, atol=1e-8)
    assert a.working_mode[0]
    assert np.all(a.residual < 1e-9)
    assert len(a.residual) == len(b.residual), (len(a.residual), len(b.residual))
    for X in b.pose:       # every mode of the larger search is in the smaller one
        d = np.abs(a.pose[:, :3] - X[:3]).max(axis=1) + rotation_error(
            a.pose, np.repeat(X[None], len(a.pose), 0))
        assert d.min() < 1e-6
    # Each mode really closes the loops: its IK (any branch) is consistent with q.
    for X in a.pose[a.working_mode]:
        np.testing.assert_allclose(mech.inverse(X).q[0], q, atol=1e-7)


@pytest.mark.parametrize("shape", [(5,), (3, 5), (2, 3, 3)])
def test_bad_pose_shape_raises_named_error(mech, shape):
    with pytest.raises(ValueError, match="poses: must be an array of shape"):
        mech.jacobian(np.zeros(shape))
