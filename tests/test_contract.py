"""Contract suite: the checks of :mod:`pkmlab.testing`, run on every registered family
(see conftest.MECHANISMS)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import random_valid_poses

from pkmlab import testing


def test_ik_fk_round_trip_1000_poses(mech):
    testing.check_round_trip(mech, 1000)


def test_jacobian_matches_finite_differences(mech):
    testing.check_jacobian(mech)


def test_batched_equals_one_at_a_time_and_matrix_input(mech):
    testing.check_batching(mech)


def test_statuses_are_data(mech):
    testing.check_statuses(mech)


def test_stroke_violations_along_z_for_prismatic_families(mech):
    if mech.actuator_unit != "mm":
        pytest.skip("rotary actuators: the override windows of check_statuses cover it")
    if not np.all(mech.jacobian(mech.nominal_pose)[0, :, 2] > 0):
        pytest.skip("not every actuator rises with z (e.g. horizontal rails): the override "
                    "windows of check_statuses cover it")
    lo, hi = mech.stroke
    span = hi - lo
    X = np.repeat(mech.nominal_pose[None], 3, axis=0)
    X[1, 2] += 0.75 * span + 1.0         # every actuator pushed past its maximum
    X[2, 2] -= 0.75 * span + 1.0         # ... and below its minimum
    ik = mech.inverse(X)
    assert ik.valid.tolist() == [True, False, False]
    assert ik.reason_text[1] == "stroke above maximum"
    assert ik.reason_text[2] == "stroke below minimum"
    assert np.all(np.isfinite(ik.q))


def test_assembly_modes_nominal_first_and_doubling_starts_finds_nothing_new(mech):
    testing.check_assembly_modes(mech)


def test_bad_pose_shape_raises_named_error(mech):
    testing.check_bad_shapes(mech)


def test_joint_chains_close(mech):
    testing.check_joints(mech)


def test_parameters_round_trip(mech):
    testing.check_parameters(mech)


def test_checks_can_fail(mech):
    """A Jacobian with one wrong entry, or a leg whose status hides a NaN, is caught."""
    import dataclasses

    # a free column: a rotation one, or a translation one for a translational mechanism
    col, what = (4, "rotation") if mech.mobility.rotations else (0, "translation")

    class Broken(type(mech)):
        def _jacobian(self, p, R):
            J = super()._jacobian(p, R)
            J[:, 2, col] *= 1.001
            return J

    broken = Broken(**{f.name: getattr(mech, f.name) for f in dataclasses.fields(mech)
                       if f.init})
    with pytest.raises(AssertionError, match=f"{what} columns"):
        testing.check_jacobian(broken)
    # the fused IK + Jacobian pass honours a subclass's own Jacobian too
    X = random_valid_poses(mech, 3, seed=2)
    np.testing.assert_array_equal(broken.inverse_and_jacobian(X)[1], broken.jacobian(X))
    np.testing.assert_allclose(mech.inverse_and_jacobian(X)[1], mech.jacobian(X), rtol=1e-14,
                               atol=1e-14)


def test_conftest_poses_are_the_testing_ones(mech):
    np.testing.assert_array_equal(random_valid_poses(mech, 5, seed=9),
                                  testing.random_valid_poses(mech, 5, seed=9))
